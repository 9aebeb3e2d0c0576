!> Spline geometry: tooth angles (Eqs. 8-9), the profile shift (Eq. 12) and the contact-point
!> radius (Eq. 13, one point per tooth pair on the active profile).
module spline_geometry
  use spline_kinds, only: wp, pi
  implicit none
  private
  public :: tooth_angles, tooth_angles_at, tooth1_angle, pitch_rotation, contact_radius, &
       profile_shift, iso4156_radii, active_profile, &
       root_section

contains

  !> ISO 4156 flat-root (30 deg) spline radii for module m and Z teeth (docs/model.md section 12):
  !> pitch R = m Z / 2, external minor (root) m (Z - 1.5) / 2, internal major (root)
  !> m (Z + 1.5) / 2 and internal minor (tip) m (Z - 1) / 2.
  pure subroutine iso4156_radii(z, m, r_pitch, rf_ext, rf_int, ra_int)
    integer, intent(in) :: z
    real(wp), intent(in) :: m
    real(wp), intent(out) :: r_pitch, rf_ext, rf_int, ra_int
    r_pitch = 0.5_wp*m*z
    rf_ext = 0.5_wp*m*(z - 1.5_wp)
    rf_int = 0.5_wp*m*(z + 1.5_wp)
    ra_int = 0.5_wp*m*(z - 1.0_wp)
  end subroutine iso4156_radii

  !> The external tooth's root section for the bending stress estimate (docs/model.md section
  !> 15, "Tooth stresses"): the load at the pitch circle R = m Z / 2 (the contact point of docs/
  !> model.md section 6) stands h_f = R - r_f = 0.75 m above the critical section at the root
  !> (minor) circle r_f = m (Z - 1.5) / 2 (iso4156_radii); the flanks of ISO 4156's basic rack
  !> are straight at the pressure angle, so the tooth there is t_f = s + 2 h_f tan(alpha) thick
  !> (s: the tooth thickness at the pitch circle).
  pure subroutine root_section(z, m, s, alpha, h_f, t_f)
    integer, intent(in) :: z
    real(wp), intent(in) :: m, s, alpha
    real(wp), intent(out) :: h_f, t_f
    real(wp) :: r, rf, rfi, rai
    call iso4156_radii(z, m, r, rf, rfi, rai)
    h_f = r - rf
    t_f = s + 2.0_wp*h_f*tan(alpha)
  end subroutine root_section

  !> Eqs. 8-9: line-of-action angle of every tooth pair, phi_j = 2 pi j / Z + omega t + theta_0 - alpha,
  !> returned as sin and cos (what the mesh needs). Two sin/cos pairs per call instead of Z: the
  !> teeth are equally spaced, so phi_{j+1} = phi_j + 2 pi / Z is a rotation (round-off grows
  !> like j eps: 1e-15 at Z = 16, 1.4e-14 at Z = 1000, the most a case allows).
  !> sd, cd: sin and cos of the pitch angle 2 pi / Z (pitch_rotation, once per case).
  pure subroutine tooth_angles(z, omega, t, theta0, alpha, sd, cd, sphi, cphi)
    integer, intent(in) :: z
    real(wp), intent(in) :: omega, t, theta0, alpha, sd, cd
    real(wp), intent(out) :: sphi(z), cphi(z)
    integer :: j
    real(wp) :: phi
    phi = angle1(z, omega, t, theta0, alpha)
    sphi(1) = sin(phi)
    cphi(1) = cos(phi)
    do j = 2, z
      call step(sd, cd, sphi(j-1), cphi(j-1), sphi(j), cphi(j))
    end do
  end subroutine tooth_angles

  !> Eqs. 8-9 for tooth 1: phi_1 = 2 pi / Z + omega t + theta_0 - alpha. For other modules; this
  !> one calls angle1, which the compiler inlines (spline_mesh::tooth_approach says why).
  elemental real(wp) function tooth1_angle(z, omega, t, theta0, alpha) result(phi)
    integer, intent(in) :: z
    real(wp), intent(in) :: omega, t, theta0, alpha
    phi = angle1(z, omega, t, theta0, alpha)
  end function tooth1_angle

  elemental real(wp) function angle1(z, omega, t, theta0, alpha) result(phi)
    integer, intent(in) :: z
    real(wp), intent(in) :: omega, t, theta0, alpha
    phi = 2.0_wp*pi/z + omega*t + theta0 - alpha
  end function angle1

  !> tooth_angles at the n times t(1:n) at once (bit for bit): sphi(i, j), cphi(i, j) of tooth j
  !> at t(i), ld >= n the leading dimension of the caller's block. For other modules (the mesh's
  !> outputs); here angle1 and step are inlined and each pitch rotation runs over the n times.
  pure subroutine tooth_angles_at(z, n, ld, omega, t, theta0, alpha, sd, cd, sphi, cphi)
    integer, intent(in) :: z, n, ld
    real(wp), intent(in) :: omega, t(n), theta0, alpha, sd, cd
    real(wp), intent(inout) :: sphi(ld, z), cphi(ld, z)
    integer :: i, j
    real(wp) :: phi
    do i = 1, n
      phi = angle1(z, omega, t(i), theta0, alpha)
      sphi(i, 1) = sin(phi)
      cphi(i, 1) = cos(phi)
    end do
    do j = 2, z
      do i = 1, n
        call step(sd, cd, sphi(i, j-1), cphi(i, j-1), sphi(i, j), cphi(i, j))
      end do
    end do
  end subroutine tooth_angles_at

  elemental subroutine step(sd, cd, s, c, sn, cn)
    real(wp), intent(in) :: sd, cd, s, c
    real(wp), intent(out) :: sn, cn
    sn = s*cd + c*sd
    cn = c*cd - s*sd
  end subroutine step

  !> The rotation between neighbouring teeth of Eqs. 8-9: sd = sin(2 pi / Z), cd = cos(2 pi / Z).
  pure subroutine pitch_rotation(z, sd, cd)
    integer, intent(in) :: z
    real(wp), intent(out) :: sd, cd
    sd = sin(2.0_wp*pi/z)
    cd = cos(2.0_wp*pi/z)
  end subroutine pitch_rotation

  !> Eq. 12 in its exact simplified form: displacement of spline i in the tooth-profile direction,
  !> Delta = x cos(phi) + y sin(phi).
  pure real(wp) function profile_shift(x, y, sphi, cphi) result(delta)
    real(wp), intent(in) :: x, y, sphi, cphi
    delta = x*cphi + y*sphi
  end function profile_shift

  !> The active profile of a spline pair (docs/model.md section 6): the radii where both flanks
  !> exist, from the internal spline's tip (minor) circle m (Z - 1) / 2 to the external spline's
  !> tip (major) circle m (Z + 1) / 2. ISO 4156 puts each spline's form circle beyond the mate's
  !> tip circle (form clearance 0.1 m), so this is the active profile of both splines.
  pure subroutine active_profile(z, m, r_lo, r_hi)
    integer, intent(in) :: z
    real(wp), intent(in) :: m
    real(wp), intent(out) :: r_lo, r_hi
    r_lo = 0.5_wp*m*(z - 1.0_wp)
    r_hi = 0.5_wp*m*(z + 1.0_wp)
  end subroutine active_profile

  !> Contact-point radius on a spline whose centre is shifted by delta along the tooth profile
  !> (docs/model.md section 6, the project's rule): the contact point of a tooth pair is one point,
  !> the pair's pitch point P (|P| = R = m Z / 2 from the undisplaced axis, at angle alpha to the
  !> profile direction u), the same for both splines; its radius from the shifted centre delta u is
  !> Eq. 13, r_c = |P - delta u| = sqrt(delta^2 + R^2 - 2 R delta cos(alpha)), held on the active
  !> profile [r_lo, r_hi]. The paper's Eq. 14 branch is not used: switching between Eqs. 13 and 14
  !> moves r_c by 2 delta cos(alpha) at once. The pressure angle comes in as ca = cos(alpha).
  pure real(wp) function contact_radius(delta, r, ca, r_lo, r_hi) result(rc)
    real(wp), intent(in) :: delta, r, ca, r_lo, r_hi
    rc = min(max(sqrt(delta**2 + r**2 - 2.0_wp*r*delta*ca), r_lo), r_hi)
  end function contact_radius

end module spline_geometry
