!> Module spline_loads (fortran/physics/loads.f90) against a straightforward count on random outputs
!> (docs/model.md section 15): one output and one tooth at a time, a branch for each rule (free
!> where F_j = 0, else on the flank of the sign of dn_j; an onset where in contact on another
!> flank than at the output before; output k in revolution floor(omega (t_k - t_1) / 2 pi) + 1).
!> The outputs have F exactly 0 and -0 (and subnormal), dn exactly +-c, 0 and -0, a tooth never
!> loaded, flanks that switch often; runs of one output, two, fewer than 2 revolutions, revolution
!> boundaries on outputs, T_d = 0 and T_d < 0 (the drive flank +1), T_f with ties or none, and a
!> time that steps back once. Every count must agree exactly, the standard errors of the counts per
!> revolution (overlapping batch means, written out here) to round-off.
program test_loads_count
  use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_value, ieee_quiet_nan
  use spline_kinds, only: wp, pi
  use spline_model, only: model_t, nstate
  use spline_quantities, only: ntooth_q, iq_tf, nload, nload_tooth, il_free_max, il_back_max, &
       il_free_mean, il_unloaded, il_back_teeth, il_impacts_rev, il_closing_speed, il_tf_max, &
       il_tf_max_tooth, il_tf_max_t, il_batches, il_load_sharing, il_load_sharing_tooth, &
       il_sharing_rev, il_tf_rev, il_free_mean_se, il_impacts_rev_se, il_free_max_se, &
       il_back_max_se, ilt_f_peak, ilt_free, ilt_back, ilt_onsets, ilt_free_se, ilt_back_se
  use spline_loads, only: run_loads, drive_flank, approach_speed
  use spline_errors, only: itoa
  use check, only: check_true, check_done, default_case_model
  implicit none
  integer, parameter :: ntrial = 400, nquant = 10
  character(len=*), parameter :: quant(nquant) = [character(len=48) :: &
       'F_peak, load sharing and its tooth', 'free fractions and free_frac_max', &
       'back-flank fractions and back_frac_max', 'onsets and impacts per revolution', &
       'teeth free on average, unloaded, on the back', 'closing speed at the onsets', &
       'T_f max, its tooth and time', 'batches, per-revolution sharing and T_f max', &
       'SE of free and back fractions per tooth', 'SE of free teeth and impacts per rev']
  type(model_t) :: m0, m
  real(wp), allocatable :: t(:), y(:, :), tooth(:, :, :), tm(:), tl(:, :)
  real(wp) :: loads(nload), u, period
  integer :: trial, nt, nq, i, seed(64), nseed, bad(nquant), first_bad(nquant)

  call default_case_model(m0)                ! Z = 16, T_d = 30.7 N m, 6000 r/min
  call random_seed(size=nseed)
  seed = [(7919*i, i = 1, 64)]
  call random_seed(put=seed(1:min(nseed, 64)))
  period = 2*pi/m0%omega
  bad = 0; first_bad = 0
  allocate(tl(m0%z, nload_tooth))
  do trial = 1, ntrial
    m = m0
    if (mod(trial, 5) == 1) m%t_d = 0
    if (mod(trial, 5) == 2) m%t_d = -m0%t_d
    nt = trial                               ! 1, 2, ... then random lengths
    if (trial > 3) then
      call random_number(u)
      nt = 3 + int(u*400)
    end if
    nq = merge(ntooth_q, 4, mod(trial, 3) == 0)
    allocate(t(nt), y(nstate, nt), tooth(nt, m%z, nq), tm(nt))
    call random_outputs(trial, m, period, t, y, tooth, tm)
    call run_loads(m, t, y, tooth, tm, loads, tl)
    call compare(trial, m, t, y, tooth, loads, tl)
    deallocate(t, y, tooth, tm)
  end do
  do i = 1, nquant
    call check_true(trim(quant(i))//' as counted', bad(i) == 0, 'disagree in '//itoa(bad(i))// &
         ' of '//itoa(ntrial)//' random runs (first: '//itoa(first_bad(i))//')')
  end do
  call check_done('test_loads_count')

contains

  !> Random outputs of trial n: per tooth a flank that switches at random (free, +1, -1), F and dn
  !> of that flank with exact zeros, -0 and dn = +-c among them; tooth 2 never loaded, tooth 3
  !> switching rarely (whole revolutions on one flank).
  subroutine random_outputs(n, m, period, t, y, tooth, tm)
    integer, intent(in) :: n
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: period
    real(wp), intent(out) :: t(:), y(:, :), tooth(:, :, :), tm(:)
    real(wp) :: r(4), span, c
    integer :: k, j, nt, fl
    nt = size(t)
    c = m%c_bulk
    call random_number(r)
    span = period*6*r(1)                     ! 0 to 6 revolutions
    if (mod(n, 7) == 0) span = period*2.5_wp
    t(1) = 0.01_wp*r(2)
    do k = 2, nt
      call random_number(u)
      t(k) = t(k - 1) + span/(nt - 1)*(0.5_wp + u)
    end do
    if (mod(n, 7) == 0) t = t(1) + [(period*(k - 1)/20.0_wp, k = 1, nt)]  ! on the boundaries
    if (mod(n, 11) == 0 .and. nt > 4) t(3) = t(2) - 0.3_wp*period      ! a step back
    call random_number(y)
    y = (y - 0.5_wp)*1.0e-3_wp
    call random_number(tm)
    tooth = 0
    do j = 1, m%z
      fl = 0
      do k = 1, nt
        call random_number(r)
        if (r(1) < merge(0.02_wp, 0.3_wp, j == 3)) fl = int(r(2)*3) - 1   ! tooth 3: long spells
        if (j == 2) fl = 0
        select case (fl)
        case (0)
          tooth(k, j, 1) = merge(-0.0_wp, 0.0_wp, r(3) < 0.5_wp)
          tooth(k, j, 4) = c*(2*r(4) - 1)
          if (r(3) < 0.2_wp) tooth(k, j, 4) = merge(c, -c, r(4) < 0.5_wp)
        case default
          tooth(k, j, 1) = -fl*100*(r(3) + 0.01_wp)
          if (r(3) < 0.05_wp) tooth(k, j, 1) = -fl*1.0e-310_wp   ! subnormal, not 0
          tooth(k, j, 4) = fl*(c + 1.0e-5_wp*r(4))
          if (r(4) < 0.2_wp) tooth(k, j, 4) = fl*c          ! dn = +-c exactly
          if (r(4) > 0.9_wp .and. fl < 0) tooth(k, j, 4) = merge(-0.0_wp, 0.0_wp, r(3) < 0.5_wp)
        end select
        if (size(tooth, 3) >= iq_tf) tooth(k, j, iq_tf) = 10*r(3)*r(4)
      end do
    end do
    if (size(tooth, 3) >= iq_tf .and. nt > 3) then       ! a tie for the largest T_f
      tooth(nt, 1, iq_tf) = 20.0_wp
      tooth(2, 5, iq_tf) = 20.0_wp
    end if
    if (size(tooth, 3) >= iq_tf .and. mod(n, 2) == 0) tooth(:, :, iq_tf) = 0
  end subroutine random_outputs

  !> The loads by a count, output by output, against run_loads' (loads, tl).
  subroutine compare(n, m, t, y, tooth, loads, tl)
    integer, intent(in) :: n
    type(model_t), intent(in) :: m
    real(wp), intent(in) :: t(:), y(:, :), tooth(:, :, :), loads(:), tl(:, :)
    integer :: nt, z, k, j, b, nb, back, fl(size(t), m%z), rev(size(t)), kt, jt
    integer :: free(m%z), nback(m%z), ons(m%z)
    real(wp), allocatable :: free_b(:, :), back_b(:, :), ons_b(:), cnt(:), fmax(:), tfb(:)
    real(wp) :: fs, peak(m%z), speed, tfm, revs
    logical :: ok, nobatch
    nt = size(t); z = m%z
    back = -drive_flank(m)
    fs = abs(m%t_d)/(z*m%r_b)
    revs = m%omega*(t(nt) - t(1))/(2*pi)
    nb = int(revs)
    allocate(free_b(max(nb, 1), z), back_b(max(nb, 1), z), ons_b(max(nb, 1)), cnt(max(nb, 1)), &
         fmax(max(nb, 1)), tfb(max(nb, 1)))
    free_b = 0; back_b = 0; ons_b = 0; cnt = 0; fmax = 0; tfb = 0
    free = 0; nback = 0; ons = 0; speed = 0
    do k = 1, nt
      rev(k) = int(m%omega*(t(k) - t(1))/(2*pi)) + 1
      if (rev(k) < 1 .or. rev(k) > nb) rev(k) = 0
      b = rev(k)
      if (b > 0) cnt(b) = cnt(b) + 1
      do j = 1, z
        if (tooth(k, j, 1) == 0) then
          fl(k, j) = 0
          free(j) = free(j) + 1
          if (b > 0) free_b(b, j) = free_b(b, j) + 1
        else if (tooth(k, j, 4) > 0) then
          fl(k, j) = 1
        else
          fl(k, j) = -1
        end if
        if (fl(k, j) == back) then
          nback(j) = nback(j) + 1
          if (b > 0) back_b(b, j) = back_b(b, j) + 1
        end if
        if (k > 1) then
          if (fl(k, j) /= 0 .and. fl(k, j) /= fl(k - 1, j)) then
            ons(j) = ons(j) + 1
            if (b > 0) ons_b(b) = ons_b(b) + 1
            speed = max(speed, approach_speed(m, t(k - 1), y(:, k - 1), j))
          end if
        end if
        if (b > 0) fmax(b) = max(fmax(b), abs(tooth(k, j, 1)))
        if (b > 0 .and. size(tooth, 3) >= iq_tf) tfb(b) = max(tfb(b), tooth(k, j, iq_tf))
      end do
    end do
    do j = 1, z
      peak(j) = maxval(abs(tooth(:, j, 1)))
    end do
    call tally(n, 1, all(tl(:, ilt_f_peak) == peak) .and. &
         loads(il_load_sharing_tooth) == maxloc(peak, 1) .and. &
         same(loads(il_load_sharing), merge(maxval(peak)/fs, nan(), fs > 0)))
    call tally(n, 2, all(tl(:, ilt_free) == real(free, wp)/nt) .and. &
         loads(il_free_max) == maxval(real(free, wp)/nt))
    call tally(n, 3, all(tl(:, ilt_back) == real(nback, wp)/nt) .and. &
         loads(il_back_max) == maxval(real(nback, wp)/nt))
    call tally(n, 4, all(tl(:, ilt_onsets) == ons) .and. &
         loads(il_impacts_rev) == merge(sum(ons)/revs, 0.0_wp, revs > 0))
    call tally(n, 5, loads(il_free_mean) == real(sum(free), wp)/nt .and. &
         loads(il_unloaded) == count(free == nt) .and. loads(il_back_teeth) == count(nback > 0))
    call tally(n, 6, loads(il_closing_speed) == speed)
    tfm = 0; kt = 0; jt = 0
    if (size(tooth, 3) >= iq_tf) then
      do k = 1, nt
        do j = 1, z
          if (tooth(k, j, iq_tf) > tfm) then
            tfm = tooth(k, j, iq_tf); kt = k; jt = j
          end if
        end do
      end do
    end if
    ok = loads(il_tf_max) == tfm .and. loads(il_tf_max_tooth) == jt
    if (kt > 0) ok = ok .and. loads(il_tf_max_t) == t(kt)
    if (kt == 0) ok = ok .and. loads(il_tf_max_t) == -1
    call tally(n, 7, ok)
    ! the standard errors: NaN with fewer than 2 batches or a revolution without outputs
    nobatch = nb < 2
    if (.not. nobatch) nobatch = any(cnt == 0)
    ok = loads(il_batches) == nb
    if (nobatch) then
      ok = ok .and. ieee_is_nan(loads(il_sharing_rev)) .and. ieee_is_nan(loads(il_tf_rev))
    else
      ok = ok .and. close(loads(il_tf_rev), sum(tfb)/nb)
      if (fs > 0) ok = ok .and. close(loads(il_sharing_rev), sum(fmax/fs)/nb)
    end if
    call tally(n, 8, ok)
    ok = .true.
    do j = 1, z
      if (nobatch) then
        ok = ok .and. ieee_is_nan(tl(j, ilt_free_se)) .and. ieee_is_nan(tl(j, ilt_back_se))
      else
        ok = ok .and. close(tl(j, ilt_free_se), obm_se(free_b(:, j)/cnt)) .and. &
             close(tl(j, ilt_back_se), obm_se(back_b(:, j)/cnt))
      end if
    end do
    ok = ok .and. same(loads(il_free_max_se), tl(maxloc(free, 1), ilt_free_se)) .and. &
         same(loads(il_back_max_se), tl(maxloc(nback, 1), ilt_back_se))
    call tally(n, 9, ok)
    if (nobatch) then
      ok = ieee_is_nan(loads(il_free_mean_se)) .and. ieee_is_nan(loads(il_impacts_rev_se))
    else
      ok = close(loads(il_free_mean_se), obm_se(sum(free_b, 2)/cnt)) .and. &
           close(loads(il_impacts_rev_se), obm_se(ons_b))
    end if
    call tally(n, 10, ok)
  end subroutine compare

  !> Counts a disagreement of quantity i in trial n.
  subroutine tally(n, i, ok)
    integer, intent(in) :: n, i
    logical, intent(in) :: ok
    if (ok) return
    bad(i) = bad(i) + 1
    if (first_bad(i) == 0) first_bad(i) = n
  end subroutine tally

  !> Overlapping batch means (docs/model.md section 15): batches of m = floor(sqrt(n)) values,
  !> one at each start i, variance of the mean m sum_i (xb_i - mean)^2 / ((n - m)(n - m + 1)).
  real(wp) function obm_se(x) result(se)
    real(wp), intent(in) :: x(:)
    integer :: n, mb, i
    real(wp) :: ss
    n = size(x)
    mb = int(sqrt(real(n, wp)))
    ss = 0
    do i = 1, n - mb + 1
      ss = ss + (sum(x(i:i + mb - 1))/mb - sum(x)/n)**2
    end do
    se = sqrt(mb*ss/((n - mb)*(n - mb + 1.0_wp)))
  end function obm_se

  !> Equal to round-off (standard errors of fractions and counts of order 0.01 to 100: one count
  !> more or less changes them by far more).
  logical function close(a, b)
    real(wp), intent(in) :: a, b
    close = abs(a - b) <= 1.0e-12_wp*abs(b) + 1.0e-14_wp
  end function close

  logical function same(a, b)
    real(wp), intent(in) :: a, b
    same = a == b .or. (ieee_is_nan(a) .and. ieee_is_nan(b))
  end function same

  real(wp) function nan()
    nan = ieee_value(0.0_wp, ieee_quiet_nan)
  end function nan

end program test_loads_count
