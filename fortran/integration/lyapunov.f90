!> The largest Lyapunov exponent of a run (case field lyapunov) by Benettin's method: a
!> reference and a perturbed copy integrated side by side as one CVODE system
!> (spline_solver::integrate, y0b), renormalised every lyapunov_interval.
module spline_lyapunov
  use spline_kinds, only: wp
  use spline_errors, only: err_ok
  use spline_model, only: model_t, nstate
  use spline_dynamics, only: to_scaled, from_scaled, integrated_states
  use spline_solver, only: integrate
  use spline_quantities, only: nsolver_stats
  use spline_variational, only: tangent_flow
  use spline_integrator, only: lib_log_t
  implicit none
  private
  public :: lyapunov_count, lyapunov_benettin, lyapunov_tangent

contains

  !> Number of Benettin renormalisations over the output window (0 without lyapunov).
  pure integer function lyapunov_count(m) result(n)
    type(model_t), intent(in) :: m
    n = 0
    if (m%lyapunov .and. m%lyap_dt > 0.0_wp) &
         n = max(1, ceiling((m%t_end - m%t0 - m%t_transient)/m%lyap_dt - 1.0e-9_wp))
  end function lyapunov_count

  !> Largest Lyapunov exponent by Benettin's method: from the state y_start at t_start, a
  !> reference and a copy perturbed by d0 (in the scaled states of Eq. 25, along a fixed
  !> direction) are integrated over intervals of lyap_dt; after each the separation d is
  !> measured, ln(d / d0) added to the sum g, and the copy pulled back to distance d0 along the
  !> separation. lam(t) = g(t) / (t - t_start) converges to the exponent [1/s]. The two are
  !> integrated as one CVODE system (integrate's y0b), with the same steps, order and corrector
  !> iterations, so their difference carries no independent solver noise (integrated apart, a
  !> separation of 1e-8 at rtol 1e-8 measured that noise: tests/test_chaos.py). Both restart at
  !> every renormalisation. The frozen states of the torsional level (dof 3) are left out of d.
  subroutine lyapunov_benettin(m, t_start, y_start, lt, lg, ierr, errmsg, interruptible, msgs)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t_start, y_start(nstate)
    real(wp), intent(out) :: lt(:), lg(:)
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    logical, intent(in), optional :: interruptible
    type(model_t) :: mm
    real(wp) :: y(nstate), yp(nstate), t0, t1, ys(nstate), yps(nstate), dv(nstate), d, g
    real(wp) :: tout(1), y1(nstate, 1), yp1(nstate, 1), st(nsolver_stats)
    integer :: idx(nstate), n, k, i, modes(m%z*m%n_slices, 1)
    type(lib_log_t), intent(inout), optional :: msgs   !< SUNDIALS' warnings, over every interval
    type(lib_log_t) :: lib
    if (present(msgs)) lib = msgs
    call integrated_states(m, idx, n)
    mm = m
    y = y_start
    dv = 0.0_wp
    dv(idx(1:n)) = 1.0_wp/sqrt(real(n, wp))         ! unit direction in the scaled states
    call to_scaled(m, y, ys)
    yps = ys + m%lyap_d0*dv
    call from_scaled(m, yps, yp)
    t0 = t_start
    g = 0.0_wp
    do k = 1, size(lt)
      t1 = min(t_start + k*m%lyap_dt, m%t_end)
      mm%t0 = t0
      tout = t1
      call integrate(mm, y, 1, tout, y1, modes, st, ierr, errmsg, interruptible, y0b=yp, &
           youtb=yp1, msgs=lib)
      if (ierr /= err_ok) return
      call to_scaled(m, y1(:, 1), ys)
      call to_scaled(m, yp1(:, 1), yps)
      dv = 0.0_wp
      dv(idx(1:n)) = yps(idx(1:n)) - ys(idx(1:n))
      d = norm2(dv)
      if (.not. (d > 0.0_wp)) then       ! the copy fell onto the reference: perturb afresh
        dv = 0.0_wp
        dv(idx(1:n)) = 1.0_wp/sqrt(real(n, wp))
        d = m%lyap_d0
      end if
      g = g + log(d/m%lyap_d0)
      lt(k) = t1
      lg(k) = g
      yps = ys
      do i = 1, n
        yps(idx(i)) = ys(idx(i)) + dv(idx(i))*(m%lyap_d0/d)
      end do
      y = y1(:, 1)
      call from_scaled(m, yps, yp)
      t0 = t1
    end do
    if (present(msgs)) msgs = lib
  end subroutine lyapunov_benettin

  !> Largest Lyapunov exponent by Benettin's method on the tangent (no finite separation): a
  !> unit tangent vector v (scaled states of Eq. 25, the direction lyapunov_benettin starts
  !> with) integrated beside the state by the variational equations, with the saltation matrix
  !> at every located contact switch (spline_variational::tangent_flow); after each interval of
  !> lyap_dt, ln |v| is added to g and v renormalised to 1. Same outputs as lyapunov_benettin.
  subroutine lyapunov_tangent(m, t_start, y_start, lt, lg, ierr, errmsg, interruptible, msgs)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t_start, y_start(nstate)
    real(wp), intent(out) :: lt(:), lg(:)
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    logical, intent(in), optional :: interruptible
    type(model_t) :: mm
    real(wp) :: y(nstate), y1(nstate), phi(nstate, 1), t1, d, g
    integer :: idx(nstate), n, k
    type(lib_log_t), intent(inout), optional :: msgs   !< SUNDIALS' warnings, over every interval
    type(lib_log_t) :: lib
    if (present(msgs)) lib = msgs
    call integrated_states(m, idx, n)
    mm = m
    y = y_start
    phi = 0.0_wp
    phi(1:n, 1) = 1.0_wp/sqrt(real(n, wp))
    mm%t0 = t_start
    g = 0.0_wp
    lt = 0.0_wp; lg = 0.0_wp
    do k = 1, size(lt)
      t1 = min(t_start + k*m%lyap_dt, m%t_end)
      call tangent_flow(mm, t1, y, 1, phi, y1, ierr, errmsg, interruptible, msgs=lib)
      if (ierr /= err_ok) return
      d = norm2(phi(1:n, 1))
      if (.not. (d > 0.0_wp)) then       ! the tangent died out: start afresh
        phi(1:n, 1) = 1.0_wp/sqrt(real(n, wp))
        d = 1.0_wp
      end if
      g = g + log(d)
      lt(k) = t1
      lg(k) = g
      phi(1:n, 1) = phi(1:n, 1)/d
      y = y1
      mm%t0 = t1
    end do
    if (present(msgs)) msgs = lib
  end subroutine lyapunov_tangent

end module spline_lyapunov
