!> Module spline_loads (fortran/physics/loads.f90) against docs/model.md section 15 on outputs made by
!> hand, whose loads are known: a tooth always on its drive flank, one never loaded, one that
!> cycles free -> back flank -> drive flank (two onsets every three outputs), a flash
!> temperature at one tooth and time, a closing speed set by dD2/dt, and a T_m whose RMS per
!> revolution is 30, 32, 34 N m (its batch-means standard error 2/sqrt(3)); the nominal
!> stresses of the most loaded tooth (3 F_s) by the formulas of section 15 and their warnings.
program test_loads
  use spline_kinds, only: wp, pi
  use spline_model, only: model_t, nstate
  use spline_quantities, only: ntooth_q, iq_tf, nload, nload_tooth, load_q, il_f_static, &
       il_load_sharing, il_load_sharing_tooth, il_free_max, il_back_max, il_free_mean, &
       il_unloaded, il_back_teeth, il_impacts_rev, il_closing_speed, il_tf_max, il_tf_max_tooth, &
       il_tf_max_t, il_revolutions, il_batches, il_tm_rms_se, il_sharing_rev, il_sharing_rev_se, &
       ilt_f_peak, ilt_load_factor, ilt_free, ilt_back, ilt_onsets, il_sigma_root, &
       il_sigma_flank, il_tau_pitch
  use spline_loads, only: run_loads, stress_warnings
  use check, only: check_true, check_close, check_done, default_case_model
  implicit none
  integer, parameter :: nt = 30
  type(model_t) :: m
  real(wp) :: t(nt), y(nstate, nt), tm(nt), loads(nload), fs, period, revs, ft, h_f, t_f
  character(len=:), allocatable :: text
  real(wp), allocatable :: tooth(:, :, :), tl(:, :)
  integer :: k, fl, rev

  call default_case_model(m)                 ! Z = 16, T_d = 30.7 N m, 6000 r/min, l_x = 0
  allocate(tooth(nt, m%z, ntooth_q), tl(m%z, nload_tooth))
  fs = m%t_d/(m%z*m%r_b)
  period = 2*pi/m%omega
  tooth = 0; y = 0
  y(13, :) = 0.01_wp                         ! dD2/dt = 10 mm/s: d dn_j/dt of every tooth
  do k = 1, nt
    t(k) = 0.1_wp + (k - 1)*period/7.3_wp    ! 3.97 revolutions: batches of 8, 7, 7 outputs
    rev = int((k - 1)/7.3_wp)
    tm(k) = -(30.0_wp + 2*rev)
    tooth(k, :, 1) = -fs                     ! every tooth on its drive flank (dn < -c) ...
    tooth(k, :, 4) = -2*m%c_bulk
    tooth(k, 1, 1) = -2*fs                   ! ... tooth 1 at twice the load
    tooth(k, 2, 1) = 0; tooth(k, 2, 4) = 0   ! tooth 2 never loaded
    fl = mod(k, 3) - 1                       ! tooth 3: free, back, drive, free, ...
    tooth(k, 3, 1) = -3*fs*fl; tooth(k, 3, 4) = -2*m%c_bulk*fl
  end do
  tooth(7, 4, iq_tf) = 5.0_wp
  call run_loads(m, t, y, tooth, tm, loads, tl)

  revs = (nt - 1)/7.3_wp
  call check_close('F_static = T_d / (Z r_b)', loads(il_f_static), 138.5_wp, 1.0e-3_wp)
  call check_close('load factors 2, 0, 3, 1', sum(abs(tl(1:4, ilt_load_factor) - &
       [2, 0, 3, 1])), 0.0_wp, 0.0_wp, 1.0e-14_wp)
  call check_true('F_peak of tooth 3 is 3 F_s', tl(3, ilt_f_peak) == 3*fs)
  call check_close('load sharing 3, tooth 3', loads(il_load_sharing), 3.0_wp, 1.0e-15_wp)
  call check_true('load sharing tooth 3', loads(il_load_sharing_tooth) == 3)
  call check_true('free fractions 0, 1, 1/3', all(tl(1:3, ilt_free) == [0.0_wp, 1.0_wp, &
       10.0_wp/nt]) .and. all(tl(4:, ilt_free) == 0))
  call check_true('back flank: tooth 3, 1/3', tl(3, ilt_back) == 10.0_wp/nt .and. &
       count(tl(:, ilt_back) > 0) == 1)
  call check_true('onsets: 20 on tooth 3 only', tl(3, ilt_onsets) == 20 .and. &
       sum(tl(:, ilt_onsets)) == 20)
  call check_true('free max 1, back max 1/3', loads(il_free_max) == 1 .and. &
       loads(il_back_max) == 10.0_wp/nt)
  call check_close('mean free teeth 4/3', loads(il_free_mean), 4.0_wp/3, 1.0e-15_wp)
  call check_true('one tooth unloaded, one on its back flank', loads(il_unloaded) == 1 .and. &
       loads(il_back_teeth) == 1)
  call check_close('revolutions', loads(il_revolutions), revs, 1.0e-14_wp)
  call check_close('impacts per revolution', loads(il_impacts_rev), 20/revs, 1.0e-14_wp)
  call check_close('closing speed = dD2/dt', loads(il_closing_speed), 0.01_wp, 1.0e-15_wp)
  call check_true('T_f max 5 at tooth 4, t_7', loads(il_tf_max) == 5 .and. &
       loads(il_tf_max_tooth) == 4 .and. loads(il_tf_max_t) == t(7))
  call check_true('3 batches', loads(il_batches) == 3)
  call check_close('SE of the T_m RMS: sd(30, 32, 34)/sqrt(3)', loads(il_tm_rms_se), &
       2/sqrt(3.0_wp), 1.0e-14_wp)
  call check_close('load sharing per revolution 3, SE 0', loads(il_sharing_rev), 3.0_wp, &
       1.0e-15_wp)
  call check_true('load sharing SE 0', loads(il_sharing_rev_se) == 0)
  ! section 15: f_t = 3 F_s cos(alpha); the load at R = m Z / 2, the root at m (Z - 1.5) / 2,
  ! straight flanks; working depth m; shear over the tooth thickness s
  ft = 3*fs*cos(m%alpha)
  h_f = 0.75_wp*m%m_n
  t_f = m%s + 2*h_f*tan(m%alpha)
  call check_close('root bending 6 f_t h_f / (b t_f^2)', loads(il_sigma_root), &
       6*ft*h_f/(m%b*t_f**2), 1.0e-14_wp)
  call check_close('flank bearing f_t / (b m)', loads(il_sigma_flank), ft/(m%b*m%m_n), 1.0e-14_wp)
  call check_close('shear f_t / (b s)', loads(il_tau_pitch), ft/(m%b*m%s), 1.0e-14_wp)
  text = ''
  call stress_warnings(m, loads, text)
  call check_true('no stress warning at 3 F_s', text == '')
  loads(il_sigma_flank) = 311.0e6_wp
  call stress_warnings(m, loads, text)
  call check_true('bearing stress beyond 310 MPa: one line', index(text, 'flank bearing stress &
       &F cos(alpha) / (b h_w) = 311.0 MPa at the peak load of tooth 3') > 0 .and. &
       index(text, 'exceeds 310 MPa') > 0 .and. count([(text(k:k) == new_line('a'), &
       k = 1, len(text))]) == 1)
  call check_true('every load has a name', all(len_trim(load_q%name) > 0))
  call check_done('test_loads')
end program test_loads
