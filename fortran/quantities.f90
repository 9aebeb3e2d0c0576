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
  public :: nsolver_stats, nstats, stat_q

  type :: quantity_t
    character(len=24) :: name
    character(len=16) :: unit
    character(len=96) :: descr
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
       quantity_t('rc1', 'm', 'contact-point radius on the external spline (Eqs. 13-14)'), &
       quantity_t('rc2', 'm', 'contact-point radius on the internal spline (Eqs. 13-14)')]

  !> Every output quantity in the order of the executable's CSV columns: the time, the states,
  !> T_m, k_v, then the per-tooth quantities (one column per tooth each).
  integer, parameter :: nout_q = 1 + nstate + 2 + ntooth_q
  type(quantity_t), parameter :: output_q(nout_q) = [ &
       quantity_t('t', 's', 'output time'), state_q, &
       quantity_t('Tm', 'N m', 'meshing torque T_m (Eq. 22)'), &
       quantity_t('kv', '-', 'dynamic load coefficient k_v = |T_m|/T_d'), tooth_q]

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
       ist_closed_t = nsolver_stats + 7
  integer, parameter :: nstats = nsolver_stats + 7
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
            &the backlash (Eq. 2)')]

end module spline_quantities
