!> spline-dyn: the standalone (HPC) driver. Reads a case namelist, runs it with the same core
!> as the Python package, and writes a self-describing CSV (one header row naming every column
!> with its unit, '#' lines with the case and the solver statistics).
!>   usage: spline-dyn CASE.nml [-o OUT.csv] [--summary FILE] [--set FIELD=VALUE]...
!>          | --version | --help
!> --summary FILE writes the per-run summary a sweep point keeps (write_summary: the statistics,
!> the loads, T_m / k_v / F extremes and RMS, the Poincare section and the Benettin record,
!> the case), no time series; with --summary and no -o no CSV is written. Every run asked for
!> a summary writes one, a failed run too (a bad case, a failed build or run: the error, its
!> kind and exit code, and the case if every --set was read; pyspline merge records it).
!> -o and --summary take a regular file or a new path (never a FIFO, a device, a directory),
!> once each, and never the same file (compared as files, not as strings).
!> Errors and usage go to stderr, warnings as 'spline-dyn: warning: ...' lines; the exit status
!> says what failed (spline_errors err_exit_code): 0 ok, 2 bad input or usage, 3 solver
!> failure, 4 thermal interference, 130 interrupted (SIGINT). The output is checked before the
!> run (writable, not the case file itself), written to a temporary name next to it and
!> renamed when complete, so a failed or interrupted run leaves what was there untouched.
program spline_dyn
  use, intrinsic :: iso_c_binding, only: c_char, c_double, c_int, c_long_long, c_null_char
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use spline_kinds, only: wp
  use spline_errors, only: err_ok, err_case, err_interrupted, err_exit_code, msglen, err_names
  use spline_case, only: case_t, case_read_file, case_parse, case_name_of, case_write_text, &
       c_file_kind
  use spline_model, only: model_t, model_from_case, model_warnings, nstate, nkterms, kterm_names
  use spline_run, only: run_case, run_results
  use spline_mesh, only: start_warning
  use spline_quantities, only: nstats, stat_q, state_q, ntooth_q, tooth_q, nout_q, output_q, nload, &
       load_q, nload_tooth, load_tooth_q, il_load_sharing, il_free_mean, il_back_teeth, &
       il_impacts_rev, il_closing_speed, il_tf_max, il_tf_max_tooth, il_tf_max_t, il_sigma_root, &
       il_sigma_flank, il_tau_pitch, il_batches, il_tm_rms_se, il_sharing_rev, il_sharing_rev_se, &
       il_free_mean_se, il_impacts_rev_se, il_tf_rev, il_tf_rev_se, il_stress_ratio, nextreme, &
       extreme_q
  use spline_realisations, only: copy_model, copy_start, run_sections, transient_state, &
       combined_stats
  use spline_sections, only: section_count
  use spline_loads, only: load_coefficient
  use spline_lyapunov, only: lyapunov_count
  implicit none

  type :: string_t
    character(len=:), allocatable :: s
  end type string_t

  interface   ! fortran/interface/fileinfo.c
    integer(c_int) function c_same_file(a, b) bind(C, name='spline_same_file')
      import :: c_char, c_int
      character(kind=c_char), intent(in) :: a(*), b(*)
    end function c_same_file
    integer(c_int) function c_rename(from, to, errbuf, errlen) bind(C, name='spline_rename')
      import :: c_char, c_int
      character(kind=c_char), intent(in) :: from(*), to(*)
      character(kind=c_char), intent(out) :: errbuf(*)
      integer(c_int), value :: errlen
    end function c_rename
    subroutine c_unlink(path) bind(C, name='spline_unlink')
      import :: c_char
      character(kind=c_char), intent(in) :: path(*)
    end subroutine c_unlink
    integer(c_int) function c_getpid() bind(C, name='spline_getpid')
      import :: c_int
    end function c_getpid
    subroutine c_version(buf, buflen) bind(C, name='spline_version')
      import :: c_char, c_int
      character(kind=c_char), intent(out) :: buf(*)
      integer(c_int), value :: buflen
    end subroutine c_version
    integer(c_int) function c_sigint_watch() bind(C, name='spline_sigint_watch')   ! interrupt.c
      import :: c_int
    end function c_sigint_watch
    integer(c_int) function c_sigint_count() bind(C, name='spline_sigint_count')
      import :: c_int
    end function c_sigint_count
    integer(c_int) function c_csv_record(x, n, buf, cap) bind(C, name='spline_csv_record')
      import :: c_char, c_double, c_int                       ! fortran/interface/csvrow.c
      real(c_double), intent(in) :: x(*)
      integer(c_int), value :: n, cap
      character(kind=c_char), intent(out) :: buf(*)
    end function c_csv_record
  end interface

  character(len=:), allocatable :: path, out, arg, tmp, record, summary, stmp, text, start
  character(len=:), allocatable :: warned   !< the warnings printed, one per line (the summary's)
  type(string_t), allocatable :: sets(:)
  character(len=msglen) :: errmsg
  character(len=256) :: iomsg
  type(case_t) :: c
  type(model_t) :: m
  real(wp), allocatable :: t(:), y(:, :), tooth(:, :, :), tm(:)
  real(c_double), allocatable :: row(:)
  real(wp) :: stats(nstats), loads(nload), ext(nextreme)
  real(wp), allocatable :: tload(:, :), sec_t(:), sec_y(:, :), lyap_t(:), lyap_g(:)
  real(wp) :: wall
  integer :: ierr, i, j, k, n, q, u, su, nargs, nsets, ios, nt
  integer(8) :: c0, c1, rate
  integer(c_int) :: sigint0
  logical :: have_out, have_summary, write_csv, options_done, have_case, summary_open

  ! arguments (any length: allocated from get_command_argument's length)
  nargs = command_argument_count()
  allocate(sets(nargs))
  nsets = 0
  have_out = .false.
  have_summary = .false.
  warned = ''
  have_case = .false.
  summary_open = .false.
  options_done = .false.
  i = 1
  do while (i <= nargs)
    call argument(i, arg)
    if (.not. options_done .and. len(arg) > 1 .and. arg(1:1) == '-') then
      select case (arg)
      case ('-h', '--help')
        call usage(output_unit)
        stop 0, quiet=.true.
      case ('--version')
        call version(arg)
        write(*, '(a)') 'spline-dyn (pyspline) '//arg
        stop 0, quiet=.true.
      case ('-o', '--output')
        if (i == nargs) call usage_error(arg//' needs a file name')
        i = i + 1
        call argument(i, out)
        have_out = .true.
      case ('--summary')
        if (i == nargs) call usage_error(arg//' needs a file name')
        i = i + 1
        call argument(i, arg)
        call set_summary(arg)
      case ('--set')
        if (i == nargs) call usage_error('--set needs FIELD=VALUE')
        i = i + 1
        nsets = nsets + 1
        call argument(i, sets(nsets)%s)
      case ('--')
        options_done = .true.
      case default
        if (len(arg) > 6 .and. arg(1:min(6, len(arg))) == '--set=') then
          nsets = nsets + 1
          sets(nsets)%s = arg(7:)
        else if (len(arg) > 9 .and. arg(1:min(9, len(arg))) == '--output=') then
          out = arg(10:)
          have_out = .true.
        else if (len(arg) > 10 .and. arg(1:min(10, len(arg))) == '--summary=') then
          call set_summary(arg(11:))
        else
          call usage_error('unknown option '//arg)
        end if
      end select
    else if (allocated(path)) then
      call usage_error('unexpected argument '''//arg//''' after the case file '''//path// &
           ''' (one case per run)')
    else
      path = arg
    end if
    i = i + 1
  end do
  if (.not. allocated(path)) call usage_error('no case file given')
  if (have_summary) then
    if (len(summary) == 0) call usage_error('--summary needs a file name')
  end if
  write_csv = have_out .or. .not. have_summary
  if (have_out) then
    if (len(out) == 0) call usage_error('-o needs a file name')
  else
    out = trim(case_name_of(path))//'.csv'
  end if

  ! the outputs, before anything else: a regular file or a new path, never the case file, not
  ! each other; the summary opened (a temporary name next to it, renamed when complete) so
  ! that whatever fails from here is recorded in it
  if (write_csv) call check_output(out, 'the output', '-o')
  if (have_summary) then
    call check_output(summary, 'the summary', '--summary')
    if (write_csv) then
      if (c_same_file(summary//c_null_char, out//c_null_char) /= 0) &
           call usage_error('the summary '//summary//' and the CSV '//out//' are the same file')
    end if
    call temp_name(summary, stmp)
    open(newunit=su, file=stmp, status='replace', action='write', iostat=ios, iomsg=iomsg)
    if (ios /= 0) call die('cannot write the summary '//summary//': '//trim(iomsg), err_case)
    summary_open = .true.
  end if

  ! the case: the file, then the --set overrides, then validation and the model
  call case_read_file(path, c, ierr, errmsg)
  do j = 1, nsets
    if (ierr /= err_ok) exit
    call case_parse('&spline_case '//sets(j)%s//' /', c, ierr, errmsg, '--set '//sets(j)%s, &
         show_lines=.false.)
  end do
  have_case = ierr == err_ok       ! the case as asked for (its values may still be refused)
  if (ierr == err_ok) call model_from_case(c, m, ierr, errmsg)
  if (ierr /= err_ok) call die(errmsg, ierr)

  ! the CSV, before the run: writable (a temporary name next to it, renamed when complete)
  if (write_csv) then
    call temp_name(out, tmp)
    open(newunit=u, file=tmp, status='replace', action='write', iostat=ios, iomsg=iomsg)
    if (ios /= 0) call die('cannot write the output '//out//': '//trim(iomsg), err_case)
  end if
  ! From here a SIGINT is counted, not fatal (fortran/integration/interrupt.c): the run stops at its next
  ! right-hand side, the temporary file is removed, and the exit status is 130.
  sigint0 = c_sigint_watch()

  call start_warning(m, start)
  call model_warnings(m, start, text)
  call print_warnings(text)
  nt = m%n_out*m%realisations    ! realisations = K: K copies of n_out outputs, one after another
  allocate(t(nt), y(nstate, nt), tooth(nt, m%z, ntooth_q), tm(nt))
  call system_clock(c0, rate)
  if (m%realisations > 1) then
    call run_copies()
  else if (have_summary) then  ! the section and the Benettin record, as Python's api_simulate
    allocate(sec_t(section_count(m)), sec_y(nstate, section_count(m)), &
         lyap_t(lyapunov_count(m)), lyap_g(lyapunov_count(m)))
    call run_case(m, t, y, tooth, tm, stats, ierr, errmsg, interruptible=.true., sec_t=sec_t, &
         sec_y=sec_y, lyap_t=lyap_t, lyap_g=lyap_g)
  else
    call run_case(m, t, y, tooth, tm, stats, ierr, errmsg, interruptible=.true.)
  end if
  call system_clock(c1)
  wall = real(c1 - c0, wp)/rate
  if (ierr /= err_ok) then
    if (write_csv) close(u, status='delete', iostat=ios)
    call die(errmsg, ierr)       ! a failed point is a result: die writes its summary
  end if
  call check_interrupt()
  call print_warnings(trim(errmsg))            ! the integrator's (SUNDIALS') warnings, counted
  allocate(tload(m%z, nload_tooth))
  call run_results(m, t, y, tooth, tm, stats, [(0.0_wp, i = 1, ntooth_q - 4)], loads, tload, ext, &
       text)                                   ! K > 1: all copies' outputs, combined stats
  call print_warnings(text)                    ! the run's, then its loads' (stresses, T_f)
  if (have_summary) call write_summary(.true., '', err_ok)
  if (.not. write_csv) then
    write(*, '(a)') 'case '//trim(m%name)//': '//summary
    call report_loads()
    stop 0, quiet=.true.
  end if

  write(u, '(a)', iostat=ios) '# spline-dyn output (pyspline): SI units, per-tooth columns Q_j '// &
       'for teeth j = 1..Z'
  write(u, '(a)', iostat=ios) '# case: '//trim(m%name)//' ('//path//')'
  write(u, '(a,es24.16e3,a)', iostat=ios) '# k_m: ', m%k_m, &
       merge(' N/m (computed, Eq. 18)', ' N/m (case)            ', m%k_m_computed)
  write(u, '(a)', advance='no', iostat=ios) '# stats:'
  do i = 1, nstats
    write(u, '(1x,a,"=",g0)', advance='no', iostat=ios) trim(stat_q(i)%name), stats(i)
  end do
  write(u, '(a)', iostat=ios) ''
  ! the loads of the run (spline_loads::run_loads): the scalars, then one line per per-tooth
  ! quantity with its unit and a value for each tooth j = 1..Z
  write(u, '(a)', advance='no', iostat=ios) '# loads:'
  do i = 1, nload
    write(u, '(1x,a,"=",g0)', advance='no', iostat=ios) trim(load_q(i)%name), loads(i)
  end do
  write(u, '(a)', iostat=ios) ''
  do q = 1, nload_tooth
    write(u, '(a," [",a,"]:")', advance='no', iostat=ios) '# tooth loads '// &
         trim(load_tooth_q(q)%name), trim(load_tooth_q(q)%unit)
    do j = 1, m%z
      write(u, '(1x,g0)', advance='no', iostat=ios) tload(j, q)
    end do
    write(u, '(a)', iostat=ios) ''
  end do
  ! the header: every column 'NAME [UNIT]' (spline_quantities output_q, its order), per-tooth
  ! quantities as NAME_j for teeth j = 1..Z
  do i = 1, nout_q - ntooth_q
    if (i > 1) write(u, '(a)', advance='no', iostat=ios) ','
    write(u, '(a," [",a,"]")', advance='no', iostat=ios) trim(output_q(i)%name), &
         trim(output_q(i)%unit)
  end do
  do q = 1, ntooth_q
    do j = 1, m%z
      write(u, '(",",a,"_",i0," [",a,"]")', advance='no', iostat=ios) trim(tooth_q(q)%name), j, &
           trim(tooth_q(q)%unit)
    end do
  end do
  write(u, '(a)', iostat=ios) ''
  ! the records, formatted by fortran/interface/csvrow.c: 17 significant digits (exact), a quarter of the
  ! time of an ES edit descriptor
  allocate(row(1 + nstate + 2 + m%z*ntooth_q))
  allocate(character(len=26*size(row)) :: record)
  do k = 1, size(t)
    if (ios /= 0) exit
    row = [t(k), y(:, k), tm(k), load_coefficient(tm(k), m%t_d), &   ! the columns of output_q
         ((tooth(k, j, q), j = 1, m%z), q = 1, ntooth_q)]
    n = c_csv_record(row, size(row), record, len(record))
    if (n < 0) then                        ! cannot happen: a number takes at most 26 bytes
      ios = 1
      iomsg = 'a record longer than its buffer'
      exit
    end if
    write(u, '(a)', iostat=ios, iomsg=iomsg) record(1:n)
  end do
  if (ios /= 0) then
    close(u, status='delete', iostat=i)
    call die('cannot write the output '//out//': '//trim(iomsg), err_case)
  end if
  close(u, iostat=ios, iomsg=iomsg)
  if (ios /= 0) then
    call c_unlink(tmp//c_null_char)
    call die('cannot write the output '//out//': '//trim(iomsg), err_case)
  end if
  if (c_sigint_count() /= sigint0) then
    call c_unlink(tmp//c_null_char)
    call check_interrupt()
  end if
  call rename_into(tmp, out)

  write(*, '(a)') 'case '//trim(m%name)//': '//out
  write(*, '(a)', advance='no') '  mesh stiffness, potential energy method (Eq. 18) [N/m]:'
  do i = 1, nkterms
    write(*, '(1x,a,"=",es11.4)', advance='no') trim(kterm_names(i)), m%k_terms(i)
  end do
  write(*, '(a)') ''
  write(*, '(a,es11.4,a)') '  k_m used: ', m%k_m, merge(' N/m (computed)', ' N/m (case)    ', &
       m%k_m_computed)
  write(*, '(a,i0,a,es10.3,a,es10.3,a)') '  outputs ', size(t), ' on [', minval(t), ', ', maxval(t), '] s'
  write(*, '(a,2es12.4)') '  meshing torque T_m min/max [N m]: ', minval(tm), maxval(tm)
  write(*, '(a,2es12.4)') '  tooth force F_j min/max [N]:      ', minval(tooth(:, :, 1)), &
       maxval(tooth(:, :, 1))
  call report_loads()
  do i = 1, nstats
    write(*, '(2x,a24,g0)') stat_q(i)%name, stats(i)
  end do

contains

  !> realisations = K > 1 (spline_realisations, docs/accuracy.md): the transient once, then the
  !> K copies on OpenMP threads (OMP_NUM_THREADS), copy k into outputs (k - 1) n_out + 1 .. k n_out
  !> of t, y, tooth, tm and its section after the one before; stats the copies' combined; ierr,
  !> errmsg the first failed copy's (its SUNDIALS warnings printed, as Python warns them).
  subroutine run_copies()
    real(wp) :: ya(nstate), st(nstats, m%realisations)
    integer :: kk, a, ns, ie(m%realisations)
    character(len=msglen) :: msg(m%realisations)
    ns = run_sections(m)
    allocate(sec_t(ns*m%realisations), sec_y(nstate, ns*m%realisations), lyap_t(0), lyap_g(0))
    call transient_state(m, ya, ierr, errmsg, interruptible=.true.)
    if (ierr /= err_ok) return
    n = m%n_out
    !$omp parallel do schedule(static, 1) private(a)
    do kk = 1, m%realisations
      a = (kk - 1)*n
      call run_case(copy_model(m), t(a + 1:a + n), y(:, a + 1:a + n), tooth(a + 1:a + n, :, :), &
           tm(a + 1:a + n), st(:, kk), ie(kk), msg(kk), interruptible=.true., &
           sec_t=sec_t((kk - 1)*ns + 1:kk*ns), sec_y=sec_y(:, (kk - 1)*ns + 1:kk*ns), &
           y_start=copy_start(kk, ya))
    end do
    !$omp end parallel do
    call combined_stats(st, stats)
    errmsg = ''
    do kk = 1, m%realisations
      ierr = ie(kk)
      if (ierr /= err_ok) then
        errmsg = msg(kk); return
      end if
      call print_warnings(trim(msg(kk)))
    end do
  end subroutine run_copies

  !> The loads of the run on stdout (spline_loads::run_loads, docs/model.md section 15): which
  !> teeth carry what, rattle, flash temperature, stresses and their limits, standard errors.
  subroutine report_loads()
  write(*, '(a,f8.3,a,f6.2,a,i0,a,f8.3,a,es10.3,a)') '  load sharing factor ', &
       loads(il_load_sharing), ', free teeth (mean) ', loads(il_free_mean), &
       ', teeth on the back flank ', nint(loads(il_back_teeth)), ', impacts/rev ', &
       loads(il_impacts_rev), ', closing speed max ', loads(il_closing_speed), ' m/s'
  write(*, '(a,es11.4,a,i0,a,es11.4,a)') '  flash temperature T_f max [degC]: ', &
       loads(il_tf_max), ' (tooth ', nint(loads(il_tf_max_tooth)), ', t = ', loads(il_tf_max_t), ' s)'
  write(*, '(a,3f10.2)') '  tooth stresses root bending / flank bearing / shear at pitch [MPa]:', &
       1.0e-6_wp*loads([il_sigma_root, il_sigma_flank, il_tau_pitch])
  write(*, '(a,f7.1,a)') '  largest stress over its typical allowable (docs/model.md section 15):', &
       100.0_wp*loads(il_stress_ratio), ' %'
  write(*, '(a,i0,a)') '  standard errors (overlapping batch means of ', nint(loads(il_batches)), &
       ' whole revolutions; NaN: fewer than 2):'
  write(*, '(a,es11.4,a,f8.3,a,es10.3,a,f6.2,a,es10.3,a,f8.3,a,es10.3,a,es11.4,a,es10.3)') &
       '    T_m RMS +- ', loads(il_tm_rms_se), '; load sharing per revolution ', &
       loads(il_sharing_rev), ' +- ', loads(il_sharing_rev_se), '; free teeth ', &
       loads(il_free_mean), ' +- ', loads(il_free_mean_se), '; impacts/rev ', &
       loads(il_impacts_rev), ' +- ', loads(il_impacts_rev_se), '; T_f max per revolution ', &
       loads(il_tf_rev), ' +- ', loads(il_tf_rev_se)
  end subroutine report_loads

  ! The text helpers are subroutines, as in the core (docs/developing.md, "Thread safety").

  !> Command argument i, whatever its length.
  subroutine argument(i, s)
    integer, intent(in) :: i
    character(len=:), allocatable, intent(out) :: s
    integer :: n
    call get_command_argument(i, length=n)
    allocate(character(len=n) :: s)
    if (n > 0) call get_command_argument(i, s)
  end subroutine argument

  subroutine version(s)
    character(len=:), allocatable, intent(out) :: s
    character(kind=c_char) :: buf(256)
    integer :: i
    buf = c_null_char
    call c_version(buf, int(size(buf), c_int))
    s = ''
    do i = 1, size(buf)
      if (buf(i) == c_null_char) exit
      s = s//buf(i)
    end do
  end subroutine version

  !> A temporary name in the output's directory: .NAME.tmp-PID (hidden, this process's own).
  subroutine temp_name(file, s)
    character(len=*), intent(in) :: file
    character(len=:), allocatable, intent(out) :: s
    character(len=16) :: pid
    integer :: slash
    write(pid, '(i0)') c_getpid()
    slash = index(file, '/', back=.true.)
    s = file(1:slash)//'.'//file(slash+1:)//'.tmp-'//trim(pid)
  end subroutine temp_name

  subroutine rename_into(from, to)
    character(len=*), intent(in) :: from, to
    character(kind=c_char) :: buf(256)
    character(len=256) :: why
    integer :: i
    buf = c_null_char
    if (c_rename(from//c_null_char, to//c_null_char, buf, int(size(buf), c_int)) == 0) return
    why = ''
    do i = 1, size(buf)
      if (buf(i) == c_null_char) exit
      why(i:i) = buf(i)
    end do
    call c_unlink(from//c_null_char)
    call die('cannot write the output '//to//': '//trim(why), err_case)
  end subroutine rename_into

  !> The summary of the run (what a sweep point keeps; pyspline merge reads it, pyspline/
  !> batch.py): '#' comments; lines NAME [UNIT] = VALUES, the numbers comma-separated with 17
  !> significant digits (every double reads back exactly; units of spline_quantities); lines
  !> NAME = 'TEXT' (warnings: the 'warning:' lines printed, without their prefix); then the
  !> case as a namelist (every field). ok: the run finished, else the
  !> summary has the error (msg, its kind and exit code from code), the --set options and the
  !> case if every --set was read (have_case). Written to a temporary name and renamed when
  !> complete.
  subroutine write_summary(ok, msg, code)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: msg
    integer, intent(in) :: code
    character(len=:), allocatable :: text
    integer, parameter :: id2 = 6, ivd2 = 13
    integer :: i2, nt
    summary_open = .false.
    ios = 0
    call version(text)
    write(su, '(a)', iostat=ios) '# spline-dyn summary (pyspline '//text//'): one run, '// &
         'SI units; NAME [UNIT] = VALUES (17 significant digits), then the case'
    write(su, '(a)', iostat=ios) "format = 'pyspline-summary 1'"
    call put_text('case_file', path)
    ! the warning lines printed, as a sweep point keeps them
    if (len(warned) > 0) call put_text('warnings', warned(1:len(warned) - 1))
    if (.not. ok) then
      call put_text('error', trim(msg))
      call put_text('error_kind', trim(err_names(code)))
      write(su, '(a,i0)', iostat=ios) 'exit_code [] = ', err_exit_code(code)
      do i2 = 1, nsets
        call put_text('set', sets(i2)%s)
      end do
    else
      do i2 = 1, nstats
        call put('stats.'//stat_q(i2)%name, stat_q(i2)%unit, [stats(i2)])
      end do
      call put('run.wall_s', 's', [wall])
      do i2 = 1, nload
        call put('loads.'//load_q(i2)%name, load_q(i2)%unit, [loads(i2)])
      end do
      do i2 = 1, nload_tooth
        call put('tooth_loads.'//load_tooth_q(i2)%name, load_tooth_q(i2)%unit, tload(:, i2))
      end do
      call put('model.spacing_error', 'm', m%spacing_error(1:m%z))   ! in use: list + seeded
      nt = size(t)
      call put('run.t_first', 's', t(1:min(1, nt)))
      do i2 = 1, nextreme                  ! spline_run::run_results' (Python's too)
        call put('run.'//extreme_q(i2)%name, extreme_q(i2)%unit, [ext(i2)])
      end do
      call put('section.t', 's', sec_t)
      call put('section.D2', state_q(id2)%unit, sec_y(id2, :))
      call put('section.vD2', state_q(ivd2)%unit, sec_y(ivd2, :))
      call put('lyapunov.t', 's', lyap_t)
      call put('lyapunov.log_growth', '', lyap_g)
    end if
    if (have_case) then
      call case_write_text(c, text)
      if (ios == 0) write(su, '(a)', advance='no', iostat=ios, iomsg=iomsg) text
    end if
    if (ios == 0) close(su, iostat=ios, iomsg=iomsg)
    if (ios /= 0) then
      close(su, status='delete', iostat=i2)
      call c_unlink(stmp//c_null_char)
      call die('cannot write the summary '//summary//': '//trim(iomsg), err_case)
    end if
    call rename_into(stmp, summary)
  end subroutine write_summary

  !> One summary line: NAME [UNIT] = x(1),x(2),... (fortran/interface/csvrow.c: 17 significant digits).
  subroutine put(name, unit, x)
    character(len=*), intent(in) :: name, unit
    real(wp), intent(in) :: x(:)
    character(len=:), allocatable :: buf
    integer :: nb
    if (ios /= 0) return
    allocate(character(len=26*size(x) + 1) :: buf)
    nb = c_csv_record(real(x, c_double), size(x), buf, len(buf))
    write(su, '(a)', iostat=ios, iomsg=iomsg) trim(name)//' ['//trim(unit)//'] = '// &
         buf(1:max(nb, 0))
  end subroutine put

  !> One summary line NAME = 'TEXT': in single quotes, a quote doubled and a line break
  !> written as \n.
  subroutine put_text(name, text)
    character(len=*), intent(in) :: name, text
    character(len=:), allocatable :: s
    integer :: i2
    s = "'"
    do i2 = 1, len(text)
      if (text(i2:i2) == "'") then
        s = s//"''"
      else if (text(i2:i2) == new_line('a')) then
        s = s//'\n'
      else
        s = s//text(i2:i2)
      end if
    end do
    write(su, '(a)', iostat=ios) name//' = '//s//"'"
  end subroutine put_text

  !> A SIGINT since the watch began: remove the temporary files, exit 130.
  subroutine check_interrupt()
    integer :: ios2
    if (c_sigint_count() == sigint0) return
    if (write_csv) close(u, status='delete', iostat=ios2)
    call die('case '//trim(m%name)//': interrupted (SIGINT)', err_interrupted)
  end subroutine check_interrupt

  subroutine print_warnings(text)
    character(len=*), intent(in) :: text
    integer :: a, b
    a = 1
    do while (a <= len(text))
      b = index(text(a:), new_line('a'))
      if (b == 0) then
        b = len(text) + 1
      else
        b = a + b - 1
      end if
      if (b > a) then
        write(error_unit, '(a)') 'spline-dyn: warning: '//text(a:b-1)
        warned = warned//text(a:b-1)//new_line('a')
      end if
      a = b + 1
    end do
  end subroutine print_warnings

  subroutine usage(unit)
    integer, intent(in) :: unit
    write(unit, '(a)') 'usage: spline-dyn CASE.nml [-o OUT.csv] [--summary FILE] [--set FIELD=VALUE]...'
    write(unit, '(a)') '       spline-dyn --version | --help'
    write(unit, '(a)') '  runs one pyspline case (namelist &spline_case) and writes a CSV (default: '// &
         'the case file''s stem .csv)'
    write(unit, '(a)') '  --summary FILE     writes the run''s summary (no time series; no CSV '// &
         'without -o): pyspline merge'
    write(unit, '(a)') '  --set FIELD=VALUE  replaces a field of the case file (repeatable; '// &
         'strings in quotes)'
    write(unit, '(a)') '  exit status: 0 ok, 2 bad input or usage, 3 solver failure, '// &
         '4 thermal interference, 130 interrupted'
  end subroutine usage

  !> A usage error: the reason and the usage on stderr, exit status 2.
  subroutine usage_error(why)
    character(len=*), intent(in) :: why
    write(error_unit, '(a)') 'spline-dyn: error: '//why
    call usage(error_unit)
    stop 2, quiet=.true.
  end subroutine usage_error

  !> --summary FILE: once.
  subroutine set_summary(file)
    character(len=*), intent(in) :: file
    if (have_summary) call usage_error('--summary given twice ('''//summary//''' and '''// &
         file//'''): one summary per run')
    summary = file
    have_summary = .true.
  end subroutine set_summary

  !> An output (what: 'the output', 'the summary'; opt: its option) is a regular file or a
  !> new path, and not the case file: else exit 2, the node untouched.
  subroutine check_output(file, what, opt)
    character(len=*), intent(in) :: file, what, opt
    character(kind=c_char) :: buf(256)
    integer(c_long_long) :: nbytes
    character(len=:), allocatable :: is
    buf = c_null_char
    select case (c_file_kind(file//c_null_char, nbytes, buf, int(size(buf), c_int)))
    case (0, -1); is = ''
    case (1); is = 'a directory'
    case (2); is = 'a FIFO (named pipe)'
    case (3); is = 'a character device'
    case (4); is = 'a block device'
    case (5); is = 'a socket'
    case (-2); is = 'a dangling symbolic link'
    case default; is = 'not a regular file'
    end select
    if (len(is) > 0) call die(what//' '//file//' is '//is//': '//opt// &
         ' takes a regular file or a new path', err_case)
    if (c_same_file(path//c_null_char, file//c_null_char) /= 0) &
         call die(what//' '//file//' is the case file '//path//': not overwritten '// &
         '(give another '//opt//')', err_case)
  end subroutine check_output

  !> Print the message to stderr and exit with the status of the error code (spline_errors);
  !> an open summary records the error first (not an interrupt: its temporary file goes).
  subroutine die(msg, ierr)
    character(len=*), intent(in) :: msg
    integer, intent(in) :: ierr
    integer :: code
    if (summary_open .and. ierr /= err_interrupted) then
      call write_summary(.false., msg, ierr)
    else if (summary_open) then
      summary_open = .false.
      close(su, status='delete', iostat=code)
    end if
    write(error_unit, '(a)') 'spline-dyn: error: '//trim(msg)
    code = err_exit_code(ierr)
    stop code, quiet=.true.
  end subroutine die

end program spline_dyn
