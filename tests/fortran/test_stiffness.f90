!> Module spline_stiffness (fortran/physics/stiffness.f90) against docs/model.md sections 7 and 11 (Eq. 18):
!> the Hertz closed form, a uniform cantilever in closed form (Timoshenko: bending, shear, axial),
!> the scaling of every term with face width b, Young's modulus E and Poisson's ratio nu,
!> convergence in the Gauss points, the series combination of Eq. 18 (with and without the
!> fillet foundation), and the k_m that model_from_case derives. (tests/stiffness_check.f90 holds
!> the rack limit, Tian's spur gear and the ROSS numbers.)
program test_stiffness
  use spline_kinds, only: wp, pi
  use spline_stiffness, only: hertz_stiffness, external_tooth_stiffness, internal_tooth_stiffness, &
       spline_mesh_stiffness, fillet_foundation_stiffness, fillet_foundation_stiffness_internal, &
       spline_mesh_stiffness_fillet, gauss_legendre, gauss_legendre_node
  use spline_case, only: case_t
  use spline_model, only: model_t, ik_m
  use check, only: check_true, check_close, check_done, default_case_model
  implicit none
  real(wp), parameter :: eps = epsilon(1.0_wp)
  ! the paper's spline (docs/model.md section 12) and its ISO 4156 radii (section 7)
  real(wp), parameter :: z = 16, m = 2.0e-3_wp, alpha = pi/6, b = 0.03_wp, e = 2.1e11_wp, nu = 0.3_wp
  real(wp), parameter :: rp = 16.0e-3_wp, rf1 = 14.5e-3_wp, rf2 = 17.5e-3_wp, ra2 = 15.0e-3_wp
  real(wp), parameter :: rho = 0.4e-3_wp, rint1 = 7.25e-3_wp, rout2 = 35.0e-3_wp
  integer, parameter :: nq = 32
  real(wp) :: k1(3), k2(3), k1s(3), k2s(3), kh, km, kmf, kf1, kf2, kf1s, kf2s, t(10), ref(3)
  real(wp) :: alpha20, rb, psi0, hb, xb, xr, len, beta, g, inertia, area, want(3)
  integer :: ierr, n
  character(len=256) :: msg
  character(len=64) :: tag
  type(case_t) :: c
  type(model_t) :: md
  logical :: ok
  real(wp), allocatable :: gs(:), gw(:)
  real(wp) :: gsi, gwi

  ! ---- the 32-point Gauss-Legendre rule of a model build is a table: the Newton solve of each
  !      node gives it bit for bit; it integrates x^62 exactly (2/63)
  call gauss_legendre(nq, gs, gw)
  ok = size(gs) == nq .and. size(gw) == nq
  do n = 1, nq
    call gauss_legendre_node(nq, n, gsi, gwi)
    ok = ok .and. gs(n) == gsi .and. gw(n) == gwi
  end do
  call check_true('gauss_legendre(32): the table is the solved rule bit for bit', ok)
  call check_close('gauss_legendre(32) integrates x^62 exactly', sum(gw*gs**62), 2.0_wp/63, 1e-13_wp)
  call gauss_legendre(5, gs, gw)
  call check_close('gauss_legendre(5) integrates x^8 exactly', sum(gw*gs**8), 2.0_wp/9, 1e-14_wp)

  ! ---- Hertz line contact, Eq. 18: k_h = pi E b / (4 (1 - nu^2))
  kh = hertz_stiffness(e, nu, b)
  call check_close('hertz k_h = pi E b / (4 (1 - nu^2))', kh, pi*e*b/(4*(1 - nu**2)), 4*eps)
  call check_close('hertz linear in b', hertz_stiffness(e, nu, 3*b), 3*kh, 4*eps)
  call check_close('hertz linear in E', hertz_stiffness(3*e, nu, b), 3*kh, 4*eps)
  call check_close('hertz nu = 0: pi E b / 4', hertz_stiffness(e, 0.0_wp, b), pi*e*b/4, 4*eps)

  ! ---- a uniform cantilever in closed form: alpha = 20 deg puts the external root circle
  !      (14.5 mm) inside the base circle (15.04 mm), where the tooth is Chen & Shao's straight
  !      segment of half thickness h_b = r_b sin(psi0) from x_r = sqrt(r_root^2 - h_b^2) to
  !      x_b = r_b cos(psi0); loaded at the base circle (t_c = 0) the involute part is empty and the
  !      load angle is beta = -psi0, h_c = h_b. Over the length L = x_b - x_r with s = x_c - x:
  !      1/k_b = int_0^L (cos(beta) s - sin(beta) h_b)^2 ds / (E I), I = 2/3 h_b^3 b
  !      1/k_s = 1.2 cos(beta)^2 L / (G A), 1/k_a = sin(beta)^2 L / (E A), A = 2 h_b b
  alpha20 = 20*pi/180
  rb = 0.5_wp*m*z*cos(alpha20)
  psi0 = pi/(2*z) + tan(alpha20) - alpha20
  hb = rb*sin(psi0); xb = rb*cos(psi0); xr = sqrt(rf1**2 - hb**2); len = xb - xr
  beta = -psi0; g = e/(2*(1 + nu)); inertia = 2*hb**3*b/3; area = 2*hb*b
  want(1) = 1/((cos(beta)**2*len**3/3 - cos(beta)*sin(beta)*hb*len**2 + sin(beta)**2*hb**2*len) &
       /(e*inertia))
  want(2) = 1/(1.2_wp*cos(beta)**2*len/(g*area))
  want(3) = 1/(sin(beta)**2*len/(e*area))
  do n = 2, 32, 30     ! the integrand is a quadratic in x: exact from 2 Gauss points on
    call external_tooth_stiffness(z, m, alpha20, b, rf1, e, nu, rb, n, k1(1), k1(2), k1(3), ierr, msg)
    call check_true('uniform cantilever: no error', ierr == 0, trim(msg))
    write(tag, '(a,i0,a)') 'uniform cantilever (', n, ' points)'
    call check_close(trim(tag)//' k_b closed form', k1(1), want(1), 1.0e-13_wp)
    call check_close(trim(tag)//' k_s closed form', k1(2), want(2), 1.0e-13_wp)
    call check_close(trim(tag)//' k_a closed form', k1(3), want(3), 1.0e-13_wp)
  end do

  ! ---- both teeth of the spline at the pitch point
  call external_tooth_stiffness(z, m, alpha, b, rf1, e, nu, rp, nq, k1(1), k1(2), k1(3), ierr, msg)
  call check_true('external tooth at the pitch point: no error', ierr == 0, trim(msg))
  call internal_tooth_stiffness(z, m, alpha, b, rf2, ra2, e, nu, rp, nq, k2(1), k2(2), k2(3), ierr, msg)
  call check_true('internal tooth at the pitch point: no error', ierr == 0, trim(msg))

  ! scaling: every beam term is linear in b (I, A ~ b) and in E (G = E / (2 (1 + nu)))
  call external_tooth_stiffness(z, m, alpha, 3*b, rf1, e, nu, rp, nq, k1s(1), k1s(2), k1s(3), ierr, msg)
  call internal_tooth_stiffness(z, m, alpha, 3*b, rf2, ra2, e, nu, rp, nq, k2s(1), k2s(2), k2s(3), &
       ierr, msg)
  call check_true('external k_b, k_s, k_a linear in b', all(abs(k1s - 3*k1) <= 1.0e-14_wp*3*k1))
  call check_true('internal k_b, k_s, k_a linear in b', all(abs(k2s - 3*k2) <= 1.0e-14_wp*3*k2))
  call external_tooth_stiffness(z, m, alpha, b, rf1, 3*e, nu, rp, nq, k1s(1), k1s(2), k1s(3), ierr, msg)
  call internal_tooth_stiffness(z, m, alpha, b, rf2, ra2, 3*e, nu, rp, nq, k2s(1), k2s(2), k2s(3), &
       ierr, msg)
  call check_true('external k_b, k_s, k_a linear in E', all(abs(k1s - 3*k1) <= 1.0e-14_wp*3*k1))
  call check_true('internal k_b, k_s, k_a linear in E', all(abs(k2s - 3*k2) <= 1.0e-14_wp*3*k2))
  ! nu enters the shear term only, through G (no plane-strain factor on the beam terms)
  call external_tooth_stiffness(z, m, alpha, b, rf1, e, 0.0_wp, rp, nq, k1s(1), k1s(2), k1s(3), ierr, msg)
  call internal_tooth_stiffness(z, m, alpha, b, rf2, ra2, e, 0.0_wp, rp, nq, k2s(1), k2s(2), k2s(3), &
       ierr, msg)
  call check_close('external k_s(nu = 0) / k_s(nu = 0.3) = 1.3', k1s(2)/k1(2), 1.3_wp, 1.0e-14_wp)
  call check_close('internal k_s(nu = 0) / k_s(nu = 0.3) = 1.3', k2s(2)/k2(2), 1.3_wp, 1.0e-14_wp)
  call check_true('external k_b, k_a independent of nu', &
       abs(k1s(1) - k1(1)) <= 4*eps*k1(1) .and. abs(k1s(3) - k1(3)) <= 4*eps*k1(3))
  call check_true('internal k_b, k_a independent of nu', &
       abs(k2s(1) - k2(1)) <= 4*eps*k2(1) .and. abs(k2s(3) - k2(3)) <= 4*eps*k2(3))

  ! ---- convergence in the Gauss points (smooth integrands in the roll parameter: spectral):
  !      the error against 128 points shrinks with every doubling until round-off, and is below
  !      1e-12 from 16 points on (the model uses 32)
  call external_tooth_stiffness(z, m, alpha, b, rf1, e, nu, rp, 128, ref(1), ref(2), ref(3), ierr, msg)
  call convergence('external', ref, .true.)
  call internal_tooth_stiffness(z, m, alpha, b, rf2, ra2, e, nu, rp, 128, ref(1), ref(2), ref(3), &
       ierr, msg)
  call convergence('internal', ref, .false.)

  ! ---- Eq. 18: 1/k_m = 1/k_h + sum over both teeth of 1/k_b + 1/k_s + 1/k_a
  call spline_mesh_stiffness(z, m, alpha, b, e, nu, rf1, rf2, ra2, nq, t(1), t(2), t(3), t(4), &
       t(6), t(7), t(8), km, ierr, msg)
  call check_true('spline_mesh_stiffness: no error', ierr == 0, trim(msg))
  call check_true('spline_mesh_stiffness: its terms are the teeth at the pitch point and k_h', &
       t(1) == kh .and. all(t(2:4) == k1) .and. all(t(6:8) == k2))
  call check_close('Eq. 18 series sum', km, 1/(1/kh + sum(1/k1) + sum(1/k2)), 8*eps)
  call check_true('Eq. 18: k_m below every term, above min/7', &
       km < min(kh, minval(k1), minval(k2)) .and. km > min(kh, minval(k1), minval(k2))/7)

  ! ---- with the fillet foundation (docs/model.md section 11): off = bit for bit Eq. 18;
  !      on = two more compliances in series, each linear in E and b
  call spline_mesh_stiffness_fillet(z, m, alpha, b, e, nu, rf1, rf2, ra2, rho, rho, rint1, rout2, &
       .false., nq, t(1), t(2), t(3), t(4), t(5), t(6), t(7), t(8), t(9), t(10), ierr, msg)
  call check_true('fillet off: k_m bit for bit that of Eq. 18, k_f1 = k_f2 = 0', &
       ierr == 0 .and. t(10) == km .and. t(5) == 0 .and. t(9) == 0, trim(msg))
  call spline_mesh_stiffness_fillet(z, m, alpha, b, e, nu, rf1, rf2, ra2, rho, rho, rint1, rout2, &
       .true., nq, t(1), t(2), t(3), t(4), t(5), t(6), t(7), t(8), t(9), kmf, ierr, msg)
  call check_true('fillet on: no error', ierr == 0, trim(msg))
  call fillet_foundation_stiffness(z, m, alpha, b, rf1, rho, rint1, e, nu, rp, kf1, ierr, msg)
  call fillet_foundation_stiffness_internal(z, m, alpha, b, rf2, rho, rout2, e, nu, rp, kf2, ierr, msg)
  call check_true('fillet on: k_f1, k_f2 are the fillet routines at the pitch point', &
       t(5) == kf1 .and. t(9) == kf2)
  call check_close('fillet on: 1/k_m = 1/k_m(Eq. 18) + 1/k_f1 + 1/k_f2', 1/kmf, 1/km + 1/kf1 + 1/kf2, &
       8*eps)
  call fillet_foundation_stiffness(z, m, alpha, 3*b, rf1, rho, rint1, 3*e, nu, rp, kf1s, ierr, msg)
  call fillet_foundation_stiffness_internal(z, m, alpha, 3*b, rf2, rho, rout2, 3*e, 0.0_wp, rp, kf2s, &
       ierr, msg)
  call check_close('fillet k_f1 linear in E b', kf1s, 9*kf1, 8*eps)
  call check_close('fillet k_f2 linear in E b, independent of nu', kf2s, 9*kf2, 8*eps)

  ! ---- model_from_case: k_m = 0 asks for Eq. 18 with the fillet terms at the ISO 4156 radii,
  !      fillet radius 0.2 m, bore at half the external root radius, rim at twice the internal one
  call default_case_model(md)
  call check_true('model: k_m computed (case k_m = 0)', md%k_m_computed)
  call check_close('model: k_m = Eq. 18 with fillet terms', md%k_m, kmf, 4*eps)
  call check_true('model: k_terms(k_m) is its k_m', md%k_terms(ik_m) == md%k_m)
  c%fillet = .false.
  call default_case_model(md, c)
  call check_close('model, fillet = .false.: k_m = Eq. 18', md%k_m, km, 4*eps)
  c%k_m = 2.54295e5_wp
  call default_case_model(md, c)
  call check_true('model: a given k_m is used as given, Eq. 18 still reported', &
       md%k_m == c%k_m .and. .not. md%k_m_computed .and. md%k_terms(ik_m) == km)

  call check_done('test_stiffness')

contains

  !> Errors of k_b, k_s, k_a at 2, 4, ..., 64 points against ref (128 points).
  subroutine convergence(which, ref, external)
    character(len=*), intent(in) :: which
    real(wp), intent(in) :: ref(3)
    logical, intent(in) :: external
    real(wp) :: k(3), e_prev(3), e_now(3)
    integer :: n
    character(len=200) :: line
    ok = .true.
    e_prev = huge(1.0_wp)
    n = 2
    do while (n <= 64)
      if (external) then
        call external_tooth_stiffness(z, m, alpha, b, rf1, e, nu, rp, n, k(1), k(2), k(3), ierr, msg)
      else
        call internal_tooth_stiffness(z, m, alpha, b, rf2, ra2, e, nu, rp, n, k(1), k(2), k(3), ierr, msg)
      end if
      e_now = abs(k - ref)/ref
      write(line, '(a,i3,a,3es10.2)') 'points', n, ': relative errors k_b k_s k_a', e_now
      print '(4x,a)', trim(line)
      ! shrinking with each doubling, or already at round-off
      ok = ok .and. all(e_now < e_prev .or. e_now <= 1.0e-14_wp)
      if (n >= 16) ok = ok .and. all(e_now <= 1.0e-12_wp)
      e_prev = e_now
      n = 2*n
    end do
    call check_true(which//' tooth: k_b, k_s, k_a converge as the Gauss points double', ok)
  end subroutine convergence

end program test_stiffness
