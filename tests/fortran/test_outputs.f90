!> spline_mesh's mesh_outputs (the per-tooth outputs in one pass per tooth, run.f90's
!> bulk_tooth_outputs) against mesh_eval (the definition, run.f90's tooth_quantities) at every
!> output of every shipped case (the case files are the arguments, meson.build): each case run
!> for 20 ms, 201 outputs, as a level mesh_outputs serves (one slice, no angular misalignment,
!> thermal none or bulk).
!> F, F_x, F_y, dn and T_m must agree to the bit (mesh_outputs repeats mesh_eval's arithmetic
!> operation for operation), and the run must not fall back to mesh_eval (outputs_fallback).
program test_outputs
  use spline_kinds, only: wp
  use spline_case, only: case_t, case_read_file
  use spline_model, only: model_t, model_from_case, set_thermal_level, nstate, thermal_bulk
  use spline_quantities, only: nstats, ntooth_q
  use spline_dynamics, only: start_state
  use spline_solver, only: integrate
  use spline_run, only: output_times, tooth_outputs, tooth_quantities
  use check, only: check_true, check_done
  implicit none
  integer, parameter :: nt = 201
  character(len=1024) :: path
  character(len=512) :: msg
  type(case_t) :: c
  type(model_t) :: m
  real(wp) :: t(nt), y(nstate, nt), y0(nstate), stats(nstats), tm(nt), tmk, dmax, fmax
  real(wp), allocatable :: tooth(:, :, :), row(:, :)
  integer, allocatable :: modes(:, :)
  integer :: i, k, ierr
  logical :: fallback

  do i = 1, command_argument_count()
    call get_command_argument(i, path)
    msg = ''
    call case_read_file(trim(path), c, ierr, msg)
    call check_true('read '//trim(path), ierr == 0, trim(msg))
    c%t_transient = 0; c%revolutions = 0; c%transient_revolutions = 0
    c%outputs_per_revolution = 0; c%t_end = c%t0 + 2.0e-2_wp; c%n_out = nt
    c%n_slices = 1; c%gamma_x = 0; c%gamma_y = 0     ! no slices: no angular misalignment
    call model_from_case(c, m, ierr, msg)
    call check_true('model '//trim(path), ierr == 0, trim(msg))
    if (ierr /= 0) cycle
    call set_thermal_level(m, min(m%thermal, thermal_bulk))
    allocate(tooth(nt, m%z, ntooth_q), row(m%z, ntooth_q), modes(m%z, nt))
    call output_times(m, t)
    call start_state(m, y0, ierr, msg)
    if (ierr == 0) call integrate(m, y0, nt, t, y, modes, stats, ierr, msg)
    call check_true('run '//trim(path), ierr == 0, trim(msg))
    call tooth_outputs(m, t, y, modes, tooth, tm, ierr, msg, fallback=fallback)
    call check_true('no fallback '//trim(path), ierr == 0 .and. .not. fallback, trim(msg))
    dmax = 0; fmax = 0
    do k = 1, nt
      if (modes(1, k) == 2) then
        call tooth_quantities(m, t(k), y(:, k), row, tmk, ierr, msg)
      else
        call tooth_quantities(m, t(k), y(:, k), row, tmk, ierr, msg, modes(:, k))
      end if
      dmax = max(dmax, maxval(abs(row(:, 1:4) - tooth(k, :, 1:4))), abs(tmk - tm(k)))
      fmax = max(fmax, maxval(abs(row(:, 1))))
    end do
    write(msg, '(a,es10.3,a,es10.3,a)') 'largest |difference| ', dmax, ' (largest |F| ', fmax, ')'
    call check_true('mesh_outputs = mesh_eval at every output '//trim(path), dmax == 0, trim(msg))
    deallocate(tooth, row, modes)
  end do
  call check_true('every shipped case checked', command_argument_count() >= 16)
  call check_done('test_outputs')
end program test_outputs
