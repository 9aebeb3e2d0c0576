!> Poincare sections: the instants at which the shaft (section = 'shaft') or the tooth pass
!> (section = 'tooth') angle omega t is a whole number of turns, in the output window. The
!> solver returns the state at each (spline_solver::integrate, tsec); a section does not stop
!> CVODE.
module spline_sections
  use spline_kinds, only: wp, pi
  use spline_model, only: model_t
  implicit none
  private
  public :: section_count, section_times

contains

  !> Period of the Poincare section [s]: the shaft revolution 2 pi / omega (section 1) or the
  !> tooth pass 2 pi / (Z omega) (section 2); 0 without a section.
  pure real(wp) function section_period(m) result(p)
    type(model_t), intent(in) :: m
    p = 0.0_wp
    if (m%section == 1) p = 2.0_wp*pi/m%omega
    if (m%section == 2) p = 2.0_wp*pi/(m%z*m%omega)
  end function section_period

  !> Range k0..k1 of the section times k p in the output window [t0 + t_transient, t_end]
  !> (after t0; a relative 1e-9 of p absorbs the round-off of t/p).
  pure subroutine section_range(m, k0, k1)
    type(model_t), intent(in) :: m
    integer(8), intent(out) :: k0, k1
    real(wp) :: p
    p = section_period(m)
    k0 = 1; k1 = 0
    if (p <= 0.0_wp) return
    k0 = ceiling((m%t0 + m%t_transient)/p - 1.0e-9_wp, 8)
    if (k0*p <= m%t0) k0 = k0 + 1
    k1 = floor(m%t_end/p + 1.0e-9_wp, 8)
  end subroutine section_range

  !> Number of Poincare section points of a run.
  pure integer function section_count(m) result(n)
    type(model_t), intent(in) :: m
    integer(8) :: k0, k1
    call section_range(m, k0, k1)
    n = int(max(k1 - k0 + 1, 0_8))
  end function section_count

  !> The section times: the instants at which the shaft (or the tooth pass) angle omega t is a
  !> whole number of turns. The shaft turns at the constant speed omega (Eqs. 8-9), so the
  !> section condition omega t = 2 pi k has these roots in closed form.
  pure subroutine section_times(m, ts)
    type(model_t), intent(in) :: m
    real(wp), intent(out) :: ts(:)
    integer(8) :: k0, k1, k
    call section_range(m, k0, k1)
    do k = k0, k1
      ts(k - k0 + 1) = min(k*section_period(m), m%t_end)
    end do
  end subroutine section_times

end module spline_sections
