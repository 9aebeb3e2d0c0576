!> The flop floor of the mesh right-hand side (bench/anatomy.py): a branch-free kernel doing only
!> the arithmetic a mesh evaluation cannot avoid (tooth angles by rotation, Eq. 11 and its
!> rate, Eqs. 15-17 with every tooth in contact, Eqs. 19-22), with the paper's numbers. It is
!> benchmark instrumentation, not the model: built on demand by f2py, never installed.
subroutine time_floor(z, n, y, t_floor, flops)
  implicit none
  integer, intent(in) :: z, n
  double precision, intent(in) :: y(14)
  double precision, intent(out) :: t_floor, flops
  double precision :: acc, dt
  integer :: k
  integer(8) :: c0, c1, rate
  dt = 1.0d-3/n
  acc = 0
  call system_clock(c0, rate)
  do k = 1, n
    acc = acc + floor_kernel(k*dt)
  end do
  call system_clock(c1)
  t_floor = dble(c1 - c0)/rate/n
  ! 28 flops per tooth (rotation 6, dn 4, its rate 9, force 4, sums 5), the torsional and
  ! lateral accelerations and scalings (about 40 + 2 x 14), one sin/cos pair
  flops = 28.0d0*z + 2*14 + 40.0d0
  if (acc == 1.2345d300) t_floor = -1      ! keeps the loop from being optimised out
contains
  double precision function floor_kernel(t) result(r)
    double precision, intent(in) :: t
    double precision :: s, c, s1, ex, ey, evx, evy, dn, ddn, fj, fx, fy, fs
    integer :: j
    double precision, parameter :: sd = 0.38268343236508978d0, cd = 0.92387953251128674d0
    s = sin(628.3d0*t); c = cos(628.3d0*t)
    ex = y(1) - y(3); ey = y(2) - y(4); evx = y(8) - y(10); evy = y(9) - y(11)
    fx = 0; fy = 0; fs = 0
    do j = 1, z
      dn = ex*s - ey*c + y(6)
      ddn = evx*s - evy*c + y(13) + 628.3d0*(ex*c + ey*s)
      fj = 2.5d5*(dn - 2.0d-4) + 0.053d0*ddn
      fx = fx - fj*s
      fy = fy + fj*c
      fs = fs + fj
      s1 = s*cd + c*sd
      c = c*cd - s*sd
      s = s1
    end do
    r = fx + fy + fs + sum(y)*1.0d-3 + y(5)*7.855d0 + y(7)*7.856d0
  end function floor_kernel
end subroutine time_floor
