!> Module spline_linear (fortran/integration/linear.f90): the closed-form tail at many output times at once
!> (tail_states) against the tail at each time (tail_state): the same bits at every anchor and
!> wherever the times are not uniformly spaced; between anchors (the step matrix advancing the
!> motion about the equilibrium) within 1e-12 of the motion's largest excursion per state kind,
!> displacements and velocities (the bound of tail_states: about nanchor n eps |P| ~ 1e-13); in
!> SI units (units = state_units, as the run asks for them) from_scaled's bits of every column.
!> tail_out_of_reach, which lets tail_try skip the switch functions: over random states about the
!> backlash, never where every tooth is on one flank (by the switch functions), and it decides
!> most of the states where not.
program test_linear
  use spline_kinds, only: wp
  use spline_case, only: case_t
  use spline_model, only: model_t, nstate, ndof
  use spline_dynamics, only: start_state, to_scaled, from_scaled, state_units, integrated_states
  use spline_linear, only: tail_t, tail_try, tail_state, tail_states, tail_out_of_reach
  use spline_mesh, only: mesh_switch_functions
  use check, only: check_true, check_done, default_case_model
  implicit none
  integer, parameter :: nt = 1000
  type(case_t) :: cs
  type(model_t) :: md
  type(tail_t) :: tl
  real(wp) :: y(nstate), ys(nstate), taus(nt), tau0, ref(nstate, nt), got(nstate, nt), ex(nstate), &
       err(nstate), scale(2), tol(nstate), si(nstate, nt), col(nstate)
  integer :: idx(nstate), n, i, ierr, nout, nflank, nmiss
  integer, allocatable :: seed(:)
  real(wp), allocatable :: g(:)
  real(wp) :: r(6), c
  character(len=512) :: msg
  logical :: ok

  msg = ''
  cs%l_x = 1.0e-4_wp
  cs%k_m = 254295.0_wp
  cs%dv0(6) = 1.0e-3_wp          ! a small kick of D2 at the static equilibrium: a decaying motion
  call default_case_model(md, cs)
  call start_state(md, y, ierr, msg)
  call check_true('start state', ierr == 0, msg)
  call to_scaled(md, y, ys)
  call integrated_states(md, idx, n)
  tau0 = 0.3_wp
  ok = tail_try(tl, md, idx, n, tau0, ys)
  call check_true('the tail holds from the kicked equilibrium', ok)

  ! uniform output times as spline_run::output_times spaces them (scaled), over 60 revolutions
  taus = [(tau0 + (400.0_wp - tau0)*(i - 1)/real(nt - 1, wp), i = 1, nt)]
  do i = 1, nt
    call tail_state(tl, taus(i), ref(:, i))
  end do
  call tail_states(tl, taus, got)
  call check_true('tail_states: anchors to the bit', all(got(:, 1::32) == ref(:, 1::32)))
  ex = maxval(abs(ref - spread(ref(:, nt), 2, nt)), dim=2)   ! excursion about the end (y*)
  scale = [maxval(ex(1:ndof)), maxval(ex(ndof+1:))]
  tol(1:ndof) = 1.0e-12_wp*scale(1)
  tol(ndof+1:) = 1.0e-12_wp*scale(2)
  err = maxval(abs(got - ref), dim=2)
  call check_true('tail_states: between anchors within 1e-12 of the motion', all(err <= tol), &
       'worst relative error '//trim(fmt(maxval(err/max(tol*1.0e12_wp, tiny(1.0_wp))))))
  call check_true('tail_states: the motion is not trivial', scale(1) > 0 .and. scale(2) > 0 .and. &
       any(got(:, 2::32) /= ref(:, 2::32)))
  call tail_states(tl, taus, si, state_units(md))
  ok = .true.
  do i = 1, nt
    call from_scaled(md, got(:, i), col)
    ok = ok .and. all(si(:, i) == col)
  end do
  call check_true('tail_states in SI units: from_scaled of its scaled states, to the bit', ok)
  ! non-uniform times: every time exact
  taus(2:) = taus(2:) + 1.0e-3_wp*[(mod(i, 3), i = 2, nt)]
  do i = 1, nt
    call tail_state(tl, taus(i), ref(:, i))
  end do
  call tail_states(tl, taus, got)
  call check_true('tail_states: non-uniform times to the bit', all(got == ref))

  ! tail_out_of_reach against the switch functions at 20 000 random states: centre offsets and
  ! D2 within 3 backlashes (all teeth on a flank, some free, all free), random shaft angles
  call random_seed(size=i)
  allocate(seed(i), g(2*md%z))
  seed = 20261127
  call random_seed(put=seed)
  c = md%c_bulk
  nout = 0; nflank = 0; nmiss = 0
  ok = .true.
  do i = 1, 20000
    call random_number(r)
    y = 0.0_wp
    y(1:2) = 3.0_wp*c*(2.0_wp*r(1:2) - 1.0_wp) - [md%l_x, md%l_y]
    y(6) = 3.0_wp*c*(2.0_wp*r(3) - 1.0_wp)
    call mesh_switch_functions(md, r(4), y(1:ndof), g)
    if (all(g(1::2) > 0.0_wp) .or. all(g(2::2) < 0.0_wp)) then
      nflank = nflank + 1
      ok = ok .and. .not. tail_out_of_reach(md, y)
    else if (tail_out_of_reach(md, y)) then
      nout = nout + 1
    else
      nmiss = nmiss + 1
    end if
  end do
  call check_true('tail_out_of_reach: never where every tooth is on one flank', ok)
  call check_true('tail_out_of_reach: both kinds of states sampled', nflank > 100 .and. nout > 100)
  call check_true('tail_out_of_reach: decides most states with a tooth off its flank', &
       nout > 10*nmiss, 'out of reach '//trim(fmt(real(nout, wp)))//', not decided '// &
       trim(fmt(real(nmiss, wp))))
  call check_done('test_linear')
contains
  function fmt(x) result(s)
    real(wp), intent(in) :: x
    character(len=24) :: s
    write(s, '(es10.3)') x
  end function fmt
end program test_linear
