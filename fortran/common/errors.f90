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

  interface num
    module procedure num_e, num_digits, num_readable
  end interface num

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

  ! The text helpers below are functions whose result length is a specification expression
  ! (the caller sizes it; the text is formed twice): gfortran 12 keeps the length of every call
  ! of a function with a deferred-length result (character(len=:), allocatable) in a static
  ! variable, one for all threads (docs/developing.md, "Thread safety").

  !> An integer as text, for messages.
  pure function itoa(i) result(s)
    integer, intent(in) :: i
    character(len=len_trim(i0(i))) :: s
    s = i0(i)
  end function itoa

  pure function i0(i) result(buf)
    integer, intent(in) :: i
    character(len=12) :: buf
    write(buf, '(i0)') i
  end function i0

  !> A real as text in the format f, without blanks, for messages (e.g. '(es10.3)', '(f0.2)').
  pure function ftoa(x, f) result(s)
    real(wp), intent(in) :: x
    character(len=*), intent(in) :: f
    character(len=len_trim(fmt_real(x, f))) :: s
    s = fmt_real(x, f)
  end function ftoa

  pure function fmt_real(x, f) result(buf)
    real(wp), intent(in) :: x
    character(len=*), intent(in) :: f
    character(len=40) :: buf
    write(buf, f) x
    buf = adjustl(buf)
  end function fmt_real

  !> A number for messages: 3 decimals (or digits) in E form, a three-digit exponent where
  !> needed (5.000E+06, 1.000E-100). readable (spline_model's plausibility warnings): from 1e-2
  !> to 1e4 fixed, 4 decimals below 10, then 3, 2, 1 (0.2546, 19.096, 1234.5); else the E form
  !> with 3 decimals, as Fortran's es writes it (5.000E+06, 1.000-100). The generic num: num(x),
  !> num(x, digits), num(x, readable=...) (a specification expression takes no optional argument).
  pure function num_e(x) result(s)
    real(wp), intent(in) :: x
    character(len=len_trim(num_text(x, 3, .false.))) :: s
    s = num_text(x, 3, .false.)
  end function num_e

  pure function num_digits(x, digits) result(s)
    real(wp), intent(in) :: x
    integer, intent(in) :: digits
    character(len=len_trim(num_text(x, digits, .false.))) :: s
    s = num_text(x, digits, .false.)
  end function num_digits

  pure function num_readable(x, readable) result(s)
    real(wp), intent(in) :: x
    logical, intent(in) :: readable
    character(len=len_trim(num_text(x, 3, readable))) :: s
    s = num_text(x, 3, readable)
  end function num_readable

  pure function num_text(x, d, fixed) result(buf)
    real(wp), intent(in) :: x
    integer, intent(in) :: d
    logical, intent(in) :: fixed
    character(len=24) :: buf
    character(len=16) :: fmt
    if (fixed .and. abs(x) >= 1.0e-2_wp .and. abs(x) < 1.0e4_wp) then
      write(fmt, '(a,i0,a)') '(f12.', 4 - count(abs(x) >= [10.0_wp, 100.0_wp, 1000.0_wp]), ')'
    else if (.not. fixed .and. x /= 0.0_wp .and. &
         (abs(x) >= 1.0e100_wp .or. abs(x) < 1.0e-99_wp)) then
      write(fmt, '(a,i0,a,i0,a)') '(es', d + 9, '.', d, 'e3)'
    else
      write(fmt, '(a,i0,a,i0,a)') '(es', d + 8, '.', d, ')'
    end if
    write(buf, fmt) x
    buf = adjustl(buf)
  end function num_text

end module spline_errors
