!> The model: parameters of one scene derived from a validated case (SI units, radians, rad/s).
!> model_from_case is the constructor; each piece of physics it needs lives in its physics
!> module (geometry, stiffness, thermal). A model_t holds no pointers or allocatables, so it can
!> be copied bitwise (the Python layer keeps a loaded case as such a copy: spline_api).
module spline_model
  use spline_kinds, only: wp, pi, max_teeth
  use, intrinsic :: iso_fortran_env, only: int64
  use spline_errors, only: err_ok, err_case, err_thermal, itoa, ftoa, num
  use spline_case, only: case_t, case_validate, case_run_times, namelen, option_index, thermal_values, &
       method_values, nonlinear_values, start_values, fidelity_values, section_values, nripple, &
       lyapunov_method_values, goal_values, erk_table_values
  use spline_geometry, only: iso4156_radii, pitch_rotation
  use spline_stiffness, only: spline_mesh_stiffness_fillet
  use spline_thermal, only: backlash_coefficient, thermal_backlash
  use spline_accuracy, only: accuracy_settings, check_factor
  implicit none
  private
  public :: model_t, model_from_case, set_thermal_level, model_magic, model_warnings
  public :: nstate, ndof, thermal_none, thermal_bulk, thermal_oneway, thermal_coupled
  public :: nkterms, kterm_names, ik_m, lyapunov_separation, static_tooth_load

  integer, parameter :: ndof = 7            !< x1, y1, x2, y2, D1, D2, D3 (Eq. 24)
  integer, parameter :: nstate = 2*ndof     !< displacements then velocities
  !> thermal levels, in the order of spline_case's thermal_values
  integer, parameter :: thermal_none = 0, thermal_bulk = 1, thermal_oneway = 2, thermal_coupled = 3
  integer, parameter :: nkterms = 10        !< terms of Eq. 18 reported with every case
  character(len=4), parameter :: kterm_names(nkterms) = [character(len=4) :: &
       'k_h', 'k_b1', 'k_s1', 'k_a1', 'k_f1', 'k_b2', 'k_s2', 'k_a2', 'k_f2', 'k_m']
  integer, parameter :: ik_m = nkterms      !< position of the total k_m in k_terms
  integer, parameter :: stiffness_nquad = 32   !< Gauss points: converged to 1e-15 from 16 on
  !> Marks a model_t built by this build's constructor (layout version in the last digits):
  !> a copy handed back from outside is checked against it.
  integer, parameter :: model_magic = 517730009
  !> A given k_m this many times below Eq. 18 draws a warning (model_warnings): the paper's
  !> calibrated 2.54e5 N/m is ~7600 times below for its spline, a deliberate fit; N/mm read
  !> as N/m is 1000 times, on top of such a fit 1e4 is passed.
  real(wp), parameter :: k_m_warn_ratio = 1.0e4_wp
  !> Plausibility limits of model_warnings (docs/model.md section 12, "Plausibility warnings"):
  !> the offset the supports leave at the mesh over the static tooth deflection (load-sharing
  !> factor 1.1); the static shaft wind-up [rad]
  !> (a solid steel shaft at 300 MPa shear twists 2 tau L / (G d) = 0.0075 L/d rad: 0.2 rad at
  !> L/d = 27; an elastomer coupling 5-10 deg at its rated torque); the static tooth deflection
  !> as a fraction of the module (a tooth at a 1000 MPa root bending stress deflects ~1.6 %).
  real(wp), parameter :: support_limit = 0.1_wp, windup_limit = 0.2_wp
  real(wp), parameter :: deflection_limit = 0.05_wp

  type :: model_t
    integer  :: magic = 0
    character(len=namelen) :: name = ''
    integer  :: z = 0
    real(wp) :: m_n, alpha, b, s, c0, e_mod, nu, lambda_th, k_cond, rho, c_heat
    real(wp) :: j_m, j_l, j_1, j_2, m_1, m_2, k_p1, k_p2, c_p1, c_p2
    real(wp) :: k_t1, k_t2, c_t1, c_t2, k_m, c_m, t_d, t_l, omega, grav, l_x, l_y
    integer  :: thermal = thermal_none
    integer  :: dof = 7                     !< 7: bending-torsion, 3: torsional (lateral frozen)
    logical  :: auto = .false.              !< fidelity = auto
    real(wp) :: fidelity_tol = 1.0e-3_wp
    real(wp) :: t_bulk, f_m, u_flash, eta_hertz
    integer  :: method_bdf = 1              !< 1 = BDF, 0 = Adams (CVODE)
    logical  :: erk = .false.               !< ARKODE ERKStep instead of CVODE (spline_integrator)
    !> ERKStep's table: Cash-Karp, else Dormand-Prince
    logical  :: cash_karp = .false.
    logical  :: newton = .true.             !< Newton + dense solver, else fixed-point iteration
    logical  :: roots = .false.
    logical  :: stald = .false.
    logical  :: linear_tail = .true.        !< closed-form tail in proven full contact (spline_linear)
    real(wp) :: rtol, atol
    !> the transient's rtol, atol 1e-2 of it (goal = 'statistics'; 0: the window's rtol, atol)
    real(wp) :: rtol_transient = 0.0_wp
    !> the case's accuracy target (0: none), an error estimate asked for (accuracy or check),
    !> goal = 'statistics' (spline_accuracy)
    real(wp) :: accuracy = 0.0_wp
    logical  :: estimate = .false., goal_statistics = .false.
    real(wp) :: check_div = check_factor    !< the estimate's tighter run: rtol, atol / check_div
    integer  :: max_steps, max_total_steps, n_out
    real(wp) :: t0, t_end, t_transient
    !> realisations = K > 1 (spline_realisations): n_out and t_end are one copy's, the first
    !> n_out / K outputs of the case's (the K copies together span what one run would)
    integer  :: realisations = 1
    logical  :: start_equilibrium = .true.
    real(wp) :: dq0(ndof), dv0(ndof)
    real(wp) :: l_ref, w_ref                !< scales of Eq. 25
    !> reciprocals for the right-hand side (spline_dynamics::accelerations, rhs_scaled):
    !> 1/m_1, 1/m_2, 1/J_1, 1/J_2, 1/J_M, 1/J_L, 1/r_b, 1/w_ref, 1/(l_ref w_ref^2)
    real(wp) :: inv_m1, inv_m2, inv_j1, inv_j2, inv_jm, inv_jl, inv_rb, inv_w_ref, inv_acc_ref
    integer  :: section = 0                 !< Poincare section: 0 none, 1 shaft, 2 tooth pass
    logical  :: lyapunov = .false.          !< largest Lyapunov exponent (Benettin)
    logical  :: lyap_tangent = .false.      !< by the tangent vector (else a separated copy)
    real(wp) :: lyap_dt = 0.0_wp            !< renormalisation interval [s]
    real(wp) :: lyap_d0 = 0.0_wp            !< initial separation (scaled states, Eq. 25)
    ! derived geometry
    real(wp) :: r_pitch                     !< R = m Z / 2
    real(wp) :: cos_alpha, sin_alpha        !< of the pressure angle (once per case, not per tooth)
    real(wp) :: r_b                         !< base radius R cos(alpha)
    real(wp) :: theta0                      !< pi / (2 Z)  (Eq. 9)
    real(wp) :: sin_pitch, cos_pitch        !< of the pitch angle 2 pi / Z (Eqs. 8-9, once per case)
    !> cos and sin of tooth j's offset (j - 1) 2 pi / Z from tooth 1 (0 beyond z): the
    !> right-hand side's kernel (spline_mesh::mesh_forces)
    real(wp) :: cos_offset(max_teeth) = 0.0_wp, sin_offset(max_teeth) = 0.0_wp
    real(wp) :: kappa                       !< 2 lambda s cos(alpha): backlash loss per degC (Eq. 2)
    real(wp) :: c_bulk                      !< backlash with the bulk rise only [m]
    logical  :: k_m_computed = .false.      !< k_m from Eq. 18 (the case left k_m = 0)
    real(wp) :: k_terms(nkterms) = 0.0_wp   !< Eq. 18 terms k_h, k_b1, ..., k_m (0: not computable)
    real(wp) :: k_m_nofillet = 0.0_wp       !< Eq. 18 without the fillet foundation (warnings)
    ! beyond the paper (docs/model.md section 11; docs/model.md)
    real(wp) :: zeta_m = 0.0_wp             !< mesh damping ratio (c_m from it when > 0)
    real(wp) :: m_e = 0.0_wp                !< effective torsional mass of a tooth pair [kg]
    integer  :: n_ripple = 0                !< torque-ripple terms in use
    real(wp) :: ripple_order(nripple) = 0.0_wp, ripple_amp(nripple) = 0.0_wp
    real(wp) :: ripple_phase(nripple) = 0.0_wp     !< [rad]
    real(wp) :: unbalance(2) = 0.0_wp       !< m_u e of splines 1, 2 [kg m]
    real(wp) :: unbalance_phase(2) = 0.0_wp !< [rad]
    real(wp) :: gamma_x = 0.0_wp, gamma_y = 0.0_wp  !< angular misalignment of spline 1 [rad]
    integer  :: n_slices = 1                !< face-width slices
    !> tooth spacing (index) errors e_j of spline 1 [m] (0 beyond z), and whether any is nonzero
    real(wp) :: spacing_error(max_teeth) = 0.0_wp
    logical  :: spacing = .false.
    !> not a case field: a call's wall-time bound [s] over all its runs (0: none) and the
    !> system_clock count it counts from (spline_api's unpack sets them for api_simulate and
    !> api_start_state; spline_integrator::integrator_open)
    real(wp) :: max_seconds = 0.0_wp
    integer(8) :: wall_start = 0
  end type model_t

contains

  !> Build the model of a case: validate it, derive the geometry (docs/model.md section 2, Eq. 9),
  !> the mesh stiffness (Eq. 18; used when the case leaves k_m = 0), the thermal constants
  !> (Eq. 2) and the scales of Eq. 25. ierr: err_case (bad field) or err_thermal (the bulk
  !> temperature alone closes the backlash).
  subroutine model_from_case(c, m, ierr, errmsg)
    type(case_t), intent(in) :: c
    type(model_t), intent(out) :: m
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp) :: rf1, rf2, ra2, rho_f, r_bore, r_rim
    integer :: j, k

    call case_validate(c, ierr, errmsg)
    if (ierr /= err_ok) return

    m%name = c%name
    m%z = c%z; m%m_n = c%module_m; m%alpha = c%alpha_deg*pi/180.0_wp; m%b = c%b; m%s = c%s
    m%c0 = c%c0; m%e_mod = c%e_mod; m%nu = c%nu; m%lambda_th = c%lambda_th
    m%k_cond = c%k_cond; m%rho = c%rho; m%c_heat = c%c_heat
    m%j_m = c%j_m; m%j_l = c%j_l; m%j_1 = c%j_1; m%j_2 = c%j_2; m%m_1 = c%m_1; m%m_2 = c%m_2
    m%k_p1 = c%k_p1; m%k_p2 = c%k_p2; m%c_p1 = c%c_p1; m%c_p2 = c%c_p2
    m%k_t1 = c%k_t1; m%k_t2 = c%k_t2; m%c_t1 = c%c_t1; m%c_t2 = c%c_t2
    m%k_m = c%k_m; m%c_m = c%c_m; m%t_d = c%t_d; m%t_l = c%t_l
    m%omega = c%speed_rpm*2.0_wp*pi/60.0_wp; m%grav = c%grav; m%l_x = c%l_x; m%l_y = c%l_y
    m%t_bulk = c%t_bulk; m%f_m = c%f_m; m%u_flash = c%u_flash; m%eta_hertz = c%eta_hertz
    m%rtol = c%rtol; m%atol = c%atol; m%max_steps = c%max_steps
    m%max_total_steps = c%max_total_steps
    m%t0 = c%t0      ! t_end, t_transient, n_out: as given, or from the shaft revolutions
    call case_run_times(c, m%t_end, m%t_transient, m%n_out)
    m%realisations = c%realisations
    if (m%realisations > 1) then
      m%t_end = m%t0 + m%t_transient + (m%t_end - m%t0 - m%t_transient)* &
           (m%n_out/m%realisations - 1)/real(m%n_out - 1, wp)
      m%n_out = m%n_out/m%realisations
    end if
    m%roots = c%roots; m%stald = c%stald; m%linear_tail = c%linear_tail; m%dq0 = c%dq0; m%dv0 = c%dv0
    m%dof = c%dof; m%fidelity_tol = c%fidelity_tol
    m%auto = option_index(fidelity_values, c%fidelity) == 2
    k = chosen_method(c)        ! the integrator, roots and tolerances an accuracy or goal picks
    call accuracy_settings(c, k, m%roots, m%rtol, m%atol, m%rtol_transient, m%check_div)
    m%accuracy = c%accuracy; m%goal_statistics = option_index(goal_values, c%goal) == 2
    m%estimate = (c%accuracy > 0.0_wp .or. c%check) .and. .not. m%goal_statistics
    m%method_bdf = merge(1, 0, k == 1)
    m%erk = k == 3
    m%cash_karp = m%goal_statistics .or. option_index(erk_table_values, c%erk_table) == 2
    select case (option_index(nonlinear_values, c%nonlinear))
    case (1)
      m%newton = .true.
    case (2)
      m%newton = .false.
    case default                  ! auto: Newton for BDF (stiff), fixed-point for Adams
      m%newton = m%method_bdf == 1
    end select
    m%start_equilibrium = option_index(start_values, c%start) == 1
    m%section = option_index(section_values, c%section) - 1
    m%lyapunov = c%lyapunov
    m%lyap_tangent = option_index(lyapunov_method_values, c%lyapunov_method) == 2
    m%lyap_d0 = lyapunov_separation(c%lyapunov_d0, m%rtol)
    if (m%omega > 0.0_wp) m%lyap_dt = c%lyapunov_interval*2.0_wp*pi/m%omega

    ! geometry (docs/model.md sections 2 and 12, Eq. 9)
    call iso4156_radii(m%z, m%m_n, m%r_pitch, rf1, rf2, ra2)
    m%cos_alpha = cos(m%alpha)
    m%sin_alpha = sin(m%alpha)
    m%r_b = m%r_pitch*m%cos_alpha
    m%theta0 = pi/(2.0_wp*m%z)
    call pitch_rotation(m%z, m%sin_pitch, m%cos_pitch)
    m%cos_offset(1:m%z) = [(cos((j - 1)*2.0_wp*pi/m%z), j = 1, m%z)]
    m%sin_offset(1:m%z) = [(sin((j - 1)*2.0_wp*pi/m%z), j = 1, m%z)]

    ! Eq. 18 at the pitch point, with the fillet-foundation terms k_f1, k_f2 (Sainsot 2004)
    ! when the case counts them: always reported; used if the case leaves k_m = 0. The fillet
    ! geometry: root fillet radius 0.2 m (ISO 4156 flat root), the external spline's bore at
    ! half its root radius, the internal spline's rim at twice its root radius, unless given.
    rho_f = c%fillet_radius
    if (rho_f == 0.0_wp) rho_f = 0.2_wp*m%m_n
    r_bore = c%r_bore
    if (r_bore == 0.0_wp) r_bore = 0.5_wp*rf1
    r_rim = c%r_rim
    if (r_rim == 0.0_wp) r_rim = 2.0_wp*rf2
    call spline_mesh_stiffness_fillet(real(m%z, wp), m%m_n, m%alpha, m%b, m%e_mod, m%nu, rf1, rf2, &
         ra2, rho_f, rho_f, r_bore, r_rim, c%fillet, stiffness_nquad, m%k_terms(1), m%k_terms(2), &
         m%k_terms(3), m%k_terms(4), m%k_terms(5), m%k_terms(6), m%k_terms(7), m%k_terms(8), &
         m%k_terms(9), m%k_terms(10), ierr, errmsg)
    if (ierr == err_ok) then        ! Eq. 18 without the fillet terms (k_f1 = k_f2 = 0 when off)
      m%k_m_nofillet = 1.0_wp/(1.0_wp/m%k_terms(1) + 1.0_wp/m%k_terms(2) + 1.0_wp/m%k_terms(3) &
           + 1.0_wp/m%k_terms(4) + 1.0_wp/m%k_terms(6) + 1.0_wp/m%k_terms(7) + 1.0_wp/m%k_terms(8))
    end if
    if (ierr /= err_ok) then
      m%k_terms = 0.0_wp
      if (c%k_m == 0.0_wp) then
        errmsg = 'case '//trim(m%name)//': field k_m = 0 asks for the potential-energy stiffness '// &
             '(Eq. 18), which fails for this geometry: '//trim(errmsg)//'; set k_m in N/m '// &
             '(or fillet = .false., fillet_radius, r_bore, r_rim)'
        ierr = err_case; return
      end if
      ierr = err_ok
    end if
    if (c%k_m == 0.0_wp) then
      m%k_m = m%k_terms(ik_m)
      m%k_m_computed = .true.
    end if

    ! mesh damping as a ratio: c_m = 2 zeta_m sqrt(k_m m_e), with the tooth pair's effective
    ! torsional mass m_e = 1 / (r_b^2 / J_1 + r_b^2 / J_2) (docs/model.md section 11)
    m%m_e = 1.0_wp/(m%r_b**2/m%j_1 + m%r_b**2/m%j_2)
    m%zeta_m = c%zeta_m
    if (c%zeta_m > 0.0_wp) m%c_m = 2.0_wp*c%zeta_m*sqrt(m%k_m*m%m_e)

    ! torque ripple, unbalance, angular misalignment (docs/model.md section 11)
    m%n_ripple = count(c%ripple_amp /= 0.0_wp)
    m%ripple_order(1:m%n_ripple) = pack(c%ripple_order, c%ripple_amp /= 0.0_wp)
    m%ripple_amp(1:m%n_ripple) = pack(c%ripple_amp, c%ripple_amp /= 0.0_wp)
    m%ripple_phase(1:m%n_ripple) = pack(c%ripple_phase_deg, c%ripple_amp /= 0.0_wp)*pi/180.0_wp
    m%unbalance = c%unbalance
    m%unbalance_phase = c%unbalance_phase_deg*pi/180.0_wp
    m%gamma_x = c%gamma_x; m%gamma_y = c%gamma_y
    m%n_slices = c%n_slices

    ! thermal (Eq. 2)
    m%kappa = backlash_coefficient(m%lambda_th, m%s, m%cos_alpha)
    call set_thermal_level(m, option_index(thermal_values, c%thermal) - 1)
    if (m%c_bulk <= 0.0_wp) then
      write(errmsg, '(a,es10.3,a,es10.3,a)') 'case '//trim(m%name)//': thermal interference: '// &
           't_bulk = ', m%t_bulk, ' degC closes the backlash (c = ', m%c_bulk, ' m, Eq. 2)'
      ierr = err_thermal
      return
    end if

    ! tooth spacing errors (docs/model.md section 11): the list plus the seeded random ones;
    ! each part is below c0 (case check), the sum must keep both gaps at c0 and at the bulk
    ! temperature's backlash c_bulk (Eq. 2) too
    m%spacing_error = c%spacing_error
    if (c%spacing_error_amp > 0.0_wp) m%spacing_error(1:m%z) = m%spacing_error(1:m%z) + &
         random_spacing_errors(m%z, c%spacing_error_amp, c%spacing_error_seed)
    m%spacing = any(m%spacing_error /= 0.0_wp)
    if (maxval(abs(m%spacing_error(1:m%z))) >= min(m%c0, m%c_bulk)) then
      write(errmsg, '(a,i0,a,es10.3,a,es10.3,a)') 'case '//trim(m%name)//': field spacing_error(', &
           maxloc(abs(m%spacing_error(1:m%z)), dim=1), ') is not smaller in magnitude than the '// &
           'backlash (c0, or at the bulk temperature): |e_j| = ', &
           maxval(abs(m%spacing_error(1:m%z))), ' m (with spacing_error_amp), c = ', &
           min(m%c0, m%c_bulk), ' m (Eq. 2)'
      ierr = err_case
      return
    end if

    ! scales of Eq. 25
    m%l_ref = c%l_ref
    if (m%l_ref == 0.0_wp) m%l_ref = m%c0
    m%w_ref = c%w_ref
    if (m%w_ref == 0.0_wp) m%w_ref = m%omega
    if (m%w_ref == 0.0_wp) m%w_ref = sqrt(max(m%k_p1, m%k_m)/m%m_1)
    m%inv_m1 = 1.0_wp/m%m_1; m%inv_m2 = 1.0_wp/m%m_2
    m%inv_j1 = 1.0_wp/m%j_1; m%inv_j2 = 1.0_wp/m%j_2
    m%inv_jm = 1.0_wp/m%j_m; m%inv_jl = 1.0_wp/m%j_l
    m%inv_rb = 1.0_wp/m%r_b; m%inv_w_ref = 1.0_wp/m%w_ref
    m%inv_acc_ref = 1.0_wp/(m%l_ref*m%w_ref**2)
    m%magic = model_magic
    errmsg = ''
    ierr = err_ok

  contains

    !> Random tooth spacing errors, the same numbers on every compiler (docs/model.md section
    !> 11): MINSTD (Park & Miller 1993), x <- 48271 x mod (2^31 - 1) from x = seed, in 64-bit
    !> integers (no overflow); 8 draws discarded, then u_j = x/(2^31 - 1) for teeth 1 .. z,
    !> d_j = 2 u_j - 1, the mean taken off, scaled so that the largest |e_j| is amp.
    pure function random_spacing_errors(z, amp, seed) result(e)
      integer, intent(in) :: z, seed
      real(wp), intent(in) :: amp
      real(wp) :: e(z)
      integer(int64), parameter :: mod31 = 2147483647_int64
      integer(int64) :: x
      integer :: j
      x = int(seed, int64)
      do j = 1, 8
        x = mod(48271_int64*x, mod31)
      end do
      do j = 1, z
        x = mod(48271_int64*x, mod31)
        e(j) = 2.0_wp*(real(x, wp)/real(mod31, wp)) - 1.0_wp
      end do
      e = e - sum(e)/z
      e = e*(amp/maxval(abs(e)))
    end function random_spacing_errors
  end subroutine model_from_case

  !> Warnings about a valid model (ran, but deserves a second look), one per line ('' if
  !> none), each naming the fields, the number and the limit (docs/model.md section 12,
  !> "Plausibility warnings"): a given k_m far below the potential-energy stiffness of the
  !> geometry (Eq. 18), supports that take most of the offset, a shaft wound up beyond
  !> windup_limit, a start at rest with teeth overlapping, a tooth deflected beyond
  !> deflection_limit of the module. The executable prints them to stderr, Python raises
  !> pyspline.SplineWarning (api_load_file's and api_load_fields' warn). start: the start
  !> warning, spline_mesh::start_warning (Eq. 11 lives in spline_mesh, which uses this module).
  !> A subroutine, as every text builder of the core (docs/developing.md, "Thread safety").
  subroutine model_warnings(m, start, text)
    type(model_t), intent(in) :: m
    character(len=*), intent(in) :: start
    character(len=:), allocatable, intent(out) :: text
    text = ''
    if (.not. m%k_m_computed .and. m%k_m_nofillet > 0.0_wp) then
      if (m%k_m*k_m_warn_ratio < m%k_m_nofillet) then
        text = text//'case '//trim(m%name)//': field k_m = '//ftoa(m%k_m, '(es10.3)')//' N/m is '// &
             ftoa(m%k_m_nofillet/m%k_m, '(es8.1)')//' times below the potential-energy mesh '// &
             'stiffness of this geometry (Eq. 18: '//ftoa(m%k_m_nofillet, '(es10.3)')//' N/m): a '// &
             'unit slip (N/mm for N/m)? Run as given'//new_line('a')
      end if
    end if
    call support_warning(m, text)
    call windup_warning(m, text)
    text = text//start
    call load_warning(m, text)
    call separation_warning(m, text)
  end subroutine model_warnings

  !> Benettin's separated copy with a given lyapunov_d0 below the default's (lyapunov_separation)
  !> where the copy's contact switches are not located for it: roots off (a switch falls inside
  !> a step). There a small d0 reads nonsense: 11-82 1/s at d0 = rtol and rtol / 10 on a drive
  !> whose exponent is -1.8 1/s (tests/test_chaos.py). ERK with roots locates the copy's too
  !> (spline_solver::settle_roots: d0 = 1e-8 and 1e-9 read CVODE's -1.8).
  subroutine separation_warning(m, text)
    type(model_t), intent(in) :: m
    character(len=:), allocatable, intent(inout) :: text
    real(wp) :: d
    if (.not. m%lyapunov .or. m%lyap_tangent .or. m%roots) return
    d = lyapunov_separation(0.0_wp, m%rtol)
    if (m%lyap_d0 >= d) return
    text = text//'case '//trim(m%name)//': field lyapunov_d0 = '//num(m%lyap_d0, readable=.true.)// &
         ' is below the default separation '//num(d, readable=.true.)//' (1e4 rtol) with '// &
         'roots = .false.: the separated copy '// &
         'does not see its own contact switches and can read nonsense (+11 to +82 1/s '// &
         'measured for a true -1.8 1/s); lyapunov_d0 = 0 or lyapunov_method = ''tangent''? '// &
         'Run as given'//new_line('a')
  end subroutine separation_warning

  !> Supports too soft for the offset to reach the teeth. Under torque every tooth is on its
  !> drive flank and the mesh resists a lateral offset from zero, the backlash taken up by the
  !> twist, with K = sum_j k_m sin^2(phi_j) = Z k_m / 2 (Eqs. 11, 19-21) in series with the
  !> supports' k_s = k_p1 k_p2 / (k_p1 + k_p2) (Eq. 23): the offset left at the mesh is
  !> e = |l| k_s / (K + k_s) (docs/model.md section 11, static full contact). What decides the
  !> load sharing is e against the static tooth deflection delta = F0 / k_m, F0 = |T_d| / (Z r_b):
  !> the tooth loads are F0 (1 + (e / delta) sin(phi_j - psi)) while e <= delta (load-sharing
  !> factor 1 + e / delta), and teeth unload beyond it. Warned when the offset would unload teeth
  !> on rigid supports, |l| > delta, but the supports leave e <= support_limit delta (not with a
  !> floating spline, k_p = 0, frozen lateral motion, dof = 3, or no drive torque).
  subroutine support_warning(m, text)
    type(model_t), intent(in) :: m
    character(len=:), allocatable, intent(inout) :: text
    real(wp) :: l, k_mesh, k_s, e, delta
    character(len=:), allocatable :: alone
    l = hypot(m%l_x, m%l_y)
    if (m%dof /= 7 .or. min(m%k_p1, m%k_p2) <= 0.0_wp .or. m%t_d == 0.0_wp) return
    k_mesh = m%z*m%k_m/2.0_wp
    k_s = 1.0_wp/(1.0_wp/m%k_p1 + 1.0_wp/m%k_p2)
    e = l*k_s/(k_mesh + k_s)
    delta = static_tooth_load(m)/m%k_m
    if (l <= delta .or. e > support_limit*delta) return
    alone = ''
    if (m%spacing) alone = ' from the misalignment alone (the spacing errors add their own)'
    text = text//'case '//trim(m%name)//': fields k_p1 = '//num(m%k_p1, readable=.true.)// &
         ', k_p2 = '//num(m%k_p2, readable=.true.)//' N/m: the supports (in series '// &
         num(k_s, readable=.true.)//' N/m, the mesh Z k_m / 2 = '// &
         num(k_mesh, readable=.true.)//' N/m) leave e = '//num(e, readable=.true.)// &
         ' m of the offset |l| = '//num(l, readable=.true.)//' m at the mesh, '// &
         num(100.0_wp*e/delta, readable=.true.)// &
         ' % of the static tooth deflection |T_d| / (Z r_b k_m) = '// &
         num(delta, readable=.true.)//' m (limit '//itoa(nint(100.0_wp*support_limit))// &
         ' %): the teeth barely see the misalignment: it raises the static load-sharing '// &
         'factor to 1 + e / delta = '//num(1.0_wp + e/delta, readable=.true.)//alone// &
         '. Run as given'//new_line('a')
  end subroutine support_warning

  !> Static wind-up of the shafts, T_d / k_t1 and T_L / k_t2, above windup_limit (not for a
  !> free shaft, k_t = 0).
  subroutine windup_warning(m, text)
    type(model_t), intent(in) :: m
    character(len=:), allocatable, intent(inout) :: text
    character(len=:), allocatable :: shafts
    shafts = ''
    call shaft('k_t1', m%k_t1, 't_d', m%t_d)
    call shaft('k_t2', m%k_t2, 't_l', m%t_l)
    if (len(shafts) > 0) text = text//'case '//trim(m%name)//': '//shafts//' (limit '// &
         ftoa(windup_limit, '(f4.2)')//' rad = '//ftoa(windup_limit*180.0_wp/pi, '(f4.1)')// &
         ' deg): shafts this soft? Run as given'//new_line('a')
  contains
    subroutine shaft(kname, k, tname, t)
      character(len=*), intent(in) :: kname, tname
      real(wp), intent(in) :: k, t
      if (k <= 0.0_wp .or. abs(t) <= windup_limit*k) return
      if (len(shafts) > 0) shafts = shafts//'; '
      shafts = shafts//'field '//kname//' = '//num(k, readable=.true.)// &
           ' N m/rad winds its shaft '//num(abs(t)/k, readable=.true.)//' rad under '// &
           tname//' = '//num(t, readable=.true.)//' N m'
    end subroutine shaft
  end subroutine windup_warning

  !> The static tooth load T / (Z r_b) of the larger torque, all teeth sharing it, deflects a
  !> tooth by that load over the geometry's Eq. 18 stiffness (whatever k_m the case gives):
  !> above deflection_limit of the module no steel tooth carries it.
  subroutine load_warning(m, text)
    type(model_t), intent(in) :: m
    character(len=:), allocatable, intent(inout) :: text
    real(wp) :: t, f, k, d
    character(len=3) :: tname
    k = m%k_terms(ik_m)
    if (k <= 0.0_wp) return
    t = m%t_d; tname = 't_d'
    if (abs(m%t_l) > abs(t)) then
      t = m%t_l; tname = 't_l'
    end if
    f = static_tooth_load(m, t)
    d = f/k
    if (d <= deflection_limit*m%m_n) return
    text = text//'case '//trim(m%name)//': field '//tname//' = '//num(t, readable=.true.)// &
         ' N m loads each tooth with '//num(f, readable=.true.)// &
         ' N (T / (Z r_b)) and deflects it '//num(d, readable=.true.)//' m (Eq. 18: '// &
         num(k, readable=.true.)//' N/m), '//num(100.0_wp*d/m%m_n, readable=.true.)// &
         ' % of the module (limit '// &
         itoa(nint(100.0_wp*deflection_limit))//' %): a torque in N mm? Run as given'//new_line('a')
  end subroutine load_warning

  !> |T| / (Z r_b): the load of each tooth when the Z teeth share the torque T equally (the
  !> static, aligned mesh of Eq. 22) [N]; T: the driving torque T_d unless given.
  pure real(wp) function static_tooth_load(m, t) result(f0)
    type(model_t), intent(in) :: m
    real(wp), intent(in), optional :: t
    f0 = abs(m%t_d)
    if (present(t)) f0 = abs(t)
    f0 = f0/(m%z*m%r_b)
  end function static_tooth_load

  !> The integrator of a case, as its position in method_values (1 bdf, 2 adams, 3 erk): the
  !> case's, or for method = 'auto' the one that won on the shipped scenes at their own settings
  !> (docs/running.md section 2). With the stiff mesh of Eq. 18 (k_m = 0): ERK from
  !> rest (the teeth take up the backlash with hundreds of impacts, and a one-step method
  !> restarts at each for nothing); BDF from equilibrium in one face slice (slices switch one by
  !> one, and each switch restarts BDF at order 1). Adams with a given (calibrated) k_m, and from
  !> rest with Benettin's separated copy (lyapunov_method = 'copy'): chosen when ERK lost the
  !> copy's switches (physical_z24 unbalanced, d0 = 1e-8: +402 1/s against CVODE's -2.2); ERK
  !> keeps them since (spline_solver::settle_roots: -2.18 as CVODE; test_chaos), and is not
  !> cheaper: the same exponents, ERK 15 % faster on physical_z24, 40 % slower on its
  !> unbalanced variant, up to 30 % on chaos_z24 (docs/running.md section 2).
  pure integer function chosen_method(c) result(k)
    type(case_t), intent(in) :: c
    k = option_index(method_values, c%method)
    if (k /= 4) return
    k = 2
    if (c%k_m /= 0.0_wp) return
    if (option_index(start_values, c%start) == 2) then
      if (.not. (c%lyapunov .and. option_index(lyapunov_method_values, c%lyapunov_method) == 1)) k = 3
    else if (c%n_slices == 1) then
      k = 1
    end if
  end function chosen_method

  !> Set the thermal level of a model and the backlash it implies at the bulk temperature:
  !> Eq. 2 with T_B = T_M, or c_0 for the level none.
  pure subroutine set_thermal_level(m, level)
    type(model_t), intent(inout) :: m
    integer, intent(in) :: level
    m%thermal = level
    m%c_bulk = m%c0
    if (level /= thermal_none) m%c_bulk = thermal_backlash(m%c0, m%kappa, m%t_bulk)
  end subroutine set_thermal_level

  !> Benettin's initial separation d0 in the scaled states of Eq. 25: the case's lyapunov_d0, or,
  !> if it is 0, 1e4 rtol within [1e-8, 1e-3]. The copy is integrated beside the reference with
  !> the same steps, so where the right-hand side is smooth, or its contact switches are located
  !> (roots), any d0 gives the exponent. Without roots a switch falls inside a step, which a tiny
  !> separation cannot resolve: d0 = rtol and rtol / 10 then read 11-82 1/s on a drive whose
  !> exponent is -1.8 1/s, while 1e4 rtol reads it right (tests/test_chaos.py; a smaller given
  !> d0 draws separation_warning). The cap keeps d0 e^(lambda T) small against the motion.
  pure real(wp) function lyapunov_separation(d0, rtol) result(d)
    real(wp), intent(in) :: d0, rtol
    d = d0
    if (d == 0.0_wp) d = min(1.0e-3_wp, max(1.0e-8_wp, 1.0e4_wp*rtol))
  end function lyapunov_separation

end module spline_model
