!> The fidelity ladder ("model no more than a scene needs"): error estimates for the cheaper
!> model levels against the level a case sets, and the level fidelity = 'auto' runs (auto_level, called by spline_run::run_case).
!>
!> Both estimates are relative to the static tooth load F0 = |T_d| / (Z r_b) (Eq. 22 with every
!> tooth equal) and bound the change of a tooth force as k_m times a displacement the cheaper
!> level leaves out (Eqs. 15-17):
!>  - torsional only (dof 3) leaves out the lateral motion. Its drivers are the misalignment
!>    (l_x, l_y), the difference of the gravity sags g |m_1/k_p1 - m_2/k_p2|, a lateral start
!>    offset, the unbalance (its static deflection m_u e omega^2 / k_p) and the angular
!>    misalignment (gamma b / 2 at the face ends), and the first harmonic of the tooth spacing
!>    errors, an eccentricity (2/Z) |sum_j e_j exp(2 pi i j/Z)| (docs/model.md section 11).
!>    Without them every tooth sees the same dn_j, sum_j F_j sin(phi_j) = 0 (Z >= 3) and the
!>    lateral states never move: dof 3 is then exact.
!>  - a temperature dT left out of Eq. 2 moves the backlash by kappa dT, kappa = 2 lambda s cos(alpha).
module spline_fidelity
  use spline_kinds, only: wp, pi
  use spline_model, only: model_t, thermal_none, thermal_bulk, thermal_oneway, thermal_coupled, &
       set_thermal_level
  implicit none
  private
  public :: static_tooth_load, lateral_estimate, backlash_estimate, auto_level, auto_tol

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
    eps_lat = lateral_estimate(m)
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

  !> F0 = |T_d| / (Z r_b): the tooth load of the static, aligned mesh (Eq. 22) [N].
  pure real(wp) function static_tooth_load(m) result(f0)
    type(model_t), intent(in) :: m
    f0 = abs(m%t_d)/(m%z*m%r_b)
  end function static_tooth_load

  !> Estimated relative tooth-force error of the torsional level: k_m e / F0, with e the lateral
  !> excitation |(l_x, l_y)| + g |m_1/k_p1 - m_2/k_p2| + |lateral dq0|. Huge (never reduce) for a
  !> lateral start velocity, a free lateral body (k_p = 0) or no load.
  pure real(wp) function lateral_estimate(m) result(eps)
    type(model_t), intent(in) :: m
    real(wp) :: e, f0, es, ec
    integer :: j
    f0 = static_tooth_load(m)
    eps = huge(1.0_wp)
    if (f0 == 0.0_wp .or. m%k_p1 == 0.0_wp .or. m%k_p2 == 0.0_wp) return
    if (any(m%dv0(1:4) /= 0.0_wp)) return
    e = hypot(m%l_x, m%l_y) + m%grav*abs(m%m_1/m%k_p1 - m%m_2/m%k_p2) + norm2(m%dq0(1:4)) &
         + m%omega**2*(m%unbalance(1)/m%k_p1 + m%unbalance(2)/m%k_p2) &
         + 0.5_wp*m%b*hypot(m%gamma_x, m%gamma_y)
    if (m%spacing) then
      es = 0.0_wp; ec = 0.0_wp
      do j = 1, m%z
        es = es + m%spacing_error(j)*sin(2.0_wp*pi*j/m%z)
        ec = ec + m%spacing_error(j)*cos(2.0_wp*pi*j/m%z)
      end do
      e = e + 2.0_wp/m%z*hypot(es, ec)
    end if
    eps = m%k_m*e/f0
  end function lateral_estimate

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
