!> The integrator layer: the SUNDIALS objects of one run (SUNDIALS 6.4, Fortran 2003 interface)
!> and every call on them, for the state run (spline_solver::integrate) and the variational run
!> (spline_variational::tangent_flow) alike: CVODE (Adams or BDF, fixed-point or Newton with a
!> dense or a band Jacobian; cvode_create) and ARKODE's ERKStep (erk_create), their work bounds
!> (max_steps between outputs, max_total_steps over the run, a wall-time bound on request:
!> integrator_advance), root finding and the restart after a located switch
!> (integrator_land_on_root, integrator_restart), and SUNDIALS' own messages (lib_handler: never
!> printed; an error's text joins the error message, warnings are counted in the run's log).
!> Counters of a run: add_counters; its failure messages and warnings: spline_integrator_report.
!> Reentrant: everything a run changes sits in its integrator_t (the caller's, a target); the
!> message handler's user data is that run's log, never a module variable.
!>
!> ERKStep (method = 'erk') is an explicit one-step Runge-Kutta pair (Dormand-Prince 5(4), 7
!> stages, ARKODE_DORMAND_PRINCE_7_4_5; Cash-Karp 5(4), 6 stages, with erk_table = 'cash_karp'
!> and goal = 'statistics', docs/accuracy.md) for the scaled system of Eq. 25. Chosen by measurement over Fehlberg's 13-stage 7(8) pair
!> (with switches located, at the defaults): physical_z24 F error 1.6e-5 with 68 700 RHS calls
!> at rtol 1e-8 against 4.7e-5 with 117 700; paper_lx1e-4 2.4e-9 with 7 500 against 8.9e-8 with
!> 7 200. The impacts bound the steps there, not the order. A contact switch (root finding) restarts it for
!> nothing: ERKStepReset keeps its step size and counters, where CVODE restarts at order 1 with
!> a small step. ERKStep uses the same right-hand side and root functions as CVODE (C function
!> pointers and user data). Every SUNDIALS return is checked. ERKStep's dense output is its Hermite
!> interpolant of degree 4 (one right-hand side per step interpolated), of degree 3 (none) at
!> rtol >= 1e-5 (cubic_rtol).
module spline_integrator
  use, intrinsic :: iso_c_binding
  use fcvode_mod
  use farkode_mod, only: ARK_NORMAL, ARK_ROOT_RETURN, ARK_TSTOP_RETURN, ARKODE_DORMAND_PRINCE_7_4_5, &
       ARKODE_CASH_KARP_6_4_5
  use farkode_erkstep_mod
  use fsundials_context_mod
  use fsundials_nvector_mod
  use fnvector_serial_mod, only: FN_VEnableFusedOps_Serial, FN_VMake_Serial
  use fsundials_matrix_mod
  use fsundials_linearsolver_mod
  use fsundials_nonlinearsolver_mod
  use fsunmatrix_dense_mod, only: FSUNDenseMatrix
  use fsunlinsol_dense_mod, only: FSUNLinSol_Dense
  use fsunmatrix_band_mod, only: FSUNBandMatrix
  use fsunlinsol_band_mod, only: FSUNLinSol_Band
  use fsunnonlinsol_fixedpoint_mod, only: FSUNNonlinSol_FixedPoint
  use spline_kinds, only: wp
  use spline_errors, only: msglen
  use spline_model, only: model_t
  use spline_quantities, only: nstats => nsolver_stats, ist_steps, ist_rhs_evals, ist_jac_evals, &
       ist_lin_rhs_evals, ist_err_test_fails, ist_nonlin_conv_fails, ist_root_fn_evals
  implicit none
  private
  public :: integrator_t, lib_log_t, integrator_open, cvode_create, erk_create, integrator_advance, &
       integrator_root_info, integrator_root_directions, integrator_land_on_root, &
       integrator_restart, integrator_steps_done, integrator_last_step, integrator_free, &
       root_crossings, integrator_time, integrator_name, c_copy, stalled_flag, add_counters, &
       integrator_tolerances

  interface
    !> lincomb.c: ERKStep's linear combinations on v and its clones element by element
    integer(c_int) function lincomb_by_element(v) bind(C, name='spline_lincomb_by_element')
      import :: c_int, c_ptr
      type(c_ptr), value :: v
    end function lincomb_by_element
  end interface

  !> SUNDIALS' own messages of a run (lib_handler), kept instead of printed: the last error's
  !> text, and the warnings (how many, the first one's text).
  type :: lib_log_t
    integer :: nwarn = 0
    character(len=msglen) :: first = ''
    character(len=msglen) :: err = ''
  end type lib_log_t

  !> The SUNDIALS objects of one run (CVODE's or ERKStep's), its work bounds and its messages.
  type :: integrator_t
    logical :: erk = .false.                !< ARKODE ERKStep, else CVODE
    logical :: newton = .false.             !< CVODE with Newton iteration (Jacobian counters)
    logical :: roots = .false.              !< root functions in use (their counter)
    integer(c_int) :: nroot = 0             !< ERKStep: the root functions, to switch them back on
    type(c_funptr) :: groots = c_null_funptr
    type(c_ptr) :: sunctx = c_null_ptr
    type(c_ptr) :: mem = c_null_ptr         !< CVODE or ERKStep
    type(N_Vector), pointer :: sv => null() !< the state vector, on the caller's array
    type(SUNMatrix), pointer :: amat => null()
    type(SUNLinearSolver), pointer :: ls => null()
    type(SUNNonlinearSolver), pointer :: nls => null()
    !> ERKStep: the step that crossed the last located switch, to restart with after it
    real(c_double) :: h_cross = 0.0_c_double
    !> the run in messages: 'the run' (spline_solver) or 'the variational run'
    character(len=24) :: run = 'the run'
    integer(8) :: max_steps = 0, max_total_steps = 0   !< the case's work bounds
    integer(8) :: steps0 = 0                !< CVODE steps before its last CVodeReInit
    logical :: total_bound = .false.        !< the work bound met is max_total_steps
    real(wp) :: max_seconds = 0.0_wp        !< wall-time bound (s) of the run; 0: none
    integer(8) :: clock0 = 0, rate = 1      !< system_clock at the start, its rate
    logical :: wall_bound = .false.         !< the run stopped at max_seconds
    !> a call 'succeeded' short of its tout: the step had fallen below round-off of t, the
    !> state returned is not the state there (integrator_evolve); t_stalled: where it stood
    logical :: stalled = .false.
    real(c_double) :: t_stalled = 0.0_c_double
    type(lib_log_t) :: log                  !< SUNDIALS' messages (lib_handler's user data)
  end type integrator_t

  !> failed error tests allowed on one step (ARKODE's default 7 gave up on paper_lx1e-4)
  integer(c_int), parameter :: max_err_test_fails = 30
  !> dense output: Hermite of degree 4 (one right-hand side per step that is interpolated) where
  !> rtol < cubic_rtol, of degree 3 (none) where looser (spline_integrator::erk_create)
  real(wp), parameter :: cubic_rtol = 1.0e-5_wp
  !> CVODE's first step after a contact switch, as a fraction of the step that crossed it. Its
  !> own estimate (CVodeReInit) chattered at loose tolerances: chaos_z24 with roots at rtol
  !> 3e-2 found 867 726 switches where tight runs find 11 200 (2.8 s; BDF at 1e-2, 4.2 s). With
  !> 0.1: 16 900 switches in 0.15 s; with 0.01 it chattered again; with 1 (order 1 on a step
  !> sized for a higher order) BDF on physical_z24 took 15-20 % longer. docs/performance.md.
  real(c_double), parameter :: cvode_restart_fraction = 0.1_c_double
  !> ... but never below this many times CVODE's root tolerance at the restart, 100 uround
  !> (|t| + |h|): in a cluster of switches each restart's first step is the step that crossed
  !> the next one, so the fraction compounds (the 16 teeth of an aligned Z16 drive switch
  !> within 1e-13 s of each other, split by round-off: 1e-16 of the step), and a step below the
  !> tolerance cannot tell a root from its start; with 10 of it CVODE's look just past a
  !> switch function that is zero at the restart (0.1 of the step) passes the tolerance.
  real(c_double), parameter :: cvode_restart_floor = 10*100*epsilon(1.0_c_double)
  !> steps per integrator call in a run with a wall-time bound (the clock is read between calls)
  integer(8), parameter :: wall_chunk = 20000
  !> integrator_evolve's flag for a call that returned short of its tout (not a SUNDIALS code)
  integer(c_int), parameter :: stalled_flag = -9999_c_int

contains

  !> The SUNDIALS context and the state vector on the caller's array yr (a target that outlives
  !> the run); the run's name in messages and its work bounds, the case's; the wall clock
  !> started (or at the system_clock count wall_start, optional: a bound over several runs),
  !> max_seconds (optional, > 0) its bound; without it, the model's call bound (m%max_seconds,
  !> from m%wall_start) if it has one. flag /= 0: the first failure, stage names it.
  subroutine integrator_open(m, run, yr, cv, flag, stage, max_seconds, wall_start)
    type(model_t), intent(in) :: m
    character(len=*), intent(in) :: run
    real(c_double), intent(inout), target :: yr(:)
    type(integrator_t), intent(inout) :: cv
    integer(c_int), intent(out) :: flag
    character(len=*), intent(out) :: stage
    real(wp), intent(in), optional :: max_seconds
    integer(8), intent(in), optional :: wall_start
    cv%run = run
    cv%max_steps = m%max_steps
    cv%max_total_steps = m%max_total_steps
    call system_clock(cv%clock0, cv%rate)
    if (present(max_seconds)) then
      cv%max_seconds = max_seconds
    else if (m%max_seconds > 0.0_wp) then
      cv%max_seconds = m%max_seconds
      cv%clock0 = m%wall_start
    end if
    if (present(wall_start)) cv%clock0 = wall_start
    stage = 'creating the SUNDIALS context'
    flag = sundials_context_new(cv%sunctx)
    if (flag /= 0) return
    stage = 'creating the state vector'
    cv%sv => FN_VMake_Serial(int(size(yr), c_long), yr, cv%sunctx)
    if (.not. associated(cv%sv)) flag = -1
  end subroutine integrator_open

  !> SUNDIALS 6.x context (SUNDIALS 7 takes SUN_COMM_NULL here): the one version-specific call.
  integer(c_int) function sundials_context_new(sunctx) result(flag)
    type(c_ptr), intent(out) :: sunctx
    flag = FSUNContext_Create(c_null_ptr, sunctx)
  end function sundials_context_new

  !> Create CVODE on cv%sv at tau: the case's method (Adams or BDF, stability limit detection),
  !> tolerances and step bound, SUNDIALS' messages to lib_handler, the right-hand side rhs (user
  !> data udata), the (non)linear solver: m%newton: Newton with a dense matrix (CVODE's
  !> difference Jacobian; jac = c_null_funptr), or the Jacobian function jac in a band matrix of
  !> half-width band; else fixed-point iteration (no Anderson acceleration); nroot > 0: the root
  !> functions roots. flag /= 0: the first failure; stage names the step.
  subroutine cvode_create(m, tau, nroot, rhs, roots, jac, band, udata, cv, flag, stage)
    type(model_t), intent(in) :: m
    real(c_double), intent(in) :: tau
    integer(c_int), intent(in) :: nroot
    type(c_funptr), value :: rhs, roots, jac   ! by value: no address constant to relocate
    integer, intent(in) :: band
    type(c_ptr), intent(in) :: udata
    type(integrator_t), intent(inout), target :: cv
    integer(c_int), intent(out) :: flag
    character(len=*), intent(out) :: stage
    integer(c_long) :: nn
    cv%newton = m%newton
    cv%roots = nroot > 0
    nn = FN_VGetLength(cv%sv)
    stage = 'creating CVODE'
    cv%mem = FCVodeCreate(merge(CV_BDF, CV_ADAMS, m%method_bdf == 1), cv%sunctx)
    flag = -1
    if (.not. c_associated(cv%mem)) return
    flag = FCVodeSetErrHandlerFn(cv%mem, c_funloc(lib_handler), c_loc(cv%log))
    if (flag == 0) then
      stage = 'initialising CVODE'
      flag = FCVodeInit(cv%mem, rhs, tau, cv%sv)
    end if
    if (flag == 0) flag = FCVodeSetUserData(cv%mem, udata)
    if (flag == 0) then
      stage = 'setting the tolerances'
      flag = FCVodeSStolerances(cv%mem, real(m%rtol, c_double), real(m%atol, c_double))
    end if
    if (flag /= 0) return
    stage = 'attaching the (non)linear solver'
    flag = -1
    if (m%newton .and. c_associated(jac)) then
      ! a band of half-width band holds a block-diagonal Jacobian (spline_variational)
      cv%amat => FSUNBandMatrix(nn, int(band, c_long), int(band, c_long), cv%sunctx)
      if (associated(cv%amat)) cv%ls => FSUNLinSol_Band(cv%sv, cv%amat, cv%sunctx)
      if (associated(cv%ls)) flag = FCVodeSetLinearSolver(cv%mem, cv%ls, cv%amat)
      if (flag == 0) flag = FCVodeSetJacFn(cv%mem, jac)
    else if (m%newton) then
      cv%amat => FSUNDenseMatrix(nn, nn, cv%sunctx)
      if (associated(cv%amat)) cv%ls => FSUNLinSol_Dense(cv%sv, cv%amat, cv%sunctx)
      if (associated(cv%ls)) flag = FCVodeSetLinearSolver(cv%mem, cv%ls, cv%amat)
    else
      cv%nls => FSUNNonlinSol_FixedPoint(cv%sv, 0, cv%sunctx)
      if (associated(cv%nls)) flag = FCVodeSetNonlinearSolver(cv%mem, cv%nls)
    end if
    if (flag == 0) then
      stage = 'setting the solver options'
      flag = FCVodeSetMaxNumSteps(cv%mem, int(m%max_steps, c_long))
    end if
    if (flag == 0 .and. m%stald .and. m%method_bdf == 1) flag = FCVodeSetStabLimDet(cv%mem, 1)
    if (flag == 0 .and. nroot > 0) then
      stage = 'setting up root finding'
      flag = root_init(cv, nroot, roots)
    end if
  end subroutine cvode_create

  !> Create ERKStep on cv%sv at tau with the model's tolerances and step bound, its table,
  !> SUNDIALS' messages to lib_handler, the right-hand side rhs (user data udata) and, nroot > 0,
  !> the root functions roots. flag /= 0: the first failure; stage names the step.
  subroutine erk_create(m, tau, nroot, rhs, roots, udata, cv, flag, stage)
    type(model_t), intent(in) :: m
    real(c_double), intent(in) :: tau
    integer(c_int), intent(in) :: nroot
    type(c_funptr), value :: rhs, roots   ! by value: no address constant to relocate
    type(c_ptr), intent(in) :: udata
    type(integrator_t), intent(inout), target :: cv
    integer(c_int), intent(out) :: flag
    character(len=*), intent(out) :: stage
    type(c_ptr) :: ud
    ud = udata
    cv%erk = .true.
    cv%roots = nroot > 0
    cv%nroot = nroot
    cv%groots = roots
    stage = 'creating ARKODE ERKStep'
    ! the stage sums, the solution and its error estimate as one loop each, not one vector
    ! operation per term (N_VLinearCombination; the same operations in the same order: results
    ! bit for bit); before ERKStep clones its vectors from cv%sv
    flag = FN_VEnableFusedOps_Serial(cv%sv, 1_c_int)
    ! ... and those sums element by element (lincomb.c: SUNDIALS' bits, a third of its work)
    if (flag == 0) flag = lincomb_by_element(c_loc(cv%sv))
    if (flag == 0) then
      cv%mem = FERKStepCreate(rhs, tau, cv%sv, cv%sunctx)
      if (.not. c_associated(cv%mem)) flag = -1
    end if
    if (flag == 0) flag = FERKStepSetErrHandlerFn(cv%mem, c_funloc(lib_handler), c_loc(cv%log))
    if (flag == 0) flag = FERKStepSetUserData(cv%mem, ud)
    if (flag == 0) then
      stage = 'setting the tolerances'
      flag = FERKStepSStolerances(cv%mem, real(m%rtol, c_double), real(m%atol, c_double))
    end if
    if (flag == 0) then
      stage = 'setting the solver options'
      flag = FERKStepSetTableNum(cv%mem, merge(ARKODE_CASH_KARP_6_4_5, ARKODE_DORMAND_PRINCE_7_4_5, &
           m%cash_karp))
    end if
    if (flag == 0) flag = FERKStepSetMaxNumSteps(cv%mem, int(m%max_steps, c_long))
    ! a contact switch inside a step (roots off) is a kink the order-5 error model does not
    ! expect: the step must shrink by orders of magnitude, more than 7 failed tries allow
    if (flag == 0) flag = FERKStepSetMaxErrTestFails(cv%mem, max_err_test_fails)
    ! dense output (outputs, root finding): Hermite of degree 4 (the most for order 5), one
    ! right-hand side per step that is interpolated (an output or the root functions in it); with
    ! the 8th-order table degree 5 (two) gave the same F error for 60 % more right-hand sides.
    ! Degree 3 (none) where rtol >= cubic_rtol: there the step's own error is the larger, with
    ! Dormand-Prince (F error, degree 3 / degree 4, at rtol 1e-3, 1e-4, 1e-5: paper_lx1e-4 with
    ! 6401 outputs 0.67, 1.05, 1.00 for 45, 42, 33 % fewer right-hand sides; physical_z24 with
    ! roots 1.23, 1.81, 1.02 for 50, 46, 45 % fewer); tighter it is not (at 1e-6 to 1e-8 3.0, 3.3,
    ! 4.5 and 1.6, 2.0, 1.6 times the error): docs/running.md section 2
    if (flag == 0) flag = FERKStepSetInterpolantDegree(cv%mem, merge(3_c_int, 4_c_int, &
         m%rtol >= cubic_rtol))
    if (flag == 0 .and. nroot > 0) then
      stage = 'setting up root finding'
      flag = root_init(cv, nroot, roots)
    end if
  end subroutine erk_create

  !> Root finding on the nroot functions roots (none: nroot = 0), without the warning about
  !> functions that are zero at the start (a switch function can stay at zero: a free tooth's).
  integer(c_int) function root_init(cv, nroot, roots) result(flag)
    type(integrator_t), intent(inout) :: cv
    integer(c_int), intent(in) :: nroot
    type(c_funptr), value :: roots
    if (cv%erk) then
      flag = FERKStepRootInit(cv%mem, nroot, roots)
      if (flag == 0 .and. nroot > 0) flag = FERKStepSetNoInactiveRootWarn(cv%mem)
    else
      flag = FCVodeRootInit(cv%mem, nroot, roots)
      if (flag == 0 .and. nroot > 0) flag = FCVodeSetNoInactiveRootWarn(cv%mem)
    end if
  end function root_init

  !> Integrate from tau towards tout (normal mode: the state there, interpolated) within the
  !> work bounds: max_steps since the step count done_k (integrator_steps_done at the last
  !> output), max_total_steps over the run, and the wall time max_seconds. A bound met returns
  !> CV_TOO_MUCH_WORK (cv%total_bound, cv%wall_bound say which; integrator_fail_text names it),
  !> tret the time reached. The returns of both integrators are CVODE's codes (ARK_ROOT_RETURN
  !> becomes CV_ROOT_RETURN; success, CV_TOO_MUCH_WORK and the other failures have the same
  !> values in both).
  integer(c_int) function integrator_advance(cv, tau, tout, done_k, tret) result(flag)
    type(integrator_t), intent(inout) :: cv
    real(c_double), intent(in) :: tau, tout
    integer(8), intent(in) :: done_k
    real(c_double), intent(out) :: tret(1)
    integer(8) :: done, allow, now, chunk
    done = integrator_steps_done(cv)
    allow = min(cv%max_steps - (done - done_k), cv%max_total_steps - done)
    cv%total_bound = cv%max_total_steps - done <= cv%max_steps - (done - done_k)
    tret = tau
    flag = CV_TOO_MUCH_WORK
    if (allow <= 0) return
    if (cv%max_seconds <= 0.0_wp) then
      flag = integrator_evolve(cv, allow, tout, tret)
      return
    end if
    ! the clock read between calls of at most wall_chunk steps; the caller sees one call
    do
      call system_clock(now)
      cv%wall_bound = real(now - cv%clock0, wp) >= cv%max_seconds*cv%rate
      if (cv%wall_bound) return
      chunk = min(allow, wall_chunk)
      flag = integrator_evolve(cv, chunk, tout, tret)
      if (flag /= CV_TOO_MUCH_WORK .or. chunk == allow) return
      allow = allow - chunk
    end do
  end function integrator_advance

  !> Integrate towards tout (normal mode: the state there, interpolated) within allow steps.
  !> The returns of both are CVODE's codes (ARK_ROOT_RETURN becomes CV_ROOT_RETURN; success,
  !> CV_TOO_MUCH_WORK and the other failures have the same values in both).
  integer(c_int) function integrator_evolve(cv, allow, tout, tret) result(flag)
    type(integrator_t), intent(inout) :: cv
    integer(8), intent(in) :: allow
    real(c_double), intent(in) :: tout
    real(c_double), intent(out) :: tret(1)
    if (cv%erk) then
      flag = FERKStepSetMaxNumSteps(cv%mem, int(allow, c_long))
      if (flag == 0) flag = FERKStepEvolve(cv%mem, tout, cv%sv, tret, ARK_NORMAL)
      if (flag == ARK_ROOT_RETURN) flag = CV_ROOT_RETURN
    else
      flag = FCVodeSetMaxNumSteps(cv%mem, int(allow, c_long))
      if (flag == 0) flag = FCVode(cv%mem, tout, cv%sv, tret, CV_NORMAL)
    end if
    if (flag == 0) call check_reached(cv, tout, flag)
  end function integrator_evolve

  !> A successful call in normal mode stands at or past tout. One that does not was fooled by
  !> a step below round-off: CVODE's test (t_n - tout) h >= 0 underflows to -0 for a
  !> subnormal h, and it returns 'success' at tout with its interpolation's error ignored (the
  !> state left as it was, not the state at tout; the next call fails with CV_ILL_INPUT, "tout
  !> too far back"). Then flag = stalled_flag, cv%stalled and where it stood, for the message.
  subroutine check_reached(cv, tout, flag)
    type(integrator_t), intent(inout) :: cv
    real(c_double), intent(in) :: tout
    integer(c_int), intent(inout) :: flag
    real(c_double) :: tn
    tn = integrator_time(cv, tout)
    if (tn >= tout) return
    cv%stalled = .true.
    cv%t_stalled = tn
    flag = stalled_flag
  end subroutine check_reached

  !> Where the integrator stands (its last step's end, scaled time): where a failed call
  !> stopped; tau when that cannot be read (no integrator made).
  real(c_double) function integrator_time(cv, tau) result(tn)
    type(integrator_t), intent(in) :: cv
    real(c_double), intent(in) :: tau
    real(c_double) :: t(1)
    integer(c_int) :: flag
    tn = tau
    if (.not. c_associated(cv%mem)) return
    if (cv%erk) then
      flag = FERKStepGetCurrentTime(cv%mem, t)
    else
      flag = FCVodeGetCurrentTime(cv%mem, t)
    end if
    if (flag == 0) tn = t(1)
  end function integrator_time

  !> ERKStep returned at a root troot: redo its last step from its start (tn - h) to land on
  !> troot exactly (stop time), root functions off, contact states still the old ones. The state
  !> there (cv%sv) is then the method's own, of its order, not the Hermite interpolant of the
  !> step that crossed, whose error the step control does not see (restarting from it left an
  !> F error of 4e-3 on physical_z24 at rtol 1e-9, with 648 switches; landed: 2e-5).
  !> CVODE: nothing (its interpolant is of its own order).
  integer(c_int) function integrator_land_on_root(cv, troot) result(flag)
    type(integrator_t), intent(inout) :: cv
    real(c_double), intent(in) :: troot
    real(c_double) :: tn(1), h(1), tret(1), t1
    flag = 0
    if (.not. cv%erk) return
    flag = FERKStepGetCurrentTime(cv%mem, tn)
    if (flag == 0) flag = FERKStepGetLastStep(cv%mem, h)
    if (flag /= 0) return
    t1 = tn(1) - h(1)
    if (.not. (t1 < troot)) return
    cv%h_cross = h(1)
    flag = FERKStepGetDky(cv%mem, t1, 0_c_int, cv%sv)    ! the step's start: its own state
    if (flag == 0) flag = root_init(cv, 0_c_int, c_null_funptr)
    if (flag == 0) flag = FERKStepReset(cv%mem, t1, cv%sv)
    if (flag == 0) flag = FERKStepSetStopTime(cv%mem, troot)
    if (flag == 0) flag = FERKStepEvolve(cv%mem, troot, cv%sv, tret, ARK_NORMAL)
    if (flag == ARK_TSTOP_RETURN) flag = 0
    if (flag == 0) flag = root_init(cv, cv%nroot, cv%groots)
  end function integrator_land_on_root

  !> The switches to apply where a run stopped on located roots (rootsfound: +-1 per root
  !> function reported, 0 others), from the switch functions g and their rates dg in the landed
  !> state and the directions dirs that change a contact state (eq16_root_directions): a
  !> reported root whose function has reached or crossed zero in its direction; one not yet
  !> crossed there (the root is found on the interpolant of the crossing step, the landed state
  !> may be 1e-15 of c short) keeps its state until it does, and root finding reports it again.
  !> A function exactly zero counts as crossed: root finding leaves out a function that is
  !> zero at its start, and would miss that switch. The other way round, a function not
  !> reported that has crossed in dirs, or stands at exactly zero moving that way (its rate),
  !> switches too: the restart's root search starts on the far side (ARKODE takes a function
  !> zero at its start from a look a tenth of a step ahead) and would never see it. In a
  !> cluster of near-simultaneous switches (the 16 teeth of an aligned drive, 1e-11 apart on
  !> the scaled time) the interpolant reports the teeth a few at a time while the landed state
  !> has crossed more: with ERK those were lost, their teeth held in the wrong contact state for
  !> the rest of the run (the Z16 drive at 2356.25 r/min: 34 of 64 switches located, lateral
  !> speeds 0.4 scaled off the symmetric orbit; tests/test_erk.py).
  pure function root_crossings(rootsfound, dirs, g, dg) result(crossed)
    integer(c_int), intent(in) :: rootsfound(:)
    integer, intent(in) :: dirs(:)
    real(wp), intent(in) :: g(:), dg(:)
    integer(c_int) :: crossed(size(rootsfound))
    integer :: i
    crossed = 0
    do i = 1, size(rootsfound)
      if (rootsfound(i) /= 0) then
        if (rootsfound(i)*g(i) >= 0.0_wp) crossed(i) = rootsfound(i)
      else if (dirs(i)*g(i) > 0.0_wp .or. (g(i) == 0.0_wp .and. dirs(i)*dg(i) > 0.0_wp)) then
        crossed(i) = int(dirs(i), c_int)
      end if
    end do
  end function root_crossings

  !> Locate only the crossings of root function i in direction dirs(i) (+1 rising, -1 falling,
  !> 0 either) from the next call on. CVODE only: ERKStep's landing on a root
  !> (integrator_land_on_root) switches root finding off and on, which resets the directions,
  !> and settle_roots (spline_solver) counts on seeing a landed root again later.
  integer(c_int) function integrator_root_directions(cv, dirs) result(flag)
    type(integrator_t), intent(inout) :: cv
    integer, intent(in) :: dirs(:)
    integer(c_int), target :: d(size(dirs))
    flag = 0
    if (cv%erk .or. .not. cv%roots) return
    d = int(dirs, c_int)
    flag = FCVodeSetRootDirection(cv%mem, d)
  end function integrator_root_directions

  integer(c_int) function integrator_root_info(cv, rootsfound) result(flag)
    type(integrator_t), intent(inout) :: cv
    integer(c_int), intent(inout) :: rootsfound(:)
    if (cv%erk) then
      flag = FERKStepGetRootInfo(cv%mem, rootsfound)
    else
      flag = FCVodeGetRootInfo(cv%mem, rootsfound)
    end if
  end function integrator_root_info

  !> Steps taken in the run so far, over every restart.
  integer(8) function integrator_steps_done(cv) result(n)
    type(integrator_t), intent(in) :: cv
    integer(c_long) :: cnt(1)
    integer(c_int) :: flag
    n = cv%steps0
    if (.not. c_associated(cv%mem)) return
    if (cv%erk) then
      flag = FERKStepGetNumSteps(cv%mem, cnt)
    else
      flag = FCVodeGetNumSteps(cv%mem, cnt)
    end if
    if (flag == 0) n = n + cnt(1)
  end function integrator_steps_done

  !> Set the run's tolerances to rtol, atol (scalar) from its next step on.
  integer(c_int) function integrator_tolerances(cv, rtol, atol) result(flag)
    type(integrator_t), intent(inout) :: cv
    real(wp), intent(in) :: rtol, atol
    if (cv%erk) then
      flag = FERKStepSStolerances(cv%mem, real(rtol, c_double), real(atol, c_double))
    else
      flag = FCVodeSStolerances(cv%mem, real(rtol, c_double), real(atol, c_double))
    end if
  end function integrator_tolerances

  !> Restart at tau from the state in cv%sv (a contact switch: the right-hand side's branch
  !> changed). CVODE: its counters added to stats first (CVodeReInit zeroes them), then it
  !> starts afresh at order 1 with cvode_restart_fraction of the step that crossed the switch.
  !> ERKStep: ERKStepReset, counters kept, with the step that crossed (not the landing's
  !> remainder, which its growth limit took several steps to recover).
  !> floored (default .true.): CVODE's first step at least cvode_restart_floor (|tau| + |h|).
  !> The variational run passes .false.: with the floor there the ERK S-curve continuation's
  !> corrector failed near 2355.58 r/min (tests/test_cont_drives.py::test_erk_traces_the_s_curve)
  !> while ERK's state run lost switches in the teeth's clusters (spline_solver::settle_roots);
  !> with them kept it completes with the floor too (2200-2500 and 2330-2470 r/min, the same
  !> folds), which was not adopted; the state run (and the period map on it) needs it, without it
  !> BDF's map through the Z16 drive's grazing cluster closed 6.6 % off the orbit
  !> (tests/test_solver.py).
  integer(c_int) function integrator_restart(cv, tau, stats, floored) result(flag)
    type(integrator_t), intent(inout) :: cv
    real(c_double), intent(in) :: tau
    real(wp), intent(inout), optional :: stats(nstats)
    logical, intent(in), optional :: floored
    logical :: fl
    fl = .true.
    if (present(floored)) fl = floored
    if (cv%erk) then
      flag = FERKStepReset(cv%mem, tau, cv%sv)
      if (flag == 0 .and. cv%h_cross > 0.0_c_double) flag = FERKStepSetInitStep(cv%mem, cv%h_cross)
      cv%h_cross = 0.0_c_double
    else
      cv%steps0 = integrator_steps_done(cv)
      if (present(stats)) call add_counters(cv, stats)
      flag = cvode_restart(cv%mem, tau, cv%sv, fl)
    end if
  end function integrator_restart

  !> CVODE (mem) restarted at tau from sv after a contact switch: CVodeReInit, at order 1 with
  !> cvode_restart_fraction of the step that crossed the switch, if floored at least
  !> cvode_restart_floor (|tau| + |h|).
  integer(c_int) function cvode_restart(mem, tau, sv, floored) result(flag)
    type(c_ptr), intent(in) :: mem
    real(c_double), intent(in) :: tau
    type(N_Vector), intent(inout) :: sv
    logical, intent(in) :: floored
    real(c_double) :: hl(1), h0
    flag = FCVodeGetLastStep(mem, hl)
    h0 = cvode_restart_fraction*hl(1)
    if (floored) h0 = max(h0, cvode_restart_floor*(abs(tau) + abs(hl(1))))
    if (flag == 0) flag = FCVodeSetInitStep(mem, h0)
    if (flag == 0) flag = FCVodeReInit(mem, tau, sv)
  end function cvode_restart

  integer(c_int) function integrator_last_step(cv, h) result(flag)
    type(integrator_t), intent(inout) :: cv
    real(c_double), intent(out) :: h(1)
    if (cv%erk) then
      flag = FERKStepGetLastStep(cv%mem, h)
    else
      flag = FCVodeGetLastStep(cv%mem, h)
    end if
  end function integrator_last_step


  !> The integrator's name in messages.
  pure function integrator_name(cv) result(name)
    type(integrator_t), intent(in) :: cv
    character(len=merge(6, 5, cv%erk)) :: name
    name = merge('ARKODE', 'CVODE ', cv%erk)
  end function integrator_name




  !> Add the counters since the last (re)initialisation to stats (positions ist_* of
  !> spline_quantities). A counter that cannot be read (nonzero flag) adds nothing.
  subroutine add_counters(cv, stats)
    type(integrator_t), intent(inout) :: cv
    real(wp), intent(inout) :: stats(nstats)
    integer(c_long) :: cnt(1)
    if (cv%erk) then
      call add(ist_steps, FERKStepGetNumSteps(cv%mem, cnt))
      call add(ist_rhs_evals, FERKStepGetNumRhsEvals(cv%mem, cnt))
      call add(ist_err_test_fails, FERKStepGetNumErrTestFails(cv%mem, cnt))
      if (cv%roots) call add(ist_root_fn_evals, FERKStepGetNumGEvals(cv%mem, cnt))
      return
    end if
    call add(ist_steps, FCVodeGetNumSteps(cv%mem, cnt))
    call add(ist_rhs_evals, FCVodeGetNumRhsEvals(cv%mem, cnt))
    if (cv%newton) then
      call add(ist_jac_evals, FCVodeGetNumJacEvals(cv%mem, cnt))
      call add(ist_lin_rhs_evals, FCVodeGetNumLinRhsEvals(cv%mem, cnt))
    end if
    call add(ist_err_test_fails, FCVodeGetNumErrTestFails(cv%mem, cnt))
    call add(ist_nonlin_conv_fails, FCVodeGetNumNonlinSolvConvFails(cv%mem, cnt))
    if (cv%roots) call add(ist_root_fn_evals, FCVodeGetNumGEvals(cv%mem, cnt))
  contains
    subroutine add(i, flag)          ! the getter has filled cnt by the time this runs
      integer, intent(in) :: i
      integer(c_int), intent(in) :: flag
      if (flag == 0) stats(i) = stats(i) + cnt(1)
    end subroutine add
  end subroutine add_counters

  !> SUNDIALS' message handler (CVodeSetErrHandlerFn, ERKStepSetErrHandlerFn): nothing is
  !> printed. An error's text is kept for the error message; a warning (error_code > 0, e.g.
  !> CVODE's "t + h = t") is counted and the first one kept. udata: the run's lib_log_t.
  subroutine lib_handler(error_code, module, function, msg, udata) bind(C)
    integer(c_int), value :: error_code
    type(c_ptr), value :: module, function, msg, udata
    type(lib_log_t), pointer :: log
    character(len=msglen) :: mod_name, fun_name, text
    call c_f_pointer(udata, log)
    if (error_code > 0) then
      log%nwarn = log%nwarn + 1
      if (log%nwarn == 1) then
        call c_copy(module, mod_name)
        call c_copy(function, fun_name)
        call c_copy(msg, text)
        log%first = trim(mod_name)//' in '//trim(fun_name)//': '//text
      end if
    else
      call c_copy(msg, log%err)
    end if
  end subroutine lib_handler

  !> The C string at p (blank if null) into s, cut at len(s).
  subroutine c_copy(p, s)
    type(c_ptr), intent(in) :: p
    character(len=*), intent(out) :: s
    character(kind=c_char), pointer :: chars(:)
    integer :: n, i
    interface
      integer(c_size_t) function strlen(str) bind(C, name='strlen')
        import :: c_ptr, c_size_t
        type(c_ptr), value :: str
      end function strlen
    end interface
    s = ''
    if (.not. c_associated(p)) return
    n = min(int(strlen(p)), len(s))
    call c_f_pointer(p, chars, [n])
    do i = 1, n
      s(i:i) = chars(i)
    end do
  end subroutine c_copy

  !> Free what was made (the statistics read first: integrate's collect_stats).
  subroutine integrator_free(cv)
    type(integrator_t), intent(inout) :: cv
    integer(c_int) :: flag
    if (c_associated(cv%mem)) then
      if (cv%erk) then
        call FERKStepFree(cv%mem)
      else
        call FCVodeFree(cv%mem)
      end if
    end if
    if (associated(cv%ls)) flag = FSUNLinSolFree(cv%ls)
    if (associated(cv%nls)) flag = FSUNNonlinSolFree(cv%nls)
    if (associated(cv%amat)) call FSUNMatDestroy(cv%amat)
    if (associated(cv%sv)) call FN_VDestroy(cv%sv)
    flag = FSUNContext_Free(cv%sunctx)
  end subroutine integrator_free

end module spline_integrator
