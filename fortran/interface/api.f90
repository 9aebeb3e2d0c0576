!> The thin interface that f2py wraps (signatures and GIL release: fortran/interface/_core.pyf).
!>
!> A case crosses in one call (api_load_file for a file, api_load_fields for fields Python
!> holds): checked, parsed, validated and built, it comes back as its fields (two flat arrays
!> laid out by the field table: spline_case_values) and as a loaded model: the bytes of its
!> model_t, owned by the caller (a numpy int32 array: f2py maps no 1-byte integer kind to C
!> correctly), with the sizes and warnings Python needs. Every other entry
!> point takes those bytes, so nothing here keeps state between calls: any number of loaded
!> cases can be used at once, from any thread, and a loaded case can be pickled to another
!> process of the same build. The bytes are checked (size and a marker) on every call.
!> Errors: ierr (spline_errors: 1 bad case, 2 solver, 3 thermal interference, 4 interrupted)
!> with a message. State vectors have 14 entries, literal here because f2py cannot see
!> imported parameters. Nothing here computes physics: it calls the modules.
module spline_api
  use, intrinsic :: iso_c_binding, only: c_double, c_int
  use spline_kinds, only: wp
  use spline_errors, only: err_ok, err_case, nerr, err_names, msglen, itoa
  use spline_case, only: case_t, case_read_file, case_read_text, case_suggest, case_field, &
       case_field_meta
  use spline_case_values, only: case_value_sizes, case_to_values, case_from_values
  use spline_model, only: model_t, model_from_case, model_magic, nstate, ndof, nkterms, &
       kterm_names, model_warnings
  use spline_stiffness, only: external_tooth_stiffness, internal_tooth_stiffness
  use spline_dynamics, only: accelerations, start_state
  use spline_mesh, only: start_warning
  use spline_run, only: run_case, run_results, tooth_quantities, output_times
  use spline_quantities, only: quantity_t, nstats, stat_q, ntooth_q, tooth_q, state_q, nout_q, &
       output_q, nload, load_q, nload_tooth, load_tooth_q, nextreme, extreme_q
  use spline_realisations, only: copy_model, copy_start, run_sections, transient_state, &
       combined_stats
  use spline_sections, only: section_count
  use spline_lyapunov, only: lyapunov_count, lyapunov_benettin, lyapunov_tangent
  use spline_orbits, only: period_map, map_and_monodromy
  implicit none
  private
  public :: api_load_file, api_load_fields, api_load_text, api_read_text, api_model_size
  public :: api_simulate, api_results
  public :: api_rhs, api_rhs_mesh, api_start_state
  public :: api_output_times, api_model_info, api_defaults, api_names, api_tooth_stiffness
  public :: api_field_hint, api_period_map, api_map_monodromy, api_lyapunov

  integer, parameter :: ninfo = 12   !< entries of api_model_info
  integer, parameter :: nsizes = 5   !< entries of a load's sizes (load_model)

contains

  !> Load a case file in one call: check the path (case_check_file: a regular file of at most
  !> max_case_bytes), read and parse it (case_read_file: the reader and messages of spline-dyn,
  !> naming path and line; the name defaults to the file's stem), return its fields (values,
  !> chars: laid out by the field table, spline_case_values) and, if build /= 0, validate it and
  !> build its model (load_model). stage: 0 the file was refused (ierr, errmsg say why), 1 read
  !> (not built, or the build failed: ierr, errmsg), 2 built. Called without the GIL.
  subroutine api_load_file(path, build, nb, nv, nc, model, sizes, values, chars, warn, stage, &
       ierr, errmsg)
    character(len=*), intent(in) :: path
    integer(c_int), intent(in) :: build, nb, nv, nc
    integer(c_int), intent(out) :: model(nb), sizes(nsizes), chars(nc)
    real(c_double), intent(out) :: values(nv)
    character(len=4096), intent(out) :: warn
    integer(c_int), intent(out) :: stage, ierr
    character(len=msglen), intent(out) :: errmsg
    type(case_t) :: c
    integer :: ie
    model = 0; sizes = 0; values = 0; chars = iachar(' '); warn = ''; stage = 0
    call case_read_file(path, c, ie, errmsg)
    if (ie == err_ok) call fields_out(c, values, chars, ie, errmsg)
    if (ie == err_ok) then
      stage = 1
      if (build /= 0) call load_model(c, model, sizes, warn, ie, errmsg)
      if (build /= 0 .and. ie == err_ok) stage = 2
    end if
    ierr = ie
  end subroutine api_load_file

  !> Validate a case given as its fields (values, chars: as api_load_file returns them) and
  !> build its model (load_model). Called without the GIL.
  subroutine api_load_fields(values, nv, chars, nc, nb, model, sizes, warn, ierr, errmsg)
    integer(c_int), intent(in) :: nv, nc, nb
    real(c_double), intent(in) :: values(nv)
    integer(c_int), intent(in) :: chars(nc)
    integer(c_int), intent(out) :: model(nb), sizes(nsizes)
    character(len=4096), intent(out) :: warn
    integer(c_int), intent(out) :: ierr
    character(len=msglen), intent(out) :: errmsg
    type(case_t) :: c
    character(len=nc) :: s
    integer :: ie, i
    model = 0; sizes = 0; warn = ''
    do i = 1, nc
      s(i:i) = achar(iand(chars(i), 255))
    end do
    call case_from_values(values, s, c, ie, errmsg)
    if (ie == err_ok) call load_model(c, model, sizes, warn, ie, errmsg)
    ierr = ie
  end subroutine api_load_fields

  !> Read a case from namelist text (messages name the case, no line), validate it and build
  !> its model (load_model): for the values api_load_fields cannot carry (an integer beyond
  !> 32 bits, a string longer than its field), so that the reader says what is wrong.
  subroutine api_load_text(text, nb, model, sizes, warn, ierr, errmsg)
    character(len=*), intent(in) :: text
    integer(c_int), intent(in) :: nb
    integer(c_int), intent(out) :: model(nb), sizes(nsizes)
    character(len=4096), intent(out) :: warn
    integer(c_int), intent(out) :: ierr
    character(len=msglen), intent(out) :: errmsg
    type(case_t) :: c
    integer :: ie
    model = 0; sizes = 0; warn = ''
    call case_read_text(text, c, ie, errmsg)
    if (ie == err_ok) call load_model(c, model, sizes, warn, ie, errmsg)
    ierr = ie
  end subroutine api_load_text

  !> Read a case from namelist text, without validating or building it (pyspline merge: the
  !> case of a spline-dyn summary, also of a run its values failed); its fields as
  !> api_load_file returns them.
  subroutine api_read_text(text, nv, nc, values, chars, ierr, errmsg)
    character(len=*), intent(in) :: text
    integer(c_int), intent(in) :: nv, nc
    real(c_double), intent(out) :: values(nv)
    integer(c_int), intent(out) :: chars(nc)
    integer(c_int), intent(out) :: ierr
    character(len=msglen), intent(out) :: errmsg
    type(case_t) :: c
    integer :: ie
    values = 0; chars = iachar(' ')
    call case_read_text(text, c, ie, errmsg)
    if (ie == err_ok) call fields_out(c, values, chars, ie, errmsg)
    ierr = ie
  end subroutine api_read_text

  !> The fields of c as api_load_file returns them (characters as byte values 0..255).
  subroutine fields_out(c, values, chars, ierr, errmsg)
    type(case_t), intent(in) :: c
    real(c_double), intent(out) :: values(:)
    integer(c_int), intent(out) :: chars(:)
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    character(len=size(chars)) :: s
    integer :: nv, nc, i
    call case_value_sizes(nv, nc)
    ierr = err_ok; errmsg = ''
    if (size(values) /= nv .or. size(chars) /= nc) then
      ierr = err_case
      errmsg = 'case values: the arrays do not match the field table (api_names(''layout''))'
      return
    end if
    call case_to_values(c, values, s)
    do i = 1, nc
      chars(i) = iachar(s(i:i))
    end do
  end subroutine fields_out

  !> Validate c and build its model (model_from_case) into the caller's bytes, with what
  !> Python needs to use it (sizes: z, n_out, Poincare section points, Benettin
  !> renormalisations, face slices (0 for an unsliced face)) and its warnings (model_warnings,
  !> one per line).
  subroutine load_model(c, model, sizes, warn, ierr, errmsg)
    type(case_t), intent(in) :: c
    integer(c_int), intent(out) :: model(:), sizes(nsizes)
    character(len=*), intent(out) :: warn
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    type(model_t) :: m
    character(len=:), allocatable :: start, text
    model = 0; sizes = 0; warn = ''
    call model_from_case(c, m, ierr, errmsg)
    if (ierr == err_ok .and. size(model) /= model_words()) then
      ierr = err_case; errmsg = 'api_load: the model array has the wrong size (api_model_size)'
    end if
    if (ierr /= err_ok) return
    model = transfer(m, model)
    sizes = [m%z, m%n_out, run_sections(m), lyapunov_count(m), &
         merge(m%n_slices, 0, m%n_slices > 1)]       ! realisations > 1: one copy's
    call start_warning(m, start)
    call model_warnings(m, start, text)
    warn = text
  end subroutine load_model

  !> The case field nearest to a misspelt name (blank if none is near): the suggestion of the
  !> reader's 'did you mean', for the fields Python is given as a dict.
  subroutine api_field_hint(word, hint)
    character(len=*), intent(in) :: word
    character(len=32), intent(out) :: hint
    hint = case_suggest(word)
  end subroutine api_field_hint

  !> 4-byte words in a loaded model (the size of the array the api_load_* calls fill), for
  !> Python (a subroutine: f2py's wrapper of a module function without arguments does not
  !> match its own interface).
  subroutine api_model_size(nb)
    integer(c_int), intent(out) :: nb
    nb = model_words()
  end subroutine api_model_size

  !> 4-byte words in a loaded model: those transfer packs a model_t into.
  integer(c_int) function model_words() result(nb)
    type(model_t) :: m
    nb = size(transfer(m, [0_c_int]))
  end function model_words

  !> The model_t in the bytes of a loaded model; ierr = err_case if they are not one.
  !> max_seconds (optional, > 0): the call's wall-time bound over all its runs, from now
  !> (m%max_seconds, m%wall_start; spline_integrator::integrator_open); 0: none.
  subroutine unpack(model, m, ierr, errmsg, max_seconds)
    integer(c_int), intent(in) :: model(:)
    type(model_t), intent(out) :: m
    integer, intent(out) :: ierr
    character(len=*), intent(out) :: errmsg
    real(c_double), intent(in), optional :: max_seconds
    ierr = err_ok
    errmsg = ''
    if (size(model) == model_words()) then
      m = transfer(model, m)
      if (m%magic == model_magic) then
        if (present(max_seconds)) then
          if (max_seconds > 0.0_c_double) then
            m%max_seconds = max_seconds
            call system_clock(m%wall_start)
          end if
        end if
        return
      end if
    end if
    ierr = err_case
    errmsg = 'not a loaded case of this build of pyspline (load the case again)'
  end subroutine unpack

  !> Simulate a loaded model: output times t, SI states y (14 x nt: a column per output), per-tooth quantities tooth
  !> (nt x z x nq, order of api_names('tooth')), meshing torque tm and run statistics; the
  !> Poincare section (times sec_t, SI states sec_y: nsec x 14) and the Benettin record (times
  !> lyap_t, cumulative log growth lyap_g), sized by the load's sizes; for a sliced face (nslice > 0,
  !> nft = nt, else both 0) the load of every slice face(nt, z, nslice) and the tilting moment
  !> tilt(nt, 2) (M_x, M_y) on spline 1 [N m]. nqw: the quantities written into tooth, 4 for a
  !> level without flash temperature or slices (F, F_x, F_y, dn; its c_j, T_f, r_c1, r_c2 are
  !> the constants consts, run_case's nq), else nq (consts 0). In the same call, what follows from
  !> the outputs (spline_run::run_results): the loads (order of api_names('loads')), tload(z, :)
  !> (api_names('tooth_loads')), the extremes and RMS ext (api_names('extremes')) and the run's
  !> warnings, one per line (blank if none; the integrator's are errmsg's on success).
  !> A case with realisations = K > 1 runs copy `copy` (1..K) from ya, the state at the end of
  !> the transient (api_start_state), over its window (spline_realisations); loads, tload, ext
  !> and warnings stay 0 and blank: they are the K copies' together (api_results).
  !> nk: the runs t, y, tooth and tm hold (1, or K: the copies' arrays, copy k writing block k
  !> of nt rows in place and no other element, so the K copies may run at once on one set of
  !> arrays; its sections, face and tilt are its own).
  !> A SIGINT during the run stops it (ierr 4). max_seconds > 0: the call's wall-time bound
  !> over all its runs (a run past it fails naming it, as a solver failure; 0: none).
  !> Called without the GIL.
  subroutine api_simulate(model, nb, z, nt, nk, nq, ns, nsec, nlyap, nft, nslice, nl, ntl, nx, t, &
       y, tooth, tm, stats, sec_t, sec_y, lyap_t, lyap_g, face, tilt, nqw, consts, loads, tload, &
       ext, warnings, copy, ya, ierr, errmsg, max_seconds)
    integer(c_int), intent(in) :: nb, z, nt, nk, nq, ns, nsec, nlyap, nft, nslice, nl, ntl, nx
    integer(c_int), intent(in) :: copy
    real(c_double), intent(in) :: ya(14), max_seconds
    integer(c_int), intent(in) :: model(nb)
    real(c_double), intent(inout) :: t(nt*nk), y(14, nt*nk), tooth(nt*nk, z, nq), tm(nt*nk)
    real(c_double), intent(out) :: stats(ns)
    real(c_double), intent(out) :: sec_t(nsec), sec_y(nsec, 14), lyap_t(nlyap), lyap_g(nlyap)
    real(c_double), intent(out) :: face(nft, z, nslice), tilt(nft, 2), consts(4)
    real(c_double), intent(out) :: loads(nl), tload(z, ntl), ext(nx)
    character(len=8192), intent(out) :: warnings
    integer(c_int), intent(out) :: nqw, ierr
    character(len=msglen), intent(out) :: errmsg
    type(model_t) :: m
    real(wp), allocatable :: scol(:, :)
    character(len=:), allocatable :: text
    integer :: ie, nw, r
    stats = 0; sec_t = 0; sec_y = 0; lyap_t = 0; lyap_g = 0   ! t, y, tooth, tm: below
    face = 0; tilt = 0; nqw = nq; consts = 0; loads = 0; tload = 0; ext = 0; warnings = ''
    call unpack(model, m, ie, errmsg, max_seconds)
    if (ie == err_ok .and. (m%z /= z .or. m%n_out /= nt .or. nq /= ntooth_q .or. ns /= nstats &
         .or. nsec /= run_sections(m) .or. (m%realisations > 1 .and. &
         (copy < 1 .or. copy > m%realisations)) .or. nlyap /= lyapunov_count(m) .or. &
         nslice /= merge(m%n_slices, 0, m%n_slices > 1) .or. nft /= merge(nt, 0, nslice > 0) &
         .or. nl /= nload .or. ntl /= nload_tooth .or. nx /= nextreme .or. &
         (nk /= 1 .and. nk /= max(m%realisations, 1)))) then
      ie = err_case
      errmsg = 'api_simulate: array sizes do not match the loaded case'
    end if
    if (ie == err_ok) then
      allocate(scol(nstate, nsec))
      r = merge(copy - 1, 0, nk > 1)            ! this run's block of rows
      call run_rows(t(r*nt+1:(r+1)*nt), y(:, r*nt+1:(r+1)*nt), tooth(r*nt+1:(r+1)*nt, :, :), &
           tm(r*nt+1:(r+1)*nt))
      nqw = nw
      sec_y = transpose(scol)
      if (ie == err_ok .and. m%realisations == 1) then     ! nk = 1: the arrays, contiguous
        call run_results(m, t, y, tooth(:, :, 1:nw), tm, stats, consts, loads, tload, ext, text)
        warnings = text
      end if
    else
      t = 0; y = 0; tooth = 0; tm = 0       ! run_case defines them whenever it runs
    end if
    ierr = ie
  contains
    !> The run into its rows (t, y, tm contiguous; tooth a section of the caller's array).
    subroutine run_rows(t, y, tooth, tm)
      real(wp), intent(out) :: t(nt), y(nstate, nt), tooth(:, :, :), tm(nt)
      if (m%realisations > 1 .and. nslice > 0) then
        call run_case(copy_model(m), t, y, tooth, tm, stats, ie, errmsg, interruptible=.true., &
             sec_t=sec_t, sec_y=scol, face=face, tilt=tilt, nq=nw, consts=consts, &
             y_start=copy_start(copy, ya))
      else if (m%realisations > 1) then
        call run_case(copy_model(m), t, y, tooth, tm, stats, ie, errmsg, interruptible=.true., &
             sec_t=sec_t, sec_y=scol, nq=nw, consts=consts, y_start=copy_start(copy, ya))
      else if (nslice > 0) then
        call run_case(m, t, y, tooth, tm, stats, ie, errmsg, interruptible=.true., &
             sec_t=sec_t, sec_y=scol, lyap_t=lyap_t, lyap_g=lyap_g, face=face, tilt=tilt, &
             nq=nw, consts=consts)
      else
        call run_case(m, t, y, tooth, tm, stats, ie, errmsg, interruptible=.true., &
             sec_t=sec_t, sec_y=scol, lyap_t=lyap_t, lyap_g=lyap_g, nq=nw, consts=consts)
      end if
    end subroutine run_rows
  end subroutine api_simulate

  !> What follows from the outputs of a case with realisations = K (spline_run::run_results):
  !> t, y, tooth(:, :, 1:nq), tm the K copies' outputs one after another as api_simulate gave
  !> them (nq: its nqw, consts: its consts), stats(:, k) copy k's statistics. st: the copies'
  !> statistics combined (spline_realisations::combined_stats); loads, tload, ext and warnings
  !> as api_simulate gives them for one run, from the copies' outputs together (the loads:
  !> spline_loads::combined_loads, standard errors from the spread between the copies).
  subroutine api_results(model, nb, z, nt, nq, ns, k, nl, ntl, nx, t, y, tooth, tm, stats, &
       consts, st, loads, tload, ext, warnings, ierr, errmsg)
    integer(c_int), intent(in) :: nb, z, nt, nq, ns, k, nl, ntl, nx
    integer(c_int), intent(in) :: model(nb)
    real(c_double), intent(in) :: t(nt), y(14, nt), tooth(nt, z, nq), tm(nt), stats(ns, k)
    real(c_double), intent(in) :: consts(4)
    real(c_double), intent(out) :: st(ns), loads(nl), tload(z, ntl), ext(nx)
    character(len=8192), intent(out) :: warnings
    integer(c_int), intent(out) :: ierr
    character(len=msglen), intent(out) :: errmsg
    type(model_t) :: m
    character(len=:), allocatable :: text
    integer :: ie
    st = 0; loads = 0; tload = 0; ext = 0; warnings = ''
    call unpack(model, m, ie, errmsg)
    if (ie == err_ok .and. (m%z /= z .or. (nq /= ntooth_q .and. nq /= 4) .or. ns /= nstats .or. &
         k /= m%realisations .or. nt /= k*m%n_out .or. nl /= nload .or. ntl /= nload_tooth .or. &
         nx /= nextreme)) then
      ie = err_case; errmsg = 'api_results: array sizes do not match the loaded case'
    end if
    if (ie == err_ok) then
      call combined_stats(stats, st)
      call run_results(m, t, y, tooth, tm, st, consts, loads, tload, ext, text)
      warnings = text
    end if
    ierr = ie
  end subroutine api_results

  !> SI right-hand side dy/dt at (t, y) of a loaded model, contact states from the state:
  !> the project's Fortran RHS for solvers driven from Python (the benchmarks' peers).
  subroutine api_rhs(model, nb, t, y, ydot, ierr)
    integer(c_int), intent(in) :: nb
    integer(c_int), intent(in) :: model(nb)
    real(c_double), intent(in) :: t, y(14)
    real(c_double), intent(out) :: ydot(14)
    integer(c_int), intent(out) :: ierr
    character(len=msglen) :: errmsg
    type(model_t) :: m
    integer :: ie
    ydot = 0
    call unpack(model, m, ie, errmsg)
    if (ie == err_ok) then
      ydot(1:ndof) = y(ndof+1:)
      call accelerations(m, t, y(1:ndof), y(ndof+1:), ydot(ndof+1:), ie, errmsg)
    end if
    ierr = ie
  end subroutine api_rhs

  !> api_rhs plus the mesh: per-tooth mesh(:, k) in the order of api_names('tooth') and the
  !> torque tm, for tests that hold the core against the independent numpy oracle.
  subroutine api_rhs_mesh(model, nb, z, nq, t, y, ydot, mesh, tm, ierr, errmsg)
    integer(c_int), intent(in) :: nb, z, nq
    integer(c_int), intent(in) :: model(nb)
    real(c_double), intent(in) :: t, y(14)
    real(c_double), intent(out) :: ydot(14), mesh(z, nq), tm
    integer(c_int), intent(out) :: ierr
    character(len=msglen), intent(out) :: errmsg
    type(model_t) :: m
    integer :: ie
    ydot = 0; mesh = 0; tm = 0
    call unpack(model, m, ie, errmsg)
    if (ie == err_ok .and. (m%z /= z .or. nq /= ntooth_q)) then
      ie = err_case; errmsg = 'api_rhs_mesh: array sizes do not match the loaded case'
    end if
    if (ie == err_ok) then
      ydot(1:ndof) = y(ndof+1:)
      call accelerations(m, t, y(1:ndof), y(ndof+1:), ydot(ndof+1:), ie, errmsg)
    end if
    if (ie == err_ok) call tooth_quantities(m, t, y, mesh, tm, ie, errmsg)
    ierr = ie
  end subroutine api_rhs_mesh

  !> The start state of a loaded model (SI): static equilibrium or rest, plus dq0, dv0; with
  !> transient = 1 the state at the end of the transient (spline_realisations::transient_state,
  !> from which realisations = K > 1 runs its copies; a SIGINT stops it, ierr 4; max_seconds > 0:
  !> its wall-time bound, a run past it fails naming it, as api_simulate's; 0: none).
  subroutine api_start_state(model, nb, transient, y, ierr, errmsg, max_seconds)
    integer(c_int), intent(in) :: nb, transient
    integer(c_int), intent(in) :: model(nb)
    real(c_double), intent(out) :: y(14)
    integer(c_int), intent(out) :: ierr
    character(len=msglen), intent(out) :: errmsg
    real(c_double), intent(in) :: max_seconds
    type(model_t) :: m
    integer :: ie
    y = 0
    call unpack(model, m, ie, errmsg, max_seconds)
    if (ie == err_ok .and. transient == 1) then
      call transient_state(m, y, ie, errmsg, interruptible=.true.)
    else if (ie == err_ok) then
      call start_state(m, y, ie, errmsg)
    end if
    ierr = ie
  end subroutine api_start_state

  !> The period map of a loaded model (spline_orbits::period_map): y1(:, k) the SI state at
  !> t1 of the run from y0(:, k) at t0; mask(i) = 1 for the states its level integrates.
  !> max_seconds (> 0): the call's wall-time bound. On success errmsg holds the integrator's
  !> warnings ('' if none). Called without the GIL; a SIGINT stops it (ierr 4).
  subroutine api_period_map(model, nb, t0, t1, nc, y0, y1, mask, ierr, errmsg, max_seconds)
    integer(c_int), intent(in) :: nb, nc
    integer(c_int), intent(in) :: model(nb)
    real(c_double), intent(in) :: t0, t1, y0(14, nc), max_seconds
    real(c_double), intent(out) :: y1(14, nc)
    integer(c_int), intent(out) :: mask(14), ierr
    character(len=msglen), intent(out) :: errmsg
    type(model_t) :: m
    integer :: ie, mk(14)
    y1 = 0; mask = 0
    call unpack(model, m, ie, errmsg)
    if (ie == err_ok) then
      call period_map(m, t0, t1, y0, y1, mk, ie, errmsg, interruptible=.true., &
           max_seconds=max_seconds)
      mask = mk
    end if
    ierr = ie
  end subroutine api_period_map

  !> The period map and its monodromy from the variational equations with the saltation
  !> matrices (spline_orbits::map_and_monodromy; salt = 0: without them): y1 the SI state at
  !> t1, phi(1:k, 1:k) dP/dy0 over the k integrated states (mask) in the scaled states of
  !> Eq. 25, nswitch the contact switches located; max_seconds (> 0) the run's wall-time bound.
  !> On success errmsg holds the integrator's warnings. Called without the GIL.
  subroutine api_map_monodromy(model, nb, t0, t1, y0, salt, y1, phi, mask, nswitch, ierr, &
       errmsg, max_seconds)
    integer(c_int), intent(in) :: nb, salt
    integer(c_int), intent(in) :: model(nb)
    real(c_double), intent(in) :: t0, t1, y0(14), max_seconds
    real(c_double), intent(out) :: y1(14), phi(14, 14)
    integer(c_int), intent(out) :: mask(14), nswitch, ierr
    character(len=msglen), intent(out) :: errmsg
    type(model_t) :: m
    integer :: ie, mk(14), ns
    y1 = 0; phi = 0; mask = 0; nswitch = 0
    call unpack(model, m, ie, errmsg)
    if (ie == err_ok) then
      call map_and_monodromy(m, t0, t1, y0, y1, phi, mk, ns, ie, errmsg, interruptible=.true., &
           saltation=salt /= 0, max_seconds=max_seconds)
      mask = mk
      nswitch = ns
    end if
    ierr = ie
  end subroutine api_map_monodromy

  !> The largest Lyapunov exponent's running sums from (t_start, y_start), SI, over nl
  !> renormalisations of the model's lyapunov_interval: tangent = 0 by a separated copy
  !> (spline_lyapunov::lyapunov_benettin, as runs do), 1 by the tangent vector
  !> (lyapunov_tangent). The model level as the case sets it (not auto). Called without the GIL.
  subroutine api_lyapunov(model, nb, tangent, t_start, y_start, nl, lt, lg, ierr, errmsg)
    integer(c_int), intent(in) :: nb, tangent, nl
    integer(c_int), intent(in) :: model(nb)
    real(c_double), intent(in) :: t_start, y_start(14)
    real(c_double), intent(out) :: lt(nl), lg(nl)
    integer(c_int), intent(out) :: ierr
    character(len=msglen), intent(out) :: errmsg
    type(model_t) :: m
    integer :: ie
    lt = 0; lg = 0
    call unpack(model, m, ie, errmsg)
    if (ie == err_ok) then
      m%t_end = t_start + nl*m%lyap_dt
      if (tangent /= 0) then
        call lyapunov_tangent(m, t_start, y_start, lt, lg, ie, errmsg, interruptible=.true.)
      else
        call lyapunov_benettin(m, t_start, y_start, lt, lg, ie, errmsg, interruptible=.true.)
      end if
    end if
    ierr = ie
  end subroutine api_lyapunov

  !> The output times of a loaded model (uniform after the transient).
  subroutine api_output_times(model, nb, nt, t, ierr, errmsg)
    integer(c_int), intent(in) :: nb, nt
    integer(c_int), intent(in) :: model(nb)
    real(c_double), intent(out) :: t(nt)
    integer(c_int), intent(out) :: ierr
    character(len=msglen), intent(out) :: errmsg
    type(model_t) :: m
    integer :: ie
    t = 0
    call unpack(model, m, ie, errmsg)
    if (ie == err_ok .and. m%n_out /= nt) then
      ie = err_case; errmsg = 'api_output_times: nt does not match the loaded case'
    end if
    if (ie == err_ok) call output_times(m, t)
    ierr = ie
  end subroutine api_output_times

  !> Derived quantities of a loaded model, in the order of api_names('info'): base radius r_b
  !> [m], pitch radius [m], shaft speed omega [rad/s], the scales of Eq. 25 l_ref [m] and
  !> w_ref [rad/s], the backlash at the bulk temperature [m], kappa [m/degC] (Eq. 2), the
  !> k_m used [N/m], 1 if it is computed (Eq. 18), the thermal level (0 none .. 3 coupled);
  !> and the Eq. 18 terms (order of api_names('kterms')); the tooth spacing errors in use e_j
  !> of teeth 1 .. z [m] (the list plus the seeded ones, docs/model.md section 11).
  subroutine api_model_info(model, nb, z, info, terms, spacing, ierr, errmsg)
    integer(c_int), intent(in) :: nb, z
    integer(c_int), intent(in) :: model(nb)
    real(c_double), intent(out) :: info(ninfo), terms(nkterms), spacing(z)
    integer(c_int), intent(out) :: ierr
    character(len=msglen), intent(out) :: errmsg
    type(model_t) :: m
    integer :: ie
    info = 0; terms = 0; spacing = 0
    call unpack(model, m, ie, errmsg)
    if (ie == err_ok .and. z /= m%z) then
      ie = err_case
      errmsg = 'case '//trim(m%name)//': api_model_info for '//itoa(z)//' teeth, the model has '// &
           itoa(m%z)
    end if
    if (ie == err_ok) then
      spacing = m%spacing_error(1:z)
      info = [m%r_b, m%r_pitch, m%omega, m%l_ref, m%w_ref, m%c_bulk, m%kappa, m%k_m, &
           merge(1.0_wp, 0.0_wp, m%k_m_computed), real(m%thermal, wp), m%c_m, m%m_e]
      terms = m%k_terms
    end if
    ierr = ie
  end subroutine api_model_info

  !> Every case field with its default (case_t's component defaults), laid out as
  !> api_load_file returns fields: Python reads its defaults here.
  subroutine api_defaults(nv, nc, values, chars, ierr, errmsg)
    integer(c_int), intent(in) :: nv, nc
    real(c_double), intent(out) :: values(nv)
    integer(c_int), intent(out) :: chars(nc)
    integer(c_int), intent(out) :: ierr
    character(len=msglen), intent(out) :: errmsg
    integer :: ie
    call fields_out(case_t(), values, chars, ie, errmsg)
    ierr = ie
  end subroutine api_defaults

  !> Name, unit and one-line description of entry i (1, 2, ...) of a list; blank past its end.
  !> Units are SI ('-' a ratio, '' none). Lists: 'outputs' (every output quantity in the order
  !> of the executable's CSV columns: t, the states, Tm, kv, the per-tooth quantities),
  !> 'states' (a state vector's), 'tooth' (the per-tooth quantities, order of api_simulate's
  !> tooth), 'stats' (a run's statistics), 'loads' and 'tooth_loads' (the loads of a run, its
  !> scalars and per tooth), 'extremes' (a run's extremes and RMS; all of them api_simulate's
  !> outputs): the table of spline_quantities; 'fields' (the case
  !> fields, case_type.f90's table); 'layout' (the case fields, unit: type i, r, l or c and
  !> the size, e.g. 'r7', 'c16': how api_load_fields lays them out); 'info'
  !> (api_model_info), 'kterms' (Eq. 18 terms), 'errors' (error codes 0..nerr, i = code + 1).
  subroutine api_names(kind, i, name, unit, descr)
    character(len=*), intent(in) :: kind
    integer(c_int), intent(in) :: i
    character(len=32), intent(out) :: name, unit
    character(len=128), intent(out) :: descr
    character(len=16), parameter :: info_names(ninfo) = [character(len=16) :: 'r_b', 'r_pitch', &
         'omega', 'l_ref', 'w_ref', 'c_bulk', 'kappa', 'k_m', 'k_m_computed', 'thermal_level', &
         'c_m', 'm_e']
    character(len=8), parameter :: info_units(ninfo) = [character(len=8) :: 'm', 'm', 'rad/s', &
         'm', 'rad/s', 'm', 'm/degC', 'N/m', '', '', 'N s/m', 'kg']
    character(len=1) :: ftype
    integer :: n
    name = ''; unit = ''; descr = ''
    select case (kind)
    case ('outputs')
      if (i >= 1 .and. i <= nout_q) call row(output_q(i))
    case ('states')
      if (i >= 1 .and. i <= size(state_q)) call row(state_q(i))
    case ('tooth')
      if (i >= 1 .and. i <= ntooth_q) call row(tooth_q(i))
    case ('stats')
      if (i >= 1 .and. i <= nstats) call row(stat_q(i))
    case ('loads')
      if (i >= 1 .and. i <= nload) call row(load_q(i))
    case ('tooth_loads')
      if (i >= 1 .and. i <= nload_tooth) call row(load_tooth_q(i))
    case ('extremes')
      if (i >= 1 .and. i <= nextreme) call row(extreme_q(i))
    case ('fields')
      call case_field_meta(i, name, ftype, n, unit, descr)
    case ('layout')
      call case_field(i, name, unit, n)
      if (len_trim(name) > 0 .and. (n > 1 .or. unit == 'c')) write(unit, '(a,i0)') trim(unit), n
    case ('info')
      if (i >= 1 .and. i <= ninfo) then
        name = info_names(i); unit = info_units(i)
      end if
    case ('kterms')
      if (i >= 1 .and. i <= nkterms) then
        name = kterm_names(i); unit = 'N/m'
      end if
    case ('errors')
      if (i >= 1 .and. i <= nerr + 1) name = err_names(i - 1)
    end select
  contains
    subroutine row(q)
      type(quantity_t), intent(in) :: q
      name = q%name; unit = q%unit; descr = q%descr
    end subroutine row
  end subroutine api_names

  !> Bending, shear and axial stiffness of one involute tooth (potential energy method) for any
  !> gear: external (internal = 0; r_tip unused) or internal (ring) tooth. Angles in radians.
  subroutine api_tooth_stiffness(internal, z, m, alpha, b, r_root, r_tip, e, nu, r_contact, &
       nquad, kb, ks, ka, ierr, errmsg)
    integer(c_int), intent(in) :: internal, nquad
    real(c_double), intent(in) :: z, m, alpha, b, r_root, r_tip, e, nu, r_contact
    real(c_double), intent(out) :: kb, ks, ka
    integer(c_int), intent(out) :: ierr
    character(len=msglen), intent(out) :: errmsg
    integer :: ie
    if (internal /= 0) then
      call internal_tooth_stiffness(z, m, alpha, b, r_root, r_tip, e, nu, r_contact, nquad, &
           kb, ks, ka, ie, errmsg)
    else
      call external_tooth_stiffness(z, m, alpha, b, r_root, e, nu, r_contact, nquad, &
           kb, ks, ka, ie, errmsg)
    end if
    ierr = ie
    if (ie == 0) errmsg = ''
  end subroutine api_tooth_stiffness

end module spline_api
