!> The one table of what a run outputs: name, SI unit ('-' a ratio, '' none, e.g. a count) and
!> a one-line description of every output quantity (the time, the states, T_m and k_v, the
!> per-tooth quantities) and of every run statistic. The executable's CSV header, Python's
!> Result and sweep datasets (api_names) and the README's result table follow it
!> (tests/test_names.py); adding a quantity means adding its row here. The positions of the
!> statistics in a run's stats array are named here too (ist_*).
module spline_quantities
  use spline_model, only: nstate
  implicit none
  private
  public :: quantity_t, nout_q, output_q, state_q, tooth_q, ntooth_q, iq_tf
  public :: nsolver_stats, nstats, stat_q, nload_tooth, load_tooth_q, nload, load_q, nextreme, extreme_q

  type :: quantity_t
    character(len=24) :: name
    character(len=16) :: unit
    character(len=128) :: descr
  end type quantity_t

  !> The states, in the order of a state vector y (SI).
  type(quantity_t), parameter :: state_q(nstate) = [ &
       quantity_t('x1', 'm', 'x displacement of spline 1'), &
       quantity_t('y1', 'm', 'y displacement of spline 1'), &
       quantity_t('x2', 'm', 'x displacement of spline 2'), &
       quantity_t('y2', 'm', 'y displacement of spline 2'), &
       quantity_t('D1', 'm', 'torsional displacement D_1 (motor - spline 1, on the base circle)'), &
       quantity_t('D2', 'm', &
            'relative displacement D_2 (spline 1 - spline 2, on the base circle)'), &
       quantity_t('D3', 'm', 'torsional displacement D_3 (spline 2 - load, on the base circle)'), &
       quantity_t('vx1', 'm/s', 'velocity of x1'), quantity_t('vy1', 'm/s', 'velocity of y1'), &
       quantity_t('vx2', 'm/s', 'velocity of x2'), quantity_t('vy2', 'm/s', 'velocity of y2'), &
       quantity_t('vD1', 'm/s', 'velocity of D1'), quantity_t('vD2', 'm/s', 'velocity of D2'), &
       quantity_t('vD3', 'm/s', 'velocity of D3')]

  !> The per-tooth quantities (spline_run::tooth_quantities), at every output time.
  integer, parameter :: ntooth_q = 8
  integer, parameter :: iq_tf = 6                  !< position of T_f in tooth_q
  type(quantity_t), parameter :: tooth_q(ntooth_q) = [ &
       quantity_t('F', 'N', 'tooth load F_j (Eqs. 15-17)'), &
       quantity_t('Fx', 'N', 'x component of the tooth load'), &
       quantity_t('Fy', 'N', 'y component of the tooth load'), &
       quantity_t('dn', 'm', 'relative displacement along the line of action dn_j (Eq. 11)'), &
       quantity_t('c', 'm', 'backlash c_j (Eq. 2)'), &
       quantity_t('Tf', 'degC', 'flash temperature T_f (Eqs. 3-7)'), &
       quantity_t('rc1', 'm', 'contact-point radius on the external spline (Eq. 13, one point per tooth pair)'), &
       quantity_t('rc2', 'm', 'contact-point radius on the internal spline (Eq. 13, one point per tooth pair)')]

  !> Every output quantity in the order of the executable's CSV columns: the time, the states,
  !> T_m, k_v, then the per-tooth quantities (one column per tooth each).
  integer, parameter :: nout_q = 1 + nstate + 2 + ntooth_q
  type(quantity_t), parameter :: output_q(nout_q) = [ &
       quantity_t('t', 's', 'output time'), state_q, &
       quantity_t('Tm', 'N m', 'meshing torque T_m (Eq. 22)'), &
       quantity_t('kv', '-', 'dynamic load coefficient k_v = |T_m|/|T_d|'), tooth_q]

  !> The statistics of a run: the solver's (spline_solver::integrate fills stats(1:
  !> nsolver_stats)), then the run's (spline_run::run_case).
  integer, parameter, public :: ist_steps = 1, ist_rhs_evals = 2, ist_jac_evals = 3, &
       ist_lin_rhs_evals = 4, ist_err_test_fails = 5, ist_nonlin_conv_fails = 6, &
       ist_roots_found = 7, ist_root_fn_evals = 8, ist_last_step = 9, ist_mode_resyncs = 10, &
       ist_coupling_residual = 11, ist_coupling_iterations = 12, ist_linear_tail_t = 13
  integer, parameter :: nsolver_stats = 13
  integer, parameter, public :: ist_core_wall = nsolver_stats + 1, ist_dof = nsolver_stats + 2, &
       ist_thermal_level = nsolver_stats + 3, ist_eps_lateral = nsolver_stats + 4, &
       ist_eps_thermal = nsolver_stats + 5, ist_closed = nsolver_stats + 6, &
       ist_closed_t = nsolver_stats + 7, ist_f_error = nsolver_stats + 8, &
       ist_f_error_t = nsolver_stats + 9, ist_f_parted_t = nsolver_stats + 10, &
       ist_rtol_used = nsolver_stats + 11, ist_outputs_fallback = nsolver_stats + 12
  integer, parameter :: nstats = nsolver_stats + 12
  type(quantity_t), parameter :: stat_q(nstats) = [ &
       quantity_t('steps', '', 'CVODE steps (all restarts)'), &
       quantity_t('rhs_evals', '', 'right-hand-side evaluations of CVODE'), &
       quantity_t('jac_evals', '', 'Jacobian evaluations (Newton iteration)'), &
       quantity_t('lin_rhs_evals', '', 'right-hand-side evaluations of the difference-quotient &
            &Jacobian'), &
       quantity_t('err_test_fails', '', 'local error test failures'), &
       quantity_t('nonlin_conv_fails', '', 'nonlinear solver convergence failures'), &
       quantity_t('roots_found', '', 'contact switches located by root finding'), &
       quantity_t('root_fn_evals', '', 'root function evaluations'), &
       quantity_t('last_step_s', 's', 'last step size of CVODE'), &
       quantity_t('mode_resyncs', '', 'contact states resynchronised at output times (switches &
            &missed)'), &
       quantity_t('coupling_residual_degC', 'degC', 'largest residual |T - T_f(F(T))| of the &
            &flash-temperature coupling accepted'), &
       quantity_t('coupling_iterations', '', 'most secant iterations of the flash-temperature &
            &coupling on one tooth'), &
       quantity_t('linear_tail_t_s', 's', 'time the closed-form linear tail began (-1: none)'), &
       quantity_t('core_wall_s', 's', 'elapsed time of the run in the core'), &
       quantity_t('dof', '', 'degrees of freedom of the model level that ran (7 or 3)'), &
       quantity_t('thermal_level', '', 'thermal level that ran (0 none, 1 bulk, 2 oneway, &
            &3 coupled)'), &
       quantity_t('fidelity_eps_lateral', '-', 'fidelity auto: estimated relative error of the &
            &torsional model (0: not estimated)'), &
       quantity_t('fidelity_eps_thermal', '-', 'fidelity auto: estimated relative error of the &
            &cheaper thermal level (0: not estimated)'), &
       quantity_t('backlash_closed', '', 'one-way samples (time, tooth) whose flash temperature &
            &closes the backlash (Eq. 2)'), &
       quantity_t('backlash_closed_t_s', 's', 'first time the one-way flash temperature closes &
            &the backlash (Eq. 2)'), &
       quantity_t('F_error_est', '-', 'estimated error of F_j: max |F_j - F_j of a tighter run| &
            &/ max |F_j| up to F_error_t_s (-1: not estimated; docs/accuracy.md)'), &
       quantity_t('F_error_t_s', 's', 'last output compared for F_error_est: the run''s end, &
            &its linear tail, or before a tighter run parts from it (-1: none)'), &
       quantity_t('F_parted_t_s', 's', 'first output where a tighter run''s F_j differ by over &
            &0.1 max |F_j|: the trajectories part (chaos; -1: never, or not estimated)'), &
       quantity_t('rtol_used', '-', 'relative tolerance of the run (the case''s, or what accuracy &
            &or goal picked)'), &
       quantity_t('outputs_fallback', '', '1: per-tooth outputs from mesh_eval at every output, &
            &as mesh_outputs differed from it at the first or last (a drift; 0 expected)')]

  !> The loads of a run (spline_loads::run_loads, docs/model.md section 15), per tooth: their
  !> positions in a run's tooth-load array (ilt_*) and the table.
  integer, parameter, public :: ilt_f_peak = 1, ilt_load_factor = 2, ilt_free = 3, &
       ilt_back = 4, ilt_onsets = 5, ilt_free_se = 6, ilt_back_se = 7
  integer, parameter :: nload_tooth = 7
  type(quantity_t), parameter :: load_tooth_q(nload_tooth) = [ &
       quantity_t('F_peak', 'N', 'largest tooth load |F_j| over the outputs'), &
       quantity_t('load_factor', '-', 'tooth load factor F_peak / (T_d / (Z r_b))'), &
       quantity_t('free_frac', '-', 'fraction of the outputs the tooth is free (F_j = 0)'), &
       quantity_t('back_frac', '-', 'fraction of the outputs the tooth is in contact on its &
            &back flank'), &
       quantity_t('onsets', '', 'contact onsets (impacts): free or on the other flank at one &
            &output, in contact at the next'), &
       quantity_t('free_frac_se', '-', 'standard error of free_frac by overlapping batch means &
            &of revolutions (NaN: < 2 batches)'), &
       quantity_t('back_frac_se', '-', 'standard error of back_frac by overlapping batch means &
            &of revolutions (NaN: < 2 batches)')]

  !> The loads of a run, the scalars: their positions in a run's load array (il_*) and the table.
  integer, parameter, public :: il_f_static = 1, il_load_sharing = 2, il_load_sharing_tooth = 3, &
       il_free_max = 4, il_back_max = 5, il_free_mean = 6, il_unloaded = 7, il_back_teeth = 8, &
       il_impacts_rev = 9, il_closing_speed = 10, il_tf_max = 11, il_tf_max_tooth = 12, &
       il_tf_max_t = 13, il_revolutions = 14, il_batches = 15, il_tm_rms_se = 16, &
       il_sharing_rev = 17, il_sharing_rev_se = 18, il_sigma_root = 19, il_sigma_flank = 20, &
       il_tau_pitch = 21, il_kv_rms_se = 22, il_f_rms_se = 23, il_d2_rms_se = 24, &
       il_free_mean_se = 25, il_free_max_se = 26, il_back_max_se = 27, il_impacts_rev_se = 28, &
       il_tf_rev = 29, il_tf_rev_se = 30, il_stress_ratio = 31
  integer, parameter :: nload = 31
  type(quantity_t), parameter :: load_q(nload) = [ &
       quantity_t('F_static', 'N', 'static tooth load of equal load sharing |T_d| / (Z r_b)'), &
       quantity_t('load_sharing', '-', 'load-sharing factor: the largest tooth load factor'), &
       quantity_t('load_sharing_tooth', '', 'the tooth of the largest load factor'), &
       quantity_t('free_frac_max', '-', 'largest fraction of the outputs a tooth is free'), &
       quantity_t('back_frac_max', '-', 'largest fraction of the outputs a tooth is on its &
            &back flank'), &
       quantity_t('teeth_free_mean', '', 'mean number of free teeth at an output'), &
       quantity_t('teeth_unloaded', '', 'teeth free at every output'), &
       quantity_t('teeth_back', '', 'teeth on their back flank at some output'), &
       quantity_t('impacts_per_rev', '', 'contact onsets of all teeth per shaft revolution'), &
       quantity_t('closing_speed_max', 'm/s', 'largest |d dn_j/dt| at the output before a &
            &contact onset'), &
       quantity_t('Tf_max', 'degC', 'largest flash temperature T_f over teeth and outputs'), &
       quantity_t('Tf_max_tooth', '', 'the tooth of the largest T_f (0: T_f is 0 throughout)'), &
       quantity_t('Tf_max_t_s', 's', 'the time of the largest T_f (-1: T_f is 0 throughout)'), &
       quantity_t('revolutions', '', 'shaft revolutions spanned by the outputs'), &
       quantity_t('batches', '', 'whole revolutions of the outputs, the values the &
            &standard errors are taken over'), &
       quantity_t('Tm_rms_se', 'N m', 'standard error of the RMS of T_m by overlapping batch &
            &means of sqrt(batches) revolutions (NaN: < 2 batches)'), &
       quantity_t('load_sharing_rev', '-', 'mean over the revolutions of each one''s &
            &load-sharing factor'), &
       quantity_t('load_sharing_rev_se', '-', 'standard error of load_sharing_rev by overlapping &
            &batch means (NaN: < 2 batches)'), &
       quantity_t('sigma_root', 'Pa', 'nominal root bending stress of the most loaded tooth at &
            &its peak load, 6 F cos(alpha) h_f / (b t_f^2)'), &
       quantity_t('sigma_flank', 'Pa', 'nominal flank bearing (compressive) stress at that load, &
            &F cos(alpha) / (b h_w)'), &
       quantity_t('tau_pitch', 'Pa', 'nominal tooth shear stress at the pitch circle at that load, &
            &F cos(alpha) / (b s)'), &
       quantity_t('kv_rms_se', '-', 'standard error of the RMS of k_v by overlapping batch means &
            &(NaN: < 2 batches or T_d = 0)'), &
       quantity_t('F_rms_se', 'N', 'standard error of the RMS of the tooth loads F_j over all &
            &teeth by overlapping batch means (NaN: < 2 batches)'), &
       quantity_t('D2_rms_se', 'm', 'standard error of the RMS of D_2 by overlapping batch means &
            &(NaN: < 2 batches)'), &
       quantity_t('teeth_free_mean_se', '', 'standard error of teeth_free_mean by overlapping &
            &batch means (NaN: < 2 batches)'), &
       quantity_t('free_frac_max_se', '-', 'standard error of the free fraction of the tooth of &
            &free_frac_max (NaN: < 2 batches)'), &
       quantity_t('back_frac_max_se', '-', 'standard error of the back-flank fraction of the &
            &tooth of back_frac_max (NaN: < 2 batches)'), &
       quantity_t('impacts_per_rev_se', '', 'standard error of the contact onsets per &
            &revolution by overlapping batch means (NaN: < 2 batches)'), &
       quantity_t('Tf_max_rev', 'degC', 'mean over the revolutions of each one''s largest T_f'), &
       quantity_t('Tf_max_rev_se', 'degC', 'standard error of Tf_max_rev by overlapping batch &
            &means (NaN: < 2 batches)'), &
       quantity_t('stress_ratio', '-', 'largest of sigma_root, sigma_flank, tau_pitch over its &
            &limit (1: at the typical allowable warned beyond)')]

  !> The extremes and RMS of a run's outputs (spline_loads::run_extremes): max, min and RMS
  !> (sqrt(mean(x**2))) of T_m, k_v, the tooth loads F_j and flash temperatures T_f over all
  !> teeth, D_2 and dD_2/dt; what a sweep point keeps and spline-dyn's summary writes (run.*).
  integer, parameter :: nextreme = 18
  type(quantity_t), parameter :: extreme_q(nextreme) = [ &
       quantity_t('Tm_max', 'N m', 'largest T_m'), quantity_t('Tm_min', 'N m', 'smallest T_m'), &
       quantity_t('Tm_rms', 'N m', 'RMS of T_m'), quantity_t('kv_max', '-', 'largest k_v'), &
       quantity_t('kv_min', '-', 'smallest k_v'), quantity_t('kv_rms', '-', 'RMS of k_v'), &
       quantity_t('F_max', 'N', 'largest tooth load F_j over all teeth'), &
       quantity_t('F_min', 'N', 'smallest tooth load F_j over all teeth'), &
       quantity_t('F_rms', 'N', 'RMS of the tooth loads F_j over all teeth'), &
       quantity_t('Tf_max', 'degC', 'largest flash temperature T_f over all teeth'), &
       quantity_t('Tf_min', 'degC', 'smallest flash temperature T_f over all teeth'), &
       quantity_t('Tf_rms', 'degC', 'RMS of the flash temperatures T_f over all teeth'), &
       quantity_t('D2_max', 'm', 'largest D_2'), quantity_t('D2_min', 'm', 'smallest D_2'), &
       quantity_t('D2_rms', 'm', 'RMS of D_2'), quantity_t('vD2_max', 'm/s', 'largest dD_2/dt'), &
       quantity_t('vD2_min', 'm/s', 'smallest dD_2/dt'), quantity_t('vD2_rms', 'm/s', 'RMS of dD_2/dt')]

end module spline_quantities
