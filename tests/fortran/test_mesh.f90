!> Module spline_mesh (fortran/physics/mesh.f90) against docs/model.md sections 2-4 (Eqs. 11, 15-17, 19-22):
!> closed forms in full contact (uniform clearance: T_m = r_b Z k_m delta; lateral offset: the
!> isotropic restoring force Z k_m e / 2), zero forces inside the backlash, a tooth-by-tooth
!> recomputation in partial contact, the forces as the gradient of the mesh potential, and the
!> symmetries (point reflection, rotation with the mesh frame, tooth-pass period, face slices).
program test_mesh
  use spline_kinds, only: wp, pi
  use spline_model, only: model_t
  use spline_mesh, only: mesh_eval, mesh_forces, mesh_switch_functions, tooth_approach, &
       eq16_root_mode, eq16_root_directions
  use check, only: check_true, check_close, check_done, default_case_model
  implicit none
  real(wp), parameter :: eps = epsilon(1.0_wp)
  type(model_t) :: md, ms
  real(wp) :: q(7), v(7), fx, fy, tm, fx2, fy2, tm2, c, km, z, d, vel, fj, t, tz, th, scale, h
  real(wp) :: ex, ey, dn(1000), f(1000), g(2000), want_fx, want_fy, gx, gy, gd, gx2
  real(wp) :: dg(2000), gp(2000), gm(2000)
  real(wp) :: phi, s, co, dnj, ddn, delta, sumf
  integer :: ierr, j, k, n_pos, n_neg, modes_k(1000)
  character(len=256) :: msg
  character(len=64) :: tag
  logical :: ok

  call default_case_model(md)
  c = md%c_bulk; km = md%k_m; z = md%z
  call check_true('model: thermal none, c_bulk = c0 = 0.2 mm', md%c_bulk == 2.0e-4_wp)

  ! ---- full contact with uniform clearance (centred shaft): dn_j = D2 for every tooth, so
  !      F_j = k_m (D2 -+ c) + c_m dD2/dt on every tooth (Eqs. 15-17), T_m = r_b Z F_j (Eq. 22),
  !      and F_x1 = -F sum sin(phi_j) = 0, F_y1 = F sum cos(phi_j) = 0
  d = 1.0e-6_wp; vel = 0.01_wp
  do k = 1, 4
    t = (k - 1)*1.3e-4_wp
    q = 0; v = 0
    q(6) = merge(-1.0_wp, 1.0_wp, mod(k, 2) == 1)*(c + d)
    v(6) = merge(vel, -vel, k <= 2)
    call mesh_eval(md, t, q, v, fx, fy, tm, ierr, msg)
    fj = km*sign(d, q(6)) + md%c_m*v(6)
    write(tag, '(a,i0,a)') 'uniform clearance #', k, ':'
    call check_close(trim(tag)//' T_m = r_b Z (k_m delta + c_m dD2/dt)', tm, md%r_b*z*fj, 1.0e-13_wp)
    call check_close(trim(tag)//' F_x1 = 0', fx, 0.0_wp, 0.0_wp, z*z*eps*abs(fj))
    call check_close(trim(tag)//' F_y1 = 0', fy, 0.0_wp, 0.0_wp, z*z*eps*abs(fj))
  end do

  ! ---- inside the backlash (|dn_j| <= |D2| + |e| < c for every tooth): no force, not even damping
  q = 0; v = 0
  q(1) = 0.2_wp*c; q(4) = -0.1_wp*c; q(6) = 0.5_wp*c
  v = [0.1_wp, -0.2_wp, 0.3_wp, 0.05_wp, 1.0_wp, -0.5_wp, 2.0_wp]
  call mesh_eval(md, 2.0e-4_wp, q, v, fx, fy, tm, ierr, msg)
  call check_true('inside the backlash: F_x1 = F_y1 = T_m = 0 exactly', &
       ierr == 0 .and. fx == 0 .and. fy == 0 .and. tm == 0)

  ! ---- full contact with a lateral offset e = (x1 + l_x - x2, y1 + l_y - y2), all teeth on the
  !      back flank, at rest: F_j = k_m (e_x sin - e_y cos + D2 + c) + c_m omega (e_x cos + e_y sin)
  !      (the frame turns, so dn_j changes at rate omega (e_x cos + e_y sin)); with sum sin = sum cos
  !      = sum sin cos = 0 and sum sin^2 = sum cos^2 = Z/2 (Z >= 3): T_m = r_b Z k_m (D2 + c),
  !      F_x1 = -Z/2 (k_m e_x + c_m omega e_y), F_y1 = -Z/2 (k_m e_y - c_m omega e_x)
  ms = md
  ms%l_x = 1.0e-7_wp; ms%l_y = -0.5e-7_wp
  q = 0; v = 0
  q(1) = 1.5e-7_wp; q(2) = 0.5e-7_wp; q(3) = -0.5e-7_wp; q(4) = 1.0e-7_wp
  q(6) = -(c + 1.0e-6_wp)
  ex = q(1) + ms%l_x - q(3); ey = q(2) + ms%l_y - q(4)
  do k = 1, 3
    t = (k - 1)*0.77e-4_wp
    call mesh_eval(ms, t, q, v, fx, fy, tm, ierr, msg, dn=dn)
    write(tag, '(a,es9.2,a)') 'offset, t =', t, ':'
    call check_true(trim(tag)//' every tooth in back-flank contact', all(dn(1:md%z) < -c))
    call check_close(trim(tag)//' T_m = r_b Z k_m (D2 + c)', tm, md%r_b*z*km*(q(6) + c), 1.0e-12_wp)
    call check_close(trim(tag)//' F_x1 = -Z/2 (k_m e_x + c_m omega e_y)', fx, &
         -z*(km*ex + ms%c_m*ms%omega*ey)/2, 1.0e-12_wp)
    call check_close(trim(tag)//' F_y1 = -Z/2 (k_m e_y - c_m omega e_x)', fy, &
         -z*(km*ey - ms%c_m*ms%omega*ex)/2, 1.0e-12_wp)
  end do

  ! ---- partial contact, tooth by tooth from docs/model.md (Eqs. 8-9, 11, 15-17, 22), with
  !      velocities: both flanks and free teeth occur
  ms = md
  ms%l_x = 0.5e-4_wp
  q = [3.0e-4_wp, 1.0e-4_wp, -0.5e-4_wp, 0.2e-4_wp, 1.0e-5_wp, -0.5e-4_wp, 2.0e-5_wp]
  v = [0.02_wp, -0.01_wp, 0.005_wp, 0.03_wp, 0.1_wp, -0.02_wp, 0.05_wp]
  t = 3.1e-4_wp
  call mesh_eval(ms, t, q, v, fx, fy, tm, ierr, msg, dn=dn, f=f)
  ex = q(1) + ms%l_x - q(3); ey = q(2) + ms%l_y - q(4)
  want_fx = 0; want_fy = 0; sumf = 0; scale = 0; n_pos = 0; n_neg = 0; ok = .true.
  do j = 1, md%z
    phi = 2*pi*j/z + ms%omega*t + pi/(2*z) - ms%alpha
    s = sin(phi); co = cos(phi)
    dnj = ex*s - ey*co + q(6)
    ddn = (v(1) - v(3))*s - (v(2) - v(4))*co + v(6) + ms%omega*(ex*co + ey*s)
    delta = 0
    if (dnj > c) delta = dnj - c
    if (dnj < -c) delta = dnj + c
    fj = 0
    if (delta /= 0) fj = km*delta + ms%c_m*ddn
    if (dnj > c) n_pos = n_pos + 1
    if (dnj < -c) n_neg = n_neg + 1
    ok = ok .and. abs(dn(j) - dnj) <= 1.0e-12_wp*c .and. abs(f(j) - fj) <= 1.0e-10_wp*km*c
    want_fx = want_fx - fj*s; want_fy = want_fy + fj*co; sumf = sumf + fj
    scale = scale + abs(fj)
  end do
  call check_true('partial contact: both flanks and free teeth occur', &
       n_pos > 0 .and. n_neg > 0 .and. n_pos + n_neg < md%z)
  call check_true('partial contact: dn_j and F_j of every tooth as recomputed', ok)
  call check_close('partial contact: T_m = r_b sum F_j', tm, ms%r_b*sumf, 0.0_wp, 1.0e-12_wp*ms%r_b*scale)
  call check_close('partial contact: F_x1 = -sum F_j sin(phi_j)', fx, want_fx, 0.0_wp, 1.0e-12_wp*scale)
  call check_close('partial contact: F_y1 = sum F_j cos(phi_j)', fy, want_fy, 0.0_wp, 1.0e-12_wp*scale)
  call mesh_switch_functions(ms, t, q, g)
  call check_true('switch functions g = dn_j -/+ c', all(abs(g(1:2*md%z:2) - (dn(1:md%z) - c)) &
       <= 4*eps*c) .and. all(abs(g(2:2*md%z:2) - (dn(1:md%z) + c)) <= 4*eps*c))
  ! their rates dg/dt with the velocities v: central differences along the motion (q + v dt
  ! at t + dt; the teeth turn with omega)
  h = 1.0e-7_wp
  call mesh_switch_functions(ms, t, q, g, v, dg)
  call mesh_switch_functions(ms, t + h, q + h*v, gp)
  call mesh_switch_functions(ms, t - h, q - h*v, gm)
  call check_true('switch functions: their rates dg/dt', all(abs(dg(1:2*md%z) - &
       (gp(1:2*md%z) - gm(1:2*md%z))/(2*h)) <= 1.0e-7_wp*maxval(abs(dg(1:2*md%z)))))

  ! ---- the forces are the gradient of the mesh potential V = k_m/2 sum delta_j^2 (section 4):
  !      F_x1 = -dV/dx1, F_y1 = -dV/dy1, -F_x1 = -dV/dx2, T_m = r_b dV/dD2 (v = 0; central
  !      differences, exact on each quadratic piece); c_m = 0: the turning frame alone would damp
  v = 0
  ms%c_m = 0
  call mesh_eval(ms, t, q, v, fx, fy, tm, ierr, msg)
  h = 1.0e-9_wp
  gx = dpot(1); gy = dpot(2); gx2 = dpot(3); gd = dpot(6)
  scale = abs(fx) + abs(fy) + abs(tm)/ms%r_b
  call check_close('potential: F_x1 = -dV/dx1', fx, -gx, 0.0_wp, 1.0e-9_wp*scale)
  call check_close('potential: F_y1 = -dV/dy1', fy, -gy, 0.0_wp, 1.0e-9_wp*scale)
  call check_close('potential: -F_x1 = -dV/dx2', -fx, -gx2, 0.0_wp, 1.0e-9_wp*scale)
  call check_close('potential: T_m = r_b dV/dD2', tm, ms%r_b*gd, 0.0_wp, 1.0e-9_wp*ms%r_b*scale)

  ! ---- symmetries, in partial contact with velocities
  v = [0.02_wp, -0.01_wp, 0.005_wp, 0.03_wp, 0.1_wp, -0.02_wp, 0.05_wp]
  ms = md
  call mesh_eval(ms, t, q, v, fx, fy, tm, ierr, msg)
  ! point reflection: q, v -> -q, -v turns every dn_j, its rate and F_j
  call mesh_eval(ms, t, -q, -v, fx2, fy2, tm2, ierr, msg)
  call check_true('reflection q, v -> -q, -v: forces and torque change sign, bit for bit', &
       fx2 == -fx .and. fy2 == -fy .and. tm2 == -tm)
  ! one tooth pitch later the teeth are relabelled: the same sums
  tz = 2*pi/(z*ms%omega)
  call mesh_eval(ms, t + tz, q, v, fx2, fy2, tm2, ierr, msg)
  scale = abs(fx) + abs(fy) + abs(tm)/ms%r_b
  call check_close('tooth-pass period: F_x1', fx2, fx, 0.0_wp, 1.0e-11_wp*scale)
  call check_close('tooth-pass period: F_y1', fy2, fy, 0.0_wp, 1.0e-11_wp*scale)
  call check_close('tooth-pass period: T_m', tm2, tm, 0.0_wp, 1.0e-11_wp*ms%r_b*scale)
  ! isotropy: turning the lateral state by th and the mesh frame by th (t + th/omega) leaves
  ! every dn_j unchanged, turns (F_x1, F_y1) by th and keeps T_m
  th = 0.37_wp
  call mesh_eval(ms, t + th/ms%omega, rot(q), rot(v), fx2, fy2, tm2, ierr, msg)
  call check_close('rotation by 0.37 rad: F_x1 turned', fx2, cos(th)*fx - sin(th)*fy, 0.0_wp, &
       1.0e-11_wp*scale)
  call check_close('rotation by 0.37 rad: F_y1 turned', fy2, sin(th)*fx + cos(th)*fy, 0.0_wp, &
       1.0e-11_wp*scale)
  call check_close('rotation by 0.37 rad: T_m kept', tm2, tm, 0.0_wp, 1.0e-11_wp*ms%r_b*scale)
  ! face slices without angular misalignment: n_s slices of k_m / n_s, c_m / n_s are the tooth
  ms%n_slices = 4
  call mesh_eval(ms, t, q, v, fx2, fy2, tm2, ierr, msg)
  call check_close('4 slices, no tilt: T_m as one slice', tm2, tm, 0.0_wp, 1.0e-14_wp*ms%r_b*scale)
  call check_close('4 slices, no tilt: F_x1 as one slice', fx2, fx, 0.0_wp, 1.0e-14_wp*scale)

  ! ---- the right-hand side's kernel (mesh_forces: Eq. 11 in tooth 1's frame with the model's
  !      tooth offsets, no rotation chain) agrees with mesh_eval to round-off (1e-14 of the sum
  !      of |F_j|, |F_j| c-scaled: the two differ by a few ulp of dn_j) in partial contact (teeth
  !      on both flanks and free), with the contact states decided by the state and frozen (some
  !      frozen states disagreeing with the state), with spacing errors; and Eq. 11 for other
  !      modules (tooth_approach) is mesh_eval's dn_j to the bit
  ms = md
  ms%l_x = 0.7_wp*c; ms%l_y = -0.4_wp*c
  ok = .true.
  do k = 1, 40
    ms%spacing = mod(k, 2) == 0
    ms%spacing_error(1:md%z) = merge(0.05_wp*c*[(sin(3.1_wp*j + k), j = 1, md%z)], &
         [(0.0_wp, j = 1, md%z)], ms%spacing)
    t = 1.0e-4_wp*k
    q = c*[sin(1.3_wp*k), cos(0.7_wp*k), 0.3_wp*sin(2.1_wp*k), -0.2_wp*cos(k + 0.5_wp), &
         10*sin(0.3_wp*k), 1.1_wp*sin(0.9_wp*k), 5*cos(0.4_wp*k)]
    v = 0.01_wp*[cos(1.7_wp*k), sin(0.2_wp*k), sin(k + 1.0_wp), cos(2.3_wp*k), 1.0_wp, &
         sin(1.9_wp*k), -1.0_wp]
    call mesh_eval(ms, t, q, v, fx, fy, tm, ierr, msg, dn=dn, f=f)
    call mesh_forces(ms, t, q, v, fx2, fy2, tm2)
    scale = sum(abs(f(1:md%z)))
    ok = ok .and. same(fx2, fx) .and. same(fy2, fy) .and. same(tm2/ms%r_b, tm/ms%r_b)
    n_pos = count(dn(1:md%z) > c); n_neg = count(dn(1:md%z) < -c)
    modes_k(1:md%z) = [(merge(1, merge(-1, 0, dn(j) < -c), dn(j) > c), j = 1, md%z)]
    modes_k(1:md%z:3) = -modes_k(1:md%z:3)        ! some frozen states off the state's
    call mesh_eval(ms, t, q, v, fx, fy, tm, ierr, msg, mode=modes_k(1:md%z), f=f)
    call mesh_forces(ms, t, q, v, fx2, fy2, tm2, modes_k(1:md%z))
    scale = sum(abs(f(1:md%z)))
    ok = ok .and. same(fx2, fx) .and. same(fy2, fy) .and. same(tm2/ms%r_b, tm/ms%r_b)
    call mesh_eval(ms, t, q, v, fx, fy, tm, ierr, msg, dn=dn, sphi_out=g(1:md%z), &
         cphi_out=g(md%z+1:2*md%z))
    do j = 1, md%z
      call tooth_approach(q(1) + ms%l_x - q(3), q(2) + ms%l_y - q(4), v(1) - v(3), v(2) - v(4), &
           q(6), v(6), ms%omega, ms%spacing_error(j), g(j), g(md%z + j), dnj, ddn)
      ok = ok .and. dnj == dn(j)
    end do
  end do
  call check_true('mesh_forces = mesh_eval to 1e-14 of sum |F_j|, state-decided and frozen '// &
       'contact states, with and without spacing errors; tooth_approach = mesh_eval''s dn_j '// &
       '(40 states)', ok)
  call check_true('those states have teeth on both flanks and free', n_pos > 0 .and. n_neg > 0 &
       .and. n_pos + n_neg < md%z)

  ! the root directions the runs locate are exactly the crossings that change the contact state
  block
    integer :: mode, fn, dir, r(2), dirs(2), every(6)
    logical :: agree
    agree = .true.
    every = eq16_root_directions([-1, 0, 1])    ! three contacts: two root functions each
    do mode = -1, 1
      dirs = every(2*mode + 3:2*mode + 4)
      do fn = 1, 2                        ! g_drive, g_back
        do dir = -1, 1, 2                 ! falling, rising
          r = 0
          r(fn) = dir
          agree = agree .and. ((eq16_root_mode(mode, r(1), r(2)) /= mode) .eqv. &
               (dirs(fn) == 0 .or. dir == dirs(fn)))
        end do
      end do
    end do
    call check_true('Eq. 16 root directions: a crossing changes the contact state (-1, 0, +1) '// &
         'exactly when it is in a direction located (0: either)', agree)
  end block

  call check_done('test_mesh')

contains

  !> Whether got agrees with want to 1e-14 of scale (mesh_forces against mesh_eval).
  logical function same(got, want)
    real(wp), intent(in) :: got, want
    same = abs(got - want) <= 1.0e-14_wp*scale
  end function same

  !> Central difference of V = k_m/2 sum delta_j^2 with respect to q(k), at (ms, t, q).
  real(wp) function dpot(k)
    integer, intent(in) :: k
    real(wp) :: qp(7), qm(7)
    qp = q; qm = q
    qp(k) = q(k) + h; qm(k) = q(k) - h
    dpot = (potential(qp) - potential(qm))/(2*h)
  end function dpot

  real(wp) function potential(qq)
    real(wp), intent(in) :: qq(7)
    real(wp) :: p, dd
    integer :: i
    potential = 0
    do i = 1, md%z
      p = 2*pi*i/z + ms%omega*t + pi/(2*z) - ms%alpha
      dd = (qq(1) + ms%l_x - qq(3))*sin(p) - (qq(2) + ms%l_y - qq(4))*cos(p) + qq(6)
      if (abs(dd) > c) potential = potential + 0.5_wp*km*(abs(dd) - c)**2
    end do
  end function potential

  !> The lateral components of both splines turned by th; D1-D3 kept.
  function rot(x) result(y)
    real(wp), intent(in) :: x(7)
    real(wp) :: y(7)
    y = x
    y(1) = cos(th)*x(1) - sin(th)*x(2); y(2) = sin(th)*x(1) + cos(th)*x(2)
    y(3) = cos(th)*x(3) - sin(th)*x(4); y(4) = sin(th)*x(3) + cos(th)*x(4)
  end function rot

end program test_mesh
