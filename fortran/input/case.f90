!> Case input: the namelist group &spline_case mapped to case fields (type case_t), read from a
!> file or text and validated. Nothing here computes physics: spline_model builds the model
!> from a valid case. The concerns live in their own modules, and this one gives them to the
!> rest of the core under one name (use spline_case):
!>   spline_case_type   case_t with its defaults, the field table (name, type, size, unit,
!>                      description, simple range), the option values (case_type.f90)
!>   spline_case_parse  the reader of a case's text (case_parse), the namelist copy I/O and
!>                      case_write_text (case_parse.f90; its tokens: case_lex.f90)
!>   spline_case_check  case_validate (case_check.f90)
!>   spline_case_text   text helpers and the spelling hint case_suggest (case_text.f90)
!> and here: the checks of a case file before it is opened, and reading a file or a text.
module spline_case
  use, intrinsic :: iso_c_binding, only: c_char, c_int, c_long_long, c_null_char
  use spline_errors, only: err_ok, err_case
  use spline_case_type, only: case_t, case_field, case_field_meta, case_name_of, option_index, &
       case_output_bytes, case_run_times, namelen, nripple, ndof_case, nfields, max_case_bytes, &
       max_output_bytes, thermal_values, method_values, nonlinear_values, start_values, fidelity_values, section_values, &
       lyapunov_method_values, goal_values, erk_table_values
  use spline_case_text, only: case_suggest, shown
  use spline_case_parse, only: case_parse, case_write_text
  use spline_case_check, only: case_validate
  implicit none
  private
  public :: case_t, case_read_file, case_read_text, case_parse, case_write_text, case_validate
  public :: case_name_of, case_suggest, case_field, case_field_meta, case_check_file, case_output_bytes
  public :: case_run_times, c_file_kind   ! c_file_kind: also spline-dyn's output checks
  public :: namelen, nripple, ndof_case, thermal_values, method_values, nonlinear_values, start_values, &
       fidelity_values, section_values, option_index, nfields, max_case_bytes, max_output_bytes, &
       lyapunov_method_values, goal_values, erk_table_values

  interface   ! fortran/interface/fileinfo.c
    integer(c_int) function c_file_kind(path, size, errbuf, errlen) bind(C, name='spline_file_kind')
      import :: c_char, c_int, c_long_long
      character(kind=c_char), intent(in) :: path(*)
      integer(c_long_long), intent(out) :: size
      character(kind=c_char), intent(out) :: errbuf(*)
      integer(c_int), value :: errlen
    end function c_file_kind
  end interface

contains

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

end module spline_case
