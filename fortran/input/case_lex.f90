!> The tokens of a case's text (namelist syntax): words, strings, '=', ',', '/', group names,
!> subscripts, with the line of each. spline_case_parse reads the items from them.
module spline_case_lex
  use spline_case_text, only: word_char
  implicit none
  private
  public :: tokenize
  public :: tk_word, tk_string, tk_equals, tk_comma, tk_slash, tk_group, tk_subscript, &
       tk_badstring, tk_other

  integer, parameter :: tk_word = 1, tk_string = 2, tk_equals = 3, tk_comma = 4, tk_slash = 5, &
       tk_group = 6, tk_subscript = 7, tk_badstring = 8, tk_other = 9

contains

  !> Split text into tokens: tk kind, ta:tb its characters, tl its line (ntok of them). A
  !> control character (not a text file) stops it: ctrl its position, ctrl_line its line
  !> (0 if none).
  subroutine tokenize(text, tk, ta, tb, tl, ntok, ctrl, ctrl_line)
    character(len=*), intent(in) :: text
    integer, allocatable, intent(out) :: tk(:), ta(:), tb(:), tl(:)
    integer, intent(out) :: ntok, ctrl, ctrl_line
    integer :: i, j, n, line, cap, i0, i1
    character :: ch, q
    ctrl = 0; ctrl_line = 0
    n = len(text)
    cap = 64
    allocate(tk(cap), ta(cap), tb(cap), tl(cap))
    ntok = 0
    line = 1
    i = 1
    do while (i <= n)
      ch = text(i:i)
      if (ch == new_line('a')) then
        line = line + 1; i = i + 1; cycle
      end if
      if (ch == ' ' .or. ch == char(9) .or. ch == char(13) .or. ch == char(12)) then
        i = i + 1; cycle
      end if
      if (iachar(ch) < 32 .or. iachar(ch) == 127) then
        call control(i, line); return
      end if
      select case (ch)
      case ('!')
        j = index(text(i:), new_line('a'))
        if (j == 0) then
          j = n + 1
        else
          j = i + j - 1
        end if
        do i0 = i, j - 1          ! control characters in a comment too: not a text file
          if ((iachar(text(i0:i0)) < 32 .and. index(char(9)//char(13)//char(12), text(i0:i0)) == 0) &
               .or. iachar(text(i0:i0)) == 127) then
            call control(i0, line); return
          end if
        end do
        i = j
      case ('''', '"')
        q = ch
        j = i + 1
        do
          if (j > n) exit
          if (text(j:j) == new_line('a')) exit
          if (iachar(text(j:j)) < 32 .and. text(j:j) /= char(9) .and. text(j:j) /= char(13)) then
            call control(j, line); return
          end if
          if (text(j:j) == q) then
            if (j < n) then
              if (text(j+1:j+1) == q) then
                j = j + 2; cycle
              end if
            end if
            exit
          end if
          j = j + 1
        end do
        if (j <= n) then
          if (text(j:j) == q) then            ! closed
            call push(tk_string, i, j, line)
            i = j + 1
            cycle
          end if
        end if
        i1 = j - 1                            ! not closed on its line: up to the line's end
        if (i1 > i) then
          if (text(i1:i1) == char(13)) i1 = i1 - 1
        end if
        call push(tk_badstring, i, i1, line)
        i = j
      case ('=')
        call push(tk_equals, i, i, line); i = i + 1
      case (',')
        call push(tk_comma, i, i, line); i = i + 1
      case ('/')
        call push(tk_slash, i, i, line); i = i + 1
      case ('&', '$')
        j = i + 1
        do while (j <= n)
          if (.not. word_char(text(j:j))) exit
          j = j + 1
        end do
        call push(tk_group, i + 1, j - 1, line)
        i = j
      case ('(')
        j = i + 1
        do while (j <= n)
          if (text(j:j) == ')' .or. text(j:j) == new_line('a')) exit
          j = j + 1
        end do
        if (j <= n) then
          if (text(j:j) == ')') then
            call push(tk_subscript, i, j, line)
            i = j + 1
            cycle
          end if
        end if
        call push(tk_other, i, i, line); i = i + 1
      case (')', ';')
        call push(tk_other, i, i, line); i = i + 1
      case default
        j = i
        do while (j <= n)
          if (.not. word_char(text(j:j))) exit
          j = j + 1
        end do
        call push(tk_word, i, j - 1, line)
        i = j
      end select
    end do

  contains

    subroutine push(kind, a, b, line)
      integer, intent(in) :: kind, a, b, line
      integer, allocatable :: t(:)
      integer :: cap
      if (ntok == size(tk)) then
        cap = 2*size(tk)
        allocate(t(cap)); t(1:ntok) = tk(1:ntok); call move_alloc(t, tk)
        allocate(t(cap)); t(1:ntok) = ta(1:ntok); call move_alloc(t, ta)
        allocate(t(cap)); t(1:ntok) = tb(1:ntok); call move_alloc(t, tb)
        allocate(t(cap)); t(1:ntok) = tl(1:ntok); call move_alloc(t, tl)
      end if
      ntok = ntok + 1
      tk(ntok) = kind; ta(ntok) = a; tb(ntok) = b; tl(ntok) = line
    end subroutine push

    subroutine control(i, line)
      integer, intent(in) :: i, line
      ctrl = i; ctrl_line = line
    end subroutine control

  end subroutine tokenize

end module spline_case_lex
