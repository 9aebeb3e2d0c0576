!> Assertions shared by the Fortran test programs (tests/fortran/test_*.f90, run by `meson test`).
!> Every check prints one line, PASS or FAIL, with what it compared; check_done ends the program
!> with error stop 1 if any check failed. The counters are module variables: a test program is
!> one serial run (the core itself keeps no such state).
module check
  use spline_kinds, only: wp
  implicit none
  private
  public :: check_true, check_close, check_done, default_case_model

  integer :: n_checks = 0, n_failed = 0

contains

  !> Passes when ok; detail says what was tested.
  subroutine check_true(name, ok, detail)
    character(len=*), intent(in) :: name
    logical, intent(in) :: ok
    character(len=*), intent(in), optional :: detail
    n_checks = n_checks + 1
    if (.not. ok) n_failed = n_failed + 1
    if (present(detail)) then
      if (len_trim(detail) == 0) then
        print '(a,1x,a)', merge('PASS', 'FAIL', ok), name
        return
      end if
      print '(a,1x,a,": ",a)', merge('PASS', 'FAIL', ok), name, detail
    else
      print '(a,1x,a)', merge('PASS', 'FAIL', ok), name
    end if
  end subroutine check_true

  !> Passes when |got - want| <= rtol |want| + atol (atol default 0). A NaN fails.
  subroutine check_close(name, got, want, rtol, atol)
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: got, want, rtol
    real(wp), intent(in), optional :: atol
    real(wp) :: tol, err
    character(len=160) :: detail
    tol = rtol*abs(want)
    if (present(atol)) tol = tol + atol
    err = abs(got - want)
    write(detail, '(a,es24.16,a,es24.16,a,es9.2,a,es9.2)') 'got', got, ' want', want, ' |err|', &
         err, ' tol', tol
    call check_true(name, err <= tol, trim(detail))
  end subroutine check_close

  !> Prints the summary; error stop 1 if any check failed.
  subroutine check_done(program_name)
    character(len=*), intent(in) :: program_name
    print '(a,": ",i0," checks, ",i0," failed")', program_name, n_checks, n_failed
    if (n_failed > 0) error stop 1
  end subroutine check_done

  !> The model of case c (model_from_case), default a case_t with its defaults (the paper's
  !> spline and drive). Stops the program if the constructor fails.
  subroutine default_case_model(m, c)
    use spline_case, only: case_t
    use spline_model, only: model_t, model_from_case
    type(model_t), intent(out) :: m
    type(case_t), intent(in), optional :: c
    type(case_t) :: cc
    integer :: ierr
    character(len=512) :: msg
    if (present(c)) cc = c
    call model_from_case(cc, m, ierr, msg)
    if (ierr /= 0) then
      print '(a)', 'FAIL model_from_case: '//trim(msg)
      error stop 1
    end if
  end subroutine default_case_model

end module check
