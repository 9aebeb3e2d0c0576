!> Time integration with CVODE (SUNDIALS 6.4, Fortran 2003 interface) of the scaled system of
!> Eq. 25, with optional root finding on the contact switches of Eq. 16. Version-specific calls
!> (context creation) are kept in sundials_context_new.
module spline_solver
  use, intrinsic :: iso_c_binding
  use fcvode_mod
  use fsundials_context_mod
  use fsundials_nvector_mod
  use fsundials_matrix_mod
  use fsundials_linearsolver_mod
  use fnvector_serial_mod
  use fsunmatrix_dense_mod
  use fsunlinsol_dense_mod
  use fsundials_nonlinearsolver_mod
  use fsunnonlinsol_fixedpoint_mod
  use spline_kinds, only: wp
  use spline_case_io, only: model_t, nstate, ndof, thermal_coupled
  use spline_dynamics, only: rhs_scaled, to_scaled, from_scaled
  use spline_mesh, only: mesh_switch_functions, coupling_stats_reset, coupling_worst_residual, &
       coupling_max_iterations
  implicit none
  private
  public :: integrate, nstats, stat_names

  integer, parameter :: nstats = 12
  character(len=24), parameter :: stat_names(nstats) = [character(len=24) :: &
       'steps', 'rhs_evals', 'jac_evals', 'lin_rhs_evals', 'err_test_fails', &
       'nonlin_conv_fails', 'roots_found', 'root_fn_evals', 'last_step_s', &
       'mode_resyncs', 'coupling_residual_degC', 'coupling_iterations']

  ! What the C callbacks see (CVODE calls them without our arguments): the model being
  ! integrated, the frozen contact states between located switches (allocated only when
  ! root finding is on: an unallocated array is an absent optional argument), the frozen
  ! root/tip branches of Eqs. 13-14 (coupled flash temperature only), and the first error.
  ! The integrated states are ys_full(idx): all 14 for dof = 7; the torsional level (dof = 3)
  ! integrates D1, D2, D3 and their velocities and holds the lateral states at ys_full.
  type(model_t), save :: mdl
  integer, allocatable, save :: idx(:)
  real(c_double), save :: ys_full(nstate)
  integer, allocatable, save :: modes(:), branches(:, :)
  logical, save :: frozen = .false.
  integer, save :: cb_ierr = 0
  character(len=512), save :: cb_msg = ''
  character(len=512), save :: cvode_msg = ''

contains

  !> Integrate the model from y0 (SI, at m%t0) and return the SI state at the times tout(1:nt)
  !> (ascending, >= t0) in yout(:, k), the final contact states and the solver statistics.
  subroutine integrate(m, y0, nt, tout, yout, modes_out, stats, ierr, errmsg)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: y0(nstate)
    integer, intent(in) :: nt
    real(wp), intent(in) :: tout(nt)
    real(wp), intent(out) :: yout(nstate, nt)
    integer, intent(out) :: modes_out(m%z, nt)
    real(wp), intent(out) :: stats(nstats)
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(c_double) :: ys(nstate)
    real(c_double), allocatable, target :: yr(:)
    real(c_double) :: tau, tau_out, tret(1), hlast(1)
    type(c_ptr) :: ctx, mem
    type(N_Vector), pointer :: sv
    type(SUNMatrix), pointer :: amat
    type(SUNLinearSolver), pointer :: ls
    type(SUNNonlinearSolver), pointer :: nls
    integer(c_int) :: flag, nroot
    integer(c_int), allocatable :: rootsfound(:)
    integer :: k, k0, nroots, nresync

    ierr = 0
    errmsg = ''
    stats = 0.0_wp
    mdl = m
    cb_ierr = 0; cb_msg = ''; cvode_msg = ''
    nroots = 0; nresync = 0
    call coupling_stats_reset()
    if (allocated(modes)) deallocate(modes)
    if (allocated(branches)) deallocate(branches)
    frozen = m%roots
    nroot = 0
    if (frozen) then
      allocate(modes(m%z))
      nroot = 2*m%z
      if (m%thermal == thermal_coupled) then
        allocate(branches(2, m%z))
        nroot = 4*m%z
      end if
    end if
    allocate(rootsfound(nroot))
    call to_scaled(m, y0, ys)
    if (m%dof == 3) then
      idx = [5, 6, 7, 12, 13, 14]
      ys(ndof+1:ndof+4) = 0.0_wp                 ! lateral states frozen at the start displacement
    else
      idx = [(k, k = 1, nstate)]
    end if
    ys_full = ys
    yr = ys(idx)
    tau = m%t0*m%w_ref
    k = 0
    if (frozen) call sync_modes(tau, ys, k)

    ctx = sundials_context_new()
    sv => FN_VMake_Serial(int(size(idx), c_long), yr, ctx)
    flag = FN_VEnableFusedOps_Serial(sv, 1)   ! fused vector kernels: less overhead per step
    amat => FSUNDenseMatrix(int(size(idx), c_long), int(size(idx), c_long), ctx)
    ls => FSUNLinSol_Dense(sv, amat, ctx)
    if (m%method_bdf == 1) then
      mem = FCVodeCreate(CV_BDF, ctx)
    else
      mem = FCVodeCreate(CV_ADAMS, ctx)
    end if
    flag = FCVodeInit(mem, c_funloc(rhs_cb), tau, sv)
    if (flag == 0) flag = FCVodeSetErrHandlerFn(mem, c_funloc(err_cb), c_null_ptr)
    if (flag == 0) flag = FCVodeSStolerances(mem, real(m%rtol, c_double), real(m%atol, c_double))
    if (m%newton) then
      if (flag == 0) flag = FCVodeSetLinearSolver(mem, ls, amat)
    else
      nls => FSUNNonlinSol_FixedPoint(sv, 0, ctx)   ! functional iteration, no Anderson acceleration
      if (flag == 0) flag = FCVodeSetNonlinearSolver(mem, nls)
    end if
    if (flag == 0) flag = FCVodeSetMaxNumSteps(mem, int(m%max_steps, c_long))
    if (flag == 0 .and. m%stald .and. m%method_bdf == 1) flag = FCVodeSetStabLimDet(mem, 1)
    if (flag == 0 .and. frozen) flag = FCVodeRootInit(mem, nroot, c_funloc(roots_cb))
    if (flag == 0 .and. frozen) flag = FCVodeSetNoInactiveRootWarn(mem)
    if (flag /= 0) then
      call fail(flag, tau, 'setting up CVODE')
      ierr = 2
    else
      do k = 1, nt
        tau_out = tout(k)*m%w_ref
        do while (tau < tau_out)
          flag = FCVode(mem, tau_out, sv, tret, CV_NORMAL)
          if (flag < 0) exit
          tau = tret(1)
          if (flag == CV_ROOT_RETURN) then
            ! Step onto the switch, flip the states of the teeth that crossed, restart.
            flag = FCVodeGetRootInfo(mem, rootsfound)
            call apply_roots(rootsfound, nroots)
            call add_counters(mem, stats)           ! CVodeReInit zeroes CVODE's counters
            flag = FCVodeReInit(mem, tau, sv)
            if (flag < 0) exit
          end if
        end do
        if (flag < 0) then
          call fail(flag, tau, 'integrating')
          exit
        end if
        ! Safety net: a grazing contact can touch a switch without a sign change over a step.
        ys(idx) = yr
        if (frozen) then
          k0 = nresync
          call sync_modes(tau, ys, nresync)
          if (nresync > k0 .and. k < nt) then
            call add_counters(mem, stats)
            flag = FCVodeReInit(mem, tau, sv)
          end if
        end if
        call from_scaled(m, ys, yout(:, k))
        if (frozen) then
          modes_out(:, k) = modes
        else
          modes_out(:, k) = 2     ! 2: decided by the state
        end if
      end do
    end if

    call add_counters(mem, stats)
    stats(7) = nroots
    flag = FCVodeGetLastStep(mem, hlast);              stats(9) = hlast(1)/m%w_ref
    stats(10) = nresync
    stats(11) = coupling_worst_residual()
    stats(12) = coupling_max_iterations()

    call FCVodeFree(mem)
    flag = FSUNLinSolFree(ls)
    if (.not. m%newton) flag = FSUNNonlinSolFree(nls)
    call FSUNMatDestroy(amat)
    call FN_VDestroy(sv)
    flag = FSUNContext_Free(ctx)

  contains

    subroutine fail(flag, tau, what)
      integer(c_int), intent(in) :: flag
      real(c_double), intent(in) :: tau
      character(len=*), intent(in) :: what
      character(len=:), allocatable :: fname
      fname = FCVodeGetReturnFlagName(int(flag, c_long))
      ierr = 2
      if (cb_ierr /= 0) then
        ierr = 3
        errmsg = cb_msg                       ! the physics said why (e.g. thermal interference)
        return
      end if
      write(errmsg, '(a,i0,a,es12.5,a)') 'case '//trim(m%name)//': CVODE failed while '//what// &
           ' with flag '//fname//' (', flag, ') at t = ', tau/m%w_ref, ' s'
      if (len_trim(cvode_msg) > 0) errmsg = trim(errmsg)//': '//trim(cvode_msg)
    end subroutine fail

  end subroutine integrate

  !> Add CVODE's counters since the last (re)initialisation to stats (order of stat_names).
  subroutine add_counters(mem, stats)
    type(c_ptr), intent(in) :: mem
    real(wp), intent(inout) :: stats(nstats)
    integer(c_long) :: cnt(1)
    integer(c_int) :: flag
    cnt = 0
    flag = FCVodeGetNumSteps(mem, cnt);                stats(1) = stats(1) + cnt(1)
    flag = FCVodeGetNumRhsEvals(mem, cnt);             stats(2) = stats(2) + cnt(1)
    if (mdl%newton) then
      flag = FCVodeGetNumJacEvals(mem, cnt);           stats(3) = stats(3) + cnt(1)
      flag = FCVodeGetNumLinRhsEvals(mem, cnt);        stats(4) = stats(4) + cnt(1)
    end if
    flag = FCVodeGetNumErrTestFails(mem, cnt);         stats(5) = stats(5) + cnt(1)
    flag = FCVodeGetNumNonlinSolvConvFails(mem, cnt);  stats(6) = stats(6) + cnt(1)
    if (frozen) then
      flag = FCVodeGetNumGEvals(mem, cnt);             stats(8) = stats(8) + cnt(1)
    end if
  end subroutine add_counters

  !> SUNDIALS 6.x context (SUNDIALS 7 takes SUN_COMM_NULL here): the one version-specific call.
  function sundials_context_new() result(ctx)
    type(c_ptr) :: ctx
    integer(c_int) :: flag
    flag = FSUNContext_Create(c_null_ptr, ctx)
  end function sundials_context_new

  !> Contact states (and branches) from the sign of the switch functions. Counts the switches
  !> whose stored state disagreed clearly (beyond round-off) with the state: a missed switch.
  subroutine sync_modes(tau, ys, nchanged)
    real(c_double), intent(in) :: tau, ys(nstate)
    integer, intent(inout) :: nchanged
    real(wp) :: y(nstate), g(2*mdl%z), gb(2*mdl%z), eps, epsv
    integer :: j, i, want
    call from_scaled(mdl, ys, y)
    call mesh_switch_functions(mdl, tau/mdl%w_ref, y(1:ndof), g, y(ndof+1:), gb)
    eps = 1.0e-9_wp*mdl%c_bulk
    epsv = eps*mdl%w_ref
    do j = 1, mdl%z
      want = 0
      if (g(2*j - 1) > 0.0_wp) want = 1
      if (g(2*j) < 0.0_wp) want = -1
      if (want /= modes(j)) then
        if (abs(g(2*j - 1)) > eps .and. abs(g(2*j)) > eps) nchanged = nchanged + 1
        modes(j) = want
      end if
      if (.not. allocated(branches)) cycle
      do i = 1, 2
        want = merge(-1, 1, gb(2*j - 2 + i) < 0.0_wp)
        if (want /= branches(i, j)) then
          if (abs(gb(2*j - 2 + i)) > epsv) nchanged = nchanged + 1
          branches(i, j) = want
        end if
      end do
    end do
  end subroutine sync_modes

  !> A located root of g_{2j-1} = dn_j - c_j (rising: drive flank engages, falling: it opens)
  !> or of g_{2j} = dn_j + c_j (falling: back flank engages, rising: it opens); then, in coupled
  !> mode, of dDelta_ij/dt (rising: the contact point moves to the tip, falling: to the root).
  subroutine apply_roots(rootsfound, nroots)
    integer(c_int), intent(in) :: rootsfound(:)
    integer, intent(inout) :: nroots
    integer :: j, i, z
    z = size(modes)
    do j = 1, z
      if (rootsfound(2*j - 1) == 1) modes(j) = 1
      if (rootsfound(2*j - 1) == -1) modes(j) = 0
      if (rootsfound(2*j) == -1) modes(j) = -1
      if (rootsfound(2*j) == 1) modes(j) = 0
      if (.not. allocated(branches)) cycle
      do i = 1, 2
        if (rootsfound(2*z + 2*j - 2 + i) /= 0) branches(i, j) = rootsfound(2*z + 2*j - 2 + i)
      end do
    end do
    nroots = nroots + count(rootsfound /= 0)
  end subroutine apply_roots

  integer(c_int) function rhs_cb(tau, sv_y, sv_f, udata) result(ret) bind(C)
    real(c_double), value :: tau
    type(N_Vector) :: sv_y, sv_f
    type(c_ptr), value :: udata
    real(c_double), pointer :: ys(:), fs(:)
    real(c_double) :: yf(nstate), ff(nstate)
    integer :: ierr
    ys => FN_VGetArrayPointer(sv_y)
    fs => FN_VGetArrayPointer(sv_f)
    yf = ys_full
    yf(idx) = ys
    call rhs_scaled(mdl, tau, yf, ff, ierr, cb_msg, modes, branches)   ! absent if unallocated
    fs = ff(idx)
    ret = 0
    if (ierr /= 0) then
      cb_ierr = ierr
      ret = -1
    end if
  end function rhs_cb

  integer(c_int) function roots_cb(tau, sv_y, gout, udata) result(ret) bind(C)
    real(c_double), value :: tau
    type(N_Vector) :: sv_y
    real(c_double) :: gout(*)
    type(c_ptr), value :: udata
    real(c_double), pointer :: ys(:)
    real(c_double) :: yf(nstate)
    real(wp) :: y(nstate)
    integer :: z
    ys => FN_VGetArrayPointer(sv_y)
    yf = ys_full
    yf(idx) = ys
    call from_scaled(mdl, yf, y)
    z = mdl%z
    if (allocated(branches)) then
      call mesh_switch_functions(mdl, tau/mdl%w_ref, y(1:ndof), gout(1:2*z), y(ndof+1:), &
           gout(2*z+1:4*z))
    else
      call mesh_switch_functions(mdl, tau/mdl%w_ref, y(1:ndof), gout(1:2*z))
    end if
    ret = 0
  end function roots_cb

  !> CVODE's own error text, kept for the exception instead of being printed to stderr.
  subroutine err_cb(error_code, module, function, msg, udata) bind(C)
    integer(c_int), value :: error_code
    type(c_ptr), value :: module, function, msg, udata
    cvode_msg = c_string(msg)
  end subroutine err_cb

  function c_string(p) result(s)
    type(c_ptr), intent(in) :: p
    character(len=:), allocatable :: s
    character(kind=c_char), pointer :: chars(:)
    integer :: n
    interface
      integer(c_size_t) function strlen(str) bind(C, name='strlen')
        import :: c_ptr, c_size_t
        type(c_ptr), value :: str
      end function strlen
    end interface
    if (.not. c_associated(p)) then
      s = ''; return
    end if
    n = int(strlen(p))
    call c_f_pointer(p, chars, [n])
    allocate(character(len=n) :: s)
    s = transfer(chars, s)
  end function c_string

end module spline_solver
