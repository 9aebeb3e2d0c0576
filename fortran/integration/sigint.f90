!> The interface of fortran/integration/interrupt.c: a SIGINT during a run (the GIL is released while the
!> core runs) is counted, and a run compares the count with the one it started with.
module spline_sigint
  use, intrinsic :: iso_c_binding, only: c_int
  implicit none
  private
  public :: sigint_watch, sigint_unwatch, sigint_count

  interface
    integer(c_int) function sigint_watch() bind(C, name='spline_sigint_watch')
      import :: c_int
    end function sigint_watch
    subroutine sigint_unwatch() bind(C, name='spline_sigint_unwatch')
    end subroutine sigint_unwatch
    integer(c_int) function sigint_count() bind(C, name='spline_sigint_count')
      import :: c_int
    end function sigint_count
  end interface
end module spline_sigint
