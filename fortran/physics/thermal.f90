!> Thermal physics: thermal backlash (Eq. 2) and Blok's flash temperature (Eqs. 3-7).
module spline_thermal
  use spline_kinds, only: wp
  implicit none
  private
  public :: thermal_backlash, backlash_coefficient, flash_temperature

contains

  !> Eq. 2's coefficient: kappa = 2 lambda s cos(alpha), the backlash lost per degC of contact
  !> temperature [m/degC].
  pure real(wp) function backlash_coefficient(lambda_th, s, cos_alpha) result(kappa)
    real(wp), intent(in) :: lambda_th, s, cos_alpha
    kappa = 2.0_wp*lambda_th*s*cos_alpha
  end function backlash_coefficient

  !> Eq. 2: backlash of a tooth pair at contact temperature T_B = T_M + T_f (Eq. 1):
  !> c = c_0 - 2 lambda s T_B cos(alpha) = c_0 - kappa T_B.
  pure real(wp) function thermal_backlash(c0, kappa, t_b) result(c)
    real(wp), intent(in) :: c0, kappa, t_b
    c = c0 - kappa*t_b
  end function thermal_backlash

  !> Eqs. 3-7 (Eq. 3 corrected: c_2 v_2 under the second root): Blok flash temperature of a
  !> tooth pair carrying |F| over face width b, with contact-point radii rc1, rc2 on the two splines.
  !>   f_e = |F|/b, v_i = omega rc_i cos(alpha) (Eq. 7), R_i = rc_i sin(alpha_mi),
  !>   alpha_mi = acos(r_b/rc_i) (Eqs. 5-6), B = eta sqrt(2(1-nu^2)/E f_e R1 R2/(R1+R2)) (Eq. 4),
  !>   T_f = u f_m f_e |v1 - v2| / (sqrt(B) (sqrt(g rho c v1) + sqrt(g rho c v2))).
  !> No load or no motion: T_f = 0. Also returns the Hertz width B (0 when unloaded).
  !> The pressure angle comes in as ca = cos(alpha).
  pure subroutine flash_temperature(f, rc1, rc2, r_b, ca, omega, b, e_mod, nu, eta, u, f_m, &
       k_cond, rho, c_heat, tf, bh)
    real(wp), intent(in) :: f, rc1, rc2, r_b, ca, omega, b, e_mod, nu, eta, u, f_m
    real(wp), intent(in) :: k_cond, rho, c_heat
    real(wp), intent(out) :: tf, bh
    real(wp) :: fe, v1, v2, rr1, rr2
    fe = abs(f)/b
    v1 = omega*rc1*ca
    v2 = omega*rc2*ca
    tf = 0.0_wp
    bh = 0.0_wp
    if (fe == 0.0_wp .or. v1 + v2 <= 0.0_wp) return
    rr1 = sqrt(max(0.0_wp, rc1**2 - r_b**2))     ! rc sin(acos(r_b / rc)), exactly
    rr2 = sqrt(max(0.0_wp, rc2**2 - r_b**2))
    bh = eta*sqrt(2.0_wp*(1.0_wp - nu**2)/e_mod*fe*rr1*rr2/(rr1 + rr2))
    tf = u*f_m*fe*abs(v1 - v2)/(sqrt(bh)*(sqrt(k_cond*rho*c_heat*v1) + sqrt(k_cond*rho*c_heat*v2)))
  end subroutine flash_temperature

end module spline_thermal
