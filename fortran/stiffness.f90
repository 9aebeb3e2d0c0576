!> Mesh stiffness of the spline tooth pair by the potential energy method (MODEL.md Section 7,
!> the paper's Eq. 18):
!>   1/k_m = 1/k_h + sum over the external AND the internal tooth of (1/k_b + 1/k_s + 1/k_a).
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
!> Gauss-Legendre nodes are generated one at a time (Newton on P_n): no work arrays.
module spline_stiffness
  use spline_kinds, only: wp, pi
  implicit none
  private
  public :: hertz_stiffness, external_tooth_stiffness, internal_tooth_stiffness, &
       spline_mesh_stiffness

  real(wp), parameter :: kappa_shear = 1.2_wp   !< shear correction factor of a rectangular section
  integer, parameter :: ext_tooth = 1, int_tooth = -1

contains

  !> Hertz contact stiffness of a line contact of face width b, Yang & Lin (1987), MODEL.md
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
    real(wp) :: rb, psi0, tc, tlo, psic, xc, hc, beta, g, cb, cs, ca, hb, xb, xr

    kb = 0.0_wp; ks = 0.0_wp; ka = 0.0_wp
    call check_common('external_tooth_stiffness', z, m, alpha, b, e, nu, nquad, ierr, errmsg)
    if (ierr /= 0) return
    rb = 0.5_wp*m*z*cos(alpha)
    psi0 = pi/(2.0_wp*z) + involute(alpha)                 ! alpha_2 of Tian
    ierr = 1
    if (.not. (r_root > 0.0_wp)) then
      errmsg = 'external_tooth_stiffness: r_root must be > 0, got '//num(r_root)
      return
    end if
    if (.not. (r_contact > r_root .and. r_contact >= rb)) then
      errmsg = 'external_tooth_stiffness: r_contact = '//num(r_contact)//' must be above the root'// &
           ' circle r_root = '//num(r_root)//' and on the involute (>= base radius '//num(rb)//')'
      return
    end if
    tc = roll(r_contact, rb)
    psic = half_angle(ext_tooth, psi0, tc)
    if (.not. (psic > 0.0_wp)) then
      errmsg = 'external_tooth_stiffness: r_contact = '//num(r_contact)// &
           ' lies beyond the pointed tip of the tooth (zero thickness)'
      return
    end if
    if (r_root < rb .and. .not. (r_root > rb*sin(psi0))) then
      errmsg = 'external_tooth_stiffness: r_root = '//num(r_root)// &
           ' is smaller than the half thickness of the tooth at the base circle'
      return
    end if
    ierr = 0; errmsg = ''

    g = e/(2.0_wp*(1.0_wp + nu))
    xc = r_contact*cos(psic); hc = r_contact*sin(psic)
    beta = atan(tc) - psic
    tlo = roll(max(r_root, rb), rb)
    call involute_compliance(ext_tooth, rb, psi0, tlo, tc, xc, hc, beta, b, e, g, nquad, cb, cs, ca)
    if (r_root < rb) then
      hb = rb*sin(psi0); xb = rb*cos(psi0); xr = sqrt(r_root**2 - hb**2)
      call straight_compliance(xr, xb, hb, xc, hc, beta, b, e, g, nquad, cb, cs, ca)
    end if
    kb = 1.0_wp/cb; ks = 1.0_wp/cs; ka = 1.0_wp/ca
  end subroutine external_tooth_stiffness

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
    real(wp) :: rb, psi0, tc, tf, psic, xc, hc, beta, g, cb, cs, ca

    kb = 0.0_wp; ks = 0.0_wp; ka = 0.0_wp
    call check_common('internal_tooth_stiffness', z, m, alpha, b, e, nu, nquad, ierr, errmsg)
    if (ierr /= 0) return
    rb = 0.5_wp*m*z*cos(alpha)
    psi0 = pi/(2.0_wp*z) - involute(alpha)     ! ring tooth half angle extrapolated to t = 0
    ierr = 1
    if (.not. (r_tip >= rb)) then
      errmsg = 'internal_tooth_stiffness: r_tip = '//num(r_tip)// &
           ' must not be inside the base circle (base radius '//num(rb)//')'
      return
    end if
    if (.not. (r_root > r_tip)) then
      errmsg = 'internal_tooth_stiffness: r_root = '//num(r_root)// &
           ' must be larger than r_tip = '//num(r_tip)
      return
    end if
    if (.not. (r_contact >= r_tip .and. r_contact < r_root)) then
      errmsg = 'internal_tooth_stiffness: r_contact = '//num(r_contact)// &
           ' must lie on the active flank [r_tip, r_root)'
      return
    end if
    if (.not. (half_angle(int_tooth, psi0, roll(r_tip, rb)) > 0.0_wp)) then
      errmsg = 'internal_tooth_stiffness: the ring tooth has no thickness at r_tip = '//num(r_tip)
      return
    end if
    if (.not. (half_angle(int_tooth, psi0, roll(r_root, rb)) < pi/z)) then
      errmsg = 'internal_tooth_stiffness: r_root = '//num(r_root)// &
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
    call involute_compliance(int_tooth, rb, psi0, tc, tf, xc, hc, beta, b, e, g, nquad, cb, cs, ca)
    kb = 1.0_wp/cb; ks = 1.0_wp/cs; ka = 1.0_wp/ca
  end subroutine internal_tooth_stiffness

  !> MODEL.md Eq. 18 at the pitch point (r_contact = m z / 2 on both teeth):
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

    kh = 0.0_wp; km = 0.0_wp
    rp = 0.5_wp*m*z
    call external_tooth_stiffness(z, m, alpha, b, rf1, e, nu, rp, nquad, kb1, ks1, ka1, ierr, errmsg)
    if (ierr /= 0) then
      errmsg = 'spline_mesh_stiffness (rf1, pitch point): '//trim(errmsg)
      return
    end if
    call internal_tooth_stiffness(z, m, alpha, b, rf2, ra2, e, nu, rp, nquad, kb2, ks2, ka2, &
         ierr, errmsg)
    if (ierr /= 0) then
      errmsg = 'spline_mesh_stiffness (rf2, ra2, pitch point): '//trim(errmsg)
      return
    end if
    kh = hertz_stiffness(e, nu, b)
    km = 1.0_wp/(1.0_wp/kh + 1.0_wp/kb1 + 1.0_wp/ks1 + 1.0_wp/ka1 &
                 + 1.0_wp/kb2 + 1.0_wp/ks2 + 1.0_wp/ka2)
  end subroutine spline_mesh_stiffness

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
      errmsg = who//': z (number of teeth) must be >= 3, got '//num(z)
    else if (.not. (m > 0.0_wp)) then
      errmsg = who//': m (module) must be > 0, got '//num(m)
    else if (.not. (alpha > 0.0_wp .and. alpha < 0.5_wp*pi)) then
      errmsg = who//': alpha (pressure angle, rad) must be in (0, pi/2), got '//num(alpha)
    else if (.not. (b > 0.0_wp)) then
      errmsg = who//': b (face width) must be > 0, got '//num(b)
    else if (.not. (e > 0.0_wp)) then
      errmsg = who//': e (Young modulus) must be > 0, got '//num(e)
    else if (.not. (nu >= 0.0_wp .and. nu < 0.5_wp)) then
      errmsg = who//': nu (Poisson ratio) must be in [0, 0.5), got '//num(nu)
    else if (nquad < 1) then
      errmsg = who//': nquad (Gauss points) must be >= 1'
    else
      ierr = 0; errmsg = ''
    end if
  end subroutine check_common

  !> Adds the compliances (1/k per unit face, Section header formulas) of the involute part
  !> t in [ta, tb] of a tooth with half angle psi(t) = psi0 -/+ (t - atan t) (external/internal)
  !> and point r = rb sqrt(1 + t^2), x = r cos(psi), h = r sin(psi). Gauss-Legendre in t.
  pure subroutine involute_compliance(side, rb, psi0, ta, tb, xc, hc, beta, b, e, g, nquad, &
       cb, cs, ca)
    integer, intent(in) :: side, nquad
    real(wp), intent(in) :: rb, psi0, ta, tb, xc, hc, beta, b, e, g
    real(wp), intent(out) :: cb, cs, ca
    integer :: i
    real(wp) :: s, w, t, r, psi, x, h, dxdt, half, mid
    cb = 0.0_wp; cs = 0.0_wp; ca = 0.0_wp
    half = 0.5_wp*(tb - ta); mid = 0.5_wp*(tb + ta)
    do i = 1, nquad
      call gauss_legendre_node(nquad, i, s, w)
      t = mid + half*s
      r = rb*sqrt(1.0_wp + t**2)
      psi = half_angle(side, psi0, t)
      x = r*cos(psi); h = r*sin(psi)
      ! dx/dt = r' cos(psi) - r sin(psi) psi', r' = rb t / sqrt(1+t^2), psi' = -/+ t^2/(1+t^2)
      dxdt = rb*t/sqrt(1.0_wp + t**2)*(cos(psi) + side*t*sin(psi))
      call add_slice(abs(x - xc), h, abs(dxdt)*w*half, hc, beta, b, e, g, cb, cs, ca)
    end do
  end subroutine involute_compliance

  !> Adds the compliances of the straight root segment of constant half thickness h (Chen & Shao
  !> 2011: profile between root and base circle taken as a straight line), x in [xa, xb].
  pure subroutine straight_compliance(xa, xb, h, xc, hc, beta, b, e, g, nquad, cb, cs, ca)
    real(wp), intent(in) :: xa, xb, h, xc, hc, beta, b, e, g
    integer, intent(in) :: nquad
    real(wp), intent(inout) :: cb, cs, ca
    integer :: i
    real(wp) :: s, w, half, mid
    half = 0.5_wp*(xb - xa); mid = 0.5_wp*(xb + xa)
    do i = 1, nquad    ! integrand is a quadratic polynomial in x: exact for nquad >= 2
      call gauss_legendre_node(nquad, i, s, w)
      call add_slice(abs(mid + half*s - xc), h, w*half, hc, beta, b, e, g, cb, cs, ca)
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

  !> A number for an error message.
  pure function num(x) result(s)
    real(wp), intent(in) :: x
    character(len=:), allocatable :: s
    character(len=24) :: buf
    write(buf, '(es12.5)') x
    s = trim(adjustl(buf))
  end function num

end module spline_stiffness
