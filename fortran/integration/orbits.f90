!> The period map of a forced run, for periodic orbits (docs/orbits.md): from a state y0 at
!> time t0, integrate to t1 = t0 + n T and return the state there (spline_solver::integrate,
!> with the case's tolerances, contact switches and linear tail). Python's
!> pyspline.periodic_orbit solves P^n(y0) = y0 with it and differences it for the monodromy.
!> Every map call is bounded: in steps by the case's max_steps (the run has one output
!> interval) and max_total_steps, in wall time by max_seconds (an argument: > 0 bounds the
!> whole call). On success errmsg holds the integrator's warnings over the call's runs.
module spline_orbits
  use spline_kinds, only: wp
  use spline_errors, only: err_ok
  use spline_integrator, only: lib_log_t
  use spline_model, only: model_t, nstate
  use spline_dynamics, only: integrated_states
  use spline_solver, only: integrate
  use spline_fidelity, only: auto_level
  use spline_quantities, only: nsolver_stats
  use spline_variational, only: tangent_flow
  implicit none
  private
  public :: period_map, map_and_monodromy

contains

  !> y1(:, k): the SI state at t1 of the run that starts from y0(:, k) (SI) at t0, one column at
  !> a time (each its own CVODE run). The model level is the case's, or for fidelity = 'auto'
  !> the one spline_fidelity::auto_level picks first (a coupled case's one-way level: the re-run
  !> coupled of spline_run::run_case is not made here). mask(i) = 1 for the states that level
  !> integrates (dof 3: the torsional ones; the lateral ones stay at their start displacement,
  !> at rest). ierr /= err_ok: the first column that failed stops the map (errmsg says why).
  !> max_seconds (> 0): the wall time the whole call may take (every column's run counts from
  !> the call's start); 0: no bound.
  subroutine period_map(m, t0, t1, y0, y1, mask, ierr, errmsg, interruptible, max_seconds)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t0, t1, y0(:, :)
    real(wp), intent(out) :: y1(:, :)
    integer, intent(out) :: mask(nstate), ierr
    character(len=*), intent(out) :: errmsg
    logical, intent(in), optional :: interruptible
    real(wp), intent(in) :: max_seconds
    type(model_t) :: run
    type(lib_log_t) :: msgs
    real(wp) :: eps_lat, eps_th, tout(1), st(nsolver_stats)
    integer(8) :: c0
    integer :: k, idx(nstate), n
    integer, allocatable :: modes(:, :)
    call system_clock(c0)
    call auto_level(m, run, eps_lat, eps_th)
    run%t0 = t0
    run%t_end = t1
    call integrated_states(run, idx, n)
    mask = 0
    mask(idx(1:n)) = 1
    allocate(modes(run%z*run%n_slices, 1))
    tout = t1
    y1 = 0.0_wp
    ierr = err_ok
    errmsg = ''
    do k = 1, size(y0, 2)
      call integrate(run, y0(:, k), 1, tout, y1(:, k:k), modes, st, ierr, errmsg, interruptible, &
           msgs=msgs, max_seconds=max_seconds, wall_start=c0, name='the period map')
      if (ierr /= err_ok) return
    end do
  end subroutine period_map

  !> The period map and its monodromy from the variational equations (spline_variational):
  !> y1 the SI state at t1 of the run from y0 (SI) at t0, phi(1:k, 1:k) = dP/dy0 over the k
  !> integrated states (mask, in their order) in the scaled states of Eq. 25, with the saltation
  !> matrix at every located contact switch (saltation = .false.: without it, to show it
  !> matters). The model level as period_map's. nswitch: the switches located. max_seconds:
  !> the run's wall-time bound (0: none).
  subroutine map_and_monodromy(m, t0, t1, y0, y1, phi, mask, nswitch, ierr, errmsg, &
       interruptible, saltation, max_seconds)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t0, t1, y0(nstate)
    real(wp), intent(out) :: y1(nstate), phi(nstate, nstate)
    integer, intent(out) :: mask(nstate), nswitch, ierr
    character(len=*), intent(out) :: errmsg
    logical, intent(in), optional :: interruptible, saltation
    real(wp), intent(in) :: max_seconds
    type(model_t) :: run
    real(wp) :: eps_lat, eps_th
    integer :: k, idx(nstate), n
    call auto_level(m, run, eps_lat, eps_th)
    run%t0 = t0
    run%t_end = t1
    call integrated_states(run, idx, n)
    mask = 0
    mask(idx(1:n)) = 1
    phi = 0.0_wp
    do k = 1, n
      phi(k, k) = 1.0_wp
    end do
    call tangent_flow(run, t1, y0, n, phi, y1, ierr, errmsg, interruptible, saltation, nswitch, &
         max_seconds=max_seconds)
  end subroutine map_and_monodromy

end module spline_orbits
