!> Mesh stiffness of the spline tooth pair by the potential energy method (docs/model.md section 7,
!> the paper's Eq. 18):
!>   1/k_m = 1/k_h + sum over the external AND the internal tooth of (1/k_b + 1/k_s + 1/k_a),
!> optionally (docs/model.md section 11) + 1/k_f per tooth, the fillet-foundation compliance of Sainsot,
!> Velex & Duverger (2004): fillet_foundation_stiffness[_internal], spline_mesh_stiffness_fillet.
!>
!> Every tooth is a variable-section cantilever ("slice beam") clamped at its root circle and
!> loaded at the contact point by a unit force F along the line of action (Yang & Lin 1987;
!> Tian 2004; Chen & Shao 2011). With F_b = F cos(beta) (normal to the tooth centre line),
!> F_a = F sin(beta) (along it), section half-thickness h(x), I = (2/3) h^3 b, A = 2 h b:
!>   1/k_b = int (cos(beta) |x - x_c| - sin(beta) h_c)^2 / (E I) dx      (bending)
!>   1/k_s = int 1.2 cos(beta)^2 / (G A) dx                              (shear, kappa = 1.2)
!>   1/k_a = int sin(beta)^2 / (E A) dx                                  (axial compression)
!> the integrals running from the contact section x_c to the root section. G = E / (2 (1 + nu)).
!> Elastic constants: E and G as printed by Tian 2004 and Chen & Shao 2011 (no plane-strain
!> factor 1/(1 - nu^2) on the tooth beam; only the Hertz term carries (1 - nu^2)). A wide-face
!> (plane-strain) variant would multiply k_b and k_a by 1/(1 - nu^2) = 1.099 for nu = 0.3; it is
!> deliberately NOT applied, so that the published formulas are reproduced exactly.
!>
!> The involute is parametrised by its roll parameter t = tan(alpha_r) (alpha_r: pressure angle
!> at radius r = r_b sqrt(1 + t^2)); in t every integrand is smooth (no square-root end
!> singularity at the base circle), so plain Gauss-Legendre with nquad points converges
!> spectrally. This is Tian's angle parametrisation (his alpha = alpha_2 - t) written for either
!> tooth, so the external integrals are term by term those of Tian 2004 / Chen & Shao 2011.
!> The Gauss-Legendre rule (Newton on P_n; the 32-point rule of a model build from a table) is
!> made once per call of a public routine and handed to every integral of it
!> (spline_mesh_stiffness: one rule for both teeth).
module spline_stiffness
  use spline_kinds, only: wp, pi
  use spline_errors, only: num
  implicit none
  private
  public :: hertz_stiffness, external_tooth_stiffness, internal_tooth_stiffness, &
       spline_mesh_stiffness, sainsot_fillet_compliance, fillet_foundation_stiffness, &
       fillet_foundation_stiffness_internal, spline_mesh_stiffness_fillet, gauss_legendre, &
       gauss_legendre_node

  real(wp), parameter :: kappa_shear = 1.2_wp   !< shear correction factor of a rectangular section
  integer, parameter :: ext_tooth = 1, int_tooth = -1

  !> Polynomial coefficients of the fillet-foundation formula of Sainsot, Velex & Duverger (2004),
  !> the coefficient table of the paper (also printed by Chaari et al. 2009 and used by ROSS's
  !> GearElementTVMS). Column i = X_i in (L, M, P, Q); rows = (A_i, B_i, C_i, D_i, E_i, F_i) of
  !>   X_i = A_i/theta_f^2 + B_i h_f^2 + C_i h_f/theta_f + D_i/theta_f + E_i h_f + F_i.
  real(wp), parameter :: sainsot_coef(6, 4) = reshape([ &
       -5.574e-5_wp, -1.9986e-3_wp, -2.3015e-4_wp,  4.7702e-3_wp,  0.0271_wp, 6.8045_wp, &  ! L
       60.111e-5_wp,  28.100e-3_wp, -83.431e-4_wp, -9.9256e-3_wp,  0.1624_wp, 0.9086_wp, &  ! M
      -50.952e-5_wp,  185.50e-3_wp,  0.0538e-4_wp,  53.300e-3_wp,  0.2895_wp, 0.9236_wp, &  ! P
      -6.2042e-5_wp,  9.0889e-3_wp, -4.0964e-4_wp,  7.8297e-3_wp, -0.1472_wp, 0.6904_wp], & ! Q
       [6, 4])

  !> The 32-point Gauss-Legendre rule (model_from_case's nquad) as gauss_legendre_node solves it,
  !> to 18 digits, which read back bit for bit (tests/fortran/test_stiffness.f90 solves it again):
  !> a model build solves no Newton iteration.
  real(wp), parameter :: gl32_s(32) = [ &
       9.97263861849481570E-01_wp, 9.85611511545268382E-01_wp, 9.64762255587506390E-01_wp, &
       9.34906075937739667E-01_wp, 8.96321155766052091E-01_wp, 8.49367613732569970E-01_wp, &
       7.94483795967942386E-01_wp, 7.32182118740289711E-01_wp, 6.63044266930215231E-01_wp, &
       5.87715757240762304E-01_wp, 5.06899908932229359E-01_wp, 4.21351276130635333E-01_wp, &
       3.31868602282127667E-01_wp, 2.39287362252137065E-01_wp, 1.44471961582796488E-01_wp, &
       4.83076656877383104E-02_wp, -4.83076656877383104E-02_wp, -1.44471961582796488E-01_wp, &
       -2.39287362252137065E-01_wp, -3.31868602282127667E-01_wp, -4.21351276130635333E-01_wp, &
       -5.06899908932229359E-01_wp, -5.87715757240762304E-01_wp, -6.63044266930215231E-01_wp, &
       -7.32182118740289711E-01_wp, -7.94483795967942386E-01_wp, -8.49367613732569970E-01_wp, &
       -8.96321155766052091E-01_wp, -9.34906075937739667E-01_wp, -9.64762255587506390E-01_wp, &
       -9.85611511545268382E-01_wp, -9.97263861849481570E-01_wp]
  real(wp), parameter :: gl32_w(32) = [ &
       7.01861000946952130E-03_wp, 1.62743947309057085E-02_wp, 2.53920653092621421E-02_wp, &
       3.42738629130214176E-02_wp, 4.28358980222266969E-02_wp, 5.09980592623761469E-02_wp, &
       5.86840934785351279E-02_wp, 6.58222227763617940E-02_wp, 7.23457941088486156E-02_wp, &
       7.81938957870704360E-02_wp, 8.33119242269467208E-02_wp, 8.76520930044037416E-02_wp, &
       9.11738786957639047E-02_wp, 9.38443990808044137E-02_wp, 9.56387200792748610E-02_wp, &
       9.65400885147278537E-02_wp, 9.65400885147278537E-02_wp, 9.56387200792748610E-02_wp, &
       9.38443990808044137E-02_wp, 9.11738786957639047E-02_wp, 8.76520930044037416E-02_wp, &
       8.33119242269467208E-02_wp, 7.81938957870704360E-02_wp, 7.23457941088486156E-02_wp, &
       6.58222227763617940E-02_wp, 5.86840934785351279E-02_wp, 5.09980592623761469E-02_wp, &
       4.28358980222266969E-02_wp, 3.42738629130214176E-02_wp, 2.53920653092621421E-02_wp, &
       1.62743947309057085E-02_wp, 7.01861000946952130E-03_wp]

contains

  !> Hertz contact stiffness of a line contact of face width b, Yang & Lin (1987), docs/model.md
  !> Eq. 18: k_h = pi E b / (4 (1 - nu^2)) (independent of the contact position).
  pure function hertz_stiffness(e, nu, b) result(kh)
    real(wp), intent(in) :: e, nu, b
    real(wp) :: kh
    kh = pi*e*b/(4.0_wp*(1.0_wp - nu**2))
  end function hertz_stiffness

  !> Bending, shear and axial-compression stiffness [N/m] of ONE external involute tooth loaded
  !> at radius r_contact (Tian 2004, Eqs. of 1/k_b, 1/k_s, 1/k_a; Chen & Shao 2011 for the root).
  !> Tooth thickness pi m / 2 at the pitch circle: half tooth angle on the base circle
  !> alpha_2 = pi/(2z) + inv(alpha); at radius r the half angle is psi = alpha_2 - inv(alpha_r).
  !> Load angle (between the line of action and the normal to the tooth centre line):
  !> beta = alpha_c - psi_c = t_c - alpha_2 (Tian's alpha_1).
  !>  * r_root <  r_b: involute from the base circle to the contact, plus the Chen & Shao (2011)
  !>    straight segment of constant half thickness h_b = r_b sin(alpha_2) from the root circle
  !>    (x = sqrt(r_root^2 - h_b^2)) to the base circle (x = r_b cos(alpha_2)).
  !>  * r_root >= r_b: the involute is cut by the root circle above the base circle (the case of
  !>    the external spline); integrate the involute from the root circle only.
  pure subroutine external_tooth_stiffness(z, m, alpha, b, r_root, e, nu, r_contact, nquad, &
       kb, ks, ka, ierr, errmsg)
    real(wp), intent(in) :: z, m, alpha, b, r_root, e, nu, r_contact
    integer, intent(in) :: nquad
    real(wp), intent(out) :: kb, ks, ka
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp), allocatable :: s(:), w(:)
    call gauss_legendre(nquad, s, w)
    call external_tooth_rule(z, m, alpha, b, r_root, e, nu, r_contact, s, w, kb, ks, ka, ierr, errmsg)
  end subroutine external_tooth_stiffness

  !> external_tooth_stiffness with the Gauss-Legendre rule s, w (gauss_legendre) given.
  pure subroutine external_tooth_rule(z, m, alpha, b, r_root, e, nu, r_contact, s, w, &
       kb, ks, ka, ierr, errmsg)
    real(wp), intent(in) :: z, m, alpha, b, r_root, e, nu, r_contact, s(:), w(:)
    real(wp), intent(out) :: kb, ks, ka
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp) :: rb, psi0, tc, tlo, psic, xc, hc, beta, g, cb, cs, ca, hb, xb, xr

    kb = 0.0_wp; ks = 0.0_wp; ka = 0.0_wp
    call check_common('external_tooth_stiffness', z, m, alpha, b, e, nu, size(s), ierr, errmsg)
    if (ierr /= 0) return
    rb = 0.5_wp*m*z*cos(alpha)
    psi0 = pi/(2.0_wp*z) + involute(alpha)                 ! alpha_2 of Tian
    ierr = 1
    if (.not. (r_root > 0.0_wp)) then
      errmsg = 'external_tooth_stiffness: r_root must be > 0, got '//num(r_root, 5)
      return
    end if
    if (.not. (r_contact > r_root .and. r_contact >= rb)) then
      errmsg = 'external_tooth_stiffness: r_contact = '//num(r_contact, 5)//' must be above the root'// &
           ' circle r_root = '//num(r_root, 5)//' and on the involute (>= base radius '//num(rb, 5)//')'
      return
    end if
    tc = roll(r_contact, rb)
    psic = half_angle(ext_tooth, psi0, tc)
    if (.not. (psic > 0.0_wp)) then
      errmsg = 'external_tooth_stiffness: r_contact = '//num(r_contact, 5)// &
           ' lies beyond the pointed tip of the tooth (zero thickness)'
      return
    end if
    if (r_root < rb .and. .not. (r_root > rb*sin(psi0))) then
      errmsg = 'external_tooth_stiffness: r_root = '//num(r_root, 5)// &
           ' is smaller than the half thickness of the tooth at the base circle'
      return
    end if
    ierr = 0; errmsg = ''

    g = e/(2.0_wp*(1.0_wp + nu))
    xc = r_contact*cos(psic); hc = r_contact*sin(psic)
    beta = atan(tc) - psic
    tlo = roll(max(r_root, rb), rb)
    call involute_compliance(ext_tooth, rb, psi0, tlo, tc, xc, hc, beta, b, e, g, s, w, cb, cs, ca)
    if (r_root < rb) then
      hb = rb*sin(psi0); xb = rb*cos(psi0); xr = sqrt(r_root**2 - hb**2)
      call straight_compliance(xr, xb, hb, xc, hc, beta, b, e, g, s, w, cb, cs, ca)
    end if
    kb = 1.0_wp/cb; ks = 1.0_wp/cs; ka = 1.0_wp/ca
  end subroutine external_tooth_rule

  !> Bending, shear and axial-compression stiffness [N/m] of ONE internal (ring) tooth loaded at
  !> radius r_contact. Formulation: slice-beam (variable-section cantilever) integration of the
  !> exact internal involute profile with the same energy expressions as the external tooth
  !> (Yang & Lin 1987 / Tian 2004). This is the approach of the ring-tooth model of Chen & Shao
  !> (2013, Mech. Mach. Theory 69: 1-12), derived here from first principles; their printed
  !> integrals were not available to compare term by term (the ring-rim deformation of that paper
  !> is not included: the tooth is clamped at its root circle). Checked in tests/stiffness_check.f90
  !> against the rack (z -> infinity) closed form.
  !> Geometry: the SPACE of the ring is pi m / 2 at the pitch circle, so the space half angle is
  !> pi/(2z) + inv(alpha) - inv(alpha_r) and the ring tooth half angle is
  !> psi(r) = pi/(2z) - inv(alpha) + inv(alpha_r): it thickens towards its root (larger r).
  !> The ring tooth is clamped at its root circle r_root (the LARGER radius) and free at its tip
  !> r_tip; the loaded part runs from r_contact out to r_root. The force on the ring tooth,
  !> F(-cos(alpha_c) e_t + sin(alpha_c) e_r), compresses the tooth towards its root; its load
  !> angle to the normal of the tooth centre line is beta = alpha_c + psi_c (not alpha_c - psi_c
  !> as for the external tooth), and the bending moment at a section at distance |x - x_c| from
  !> the contact is F (cos(beta) |x - x_c| - sin(beta) h_c), the same form as Tian's.
  pure subroutine internal_tooth_stiffness(z, m, alpha, b, r_root, r_tip, e, nu, r_contact, &
       nquad, kb, ks, ka, ierr, errmsg)
    real(wp), intent(in) :: z, m, alpha, b, r_root, r_tip, e, nu, r_contact
    integer, intent(in) :: nquad
    real(wp), intent(out) :: kb, ks, ka
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp), allocatable :: s(:), w(:)
    call gauss_legendre(nquad, s, w)
    call internal_tooth_rule(z, m, alpha, b, r_root, r_tip, e, nu, r_contact, s, w, kb, ks, ka, &
         ierr, errmsg)
  end subroutine internal_tooth_stiffness

  !> internal_tooth_stiffness with the Gauss-Legendre rule s, w (gauss_legendre) given.
  pure subroutine internal_tooth_rule(z, m, alpha, b, r_root, r_tip, e, nu, r_contact, s, w, &
       kb, ks, ka, ierr, errmsg)
    real(wp), intent(in) :: z, m, alpha, b, r_root, r_tip, e, nu, r_contact, s(:), w(:)
    real(wp), intent(out) :: kb, ks, ka
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp) :: rb, psi0, tc, tf, psic, xc, hc, beta, g, cb, cs, ca

    kb = 0.0_wp; ks = 0.0_wp; ka = 0.0_wp
    call check_common('internal_tooth_stiffness', z, m, alpha, b, e, nu, size(s), ierr, errmsg)
    if (ierr /= 0) return
    rb = 0.5_wp*m*z*cos(alpha)
    psi0 = pi/(2.0_wp*z) - involute(alpha)     ! ring tooth half angle extrapolated to t = 0
    ierr = 1
    if (.not. (r_tip >= rb)) then
      errmsg = 'internal_tooth_stiffness: r_tip = '//num(r_tip, 5)// &
           ' must not be inside the base circle (base radius '//num(rb, 5)//')'
      return
    end if
    if (.not. (r_root > r_tip)) then
      errmsg = 'internal_tooth_stiffness: r_root = '//num(r_root, 5)// &
           ' must be larger than r_tip = '//num(r_tip, 5)
      return
    end if
    if (.not. (r_contact >= r_tip .and. r_contact < r_root)) then
      errmsg = 'internal_tooth_stiffness: r_contact = '//num(r_contact, 5)// &
           ' must lie on the active flank [r_tip, r_root)'
      return
    end if
    if (.not. (half_angle(int_tooth, psi0, roll(r_tip, rb)) > 0.0_wp)) then
      errmsg = 'internal_tooth_stiffness: the ring tooth has no thickness at r_tip = '//num(r_tip, 5)
      return
    end if
    if (.not. (half_angle(int_tooth, psi0, roll(r_root, rb)) < pi/z)) then
      errmsg = 'internal_tooth_stiffness: r_root = '//num(r_root, 5)// &
           ' lies beyond the radius where the tooth space closes'
      return
    end if
    ierr = 0; errmsg = ''

    g = e/(2.0_wp*(1.0_wp + nu))
    tc = roll(r_contact, rb)
    psic = half_angle(int_tooth, psi0, tc)
    xc = r_contact*cos(psic); hc = r_contact*sin(psic)
    beta = atan(tc) + psic
    tf = roll(r_root, rb)
    call involute_compliance(int_tooth, rb, psi0, tc, tf, xc, hc, beta, b, e, g, s, w, cb, cs, ca)
    kb = 1.0_wp/cb; ks = 1.0_wp/cs; ka = 1.0_wp/ca
  end subroutine internal_tooth_rule

  !> docs/model.md Eq. 18 at the pitch point (r_contact = m z / 2 on both teeth):
  !>   1/k_m = 1/k_h + 1/k_b1 + 1/k_s1 + 1/k_a1 + 1/k_b2 + 1/k_s2 + 1/k_a2,
  !> tooth 1 = external spline (root radius rf1), tooth 2 = internal spline (root rf2, tip ra2).
  pure subroutine spline_mesh_stiffness(z, m, alpha, b, e, nu, rf1, rf2, ra2, nquad, kh, &
       kb1, ks1, ka1, kb2, ks2, ka2, km, ierr, errmsg)
    real(wp), intent(in) :: z, m, alpha, b, e, nu, rf1, rf2, ra2
    integer, intent(in) :: nquad
    real(wp), intent(out) :: kh, kb1, ks1, ka1, kb2, ks2, ka2, km
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp) :: rp
    real(wp), allocatable :: s(:), w(:)

    kh = 0.0_wp; km = 0.0_wp
    rp = 0.5_wp*m*z
    call gauss_legendre(nquad, s, w)         ! one rule for both teeth
    call external_tooth_rule(z, m, alpha, b, rf1, e, nu, rp, s, w, kb1, ks1, ka1, ierr, errmsg)
    if (ierr /= 0) then
      errmsg = 'spline_mesh_stiffness (rf1, pitch point): '//trim(errmsg)
      return
    end if
    call internal_tooth_rule(z, m, alpha, b, rf2, ra2, e, nu, rp, s, w, kb2, ks2, ka2, ierr, errmsg)
    if (ierr /= 0) then
      errmsg = 'spline_mesh_stiffness (rf2, ra2, pitch point): '//trim(errmsg)
      return
    end if
    kh = hertz_stiffness(e, nu, b)
    km = 1.0_wp/(1.0_wp/kh + 1.0_wp/kb1 + 1.0_wp/ks1 + 1.0_wp/ka1 &
                 + 1.0_wp/kb2 + 1.0_wp/ks2 + 1.0_wp/ka2)
  end subroutine spline_mesh_stiffness

  ! ---------------------------------- fillet-foundation compliance -----------------------------
  !> Fillet-foundation ("gear body") compliance of ONE tooth, Sainsot, Velex & Duverger (2004),
  !> J. Mech. Des. 126(4): 748-752, their analytical formula for the body-induced deflection delta_f
  !> under a unit load (the form used by Ma et al. 2014 and by ROSS's GearElementTVMS):
  !>   1/k_f = cos(alpha_m)^2/(E b) [L (u_f/S_f)^2 + M (u_f/S_f) + P (1 + Q tan(alpha_m)^2)],
  !> L, M, P, Q from the coefficient table (sainsot_coef) at (theta_f, h_f). Quantities (Sainsot's
  !> figure of the tooth on its body):
  !>   alpha_m  angle between the line of action and the normal to the tooth centre line (the load
  !>            angle beta of the slice-beam routines above);
  !>   u_f      distance, along the tooth centre line, from the root circle to the point where the
  !>            line of action crosses the centre line (that point is at radius r_b/cos(alpha_m):
  !>            the line of action is tangent to the base circle);
  !>   S_f      root thickness 2 r_f theta_f (arc on the root circle between the two fillet ends);
  !>   theta_f  half angle, seen from the centre, between the tooth centre line and the point where
  !>            the fillet meets the root circle;
  !>   h_f      r_f/r_int, root radius over the radius of the bore (the body's inner boundary).
  !> E alone enters (no plane-strain factor), as in Ma et al. and ROSS. Returns c = 1/k_f [m/N]
  !> and optionally coef = (L, M, P, Q). No checks: see the two callers below.
  pure subroutine sainsot_fillet_compliance(theta_f, h_f, u_f, s_f, alpha_m, e, b, c, coef)
    real(wp), intent(in) :: theta_f, h_f, u_f, s_f, alpha_m, e, b
    real(wp), intent(out) :: c
    real(wp), intent(out), optional :: coef(4)
    real(wp) :: x(4), r
    integer :: i
    do i = 1, 4
      x(i) = dot_product(sainsot_coef(:, i), &
           [1.0_wp/theta_f**2, h_f**2, h_f/theta_f, 1.0_wp/theta_f, h_f, 1.0_wp])
    end do
    r = u_f/s_f
    c = cos(alpha_m)**2/(e*b)*(x(1)*r**2 + x(2)*r + x(3)*(1.0_wp + x(4)*tan(alpha_m)**2))
    if (present(coef)) coef = x
  end subroutine sainsot_fillet_compliance

  !> Fillet-foundation stiffness k_f [N/m] of ONE external tooth loaded at radius r_contact
  !> (Sainsot et al. 2004; formula and symbols in sainsot_fillet_compliance).
  !> Root geometry: the tooth is generated by its basic rack (hob), whose tip line cuts the root
  !> circle r_root and whose tip corners are rounded with radius rho_f. The fillet then meets the
  !> root circle where the rack's tip round touches it, at
  !>   theta_f = [pi m/4 + (h_d - rho_f) tan(alpha) + rho_f/cos(alpha)] / r_p,  h_d = r_p - r_root
  !> (rack coordinate of the round's centre, rolled onto the pitch circle r_p = m z/2; exact for a
  !> rack-generated tooth with x = 0; it is where ROSS's own trochoid ends, see tests/test_ross.py).
  !> The spline (ISO 4156, 30 deg flat root): r_root = m (Z - 1.5)/2 = 14.5 mm, dedendum 0.75 m,
  !> rho_f = 0.2 m (the standard's minimum root fillet radius for the flat root), theta_f = 0.1667.
  !> Bore r_int: the body is taken as a ring r_int..r_root; a solid shaft has no r_int (h_f -> inf,
  !> outside Sainsot's fit), so r_int is an input; for the spline it is NOT given by the paper:
  !> the reference values take r_int = r_root/2 (h_f = 2), see docs/stiffness.md for the spread.
  !> u_f < 0 (the line of action crossing the centre line inside the root circle: low contacts on
  !> short teeth) is allowed; the bracket is a positive quadratic form in u_f/S_f (M^2 < 4 L P in
  !> and near the fitted range), and a non-positive compliance is reported as an error.
  !> nu is checked but unused (the formula has E only); kept for the common argument pattern.
  !> detail (optional) = (theta_f, h_f, u_f, S_f, alpha_m, L, M, P, Q).
  pure subroutine fillet_foundation_stiffness(z, m, alpha, b, r_root, rho_f, r_int, e, nu, &
       r_contact, kf, ierr, errmsg, detail)
    real(wp), intent(in) :: z, m, alpha, b, r_root, rho_f, r_int, e, nu, r_contact
    real(wp), intent(out) :: kf
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp), intent(out), optional :: detail(9)
    character(len=*), parameter :: who = 'fillet_foundation_stiffness'
    real(wp) :: rb, rp, psi0, tc, psic, am, thf, uf

    kf = 0.0_wp
    if (present(detail)) detail = 0.0_wp
    call check_common(who, z, m, alpha, b, e, nu, 1, ierr, errmsg)
    if (ierr /= 0) return
    rp = 0.5_wp*m*z; rb = rp*cos(alpha)
    psi0 = pi/(2.0_wp*z) + involute(alpha)
    call check_fillet(who, z, m, alpha, rp - r_root, rho_f, 'r_root', r_root, thf, ierr, errmsg)
    if (ierr /= 0) return
    ierr = 1
    if (.not. (r_int > 0.0_wp .and. r_int < r_root)) then
      errmsg = who//': r_int (bore radius) = '//num(r_int, 5)//' must be in (0, r_root = '//num(r_root, 5)//')'
      return
    end if
    tc = roll(r_contact, rb)
    psic = half_angle(ext_tooth, psi0, tc)
    if (.not. (r_contact > r_root .and. r_contact >= rb .and. psic > 0.0_wp)) then
      errmsg = who//': r_contact = '//num(r_contact, 5)//' must be on the flank: above r_root = '// &
           num(r_root, 5)//', >= base radius '//num(rb, 5)//', below the pointed tip'
      return
    end if
    ierr = 0; errmsg = ''
    am = atan(tc) - psic                    ! load angle (Tian's alpha_1)
    uf = rb/cos(am) - r_root                ! line of action crosses the centre line at r_b/cos(alpha_m)
    call fillet_stiffness_of(who, thf, r_root/r_int, uf, 2.0_wp*r_root*thf, am, e, b, kf, ierr, &
         errmsg, detail)
  end subroutine fillet_foundation_stiffness

  !> Fillet-foundation stiffness k_f [N/m] of ONE internal (ring) tooth at radius r_contact.
  !> Sainsot et al. fitted their formula on EXTERNAL gears only; no internal-gear fit exists. The
  !> documented APPROXIMATION: Sainsot's formula applied with the ring tooth's own geometry, the body
  !> being the ring r_root..r_out outside the teeth (the mirror image of the external body):
  !>   alpha_m = beta = alpha_c + psi_c (the ring tooth's load angle, see internal_tooth_stiffness),
  !>   u_f = r_root - r_b/cos(alpha_m) (the line of action crosses the centre line at r_b/cos(alpha_m),
  !>         normally between the contact and the ring's root circle), S_f = 2 r_root theta_f,
  !>   h_f = r_out/r_root (>= 1: the external h_f = r_root/r_int with the roles of the radii swapped),
  !>   theta_f from the basic rack as for the external tooth with dedendum h_d = r_root - r_p (the rack
  !>         limit of the shaper cutter that cuts a ring; error O(1/z_cutter)).
  !> The spline: r_root = m (Z + 1.5)/2 = 17.5 mm, rho_f = 0.2 m; r_out (sleeve outer radius) not
  !> given by the paper: reference values take r_out = 2 r_root (h_f = 2). nu: as the external one.
  !> detail (optional) = (theta_f, h_f, u_f, S_f, alpha_m, L, M, P, Q).
  pure subroutine fillet_foundation_stiffness_internal(z, m, alpha, b, r_root, rho_f, r_out, e, nu, &
       r_contact, kf, ierr, errmsg, detail)
    real(wp), intent(in) :: z, m, alpha, b, r_root, rho_f, r_out, e, nu, r_contact
    real(wp), intent(out) :: kf
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp), intent(out), optional :: detail(9)
    character(len=*), parameter :: who = 'fillet_foundation_stiffness_internal'
    real(wp) :: rb, rp, psi0, tc, psic, am, thf, uf

    kf = 0.0_wp
    if (present(detail)) detail = 0.0_wp
    call check_common(who, z, m, alpha, b, e, nu, 1, ierr, errmsg)
    if (ierr /= 0) return
    rp = 0.5_wp*m*z; rb = rp*cos(alpha)
    psi0 = pi/(2.0_wp*z) - involute(alpha)
    call check_fillet(who, z, m, alpha, r_root - rp, rho_f, 'r_root', r_root, thf, ierr, errmsg)
    if (ierr /= 0) return
    ierr = 1
    if (.not. (r_out > r_root)) then
      errmsg = who//': r_out (outer radius of the ring body) = '//num(r_out, 5)// &
           ' must be larger than r_root = '//num(r_root, 5)
      return
    end if
    tc = roll(r_contact, rb)
    psic = half_angle(int_tooth, psi0, tc)
    if (.not. (r_contact < r_root .and. r_contact >= rb .and. psic > 0.0_wp)) then
      errmsg = who//': r_contact = '//num(r_contact, 5)//' must be on the flank: below r_root = '// &
           num(r_root, 5)//', >= base radius '//num(rb, 5)//', where the ring tooth has thickness'
      return
    end if
    ierr = 0; errmsg = ''
    am = atan(tc) + psic
    uf = r_root - rb/cos(am)
    call fillet_stiffness_of(who, thf, r_out/r_root, uf, 2.0_wp*r_root*thf, am, e, b, kf, ierr, &
         errmsg, detail)
  end subroutine fillet_foundation_stiffness_internal

  !> The last step of both fillet routines: Sainsot's compliance at the fillet geometry found
  !> (theta_f, h_f, u_f, S_f, alpha_m), checked positive (the fit's quadratic form can leave its
  !> range), as k_f [N/m] and the optional detail (theta_f, h_f, u_f, S_f, alpha_m, L, M, P, Q).
  pure subroutine fillet_stiffness_of(who, thf, hf, uf, sf, am, e, b, kf, ierr, errmsg, detail)
    character(len=*), intent(in) :: who
    real(wp), intent(in) :: thf, hf, uf, sf, am, e, b
    real(wp), intent(out) :: kf
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp), intent(out), optional :: detail(9)
    real(wp) :: c, coef(4)
    call sainsot_fillet_compliance(thf, hf, uf, sf, am, e, b, c, coef)
    if (.not. (c > 0.0_wp)) then      ! the fit's quadratic form left its positive range
      ierr = 1
      errmsg = who//': Sainsot''s fit gives no positive compliance at h_f = '//num(hf, 5)// &
           ', theta_f = '//num(thf, 5)//' (r_int/r_out, rho_f, r_root out of range)'
      return
    end if
    kf = 1.0_wp/c
    if (present(detail)) detail = [thf, hf, uf, sf, am, coef]
  end subroutine fillet_stiffness_of

  !> spline_mesh_stiffness plus the fillet-foundation terms (docs/model.md section 11), at the pitch point:
  !>   fillet = .true.:  1/k_m = 1/k_h + sum_{i=1,2} (1/k_bi + 1/k_si + 1/k_ai + 1/k_fi)
  !>   fillet = .false.: k_m exactly (bit for bit) that of spline_mesh_stiffness; kf1 = kf2 = 0 and
  !>                     rho_f1, rho_f2, rint1, rout2 are then neither used nor checked.
  !> Tooth 1 external (root rf1, fillet radius rho_f1, bore rint1), tooth 2 internal (root rf2, tip
  !> ra2, fillet radius rho_f2, body outer radius rout2).
  pure subroutine spline_mesh_stiffness_fillet(z, m, alpha, b, e, nu, rf1, rf2, ra2, rho_f1, rho_f2, &
       rint1, rout2, fillet, nquad, kh, kb1, ks1, ka1, kf1, kb2, ks2, ka2, kf2, km, ierr, errmsg)
    real(wp), intent(in) :: z, m, alpha, b, e, nu, rf1, rf2, ra2, rho_f1, rho_f2, rint1, rout2
    logical, intent(in) :: fillet
    integer, intent(in) :: nquad
    real(wp), intent(out) :: kh, kb1, ks1, ka1, kf1, kb2, ks2, ka2, kf2, km
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp) :: rp

    kf1 = 0.0_wp; kf2 = 0.0_wp
    call spline_mesh_stiffness(z, m, alpha, b, e, nu, rf1, rf2, ra2, nquad, kh, kb1, ks1, ka1, &
         kb2, ks2, ka2, km, ierr, errmsg)
    if (ierr /= 0 .or. .not. fillet) return
    rp = 0.5_wp*m*z
    km = 0.0_wp
    call fillet_foundation_stiffness(z, m, alpha, b, rf1, rho_f1, rint1, e, nu, rp, kf1, ierr, errmsg)
    if (ierr /= 0) then
      errmsg = 'spline_mesh_stiffness_fillet (rf1, rho_f1, rint1, pitch point): '//trim(errmsg)
      return
    end if
    call fillet_foundation_stiffness_internal(z, m, alpha, b, rf2, rho_f2, rout2, e, nu, rp, kf2, &
         ierr, errmsg)
    if (ierr /= 0) then
      errmsg = 'spline_mesh_stiffness_fillet (rf2, rho_f2, rout2, pitch point): '//trim(errmsg)
      return
    end if
    km = 1.0_wp/(1.0_wp/kh + 1.0_wp/kb1 + 1.0_wp/ks1 + 1.0_wp/ka1 + 1.0_wp/kf1 &
                 + 1.0_wp/kb2 + 1.0_wp/ks2 + 1.0_wp/ka2 + 1.0_wp/kf2)
  end subroutine spline_mesh_stiffness_fillet

  !> Checks the rack-generated root (dedendum hd = |r_root - r_p|, tip radius rho_f) and returns
  !> theta_f (see fillet_foundation_stiffness). The round must fit between the tip line and the
  !> pitch line (rho_f (1 - sin alpha) <= hd) and the root must keep a flat between the teeth
  !> (theta_f < pi/z).
  pure subroutine check_fillet(who, z, m, alpha, hd, rho_f, rname, r_root, thf, ierr, errmsg)
    character(len=*), intent(in) :: who, rname
    real(wp), intent(in) :: z, m, alpha, hd, rho_f, r_root
    real(wp), intent(out) :: thf
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    thf = 0.0_wp
    ierr = 1
    if (.not. (hd > 0.0_wp)) then
      errmsg = who//': '//rname//' = '//num(r_root, 5)//' must lie beyond the pitch circle (radius '// &
           num(0.5_wp*m*z, 5)//'), on the root side'
    else if (.not. (rho_f >= 0.0_wp .and. rho_f*(1.0_wp - sin(alpha)) <= hd)) then
      errmsg = who//': rho_f (root fillet radius) = '//num(rho_f, 5)//' must be >= 0 and fit the'// &
           ' dedendum (rho_f (1 - sin alpha) <= '//num(hd, 5)//')'
    else
      thf = (0.25_wp*pi*m + (hd - rho_f)*tan(alpha) + rho_f/cos(alpha))/(0.5_wp*m*z)
      if (.not. (thf < pi/z)) then
        errmsg = who//': the root fillets overlap (theta_f = '//num(thf, 5)//' >= pi/z): rho_f = '// &
             num(rho_f, 5)//' or '//rname//' = '//num(r_root, 5)//' too large'
      else
        ierr = 0; errmsg = ''
      end if
    end if
  end subroutine check_fillet

  ! ---------------------------------------------------------------------------------------------

  !> Argument checks shared by both teeth.
  pure subroutine check_common(who, z, m, alpha, b, e, nu, nquad, ierr, errmsg)
    character(len=*), intent(in) :: who
    real(wp), intent(in) :: z, m, alpha, b, e, nu
    integer, intent(in) :: nquad
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    ierr = 1
    if (.not. (z >= 3.0_wp)) then
      errmsg = who//': z (number of teeth) must be >= 3, got '//num(z, 5)
    else if (.not. (m > 0.0_wp)) then
      errmsg = who//': m (module) must be > 0, got '//num(m, 5)
    else if (.not. (alpha > 0.0_wp .and. alpha < 0.5_wp*pi)) then
      errmsg = who//': alpha (pressure angle, rad) must be in (0, pi/2), got '//num(alpha, 5)
    else if (.not. (b > 0.0_wp)) then
      errmsg = who//': b (face width) must be > 0, got '//num(b, 5)
    else if (.not. (e > 0.0_wp)) then
      errmsg = who//': e (Young modulus) must be > 0, got '//num(e, 5)
    else if (.not. (nu >= 0.0_wp .and. nu < 0.5_wp)) then
      errmsg = who//': nu (Poisson ratio) must be in [0, 0.5), got '//num(nu, 5)
    else if (nquad < 1) then
      errmsg = who//': nquad (Gauss points) must be >= 1'
    else
      ierr = 0; errmsg = ''
    end if
  end subroutine check_common

  !> Adds the compliances (1/k per unit face, Section header formulas) of the involute part
  !> t in [ta, tb] of a tooth with half angle psi(t) = psi0 -/+ (t - atan t) (external/internal)
  !> and point r = rb sqrt(1 + t^2), x = r cos(psi), h = r sin(psi). Gauss-Legendre in t.
  pure subroutine involute_compliance(side, rb, psi0, ta, tb, xc, hc, beta, b, e, g, s, w, &
       cb, cs, ca)
    integer, intent(in) :: side
    real(wp), intent(in) :: rb, psi0, ta, tb, xc, hc, beta, b, e, g, s(:), w(:)
    real(wp), intent(out) :: cb, cs, ca
    integer :: i
    real(wp) :: t, r, psi, x, h, dxdt, half, mid
    cb = 0.0_wp; cs = 0.0_wp; ca = 0.0_wp
    half = 0.5_wp*(tb - ta); mid = 0.5_wp*(tb + ta)
    do i = 1, size(s)
      t = mid + half*s(i)
      r = rb*sqrt(1.0_wp + t**2)
      psi = half_angle(side, psi0, t)
      x = r*cos(psi); h = r*sin(psi)
      ! dx/dt = r' cos(psi) - r sin(psi) psi', r' = rb t / sqrt(1+t^2), psi' = -/+ t^2/(1+t^2)
      dxdt = rb*t/sqrt(1.0_wp + t**2)*(cos(psi) + side*t*sin(psi))
      call add_slice(abs(x - xc), h, abs(dxdt)*w(i)*half, hc, beta, b, e, g, cb, cs, ca)
    end do
  end subroutine involute_compliance

  !> Adds the compliances of the straight root segment of constant half thickness h (Chen & Shao
  !> 2011: profile between root and base circle taken as a straight line), x in [xa, xb].
  pure subroutine straight_compliance(xa, xb, h, xc, hc, beta, b, e, g, s, w, cb, cs, ca)
    real(wp), intent(in) :: xa, xb, h, xc, hc, beta, b, e, g, s(:), w(:)
    real(wp), intent(inout) :: cb, cs, ca
    integer :: i
    real(wp) :: half, mid
    half = 0.5_wp*(xb - xa); mid = 0.5_wp*(xb + xa)
    do i = 1, size(s)    ! integrand is a quadratic polynomial in x: exact for nquad >= 2
      call add_slice(abs(mid + half*s(i) - xc), h, w(i)*half, hc, beta, b, e, g, cb, cs, ca)
    end do
  end subroutine straight_compliance

  !> One slice dx of the cantilever (energy densities of Yang & Lin 1987 / Tian 2004):
  !> lever = |x - x_c|, I = (2/3) h^3 b, A = 2 h b, M/F = cos(beta) lever - sin(beta) h_c.
  pure subroutine add_slice(lever, h, dx, hc, beta, b, e, g, cb, cs, ca)
    real(wp), intent(in) :: lever, h, dx, hc, beta, b, e, g
    real(wp), intent(inout) :: cb, cs, ca
    real(wp) :: area, inertia
    area = 2.0_wp*h*b
    inertia = 2.0_wp*h**3*b/3.0_wp
    cb = cb + (cos(beta)*lever - sin(beta)*hc)**2/(e*inertia)*dx
    cs = cs + kappa_shear*cos(beta)**2/(g*area)*dx
    ca = ca + sin(beta)**2/(e*area)*dx
  end subroutine add_slice

  !> The n-point Gauss-Legendre rule on [-1, 1]: nodes s, weights w (none if n < 1); for n = 32
  !> the table gl32_s, gl32_w, else solved node by node.
  pure subroutine gauss_legendre(n, s, w)
    integer, intent(in) :: n
    real(wp), allocatable, intent(out) :: s(:), w(:)
    integer :: i
    if (n == size(gl32_s)) then
      s = gl32_s; w = gl32_w
      return
    end if
    allocate(s(max(n, 0)), w(max(n, 0)))
    do i = 1, n
      call gauss_legendre_node(n, i, s(i), w(i))
    end do
  end subroutine gauss_legendre

  !> i-th node s and weight w of the n-point Gauss-Legendre rule on [-1, 1] (Newton on the
  !> three-term recurrence of P_n; initial guess of Tricomi, cos(pi (i - 1/4) / (n + 1/2))).
  pure subroutine gauss_legendre_node(n, i, s, w)
    integer, intent(in) :: n, i
    real(wp), intent(out) :: s, w
    integer :: it, k
    real(wp) :: p0, p1, p2, dp, ds
    s = cos(pi*(i - 0.25_wp)/(n + 0.5_wp))
    dp = 1.0_wp
    do it = 1, 100
      p0 = 1.0_wp; p1 = s
      do k = 2, n
        p2 = ((2*k - 1)*s*p1 - (k - 1)*p0)/k
        p0 = p1; p1 = p2
      end do
      dp = n*(s*p1 - p0)/(s**2 - 1.0_wp)      ! P_n'(s) from P_n and P_{n-1}
      ds = p1/dp
      s = s - ds
      if (abs(ds) <= 4.0_wp*epsilon(1.0_wp)) exit
    end do
    w = 2.0_wp/((1.0_wp - s**2)*dp**2)
  end subroutine gauss_legendre_node

  !> Involute function inv(a) = tan(a) - a.
  pure elemental real(wp) function involute(a)
    real(wp), intent(in) :: a
    involute = tan(a) - a
  end function involute

  !> Roll parameter t = tan(alpha_r) of the involute point at radius r >= rb.
  pure elemental real(wp) function roll(r, rb)
    real(wp), intent(in) :: r, rb
    roll = sqrt(max((r/rb)**2 - 1.0_wp, 0.0_wp))
  end function roll

  !> Half tooth angle at roll parameter t: inv(alpha_r) = t - atan(t);
  !> external tooth psi = psi0 - inv(alpha_r), internal (ring) tooth psi = psi0 + inv(alpha_r).
  pure elemental real(wp) function half_angle(side, psi0, t)
    integer, intent(in) :: side
    real(wp), intent(in) :: psi0, t
    half_angle = psi0 - side*(t - atan(t))
  end function half_angle

end module spline_stiffness
