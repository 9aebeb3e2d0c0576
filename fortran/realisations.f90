!> realisations = K (docs/accuracy.md, goal = 'statistics'): after the transient, K copies of the
!> drive run over 1/K of the sampling window each, copy k from the state at the transient's end
!> with each component multiplied by 1 + d0 u_ki (copy 1 unperturbed; u_ki in [-1, 1) from a hash
!> of k and i: the same bits on every machine and thread). Their statistics are combined, with
!> standard errors from the spread between the copies. The executable runs the copies on OpenMP
!> threads, Python on its executor: both run copy k as spline_run::run_case(copy_model(m), ...,
!> y_start = copy_start(k, transient_state)) and combine with combined_loads, combined_stats.
module spline_realisations
  use spline_kinds, only: wp
  use spline_errors, only: err_ok
  use spline_model, only: model_t, nstate
  use spline_run, only: run_case
  use spline_dynamics, only: start_state
  use spline_sections, only: section_count
  use spline_loads, only: run_loads
  use spline_quantities, only: nstats, ntooth_q, nload, nload_tooth, nsolver_stats, &
       ist_core_wall, ist_last_step, ist_coupling_residual, ist_coupling_iterations, &
       ist_linear_tail_t, il_load_sharing, il_closing_speed, il_tf_max, il_tf_max_tooth, &
       il_tf_max_t, il_sigma_root, il_sigma_flank, il_tau_pitch, il_stress_ratio, il_free_mean, &
       il_impacts_rev, il_sharing_rev, il_tf_rev, il_revolutions, il_batches, il_load_sharing_tooth, &
       il_free_max, il_back_max, il_unloaded, il_back_teeth, il_tm_rms_se, il_kv_rms_se, &
       il_f_rms_se, il_d2_rms_se, il_sharing_rev_se, il_free_mean_se, il_impacts_rev_se, &
       il_tf_rev_se, il_free_max_se, il_back_max_se, ilt_f_peak, ilt_load_factor, ilt_free, &
       ilt_back, ilt_onsets, ilt_free_se, ilt_back_se
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  implicit none
  private
  public :: copy_model, run_sections, transient_state, copy_start, combined_loads, combined_stats
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

  !> The loads of a run's outputs (spline_loads::run_loads); with m%realisations = K > 1 the
  !> outputs are K copies' of m%n_out each, one after the other, and their loads combine: extremes
  !> the largest, means and fractions the mean, counts the sum; the standard errors are the spread
  !> between the copies, sd / sqrt(K), of the value each is about (the RMS of T_m, k_v, F_j over
  !> all teeth and D_2 from each copy's outputs; the rest from its loads).
  pure subroutine combined_loads(m, t, y, tooth, tm, loads, tload)
    type(model_t), intent(in) :: m
    real(wp), intent(in), contiguous :: t(:), tooth(:, :, :), tm(:)
    real(wp), intent(in) :: y(:, :)
    real(wp), intent(out) :: loads(nload), tload(m%z, nload_tooth)
    real(wp) :: lk(nload, m%realisations), tk(m%z, nload_tooth, m%realisations)
    real(wp) :: rms(m%realisations, 3), nan
    integer :: k, n, a, j, kmax
    n = m%n_out
    if (m%realisations == 1 .or. size(t) /= n*m%realisations) then
      call run_loads(m, t, y, tooth, tm, loads, tload); return
    end if
    nan = ieee_value(0.0_wp, ieee_quiet_nan)
    do k = 1, m%realisations
      a = (k - 1)*n
      call run_loads(m, t(a + 1:a + n), y(:, a + 1:a + n), tooth(a + 1:a + n, :, :), &
           tm(a + 1:a + n), lk(:, k), tk(:, :, k))
      rms(k, 1) = sqrt(sum(tm(a + 1:a + n)**2)/n)
      rms(k, 2) = sqrt(sum(tooth(a + 1:a + n, :, 1)**2)/(n*m%z))
      rms(k, 3) = sqrt(sum(y(6, a + 1:a + n)**2)/n)
    end do
    loads = lk(:, 1)
    tload = tk(:, :, 1)
    do j = 1, m%z                               ! per tooth
      tload(j, ilt_f_peak) = maxval(tk(j, ilt_f_peak, :))
      tload(j, ilt_load_factor) = biggest(tk(j, ilt_load_factor, :))
      tload(j, ilt_free) = sum(tk(j, ilt_free, :))/m%realisations
      tload(j, ilt_back) = sum(tk(j, ilt_back, :))/m%realisations
      tload(j, ilt_onsets) = sum(tk(j, ilt_onsets, :))
      tload(j, ilt_free_se) = spread_se(tk(j, ilt_free, :))
      tload(j, ilt_back_se) = spread_se(tk(j, ilt_back, :))
    end do
    do j = 1, nload                             ! the run's
      if (any(j == [il_load_sharing, il_closing_speed, il_tf_max, il_sigma_root, il_sigma_flank, &
           il_tau_pitch, il_stress_ratio])) loads(j) = biggest(lk(j, :))
      if (any(j == [il_free_mean, il_impacts_rev, il_sharing_rev, il_tf_rev])) &
           loads(j) = sum(lk(j, :))/m%realisations
      if (any(j == [il_revolutions, il_batches])) loads(j) = sum(lk(j, :))
    end do
    kmax = maxloc(lk(il_tf_max, :), 1)
    loads(il_tf_max_tooth) = lk(il_tf_max_tooth, kmax)
    loads(il_tf_max_t) = lk(il_tf_max_t, kmax)
    loads(il_load_sharing_tooth) = maxloc(tload(:, ilt_f_peak), 1)
    loads(il_free_max) = maxval(tload(:, ilt_free))
    loads(il_back_max) = maxval(tload(:, ilt_back))
    loads(il_unloaded) = count(tload(:, ilt_free) == 1.0_wp)
    loads(il_back_teeth) = count(tload(:, ilt_back) > 0.0_wp)
    loads(il_tm_rms_se) = spread_se(rms(:, 1))
    loads(il_kv_rms_se) = nan
    if (m%t_d /= 0.0_wp) loads(il_kv_rms_se) = spread_se(rms(:, 1)/abs(m%t_d))
    loads(il_f_rms_se) = spread_se(rms(:, 2))
    loads(il_d2_rms_se) = spread_se(rms(:, 3))
    loads(il_sharing_rev_se) = spread_se(lk(il_sharing_rev, :))
    loads(il_free_mean_se) = spread_se(lk(il_free_mean, :))
    loads(il_impacts_rev_se) = spread_se(lk(il_impacts_rev, :))
    loads(il_tf_rev_se) = spread_se(lk(il_tf_rev, :))
    loads(il_free_max_se) = tload(maxloc(tload(:, ilt_free), 1), ilt_free_se)
    loads(il_back_max_se) = tload(maxloc(tload(:, ilt_back), 1), ilt_back_se)
  contains
    !> the largest of x, NaN if one is (a load sharing without drive torque)
    pure real(wp) function biggest(x)
      real(wp), intent(in) :: x(:)
      biggest = maxval(x)
      if (any(x /= x)) biggest = nan
    end function biggest
    !> the standard error of the mean of the copies' values x: sd(x) / sqrt(K)
    pure real(wp) function spread_se(x)
      real(wp), intent(in) :: x(:)
      real(wp) :: mean
      mean = sum(x)/size(x)
      spread_se = sqrt(sum((x - mean)**2)/(size(x) - 1)/size(x))
    end function spread_se
  end subroutine combined_loads

end module spline_realisations
