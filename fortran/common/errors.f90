!> Error codes shared by every layer (core, f2py API, executable, Python exceptions).
!> A routine that can fail returns ierr (one of these) and a message naming the case and the
!> field, or the CVODE flag and the time. Python maps them to exceptions (pyspline.errors),
!> the executable to exit codes (err_exit_code).
module spline_errors
  use spline_kinds, only: wp
  implicit none
  private
  public :: err_ok, err_case, err_solver, err_thermal, err_interrupted, nerr, err_names
  public :: msglen, err_exit_code, itoa, ftoa, num

  integer, parameter :: err_ok = 0           !< success
  integer, parameter :: err_case = 1         !< bad case: field missing, ill-typed, out of range
  integer, parameter :: err_solver = 2       !< CVODE failed, or no static equilibrium
  integer, parameter :: err_thermal = 3      !< heat closed the backlash (Eq. 2: c_j <= 0)
  integer, parameter :: err_interrupted = 4  !< SIGINT arrived during a run (Python: KeyboardInterrupt)
  integer, parameter :: nerr = 4
  character(len=12), parameter :: err_names(0:nerr) = [character(len=12) :: 'ok', 'case', &
       'solver', 'thermal', 'interrupted']
  integer, parameter :: msglen = 512         !< length of every error message buffer

contains

  !> Exit status of spline-dyn for an error code: 0 ok, 2 bad input (a case file that is no
  !> file, bad syntax, a field out of range, too much memory; also a usage error and an output
  !> that cannot be written or is the case file), 3 solver failure (CVODE, no static
  !> equilibrium, a work bound max_steps / max_total_steps, a non-finite output), 4 thermal
  !> interference, 130 interrupted (128 + SIGINT, the shell convention).
  pure integer function err_exit_code(ierr) result(code)
    integer, intent(in) :: ierr
    select case (ierr)
    case (err_ok);          code = 0
    case (err_case);        code = 2
    case (err_solver);      code = 3
    case (err_thermal);     code = 4
    case (err_interrupted); code = 130
    case default;           code = 1
    end select
  end function err_exit_code

  !> An integer as text, for messages.
  pure function itoa(i) result(s)
    integer, intent(in) :: i
    character(len=:), allocatable :: s
    character(len=12) :: buf
    write(buf, '(i0)') i
    s = trim(buf)
  end function itoa

  !> A real as text in the format f, without blanks, for messages (e.g. '(es10.3)', '(f0.2)').
  pure function ftoa(x, f) result(s)
    real(wp), intent(in) :: x
    character(len=*), intent(in) :: f
    character(len=:), allocatable :: s
    character(len=40) :: buf
    write(buf, f) x
    s = trim(adjustl(buf))
  end function ftoa

  !> A number for messages: 3 decimals (or digits) in E form, a three-digit exponent where
  !> needed (5.000E+06, 1.000E-100). readable (spline_model's plausibility warnings): from 1e-2
  !> to 1e4 fixed, 4 decimals below 10, then 3, 2, 1 (0.2546, 19.096, 1234.5); else the E form
  !> with 3 decimals, as Fortran's es writes it (5.000E+06, 1.000-100).
  pure function num(x, digits, readable) result(s)
    real(wp), intent(in) :: x
    integer, intent(in), optional :: digits
    logical, intent(in), optional :: readable
    character(len=:), allocatable :: s
    character(len=24) :: buf
    character(len=16) :: fmt
    integer :: d
    logical :: fixed
    d = 3
    if (present(digits)) d = digits
    fixed = .false.
    if (present(readable)) fixed = readable
    if (fixed .and. abs(x) >= 1.0e-2_wp .and. abs(x) < 1.0e4_wp) then
      write(fmt, '(a,i0,a)') '(f12.', 4 - count(abs(x) >= [10.0_wp, 100.0_wp, 1000.0_wp]), ')'
    else if (.not. fixed .and. x /= 0.0_wp .and. &
         (abs(x) >= 1.0e100_wp .or. abs(x) < 1.0e-99_wp)) then
      write(fmt, '(a,i0,a,i0,a)') '(es', d + 9, '.', d, 'e3)'
    else
      write(fmt, '(a,i0,a,i0,a)') '(es', d + 8, '.', d, ')'
    end if
    write(buf, fmt) x
    s = trim(adjustl(buf))
  end function num

end module spline_errors
