!> spline-dyn: the standalone (HPC) driver. Reads a case namelist, runs it with the same core
!> as the Python package, and writes a self-describing CSV (one header row naming every column
!> with its unit, '#' lines with the case and the solver statistics).
!>   usage: spline-dyn CASE.nml [-o OUT.csv]
program spline_dyn
  use spline_kinds, only: wp
  use spline_errors, only: err_ok, err_exit_code, msglen
  use spline_case, only: case_t, case_read_file, case_name_of
  use spline_model, only: model_t, model_from_case, nstate, nkterms, kterm_names
  use spline_run, only: nstats, stat_names, run_case, ntooth_q, tooth_q_names, tooth_q_units
  implicit none
  character(len=1024) :: path, out, arg
  character(len=msglen) :: errmsg
  type(case_t) :: c
  type(model_t) :: m
  real(wp), allocatable :: t(:), y(:, :), tooth(:, :, :), tm(:)
  real(wp) :: stats(nstats)
  integer :: ierr, i, j, k, q, u, nargs
  character(len=8), parameter :: state_names(nstate) = [character(len=8) :: 'x1', 'y1', 'x2', &
       'y2', 'D1', 'D2', 'D3', 'vx1', 'vy1', 'vx2', 'vy2', 'vD1', 'vD2', 'vD3']

  nargs = command_argument_count()
  path = ''; out = ''
  i = 1
  do while (i <= nargs)
    call get_command_argument(i, arg)
    if (arg == '-o') then
      i = i + 1
      call get_command_argument(i, out)
    else if (arg == '-h' .or. arg == '--help') then
      call usage(0)
    else
      path = arg
    end if
    i = i + 1
  end do
  if (len_trim(path) == 0) call usage(2)
  if (len_trim(out) == 0) out = trim(case_name_of(path))//'.csv'

  call case_read_file(trim(path), c, ierr, errmsg)
  if (ierr == err_ok) call model_from_case(c, m, ierr, errmsg)
  if (ierr /= err_ok) call die(errmsg, ierr)
  allocate(t(m%n_out), y(nstate, m%n_out), tooth(m%n_out, m%z, ntooth_q), tm(m%n_out))
  call run_case(m, t, y, tooth, tm, stats, ierr, errmsg)
  if (ierr /= err_ok) call die(errmsg, ierr)

  open(newunit=u, file=trim(out), status='replace', action='write', iostat=ierr)
  if (ierr /= 0) call die('cannot write '//trim(out), 1)
  write(u, '(a)') '# spline-dyn output (pyspline): SI units, per-tooth columns Q_j for teeth j = 1..Z'
  write(u, '(a)') '# case: '//trim(m%name)//' ('//trim(path)//')'
  write(u, '(a,es24.16e3,a)') '# k_m: ', m%k_m, merge(' N/m (computed, Eq. 18)', ' N/m (case)            ', &
       m%k_m_computed)
  write(u, '(a)', advance='no') '# stats:'
  do i = 1, nstats
    write(u, '(1x,a,"=",g0)', advance='no') trim(stat_names(i)), stats(i)
  end do
  write(u, '(a)') ''
  write(u, '(a)', advance='no') 't [s]'
  do i = 1, nstate
    write(u, '(a)', advance='no') ','//trim(state_names(i))//merge(' [m]  ', ' [m/s]', i <= 7)
  end do
  write(u, '(a)', advance='no') ',Tm [N m],kv [-]'
  do q = 1, ntooth_q
    do j = 1, m%z
      write(u, '(",",a,"_",i0," [",a,"]")', advance='no') trim(tooth_q_names(q)), j, &
           trim(tooth_q_units(q))
    end do
  end do
  write(u, '(a)') ''
  do k = 1, m%n_out
    write(u, '(es24.16e3,*(:,",",es24.16e3))') t(k), y(:, k), tm(k), abs(tm(k))/m%t_d, &
         ((tooth(k, j, q), j = 1, m%z), q = 1, ntooth_q)
  end do
  close(u)

  write(*, '(a)') 'case '//trim(m%name)//': '//trim(out)
  write(*, '(a)', advance='no') '  mesh stiffness, potential energy method (Eq. 18) [N/m]:'
  do i = 1, nkterms
    write(*, '(1x,a,"=",es11.4)', advance='no') trim(kterm_names(i)), m%k_terms(i)
  end do
  write(*, '(a)') ''
  write(*, '(a,es11.4,a)') '  k_m used: ', m%k_m, merge(' N/m (computed)', ' N/m (case)    ', &
       m%k_m_computed)
  write(*, '(a,i0,a,es10.3,a,es10.3,a)') '  outputs ', m%n_out, ' on [', t(1), ', ', t(m%n_out), '] s'
  write(*, '(a,2es12.4)') '  meshing torque T_m min/max [N m]: ', minval(tm), maxval(tm)
  write(*, '(a,2es12.4)') '  tooth force F_j min/max [N]:      ', minval(tooth(:, :, 1)), &
       maxval(tooth(:, :, 1))
  do i = 1, nstats
    write(*, '(2x,a24,g0)') stat_names(i), stats(i)
  end do

contains

  subroutine usage(code)
    integer, intent(in) :: code
    write(*, '(a)') 'usage: spline-dyn CASE.nml [-o OUT.csv]'
    write(*, '(a)') '  runs one pyspline case (namelist &spline_case) and writes a CSV'
    stop code
  end subroutine usage

  !> Print the message to stderr and exit with the status of the error code (spline_errors).
  subroutine die(msg, ierr)
    character(len=*), intent(in) :: msg
    integer, intent(in) :: ierr
    write(0, '(a)') 'spline-dyn: error: '//trim(msg)
    error stop err_exit_code(ierr), quiet=.true.
  end subroutine die

end program spline_dyn
