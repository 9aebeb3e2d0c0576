!> realisations = K (docs/accuracy.md, goal = 'statistics'): after the transient, K copies of the
!> drive run over 1/K of the sampling window each, copy k from the state at the transient's end
!> with each component multiplied by 1 + d0 u_ki (copy 1 unperturbed; u_ki in [-1, 1) from a hash
!> of k and i: the same bits on every machine and thread). Their statistics are combined, with
!> standard errors from the spread between the copies. The executable runs the copies on OpenMP
!> threads, Python on its executor: both run copy k as spline_run::run_case(copy_model(m), ...,
!> y_start = copy_start(k, transient_state)), combine the statistics with combined_stats and
!> give the copies' outputs, one after another, to spline_run::run_results (its loads:
!> spline_loads::combined_loads).
module spline_realisations
  use spline_kinds, only: wp
  use spline_errors, only: err_ok
  use spline_model, only: model_t, nstate
  use spline_run, only: run_case
  use spline_dynamics, only: start_state
  use spline_sections, only: section_count
  use spline_quantities, only: nstats, ntooth_q, nsolver_stats, ist_core_wall, ist_last_step, &
       ist_coupling_residual, ist_coupling_iterations, ist_linear_tail_t
  implicit none
  private
  public :: copy_model, run_sections, transient_state, copy_start, combined_stats
  public :: realisation_d0

  !> the relative perturbation of a copy's start state: tiny against the state, yet a chaotic
  !> drive's copies part within tens of milliseconds (chaos_z24: exponent about 1000 1/s)
  real(wp), parameter :: realisation_d0 = 1.0e-6_wp

contains

  !> A copy of m: from t0 + t_transient (no transient) over its window (m%n_out outputs).
  pure function copy_model(m) result(mk)
    type(model_t), intent(in) :: m
    type(model_t) :: mk
    mk = m
    mk%t0 = m%t0 + m%t_transient; mk%t_transient = 0.0_wp
  end function copy_model

  !> The Poincare section points of one run of m (of one copy with realisations > 1, which
  !> leaves out a section instant at the transient's end, where its run starts).
  pure integer function run_sections(m) result(n)
    type(model_t), intent(in) :: m
    if (m%realisations > 1) then
      n = section_count(copy_model(m))
    else
      n = section_count(m)
    end if
  end function run_sections

  !> The state at the end of m's transient, t0 + t_transient (the start state if there is none).
  subroutine transient_state(m, ya, ierr, errmsg, interruptible)
    type(model_t), intent(in) :: m
    real(wp), intent(out) :: ya(nstate)
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    logical, intent(in), optional :: interruptible
    type(model_t) :: mt
    real(wp) :: t(1), y(nstate, 1), tooth(1, m%z, ntooth_q), tm(1), st(nstats)
    mt = m
    mt%n_out = 1; mt%t_end = m%t0 + m%t_transient; mt%t_transient = 0.0_wp
    mt%section = 0; mt%realisations = 1
    if (m%rtol_transient > 0.0_wp) then          ! the transient's own tolerances
      mt%rtol = m%rtol_transient; mt%atol = 1.0e-2_wp*m%rtol_transient; mt%rtol_transient = 0.0_wp
    end if
    if (m%t_transient > 0.0_wp) then
      call run_case(mt, t, y, tooth, tm, st, ierr, errmsg, interruptible)
      ya = y(:, 1)
    else
      call start_state(m, ya, ierr, errmsg)
    end if
  end subroutine transient_state

  !> Copy k's start state: ya with component i multiplied by 1 + realisation_d0 u_ki (k > 1).
  pure function copy_start(k, ya) result(y0)
    integer, intent(in) :: k
    real(wp), intent(in) :: ya(nstate)
    real(wp) :: y0(nstate)
    integer :: i
    integer(8) :: h
    y0 = ya
    if (k <= 1) return
    do i = 1, nstate
      h = int(k, 8)*1000003_8 + int(i, 8)*7919_8
      h = modulo(h*2654435761_8, 4294967296_8)         ! Knuth's multiplicative hash, 32 bits
      y0(i) = ya(i)*(1.0_wp + realisation_d0*(real(h, wp)/2147483648.0_wp - 1.0_wp))
    end do
  end function copy_start

  !> The statistics of K runs (stats(:, k), K = size(stats, 2)): the counters and core time
  !> summed, the rest copy 1's.
  pure subroutine combined_stats(stats, st)
    real(wp), intent(in) :: stats(:, :)
    real(wp), intent(out) :: st(nstats)
    integer :: i
    st = stats(:, 1)
    do i = 1, nsolver_stats
      if (any(i == [ist_last_step, ist_coupling_residual, ist_coupling_iterations, &
           ist_linear_tail_t])) cycle
      st(i) = sum(stats(i, :))
    end do
    st(ist_core_wall) = sum(stats(ist_core_wall, :))
  end subroutine combined_stats

end module spline_realisations
