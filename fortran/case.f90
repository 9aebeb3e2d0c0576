!> Case input: the namelist group &spline_case mapped to case fields (type case_t), and their
!> validation. Nothing here computes physics: spline_model builds the model from a valid case.
!>
!> Every field is in SI units (angles in degrees only where the name ends in _deg). The
!> defaults are the default values of case_t's components: the only place they live.
!>
!> Reading (case_parse) is the one diagnosis of a case's text, for the executable and for
!> Python alike (pyspline hands the bytes of a case file to api_parse): the text is first
!> tokenised and checked here, every error naming the line, the field and what was expected
!> (unknown fields get the nearest field name as a suggestion); only text that passed is
!> then read by the compiler's namelist input, one element per record, into local variables
!> (nml_io), so reading a case changes no module variable (reentrant).
module spline_case
  use, intrinsic :: iso_c_binding, only: c_char, c_int, c_long_long, c_null_char
  use spline_kinds, only: wp, pi, max_teeth
  use spline_errors, only: err_ok, err_case, msglen, itoa
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
  implicit none
  private
  public :: case_t, case_read_file, case_read_text, case_parse, case_write_text, case_validate
  public :: case_name_of, case_suggest, case_field, case_check_file, case_output_bytes
  public :: namelen, nripple, ndof_case, thermal_values, method_values, nonlinear_values, start_values, &
       fidelity_values, section_values, option_index, nfields, max_case_bytes, max_output_bytes

  integer, parameter :: namelen = 128
  integer, parameter :: nripple = 4         !< torque-ripple orders a case can give
  integer, parameter :: ndof_case = 7        !< entries of dq0, dv0: x1, y1, x2, y2, D1, D2, D3
  integer, parameter :: optlen = 16
  !> Largest case file read [bytes]: a case with every field and comments is ~5 kB.
  integer, parameter :: max_case_bytes = 1048576
  !> Largest memory a run's outputs may take [bytes] (checked before anything is allocated:
  !> case_output_bytes). 8 GiB: a million outputs of a 16-tooth case take 1.3 GB.
  real(wp), parameter :: max_output_bytes = 8.0_wp*1024.0_wp**3
  ! The values of the option fields; spline_model maps each to its position.
  character(len=optlen), parameter :: thermal_values(4) = [character(len=optlen) :: &
       'none', 'bulk', 'oneway', 'coupled']
  character(len=optlen), parameter :: method_values(2) = [character(len=optlen) :: 'bdf', 'adams']
  character(len=optlen), parameter :: nonlinear_values(3) = [character(len=optlen) :: &
       'newton', 'fixedpoint', 'auto']
  character(len=optlen), parameter :: start_values(2) = [character(len=optlen) :: &
       'equilibrium', 'rest']
  character(len=optlen), parameter :: fidelity_values(2) = [character(len=optlen) :: 'given', 'auto']
  character(len=optlen), parameter :: jacobian_values(1) = [character(len=optlen) :: 'dq']
  character(len=optlen), parameter :: section_values(3) = [character(len=optlen) :: &
       'none', 'shaft', 'tooth']

  !> The fields of a case with their defaults: the paper's spline and drive (docs/model.md section 12).
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
    !> The defaults are what won where it was measured (docs/performance.md, "Impacting scenes,
    !> and how the defaults were chosen"): Adams with fixed-point iteration, on every scene of
    !> the stability sweep and on the impacting Z = 24 scene.
    character(len=optlen) :: method = 'adams'      !< adams | bdf
    character(len=optlen) :: jacobian = 'dq'       !< dq (difference quotients)
    character(len=optlen) :: nonlinear = 'auto'    !< auto (adams: fixedpoint, bdf: newton) | newton | fixedpoint
    logical  :: roots = .false.             !< locate the contact switches by root finding
    logical  :: stald = .false.             !< BDF stability-limit detection
    logical  :: linear_tail = .true.        !< closed-form tail once full contact is proven to last
    real(wp) :: rtol = 1.0e-8_wp, atol = 1.0e-10_wp   !< tolerances on the scaled states [-]
    integer  :: max_steps = 100000          !< CVODE steps allowed between two output times
    integer  :: max_total_steps = 20000000  !< CVODE steps allowed over the whole run (all restarts)
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
    real(wp) :: lyapunov_d0 = 0.0_wp        !< initial separation, scaled states of Eq. 25 [-]; 0: auto
    ! beyond the paper (docs/model.md "Beyond the paper")
    logical  :: fillet = .true.             !< fillet-foundation term in a computed k_m (Eq. 18 + k_f)
    real(wp) :: fillet_radius = 0.0_wp      !< root fillet radius [m]; 0 = 0.2 m (ISO 4156 flat root)
    real(wp) :: r_bore = 0.0_wp             !< bore radius of the external spline [m]; 0 = half its root radius
    real(wp) :: r_rim = 0.0_wp              !< outer radius of the internal spline's rim [m]; 0 = twice its root radius
    real(wp) :: zeta_m = 0.0_wp             !< mesh damping ratio [-]; > 0: c_m = 2 zeta_m sqrt(k_m m_e)
    real(wp) :: ripple_order(nripple) = 0.0_wp      !< torque ripple: engine orders n_k [-]
    real(wp) :: ripple_amp(nripple) = 0.0_wp        !< amplitudes a_k, relative to T_d [-]
    real(wp) :: ripple_phase_deg(nripple) = 0.0_wp  !< phases psi_k [deg]
    real(wp) :: unbalance(2) = 0.0_wp       !< mass unbalance m_u e of splines 1, 2 [kg m]
    real(wp) :: unbalance_phase_deg(2) = 0.0_wp     !< its phase beta_i [deg]
    real(wp) :: gamma_x = 0.0_wp, gamma_y = 0.0_wp  !< angular misalignment of spline 1 about x, y [rad]
    integer  :: n_slices = 1                !< face-width slices (angular misalignment) [-]
  end type case_t

  !> A field of the namelist: its name, type (i integer, r real, l logical, c character) and
  !> size (elements of an array, or the length of a character field). Same order as case_t
  !> and the namelist in nml_io (tests/test_input.py checks the table against the defaults).
  type :: field_t
    character(len=20) :: name
    character(len=1) :: kind
    integer :: n
  end type field_t
  integer, parameter :: nfields = 79
  type(field_t), parameter :: fields(nfields) = [ &
       field_t('name', 'c', namelen), field_t('z', 'i', 1), field_t('module_m', 'r', 1), &
       field_t('alpha_deg', 'r', 1), field_t('b', 'r', 1), field_t('s', 'r', 1), &
       field_t('c0', 'r', 1), field_t('e_mod', 'r', 1), field_t('nu', 'r', 1), &
       field_t('lambda_th', 'r', 1), field_t('k_cond', 'r', 1), field_t('rho', 'r', 1), &
       field_t('c_heat', 'r', 1), field_t('j_m', 'r', 1), field_t('j_l', 'r', 1), &
       field_t('j_1', 'r', 1), field_t('j_2', 'r', 1), field_t('m_1', 'r', 1), &
       field_t('m_2', 'r', 1), field_t('k_p1', 'r', 1), field_t('k_p2', 'r', 1), &
       field_t('c_p1', 'r', 1), field_t('c_p2', 'r', 1), field_t('k_t1', 'r', 1), &
       field_t('k_t2', 'r', 1), field_t('c_t1', 'r', 1), field_t('c_t2', 'r', 1), &
       field_t('k_m', 'r', 1), field_t('c_m', 'r', 1), field_t('t_d', 'r', 1), &
       field_t('t_l', 'r', 1), field_t('speed_rpm', 'r', 1), field_t('grav', 'r', 1), &
       field_t('l_x', 'r', 1), field_t('l_y', 'r', 1), field_t('dof', 'i', 1), &
       field_t('thermal', 'c', optlen), field_t('t_bulk', 'r', 1), field_t('f_m', 'r', 1), &
       field_t('u_flash', 'r', 1), field_t('eta_hertz', 'r', 1), field_t('method', 'c', optlen), &
       field_t('jacobian', 'c', optlen), field_t('nonlinear', 'c', optlen), &
       field_t('roots', 'l', 1), field_t('stald', 'l', 1), field_t('linear_tail', 'l', 1), &
       field_t('rtol', 'r', 1), &
       field_t('atol', 'r', 1), field_t('max_steps', 'i', 1), field_t('max_total_steps', 'i', 1), &
       field_t('t0', 'r', 1), field_t('t_end', 'r', 1), field_t('t_transient', 'r', 1), &
       field_t('n_out', 'i', 1), field_t('start', 'c', optlen), field_t('dq0', 'r', ndof_case), &
       field_t('dv0', 'r', ndof_case), field_t('l_ref', 'r', 1), field_t('w_ref', 'r', 1), &
       field_t('fidelity', 'c', optlen), field_t('fidelity_tol', 'r', 1), &
       field_t('section', 'c', optlen), field_t('lyapunov', 'l', 1), &
       field_t('lyapunov_interval', 'r', 1), field_t('lyapunov_d0', 'r', 1), &
       field_t('fillet', 'l', 1), field_t('fillet_radius', 'r', 1), field_t('r_bore', 'r', 1), &
       field_t('r_rim', 'r', 1), field_t('zeta_m', 'r', 1), field_t('ripple_order', 'r', nripple), &
       field_t('ripple_amp', 'r', nripple), field_t('ripple_phase_deg', 'r', nripple), &
       field_t('unbalance', 'r', 2), field_t('unbalance_phase_deg', 'r', 2), &
       field_t('gamma_x', 'r', 1), field_t('gamma_y', 'r', 1), field_t('n_slices', 'i', 1)]

  ! tokens of the case text
  integer, parameter :: tk_word = 1, tk_string = 2, tk_equals = 3, tk_comma = 4, tk_slash = 5, &
       tk_group = 6, tk_subscript = 7, tk_badstring = 8, tk_other = 9

  interface   ! fortran/fileinfo.c
    integer(c_int) function c_file_kind(path, size, errbuf, errlen) bind(C, name='spline_file_kind')
      import :: c_char, c_int, c_long_long
      character(kind=c_char), intent(in) :: path(*)
      integer(c_long_long), intent(out) :: size
      character(kind=c_char), intent(out) :: errbuf(*)
      integer(c_int), value :: errlen
    end function c_file_kind
  end interface

  interface   ! fortran/iolock.c: one lock around the parser's reads from internal files
    subroutine io_lock() bind(C, name='spline_io_lock')
    end subroutine io_lock
    subroutine io_unlock() bind(C, name='spline_io_unlock')
    end subroutine io_unlock
  end interface

contains

  !> Field number i of the namelist (1 .. nfields): name, type (i, r, l, c) and size.
  !> An empty name past the end.
  subroutine case_field(i, name, kind, n)
    integer, intent(in) :: i
    character(len=*), intent(out) :: name, kind
    integer, intent(out) :: n
    name = ''; kind = ''; n = 0
    if (i < 1 .or. i > nfields) return
    name = fields(i)%name; kind = fields(i)%kind; n = fields(i)%n
  end subroutine case_field

  !> Check that path names a regular file of at most max_case_bytes, before it is opened
  !> (a FIFO would block the open, a device never end). ierr = err_case with a message saying
  !> what the path is instead. pyspline.case._check_file says the same in the same words.
  subroutine case_check_file(path, nbytes, ierr, errmsg)
    character(len=*), intent(in) :: path
    integer(c_long_long), intent(out) :: nbytes
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    character(kind=c_char) :: buf(256)
    character(len=256) :: why
    integer(c_int) :: kind
    integer :: i
    buf = c_null_char
    kind = c_file_kind(path//c_null_char, nbytes, buf, int(size(buf), c_int))
    why = ''
    do i = 1, size(buf)
      if (buf(i) == c_null_char) exit
      why(i:i) = buf(i)
    end do
    ierr = err_case
    select case (kind)
    case (0)
      if (nbytes > max_case_bytes) then
        write(errmsg, '(a,i0,a,i0,a)') 'case file '//shown(path)//' is ', nbytes, &
             ' bytes: a case file holds at most ', max_case_bytes, ' bytes'
        return
      end if
      ierr = err_ok; errmsg = ''
    case (1); errmsg = 'case file '//shown(path)//' is a directory, not a case file'
    case (2); errmsg = 'case file '//shown(path)//' is a FIFO (named pipe), not a case file'
    case (3); errmsg = 'case file '//shown(path)//' is a character device, not a case file'
    case (4); errmsg = 'case file '//shown(path)//' is a block device, not a case file'
    case (5); errmsg = 'case file '//shown(path)//' is a socket, not a case file'
    case (6); errmsg = 'case file '//shown(path)//' is not a regular file'
    case (-1); errmsg = 'case file '//shown(path)//' does not exist'
    case (-2); errmsg = 'case file '//shown(path)//' does not exist (a dangling symbolic link)'
    case (-3); errmsg = 'case file '//shown(path)//': '//trim(why)//' (a symbolic-link loop)'
    case default; errmsg = 'case file '//shown(path)//': '//trim(why)
    end select
  end subroutine case_check_file

  !> Read a case from a namelist file (group &spline_case): the file is checked
  !> (case_check_file), read whole and parsed (case_parse). Fields not given keep their
  !> defaults; the name defaults to the file's stem.
  subroutine case_read_file(path, c, ierr, errmsg)
    character(len=*), intent(in) :: path
    type(case_t), intent(out) :: c
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    integer(c_long_long) :: nbytes
    character(len=:), allocatable :: text
    character(len=256) :: iomsg
    integer :: u, ios
    c = case_t()
    c%name = case_name_of(path)
    call case_check_file(path, nbytes, ierr, errmsg)
    if (ierr /= err_ok) return
    allocate(character(len=int(nbytes)) :: text)
    open(newunit=u, file=path, status='old', action='read', access='stream', form='unformatted', &
         iostat=ios, iomsg=iomsg)
    if (ios == 0 .and. nbytes > 0) read(u, iostat=ios, iomsg=iomsg) text
    if (ios == 0) then
      close(u)
    else
      close(u, iostat=ierr)
      errmsg = 'case file '//shown(path)//': cannot read it: '//trim(iomsg)
      ierr = err_case; return
    end if
    call case_parse(text, c, ierr, errmsg, path)
  end subroutine case_read_file

  !> Read a case from namelist text held in memory (what pyspline's Case.text() writes):
  !> defaults for the fields not given; messages name the case but no line.
  subroutine case_read_text(text, c, ierr, errmsg)
    character(len=*), intent(in) :: text
    type(case_t), intent(out) :: c
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    c = case_t()
    call case_parse(text, c, ierr, errmsg)
  end subroutine case_read_text

  !> Parse namelist text (one group &spline_case) into c: the fields it gives replace c's,
  !> the others keep their values (defaults, or a case being amended: spline-dyn --set).
  !> origin: the file the text came from (messages say 'case NAME (origin, line N)'); absent or
  !> empty: 'case NAME' only. show_lines = .false. leaves the line out (one-line texts).
  !> Nothing is changed unless the whole text is valid. Refused, with ierr = err_case and a
  !> message naming the line, the field and what was expected: a missing or misspelt group,
  !> text outside the group, a second group, no closing '/', an unknown field (with the
  !> nearest name), a missing '=', a value of the wrong type (a number for a logical, a
  !> string for a number, an unquoted string), an integer beyond 32 bits, a number beyond
  !> the largest double, a string longer than its field (blank padding aside), more values
  !> than elements (a decimal comma), a subscript outside the array, an unclosed string, a
  !> field given twice, and control characters (not a text file).
  subroutine case_parse(text, c, ierr, errmsg, origin, show_lines)
    character(len=*), intent(in) :: text
    type(case_t), intent(inout) :: c
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    character(len=*), intent(in), optional :: origin
    logical, intent(in), optional :: show_lines
    call io_lock()           ! internal reads are not thread-safe in libgfortran (iolock.c)
    call parse_unlocked(text, c, ierr, errmsg, origin, show_lines)
    call io_unlock()
  end subroutine case_parse

  subroutine parse_unlocked(text, c, ierr, errmsg, origin, show_lines)
    character(len=*), intent(in) :: text
    type(case_t), intent(inout) :: c
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    character(len=*), intent(in), optional :: origin
    logical, intent(in), optional :: show_lines
    integer, allocatable :: tk(:), ta(:), tb(:), tl(:)
    integer, allocatable :: set_line(:, :)
    character(len=:), allocatable :: recs(:), from
    character(len=256) :: iomsg
    integer :: ntok, p, f, i0, i1, group_line, nrec
    logical :: lines_on
    type(case_t) :: work
    character(len=namelen) :: name_now

    ierr = err_ok
    errmsg = ''
    from = ''
    if (present(origin)) from = shown(origin)
    lines_on = len(from) > 0
    if (present(show_lines)) lines_on = lines_on .and. show_lines
    name_now = c%name
    allocate(character(len=2*namelen + 48) :: recs(nfields*ndof_case + 2))

    call tokenize()
    if (ierr /= err_ok) return

    ! the group opener
    p = 1
    if (ntok == 0) then
      call fail(0, 'no group &spline_case: the text is empty or holds only comments'); return
    end if
    select case (tk(1))
    case (tk_group)
      if (lower(tok(1)) /= 'spline_case') then
        call fail(tl(1), 'found the group &'//tok(1)//' where &spline_case was expected'); return
      end if
    case (tk_word)
      if (lower(tok(1)) == 'spline_case') then
        call fail(tl(1), 'the group name spline_case lacks its ''&'': write &spline_case'); return
      end if
      call fail(tl(1), 'expected the group &spline_case, found '''//clip(tok(1))//''''); return
    case default
      call fail(tl(1), 'expected the group &spline_case, found '''//clip(tok(1))//''''); return
    end select
    group_line = tl(1)
    p = 2

    ! the items, checked first (nothing assigned yet), each element to one record in its
    ! canonical form (short, whatever the text held: no element is given twice, so there are
    ! at most nfields x 7 records)
    allocate(set_line(nfields, ndof_case))
    set_line = 0
    nrec = 1
    recs(1) = '&spline_case'
    do
      if (p > ntok) then
        call fail(tl(ntok), 'the group &spline_case opened on line '//itoa(group_line)// &
             ' is not closed by ''/'''); return
      end if
      if (tk(p) == tk_slash) exit
      if (tk(p) == tk_group) then
        if (lower(tok(p)) == 'end') exit
        call fail(tl(p), 'the group &'//tok(p)//' begins before ''/'' closes &spline_case'); return
      end if
      if (tk(p) == tk_comma) then              ! a separator between items
        p = p + 1; cycle
      end if
      call item()
      if (ierr /= err_ok) return
    end do
    ! after the group: comments only
    if (p < ntok) then
      if (tk(p + 1) == tk_group) then
        call fail(tl(p + 1), 'a second group &'//tok(p + 1)//': a case file holds one group '// &
             '&spline_case'); return
      end if
      call fail(tl(p + 1), 'text after the end of the group &spline_case: '''// &
           clip(tok(p + 1))//''''); return
    end if
    nrec = nrec + 1
    recs(nrec) = '/'

    ! the checked elements, read by the namelist input into a copy, then kept
    work = c
    call nml_io(work, ierr, iomsg, lines=recs(1:nrec))
    if (ierr /= 0) then
      call fail(0, 'the namelist input refused the checked text: '//trim(iomsg)); return
    end if
    c = work
    ierr = err_ok

  contains

    !> One item: NAME [(subscript)] = values.
    subroutine item()
      character(len=:), allocatable :: name
      integer :: lo, hi, k, r, q, line, pv
      logical :: after_sep
      character(len=:), allocatable :: v, canon
      line = tl(p)
      if (tk(p) /= tk_word) then
        select case (tk(p))
        case (tk_equals); call fail(line, '''='' without a field name before it')
        case (tk_string, tk_badstring)
          call fail(line, 'expected a field name, found the string '//clip(tok(p)))
        case default; call fail(line, 'expected a field name, found '''//clip(tok(p))//'''')
        end select
        return
      end if
      name = lower(tok(p))
      f = field_index(name)
      if (f == 0) then
        call fail(line, 'unknown field '''//clip(tok(p))//''''//hint(name)); return
      end if
      p = p + 1
      lo = 1; hi = fields(f)%n
      if (fields(f)%kind == 'c') hi = 1
      if (p <= ntok) then
        if (tk(p) == tk_subscript) then
          if (hi == 1) then
            call fail(line, 'field '//trim(fields(f)%name)//' is not an array: no subscript ('// &
                 clip(tok(p))//')'); return
          end if
          call subscript(tok(p), lo, hi)
          if (ierr /= err_ok) return
          p = p + 1
        end if
      end if
      if (p > ntok) then
        call fail(line, 'field '//trim(fields(f)%name)//': expected ''='' after the field name, '// &
             'found the end of the text'); return
      end if
      if (tk(p) /= tk_equals) then
        call fail(line, 'field '//trim(fields(f)%name)//': expected ''='' after the field name, '// &
             'found '''//clip(tok(p))//''''); return
      end if
      p = p + 1
      ! values up to the next item, '/' or the end; null values (the element keeps its value):
      ! nothing between '=' or a comma and the next comma, and r*; 'name =' alone is one null
      after_sep = .true.        ! just after '=' or a comma
      k = lo
      do while (p <= ntok)
        if (ends_values(p)) exit
        select case (tk(p))
        case (tk_comma)
          if (after_sep) then           ! a null value: the element keeps its value
            if (k > hi) then
              call too_many(1); return
            end if
            k = k + 1
          end if
          after_sep = .true.
          p = p + 1; cycle
        case (tk_badstring)
          call fail(tl(p), 'field '//trim(fields(f)%name)//': the string '//clip(tok(p))// &
               ' is not closed on its line (a missing '//tok_first(p)//')'); return
        case (tk_equals)
          call fail(tl(p), 'field '//trim(fields(f)%name)//': a second ''='''); return
        case (tk_subscript, tk_other)
          call fail(tl(p), 'field '//trim(fields(f)%name)//': unexpected '''//clip(tok(p))// &
               ''''); return
        end select
        ! a word that names a field, or begins a line and is no value of this field: the
        ! '=' after a field name is missing
        if (tk(p) == tk_word) then
          if (field_index(lower(tok(p))) > 0) then
            call fail(tl(p), 'field '//lower(tok(p))//': expected ''='' after the field name, '// &
                 'found '//after(p)); return
          end if
          if (tl(p) > tl(p - 1) .and. .not. is_value(f, tok(p))) then
            call fail(tl(p), ''''//clip(tok(p))//''' is neither a field nor a value of field '// &
                 trim(fields(f)%name)//' (a missing ''=''?)'//hint(lower(tok(p)))); return
          end if
        end if
        ! a value: [r*]constant or r*
        v = tok(p)
        pv = p
        r = 1
        if (tk(p) == tk_word) then
          q = index(v, '*')
          if (q > 0) then
            if (.not. is_digits(v(1:q-1))) then
              call fail(tl(p), 'field '//trim(fields(f)%name)//' = '//clip(v)//': expected '// &
                   expected(f)); return
            end if
            if (q - 1 > 9) then
              r = huge(0)
            else
              read(v(1:q-1), *) r
            end if
            if (r < 1) then
              call fail(tl(p), 'field '//trim(fields(f)%name)//' = '//clip(v)//': a repeat count '// &
                   'must be at least 1'); return
            end if
            v = v(q+1:)
            if (len(v) == 0 .and. p < ntok) then     ! r*'string'
              if (tk(p + 1) == tk_string .and. ta(p + 1) == tb(p) + 1) then
                p = p + 1
                v = tok(p)
              end if
            end if
          end if
        end if
        if (r > hi - k + 1 .or. k > hi) then
          call too_many(r); return
        end if
        if (len(v) > 0) then
          call check_value(v, tk(p), tl(p), canon)
          if (ierr /= err_ok) return
          do q = k, k + r - 1
            if (set_line(f, q) /= 0) then
              call fail(tl(pv), 'field '//trim(element(f, q))//' is given twice (lines '// &
                   itoa(set_line(f, q))//' and '//itoa(tl(pv))//')'); return
            end if
            set_line(f, q) = tl(pv)
            nrec = nrec + 1
            recs(nrec) = trim(element(f, q))//' = '//canon
          end do
        end if
        k = k + r
        after_sep = .false.
        p = p + 1
      end do
    end subroutine item

    !> More values than the field (from the subscript on) holds.
    subroutine too_many(r)
      integer, intent(in) :: r
      integer :: total, q, nn
      logical :: digits_only
      character(len=:), allocatable :: why
      ! count every value of this item (for the message)
      total = 0; digits_only = .true.; nn = 0
      q = p
      do while (q <= ntok)
        if (ends_values(q)) exit
        if (tk(q) == tk_word .or. tk(q) == tk_string) then
          nn = nn + 1
          if (.not. is_digits(tok(q))) digits_only = .false.
        end if
        q = q + 1
      end do
      if (fields(f)%n == 1 .or. fields(f)%kind == 'c') then
        why = 'field '//trim(fields(f)%name)//': more than one value for a single '// &
             trim(kind_word(fields(f)%kind))
        if (fields(f)%kind == 'r' .and. digits_only .and. nn > 0) why = why//' (a decimal comma? use a '// &
             'decimal point, e.g. 0.001)'
      else
        why = 'field '//trim(fields(f)%name)//': more values than its '// &
             itoa(fields(f)%n)//' elements'
      end if
      if (r > 1 .and. nn == 1) why = why//' (repeat count '//itoa(r)//')'
      call fail(tl(p), why)
    end subroutine too_many

    !> The value v (a token of kind kind) for field f; canon: the value as the namelist input
    !> gets it (a whole number, a real to 17 digits, .true./.false., a quoted string).
    subroutine check_value(v, kind, line, canon)
      character(len=*), intent(in) :: v
      integer, intent(in) :: kind, line
      character(len=:), allocatable, intent(out) :: canon
      character(len=:), allocatable :: content
      real(wp) :: x
      integer(8) :: iv
      integer :: ios, n0
      character(len=len(v)) :: u
      character(len=32) :: buf
      canon = ''
      select case (fields(f)%kind)
      case ('i')
        if (kind /= tk_word .or. .not. is_integer(v)) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)//': expected '// &
               expected(f)); return
        end if
        n0 = verify(v, '+-0')          ! first significant digit
        if (n0 == 0) then              ! zero
          canon = '0'; return
        end if
        if (len(v) - n0 + 1 > 10) then
          ios = 1
        else
          read(v, *, iostat=ios) iv
          if (ios == 0 .and. abs(iv) > huge(0)) ios = 1
        end if
        if (ios /= 0) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)// &
               ' does not fit a 32-bit integer (at most '//itoa(huge(0))//')'); return
        end if
        canon = itoa(int(iv))
      case ('r')
        if (kind /= tk_word .or. .not. is_real(v)) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)//': expected '// &
               expected(f)); return
        end if
        u = v
        do n0 = 1, len(u)
          if (index('dDqQ', u(n0:n0)) > 0) u(n0:n0) = 'e'
        end do
        read(u, *, iostat=ios) x
        if (ios /= 0) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)//': expected '// &
               expected(f)); return
        end if
        if (.not. ieee_is_finite(x) .and. .not. ieee_is_nan(x) .and. index(lower(v), 'inf') == 0) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)// &
               ' is beyond the largest number (1.8e308)'); return
        end if
        if (ieee_is_nan(x)) then
          canon = 'NaN'                ! (refused by case_validate, naming the field)
        else if (.not. ieee_is_finite(x)) then
          canon = trim(merge('+Infinity', '-Infinity', x > 0.0_wp))
        else
          write(buf, '(es25.17e3)') x
          canon = trim(adjustl(buf))
        end if
      case ('l')
        if (kind /= tk_word .or. .not. is_logical(v)) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)//': expected '// &
               expected(f)); return
        end if
        canon = '.false.'
        if (index('tT', v(verify(v, '.'):verify(v, '.'))) > 0) canon = '.true.'
      case ('c')
        if (kind /= tk_string) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)//': expected '// &
               expected(f)//', e.g. '''//clip(v)//''''); return
        end if
        content = unquote(v)
        if (len_trim(content) > fields(f)%n) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)//' is longer than '// &
               itoa(fields(f)%n)//' characters'); return
        end if
        canon = quoted(trim(content))
        if (f == 1) name_now = content
      end select
    end subroutine check_value

    !> (i) or (i:j) for field f: the elements lo..hi.
    subroutine subscript(s, lo, hi)
      character(len=*), intent(in) :: s
      integer, intent(inout) :: lo, hi
      character(len=:), allocatable :: inner
      integer :: colon, ios, n, a, b
      n = fields(f)%n
      inner = trim(adjustl(s(2:len(s)-1)))
      colon = index(inner, ':')
      ios = 1
      if (colon == 0) then
        if (is_integer(inner) .and. len(inner) < 10) then
          read(inner, *, iostat=ios) a
          b = a
        end if
      else
        if (is_integer(trim(adjustl(inner(1:colon-1)))) .and. is_integer(trim(adjustl(inner(colon+1:)))) &
             .and. len(inner) < 20) then
          read(inner(1:colon-1), *, iostat=ios) a
          if (ios == 0) read(inner(colon+1:), *, iostat=ios) b
        end if
      end if
      if (ios /= 0) then
        call fail(tl(p), 'field '//trim(fields(f)%name)//s//': expected an element number '// &
             '1 to '//itoa(n)); return
      end if
      if (a < 1 .or. a > n .or. b < a .or. b > n) then
        call fail(tl(p), 'field '//trim(fields(f)%name)//s//': element outside 1 to '//itoa(n)); return
      end if
      lo = a; hi = b
    end subroutine subscript

    !> Split the text into tokens (tk kind, ta:tb its characters, tl its line).
    subroutine tokenize()
      integer :: i, j, n, line, cap
      character :: ch, q
      n = len(text)
      cap = 64
      allocate(tk(cap), ta(cap), tb(cap), tl(cap))
      ntok = 0
      line = 1
      i = 1
      do while (i <= n)
        ch = text(i:i)
        if (ch == new_line('a')) then
          line = line + 1; i = i + 1; cycle
        end if
        if (ch == ' ' .or. ch == char(9) .or. ch == char(13) .or. ch == char(12)) then
          i = i + 1; cycle
        end if
        if (iachar(ch) < 32 .or. iachar(ch) == 127) then
          call control(i, line); return
        end if
        select case (ch)
        case ('!')
          j = index(text(i:), new_line('a'))
          if (j == 0) then
            j = n + 1
          else
            j = i + j - 1
          end if
          do i0 = i, j - 1          ! control characters in a comment too: not a text file
            if ((iachar(text(i0:i0)) < 32 .and. index(char(9)//char(13)//char(12), text(i0:i0)) == 0) &
                 .or. iachar(text(i0:i0)) == 127) then
              call control(i0, line); return
            end if
          end do
          i = j
        case ('''', '"')
          q = ch
          j = i + 1
          do
            if (j > n) exit
            if (text(j:j) == new_line('a')) exit
            if (iachar(text(j:j)) < 32 .and. text(j:j) /= char(9) .and. text(j:j) /= char(13)) then
              call control(j, line); return
            end if
            if (text(j:j) == q) then
              if (j < n) then
                if (text(j+1:j+1) == q) then
                  j = j + 2; cycle
                end if
              end if
              exit
            end if
            j = j + 1
          end do
          if (j <= n) then
            if (text(j:j) == q) then            ! closed
              call push(tk_string, i, j, line)
              i = j + 1
              cycle
            end if
          end if
          i1 = j - 1                            ! not closed on its line: up to the line's end
          if (i1 > i) then
            if (text(i1:i1) == char(13)) i1 = i1 - 1
          end if
          call push(tk_badstring, i, i1, line)
          i = j
        case ('=')
          call push(tk_equals, i, i, line); i = i + 1
        case (',')
          call push(tk_comma, i, i, line); i = i + 1
        case ('/')
          call push(tk_slash, i, i, line); i = i + 1
        case ('&', '$')
          j = i + 1
          do while (j <= n)
            if (.not. word_char(text(j:j))) exit
            j = j + 1
          end do
          call push(tk_group, i + 1, j - 1, line)
          i = j
        case ('(')
          j = i + 1
          do while (j <= n)
            if (text(j:j) == ')' .or. text(j:j) == new_line('a')) exit
            j = j + 1
          end do
          if (j <= n) then
            if (text(j:j) == ')') then
              call push(tk_subscript, i, j, line)
              i = j + 1
              cycle
            end if
          end if
          call push(tk_other, i, i, line); i = i + 1
        case (')', ';')
          call push(tk_other, i, i, line); i = i + 1
        case default
          j = i
          do while (j <= n)
            if (.not. word_char(text(j:j))) exit
            j = j + 1
          end do
          call push(tk_word, i, j - 1, line)
          i = j
        end select
      end do
    end subroutine tokenize

    subroutine push(kind, a, b, line)
      integer, intent(in) :: kind, a, b, line
      integer, allocatable :: t(:)
      integer :: cap
      if (ntok == size(tk)) then
        cap = 2*size(tk)
        allocate(t(cap)); t(1:ntok) = tk(1:ntok); call move_alloc(t, tk)
        allocate(t(cap)); t(1:ntok) = ta(1:ntok); call move_alloc(t, ta)
        allocate(t(cap)); t(1:ntok) = tb(1:ntok); call move_alloc(t, tb)
        allocate(t(cap)); t(1:ntok) = tl(1:ntok); call move_alloc(t, tl)
      end if
      ntok = ntok + 1
      tk(ntok) = kind; ta(ntok) = a; tb(ntok) = b; tl(ntok) = line
    end subroutine push

    subroutine control(i, line)
      integer, intent(in) :: i, line
      character(len=2) :: hex
      integer :: col
      write(hex, '(z2.2)') iachar(text(i:i))
      col = i - index(text(1:i), new_line('a'), back=.true.)
      call fail(line, 'byte 0x'//hex//' at column '//itoa(col)//' is a control character: '// &
           'this is not a text file')
    end subroutine control

    !> Token q ends the values of an item: '/', the next group, or the next item's name.
    logical function ends_values(q)
      integer, intent(in) :: q
      ends_values = tk(q) == tk_slash .or. tk(q) == tk_group
      if (.not. ends_values .and. tk(q) == tk_word) ends_values = next_is_item(q)
    end function ends_values

    !> A word at token q starts the next item: NAME = or NAME(...) =.
    logical function next_is_item(q)
      integer, intent(in) :: q
      next_is_item = .false.
      if (q + 1 > ntok) return
      if (tk(q + 1) == tk_equals) then
        next_is_item = .true.
      else if (tk(q + 1) == tk_subscript .and. q + 2 <= ntok) then
        next_is_item = tk(q + 2) == tk_equals
      end if
    end function next_is_item

    function tok(q) result(s)
      integer, intent(in) :: q
      character(len=:), allocatable :: s
      s = text(ta(q):tb(q))
    end function tok

    !> The token after q, for messages: 'TEXT' or the end of the text.
    function after(q) result(s)
      integer, intent(in) :: q
      character(len=:), allocatable :: s
      if (q < ntok) then
        s = ''''//clip(tok(q + 1))//''''
      else
        s = 'the end of the text'
      end if
    end function after

    function tok_first(q) result(s)
      integer, intent(in) :: q
      character(len=1) :: s
      s = text(ta(q):ta(q))
    end function tok_first

    !> The message prefix 'case NAME (origin, line N): ' and the reason.
    subroutine fail(line, why)
      integer, intent(in) :: line
      character(len=*), intent(in) :: why
      character(len=:), allocatable :: where
      where = 'case '//trim(name_now)
      if (len(from) > 0) then
        if (lines_on .and. line > 0) then
          where = where//' ('//from//', line '//itoa(line)//')'
        else
          where = where//' ('//from//')'
        end if
      end if
      errmsg = where//': '//why
      ierr = err_case
    end subroutine fail

  end subroutine parse_unlocked

  !> A word w is a constant of field f's type (a repeat r*c counts by its constant).
  pure logical function is_value(f, w)
    integer, intent(in) :: f
    character(len=*), intent(in) :: w
    integer :: q
    q = index(w, '*')
    if (q > 0) then
      is_value = is_digits(w(1:q-1))
      if (is_value .and. q < len(w)) is_value = is_value_plain(w(q+1:))
    else
      is_value = is_value_plain(w)
    end if
  contains
    pure logical function is_value_plain(v)
      character(len=*), intent(in) :: v
      select case (fields(f)%kind)
      case ('i'); is_value_plain = is_integer(v)
      case ('r'); is_value_plain = is_real(v)
      case ('l'); is_value_plain = is_logical(v)
      case default; is_value_plain = .false.
      end select
    end function is_value_plain
  end function is_value

  !> What field f expects, for messages.
  function expected(f) result(s)
    integer, intent(in) :: f
    character(len=:), allocatable :: s
    select case (fields(f)%kind)
    case ('i'); s = 'a whole number'
    case ('r'); s = 'a number (e.g. 1.5e-3)'
    case ('l'); s = '.true. or .false.'
    case default; s = 'a quoted string of at most '//itoa(fields(f)%n)//' characters'
    end select
  end function expected

  function kind_word(k) result(s)
    character(len=1), intent(in) :: k
    character(len=:), allocatable :: s
    select case (k)
    case ('i'); s = 'whole number'
    case ('r'); s = 'number'
    case ('l'); s = 'logical'
    case default; s = 'string'
    end select
  end function kind_word

  !> NAME or NAME(k) for element k of field f.
  function element(f, k) result(s)
    integer, intent(in) :: f, k
    character(len=:), allocatable :: s
    s = trim(fields(f)%name)
    if (fields(f)%n > 1 .and. fields(f)%kind /= 'c') s = s//'('//itoa(k)//')'
  end function element

  !> ': did you mean NAME?' for the nearest field, or a pointer to the list of fields.
  function hint(word) result(s)
    character(len=*), intent(in) :: word
    character(len=:), allocatable :: s
    character(len=20) :: best
    best = case_suggest(word)
    if (len_trim(best) > 0) then
      s = ': did you mean '//trim(best)//'?'
    else
      s = ' (cases/template.nml lists every field)'
    end if
  end function hint

  !> The field name nearest to word (Damerau-Levenshtein distance at most 2, and less than
  !> the word's length; or the one field the word begins), else blank.
  function case_suggest(word) result(best)
    character(len=*), intent(in) :: word
    character(len=20) :: best
    character(len=:), allocatable :: w
    integer :: i, d, dbest, nprefix, iprefix
    w = lower(trim(adjustl(word)))
    best = ''
    dbest = huge(0)
    nprefix = 0; iprefix = 0
    if (len(w) == 0 .or. len(w) > 64) return
    do i = 1, nfields
      d = distance(w, trim(fields(i)%name))
      if (d < dbest) then
        dbest = d; best = fields(i)%name
      end if
      if (len(w) >= 4 .and. index(fields(i)%name, w) == 1) then
        nprefix = nprefix + 1; iprefix = i
      end if
    end do
    if (dbest == 0) return
    if (dbest <= 2 .and. dbest < len(w)) return
    best = ''
    if (nprefix == 1) best = fields(iprefix)%name
  end function case_suggest

  !> Optimal-string-alignment distance (insertions, deletions, substitutions, transpositions).
  pure integer function distance(a, b) result(dist)
    character(len=*), intent(in) :: a, b
    integer :: d(0:len(a), 0:len(b)), i, j, cost
    do i = 0, len(a)
      d(i, 0) = i
    end do
    do j = 0, len(b)
      d(0, j) = j
    end do
    do i = 1, len(a)
      do j = 1, len(b)
        cost = merge(0, 1, a(i:i) == b(j:j))
        d(i, j) = min(d(i-1, j) + 1, d(i, j-1) + 1, d(i-1, j-1) + cost)
        if (i > 1 .and. j > 1) then
          if (a(i:i) == b(j-1:j-1) .and. a(i-1:i-1) == b(j:j)) d(i, j) = min(d(i, j), d(i-2, j-2) + 1)
        end if
      end do
    end do
    dist = d(len(a), len(b))
  end function distance

  pure integer function field_index(name) result(f)
    character(len=*), intent(in) :: name
    do f = 1, nfields
      if (fields(f)%name == name) return
    end do
    f = 0
  end function field_index

  pure logical function word_char(ch)
    character, intent(in) :: ch
    word_char = .not. (ch == ' ' .or. iachar(ch) < 32 .or. iachar(ch) == 127 .or. &
         index(',/=()!''"&$;', ch) > 0)
  end function word_char

  pure logical function is_digits(s)
    character(len=*), intent(in) :: s
    is_digits = len(s) > 0 .and. verify(s, '0123456789') == 0
  end function is_digits

  pure logical function is_integer(s)
    character(len=*), intent(in) :: s
    integer :: i0
    i0 = 1
    if (len(s) > 0) then
      if (s(1:1) == '+' .or. s(1:1) == '-') i0 = 2
    end if
    is_integer = is_digits(s(i0:))
  end function is_integer

  !> A real constant: [sign] digits [. [digits]] | [sign] . digits, then an optional exponent
  !> (e, d or q, optional sign, digits); or [sign] NaN, Inf, Infinity (any case).
  pure logical function is_real(s)
    character(len=*), intent(in) :: s
    integer :: i, n, nd
    character(len=len(s)) :: l
    is_real = .false.
    n = len(s)
    i = 1
    if (n == 0) return
    if (s(1:1) == '+' .or. s(1:1) == '-') i = 2
    l = lower(s)
    if (i <= n) then
      if (l(i:) == 'nan' .or. l(i:) == 'inf' .or. l(i:) == 'infinity') then
        is_real = .true.; return
      end if
    end if
    nd = 0
    do while (i <= n)
      if (index('0123456789', s(i:i)) == 0) exit
      i = i + 1; nd = nd + 1
    end do
    if (i <= n) then
      if (s(i:i) == '.') then
        i = i + 1
        do while (i <= n)
          if (index('0123456789', s(i:i)) == 0) exit
          i = i + 1; nd = nd + 1
        end do
      end if
    end if
    if (nd == 0) return
    if (i <= n) then
      if (index('eEdDqQ', s(i:i)) == 0) return
      i = i + 1
      if (i <= n) then
        if (s(i:i) == '+' .or. s(i:i) == '-') i = i + 1
      end if
      if (i > n) return
      if (verify(s(i:), '0123456789') /= 0) return
    end if
    is_real = .true.
  end function is_real

  !> Fortran's logical constants: T, F, .T., .F., .TRUE., .FALSE. (any case, the dots optional).
  pure logical function is_logical(s)
    character(len=*), intent(in) :: s
    character(len=len(s)) :: l
    integer :: a, b
    l = lower(s)
    a = 1; b = len(l)
    if (b == 0) then
      is_logical = .false.; return
    end if
    if (l(1:1) == '.') a = 2
    if (b >= a) then
      if (l(b:b) == '.') b = b - 1
    end if
    is_logical = .false.
    if (b < a) return
    is_logical = l(a:b) == 't' .or. l(a:b) == 'f' .or. l(a:b) == 'true' .or. l(a:b) == 'false'
  end function is_logical

  !> The characters of a quoted string (doubled quotes collapsed).
  pure function unquote(v) result(s)
    character(len=*), intent(in) :: v
    character(len=:), allocatable :: s
    character(len=max(len(v) - 2, 0)) :: buf
    character :: q
    integer :: i, n, k
    q = v(1:1)
    n = len(v) - 1
    i = 2
    k = 0
    do while (i <= n)
      k = k + 1
      buf(k:k) = v(i:i)
      if (v(i:i) == q) i = i + 1
      i = i + 1
    end do
    s = buf(1:k)
  end function unquote

  !> s in apostrophes, its apostrophes doubled (a namelist string constant).
  pure function quoted(s) result(q)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: q
    character(len=2*len(s) + 2) :: buf
    integer :: i, k
    buf(1:1) = ''''
    k = 1
    do i = 1, len(s)
      k = k + 1
      buf(k:k) = s(i:i)
      if (s(i:i) == '''') then
        k = k + 1
        buf(k:k) = ''''
      end if
    end do
    k = k + 1
    buf(k:k) = ''''
    q = buf(1:k)
  end function quoted

  pure function lower(s) result(l)
    character(len=*), intent(in) :: s
    character(len=len(s)) :: l
    integer :: i, k
    l = s
    do i = 1, len(s)
      k = iachar(s(i:i))
      if (k >= iachar('A') .and. k <= iachar('Z')) l(i:i) = achar(k + 32)
    end do
  end function lower

  !> A path as messages show it: whole up to 240 characters, else '...' and its last 237
  !> (pyspline.case._shown says the same).
  pure function shown(path) result(s)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: s
    if (len(path) > 240) then
      s = '...'//path(len(path)-236:)
    else
      s = path
    end if
  end function shown

  !> At most 40 characters of a token, for messages.
  pure function clip(s) result(c)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: c
    if (len(s) > 40) then
      c = s(1:37)//'...'
    else
      c = s
    end if
  end function clip

  !> A case as namelist text (every field, one per line): Python reads the defaults from it.
  subroutine case_write_text(c, text)
    type(case_t), intent(in) :: c
    character(len=:), allocatable, intent(out) :: text
    type(case_t) :: cc
    character(len=256) :: lines(120), iomsg
    integer :: i, ierr
    lines = ''
    cc = c
    call io_lock()           ! namelist I/O is not thread-safe in libgfortran (iolock.c)
    call nml_io(cc, ierr, iomsg, out=lines)
    call io_unlock()
    text = ''
    do i = 1, size(lines)
      if (len_trim(lines(i)) > 0) text = text//trim(lines(i))//new_line('a')
    end do
  end subroutine case_write_text

  !> The namelist group &spline_case over local variables (one per case_t component, in the
  !> same order): copy the case in, then read into it (unit or records) or write it out.
  !> Callers hold io_lock (case_parse, case_write_text): namelist I/O on internal files is not
  !> thread-safe in libgfortran (iolock.c).
  subroutine nml_io(c, ierr, iomsg, unit, lines, out)
    type(case_t), intent(inout) :: c
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: iomsg
    integer, intent(in), optional :: unit
    character(len=*), intent(in), optional :: lines(:)
    character(len=*), intent(out), optional :: out(:)
    character(len=namelen) :: name
    integer :: z, dof, max_steps, max_total_steps, n_out
    real(wp) :: module_m, alpha_deg, b, s, c0, e_mod, nu, lambda_th, k_cond, rho, c_heat, j_m, j_l, j_1, &
         j_2, m_1, m_2, k_p1, k_p2, c_p1, c_p2, k_t1, k_t2, c_t1, c_t2, k_m, c_m, t_d, t_l, &
         speed_rpm, grav, l_x, l_y, t_bulk, f_m, u_flash, eta_hertz, rtol, atol, t0, t_end, &
         t_transient, dq0(ndof_case), dv0(ndof_case), l_ref, w_ref, fidelity_tol
    character(len=optlen) :: thermal, method, jacobian, nonlinear, start, fidelity, section
    logical :: roots, stald, lyapunov, linear_tail
    real(wp) :: lyapunov_interval, lyapunov_d0
    logical :: fillet
    real(wp) :: fillet_radius, r_bore, r_rim, zeta_m, ripple_order(nripple), ripple_amp(nripple), &
         ripple_phase_deg(nripple), unbalance(2), unbalance_phase_deg(2), gamma_x, gamma_y
    integer :: n_slices
    namelist /spline_case/ name, z, module_m, alpha_deg, b, s, c0, e_mod, nu, lambda_th, k_cond, rho, c_heat, j_m, &
         j_l, j_1, j_2, m_1, m_2, k_p1, k_p2, c_p1, c_p2, k_t1, k_t2, c_t1, c_t2, k_m, c_m, t_d, &
         t_l, speed_rpm, grav, l_x, l_y, dof, thermal, t_bulk, f_m, u_flash, eta_hertz, method, &
         jacobian, nonlinear, roots, stald, linear_tail, rtol, atol, max_steps, max_total_steps, &
         t0, t_end, &
         t_transient, n_out, start, dq0, dv0, l_ref, w_ref, fidelity, fidelity_tol, section, &
         lyapunov, lyapunov_interval, lyapunov_d0, fillet, fillet_radius, r_bore, r_rim, zeta_m, &
         ripple_order, ripple_amp, ripple_phase_deg, unbalance, unbalance_phase_deg, gamma_x, &
         gamma_y, n_slices
    name = c%name; z = c%z; module_m = c%module_m; alpha_deg = c%alpha_deg; b = c%b; s = c%s
    c0 = c%c0; e_mod = c%e_mod; nu = c%nu; lambda_th = c%lambda_th; k_cond = c%k_cond
    rho = c%rho; c_heat = c%c_heat; j_m = c%j_m; j_l = c%j_l; j_1 = c%j_1; j_2 = c%j_2
    m_1 = c%m_1; m_2 = c%m_2; k_p1 = c%k_p1; k_p2 = c%k_p2; c_p1 = c%c_p1; c_p2 = c%c_p2
    k_t1 = c%k_t1; k_t2 = c%k_t2; c_t1 = c%c_t1; c_t2 = c%c_t2; k_m = c%k_m; c_m = c%c_m
    t_d = c%t_d; t_l = c%t_l; speed_rpm = c%speed_rpm; grav = c%grav; l_x = c%l_x; l_y = c%l_y
    dof = c%dof; thermal = c%thermal; t_bulk = c%t_bulk; f_m = c%f_m; u_flash = c%u_flash
    eta_hertz = c%eta_hertz; method = c%method; jacobian = c%jacobian; nonlinear = c%nonlinear
    roots = c%roots; stald = c%stald; linear_tail = c%linear_tail; rtol = c%rtol; atol = c%atol
    max_steps = c%max_steps
    max_total_steps = c%max_total_steps
    t0 = c%t0; t_end = c%t_end; t_transient = c%t_transient; n_out = c%n_out; start = c%start
    dq0 = c%dq0; dv0 = c%dv0; l_ref = c%l_ref; w_ref = c%w_ref; fidelity = c%fidelity
    fidelity_tol = c%fidelity_tol; section = c%section; lyapunov = c%lyapunov
    lyapunov_interval = c%lyapunov_interval; lyapunov_d0 = c%lyapunov_d0
    fillet = c%fillet; fillet_radius = c%fillet_radius; r_bore = c%r_bore; r_rim = c%r_rim
    zeta_m = c%zeta_m; ripple_order = c%ripple_order; ripple_amp = c%ripple_amp
    ripple_phase_deg = c%ripple_phase_deg; unbalance = c%unbalance
    unbalance_phase_deg = c%unbalance_phase_deg; gamma_x = c%gamma_x; gamma_y = c%gamma_y
    n_slices = c%n_slices
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
    c%nonlinear = nonlinear; c%roots = roots; c%stald = stald; c%linear_tail = linear_tail
    c%rtol = rtol; c%atol = atol
    c%max_steps = max_steps; c%max_total_steps = max_total_steps
    c%t0 = t0; c%t_end = t_end; c%t_transient = t_transient
    c%n_out = n_out; c%start = start; c%dq0 = dq0; c%dv0 = dv0; c%l_ref = l_ref
    c%w_ref = w_ref; c%fidelity = fidelity; c%fidelity_tol = fidelity_tol
    c%section = section; c%lyapunov = lyapunov; c%lyapunov_interval = lyapunov_interval
    c%lyapunov_d0 = lyapunov_d0
    c%fillet = fillet; c%fillet_radius = fillet_radius; c%r_bore = r_bore; c%r_rim = r_rim
    c%zeta_m = zeta_m; c%ripple_order = ripple_order; c%ripple_amp = ripple_amp
    c%ripple_phase_deg = ripple_phase_deg; c%unbalance = unbalance
    c%unbalance_phase_deg = unbalance_phase_deg; c%gamma_x = gamma_x; c%gamma_y = gamma_y
    c%n_slices = n_slices
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

  !> Memory a run of the case needs for its outputs [bytes], in floating point (no integer
  !> overflow whatever the sizes): per output time, the time, 14 states, the torque and
  !> Z x 8 per-tooth quantities, twice (the core's arrays and their copies for the caller),
  !> plus the contact states; the Poincare section points (15 numbers each) and the Benettin
  !> record (2 numbers per renormalisation).
  pure real(wp) function case_output_bytes(c) result(bytes)
    type(case_t), intent(in) :: c
    real(wp) :: nt, nsec, nlyap, window, omega
    nt = real(c%n_out, wp)
    window = max(c%t_end - c%t0 - c%t_transient, 0.0_wp)
    omega = c%speed_rpm*2.0_wp*pi/60.0_wp
    nsec = 0.0_wp
    if (option_index(section_values, c%section) == 2) nsec = window*omega/(2.0_wp*pi) + 2.0_wp
    if (option_index(section_values, c%section) == 3) nsec = window*omega*c%z/(2.0_wp*pi) + 2.0_wp
    nlyap = 0.0_wp
    if (c%lyapunov .and. omega > 0.0_wp .and. c%lyapunov_interval > 0.0_wp) &
         nlyap = window*omega/(2.0_wp*pi*c%lyapunov_interval) + 2.0_wp
    bytes = nt*(2.0_wp*8.0_wp*(16.0_wp + 8.0_wp*c%z) + 4.0_wp*c%z) + 2.0_wp*8.0_wp*15.0_wp*nsec &
         + 2.0_wp*8.0_wp*2.0_wp*nlyap
    if (c%n_slices > 1) bytes = bytes + nt*2.0_wp*8.0_wp*(c%z*c%n_slices + 2.0_wp)
  end function case_output_bytes

  !> Check every field against its physical range (in its unit, with the reason), the
  !> option values, the fields that bound each other (tooth thickness against the circular
  !> pitch, backlash against the tooth space, misalignment against the tooth depth and the
  !> base circle, the output window and its time resolution) and the memory the outputs need.
  !> ierr = err_case with a message naming the case, the field and why.
  subroutine case_validate(c, ierr, errmsg)
    type(case_t), intent(in) :: c
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp) :: reals(50)
    character(len=12), parameter :: real_names(50) = [character(len=12) :: &
         'module_m', 'alpha_deg', 'b', 's', 'c0', 'e_mod', 'nu', 'lambda_th', 'k_cond', 'rho', &
         'c_heat', 'j_m', 'j_l', 'j_1', 'j_2', 'm_1', 'm_2', 'k_p1', 'k_p2', 'c_p1', 'c_p2', &
         'k_t1', 'k_t2', 'c_t1', 'c_t2', 'k_m', 'c_m', 't_d', 't_l', 'speed_rpm', 'grav', &
         'l_x', 'l_y', 't_bulk', 'f_m', 'u_flash', 'eta_hertz', 'rtol', 'atol', 't0', 't_end', &
         't_transient', 'l_ref', 'w_ref', 'dq0', 'dv0', 'fidelity_tol', 'lyapunov_int', &
         'lyapunov_d0', 'lyapunov_d0']
    real(wp) :: r_pitch, depth, involute, e, ta, dt_out, bytes
    type(case_t) :: dflt          ! the defaults (component defaults of case_t)
    integer :: i

    ierr = err_case
    errmsg = ''
    reals = [c%module_m, c%alpha_deg, c%b, c%s, c%c0, c%e_mod, c%nu, c%lambda_th, c%k_cond, &
         c%rho, c%c_heat, c%j_m, c%j_l, c%j_1, c%j_2, c%m_1, c%m_2, c%k_p1, c%k_p2, c%c_p1, &
         c%c_p2, c%k_t1, c%k_t2, c%c_t1, c%c_t2, c%k_m, c%c_m, c%t_d, c%t_l, c%speed_rpm, &
         c%grav, c%l_x, c%l_y, c%t_bulk, c%f_m, c%u_flash, c%eta_hertz, c%rtol, c%atol, c%t0, &
         c%t_end, c%t_transient, c%l_ref, c%w_ref, sum(abs(c%dq0)), sum(abs(c%dv0)), &
         c%fidelity_tol, c%lyapunov_interval, c%lyapunov_d0, c%lyapunov_d0]
    do i = 1, size(reals)
      if (.not. ieee_is_finite(reals(i))) then
        if (real_names(i) == 'lyapunov_int') then
          call fail('lyapunov_interval', 'is not a finite number')
        else
          call fail(real_names(i), 'is not a finite number')
        end if
        return
      end if
    end do

    ! geometry (ISO 4156 and beyond it, with margin)
    if (c%z < 3) then; call fail('z', 'must be at least 3 teeth'); return; end if
    if (c%z > max_teeth) then
      call fail('z', 'is more than '//itoa(max_teeth)//' teeth (the largest spline the tooth-angle recurrence is '// &
           'checked for)'); return
    end if
    if (.not. in_range(c%module_m, 1.0e-4_wp, 0.1_wp, 'module_m', &
         'metres (2 mm is 2e-3; ISO 4156 modules run from 0.25 to 10 mm)')) return
    if (.not. in_range(c%alpha_deg, 5.0_wp, 60.0_wp, 'alpha_deg', &
         'degrees (ISO 4156: 30, 37.5 or 45)')) return
    if (.not. in_range(c%b, 1.0e-4_wp, 10.0_wp, 'b', 'metres, a face width')) return
    if (.not. in_range(c%s, 1.0e-5_wp, 0.2_wp, 's', 'metres, a tooth thickness')) return
    if (.not. (c%s < pi*c%module_m)) then
      call fail('s', '= '//num(c%s)//' m is not less than the circular pitch pi module_m = '// &
           num(pi*c%module_m)//' m (module_m = '//num(c%module_m)//' m): the mating tooth would '// &
           'have no thickness left'); return
    end if
    if (.not. in_range(c%c0, 1.0e-8_wp, 0.01_wp, 'c0', 'metres (0.2 mm is 2e-4)')) return
    if (.not. (c%c0 < pi*c%module_m - c%s)) then
      call fail('c0', '= '//num(c%c0)//' m is not less than the tooth space pi module_m - s = '// &
           num(pi*c%module_m - c%s)//' m (module_m = '//num(c%module_m)//' m, s = '//num(c%s)// &
           ' m): no tooth fits the gap'); return
    end if

    ! material
    if (.not. in_range(c%e_mod, 1.0e8_wp, 1.0e13_wp, 'e_mod', 'pascals (steel 2.1e11)')) return
    if (.not. in_range(c%nu, 0.0_wp, 0.4999_wp, 'nu', 'a ratio below 1/2')) return
    if (.not. in_range(c%lambda_th, 0.0_wp, 1.0e-3_wp, 'lambda_th', '1/degC (steel 1.2e-5)')) return
    if (.not. positive_in(c%k_cond, 1.0e-2_wp, 5.0e3_wp, 'k_cond', 'W/(m K) (steel 46)')) return
    if (.not. positive_in(c%rho, 100.0_wp, 3.0e4_wp, 'rho', 'kg/m^3 (steel 7800)')) return
    if (.not. positive_in(c%c_heat, 10.0_wp, 1.0e5_wp, 'c_heat', 'J/(kg K) (steel 480)')) return

    ! drive: inertias from a 1 g ring of 1 mm to a ship's shaft line; masses from 0.1 g to
    ! 100 t; stiffnesses and dampings from 0 (none) to beyond any steel part
    if (.not. positive_in(c%j_m, 1.0e-9_wp, 1.0e6_wp, 'j_m', 'kg m^2')) return
    if (.not. positive_in(c%j_l, 1.0e-9_wp, 1.0e6_wp, 'j_l', 'kg m^2')) return
    if (.not. positive_in(c%j_1, 1.0e-9_wp, 1.0e6_wp, 'j_1', 'kg m^2')) return
    if (.not. positive_in(c%j_2, 1.0e-9_wp, 1.0e6_wp, 'j_2', 'kg m^2')) return
    if (.not. positive_in(c%m_1, 1.0e-4_wp, 1.0e5_wp, 'm_1', 'kg')) return
    if (.not. positive_in(c%m_2, 1.0e-4_wp, 1.0e5_wp, 'm_2', 'kg')) return
    if (.not. nonneg_in(c%k_p1, 1.0_wp, 1.0e12_wp, 'k_p1', 'N/m; 0 for no support')) return
    if (.not. nonneg_in(c%k_p2, 1.0_wp, 1.0e12_wp, 'k_p2', 'N/m; 0 for no support')) return
    if (.not. nonneg_in(c%c_p1, 0.0_wp, 1.0e7_wp, 'c_p1', 'N s/m')) return
    if (.not. nonneg_in(c%c_p2, 0.0_wp, 1.0e7_wp, 'c_p2', 'N s/m')) return
    if (.not. nonneg_in(c%k_t1, 1.0e-3_wp, 1.0e9_wp, 'k_t1', 'N m/rad; 0 for a free shaft')) return
    if (.not. nonneg_in(c%k_t2, 1.0e-3_wp, 1.0e9_wp, 'k_t2', 'N m/rad; 0 for a free shaft')) return
    if (.not. nonneg_in(c%c_t1, 0.0_wp, 1.0e6_wp, 'c_t1', 'N m s/rad')) return
    if (.not. nonneg_in(c%c_t2, 0.0_wp, 1.0e6_wp, 'c_t2', 'N m s/rad')) return
    if (.not. nonneg_in(c%k_m, 1.0e2_wp, 1.0e12_wp, 'k_m', &
         'N/m per tooth pair; 0 for the computed one, Eq. 18')) return
    if (.not. nonneg_in(c%c_m, 0.0_wp, 1.0e6_wp, 'c_m', 'N s/m')) return
    if (.not. in_range(c%t_d, -1.0e7_wp, 1.0e7_wp, 't_d', 'N m (the largest shafts carry ~1e7)')) return
    if (.not. in_range(c%t_l, -1.0e7_wp, 1.0e7_wp, 't_l', 'N m (the largest shafts carry ~1e7)')) return
    if (.not. in_range(c%speed_rpm, 0.0_wp, 1.0e6_wp, 'speed_rpm', 'r/min, not negative')) return
    if (.not. in_range(c%grav, -100.0_wp, 100.0_wp, 'grav', 'm/s^2 (Earth 9.81; 0 in orbit)')) return

    ! misalignment: the teeth overlap radially over one module (ISO 4156: external major
    ! m (Z + 1), internal minor m (Z - 1)), and the contact point must stay on the involute,
    ! above the base circle: a shift Delta moves it to about R - Delta cos(alpha) (Eq. 13), which
    ! reaches r_b = R cos(alpha) at Delta = R (1 / cos(alpha) - 1)
    r_pitch = 0.5_wp*c%module_m*c%z
    depth = c%module_m
    involute = r_pitch*(1.0_wp/cos(c%alpha_deg*pi/180.0_wp) - 1.0_wp)
    e = hypot(c%l_x, c%l_y)
    if (.not. (e < min(depth, involute, r_pitch))) then
      call fail('l_x', '= '//num(c%l_x)//' m, l_y = '//num(c%l_y)//' m: a misalignment of '// &
           num(e)//' m must be less than '//num(min(depth, involute))//' m, the smaller of the '// &
           'tooth overlap (one module) and the shift that moves the contact point to the base '// &
           'circle, R (1/cos alpha - 1) (pitch radius R = m Z / 2 = '//num(r_pitch)//' m)'); return
    end if

    ! thermal
    if (.not. in_range(c%t_bulk, -273.15_wp, 1.0e4_wp, 't_bulk', &
         'degC, a rise: not below absolute zero, not beyond 1e4')) return
    if (.not. nonneg_in(c%f_m, 0.0_wp, 1.0e6_wp, 'f_m', &
         'a friction coefficient (physical: below 1; fitted factors up to 1e6)')) return
    if (.not. nonneg_in(c%u_flash, 0.0_wp, 10.0_wp, 'u_flash', 'Blok''s factor (0.83)')) return
    if (.not. positive_in(c%eta_hertz, 1.0e-2_wp, 100.0_wp, 'eta_hertz', 'Hertz factor (1.127)')) return

    ! solver
    if (.not. in_range(c%rtol, 1.0e-15_wp, 0.1_wp, 'rtol', 'a relative tolerance')) return
    if (.not. positive_in(c%atol, 1.0e-20_wp, 1.0_wp, 'atol', &
         'an absolute tolerance on the scaled states of Eq. 25, which are of order 1')) return
    if (c%max_steps < 1) then; call fail('max_steps', 'must be at least 1'); return; end if
    if (c%max_total_steps < 1) then
      call fail('max_total_steps', 'must be at least 1'); return
    end if

    ! times: within a million seconds (11.6 days) of 0, where a double still resolves the
    ! tooth angle omega t to 1e-5 rad at the largest speed
    if (.not. in_range(c%t0, -1.0e6_wp, 1.0e6_wp, 't0', 's (the tooth angle omega t keeps its '// &
         'digits within 1e6 s)')) return
    if (.not. (c%t_end > c%t0)) then; call fail('t_end', 'must be greater than t0'); return; end if
    if (.not. in_range(c%t_end, -1.0e6_wp, 1.0e6_wp, 't_end', 's (the tooth angle omega t keeps '// &
         'its digits within 1e6 s)')) return
    if (.not. (c%t_end - c%t0 >= 1.0e-9_wp)) then
      call fail('t_end', '- t0 = '//num(c%t_end - c%t0)//' s: a run lasts at least 1e-9 s'); return
    end if
    if (.not. nonneg(c%t_transient, 't_transient')) return
    ta = c%t0 + c%t_transient
    if (.not. (ta <= c%t_end)) then
      call fail('t_transient', '= '//num(c%t_transient)//' s ends after t_end: t0 + t_transient '// &
           'must not pass t_end'); return
    end if
    if (c%n_out < 1) then; call fail('n_out', 'must be at least 1'); return; end if
    if (c%n_out > 1) then
      if (.not. (ta < c%t_end)) then
        call fail('t_transient', '= '//num(c%t_transient)//' s leaves no output window: '// &
             itoa(c%n_out)//' output times would all be t_end (use n_out = 1, or a shorter '// &
             't_transient)'); return
      end if
      dt_out = (c%t_end - ta)/real(c%n_out - 1, wp)
      if (.not. (dt_out > 1.0e3_wp*spacing_of(max(abs(ta), abs(c%t_end))))) then
        call fail('n_out', '= '//itoa(c%n_out)//' puts the output times '//num(dt_out)//' s '// &
             'apart, closer than the time resolution at t = '//num(c%t_end)//' s'); return
      end if
    end if
    do i = 1, ndof_case
      if (abs(c%dq0(i)) > 1.0_wp) then
        call fail('dq0('//itoa(i)//')', '= '//num(c%dq0(i))//' m is outside -1 .. 1 m '// &
             '(a start offset, added to the start displacements)'); return
      end if
      if (abs(c%dv0(i)) > 1.0e3_wp) then
        call fail('dv0('//itoa(i)//')', '= '//num(c%dv0(i))//' m/s is outside -1e3 .. 1e3 m/s '// &
             '(a start velocity offset)'); return
      end if
    end do
    if (.not. nonneg_in(c%l_ref, 1.0e-9_wp, 1.0_wp, 'l_ref', &
         'm, a length scale of the motion; 0 for c0')) return
    if (.not. nonneg_in(c%w_ref, 1.0e-3_wp, 1.0e7_wp, 'w_ref', &
         'rad/s, a frequency scale; 0 for the shaft speed')) return
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
    if (.not. in_range(c%lyapunov_interval, 1.0e-3_wp, 1.0e3_wp, 'lyapunov_interval', &
         'shaft revolutions')) return
    if (c%lyapunov_d0 /= 0.0_wp) then      ! 0: chosen from rtol (model: lyapunov_separation)
      if (.not. in_range(c%lyapunov_d0, 1.0e-12_wp, 1.0e-3_wp, 'lyapunov_d0', &
           'a separation of the scaled states (0: chosen from rtol)')) return
    end if
    if ((c%lyapunov .or. option_index(section_values, c%section) > 1) .and. c%speed_rpm <= 0.0_wp) then
      call fail('speed_rpm', 'must be positive for a Poincare section or a Lyapunov exponent '// &
           '(both are timed by the shaft revolution)'); return
    end if

    ! beyond the paper
    if (.not. all_finite([c%fillet_radius, c%r_bore, c%r_rim, c%zeta_m, c%ripple_order, &
         c%ripple_amp, c%ripple_phase_deg, c%unbalance, c%unbalance_phase_deg, c%gamma_x, &
         c%gamma_y])) then
      call fail('fillet_radius', '.. gamma_y (the fields beyond the paper) must be finite numbers')
      return
    end if
    if (.not. in_range(c%fillet_radius, 0.0_wp, c%module_m, 'fillet_radius', &
         'metres, at most one module; 0 = 0.2 m')) return
    if (.not. in_range(c%r_bore, 0.0_wp, 0.5_wp*c%module_m*(c%z - 1.5_wp), 'r_bore', &
         'metres, inside the external root circle; 0 = half its radius')) return
    if (c%r_rim /= 0.0_wp .and. .not. in_range(c%r_rim, 0.5_wp*c%module_m*(c%z + 1.5_wp), &
         100.0_wp*c%module_m*c%z, 'r_rim', 'metres, outside the internal root circle; 0 = twice '// &
         'its radius')) return
    if (.not. in_range(c%zeta_m, 0.0_wp, 1.0_wp, 'zeta_m', 'a damping ratio')) return
    if (c%zeta_m > 0.0_wp .and. c%c_m /= dflt%c_m) then
      call fail('zeta_m', 'and c_m are both given: give the mesh damping one way'); return
    end if
    do i = 1, nripple
      if (.not. in_range(c%ripple_order(i), 0.0_wp, 1000.0_wp, 'ripple_order', &
           'engine orders (multiples of the shaft speed)')) return
      if (.not. in_range(c%ripple_amp(i), -10.0_wp, 10.0_wp, 'ripple_amp', &
           'a fraction of T_d')) return
    end do
    if (.not. in_range(minval(c%unbalance), 0.0_wp, 1.0_wp, 'unbalance', 'kg m (m_u e)')) return
    if (.not. in_range(maxval(c%unbalance), 0.0_wp, 1.0_wp, 'unbalance', 'kg m (m_u e)')) return
    if (.not. in_range(hypot(c%gamma_x, c%gamma_y), 0.0_wp, c%module_m/c%b, 'gamma_x', &
         'radians: |(gamma_x, gamma_y)| b / 2 must stay within half a module at the face ends')) return
    if (c%n_slices < 1 .or. c%n_slices > 256) then
      call fail('n_slices', '= '//itoa(c%n_slices)//' is outside 1 .. 256'); return
    end if
    if ((c%gamma_x /= 0.0_wp .or. c%gamma_y /= 0.0_wp) .and. c%n_slices < 2) then
      call fail('n_slices', 'must be at least 2 for an angular misalignment (gamma_x, gamma_y): '// &
           'the face is cut into slices'); return
    end if
    if (c%n_slices > 1 .and. option_index(thermal_values, c%thermal) > 2) then
      call fail('n_slices', '> 1 needs thermal = none or bulk: the flash temperature (oneway, '// &
           'coupled) is modelled for a whole tooth'); return
    end if

    ! memory, before anything is allocated
    bytes = case_output_bytes(c)
    if (bytes > max_output_bytes) then
      if (c%lyapunov .or. option_index(section_values, c%section) > 1) then
        call fail('n_out', '= '//itoa(c%n_out)//' with z = '//itoa(c%z)//' teeth, the Poincare '// &
             'section and the Lyapunov record need '//size_text(bytes)//' of memory for the '// &
             'outputs, more than the limit of '//size_text(max_output_bytes)//': lower n_out '// &
             '(or shorten the run)'); return
      end if
      call fail('n_out', '= '//itoa(c%n_out)//' with z = '//itoa(c%z)//' teeth needs '// &
           size_text(bytes)//' of memory for the outputs, more than the limit of '// &
           size_text(max_output_bytes)//': lower n_out'); return
    end if
    ierr = err_ok

  contains

    pure logical function all_finite(x)
      real(wp), intent(in) :: x(:)
      all_finite = all(ieee_is_finite(x))
    end function all_finite

    subroutine fail(field, why)
      character(len=*), intent(in) :: field, why
      errmsg = 'case '//trim(c%name)//': field '//trim(field)//' '//why
    end subroutine fail

    logical function nonneg(x, field)
      real(wp), intent(in) :: x
      character(len=*), intent(in) :: field
      nonneg = x >= 0.0_wp
      if (.not. nonneg) call fail(field, 'must not be negative')
    end function nonneg

    !> x > 0 and within lo .. hi.
    logical function positive_in(x, lo, hi, field, unit)
      real(wp), intent(in) :: x, lo, hi
      character(len=*), intent(in) :: field, unit
      positive_in = x > 0.0_wp
      if (.not. positive_in) then
        call fail(field, 'must be positive'); return
      end if
      positive_in = in_range(x, lo, hi, field, unit)
    end function positive_in

    !> x = 0 (the field's 'none' or 'computed') or within lo .. hi.
    logical function nonneg_in(x, lo, hi, field, unit)
      real(wp), intent(in) :: x, lo, hi
      character(len=*), intent(in) :: field, unit
      nonneg_in = x >= 0.0_wp
      if (.not. nonneg_in) then
        call fail(field, 'must not be negative'); return
      end if
      if (x == 0.0_wp) return
      nonneg_in = in_range(x, lo, hi, field, unit)
    end function nonneg_in

    logical function in_range(x, lo, hi, field, unit)
      real(wp), intent(in) :: x, lo, hi
      character(len=*), intent(in) :: field, unit
      in_range = x >= lo .and. x <= hi
      if (.not. in_range) call fail(field, '= '//num(x)//' is outside '//num(lo, 2)//' .. '// &
           num(hi, 2)//' (unit: '//unit//')')
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

  !> The gap between x and the next double (the time resolution at x).
  pure real(wp) function spacing_of(x)
    real(wp), intent(in) :: x
    spacing_of = spacing(max(x, tiny(1.0_wp)))
  end function spacing_of

  !> A number for messages: 3 decimals (or digits), a three-digit exponent where needed.
  pure function num(x, digits) result(s)
    real(wp), intent(in) :: x
    integer, intent(in), optional :: digits
    character(len=:), allocatable :: s
    character(len=24) :: buf
    character(len=16) :: fmt
    integer :: d
    d = 3
    if (present(digits)) d = digits
    if (x /= 0.0_wp .and. (abs(x) >= 1.0e100_wp .or. abs(x) < 1.0e-99_wp)) then
      write(fmt, '(a,i0,a,i0,a)') '(es', d + 9, '.', d, 'e3)'
    else
      write(fmt, '(a,i0,a,i0,a)') '(es', d + 8, '.', d, ')'
    end if
    write(buf, fmt) x
    s = trim(adjustl(buf))
  end function num

  !> A byte count in kB, MB, GB or TB (powers of 1000).
  pure function size_text(bytes) result(s)
    real(wp), intent(in) :: bytes
    character(len=:), allocatable :: s
    character(len=24) :: buf
    character(len=2), parameter :: units(5) = ['B ', 'kB', 'MB', 'GB', 'TB']
    real(wp) :: v
    integer :: k
    v = bytes; k = 1
    do while (v >= 1000.0_wp .and. k < 5)
      v = v/1000.0_wp; k = k + 1
    end do
    write(buf, '(f0.1)') v
    s = trim(buf)//' '//trim(units(k))
  end function size_text

end module spline_case
