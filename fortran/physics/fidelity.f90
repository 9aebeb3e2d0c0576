!> The fidelity ladder ("model no more than a scene needs"): error estimates for the cheaper
!> model levels against the level a case sets, and the level fidelity = 'auto' runs (auto_level, called by spline_run::run_case).
!>
!> Both estimates are relative to the static tooth load F0 = |T_d| / (Z r_b) (Eq. 22 with every
!> tooth equal) and bound the change of a tooth force as k_m times a displacement the cheaper
!> level leaves out (Eqs. 15-17):
!>  - torsional only (dof 3) leaves out the lateral motion. Its drivers are the misalignment
!>    (l_x, l_y), the difference of the gravity sags g |m_1/k_p1 - m_2/k_p2|, a lateral start
!>    offset, the unbalance (its static deflection m_u e omega^2 / k_p) and the angular
!>    misalignment (gamma b / 2 at the face ends), and the lateral offset the tooth spacing
!>    errors make (spacing_offset: from the static equilibrium, partial contact included; with
!>    every tooth engaged only their first harmonic moves the centres, once teeth unload any
!>    pattern does, docs/model.md section 11). Without them every tooth sees the same dn_j,
!>    sum_j F_j sin(phi_j) = 0 (Z >= 3) and the lateral states never move: dof 3 is then exact.
!>  - a temperature dT left out of Eq. 2 moves the backlash by kappa dT, kappa = 2 lambda s cos(alpha).
module spline_fidelity
  use spline_kinds, only: wp
  use spline_model, only: model_t, ndof, thermal_none, thermal_bulk, thermal_oneway, &
       thermal_coupled, set_thermal_level, static_tooth_load
  use spline_dynamics, only: static_equilibrium
  use spline_errors, only: err_ok, msglen
  implicit none
  private
  public :: lateral_estimate, backlash_estimate, auto_level, auto_tol

  real(wp), parameter :: fidelity_margin = 0.5_wp   !< auto reduces when estimate <= margin * tol

contains

  !> fidelity = 'auto': run is m at the cheapest level of the ladder whose estimated error
  !> against the level m sets is within auto_tol(m), and that reports the same quantities
  !> (run = m otherwise). The estimates are not bounds: measured errors reach 1.3 of them,
  !> paper_T50/T100 one-way over 1 s (`python bench/run.py ladder`), hence the margin.
  !>  - dof 7 -> 3 when lateral_estimate <= tol;
  !>  - thermal bulk -> none when backlash_estimate(T_M) <= tol;
  !>  - thermal coupled -> oneway (same T_f output, no iteration in the RHS), checked afterwards
  !>    by spline_run::run_case: if backlash_estimate(max T_f of the one-way run) > tol the case
  !>    is run coupled.
  !> eps_lat, eps_th: the estimates (0 when not computed).
  subroutine auto_level(m, run, eps_lat, eps_th)
    type(model_t), intent(in) :: m
    type(model_t), intent(out) :: run
    real(wp), intent(out) :: eps_lat, eps_th
    real(wp) :: tol
    run = m
    eps_lat = 0.0_wp; eps_th = 0.0_wp
    tol = auto_tol(m)
    if (.not. m%auto) return
    eps_lat = lateral_estimate(m, spacing_offset(m))
    if (m%dof == 7 .and. eps_lat <= tol) run%dof = 3
    if (m%thermal == thermal_bulk) then
      eps_th = backlash_estimate(m, m%t_bulk)
      if (eps_th <= tol) call set_thermal_level(run, thermal_none)
    end if
    if (m%thermal == thermal_coupled) call set_thermal_level(run, thermal_oneway)
  end subroutine auto_level

  !> The error an estimate may reach for fidelity = 'auto' to take a cheaper level.
  pure real(wp) function auto_tol(m) result(tol)
    type(model_t), intent(in) :: m
    tol = fidelity_margin*m%fidelity_tol
  end function auto_tol

  !> Estimated relative tooth-force error of the torsional level: k_m e / F0, with e the lateral
  !> excitation |(l_x, l_y)| + g |m_1/k_p1 - m_2/k_p2| + |lateral dq0| + the unbalance's and
  !> the tilt's (above) + e_sp, the spacing errors' offset (spacing_offset). Huge (never reduce)
  !> for a lateral start velocity, a free lateral body (k_p = 0) or no load.
  pure real(wp) function lateral_estimate(m, e_sp) result(eps)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: e_sp
    real(wp) :: e, f0
    f0 = static_tooth_load(m)
    eps = huge(1.0_wp)
    if (f0 == 0.0_wp .or. m%k_p1 == 0.0_wp .or. m%k_p2 == 0.0_wp) return
    if (any(m%dv0(1:4) /= 0.0_wp)) return
    e = hypot(m%l_x, m%l_y) + m%grav*abs(m%m_1/m%k_p1 - m%m_2/m%k_p2) + norm2(m%dq0(1:4)) &
         + m%omega**2*(m%unbalance(1)/m%k_p1 + m%unbalance(2)/m%k_p2) &
         + 0.5_wp*m%b*hypot(m%gamma_x, m%gamma_y) + e_sp
    eps = m%k_m*e/f0
  end function lateral_estimate

  !> The lateral offset of the centres, |(x1 - x2, y1 - y2)|, that the tooth spacing errors
  !> make in the static equilibrium at t0 (spline_dynamics::static_equilibrium, with the errors
  !> less without them): the lateral force of the set of teeth the errors leave engaged, against
  !> the supports and the mesh. With every tooth engaged that is the errors' first harmonic,
  !> k_m (E_s, -E_c) against K + k_s (docs/model.md section 11); once teeth unload, any pattern.
  !> 0 without errors; huge (keep the lateral motion) where an equilibrium is not found.
  real(wp) function spacing_offset(m) result(e)
    type(model_t), intent(in) :: m
    type(model_t) :: m0
    real(wp) :: q(ndof), q0(ndof)
    integer :: ierr
    character(len=msglen) :: msg
    e = 0.0_wp
    if (.not. m%spacing) return
    e = huge(1.0_wp)
    msg = ''
    call static_equilibrium(m, m%t0, q, ierr, msg)
    if (ierr /= err_ok) return
    m0 = m
    m0%spacing = .false.; m0%spacing_error = 0.0_wp
    call static_equilibrium(m0, m%t0, q0, ierr, msg)
    if (ierr /= err_ok) return
    e = hypot(q(1) - q(3) - q0(1) + q0(3), q(2) - q(4) - q0(2) + q0(4))
  end function spacing_offset

  !> Estimated relative tooth-force error of leaving a temperature dtemp [degC] out of the
  !> backlash (Eq. 2): k_m kappa |dtemp| / F0. Huge with no load.
  pure real(wp) function backlash_estimate(m, dtemp) result(eps)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: dtemp
    real(wp) :: f0
    f0 = static_tooth_load(m)
    eps = huge(1.0_wp)
    if (f0 == 0.0_wp) return
    eps = m%k_m*m%kappa*abs(dtemp)/f0
  end function backlash_estimate

end module spline_fidelity
