!> The state run: time integration of the scaled system of Eq. 25 with CVODE or ARKODE's
!> ERKStep (method = 'erk'), made and driven through the integrator layer (spline_integrator),
!> with optional root finding on the contact switches of Eq. 16, outputs, sections and the
!> linear tail.
!>
!> Reentrant: all run state sits in a solver_ctx_t and an integrator_t local to `integrate`;
!> the integrator hands the context to the callbacks as their user data. No module variable
!> changes during a run.
module spline_solver
  use, intrinsic :: iso_c_binding
  use fcvode_mod, only: CV_ROOT_RETURN
  use fsundials_nvector_mod, only: N_Vector, FN_VGetArrayPointer
  use spline_sigint, only: sigint_watch, sigint_unwatch, sigint_count
  use spline_kinds, only: wp, pi
  use spline_errors, only: err_ok, err_solver, err_interrupted, msglen
  use spline_model, only: model_t, nstate, ndof
  use spline_dynamics, only: rhs_scaled, to_scaled, from_scaled, state_units, integrated_states
  use spline_mesh, only: mesh_switch_functions, coupling_stats_t, eq16_mode, eq16_root_mode, &
       eq16_root_directions
  use spline_linear, only: tail_t, tail_possible, tail_try, tail_state, tail_states
  use spline_integrator, only: integrator_t, lib_log_t, integrator_open, cvode_create, &
       erk_create, integrator_advance, integrator_root_info, integrator_root_directions, &
       integrator_land_on_root, integrator_restart, integrator_steps_done, integrator_last_step, &
       add_counters, integrator_free, root_crossings, integrator_tolerances
  use spline_integrator_report, only: integrator_fail_text, integrator_warnings
  use spline_quantities, only: nstats => nsolver_stats, ist_roots_found, &
       ist_last_step, ist_mode_resyncs, ist_coupling_residual, ist_coupling_iterations, &
       ist_linear_tail_t
  implicit none
  private
  public :: integrate

  !> Everything a run changes, owned by `integrate` and given to CVODE as user data.
  type :: solver_ctx_t
    type(model_t) :: m                      !< the model integrated
    integer :: n = nstate                   !< integrated states of a copy: ys_full(idx(1:n), c)
    integer :: idx(nstate)
    integer :: ncopy = 1                    !< 1, or 2: a perturbed copy beside the reference
    real(c_double) :: ys_full(nstate, 2)    !< scaled full state per copy; frozen entries stay here
    logical :: frozen = .false.             !< root finding: contact states frozen between switches
    integer :: nrc = 0                      !< root functions per copy
    integer, allocatable :: modes(:, :)     !< contact state (+1, 0, -1) per contact and copy
    type(coupling_stats_t) :: cstats        !< work of the flash-temperature coupling
    logical :: watch = .false.              !< stop on SIGINT (callers that can raise it)
    integer(c_int) :: sigint0 = 0           !< SIGINT count when the run began
    integer :: cb_ierr = err_ok             !< first error raised inside a callback
    character(len=msglen) :: cb_msg = ''
  end type solver_ctx_t

contains

  !> Integrate the model from y0 (SI, at m%t0) and return the SI state at the times tout(1:nt)
  !> (ascending, >= t0) in yout(:, k), the contact states there (2: decided by the state) and
  !> the solver statistics. interruptible: a SIGINT during the run stops it (err_interrupted).
  !> tsec (optional, ascending, > t0): section times; ysec(:, i) the SI state at tsec(i).
  !> Sections do not stop CVODE: asked for the state at that instant (CV_NORMAL), it returns its
  !> dense output there (the interpolant CVODE also locates roots on), and unlike a stop time
  !> (20 % more work on paper_lx1e-4, docs/performance.md) the steps go on as they would, except
  !> that the first step after a (re)start (CVodeInit; CVodeReInit at a contact switch) is sized
  !> from the next requested time: with root finding a section can change the steps (chaos_z24
  !> with section = 'tooth': 289308 steps instead of 290972).
  !> y0b, youtb (optional, together): a second copy started at y0b, integrated beside the first
  !> as one CVODE system (same steps, order and corrector iterations: their difference carries
  !> no independent solver noise; spline_lyapunov); youtb(:, k) its state at tout(k). Contact
  !> switches of either copy are located (root finding) and restart both.
  !> The linear tail (spline_linear): a single copy whose case allows it is tried at the start,
  !> after every output and, without root finding, each quarter shaft revolution between them.
  !> Once every tooth is proven to stay in contact on one flank for ever, the remaining outputs
  !> and sections are the closed-form solution; stats(ist_linear_tail_t) is the time the tail
  !> began (-1: none).
  !> SUNDIALS' messages are never printed (spline_integrator::lib_handler): a failure's text
  !> joins errmsg; its warnings, counted in msgs (optional: one log across the runs of a caller),
  !> are errmsg on success (spline_integrator::integrator_warnings; '' if none).
  !> max_seconds (optional, > 0): the run's wall-time bound (a map run's), counted from the
  !> system_clock count wall_start (optional; default: the run's start).
  subroutine integrate(m, y0, nt, tout, yout, modes_out, stats, ierr, errmsg, interruptible, &
       tsec, ysec, y0b, youtb, msgs, max_seconds, wall_start, name)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: y0(nstate)
    integer, intent(in) :: nt
    real(wp), intent(in) :: tout(nt)
    real(wp), intent(out) :: yout(nstate, nt)
    integer, intent(out) :: modes_out(m%z*m%n_slices, nt)
    real(wp), intent(out) :: stats(nstats)
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    logical, intent(in), optional :: interruptible
    real(wp), intent(in), optional :: tsec(:)
    real(wp), intent(out), optional :: ysec(:, :)
    real(wp), intent(in), optional :: y0b(nstate)
    real(wp), intent(out), optional :: youtb(nstate, nt)
    type(lib_log_t), intent(inout), optional :: msgs
    real(wp), intent(in), optional :: max_seconds
    integer(8), intent(in), optional :: wall_start
    character(len=*), intent(in), optional :: name   !< the run's name in messages ('the run')
    type(solver_ctx_t), target :: ctx
    type(integrator_t), target :: cv
    real(c_double), allocatable, target :: yr(:)   !< CVODE's state vector (the copies' integrated states)
    real(c_double) :: tau                          !< where the integration stands (scaled time)
    real(c_double) :: tau_chk, dchk                !< next linear-tail check, and their spacing
    integer(c_int) :: flag, nroot
    integer :: k, nroots, nresync   !< output; switches located; missed switches resynchronised
    integer :: kdone                !< outputs stored (those after it are zeroed at the end)
    integer, allocatable :: dirs(:), dirs_set(:)   !< root directions wanted, and set in CVODE
    integer :: ks, nsec             !< next section to store; sections
    logical :: use_tail, fresh      !< the linear tail is tried; CVODE has just (re)started
    logical :: loose                !< the transient runs at its own tolerances
    character(len=40) :: stage
    type(tail_t) :: tail

    call start_run()
    if (present(msgs)) cv%log = msgs
    if (present(name)) then
      call integrator_open(m, name, yr, cv, flag, stage, max_seconds, wall_start)
    else
      call integrator_open(m, 'the run', yr, cv, flag, stage, max_seconds, wall_start)
    end if
    if (flag == 0 .and. m%erk) then
      call erk_create(m, tau, nroot, c_funloc(rhs_cb), c_funloc(roots_cb), c_loc(ctx), cv, &
           flag, stage)
    else if (flag == 0) then
      call cvode_create(m, tau, nroot, c_funloc(rhs_cb), c_funloc(roots_cb), c_null_funptr, 0, &
           c_loc(ctx), cv, flag, stage)
    end if
    ! a transient of its own tolerances (goal = 'statistics', spline_accuracy): up to the first
    ! output, then the window's
    loose = m%rtol_transient > 0.0_wp .and. m%t_transient > 0.0_wp
    if (flag == 0 .and. loose) then
      stage = 'setting the transient''s tolerances'
      flag = integrator_tolerances(cv, m%rtol_transient, 1.0e-2_wp*m%rtol_transient)
    end if
    call schedule_tail_checks()
    if (flag /= 0) then
      call fail(flag, tau, trim(stage))
    else if (.not. take_linear_tail(0)) then
      outputs: do k = 1, nt
        if (.not. integrate_to_output(k)) exit outputs
        if (.not. store_output(k)) exit outputs
        if (k == 1 .and. loose) then
          flag = integrator_tolerances(cv, m%rtol, m%atol)
          if (flag /= 0) then
            call fail(flag, tau, 'setting the window''s tolerances')
            exit outputs
          end if
        end if
        if (k < nt) then
          if (take_linear_tail(k)) exit outputs
        end if
      end do outputs
    end if
    yout(:, kdone+1:) = 0.0_wp        ! the outputs not reached (stored ones written once)
    if (present(youtb)) youtb(:, kdone+1:) = 0.0_wp
    call collect_stats()
    if (ctx%watch) call sigint_unwatch()
    call integrator_free(cv)
    if (present(msgs)) msgs = cv%log
    if (ierr == err_ok) call integrator_warnings(cv%log, m%name, errmsg)

  contains

    !> Outputs zeroed; the run context: the copies' scaled start states, the integrated states
    !> (dof 3 holds the lateral ones), contact states from the start state, the SIGINT watch.
    subroutine start_run()
      integer :: c, nn, nstart
      nstart = 0
      ierr = err_ok
      errmsg = ''
      stats = 0.0_wp
      stats(ist_linear_tail_t) = -1.0_wp
      kdone = 0
      modes_out = 2
      ctx%m = m
      nroots = 0; nresync = 0
      ctx%frozen = m%roots
      if (present(y0b)) ctx%ncopy = 2
      nroot = 0
      if (ctx%frozen) then
        allocate(ctx%modes(m%z*m%n_slices, ctx%ncopy))
        nroot = 2*m%z*m%n_slices
      end if
      ctx%nrc = nroot
      nroot = nroot*ctx%ncopy
      allocate(dirs(nroot), dirs_set(nroot))
      dirs_set = 2                               ! none set yet
      nsec = 0
      if (present(tsec)) nsec = size(tsec)
      if (present(ysec)) ysec = 0.0_wp
      ks = 1
      call integrated_states(m, ctx%idx, ctx%n)
      nn = ctx%n
      call to_scaled(m, y0, ctx%ys_full(:, 1))
      if (ctx%ncopy == 2) call to_scaled(m, y0b, ctx%ys_full(:, 2))
      ! dof 3: the lateral states are held at the start displacement, at rest
      if (nn < nstate) ctx%ys_full(ndof+1:ndof+4, :) = 0.0_wp
      yr = [(ctx%ys_full(ctx%idx(1:nn), c), c = 1, ctx%ncopy)]
      tau = m%t0*m%w_ref
      if (ctx%frozen) then
        do c = 1, ctx%ncopy
          call sync_modes(ctx, c, tau, yr, nstart)   ! the start's states (not counted)
        end do
      end if
      if (present(interruptible)) ctx%watch = interruptible
      if (ctx%watch) ctx%sigint0 = sigint_watch()
    end subroutine start_run

    !> The linear tail is also tried between outputs (the transient): each quarter shaft revolution.
    subroutine schedule_tail_checks()
      use_tail = ctx%ncopy == 1 .and. tail_possible(m)
      dchk = huge(1.0_c_double)
      if (m%omega > 0.0_wp) dchk = 0.5_wp*pi*m%w_ref/m%omega
      tau_chk = tau + dchk
      fresh = .true.
    end subroutine schedule_tail_checks

    !> Integrate from tau to the output time tout(k): CVODE calls up to the next output, section
    !> time or tail check, within the work bounds; section states stored, contact switches
    !> applied. .false.: the run ends here (an error: ierr set; or the linear tail took over).
    logical function integrate_to_output(k) result(going)
      integer, intent(in) :: k
      real(c_double) :: tau_out, tau_to, tret(1)
      integer(c_int) :: flag
      integer(8) :: done_k
      integer :: c
      going = .false.
      tau_out = tout(k)*m%w_ref
      done_k = integrator_steps_done(cv)
      do while (tau < tau_out)
        ! work bounds across restarts: max_steps per output interval, max_total_steps over the
        ! run (spline_integrator::integrator_advance)
        tau_to = next_stop(tau_out)
        if (ctx%frozen) then
          ! only the crossings that change a contact state are switches (CVODE): the
          ! directions follow the contact states, set again only when these changed (the
          ! start, a switch, a resynchronisation; CVODE keeps them across restarts)
          dirs = [(eq16_root_directions(ctx%modes(:, c)), c = 1, ctx%ncopy)]
          if (any(dirs /= dirs_set)) then
            flag = integrator_root_directions(cv, dirs)
            if (flag /= 0) then
              call fail(flag, tau, 'setting the directions of the contact switches')
              return
            end if
            dirs_set = dirs
          end if
        end if
        flag = integrator_advance(cv, tau, tau_to, done_k, tret)
        if (flag < 0) then
          call fail(flag, tret(1), 'integrating')
          return
        end if
        tau = tret(1)
        fresh = .false.
        call store_section()
        if (use_tail .and. tau >= tau_chk .and. flag /= CV_ROOT_RETURN) then
          tau_chk = tau_chk + dchk
          if (take_linear_tail(k - 1)) return
        end if
        if (flag == CV_ROOT_RETURN) then
          if (.not. switch_contacts()) return
        end if
      end do
      going = .true.
    end function integrate_to_output

    !> Where the next CVode call returns: the output time tau_out, or an earlier section time
    !> or tail check. Tail checks are not taken with root finding (a return starts CVODE's next
    !> root search there), nor on a first call after CVodeInit/ReInit (its tout sets CVODE's
    !> initial step) unless tout is more than 4 revolutions away: a run that never takes the
    !> tail keeps the steps it has with linear_tail off, unless it starts so far from an output.
    real(c_double) function next_stop(tau_out) result(tau_to)
      real(c_double), intent(in) :: tau_out
      tau_to = tau_out
      if (ks <= nsec) tau_to = min(tau_out, real(tsec(ks)*m%w_ref, c_double))
      if (use_tail .and. .not. ctx%frozen) then
        do while (tau_chk <= tau)
          tau_chk = tau_chk + dchk
        end do
        if (.not. fresh .or. tau_to - tau > 16*dchk) tau_to = min(tau_to, tau_chk)
      end if
    end function next_stop

    !> CVode returned at the next section instant: store the SI state there.
    subroutine store_section()
      if (ks > nsec) return
      if (tau >= tsec(ks)*m%w_ref) then
        call from_scaled(m, copy_state(ctx, yr, 1), ysec(:, ks))
        ks = ks + 1
      end if
    end subroutine store_section

    !> CVode stopped on a contact switch: step onto it, flip the states of the teeth that
    !> crossed, restart. .false. if a call failed (ierr, errmsg set).
    logical function switch_contacts() result(ok)
      integer(c_int) :: rootsfound(nroot), flag
      flag = integrator_root_info(cv, rootsfound)
      ok = flag == 0
      if (.not. ok) then
        call fail(flag, tau, 'reading the roots found')
        return
      end if
      flag = integrator_land_on_root(cv, tau)
      ok = flag == 0
      if (.not. ok) then
        call fail(flag, tau, 'stepping onto a contact switch')
        return
      end if
      call settle_roots(ctx, rootsfound, tau, yr, nroots)
      ok = restart_cvode('restarting at a contact switch')
    end function switch_contacts

    !> At output time tout(k) (tau): stop on a SIGINT; resynchronise contact states that missed
    !> a switch (a grazing contact can touch one without a sign change over a step), restarting
    !> CVODE if any did; store the outputs. .false. if the run ends here (ierr, errmsg set).
    logical function store_output(k) result(going)
      integer, intent(in) :: k
      integer :: c, k0
      going = .false.
      if (interrupted(ctx)) then
        call fail(-1_c_int, tau, 'integrating')
        return
      end if
      if (ctx%frozen) then
        k0 = nresync
        do c = 1, ctx%ncopy
          call sync_modes(ctx, c, tau, yr, nresync)
        end do
        if (nresync > k0 .and. k < nt) then
          if (.not. restart_cvode('restarting after a missed switch')) return
        end if
      end if
      call from_scaled(m, copy_state(ctx, yr, 1), yout(:, k))
      if (present(youtb)) call from_scaled(m, copy_state(ctx, yr, 2), youtb(:, k))
      if (ctx%frozen) modes_out(:, k) = ctx%modes(:, 1)
      kdone = k
      going = .true.
    end function store_output

    !> Try the linear tail at tau, after output k0: if it holds, fill outputs k0+1..nt and the
    !> sections not yet reached with the closed-form solution and return .true. (the run is done).
    logical function take_linear_tail(k0) result(taken)
      integer, intent(in) :: k0
      real(c_double) :: yt(nstate)
      integer :: j
      taken = .false.
      if (.not. use_tail) return
      taken = tail_try(tail, m, ctx%idx, ctx%n, tau, copy_state(ctx, yr, 1))
      if (.not. taken) return
      stats(ist_linear_tail_t) = tau/m%w_ref
      call tail_states(tail, tout(k0+1:nt)*m%w_ref, yout(:, k0+1:nt), state_units(m))   ! SI
      if (ctx%frozen) modes_out(:, k0+1:nt) = tail%flank
      kdone = nt
      do j = ks, nsec
        call tail_state(tail, tsec(j)*m%w_ref, yt)
        call from_scaled(m, yt, ysec(:, j))
      end do
      ks = nsec + 1
    end function take_linear_tail

    !> Restart the integrator at tau (a contact switch: the right-hand side's branch changed;
    !> spline_integrator::integrator_restart); .false. if it failed (ierr, errmsg set).
    logical function restart_cvode(what) result(ok)
      character(len=*), intent(in) :: what
      integer(c_int) :: flag
      fresh = .true.
      flag = integrator_restart(cv, tau, stats)
      ok = flag == 0
      if (.not. ok) call fail(flag, tau, what)
    end function restart_cvode

    !> The statistics CVODE and the run kept (positions ist_* of spline_quantities).
    subroutine collect_stats()
      real(c_double) :: hlast(1)
      if (c_associated(cv%mem)) then
        call add_counters(cv, stats)
        if (integrator_last_step(cv, hlast) == 0) stats(ist_last_step) = hlast(1)/m%w_ref
      end if
      stats(ist_roots_found) = nroots
      stats(ist_mode_resyncs) = nresync
      stats(ist_coupling_residual) = ctx%cstats%worst_residual
      stats(ist_coupling_iterations) = ctx%cstats%max_iterations
    end subroutine collect_stats

    subroutine fail(flag, tau, what)
      integer(c_int), intent(in) :: flag
      real(c_double), intent(in) :: tau
      character(len=*), intent(in) :: what
      if (ierr /= err_ok) return
      ierr = err_solver
      if (ctx%cb_ierr /= err_ok) then
        ierr = ctx%cb_ierr
        errmsg = ctx%cb_msg                  ! the physics said why (e.g. thermal interference)
        return
      end if
      if (interrupted(ctx)) then
        ierr = err_interrupted
        write(errmsg, '(a,es12.5,a)') 'case '//trim(m%name)//': interrupted (SIGINT) at t = ', &
             tau/m%w_ref, ' s'
        return
      end if
      call integrator_fail_text(cv, m, flag, tau, what, errmsg)
    end subroutine fail

  end subroutine integrate

  !> A SIGINT arrived since the run began (only for runs that watch).
  logical function interrupted(ctx)
    type(solver_ctx_t), intent(in) :: ctx
    interrupted = .false.
    if (ctx%watch) interrupted = sigint_count() /= ctx%sigint0
  end function interrupted

  !> Contact states from the sign of the switch functions. Counts the switches
  !> whose stored state disagreed clearly (beyond round-off) with the state: a missed switch.
  subroutine sync_modes(ctx, c, tau, v, nchanged)
    type(solver_ctx_t), intent(inout) :: ctx
    integer, intent(in) :: c                   !< the copy
    real(c_double), intent(in) :: tau, v(:)    !< v: the integrated states (CVODE's vector)
    integer, intent(inout) :: nchanged
    real(wp) :: y(nstate), g(2*ctx%m%z*ctx%m%n_slices), eps
    integer :: j, want
    call from_scaled(ctx%m, copy_state(ctx, v, c), y)
    call mesh_switch_functions(ctx%m, tau/ctx%m%w_ref, y(1:ndof), g)
    eps = 1.0e-9_wp*ctx%m%c_bulk
    do j = 1, ctx%m%z*ctx%m%n_slices         ! every contact: a tooth, or a slice of a tooth
      want = eq16_mode(g(2*j - 1), g(2*j))
      if (want /= ctx%modes(j, c)) then
        if (abs(g(2*j - 1)) > eps .and. abs(g(2*j)) > eps) nchanged = nchanged + 1
        ctx%modes(j, c) = want
      end if
    end do
  end subroutine sync_modes

  !> A located root of g_{2j-1} = dn_j - c_j (rising: drive flank engages, falling: it opens)
  !> or of g_{2j} = dn_j + c_j (falling: back flank engages, rising: it opens).
  !> The root functions of copy c are rootsfound((c - 1) nrc + 1 : c nrc).
  subroutine apply_roots(ctx, rootsfound, nroots)
    type(solver_ctx_t), intent(inout) :: ctx
    integer(c_int), intent(in) :: rootsfound(:)
    integer, intent(inout) :: nroots
    integer :: j, nc, c, o
    nc = ctx%m%z*ctx%m%n_slices                      ! contacts: teeth, or slices of teeth
    do c = 1, ctx%ncopy
      o = (c - 1)*ctx%nrc
      do j = 1, nc
        ctx%modes(j, c) = eq16_root_mode(ctx%modes(j, c), rootsfound(o + 2*j - 1), &
             rootsfound(o + 2*j))
      end do
    end do
    nroots = nroots + count(rootsfound /= 0)
  end subroutine apply_roots

  !> The integrator stopped on located roots (ERKStep landed on them: integrator_land_on_root;
  !> CVODE returns the interpolated state at the root): the teeth whose switch functions have
  !> crossed in the landed state v switch (spline_integrator::root_crossings), the others keep
  !> their contact states until they do. Applying a reported root that had not crossed yet
  !> switched a contact early (its damping force at the impact speed at once); with CVODE, an
  !> aligned drive's 16 back flanks engaging 4.7 us after the section time (the doubling scene's
  !> period-2 orbit at 1620.12 r/min) chattered in and out there and the one-output period map
  !> closed 1.5 scaled off the orbit (tests/test_solver.py).
  subroutine settle_roots(ctx, rootsfound, tau, v, nroots)
    type(solver_ctx_t), intent(inout) :: ctx
    integer(c_int), intent(in) :: rootsfound(:)
    real(c_double), intent(in) :: tau, v(:)
    integer, intent(inout) :: nroots
    real(wp) :: y(nstate), g(ctx%nrc), dg(ctx%nrc)
    integer(c_int) :: crossed(size(rootsfound))
    integer :: c, o
    do c = 1, ctx%ncopy
      o = (c - 1)*ctx%nrc
      call from_scaled(ctx%m, copy_state(ctx, v, c), y)
      call mesh_switch_functions(ctx%m, tau/ctx%m%w_ref, y(1:ndof), g, y(ndof+1:), dg)
      crossed(o+1:o+ctx%nrc) = root_crossings(rootsfound(o+1:o+ctx%nrc), &
           eq16_root_directions(ctx%modes(:, c)), g, dg)
    end do
    call apply_roots(ctx, crossed, nroots)
  end subroutine settle_roots

  !> CVODE's right-hand side: Eq. 25 on the integrated states, the others held in ys_full.
  !> Every state integrated (n = nstate, idx the identity: the common case): on the vectors
  !> themselves, no gather. Returns -1 (unrecoverable) on a physics error or a SIGINT, kept in
  !> the context.
  integer(c_int) function rhs_cb(tau, sv_y, sv_f, udata) result(ret) bind(C)
    real(c_double), value :: tau
    type(N_Vector) :: sv_y, sv_f
    type(c_ptr), value :: udata
    type(solver_ctx_t), pointer :: ctx
    real(c_double), pointer, contiguous :: ys(:), fs(:)
    real(c_double) :: yf(nstate), ff(nstate)
    integer :: ierr, c, o, n
    call c_f_pointer(udata, ctx)
    n = ctx%n
    ys => vector_data(sv_y, n*ctx%ncopy)
    fs => vector_data(sv_f, n*ctx%ncopy)
    ierr = err_ok
    do c = 1, ctx%ncopy
      o = (c - 1)*n
      if (n == nstate) then
        call copy_rhs(ys(o+1:o+n), fs(o+1:o+n))
      else
        yf = copy_state(ctx, ys, c)
        call copy_rhs(yf, ff)
        fs(o+1:o+n) = ff(ctx%idx(1:n))
      end if
      if (ierr /= err_ok) exit
    end do
    ret = 0
    if (ierr /= err_ok) then
      ctx%cb_ierr = ierr
      ret = -1
    else if (interrupted(ctx)) then
      ret = -1
    end if
  contains
    subroutine copy_rhs(y, f)            ! Eq. 25 for copy c, in its contact states if frozen
      real(c_double), intent(in) :: y(nstate)
      real(c_double), intent(out) :: f(nstate)
      if (.not. ctx%frozen) then
        call rhs_scaled(ctx%m, tau, y, f, ierr, ctx%cb_msg, cstats=ctx%cstats)
      else
        call rhs_scaled(ctx%m, tau, y, f, ierr, ctx%cb_msg, ctx%modes(:, c), cstats=ctx%cstats)
      end if
    end subroutine copy_rhs
  end function rhs_cb

  !> The n numbers of the serial vector v. SUNDIALS' Fortran FN_VGetArrayPointer asks the
  !> vector's length through three more calls on each use (2 % of an ERK run on chaos_z24), its
  !> C N_VGetArrayPointer through the vector's operations (lincomb.c's spline_serial_data not).
  function vector_data(v, n) result(x)
    type(N_Vector), target, intent(in) :: v
    integer, intent(in) :: n
    real(c_double), pointer, contiguous :: x(:)
    interface
      type(c_ptr) function array_pointer(v) bind(C, name='spline_serial_data')
        import :: c_ptr
        type(c_ptr), value :: v
      end function array_pointer
    end interface
    call c_f_pointer(array_pointer(c_loc(v)), x, [n])
  end function vector_data

  integer(c_int) function roots_cb(tau, sv_y, gout, udata) result(ret) bind(C)
    real(c_double), value :: tau
    type(N_Vector) :: sv_y
    real(c_double) :: gout(*)
    type(c_ptr), value :: udata
    type(solver_ctx_t), pointer :: ctx
    real(c_double), pointer :: ys(:)
    real(wp) :: y(nstate)
    integer :: nc, c, og
    call c_f_pointer(udata, ctx)
    ys => FN_VGetArrayPointer(sv_y)
    nc = ctx%m%z*ctx%m%n_slices
    do c = 1, ctx%ncopy
      og = (c - 1)*ctx%nrc
      call from_scaled(ctx%m, copy_state(ctx, ys, c), y)
      call mesh_switch_functions(ctx%m, tau/ctx%m%w_ref, y(1:ndof), gout(og+1:og+2*nc))
    end do
    ret = 0
  end function roots_cb

  !> The scaled full state of copy c: the held (frozen) entries from ys_full, the integrated ones
  !> from v, CVODE's vector (the copies one after the other, n states each). Every state
  !> integrated: one copy (its stores are read back as pairs at once: stored element by element
  !> they could not be forwarded); else element by element (an array assignment with a vector
  !> subscript made a heap temporary on every call, at every output and tail try).
  pure function copy_state(ctx, v, c) result(yf)
    type(solver_ctx_t), intent(in) :: ctx
    real(c_double), intent(in) :: v(:)
    integer, intent(in) :: c
    real(c_double) :: yf(nstate)
    integer :: i
    if (ctx%n == nstate) then
      yf = v((c - 1)*nstate + 1:c*nstate)
      return
    end if
    yf = ctx%ys_full(:, c)
    do i = 1, ctx%n
      yf(ctx%idx(i)) = v((c - 1)*ctx%n + i)
    end do
  end function copy_state

end module spline_solver
