!> Spline geometry: tooth angles (Eqs. 8-9) and the contact-point radius (Eqs. 12-14).
module spline_geometry
  use spline_kinds, only: wp, pi
  implicit none
  private
  public :: tooth_angles, pitch_rotation, contact_radius, profile_shift, iso4156_radii

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
    phi = 2.0_wp*pi/z + omega*t + theta0 - alpha
    sphi(1) = sin(phi)
    cphi(1) = cos(phi)
    do j = 2, z
      sphi(j) = sphi(j-1)*cd + cphi(j-1)*sd
      cphi(j) = cphi(j-1)*cd - sphi(j-1)*sd
    end do
  end subroutine tooth_angles

  !> The rotation between neighbouring teeth of Eqs. 8-9: sd = sin(2 pi / Z), cd = cos(2 pi / Z).
  pure subroutine pitch_rotation(z, sd, cd)
    integer, intent(in) :: z
    real(wp), intent(out) :: sd, cd
    sd = sin(2.0_wp*pi/z)
    cd = cos(2.0_wp*pi/z)
  end subroutine pitch_rotation

  !> Eq. 12 in its exact simplified form: displacement of spline i in the tooth-profile direction,
  !> Delta = x cos(phi) + y sin(phi), and its total time derivative (phi' = omega).
  pure subroutine profile_shift(x, y, vx, vy, omega, sphi, cphi, delta, ddelta)
    real(wp), intent(in) :: x, y, vx, vy, omega, sphi, cphi
    real(wp), intent(out) :: delta, ddelta
    delta = x*cphi + y*sphi
    ddelta = vx*cphi + vy*sphi + omega*(-x*sphi + y*cphi)
  end subroutine profile_shift

  !> Eqs. 13-14: radius of the contact point of a spline with pitch radius r (R = m Z / 2) whose
  !> profile is shifted by delta. Moving towards the root (ddelta < 0): law of cosines (Eq. 13);
  !> otherwise towards the tip: law of sines (Eq. 14),
  !>   rc = R sin(pi - alpha - beta) / sin(alpha),  sin(beta) = Delta sin(alpha) / R,
  !> evaluated in the exact equivalent form rc = R cos(beta) + Delta cos(alpha) (expand
  !> sin(alpha + beta); |beta| < pi/2), which needs no inverse sine. The pressure angle comes in
  !> as ca = cos(alpha), sa = sin(alpha) (computed once per case, not per tooth).
  pure real(wp) function contact_radius(delta, ddelta, r, ca, sa) result(rc)
    real(wp), intent(in) :: delta, ddelta, r, ca, sa
    real(wp) :: sb
    if (ddelta < 0.0_wp) then
      rc = sqrt(delta**2 + r**2 - 2.0_wp*r*delta*ca)
    else
      sb = delta*sa/r
      rc = r*sqrt(1.0_wp - sb*sb) + delta*ca
    end if
  end function contact_radius

end module spline_geometry
