!> ARKODE's ERKStep (SUNDIALS 6.4, Fortran 2003 interface) beside CVODE: an explicit one-step
!> Runge-Kutta pair (Dormand-Prince 5(4), 7 stages, ARKODE_DORMAND_PRINCE_7_4_5) for the scaled
!> system of Eq. 25, method = 'erk'. Chosen by measurement over Fehlberg's 13-stage 7(8) pair
!> (with switches located, at the defaults): physical_z24 F error 1.6e-5 with 68 700 RHS calls
!> at rtol 1e-8 against 4.7e-5 with 117 700; paper_lx1e-4 2.4e-9 with 7 500 against 8.9e-8 with
!> 7 200. The impacts bound the steps there, not the order. A contact switch (root finding) restarts it for
!> nothing: ERKStepReset keeps its step size and counters, where CVODE restarts at order 1 with
!> a small step. spline_solver::integrate drives either integrator through the calls here, so a
!> run's logic (outputs, sections, linear tail, root finding, work bounds) is one; ERKStep uses
!> the same right-hand side, root functions and error handler (given as C function pointers and
!> user data). Every SUNDIALS return is checked. ERKStep's dense output is its Hermite
!> interpolant of degree 4 (one right-hand side per step interpolated), of degree 3 (none) at
!> rtol >= 1e-5 (cubic_rtol).
module spline_erk
  use, intrinsic :: iso_c_binding
  use fcvode_mod
  use farkode_mod, only: ARK_NORMAL, ARK_ROOT_RETURN, ARK_TSTOP_RETURN, ARKODE_DORMAND_PRINCE_7_4_5
  use farkode_erkstep_mod
  use fsundials_context_mod
  use fsundials_nvector_mod
  use fnvector_serial_mod, only: FN_VEnableFusedOps_Serial
  use fsundials_matrix_mod
  use fsundials_linearsolver_mod
  use fsundials_nonlinearsolver_mod
  use spline_kinds, only: wp
  use spline_model, only: model_t
  use spline_quantities, only: nstats => nsolver_stats, ist_steps, ist_rhs_evals, ist_jac_evals, &
       ist_lin_rhs_evals, ist_err_test_fails, ist_nonlin_conv_fails, ist_root_fn_evals
  implicit none
  private
  public :: integrator_t, erk_create, integrator_evolve, integrator_root_info, integrator_steps, &
       integrator_land_on_root, &
       integrator_restart, integrator_last_step, integrator_flag_name, integrator_name, &
       add_counters, integrator_free, cvode_restart

  !> The SUNDIALS objects of one run: CVODE's (spline_solver::cvode_setup) or ERKStep's.
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
  end type integrator_t

  !> failed error tests allowed on one step (ARKODE's default 7 gave up on paper_lx1e-4)
  integer(c_int), parameter :: max_err_test_fails = 30
  !> dense output: Hermite of degree 4 (one right-hand side per step that is interpolated) where
  !> rtol < cubic_rtol, of degree 3 (none) where looser (spline_erk::erk_create)
  real(wp), parameter :: cubic_rtol = 1.0e-5_wp
  !> CVODE's first step after a contact switch, as a fraction of the step that crossed it. Its
  !> own estimate (CVodeReInit) chattered at loose tolerances: chaos_z24 with roots at rtol
  !> 3e-2 found 867 726 switches where tight runs find 11 200 (2.8 s; BDF at 1e-2, 4.2 s). With
  !> 0.1: 16 900 switches in 0.15 s; with 0.01 it chattered again; with 1 (order 1 on a step
  !> sized for a higher order) BDF on physical_z24 took 15-20 % longer. docs/performance.md.
  real(c_double), parameter :: cvode_restart_fraction = 0.1_c_double

contains

  !> Create ERKStep on cv%sv at tau with the model's tolerances and step bound, its table, the right-hand side rhs, the error handler errh (user data udata) and, nroot > 0,
  !> the root functions roots. flag /= 0: the first failure; stage names the step.
  subroutine erk_create(m, tau, nroot, rhs, roots, errh, udata, cv, flag, stage)
    type(model_t), intent(in) :: m
    real(c_double), intent(in) :: tau
    integer(c_int), intent(in) :: nroot
    type(c_funptr), value :: rhs, roots, errh   ! by value: no address constant to relocate
    type(c_ptr), intent(in) :: udata
    type(integrator_t), intent(inout) :: cv
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
    if (flag == 0) then
      cv%mem = FERKStepCreate(rhs, tau, cv%sv, cv%sunctx)
      if (.not. c_associated(cv%mem)) flag = -1
    end if
    if (flag == 0) flag = FERKStepSetUserData(cv%mem, ud)
    if (flag == 0) flag = FERKStepSetErrHandlerFn(cv%mem, errh, ud)
    if (flag == 0) then
      stage = 'setting the tolerances'
      flag = FERKStepSStolerances(cv%mem, real(m%rtol, c_double), real(m%atol, c_double))
    end if
    if (flag == 0) then
      stage = 'setting the solver options'
      flag = FERKStepSetTableNum(cv%mem, ARKODE_DORMAND_PRINCE_7_4_5)
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
    ! 4.5 and 1.6, 2.0, 1.6 times the error): docs/model.md section 8
    if (flag == 0) flag = FERKStepSetInterpolantDegree(cv%mem, merge(3_c_int, 4_c_int, &
         m%rtol >= cubic_rtol))
    if (flag == 0 .and. nroot > 0) then
      stage = 'setting up root finding'
      flag = FERKStepRootInit(cv%mem, nroot, roots)
      if (flag == 0) flag = FERKStepSetNoInactiveRootWarn(cv%mem)
    end if
  end subroutine erk_create

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
  end function integrator_evolve

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
    if (flag == 0) flag = FERKStepRootInit(cv%mem, 0_c_int, c_null_funptr)
    if (flag == 0) flag = FERKStepReset(cv%mem, t1, cv%sv)
    if (flag == 0) flag = FERKStepSetStopTime(cv%mem, troot)
    if (flag == 0) flag = FERKStepEvolve(cv%mem, troot, cv%sv, tret, ARK_NORMAL)
    if (flag == ARK_TSTOP_RETURN) flag = 0
    if (flag == 0) flag = FERKStepRootInit(cv%mem, cv%nroot, cv%groots)
    if (flag == 0) flag = FERKStepSetNoInactiveRootWarn(cv%mem)
  end function integrator_land_on_root

  integer(c_int) function integrator_root_info(cv, rootsfound) result(flag)
    type(integrator_t), intent(inout) :: cv
    integer(c_int), intent(inout) :: rootsfound(:)
    if (cv%erk) then
      flag = FERKStepGetRootInfo(cv%mem, rootsfound)
    else
      flag = FCVodeGetRootInfo(cv%mem, rootsfound)
    end if
  end function integrator_root_info

  !> Steps since the last (re)initialisation (CVODE: since CVodeReInit; ERKStep: the run).
  integer(c_int) function integrator_steps(cv, cnt) result(flag)
    type(integrator_t), intent(inout) :: cv
    integer(c_long), intent(out) :: cnt(1)
    if (cv%erk) then
      flag = FERKStepGetNumSteps(cv%mem, cnt)
    else
      flag = FCVodeGetNumSteps(cv%mem, cnt)
    end if
  end function integrator_steps

  !> Restart at tau from the state in cv%sv (a contact switch: the right-hand side's branch
  !> changed). CVODE: its counters added to stats first (CVodeReInit zeroes them), then it
  !> starts afresh at order 1 with cvode_restart_fraction of the step that crossed the switch.
  !> ERKStep: ERKStepReset, counters kept, with the step that crossed (not the landing's
  !> remainder, which its growth limit took several steps to recover).
  integer(c_int) function integrator_restart(cv, tau, stats) result(flag)
    type(integrator_t), intent(inout) :: cv
    real(c_double), intent(in) :: tau
    real(wp), intent(inout) :: stats(nstats)
    if (cv%erk) then
      flag = FERKStepReset(cv%mem, tau, cv%sv)
      if (flag == 0 .and. cv%h_cross > 0.0_c_double) flag = FERKStepSetInitStep(cv%mem, cv%h_cross)
      cv%h_cross = 0.0_c_double
    else
      call add_counters(cv, stats)
      flag = cvode_restart(cv%mem, tau, cv%sv)
    end if
  end function integrator_restart

  !> CVODE (mem) restarted at tau from sv after a contact switch: CVodeReInit, at order 1 with
  !> cvode_restart_fraction of the step that crossed the switch (integrator_restart, and the
  !> variational run of spline_variational).
  integer(c_int) function cvode_restart(mem, tau, sv) result(flag)
    type(c_ptr), intent(in) :: mem
    real(c_double), intent(in) :: tau
    type(N_Vector), intent(inout) :: sv
    real(c_double) :: hl(1)
    flag = FCVodeGetLastStep(mem, hl)
    if (flag == 0) flag = FCVodeSetInitStep(mem, cvode_restart_fraction*hl(1))
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

  function integrator_flag_name(cv, flag) result(fname)
    type(integrator_t), intent(in) :: cv
    integer(c_int), intent(in) :: flag
    character(len=:), allocatable :: fname
    if (cv%erk) then
      fname = FERKStepGetReturnFlagName(int(flag, c_long))
      if (flag == CV_ROOT_RETURN) fname = 'ARK_ROOT_RETURN'
    else
      fname = FCVodeGetReturnFlagName(int(flag, c_long))
    end if
  end function integrator_flag_name

  !> The integrator's name in messages.
  pure function integrator_name(cv) result(name)
    type(integrator_t), intent(in) :: cv
    character(len=:), allocatable :: name
    name = merge('ARKODE', 'CVODE ', cv%erk)
    name = trim(name)
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

end module spline_erk
