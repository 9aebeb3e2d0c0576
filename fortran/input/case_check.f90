!> Validation of a case (case_validate): every field against its physical range (in its unit,
!> with the reason), the option values, the fields that bound each other and the memory the
!> outputs need. The simple ranges come from the field table (spline_case_type: rule, lo, hi,
!> note), checked in the table's order between the rules of their own, which are written out
!> here; the order of the checks decides which message a case with several faults gets.
module spline_case_check
  use spline_kinds, only: wp, pi, max_teeth
  use spline_errors, only: err_ok, err_case, itoa, num
  use spline_case_type, only: case_t, fields, nfields, field_index, ndof_case, nripple, &
       option_index, case_output_bytes, case_run_times, max_output_bytes, thermal_values, method_values, &
       nonlinear_values, start_values, fidelity_values, jacobian_values, section_values, &
       lyapunov_method_values, goal_values, erk_table_values
  use spline_case_text, only: size_text
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: case_validate

contains

  !> The values of the real fields (kind 'r'), every element, in the field table's order.
  pure function real_values(c) result(x)
    type(case_t), intent(in) :: c
    real(wp), allocatable :: x(:)
    x = [c%module_m, c%alpha_deg, c%b, c%s, c%c0, c%e_mod, c%nu, c%lambda_th, c%k_cond, c%rho, &
         c%c_heat, c%j_m, c%j_l, c%j_1, c%j_2, c%m_1, c%m_2, c%k_p1, c%k_p2, c%c_p1, c%c_p2, &
         c%k_t1, c%k_t2, c%c_t1, c%c_t2, c%k_m, c%c_m, c%t_d, c%t_l, c%speed_rpm, c%grav, &
         c%l_x, c%l_y, c%t_bulk, c%f_m, c%u_flash, c%eta_hertz, c%rtol, c%atol, c%accuracy, &
         c%t0, c%t_end, &
         c%t_transient, c%revolutions, c%transient_revolutions, c%outputs_per_revolution, &
         c%dq0, c%dv0, c%l_ref, c%w_ref, c%fidelity_tol, c%lyapunov_interval, c%lyapunov_d0, &
         c%fillet_radius, c%r_bore, c%r_rim, c%zeta_m, c%ripple_order, &
         c%ripple_amp, c%ripple_phase_deg, c%unbalance, c%unbalance_phase_deg, c%gamma_x, &
         c%gamma_y, c%spacing_error, c%spacing_error_amp]
  end function real_values

  !> Check every field (see the module's comment). ierr = err_case with a message naming
  !> the case, the field and why.
  subroutine case_validate(c, ierr, errmsg)
    type(case_t), intent(in) :: c
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp), allocatable :: x(:)
    integer :: at(nfields + 1)    ! field f's values: x(at(f) : at(f + 1) - 1)
    real(wp) :: r_pitch, depth, involute, e, ta, dt_out, bytes, t_end, t_transient
    character(len=:), allocatable :: nout_name
    character(len=120) :: nout_is
    type(case_t) :: dflt          ! the defaults (component defaults of case_t)
    integer :: i, f, beyond, i_dq0, i_dv0, n_out

    ierr = err_case
    errmsg = ''
    x = real_values(c)
    at(1) = 1
    do f = 1, nfields
      at(f + 1) = at(f) + merge(fields(f)%n, 0, fields(f)%kind == 'r')
    end do
    if (size(x) /= at(nfields + 1) - 1) then
      errmsg = 'spline_case_check: real_values does not list the real fields of the table'; return
    end if
    beyond = field_index('fillet')       ! the fields beyond the paper: from fillet on
    i_dq0 = field_index('dq0'); i_dv0 = field_index('dv0')
    ! the paper's fields finite, in the table's order but for dq0 and dv0, after w_ref (the
    ! order the messages have always had); an array by the sum of its magnitudes
    do f = 1, beyond - 1
      if (fields(f)%kind /= 'r' .or. f == i_dq0 .or. f == i_dv0) cycle
      if (.not. finite(f)) return
      if (fields(f)%name /= 'w_ref') cycle
      if (.not. finite(i_dq0)) return
      if (.not. finite(i_dv0)) return
    end do

    ! geometry (ISO 4156 and beyond it, with margin)
    if (c%z < 3) then; call fail('z', 'must be at least 3 teeth'); return; end if
    if (c%z > max_teeth) then
      call fail('z', 'is more than '//itoa(max_teeth)//' teeth (the largest spline the tooth-angle recurrence is '// &
           'checked for)'); return
    end if
    if (.not. ranges('module_m', 's')) return
    if (.not. (c%s < pi*c%module_m)) then
      call fail('s', '= '//num(c%s)//' m is not less than the circular pitch pi module_m = '// &
           num(pi*c%module_m)//' m (module_m = '//num(c%module_m)//' m): the mating tooth would '// &
           'have no thickness left'); return
    end if
    if (.not. ranges('c0', 'c0')) return
    if (.not. (c%c0 < pi*c%module_m - c%s)) then
      call fail('c0', '= '//num(c%c0)//' m is not less than the tooth space pi module_m - s = '// &
           num(pi*c%module_m - c%s)//' m (module_m = '//num(c%module_m)//' m, s = '//num(c%s)// &
           ' m): no tooth fits the gap'); return
    end if
    ! material, drive
    if (.not. ranges('e_mod', 'grav')) return

    ! misalignment: the teeth overlap radially over one module (ISO 4156: external major
    ! m (Z + 1), internal minor m (Z - 1)), and the contact point must stay on the involute,
    ! above the base circle: a shift Delta moves it to about R - Delta cos(alpha) (Eq. 13), which
    ! reaches r_b = R cos(alpha) at Delta = R (1 / cos(alpha) - 1)
    r_pitch = 0.5_wp*c%module_m*c%z
    depth = c%module_m
    involute = r_pitch*(1.0_wp/cos(c%alpha_deg*pi/180.0_wp) - 1.0_wp)
    e = hypot(c%l_x, c%l_y)
    if (.not. (e < min(depth, involute, r_pitch))) then
      call fail('l_x', '= '//num(c%l_x)//' m, l_y = '//num(c%l_y)//' m: a misalignment of '// &
           num(e)//' m must be less than '//num(min(depth, involute))//' m, the smaller of the '// &
           'tooth overlap (one module) and the shift that moves the contact point to the base '// &
           'circle, R (1/cos alpha - 1) (pitch radius R = m Z / 2 = '//num(r_pitch)//' m)'); return
    end if

    ! thermal, solver tolerances
    if (.not. ranges('t_bulk', 'atol')) return
    if (.not. ranges('accuracy', 'accuracy')) return
    if (c%max_steps < 1) then; call fail('max_steps', 'must be at least 1'); return; end if
    if (c%max_total_steps < 1) then
      call fail('max_total_steps', 'must be at least 1'); return
    end if

    ! times, given in seconds and n_out or in shaft revolutions (case_run_times: a revolution
    ! field wins over its time field; its messages name it)
    if (.not. ranges('t0', 't0')) return
    if (.not. ranges('revolutions', 'outputs_per_revolution')) return
    do f = field_index('revolutions'), field_index('outputs_per_revolution')
      if (x(at(f)) > 0.0_wp .and. .not. (c%speed_rpm > 0.0_wp)) then
        call fail(trim(fields(f)%name), '= '//num(x(at(f)))//' needs a positive speed_rpm '// &
             '(it counts shaft revolutions); give the run in seconds at speed_rpm = 0'); return
      end if
    end do
    call case_run_times(c, t_end, t_transient, n_out)
    if (c%revolutions > 0.0_wp) then
      if (.not. (t_end <= fields(field_index('t_end'))%hi)) then
        call fail('revolutions', '= '//num(c%revolutions)//' at speed_rpm = '//num(c%speed_rpm)// &
             ' ends at t_end = '//num(t_end)//' s, beyond '// &
             num(fields(field_index('t_end'))%hi)//' s (the tooth angle omega t keeps its '// &
             'digits within 1e6 s)'); return
      end if
      if (.not. (t_end - c%t0 >= 1.0e-9_wp)) then
        call fail('revolutions', '= '//num(c%revolutions)//' at speed_rpm = '// &
             num(c%speed_rpm)//' lasts '//num(t_end - c%t0)//' s: a run lasts at least 1e-9 s')
        return
      end if
    else
      if (.not. (c%t_end > c%t0)) then; call fail('t_end', 'must be greater than t0'); return; end if
      if (.not. ranges('t_end', 't_end')) return
      if (.not. (c%t_end - c%t0 >= 1.0e-9_wp)) then
        call fail('t_end', '- t0 = '//num(c%t_end - c%t0)//' s: a run lasts at least 1e-9 s'); return
      end if
    end if
    if (.not. ranges('t_transient', 't_transient')) return
    ta = c%t0 + t_transient
    if (.not. (ta <= t_end)) then
      if (c%transient_revolutions > 0.0_wp) then
        call fail('transient_revolutions', '= '//num(c%transient_revolutions)//' ends after '// &
             't_end = '//num(t_end)//' s: the transient must not pass the end of the run'); return
      else if (c%revolutions > 0.0_wp) then
        call fail('t_transient', '= '//num(c%t_transient)//' s ends after t_end = '// &
             num(t_end)//' s (revolutions = '//num(c%revolutions)//'): t0 + t_transient '// &
             'must not pass t_end'); return
      end if
      call fail('t_transient', '= '//num(c%t_transient)//' s ends after t_end: t0 + t_transient '// &
           'must not pass t_end'); return
    end if
    ! n_out, or outputs_per_revolution where it gives n_out: nout_name, nout_is name it
    nout_name = trim(merge('outputs_per_revolution', 'n_out                 ', &
         c%outputs_per_revolution > 0.0_wp))
    nout_is = '= '//itoa(n_out)
    if (c%outputs_per_revolution > 0.0_wp) then
      nout_is = '= '//num(c%outputs_per_revolution)//' gives n_out = '//itoa(n_out)
      if (n_out > 2000000000) nout_is = '= '//num(c%outputs_per_revolution)//' gives more '// &
           'than 2e9 output times (n_out)'
    end if
    if (n_out < 1) then; call fail('n_out', 'must be at least 1'); return; end if
    if (n_out > 1) then
      if (.not. (ta < t_end)) then
        call fail('t_transient', '= '//num(t_transient)//' s leaves no output window: '// &
             itoa(n_out)//' output times would all be t_end (use n_out = 1, or a shorter '// &
             't_transient)'); return
      end if
      dt_out = (t_end - ta)/real(n_out - 1, wp)
      if (.not. (dt_out > 1.0e3_wp*spacing_of(max(abs(ta), abs(t_end))))) then
        call fail(nout_name, trim(nout_is)//' puts the output times '//num(dt_out)//' s '// &
             'apart, closer than the time resolution at t = '//num(t_end)//' s'); return
      end if
    end if
    do i = 1, ndof_case
      if (abs(c%dq0(i)) > 1.0_wp) then
        call fail('dq0('//itoa(i)//')', '= '//num(c%dq0(i))//' m is outside -1 .. 1 m '// &
             '(a start offset, added to the start displacements)'); return
      end if
      if (abs(c%dv0(i)) > 1.0e3_wp) then
        call fail('dv0('//itoa(i)//')', '= '//num(c%dv0(i))//' m/s is outside -1e3 .. 1e3 m/s '// &
             '(a start velocity offset)'); return
      end if
    end do
    if (.not. ranges('l_ref', 'w_ref')) return
    if (c%dof /= 3 .and. c%dof /= 7) then
      call fail('dof', 'must be 7 (bending-torsion) or 3 (torsional only)'); return
    end if
    if (.not. ranges('fidelity_tol', 'fidelity_tol')) return
    if (.not. one_of(thermal_values, c%thermal, 'thermal')) return
    if (.not. one_of(fidelity_values, c%fidelity, 'fidelity')) return
    if (.not. one_of(method_values, c%method, 'method')) return
    if (.not. one_of(jacobian_values, c%jacobian, 'jacobian')) return
    if (.not. one_of(nonlinear_values, c%nonlinear, 'nonlinear')) return
    if (.not. one_of(start_values, c%start, 'start')) return
    if (.not. one_of(section_values, c%section, 'section')) return
    if (.not. one_of(lyapunov_method_values, c%lyapunov_method, 'lyapunov_method')) return
    if (.not. one_of(goal_values, c%goal, 'goal')) return
    if (.not. one_of(erk_table_values, c%erk_table, 'erk_table')) return
    if (option_index(goal_values, c%goal) == 2 .and. c%accuracy > 0.0_wp) then
      call fail('accuracy', '= '//num(c%accuracy)//' is the error of the trajectory''s tooth '// &
           'forces; goal = ''statistics'' reads statistics, whose error is their standard error: '// &
           'set accuracy = 0 or goal = ''trajectory'''); return
    end if
    if (option_index(goal_values, c%goal) == 2 .and. c%check) then
      call fail('check', '= .true. estimates the error of the trajectory''s tooth forces; goal = '// &
           '''statistics'' does not resolve the trajectory (its statistics carry standard errors): '// &
           'set check = .false. or goal = ''trajectory'''); return
    end if
    if (.not. realisations_ok()) return
    if (.not. ranges('lyapunov_interval', 'lyapunov_d0')) return  ! d0 = 0: chosen from rtol
    if ((c%lyapunov .or. option_index(section_values, c%section) > 1) .and. c%speed_rpm <= 0.0_wp) then
      call fail('speed_rpm', 'must be positive for a Poincare section or a Lyapunov exponent '// &
           '(both are timed by the shaft revolution)'); return
    end if

    ! beyond the paper
    if (.not. finite(field_index('spacing_error'))) return
    if (.not. finite(field_index('spacing_error_amp'))) return
    if (.not. all(ieee_is_finite(x(at(beyond):)))) then
      call fail('fillet_radius', '.. gamma_y (the fields beyond the paper) must be finite numbers')
      return
    end if
    if (.not. in_range(c%fillet_radius, 0.0_wp, c%module_m, 'fillet_radius', &
         'metres, at most one module; 0 = 0.2 m')) return
    if (.not. in_range(c%r_bore, 0.0_wp, 0.5_wp*c%module_m*(c%z - 1.5_wp), 'r_bore', &
         'metres, inside the external root circle; 0 = half its radius')) return
    if (c%r_rim /= 0.0_wp .and. .not. in_range(c%r_rim, 0.5_wp*c%module_m*(c%z + 1.5_wp), &
         100.0_wp*c%module_m*c%z, 'r_rim', 'metres, outside the internal root circle; 0 = twice '// &
         'its radius')) return
    if (.not. ranges('zeta_m', 'zeta_m')) return
    if (c%zeta_m > 0.0_wp .and. c%c_m /= dflt%c_m) then
      call fail('zeta_m', 'and c_m are both given: give the mesh damping one way'); return
    end if
    do i = 1, nripple
      if (.not. field_rule(field_index('ripple_order'), c%ripple_order(i))) return
      if (.not. field_rule(field_index('ripple_amp'), c%ripple_amp(i))) return
    end do
    if (.not. field_rule(field_index('unbalance'), minval(c%unbalance))) return
    if (.not. field_rule(field_index('unbalance'), maxval(c%unbalance))) return
    if (.not. in_range(hypot(c%gamma_x, c%gamma_y), 0.0_wp, c%module_m/c%b, 'gamma_x', &
         'radians: |(gamma_x, gamma_y)| b / 2 must stay within half a module at the face ends')) return
    if (c%n_slices < 1 .or. c%n_slices > 256) then
      call fail('n_slices', '= '//itoa(c%n_slices)//' is outside 1 .. 256'); return
    end if
    if ((c%gamma_x /= 0.0_wp .or. c%gamma_y /= 0.0_wp) .and. c%n_slices < 2) then
      call fail('n_slices', 'must be at least 2 for an angular misalignment (gamma_x, gamma_y): '// &
           'the face is cut into slices'); return
    end if
    if (c%n_slices > 1 .and. option_index(thermal_values, c%thermal) > 2) then
      call fail('n_slices', '> 1 needs thermal = none or bulk: the flash temperature (oneway, '// &
           'coupled) is modelled for a whole tooth'); return
    end if
    ! spacing errors: both flanks of every tooth keep a gap, |e_j| < c0 (the backlash at the
    ! bulk temperature is checked by spline_model::model_from_case); none beyond tooth z
    do i = 1, max_teeth
      if (i > c%z .and. c%spacing_error(i) /= 0.0_wp) then
        call fail('spacing_error('//itoa(i)//')', '= '//num(c%spacing_error(i))//' m is given '// &
             'for a tooth beyond z = '//itoa(c%z)//': list one error per tooth, teeth 1 .. z'); return
      end if
      if (.not. abs(c%spacing_error(i)) < c%c0) then
        call fail('spacing_error('//itoa(i)//')', '= '//num(c%spacing_error(i))//' m is not '// &
             'smaller in magnitude than the backlash c0 = '//num(c%c0)//' m: tooth '//itoa(i)// &
             ' would close a flank''s gap (|e_j| < c_j)'); return
      end if
    end do
    if (.not. (c%spacing_error_amp >= 0.0_wp .and. c%spacing_error_amp < c%c0)) then
      call fail('spacing_error_amp', '= '//num(c%spacing_error_amp)//' m is outside 0 .. c0 = '// &
           num(c%c0)//' m (the largest random spacing error; both flanks keep a gap)'); return
    end if
    if (c%spacing_error_seed < 1 .or. c%spacing_error_seed > 2147483646) then
      call fail('spacing_error_seed', '= '//itoa(c%spacing_error_seed)//' is outside 1 .. 2147483646'); return
    end if

    ! memory, before anything is allocated
    bytes = case_output_bytes(c)
    if (bytes > max_output_bytes) then
      if (c%lyapunov .or. option_index(section_values, c%section) > 1) then
        call fail(nout_name, trim(nout_is)//' with z = '//itoa(c%z)//' teeth, the Poincare '// &
             'section and the Lyapunov record need '//trim(size_text(bytes))//' of memory for the '// &
             'outputs, more than the limit of '//trim(size_text(max_output_bytes))//': lower '// &
             nout_name//' (or shorten the run)'); return
      end if
      call fail(nout_name, trim(nout_is)//' with z = '//itoa(c%z)//' teeth needs '// &
           trim(size_text(bytes))//' of memory for the outputs, more than the limit of '// &
           trim(size_text(max_output_bytes))//': lower '//nout_name); return
    end if
    ierr = err_ok

  contains

    !> realisations = K (spline_realisations): at least 1; K > 1 reads statistics over copies of
    !> the drive whose trajectories differ (goal = 'statistics'), without the Lyapunov exponent (a
    !> property of one trajectory), each copy with at least 2 of the n_out outputs.
    logical function realisations_ok() result(ok)
      ok = .false.
      if (c%realisations < 1) then
        call fail('realisations', '= '//itoa(c%realisations)//' must be at least 1 (the '// &
             'number of perturbed copies the sampling window is split into)'); return
      end if
      if (c%realisations > 1 .and. option_index(goal_values, c%goal) /= 2) then
        call fail('realisations', '= '//itoa(c%realisations)//' runs perturbed copies whose '// &
             'trajectories part: it reads statistics, set goal = ''statistics'' (or '// &
             'realisations = 1 for one trajectory)'); return
      end if
      if (c%realisations > 1 .and. c%lyapunov) then
        call fail('realisations', '= '//itoa(c%realisations)//' with lyapunov = .true.: the '// &
             'exponent is a property of one trajectory; set realisations = 1'); return
      end if
      if (c%realisations > 1 .and. n_out/c%realisations < 2) then   ! K = 1: any n_out
        call fail('realisations', '= '//itoa(c%realisations)//' leaves fewer than 2 of the '// &
             itoa(n_out)//' outputs to each copy: at most '//itoa(max(n_out/2, 1)))
        return
      end if
      ok = .true.
    end function realisations_ok

    logical function finite(g)
      integer, intent(in) :: g
      finite = ieee_is_finite(sum(abs(x(at(g):at(g + 1) - 1))))
      if (.not. finite) call fail(fields(g)%name, 'is not a finite number')
    end function finite

    !> The table's rule of every field from first to last (in the table's order), on each
    !> element of the field's values.
    logical function ranges(first, last)
      character(len=*), intent(in) :: first, last
      integer :: g, k
      ranges = .true.
      do g = field_index(first), field_index(last)
        if (fields(g)%rule == ' ') cycle
        do k = at(g), at(g + 1) - 1
          ranges = field_rule(g, x(k))
          if (.not. ranges) return
        end do
      end do
    end function ranges

    !> The table's rule of field g on the value v (see spline_case_type's field_t).
    !> (The name and note are trimmed for a message only: this runs for every element.)
    logical function field_rule(g, v)
      integer, intent(in) :: g
      real(wp), intent(in) :: v
      field_rule = .true.
      select case (fields(g)%rule)
      case ('p')                            ! positive, within lo .. hi
        field_rule = v > 0.0_wp
        if (.not. field_rule) then
          call fail(fields(g)%name, 'must be positive'); return
        end if
      case ('n')                            ! 0 ('none' or 'computed') or within lo .. hi
        field_rule = v >= 0.0_wp
        if (.not. field_rule) then
          call fail(fields(g)%name, 'must not be negative'); return
        end if
        if (v == 0.0_wp) return
      case ('z')                            ! 0 (chosen by the model) or within lo .. hi
        if (v == 0.0_wp) return
      case (' ')
        return
      end select
      field_rule = v >= fields(g)%lo .and. v <= fields(g)%hi
      if (.not. field_rule) field_rule = in_range(v, fields(g)%lo, fields(g)%hi, fields(g)%name, &
           trim(fields(g)%note))
    end function field_rule

    subroutine fail(field, why)
      character(len=*), intent(in) :: field, why
      errmsg = 'case '//trim(c%name)//': field '//trim(field)//' '//why
    end subroutine fail

    logical function in_range(v, lo, hi, field, unit)
      real(wp), intent(in) :: v, lo, hi
      character(len=*), intent(in) :: field, unit
      in_range = v >= lo .and. v <= hi
      if (.not. in_range) call fail(field, '= '//num(v)//' is outside '//num(lo, 2)//' .. '// &
           num(hi, 2)//' (unit: '//unit//')')
    end function in_range

    logical function one_of(values, value, field)
      character(len=*), intent(in) :: values(:), value, field
      character(len=:), allocatable :: list
      integer :: k
      one_of = option_index(values, value) > 0
      if (one_of) return
      list = trim(values(1))
      do k = 2, size(values)
        if (k == size(values)) then
          list = list//' or '//trim(values(k))
        else
          list = list//', '//trim(values(k))
        end if
      end do
      call fail(field, 'is "'//trim(value)//'": use '//list)
    end function one_of

  end subroutine case_validate

  !> The gap between x and the next double (the time resolution at x).
  pure real(wp) function spacing_of(x)
    real(wp), intent(in) :: x
    spacing_of = spacing(max(x, tiny(1.0_wp)))
  end function spacing_of

end module spline_case_check
