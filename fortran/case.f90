!> Case input: the namelist group &spline_case mapped to case fields (type case_t), and their
!> validation. Nothing here computes physics: spline_model builds the model from a valid case.
!>
!> Every field is in SI units (angles in degrees only where the name ends in _deg). The
!> defaults are the default values of case_t's components: the only place they live.
!> The namelist group is declared inside nml_read/nml_write over local variables, so reading
!> a case changes no module variable (reentrant).
module spline_case
  use spline_kinds, only: wp
  use spline_errors, only: err_ok, err_case, msglen
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: case_t, case_read_file, case_read_text, case_write_text, case_validate, case_name_of
  public :: namelen, ndof_case, thermal_values, method_values, nonlinear_values, start_values, &
       fidelity_values, section_values, option_index

  integer, parameter :: namelen = 128
  integer, parameter :: ndof_case = 7        !< entries of dq0, dv0: x1, y1, x2, y2, D1, D2, D3
  integer, parameter :: optlen = 16
  ! The values of the option fields; spline_model maps each to its position.
  character(len=optlen), parameter :: thermal_values(4) = [character(len=optlen) :: &
       'none', 'bulk', 'oneway', 'coupled']
  character(len=optlen), parameter :: method_values(2) = [character(len=optlen) :: 'bdf', 'adams']
  character(len=optlen), parameter :: nonlinear_values(2) = [character(len=optlen) :: &
       'newton', 'fixedpoint']
  character(len=optlen), parameter :: start_values(2) = [character(len=optlen) :: &
       'equilibrium', 'rest']
  character(len=optlen), parameter :: fidelity_values(2) = [character(len=optlen) :: 'given', 'auto']
  character(len=optlen), parameter :: jacobian_values(1) = [character(len=optlen) :: 'dq']
  character(len=optlen), parameter :: section_values(3) = [character(len=optlen) :: &
       'none', 'shaft', 'tooth']

  !> The fields of a case with their defaults: the paper's spline and drive (MODEL.md Section 8).
  type :: case_t
    character(len=namelen) :: name = 'unnamed'   !< case name, used in messages
    integer  :: z = 16                      !< number of teeth Z [-]
    real(wp) :: module_m = 2.0e-3_wp        !< module m [m]
    real(wp) :: alpha_deg = 30.0_wp         !< pressure angle alpha [deg]
    real(wp) :: b = 0.03_wp                 !< face width [m]
    real(wp) :: s = 3.14e-3_wp              !< tooth thickness [m]
    real(wp) :: c0 = 2.0e-4_wp              !< nominal backlash c_0 [m]
    real(wp) :: e_mod = 2.1e11_wp           !< Young's modulus [Pa]
    real(wp) :: nu = 0.3_wp                 !< Poisson ratio [-]
    real(wp) :: lambda_th = 1.2e-5_wp       !< thermal expansion coefficient [1/degC]
    real(wp) :: k_cond = 46.47_wp           !< conductivity [W/(m K)]
    real(wp) :: rho = 7800.0_wp             !< density [kg/m^3]
    real(wp) :: c_heat = 481.48_wp          !< heat capacity [J/(kg K)]
    real(wp) :: j_m = 7.54e-3_wp, j_l = 7.52e-3_wp, j_1 = 3.43e-3_wp, j_2 = 3.73e-3_wp  !< [kg m^2]
    real(wp) :: m_1 = 2.0_wp, m_2 = 2.0_wp  !< masses of splines 1, 2 [kg]
    real(wp) :: k_p1 = 5.0e6_wp, k_p2 = 5.0e6_wp   !< support stiffness [N/m]
    real(wp) :: c_p1 = 5.0_wp, c_p2 = 5.0_wp       !< support damping [N s/m]
    real(wp) :: k_t1 = 7.855_wp, k_t2 = 7.856_wp   !< shaft torsional stiffness [N m/rad]
    real(wp) :: c_t1 = 0.191_wp, c_t2 = 0.196_wp   !< shaft torsional damping [N m s/rad]
    real(wp) :: k_m = 0.0_wp                !< mesh stiffness per tooth pair [N/m]; 0 = computed (Eq. 18)
    real(wp) :: c_m = 0.053_wp              !< mesh damping per tooth pair [N s/m]
    real(wp) :: t_d = 30.7_wp, t_l = 30.7_wp       !< driving and load torque [N m]
    real(wp) :: speed_rpm = 6000.0_wp       !< shaft speed [r/min]
    real(wp) :: grav = 9.81_wp              !< gravity [m/s^2]
    real(wp) :: l_x = 0.0_wp, l_y = 0.0_wp  !< parallel misalignment of spline 1 [m]
    integer  :: dof = 7                     !< 7 (bending-torsion, Eq. 24) | 3 (torsional only)
    character(len=optlen) :: thermal = 'none'      !< none | bulk | oneway | coupled
    real(wp) :: t_bulk = 0.0_wp             !< bulk temperature rise T_M [degC]
    real(wp) :: f_m = 0.1_wp, u_flash = 0.83_wp, eta_hertz = 1.127_wp  !< friction, Blok u, Hertz eta [-]
    character(len=optlen) :: method = 'bdf'        !< bdf | adams
    character(len=optlen) :: jacobian = 'dq'       !< dq (difference quotients)
    character(len=optlen) :: nonlinear = 'newton'  !< newton | fixedpoint
    logical  :: roots = .false.             !< locate the contact switches by root finding
    logical  :: stald = .false.             !< BDF stability-limit detection
    real(wp) :: rtol = 1.0e-8_wp, atol = 1.0e-10_wp   !< tolerances on the scaled states [-]
    integer  :: max_steps = 100000          !< CVODE steps allowed between two output times
    real(wp) :: t0 = 0.0_wp, t_end = 0.1_wp !< start and end time [s]
    real(wp) :: t_transient = 0.0_wp        !< time after t0 integrated but not output [s]
    integer  :: n_out = 1001                !< number of uniform output times
    character(len=optlen) :: start = 'equilibrium' !< equilibrium | rest
    real(wp) :: dq0(ndof_case) = 0.0_wp, dv0(ndof_case) = 0.0_wp   !< start offsets [m], [m/s]
    real(wp) :: l_ref = 0.0_wp, w_ref = 0.0_wp     !< scales of Eq. 25 [m], [rad/s]; 0 = c0, shaft speed
    character(len=optlen) :: fidelity = 'given'    !< given | auto
    real(wp) :: fidelity_tol = 1.0e-3_wp    !< auto: allowed relative error of T_m and F_j [-]
    character(len=optlen) :: section = 'none'      !< Poincare section: none | shaft | tooth (pass)
    logical  :: lyapunov = .false.          !< largest Lyapunov exponent (Benettin) over the output window
    real(wp) :: lyapunov_interval = 1.0_wp  !< renormalisation interval [shaft revolutions]
    real(wp) :: lyapunov_d0 = 1.0e-8_wp     !< initial separation, in the scaled states of Eq. 25 [-]
  end type case_t

contains

  !> Read a case from a namelist file (group &spline_case). Fields not given keep their
  !> defaults; the name defaults to the file's stem.
  subroutine case_read_file(path, c, ierr, errmsg)
    character(len=*), intent(in) :: path
    type(case_t), intent(out) :: c
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    integer :: u
    character(len=256) :: iomsg
    c = case_t()
    c%name = case_name_of(path)
    errmsg = ''
    open(newunit=u, file=path, status='old', action='read', iostat=ierr, iomsg=iomsg)
    if (ierr /= 0) then
      errmsg = 'cannot open case file '//trim(path)//': '//trim(iomsg)
      ierr = err_case; return
    end if
    call nml_io(c, ierr, iomsg, unit=u)
    close(u)
    if (ierr /= 0) then
      errmsg = 'case '//trim(path)//': bad namelist &spline_case: '//trim(iomsg)
      ierr = err_case
    end if
  end subroutine case_read_file

  !> Read a case from namelist text held in memory (lines separated by newlines).
  subroutine case_read_text(text, c, ierr, errmsg)
    character(len=*), intent(in) :: text
    type(case_t), intent(out) :: c
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    character(len=:), allocatable :: lines(:)
    character(len=256) :: iomsg
    integer :: n, i, i0, i1, w
    ! split into records: a namelist comment ('!') ends at the end of its record
    n = 1; w = 0; i0 = 1
    do i = 1, len(text)
      if (text(i:i) == new_line('a')) then
        n = n + 1; w = max(w, i - i0); i0 = i + 1
      end if
    end do
    w = max(w, len(text) - i0 + 1, 1)
    allocate(character(len=w) :: lines(n))
    n = 0; i0 = 1
    do i = 1, len(text) + 1
      if (i > len(text)) then
        i1 = i
      else if (text(i:i) == new_line('a')) then
        i1 = i
      else
        cycle
      end if
      n = n + 1
      lines(n) = text(i0:i1-1)
      i0 = i + 1
    end do
    c = case_t()
    errmsg = ''
    call nml_io(c, ierr, iomsg, lines=lines)
    if (ierr /= 0) then
      errmsg = 'bad namelist &spline_case: '//trim(iomsg)
      ierr = err_case
    end if
  end subroutine case_read_text

  !> A case as namelist text (every field, one per line): Python reads the defaults from it.
  subroutine case_write_text(c, text)
    type(case_t), intent(in) :: c
    character(len=:), allocatable, intent(out) :: text
    type(case_t) :: cc
    character(len=256) :: lines(120), iomsg
    integer :: i, ierr
    lines = ''
    cc = c
    call nml_io(cc, ierr, iomsg, out=lines)
    text = ''
    do i = 1, size(lines)
      if (len_trim(lines(i)) > 0) text = text//trim(lines(i))//new_line('a')
    end do
  end subroutine case_write_text

  !> The namelist group &spline_case over local variables (one per case_t component, in the
  !> same order): copy the case in, then read into it (unit or records) or write it out.
  subroutine nml_io(c, ierr, iomsg, unit, lines, out)
    type(case_t), intent(inout) :: c
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: iomsg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: lines(:)
    character(len=*), intent(out), optional :: out(:)
    character(len=namelen) :: name
    integer :: z, dof, max_steps, n_out
    real(wp) :: module_m, alpha_deg, b, s, c0, e_mod, nu, lambda_th, k_cond, rho, c_heat, j_m, j_l, j_1, &
         j_2, m_1, m_2, k_p1, k_p2, c_p1, c_p2, k_t1, k_t2, c_t1, c_t2, k_m, c_m, t_d, t_l, &
         speed_rpm, grav, l_x, l_y, t_bulk, f_m, u_flash, eta_hertz, rtol, atol, t0, t_end, &
         t_transient, dq0(ndof_case), dv0(ndof_case), l_ref, w_ref, fidelity_tol
    character(len=optlen) :: thermal, method, jacobian, nonlinear, start, fidelity, section
    logical :: roots, stald, lyapunov
    real(wp) :: lyapunov_interval, lyapunov_d0
    namelist /spline_case/ name, z, module_m, alpha_deg, b, s, c0, e_mod, nu, lambda_th, k_cond, rho, c_heat, j_m, &
         j_l, j_1, j_2, m_1, m_2, k_p1, k_p2, c_p1, c_p2, k_t1, k_t2, c_t1, c_t2, k_m, c_m, t_d, &
         t_l, speed_rpm, grav, l_x, l_y, dof, thermal, t_bulk, f_m, u_flash, eta_hertz, method, &
         jacobian, nonlinear, roots, stald, rtol, atol, max_steps, t0, t_end, t_transient, n_out, &
         start, dq0, dv0, l_ref, w_ref, fidelity, fidelity_tol, section, lyapunov, &
         lyapunov_interval, lyapunov_d0
    name = c%name; z = c%z; module_m = c%module_m; alpha_deg = c%alpha_deg; b = c%b; s = c%s
    c0 = c%c0; e_mod = c%e_mod; nu = c%nu; lambda_th = c%lambda_th; k_cond = c%k_cond
    rho = c%rho; c_heat = c%c_heat; j_m = c%j_m; j_l = c%j_l; j_1 = c%j_1; j_2 = c%j_2
    m_1 = c%m_1; m_2 = c%m_2; k_p1 = c%k_p1; k_p2 = c%k_p2; c_p1 = c%c_p1; c_p2 = c%c_p2
    k_t1 = c%k_t1; k_t2 = c%k_t2; c_t1 = c%c_t1; c_t2 = c%c_t2; k_m = c%k_m; c_m = c%c_m
    t_d = c%t_d; t_l = c%t_l; speed_rpm = c%speed_rpm; grav = c%grav; l_x = c%l_x; l_y = c%l_y
    dof = c%dof; thermal = c%thermal; t_bulk = c%t_bulk; f_m = c%f_m; u_flash = c%u_flash
    eta_hertz = c%eta_hertz; method = c%method; jacobian = c%jacobian; nonlinear = c%nonlinear
    roots = c%roots; stald = c%stald; rtol = c%rtol; atol = c%atol; max_steps = c%max_steps
    t0 = c%t0; t_end = c%t_end; t_transient = c%t_transient; n_out = c%n_out; start = c%start
    dq0 = c%dq0; dv0 = c%dv0; l_ref = c%l_ref; w_ref = c%w_ref; fidelity = c%fidelity
    fidelity_tol = c%fidelity_tol; section = c%section; lyapunov = c%lyapunov
    lyapunov_interval = c%lyapunov_interval; lyapunov_d0 = c%lyapunov_d0
    iomsg = ''
    if (present(out)) then
      write(out, nml=spline_case, iostat=ierr, iomsg=iomsg)
      return
    end if
    if (present(unit)) then
      read(unit, nml=spline_case, iostat=ierr, iomsg=iomsg)
    else
      read(lines, nml=spline_case, iostat=ierr, iomsg=iomsg)
    end if
    if (ierr /= 0) return
    c%name = name; c%z = z; c%module_m = module_m; c%alpha_deg = alpha_deg; c%b = b; c%s = s
    c%c0 = c0; c%e_mod = e_mod; c%nu = nu; c%lambda_th = lambda_th; c%k_cond = k_cond
    c%rho = rho; c%c_heat = c_heat; c%j_m = j_m; c%j_l = j_l; c%j_1 = j_1; c%j_2 = j_2
    c%m_1 = m_1; c%m_2 = m_2; c%k_p1 = k_p1; c%k_p2 = k_p2; c%c_p1 = c_p1; c%c_p2 = c_p2
    c%k_t1 = k_t1; c%k_t2 = k_t2; c%c_t1 = c_t1; c%c_t2 = c_t2; c%k_m = k_m; c%c_m = c_m
    c%t_d = t_d; c%t_l = t_l; c%speed_rpm = speed_rpm; c%grav = grav; c%l_x = l_x
    c%l_y = l_y; c%dof = dof; c%thermal = thermal; c%t_bulk = t_bulk; c%f_m = f_m
    c%u_flash = u_flash; c%eta_hertz = eta_hertz; c%method = method; c%jacobian = jacobian
    c%nonlinear = nonlinear; c%roots = roots; c%stald = stald; c%rtol = rtol; c%atol = atol
    c%max_steps = max_steps; c%t0 = t0; c%t_end = t_end; c%t_transient = t_transient
    c%n_out = n_out; c%start = start; c%dq0 = dq0; c%dv0 = dv0; c%l_ref = l_ref
    c%w_ref = w_ref; c%fidelity = fidelity; c%fidelity_tol = fidelity_tol
    c%section = section; c%lyapunov = lyapunov; c%lyapunov_interval = lyapunov_interval
    c%lyapunov_d0 = lyapunov_d0
  end subroutine nml_io

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

  !> Position of an option's value in its list of values (0: not among them).
  pure integer function option_index(values, value) result(k)
    character(len=*), intent(in) :: values(:), value
    do k = 1, size(values)
      if (values(k) == value) return
    end do
    k = 0
  end function option_index

  !> Check every field's type-independent range (in its unit) and the option values.
  !> ierr = err_case with a message naming the case, the field and why.
  subroutine case_validate(c, ierr, errmsg)
    type(case_t), intent(in) :: c
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

    ierr = err_case
    errmsg = ''
    reals = [c%module_m, c%alpha_deg, c%b, c%s, c%c0, c%e_mod, c%nu, c%lambda_th, c%k_cond, &
         c%rho, c%c_heat, c%j_m, c%j_l, c%j_1, c%j_2, c%m_1, c%m_2, c%k_p1, c%k_p2, c%c_p1, &
         c%c_p2, c%k_t1, c%k_t2, c%c_t1, c%c_t2, c%k_m, c%c_m, c%t_d, c%t_l, c%speed_rpm, &
         c%grav, c%l_x, c%l_y, c%t_bulk, c%f_m, c%u_flash, c%eta_hertz, c%rtol, c%atol, c%t0, &
         c%t_end, c%t_transient, c%l_ref, c%w_ref, sum(c%dq0), sum(c%dv0), &
         maxval(abs(c%dq0)), maxval(abs(c%dv0)), c%fidelity_tol]
    do i = 1, size(reals)
      if (.not. ieee_is_finite(reals(i))) then
        call fail(real_names(i), 'is not a finite number'); return
      end if
    end do

    if (c%z < 3) then; call fail('z', 'must be at least 3 teeth'); return; end if
    if (c%z > 1000) then; call fail('z', 'is more than 1000 teeth'); return; end if
    if (.not. in_range(c%module_m, 1.0e-4_wp, 0.1_wp, 'module_m', 'metres (2 mm is 2e-3)')) return
    if (.not. in_range(c%alpha_deg, 5.0_wp, 60.0_wp, 'alpha_deg', 'degrees')) return
    if (.not. in_range(c%b, 1.0e-4_wp, 10.0_wp, 'b', 'metres')) return
    if (.not. in_range(c%s, 1.0e-5_wp, 0.2_wp, 's', 'metres')) return
    if (.not. in_range(c%c0, 1.0e-8_wp, 0.01_wp, 'c0', 'metres (0.2 mm is 2e-4)')) return
    if (.not. in_range(c%e_mod, 1.0e8_wp, 1.0e13_wp, 'e_mod', 'pascals')) return
    if (.not. in_range(c%nu, 0.0_wp, 0.4999_wp, 'nu', 'a ratio')) return
    if (.not. in_range(c%lambda_th, 0.0_wp, 1.0e-3_wp, 'lambda_th', '1/degC')) return
    if (.not. positive(c%k_cond, 'k_cond')) return
    if (.not. positive(c%rho, 'rho')) return
    if (.not. positive(c%c_heat, 'c_heat')) return
    if (.not. positive(c%j_m, 'j_m')) return
    if (.not. positive(c%j_l, 'j_l')) return
    if (.not. positive(c%j_1, 'j_1')) return
    if (.not. positive(c%j_2, 'j_2')) return
    if (.not. positive(c%m_1, 'm_1')) return
    if (.not. positive(c%m_2, 'm_2')) return
    if (.not. nonneg(c%k_p1, 'k_p1')) return
    if (.not. nonneg(c%k_p2, 'k_p2')) return
    if (.not. nonneg(c%c_p1, 'c_p1')) return
    if (.not. nonneg(c%c_p2, 'c_p2')) return
    if (.not. nonneg(c%k_t1, 'k_t1')) return
    if (.not. nonneg(c%k_t2, 'k_t2')) return
    if (.not. nonneg(c%c_t1, 'c_t1')) return
    if (.not. nonneg(c%c_t2, 'c_t2')) return
    if (.not. nonneg(c%k_m, 'k_m')) return
    if (.not. nonneg(c%c_m, 'c_m')) return
    if (.not. in_range(c%speed_rpm, 0.0_wp, 1.0e6_wp, 'speed_rpm', 'r/min, not negative')) return
    if (max(abs(c%l_x), abs(c%l_y)) > 0.5_wp*c%module_m*c%z) then
      call fail('l_x', 'and l_y must be smaller than the pitch radius m Z / 2'); return
    end if
    if (.not. nonneg(c%f_m, 'f_m')) return
    if (.not. nonneg(c%u_flash, 'u_flash')) return
    if (.not. positive(c%eta_hertz, 'eta_hertz')) return
    if (.not. in_range(c%rtol, 1.0e-15_wp, 0.1_wp, 'rtol', 'a relative tolerance')) return
    if (.not. positive(c%atol, 'atol')) return
    if (c%max_steps < 1) then; call fail('max_steps', 'must be at least 1'); return; end if
    if (c%n_out < 1) then; call fail('n_out', 'must be at least 1'); return; end if
    if (.not. (c%t_end > c%t0)) then; call fail('t_end', 'must be greater than t0'); return; end if
    if (.not. nonneg(c%t_transient, 't_transient')) return
    if (.not. (c%t0 + c%t_transient <= c%t_end)) then
      call fail('t_transient', 'must end before t_end'); return
    end if
    if (.not. nonneg(c%l_ref, 'l_ref')) return
    if (.not. nonneg(c%w_ref, 'w_ref')) return
    if (c%dof /= 3 .and. c%dof /= 7) then
      call fail('dof', 'must be 7 (bending-torsion) or 3 (torsional only)'); return
    end if
    if (.not. in_range(c%fidelity_tol, 1.0e-12_wp, 1.0_wp, 'fidelity_tol', 'a relative error')) return
    if (.not. one_of(thermal_values, c%thermal, 'thermal')) return
    if (.not. one_of(fidelity_values, c%fidelity, 'fidelity')) return
    if (.not. one_of(method_values, c%method, 'method')) return
    if (.not. one_of(jacobian_values, c%jacobian, 'jacobian')) return
    if (.not. one_of(nonlinear_values, c%nonlinear, 'nonlinear')) return
    if (.not. one_of(start_values, c%start, 'start')) return
    if (.not. one_of(section_values, c%section, 'section')) return
    if (.not. ieee_is_finite(c%lyapunov_interval) .or. .not. ieee_is_finite(c%lyapunov_d0)) then
      call fail('lyapunov_interval', 'and lyapunov_d0 must be finite numbers'); return
    end if
    if (.not. in_range(c%lyapunov_interval, 1.0e-3_wp, 1.0e3_wp, 'lyapunov_interval', &
         'shaft revolutions')) return
    if (.not. in_range(c%lyapunov_d0, 1.0e-12_wp, 1.0e-3_wp, 'lyapunov_d0', &
         'a separation of the scaled states')) return
    if ((c%lyapunov .or. option_index(section_values, c%section) > 1) .and. c%speed_rpm <= 0.0_wp) then
      call fail('speed_rpm', 'must be positive for a Poincare section or a Lyapunov exponent '// &
           '(both are timed by the shaft revolution)'); return
    end if
    ierr = err_ok

  contains

    subroutine fail(field, why)
      character(len=*), intent(in) :: field, why
      errmsg = 'case '//trim(c%name)//': field '//trim(field)//' '//why
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

    logical function one_of(values, value, field)
      character(len=*), intent(in) :: values(:), value, field
      character(len=:), allocatable :: list
      integer :: k
      one_of = option_index(values, value) > 0
      if (one_of) return
      list = trim(values(1))
      do k = 2, size(values)
        if (k == size(values)) then
          list = list//' or '//trim(values(k))
        else
          list = list//', '//trim(values(k))
        end if
      end do
      call fail(field, 'is "'//trim(value)//'": use '//list)
    end function one_of

  end subroutine case_validate

end module spline_case
