!> Working precision and physical constants shared by every module.
module spline_kinds
  use, intrinsic :: iso_c_binding, only: c_double, c_int
  implicit none
  private
  public :: wp, ip, pi, max_teeth

  integer, parameter :: wp = c_double   !< working real kind (C double, for f2py and CVODE)
  integer, parameter :: ip = c_int      !< integer kind passed through the C/f2py boundary
  !> Most teeth a case may have: the tooth-angle recurrence is checked that far (geometry), and
  !> the right-hand side keeps its per-tooth work arrays on the stack at this size (no allocation
  !> per call).
  integer, parameter :: max_teeth = 1000
  real(wp), parameter :: pi = 3.14159265358979323846264338327950288_wp
end module spline_kinds
