!> The variational equations of Eq. 25 (docs/orbits.md, spec section 11): the state and tangent
!> vectors Phi integrated beside it, dPhi/dtau = J(tau) Phi, with the saltation matrix
!>   S = I + (f+ - f-) h_y / (h_y f- + h_t)
!> applied to Phi at every located contact switch h = dn_k -+ c = 0 (the mesh damping acts only
!> in contact, so the vector field jumps there). Between switches the contact state of every
!> tooth (slice) is frozen and the right-hand side is affine in the state, so J depends on time
!> and the contact states only: spline_dynamics' closed form (rhs_jacobian) from Eqs.
!> 11, 15-17 and 19-24. Everything is in the scaled states and time of Eq. 25. The thermal level
!> coupled (the tooth force depends on itself through the flash temperature) is not covered.
!> The run is CVODE's (the case's method and solver) made and driven through the integrator
!> layer (spline_integrator), as the state run's is: same set-up, work bounds, messages and
!> restart after a located switch. Reentrant: the run's state sits in a context and an
!> integrator_t local to tangent_flow, the context handed to CVODE as user data.
module spline_variational
  use, intrinsic :: iso_c_binding
  use fcvode_mod, only: CV_ROOT_RETURN
  use fsundials_nvector_mod, only: N_Vector, FN_VGetArrayPointer
  use fsundials_matrix_mod, only: SUNMatrix
  use fsunmatrix_band_mod, only: FSUNBandMatrix_Data, FSUNBandMatrix_LDim, &
       FSUNBandMatrix_StoredUpperBandwidth
  use spline_sigint, only: sigint_watch, sigint_unwatch, sigint_count
  use spline_kinds, only: wp, max_teeth
  use spline_errors, only: err_ok, err_case, err_solver, err_interrupted, msglen
  use spline_model, only: model_t, nstate, ndof, thermal_coupled
  use spline_geometry, only: tooth_angles
  use spline_dynamics, only: rhs_scaled, rhs_jacobian, to_scaled, from_scaled, integrated_states
  use spline_mesh, only: mesh_switch_functions, eq11_gradient, eq16_mode, eq16_root_mode, &
       eq16_root_directions, tooth_approach, slice_approach
  use spline_integrator, only: integrator_t, lib_log_t, integrator_open, cvode_create, &
       integrator_advance, integrator_root_info, integrator_root_directions, integrator_restart, &
       integrator_free, root_crossings
  use spline_integrator_report, only: integrator_fail_text, integrator_warnings
  implicit none
  private
  public :: tangent_flow, variational_check

  !> One tangent run: owned by tangent_flow, given to CVODE as user data.
  type :: tan_ctx_t
    type(model_t) :: m
    integer :: n = nstate, idx(nstate), ntan = 0
    real(c_double) :: ys_full(nstate)          !< scaled full state; the frozen entries stay here
    integer, allocatable :: modes(:)            !< contact state per contact (+1, 0, -1)
    integer :: nc = 0                           !< contacts: teeth, or slices of teeth
    logical :: watch = .false.
    integer(c_int) :: sigint0 = 0
    integer :: cb_ierr = err_ok
    character(len=msglen) :: cb_msg = ''
  end type tan_ctx_t

  interface
    !> CVODE's Jacobian callback of the run (fortran/integration/tan_jac.c): calls tan_jac.
    integer(c_int) function tan_jac_cvode(tau, y, fy, jmat, udata, tmp1, tmp2, tmp3) bind(C)
      import :: c_int, c_double, c_ptr
      real(c_double), value :: tau
      type(c_ptr), value :: y, fy, jmat, udata, tmp1, tmp2, tmp3
    end function tan_jac_cvode
  end interface

contains

  !> ierr = err_case (errmsg says why) for a model the variational equations do not cover:
  !> the thermal level coupled.
  subroutine variational_check(m, ierr, errmsg)
    type(model_t), intent(in) :: m
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    ierr = err_ok
    errmsg = ''
    if (m%thermal == thermal_coupled) then
      ierr = err_case
      errmsg = 'case '//trim(m%name)//': thermal = ''coupled'': the variational equations '// &
           '(exact monodromy, tangent Lyapunov exponent) do not cover it (the tooth force '// &
           'depends on itself through the flash temperature): use thermal = ''oneway'' or '// &
           'fidelity = ''auto''; or the finite-difference monodromy (monodromy = ''fd''), the '// &
           'separated copy (lyapunov_method = ''copy'')'
    end if
  end subroutine variational_check

  !> Integrate the state from y0 (SI, at m%t0) to t1 and the ntan tangent vectors phi(:, k)
  !> (scaled integrated states, ctx order: integrated_states) beside it: the variational
  !> equations of the run with root-located contact switches (always, whatever the case's
  !> roots), the saltation matrix applied to phi at each switch (unless saltation = .false.,
  !> kept to show it matters). CVODE's method, (non)linear solver and tolerances are the case's;
  !> the tangents are in its error control. y1: the SI state at t1; phi: the tangents there.
  !> nswitch (optional): the switches located. ierr: err_case (variational_check), err_solver,
  !> err_interrupted; errmsg says why. On success errmsg holds SUNDIALS' warnings, counted in
  !> msgs (optional: across a caller's runs), as spline_solver::integrate's; max_seconds
  !> (optional, > 0): the run's wall-time bound.
  subroutine tangent_flow(m, t1, y0, ntan, phi, y1, ierr, errmsg, interruptible, saltation, &
       nswitch, msgs, max_seconds)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t1, y0(nstate)
    integer, intent(in) :: ntan
    real(wp), intent(inout) :: phi(:, :)
    real(wp), intent(out) :: y1(nstate)
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    logical, intent(in), optional :: interruptible, saltation
    integer, intent(out), optional :: nswitch
    type(lib_log_t), intent(inout), optional :: msgs
    real(wp), intent(in), optional :: max_seconds
    type(tan_ctx_t), target :: ctx
    type(integrator_t), target :: cv
    real(c_double), allocatable, target :: yr(:)
    real(c_double) :: tau, tau1, tret(1)
    integer(c_int) :: flag, nroot
    integer(c_int), allocatable :: rootsfound(:)
    integer :: n, k, nsw
    logical :: salt
    character(len=48) :: stage
    salt = .true.
    if (present(saltation)) salt = saltation
    y1 = 0.0_wp
    nsw = 0
    if (present(nswitch)) nswitch = 0
    call variational_check(m, ierr, errmsg)
    if (ierr /= err_ok) return
    ctx%m = m
    ctx%ntan = ntan
    call integrated_states(m, ctx%idx, ctx%n)
    n = ctx%n
    ctx%nc = m%z*m%n_slices
    allocate(ctx%modes(ctx%nc))
    nroot = int(2*ctx%nc, c_int)
    allocate(rootsfound(nroot))
    call to_scaled(m, y0, ctx%ys_full)
    if (n < nstate) ctx%ys_full(ndof+1:ndof+4) = 0.0_wp   ! dof 3: lateral states held, at rest
    allocate(yr(n*(1 + ntan)))
    yr(1:n) = ctx%ys_full(ctx%idx(1:n))
    do k = 1, ntan
      yr(k*n+1:(k+1)*n) = phi(1:n, k)
    end do
    tau = m%t0*m%w_ref
    tau1 = t1*m%w_ref
    call sync_modes(ctx, tau, yr)
    if (present(interruptible)) ctx%watch = interruptible
    if (ctx%watch) ctx%sigint0 = sigint_watch()
    if (present(msgs)) cv%log = msgs
    call integrator_open(m, 'the variational run', yr, cv, flag, stage, max_seconds)
    ! Newton: the exact block-diagonal Jacobian (tan_jac) in a band of half-width n - 1; its
    ! LU costs (1 + ntan) n^3 instead of ((1 + ntan) n)^3 at every restart (a rattling drive
    ! restarts thousands of times a revolution)
    if (flag == 0) call cvode_create(m, tau, nroot, c_funloc(tan_rhs_cb), c_funloc(tan_roots_cb), &
         c_funloc(tan_jac_cvode), n - 1, c_loc(ctx), cv, flag, stage)
    do while (flag == 0 .and. tau < tau1)
      ! only the crossings that change a contact state are switches (as in spline_solver)
      stage = 'setting the directions of the contact switches'
      flag = integrator_root_directions(cv, eq16_root_directions(ctx%modes))
      if (flag /= 0) exit
      ! max_steps and max_total_steps over the run (its one output interval), across restarts
      stage = 'integrating'
      flag = integrator_advance(cv, tau, tau1, 0_8, tret)
      if (flag < 0) exit
      tau = tret(1)
      if (flag == CV_ROOT_RETURN) then
        stage = 'reading the roots found'
        flag = integrator_root_info(cv, rootsfound)
        if (flag /= 0) exit
        call switch(rootsfound)
        if (ctx%cb_ierr /= err_ok) then
          flag = -1
          exit
        end if
        stage = 'restarting at a contact switch'
        flag = integrator_restart(cv, tau, floored=.false.)
      else
        flag = 0
      end if
    end do
    if (flag /= 0) then
      call fail(flag)
    else
      y1 = 0.0_wp
      ctx%ys_full(ctx%idx(1:n)) = yr(1:n)
      call from_scaled(m, ctx%ys_full, y1)
      do k = 1, ntan
        phi(1:n, k) = yr(k*n+1:(k+1)*n)
      end do
    end if
    if (present(nswitch)) nswitch = nsw
    if (ctx%watch) call sigint_unwatch()
    call integrator_free(cv)
    if (present(msgs)) msgs = cv%log
    if (ierr == err_ok) call integrator_warnings(cv%log, m%name, errmsg)

  contains

    !> Flip the contact states of the contacts whose switch functions have crossed in the
    !> landed state (spline_integrator::root_crossings, as the state run), one at a time, each
    !> with its saltation matrix applied to the tangents.
    subroutine switch(rootsfound)
      integer(c_int), intent(in) :: rootsfound(:)
      integer(c_int) :: crossed(size(rootsfound))
      real(wp) :: y(nstate), g(2*ctx%nc), dg(2*ctx%nc)
      integer :: j, new
      ctx%ys_full(ctx%idx(1:n)) = yr(1:n)
      call from_scaled(m, ctx%ys_full, y)
      call mesh_switch_functions(m, tau/m%w_ref, y(1:ndof), g, y(ndof+1:), dg)
      crossed = root_crossings(rootsfound, eq16_root_directions(ctx%modes), g, dg)
      do j = 1, ctx%nc
        new = eq16_root_mode(ctx%modes(j), crossed(2*j - 1), crossed(2*j))
        if (new == ctx%modes(j)) cycle
        nsw = nsw + 1
        if (salt) call apply_saltation(ctx, tau, j, new, yr)
        ctx%modes(j) = new
        if (ctx%cb_ierr /= err_ok) return
      end do
    end subroutine switch

    subroutine fail(flag)
      integer(c_int), intent(in) :: flag
      ierr = err_solver
      if (ctx%cb_ierr /= err_ok) then
        ierr = ctx%cb_ierr
        errmsg = ctx%cb_msg
      else if (ctx%watch .and. sigint_count() /= ctx%sigint0) then
        ierr = err_interrupted
        write(errmsg, '(a,es12.5,a)') 'case '//trim(m%name)//': interrupted (SIGINT) at t = ', &
             tau/m%w_ref, ' s'
      else
        call integrator_fail_text(cv, m, flag, tau, trim(stage), errmsg)
      end if
    end subroutine fail

  end subroutine tangent_flow

  !> Contact states from the signs of the switch functions at tau (the run's start).
  subroutine sync_modes(ctx, tau, v)
    type(tan_ctx_t), intent(inout) :: ctx
    real(c_double), intent(in) :: tau, v(:)
    real(wp) :: y(nstate), g(2*ctx%nc), ys(nstate)
    ys = ctx%ys_full
    ys(ctx%idx(1:ctx%n)) = v(1:ctx%n)
    call from_scaled(ctx%m, ys, y)
    call mesh_switch_functions(ctx%m, tau/ctx%m%w_ref, y(1:ndof), g)
    ctx%modes = eq16_mode(g(1::2), g(2::2))
  end subroutine sync_modes

  !> Phi <- S Phi at the switch of contact k (tooth j, slice s) to state new, at tau:
  !> S = I + (f+ - f-) h_y^T / (h_y f- + h_tau), h = dn_k -+ c (Eq. 11, scaled states), f-, f+
  !> the right-hand sides with the old and new contact states (the velocity rows jump by the
  !> mesh damping's force). h_y f- + h_tau = d(dn_k)/dtau: the contact's approach rate.
  subroutine apply_saltation(ctx, tau, k, new, v)
    type(tan_ctx_t), intent(inout) :: ctx
    real(c_double), intent(in) :: tau
    integer, intent(in) :: k, new
    real(c_double), intent(inout) :: v(:)
    real(wp) :: ys(nstate), y(nstate), fm(nstate), fp(nstate), hy(nstate), ht, den, sp(max_teeth)
    real(wp) :: cp(max_teeth), ex, ey, dn, ddn, dns, dfi(nstate), hphi, u(ndof)
    integer :: mode_new(size(ctx%modes)), j, is, ns, n, c, ie
    associate(m => ctx%m)
      n = ctx%n
      ns = m%n_slices
      j = (k - 1)/ns + 1
      is = k - (j - 1)*ns
      ys = ctx%ys_full
      ys(ctx%idx(1:n)) = v(1:n)
      call from_scaled(m, ys, y)
      call tooth_angles(m%z, m%omega, tau/m%w_ref, m%theta0, m%alpha, m%sin_pitch, m%cos_pitch, sp, cp)
      ex = y(1) + m%l_x - y(3)
      ey = y(2) + m%l_y - y(4)
      hy = 0.0_wp
      call eq11_gradient(sp(j), cp(j), u)
      hy(1:ndof) = m%l_ref*u
      ! h_tau: the contact's approach rate at rest (Eq. 11's rate with the velocities 0)
      call tooth_approach(ex, ey, 0.0_wp, 0.0_wp, y(6), 0.0_wp, m%omega, m%spacing_error(j), &
           sp(j), cp(j), dn, ddn)
      call slice_approach(m, is, sp(j), cp(j), dn, ddn, dns, ht)
      ht = ht/m%w_ref
      mode_new = ctx%modes
      mode_new(k) = new
      call rhs_scaled(m, tau, ys, fm, ie, ctx%cb_msg, ctx%modes(1:ctx%nc))
      if (ie == err_ok) call rhs_scaled(m, tau, ys, fp, ie, ctx%cb_msg, mode_new(1:ctx%nc))
      if (ie /= err_ok) then
        ctx%cb_ierr = ie
        return
      end if
      den = dot_product(hy, fm) + ht
      if (den == 0.0_wp) return            ! grazing: S is unbounded there (not handled)
      dfi = (fp - fm)/den
      do c = 1, ctx%ntan
        hphi = dot_product(hy(ctx%idx(1:n)), v(c*n+1:(c+1)*n))
        v(c*n+1:(c+1)*n) = v(c*n+1:(c+1)*n) + dfi(ctx%idx(1:n))*hphi
      end do
    end associate
  end subroutine apply_saltation

  !> CVODE's right-hand side: Eq. 25 on the integrated states (frozen contact states), and
  !> J Phi for the tangents.
  integer(c_int) function tan_rhs_cb(tau, sv_y, sv_f, udata) result(ret) bind(C)
    real(c_double), value :: tau
    type(N_Vector) :: sv_y, sv_f
    type(c_ptr), value :: udata
    type(tan_ctx_t), pointer :: ctx
    real(c_double), pointer :: ys(:), fs(:)
    real(wp) :: yf(nstate), ff(nstate), jac(nstate, nstate), jr(nstate, nstate)
    integer :: ie, n, k
    call c_f_pointer(udata, ctx)
    ys => FN_VGetArrayPointer(sv_y)
    fs => FN_VGetArrayPointer(sv_f)
    n = ctx%n
    yf = ctx%ys_full
    yf(ctx%idx(1:n)) = ys(1:n)
    call rhs_scaled(ctx%m, tau, yf, ff, ie, ctx%cb_msg, ctx%modes(1:ctx%nc))
    fs(1:n) = ff(ctx%idx(1:n))
    if (ctx%ntan > 0) then
      call rhs_jacobian(ctx%m, tau, ctx%modes(1:ctx%nc), jac)
      jr(1:n, 1:n) = jac(ctx%idx(1:n), ctx%idx(1:n))
      do k = 1, ctx%ntan
        fs(k*n+1:(k+1)*n) = matmul(jr(1:n, 1:n), ys(k*n+1:(k+1)*n))
      end do
    end if
    ret = 0
    if (ie /= err_ok) then
      ctx%cb_ierr = ie
      ret = -1
    else if (ctx%watch) then
      if (sigint_count() /= ctx%sigint0) ret = -1
    end if
  end function tan_rhs_cb

  !> The augmented system's Jacobian: J on the diagonal blocks (the state's and each tangent's;
  !> J does not depend on the state between switches, so the blocks off the diagonal are 0).
  !> CVODE calls it through tan_jac.c's tan_jac_cvode, which drops the arguments it needs not.
  integer(c_int) function tan_jac(tau, jmat, udata) result(ret) bind(C, name='tan_jac')
    real(c_double), value :: tau
    type(SUNMatrix) :: jmat
    type(c_ptr), value :: udata
    type(tan_ctx_t), pointer :: ctx
    real(c_double), pointer :: flat(:)
    real(wp) :: jac(nstate, nstate)
    integer :: n, k, i, j, ldim, smu
    call c_f_pointer(udata, ctx)
    n = ctx%n
    flat => FSUNBandMatrix_Data(jmat)
    ldim = int(FSUNBandMatrix_LDim(jmat))
    smu = int(FSUNBandMatrix_StoredUpperBandwidth(jmat))
    flat = 0.0_c_double
    call rhs_jacobian(ctx%m, tau, ctx%modes(1:ctx%nc), jac)
    ! band storage: entry (r, c) (0-based) at data(c ldim + smu + r - c)
    do k = 0, ctx%ntan
      do j = 1, n
        do i = 1, n
          flat((k*n + j - 1)*ldim + smu + i - j + 1) = jac(ctx%idx(i), ctx%idx(j))
        end do
      end do
    end do
    ret = 0
  end function tan_jac

  !> Root functions: the contact switches of Eq. 16 (spline_mesh::mesh_switch_functions).
  integer(c_int) function tan_roots_cb(tau, sv_y, gout, udata) result(ret) bind(C)
    real(c_double), value :: tau
    type(N_Vector) :: sv_y
    real(c_double) :: gout(*)
    type(c_ptr), value :: udata
    type(tan_ctx_t), pointer :: ctx
    real(c_double), pointer :: ys(:)
    real(wp) :: y(nstate), yf(nstate)
    call c_f_pointer(udata, ctx)
    ys => FN_VGetArrayPointer(sv_y)
    yf = ctx%ys_full
    yf(ctx%idx(1:ctx%n)) = ys(1:ctx%n)
    call from_scaled(ctx%m, yf, y)
    call mesh_switch_functions(ctx%m, tau/ctx%m%w_ref, y(1:ndof), gout(1:2*ctx%nc))
    ret = 0
  end function tan_roots_cb

end module spline_variational
