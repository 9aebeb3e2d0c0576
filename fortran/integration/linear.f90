!> The linear tail (docs/running.md section 4). With every tooth pair in contact on the same flank,
!> the mesh of Eqs. 15-17 and 19-22 is a linear, isotropic spring: for Z >= 3,
!> sum_j sin^2(phi_j) = sum_j cos^2(phi_j) = Z/2 and sum_j sin(phi_j) cos(phi_j) = 0 (Eqs. 8-9),
!> whatever the shaft angle. Without torque ripple, unbalance, the coupled flash temperature
!> (Eqs. 1-7 fed back) or face slices, the scaled system of Eq. 25 is then affine and
!> time-invariant, ys' = A ys + b, and its solution is known in closed form:
!>   ys(tau) = y* + Re sum_k v_k c_k exp(lambda_k (tau - tau_0)),  A y* + b = 0,
!> with (lambda_k, v_k) the eigenpairs of A and c = V^-1 (ys(tau_0) - y*).
!>
!> The tail is used only where it is proven to hold for the rest of the run (tail_try), not
!> guessed: every tooth j stays in contact on flank s (Eq. 16: s dn_j > c) if
!>   s D2(tau) - c - |e(tau)| > 0,  e = (x1 + l_x - x2, y1 + l_y - y2),
!> because dn_j = e_x sin(phi_j) - e_y cos(phi_j) + D2 (Eq. 11) and |e_x sin - e_y cos| <= |e|.
!> With all Re(lambda_k) < 0 each modal term only shrinks, so for all tau >= tau_0
!>   |D2(tau) - D2*| <= sum_k |v_6k| |c_k|,  |e(tau) - e*| <= sum_k |(v_1k - v_3k, v_2k - v_4k)| |c_k|,
!> and the condition holds for ever if s D2* - c - |e*| exceeds these bounds (with a margin for
!> the round-off of the eigenvectors). A is the core's frozen-contact Jacobian (spline_dynamics::
!> rhs_jacobian, every contact frozen on flank s); the right-hand side (rhs_scaled) is checked to
!> be that affine, time-invariant map at a second state and time before use.
module spline_linear
  use spline_kinds, only: wp, max_teeth
  use spline_errors, only: err_ok
  use spline_model, only: model_t, nstate, ndof, thermal_coupled
  use spline_dynamics, only: rhs_scaled, rhs_jacobian, from_scaled
  use spline_mesh, only: mesh_switch_functions
  implicit none
  private
  public :: tail_t, tail_possible, tail_try, tail_state, tail_states, tail_out_of_reach

  !> The closed-form tail of one run (held by the solver's context).
  type :: tail_t
    logical :: off = .false.           !< not possible in this run (never tried again)
    integer :: flank = 0               !< flank of the system built (+1, -1; 0: none yet)
    integer :: n = 0                   !< integrated states (ys_full(idx(1:n)))
    integer :: idx(nstate) = 0
    complex(wp), allocatable :: lam(:), v(:, :), w(:, :), c(:)
    real(wp), allocatable :: ystar(:)  !< y* over the integrated states (scaled, Eq. 25)
    !> what mode k can move D2 and |e| by per unit |c_k|: |v_6k| + |(v_1k - v_3k, v_2k - v_4k)|
    real(wp), allocatable :: weight(:)
    real(wp) :: margin = 0.0_wp        !< s D2* - c - |e*| at the equilibrium, less the round-off
    real(wp) :: held(nstate) = 0.0_wp  !< the full scaled state (its held entries at dof 3)
    real(wp) :: tau0 = 0.0_wp          !< scaled time the tail starts at
  end type tail_t

  interface
    subroutine zgeev(jobvl, jobvr, n, a, lda, w, vl, ldvl, vr, ldvr, work, lwork, rwork, info)
      import :: wp
      character, intent(in) :: jobvl, jobvr
      integer, intent(in) :: n, lda, ldvl, ldvr, lwork
      complex(wp), intent(inout) :: a(lda, *)
      complex(wp), intent(out) :: w(*), vl(ldvl, *), vr(ldvr, *), work(*)
      real(wp), intent(out) :: rwork(*)
      integer, intent(out) :: info
    end subroutine zgeev
    subroutine zgesv(n, nrhs, a, lda, ipiv, b, ldb, info)
      import :: wp
      integer, intent(in) :: n, nrhs, lda, ldb
      complex(wp), intent(inout) :: a(lda, *), b(ldb, *)
      integer, intent(out) :: ipiv(*), info
    end subroutine zgesv
  end interface

contains

  !> Whether the model's right-hand side can be affine and time-invariant in full contact:
  !> the case allows it (linear_tail), Z >= 3, no face slices, no coupled flash temperature,
  !> no torque ripple, no unbalance, no tooth spacing errors (their first harmonic turns with
  !> the shaft, a time-varying lateral force, and the contact bound above has no e_j).
  pure logical function tail_possible(m)
    type(model_t), intent(in) :: m
    tail_possible = m%linear_tail .and. m%z >= 3 .and. m%n_slices == 1 .and. &
         m%thermal /= thermal_coupled .and. m%n_ripple == 0 .and. all(m%unbalance == 0.0_wp) &
         .and. .not. m%spacing
  end function tail_possible

  !> Try to start the tail at scaled time tau from the full scaled state ys (integrated states
  !> idx(1:n)): .true. if every tooth is in contact on one flank and stays there for ever
  !> (the bound above). Builds the system of a flank on its first use; a failure to build it
  !> (not affine, not asymptotically stable, eigenvectors near defective, LAPACK) turns the
  !> tail off for the run.
  logical function tail_try(tl, m, idx, n, tau, ys) result(ok)
    type(tail_t), intent(inout) :: tl
    type(model_t), intent(in) :: m
    integer, intent(in) :: idx(nstate), n
    real(wp), intent(in) :: tau, ys(nstate)
    real(wp) :: y(nstate), g(2*max_teeth), z(nstate)   ! fixed sizes: no allocation per try
    integer :: s, nz
    ok = .false.
    if (tl%off) return
    call from_scaled(m, ys, y)
    if (tail_out_of_reach(m, y)) return     ! the test below would fail (a chaotic drive: mostly)
    nz = 2*m%z                              ! g(2j-1) = dn_j - c, g(2j) = dn_j + c
    call mesh_switch_functions(m, tau/m%w_ref, y(1:ndof), g(1:nz))
    if (all(g(1:nz:2) > 0.0_wp)) then
      s = 1
    else if (all(g(2:nz:2) < 0.0_wp)) then
      s = -1
    else
      return
    end if
    if (s /= tl%flank) then
      call build(tl, m, idx, n, tau, ys, s)
      if (tl%off) return
    end if
    ! the motion about the equilibrium, bounded mode by mode, against the equilibrium's margin
    z(1:n) = ys(idx(1:n)) - tl%ystar
    tl%c = matmul(tl%w, cmplx(z(1:n), 0.0_wp, wp))
    ok = tl%margin - 1.01_wp*sum(tl%weight*abs(tl%c)) > 0.0_wp
    if (ok) then
      tl%tau0 = tau
      tl%held = ys
    end if
  end function tail_try

  !> Whether some tooth is off both flanks at the SI state y (tail_try's test then fails), known
  !> without the switch functions: the tooth nearest the direction of the centre offset e (within
  !> pi/Z) has s dn_j <= s D2 - |e| cos(pi/Z) on either flank s (Eq. 11, no spacing errors), so
  !> where |D2| - |e| cos(pi/Z) falls short of the backlash by more than any round-off (1e-9 of
  !> c and |e|) the test fails. cos^2(pi/Z) = (1 + cos(2 pi/Z))/2, the model's cos_pitch.
  pure logical function tail_out_of_reach(m, y) result(out)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: y(nstate)
    real(wp) :: e2, d
    e2 = (y(1) + m%l_x - y(3))**2 + (y(2) + m%l_y - y(4))**2
    d = abs(y(6)) - m%c_bulk*(1.0_wp - 1.0e-9_wp)
    out = d < 0.0_wp .or. d**2 < (1.0_wp - 1.0e-9_wp)*e2*0.5_wp*(1.0_wp + m%cos_pitch)
  end function tail_out_of_reach

  !> The system of flank s: A = rhs_jacobian with every contact frozen on s, checked against
  !> rhs_scaled (affine and time-invariant); y*; the eigenpairs of A and V^-1.
  subroutine build(tl, m, idx, n, tau, ys, s)
    type(tail_t), intent(inout) :: tl
    type(model_t), intent(in) :: m
    integer, intent(in) :: idx(nstate), n, s
    real(wp), intent(in) :: tau, ys(nstate)
    real(wp) :: a(n, n), jac(nstate, nstate), f0(nstate), f1(nstate), y1(nstate), d(n), scale, &
         rwork(2*n), cs
    complex(wp) :: ac(n, n), vl(1, 1), work(4*n), vr(n, n), winv(n, n), lam(n), am(n, n), &
         vf(nstate, n)
    integer :: mode(m%z), k, ierr, info, ipiv(n)
    character(len=256) :: msg
    tl%off = .true.
    tl%flank = s
    tl%n = n
    tl%idx = idx
    mode = s
    msg = ''
    call rhs_scaled(m, tau, ys, f0, ierr, msg, mode=mode)
    if (ierr /= err_ok) return
    call rhs_jacobian(m, tau, mode, jac)
    a = jac(idx(1:n), idx(1:n))
    ! affine and time-invariant: a second state at a second time
    y1 = ys
    do k = 1, n
      d(k) = 0.1_wp*(1.0_wp + abs(ys(idx(k))))*merge(1.0_wp, -1.0_wp, mod(k, 2) == 0)
      y1(idx(k)) = ys(idx(k)) + d(k)
    end do
    call rhs_scaled(m, tau + 0.37_wp, y1, f1, ierr, msg, mode=mode)
    if (ierr /= err_ok) return
    scale = maxval(abs(f0(idx(1:n)))) + maxval(abs(matmul(abs(a), abs(d))))
    if (maxval(abs(f1(idx(1:n)) - f0(idx(1:n)) - matmul(a, d))) > 1.0e-10_wp*scale) return
    ! eigenpairs (LAPACK), asymptotic stability, V^-1
    ac = cmplx(a, 0.0_wp, wp)
    call zgeev('N', 'V', n, ac, n, lam, vl, 1, vr, n, work, size(work), rwork, info)
    if (info /= 0) return
    if (.not. maxval(real(lam)) < -1.0e-9_wp*maxval(abs(lam))) return
    am = vr
    winv = (0.0_wp, 0.0_wp)
    do k = 1, n
      winv(k, k) = (1.0_wp, 0.0_wp)
    end do
    call zgesv(n, n, am, n, ipiv, winv, n, info)
    if (info /= 0) return
    ! near-defective eigenvectors: V^-1 V far from I means c = V^-1 z cannot be trusted
    am = matmul(winv, vr)
    do k = 1, n
      am(k, k) = am(k, k) - 1.0_wp
    end do
    if (maxval(abs(am)) > 1.0e-8_wp) return
    ! y* = ys - A^-1 f(ys): solve with the eigenpairs (A = V diag(lam) V^-1)
    tl%ystar = ys(idx(1:n)) - real(matmul(vr, matmul(winv, cmplx(f0(idx(1:n)), 0.0_wp, wp))/lam))
    ! the bound's constants (module comment): the equilibrium's margin on flank s and each
    ! mode's reach in D2 and e (vf: the eigenvectors over the full state, 0 on a held state)
    y1 = ys
    y1(idx(1:n)) = tl%ystar
    cs = m%c_bulk/m%l_ref
    tl%margin = s*y1(6) - cs - hypot(y1(1) - y1(3) + m%l_x/m%l_ref, y1(2) - y1(4) + m%l_y/m%l_ref) &
         - 1.0e-9_wp*(abs(y1(6)) + cs)
    vf = (0.0_wp, 0.0_wp)
    vf(idx(1:n), :) = vr
    tl%weight = abs(vf(6, :)) + sqrt(abs(vf(1, :) - vf(3, :))**2 + abs(vf(2, :) - vf(4, :))**2)
    tl%lam = lam
    tl%v = vr
    tl%w = winv
    tl%off = .false.
  end subroutine build

  !> The full scaled state of the tail at scaled time tau (>= its start): tail_states at one time.
  subroutine tail_state(tl, tau, ys)
    type(tail_t), intent(in) :: tl
    real(wp), intent(in) :: tau
    real(wp), intent(out) :: ys(nstate)
    real(wp) :: one(nstate, 1)
    call tail_states(tl, [tau], one)
    ys = one(:, 1)
  end subroutine tail_state

  !> The tail at the ascending scaled times taus(i) (>= its start) into ys(:, i), as tail_state
  !> (bit for bit) at every nanchor-th time; between those, when the times are uniformly spaced
  !> (h, to the round-off of their computation), the motion about the equilibrium,
  !> x = ys - y*, advanced by the real step matrix P = Re(V diag(exp(lambda h)) V^-1):
  !> one real n x n product per time instead of n complex exponentials and an n x n complex
  !> product. Each step adds round-off of order n eps |P| |x|, at most nanchor - 1 steps from
  !> an exact anchor (about 1e-13 of the motion; tests/fortran/test_linear.f90).
  !> units (optional): each state's times units(i) (spline_dynamics::state_units: the SI states
  !> of from_scaled, to the bit, written once).
  subroutine tail_states(tl, taus, ys, units)
    type(tail_t), intent(in) :: tl
    real(wp), intent(in) :: taus(:)
    real(wp), intent(out) :: ys(:, :)
    real(wp), intent(in), optional :: units(nstate)
    integer, parameter :: nanchor = 32
    complex(wp) :: vh(tl%n, tl%n)
    ! fixed size (nstate; the rows and columns past n zero, never used): the compiler keeps the
    ! product's 14 sums in registers (with n's size they went through memory at every column)
    real(wp) :: p(nstate, nstate), x(nstate), xn(nstate), h, u(nstate), held(nstate)
    integer :: i, j, n, nt
    logical :: uniform
    u = 1.0_wp
    if (present(units)) u = units
    held = tl%held*u
    n = tl%n
    nt = size(taus)
    uniform = nt > 2
    if (uniform) then
      h = (taus(nt) - taus(1))/(nt - 1)
      uniform = all(abs(taus(2:) - taus(:nt-1) - h) <= 16*epsilon(h)*abs(taus(nt)))
    end if
    p = 0.0_wp; x = 0.0_wp
    if (uniform) then
      do j = 1, n
        vh(:, j) = tl%v(:, j)*exp(tl%lam(j)*h)
      end do
      p(1:n, 1:n) = real(matmul(vh, tl%w))
    end if
    do i = 1, nt
      if (uniform .and. mod(i - 1, nanchor) /= 0) then
        xn = 0.0_wp
        do j = 1, n                    ! P x by columns (n ~ 14: no library call)
          xn = xn + p(:, j)*x(j)
        end do
        x = xn
      else
        x(1:n) = real(matmul(tl%v, tl%c*exp(tl%lam*(taus(i) - tl%tau0))))
      end if
      ys(:, i) = held
      do j = 1, n                      ! element by element: no temporary at each time
        ys(tl%idx(j), i) = (tl%ystar(j) + x(j))*u(tl%idx(j))
      end do
    end do
  end subroutine tail_states

end module spline_linear
