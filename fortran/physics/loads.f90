!> The loads of a run, computed once from its outputs (docs/model.md section 15) for the
!> executable and Python alike: per tooth the peak load and the load factor, the fractions of
!> the outputs the tooth is free and on its back flank, its contact onsets (impacts); for the
!> run the load-sharing factor, impacts per revolution, the largest closing speed and the
!> largest flash temperature with its tooth and time; the nominal stresses of the most loaded
!> tooth at its peak load and their warnings (tooth_stresses, stress_warnings). Names and units:
!> spline_quantities (load_q, load_tooth_q).
module spline_loads
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use spline_kinds, only: wp, pi, max_teeth
  use spline_model, only: model_t, nstate, static_tooth_load
  use spline_geometry, only: tooth_angles, root_section, active_profile
  use spline_mesh, only: tooth_approach
  use spline_errors, only: itoa, ftoa
  use spline_quantities, only: iq_tf, nload, nload_tooth, nextreme, il_f_static, &
       il_load_sharing, il_load_sharing_tooth, il_free_max, il_back_max, il_free_mean, &
       il_unloaded, il_back_teeth, il_impacts_rev, il_closing_speed, il_tf_max, il_tf_max_tooth, &
       il_tf_max_t, il_revolutions, il_batches, il_tm_rms_se, il_sharing_rev, &
       il_sharing_rev_se, il_sigma_root, il_sigma_flank, il_tau_pitch, il_kv_rms_se, &
       il_f_rms_se, il_d2_rms_se, il_free_mean_se, il_free_max_se, il_back_max_se, &
       il_impacts_rev_se, il_tf_rev, il_tf_rev_se, il_stress_ratio, ilt_f_peak, ilt_load_factor, ilt_free, &
       ilt_back, ilt_onsets, ilt_free_se, ilt_back_se
  implicit none
  private
  public :: run_loads, combined_loads, run_extremes, drive_flank, approach_speed, tooth_stresses, &
       stress_warnings, load_coefficient

  !> Limits of stress_warnings [Pa] (docs/model.md section 15, "Tooth stresses"): typical
  !> allowables of case-hardened steel splines (58-63 HRC) at full load, 10^4 torque cycles,
  !> uniform drive: shear 50,000 psi (Dudley, "When splines need stress control", Product
  !> Engineering 1957, as in Machinery's Handbook's involute-spline stress tables); flank
  !> compression of a fixed spline 9 x 5,000 psi (same tables); root bending 400 MPa, a
  !> typical value, not a standard's: of the order of ISO 6336-5's nominal bending endurance
  !> limit of good case-hardened gear steel (about 500 MPa, approximate) over a safety of 1.25.
  real(wp), parameter :: sigma_root_limit = 400.0e6_wp, sigma_flank_limit = 310.0e6_wp, &
       tau_pitch_limit = 345.0e6_wp
  !> Limits of flash_warning [degC] on the contact temperature T_B = T_M + T_f (Eq. 1), the
  !> temperature of Blok's criterion (scuffing when the bulk plus flash temperature of the
  !> contact reaches a critical value of the oil and steel; T_f alone would pass a hot bulk):
  !> scuffing_temp, the top of the scuffing temperatures of gear oils on steel (about 150-400
  !> degC by the oil's FZG load stage in the flash-temperature method of ISO/TS 6336-20,
  !> formerly ISO/TR 13989-1); tempering_temp, the top of steel's tempering range (150-650
  !> degC, below the A1 transformation at 727 degC; solidus about 1400 degC), past which the
  !> surface loses its hardness and the model its ground.
  real(wp), parameter :: scuffing_temp = 400.0_wp, tempering_temp = 650.0_wp

contains

  !> The flank a tooth is in contact on at one output: 0 free (F_j = 0, Eqs. 15-17: |dn_j| <=
  !> c_j), else the sign of dn_j (+1: dn_j > c_j, -1: dn_j < -c_j; the sign of the elastic
  !> force, docs/model.md section 1; for a sliced face the face centre's). Private, so inlined:
  !> run_loads' loop over the outputs vectorises.
  elemental integer function tooth_flank(f, dn)
    real(wp), intent(in) :: f, dn
    integer :: s
    s = merge(1, -1, dn > 0.0_wp)
    tooth_flank = merge(0, s, f == 0.0_wp)
  end function tooth_flank

  !> The flank a contact starts on at an output (a contact onset, an impact): fl, the tooth's
  !> flank there, if it is in contact (fl /= 0) and was not on that flank at the output before
  !> (fl_prev: free or the other flank); else 0.
  elemental integer function contact_onset(fl, fl_prev)
    integer, intent(in) :: fl, fl_prev
    contact_onset = merge(fl, 0, fl /= fl_prev)
  end function contact_onset

  !> The drive flank: the flank every tooth is on at the static equilibrium under T_d (docs/
  !> model.md section 1): -1 for T_d >= 0 (F_j = -T_d / (Z r_b) < 0), +1 for T_d < 0.
  pure integer function drive_flank(m)
    type(model_t), intent(in) :: m
    drive_flank = merge(1, -1, m%t_d < 0.0_wp)
  end function drive_flank

  !> |d dn_j/dt| of tooth j at time t in state y (SI): the total rate of Eq. 11 with the turning
  !> frame (docs/model.md section 2), at the face centre.
  pure real(wp) function approach_speed(m, t, y, j) result(s)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t, y(nstate)
    integer, intent(in) :: j
    real(wp) :: sp(max_teeth), cp(max_teeth)
    call tooth_angles(m%z, m%omega, t, m%theta0, m%alpha, m%sin_pitch, m%cos_pitch, sp, cp)
    s = approach_rate(m, y, j, sp(j), cp(j))
  end function approach_speed

  !> approach_speed of tooth j in state y at the tooth angle phi_j of sine sp and cosine cp.
  pure real(wp) function approach_rate(m, y, j, sp, cp) result(s)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: y(nstate), sp, cp
    integer, intent(in) :: j
    real(wp) :: dn, ddn
    call tooth_approach(y(1) + m%l_x - y(3), y(2) + m%l_y - y(4), y(8) - y(10), y(9) - y(11), &
         y(6), y(13), m%omega, m%spacing_error(j), sp, cp, dn, ddn)
    s = abs(ddn)
  end function approach_rate

  !> The loads of a run from its outputs (t(k), SI states y(:, k), tooth(k, j, :) in the order
  !> of spline_quantities tooth_q, or only the first 4 (F, F_x, F_y, dn: a level without T_f,
  !> run_case's nq), T_m tm(k)): loads(nload) in the order of load_q, tload(z, nload_tooth)
  !> in the order of load_tooth_q. Over the output times as given (after the transient):
  !> - F_peak_j = max_k |F_j(t_k)|, load factor F_peak_j / F_s with F_s = |T_d| / (Z r_b), the
  !>   load of each tooth when all Z share T_d equally (NaN if T_d = 0); load_sharing = max_j.
  !> - free: F_j = 0; back flank: in contact on the flank opposite to drive_flank (tooth_flank);
  !>   fractions of the nt outputs.
  !> - onset of tooth j at t_k: in contact at t_k on another flank than at t_(k-1) (free or the
  !>   other one). impacts_per_rev = onsets of all teeth / revolutions, revolutions =
  !>   omega (t_nt - t_1) / (2 pi) (0 if that is 0); the closing speed of an onset is
  !>   approach_speed at t_(k-1), the last output before it.
  !> - T_f max over teeth and outputs, the first tooth and time where it occurs (0 and -1 if it
  !>   is 0 throughout: a thermal level without T_f).
  !> - standard errors by batch means (batch_means): per whole revolution of the outputs the
  !>   value of each mean-like statistic, their standard errors by overlapping batches of
  !>   floor(sqrt(revolutions)) revolutions (std_error).
  pure subroutine run_loads(m, t, y, tooth, tm, loads, tload)
    type(model_t), intent(in) :: m
    real(wp), intent(in), contiguous :: t(:), tooth(:, :, :), tm(:)
    real(wp), intent(in) :: y(:, :)
    real(wp), intent(out) :: loads(nload), tload(m%z, nload_tooth)
    integer :: nt, j, k, r, b, kb, nb, nrun, nfree, nback, nons, on, back
    integer, allocatable :: k0(:), rev(:), fl(:), onk(:)
    real(wp), allocatable :: f_sq(:), tf_max(:), f_max_b(:), free_b(:, :), back_b(:, :), ons_b(:)
    real(wp) :: fs, tfm, speed, fpk, frun, sp(max_teeth), cp(max_teeth)
    nt = size(t)
    loads = 0.0_wp; tload = 0.0_wp
    if (nt == 0) return
    back = -drive_flank(m)
    fs = static_tooth_load(m)
    speed = 0.0_wp
    loads(il_revolutions) = m%omega*(t(nt) - t(1))/(2.0_wp*pi)
    nb = int(loads(il_revolutions))
    allocate(k0(nt + 1), rev(0:nt), fl(nt), onk(nt), f_sq(nt), f_max_b(max(nb, 1)), &
         free_b(max(nb, 1), m%z), back_b(max(nb, 1), m%z), ons_b(max(nb, 1)))
    ! the runs of consecutive outputs in one revolution: outputs k0(r) .. k0(r + 1) - 1 in
    ! revolution rev(r) = floor(omega (t_k - t_1) / 2 pi) + 1, 0 outside the nb whole ones
    ! (the batches of batch_means; a run is a revolution where t increases)
    nrun = 0
    rev(0) = -1
    do k = 1, nt
      b = int(m%omega*(t(k) - t(1))/(2.0_wp*pi)) + 1
      if (b > nb .or. b < 1) b = 0
      if (b == rev(nrun)) cycle
      nrun = nrun + 1
      k0(nrun) = k
      rev(nrun) = b
    end do
    k0(nrun + 1) = nt + 1
    free_b = 0.0_wp; back_b = 0.0_wp; ons_b = 0.0_wp; onk = 0
    f_max_b = 0.0_wp; f_sq = 0.0_wp
    if (size(tooth, 3) >= iq_tf) then
      tf_max = tooth(:, 1, iq_tf)
    else
      allocate(tf_max(0))
    end if
    do j = 1, m%z
      ! per run: the outputs tooth j is free and on the back flank, its largest |F_j| (over the
      ! teeth per revolution f_max_b); per output its flank (fl) and over the teeth 1..j the sum
      ! of F_j^2 (in the order of the teeth)
      fpk = 0.0_wp
      do r = 1, nrun
        frun = 0.0_wp
        nfree = 0; nback = 0
        do k = k0(r), k0(r + 1) - 1
          fl(k) = tooth_flank(tooth(k, j, 1), tooth(k, j, 4))
          nfree = nfree + merge(1, 0, fl(k) == 0)
          nback = nback + merge(1, 0, fl(k) == back)
          frun = max(frun, abs(tooth(k, j, 1)))
          f_sq(k) = f_sq(k) + tooth(k, j, 1)**2
        end do
        ! its contact onsets in the run (output 1 is none; on the drive flank throughout, the
        ! run has one at most at its first output); per output the teeth with one (onk)
        kb = k0(r + 1) - 1
        if (nfree + nback == 0) kb = k0(r)
        nons = 0
        do k = max(k0(r), 2), kb
          on = merge(1, 0, contact_onset(fl(k), fl(k - 1)) /= 0)
          nons = nons + on
          onk(k) = onk(k) + on
        end do
        fpk = max(fpk, frun)
        tload(j, ilt_free) = tload(j, ilt_free) + nfree
        tload(j, ilt_back) = tload(j, ilt_back) + nback
        tload(j, ilt_onsets) = tload(j, ilt_onsets) + nons
        b = rev(r)
        if (b == 0) cycle
        f_max_b(b) = max(f_max_b(b), frun)
        free_b(b, j) = free_b(b, j) + nfree
        back_b(b, j) = back_b(b, j) + nback
        ons_b(b) = ons_b(b) + nons
      end do
      tload(j, ilt_f_peak) = fpk
      if (size(tooth, 3) >= iq_tf .and. j > 1) then
        do k = 1, nt
          tf_max(k) = max(tf_max(k), tooth(k, j, iq_tf))
        end do
      end if
    end do
    ! the largest closing speed: approach_speed at the output before each onset (the tooth
    ! angles once per output)
    do k = 2, nt
      if (onk(k) == 0) cycle
      call tooth_angles(m%z, m%omega, t(k - 1), m%theta0, m%alpha, m%sin_pitch, m%cos_pitch, &
           sp, cp)
      do j = 1, m%z
        if (contact_onset(tooth_flank(tooth(k, j, 1), tooth(k, j, 4)), &
             tooth_flank(tooth(k - 1, j, 1), tooth(k - 1, j, 4))) /= 0) &
             speed = max(speed, approach_rate(m, y(:, k - 1), j, sp(j), cp(j)))
      end do
    end do
    if (fs > 0.0_wp) then
      tload(:, ilt_load_factor) = tload(:, ilt_f_peak)/fs
    else
      tload(:, ilt_load_factor) = ieee_value(fs, ieee_quiet_nan)
    end if
    loads(il_f_static) = fs
    call tooth_stresses(m, maxval(tload(:, ilt_f_peak)), loads(il_sigma_root), &
         loads(il_sigma_flank), loads(il_tau_pitch))
    loads(il_stress_ratio) = max(loads(il_sigma_root)/sigma_root_limit, &
         loads(il_sigma_flank)/sigma_flank_limit, loads(il_tau_pitch)/tau_pitch_limit)
    loads(il_load_sharing) = maxval(tload(:, ilt_load_factor))
    loads(il_load_sharing_tooth) = maxloc(tload(:, ilt_f_peak), 1)
    if (fs == 0.0_wp) loads(il_load_sharing) = ieee_value(fs, ieee_quiet_nan)
    loads(il_free_mean) = sum(tload(:, ilt_free))/nt
    loads(il_unloaded) = count(tload(:, ilt_free) == nt)
    loads(il_back_teeth) = count(tload(:, ilt_back) > 0)
    tload(:, ilt_free) = tload(:, ilt_free)/nt
    tload(:, ilt_back) = tload(:, ilt_back)/nt
    loads(il_free_max) = maxval(tload(:, ilt_free))
    loads(il_back_max) = maxval(tload(:, ilt_back))
    if (loads(il_revolutions) > 0.0_wp) &
         loads(il_impacts_rev) = nint(sum(tload(:, ilt_onsets)))/loads(il_revolutions)
    loads(il_closing_speed) = speed
    call batch_means(m, rev(1:nrun), k0(:nrun + 1), y, tm, fs, f_sq, tf_max, f_max_b, free_b, &
         back_b, ons_b, loads, tload)
    tfm = 0.0_wp                 ! T_f = 0 where the outputs stop before it (no flash temperature)
    if (size(tf_max) > 0) tfm = maxval(tf_max)
    loads(il_tf_max) = tfm
    loads(il_tf_max_tooth) = 0.0_wp
    loads(il_tf_max_t) = -1.0_wp
    if (tfm > 0.0_wp) then       ! its first output, and there its first tooth
      k = findloc(tf_max, tfm, 1)
      loads(il_tf_max_tooth) = findloc(tooth(k, :, iq_tf), tfm, 1)
      loads(il_tf_max_t) = t(k)
    end if
  end subroutine run_loads

  !> The loads of a run's outputs (run_loads); with m%realisations = K > 1 (spline_realisations:
  !> the case's K perturbed copies) the outputs are K copies' of m%n_out each, one after the
  !> other, and their loads combine (spline_run::run_results calls this for both): extremes
  !> the largest, means and fractions the mean, counts the sum; the standard errors are the spread
  !> between the copies, sd / sqrt(K), of the value each is about (the RMS of T_m, k_v, F_j over
  !> all teeth and D_2 from each copy's outputs; the rest from its loads). With K = 1, or
  !> outputs that are not K copies' (one copy's), run_loads.
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
      rms(k, :) = [rms_of(tm(a + 1:a + n)), rms_of(reshape(tooth(a + 1:a + n, :, 1), [n*m%z])), &
           rms_of(y(6, a + 1:a + n))]
    end do
    loads = lk(:, 1)
    tload = tk(:, :, 1)
    do j = 1, m%z                               ! per tooth
      tload(j, ilt_f_peak) = maxval(tk(j, ilt_f_peak, :))
      tload(j, ilt_load_factor) = biggest(tk(j, ilt_load_factor, :))
      tload(j, ilt_free) = sum(tk(j, ilt_free, :))/m%realisations
      tload(j, ilt_back) = sum(tk(j, ilt_back, :))/m%realisations
      tload(j, ilt_onsets) = sum(tk(j, ilt_onsets, :))
      tload(j, ilt_free_se) = se(tk(j, ilt_free, :), tk(j, ilt_free_se, :))
      tload(j, ilt_back_se) = se(tk(j, ilt_back, :), tk(j, ilt_back_se, :))
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
    loads(il_tm_rms_se) = se(rms(:, 1), lk(il_tm_rms_se, :))
    loads(il_kv_rms_se) = nan
    if (m%t_d /= 0.0_wp) loads(il_kv_rms_se) = se(rms(:, 1)/abs(m%t_d), lk(il_kv_rms_se, :))
    loads(il_f_rms_se) = se(rms(:, 2), lk(il_f_rms_se, :))
    loads(il_d2_rms_se) = se(rms(:, 3), lk(il_d2_rms_se, :))
    loads(il_sharing_rev_se) = se(lk(il_sharing_rev, :), lk(il_sharing_rev_se, :))
    loads(il_free_mean_se) = se(lk(il_free_mean, :), lk(il_free_mean_se, :))
    loads(il_impacts_rev_se) = se(lk(il_impacts_rev, :), lk(il_impacts_rev_se, :))
    loads(il_tf_rev_se) = se(lk(il_tf_rev, :), lk(il_tf_rev_se, :))
    loads(il_free_max_se) = tload(maxloc(tload(:, ilt_free), 1), ilt_free_se)
    loads(il_back_max_se) = tload(maxloc(tload(:, ilt_back), 1), ilt_back_se)
  contains
    !> the largest of x, NaN if one is (a load sharing without drive torque)
    pure real(wp) function biggest(x)
      real(wp), intent(in) :: x(:)
      biggest = maxval(x)
      if (any(x /= x)) biggest = nan
    end function biggest
    !> the standard error of the mean of the copies' values x: their spread sd(x) / sqrt(K),
    !> never below the copies' own batch-means errors b combined, sqrt(sum(b^2)) / K, where
    !> they have them (2 revolutions each): copies that did not part, a settled drive's, have
    !> no spread, and it says nothing of the error
    pure real(wp) function se(x, b)
      real(wp), intent(in) :: x(:), b(:)
      real(wp) :: mean
      mean = sum(x)/size(x)
      se = sqrt(sum((x - mean)**2)/(size(x) - 1)/size(x))
      if (all(b == b)) se = max(se, sqrt(sum(b**2))/size(x))
    end function se
  end subroutine combined_loads


  !> The dynamic load coefficient k_v = |T_m|/|T_d| (output_q's kv, Eq. 22's torque over the
  !> drive's); undefined (NaN) at T_d = 0, whatever T_m (a driveless run that still rattles).
  elemental real(wp) function load_coefficient(tm, t_d) result(kv)
    real(wp), intent(in) :: tm, t_d
    if (t_d == 0.0_wp) then
      kv = ieee_value(kv, ieee_quiet_nan)
    else
      kv = abs(tm)/abs(t_d)
    end if
  end function load_coefficient

  !> The extremes and RMS of a run's outputs x(nextreme), spline_quantities' extreme_q: max, min
  !> and RMS (sqrt(sum(x**2)/n), a sequential sum) of T_m (tm), k_v = |T_m|/|T_d|, the tooth loads
  !> f(nt, Z) and flash temperatures tf(nt, Z) over all teeth, D_2 and dD_2/dt (y: SI states,
  !> a column per output). tf absent: T_f is the level's constant tf_const at every output (0
  !> without flash temperature: its RMS |tf_const|). The one computation of them: spline-dyn's
  !> summary and Python's (Result.extremes, the sweep point's summary). The arrays are read in
  !> place (a tooth array of 6401 outputs and 16 teeth copied or broadcast cost more than the run's
  !> tail).
  pure subroutine run_extremes(m, y, tm, f, x, tf, tf_const)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: y(:, :), tm(:)
    real(wp), intent(in), contiguous :: f(:, :)
    real(wp), intent(out) :: x(nextreme)
    real(wp), intent(in), contiguous, optional :: tf(:, :)
    real(wp), intent(in), optional :: tf_const
    x(1:3) = three(size(tm), tm)
    x(4:6) = three(size(tm), load_coefficient(tm, m%t_d))
    x(7:9) = three(size(f), f)
    if (present(tf)) then
      x(10:12) = three(size(tf), tf)
    else
      x(10:12) = [tf_const, tf_const, abs(tf_const)]
    end if
    x(13:15) = three(size(y, 2), y(6, :))
    x(16:18) = three(size(y, 2), y(13, :))
  contains
    !> [maxval(v), minval(v), rms_of(v)] of finite v (the run's checked outputs), n >= 1, in
    !> one pass: the first of equal extremes (strict comparisons, as maxval and minval), the
    !> squares summed in order.
    pure function three(n, v) result(r)
      integer, intent(in) :: n
      real(wp), intent(in) :: v(n)       ! explicit shape: a contiguous 2-D array read as it is
      real(wp) :: r(3), mx, mn, sq
      integer :: i
      mx = v(1); mn = v(1); sq = 0.0_wp
      do i = 1, n
        if (v(i) > mx) mx = v(i)
        if (v(i) < mn) mn = v(i)
        sq = sq + v(i)**2
      end do
      r = [mx, mn, sqrt(sq/n)]
    end function three
  end subroutine run_extremes

  !> The root mean square of v (run_extremes; combined_loads' per-copy values).
  pure real(wp) function rms_of(v)
    real(wp), intent(in) :: v(:)
    rms_of = sqrt(sum(v**2)/size(v))
  end function rms_of

  !> Nominal stresses of a tooth carrying the load f along its line of action (docs/model.md
  !> section 15, "Tooth stresses"), from its tangential part at the pitch circle
  !> f_t = f cos(alpha) spread evenly over the face width b:
  !> - root bending sigma_root = 6 f_t h_f / (b t_f^2): the tooth a cantilever loaded at the
  !>   pitch circle, h_f above its root section t_f thick (spline_geometry::root_section; the
  !>   cantilever of Lewis 1892, no form or stress-correction factor);
  !> - flank bearing sigma_flank = f_t / (b h_w) over the working depth h_w = m (the active
  !>   profile, spline_geometry::active_profile; Dudley 1957's compressive stress);
  !> - shear at the pitch circle tau_pitch = f_t / (b s), s the tooth thickness there (Dudley
  !>   1957's tooth shear with f_t the peak, not 2 T / (D N)).
  pure subroutine tooth_stresses(m, f, sigma_root, sigma_flank, tau_pitch)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: f
    real(wp), intent(out) :: sigma_root, sigma_flank, tau_pitch
    real(wp) :: ft, h_f, t_f, r_lo, r_hi
    ft = abs(f)*m%cos_alpha
    call root_section(m%z, m%m_n, m%s, m%alpha, h_f, t_f)
    call active_profile(m%z, m%m_n, r_lo, r_hi)
    sigma_root = 6.0_wp*ft*h_f/(m%b*t_f**2)
    sigma_flank = ft/(m%b*(r_hi - r_lo))
    tau_pitch = ft/(m%b*m%s)
  end subroutine tooth_stresses

  !> Warnings about a run's loads (loads in the order of load_q, as run_loads makes them), one
  !> line each, appended to text: a nominal stress of tooth_stresses beyond its limit
  !> (sigma_root_limit, sigma_flank_limit, tau_pitch_limit); the contact temperature beyond
  !> scuffing_temp or tempering_temp (flash_warning). The executable prints them to
  !> stderr, Python raises pyspline.SplineWarning (api_simulate, through spline_run::
  !> run_results): the same words.
  subroutine stress_warnings(m, loads, text)
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: loads(nload)
    character(len=:), allocatable, intent(inout) :: text
    call over('root bending stress 6 F cos(alpha) h_f / (b t_f^2)', loads(il_sigma_root), &
         sigma_root_limit)
    call over('flank bearing stress F cos(alpha) / (b h_w)', loads(il_sigma_flank), &
         sigma_flank_limit)
    call over('shear stress at the pitch circle F cos(alpha) / (b s)', loads(il_tau_pitch), &
         tau_pitch_limit)
    call flash_warning()
  contains
    !> T_B = T_M + max T_f (a run with flash temperature) beyond scuffing_temp, or, stronger,
    !> beyond tempering_temp.
    subroutine flash_warning()
      character(len=:), allocatable :: line
      real(wp) :: tb
      tb = m%t_bulk + loads(il_tf_max)
      if (.not. loads(il_tf_max) > 0.0_wp .or. .not. tb > scuffing_temp) return
      line = 'case '//trim(m%name)//': contact temperature T_M + T_f = '// &
           ftoa(m%t_bulk, '(f12.1)')//' + '//ftoa(loads(il_tf_max), '(f12.1)')// &
           ' degC (Eq. 1, the largest T_f, tooth '// &
           itoa(nint(loads(il_tf_max_tooth)))//' at t = '//ftoa(loads(il_tf_max_t), '(es10.3)')// &
           ' s, f_m = '//ftoa(m%f_m, '(es10.3)')//') exceeds '
      if (tb > tempering_temp) then
        line = line//itoa(nint(tempering_temp))//' degC, past steel''s tempering range (A1 727 '// &
             'degC, solidus about 1400 degC): the flank would lose its hardness or melt, Blok''s '// &
             'flash temperature is outside its range; f_m, the load or the speed? Run as given'
      else
        line = line//itoa(nint(scuffing_temp))//' degC, the top of typical scuffing temperatures '// &
             'of gear oils on steel (Blok''s criterion; ISO/TS 6336-20): scuffing likely. Run as given'
      end if
      text = text//line//new_line('a')
    end subroutine flash_warning

    subroutine over(what, x, limit)
      character(len=*), intent(in) :: what
      real(wp), intent(in) :: x, limit
      character(len=:), allocatable :: h
      if (.not. x > limit) return
      call hint(x, limit, h)
      text = text//'case '//trim(m%name)//': '//what//' = '//ftoa(x*1.0e-6_wp, '(f0.1)')// &
           ' MPa at the peak load of tooth '//itoa(nint(loads(il_load_sharing_tooth)))// &
           ' (t_d = '//ftoa(m%t_d, '(es10.3)')//' N m) exceeds '//itoa(nint(limit*1.0e-6_wp))// &
           ' MPa, a typical allowable of case-hardened steel (an estimate, docs/model.md '// &
           'section 15)'//h//'. Run as given'//new_line('a')
    end subroutine over
    !> Why: the static load alone (F_static, the peak over the load-sharing factor) beyond the
    !> limit points to the torque's unit, else the run's dynamic peak.
    subroutine hint(x, limit, h)
      real(wp), intent(in) :: x, limit
      character(len=:), allocatable, intent(out) :: h
      h = ': a dynamic peak (no drive torque)'
      if (.not. loads(il_f_static) > 0.0_wp) return
      if (x/loads(il_load_sharing) > limit) then
        h = ': the static load alone is beyond it (a torque in N mm?)'
      else
        h = ': a dynamic peak, load-sharing factor '//ftoa(loads(il_load_sharing), '(f0.2)')
      end if
    end subroutine hint
  end subroutine stress_warnings

  !> Standard errors by batch means (e.g. Law & Kelton, Simulation Modeling and Analysis, ch.
  !> 9.5): output k belongs to revolution floor(omega (t_k - t_1) / 2 pi) + 1, the outputs k0(r)
  !> .. k0(r + 1) - 1 of run r (run_loads) to revolution rev(r) (0 outside the nb =
  !> floor(revolutions) whole ones, which are the batches). Per batch b its value of each
  !> statistic that is a mean over the outputs (docs/model.md section 15): the RMS of T_m, k_v =
  !> |T_m| / |T_d|, F_j (all teeth) and D_2; the load-sharing factor max |F_j| / F_s and the
  !> largest T_f of the revolution (their means load_sharing_rev, Tf_max_rev: what an extreme is
  !> given instead); per tooth the fractions free and on the back flank (free_b, back_b: counts),
  !> the mean number of free teeth and the contact onsets (ons_b) of the revolution. From
  !> run_loads also: the largest |F_j| of each revolution (f_max_b); per output over the teeth
  !> the sum of F_j^2 (f_sq) and the largest T_f (tf_max, empty without T_f). The standard error
  !> of their mean by std_error (overlapping batches of floor(sqrt(nb)) revolutions: in a chaotic
  !> run consecutive revolutions are correlated); that of free_frac_max and back_frac_max is the
  !> standard error of the tooth that has the largest. NaN with fewer than 2 batches (and for k_v
  !> and the load sharing when T_d = 0).
  pure subroutine batch_means(m, rev, k0, y, tm, fs, f_sq, tf_max, f_max_b, free_b, back_b, &
       ons_b, loads, tload)
    type(model_t), intent(in) :: m
    integer, intent(in) :: rev(:), k0(:)
    real(wp), intent(in) :: y(:, :), tm(:), fs, f_sq(:), tf_max(:), f_max_b(:)
    real(wp), intent(inout) :: free_b(:, :), back_b(:, :), ons_b(:)
    real(wp), intent(inout) :: loads(nload), tload(m%z, nload_tooth)
    real(wp), allocatable :: sq(:), fmax(:), cnt(:), sqf(:), sqd(:), tfb(:)
    real(wp) :: nan
    integer :: nb, b, k, j, r
    nan = ieee_value(0.0_wp, ieee_quiet_nan)
    nb = int(loads(il_revolutions))
    loads(il_batches) = nb
    loads([il_tm_rms_se, il_sharing_rev, il_sharing_rev_se, il_kv_rms_se, il_f_rms_se, &
         il_d2_rms_se, il_free_mean_se, il_free_max_se, il_back_max_se, il_impacts_rev_se, &
         il_tf_rev, il_tf_rev_se]) = nan
    tload(:, ilt_free_se) = nan
    tload(:, ilt_back_se) = nan
    if (nb < 2) return
    allocate(sq(nb), fmax(nb), cnt(nb), sqf(nb), sqd(nb), tfb(nb))
    sq = 0.0_wp; cnt = 0.0_wp; sqf = 0.0_wp; sqd = 0.0_wp; tfb = 0.0_wp
    fmax = f_max_b
    do r = 1, size(k0) - 1      ! the runs k0(r) .. k0(r + 1) - 1 of outputs in one revolution
      b = rev(r)
      if (b == 0) cycle
      cnt(b) = cnt(b) + (k0(r + 1) - k0(r))
      do k = k0(r), k0(r + 1) - 1
        sq(b) = sq(b) + tm(k)**2
        sqf(b) = sqf(b) + f_sq(k)
        sqd(b) = sqd(b) + y(6, k)**2
      end do
      if (size(tf_max) > 0) tfb(b) = max(tfb(b), maxval(tf_max(k0(r):k0(r + 1) - 1)))
    end do
    if (any(cnt == 0.0_wp)) return          ! a revolution without outputs: no batches
    sq = sqrt(sq/cnt)
    loads(il_tm_rms_se) = std_error(sq)
    if (fs > 0.0_wp) then
      fmax = fmax/fs
      loads(il_sharing_rev) = sum(fmax)/nb
      loads(il_sharing_rev_se) = std_error(fmax)
      loads(il_kv_rms_se) = std_error(sq/abs(m%t_d))
    end if
    loads(il_f_rms_se) = std_error(sqrt(sqf/(cnt*m%z)))
    loads(il_d2_rms_se) = std_error(sqrt(sqd/cnt))
    loads(il_tf_rev) = sum(tfb)/nb
    loads(il_tf_rev_se) = std_error(tfb)
    loads(il_impacts_rev_se) = std_error(ons_b)
    loads(il_free_mean_se) = std_error(sum(free_b, 2)/cnt)
    do j = 1, m%z
      free_b(:, j) = free_b(:, j)/cnt
      back_b(:, j) = back_b(:, j)/cnt
      tload(j, ilt_free_se) = std_error(free_b(:, j))
      tload(j, ilt_back_se) = std_error(back_b(:, j))
    end do
    loads(il_free_max_se) = tload(maxloc(tload(:, ilt_free), 1), ilt_free_se)
    loads(il_back_max_se) = tload(maxloc(tload(:, ilt_back), 1), ilt_back_se)
  end subroutine batch_means

  !> Standard error of the mean of x(1..n) (n >= 2), consecutive and possibly correlated, by
  !> overlapping batch means (Meketon & Schmeiser 1984; docs/model.md section 15): batches of
  !> m = floor(sqrt(n)) consecutive values, one starting at each of i = 1..n-m+1, with means
  !> xb_i; variance of the mean n m / ((n - m)(n - m + 1)) sum_i (xb_i - mean)^2 / n.
  !> m = 1 (n < 4) is sd(x) / sqrt(n).
  pure real(wp) function std_error(x) result(se)
    real(wp), intent(in) :: x(:)
    real(wp) :: mean, ss, xb(size(x))
    integer :: n, m, l
    n = size(x)
    m = int(sqrt(real(n, wp)))
    mean = sum(x)/n
    xb = 0.0_wp                  ! the batch sums x_i + ... + x_(i+m-1), added in this order
    do l = 0, m - 1
      xb(1:n - m + 1) = xb(1:n - m + 1) + x(1 + l:n - m + 1 + l)
    end do
    ss = sum((xb(1:n - m + 1)/m - mean)**2)
    se = sqrt(real(m, wp)*ss/(real(n - m, wp)*real(n - m + 1, wp)))
  end function std_error

end module spline_loads
