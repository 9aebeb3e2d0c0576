!> Module spline_dynamics (fortran/physics/dynamics.f90) against docs/model.md sections 1 and 5
!> (Eqs. 23-25): the static equilibrium in closed form (full contact, gravity, parallel
!> misalignment, unequal supports) and zero accelerations there, linearity of the right-hand
!> side in full contact, free bodies inside the backlash, and the scaled system of Eq. 25
!> against the SI one.
program test_dynamics
  use spline_kinds, only: wp, pi
  use spline_case, only: case_t
  use spline_model, only: model_t, ndof, nstate
  use spline_mesh, only: mesh_eval
  use spline_dynamics, only: accelerations, static_equilibrium, rhs_scaled, to_scaled, from_scaled
  use check, only: check_true, check_close, check_done, default_case_model
  implicit none
  real(wp), parameter :: eps = epsilon(1.0_wp)
  real(wp), parameter :: w1(5) = [0, 1, 0, 1, 2], w2(5) = [0, 0, 1, 1, 0]
  type(case_t) :: cs
  type(model_t) :: md
  real(wp) :: q(ndof), qe(ndof), v(ndof), a(ndof), a0(ndof), a1(ndof), a2(ndof), a12(ndof)
  real(wp) :: scale(ndof), kk, k1, k2, ex, ey, c, y(nstate), ys(nstate), y2(nstate), dys(nstate)
  real(wp) :: d1(nstate), d2(nstate), t, fx, fy, tm, dn(1000)
  integer :: ierr, k
  character(len=512) :: msg
  logical :: ok

  msg = ''
  ! ---- a drive with gravity, parallel misalignment and unequal supports and masses
  cs%l_x = 1.0e-4_wp; cs%l_y = -5.0e-5_wp
  cs%m_1 = 2.0_wp; cs%m_2 = 3.0_wp; cs%k_p2 = 4.0e6_wp
  call default_case_model(md, cs)
  c = md%c_bulk

  ! ---- static equilibrium in closed form (docs/model.md sections 1, 5; T_d = T_L):
  !      J_M: T_d + S_1 = 0 -> D1 = -r_b T_d / k_T1;  J_L: S_3 = T_L -> D3 = r_b T_L / k_T2;
  !      J_1: T_m = S_1 = -T_d, every tooth on the back flank: r_b Z k_m (D2 + c) = -T_d;
  !      laterally the mesh in full contact is the isotropic spring K = Z k_m / 2 on
  !      e = (x1 + l_x - x2, y1 + l_y - y2) (at rest its damping adds c_m omega Z/2 across, see
  !      test_mesh: zero here, c_m = 0), against the supports k_1, k_2 and gravity:
  !      e_x (1 + K/k_1 + K/k_2) = l_x,  e_y (1 + K/k_1 + K/k_2) = l_y - m_1 g/k_1 + m_2 g/k_2
  md%c_m = 0
  kk = md%z*md%k_m/2; k1 = md%k_p1; k2 = md%k_p2
  ex = md%l_x/(1 + kk/k1 + kk/k2)
  ey = (md%l_y - md%m_1*md%grav/k1 + md%m_2*md%grav/k2)/(1 + kk/k1 + kk/k2)
  qe(1) = -kk*ex/k1; qe(3) = kk*ex/k2
  qe(2) = (-kk*ey - md%m_1*md%grav)/k1; qe(4) = (kk*ey - md%m_2*md%grav)/k2
  qe(5) = -md%r_b*md%t_d/md%k_t1
  qe(6) = -c - md%t_d/(md%z*md%k_m*md%r_b)
  qe(7) = md%r_b*md%t_l/md%k_t2
  call check_true('closed form: T_d = T_L (a steady state exists)', md%t_d == md%t_l)
  v = 0
  call mesh_eval(md, md%t0, qe, v, fx, fy, tm, ierr, msg, dn=dn)
  call check_true('closed form: every tooth on the back flank (full contact)', all(dn(1:md%z) < -c))
  ! the size of the terms of each equation: support, gravity, mesh, shaft
  scale(1:4) = md%grav + [k1*abs(qe(1))/md%m_1, k1*abs(qe(2))/md%m_1, k2*abs(qe(3))/md%m_2, &
       k2*abs(qe(4))/md%m_2]
  scale(5:7) = md%r_b*md%t_d/min(md%j_1, md%j_2, md%j_m, md%j_l)
  call accelerations(md, md%t0, qe, v, a, ierr, msg)
  ok = ierr == 0 .and. all(abs(a) <= 1.0e-10_wp*scale)
  call check_true('closed form: accelerations vanish (within 1e-10 of each equation''s terms)', ok)
  print '(4x,a,7es10.2)', '|a| / terms:', abs(a)/scale
  call static_equilibrium(md, md%t0, q, ierr, msg)
  call check_true('static_equilibrium: converged', ierr == 0, trim(msg))
  do k = 1, ndof
    call check_close('static_equilibrium = closed form, q('//achar(48 + k)//')', q(k), qe(k), &
         1.0e-9_wp, 1.0e-12_wp*md%l_ref)
  end do
  call accelerations(md, md%t0, q, v, a, ierr, msg)
  call check_true('static_equilibrium: accelerations vanish (within 1e-10 of the terms)', &
       ierr == 0 .and. all(abs(a) <= 1.0e-10_wp*scale))
  print '(4x,a,7es10.2)', '|a| / terms:', abs(a)/scale

  ! ---- linearity in full contact: around the equilibrium, small steps keep every contact
  !      state, so the right-hand side is affine there: f(y + d1 + d2) - f(y + d1) - f(y + d2) + f(y)
  !      = 0 and f(y + 2 d1) - f(y) = 2 (f(y + d1) - f(y)). Damping on (c_m from the case).
  call default_case_model(md, cs)
  call static_equilibrium(md, md%t0, qe, ierr, msg)
  t = 1.1e-3_wp
  y = 0; y(1:ndof) = qe
  d1 = [2.0e-9_wp, -1.0e-9_wp, 1.5e-9_wp, 0.5e-9_wp, 1.0e-6_wp, -3.0e-9_wp, 2.0e-6_wp, &
        1.0e-4_wp, 2.0e-4_wp, -1.0e-4_wp, 0.5e-4_wp, 1.0e-2_wp, -2.0e-4_wp, 3.0e-3_wp]
  d2 = [-1.0e-9_wp, 2.5e-9_wp, 0.5e-9_wp, -2.0e-9_wp, -2.0e-6_wp, 2.0e-9_wp, 1.0e-6_wp, &
        -3.0e-4_wp, 1.0e-4_wp, 2.0e-4_wp, -1.0e-4_wp, -2.0e-2_wp, 1.0e-4_wp, -1.0e-3_wp]
  ok = .true.
  do k = 1, 5
    call mesh_eval(md, t, y(1:ndof) + w1(k)*d1(1:ndof) + w2(k)*d2(1:ndof), v, fx, fy, tm, ierr, &
         msg, dn=dn)
    ok = ok .and. all(dn(1:md%z) < -c)
  end do
  call check_true('linearity: y, y + d1, y + d2, y + d1 + d2, y + 2 d1 all in full contact', ok)
  a0 = f(y); a1 = f(y + d1); a2 = f(y + d2); a12 = f(y + d1 + d2)
  scale = abs(a1 - a0) + abs(a2 - a0)
  print '(4x,a,7es10.2)', 'second difference / first:', abs(a12 - a1 - a2 + a0)/scale
  call check_true('linearity: f(y+d1+d2) - f(y+d1) - f(y+d2) + f(y) = 0 (1e-9 of the changes)', &
       all(abs(a12 - a1 - a2 + a0) <= 1.0e-9_wp*scale))
  a2 = f(y + 2*d1)
  call check_true('linearity: f(y + 2 d1) - f(y) = 2 (f(y + d1) - f(y)) (1e-9 of the change)', &
       all(abs((a2 - a0) - 2*(a1 - a0)) <= 1.0e-9_wp*abs(a1 - a0)))

  ! ---- no torque, no gravity, no misalignment, every tooth inside its backlash, shafts untwisted,
  !      at rest: the supports alone act, a_i = -k_p q_i / m (lateral), and the torsional
  !      accelerations are exactly zero
  cs = case_t()
  cs%t_d = 0; cs%t_l = 0; cs%grav = 0
  call default_case_model(md, cs)
  q = 0; v = 0
  q(1) = 0.3_wp*md%c_bulk; q(4) = -0.2_wp*md%c_bulk; q(6) = 0.4_wp*md%c_bulk
  call accelerations(md, 2.3e-3_wp, q, v, a, ierr, msg)
  call check_true('inside the backlash: torsional accelerations exactly 0', ierr == 0 .and. all(a(5:7) == 0))
  call check_true('inside the backlash: lateral accelerations -k_p q / m (supports alone)', &
       all(abs(a(1:4) + [md%k_p1/md%m_1, md%k_p1/md%m_1, md%k_p2/md%m_2, md%k_p2/md%m_2]*q(1:4)) &
       <= 4*eps*abs(a(1:4))) .and. a(2) == 0 .and. a(3) == 0)

  ! ---- Eq. 25: ys = (q / l, v / (l w)) in tau = w t, d(ys)/d(tau) = (vs, a / (l w^2)); the
  !      default scales are l = c0 and w = omega = 2 pi 6000 / 60 (docs/model.md section 5)
  call default_case_model(md)
  call check_close('Eq. 25 default l = c0', md%l_ref, 2.0e-4_wp, 0.0_wp)
  call check_close('Eq. 25 default w = omega', md%w_ref, 200*pi, 2*eps)
  y = [3.0e-4_wp, 1.0e-4_wp, -0.5e-4_wp, 0.2e-4_wp, 1.0e-5_wp, -2.5e-4_wp, 2.0e-5_wp, &
       0.02_wp, -0.01_wp, 0.005_wp, 0.03_wp, 0.1_wp, -0.02_wp, 0.05_wp]
  call to_scaled(md, y, ys)
  call check_true('to_scaled: ys = (q / l, v / (l w))', &
       all(abs(ys(1:ndof) - y(1:ndof)/md%l_ref) <= 2*eps*abs(ys(1:ndof))) .and. &
       all(abs(ys(ndof+1:) - y(ndof+1:)/(md%l_ref*md%w_ref)) <= 4*eps*abs(ys(ndof+1:))))
  call from_scaled(md, ys, y2)
  call check_true('from_scaled(to_scaled(y)) = y within 4 eps', all(abs(y2 - y) <= 4*eps*abs(y)))
  t = 1.7e-3_wp
  call rhs_scaled(md, md%w_ref*t, ys, dys, ierr, msg)
  call check_true('rhs_scaled: d(q/l)/d(tau) = v / (l w)', &
       all(abs(dys(1:ndof)*md%l_ref*md%w_ref - y(ndof+1:)) <= 8*eps*abs(y(ndof+1:))))
  call accelerations(md, t, y(1:ndof), y(ndof+1:), a, ierr, msg)
  print '(4x,a,7es10.2)', 'relative difference of a:', abs(dys(ndof+1:)*md%l_ref*md%w_ref**2 - a)/abs(a)
  call check_true('rhs_scaled: d(v/(l w))/d(tau) = a / (l w^2) within 1e-12', &
       all(abs(dys(ndof+1:)*md%l_ref*md%w_ref**2 - a) <= 1.0e-12_wp*abs(a)))

  call check_done('test_dynamics')

contains

  !> Accelerations at state yy (SI), time t.
  function f(yy) result(acc)
    real(wp), intent(in) :: yy(nstate)
    real(wp) :: acc(ndof)
    call accelerations(md, t, yy(1:ndof), yy(ndof+1:), acc, ierr, msg)
    if (ierr /= 0) then
      print '(a)', 'FAIL accelerations: '//trim(msg)
      error stop 1
    end if
  end function f

end program test_dynamics
