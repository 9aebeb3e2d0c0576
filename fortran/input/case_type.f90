!> The case: its fields (type case_t, whose component defaults are the defaults: the only place
!> they live) and the one table of the fields (name, type, size, unit, description and the
!> simple allowed range that spline_case_check applies). Every field is in SI units (angles in
!> degrees only where the name ends in _deg).
module spline_case_type
  use spline_kinds, only: wp, pi, max_teeth
  implicit none
  private
  public :: case_t, field_t, fields, nfields, field_index, case_field, case_field_meta, &
       case_name_of, option_index, case_output_bytes, case_run_times
  public :: namelen, optlen, nripple, ndof_case, max_case_bytes, max_output_bytes
  public :: thermal_values, method_values, nonlinear_values, start_values, fidelity_values, &
       jacobian_values, section_values, lyapunov_method_values, goal_values, erk_table_values

  integer, parameter :: namelen = 128
  integer, parameter :: nripple = 4         !< torque-ripple orders a case can give
  integer, parameter :: ndof_case = 7       !< entries of dq0, dv0: x1, y1, x2, y2, D1, D2, D3
  integer, parameter :: optlen = 16
  !> Largest case file read [bytes]: a case with every field and comments is ~5 kB.
  integer, parameter :: max_case_bytes = 1048576
  !> Largest memory a run's outputs may take [bytes] (checked before anything is allocated:
  !> case_output_bytes). 8 GiB: a million outputs of a 16-tooth case take 1.3 GB.
  real(wp), parameter :: max_output_bytes = 8.0_wp*1024.0_wp**3
  ! The values of the option fields; spline_model maps each to its position.
  character(len=optlen), parameter :: thermal_values(4) = [character(len=optlen) :: &
       'none', 'bulk', 'oneway', 'coupled']
  character(len=optlen), parameter :: method_values(4) = [character(len=optlen) :: &
       'bdf', 'adams', 'erk', 'auto']
  character(len=optlen), parameter :: nonlinear_values(3) = [character(len=optlen) :: &
       'newton', 'fixedpoint', 'auto']
  character(len=optlen), parameter :: start_values(2) = [character(len=optlen) :: &
       'equilibrium', 'rest']
  character(len=optlen), parameter :: fidelity_values(2) = [character(len=optlen) :: 'given', 'auto']
  character(len=optlen), parameter :: jacobian_values(1) = [character(len=optlen) :: 'dq']
  character(len=optlen), parameter :: section_values(3) = [character(len=optlen) :: &
       'none', 'shaft', 'tooth']
  character(len=optlen), parameter :: goal_values(2) = [character(len=optlen) :: &
       'trajectory', 'statistics']
  character(len=optlen), parameter :: erk_table_values(2) = [character(len=optlen) :: &
       'dormand_prince', 'cash_karp']
  character(len=optlen), parameter :: lyapunov_method_values(2) = [character(len=optlen) :: &
       'copy', 'tangent']

  !> The fields of a case with their defaults: the paper's spline and drive (docs/model.md
  !> section 12). Unit and meaning of each: the table `fields` below (same order).
  type :: case_t
    character(len=namelen) :: name = 'unnamed'
    integer  :: z = 16
    real(wp) :: module_m = 2.0e-3_wp, alpha_deg = 30.0_wp, b = 0.03_wp, s = 3.14e-3_wp
    real(wp) :: c0 = 2.0e-4_wp
    real(wp) :: e_mod = 2.1e11_wp, nu = 0.3_wp, lambda_th = 1.2e-5_wp, k_cond = 46.47_wp
    real(wp) :: rho = 7800.0_wp, c_heat = 481.48_wp
    real(wp) :: j_m = 7.54e-3_wp, j_l = 7.52e-3_wp, j_1 = 3.43e-3_wp, j_2 = 3.73e-3_wp
    real(wp) :: m_1 = 2.0_wp, m_2 = 2.0_wp
    real(wp) :: k_p1 = 5.0e6_wp, k_p2 = 5.0e6_wp, c_p1 = 5.0_wp, c_p2 = 5.0_wp
    real(wp) :: k_t1 = 7.855_wp, k_t2 = 7.856_wp, c_t1 = 0.191_wp, c_t2 = 0.196_wp
    real(wp) :: k_m = 0.0_wp, c_m = 0.053_wp
    real(wp) :: t_d = 30.7_wp, t_l = 30.7_wp, speed_rpm = 6000.0_wp, grav = 9.81_wp
    real(wp) :: l_x = 0.0_wp, l_y = 0.0_wp
    integer  :: dof = 7
    character(len=optlen) :: thermal = 'none'
    real(wp) :: t_bulk = 0.0_wp, f_m = 0.1_wp, u_flash = 0.83_wp, eta_hertz = 1.127_wp
    !> The solver defaults: method 'auto' picks per scene (docs/running.md section 2) what won where
    !> it was measured (docs/running.md, "Impacting scenes, and how the defaults were
    !> chosen"), with located contact switches.
    character(len=optlen) :: method = 'auto', jacobian = 'dq', nonlinear = 'auto'
    !> ERKStep's Butcher table (method = 'erk'; goal = 'statistics' runs its window on 'cash_karp')
    character(len=optlen) :: erk_table = 'dormand_prince'
    logical  :: roots = .true., stald = .false., linear_tail = .true.
    real(wp) :: rtol = 1.0e-8_wp, atol = 1.0e-10_wp
    integer  :: max_steps = 100000, max_total_steps = 20000000
    !> Accuracy as an input (spline_accuracy, docs/accuracy.md): 0 keeps rtol, atol as given.
    real(wp) :: accuracy = 0.0_wp
    character(len=optlen) :: goal = 'trajectory'
    logical  :: check = .false.
    !> goal = 'statistics': perturbed copies after the transient (spline_realisations)
    integer  :: realisations = 1
    real(wp) :: t0 = 0.0_wp, t_end = 0.1_wp, t_transient = 0.0_wp
    integer  :: n_out = 1001
    !> The run in shaft revolutions (0: t_end, t_transient, n_out as given); case_run_times.
    real(wp) :: revolutions = 0.0_wp, transient_revolutions = 0.0_wp
    real(wp) :: outputs_per_revolution = 0.0_wp
    character(len=optlen) :: start = 'equilibrium'
    real(wp) :: dq0(ndof_case) = 0.0_wp, dv0(ndof_case) = 0.0_wp
    real(wp) :: l_ref = 0.0_wp, w_ref = 0.0_wp
    character(len=optlen) :: fidelity = 'given'
    real(wp) :: fidelity_tol = 1.0e-3_wp
    character(len=optlen) :: section = 'none'
    logical  :: lyapunov = .false.
    real(wp) :: lyapunov_interval = 1.0_wp, lyapunov_d0 = 0.0_wp
    character(len=optlen) :: lyapunov_method = 'copy'
    ! beyond the paper (docs/model.md "Beyond the paper"): every field from fillet on
    logical  :: fillet = .true.
    real(wp) :: fillet_radius = 0.0_wp, r_bore = 0.0_wp, r_rim = 0.0_wp, zeta_m = 0.0_wp
    real(wp) :: ripple_order(nripple) = 0.0_wp, ripple_amp(nripple) = 0.0_wp
    real(wp) :: ripple_phase_deg(nripple) = 0.0_wp
    real(wp) :: unbalance(2) = 0.0_wp, unbalance_phase_deg(2) = 0.0_wp
    real(wp) :: gamma_x = 0.0_wp, gamma_y = 0.0_wp
    integer  :: n_slices = 1
    real(wp) :: spacing_error(max_teeth) = 0.0_wp
    real(wp) :: spacing_error_amp = 0.0_wp
    integer  :: spacing_error_seed = 1
  end type case_t

  !> A field of the namelist: name; type (i integer, r real, l logical, c character); size
  !> (elements of an array, or the length of a character field); unit ('' for none, '-' for
  !> a ratio); a one-line description; and the simple range spline_case_check applies to
  !> each element (rule 'r': within lo .. hi; 'p': positive and within lo .. hi; 'n': 0 or
  !> within lo .. hi, and not negative; 'z': 0 or within lo .. hi; ' ': none here, or a rule
  !> of its own there), with the note its message gives. Same order as case_t (the namelist
  !> order; tests/test_input.py checks the table against the defaults and its units against
  !> cases/template.nml; Python reads names, units and descriptions through api_names('fields')).
  type :: field_t
    character(len=24) :: name
    character(len=1) :: kind
    integer :: n
    character(len=20) :: unit = ''
    character(len=72) :: descr = ''
    character(len=1) :: rule = ' '
    real(wp) :: lo = 0.0_wp, hi = 0.0_wp
    character(len=80) :: note = ''
  end type field_t
  integer, parameter :: nfields = 91
  real(wp), parameter :: inf_ = huge(1.0_wp)
  type(field_t), parameter :: fields(nfields) = [ &
       field_t('name', 'c', namelen, '', 'case name, used in messages (default: the file name)'), &
       field_t('z', 'i', 1, '-', 'number of teeth Z'), &
       field_t('module_m', 'r', 1, 'm', 'module m', 'r', 1.0e-4_wp, 0.1_wp, &
               'metres (2 mm is 2e-3; ISO 4156 modules run from 0.25 to 10 mm)'), &
       field_t('alpha_deg', 'r', 1, 'deg', 'pressure angle alpha', 'r', 5.0_wp, 60.0_wp, &
               'degrees (ISO 4156: 30, 37.5 or 45)'), &
       field_t('b', 'r', 1, 'm', 'face width', 'r', 1.0e-4_wp, 10.0_wp, 'metres, a face width'), &
       field_t('s', 'r', 1, 'm', 'tooth thickness', 'r', 1.0e-5_wp, 0.2_wp, &
               'metres, a tooth thickness'), &
       field_t('c0', 'r', 1, 'm', 'nominal backlash c_0', 'r', 1.0e-8_wp, 0.01_wp, &
               'metres (0.2 mm is 2e-4)'), &
       field_t('e_mod', 'r', 1, 'Pa', 'Young''s modulus E', 'r', 1.0e8_wp, 1.0e13_wp, &
               'pascals (steel 2.1e11)'), &
       field_t('nu', 'r', 1, '-', 'Poisson ratio', 'r', 0.0_wp, 0.4999_wp, 'a ratio below 1/2'), &
       field_t('lambda_th', 'r', 1, '1/degC', 'thermal expansion coefficient lambda', 'r', 0.0_wp, &
               1.0e-3_wp, '1/degC (steel 1.2e-5)'), &
       field_t('k_cond', 'r', 1, 'W/(m K)', 'thermal conductivity g', 'p', 1.0e-2_wp, 5.0e3_wp, &
               'W/(m K) (steel 46)'), &
       field_t('rho', 'r', 1, 'kg/m^3', 'density', 'p', 100.0_wp, 3.0e4_wp, 'kg/m^3 (steel 7800)'), &
       field_t('c_heat', 'r', 1, 'J/(kg K)', 'heat capacity c', 'p', 10.0_wp, 1.0e5_wp, &
               'J/(kg K) (steel 480)'), &
       ! drive: inertias from a 1 g ring of 1 mm to a ship's shaft line; masses from 0.1 g to
       ! 100 t; stiffnesses and dampings from 0 (none) to beyond any steel part
       field_t('j_m', 'r', 1, 'kg m^2', 'motor inertia J_M', 'p', 1.0e-9_wp, 1.0e6_wp, 'kg m^2'), &
       field_t('j_l', 'r', 1, 'kg m^2', 'load inertia J_L', 'p', 1.0e-9_wp, 1.0e6_wp, 'kg m^2'), &
       field_t('j_1', 'r', 1, 'kg m^2', 'external spline inertia J_1', 'p', 1.0e-9_wp, 1.0e6_wp, &
               'kg m^2'), &
       field_t('j_2', 'r', 1, 'kg m^2', 'internal spline inertia J_2', 'p', 1.0e-9_wp, 1.0e6_wp, &
               'kg m^2'), &
       field_t('m_1', 'r', 1, 'kg', 'external spline mass m_1', 'p', 1.0e-4_wp, 1.0e5_wp, 'kg'), &
       field_t('m_2', 'r', 1, 'kg', 'internal spline mass m_2', 'p', 1.0e-4_wp, 1.0e5_wp, 'kg'), &
       field_t('k_p1', 'r', 1, 'N/m', 'support stiffness of spline 1, x and y', 'n', 1.0_wp, &
               1.0e12_wp, 'N/m; 0 for no support'), &
       field_t('k_p2', 'r', 1, 'N/m', 'support stiffness of spline 2, x and y', 'n', 1.0_wp, &
               1.0e12_wp, 'N/m; 0 for no support'), &
       field_t('c_p1', 'r', 1, 'N s/m', 'support damping of spline 1', 'n', 0.0_wp, 1.0e7_wp, 'N s/m'), &
       field_t('c_p2', 'r', 1, 'N s/m', 'support damping of spline 2', 'n', 0.0_wp, 1.0e7_wp, 'N s/m'), &
       field_t('k_t1', 'r', 1, 'N m/rad', 'torsional stiffness motor-spline 1', 'n', 1.0e-3_wp, &
               1.0e9_wp, 'N m/rad; 0 for a free shaft'), &
       field_t('k_t2', 'r', 1, 'N m/rad', 'torsional stiffness spline 2-load', 'n', 1.0e-3_wp, &
               1.0e9_wp, 'N m/rad; 0 for a free shaft'), &
       field_t('c_t1', 'r', 1, 'N m s/rad', 'torsional damping motor-spline 1', 'n', 0.0_wp, &
               1.0e6_wp, 'N m s/rad'), &
       field_t('c_t2', 'r', 1, 'N m s/rad', 'torsional damping spline 2-load', 'n', 0.0_wp, &
               1.0e6_wp, 'N m s/rad'), &
       field_t('k_m', 'r', 1, 'N/m', 'mesh stiffness per tooth pair; 0 = computed (Eq. 18)', 'n', &
               1.0e2_wp, 1.0e12_wp, 'N/m per tooth pair; 0 for the computed one, Eq. 18'), &
       field_t('c_m', 'r', 1, 'N s/m', 'mesh damping per tooth pair', 'n', 0.0_wp, 1.0e6_wp, 'N s/m'), &
       field_t('t_d', 'r', 1, 'N m', 'driving torque T_d', 'r', -1.0e7_wp, 1.0e7_wp, &
               'N m (the largest shafts carry ~1e7)'), &
       field_t('t_l', 'r', 1, 'N m', 'load torque T_L', 'r', -1.0e7_wp, 1.0e7_wp, &
               'N m (the largest shafts carry ~1e7)'), &
       field_t('speed_rpm', 'r', 1, 'r/min', 'shaft speed', 'r', 0.0_wp, 1.0e6_wp, &
               'r/min, not negative'), &
       field_t('grav', 'r', 1, 'm/s^2', 'gravity, acting in -y', 'r', -100.0_wp, 100.0_wp, &
               'm/s^2 (Earth 9.81; 0 in orbit)'), &
       field_t('l_x', 'r', 1, 'm', 'parallel misalignment of spline 1 in x'), &
       field_t('l_y', 'r', 1, 'm', 'parallel misalignment of spline 1 in y'), &
       field_t('dof', 'i', 1, '', '7: bending-torsion (Eq. 24) | 3: torsional only'), &
       field_t('thermal', 'c', optlen, '', 'none | bulk | oneway | coupled (Eqs. 1-7)'), &
       field_t('t_bulk', 'r', 1, 'degC', 'bulk temperature rise T_M', 'r', -273.15_wp, 1.0e4_wp, &
               'degC, a rise: not below absolute zero, not beyond 1e4'), &
       field_t('f_m', 'r', 1, '-', 'friction coefficient', 'n', 0.0_wp, 1.0e6_wp, &
               'a friction coefficient (physical: below 1; fitted factors up to 1e6)'), &
       field_t('u_flash', 'r', 1, '-', 'Blok factor u', 'n', 0.0_wp, 10.0_wp, 'Blok''s factor (0.83)'), &
       field_t('eta_hertz', 'r', 1, '-', 'Hertz factor eta', 'p', 1.0e-2_wp, 100.0_wp, &
               'Hertz factor (1.127)'), &
       field_t('method', 'c', optlen, '', 'auto | adams | bdf (CVODE) | erk (ARKODE, order 5)'), &
       field_t('jacobian', 'c', optlen, '', 'dq: dense difference-quotient Jacobian'), &
       field_t('nonlinear', 'c', optlen, '', 'auto (adams: fixedpoint, bdf: newton) | newton | fixedpoint'), &
       field_t('erk_table', 'c', optlen, '', 'erk: dormand_prince (5(4), 7 stages) | cash_karp '// &
               '(5(4), 6 stages)'), &
       field_t('roots', 'l', 1, '', 'locate the contact switches by root finding'), &
       field_t('stald', 'l', 1, '', 'BDF stability-limit detection'), &
       field_t('linear_tail', 'l', 1, '', 'closed-form tail once full contact is proven to last'), &
       field_t('rtol', 'r', 1, '-', 'relative tolerance', 'r', 1.0e-15_wp, 0.1_wp, &
               'a relative tolerance'), &
       field_t('atol', 'r', 1, '-', 'absolute tolerance on the scaled states (Eq. 25)', 'p', &
               1.0e-20_wp, 1.0_wp, &
               'an absolute tolerance on the scaled states of Eq. 25, which are of order 1'), &
       field_t('max_steps', 'i', 1, '', 'CVODE steps allowed between two output times'), &
       field_t('max_total_steps', 'i', 1, '', 'CVODE steps allowed over the whole run'), &
       field_t('accuracy', 'r', 1, '-', 'largest relative error of F_j accepted; 0: rtol, atol as '// &
               'given', 'n', 1.0e-9_wp, 0.1_wp, 'a relative error of the tooth forces (0: rtol '// &
               'and atol as given)'), &
       field_t('goal', 'c', optlen, '', 'trajectory | statistics (cheapest settings, bias under the standard error)'), &
       field_t('check', 'l', 1, '', 'estimate the error of F_j against a tighter run (F_error_est)'), &
       field_t('realisations', 'i', 1, '', 'goal statistics: K perturbed copies after the '// &
               'transient, 1/K window each'), &
       ! times: within a million seconds (11.6 days) of 0, where a double still resolves the
       ! tooth angle omega t to 1e-5 rad at the largest speed
       field_t('t0', 'r', 1, 's', 'start time', 'r', -1.0e6_wp, 1.0e6_wp, &
               's (the tooth angle omega t keeps its digits within 1e6 s)'), &
       field_t('t_end', 'r', 1, 's', 'end time', 'r', -1.0e6_wp, 1.0e6_wp, &
               's (the tooth angle omega t keeps its digits within 1e6 s)'), &
       field_t('t_transient', 'r', 1, 's', 'integrated after t0 but not output', 'n', 0.0_wp, inf_), &
       field_t('n_out', 'i', 1, '', 'number of uniform output times'), &
       field_t('revolutions', 'r', 1, 'rev', 'run after t0 in shaft revolutions; 0 = t_end', 'n', &
               0.0_wp, inf_, 'shaft revolutions, not negative; 0 for t_end'), &
       field_t('transient_revolutions', 'r', 1, 'rev', &
               'transient in shaft revolutions; 0 = t_transient', 'n', 0.0_wp, inf_, &
               'shaft revolutions, not negative; 0 for t_transient'), &
       field_t('outputs_per_revolution', 'r', 1, '1/rev', &
               'output times per shaft revolution; 0 = n_out', 'n', 0.0_wp, inf_, &
               'outputs per shaft revolution, not negative; 0 for n_out'), &
       field_t('start', 'c', optlen, '', 'equilibrium (static, computed) | rest'), &
       field_t('dq0', 'r', ndof_case, 'm', 'added to the start displacements x1 y1 x2 y2 D1 D2 D3'), &
       field_t('dv0', 'r', ndof_case, 'm/s', 'added to the start velocities'), &
       field_t('l_ref', 'r', 1, 'm', 'length scale of Eq. 25; 0 = c0', 'n', 1.0e-9_wp, 1.0_wp, &
               'm, a length scale of the motion; 0 for c0'), &
       field_t('w_ref', 'r', 1, 'rad/s', 'frequency scale of Eq. 25; 0 = shaft speed', 'n', &
               1.0e-3_wp, 1.0e7_wp, 'rad/s, a frequency scale; 0 for the shaft speed'), &
       field_t('fidelity', 'c', optlen, '', 'given | auto (cheapest level within fidelity_tol)'), &
       field_t('fidelity_tol', 'r', 1, '-', 'auto: allowed relative error of T_m and F_j', 'r', &
               1.0e-12_wp, 1.0_wp, 'a relative error'), &
       field_t('section', 'c', optlen, '', 'Poincare section: none | shaft | tooth'), &
       field_t('lyapunov', 'l', 1, '', 'largest Lyapunov exponent (Benettin) over the output window'), &
       field_t('lyapunov_interval', 'r', 1, 'shaft revolutions', 'Benettin renormalisation interval', &
               'r', 1.0e-3_wp, 1.0e3_wp, 'shaft revolutions'), &
       field_t('lyapunov_d0', 'r', 1, '-', 'initial separation, scaled states of Eq. 25; 0: auto', &
               'z', 1.0e-12_wp, 1.0e-3_wp, 'a separation of the scaled states (0: chosen from rtol)'), &
       field_t('lyapunov_method', 'c', optlen, '', 'copy (a separated copy) | tangent (variational '// &
               'equations)'), &
       field_t('fillet', 'l', 1, '', 'fillet-foundation term k_f in a computed k_m'), &
       field_t('fillet_radius', 'r', 1, 'm', 'root fillet radius; 0 = 0.2 module'), &
       field_t('r_bore', 'r', 1, 'm', 'bore radius of the external spline; 0 = half its root radius'), &
       field_t('r_rim', 'r', 1, 'm', 'outer radius of the internal spline''s rim; 0 = twice its root radius'), &
       field_t('zeta_m', 'r', 1, '-', 'mesh damping ratio; > 0: c_m = 2 zeta_m sqrt(k_m m_e)', 'r', &
               0.0_wp, 1.0_wp, 'a damping ratio'), &
       field_t('ripple_order', 'r', nripple, '-', 'torque ripple: engine orders n_k', 'r', 0.0_wp, &
               1000.0_wp, 'engine orders (multiples of the shaft speed)'), &
       field_t('ripple_amp', 'r', nripple, '-', 'torque ripple amplitudes a_k, relative to T_d', 'r', &
               -10.0_wp, 10.0_wp, 'a fraction of T_d'), &
       field_t('ripple_phase_deg', 'r', nripple, 'deg', 'torque ripple phases psi_k'), &
       field_t('unbalance', 'r', 2, 'kg m', 'mass unbalance m_u e of splines 1, 2', 'r', 0.0_wp, &
               1.0_wp, 'kg m (m_u e)'), &
       field_t('unbalance_phase_deg', 'r', 2, 'deg', 'phase beta_i of the unbalance'), &
       field_t('gamma_x', 'r', 1, 'rad', 'angular misalignment of spline 1 about x'), &
       field_t('gamma_y', 'r', 1, 'rad', 'angular misalignment of spline 1 about y'), &
       field_t('n_slices', 'i', 1, '-', 'face-width slices (angular misalignment)'), &
       field_t('spacing_error', 'r', max_teeth, 'm', 'tooth spacing (index) error e_j of spline 1, '// &
               'teeth 1 .. z'), &
       field_t('spacing_error_amp', 'r', 1, 'm', 'largest seeded random spacing error (mean 0); 0: none'), &
       field_t('spacing_error_seed', 'i', 1, '-', 'seed of the random spacing errors, 1 .. 2147483646')]

contains

  !> Field number i of the namelist (1 .. nfields): name, type (i, r, l, c) and size.
  !> An empty name past the end.
  subroutine case_field(i, name, kind, n)
    integer, intent(in) :: i
    character(len=*), intent(out) :: name, kind
    integer, intent(out) :: n
    name = ''; kind = ''; n = 0
    if (i < 1 .or. i > nfields) return
    name = fields(i)%name; kind = fields(i)%kind; n = fields(i)%n
  end subroutine case_field

  !> case_field, and the field's unit ('' none, '-' a ratio) and one-line description.
  subroutine case_field_meta(i, name, kind, n, unit, descr)
    integer, intent(in) :: i
    character(len=*), intent(out) :: name, kind, unit, descr
    integer, intent(out) :: n
    call case_field(i, name, kind, n)
    unit = ''; descr = ''
    if (i < 1 .or. i > nfields) return
    unit = fields(i)%unit; descr = fields(i)%descr
  end subroutine case_field_meta

  !> Position of a field (lower-case name) in the table; 0: no such field. Only names of the
  !> same length are compared (it runs for every word of a case's text, and in validation).
  pure integer function field_index(name) result(f)
    character(len=*), intent(in) :: name
    integer, parameter :: name_len(nfields) = len_trim(fields%name)
    integer :: n
    n = len_trim(name)
    do f = 1, nfields
      if (name_len(f) /= n) cycle
      if (fields(f)%name(1:n) == name(1:n)) return
    end do
    f = 0
  end function field_index

  !> The file name without directory and extension: the case name unless the file sets one.
  pure function case_name_of(path) result(stem)
    character(len=*), intent(in) :: path
    character(len=namelen) :: stem
    integer :: i0, i1
    i0 = index(path, '/', back=.true.) + 1
    i1 = index(path, '.', back=.true.) - 1
    if (i1 < i0) i1 = len_trim(path)
    stem = path(i0:i1)
  end function case_name_of

  !> Position of an option's value in its list of values (0: not among them).
  pure integer function option_index(values, value) result(k)
    character(len=*), intent(in) :: values(:), value
    do k = 1, size(values)
      if (values(k) == value) return
    end do
    k = 0
  end function option_index

  !> Memory a run of the case needs for its outputs [bytes], in floating point (no integer
  !> overflow whatever the sizes): per output time, the time, 14 states, the torque and
  !> Z x 8 per-tooth quantities, twice (the core's arrays and their copies for the caller),
  !> plus the contact states; the Poincare section points (15 numbers each) and the Benettin
  !> record (2 numbers per renormalisation).
  pure real(wp) function case_output_bytes(c) result(bytes)
    type(case_t), intent(in) :: c
    real(wp) :: nt, nsec, nlyap, window, omega, t_end, t_transient
    integer :: n_out
    call case_run_times(c, t_end, t_transient, n_out)
    nt = real(n_out, wp)
    window = max(t_end - c%t0 - t_transient, 0.0_wp)
    omega = c%speed_rpm*2.0_wp*pi/60.0_wp
    nsec = 0.0_wp
    if (option_index(section_values, c%section) == 2) nsec = window*omega/(2.0_wp*pi) + 2.0_wp
    if (option_index(section_values, c%section) == 3) nsec = window*omega*c%z/(2.0_wp*pi) + 2.0_wp
    nlyap = 0.0_wp
    if (c%lyapunov .and. omega > 0.0_wp .and. c%lyapunov_interval > 0.0_wp) &
         nlyap = window*omega/(2.0_wp*pi*c%lyapunov_interval) + 2.0_wp
    bytes = nt*(2.0_wp*8.0_wp*(16.0_wp + 8.0_wp*c%z) + 4.0_wp*c%z) + 2.0_wp*8.0_wp*15.0_wp*nsec &
         + 2.0_wp*8.0_wp*2.0_wp*nlyap
    if (c%n_slices > 1) bytes = bytes + nt*2.0_wp*8.0_wp*(c%z*c%n_slices + 2.0_wp)
  end function case_output_bytes

  !> The run's end time t_end, transient t_transient [s] and number of output times n_out:
  !> the fields themselves, or, where the case gives them in shaft revolutions (a period
  !> 60 / speed_rpm s), t_end = t0 + revolutions period, t_transient = transient_revolutions
  !> period and n_out = outputs_per_revolution R + 1 to the nearest whole number, R the
  !> revolutions of the output window [t0 + t_transient, t_end] (outputs 1/outputs_per_revolution
  !> of a revolution apart when R outputs_per_revolution is whole; capped at 2e9 outputs, which
  !> the memory check refuses). A revolution field wins over its time field. Assumes
  !> speed_rpm > 0 where a revolution field is set (spline_case_check).
  pure subroutine case_run_times(c, t_end, t_transient, n_out)
    type(case_t), intent(in) :: c
    real(wp), intent(out) :: t_end, t_transient
    integer, intent(out) :: n_out
    real(wp) :: period, rev_run, rev_transient
    t_end = c%t_end; t_transient = c%t_transient; n_out = c%n_out
    if (.not. (c%revolutions > 0.0_wp .or. c%transient_revolutions > 0.0_wp .or. &
         c%outputs_per_revolution > 0.0_wp)) return
    period = 60.0_wp/c%speed_rpm
    rev_run = (c%t_end - c%t0)/period
    rev_transient = c%t_transient/period
    if (c%revolutions > 0.0_wp) then
      rev_run = c%revolutions
      t_end = c%t0 + c%revolutions*period
    end if
    if (c%transient_revolutions > 0.0_wp) then
      rev_transient = c%transient_revolutions
      t_transient = c%transient_revolutions*period
    end if
    if (c%outputs_per_revolution > 0.0_wp) &
         n_out = nint(min(c%outputs_per_revolution*max(rev_run - rev_transient, 0.0_wp), 2.0e9_wp)) + 1
  end subroutine case_run_times

end module spline_case_type
