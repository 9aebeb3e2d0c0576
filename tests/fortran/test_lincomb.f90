!> fortran/integration/lincomb.c: ERKStep's linear combinations element by element against
!> SUNDIALS' N_VLinearCombination_Serial, to the bit: random coefficients and vectors of mixed
!> magnitudes (so that another order of the sums would change the last bits), 3 to 16 terms,
!> lengths 1 to 31 (blocks of 8, 4, 2 and 1), z as the first term (with c_0 = 1 and not), and the
!> cases it leaves to SUNDIALS (2 terms; z among the later terms). spline_serial_data: the
!> numbers SUNDIALS' N_VGetArrayPointer gives, of a vector made on an array and of its clone.
program test_lincomb
  use, intrinsic :: iso_c_binding
  use check, only: check_true, check_done
  implicit none
  interface
    integer(c_int) function lincomb(nvec, c, x, z) bind(C, name='N_VLinearCombination')
      import :: c_int, c_double, c_ptr
      integer(c_int), value :: nvec
      real(c_double), intent(in) :: c(*)
      type(c_ptr), intent(in) :: x(*)
      type(c_ptr), value :: z
    end function lincomb
    integer(c_int) function lincomb_serial(nvec, c, x, z) bind(C, name='N_VLinearCombination_Serial')
      import :: c_int, c_double, c_ptr
      integer(c_int), value :: nvec
      real(c_double), intent(in) :: c(*)
      type(c_ptr), intent(in) :: x(*)
      type(c_ptr), value :: z
    end function lincomb_serial
    type(c_ptr) function make_serial(n, d, ctx) bind(C, name='N_VMake_Serial')
      import :: c_ptr, c_int64_t
      integer(c_int64_t), value :: n
      type(c_ptr), value :: d
      type(c_ptr), value :: ctx
    end function make_serial
    integer(c_int) function context_create(comm, ctx) bind(C, name='SUNContext_Create')
      import :: c_int, c_ptr
      type(c_ptr), value :: comm
      type(c_ptr), intent(out) :: ctx
    end function context_create
    integer(c_int) function by_element(v) bind(C, name='spline_lincomb_by_element')
      import :: c_int, c_ptr
      type(c_ptr), value :: v
    end function by_element
    type(c_ptr) function serial_data(v) bind(C, name='spline_serial_data')
      import :: c_ptr
      type(c_ptr), value :: v
    end function serial_data
    type(c_ptr) function array_pointer(v) bind(C, name='N_VGetArrayPointer')
      import :: c_ptr
      type(c_ptr), value :: v
    end function array_pointer
    type(c_ptr) function clone(v) bind(C, name='N_VClone')
      import :: c_ptr
      type(c_ptr), value :: v
    end function clone
  end interface
  integer, parameter :: maxn = 31, maxv = 16
  integer, parameter :: lengths(10) = [1, 2, 3, 5, 8, 13, 14, 15, 28, 31]
  real(c_double), target :: xd(maxn, maxv), zd(maxn), wd(maxn), x0(maxn)
  real(c_double) :: c(maxv), r(maxn, maxv)
  type(c_ptr) :: ctx, xv(maxv), zv, wv, xa(maxv)
  integer :: il, n, nvec, i, k, nbad, ncase
  integer, allocatable :: seed(:)

  call check_true('SUNContext', context_create(c_null_ptr, ctx) == 0)
  call random_seed(size=i)
  allocate(seed(i))
  seed = 34
  call random_seed(put=seed)
  nbad = 0; ncase = 0
  do il = 1, size(lengths)
    n = lengths(il)
    do i = 1, maxv
      xv(i) = make_serial(int(n, c_int64_t), c_loc(xd(1, i)), ctx)
    end do
    zv = make_serial(int(n, c_int64_t), c_loc(zd), ctx)
    wv = make_serial(int(n, c_int64_t), c_loc(wd), ctx)
    call check_true('spline_lincomb_by_element', by_element(zv) == 0)
    do nvec = 2, maxv
      do k = 1, 4             ! 1: z apart; 2: z first, c_0 = 1; 3: z first; 4: z a later term
        call random_number(r)
        xd = (r - 0.5_c_double)*10.0_c_double**(int(12*r) - 6)
        call random_number(c)
        c = (c - 0.5_c_double)*3.0_c_double
        xa(1:nvec) = xv(1:nvec)
        if (k == 2) c(1) = 1.0_c_double
        if (k == 2 .or. k == 3) xa(1) = zv
        if (k == 4) xa(nvec) = zv
        zd = xd(:, 1)         ! z's values where it is a term (the first term's, for k = 2, 3)
        if (k == 4) zd = xd(:, nvec)
        x0 = zd
        if (lincomb(int(nvec, c_int), c, xa, zv) /= 0) nbad = nbad + 1
        wd = zd
        zd = x0               ! the same combination by SUNDIALS, into z again
        if (lincomb_serial(int(nvec, c_int), c, xa, zv) /= 0) nbad = nbad + 1
        ncase = ncase + 1
        if (any(wd(1:n) /= zd(1:n))) then
          nbad = nbad + 1
          print '(a,i0,a,i0,a,i0)', 'differs: length ', n, ', terms ', nvec, ', case ', k
        end if
      end do
    end do
  end do
  call check_true('every combination SUNDIALS'' to the bit', nbad == 0 .and. ncase == 600)
  wv = clone(zv)
  call check_true('spline_serial_data: the array a vector was made on', &
       c_associated(serial_data(zv), c_loc(zd)) .and. c_associated(serial_data(zv), array_pointer(zv)))
  call check_true('spline_serial_data: a clone''s own array', c_associated(serial_data(wv), &
       array_pointer(wv)) .and. .not. c_associated(serial_data(wv), c_loc(zd)))
  call check_done('test_lincomb')
end program test_lincomb
