!> Accuracy as an input (docs/accuracy.md): the solver settings a case's `accuracy` or
!> `goal = 'statistics'` picks (accuracy_settings, by the rule table `rules`, learnt from
!> work-precision measurements of the shipped scenes), and the comparison of a run's tooth forces
!> with a tighter run's that gives its error estimate (force_error; spline_run::run_case runs it).
module spline_accuracy
  use spline_kinds, only: wp
  use spline_case_type, only: case_t, option_index, start_values, goal_values, &
       lyapunov_method_values
  implicit none
  private
  public :: rule_t, rules, accuracy_settings, scene_rule, force_error
  public :: stats_rtol, stats_transient_rtol, check_factor, parted, max_tighten

  !> A row of the rule: the scene it applies to, the integrator (position in method_values:
  !> 1 bdf, 2 adams, 3 erk), root finding, rtol = factor x accuracy and atol = atol_ratio x rtol
  !> (on the scaled states of Eq. 25); the error estimate's tighter run at rtol and atol / check.
  !> The factor keeps the measured force error below the
  !> accuracy: the largest error / rtol over rtol 1e-4 .. 1e-8 was 6.8 (ERK with atol = rtol,
  !> the paper's scenes; 17-64 at 1e-9 .. 1e-10 with the flash temperature), 1.2e4 (ERK with
  !> atol = rtol, physical_z24 from rest), 1.4 (Adams, physical_tilt), 1e5 (Adams with roots on an impacting
  !> scene), and BDF from the static equilibrium stays within 1e-6 from rtol 1e-4. ERK with roots
  !> at atol = rtol errs in proportion to rtol (those ratios within 2x over 3-4 decades), so a
  !> tighter run at rtol / 3 errs a third as much: the estimate read 0.59-0.97 of the error on
  !> the shipped scenes; the others' errors are not proportional (Adams' 0.05-18 x rtol on the
  !> paper's scenes) and their tighter run is at rtol / check_factor.
  type :: rule_t
    character(len=48) :: scene
    integer :: method
    logical :: roots
    real(wp) :: factor, atol_ratio, check
  end type rule_t
  type(rule_t), parameter :: rules(5) = [ &
       rule_t('given k_m (the calibrated soft mesh)', 3, .true., 0.05_wp, 1.0_wp, 3.0_wp), &
       rule_t('computed k_m, from rest (impacts)', 3, .true., 3.0e-5_wp, 1.0_wp, 3.0_wp), &
       rule_t('computed k_m, from rest, Lyapunov copy', 2, .true., 1.0e-5_wp, 1.0e-2_wp, 10.0_wp), &
       rule_t('computed k_m, from equilibrium, one slice', 1, .true., 0.1_wp, 1.0e-2_wp, 10.0_wp), &
       rule_t('computed k_m, from equilibrium, sliced face', 2, .true., 0.1_wp, 1.0e-2_wp, 10.0_wp)]
  !> goal = 'statistics': ERK without roots at rtol 1e-2 (atol 1e-4) reads chaos_z24's
  !> statistics within about 1 % (under a run's standard error; docs/accuracy.md); CVODE with roots at such rtol reads them low.
  real(wp), parameter :: stats_rtol = 1.0e-2_wp
  !> ... and its transient (no outputs) at rtol 3e-2 (atol 3e-4): 21 % fewer right-hand sides
  !> there, and it still ends on the attractor the window samples (over 20 chaos_z24
  !> realisations no window opens in a burst, the statistics as after a transient at 1e-2).
  !> At rtol 1e-1 it ran other dynamics, bursts of |T_m| to 146 N m that no accurate run shows,
  !> and 6 of 20 chaos_z24 windows opened in one (docs/accuracy.md)
  real(wp), parameter :: stats_transient_rtol = 3.0e-2_wp
  !> the error estimate's tighter run: rtol and atol / check_factor (but a rule's check), and a
  !> run whose estimate misses its accuracy runs again at rtol and atol / check_factor
  real(wp), parameter :: check_factor = 10.0_wp
  !> a force difference (relative to the largest force) from which two runs' trajectories have
  !> parted: beyond it they are not compared (chaos, or impacts the looser run misses)
  real(wp), parameter :: parted = 0.1_wp
  !> tightenings by check_factor a run with an accuracy target takes when its estimate misses
  integer, parameter :: max_tighten = 2

contains

  !> The row of `rules` that applies to a case.
  pure integer function scene_rule(c) result(i)
    type(case_t), intent(in) :: c
    if (c%k_m /= 0.0_wp) then
      i = 1
    else if (option_index(start_values, c%start) == 2) then
      i = 2
      if (c%lyapunov .and. option_index(lyapunov_method_values, c%lyapunov_method) == 1) i = 3
    else if (c%n_slices == 1) then
      i = 4
    else
      i = 5
    end if
  end function scene_rule

  !> The solver settings of a case: method (position in method_values), roots, rtol, atol come
  !> in as the case gives them (method resolved from 'auto') and leave as its accuracy or goal
  !> picks them; unchanged with accuracy = 0 and goal = 'trajectory'. rtol_transient: the
  !> transient's rtol (atol 1e-2 of it) where it differs from the window's, else 0. check: the
  !> divisor of the error estimate's tighter run (the rule's, else check_factor).
  pure subroutine accuracy_settings(c, method, roots, rtol, atol, rtol_transient, check)
    type(case_t), intent(in) :: c
    integer, intent(inout) :: method
    logical, intent(inout) :: roots
    real(wp), intent(inout) :: rtol, atol
    real(wp), intent(out) :: rtol_transient, check
    integer :: i
    rtol_transient = 0.0_wp
    check = check_factor
    if (option_index(goal_values, c%goal) == 2) then
      method = 3; roots = .false.; rtol = stats_rtol; atol = 1.0e-2_wp*stats_rtol
      rtol_transient = stats_transient_rtol
    else if (c%accuracy > 0.0_wp) then
      i = scene_rule(c)
      method = rules(i)%method; roots = rules(i)%roots
      rtol = max(1.0e-13_wp, rules(i)%factor*c%accuracy); atol = rules(i)%atol_ratio*rtol
      check = rules(i)%check
    end if
  end subroutine accuracy_settings

  !> The relative difference of the tooth forces fa (a run) and fb (a tighter run of the same
  !> outputs, n of them compared) over the outputs before their trajectories part (a difference
  !> of `parted` of the largest force): err = max |fa - fb| / max |fb| there, k_last the last output
  !> compared (0: none; they parted at the first), and whether they parted.
  pure subroutine force_error(n, fa, fb, err, k_last, part)
    integer, intent(in) :: n
    real(wp), intent(in) :: fa(:, :), fb(:, :)
    real(wp), intent(out) :: err
    integer, intent(out) :: k_last
    logical, intent(out) :: part
    real(wp) :: scale, d
    integer :: k
    scale = max(maxval(abs(fb(1:n, :))), tiny(1.0_wp))
    err = 0.0_wp; k_last = n; part = .false.
    do k = 1, n
      d = maxval(abs(fa(k, :) - fb(k, :)))/scale
      if (d > parted) then
        k_last = k - 1; part = .true.
        return
      end if
      err = max(err, d)
    end do
  end subroutine force_error

end module spline_accuracy
