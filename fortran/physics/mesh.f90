!> Tooth-pair contact and mesh forces: relative displacement along each line of action (Eq. 11),
!> dead-zone contact with time-varying backlash (Eqs. 2, 15-17), flash-temperature coupling
!> (Eqs. 1, 3-7, 12-13) and the energy-consistent mesh forces on the bodies (Eqs. 19-22, corrected).
module spline_mesh
  use spline_kinds, only: wp, max_teeth
  use spline_errors, only: err_ok, err_solver, err_thermal, itoa, num
  use spline_model, only: model_t, thermal_oneway, thermal_coupled
  use spline_geometry, only: tooth_angles, tooth_angles_at, tooth1_angle, profile_shift, contact_radius, &
       active_profile
  use spline_thermal, only: thermal_backlash, flash_temperature
  implicit none
  private
  public :: mesh_eval, mesh_forces, mesh_outputs, mesh_switch_functions, coupling_stats_t, tooth_approach
  public :: eq11_gradient, eq16_mode, eq16_root_mode, eq16_root_directions, slice_approach
  public :: start_warning

  integer, parameter :: max_coupling_iter = 60
  real(wp), parameter :: coupling_tol = 1.0e-14_wp   !< relative step tolerance on T_f

  !> How hard the flash-temperature coupling worked over a run (held by the caller's context).
  type :: coupling_stats_t
    real(wp) :: worst_residual = 0.0_wp   !< largest |T - T_f(F(T))| accepted [degC]
    integer :: max_iterations = 0         !< most secant iterations on one tooth
  end type coupling_stats_t

contains

  !> Evaluate the mesh at time t for displacements q and velocities v (SI, layout of Eq. 24).
  !> Returns the generalised mesh forces on spline 1 (F_x1, F_y1) and the meshing torque T_m
  !> (Eq. 22); spline 2 receives the opposites. Optional per-tooth outputs for reporting.
  !> mode (optional): frozen contact state per tooth (+1 drive flank, 0 free, -1 back flank),
  !> used between the located switches; without it the state decides (|dn_j| > c_j, Eq. 16).
  !> flash (optional, default false): compute T_f and the contact radii even when the thermal
  !> level does not feed them back (one-way post-processing and output).
  !> cstats (optional): updated with the work of the flash-temperature coupling.
  !> Angular misalignment (docs/model.md section 11): with n_slices > 1 the face is cut into slices
  !> at z_s; slice s of tooth j has its own dn_js (Eq. 11 with spline 1's centre at
  !> (x1 + l_x + gamma_y z_s, y1 + l_y - gamma_x z_s)), dead zone and force F_js (Eqs. 15-17
  !> with k_m / n_s, c_m / n_s); F_j is their sum; mode then holds the state of every slice
  !> (index (j - 1) n_s + s). fslice(s, j): F_js; mtilt: the tilting moment (M_x, M_y) on spline 1
  !> about the face mid-plane, M_x = -sum z_s F_js cos(phi_j), M_y = -sum z_s F_js sin(phi_j).
  pure subroutine mesh_eval(m, t, q, v, fx1, fy1, tm, ierr, errmsg, mode, flash, dn, c, f, tf, &
       rc1, rc2, sphi_out, cphi_out, cstats, fslice, mtilt)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t, q(7), v(7)
    real(wp), intent(out) :: fx1, fy1, tm
    integer, intent(out) :: ierr
    character(len=*), intent(inout) :: errmsg
    integer, intent(in), optional :: mode(m%z*m%n_slices)
    logical, intent(in), optional :: flash
    real(wp), intent(out), optional, dimension(m%z) :: dn, c, f, tf, rc1, rc2, sphi_out, cphi_out
    type(coupling_stats_t), intent(inout), optional :: cstats
    real(wp), intent(out), optional :: fslice(m%n_slices, m%z), mtilt(2)
    real(wp) :: sp(max_teeth), cp(max_teeth)   ! fixed size: no allocation per call
    real(wp) :: ex, ey, evx, evy, dnj, ddnj, cj, fj, tfj, r1, r2, sumf, resid, zs, dns, ddns, fs
    real(wp) :: mx, my
    integer :: j, mj, iters, is, ns
    logical :: want_flash, coupled

    ierr = err_ok
    call tooth_angles(m%z, m%omega, t, m%theta0, m%alpha, m%sin_pitch, m%cos_pitch, sp, cp)
    ! relative centre offset of spline 1 (misaligned, Section 1) against spline 2
    ex = q(1) + m%l_x - q(3)
    ey = q(2) + m%l_y - q(4)
    evx = v(1) - v(3)
    evy = v(2) - v(4)
    coupled = m%thermal == thermal_coupled
    want_flash = coupled
    if (present(flash)) want_flash = want_flash .or. (flash .and. m%thermal >= thermal_oneway)
    fx1 = 0.0_wp; fy1 = 0.0_wp; sumf = 0.0_wp
    mx = 0.0_wp; my = 0.0_wp
    ns = m%n_slices
    do j = 1, m%z
      ! Eq. 11 and its total time derivative (phi_j' = omega), at the face centre; tooth j of
      ! spline 1 sits e_j ahead along +dn (spacing error, docs/model.md section 11): it meets
      ! the dead zone at dn_j + e_j, the rate is unchanged
      call eq11(ex, ey, evx, evy, q(6), v(6), m%omega, m%spacing_error(j), sp(j), cp(j), &
           dnj, ddnj)
      if (ns > 1) then
        ! slices of the face (angular misalignment; thermal none or bulk: c_j = c_bulk)
        fj = 0.0_wp
        do is = 1, ns
          zs = slice_z(m, is)
          call eq11_sliced(m, zs, sp(j), cp(j), dnj, ddnj, dns, ddns)
          if (present(mode)) then
            mj = mode((j - 1)*ns + is)
          else
            mj = contact_state(dns, m%c_bulk)
          end if
          fs = 0.0_wp
          if (mj /= 0) fs = contact_force(m, dns, ddns, mj, m%c_bulk)/ns
          fj = fj + fs
          mx = mx - zs*fs*cp(j)
          my = my - zs*fs*sp(j)
          if (present(fslice)) fslice(is, j) = fs
        end do
        fx1 = fx1 - fj*sp(j)
        fy1 = fy1 + fj*cp(j)
        sumf = sumf + fj
        if (present(dn)) dn(j) = dnj
        if (present(c)) c(j) = m%c_bulk
        if (present(f)) f(j) = fj
        if (present(tf)) tf(j) = 0.0_wp
        if (present(rc1)) rc1(j) = m%r_pitch
        if (present(rc2)) rc2(j) = m%r_pitch
        cycle
      end if
      if (present(mode)) then
        mj = mode(j)
      else
        mj = contact_state(dnj, m%c_bulk)
      end if
      cj = m%c_bulk
      tfj = 0.0_wp
      r1 = m%r_pitch; r2 = m%r_pitch
      if (want_flash) call contact_radii(m, q, sp(j), cp(j), r1, r2)
      if (mj /= 0) then
        if (coupled) then
          call solve_coupled(m, dnj, ddnj, mj, r1, r2, fj, tfj, iters, resid, ierr)
          if (present(cstats)) then
            cstats%max_iterations = max(cstats%max_iterations, iters)
            cstats%worst_residual = max(cstats%worst_residual, resid)
          end if
          if (ierr /= err_ok) then
            write(errmsg, '(a,i0,a,es12.5,a)') 'case '//trim(m%name)//': thermal interference: '// &
                 'the flash temperature closes the backlash of tooth ', j, ' at t = ', t, &
                 ' s (Eq. 2: c_j <= 0)'
            if (ierr == err_solver) write(errmsg, '(a,i0,a,es12.5,a)') 'case '//trim(m%name)// &
                 ': flash-temperature coupling did not converge on tooth ', j, ' at t = ', t, ' s'
            ierr = err_thermal
            return
          end if
          cj = thermal_backlash(m%c_bulk, m%kappa, tfj)
        else
          fj = contact_force(m, dnj, ddnj, mj, cj)     ! Eqs. 15-17
          if (want_flash) tfj = flash_of(m, fj, r1, r2)
        end if
      else
        fj = 0.0_wp
      end if
      ! Eqs. 19-22 with the tooth's own line-of-action angle (docs/model.md section 4)
      fx1 = fx1 - fj*sp(j)
      fy1 = fy1 + fj*cp(j)
      sumf = sumf + fj
      if (present(dn)) dn(j) = dnj
      if (present(c)) c(j) = cj
      if (present(f)) f(j) = fj
      if (present(tf)) tf(j) = tfj
      if (present(rc1)) rc1(j) = r1
      if (present(rc2)) rc2(j) = r2
      if (present(fslice)) fslice(1, j) = fj
    end do
    tm = m%r_b*sumf
    if (present(sphi_out)) sphi_out = sp(1:m%z)
    if (present(cphi_out)) cphi_out = cp(1:m%z)
    if (present(mtilt)) mtilt = [mx, my]
  end subroutine mesh_eval

  !> start = 'rest' (plus dq0) with a tooth overlapping beyond its backlash at t0: the largest
  !> |dn_j| - c of Eq. 11 (face centre, with the tooth's spacing error e_j) over the teeth in
  !> the start state; one of spline_model::model_warnings (its argument start). It names what
  !> moved the tooth: the misalignment (l_x, l_y, when not both 0), and dq0 (its entries that
  !> enter Eq. 11, and how much it adds to that tooth's |dn_j|) when it moves the tooth.
  subroutine start_warning(m, text)
    type(model_t), intent(in) :: m
    character(len=:), allocatable, intent(out) :: text
    character(len=:), allocatable :: cause, kick
    character(len=2), parameter :: dof(5) = ['x1', 'y1', 'x2', 'y2', 'D2']
    real(wp) :: sp(m%z), cp(m%z), dn(m%z), dn0(m%z), ddn(m%z), q(5), added
    integer :: j, i
    text = ''
    if (m%start_equilibrium) return
    call tooth_angles(m%z, m%omega, m%t0, m%theta0, m%alpha, m%sin_pitch, m%cos_pitch, sp, cp)
    call eq11(m%dq0(1) + m%l_x - m%dq0(3), m%dq0(2) + m%l_y - m%dq0(4), 0.0_wp, 0.0_wp, m%dq0(6), &
         0.0_wp, 0.0_wp, m%spacing_error(1:m%z), sp, cp, dn, ddn)
    call eq11(m%l_x, m%l_y, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, m%spacing_error(1:m%z), sp, &
         cp, dn0, ddn)                     ! without dq0
    dn = abs(dn)
    j = maxloc(dn, 1)
    if (dn(j) <= m%c_bulk) return
    cause = 'l_x = '//num(m%l_x, readable=.true.)//', l_y = '//num(m%l_y, readable=.true.)//' m'
    added = dn(j) - abs(dn0(j))
    if (added /= 0.0_wp) then
      q = m%dq0([1, 2, 3, 4, 6])
      kick = ''
      do i = 1, size(q)
        if (q(i) /= 0.0_wp) kick = kick//', '//dof(i)//' = '//num(q(i), readable=.true.)
      end do
      kick = 'dq0 ('//kick(3:)//' m, adding '//num(added, readable=.true.)//' m to its |dn_j|)'
      if (m%l_x == 0.0_wp .and. m%l_y == 0.0_wp) then
        cause = kick
      else
        cause = cause//' and '//kick
      end if
    end if
    text = 'case '//trim(m%name)//': start = ''rest'' with '//cause// &
         ' starts tooth '//itoa(j)//' overlapping its backlash c = '// &
         num(m%c_bulk, readable=.true.)//' m by '//num(dn(j) - m%c_bulk, readable=.true.)// &
         ' m (Eq. 11 at t0): an impact made by the start, not the drive; '// &
         'start = ''equilibrium''? Run as given'//new_line('a')
  end subroutine start_warning

  !> Eq. 11 and its total time derivative (phi_j' = omega) for one tooth at the face centre, the
  !> one place they are written (right-hand side, switch functions, outputs, loads): the tooth's
  !> angle (sp, cp) = (sin, cos) phi_j, the relative centre offset (ex, ey) of spline 1 against
  !> spline 2 and its rate (evx, evy), D2 = q6 and its rate v6. Tooth j of spline 1 sits e_j ahead
  !> along +dn (spacing error e, docs/model.md section 11): it meets the dead zone at dn_j + e_j,
  !> the rate is unchanged.
  !> For callers in other modules; this module calls eq11, which the compiler inlines (a public
  !> procedure of a position-independent library may be interposed, so it is not inlined).
  elemental subroutine tooth_approach(ex, ey, evx, evy, q6, v6, omega, e, sp, cp, dn, ddn)
    real(wp), intent(in) :: ex, ey, evx, evy, q6, v6, omega, e, sp, cp
    real(wp), intent(out) :: dn, ddn
    call eq11(ex, ey, evx, evy, q6, v6, omega, e, sp, cp, dn, ddn)
  end subroutine tooth_approach

  elemental subroutine eq11(ex, ey, evx, evy, q6, v6, omega, e, sp, cp, dn, ddn)
    real(wp), intent(in) :: ex, ey, evx, evy, q6, v6, omega, e, sp, cp
    real(wp), intent(out) :: dn, ddn
    dn = ex*sp - ey*cp + q6 + e
    ddn = evx*sp - evy*cp + v6 + omega*(ex*cp + ey*sp)
  end subroutine eq11

  !> The gradient of Eq. 11 in the displacements q (layout of Eq. 24) for tooth angle phi_j
  !> (sp, cp: its sine and cosine): u = d(dn_j)/dq = d(d(dn_j)/dt)/dv = (sin, -cos, -sin, cos,
  !> 0, 1, 0); w (optional) = (cos, sin, -cos, -sin, 0, 0, 0), d(d(dn_j)/dt)/dq = omega w.
  pure subroutine eq11_gradient(sp, cp, u, w)
    real(wp), intent(in) :: sp, cp
    real(wp), intent(out) :: u(7)
    real(wp), intent(out), optional :: w(7)
    u = [sp, -cp, -sp, cp, 0.0_wp, 1.0_wp, 0.0_wp]
    if (present(w)) w = [cp, sp, -cp, -sp, 0.0_wp, 0.0_wp, 0.0_wp]
  end subroutine eq11_gradient

  !> The right-hand side's mesh kernel: mesh_eval's F_x1, F_y1 and T_m to round-off (a few ulp of
  !> dn_j; tests/fortran/test_mesh.f90), for a model without face slices or coupled flash
  !> temperature (the teeth's backlash is c_bulk; at the one-way level T_f does not act back).
  !> Eq. 11 in tooth 1's frame with the model's tooth offsets (no rotation chain from tooth to
  !> tooth), Eqs. 15-17 without a branch, so that the compiler vectorises the pass over the
  !> teeth, then the sums of Eqs. 19-22. mode: as mesh_eval's.
  pure subroutine mesh_forces(m, t, q, v, fx1, fy1, tm, mode)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t, q(7), v(7)
    real(wp), intent(out) :: fx1, fy1, tm
    integer, intent(in), optional :: mode(m%z)
    real(wp) :: s, c, phi, ex, ey, evx, evy, cb, km, cm, a, b, va, vb, sfc, sfs, sumf, q6, v6
    real(wp) :: dnj, ddnj, fs(max_teeth)    ! fixed size: no allocation per call
    integer :: j, z
    phi = tooth1_angle(m%z, m%omega, t, m%theta0, m%alpha)
    s = sin(phi)
    c = cos(phi)
    cb = m%c_bulk; km = m%k_m; cm = m%c_m
    ex = q(1) + m%l_x - q(3)
    ey = q(2) + m%l_y - q(4)
    evx = v(1) - v(3)
    evy = v(2) - v(4)
    ! Eq. 11 in tooth 1's frame: dn_j = a cos(o_j) + b sin(o_j) + q6 + e_j,
    ! ddn_j = va cos(o_j) + vb sin(o_j) + v6, o_j = (j - 1) 2 pi / Z (the model's offsets)
    a = ex*s - ey*c
    b = ex*c + ey*s
    va = evx*s - evy*c + m%omega*b
    vb = evx*c + evy*s - m%omega*a
    ! Eqs. 15-17 without a branch: in contact (|dn_j| > c_bulk, Eq. 16, or the frozen state
    ! mode(j) /= 0) F_j = k_m (dn_j - sign(c_bulk, dn_j)) + c_m d(dn_j)/dt, else 0
    z = m%z
    q6 = q(6); v6 = v(6)
    if (present(mode)) then
      do j = 1, z
        dnj = a*m%cos_offset(j) + b*m%sin_offset(j) + q6 + m%spacing_error(j)
        ddnj = va*m%cos_offset(j) + vb*m%sin_offset(j) + v6
        fs(j) = abs(real(mode(j), wp))*(km*(dnj - mode(j)*cb) + cm*ddnj)
      end do
    else
      do j = 1, z     ! 0.5 - sign(0.5, c_bulk - |dn_j|): 1 where |dn_j| > c_bulk, else 0
        dnj = a*m%cos_offset(j) + b*m%sin_offset(j) + q6 + m%spacing_error(j)
        ddnj = va*m%cos_offset(j) + vb*m%sin_offset(j) + v6
        fs(j) = (0.5_wp - sign(0.5_wp, cb - abs(dnj)))*(km*(dnj - sign(cb, dnj)) + cm*ddnj)
      end do
    end if
    sfc = 0.0_wp; sfs = 0.0_wp; sumf = 0.0_wp
    do j = 1, z
      sfc = sfc + fs(j)*m%cos_offset(j)
      sfs = sfs + fs(j)*m%sin_offset(j)
      sumf = sumf + fs(j)
    end do
    ! Eqs. 19-22 in tooth 1's frame: sum F_j sin(phi_j) = s sfc + c sfs,
    ! sum F_j cos(phi_j) = c sfc - s sfs
    fx1 = -(s*sfc + c*sfs)
    fy1 = c*sfc - s*sfs
    tm = m%r_b*sumf
  end subroutine mesh_forces

  !> F_j, F_jx, F_jy and dn_j at nt output times (t(k), SI states y(:, k), contact states
  !> modes(:, k), 2: decided by the state) and T_m, for a model without flash temperature or face
  !> slices: Eqs. 8-9, 11, 15-17 and 19-22 as tooth_angles and mesh_eval evaluate them,
  !> operation for operation (run.f90's tooth_outputs checks the first and last output against
  !> mesh_eval), in blocks of nblk outputs, one pass per tooth (f(k, j) is contiguous in k;
  !> tooth_angles_at: the block's angles at once). finite: whether every
  !> value written to f, fx, fy and dn is finite (x*0 is 0 for a finite x, NaN otherwise),
  !> formed while they are in registers, so the run's checks need not read them again: from F
  !> and dn alone, since F_x and F_y are F times a sine or cosine of |.| <= 1 that dn also
  !> multiplies (a non-finite angle makes dn NaN).
  pure subroutine mesh_outputs(m, nt, t, y, modes, f, fx, fy, dn, tm, finite)
    type(model_t), intent(in) :: m
    integer, intent(in) :: nt
    real(wp), intent(in) :: t(nt), y(:, :)
    integer, intent(in) :: modes(:, :)
    real(wp), intent(out), dimension(nt, m%z) :: f, fx, fy, dn
    real(wp), intent(out) :: tm(nt)
    logical, intent(out) :: finite
    integer, parameter :: nblk = 64
    real(wp) :: sp(nblk, m%z), cp(nblk, m%z)
    real(wp), dimension(nblk) :: ex, ey, evx, evy, q6, v6, sumf, fin
    real(wp) :: dnj, ddnj, fj, fxj, fyj, cb, km, cm, om
    integer :: k0, nk, i, j, k, mi
    cb = m%c_bulk; km = m%k_m; cm = m%c_m; om = m%omega
    fin = 0.0_wp
    do k0 = 0, nt - 1, nblk
      nk = min(nblk, nt - k0)
      call tooth_angles_at(m%z, nk, nblk, m%omega, t(k0+1:k0+nk), m%theta0, m%alpha, &
           m%sin_pitch, m%cos_pitch, sp, cp)
      do i = 1, nk
        k = k0 + i
        ex(i) = y(1, k) + m%l_x - y(3, k)
        ey(i) = y(2, k) + m%l_y - y(4, k)
        evx(i) = y(8, k) - y(10, k)
        evy(i) = y(9, k) - y(11, k)
        q6(i) = y(6, k)
        v6(i) = y(13, k)
      end do
      sumf = 0.0_wp
      do j = 1, m%z    ! scalar: a branch-free form the compiler vectorises measured slower
        do i = 1, nk
          k = k0 + i
          call eq11(ex(i), ey(i), evx(i), evy(i), q6(i), v6(i), om, m%spacing_error(j), &
               sp(i, j), cp(i, j), dnj, ddnj)
          mi = modes(j, k)
          if (mi == 2) mi = contact_state(dnj, cb)
          fj = merge(km*(dnj - merge(cb, -cb, mi > 0)) + cm*ddnj, 0.0_wp, mi /= 0)
          fxj = fj*sp(i, j)
          fyj = fj*cp(i, j)
          f(k, j) = fj
          fx(k, j) = fxj
          fy(k, j) = fyj
          dn(k, j) = dnj
          sumf(i) = sumf(i) + fj
          fin(i) = fin(i) + (dnj*0.0_wp + fj*0.0_wp)
        end do
      end do
      tm(k0+1:k0+nk) = m%r_b*sumf(1:nk)
    end do
    finite = all(fin == 0.0_wp)
  end subroutine mesh_outputs

  !> Eq. 16: contact state of a tooth pair, +1 drive flank (dn > c), -1 back flank (dn < -c),
  !> 0 free: eq16_mode of its switch functions (dn - c > 0 exactly when dn > c), by eq16, which
  !> the compiler inlines (tooth_approach says why: eq16_mode was a call at every output and tooth).
  pure integer function contact_state(dn, c)
    real(wp), intent(in) :: dn, c
    contact_state = eq16(dn - c, dn + c)
  end function contact_state

  !> Eqs. 15-17: tooth force in contact state mode (+-1): k_m (dn -+ c) + c_m d(dn)/dt.
  pure real(wp) function contact_force(m, dn, ddn, mode, c) result(f)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: dn, ddn, c
    integer, intent(in) :: mode
    f = m%k_m*(dn - mode*c) + m%c_m*ddn
  end function contact_force

  !> Eqs. 12-13: contact-point radii of tooth pair (sp, cp) on spline 1 (misaligned centre) and 2.
  !> One point per pair (docs/model.md section 6): the pair's pitch point, measured from each
  !> spline's shifted centre by the same formula (Eq. 13), held on the active profile. Both radii
  !> are continuous in the state; r1 = r2 whenever Delta_1 = Delta_2 (no sliding).
  pure subroutine contact_radii(m, q, sp, cp, r1, r2)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: q(7), sp, cp
    real(wp), intent(out) :: r1, r2
    real(wp) :: r_lo, r_hi
    call active_profile(m%z, m%m_n, r_lo, r_hi)
    r1 = contact_radius(profile_shift(q(1) + m%l_x, q(2) + m%l_y, sp, cp), m%r_pitch, &
         m%cos_alpha, r_lo, r_hi)
    r2 = contact_radius(profile_shift(q(3), q(4), sp, cp), m%r_pitch, m%cos_alpha, r_lo, r_hi)
  end subroutine contact_radii

  !> Eqs. 3-7 for one tooth with the model's material data.
  pure real(wp) function flash_of(m, f, r1, r2) result(tf)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: f, r1, r2
    real(wp) :: bh
    call flash_temperature(f, r1, r2, m%r_b, m%cos_alpha, m%omega, m%b, m%e_mod, m%nu, m%eta_hertz, &
         m%u_flash, m%f_m, m%k_cond, m%rho, m%c_heat, tf, bh)
  end function flash_of

  !> Eqs. 1, 2, 15-17 and 3-7 together: the tooth force F depends on itself through
  !> T_f(F) -> c(T_f) -> F. Unknown: the flash temperature T; residual
  !>   g(T) = T - T_f(F(T)),  F(T) = k_m (dn - mode (c_bulk - kappa T)) + c_m d(dn)/dt.
  !> Secant iteration from T = 0 and T = T_f(F(0)); it stops when a step is below
  !> 1e-14 (1 + T) degC. The map T -> T_f(F(T)) contracts by about k_m kappa dT_f/dF (~1e-3 for the
  !> paper's k_m), so 3-5 iterations reach round-off. ierr = err_thermal: backlash closed; err_solver: no convergence.
  !> Eqs. 3-4 make T_f a power of the load at a given contact point: f_e / sqrt(B) ~ f_e^(3/4), so
  !> T_f(F) = T_f(1 N) |F|^(3/4). Eqs. 3-7 are evaluated once per tooth, each iteration costs two sqrt.
  !> iters, resid: the secant iterations taken and the residual |g| accepted.
  pure subroutine solve_coupled(m, dn, ddn, mode, r1, r2, f, t, iters, resid, ierr)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: dn, ddn, r1, r2
    integer, intent(in) :: mode
    real(wp), intent(out) :: f, t, resid
    integer, intent(out) :: iters, ierr
    real(wp) :: ta, ga, tb, gb, tn, tf_unit, tfb
    integer :: k
    ierr = err_ok
    iters = 0
    resid = 0.0_wp
    tf_unit = flash_of(m, 1.0_wp, r1, r2)
    ta = 0.0_wp
    ga = -tf_at(ta)             ! the backlash at T = 0 (the bulk level) is open: c_bulk > 0
    tb = -ga
    t = ta
    if (ga /= 0.0_wp) then
      tfb = tf_at(tb)
      if (tfb < 0.0_wp) then
        ierr = err_thermal; return
      end if
      gb = tb - tfb
      do k = 1, max_coupling_iter
        if (gb == 0.0_wp .or. gb == ga) exit
        tn = tb - gb*(tb - ta)/(gb - ga)
        ta = tb; ga = gb
        tb = tn
        tfb = tf_at(tb)
        if (tfb < 0.0_wp) then
          ierr = err_thermal; return
        end if
        gb = tb - tfb
        if (abs(tb - ta) <= coupling_tol*(1.0_wp + abs(tb))) exit
      end do
      if (k > max_coupling_iter) then
        ierr = err_solver; return
      end if
      iters = k
      resid = abs(gb)
      t = tb
    end if
    if (thermal_backlash(m%c_bulk, m%kappa, t) <= 0.0_wp) then
      ierr = err_thermal; return
    end if
    f = contact_force(m, dn, ddn, mode, thermal_backlash(m%c_bulk, m%kappa, t))
  contains
    !> T_f(F(T)) >= 0, or -1 where the backlash at T is closed.
    pure real(wp) function tf_at(tt)
      real(wp), intent(in) :: tt
      real(wp) :: cc, q
      cc = thermal_backlash(m%c_bulk, m%kappa, tt)
      tf_at = -1.0_wp
      if (cc <= 0.0_wp) return
      q = sqrt(sqrt(abs(contact_force(m, dn, ddn, mode, cc))))
      tf_at = tf_unit*q*q*q
    end function tf_at
  end subroutine solve_coupled

  !> Root functions for the contact switches of Eq. 16: g_{2k-1} = dn_k - c_k, g_{2k} = dn_k + c_k
  !> for every contact k (a tooth, or slice s of tooth j: k = (j - 1) n_s + s), with the backlash
  !> at the bulk temperature, which decides the contact state; dn_k includes the tooth's spacing
  !> error e_j (|dn_j + e_j| = c_j, docs/model.md section 11). With the velocities v (optional),
  !> dg their rates dg/dt (both d(dn_k)/dt, Eq. 11's rate).
  pure subroutine mesh_switch_functions(m, t, q, g, v, dg)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t, q(7)
    real(wp), intent(out) :: g(2*m%z*m%n_slices)
    real(wp), intent(in), optional :: v(7)
    real(wp), intent(out), optional :: dg(2*m%z*m%n_slices)
    real(wp) :: sp(max_teeth), cp(max_teeth), ex, ey, dnj, ddnj, dns, ddns, vv(7), w
    integer :: j, is, k, ns
    call tooth_angles(m%z, m%omega, t, m%theta0, m%alpha, m%sin_pitch, m%cos_pitch, sp, cp)
    ex = q(1) + m%l_x - q(3)
    ey = q(2) + m%l_y - q(4)
    ns = m%n_slices
    vv = 0.0_wp
    w = 0.0_wp                                    ! the rate only with v
    if (present(v)) then
      vv = v
      w = m%omega
    end if
    do j = 1, m%z
      call eq11(ex, ey, vv(1) - vv(3), vv(2) - vv(4), q(6), vv(6), w, m%spacing_error(j), &
           sp(j), cp(j), dnj, ddnj)              ! Eq. 11 and its rate
      if (ns == 1) then
        g(2*j - 1) = dnj - m%c_bulk
        g(2*j) = dnj + m%c_bulk
        if (present(dg)) dg(2*j - 1:2*j) = ddnj
      else
        do is = 1, ns
          call eq11_sliced(m, slice_z(m, is), sp(j), cp(j), dnj, ddnj, dns, ddns)
          k = (j - 1)*ns + is
          g(2*k - 1) = dns - m%c_bulk
          g(2*k) = dns + m%c_bulk
          if (present(dg)) dg(2*k - 1:2*k) = ddns
        end do
      end if
    end do
  end subroutine mesh_switch_functions

  !> Eq. 11 and its rate for slice is of the n_s of the face of tooth j (docs/model.md section
  !> 11), from the tooth's at the face centre (dn, ddn: eq11's): the angular misalignment
  !> (gamma_x, gamma_y) of spline 1 moves the slice at axial position z_s by
  !> z_s (gamma_y sin phi_j + gamma_x cos phi_j) along the line of action. For other modules;
  !> this one calls eq11_sliced and slice_z, inlined (tooth_approach says why).
  elemental subroutine slice_approach(m, is, sp, cp, dn, ddn, dns, ddns)
    type(model_t), intent(in) :: m
    integer, intent(in) :: is
    real(wp), intent(in) :: sp, cp, dn, ddn
    real(wp), intent(out) :: dns, ddns
    call eq11_sliced(m, slice_z(m, is), sp, cp, dn, ddn, dns, ddns)
  end subroutine slice_approach

  !> Eq. 11 and its rate at axial position zs of the face (slice_approach's, given z_s): the
  !> one place the slice term is written (mesh_eval, mesh_switch_functions, slice_approach).
  elemental subroutine eq11_sliced(m, zs, sp, cp, dn, ddn, dns, ddns)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: zs, sp, cp, dn, ddn
    real(wp), intent(out) :: dns, ddns
    dns = dn + zs*(m%gamma_y*sp + m%gamma_x*cp)
    ddns = ddn + m%omega*zs*(m%gamma_y*cp - m%gamma_x*sp)
  end subroutine eq11_sliced

  !> The axial position of slice is of the n_s of the face, from its mid-plane:
  !> z_s = b ((s - 1/2) / n_s - 1/2).
  elemental real(wp) function slice_z(m, is) result(zs)
    type(model_t), intent(in) :: m
    integer, intent(in) :: is
    zs = m%b*((is - 0.5_wp)/m%n_slices - 0.5_wp)
  end function slice_z

  !> The contact state of Eq. 16 from a contact's switch functions (mesh_switch_functions):
  !> +1 drive flank (g_drive = dn - c > 0), -1 back flank (g_back = dn + c < 0), else 0 free.
  !> For callers in other modules; this module calls eq16, inlined (tooth_approach says why).
  elemental integer function eq16_mode(g_drive, g_back) result(mode)
    real(wp), intent(in) :: g_drive, g_back
    mode = eq16(g_drive, g_back)
  end function eq16_mode

  elemental integer function eq16(g_drive, g_back) result(mode)
    real(wp), intent(in) :: g_drive, g_back
    mode = 0
    if (g_drive > 0.0_wp) mode = 1
    if (g_back < 0.0_wp) mode = -1
  end function eq16

  !> The contact state of Eq. 16 after a located root of a contact's switch functions (root
  !> directions as SUNDIALS reports them, 0: no root): g_drive rising, the drive flank engages
  !> (+1), falling, it opens (0); g_back falling, the back flank engages (-1), rising, it opens
  !> (0); mode: the state before.
  elemental integer function eq16_root_mode(mode, root_drive, root_back) result(new)
    integer, intent(in) :: mode, root_drive, root_back
    new = mode
    if (root_drive == 1) new = 1
    if (root_drive == -1) new = 0
    if (root_back == -1) new = -1
    if (root_back == 1) new = 0
  end function eq16_root_mode

  !> The crossing directions of the switch functions (g_drive, g_back) of each contact that
  !> change its contact state modes(j) by eq16_root_mode, as SUNDIALS' root directions (+1
  !> rising, -1 falling, 0 either), in the root functions' order (dirs(2j-1:2j) for contact j):
  !> free (0), g_drive rising and g_back falling; on the drive flank (+1), g_drive falling,
  !> g_back either; on the back flank (-1), g_back rising, g_drive either. The other way (a free
  !> tooth's g_drive falling, say) leaves the state as it is. Without these directions such a
  !> crossing, at round-off level on a grazing tooth (g exactly 0 at the restart, then +-1e-20
  !> m), was located, changed no state and restarted CVODE, whose search found it again within
  !> its root tolerance: restarts without end at one instant, each cutting the first step
  !> tenfold, until the step fell below round-off (the Z16 drive of tests/test_cont_drives.py,
  !> ripple 0.13 at 2488.47 r/min: CV_ILL_INPUT, "tout too far back"). The state run (each of
  !> its copies) and the variational run set them from their contact states.
  pure function eq16_root_directions(modes) result(dirs)
    integer, intent(in) :: modes(:)
    integer :: dirs(2*size(modes))
    integer :: j
    do j = 1, size(modes)
      select case (modes(j))
      case (1)
        dirs(2*j - 1:2*j) = [-1, 0]
      case (-1)
        dirs(2*j - 1:2*j) = [0, 1]
      case default
        dirs(2*j - 1:2*j) = [1, -1]
      end select
    end do
  end function eq16_root_directions

end module spline_mesh
