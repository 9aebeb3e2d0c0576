!> The frozen-contact Jacobian of Eq. 25 in closed form (spline_dynamics::rhs_jacobian, on
!> accel_jacobian: the variational run's, the linear tail's and the static equilibrium's) against
!> unit steps of the right-hand side (spline_dynamics::rhs_scaled) with the same contact states
!> frozen (the right-hand side is affine in the state there, so a unit step is exact to
!> round-off): face slices with an
!> angular misalignment, spacing errors, mesh damping, and partial contact (teeth on the drive
!> flank, on the back flank and free, teeth with only part of their face in contact), at a time
!> off the teeth's symmetry.
program test_jacobian
  use spline_kinds, only: wp
  use spline_case, only: case_t
  use spline_model, only: model_t, nstate, ndof
  use spline_mesh, only: mesh_switch_functions, eq16_mode
  use spline_dynamics, only: rhs_scaled, to_scaled, rhs_jacobian
  use check, only: check_true, check_done, default_case_model
  implicit none
  type(case_t) :: cs
  type(model_t) :: m
  integer :: i
  cs%n_slices = 4; cs%gamma_x = 5.0e-3_wp; cs%gamma_y = -4.0e-3_wp; cs%l_x = 2.0e-5_wp
  cs%spacing_error(1:3) = [2.0e-6_wp, -1.0e-6_wp, 3.0e-6_wp]
  call default_case_model(m, cs)
  do i = -1, 1, 2                    ! D2 near the drive flank, near the back flank
    call compare(real(i, wp))
  end do
  cs%n_slices = 1; cs%gamma_x = 0; cs%gamma_y = 0
  call default_case_model(m, cs)
  call compare(1.0_wp)
  call check_done('test_jacobian')
contains
  !> At D2 = side c_bulk, lateral offsets and a tilt across the face of a fraction of c_bulk
  !> (partial contact), t = 1.3 ms.
  subroutine compare(side)
    real(wp), intent(in) :: side
    real(wp) :: y(nstate), ys(nstate), y1(nstate), f0(nstate), f1(nstate), g(2*m%z*m%n_slices)
    real(wp) :: jc(nstate, nstate), ju(nstate, nstate), tau, err
    integer :: modes(m%z*m%n_slices), k, ierr, ns, j, partial
    character(len=512) :: msg
    character(len=160) :: detail
    y = [0.07_wp, -0.04_wp, -0.02_wp, 0.03_wp, 0.1_wp, side, -0.3_wp, 0.5_wp, -0.2_wp, 0.1_wp, &
         0.3_wp, -0.4_wp, 0.2_wp, 0.6_wp]*m%c_bulk
    y(ndof+1:) = y(ndof+1:)*1.0e3_wp                   ! velocities: c_bulk per ms
    y(6) = side*m%c_bulk
    call to_scaled(m, y, ys)
    tau = 1.3e-3_wp*m%w_ref
    call mesh_switch_functions(m, tau/m%w_ref, y(1:ndof), g)
    modes = eq16_mode(g(1::2), g(2::2))
    ns = m%n_slices
    partial = 0
    do j = 1, m%z
      if (any(modes((j-1)*ns+1:j*ns) /= 0) .and. any(modes((j-1)*ns+1:j*ns) == 0)) &
           partial = partial + 1
    end do
    write(detail, '(a,i0,a,i0,a,i0,a,i0,a,i0)') 'slices ', ns, ': drive ', count(modes == 1), &
         ', back ', count(modes == -1), ', free ', count(modes == 0), ', teeth partly in contact ', &
         partial
    call check_true('partial contact', count(modes == nint(side)) > 0 .and. &
         count(modes == 0) > 0 .and. (ns == 1 .or. partial > 0), trim(detail))
    call rhs_jacobian(m, tau, modes, jc)
    msg = ''
    call rhs_scaled(m, tau, ys, f0, ierr, msg, mode=modes)
    do k = 1, nstate
      y1 = ys
      y1(k) = y1(k) + 1.0_wp
      call rhs_scaled(m, tau, y1, f1, ierr, msg, mode=modes)
      ju(:, k) = f1 - f0
    end do
    err = 0
    do k = 1, nstate      ! each row against its largest entry (rows differ in size by decades)
      err = max(err, maxval(abs(jc(k, :) - ju(k, :)))/max(maxval(abs(ju(k, :))), tiny(1.0_wp)))
    end do
    write(detail, '(a,es10.3)') 'largest |closed - unit steps| / row max ', err
    call check_true('rhs_jacobian = unit steps of rhs_scaled', ierr == 0 .and. err < 1.0e-9_wp, &
         trim(detail))
  end subroutine compare
end program test_jacobian
