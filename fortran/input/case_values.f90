!> A case's fields as two flat arrays, laid out by the field table (case_field, the order of
!> case_t): every number and logical (an integer as its value, a logical as 1 or 0) in one
!> real array, every character field (blank-padded to its size) in one string. This is how a
!> case crosses to Python and back (fortran/interface/api.f90), with no text to tokenise or re-read, and
!> how the reader (fortran/input/case_parse.f90) assigns each checked value (case_put_value).
module spline_case_values
  use spline_kinds, only: wp
  use spline_errors, only: err_ok, err_case
  use spline_case_type, only: case_t, fields, nfields
  implicit none
  private
  public :: case_value_sizes, case_to_values, case_from_values, case_value_offset, case_put_value

contains

  !> Entries of the real array (nv) and characters of the string (nc) of a case.
  subroutine case_value_sizes(nv, nc)
    integer, intent(out) :: nv, nc
    nv = sum(fields%n, mask=fields%kind /= 'c')
    nc = sum(fields%n, mask=fields%kind == 'c')
  end subroutine case_value_sizes

  !> Where field f (the table's numbering) starts in its array, by walk's layout: the entries
  !> of the real array (types i, r, l) or the characters of the string (type c) that the fields
  !> before it in the same array take.
  pure integer function case_value_offset(f) result(off)
    integer, intent(in) :: f
    integer :: g
    off = 0
    do g = 1, f - 1
      if ((fields(g)%kind == 'c') .eqv. (fields(f)%kind == 'c')) off = off + fields(g)%n
    end do
  end function case_value_offset

  !> Element k of field f, whose entries start after off (case_value_offset), into v or s as
  !> walk encodes it: x a real, i an integer, l a logical (1 or 0), str a string (blank-padded
  !> to the field's size), taken by the field's type.
  pure subroutine case_put_value(v, s, f, off, k, x, i, l, str)
    real(wp), intent(inout) :: v(:)
    character(len=*), intent(inout) :: s
    integer, intent(in) :: f, off, k, i
    real(wp), intent(in) :: x
    logical, intent(in) :: l
    character(len=*), intent(in) :: str
    select case (fields(f)%kind)
    case ('c'); s(off+1:off+fields(f)%n) = str
    case ('i'); v(off+k) = real(i, wp)
    case ('l'); v(off+k) = merge(1.0_wp, 0.0_wp, l)
    case default; v(off+k) = x
    end select
  end subroutine case_put_value

  !> The fields of c into v and s (sized by case_value_sizes).
  subroutine case_to_values(c, v, s)
    type(case_t), intent(in) :: c
    real(wp), intent(out) :: v(:)
    character(len=*), intent(out) :: s
    type(case_t) :: cc
    integer :: ierr
    character(len=80) :: errmsg
    cc = c
    v = 0; s = ''
    call walk(cc, v, s, .true., ierr, errmsg)
  end subroutine case_to_values

  !> A case from v and s (as case_to_values lays them out). ierr = err_case if the arrays do
  !> not match the field table, or an integer field is no 32-bit whole number (Python sends
  !> those as text instead, for the reader's message).
  subroutine case_from_values(v, s, c, ierr, errmsg)
    real(wp), intent(in) :: v(:)
    character(len=*), intent(in) :: s
    type(case_t), intent(out) :: c
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(wp), allocatable :: vv(:)
    character(len=:), allocatable :: ss
    integer :: nv, nc
    c = case_t()
    call case_value_sizes(nv, nc)
    if (size(v) /= nv .or. len(s) /= nc) then
      ierr = err_case
      errmsg = 'case values: the arrays do not match the field table (api_names(''layout''))'
      return
    end if
    vv = v; ss = s
    call walk(c, vv, ss, .false., ierr, errmsg)
  end subroutine case_from_values

  !> Every field of c in the order of the field table, copied to (put) or from the arrays; a
  !> field whose type or size differs from the table's is an error (this list is out of step).
  subroutine walk(c, v, s, put, ierr, errmsg)
    type(case_t), intent(inout) :: c
    real(wp), intent(inout) :: v(:)
    character(len=*), intent(inout) :: s
    logical, intent(in) :: put
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    integer :: k, iv, is
    k = 0; iv = 0; is = 0
    ierr = err_ok; errmsg = ''
    call ch(c%name); call i(c%z); call r(c%module_m); call r(c%alpha_deg); call r(c%b)
    call r(c%s); call r(c%c0); call r(c%e_mod); call r(c%nu); call r(c%lambda_th)
    call r(c%k_cond); call r(c%rho); call r(c%c_heat); call r(c%j_m); call r(c%j_l)
    call r(c%j_1); call r(c%j_2); call r(c%m_1); call r(c%m_2); call r(c%k_p1); call r(c%k_p2)
    call r(c%c_p1); call r(c%c_p2); call r(c%k_t1); call r(c%k_t2); call r(c%c_t1)
    call r(c%c_t2); call r(c%k_m); call r(c%c_m); call r(c%t_d); call r(c%t_l)
    call r(c%speed_rpm); call r(c%grav); call r(c%l_x); call r(c%l_y); call i(c%dof)
    call ch(c%thermal); call r(c%t_bulk); call r(c%f_m); call r(c%u_flash); call r(c%eta_hertz)
    call ch(c%method); call ch(c%jacobian); call ch(c%nonlinear); call ch(c%erk_table)
    call l(c%roots)
    call l(c%stald); call l(c%linear_tail); call r(c%rtol); call r(c%atol); call i(c%max_steps)
    call i(c%max_total_steps); call r(c%accuracy); call ch(c%goal); call l(c%check)
    call i(c%realisations)
    call r(c%t0); call r(c%t_end); call r(c%t_transient)
    call i(c%n_out); call r(c%revolutions); call r(c%transient_revolutions)
    call r(c%outputs_per_revolution); call ch(c%start); call ra(c%dq0); call ra(c%dv0); call r(c%l_ref)
    call r(c%w_ref); call ch(c%fidelity); call r(c%fidelity_tol); call ch(c%section)
    call l(c%lyapunov); call r(c%lyapunov_interval); call r(c%lyapunov_d0)
    call ch(c%lyapunov_method); call l(c%fillet)
    call r(c%fillet_radius); call r(c%r_bore); call r(c%r_rim); call r(c%zeta_m)
    call ra(c%ripple_order); call ra(c%ripple_amp); call ra(c%ripple_phase_deg)
    call ra(c%unbalance); call ra(c%unbalance_phase_deg); call r(c%gamma_x); call r(c%gamma_y)
    call i(c%n_slices); call ra(c%spacing_error)
    call r(c%spacing_error_amp); call i(c%spacing_error_seed)
    if (ierr == err_ok .and. (iv /= size(v) .or. is /= len(s))) call mismatch()
    if (ierr == err_ok) call field(' ', 0)       ! no field beyond the last
  contains
    !> The next field of the table must have this type and size.
    subroutine field(kind, n)
      character(len=1), intent(in) :: kind
      integer, intent(in) :: n
      k = k + 1
      if (k > nfields) then               ! past the last: kind ' ', size 0 (as case_field)
        if (kind /= ' ' .or. n /= 0) call mismatch()
      else if (fields(k)%kind /= kind .or. fields(k)%n /= n) then
        call mismatch()
      end if
    end subroutine field
    subroutine mismatch()
      ierr = err_case
      errmsg = 'case values: fortran/input/case_values.f90 is out of step with the field table'
    end subroutine mismatch
    subroutine r(x)
      real(wp), intent(inout) :: x
      call field('r', 1)
      if (ierr /= err_ok) return
      iv = iv + 1
      if (put) then
        v(iv) = x
      else
        x = v(iv)
      end if
    end subroutine r
    subroutine ra(x)
      real(wp), intent(inout) :: x(:)
      call field('r', size(x))
      if (ierr /= err_ok) return
      if (put) then
        v(iv+1:iv+size(x)) = x
      else
        x = v(iv+1:iv+size(x))
      end if
      iv = iv + size(x)
    end subroutine ra
    subroutine i(x)
      integer, intent(inout) :: x
      call field('i', 1)
      if (ierr /= err_ok) return
      iv = iv + 1
      if (put) then
        v(iv) = real(x, wp)
      else if (v(iv) == aint(v(iv)) .and. abs(v(iv)) <= real(huge(x), wp)) then
        x = int(v(iv))
      else
        ierr = err_case
        errmsg = 'case values: an integer field holds no 32-bit whole number'
      end if
    end subroutine i
    subroutine l(x)
      logical, intent(inout) :: x
      call field('l', 1)
      if (ierr /= err_ok) return
      iv = iv + 1
      if (put) then
        v(iv) = merge(1.0_wp, 0.0_wp, x)
      else
        x = v(iv) /= 0.0_wp
      end if
    end subroutine l
    subroutine ch(x)
      character(len=*), intent(inout) :: x
      call field('c', len(x))
      if (ierr /= err_ok) return
      if (put) then
        s(is+1:is+len(x)) = x
      else
        x = s(is+1:is+len(x))
      end if
      is = is + len(x)
    end subroutine ch
  end subroutine walk

end module spline_case_values
