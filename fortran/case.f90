!> Case input: the namelist /spline_case/, its defaults (the only place they live),
!> validation with messages that name the field, and the derived model parameters.
!>
!> Every field is in SI units (angles in degrees only where the name ends in _deg).
!> The fields are module variables because a Fortran namelist group can only hold plain
!> variables; `case_defaults` resets them before every read, so nothing leaks between cases.
module spline_case_io
  use spline_kinds, only: wp, pi
  use spline_stiffness, only: spline_mesh_stiffness
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: model_t, case_read_file, case_read_string, case_write_defaults, case_to_model
  public :: nstate, ndof, thermal_none, thermal_bulk, thermal_oneway, thermal_coupled
  public :: case_name_of, nkterms, kterm_names, set_thermal_level

  integer, parameter :: ndof = 7            !< x1, y1, x2, y2, D1, D2, D3 (Eq. 24)
  integer, parameter :: nstate = 2*ndof     !< displacements then velocities
  integer, parameter :: thermal_none = 0, thermal_bulk = 1, thermal_oneway = 2, thermal_coupled = 3
  integer, parameter :: namelen = 64
  integer, parameter :: nkterms = 8         !< terms of Eq. 18 reported with every case
  character(len=4), parameter :: kterm_names(nkterms) = [character(len=4) :: &
       'k_h', 'k_b1', 'k_s1', 'k_a1', 'k_b2', 'k_s2', 'k_a2', 'k_m']
  integer, parameter :: stiffness_nquad = 32   !< Gauss points: converged to 1e-15 from 16 on

  ! ---- namelist fields (declared here, given values in case_defaults only) ----
  character(len=namelen) :: name            ! case name, used in messages
  integer  :: z                             ! number of teeth Z [-]
  real(wp) :: module_m                      ! module m [m]
  real(wp) :: alpha_deg                     ! pressure angle alpha [deg]
  real(wp) :: b                             ! face width [m]
  real(wp) :: s                             ! tooth thickness [m]
  real(wp) :: c0                            ! nominal backlash c_0 [m]
  real(wp) :: e_mod, nu                     ! Young's modulus [Pa], Poisson ratio [-]
  real(wp) :: lambda_th                     ! thermal expansion coefficient [1/degC]
  real(wp) :: k_cond, rho, c_heat           ! conductivity [W/(m K)], density [kg/m^3], heat capacity [J/(kg K)]
  real(wp) :: j_m, j_l, j_1, j_2            ! inertias of motor, load, splines 1, 2 [kg m^2]
  real(wp) :: m_1, m_2                      ! masses of splines 1, 2 [kg]
  real(wp) :: k_p1, k_p2, c_p1, c_p2        ! support stiffness [N/m], damping [N s/m]
  real(wp) :: k_t1, k_t2, c_t1, c_t2        ! shaft torsional stiffness [N m/rad], damping [N m s/rad]
  real(wp) :: k_m                           ! mesh stiffness per tooth pair [N/m]; 0 = computed (Eq. 18)
  real(wp) :: c_m                           ! mesh damping per tooth pair [N s/m]
  real(wp) :: t_d, t_l                      ! driving and load torque [N m]
  real(wp) :: speed_rpm                     ! shaft speed [r/min]
  real(wp) :: grav                          ! gravity [m/s^2]
  real(wp) :: l_x, l_y                      ! parallel misalignment of spline 1 [m]
  integer  :: dof                           ! 7 (bending-torsion, Eq. 24) | 3 (torsional only: lateral frozen)
  character(len=16) :: thermal              ! none | bulk | oneway | coupled
  real(wp) :: t_bulk                        ! bulk temperature rise T_M [degC]
  real(wp) :: f_m, u_flash, eta_hertz       ! friction coefficient, Blok factor u, Hertz factor eta [-]
  character(len=16) :: method               ! bdf | adams
  character(len=16) :: jacobian             ! dq (difference quotients)
  character(len=16) :: nonlinear            ! newton (dense direct) | fixedpoint (no Jacobian: non-stiff scenes)
  logical  :: roots                         ! locate contact switches |dn_j| = c_j by root finding
  logical  :: stald                         ! BDF stability-limit detection (CVodeSetStabLimDet)
  real(wp) :: rtol, atol                    ! tolerances on the scaled states [-]
  integer  :: max_steps                     ! CVODE steps allowed between two output times
  real(wp) :: t0, t_end                     ! start and end time [s]
  real(wp) :: t_transient                   ! time after t0 integrated but not output [s]
  integer  :: n_out                         ! number of uniform output times
  character(len=16) :: start                ! equilibrium | rest
  real(wp) :: dq0(ndof), dv0(ndof)          ! added to the start state [m], [m/s]
  real(wp) :: l_ref, w_ref                  ! scales (Eq. 25): length [m] (0 = c0), frequency [rad/s] (0 = shaft speed)
  character(len=16) :: fidelity             ! given (run dof and thermal as set) | auto (cheapest level within fidelity_tol)
  real(wp) :: fidelity_tol                  ! auto: allowed relative error of T_m and F_j against the level set [-]

  namelist /spline_case/ name, z, module_m, alpha_deg, b, s, c0, e_mod, nu, lambda_th, &
       k_cond, rho, c_heat, j_m, j_l, j_1, j_2, m_1, m_2, k_p1, k_p2, c_p1, c_p2, &
       k_t1, k_t2, c_t1, c_t2, k_m, c_m, t_d, t_l, speed_rpm, grav, l_x, l_y, &
       thermal, t_bulk, f_m, u_flash, eta_hertz, method, jacobian, nonlinear, roots, rtol, atol, &
       max_steps, t0, t_end, t_transient, n_out, start, dq0, dv0, l_ref, w_ref, &
       dof, fidelity, fidelity_tol, stald

  !> Model parameters derived from a validated case (SI, radians, rad/s).
  type :: model_t
    character(len=namelen) :: name = ''
    integer  :: z = 0
    real(wp) :: m_n, alpha, b, s, c0, e_mod, nu, lambda_th, k_cond, rho, c_heat
    real(wp) :: j_m, j_l, j_1, j_2, m_1, m_2, k_p1, k_p2, c_p1, c_p2
    real(wp) :: k_t1, k_t2, c_t1, c_t2, k_m, c_m, t_d, t_l, omega, grav, l_x, l_y
    integer  :: thermal = thermal_none
    integer  :: dof = 7                     !< 7: bending-torsion, 3: torsional (lateral frozen)
    logical  :: auto = .false.              !< fidelity = auto
    real(wp) :: fidelity_tol = 1.0e-3_wp
    real(wp) :: t_bulk, f_m, u_flash, eta_hertz
    integer  :: method_bdf = 1              !< 1 = BDF, 0 = Adams
    logical  :: newton = .true.             !< Newton + dense solver, else fixed-point iteration
    logical  :: roots = .false.
    logical  :: stald = .false.
    real(wp) :: rtol, atol
    integer  :: max_steps, n_out
    real(wp) :: t0, t_end, t_transient
    logical  :: start_equilibrium = .true.
    real(wp) :: dq0(ndof), dv0(ndof)
    real(wp) :: l_ref, w_ref                !< scales of Eq. 25
    ! derived geometry
    real(wp) :: r_pitch                     !< R = m Z / 2
    real(wp) :: cos_alpha, sin_alpha        !< of the pressure angle (once per case, not per tooth)
    real(wp) :: r_b                         !< base radius R cos(alpha)
    real(wp) :: theta0                      !< pi / (2 Z)  (Eq. 9)
    real(wp) :: kappa                       !< 2 lambda s cos(alpha): backlash loss per degC (Eq. 2)
    real(wp) :: c_bulk                      !< backlash with the bulk rise only [m]
    logical  :: k_m_computed = .false.      !< k_m from Eq. 18 (the case left k_m = 0)
    real(wp) :: k_terms(nkterms) = 0.0_wp   !< Eq. 18 terms k_h, k_b1, ..., k_m (0: not computable)
  end type model_t

contains

  !> Default values of every field: the paper's spline and drive (MODEL.md Section 8).
  subroutine case_defaults()
    name = 'unnamed'
    z = 16; module_m = 2.0e-3_wp; alpha_deg = 30.0_wp; b = 0.03_wp; s = 3.14e-3_wp
    c0 = 2.0e-4_wp; e_mod = 2.1e11_wp; nu = 0.3_wp; lambda_th = 1.2e-5_wp
    k_cond = 46.47_wp; rho = 7800.0_wp; c_heat = 481.48_wp
    j_m = 7.54e-3_wp; j_l = 7.52e-3_wp; j_1 = 3.43e-3_wp; j_2 = 3.73e-3_wp
    m_1 = 2.0_wp; m_2 = 2.0_wp
    k_p1 = 5.0e6_wp; k_p2 = 5.0e6_wp; c_p1 = 5.0_wp; c_p2 = 5.0_wp
    k_t1 = 7.855_wp; k_t2 = 7.856_wp; c_t1 = 0.191_wp; c_t2 = 0.196_wp
    k_m = 0.0_wp; c_m = 0.053_wp
    t_d = 30.7_wp; t_l = 30.7_wp; speed_rpm = 6000.0_wp; grav = 9.81_wp
    l_x = 0.0_wp; l_y = 0.0_wp
    thermal = 'none'; t_bulk = 0.0_wp; f_m = 0.1_wp; u_flash = 0.83_wp; eta_hertz = 1.127_wp
    method = 'bdf'; jacobian = 'dq'; nonlinear = 'newton'; roots = .false.; stald = .false.
    rtol = 1.0e-8_wp; atol = 1.0e-10_wp; max_steps = 100000
    t0 = 0.0_wp; t_end = 0.1_wp; t_transient = 0.0_wp; n_out = 1001
    start = 'equilibrium'; dq0 = 0.0_wp; dv0 = 0.0_wp
    l_ref = 0.0_wp; w_ref = 0.0_wp
    dof = 7; fidelity = 'given'; fidelity_tol = 1.0e-3_wp
  end subroutine case_defaults

  !> Read a case from a namelist file (group &spline_case). Fields not given keep their defaults.
  subroutine case_read_file(path, m, ierr, errmsg)
    character(len=*), intent(in) :: path
    type(model_t), intent(out) :: m
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    integer :: u
    character(len=256) :: iomsg
    call case_defaults()
    name = case_name_of(path)
    open(newunit=u, file=path, status='old', action='read', iostat=ierr, iomsg=iomsg)
    if (ierr /= 0) then
      errmsg = 'cannot open case file '//trim(path)//': '//trim(iomsg)
      ierr = 1; return
    end if
    read(u, nml=spline_case, iostat=ierr, iomsg=iomsg)
    close(u)
    if (ierr /= 0) then
      errmsg = 'case '//trim(path)//': bad namelist &spline_case: '//trim(iomsg)
      ierr = 1; return
    end if
    call case_to_model(m, ierr, errmsg)
  end subroutine case_read_file

  !> Read a case from namelist text held in one string (one record: no '!' comments).
  subroutine case_read_string(text, m, ierr, errmsg)
    character(len=*), intent(in) :: text
    type(model_t), intent(out) :: m
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    character(len=256) :: iomsg
    call case_defaults()
    read(text, nml=spline_case, iostat=ierr, iomsg=iomsg)
    if (ierr /= 0) then
      errmsg = 'bad namelist &spline_case: '//trim(iomsg)
      ierr = 1; return
    end if
    call case_to_model(m, ierr, errmsg)
  end subroutine case_read_string

  !> Write the default case as a namelist to a file (Python reads its defaults from here).
  subroutine case_write_defaults(path, ierr, errmsg)
    character(len=*), intent(in) :: path
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    integer :: u
    character(len=256) :: iomsg
    call case_defaults()
    open(newunit=u, file=path, status='replace', action='write', iostat=ierr, iomsg=iomsg)
    if (ierr == 0) write(u, nml=spline_case, iostat=ierr, iomsg=iomsg)
    if (ierr /= 0) then
      errmsg = 'cannot write defaults to '//trim(path)//': '//trim(iomsg); ierr = 1
    else
      errmsg = ''
    end if
    close(u)
  end subroutine case_write_defaults

  !> The file name without directory and extension: the case name unless the file sets one.
  pure function case_name_of(path) result(stem)
    character(len=*), intent(in) :: path
    character(len=namelen) :: stem
    integer :: i0, i1
    i0 = index(path, '/', back=.true.) + 1
    i1 = index(path, '.', back=.true.) - 1
    if (i1 < i0) i1 = len_trim(path)
    stem = path(i0:i1)
  end function case_name_of

  !> Validate the namelist fields and derive the model. Every error names the field and why.
  subroutine case_to_model(m, ierr, errmsg)
    type(model_t), intent(out) :: m
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp) :: reals(49)
    character(len=12), parameter :: real_names(49) = [character(len=12) :: &
         'module_m', 'alpha_deg', 'b', 's', 'c0', 'e_mod', 'nu', 'lambda_th', 'k_cond', 'rho', &
         'c_heat', 'j_m', 'j_l', 'j_1', 'j_2', 'm_1', 'm_2', 'k_p1', 'k_p2', 'c_p1', 'c_p2', &
         'k_t1', 'k_t2', 'c_t1', 'c_t2', 'k_m', 'c_m', 't_d', 't_l', 'speed_rpm', 'grav', &
         'l_x', 'l_y', 't_bulk', 'f_m', 'u_flash', 'eta_hertz', 'rtol', 'atol', 't0', 't_end', &
         't_transient', 'l_ref', 'w_ref', 'dq0', 'dv0', 'dq0', 'dv0', 'fidelity_tol']
    integer :: i

    ierr = 1
    errmsg = ''
    reals = [module_m, alpha_deg, b, s, c0, e_mod, nu, lambda_th, k_cond, rho, c_heat, &
         j_m, j_l, j_1, j_2, m_1, m_2, k_p1, k_p2, c_p1, c_p2, k_t1, k_t2, c_t1, c_t2, k_m, c_m, &
         t_d, t_l, speed_rpm, grav, l_x, l_y, t_bulk, f_m, u_flash, eta_hertz, rtol, atol, t0, &
         t_end, t_transient, l_ref, w_ref, sum(dq0), sum(dv0), maxval(abs(dq0)), maxval(abs(dv0)), fidelity_tol]
    do i = 1, size(reals)
      if (.not. ieee_is_finite(reals(i))) then
        call fail(real_names(i), 'is not a finite number'); return
      end if
    end do

    if (z < 3) then; call fail('z', 'must be at least 3 teeth'); return; end if
    if (z > 1000) then; call fail('z', 'is more than 1000 teeth'); return; end if
    if (.not. in_range(module_m, 1.0e-4_wp, 0.1_wp, 'module_m', &
         'metres (2 mm is 2e-3)')) return
    if (.not. in_range(alpha_deg, 5.0_wp, 60.0_wp, 'alpha_deg', 'degrees')) return
    if (.not. in_range(b, 1.0e-4_wp, 10.0_wp, 'b', 'metres')) return
    if (.not. in_range(s, 1.0e-5_wp, 0.2_wp, 's', 'metres')) return
    if (.not. in_range(c0, 1.0e-8_wp, 0.01_wp, 'c0', 'metres (0.2 mm is 2e-4)')) return
    if (.not. in_range(e_mod, 1.0e8_wp, 1.0e13_wp, 'e_mod', 'pascals')) return
    if (.not. in_range(nu, 0.0_wp, 0.4999_wp, 'nu', 'a ratio')) return
    if (.not. in_range(lambda_th, 0.0_wp, 1.0e-3_wp, 'lambda_th', '1/degC')) return
    if (.not. positive(k_cond, 'k_cond')) return
    if (.not. positive(rho, 'rho')) return
    if (.not. positive(c_heat, 'c_heat')) return
    if (.not. positive(j_m, 'j_m')) return
    if (.not. positive(j_l, 'j_l')) return
    if (.not. positive(j_1, 'j_1')) return
    if (.not. positive(j_2, 'j_2')) return
    if (.not. positive(m_1, 'm_1')) return
    if (.not. positive(m_2, 'm_2')) return
    if (.not. nonneg(k_p1, 'k_p1')) return
    if (.not. nonneg(k_p2, 'k_p2')) return
    if (.not. nonneg(c_p1, 'c_p1')) return
    if (.not. nonneg(c_p2, 'c_p2')) return
    if (.not. nonneg(k_t1, 'k_t1')) return
    if (.not. nonneg(k_t2, 'k_t2')) return
    if (.not. nonneg(c_t1, 'c_t1')) return
    if (.not. nonneg(c_t2, 'c_t2')) return
    if (.not. nonneg(k_m, 'k_m')) return
    if (.not. nonneg(c_m, 'c_m')) return
    if (.not. in_range(speed_rpm, 0.0_wp, 1.0e6_wp, 'speed_rpm', 'r/min, not negative')) return
    if (max(abs(l_x), abs(l_y)) > 0.5_wp*module_m*z) then
      call fail('l_x', 'and l_y must be smaller than the pitch radius m Z / 2'); return
    end if
    if (.not. nonneg(f_m, 'f_m')) return
    if (.not. nonneg(u_flash, 'u_flash')) return
    if (.not. positive(eta_hertz, 'eta_hertz')) return
    if (.not. in_range(rtol, 1.0e-15_wp, 0.1_wp, 'rtol', 'a relative tolerance')) return
    if (.not. positive(atol, 'atol')) return
    if (max_steps < 1) then; call fail('max_steps', 'must be at least 1'); return; end if
    if (n_out < 1) then; call fail('n_out', 'must be at least 1'); return; end if
    if (.not. (t_end > t0)) then; call fail('t_end', 'must be greater than t0'); return; end if
    if (.not. nonneg(t_transient, 't_transient')) return
    if (.not. (t0 + t_transient <= t_end)) then
      call fail('t_transient', 'must end before t_end'); return
    end if
    if (.not. nonneg(l_ref, 'l_ref')) return
    if (.not. nonneg(w_ref, 'w_ref')) return
    if (dof /= 3 .and. dof /= 7) then
      call fail('dof', 'must be 7 (bending-torsion) or 3 (torsional only)'); return
    end if
    if (.not. in_range(fidelity_tol, 1.0e-12_wp, 1.0_wp, 'fidelity_tol', 'a relative error')) return

    m%name = name
    m%z = z; m%m_n = module_m; m%alpha = alpha_deg*pi/180.0_wp; m%b = b; m%s = s; m%c0 = c0
    m%e_mod = e_mod; m%nu = nu; m%lambda_th = lambda_th
    m%k_cond = k_cond; m%rho = rho; m%c_heat = c_heat
    m%j_m = j_m; m%j_l = j_l; m%j_1 = j_1; m%j_2 = j_2; m%m_1 = m_1; m%m_2 = m_2
    m%k_p1 = k_p1; m%k_p2 = k_p2; m%c_p1 = c_p1; m%c_p2 = c_p2
    m%k_t1 = k_t1; m%k_t2 = k_t2; m%c_t1 = c_t1; m%c_t2 = c_t2
    m%k_m = k_m; m%c_m = c_m; m%t_d = t_d; m%t_l = t_l
    ! Eq. 18 at the pitch point, ISO 4156 flat-root radii: external minor m (Z - 1.5) / 2,
    ! internal major m (Z + 1.5) / 2 and minor m (Z - 1) / 2. Always reported; used if k_m = 0.
    call spline_mesh_stiffness(real(z, wp), module_m, alpha_deg*pi/180.0_wp, b, e_mod, nu, &
         0.5_wp*module_m*(z - 1.5_wp), 0.5_wp*module_m*(z + 1.5_wp), 0.5_wp*module_m*(z - 1.0_wp), &
         stiffness_nquad, m%k_terms(1), m%k_terms(2), m%k_terms(3), m%k_terms(4), m%k_terms(5), &
         m%k_terms(6), m%k_terms(7), m%k_terms(8), ierr, errmsg)
    if (ierr /= 0) then
      m%k_terms = 0.0_wp
      if (k_m == 0.0_wp) then
        ierr = 1
        call fail('k_m', '= 0 asks for the potential-energy stiffness (Eq. 18), which fails for '// &
             'this geometry: '//trim(errmsg)//'; set k_m in N/m'); return
      end if
    end if
    ierr = 1
    if (k_m == 0.0_wp) then
      m%k_m = m%k_terms(8)
      m%k_m_computed = .true.
    end if
    m%omega = speed_rpm*2.0_wp*pi/60.0_wp; m%grav = grav; m%l_x = l_x; m%l_y = l_y
    m%t_bulk = t_bulk; m%f_m = f_m; m%u_flash = u_flash; m%eta_hertz = eta_hertz
    m%rtol = rtol; m%atol = atol; m%max_steps = max_steps; m%n_out = n_out
    m%t0 = t0; m%t_end = t_end; m%t_transient = t_transient
    m%roots = roots; m%stald = stald; m%dq0 = dq0; m%dv0 = dv0
    m%dof = dof; m%fidelity_tol = fidelity_tol

    select case (trim(thermal))
    case ('none');    m%thermal = thermal_none
    case ('bulk');    m%thermal = thermal_bulk
    case ('oneway');  m%thermal = thermal_oneway
    case ('coupled'); m%thermal = thermal_coupled
    case default
      call fail('thermal', 'is "'//trim(thermal)//'": use none, bulk, oneway or coupled'); return
    end select
    select case (trim(fidelity))
    case ('given'); m%auto = .false.
    case ('auto');  m%auto = .true.
    case default
      call fail('fidelity', 'is "'//trim(fidelity)//'": use given or auto'); return
    end select
    select case (trim(method))
    case ('bdf');   m%method_bdf = 1
    case ('adams'); m%method_bdf = 0
    case default
      call fail('method', 'is "'//trim(method)//'": use bdf or adams'); return
    end select
    select case (trim(jacobian))
    case ('dq')
    case default
      call fail('jacobian', 'is "'//trim(jacobian)//'": use dq'); return
    end select
    select case (trim(nonlinear))
    case ('newton');     m%newton = .true.
    case ('fixedpoint'); m%newton = .false.
    case default
      call fail('nonlinear', 'is "'//trim(nonlinear)//'": use newton or fixedpoint'); return
    end select
    select case (trim(start))
    case ('equilibrium'); m%start_equilibrium = .true.
    case ('rest');        m%start_equilibrium = .false.
    case default
      call fail('start', 'is "'//trim(start)//'": use equilibrium or rest'); return
    end select

    ! derived geometry (MODEL.md Section 2 and Eq. 9)
    m%r_pitch = 0.5_wp*m%m_n*m%z
    m%cos_alpha = cos(m%alpha)
    m%sin_alpha = sin(m%alpha)
    m%r_b = m%r_pitch*m%cos_alpha
    m%theta0 = pi/(2.0_wp*m%z)
    m%kappa = 2.0_wp*m%lambda_th*m%s*m%cos_alpha
    call set_thermal_level(m, m%thermal)
    if (m%c_bulk <= 0.0_wp) then
      write(errmsg, '(a,es10.3,a,es10.3,a)') 'case '//trim(m%name)//': thermal interference: '// &
           't_bulk = ', m%t_bulk, ' degC closes the backlash (c = ', m%c_bulk, ' m, Eq. 2)'
      ierr = 3
      return
    end if
    ! scales of Eq. 25
    m%l_ref = l_ref
    if (m%l_ref == 0.0_wp) m%l_ref = m%c0
    m%w_ref = w_ref
    if (m%w_ref == 0.0_wp) m%w_ref = m%omega
    if (m%w_ref == 0.0_wp) m%w_ref = sqrt(max(m%k_p1, m%k_m)/m%m_1)
    errmsg = ''
    ierr = 0

  contains

    subroutine fail(field, why)
      character(len=*), intent(in) :: field, why
      errmsg = 'case '//trim(name)//': field '//trim(field)//' '//why
    end subroutine fail

    logical function positive(x, field)
      real(wp), intent(in) :: x
      character(len=*), intent(in) :: field
      positive = x > 0.0_wp
      if (.not. positive) call fail(field, 'must be positive')
    end function positive

    logical function nonneg(x, field)
      real(wp), intent(in) :: x
      character(len=*), intent(in) :: field
      nonneg = x >= 0.0_wp
      if (.not. nonneg) call fail(field, 'must not be negative')
    end function nonneg

    logical function in_range(x, lo, hi, field, unit)
      real(wp), intent(in) :: x, lo, hi
      character(len=*), intent(in) :: field, unit
      character(len=80) :: buf
      in_range = x >= lo .and. x <= hi
      if (.not. in_range) then
        write(buf, '(es10.3,a,es9.2,a,es9.2)') x, ' is outside ', lo, ' ..', hi
        call fail(field, '= '//trim(adjustl(buf))//' (unit: '//unit//')')
      end if
    end function in_range

  end subroutine case_to_model

  !> Set the thermal level of a model and the backlash it implies at the bulk temperature:
  !> Eq. 2 with T_B = T_M, or c_0 for the level none.
  pure subroutine set_thermal_level(m, level)
    type(model_t), intent(inout) :: m
    integer, intent(in) :: level
    m%thermal = level
    m%c_bulk = m%c0
    if (level /= thermal_none) m%c_bulk = m%c0 - m%kappa*m%t_bulk
  end subroutine set_thermal_level

end module spline_case_io
