!> One simulation of a case, shared by the executable and the Python API: output times,
!> start state (static equilibrium by default), integration, and the per-tooth quantities
!> (Eqs. 11, 15-22 and, for the thermal levels that have it, Eqs. 1-7) at every output time.
module spline_run
  use spline_kinds, only: wp
  use spline_errors, only: err_ok
  use spline_model, only: model_t, nstate, ndof, thermal_none, thermal_bulk, thermal_oneway, &
       thermal_coupled, set_thermal_level
  use spline_dynamics, only: start_state
  use spline_mesh, only: mesh_eval
  use spline_solver, only: integrate, nsolver_stats => nstats, solver_stat_names => stat_names
  use spline_fidelity, only: lateral_estimate, backlash_estimate
  implicit none
  private
  public :: run_case, output_times, tooth_outputs, tooth_quantities, ntooth_q, tooth_q_names, tooth_q_units
  public :: nstats, stat_names

  !> Statistics of a run: the solver's, then the core's elapsed time, the model level that ran
  !> (dof, thermal 0 none .. 3 coupled) and the fidelity estimates of spline_fidelity.
  real(wp), parameter :: fidelity_margin = 0.5_wp   !< auto reduces when estimate <= margin * tol
  integer, parameter :: nstats = nsolver_stats + 5
  character(len=24), parameter :: stat_names(nstats) = [solver_stat_names, [character(len=24) :: &
       'core_wall_s', 'dof', 'thermal_level', 'fidelity_eps_lateral', 'fidelity_eps_thermal']]

  integer, parameter :: ntooth_q = 8
  integer, parameter :: iq_tf = 6                  !< position of T_f in tooth_q_names
  character(len=4), parameter :: tooth_q_names(ntooth_q) = [character(len=4) :: &
       'F', 'Fx', 'Fy', 'dn', 'c', 'Tf', 'rc1', 'rc2']
  character(len=4), parameter :: tooth_q_units(ntooth_q) = [character(len=4) :: &
       'N', 'N', 'N', 'm', 'm', 'degC', 'm', 'm']

contains

  !> Uniform output times on [t0 + t_transient, t_end] (one time: t_end).
  pure subroutine output_times(m, t)
    type(model_t), intent(in) :: m
    real(wp), intent(out) :: t(m%n_out)
    integer :: k
    real(wp) :: ta
    ta = m%t0 + m%t_transient
    if (m%n_out == 1) then
      t(1) = m%t_end
    else
      t = [(ta + (m%t_end - ta)*(k - 1)/real(m%n_out - 1, wp), k = 1, m%n_out)]
      t(m%n_out) = m%t_end
    end if
  end subroutine output_times

  !> Run a validated case: y(:, k) is the SI state at t(k), tooth(k, j, :) the quantities named
  !> in tooth_q_names for tooth j, tm(k) the meshing torque (Eq. 22).
  !> fidelity = 'auto' runs the cheapest level of the ladder whose estimated error against the
  !> level the case sets is within fidelity_tol, and that reports the same quantities. With
  !> tol = fidelity_margin * fidelity_tol (the estimates are not bounds: measured errors reach
  !> 1.3 of them, paper_T50/T100 one-way over 1 s, `pyspline bench ladder`):
  !>  - dof 7 -> 3 when lateral_estimate <= tol;
  !>  - thermal bulk -> none when backlash_estimate(T_M) <= tol;
  !>  - thermal coupled -> oneway (same T_f output, no iteration in the RHS), checked afterwards:
  !>    if backlash_estimate(max T_f of the one-way run) > tol the case is run coupled.
  !> interruptible: a SIGINT stops the run with err_interrupted (callers that can raise it).
  subroutine run_case(m, t, y, tooth, tm, stats, ierr, errmsg, interruptible)
    type(model_t), intent(in) :: m
    real(wp), intent(out) :: t(m%n_out), y(nstate, m%n_out), tooth(m%n_out, m%z, ntooth_q)
    real(wp), intent(out) :: tm(m%n_out), stats(nstats)
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    logical, intent(in), optional :: interruptible
    type(model_t) :: run
    real(wp) :: eps_lat, eps_th, tol
    integer(8) :: c0, c1, rate
    call system_clock(c0, rate)
    run = m
    eps_lat = 0.0_wp; eps_th = 0.0_wp
    tol = fidelity_margin*m%fidelity_tol
    if (m%auto) then
      eps_lat = lateral_estimate(m)
      if (m%dof == 7 .and. eps_lat <= tol) run%dof = 3
      if (m%thermal == thermal_bulk) then
        eps_th = backlash_estimate(m, m%t_bulk)
        if (eps_th <= tol) call set_thermal_level(run, thermal_none)
      end if
      if (m%thermal == thermal_coupled) call set_thermal_level(run, thermal_oneway)
    end if
    call run_level(run, t, y, tooth, tm, stats, ierr, errmsg, interruptible)
    if (ierr == err_ok .and. m%auto .and. m%thermal == thermal_coupled) then
      eps_th = backlash_estimate(m, maxval(abs(tooth(:, :, iq_tf))))
      if (eps_th > tol) then
        call set_thermal_level(run, thermal_coupled)
        call run_level(run, t, y, tooth, tm, stats, ierr, errmsg, interruptible)
      end if
    end if
    call system_clock(c1)
    stats(nsolver_stats+1:) = [real(c1 - c0, wp)/rate, real(run%dof, wp), real(run%thermal, wp), &
         eps_lat, eps_th]
  end subroutine run_case

  !> One run of the model at the level m sets.
  subroutine run_level(m, t, y, tooth, tm, stats, ierr, errmsg, interruptible)
    type(model_t), intent(in) :: m
    real(wp), intent(out) :: t(m%n_out), y(nstate, m%n_out), tooth(m%n_out, m%z, ntooth_q)
    real(wp), intent(out) :: tm(m%n_out), stats(nstats)
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    logical, intent(in), optional :: interruptible
    real(wp) :: y0(nstate)
    integer, allocatable :: modes(:, :)
    errmsg = ''
    stats = 0.0_wp
    t = 0.0_wp; y = 0.0_wp; tooth = 0.0_wp; tm = 0.0_wp
    allocate(modes(m%z, m%n_out))
    call output_times(m, t)
    call start_state(m, y0, ierr, errmsg)
    if (ierr /= 0) return
    call integrate(m, y0, m%n_out, t, y, modes, stats(1:nsolver_stats), ierr, errmsg, interruptible)
    if (ierr /= 0) return
    call tooth_outputs(m, t, y, modes, tooth, tm, ierr, errmsg)
  end subroutine run_level

  !> Per-tooth quantities at the output times, with the contact states the integration used
  !> (2: decided by the state).
  subroutine tooth_outputs(m, t, y, modes, tooth, tm, ierr, errmsg)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t(:), y(:, :)
    integer, intent(in) :: modes(:, :)
    real(wp), intent(out) :: tooth(:, :, :), tm(:)
    integer, intent(out) :: ierr
    character(len=*), intent(inout) :: errmsg
    real(wp) :: row(m%z, ntooth_q)
    integer :: k
    ierr = 0
    do k = 1, size(t)
      if (modes(1, k) == 2) then
        call tooth_quantities(m, t(k), y(:, k), row, tm(k), ierr, errmsg)
      else
        call tooth_quantities(m, t(k), y(:, k), row, tm(k), ierr, errmsg, modes(:, k))
      end if
      if (ierr /= 0) return
      tooth(k, :, :) = row
    end do
  end subroutine tooth_outputs

  !> Every per-tooth quantity (order of tooth_q_names) and the meshing torque at one state y (SI):
  !> Eqs. 11, 15-17, 19-22 and, where the thermal level has them, Eqs. 1-7 and 12-14.
  subroutine tooth_quantities(m, t, y, row, tm, ierr, errmsg, mode)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t, y(nstate)
    real(wp), intent(out) :: row(m%z, ntooth_q), tm
    integer, intent(out) :: ierr
    character(len=*), intent(inout) :: errmsg
    integer, intent(in), optional :: mode(m%z)
    real(wp) :: fx1, fy1, sp(m%z), cp(m%z)
    call mesh_eval(m, t, y(1:ndof), y(ndof+1:), fx1, fy1, tm, ierr, errmsg, mode=mode, &
         flash=.true., f=row(:, 1), dn=row(:, 4), c=row(:, 5), tf=row(:, 6), rc1=row(:, 7), &
         rc2=row(:, 8), sphi_out=sp, cphi_out=cp)
    row(:, 2) = row(:, 1)*sp     ! F_jx (Eq. 19 with phi_j)
    row(:, 3) = row(:, 1)*cp     ! F_jy
  end subroutine tooth_quantities

end module spline_run
