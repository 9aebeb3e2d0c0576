!> Instrumentation for the cost anatomy (bench/anatomy.py): CPU seconds per call of the scaled
!> right-hand side (Eq. 25) of a loaded model at its static equilibrium (every tooth in contact,
!> time advanced per call), or cycling over states taken from a run (STATES.bin), and of the root
!> functions. No physics of its own: it calls the core.
!> The meson target time-rhs, linked with the core as spline-dyn is and installed into the package
!> directory (not on PATH), where bench/anatomy.py finds it (an editable install: built on demand).
!>   usage: time-rhs MODEL.bin N [STATES.bin]   (MODEL.bin: the bytes of a loaded case,
!>   pyspline.Model.bytes; STATES.bin: K rows of (t [s], the 14 SI states), doubles, row-major)
!>   prints: CPU seconds per RHS call, per root-function evaluation (CPU: the host is shared)
program time_rhs
  use spline_kinds, only: wp
  use spline_errors, only: err_ok, err_case, err_exit_code, msglen
  use spline_model, only: model_t, model_magic, nstate, ndof
  use spline_mesh, only: mesh_switch_functions
  use spline_dynamics, only: start_state, rhs_scaled, to_scaled, state_units
  use, intrinsic :: iso_fortran_env, only: error_unit, int32
  implicit none
  type(model_t) :: m
  real(wp) :: y(nstate), ys(nstate), f(nstate), acc, dt, t_rhs, t_roots
  real(wp), allocatable :: g(:), st(:, :), tau(:)
  integer(int32), allocatable :: bytes(:)
  integer :: ierr, k, n, u, nbytes, ks, nst
  real(wp) :: c0, c1
  character(len=4096) :: path, arg
  character(len=msglen) :: errmsg

  call get_command_argument(1, path)
  call get_command_argument(2, arg)
  read(arg, *, iostat=ierr) n
  if (ierr /= 0 .or. n < 1) call stop_with(err_case, 'usage: time-rhs MODEL.bin N (N >= 1)')
  open(newunit=u, file=trim(path), access='stream', form='unformatted', status='old', &
       action='read', iostat=ierr)
  if (ierr /= 0) call stop_with(err_case, 'cannot open '//trim(path))
  inquire(unit=u, size=nbytes)
  allocate(bytes(max(nbytes, 0)/4))
  read(u, iostat=ierr) bytes
  close(u)
  if (ierr /= 0 .or. size(bytes) /= size(transfer(m, bytes))) &
       call stop_with(err_case, trim(path)//' is not a loaded case of this build')
  m = transfer(bytes, m)
  if (m%magic /= model_magic) call stop_with(err_case, trim(path)//' is not a loaded case of this build')

  allocate(g(2*m%z*m%n_slices))   ! a switch pair per contact (tooth or slice)
  dt = 1.0e-3_wp/n
  call get_command_argument(3, path)
  if (len_trim(path) > 0) then     ! states of a run: (t, y) rows, scaled here once
    open(newunit=u, file=trim(path), access='stream', form='unformatted', status='old', &
         action='read', iostat=ierr)
    if (ierr /= 0) call stop_with(err_case, 'cannot open '//trim(path))
    inquire(unit=u, size=nbytes)
    nst = nbytes/(8*(nstate + 1))
    if (nst < 1) call stop_with(err_case, trim(path)//' holds no (t, 14 states) row')
    allocate(st(nstate + 1, nst), tau(nst))
    read(u, iostat=ierr) st
    close(u)
    if (ierr /= 0) call stop_with(err_case, 'cannot read '//trim(path))
    do ks = 1, nst
      tau(ks) = st(1, ks)*m%w_ref
      call to_scaled(m, st(2:, ks), ys)
      st(2:, ks) = ys
    end do
    y = st(2:, 1)*state_units(m)     ! the root functions at the first
  else
    m%start_equilibrium = .true.
    m%dq0 = 0; m%dv0 = 0
    call start_state(m, y, ierr, errmsg)
    if (ierr /= err_ok) call stop_with(ierr, errmsg)
    nst = 1
    allocate(st(nstate + 1, 1), tau(1))
    call to_scaled(m, y, ys)
    st(2:, 1) = ys
    tau(1) = m%t0*m%w_ref
  end if
  acc = 0
  call cpu_time(c0)
  do k = 1, n
    ks = mod(k - 1, nst) + 1
    call rhs_scaled(m, tau(ks) + merge(k*dt, 0.0_wp, nst == 1), st(2:, ks), f, ierr, errmsg)
    acc = acc + f(nstate)
  end do
  call cpu_time(c1)
  t_rhs = (c1 - c0)/n
  if (ierr /= err_ok) call stop_with(ierr, errmsg)
  call cpu_time(c0)
  do k = 1, n
    call mesh_switch_functions(m, m%t0 + k*dt, y(1:ndof), g)
    acc = acc + g(1)
  end do
  call cpu_time(c1)
  t_roots = (c1 - c0)/n
  if (acc == 1.2345e300_wp) t_roots = -1     ! keeps both loops from being optimised out
  print '(es23.15,1x,es23.15)', t_rhs, t_roots

contains

  subroutine stop_with(code, msg)
    integer, intent(in) :: code
    character(len=*), intent(in) :: msg
    write(error_unit, '(a)') 'time-rhs: '//trim(msg)
    stop err_exit_code(code), quiet=.true.
  end subroutine stop_with

end program time_rhs
