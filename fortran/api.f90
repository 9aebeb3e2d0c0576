!> The thin interface that f2py wraps: flat arrays in C kinds, sizes passed in, and an error
!> code with a message (0 = ok; 1 bad case, 2 solver, 3 thermal interference). A case is given
!> as the path of a namelist file. State vectors have nstate = 14 entries, written as a literal
!> in the dummy arguments because f2py cannot see imported parameters.
!> Nothing here computes physics: it reads the case and calls the modules.
module spline_api
  use, intrinsic :: iso_c_binding, only: c_double, c_int
  use spline_kinds, only: wp
  use spline_case_io, only: model_t, case_read_file, case_write_defaults, nstate, ndof, nkterms, &
       thermal_coupled
  use spline_mesh, only: mesh_switch_functions
  use spline_stiffness, only: external_tooth_stiffness, internal_tooth_stiffness
  use spline_dynamics, only: accelerations, start_state, rhs_scaled, to_scaled
  use spline_run, only: nstats, stat_names, run_case, tooth_quantities, ntooth_q, tooth_q_names, tooth_q_units
  implicit none
  private
  public :: api_sizes, api_simulate, api_rhs, api_start_state, api_write_defaults, api_names
  public :: api_mesh_stiffness, api_tooth_stiffness, api_load, api_rhs_loaded, api_time_rhs

  type(model_t), save :: loaded          !< the case of api_load, for api_rhs_loaded
  logical, save :: have_loaded = .false.

contains

  !> Number of teeth and of output times of a case (to size the arrays of api_simulate).
  subroutine api_sizes(path, z, nt, nq, ns, ierr, errmsg)
    character(len=*), intent(in) :: path
    integer(c_int), intent(out) :: z, nt, nq, ns, ierr
    character(len=512), intent(out) :: errmsg
    type(model_t) :: m
    integer :: ie
    call case_read_file(path, m, ie, errmsg)
    ierr = ie
    z = m%z; nt = m%n_out; nq = ntooth_q; ns = nstats
  end subroutine api_sizes

  !> Simulate a case: output times t, SI states y (nt x 14), per-tooth quantities tooth
  !> (nt x z x nq, order of api_names('tooth')), meshing torque tm and solver statistics.
  subroutine api_simulate(path, z, nt, nq, ns, t, y, tooth, tm, stats, ierr, errmsg)
    character(len=*), intent(in) :: path
    integer(c_int), intent(in) :: z, nt, nq, ns
    real(c_double), intent(out) :: t(nt), y(nt, 14), tooth(nt, z, nq), tm(nt), stats(ns)
    integer(c_int), intent(out) :: ierr
    character(len=512), intent(out) :: errmsg
    type(model_t) :: m
    real(wp), allocatable :: ycol(:, :)
    integer :: ie
    t = 0; y = 0; tooth = 0; tm = 0; stats = 0
    call case_read_file(path, m, ie, errmsg)
    if (ie == 0 .and. (m%z /= z .or. m%n_out /= nt .or. nq /= ntooth_q .or. ns /= nstats)) then
      ie = 1
      errmsg = 'api_simulate: array sizes do not match the case (call api_sizes first)'
    end if
    if (ie == 0) then
      allocate(ycol(nstate, nt))
      call run_case(m, t, ycol, tooth, tm, stats, ie, errmsg)
      y = transpose(ycol)
    end if
    ierr = ie
  end subroutine api_simulate

  !> Right-hand side in SI units at (t, y) with the contact states decided by the state, plus
  !> the mesh: per-tooth mesh(:, k) in the order of api_names('tooth') and the torque tm.
  !> Exposed so that tests can hold it against the independent numpy oracle.
  subroutine api_rhs(path, z, nq, t, y, ydot, mesh, tm, ierr, errmsg)
    character(len=*), intent(in) :: path
    integer(c_int), intent(in) :: z, nq
    real(c_double), intent(in) :: t, y(14)
    real(c_double), intent(out) :: ydot(14), mesh(z, nq), tm
    integer(c_int), intent(out) :: ierr
    character(len=512), intent(out) :: errmsg
    type(model_t) :: m
    integer :: ie
    ydot = 0; mesh = 0; tm = 0
    call case_read_file(path, m, ie, errmsg)
    if (ie == 0 .and. (m%z /= z .or. nq /= ntooth_q)) then
      ie = 1; errmsg = 'api_rhs: array sizes do not match the case'
    end if
    if (ie == 0) then
      ydot(1:ndof) = y(ndof+1:)
      call accelerations(m, t, y(1:ndof), y(ndof+1:), ydot(ndof+1:), ie, errmsg)
    end if
    if (ie == 0) call tooth_quantities(m, t, y, mesh, tm, ie, errmsg)
    ierr = ie
  end subroutine api_rhs

  !> Read a case once and keep it for api_rhs_loaded (peers calling the RHS per step).
  subroutine api_load(path, ierr, errmsg)
    character(len=*), intent(in) :: path
    integer(c_int), intent(out) :: ierr
    character(len=512), intent(out) :: errmsg
    integer :: ie
    call case_read_file(path, loaded, ie, errmsg)
    have_loaded = ie == 0
    ierr = ie
  end subroutine api_load

  !> SI right-hand side of the case loaded by api_load (contact states from the state): the
  !> project's Fortran RHS for solvers driven from Python (scipy peers in the benchmarks).
  subroutine api_rhs_loaded(t, y, ydot, ierr)
    real(c_double), intent(in) :: t, y(14)
    real(c_double), intent(out) :: ydot(14)
    integer(c_int), intent(out) :: ierr
    character(len=512) :: errmsg
    integer :: ie
    ydot = 0
    ierr = 1
    if (.not. have_loaded) return
    ydot(1:ndof) = y(ndof+1:)
    call accelerations(loaded, t, y(1:ndof), y(ndof+1:), ydot(ndof+1:), ie, errmsg)
    ierr = ie
  end subroutine api_rhs_loaded

  !> The start state of a case (SI): static equilibrium or rest, plus dq0, dv0.
  subroutine api_start_state(path, y, ierr, errmsg)
    character(len=*), intent(in) :: path
    real(c_double), intent(out) :: y(14)
    integer(c_int), intent(out) :: ierr
    character(len=512), intent(out) :: errmsg
    type(model_t) :: m
    integer :: ie
    y = 0
    call case_read_file(path, m, ie, errmsg)
    if (ie == 0) call start_state(m, y, ie, errmsg)
    ierr = ie
  end subroutine api_start_state

  !> Eq. 18 terms of a case (k_h, k_b1, k_s1, k_a1, k_b2, k_s2, k_a2, k_m of the geometry) and
  !> the k_m the case uses (computed when the case leaves k_m = 0).
  subroutine api_mesh_stiffness(path, terms, k_used, computed, ierr, errmsg)
    character(len=*), intent(in) :: path
    real(c_double), intent(out) :: terms(8), k_used
    integer(c_int), intent(out) :: computed, ierr
    character(len=512), intent(out) :: errmsg
    type(model_t) :: m
    integer :: ie
    terms = 0; k_used = 0; computed = 0
    call case_read_file(path, m, ie, errmsg)
    if (ie == 0) then
      terms = m%k_terms(1:nkterms)
      k_used = m%k_m
      computed = merge(1, 0, m%k_m_computed)
    end if
    ierr = ie
  end subroutine api_mesh_stiffness

  !> Bending, shear and axial stiffness of one involute tooth (potential energy method) for any
  !> gear: external (internal = 0; r_tip unused) or internal (ring) tooth. Angles in radians.
  subroutine api_tooth_stiffness(internal, z, m, alpha, b, r_root, r_tip, e, nu, r_contact, &
       nquad, kb, ks, ka, ierr, errmsg)
    integer(c_int), intent(in) :: internal, nquad
    real(c_double), intent(in) :: z, m, alpha, b, r_root, r_tip, e, nu, r_contact
    real(c_double), intent(out) :: kb, ks, ka
    integer(c_int), intent(out) :: ierr
    character(len=512), intent(out) :: errmsg
    integer :: ie
    if (internal /= 0) then
      call internal_tooth_stiffness(z, m, alpha, b, r_root, r_tip, e, nu, r_contact, nquad, &
           kb, ks, ka, ie, errmsg)
    else
      call external_tooth_stiffness(z, m, alpha, b, r_root, e, nu, r_contact, nquad, &
           kb, ks, ka, ie, errmsg)
    end if
    ierr = ie
    if (ie == 0) errmsg = ''
  end subroutine api_tooth_stiffness

  !> Write the default case (every field) as a namelist file.
  subroutine api_write_defaults(path, ierr, errmsg)
    character(len=*), intent(in) :: path
    integer(c_int), intent(out) :: ierr
    character(len=512), intent(out) :: errmsg
    integer :: ie
    call case_write_defaults(path, ie, errmsg)
    ierr = ie
  end subroutine api_write_defaults

  !> Name (and unit) number i of a list: kind 'tooth' (per-tooth quantities) or 'stats'.
  subroutine api_names(kind, i, name, unit)
    character(len=*), intent(in) :: kind
    integer(c_int), intent(in) :: i
    character(len=32), intent(out) :: name, unit
    name = ''; unit = ''
    select case (kind)
    case ('tooth')
      if (i >= 1 .and. i <= ntooth_q) then
        name = tooth_q_names(i); unit = tooth_q_units(i)
      end if
    case ('stats')
      if (i >= 1 .and. i <= nstats) name = stat_names(i)
    end select
  end subroutine api_names

  !> Cost anatomy: CPU seconds per call of the scaled right-hand side (Eq. 25) of a case at its
  !> static equilibrium (every tooth in contact, as in a running drive; time advanced per call,
  !> contact states from the state), and of the flop floor:
  !> a kernel doing only the arithmetic the mesh cannot avoid (angles by rotation, Eq. 11 and its
  !> rate, Eqs. 15-17 with every tooth in contact, Eqs. 19-22), branch-free. flops: its count.
  !> t_roots: one evaluation of the root functions (contact switches, and in the coupled level
  !> the root/tip branch switches).
  subroutine api_time_rhs(path, n, t_rhs, t_floor, flops, t_roots, ierr, errmsg)
    character(len=*), intent(in) :: path
    integer(c_int), intent(in) :: n
    real(c_double), intent(out) :: t_rhs, t_floor, flops, t_roots
    integer(c_int), intent(out) :: ierr
    character(len=512), intent(out) :: errmsg
    type(model_t) :: m
    real(wp) :: y(nstate), ys(nstate), f(nstate), acc, dt, g(2*1000), gb(2*1000)
    integer :: ie, k
    integer(8) :: c0, c1, rate
    t_rhs = 0; t_floor = 0; flops = 0; t_roots = 0
    call case_read_file(path, m, ie, errmsg)
    m%start_equilibrium = .true.
    m%dq0 = 0; m%dv0 = 0
    if (ie == 0) call start_state(m, y, ie, errmsg)
    ierr = ie
    if (ie /= 0 .or. n < 1) return
    call to_scaled(m, y, ys)
    dt = 1.0e-3_wp/n
    acc = 0
    call system_clock(c0, rate)
    do k = 1, n
      call rhs_scaled(m, m%t0*m%w_ref + k*dt, ys, f, ie, errmsg)
      acc = acc + f(nstate)
    end do
    call system_clock(c1)
    t_rhs = real(c1 - c0, wp)/rate/n
    if (ie /= 0) then
      ierr = ie; return
    end if
    call system_clock(c0)
    do k = 1, n
      acc = acc + floor_kernel(m%z, k*dt, y)
    end do
    call system_clock(c1)
    t_floor = real(c1 - c0, wp)/rate/n
    flops = 28.0_wp*m%z + 2*nstate + 40.0_wp
    call system_clock(c0)
    do k = 1, n
      if (m%thermal == thermal_coupled) then
        call mesh_switch_functions(m, m%t0 + k*dt, y(1:ndof), g, y(ndof+1:), gb)
      else
        call mesh_switch_functions(m, m%t0 + k*dt, y(1:ndof), g)
      end if
      acc = acc + g(1)
    end do
    call system_clock(c1)
    t_roots = real(c1 - c0, wp)/rate/n
    if (acc == 1.2345e300_wp) errmsg = 'unreachable'     ! keeps both loops from being optimised out
  contains
    !> 28 flops per tooth (rotation 6, dn 4, its rate 9, force 4, sums 5), the torsional and
    !> lateral accelerations and scalings (about 40 + 2 nstate), one sin/cos pair.
    real(wp) function floor_kernel(z, t, y) result(r)
      integer, intent(in) :: z
      real(wp), intent(in) :: t, y(nstate)
      real(wp) :: s, c, s1, ex, ey, evx, evy, dn, ddn, fj, fx, fy, fs
      integer :: j
      real(wp), parameter :: sd = 0.38268343236508978_wp, cd = 0.92387953251128674_wp
      s = sin(628.3_wp*t); c = cos(628.3_wp*t)
      ex = y(1) - y(3); ey = y(2) - y(4); evx = y(8) - y(10); evy = y(9) - y(11)
      fx = 0; fy = 0; fs = 0
      do j = 1, z
        dn = ex*s - ey*c + y(6)
        ddn = evx*s - evy*c + y(13) + 628.3_wp*(ex*c + ey*s)
        fj = 2.5e5_wp*(dn - 2.0e-4_wp) + 0.053_wp*ddn
        fx = fx - fj*s
        fy = fy + fj*c
        fs = fs + fj
        s1 = s*cd + c*sd
        c = c*cd - s*sd
        s = s1
      end do
      r = fx + fy + fs + sum(y)*1.0e-3_wp + y(5)*7.855_wp + y(7)*7.856_wp
    end function floor_kernel
  end subroutine api_time_rhs

end module spline_api
