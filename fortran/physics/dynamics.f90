!> Equations of motion: the 8-DOF system of Eq. 23 reduced exactly to 7 DOF in the relative
!> coordinates of Eq. 24, its scaled first-order form (Eq. 25), and the static equilibrium.
module spline_dynamics
  use spline_kinds, only: wp, max_teeth
  use spline_errors, only: err_ok, err_solver
  use spline_model, only: model_t, ndof, nstate, thermal_coupled, static_tooth_load
  use spline_geometry, only: tooth_angles
  use spline_mesh, only: mesh_eval, mesh_forces, mesh_switch_functions, coupling_stats_t, eq16_mode, &
       eq11_gradient
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: accelerations, accel_jacobian, rhs_jacobian, driving_torque, unbalance_forces, rhs_scaled, &
       to_scaled, from_scaled, state_units, static_equilibrium, start_state, integrated_states

  integer, parameter :: max_newton = 100    !< Newton steps of the static equilibrium

contains

  !> Eqs. 23-24: accelerations of q = (x1, y1, x2, y2, D1, D2, D3) in SI units.
  !> With a1 = D1/r_b = th1 - thM, a3 = D3/r_b = th2 - thL and the shaft torques
  !> S1 = k_T1 a1 + c_T1 a1', S3 = k_T2 a3 + c_T2 a3', the four torsional equations of Eq. 23 read
  !>   J_M thM'' = T_d + S1,  J_1 th1'' = T_m - S1,  J_2 th2'' = -T_m - S3,  J_L thL'' = S3 - T_L,
  !> so (derived here: the paper's Eq. 24 has a sign slip on T_L)
  !>   D1'' = r_b ((T_m - S1)/J_1 - (T_d + S1)/J_M)
  !>   D2'' = r_b ((-T_m - S3)/J_2 - (T_m - S1)/J_1)
  !>   D3'' = r_b ((-T_m - S3)/J_2 - (S3 - T_L)/J_L)
  !> Beyond the paper (docs/model.md section 11): T_d is driving_torque(t) (torque ripple), and the
  !> unbalance forces (unbalance_forces) act on the x, y equations of splines 1 and 2.
  !> mode: the frozen contact state of every contact (tooth, or slice of a tooth: mesh_eval).
  subroutine accelerations(m, t, q, v, a, ierr, errmsg, mode, cstats)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t, q(ndof), v(ndof)
    real(wp), intent(out) :: a(ndof)
    integer, intent(out) :: ierr
    character(len=*), intent(inout) :: errmsg
    integer, intent(in), optional :: mode(m%z*m%n_slices)
    type(coupling_stats_t), intent(inout), optional :: cstats
    real(wp) :: fx1, fy1, tm, s1, s3, th1dd, fu(4), td
    if (m%n_slices == 1 .and. m%thermal /= thermal_coupled) then
      call mesh_forces(m, t, q, v, fx1, fy1, tm, mode)     ! mesh_eval's kernel, to round-off
      ierr = err_ok
    else
      call mesh_eval(m, t, q, v, fx1, fy1, tm, ierr, errmsg, mode=mode, cstats=cstats)
      if (ierr /= err_ok) return
    end if
    ! divisions by the masses, inertias and r_b as products with the model's reciprocals
    a(1) = (fx1 - m%c_p1*v(1) - m%k_p1*q(1))*m%inv_m1
    a(2) = (fy1 - m%c_p1*v(2) - m%k_p1*q(2))*m%inv_m1 - m%grav
    a(3) = (-fx1 - m%c_p2*v(3) - m%k_p2*q(3))*m%inv_m2
    a(4) = (-fy1 - m%c_p2*v(4) - m%k_p2*q(4))*m%inv_m2 - m%grav
    if (m%unbalance(1) /= 0.0_wp .or. m%unbalance(2) /= 0.0_wp) then
      call unbalance_forces(m, t, fu)
      a(1:2) = a(1:2) + fu(1:2)*m%inv_m1
      a(3:4) = a(3:4) + fu(3:4)*m%inv_m2
    end if
    s1 = (m%k_t1*q(5) + m%c_t1*v(5))*m%inv_rb
    s3 = (m%k_t2*q(7) + m%c_t2*v(7))*m%inv_rb
    th1dd = (tm - s1)*m%inv_j1
    td = m%t_d                               ! T_d(t) (driving_torque) only with a ripple
    if (m%n_ripple > 0) td = driving_torque(m, t)
    a(5) = m%r_b*(th1dd - (td + s1)*m%inv_jm)
    a(6) = m%r_b*((-tm - s3)*m%inv_j2 - th1dd)
    a(7) = m%r_b*((-tm - s3)*m%inv_j2 - (s3 - m%t_l)*m%inv_jl)
  end subroutine accelerations

  !> The frozen-contact Jacobian of the accelerations (Eqs. 23-24) at time t, in SI units:
  !> a(i, :) = d(a_i)/d(q, v) with the contact states frozen at modes (as accelerations' mode;
  !> exact: the right-hand side is affine in the state there). A tooth (slice) in contact
  !> carries F = k_m (dn -+ c) + c_m d(dn)/dt (Eqs. 15-17; / n_s per slice) with
  !> dn = e_x sin(phi) - e_y cos(phi) + D2 + e_j (Eq. 11), so
  !>   dF/dq = k_m u + c_m omega w,  dF/dv = c_m u,
  !>   u = (sin, -cos, -sin, cos, 0, 1, 0), w = (cos, sin, -cos, -sin, 0, 0, 0);
  !> F_x1 = -sum F sin, F_y1 = sum F cos, T_m = r_b sum F (Eqs. 19-22), and the accelerations
  !> are linear in them and in q, v. The one Jacobian of the core: the variational run's and the
  !> linear tail's (rhs_jacobian), the static equilibrium's; the coupled flash temperature
  !> (Eqs. 1-7 fed back) is not in it (tests/fortran/test_jacobian.f90: against unit steps).
  pure subroutine accel_jacobian(m, t, modes, a)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t
    integer, intent(in) :: modes(:)
    real(wp), intent(out) :: a(ndof, nstate)
    real(wp) :: sp(max_teeth), cp(max_teeth), u(ndof), w(ndof), gf(nstate), gx(nstate), gy(nstate)
    real(wp) :: gt(nstate), ds1(nstate), ds3(nstate), dth1(nstate), wt
    integer :: j, ns
    call tooth_angles(m%z, m%omega, t, m%theta0, m%alpha, m%sin_pitch, m%cos_pitch, sp, cp)
    ns = m%n_slices
    gx = 0.0_wp; gy = 0.0_wp; gt = 0.0_wp
    do j = 1, m%z
      wt = real(count(modes((j - 1)*ns + 1:j*ns) /= 0), wp)/ns   ! share of the face in contact
      if (wt == 0.0_wp) cycle
      call eq11_gradient(sp(j), cp(j), u, w)
      gf(1:ndof) = wt*(m%k_m*u + m%c_m*m%omega*w)
      gf(ndof+1:) = wt*m%c_m*u
      gx = gx - gf*sp(j)
      gy = gy + gf*cp(j)
      gt = gt + m%r_b*gf
    end do
    a = 0.0_wp
    a(1, :) = gx/m%m_1; a(1, 1) = a(1, 1) - m%k_p1/m%m_1; a(1, 8) = a(1, 8) - m%c_p1/m%m_1
    a(2, :) = gy/m%m_1; a(2, 2) = a(2, 2) - m%k_p1/m%m_1; a(2, 9) = a(2, 9) - m%c_p1/m%m_1
    a(3, :) = -gx/m%m_2; a(3, 3) = a(3, 3) - m%k_p2/m%m_2; a(3, 10) = a(3, 10) - m%c_p2/m%m_2
    a(4, :) = -gy/m%m_2; a(4, 4) = a(4, 4) - m%k_p2/m%m_2; a(4, 11) = a(4, 11) - m%c_p2/m%m_2
    ds1 = 0.0_wp; ds1(5) = m%k_t1/m%r_b; ds1(12) = m%c_t1/m%r_b
    ds3 = 0.0_wp; ds3(7) = m%k_t2/m%r_b; ds3(14) = m%c_t2/m%r_b
    dth1 = (gt - ds1)/m%j_1
    a(5, :) = m%r_b*(dth1 - ds1/m%j_m)
    a(6, :) = m%r_b*((-gt - ds3)/m%j_2 - dth1)
    a(7, :) = m%r_b*((-gt - ds3)/m%j_2 - ds3/m%j_l)
  end subroutine accel_jacobian

  !> J = d(ys')/d(ys), the Jacobian of Eq. 25 (rhs_scaled) at scaled time tau with the contact
  !> states frozen at modes: accel_jacobian in the scaled states.
  pure subroutine rhs_jacobian(m, tau, modes, jac)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: tau
    integer, intent(in) :: modes(:)
    real(wp), intent(out) :: jac(nstate, nstate)
    real(wp) :: a(ndof, nstate), d(nstate)
    integer :: i
    call accel_jacobian(m, tau/m%w_ref, modes, a)
    ! SI -> scaled (Eq. 25): J_s(i, k) = J(i, k) d_k / (w_ref d_i), d = (l, l w_ref)
    d(1:ndof) = m%l_ref
    d(ndof+1:) = m%l_ref*m%w_ref
    jac = 0.0_wp
    do i = 1, ndof
      jac(i, ndof + i) = 1.0_wp            ! dq/dt = v: d_k / (w d_i) = 1
    end do
    do i = 1, ndof
      jac(ndof + i, :) = a(i, :)*d/(m%w_ref*d(ndof + i))
    end do
  end subroutine rhs_jacobian

  !> Driving torque with ripple (docs/model.md section 11): T_d(t) = T_d [1 + sum_k a_k sin(n_k omega t
  !> + psi_k)], the engine orders n_k; exactly T_d without ripple.
  pure real(wp) function driving_torque(m, t) result(td)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t
    integer :: k
    td = m%t_d
    do k = 1, m%n_ripple
      td = td + m%t_d*m%ripple_amp(k)*sin(m%ripple_order(k)*m%omega*t + m%ripple_phase(k))
    end do
  end function driving_torque

  !> Mass unbalance (docs/model.md section 11): the rotating force m_ui e_i omega^2 (cos(omega t +
  !> beta_i), sin(omega t + beta_i)) on spline i: f = (f_x1, f_y1, f_x2, f_y2) [N].
  pure subroutine unbalance_forces(m, t, f)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t
    real(wp), intent(out) :: f(4)
    integer :: i
    do i = 1, 2
      f(2*i - 1) = m%unbalance(i)*m%omega**2*cos(m%omega*t + m%unbalance_phase(i))
      f(2*i) = m%unbalance(i)*m%omega**2*sin(m%omega*t + m%unbalance_phase(i))
    end do
  end subroutine unbalance_forces

  !> Eq. 25: scaled state ys = (q / l, v / (l w)) in scaled time tau = w t.
  pure subroutine to_scaled(m, y, ys)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: y(nstate)
    real(wp), intent(out) :: ys(nstate)
    ys(1:ndof) = y(1:ndof)/m%l_ref
    ys(ndof+1:) = y(ndof+1:)/(m%l_ref*m%w_ref)
  end subroutine to_scaled

  !> The SI state y of the scaled ys (y = ys state_units). For other modules; this one calls
  !> unscale, which the compiler inlines (spline_mesh::tooth_approach says why).
  pure subroutine from_scaled(m, ys, y)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: ys(nstate)
    real(wp), intent(out) :: y(nstate)
    call unscale(m, ys, y)
  end subroutine from_scaled

  pure subroutine unscale(m, ys, y)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: ys(nstate)
    real(wp), intent(out) :: y(nstate)
    y(1:ndof) = ys(1:ndof)*m%l_ref
    y(ndof+1:) = ys(ndof+1:)*(m%l_ref*m%w_ref)
  end subroutine unscale

  !> The SI unit of each scaled state (from_scaled: y = ys state_units): l for the
  !> displacements, l w for the velocities.
  pure function state_units(m) result(u)
    type(model_t), intent(in) :: m
    real(wp) :: u(nstate)
    u(1:ndof) = m%l_ref
    u(ndof+1:) = m%l_ref*m%w_ref
  end function state_units

  !> Eq. 25: d(ys)/d(tau) for the scaled state, ys' = (vs, a / (l w^2)).
  subroutine rhs_scaled(m, tau, ys, dys, ierr, errmsg, mode, cstats)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: tau, ys(nstate)
    real(wp), intent(out) :: dys(nstate)
    integer, intent(out) :: ierr
    character(len=*), intent(inout) :: errmsg
    integer, intent(in), optional :: mode(m%z*m%n_slices)
    type(coupling_stats_t), intent(inout), optional :: cstats
    real(wp) :: y(nstate), a(ndof)
    call unscale(m, ys, y)
    call accelerations(m, tau*m%inv_w_ref, y(1:ndof), y(ndof+1:), a, ierr, errmsg, mode, cstats)
    dys(1:ndof) = ys(ndof+1:)
    dys(ndof+1:) = a*m%inv_acc_ref
  end subroutine rhs_scaled

  !> The states the integrator carries, as indices into the full state (Eq. 24): all 14 at
  !> dof = 7; at dof = 3 (torsional level) D1, D2, D3 and their velocities, the lateral states
  !> being held at their start values.
  pure subroutine integrated_states(m, idx, n)
    type(model_t), intent(in) :: m
    integer, intent(out) :: idx(nstate), n
    integer :: k
    if (m%dof == 3) then
      n = 6
      idx(1:n) = [5, 6, 7, 12, 13, 14]
    else
      n = nstate
      idx = [(k, k = 1, nstate)]
    end if
  end subroutine integrated_states

  !> Start state (SI): the static equilibrium at t0 or rest, plus the case's offsets dq0, dv0.
  subroutine start_state(m, y, ierr, errmsg)
    type(model_t), intent(in) :: m
    real(wp), intent(out) :: y(nstate)
    integer, intent(out) :: ierr
    character(len=*), intent(inout) :: errmsg
    y = 0.0_wp
    ierr = err_ok
    if (m%start_equilibrium) call static_equilibrium(m, m%t0, y(1:ndof), ierr, errmsg)
    if (ierr /= err_ok) return
    y(1:ndof) = y(1:ndof) + m%dq0
    y(ndof+1:) = m%dv0
    if (.not. all(ieee_is_finite(y))) then
      ierr = err_solver
      errmsg = 'case '//trim(m%name)//': the start state is not finite (NaN or Inf): use '// &
           'start = ''rest'''
    end if
  end subroutine start_state

  !> Static equilibrium at time t: the displacements q with zero velocities for which all
  !> accelerations of Eq. 23 vanish (under T_d, T_L, gravity and misalignment). Semi-smooth
  !> Newton on the piecewise-linear residual: the Jacobian (accel_jacobian) is taken with
  !> the contact states of Eq. 16 frozen at the current iterate, so it is the exact Jacobian of
  !> the piece the iterate lies on, never a difference across a tooth's contact switch (with a
  !> misalignment and many teeth, Z >= ~150, the teeth near their switch made the plain
  !> difference Jacobian point uphill and the line search stall); backtracking line search on
  !> the residual (with the coupled flash temperature, which the Jacobian leaves out, a
  !> quasi-Newton iteration). The closed-form guess: shafts twisted by the torques, every tooth loaded
  !> equally, supports sagging under gravity. Converged when the scaled step is below 1e-12.
  subroutine static_equilibrium(m, t, q, ierr, errmsg)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t
    real(wp), intent(out) :: q(ndof)
    integer, intent(out) :: ierr
    character(len=*), intent(inout) :: errmsg
    real(wp) :: r(ndof), rn(ndof), jac(ndof, ndof), ja(ndof, nstate), dq(ndof), qn(ndof), lam
    real(wp) :: g(2*m%z*m%n_slices), dqbar(ndof), q_prev(ndof), dq_prev(ndof), lam_prev
    integer :: it, ls, modes(m%z*m%n_slices)
    q = 0.0_wp
    q(2) = -m%m_1*m%grav/max(m%k_p1, tiny(1.0_wp))
    q(4) = -m%m_2*m%grav/max(m%k_p2, tiny(1.0_wp))
    if (m%k_p1 == 0.0_wp) q(2) = 0.0_wp
    if (m%k_p2 == 0.0_wp) q(4) = 0.0_wp
    q(5) = -m%r_b*m%t_d/max(m%k_t1, tiny(1.0_wp))
    q(7) = m%r_b*m%t_l/max(m%k_t2, tiny(1.0_wp))
    q(6) = -sign(m%c_bulk, m%t_d) - sign(static_tooth_load(m)/m%k_m, m%t_d)
    if (m%spacing) q(6) = q(6) - sum(m%spacing_error(1:m%z))/m%z   ! full contact: dn_j + e_j
    lam_prev = 0.0_wp; q_prev = 0.0_wp; dq_prev = 0.0_wp
    call residual(q, r)
    if (ierr /= err_ok) return
    do it = 1, max_newton
      ! contact states at q (Eq. 16, as the right-hand side decides them)
      call mesh_switch_functions(m, t, q, g)
      modes = eq16_mode(g(1::2), g(2::2))
      call accel_jacobian(m, t, modes, ja)
      jac = ja(:, 1:ndof)/(m%l_ref*m%w_ref**2)     ! d(residual)/dq at zero velocities
      call solve_dense(jac, -r, dq, ierr)
      if (ierr /= err_ok .and. lam_prev > 1.0e-6_wp) then
        ! singular here (e.g. the step left every tooth out of contact): back to half the step
        lam_prev = 0.5_wp*lam_prev
        q = q_prev + lam_prev*dq_prev
        call residual(q, r)
        if (ierr /= err_ok) return
        cycle
      end if
      if (ierr /= err_ok) then
        ierr = err_solver
        errmsg = 'case '//trim(m%name)//': no unique static equilibrium (a free body, e.g. '// &
             'the mesh out of contact under zero torque): use start = ''rest'''
        return
      end if
      ! converged: the step is below 1e-12 l_ref, or at round-off of the displacement itself
      ! (the shaft twists r_b T / k_t reach metres at Z = 1000)
      if (all(abs(dq) < 1.0e-12_wp*m%l_ref + 1.0e-14_wp*abs(q))) then
        q = q + dq
        return
      end if
      ! damping by the natural monotonicity test (affine invariant: the simplified Newton
      ! correction at the trial point must shrink; the residual norm itself mixes rows of
      ! stiffnesses decades apart and stalled the search)
      lam = 1.0_wp
      do ls = 1, 30
        qn = q + lam*dq
        call residual(qn, rn)
        if (ierr /= err_ok) return
        call solve_dense(jac, -rn, dqbar, ierr)
        if (ierr /= err_ok) exit
        if (norm2(dqbar) < (1.0_wp - 0.25_wp*lam)*norm2(dq)) exit
        lam = 0.5_wp*lam
      end do
      if (ls > 30) then          ! no damped step passed the test: take the full one
        lam = 1.0_wp
        qn = q + dq
        call residual(qn, rn)
        if (ierr /= err_ok) return
      end if
      ierr = err_ok
      q_prev = q; dq_prev = dq; lam_prev = lam
      q = qn
      r = rn
    end do
    ierr = err_solver
    write(errmsg, '(a,i0,a)') 'case '//trim(m%name)//': static equilibrium did not converge in ', &
         max_newton, ' Newton steps: use start = ''rest'''
  contains
    subroutine residual(qq, rr)
      real(wp), intent(in) :: qq(ndof)
      real(wp), intent(out) :: rr(ndof)
      real(wp), parameter :: zero(ndof) = 0.0_wp
      call accelerations(m, t, qq, zero, rr, ierr, errmsg)
      rr = rr/(m%l_ref*m%w_ref**2)
    end subroutine residual
  end subroutine static_equilibrium

  !> Gaussian elimination with partial pivoting for the small Newton systems, on the matrix
  !> equilibrated by rows and then columns (the stiffnesses of a case span many decades: mesh
  !> k_m Z against shafts k_t, so a pivot is judged against its own row and column, not the
  !> largest entry). ierr = err_solver: singular (a zero row or column, or a pivot below 1e-13).
  subroutine solve_dense(a_in, b, x, ierr)
    real(wp), intent(in) :: a_in(:, :), b(:)
    real(wp), intent(out) :: x(:)
    integer, intent(out) :: ierr
    real(wp) :: a(size(b), size(b)), rhs(size(b)), rowtmp(size(b)), tmp, rs(size(b)), cs(size(b))
    integer :: n, i, p
    n = size(b)
    a = a_in
    rhs = b
    x = 0.0_wp
    ierr = err_solver
    do i = 1, n
      rs(i) = maxval(abs(a(i, :)))
      if (.not. rs(i) > 0.0_wp) return
      a(i, :) = a(i, :)/rs(i)
    end do
    rhs = rhs/rs
    do i = 1, n
      cs(i) = maxval(abs(a(:, i)))
      if (.not. cs(i) > 0.0_wp) return
      a(:, i) = a(:, i)/cs(i)
    end do
    ierr = err_ok
    do i = 1, n
      p = maxloc(abs(a(i:, i)), dim=1) + i - 1
      if (.not. abs(a(p, i)) > 1.0e-13_wp) then
        ierr = err_solver; return
      end if
      if (p /= i) then
        rowtmp = a(i, :); a(i, :) = a(p, :); a(p, :) = rowtmp
        tmp = rhs(i); rhs(i) = rhs(p); rhs(p) = tmp
      end if
      rhs(i+1:) = rhs(i+1:) - a(i+1:, i)/a(i, i)*rhs(i)
      a(i+1:, i:) = a(i+1:, i:) - spread(a(i+1:, i)/a(i, i), 2, n - i + 1)*spread(a(i, i:), 1, n - i)
    end do
    do i = n, 1, -1
      x(i) = (rhs(i) - dot_product(a(i, i+1:), x(i+1:)))/a(i, i)
    end do
    x = x/cs
  end subroutine solve_dense

end module spline_dynamics
