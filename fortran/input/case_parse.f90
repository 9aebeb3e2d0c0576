!> Reading a case's text (case_parse): the one diagnosis of a case, for the executable and for
!> Python alike (pyspline hands the bytes of a case file to api_parse). The text is tokenised
!> (spline_case_lex) and checked here, every error naming the line, the field and what was
!> expected (unknown fields get the nearest field name as a suggestion). Each checked value is
!> converted once and put at its element's place in the case's flat value arrays (local copies,
!> spline_case_values: the one list of the fields, walk), which become the case only if the
!> whole text passed, so reading a case changes no module variable (reentrant). Writing a case
!> as namelist text (case_write_text) uses the compiler's namelist output.
module spline_case_parse
  use spline_kinds, only: wp, max_teeth
  use spline_errors, only: err_ok, err_case, itoa
  use spline_case_type, only: case_t, fields, nfields, namelen, field_index
  use spline_case_values, only: case_value_sizes, case_to_values, case_from_values, &
       case_value_offset, case_put_value
  use spline_case_text, only: lower, unquote, shown, clip, hint, is_digits, is_integer, &
       is_real, is_logical, is_value, expected, kind_word, element
  use spline_case_lex, only: tokenize, tk_word, tk_string, tk_equals, tk_comma, tk_slash, &
       tk_group, tk_subscript, tk_badstring, tk_other
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan, ieee_value, ieee_quiet_nan
  implicit none
  private
  public :: case_parse, case_write_text

  interface   ! fortran/interface/iolock.c: one lock around the parser's reads from internal files
    subroutine io_lock() bind(C, name='spline_io_lock')
    end subroutine io_lock
    subroutine io_unlock() bind(C, name='spline_io_unlock')
    end subroutine io_unlock
  end interface

contains

  !> Parse namelist text (one group &spline_case) into c: the fields it gives replace c's,
  !> the others keep their values (defaults, or a case being amended: spline-dyn --set).
  !> origin: the file the text came from (messages say 'case NAME (origin, line N)'); absent or
  !> empty: 'case NAME' only. show_lines = .false. leaves the line out (one-line texts).
  !> Nothing is changed unless the whole text is valid. Refused, with ierr = err_case and a
  !> message naming the line, the field and what was expected: a missing or misspelt group,
  !> text outside the group, a second group, no closing '/', an unknown field (with the
  !> nearest name), a missing '=', a value of the wrong type (a number for a logical, a
  !> string for a number, an unquoted string), an integer beyond 32 bits, a number beyond
  !> the largest double, a string longer than its field (blank padding aside), more values
  !> than elements (a decimal comma), a subscript outside the array, an unclosed string, a
  !> field given twice, and control characters (not a text file).
  !> A UTF-8 byte-order mark (EF BB BF, which some editors write) before the text is skipped.
  subroutine case_parse(text, c, ierr, errmsg, origin, show_lines)
    character(len=*), intent(in) :: text
    type(case_t), intent(inout) :: c
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    character(len=*), intent(in), optional :: origin
    logical, intent(in), optional :: show_lines
    character(len=3), parameter :: bom = char(239)//char(187)//char(191)
    integer :: i0
    i0 = 1
    if (len(text) >= 3) then
      if (text(1:3) == bom) i0 = 4
    end if
    call io_lock()           ! internal reads are not thread-safe in libgfortran (iolock.c)
    call parse_unlocked(text(i0:), c, ierr, errmsg, origin, show_lines)
    call io_unlock()
  end subroutine case_parse

  subroutine parse_unlocked(text, c, ierr, errmsg, origin, show_lines)
    character(len=*), intent(in) :: text
    type(case_t), intent(inout) :: c
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    character(len=*), intent(in), optional :: origin
    logical, intent(in), optional :: show_lines
    integer, allocatable :: tk(:), ta(:), tb(:), tl(:)
    integer, allocatable :: set_line(:)     ! line that set each element: field f's at(f) + q
    integer :: at(nfields + 1)
    character(len=:), allocatable :: from
    integer :: ntok, p, f, off, i0, i1, group_line
    character(len=:), allocatable :: why
    logical :: lines_on
    type(case_t) :: work
    character(len=namelen) :: name_now
    real(wp), allocatable :: vals(:)        ! the case's values (spline_case_values' layout)
    character(len=:), allocatable :: chars
    integer :: nv, nc

    ierr = err_ok
    errmsg = ''
    from = ''
    if (present(origin)) from = shown(origin)
    lines_on = len(from) > 0
    if (present(show_lines)) lines_on = lines_on .and. show_lines
    name_now = c%name

    call tokenize(text, tk, ta, tb, tl, ntok, i0, i1)
    if (i0 > 0) then
      call control(i0, i1); return
    end if
    if (ierr /= err_ok) return

    ! the group opener
    p = 1
    if (ntok == 0) then
      call fail(0, 'no group &spline_case: the text is empty or holds only comments'); return
    end if
    select case (tk(1))
    case (tk_group)
      if (lower(tok(1)) /= 'spline_case') then
        call fail(tl(1), 'found the group &'//tok(1)//' where &spline_case was expected'); return
      end if
    case (tk_word)
      if (lower(tok(1)) == 'spline_case') then
        call fail(tl(1), 'the group name spline_case lacks its ''&'': write &spline_case'); return
      end if
      call fail(tl(1), 'expected the group &spline_case, found '''//clip(tok(1))//''''); return
    case default
      call fail(tl(1), 'expected the group &spline_case, found '''//clip(tok(1))//''''); return
    end select
    group_line = tl(1)
    p = 2

    ! the items, each checked element put into the value arrays of c (kept if the whole text
    ! passes)
    at(1) = 0
    do f = 1, nfields
      at(f + 1) = at(f) + merge(1, fields(f)%n, fields(f)%kind == 'c')
    end do
    allocate(set_line(at(nfields + 1)))
    call case_value_sizes(nv, nc)
    allocate(vals(nv))
    allocate(character(len=nc) :: chars)
    call case_to_values(c, vals, chars)
    set_line = 0
    do
      if (p > ntok) then
        call fail(tl(ntok), 'the group &spline_case opened on line '//itoa(group_line)// &
             ' is not closed by ''/'''); return
      end if
      if (tk(p) == tk_slash) exit
      if (tk(p) == tk_group) then
        if (lower(tok(p)) == 'end') exit
        call fail(tl(p), 'the group &'//tok(p)//' begins before ''/'' closes &spline_case'); return
      end if
      if (tk(p) == tk_comma) then              ! a separator between items
        p = p + 1; cycle
      end if
      call item()
      if (ierr /= err_ok) return
    end do
    ! after the group: comments only
    if (p < ntok) then
      if (tk(p + 1) == tk_group) then
        call fail(tl(p + 1), 'a second group &'//tok(p + 1)//': a case file holds one group '// &
             '&spline_case'); return
      end if
      call fail(tl(p + 1), 'text after the end of the group &spline_case: '''// &
           clip(tok(p + 1))//''''); return
    end if
    call case_from_values(vals, chars, work, ierr, errmsg)
    if (ierr /= err_ok) then
      why = trim(errmsg)
      call fail(0, why); return
    end if
    c = work

  contains

    !> One item: NAME [(subscript)] = values.
    subroutine item()
      character(len=:), allocatable :: name
      integer :: lo, hi, k, r, q, line, pv
      logical :: after_sep
      character(len=:), allocatable :: v, sv
      real(wp) :: x
      integer :: iv
      logical :: lv
      v = ''          ! its length defined before the first reallocating assignment reads it
      line = tl(p)
      if (tk(p) /= tk_word) then
        select case (tk(p))
        case (tk_equals); call fail(line, '''='' without a field name before it')
        case (tk_string, tk_badstring)
          call fail(line, 'expected a field name, found the string '//clip(tok(p)))
        case default; call fail(line, 'expected a field name, found '''//clip(tok(p))//'''')
        end select
        return
      end if
      name = lower(tok(p))
      f = field_index(name)
      if (f == 0) then
        call fail(line, 'unknown field '''//clip(tok(p))//''''//trim(hint(name))); return
      end if
      p = p + 1
      off = case_value_offset(f)
      lo = 1; hi = fields(f)%n
      if (fields(f)%kind == 'c') hi = 1
      if (p <= ntok) then
        if (tk(p) == tk_subscript) then
          if (hi == 1) then
            call fail(line, 'field '//trim(fields(f)%name)//' is not an array: no subscript ('// &
                 clip(tok(p))//')'); return
          end if
          call subscript(tok(p), lo, hi)
          if (ierr /= err_ok) return
          p = p + 1
        end if
      end if
      if (p > ntok) then
        call fail(line, 'field '//trim(fields(f)%name)//': expected ''='' after the field name, '// &
             'found the end of the text'); return
      end if
      if (tk(p) /= tk_equals) then
        call fail(line, 'field '//trim(fields(f)%name)//': expected ''='' after the field name, '// &
             'found '''//clip(tok(p))//''''); return
      end if
      p = p + 1
      ! values up to the next item, '/' or the end; null values (the element keeps its value):
      ! nothing between '=' or a comma and the next comma, and r*; 'name =' alone is one null
      after_sep = .true.        ! just after '=' or a comma
      k = lo
      do while (p <= ntok)
        if (ends_values(p)) exit
        select case (tk(p))
        case (tk_comma)
          if (after_sep) then           ! a null value: the element keeps its value
            if (k > hi) then
              call too_many(1); return
            end if
            k = k + 1
          end if
          after_sep = .true.
          p = p + 1; cycle
        case (tk_badstring)
          call fail(tl(p), 'field '//trim(fields(f)%name)//': the string '//clip(tok(p))// &
               ' is not closed on its line (a missing '//tok_first(p)//')'); return
        case (tk_equals)
          call fail(tl(p), 'field '//trim(fields(f)%name)//': a second ''='''); return
        case (tk_subscript, tk_other)
          call fail(tl(p), 'field '//trim(fields(f)%name)//': unexpected '''//clip(tok(p))// &
               ''''); return
        end select
        ! a word that names a field, or begins a line and is no value of this field: the
        ! '=' after a field name is missing
        if (tk(p) == tk_word) then
          if (field_index(lower(tok(p))) > 0) then
            call fail(tl(p), 'field '//lower(tok(p))//': expected ''='' after the field name, '// &
                 'found '//trim(after(p))); return
          end if
          if (tl(p) > tl(p - 1) .and. .not. is_value(f, tok(p))) then
            call fail(tl(p), ''''//clip(tok(p))//''' is neither a field nor a value of field '// &
                 trim(fields(f)%name)//' (a missing ''=''?)'//trim(hint(lower(tok(p))))); return
          end if
        end if
        ! a value: [r*]constant or r*
        v = tok(p)
        pv = p
        r = 1
        if (tk(p) == tk_word) then
          q = index(v, '*')
          if (q > 0) then
            if (.not. is_digits(v(1:q-1))) then
              call fail(tl(p), 'field '//trim(fields(f)%name)//' = '//clip(v)//': expected '// &
                   trim(expected(f))); return
            end if
            if (q - 1 > 9) then
              r = huge(0)
            else
              read(v(1:q-1), *) r
            end if
            if (r < 1) then
              call fail(tl(p), 'field '//trim(fields(f)%name)//' = '//clip(v)//': a repeat count '// &
                   'must be at least 1'); return
            end if
            v = v(q+1:)
            if (len(v) == 0 .and. p < ntok) then     ! r*'string'
              if (tk(p + 1) == tk_string .and. ta(p + 1) == tb(p) + 1) then
                p = p + 1
                v = tok(p)
              end if
            end if
          end if
        end if
        if (r > hi - k + 1 .or. k > hi) then
          call too_many(r); return
        end if
        if (len(v) > 0) then
          call check_value(v, tk(p), tl(p), x, iv, lv, sv)
          if (ierr /= err_ok) return
          do q = k, k + r - 1
            if (set_line(at(f) + q) /= 0) then
              call fail(tl(pv), 'field '//trim(element(f, q))//' is given twice (lines '// &
                   itoa(set_line(at(f) + q))//' and '//itoa(tl(pv))//')'); return
            end if
            set_line(at(f) + q) = tl(pv)
            call case_put_value(vals, chars, f, off, q, x, iv, lv, sv)
          end do
        end if
        k = k + r
        after_sep = .false.
        p = p + 1
      end do
    end subroutine item

    !> More values than the field (from the subscript on) holds.
    subroutine too_many(r)
      integer, intent(in) :: r
      integer :: total, q, nn
      logical :: digits_only
      character(len=:), allocatable :: why
      ! count every value of this item (for the message)
      total = 0; digits_only = .true.; nn = 0
      q = p
      do while (q <= ntok)
        if (ends_values(q)) exit
        if (tk(q) == tk_word .or. tk(q) == tk_string) then
          nn = nn + 1
          if (.not. is_digits(tok(q))) digits_only = .false.
        end if
        q = q + 1
      end do
      if (fields(f)%n == 1 .or. fields(f)%kind == 'c') then
        why = 'field '//trim(fields(f)%name)//': more than one value for a single '// &
             trim(kind_word(fields(f)%kind))
        if (fields(f)%kind == 'r' .and. digits_only .and. nn > 0) why = why//' (a decimal comma? use a '// &
             'decimal point, e.g. 0.001)'
      else
        why = 'field '//trim(fields(f)%name)//': more values than its '// &
             itoa(fields(f)%n)//' elements'
      end if
      if (r > 1 .and. nn == 1) why = why//' (repeat count '//itoa(r)//')'
      call fail(tl(p), why)
    end subroutine too_many

    !> The value v (a token of kind kind) for field f, as the field's type: x (a real; NaN
    !> the quiet NaN), i (a whole number), l (a logical) or s (a string's characters).
    subroutine check_value(v, kind, line, x, i, l, s)
      character(len=*), intent(in) :: v
      integer, intent(in) :: kind, line
      real(wp), intent(out) :: x
      integer, intent(out) :: i
      logical, intent(out) :: l
      character(len=:), allocatable, intent(out) :: s
      integer(8) :: iv
      integer :: ios, n0
      character(len=len(v)) :: u
      x = 0.0_wp; i = 0; l = .false.; s = ''
      select case (fields(f)%kind)
      case ('i')
        if (kind /= tk_word .or. .not. is_integer(v)) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)//': expected '// &
               trim(expected(f))); return
        end if
        n0 = verify(v, '+-0')          ! first significant digit
        if (n0 == 0) return            ! zero
        ios = 0
        if (len(v) - n0 + 1 > 10) then
          ios = 1
        else
          iv = 0
          do n0 = n0, len(v)           ! at most 10 digits: no overflow of 64 bits
            iv = 10*iv + (iachar(v(n0:n0)) - iachar('0'))
          end do
          if (v(1:1) == '-') iv = -iv
          if (abs(iv) > huge(0)) ios = 1
        end if
        if (ios /= 0) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)// &
               ' does not fit a 32-bit integer (at most '//itoa(huge(0))//')'); return
        end if
        i = int(iv)
      case ('r')
        if (kind /= tk_word .or. .not. is_real(v)) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)//': expected '// &
               trim(expected(f))); return
        end if
        u = v
        do n0 = 1, len(u)
          if (index('dDqQ', u(n0:n0)) > 0) u(n0:n0) = 'e'
        end do
        read(u, *, iostat=ios) x
        if (ios /= 0) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)//': expected '// &
               trim(expected(f))); return
        end if
        if (.not. ieee_is_finite(x) .and. .not. ieee_is_nan(x) .and. index(lower(v), 'inf') == 0) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)// &
               ' is beyond the largest number (1.8e308)'); return
        end if
        if (ieee_is_nan(x)) x = ieee_value(x, ieee_quiet_nan)   ! (refused by case_validate)
      case ('l')
        if (kind /= tk_word .or. .not. is_logical(v)) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)//': expected '// &
               trim(expected(f))); return
        end if
        l = index('tT', v(verify(v, '.'):verify(v, '.'))) > 0
      case ('c')
        if (kind /= tk_string) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)//': expected '// &
               trim(expected(f))//', e.g. '''//clip(v)//''''); return
        end if
        call unquote(v, s)
        if (len_trim(s) > fields(f)%n) then
          call fail(line, 'field '//trim(fields(f)%name)//' = '//clip(v)//' is longer than '// &
               itoa(fields(f)%n)//' characters'); return
        end if
        if (f == 1) name_now = s
      end select
    end subroutine check_value

    !> (i) or (i:j) for field f: the elements lo..hi.
    subroutine subscript(s, lo, hi)
      character(len=*), intent(in) :: s
      integer, intent(inout) :: lo, hi
      character(len=:), allocatable :: inner
      integer :: colon, ios, n, a, b
      n = fields(f)%n
      inner = trim(adjustl(s(2:len(s)-1)))
      colon = index(inner, ':')
      ios = 1
      if (colon == 0) then
        if (is_integer(inner) .and. len(inner) < 10) then
          read(inner, *, iostat=ios) a
          b = a
        end if
      else
        if (is_integer(trim(adjustl(inner(1:colon-1)))) .and. is_integer(trim(adjustl(inner(colon+1:)))) &
             .and. len(inner) < 20) then
          read(inner(1:colon-1), *, iostat=ios) a
          if (ios == 0) read(inner(colon+1:), *, iostat=ios) b
        end if
      end if
      if (ios /= 0) then
        call fail(tl(p), 'field '//trim(fields(f)%name)//s//': expected an element number '// &
             '1 to '//itoa(n)); return
      end if
      if (a < 1 .or. a > n .or. b < a .or. b > n) then
        call fail(tl(p), 'field '//trim(fields(f)%name)//s//': element outside 1 to '//itoa(n)); return
      end if
      lo = a; hi = b
    end subroutine subscript


    subroutine control(i, line)
      integer, intent(in) :: i, line
      character(len=2) :: hex
      integer :: col
      write(hex, '(z2.2)') iachar(text(i:i))
      col = i - index(text(1:i), new_line('a'), back=.true.)
      call fail(line, 'byte 0x'//hex//' at column '//itoa(col)//' is a control character: '// &
           'this is not a text file')
    end subroutine control

    !> Token q ends the values of an item: '/', the next group, or the next item's name.
    logical function ends_values(q)
      integer, intent(in) :: q
      ends_values = tk(q) == tk_slash .or. tk(q) == tk_group
      if (.not. ends_values .and. tk(q) == tk_word) ends_values = next_is_item(q)
    end function ends_values

    !> A word at token q starts the next item: NAME = or NAME(...) =.
    logical function next_is_item(q)
      integer, intent(in) :: q
      next_is_item = .false.
      if (q + 1 > ntok) return
      if (tk(q + 1) == tk_equals) then
        next_is_item = .true.
      else if (tk(q + 1) == tk_subscript .and. q + 2 <= ntok) then
        next_is_item = tk(q + 2) == tk_equals
      end if
    end function next_is_item

    function tok(q) result(s)
      integer, intent(in) :: q
      character(len=tb(q) - ta(q) + 1) :: s
      s = text(ta(q):tb(q))
    end function tok

    !> The token after q, for messages: 'TEXT' or the end of the text (trailing blanks: trim it).
    function after(q) result(s)
      integer, intent(in) :: q
      character(len=48) :: s
      if (q < ntok) then
        s = ''''//clip(tok(q + 1))//''''
      else
        s = 'the end of the text'
      end if
    end function after

    function tok_first(q) result(s)
      integer, intent(in) :: q
      character(len=1) :: s
      s = text(ta(q):ta(q))
    end function tok_first

    !> The message prefix 'case NAME (origin, line N): ' and the reason.
    subroutine fail(line, why)
      integer, intent(in) :: line
      character(len=*), intent(in) :: why
      character(len=:), allocatable :: where
      where = 'case '//trim(name_now)
      if (len(from) > 0) then
        if (lines_on .and. line > 0) then
          where = where//' ('//from//', line '//itoa(line)//')'
        else
          where = where//' ('//from//')'
        end if
      end if
      errmsg = where//': '//why
      ierr = err_case
    end subroutine fail

  end subroutine parse_unlocked

  !> A case as namelist text (every field, one per line): Python reads the defaults from it.
  !> The records: about 90 for the scalar fields and the short lists, and at least one for
  !> every 5 values of a list as long as max_teeth (spacing_error with distinct values).
  subroutine case_write_text(c, text)
    type(case_t), intent(in) :: c
    character(len=:), allocatable, intent(out) :: text
    type(case_t) :: cc
    character(len=256), allocatable :: lines(:)
    character(len=256) :: iomsg
    integer :: i, ierr
    allocate(lines(200 + max_teeth))
    lines = ''
    cc = c
    call io_lock()           ! namelist I/O is not thread-safe in libgfortran (iolock.c)
    call nml_write(cc, ierr, iomsg, lines)
    call io_unlock()
    text = ''
    do i = 1, size(lines)
      if (len_trim(lines(i)) > 0) text = text//trim(lines(i))//new_line('a')
    end do
  end subroutine case_write_text

  !> The namelist group &spline_case of a local copy of the case (one object, c: the records
  !> name its components c%NAME), written out with the 'c%' taken off, so the text names the
  !> fields. Callers hold io_lock (case_write_text): namelist I/O on internal files is not
  !> thread-safe in libgfortran.
  subroutine nml_write(case, ierr, iomsg, out)
    type(case_t), intent(in) :: case
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: iomsg
    character(len=*), intent(out) :: out(:)
    type(case_t) :: c
    integer :: i
    namelist /spline_case/ c
    c = case
    iomsg = ''
    write(out, nml=spline_case, iostat=ierr, iomsg=iomsg)
    do i = 1, size(out)
      if (out(i)(1:3) == ' C%') out(i) = ' '//out(i)(4:)
    end do
  end subroutine nml_write

end module spline_case_parse
