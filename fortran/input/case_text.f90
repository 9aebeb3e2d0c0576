!> Text helpers of the case input: the lexical forms of namelist constants, strings and
!> numbers as messages show them, the words a message uses for a field, and the spelling hint
!> (the field name nearest to a misspelt one). No state: each routine works on its arguments.
module spline_case_text
  use spline_kinds, only: wp
  use spline_errors, only: itoa, ftoa
  use spline_case_type, only: fields, nfields
  implicit none
  private
  public :: lower, unquote, shown, clip, size_text, hint, case_suggest
  public :: word_char, is_digits, is_integer, is_real, is_logical, is_value, expected, kind_word, &
       element

contains

  !> A word w is a constant of field f's type (a repeat r*c counts by its constant).
  pure logical function is_value(f, w)
    integer, intent(in) :: f
    character(len=*), intent(in) :: w
    integer :: q
    q = index(w, '*')
    if (q > 0) then
      is_value = is_digits(w(1:q-1))
      if (is_value .and. q < len(w)) is_value = is_value_plain(w(q+1:))
    else
      is_value = is_value_plain(w)
    end if
  contains
    pure logical function is_value_plain(v)
      character(len=*), intent(in) :: v
      select case (fields(f)%kind)
      case ('i'); is_value_plain = is_integer(v)
      case ('r'); is_value_plain = is_real(v)
      case ('l'); is_value_plain = is_logical(v)
      case default; is_value_plain = .false.
      end select
    end function is_value_plain
  end function is_value

  !> What field f expects, for messages (trailing blanks: trim it).
  function expected(f) result(s)
    integer, intent(in) :: f
    character(len=48) :: s
    select case (fields(f)%kind)
    case ('i'); s = 'a whole number'
    case ('r'); s = 'a number (e.g. 1.5e-3)'
    case ('l'); s = '.true. or .false.'
    case default; s = 'a quoted string of at most '//itoa(fields(f)%n)//' characters'
    end select
  end function expected

  function kind_word(k) result(s)
    character(len=1), intent(in) :: k
    character(len=12) :: s
    select case (k)
    case ('i'); s = 'whole number'
    case ('r'); s = 'number'
    case ('l'); s = 'logical'
    case default; s = 'string'
    end select
  end function kind_word

  !> NAME or NAME(k) for element k of field f (trailing blanks: trim it).
  function element(f, k) result(s)
    integer, intent(in) :: f, k
    character(len=40) :: s
    s = fields(f)%name
    if (fields(f)%n > 1 .and. fields(f)%kind /= 'c') s = trim(s)//'('//itoa(k)//')'
  end function element

  !> ': did you mean NAME?' for the nearest field, or a pointer to the list of fields (trailing
  !> blanks: trim it).
  function hint(word) result(s)
    character(len=*), intent(in) :: word
    character(len=48) :: s
    character(len=24) :: best
    best = case_suggest(word)
    if (len_trim(best) > 0) then
      s = ': did you mean '//trim(best)//'?'
    else
      s = ' (cases/template.nml lists every field)'
    end if
  end function hint

  !> The field name nearest to word (Damerau-Levenshtein distance at most 2, and less than
  !> the word's length; or the one field the word begins), else blank.
  function case_suggest(word) result(best)
    character(len=*), intent(in) :: word
    character(len=24) :: best
    character(len=:), allocatable :: w
    integer :: i, d, dbest, nprefix, iprefix
    w = lower(trim(adjustl(word)))
    best = ''
    dbest = huge(0)
    nprefix = 0; iprefix = 0
    if (len(w) == 0 .or. len(w) > 64) return
    do i = 1, nfields
      d = distance(w, trim(fields(i)%name))
      if (d < dbest) then
        dbest = d; best = fields(i)%name
      end if
      if (len(w) >= 4 .and. index(fields(i)%name, w) == 1) then
        nprefix = nprefix + 1; iprefix = i
      end if
    end do
    if (dbest == 0) return
    if (dbest <= 2 .and. dbest < len(w)) return
    best = ''
    if (nprefix == 1) best = fields(iprefix)%name
  end function case_suggest

  !> Optimal-string-alignment distance (insertions, deletions, substitutions, transpositions).
  pure integer function distance(a, b) result(dist)
    character(len=*), intent(in) :: a, b
    integer :: d(0:len(a), 0:len(b)), i, j, cost
    do i = 0, len(a)
      d(i, 0) = i
    end do
    do j = 0, len(b)
      d(0, j) = j
    end do
    do i = 1, len(a)
      do j = 1, len(b)
        cost = merge(0, 1, a(i:i) == b(j:j))
        d(i, j) = min(d(i-1, j) + 1, d(i, j-1) + 1, d(i-1, j-1) + cost)
        if (i > 1 .and. j > 1) then
          if (a(i:i) == b(j-1:j-1) .and. a(i-1:i-1) == b(j:j)) d(i, j) = min(d(i, j), d(i-2, j-2) + 1)
        end if
      end do
    end do
    dist = d(len(a), len(b))
  end function distance

  !> A character of a word: no blank, control character or namelist punctuation.
  pure logical function word_char(ch)
    character, intent(in) :: ch
    select case (ch)
    case (' ', ',', '/', '=', '(', ')', '!', '''', '"', '&', '$', ';')
      word_char = .false.
    case default
      word_char = .not. (iachar(ch) < 32 .or. iachar(ch) == 127)
    end select
  end function word_char

  pure logical function is_digits(s)
    character(len=*), intent(in) :: s
    is_digits = len(s) > 0 .and. verify(s, '0123456789') == 0
  end function is_digits

  pure logical function is_integer(s)
    character(len=*), intent(in) :: s
    integer :: i0
    i0 = 1
    if (len(s) > 0) then
      if (s(1:1) == '+' .or. s(1:1) == '-') i0 = 2
    end if
    is_integer = is_digits(s(i0:))
  end function is_integer

  !> A real constant: [sign] digits [. [digits]] | [sign] . digits, then an optional exponent
  !> (e, d or q, optional sign, digits); or [sign] NaN, Inf, Infinity (any case).
  pure logical function is_real(s)
    character(len=*), intent(in) :: s
    integer :: i, n, nd
    character(len=len(s)) :: l
    is_real = .false.
    n = len(s)
    i = 1
    if (n == 0) return
    if (s(1:1) == '+' .or. s(1:1) == '-') i = 2
    l = lower(s)
    if (i <= n) then
      if (l(i:) == 'nan' .or. l(i:) == 'inf' .or. l(i:) == 'infinity') then
        is_real = .true.; return
      end if
    end if
    nd = 0
    do while (i <= n)
      if (index('0123456789', s(i:i)) == 0) exit
      i = i + 1; nd = nd + 1
    end do
    if (i <= n) then
      if (s(i:i) == '.') then
        i = i + 1
        do while (i <= n)
          if (index('0123456789', s(i:i)) == 0) exit
          i = i + 1; nd = nd + 1
        end do
      end if
    end if
    if (nd == 0) return
    if (i <= n) then
      if (index('eEdDqQ', s(i:i)) == 0) return
      i = i + 1
      if (i <= n) then
        if (s(i:i) == '+' .or. s(i:i) == '-') i = i + 1
      end if
      if (i > n) return
      if (verify(s(i:), '0123456789') /= 0) return
    end if
    is_real = .true.
  end function is_real

  !> Fortran's logical constants: T, F, .T., .F., .TRUE., .FALSE. (any case, the dots optional).
  pure logical function is_logical(s)
    character(len=*), intent(in) :: s
    character(len=len(s)) :: l
    integer :: a, b
    l = lower(s)
    a = 1; b = len(l)
    if (b == 0) then
      is_logical = .false.; return
    end if
    if (l(1:1) == '.') a = 2
    if (b >= a) then
      if (l(b:b) == '.') b = b - 1
    end if
    is_logical = .false.
    if (b < a) return
    is_logical = l(a:b) == 't' .or. l(a:b) == 'f' .or. l(a:b) == 'true' .or. l(a:b) == 'false'
  end function is_logical

  !> The characters of a quoted string (doubled quotes collapsed).
  pure subroutine unquote(v, s)
    character(len=*), intent(in) :: v
    character(len=:), allocatable, intent(out) :: s
    character(len=max(len(v) - 2, 0)) :: buf
    character :: q
    integer :: i, n, k
    q = v(1:1)
    n = len(v) - 1
    i = 2
    k = 0
    do while (i <= n)
      k = k + 1
      buf(k:k) = v(i:i)
      if (v(i:i) == q) i = i + 1
      i = i + 1
    end do
    s = buf(1:k)
  end subroutine unquote

  pure function lower(s) result(l)
    character(len=*), intent(in) :: s
    character(len=len(s)) :: l
    integer :: i, k
    l = s
    do i = 1, len(s)
      k = iachar(s(i:i))
      if (k >= iachar('A') .and. k <= iachar('Z')) l(i:i) = achar(k + 32)
    end do
  end function lower

  !> A path as messages show it: whole up to 240 characters, else '...' and its last 237
  !> (pyspline.case._shown says the same).
  pure function shown(path) result(s)
    character(len=*), intent(in) :: path
    character(len=min(len(path), 240)) :: s
    if (len(path) > 240) then
      s = '...'//path(len(path)-236:)
    else
      s = path
    end if
  end function shown

  !> At most 40 characters of a token, for messages.
  pure function clip(s) result(c)
    character(len=*), intent(in) :: s
    character(len=min(len(s), 40)) :: c
    if (len(s) > 40) then
      c = s(1:37)//'...'
    else
      c = s
    end if
  end function clip

  !> A byte count in kB, MB, GB or TB (powers of 1000; trailing blanks: trim it).
  pure function size_text(bytes) result(s)
    real(wp), intent(in) :: bytes
    character(len=16) :: s
    character(len=2), parameter :: units(5) = ['B ', 'kB', 'MB', 'GB', 'TB']
    real(wp) :: v
    integer :: k
    v = bytes; k = 1
    do while (v >= 1000.0_wp .and. k < 5)
      v = v/1000.0_wp; k = k + 1
    end do
    s = ftoa(v, '(f0.1)')//' '//trim(units(k))
  end function size_text

end module spline_case_text
