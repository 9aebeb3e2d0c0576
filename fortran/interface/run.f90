!> One simulation of a case, shared by the executable and the Python API: the model level to run
!> (fidelity = 'auto': spline_fidelity), output times, start state (static equilibrium by
!> default), integration (with the Poincare section of spline_sections and the Lyapunov exponent
!> of spline_lyapunov when the case asks), the per-tooth quantities (Eqs. 11, 15-22 and, for the
!> thermal levels that have it, Eqs. 1-7) at every output time, and the checks of the result.
module spline_run
  use spline_kinds, only: wp, pi
  use spline_errors, only: err_ok, err_solver, itoa, ftoa, num
  use spline_model, only: model_t, nstate, ndof, thermal_oneway, thermal_coupled, set_thermal_level
  use spline_dynamics, only: start_state
  use spline_mesh, only: mesh_eval, mesh_outputs
  use spline_solver, only: integrate
  use spline_quantities, only: nsolver_stats, nstats, ntooth_q, iq_tf, tooth_q, state_q, &
       ist_core_wall, ist_dof, ist_thermal_level, ist_eps_lateral, ist_eps_thermal, ist_closed, &
       ist_closed_t, ist_roots_found, ist_f_error, ist_f_error_t, ist_f_parted_t, ist_rtol_used, &
       ist_outputs_fallback, ist_linear_tail_t, nload, nload_tooth, nextreme
  use spline_accuracy, only: force_error, check_factor, max_tighten
  use spline_fidelity, only: auto_level, auto_tol, backlash_estimate
  use spline_sections, only: section_count, section_times
  use spline_lyapunov, only: lyapunov_benettin, lyapunov_tangent
  use spline_integrator, only: lib_log_t
  use spline_integrator_report, only: integrator_warnings
  use spline_loads, only: combined_loads, run_extremes, stress_warnings
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: run_case, run_results, output_times, tooth_outputs, tooth_quantities, run_warnings

  !> rtol above which CVODE's located contact switches are warned (run_warnings)
  real(wp), parameter :: restart_rtol = 1.0e-3_wp
  !> outputs per tooth-passing period 60/(Z n) below which the peaks are warned (output_warning)
  real(wp), parameter :: outputs_per_mesh = 2.0_wp

contains

  !> Uniform output times on [t0 + t_transient, t_end] (one time: t_end).
  pure subroutine output_times(m, t)
    type(model_t), intent(in) :: m
    real(wp), intent(out) :: t(m%n_out)
    integer :: k
    real(wp) :: ta
    ta = m%t0 + m%t_transient
    if (m%n_out == 1) then
      t(1) = m%t_end
    else
      t = [(ta + (m%t_end - ta)*(k - 1)/real(m%n_out - 1, wp), k = 1, m%n_out)]
      t(m%n_out) = m%t_end
    end if
  end subroutine output_times

  !> Run a validated case: y(:, k) is the SI state at t(k), tooth(k, j, :) the quantities of
  !> spline_quantities tooth_q for tooth j (n_out x z x ntooth_q: an array or, for a copy of
  !> realisations, its rows of the copies' array, written in place), tm(k) the meshing torque
  !> (Eq. 22).
  !> fidelity = 'auto' runs the cheapest level of the ladder within fidelity_tol (auto_level);
  !> a coupled case runs one-way first and is run again coupled if the one-way flash
  !> temperature's estimate (backlash_estimate of its largest T_f) exceeds auto_tol.
  !> interruptible: a SIGINT stops the run with err_interrupted (callers that can raise it).
  !> Optional extras, sized by the caller: sec_t(section_count(m)), sec_y(nstate, ...) get the
  !> Poincare section (times, SI states); lyap_t(lyapunov_count(m)), lyap_g(...) the Benettin
  !> renormalisation times and the cumulative log growth of the separation (lyapunov_benettin);
  !> face(n_out, z, n_slices), tilt(n_out, 2) the load along the face and the tilting moment
  !> (sliced faces: angular misalignment, tooth_outputs).
  !> nq, consts (both or neither): a run whose quantities c_j, T_f, r_c1, r_c2 (tooth_q 5..8)
  !> are the level's constants (no flash temperature, no slices) writes only tooth(:, :, 1:4),
  !> nq = 4, consts = (c_j, T_f, r_c1, r_c2); else every quantity, nq = ntooth_q, consts = 0.
  !> y_start (optional): the start state at t0 instead of start_state's (a realisation's copy).
  subroutine run_case(m, t, y, tooth, tm, stats, ierr, errmsg, interruptible, sec_t, sec_y, &
       lyap_t, lyap_g, face, tilt, nq, consts, y_start)
    type(model_t), intent(in) :: m
    real(wp), intent(out) :: t(m%n_out), y(nstate, m%n_out), tooth(:, :, :)
    real(wp), intent(out) :: tm(m%n_out), stats(nstats)
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    logical, intent(in), optional :: interruptible
    real(wp), intent(out), optional :: sec_t(:), sec_y(:, :), lyap_t(:), lyap_g(:)
    real(wp), intent(out), optional :: face(:, :, :), tilt(:, :)
    integer, intent(out), optional :: nq
    real(wp), intent(out), optional :: consts(ntooth_q - 4)
    real(wp), intent(in), optional :: y_start(nstate)
    type(model_t) :: run
    real(wp) :: eps_lat, eps_th, closed, t_closed, cq(ntooth_q - 4), est(3)
    type(lib_log_t) :: lib                   !< SUNDIALS' warnings over the call's runs
    integer(8) :: c0, c1, rate
    integer :: nw, i
    logical :: fin
    call system_clock(c0, rate)
    call auto_level(m, run, eps_lat, eps_th)
    call run_once()
    ! the error estimate (accuracy or check): a run with an accuracy target whose estimate misses
    ! it, or parts from the tighter run, runs again at rtol / check_factor, max_tighten times
    est = -1.0_wp
    do i = 0, max_tighten
      if (ierr /= err_ok .or. .not. m%estimate) exit
      call estimate_error(run, t, tooth(:, :, 1), stats(ist_linear_tail_t), est, ierr, errmsg, &
           interruptible)
      if (ierr /= err_ok .or. m%accuracy == 0.0_wp .or. i == max_tighten .or. &
           (est(1) <= m%accuracy .and. est(3) < 0.0_wp)) exit
      run%rtol = run%rtol/check_factor; run%atol = run%atol/check_factor
      call run_once()
    end do
    if (present(nq)) then
      nq = nw; consts = cq
    end if
    if (present(lyap_t)) then
      lyap_t = 0.0_wp; lyap_g = 0.0_wp
      if (ierr == err_ok .and. m%lyapunov .and. m%lyap_tangent) then
        call lyapunov_tangent(run, t(1), y(:, 1), lyap_t, lyap_g, ierr, errmsg, interruptible, &
             lib)
      else if (ierr == err_ok .and. m%lyapunov) then
        call lyapunov_benettin(run, t(1), y(:, 1), lyap_t, lyap_g, ierr, errmsg, interruptible, &
             lib)
      end if
    end if
    closed = 0.0_wp; t_closed = 0.0_wp
    if (ierr == err_ok) call result_checks(run, t, y, tooth(:, :, 1:nw), tm, closed, t_closed, &
         ierr, errmsg, sec_t, sec_y, lyap_t, lyap_g, fin)
    if (ierr == err_ok) call integrator_warnings(lib, m%name, errmsg)
    call system_clock(c1)
    stats(ist_core_wall) = real(c1 - c0, wp)/rate
    stats(ist_dof) = real(run%dof, wp)
    stats(ist_thermal_level) = real(run%thermal, wp)
    stats(ist_eps_lateral) = eps_lat
    stats(ist_eps_thermal) = eps_th
    stats(ist_closed) = closed
    stats(ist_closed_t) = t_closed
    stats(ist_f_error:ist_f_parted_t) = est
    stats(ist_rtol_used) = run%rtol
  contains
    !> The run at run's level (a coupled case with fidelity = 'auto': one-way first, coupled if
    !> its flash temperature's estimate exceeds auto_tol).
    subroutine run_once()
    call run_level(run, t, y, tooth, tm, stats, ierr, errmsg, interruptible, sec_t, sec_y, &
         face, tilt, present(nq), nw, cq, fin, lib, y_start)
    if (ierr == err_ok .and. m%auto .and. m%thermal == thermal_coupled .and. nw >= iq_tf) then
      eps_th = backlash_estimate(m, maxval(abs(tooth(:, :, iq_tf))))
      if (eps_th > auto_tol(m)) then
        call set_thermal_level(run, thermal_coupled)
        call run_level(run, t, y, tooth, tm, stats, ierr, errmsg, interruptible, sec_t, sec_y, &
             face, tilt, present(nq), nw, cq, fin, lib, y_start)
      end if
    end if
    end subroutine run_once
  end subroutine run_case

  !> What follows from a finished run's outputs (t, y, tooth, tm, stats as run_case gives them;
  !> tooth(:, :, 1:nq): every quantity of tooth_q, or F, F_x, F_y, dn alone with the constants
  !> consts = (c_j, T_f, r_c1, r_c2), run_case's nq and consts): the loads (spline_loads::
  !> combined_loads, run_loads for one run: loads, tload(z, nload_tooth)), the extremes and RMS
  !> (run_extremes: ext) and the run's warnings, one per line ('' if none: run_warnings, then
  !> stress_warnings). The executable and Python (api_simulate, in the same call as the run)
  !> alike. realisations = K > 1: the K copies' outputs one after another and their combined
  !> statistics (spline_realisations::combined_stats; Python: api_results); the extremes and
  !> RMS are those of all the copies' outputs together.
  subroutine run_results(m, t, y, tooth, tm, stats, consts, loads, tload, ext, warnings)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t(:), y(:, :), tm(:), stats(nstats), consts(ntooth_q - 4)
    real(wp), intent(in), contiguous :: tooth(:, :, :)
    real(wp), intent(out) :: loads(nload), tload(m%z, nload_tooth), ext(nextreme)
    character(len=:), allocatable, intent(out) :: warnings
    call combined_loads(m, t, y, tooth, tm, loads, tload)
    if (size(tooth, 3) >= iq_tf) then
      call run_extremes(m, y, tm, tooth(:, :, 1), ext, tf=tooth(:, :, iq_tf))
    else                               ! T_f a constant of the level
      call run_extremes(m, y, tm, tooth(:, :, 1), ext, tf_const=consts(iq_tf - 4))
    end if
    warnings = ''
    call run_warnings(m, stats, warnings)
    call output_warning(m, t, warnings)
    call stress_warnings(m, loads, warnings)
  end subroutine run_results

  !> The peak loads (load sharing, tooth forces, root stresses: spline_loads) are taken at the
  !> output times t: fewer than outputs_per_mesh outputs per tooth-passing period 60/(Z n) read
  !> them low. A Z = 20 case (tests/test_warnings.py) read its load sharing 14 % low at 0.025
  !> outputs per period, 3.4 % at 0.1, 0.5 % at 1, 0.1 % at 2 and converged from 3 on.
  subroutine output_warning(m, t, text)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t(:)
    character(len=:), allocatable, intent(inout) :: text
    real(wp) :: period, per
    if (m%n_out < 2 .or. m%omega <= 0.0_wp) return
    period = 2.0_wp*pi/(m%z*m%omega)
    per = period/(t(2) - t(1))
    if (per >= outputs_per_mesh) return
    text = text//'case '//trim(m%name)//': '//num(per, readable=.true.)//' outputs per '// &
         'tooth-passing period 60/(Z n) = '//num(period, readable=.true.)//' s (limit '// &
         itoa(nint(outputs_per_mesh))//'): the peak loads (load sharing, tooth forces, root '// &
         'stresses) are taken at the outputs and read low between them; outputs_per_revolution'// &
         ' >= '//itoa(nint(outputs_per_mesh)*m%z)//'? Run as given'//new_line('a')
  end subroutine output_warning

  !> The error estimate of a run of m with tooth forces f at the outputs t (docs/accuracy.md):
  !> m at rtol and atol / m%check_div over the outputs up to the first at or after the time the
  !> run's linear tail began (tail_t; beyond it the closed form carries the error it started from:
  !> with root finding the tail begins at an output, the last one integrated), its forces
  !> compared by spline_accuracy's force_error. est = (F_error_est, F_error_t_s, F_parted_t_s) of
  !> spline_quantities (-1: none).
  subroutine estimate_error(m, t, f, tail_t, est, ierr, errmsg, interruptible)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t(:), f(:, :), tail_t
    real(wp), intent(out) :: est(3)
    integer, intent(out) :: ierr
    character(len=*), intent(inout) :: errmsg
    logical, intent(in), optional :: interruptible
    type(model_t) :: b
    real(wp), allocatable :: tb(:), yb(:, :), fb(:, :, :), tmb(:)
    real(wp) :: stb(nstats), cq(ntooth_q - 4)
    integer :: n, k, nw
    logical :: fin, part
    n = size(t)
    if (tail_t > t(1)) n = min(n, count(t < tail_t) + 1)
    b = m
    b%rtol = m%rtol/m%check_div; b%atol = m%atol/m%check_div
    b%lyapunov = .false.; b%t_end = t(n); b%n_out = n
    ! no tail of its own where it ends at the output where the run's tail began: its tries (the
    ! flank's eigenpairs, a bound at every output) cost 6-11 % of it on paper_lx1e-4
    b%linear_tail = m%linear_tail .and. tail_t <= t(1)
    allocate(tb(n), yb(nstate, n), fb(n, m%z, ntooth_q), tmb(n))
    call run_level(b, tb, yb, fb, tmb, stb, ierr, errmsg, interruptible, lazy=.true., nw=nw, &
         consts=cq, fin=fin)
    est = -1.0_wp
    if (ierr /= err_ok) then
      errmsg = 'the error estimate''s tighter run: '//errmsg; return
    end if
    call force_error(n, f(1:n, :), fb(:, :, 1), est(1), k, part)
    if (k > 0) est(2) = t(k)
    if (k == 0) est(1) = -1.0_wp
    if (part) est(3) = t(k + 1)
  end subroutine estimate_error

  !> The checks of a finished run: no output may be NaN or infinite (ierr = err_solver with a
  !> message naming the quantity, the tooth or state, and the time: the model left its range,
  !> e.g. a runaway state; the contact radii stay on the active profile, so T_f stays finite);
  !> and at the one-way thermal level, the samples where Eq. 2 with the flash temperature,
  !> c0 - kappa (T_M + T_f), is not positive: the coupled level would have stopped there with
  !> thermal interference (closed: their number, t_closed: the first time; a warning, see
  !> run_warnings). tooth_finite (optional): every value of tooth is known to be finite.
  subroutine result_checks(m, t, y, tooth, tm, closed, t_closed, ierr, errmsg, sec_t, sec_y, &
       lyap_t, lyap_g, tooth_finite)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t(:), y(:, :), tooth(:, :, :), tm(:)
    real(wp), intent(out) :: closed, t_closed
    integer, intent(inout) :: ierr
    character(len=*), intent(inout) :: errmsg
    real(wp), intent(in), optional :: sec_t(:), sec_y(:, :), lyap_t(:), lyap_g(:)
    logical, intent(in), optional :: tooth_finite
    integer :: k, j, q, i, k1
    logical :: known
    closed = 0.0_wp; t_closed = 0.0_wp
    known = .false.
    if (present(tooth_finite)) known = tooth_finite
    ! one contiguous pass over each array (tooth not again where the pass that wrote it found
    ! every value finite: tooth_finite; a copy's rows of a larger array are packed for it only
    ! then); the output-by-output search only to name a failure
    if (.not. known) known = all_finite(size(tooth), tooth)
    if (all_finite(size(t), t) .and. all_finite(size(y), y) .and. all_finite(size(tm), tm) .and. &
         known) then
      k1 = size(t) + 1
    else
      k1 = 1
    end if
    do k = k1, size(t)
      if (.not. ieee_is_finite(t(k))) call bad('the output time', '', k)
      do i = 1, nstate
        if (.not. ieee_is_finite(y(i, k))) call bad('the state '//trim(state_q(i)%name), '', k)
      end do
      if (.not. ieee_is_finite(tm(k))) call bad('the meshing torque T_m', '', k)
      do q = 1, size(tooth, 3)
        do j = 1, size(tooth, 2)
          if (.not. ieee_is_finite(tooth(k, j, q))) call bad(trim(tooth_q(q)%name)//' of tooth', &
               ' '//itoa(j), k)
        end do
      end do
      if (ierr /= err_ok) return
    end do
    if (present(sec_t)) then
      do k = 1, size(sec_t)
        if (.not. ieee_is_finite(sec_t(k)) .or. .not. all(ieee_is_finite(sec_y(:, k)))) then
          call bad('a Poincare section point', '', 0, sec_t(k)); return
        end if
      end do
    end if
    if (present(lyap_t)) then
      do k = 1, size(lyap_t)
        if (.not. ieee_is_finite(lyap_t(k)) .or. .not. ieee_is_finite(lyap_g(k))) then
          call bad('the Lyapunov growth', '', 0, lyap_t(k)); return
        end if
      end do
    end if
    if (m%thermal == thermal_oneway) then
      i = size(t) + 1      ! the first output where a tooth closes it
      do j = 1, size(tooth, 2)
        do k = 1, size(t)
          if (m%c_bulk - m%kappa*tooth(k, j, iq_tf) <= 0.0_wp) then
            i = min(i, k)
            closed = closed + 1.0_wp
          end if
        end do
      end do
      if (closed > 0.0_wp) t_closed = t(i)
    end if
  contains
    subroutine bad(what, which, k, tk)
      character(len=*), intent(in) :: what, which
      integer, intent(in) :: k
      real(wp), intent(in), optional :: tk
      real(wp) :: tt
      if (ierr /= err_ok) return
      tt = 0.0_wp
      if (k > 0) tt = t(k)
      if (present(tk)) tt = tk
      ierr = err_solver
      errmsg = 'case '//trim(m%name)//': the run produced a non-finite value (NaN or Inf): '// &
           what//which//' at t = '//ftoa(tt, '(es12.5)')//' s; the model left its range there '// &
           '(e.g. a runaway state)'
    end subroutine bad
  end subroutine result_checks

  !> Whether every element of x(n) is finite, in one branch-free pass the compiler vectorises:
  !> x*0 is 0 for a finite x and NaN for an infinite or NaN one (no early exit: it is rare).
  pure logical function all_finite(n, x)
    integer, intent(in) :: n
    real(wp), intent(in) :: x(n)
    real(wp) :: acc(8)
    integer :: i, i1
    acc = 0.0_wp
    i1 = n - mod(n, 8)
    do i = 1, i1, 8
      acc = acc + x(i:i+7)*0.0_wp
    end do
    do i = i1 + 1, n
      acc(1) = acc(1) + x(i)*0.0_wp
    end do
    all_finite = all(acc == 0.0_wp)
  end function all_finite

  !> Warnings about a finished run, one per line ('' if none), from its statistics: the
  !> one-way flash temperature that would have closed the backlash (result_checks); contact
  !> switches located for CVODE at an rtol above restart_rtol (restart_warning). The
  !> executable prints them to stderr, Python raises pyspline.SplineWarning (run_results).
  !> Appended to text, as every warning of the core (docs/developing.md, "Thread safety").
  subroutine run_warnings(m, stats, text)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: stats(nstats)
    character(len=:), allocatable, intent(inout) :: text
    call restart_warning(m, stats, text)
    call accuracy_warning(m, stats, text)
    if (stats(ist_closed) > 0.0_wp) then
      text = text//'case '//trim(m%name)//': the one-way flash temperature closes the backlash '// &
           '(Eq. 2: c0 - kappa (T_M + T_f) <= 0) in '//itoa(nint(stats(ist_closed)))//' tooth '// &
           'samples, first at t = '//ftoa(stats(ist_closed_t), '(es12.5)')//' s: the one-way '// &
           'result is not physical there (thermal = ''coupled'' stops at the interference)'// &
           new_line('a')
    end if
  end subroutine run_warnings

  !> The warnings of accuracy and goal (docs/accuracy.md): a Lyapunov exponent asked with
  !> goal = 'statistics' (its settings bias it); an estimate above the case's accuracy (after
  !> max_tighten tightenings); a tighter run that parts from the run (chaos, or impacts the run
  !> misses: its trajectory beyond is not resolved at these settings).
  subroutine accuracy_warning(m, stats, text)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: stats(nstats)
    character(len=:), allocatable, intent(inout) :: text
    if (m%goal_statistics .and. m%lyapunov) text = text//'case '//trim(m%name)//': goal = '// &
         '''statistics'' with lyapunov = .true.: the exponent is not one of the statistics its '// &
         'settings keep (chaos_z24 read 1152 against 965 1/s, docs/accuracy.md); goal = '// &
         '''trajectory'' for the exponent?'//new_line('a')
    if (.not. m%estimate) return
    if (m%accuracy > 0.0_wp .and. stats(ist_f_error) > m%accuracy) text = text//'case '// &
         trim(m%name)//': the estimated error of the tooth forces F_error_est = '// &
         num(stats(ist_f_error))//' exceeds accuracy = '//num(m%accuracy)//' at rtol '// &
         num(stats(ist_rtol_used))//' (tightened '//itoa(max_tighten)//' times)'//new_line('a')
    if (stats(ist_f_parted_t) >= 0.0_wp) text = text//'case '//trim(m%name)//': a run at rtol '// &
         num(stats(ist_rtol_used)/m%check_div)//' parts from this one at t = '// &
         num(stats(ist_f_parted_t))//' s (the tooth forces differ by over a tenth of the '// &
         'largest): beyond it the trajectory is not predictable at these settings (chaos? read '// &
         'its statistics: goal = ''statistics''); F_error_est covers the outputs before'// &
         new_line('a')
  end subroutine accuracy_warning

  !> CVODE (method adams or bdf) restarts at order 1 after every contact switch it locates
  !> (spline_integrator::integrator_restart). Above restart_rtol that falsified a rattling drive: chaos_z24
  !> with Adams or BDF and roots read its T_m RMS 2.3-2.7 N m against 3.5-3.8 (every method at
  !> rtol <= 1e-3, ERK with roots and every method without roots from 1e-2), finding 2-3 times
  !> the reference's switches (docs/running.md, "Multistep restarts at loose tolerance";
  !> tests/test_solver.py). Warned after a run that located a switch there.
  subroutine restart_warning(m, stats, text)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: stats(nstats)
    character(len=:), allocatable, intent(inout) :: text
    if (m%erk .or. .not. m%roots .or. m%rtol <= restart_rtol .or. stats(ist_roots_found) < 1) &
         return
    text = text//'case '//trim(m%name)//': rtol = '//ftoa(m%rtol, '(es10.3)')//' with method = '''// &
         trim(merge('bdf  ', 'adams', m%method_bdf == 1))//''' and '// &
         itoa(nint(stats(ist_roots_found)))//' contact switches located: CVODE restarts at '// &
         'order 1 after each, and above rtol 1e-3 that can falsify the impacts (chaos_z24 '// &
         'read its T_m RMS a third low at rtol 1e-2, atol 1e-4, with 2-3 times the switches); '// &
         'rtol <= 1e-3 or method = ''erk''?'//new_line('a')
  end subroutine restart_warning

  !> One run of the model at the level m sets (lazy, nw, consts: run_case's nq, consts; fin:
  !> tooth_outputs' finite; y_start: run_case's).
  subroutine run_level(m, t, y, tooth, tm, stats, ierr, errmsg, interruptible, sec_t, sec_y, &
       face, tilt, lazy, nw, consts, fin, lib, y_start)
    type(model_t), intent(in) :: m
    real(wp), intent(out) :: t(m%n_out), y(nstate, m%n_out), tooth(:, :, :)
    real(wp), intent(out) :: tm(m%n_out), stats(nstats)
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    logical, intent(in), optional :: interruptible
    real(wp), intent(out), optional :: sec_t(:), sec_y(:, :), face(:, :, :), tilt(:, :)
    logical, intent(in) :: lazy
    integer, intent(out) :: nw
    real(wp), intent(out) :: consts(ntooth_q - 4)
    logical, intent(out) :: fin
    type(lib_log_t), intent(inout), optional :: lib   !< SUNDIALS' warnings, counted on
    real(wp), intent(in), optional :: y_start(nstate)
    real(wp) :: y0(nstate)
    real(wp), allocatable :: ts(:), ysec(:, :)
    integer, allocatable :: modes(:, :)
    logical :: fallback
    errmsg = ''
    stats = 0.0_wp
    nw = ntooth_q; consts = 0.0_wp; fin = .false.
    allocate(modes(m%z*m%n_slices, m%n_out))
    call output_times(m, t)
    if (present(y_start)) then
      y0 = y_start; ierr = err_ok
    else
      call start_state(m, y0, ierr, errmsg)
    end if
    if (ierr == err_ok) then
      call integrate_level()           ! y: zero where it did not reach
    else
      y = 0.0_wp
    end if
    ! tooth and tm are zero where the run did not reach (every output is written otherwise)
    if (ierr /= err_ok) then
      tooth = 0.0_wp; tm = 0.0_wp
      return
    end if
    call tooth_outputs(m, t, y, modes, tooth, tm, ierr, errmsg, face, tilt, lazy, nw, consts, fin, &
         fallback)
    stats(ist_outputs_fallback) = merge(1.0_wp, 0.0_wp, fallback)
    if (ierr /= err_ok) then
      tooth = 0.0_wp; tm = 0.0_wp; nw = ntooth_q; consts = 0.0_wp; fin = .false.
    end if
  contains
    subroutine integrate_level()
    ! A section does not stop CVODE, but with root finding the first step after each restart
    ! depends on the next requested time, which may be a section time (spline_solver::integrate):
    ! a run that asks for a section takes its times whether or not the caller keeps the points
    ! (same numbers everywhere).
    if (present(sec_t)) then
      call section_times(m, sec_t)
      call integrate(m, y0, m%n_out, t, y, modes, stats(1:nsolver_stats), ierr, errmsg, &
           interruptible, sec_t, sec_y, msgs=lib)
    else
      allocate(ts(section_count(m)), ysec(nstate, section_count(m)))
      call section_times(m, ts)
      call integrate(m, y0, m%n_out, t, y, modes, stats(1:nsolver_stats), ierr, errmsg, &
           interruptible, ts, ysec, msgs=lib)
    end if
    end subroutine integrate_level
  end subroutine run_level

  !> Per-tooth quantities at the output times, with the contact states the integration used
  !> (2: decided by the state).
  !> face(k, j, s), tilt(k, :) (optional): the load of slice s of tooth j along the face and the
  !> tilting moment (M_x, M_y) on spline 1 (mesh_eval), for sliced faces.
  !> Without flash temperature or slices, bulk_tooth_outputs forms them in one pass per tooth; it
  !> must agree with tooth_quantities (mesh_eval, the definition) to the bit at the first and the
  !> last output, else (a change to one and not the other) every output is formed by mesh_eval.
  !> lazy (optional): there, c_j, T_f, r_c1, r_c2 are not written but returned once in consts
  !> (nw = 4 quantities written; else nw = ntooth_q, consts = 0). finite (optional): there, whether
  !> every value written to tooth is finite (mesh_outputs' finite); else .false. (not known).
  !> fallback (optional): whether mesh_outputs' outputs were replaced by mesh_eval's (a drift;
  !> the run's outputs_fallback).
  subroutine tooth_outputs(m, t, y, modes, tooth, tm, ierr, errmsg, face, tilt, lazy, nw, consts, &
       finite, fallback)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t(:), y(:, :)
    integer, intent(in) :: modes(:, :)
    real(wp), intent(out) :: tooth(:, :, :), tm(:)
    integer, intent(out) :: ierr
    character(len=*), intent(inout) :: errmsg
    real(wp), intent(out), optional :: face(:, :, :), tilt(:, :)
    logical, intent(in), optional :: lazy
    integer, intent(out), optional :: nw
    real(wp), intent(out), optional :: consts(ntooth_q - 4)
    logical, intent(out), optional :: finite, fallback
    real(wp) :: row(m%z, ntooth_q), fs(m%n_slices, m%z), mt(2), cq(ntooth_q - 4)
    integer :: k, nq
    logical :: lz, fin
    ierr = err_ok
    if (present(finite)) finite = .false.
    if (present(fallback)) fallback = .false.
    lz = .false.
    if (present(lazy)) lz = lazy
    nq = ntooth_q
    cq = 0.0_wp
    if (.not. present(face) .and. m%n_slices == 1 .and. m%thermal < thermal_oneway) then
      cq = [m%c_bulk, 0.0_wp, m%r_pitch, m%r_pitch]     ! c_j, T_f, r_c1, r_c2
      if (lz) nq = 4
      call bulk_tooth_outputs(m, t, y, modes, tooth, tm, cq, .not. lz, fin)
      if (same_as_mesh(1) .and. same_as_mesh(size(t))) then
        if (present(nw)) then
          nw = nq; consts = cq
        end if
        if (present(finite)) finite = fin .and. all(ieee_is_finite(cq))
        return
      end if
      if (present(fallback)) fallback = .true.
    end if
    nq = ntooth_q
    if (present(nw)) then
      nw = nq; consts = 0.0_wp
    end if
    do k = 1, size(t)
      call quantities_at(k)
      if (ierr /= err_ok) return
      tooth(k, :, :) = row
      if (present(face)) face(k, :, :) = transpose(fs)
      if (present(tilt)) tilt(k, :) = mt
    end do
  contains
    !> tooth_quantities at output k into row, tm(k).
    subroutine quantities_at(k)
      integer, intent(in) :: k
      if (modes(1, k) == 2) then
        call tooth_quantities(m, t(k), y(:, k), row, tm(k), ierr, errmsg, fslice=fs, mtilt=mt)
      else
        call tooth_quantities(m, t(k), y(:, k), row, tm(k), ierr, errmsg, modes(:, k), fs, mt)
      end if
    end subroutine quantities_at
    !> Whether output k of bulk_tooth_outputs is tooth_quantities' to the bit.
    logical function same_as_mesh(k) result(same)
      integer, intent(in) :: k
      real(wp) :: tmk
      integer :: j
      same = .true.
      if (k < 1) return
      tmk = tm(k)
      call quantities_at(k)
      same = ierr == err_ok .and. all(row(:, 1:nq) == tooth(k, :, 1:nq)) .and. tm(k) == tmk
      do j = nq + 1, ntooth_q
        same = same .and. all(row(:, j) == cq(j - 4))
      end do
      ierr = err_ok
    end function same_as_mesh
  end subroutine tooth_outputs

  !> The per-tooth quantities of tooth_quantities at every output time, for a model without
  !> flash temperature (thermal none or bulk: T_f = 0, both contact radii on the pitch circle,
  !> c_j = c_bulk) or face slices: F, F_x, F_y and dn from spline_mesh's mesh_outputs (Eqs. 8-9,
  !> 11, 15-17, 19-22 as mesh_eval evaluates them), the constants cq (c_j, T_f, r_c1, r_c2)
  !> filled in if fill; finite: mesh_outputs' (every value it wrote is finite).
  subroutine bulk_tooth_outputs(m, t, y, modes, tooth, tm, cq, fill, finite)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t(:), y(:, :), cq(ntooth_q - 4)
    integer, intent(in) :: modes(:, :)
    real(wp), intent(inout) :: tooth(:, :, :)
    real(wp), intent(out) :: tm(:)
    logical, intent(in) :: fill
    logical, intent(out) :: finite
    real(wp), allocatable :: part(:, :, :)
    integer :: q
    if (fill) then
      do q = 5, ntooth_q
        tooth(:, :, q) = cq(q - 4)
      end do
    end if
    if (is_contiguous(tooth)) then
      call mesh_outputs(m, size(t), t, y, modes, tooth(:, :, 1), tooth(:, :, 2), tooth(:, :, 3), &
           tooth(:, :, 4), tm, finite)
    else                 ! a copy's rows of the copies' array (realisations): formed, then stored
      allocate(part(size(t), m%z, 4))
      call mesh_outputs(m, size(t), t, y, modes, part(:, :, 1), part(:, :, 2), part(:, :, 3), &
           part(:, :, 4), tm, finite)
      tooth(:, :, 1:4) = part
    end if
  end subroutine bulk_tooth_outputs

  !> Every per-tooth quantity (order of spline_quantities tooth_q) and the meshing torque at one state y (SI):
  !> Eqs. 11, 15-17, 19-22 and, where the thermal level has them, Eqs. 1-7 and 12-14.
  subroutine tooth_quantities(m, t, y, row, tm, ierr, errmsg, mode, fslice, mtilt)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t, y(nstate)
    real(wp), intent(out) :: row(m%z, ntooth_q), tm
    integer, intent(out) :: ierr
    character(len=*), intent(inout) :: errmsg
    integer, intent(in), optional :: mode(m%z*m%n_slices)
    real(wp), intent(out), optional :: fslice(m%n_slices, m%z), mtilt(2)
    real(wp) :: fx1, fy1, sp(m%z), cp(m%z)
    call mesh_eval(m, t, y(1:ndof), y(ndof+1:), fx1, fy1, tm, ierr, errmsg, mode=mode, &
         flash=.true., f=row(:, 1), dn=row(:, 4), c=row(:, 5), tf=row(:, 6), rc1=row(:, 7), &
         rc2=row(:, 8), sphi_out=sp, cphi_out=cp, fslice=fslice, mtilt=mtilt)
    row(:, 2) = row(:, 1)*sp     ! F_jx (Eq. 19 with phi_j)
    row(:, 3) = row(:, 1)*cp     ! F_jy
  end subroutine tooth_quantities

end module spline_run
