!> Instrumentation for the cost anatomy (bench/anatomy.py): elapsed seconds per call of the scaled
!> right-hand side (Eq. 25) of a loaded model at its static equilibrium (every tooth in contact,
!> time advanced per call), and of the root functions. No physics of its own: it calls the core.
!> The meson target time-rhs, linked with the core as spline-dyn is and installed into the package
!> directory (not on PATH), where bench/anatomy.py finds it (an editable install: built on demand).
!>   usage: time-rhs MODEL.bin N   (MODEL.bin: the bytes of a loaded case, pyspline.Model.bytes)
!>   prints: seconds per RHS call, seconds per root-function evaluation
program time_rhs
  use spline_kinds, only: wp
  use spline_errors, only: err_ok, err_case, err_exit_code, msglen
  use spline_model, only: model_t, model_magic, nstate, ndof
  use spline_mesh, only: mesh_switch_functions
  use spline_dynamics, only: start_state, rhs_scaled, to_scaled
  use, intrinsic :: iso_fortran_env, only: error_unit, int32
  implicit none
  type(model_t) :: m
  real(wp) :: y(nstate), ys(nstate), f(nstate), acc, dt, t_rhs, t_roots
  real(wp), allocatable :: g(:)
  integer(int32), allocatable :: bytes(:)
  integer :: ierr, k, n, u, nbytes
  integer(8) :: c0, c1, rate
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

  m%start_equilibrium = .true.
  m%dq0 = 0; m%dv0 = 0
  call start_state(m, y, ierr, errmsg)
  if (ierr /= err_ok) call stop_with(ierr, errmsg)
  allocate(g(2*m%z*m%n_slices))   ! a switch pair per contact (tooth or slice)
  call to_scaled(m, y, ys)
  dt = 1.0e-3_wp/n
  acc = 0
  call system_clock(c0, rate)
  do k = 1, n
    call rhs_scaled(m, m%t0*m%w_ref + k*dt, ys, f, ierr, errmsg)
    acc = acc + f(nstate)
  end do
  call system_clock(c1)
  t_rhs = real(c1 - c0, wp)/rate/n
  if (ierr /= err_ok) call stop_with(ierr, errmsg)
  call system_clock(c0)
  do k = 1, n
    call mesh_switch_functions(m, m%t0 + k*dt, y(1:ndof), g)
    acc = acc + g(1)
  end do
  call system_clock(c1)
  t_roots = real(c1 - c0, wp)/rate/n
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
