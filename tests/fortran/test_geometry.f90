!> Module spline_geometry (fortran/physics/geometry.f90) and the geometry model_from_case derives from it,
!> against docs/model.md sections 2, 6 and 12: ISO 4156 radii, base radius, tooth angles
!> (Eqs. 8-9), profile shift (Eq. 12) and contact radius (Eq. 13 on the active profile).
program test_geometry
  use spline_kinds, only: wp, pi
  use spline_geometry, only: iso4156_radii, tooth_angles, pitch_rotation, profile_shift, &
       contact_radius, active_profile
  use spline_model, only: model_t
  use check, only: check_true, check_close, check_done, default_case_model
  implicit none
  real(wp), parameter :: eps = epsilon(1.0_wp)
  integer, parameter :: zs(4) = [3, 16, 24, 1000]
  real(wp), parameter :: ms(4) = [0.5e-3_wp, 2.0e-3_wp, 1.25e-3_wp, 5.0e-3_wp]
  type(model_t) :: md
  real(wp) :: rp, rfe, rfi, rai, m, sd, cd, phi, err_s, err_c, worst, alpha
  real(wp) :: sphi(1000), cphi(1000)
  real(wp) :: x, y, dl, r, delta, rc, rc_prev, want, lo, hi
  integer :: i, j, k, z
  character(len=64) :: tag
  logical :: ok

  ! ---- ISO 4156 flat-root radii (docs/model.md sections 7 and 12): pitch R = m Z / 2, external
  !      minor m (Z - 1.5) / 2, internal major m (Z + 1.5) / 2, internal minor m (Z - 1) / 2.
  !      Checked as the depths ISO 4156 gives them: dedendum 0.75 m, internal addendum 0.5 m.
  do i = 1, size(zs)
    z = zs(i); m = ms(i)
    call iso4156_radii(z, m, rp, rfe, rfi, rai)
    write(tag, '(a,i0)') 'iso4156 Z=', z
    call check_close(trim(tag)//' pitch diameter m Z', 2.0_wp*rp, m*z, 2*eps)
    call check_close(trim(tag)//' external dedendum 0.75 m', rp - rfe, 0.75_wp*m, 0.0_wp, 8*eps*rp)
    call check_close(trim(tag)//' internal dedendum 0.75 m', rfi - rp, 0.75_wp*m, 0.0_wp, 8*eps*rp)
    call check_close(trim(tag)//' internal addendum 0.5 m', rp - rai, 0.5_wp*m, 0.0_wp, 8*eps*rp)
    call check_true(trim(tag)//' order root_ext < tip_int < pitch < root_int', &
         rfe < rai .and. rai < rp .and. rp < rfi)
  end do

  ! ---- the model of the default case (Z = 16, m = 2 mm, alpha = 30 deg): docs/model.md
  !      section 7 gives the radii 14.5 / 17.5 / 15 mm and the base circle 13.86 mm
  call default_case_model(md)
  alpha = 30.0_wp*pi/180.0_wp
  call check_close('model pitch radius 16 mm', md%r_pitch, 16.0e-3_wp, 2*eps)
  call check_close('model base radius R cos(alpha)', md%r_b, 16.0e-3_wp*sqrt(3.0_wp)/2.0_wp, 4*eps)
  call check_close('model base radius 13.86 mm (docs)', md%r_b, 13.86e-3_wp, 5.0e-3_wp/13.86_wp)
  call check_close('model pressure angle 30 deg', md%alpha, pi/6.0_wp, 2*eps)
  call check_close('model cos(alpha)', md%cos_alpha, sqrt(3.0_wp)/2.0_wp, 2*eps)
  call check_close('model sin(alpha)', md%sin_alpha, 0.5_wp, 2*eps)
  call check_close('model theta0 = pi/(2Z)', md%theta0, pi/32.0_wp, 2*eps)
  call check_close('model sin(2 pi/Z)', md%sin_pitch, sin(pi/8.0_wp), 2*eps)
  call check_close('model cos(2 pi/Z)', md%cos_pitch, cos(pi/8.0_wp), 2*eps)

  ! ---- Eqs. 8-9: phi_j = 2 pi j / Z + omega t + theta0 - alpha, each tooth against the direct
  !      sin/cos (round-off of the rotation recurrence grows like j eps, docs/model.md section 2);
  !      the Z angles are equally spaced, so sum sin = sum cos = 0 (Z >= 2)
  do i = 1, size(zs)
    z = zs(i)
    call pitch_rotation(z, sd, cd)
    call tooth_angles(z, 628.3_wp, 1.234e-3_wp, pi/(2*z), pi/6.0_wp, sd, cd, sphi, cphi)
    worst = 0.0_wp
    do j = 1, z
      phi = 2.0_wp*pi*j/z + 628.3_wp*1.234e-3_wp + pi/(2*z) - pi/6.0_wp
      err_s = abs(sphi(j) - sin(phi)); err_c = abs(cphi(j) - cos(phi))
      worst = max(worst, err_s/(4*j*eps), err_c/(4*j*eps))
    end do
    write(tag, '(a,i0)') 'tooth_angles Z=', z
    call check_true(trim(tag)//' each tooth within 4 j eps of sin/cos(phi_j)', worst <= 1.0_wp)
    call check_close(trim(tag)//' sum sin(phi_j) = 0', sum(sphi(1:z)), 0.0_wp, 0.0_wp, z*z*eps)
    call check_close(trim(tag)//' sum cos(phi_j) = 0', sum(cphi(1:z)), 0.0_wp, 0.0_wp, z*z*eps)
    ok = all(abs(sphi(1:z)**2 + cphi(1:z)**2 - 1.0_wp) <= 8*z*eps)
    call check_true(trim(tag)//' sin^2 + cos^2 = 1 for every tooth', ok)
  end do

  ! ---- Eq. 12: Delta = x cos(phi) + y sin(phi)
  x = 3.0e-5_wp; y = -1.7e-5_wp; phi = 0.7_wp
  dl = profile_shift(x, y, sin(phi), cos(phi))
  call check_close('profile_shift Delta = x cos + y sin', dl, x*cos(phi) + y*sin(phi), 4*eps)

  ! ---- the contact radius (docs/model.md section 6), R = 16 mm, alpha = 30 deg, m = 2 mm, Z = 16
  r = 16.0e-3_wp
  call active_profile(16, 2.0e-3_wp, lo, hi)
  call check_close('active_profile: internal tip circle m (Z - 1) / 2', lo, 15.0e-3_wp, 2*eps)
  call check_close('active_profile: external tip circle m (Z + 1) / 2', hi, 17.0e-3_wp, 2*eps)
  call check_close('contact_radius Delta = 0: R', &
       contact_radius(0.0_wp, r, cos(pi/6), lo, hi), r, 2*eps)
  ! Eq. 13 is the distance |P - Delta u| with |P| = R, angle(P, u) = alpha; it moves at most as
  ! fast as Delta (|d r_c / d Delta| <= 1, the triangle inequality) and is held on [lo, hi]
  worst = 0.0_wp
  ok = .true.
  rc_prev = 0.0_wp
  do k = -40, 40
    delta = k*2.0e-3_wp/20      ! |Delta| <= 2 m: beyond m / 2 the radius reaches the tip circles
    rc = contact_radius(delta, r, cos(pi/6), lo, hi)
    want = min(max(hypot(r - delta*cos(pi/6), delta*sin(pi/6)), lo), hi)
    worst = max(worst, abs(rc - want)/(4*eps*r))
    ok = ok .and. rc >= lo .and. rc <= hi
    if (k > -40) ok = ok .and. rc <= rc_prev .and. rc_prev - rc <= 2.0e-3_wp/20*(1 + 4*eps)
    rc_prev = rc
  end do
  call check_true('contact_radius = Eq. 13 (|P - Delta u|) held on [15, 17] mm, |Delta| <= 2 m', &
       worst <= 1.0_wp)
  call check_true('contact_radius on the active profile, falling in Delta, |dr_c| <= |dDelta|', ok)
  call check_close('contact_radius Delta = 2 m: the internal tip circle', &
       contact_radius(2*2.0e-3_wp, r, cos(pi/6), lo, hi), lo, 0.0_wp)
  call check_close('contact_radius Delta = -2 m: the external tip circle', &
       contact_radius(-2*2.0e-3_wp, r, cos(pi/6), lo, hi), hi, 0.0_wp)

  call check_done('test_geometry')
end program test_geometry
