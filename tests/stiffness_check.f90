!> Standalone check of module spline_stiffness (docs/model.md section 7, Eq. 18). Build and run:
!>   gfortran -O2 fortran/common/kinds.f90 fortran/common/errors.f90 fortran/physics/stiffness.f90 tests/stiffness_check.f90 -o /tmp/stiff && /tmp/stiff
!> (add -J /tmp to keep the .mod files out of the source tree)
!> Prints: the spline's terms (docs/model.md section 12), a convergence table in nquad, the spur gear
!> of Tian (2004) / Chen & Shao (2011) at its pitch point, two independent cross-checks
!> (Tian's closed-form integrands in his angle variable, and the rack / trapezoid closed form
!> that both tooth routines must approach for z -> infinity), the fillet-foundation terms of
!> Sainsot et al. (2004) (docs/model.md section 11) with their checks, the numbers that
!> tests/test_ross.py compares with ROSS (lines starting with '@', key=value), the ISO 6336-1
!> comparison of docs/stiffness.md, and the error paths.
!> Exit status 1 if a cross-check fails (tolerances printed with each check).
program stiffness_check
  use spline_kinds, only: wp, pi
  use spline_stiffness, only: hertz_stiffness, external_tooth_stiffness, &
       internal_tooth_stiffness, spline_mesh_stiffness, sainsot_fillet_compliance, &
       fillet_foundation_stiffness, fillet_foundation_stiffness_internal, spline_mesh_stiffness_fillet
  implicit none
  real(wp), parameter :: deg = pi/180.0_wp
  integer, parameter :: nref = 64
  integer :: ierr, i, nfail
  character(len=256) :: msg
  real(wp) :: kh, kb1, ks1, ka1, kb2, ks2, ka2, km, ref(7), cur(7), kf1, kf2
  real(wp) :: z, m, alpha, b, e, nu
  integer, parameter :: nq(5) = [8, 16, 32, 64, 128]

  nfail = 0

  ! ---------------- 1. the spline (docs/model.md section 12) -----------------------------------------
  z = 16; m = 2e-3_wp; alpha = 30*deg; b = 0.03_wp; e = 2.1e11_wp; nu = 0.3_wp
  call spline_mesh_stiffness(z, m, alpha, b, e, nu, 14.5e-3_wp, 17.5e-3_wp, 15e-3_wp, nref, &
       kh, kb1, ks1, ka1, kb2, ks2, ka2, km, ierr, msg)
  call must(ierr == 0, 'spline_mesh_stiffness returned an error: '//trim(msg))
  print '(a)', '== Spline, Z=16, m=2 mm, alpha=30 deg, b=30 mm, E=2.1e11, nu=0.3, pitch point =='
  print '(a,f8.4,a,f8.4,a)', '   base radius ', 0.5_wp*m*z*cos(alpha)*1e3_wp, ' mm, pitch radius ', &
       0.5_wp*m*z*1e3_wp, ' mm'
  print '(a,es14.6,a)', '   k_h  (Hertz)              ', kh, ' N/m'
  print '(a,es14.6,a)', '   k_b1 (external, bending)  ', kb1, ' N/m'
  print '(a,es14.6,a)', '   k_s1 (external, shear)    ', ks1, ' N/m'
  print '(a,es14.6,a)', '   k_a1 (external, axial)    ', ka1, ' N/m'
  print '(a,es14.6,a)', '   k_b2 (internal, bending)  ', kb2, ' N/m'
  print '(a,es14.6,a)', '   k_s2 (internal, shear)    ', ks2, ' N/m'
  print '(a,es14.6,a)', '   k_a2 (internal, axial)    ', ka2, ' N/m'
  print '(a,es14.6,a)', '   k_m  (Eq. 18)             ', km, ' N/m'
  call must(km > 1e8_wp .and. km < 3e9_wp, 'k_m outside the expected 1e8 - 3e9 N/m')
  ! context only (different method, includes gear-body compliance): ISO 6336-1 single stiffness
  ! c' = c'_th C_M C_R C_B b, c'_th = 1/q', q' = 0.04723 + 0.15551/z1 + 0.25791/z2 (x = 0; z2 = inf
  ! for an internal gear), C_M = 0.8, C_R = 1, C_B = (1 + 0.5 (1.2 - h_fP/m)) (1 - 0.02 (20 - alpha_deg));
  ! spline: h_fP = 0.75 m, alpha = 30 deg (outside the range ISO 6336 was fitted on).
  print '(a,es11.3,a)', '   ISO 6336-1 c''*b (indicative, h_fP=0.75m):', iso_cprime(16.0_wp, huge(1.0_wp), &
       0.75_wp, 30.0_wp)*b*1e9_wp, ' N/m'

  ! ---------------- 2. convergence in nquad -----------------------------------------------------
  ref = [kb1, ks1, ka1, kb2, ks2, ka2, km]
  print '(/a)', '== Convergence (relative difference to nquad = 64) =='
  print '(a)', '  nquad       k_b1       k_s1       k_a1       k_b2       k_s2       k_a2        k_m' // &
       '    k_m [N/m]'
  do i = 1, size(nq)
    call spline_mesh_stiffness(z, m, alpha, b, e, nu, 14.5e-3_wp, 17.5e-3_wp, 15e-3_wp, nq(i), &
         kh, cur(1), cur(2), cur(3), cur(4), cur(5), cur(6), cur(7), ierr, msg)
    print '(i7,7es11.2,es18.10)', nq(i), abs(cur/ref - 1.0_wp), cur(7)
    call must(all(abs(cur/ref - 1.0_wp) < merge(1e-8_wp, 1e-12_wp, nq(i) < 16)), &
         'not converged (tolerance 1e-8 at nquad = 8, 1e-12 from nquad = 16)')
  end do

  ! ---------------- 3. spur gear of Tian (2004) / Chen & Shao (2011) ----------------------------
  call spur_gear_case()

  ! ---------------- 4. cross-check against Tian's closed-form integrands ------------------------
  call tian_crosscheck(19.0_wp, 3.2e-3_wp, 20*deg, 16e-3_wp, 2.068e11_wp, 0.3_wp)   ! root < r_b
  call tian_crosscheck(48.0_wp, 3.2e-3_wp, 20*deg, 16e-3_wp, 2.068e11_wp, 0.3_wp)   ! root > r_b
  call tian_crosscheck(16.0_wp, 2e-3_wp, 30*deg, 0.03_wp, 2.1e11_wp, 0.3_wp, 14.5e-3_wp)  ! spline

  ! ---------------- 5. rack limit (z -> infinity): trapezoidal cantilever closed form -----------
  call rack_limit()

  ! ---------------- 6. fillet foundation (Sainsot et al. 2004), ROSS and ISO comparisons ------
  call fillet_spline()
  call ross_points('a', 62.0_wp, 2e-3_wp, 20.0_wp, 0.02_wp, 206e9_wp, 0.3_wp, 1.0_wp, 0.25_wp, &
       17.5e-3_wp, [60.5e-3_wp, 62.0e-3_wp, 63.5e-3_wp])
  call ross_points('spline', 16.0_wp, 2e-3_wp, 30.0_wp, 0.03_wp, 2.1e11_wp, 0.3_wp, 0.5_wp, 0.25_wp, &
       7.25e-3_wp, [15.2e-3_wp, 16.0e-3_wp, 16.8e-3_wp])
  call iso_table()

  ! ---------------- 7. error paths --------------------------------------------------------------
  print '(/a)', '== Error reporting ==' 
  call external_tooth_stiffness(2.0_wp, m, alpha, b, 14.5e-3_wp, e, nu, 16e-3_wp, nref, kb1, ks1, ka1, ierr, msg)
  call report_error(ierr, msg)
  call external_tooth_stiffness(z, m, alpha, b, 14.5e-3_wp, e, 0.5_wp, 16e-3_wp, nref, kb1, ks1, ka1, ierr, msg)
  call report_error(ierr, msg)
  call external_tooth_stiffness(z, m, alpha, b, 16.5e-3_wp, e, nu, 16e-3_wp, nref, kb1, ks1, ka1, ierr, msg)
  call report_error(ierr, msg)
  call external_tooth_stiffness(z, m, alpha, b, 14.5e-3_wp, e, nu, 18.5e-3_wp, nref, kb1, ks1, ka1, ierr, msg)
  call report_error(ierr, msg)
  call internal_tooth_stiffness(z, m, alpha, b, 17.5e-3_wp, 13e-3_wp, e, nu, 16e-3_wp, nref, kb2, ks2, ka2, ierr, msg)
  call report_error(ierr, msg)
  call internal_tooth_stiffness(z, m, alpha, b, 17.5e-3_wp, 15e-3_wp, e, nu, 14.9e-3_wp, nref, kb2, ks2, ka2, ierr, msg)
  call report_error(ierr, msg)
  call spline_mesh_stiffness(z, m, 0.0_wp, b, e, nu, 14.5e-3_wp, 17.5e-3_wp, 15e-3_wp, nref, &
       kh, kb1, ks1, ka1, kb2, ks2, ka2, km, ierr, msg)
  call report_error(ierr, msg)
  call fillet_foundation_stiffness(z, m, alpha, b, 14.5e-3_wp, 0.4e-3_wp, 14.5e-3_wp, e, nu, 16e-3_wp, &
       kf1, ierr, msg)                                                    ! bore as large as the root
  call report_error(ierr, msg)
  call fillet_foundation_stiffness(z, m, alpha, b, 14.5e-3_wp, 4e-3_wp, 7e-3_wp, e, nu, 16e-3_wp, &
       kf1, ierr, msg)                                                    ! fillet radius too large
  call report_error(ierr, msg)
  call fillet_foundation_stiffness(z, m, alpha, b, 16.5e-3_wp, 0.4e-3_wp, 7e-3_wp, e, nu, 16e-3_wp, &
       kf1, ierr, msg)                                                    ! root outside the pitch circle
  call report_error(ierr, msg)
  call fillet_foundation_stiffness(z, m, alpha, b, 14.5e-3_wp, 0.4e-3_wp, 7e-3_wp, e, nu, 14.0e-3_wp, &
       kf1, ierr, msg)                                                    ! contact below the root
  call report_error(ierr, msg)
  call fillet_foundation_stiffness_internal(z, m, alpha, b, 17.5e-3_wp, 0.4e-3_wp, 17e-3_wp, e, nu, &
       16e-3_wp, kf2, ierr, msg)                                          ! body inside the root circle
  call report_error(ierr, msg)
  call fillet_foundation_stiffness_internal(z, m, alpha, b, 17.5e-3_wp, -1e-3_wp, 35e-3_wp, e, nu, &
       16e-3_wp, kf2, ierr, msg)                                          ! negative fillet radius
  call report_error(ierr, msg)
  call fillet_foundation_stiffness_internal(z, m, alpha, -b, 17.5e-3_wp, 0.4e-3_wp, 35e-3_wp, e, nu, &
       16e-3_wp, kf2, ierr, msg)                                          ! negative face width
  call report_error(ierr, msg)
  call spline_mesh_stiffness_fillet(z, m, alpha, b, e, nu, 14.5e-3_wp, 17.5e-3_wp, 15e-3_wp, &
       0.4e-3_wp, 0.4e-3_wp, 7.25e-3_wp, 17e-3_wp, .true., nref, kh, kb1, ks1, ka1, kf1, kb2, ks2, &
       ka2, kf2, km, ierr, msg)                                           ! rout2 < rf2
  call report_error(ierr, msg)

  print '(/a,i0)', 'failed checks: ', nfail
  if (nfail > 0) error stop 1

contains

  subroutine must(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    if (.not. ok) then
      nfail = nfail + 1
      print '(a)', '   FAIL: '//what
    end if
  end subroutine must

  subroutine report_error(ierr, msg)
    integer, intent(in) :: ierr
    character(len=*), intent(in) :: msg
    print '(a,i0,a)', '   ierr=', ierr, '  '//trim(msg)
    call must(ierr /= 0 .and. len_trim(msg) > 0, 'bad input not reported')
  end subroutine report_error

  !> Tian (2004) / Chen & Shao (2011) spur gear pair, standard full-depth teeth (root radius
  !> m (z/2 - 1.25)), both teeth loaded at the pitch point.
  subroutine spur_gear_case()
    real(wp) :: kbp, ksp, kap, kbg, ksg, kag, khh, kmm
    real(wp), parameter :: mm = 3.2e-3_wp, aa = 20*deg, bb = 16e-3_wp, ee = 2.068e11_wp, vv = 0.3_wp
    real(wp), parameter :: z1 = 19, z2 = 48
    print '(/a)', '== Spur gear pair of Tian (2004) / Chen & Shao (2011): Z1=19, Z2=48, m=3.2 mm,'
    print '(a)',  '   alpha=20 deg, b=16 mm, E=2.068e11 Pa, nu=0.3, root radius m(z/2-1.25), pitch point =='
    call external_tooth_stiffness(z1, mm, aa, bb, mm*(z1/2 - 1.25_wp), ee, vv, mm*z1/2, nref, &
         kbp, ksp, kap, ierr, msg)
    call must(ierr == 0, trim(msg))
    call external_tooth_stiffness(z2, mm, aa, bb, mm*(z2/2 - 1.25_wp), ee, vv, mm*z2/2, nref, &
         kbg, ksg, kag, ierr, msg)
    call must(ierr == 0, trim(msg))
    khh = hertz_stiffness(ee, vv, bb)
    kmm = 1.0_wp/(1.0_wp/khh + 1.0_wp/kbp + 1.0_wp/ksp + 1.0_wp/kap + 1.0_wp/kbg + 1.0_wp/ksg + 1.0_wp/kag)
    print '(a,3(f8.3,a))', '   pinion: r_f, r_b, r_p = ', mm*(z1/2 - 1.25_wp)*1e3_wp, ', ', &
         mm*z1/2*cos(aa)*1e3_wp, ', ', mm*z1/2*1e3_wp, ' mm (root inside base circle)'
    print '(a,3(f8.3,a))', '   gear:   r_f, r_b, r_p = ', mm*(z2/2 - 1.25_wp)*1e3_wp, ', ', &
         mm*z2/2*cos(aa)*1e3_wp, ', ', mm*z2/2*1e3_wp, ' mm (root outside base circle)'
    print '(a,3es13.5)', '   pinion k_b, k_s, k_a [N/m]: ', kbp, ksp, kap
    print '(a,3es13.5)', '   gear   k_b, k_s, k_a [N/m]: ', kbg, ksg, kag
    print '(a,es13.5)',  '   k_h [N/m]:                   ', khh
    print '(a,es13.5)',  '   single-pair k at pitch [N/m]:', kmm
    print '(a,es13.5)',  '   ISO 6336-1 c''*b (context) :  ', iso_cprime(z1, z2, 1.25_wp, 20.0_wp)*bb*1e9_wp
  end subroutine spur_gear_case

  !> ISO 6336-1:2006 single stiffness c' [N/(mm um)] for x1 = x2 = 0, beta = 0, solid blanks.
  real(wp) function iso_cprime(z1, z2, hfp_over_m, alpha_deg) result(c)
    real(wp), intent(in) :: z1, z2, hfp_over_m, alpha_deg
    real(wp) :: q, cb
    q = 0.04723_wp + 0.15551_wp/z1 + 0.25791_wp/z2
    cb = (1 + 0.5_wp*(1.2_wp - hfp_over_m))*(1 - 0.02_wp*(20 - alpha_deg))
    c = 0.8_wp*cb/q
  end function iso_cprime

  !> Independent evaluation of Tian's (2004) integrals in his angle variable a in [-a1, a_hi]
  !> (a_hi = alpha_2 if the root is inside the base circle, else alpha_2 - t_root), composite
  !> Simpson with 20000 panels, plus the Chen & Shao (2011) straight-segment closed forms.
  subroutine tian_crosscheck(zz, mm, aa, bb, ee, vv, rf_in)
    real(wp), intent(in) :: zz, mm, aa, bb, ee, vv
    real(wp), intent(in), optional :: rf_in
    integer, parameter :: np = 20000
    real(wp) :: rb, rp, rf, a1, a2, ahi, hs, a, wgt, h, d, cb, cs, ca, kb, ks, ka, hb, xb, xr, tol
    integer :: j
    rp = mm*zz/2; rb = rp*cos(aa)
    rf = mm*(zz/2 - 1.25_wp)
    if (present(rf_in)) rf = rf_in
    a2 = pi/(2*zz) + tan(aa) - aa
    a1 = tan(aa) - a2                           ! load angle at the pitch point
    ahi = a2
    if (rf > rb) ahi = a2 - sqrt((rf/rb)**2 - 1)
    hs = (ahi + a1)/np
    cb = 0; cs = 0; ca = 0
    do j = 0, np
      a = -a1 + j*hs
      wgt = merge(1.0_wp, merge(4.0_wp, 2.0_wp, mod(j, 2) == 1), j == 0 .or. j == np)*hs/3
      h = sin(a) + (a2 - a)*cos(a)              ! half thickness / r_b
      d = (a2 - a)*cos(a)                       ! |dx/da| / r_b
      cb = cb + wgt*3*(1 + cos(a1)*((a2 - a)*sin(a) - cos(a)))**2*d/(2*ee*bb*h**3)
      cs = cs + wgt*1.2_wp*(1 + vv)*d*cos(a1)**2/(ee*bb*h)
      ca = ca + wgt*d*sin(a1)**2/(2*ee*bb*h)
    end do
    if (rf < rb) then                           ! Chen & Shao straight segment, closed form
      hb = rb*sin(a2); xb = rb*cos(a2); xr = sqrt(rf**2 - hb**2)
      cb = cb + ((rb - cos(a1)*xr)**3 - (rb - cos(a1)*xb)**3)/(2*ee*bb*cos(a1)*hb**3)
      cs = cs + 1.2_wp*(1 + vv)*cos(a1)**2*(xb - xr)/(ee*bb*hb)
      ca = ca + sin(a1)**2*(xb - xr)/(2*ee*bb*hb)
    end if
    call external_tooth_stiffness(zz, mm, aa, bb, rf, ee, vv, rp, nref, kb, ks, ka, ierr, msg)
    tol = 1e-9_wp
    print '(/a,f5.0,a,f6.2,a,f6.3,a,f6.3,a)', '== Cross-check vs Tian closed-form integrands: z=', zz, &
         ', alpha=', aa/deg, ' deg, r_f=', rf*1e3_wp, ' mm, r_b=', rb*1e3_wp, ' mm =='
    print '(a,3es13.5)', '   Tian/Chen-Shao k_b, k_s, k_a: ', 1/cb, 1/cs, 1/ca
    print '(a,3es13.5)', '   module         k_b, k_s, k_a: ', kb, ks, ka
    print '(a,3es10.2,a,es8.1,a)', '   relative differences: ', kb*cb - 1, ks*cs - 1, ka*ca - 1, &
         '  (tolerance ', tol, ')'
    call must(ierr == 0 .and. abs(kb*cb - 1) < tol .and. abs(ks*cs - 1) < tol .and. &
         abs(ka*ca - 1) < tol, 'Tian cross-check')
  end subroutine tian_crosscheck

  !> z -> infinity: both the external and the internal tooth become the rack tooth, a trapezoid
  !> of half thickness h(d) = pi m / 4 + d tan(alpha) at depth d below the pitch line, loaded at
  !> the pitch line with load angle alpha. Closed form (dx = dh / tan(alpha)):
  !>   1/k_b = 3/(2 E b tan a) [-A^2/(2h^2) - 2 A B/h + B^2 ln h]_{h_c}^{h_f},
  !>           M/F = A + B h, B = cos(a)/tan(a), A = -h_c (cos(a)/tan(a) + sin(a))
  !>   1/k_s = 1.2 cos(a)^2 ln(h_f/h_c) / (2 G b tan a),  1/k_a = sin(a)^2 ln(h_f/h_c) / (2 E b tan a)
  subroutine rack_limit()
    real(wp), parameter :: mm = 2e-3_wp, aa = 30*deg, bb = 0.03_wp, ee = 2.1e11_wp, vv = 0.3_wp
    real(wp) :: hc, hf, ca, cb, cs, gg, aco, bco, ta, kb, ks, ka, zz, dev(3), dev_ext(3, 3), dev_int(3, 3)
    integer :: k
    gg = ee/(2*(1 + vv)); ta = tan(aa)
    hc = pi*mm/4; hf = hc + 1.25_wp*mm*ta
    bco = cos(aa)/ta; aco = -hc*(cos(aa)/ta + sin(aa))
    cb = 3/(2*ee*bb*ta)*(-aco**2/(2*hf**2) - 2*aco*bco/hf + bco**2*log(hf) &
                         + aco**2/(2*hc**2) + 2*aco*bco/hc - bco**2*log(hc))
    cs = 1.2_wp*cos(aa)**2*log(hf/hc)/(2*gg*bb*ta)
    ca = sin(aa)**2*log(hf/hc)/(2*ee*bb*ta)
    print '(/a)', '== Rack limit: trapezoid tooth, m=2 mm, alpha=30 deg, dedendum 1.25 m, b=30 mm =='
    print '(a,3es13.5)', '   closed form        k_b, k_s, k_a: ', 1/cb, 1/cs, 1/ca
    do k = 3, 5
      zz = 10.0_wp**k
      call external_tooth_stiffness(zz, mm, aa, bb, mm*(zz/2 - 1.25_wp), ee, vv, mm*zz/2, nref, &
           kb, ks, ka, ierr, msg)
      dev = [kb*cb, ks*cs, ka*ca] - 1
      print '(a,i1,a,3es13.5,a,3es9.1)', '   external z=1e', k, ' k_b, k_s, k_a: ', kb, ks, ka, '  rel.diff', dev
      dev_ext(:, k - 2) = dev
      call must(ierr == 0, 'external rack tooth: '//trim(msg))
      call internal_tooth_stiffness(zz, mm, aa, bb, mm*(zz/2 + 1.25_wp), mm*(zz/2 - 1), ee, vv, &
           mm*zz/2, nref, kb, ks, ka, ierr, msg)
      dev = [kb*cb, ks*cs, ka*ca] - 1
      print '(a,i1,a,3es13.5,a,3es9.1)', '   internal z=1e', k, ' k_b, k_s, k_a: ', kb, ks, ka, '  rel.diff', dev
      dev_int(:, k - 2) = dev
      call must(ierr == 0, 'internal rack tooth: '//trim(msg))
    end do
    ! the involute tooth differs from the trapezoid by O(m/R) = O(1/z): deviations must fall
    ! tenfold per decade of z and be below 3e-4 at z = 1e5
    print '(a)', '   (checks: |rel.diff| < 3e-4 at z=1e5 and ratio of z=1e4 to z=1e5 deviations in [8, 12])'
    call must(all(abs(dev_ext(:, 3)) < 3e-4_wp) .and. all(abs(dev_int(:, 3)) < 3e-4_wp), &
         'rack limit not reached at z = 1e5')
    call must(all(abs(dev_ext(:, 2)/dev_ext(:, 3) - 10) < 2) .and. &
         all(abs(dev_int(:, 2)/dev_int(:, 3) - 10) < 2), 'rack limit not approached as 1/z')
  end subroutine rack_limit

  !> The spline's fillet-foundation terms (docs/model.md section 11; docs/stiffness.md): ISO 4156 flat
  !> root, fillet radius 0.2 m on both splines, bore r_int = r_root/2 (external), body outer radius
  !> r_out = 2 r_root (internal), pitch point. Checks: fillet = .false. reproduces
  !> spline_mesh_stiffness bit for bit; u_f equals the independent construction x_c - h_c tan(alpha_m)
  !> from the contact point's coordinates; k_f scales as 1/b and as 1/E.
  subroutine fillet_spline()
    real(wp), parameter :: zz = 16, mm = 2e-3_wp, aa = 30*deg, bb = 0.03_wp, ee = 2.1e11_wp, vv = 0.3_wp
    real(wp), parameter :: rf1 = 14.5e-3_wp, rf2 = 17.5e-3_wp, ra2 = 15e-3_wp, rho = 0.2_wp*mm
    real(wp) :: k0(8), k1(10), d1(9), d2(9), kf, kfb, rp, rb, psic, xc, hc, tc, uf_geo, hf
    real(wp), parameter :: hfs(5) = [1.4_wp, 2.0_wp, 3.0_wp, 5.0_wp, 7.0_wp]
    integer :: j
    rp = mm*zz/2; rb = rp*cos(aa)
    call spline_mesh_stiffness(zz, mm, aa, bb, ee, vv, rf1, rf2, ra2, nref, k0(1), k0(2), k0(3), &
         k0(4), k0(5), k0(6), k0(7), k0(8), ierr, msg)
    call spline_mesh_stiffness_fillet(zz, mm, aa, bb, ee, vv, rf1, rf2, ra2, rho, rho, rf1/2, 2*rf2, &
         .false., nref, k1(1), k1(2), k1(3), k1(4), k1(5), k1(6), k1(7), k1(8), k1(9), k1(10), ierr, msg)
    call must(ierr == 0 .and. k1(10) == k0(8) .and. k1(5) == 0 .and. k1(9) == 0, &
         'fillet = .false. must give spline_mesh_stiffness''s k_m bit for bit')
    call spline_mesh_stiffness_fillet(zz, mm, aa, bb, ee, vv, rf1, rf2, ra2, rho, rho, rf1/2, 2*rf2, &
         .true., nref, k1(1), k1(2), k1(3), k1(4), k1(5), k1(6), k1(7), k1(8), k1(9), k1(10), ierr, msg)
    call must(ierr == 0, 'spline_mesh_stiffness_fillet: '//trim(msg))
    call fillet_foundation_stiffness(zz, mm, aa, bb, rf1, rho, rf1/2, ee, vv, rp, kf, ierr, msg, d1)
    call fillet_foundation_stiffness_internal(zz, mm, aa, bb, rf2, rho, 2*rf2, ee, vv, rp, kf, ierr, msg, d2)
    print '(/a)', '== Fillet foundation (Sainsot, Velex & Duverger 2004), spline at the pitch point =='
    print '(a)',  '   ISO 4156 flat root, rho_f = 0.2 m; bore r_int = r_root/2 (ext.), r_out = 2 r_root (int.)'
    print '(a)',  '                 theta_f     h_f     u_f[mm]  S_f[mm]  alpha_m      L       M       P       Q'
    print '(a,f9.5,f8.3,2f9.4,f9.5,4f8.4)', '   external ', d1(1:2), d1(3:4)*1e3_wp, d1(5:9)
    print '(a,f9.5,f8.3,2f9.4,f9.5,4f8.4)', '   internal ', d2(1:2), d2(3:4)*1e3_wp, d2(5:9)
    print '(a,es14.6,a,f7.2,a)', '   k_f1 ', k1(5), ' N/m  (', k1(5)/bb*1e-9_wp, ' N/(mm um) per mm face)'
    print '(a,es14.6,a,f7.2,a)', '   k_f2 ', k1(9), ' N/m  (', k1(9)/bb*1e-9_wp, ' N/(mm um) per mm face)'
    print '(a,es14.6,a,f7.2,a)', '   k_m without k_f ', k0(8), ' N/m  (', k0(8)/bb*1e-9_wp, ' N/(mm um))'
    print '(a,es14.6,a,f7.2,a)', '   k_m with k_f    ', k1(10), ' N/m  (', k1(10)/bb*1e-9_wp, ' N/(mm um))'
    ! u_f from the contact point's own coordinates: the line of action leaves (x_c, h_c) at alpha_m
    tc = sqrt((rp/rb)**2 - 1)
    psic = pi/(2*zz) + tan(aa) - aa - (tc - atan(tc)); xc = rp*cos(psic); hc = rp*sin(psic)
    uf_geo = xc - hc*tan(atan(tc) - psic) - rf1
    psic = pi/(2*zz) - (tan(aa) - aa) + (tc - atan(tc)); xc = rp*cos(psic); hc = rp*sin(psic)
    print '(a,2es10.2,a)', '   u_f vs x_c -/+ h_c tan(alpha_m) (ext., int.): rel.diff', &
         d1(3)/uf_geo - 1, d2(3)/(rf2 - xc - hc*tan(atan(tc) + psic)) - 1, '  (tolerance 1e-12)'
    call must(abs(d1(3)/uf_geo - 1) < 1e-12_wp .and. &
         abs(d2(3)/(rf2 - xc - hc*tan(atan(tc) + psic)) - 1) < 1e-12_wp, 'u_f construction')
    call fillet_foundation_stiffness(zz, mm, aa, 2*bb, rf1, rho, rf1/2, 3*ee, vv, rp, kfb, ierr, msg)
    call must(abs(kfb/(6*k1(5)) - 1) < 1e-14_wp, 'k_f must scale as E b')
    ! spread with the unknown bore / sleeve radius (h_f), both teeth given the same h_f
    print '(a)', '   h_f      k_f1 [N/m]    k_f2 [N/m]   k_m with k_f [N/(mm um)]'
    do j = 1, 5
      hf = hfs(j)
      call spline_mesh_stiffness_fillet(zz, mm, aa, bb, ee, vv, rf1, rf2, ra2, rho, rho, rf1/hf, hf*rf2, &
           .true., nref, k1(1), k1(2), k1(3), k1(4), k1(5), k1(6), k1(7), k1(8), k1(9), k1(10), ierr, msg)
      print '(a,f4.1,2es14.5,f10.2)', '   ', hf, k1(5), k1(9), k1(10)/bb*1e-9_wp
      print '(a,a,f3.1,4(a,es22.15))', '@hf ', 'hf=', hf, ' kf1=', k1(5), ' kf2=', k1(9), ' km=', k1(10), &
           ' b=', bb
    end do
    print '(a,9(a,es22.15))', '@spline_iso4156 ', 'kh=', k0(1), ' kb1=', k0(2), ' ks1=', k0(3), &
         ' ka1=', k0(4), ' kb2=', k0(5), ' ks2=', k0(6), ' ka2=', k0(7), ' km=', k0(8), ' b=', bb
  end subroutine fillet_spline

  !> The numbers tests/test_ross.py compares with ROSS's GearElementTVMS (ross-rotordynamics 2.3):
  !> a gear cut by ROSS's basic rack (addendum ha m, clearance c m, tip radius rho = c m/(1 - sin a)),
  !> at the contact radii rc(:). Printed per point: ours (clamped at the root circle, involute
  !> extended down to it), ours clamped at ROSS's involute start r_s (the involute part alone), our
  !> k_f, and k_f by the same formula with ROSS's conventions (theta_f of Ma et al.,
  !> (pi/2 + 2 tan a (ha - rho/m) + 2 rho/(m cos a))/z, and u_f = y_c - r_f to the contact point).
  subroutine ross_points(name, zz, mm, adeg, bb, ee, vv, ha, cc, rint, rc)
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: zz, mm, adeg, bb, ee, vv, ha, cc, rint, rc(:)
    real(wp) :: aa, rp, rb, rf, rho, rs, kb, ks, ka, kbi, ksi, kai, kf, d(9), tc, psic, am, thm, cf
    integer :: j
    aa = adeg*deg; rp = mm*zz/2; rb = rp*cos(aa); rf = rp - (ha + cc)*mm; rho = cc*mm/(1 - sin(aa))
    rs = sqrt((rb*tan(aa) - ha*mm/sin(aa))**2 + rb**2)
    thm = (pi/2 + 2*tan(aa)*(ha - rho/mm) + 2*rho/(mm*cos(aa)))/zz
    print '(/a,a,a)', '== ROSS comparison points, gear ', name, ' (tests/test_ross.py) =='
    print '(a,a,8(a,es22.15))', '@gear ', name, ' z=', zz, ' m=', mm, ' alpha_deg=', adeg, ' b=', bb, &
         ' e=', ee, ' nu=', vv, ' ha=', ha, ' c=', cc
    print '(a,a,4(a,es22.15))', '@geom ', name, ' r_int=', rint, ' r_root=', rf, ' rho=', rho, ' r_start=', rs
    do j = 1, size(rc)
      call external_tooth_stiffness(zz, mm, aa, bb, rf, ee, vv, rc(j), nref, kb, ks, ka, ierr, msg)
      call must(ierr == 0, trim(msg))
      call external_tooth_stiffness(zz, mm, aa, bb, rs, ee, vv, rc(j), nref, kbi, ksi, kai, ierr, msg)
      call must(ierr == 0, trim(msg))
      call fillet_foundation_stiffness(zz, mm, aa, bb, rf, rho, rint, ee, vv, rc(j), kf, ierr, msg, d)
      call must(ierr == 0, trim(msg))
      tc = sqrt((rc(j)/rb)**2 - 1); psic = pi/(2*zz) + tan(aa) - aa - (tc - atan(tc)); am = atan(tc) - psic
      call sainsot_fillet_compliance(thm, rf/rint, rc(j)*cos(psic) - rf, 2*rf*thm, am, ee, bb, cf)
      print '(a,a,12(a,es22.15))', '@point ', name, ' r=', rc(j), ' kb=', kb, ' ks=', ks, ' ka=', ka, &
           ' kb_inv=', kbi, ' ks_inv=', ksi, ' ka_inv=', kai, ' kf=', kf, ' kf_rossconv=', 1/cf, &
           ' theta_f=', d(1), ' u_f=', d(3), ' alpha_m=', d(5)
      print '(a,f7.3,a,3es11.3,a,es11.3,a,es11.3)', '   r =', rc(j)*1e3_wp, ' mm  k_b, k_s, k_a', kb, ks, ka, &
           '  k_f', kf, '  k_f (ROSS conventions)', 1/cf
    end do
  end subroutine ross_points

  !> docs/stiffness.md table: per-mm single-pair stiffness at the pitch point (both teeth of gear (a)
  !> identical; the spline's ISO 4156 teeth as in fillet_spline) and ISO 6336-1 c'_th, c'.
  subroutine iso_table()
    real(wp), parameter :: mm = 2e-3_wp
    real(wp) :: kb, ks, ka, kf, khh, c0, c1, q
    call external_tooth_stiffness(62.0_wp, mm, 20*deg, 0.02_wp, 59.5e-3_wp, 206e9_wp, 0.3_wp, 62e-3_wp, &
         nref, kb, ks, ka, ierr, msg)
    call fillet_foundation_stiffness(62.0_wp, mm, 20*deg, 0.02_wp, 59.5e-3_wp, 0.38_wp*mm, 17.5e-3_wp, &
         206e9_wp, 0.3_wp, 62e-3_wp, kf, ierr, msg)
    khh = hertz_stiffness(206e9_wp, 0.3_wp, 0.02_wp)
    c0 = 1/(1/khh + 2/kb + 2/ks + 2/ka)/0.02_wp*1e-9_wp
    c1 = 1/(1/khh + 2/kb + 2/ks + 2/ka + 2/kf)/0.02_wp*1e-9_wp
    q = 0.04723_wp + 0.15551_wp/62 + 0.25791_wp/62
    print '(/a)', '== docs/stiffness.md: single pair at the pitch point, N/(mm um) per mm face width =='
    print '(a,4f8.2,a,2f8.2)', '   gear (a) pair: k_b k_s k_a k_f per tooth ', [kb, ks, ka, kf]/0.02_wp*1e-9_wp, &
         ' | total w/o, with k_f', c0, c1
    print '(a,f8.2,a,f8.2)', '   ISO 6336-1: c''_th = 1/q'' =', 1/q, '   c'' = 0.8 C_B c''_th =', &
         iso_cprime(62.0_wp, 62.0_wp, 1.25_wp, 20.0_wp)
    q = 0.04723_wp + 0.15551_wp/16
    print '(a,f8.2,a,f8.2)', '   spline ISO 6336-1 (z2 = inf): c''_th =', 1/q, '   c'' =', &
         iso_cprime(16.0_wp, huge(1.0_wp), 0.75_wp, 30.0_wp)
  end subroutine iso_table

end program stiffness_check
