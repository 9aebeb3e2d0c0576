!> What a run of the integrator layer (spline_integrator) reports: the message of a run that
!> failed (integrator_fail_text: the bound met or the integrator's own flag, with SUNDIALS' text),
!> and the warnings SUNDIALS raised (integrator_warnings). Reentrant like the layer: everything read sits in the caller's integrator_t.
module spline_integrator_report
  use, intrinsic :: iso_c_binding
  use fcvode_mod
  use farkode_erkstep_mod
  use spline_errors, only: itoa, ftoa
  use spline_model, only: model_t
  use spline_integrator, only: integrator_t, lib_log_t, integrator_time, integrator_steps_done, &
       integrator_name, c_copy, stalled_flag
  implicit none
  private
  public :: integrator_fail_text, integrator_warnings

contains

  !> The name of the integrator's return flag (CVODE's, ERKStep's), from SUNDIALS' C function:
  !> the Fortran interface's returns a deferred-length result (docs/developing.md, "Thread safety").
  subroutine integrator_flag_name(cv, flag, fname)
    type(integrator_t), intent(in) :: cv
    integer(c_int), intent(in) :: flag
    character(len=*), intent(out) :: fname
    type(c_ptr) :: p
    interface
      type(c_ptr) function cvode_flag_name(flag) bind(C, name='CVodeGetReturnFlagName')
        import :: c_ptr, c_long
        integer(c_long), value :: flag
      end function cvode_flag_name
      type(c_ptr) function erk_flag_name(flag) bind(C, name='ERKStepGetReturnFlagName')
        import :: c_ptr, c_long
        integer(c_long), value :: flag
      end function erk_flag_name
      subroutine c_free(p) bind(C, name='free')
        import :: c_ptr
        type(c_ptr), value :: p
      end subroutine c_free
    end interface
    if (cv%erk .and. flag == CV_ROOT_RETURN) then
      fname = 'ARK_ROOT_RETURN'; return
    end if
    if (cv%erk) then
      p = erk_flag_name(int(flag, c_long))
    else
      p = cvode_flag_name(int(flag, c_long))
    end if
    call c_copy(p, fname)
    call c_free(p)                ! SUNDIALS allocates the name
  end subroutine integrator_flag_name

  !> The message of a run that failed at tau with flag while doing what: the wall-time or work
  !> bound met, naming the field or argument that sets it, or the integrator's flag with
  !> SUNDIALS' own text (lib_handler). Callers report their callbacks' errors and SIGINT first.
  subroutine integrator_fail_text(cv, m, flag, tau, what, errmsg)
    type(integrator_t), intent(in) :: cv
    type(model_t), intent(in) :: m
    integer(c_int), intent(in) :: flag
    real(c_double), intent(in) :: tau
    character(len=*), intent(in) :: what
    character(len=*), intent(out) :: errmsg
    character(len=:), allocatable :: head, name
    character(len=12) :: at
    character(len=32) :: fname
    head = 'case '//trim(m%name)//': '//trim(cv%run)
    name = integrator_name(cv)
    call integrator_flag_name(cv, flag, fname)
    ! where it stopped: the caller's tau is where the run last restarted (a contact switch)
    write(at, '(es12.5)') max(tau, integrator_time(cv, tau))/m%w_ref
    if (flag == stalled_flag .and. cv%stalled) then
      errmsg = head//': the '//name//' step fell below round-off of t at t = '// &
           ftoa(cv%t_stalled/m%w_ref, '(es12.5)')//' s, short of t = '//at// &
           ' s where the state was asked for (no state there: a chain of restarts at contact '// &
           'switches)'
    else if (flag == CV_TOO_MUCH_WORK .and. cv%wall_bound) then
      errmsg = head//' took longer than its wall-time bound max_seconds = '// &
           ftoa(cv%max_seconds, '(es9.2)')//' s, at t = '//at//' s, after '// &
           itoa(int(integrator_steps_done(cv)))//' '//name//' steps'
    else if (flag == CV_TOO_MUCH_WORK .and. cv%total_bound) then
      errmsg = head//' took max_total_steps = '//itoa(int(cv%max_total_steps))//' '//name// &
           ' steps in all by t = '//at//' s (flag '//trim(fname)//'): raise max_total_steps, '// &
           'or find why the steps are so small'
    else if (flag == CV_TOO_MUCH_WORK .and. cv%run == 'the run') then
      errmsg = 'case '//trim(m%name)//': '//name//' took max_steps = '//itoa(int(cv%max_steps))// &
           ' steps between two output times without reaching the next, at t = '//at//' s (flag '// &
           trim(fname)//'): raise max_steps or n_out'
    else if (flag == CV_TOO_MUCH_WORK) then
      errmsg = head//' took max_steps = '//itoa(int(cv%max_steps))//' '//name//' steps '// &
           'without reaching its end, at t = '//at//' s (flag '//trim(fname)//'): raise max_steps '// &
           '(it bounds this run as a whole: n_out does not split it)'
    else
      if (cv%run /= 'the run') name = name//' failed in '//trim(cv%run)
      if (cv%run == 'the run') name = name//' failed'
      errmsg = 'case '//trim(m%name)//': '//name//' while '//what//' with flag '// &
           trim(fname)//' ('//itoa(int(flag))//') at t = '//at//' s'
      if (len_trim(cv%log%err) > 0) errmsg = trim(errmsg)//': '//trim(cv%log%err)
    end if
  end subroutine integrator_fail_text

  !> The warnings SUNDIALS raised in the runs of log (one line; '' if none): how many, and the
  !> first one's text. The executable prints it as a 'warning:' line, Python as a SplineWarning.
  subroutine integrator_warnings(log, name, text)
    type(lib_log_t), intent(in) :: log
    character(len=*), intent(in) :: name     !< the case's name
    character(len=*), intent(out) :: text
    text = ''
    if (log%nwarn == 0) return
    text = 'case '//trim(name)//': SUNDIALS warned '//itoa(log%nwarn)//' time(s) in this run '// &
         '(the steps may have become too small to resolve the motion); the first, from '// &
         trim(log%first)
  end subroutine integrator_warnings

end module spline_integrator_report
