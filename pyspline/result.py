"""The core's runs and their Result, below the case layer: the core's name tables (the output
quantities, states, loads, statistics), its errors and warnings as Python's, and ``run``: a
loaded Model (pyspline.case) through api_simulate into a Result. pyspline.core is the public
face (``simulate`` takes a Case, a dict or a path); this module imports no other of pyspline's
but errors and bridge (the calls of the compiled core), so that case and core both build on it.
"""
from __future__ import annotations

import concurrent.futures as cf
import contextlib
import contextvars
import functools
import os
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from . import bridge
from .errors import BY_NAME, SplineError, SplineWarning, decode

THERMAL_LEVELS = ("none", "bulk", "oneway", "coupled")   #: stats["thermal_level"] 0..3


@functools.cache
def _names(kind: str) -> tuple:
    """The core's list `kind` (api_names in fortran/interface/api.f90): (name, unit, description) per
    entry; units SI, '-' a ratio, '' none. The output quantities and statistics are the table
    of fortran/common/quantities.f90, the case fields that of fortran/input/case_type.f90."""
    out = []
    for i in range(1, 1000):
        name, unit, descr = (decode(s) for s in bridge.name_entry(kind, i))
        if not name:
            break
        out.append((name, unit, descr))
    return tuple(out)


def cf_units(unit: str) -> str:
    """A unit of the core's tables as a netCDF/CF 'units' attribute: '1' for a ratio ('-')."""
    return "1" if unit == "-" else unit


@functools.cache
def _errors() -> dict:
    """Error code of the core -> exception class (codes and names from fortran/common/errors.f90)."""
    return {i: BY_NAME.get(name, SplineError) for i, (name, *_) in enumerate(_names("errors"))}



@contextlib.contextmanager
def sundials_said(what: str):
    """SUNDIALS' counted warnings of many runs (a continuation's map runs) said once: how many
    runs warned and the first one's words; said["runs"] holds the number; every other warning
    passes as it came."""
    said = {"runs": 0}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield said
    first = None
    for w in caught:
        if issubclass(w.category, SplineWarning) and "SUNDIALS warned" in str(w.message):
            said["runs"] += 1
            first = first or str(w.message)
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    if first:
        warnings.warn(f"SUNDIALS warned in {said['runs']} of {what}; the first: {first}",
                      SplineWarning, stacklevel=3)


#: the list the core's warnings go to instead of SplineWarning while `collected` runs (per
#: thread and task: a sweep point's, on any executor)
_COLLECT = contextvars.ContextVar("pyspline_collect", default=None)


@contextlib.contextmanager
def collected():
    """The core's warnings of the runs and model builds inside (in this thread), kept in the
    list it yields (one line each) instead of raised: a sweep point's (pyspline.warned)."""
    lines: list = []
    token = _COLLECT.set(lines)
    try:
        yield lines
    finally:
        _COLLECT.reset(token)


def warning_lines(text) -> tuple:
    """The core's warnings text (bytes or str) as its lines, blank ones left out."""
    return tuple(line.strip() for line in decode(text).splitlines() if line.strip())


def _warn(text, stacklevel: int = 3) -> None:
    """The core's warnings (one per line, the words spline-dyn prints) as SplineWarning,
    attributed to the frame `stacklevel` up (3: the caller of _warn's caller); inside
    `collected`, into its list."""
    into = _COLLECT.get()
    for line in warning_lines(text):
        if into is not None:
            into.append(line)
        else:
            warnings.warn(line, SplineWarning, stacklevel=stacklevel)


def raise_for(ierr: int, errmsg) -> None:
    """Turn the core's (ierr, message) into the matching exception."""
    if ierr != 0:
        raise _errors().get(int(ierr), SplineError)(decode(errmsg))


def run_outcome(ierr: int, errmsg) -> None:
    """A run's (ierr, message): the exception, or on success the message's lines (the
    integrator's warnings, counted over the run: spline_integrator::integrator_warnings) as
    SplineWarning."""
    raise_for(ierr, errmsg)
    _warn(errmsg)


def level_name(dof: int, thermal: str) -> str:
    """A model level of the fidelity ladder, e.g. '7-DOF coupled'."""
    return f"{dof}-DOF {thermal}"



#: Result quantities from the core's table (fortran/common/quantities.f90): name -> (description,
#: unit), every output (time t, states, Tm, kv, per-tooth), the states (position and velocity,
#: order of a state vector) and the per-tooth quantities (time, tooth).
QUANTITIES = {n: (d, u) for n, u, d in _names("outputs")}
STATE_QUANTITIES = {n: (d, u) for n, u, d in _names("states")}
TOOTH_QUANTITIES = {n: (d, u) for n, u, d in _names("tooth")}
FIELDS = {n: (d, u) for n, u, d in _names("fields")}   #: the case fields: (description, unit)
STATE_NAMES = tuple(STATE_QUANTITIES)[:len(STATE_QUANTITIES) // 2]   #: x1 .. D3 (positions)
#: The loads of a run (spline_loads::run_loads, docs/model.md section 15): name -> (description,
#: unit), the scalars and the per-tooth ones (arrays over the teeth).
LOAD_QUANTITIES = {n: (d, u) for n, u, d in _names("loads")}
TOOTH_LOAD_QUANTITIES = {n: (d, u) for n, u, d in _names("tooth_loads")}
#: The extremes and RMS of a run's outputs (spline_loads::run_extremes; Result.extremes, what a
#: sweep point and spline-dyn's summary keep): name -> (description, unit).
EXTREMES = {n: (d, u) for n, u, d in _names("extremes")}


def _attrs(name: str, table: dict = None) -> dict:
    """xarray attrs of a quantity of the core's tables (an output or a load, or one of `table`):
    long_name, units (if any)."""
    long, unit = (table[name] if table else QUANTITIES.get(name) or LOAD_QUANTITIES.get(name)
                  or TOOTH_LOAD_QUANTITIES[name])
    return {"long_name": long, "units": cf_units(unit)} if unit else {"long_name": long}


def _tooth_quantity(name: str) -> property:
    def get(self):
        try:
            return self.tooth[name]
        except KeyError:
            raise AttributeError(f"this Result has no per-tooth quantity {name!r}") from None
    get.__name__ = name
    long, unit = TOOTH_QUANTITIES[name]
    return property(get, doc=f"{long} [{unit}], shape (nt, Z)")


def _state(name: str) -> property:
    i = tuple(STATE_QUANTITIES).index(name)

    def get(self):
        return self.y[:, i]
    get.__name__ = name
    long, unit = STATE_QUANTITIES[name]
    return property(get, doc=f"{long} [{unit}], shape (nt,)")


@dataclass
class Result:
    """A simulation in SI units. Per-tooth arrays have shape (nt, Z).

    Every quantity is an attribute: the states ``x1 y1 x2 y2 D1 D2 D3`` [m] and their
    velocities ``vx1 ... vD3`` [m/s] (nt,), the per-tooth ``F Fx Fy dn c Tf rc1 rc2`` (nt, Z;
    without flash temperature or slices c, Tf, rc1, rc2 are constants, read-only broadcasts),
    ``Tm`` and ``kv`` (nt,); ``loads``: the load sharing, free and back-flank teeth, impacts
    and T_f max of the run (the core's). ``to_xarray()`` gives all of it as an xarray.Dataset."""
    case: Case
    t: np.ndarray            #: output times [s]
    y: np.ndarray            #: states (nt, 14): x1, y1, x2, y2, D1, D2, D3 [m], then their velocities [m/s]
    tooth: dict              #: per-tooth quantities by name: F, Fx, Fy [N], dn, c [m], Tf [degC], rc1, rc2 [m]
    Tm: np.ndarray           #: meshing torque T_m (Eq. 22) [N m]
    stats: dict = field(default_factory=dict)   #: CVODE statistics and run time
    section_t: np.ndarray = None   #: Poincare section times [s] (case field section)
    section_y: np.ndarray = None   #: states at the section times (n, 14), SI, like y
    lyapunov: dict = None    #: Benettin record (case field lyapunov): t [s], log_growth, exponent [1/s]
    face: np.ndarray = None  #: sliced face (n_slices > 1): load of slice s of tooth j, (nt, Z, n_slices) [N]
    tilt: np.ndarray = None  #: sliced face: tilting moment (M_x, M_y) on spline 1, (nt, 2) [N m]
    #: the loads of the run (the core's, from its outputs: docs/model.md section 15), by name:
    #: scalars (load_sharing, impacts_per_rev, Tf_max, ...) and per-tooth arrays (Z,)
    #: (F_peak, load_factor, free_frac, back_frac, onsets); units: LOAD_QUANTITIES,
    #: TOOTH_LOAD_QUANTITIES
    loads: dict = None
    #: the extremes and RMS of the outputs (the core's, EXTREMES), by name: Tm_max, Tm_min,
    #: Tm_rms, kv_*, F_* and Tf_* (over all teeth), D2_*, vD2_* (floats)
    extremes: dict = None
    #: the tooth spacing errors in use e_j (Z,) [m], the case's list plus the seeded ones
    #: (Model.info()['spacing_error'])
    spacing_error: np.ndarray = None
    #: the core's warnings of the case and the run, one line each, as raised (SplineWarning):
    #: the model's (plausibility), SUNDIALS', the run's and its loads' (stresses, T_f)
    warnings: tuple = ()

    F = _tooth_quantity("F")
    Fx = _tooth_quantity("Fx")
    Fy = _tooth_quantity("Fy")
    dn = _tooth_quantity("dn")
    c = _tooth_quantity("c")
    Tf = _tooth_quantity("Tf")
    rc1 = _tooth_quantity("rc1")
    rc2 = _tooth_quantity("rc2")
    x1, y1, x2, y2 = _state("x1"), _state("y1"), _state("x2"), _state("y2")
    D1, D2, D3 = _state("D1"), _state("D2"), _state("D3")
    vx1, vy1, vx2, vy2 = _state("vx1"), _state("vy1"), _state("vx2"), _state("vy2")
    vD1, vD2, vD3 = _state("vD1"), _state("vD2"), _state("vD3")

    @property
    def level(self) -> str:
        """The model level that ran (differs from the case's under fidelity = 'auto')."""
        return level_name(self.stats["dof"], THERMAL_LEVELS[self.stats["thermal_level"]])

    @property
    def kv(self) -> np.ndarray:
        """Dynamic load coefficient k_v = |T_m| / |T_d|, shape (nt,); NaN at T_d = 0 (the core's
        spline_loads::load_coefficient, which spline-dyn's kv column and the extremes use)."""
        t_d = abs(self.case["t_d"])
        return np.abs(self.Tm) / t_d if t_d > 0 else np.full(np.shape(self.Tm), np.nan)

    def __getattr__(self, name):
        # per-tooth quantities that the core has and this class does not name yet
        tooth = self.__dict__.get("tooth", {})
        if name in tooth:
            return tooth[name]
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def __dir__(self):
        return sorted(set(super().__dir__()) | set(self.__dict__.get("tooth", {})))

    def to_xarray(self):
        """The run as an xarray.Dataset (SI units in each variable's attrs['units']).

        dims: time (the output times t [s]), tooth (1..Z), section_point (the Poincare section,
        if the case asked for one), renormalisation (the Benettin record, if lyapunov).
        Variables: the states x1 .. D3 and velocities vx1 .. vD3 (time); Tm, kv (time); the
        per-tooth F, Fx, Fy, dn, c, Tf, rc1, rc2 (time, tooth); the loads (``loads``: per
        tooth on the tooth dim, the scalars without a dim); section_t and the states on the
        section section_x1 .. section_vD3 (section_point); lyapunov_log_growth
        (renormalisation, with coordinate lyapunov_t [s]); a sliced face (n_slices > 1): face
        (time, tooth, slice) [N] and tilt (time, moment: M_x, M_y) [N m]; the extremes and RMS
        (``extremes``) as run_<name> without a dim (run_Tm_max, run_F_rms, ...: spline-dyn's
        summary lines run.<name>). attrs: case (namelist text), name, level, pyspline_version, pyspline_build,
        the exponent as lyapunov_exponent [1/s], and the run statistics as stat_<name>."""
        import xarray as xr
        from ._build_info import provenance
        z = next(iter(self.tooth.values())).shape[1] if self.tooth else 0
        tooth_no = np.arange(1, z + 1)
        coords = {"time": ("time", np.asarray(self.t), _attrs("t")),
                  "tooth": ("tooth", tooth_no, {"long_name": "tooth number j"})}
        data = {n: ("time", self.y[:, i], _attrs(n)) for i, n in enumerate(STATE_QUANTITIES)}
        data["Tm"] = ("time", self.Tm, _attrs("Tm"))
        data["kv"] = ("time", self.kv, _attrs("kv"))
        for n, arr in self.tooth.items():
            data[n] = (("time", "tooth"), arr, _attrs(n))
        for n, v in (self.loads or {}).items():     # per tooth on the tooth dim, scalars 0-d
            data[n] = (("tooth",) if n in TOOTH_LOAD_QUANTITIES else (), v, _attrs(n))
        for n, v in (self.extremes or {}).items():
            data["run_" + n] = ((), v, _attrs(n, EXTREMES))
        if self.spacing_error is not None:
            long, unit = FIELDS["spacing_error"]
            data["spacing_error"] = ("tooth", self.spacing_error,
                                     {"long_name": long + ", in use (the list plus the seeded)",
                                      "units": unit})
        if self.section_t is not None and len(self.section_t):
            sec = np.asarray(self.section_y).reshape(-1, 14)
            data["section_t"] = ("section_point", self.section_t,
                                 {"long_name": "time of the Poincare section point "
                                  f"({self.case['section']})", "units": "s"})
            for i, n in enumerate(STATE_QUANTITIES):
                a = _attrs(n)
                a["long_name"] += " on the Poincare section"
                data["section_" + n] = ("section_point", sec[:, i], a)
        if self.face is not None:               # a sliced face (n_slices > 1)
            data["face"] = (("time", "tooth", "slice"), self.face,
                            {"long_name": "load of each slice of each tooth's face",
                             "units": "N"})
            data["tilt"] = (("time", "moment"), self.tilt,
                            {"long_name": "tilting moment on spline 1 (M_x, M_y)",
                             "units": "N m"})
            coords["slice"] = ("slice", np.arange(1, self.face.shape[2] + 1),
                               {"long_name": "face slice number"})
            coords["moment"] = ("moment", np.array(["M_x", "M_y"]))
        attrs = {"case": self.case.text(), "name": self.case.name, **provenance()}
        if self.stats:
            attrs["level"] = self.level
        if self.lyapunov is not None:
            coords["lyapunov_t"] = ("renormalisation", self.lyapunov["t"],
                                    {"long_name": "time of the Benettin renormalisation",
                                     "units": "s"})
            data["lyapunov_log_growth"] = ("renormalisation", self.lyapunov["log_growth"],
                                           {"long_name": "cumulative log stretch of the "
                                            "separation (Benettin)", "units": "1"})
            attrs["lyapunov_exponent"] = float(self.lyapunov["exponent"])
        for k, v in self.stats.items():
            attrs[f"stat_{k}"] = v
        return xr.Dataset(data, coords=coords, attrs=attrs)



class SerialExecutor(cf.Executor):
    """An executor that runs each call at once in the caller's thread (a sweep's point: the
    sweep's workers are its parallelism)."""

    def submit(self, fn, /, *args, **kwargs):
        f = cf.Future()
        f.set_result(fn(*args, **kwargs))
        return f


def _outputs(model, nk: int = 1) -> tuple:
    """The arrays api_simulate writes in place, of nk runs (1, or the K copies of realisations =
    K, copy k into block k of rows): t, y columns, tooth, tm. Not zeroed (the core writes each
    element of a run's rows; f2py would zero its own)."""
    nt = model.n_out * nk
    return (np.empty(nt), np.empty((14, nt), order="F"),
            np.empty((nt, model.z, len(_names("tooth"))), order="F"), np.empty(nt))


def _simulate(model, copy: int = 0, ya=None, max_seconds: float = 0.0, out=None) -> tuple:
    """api_simulate on a loaded Model (copy k of realisations = K > 1 from ya, the state at the
    end of the transient; max_seconds > 0: the call's wall-time bound; out: _outputs' arrays to
    write into, of this run or of the K copies): (t, y columns, tooth, tm, stats, sec_t, sec_y,
    lyap_t, lyap_g, face, tilt, nqw, consts, loads, tload, ext, warnings, ierr, msg); a copy's
    loads, tload, ext and warnings are 0 and blank (the copies' together: _copies). Module
    level, so a process executor can take it."""
    t, y, tooth, tm = _outputs(model) if out is None else out
    return bridge.simulate(model.bytes, model.z, model.n_out, len(t) // model.n_out,
                           tooth.shape[2], len(_names("stats")), model.n_section,
                           model.n_lyapunov, model.n_out if model.n_slices else 0,
                           model.n_slices, len(LOAD_QUANTITIES), len(TOOTH_LOAD_QUANTITIES),
                           len(EXTREMES), t, y, tooth, tm, copy,
                           np.zeros(14) if ya is None else ya, max_seconds)


def _copy(model, copy: int, ya, end: float, out=None) -> tuple:
    """_simulate of copy `copy` within the time left until `end` (time.time(); 0: no bound; a
    microsecond once it has passed: the run stops at once). Module level, for a process
    executor."""
    return _simulate(model, copy, ya, max(end - time.time(), 1e-6) if end else 0.0, out)


def _copies(model, executor, max_seconds: float = 0.0) -> tuple:
    """realisations = K > 1 (docs/accuracy.md): the transient, then the K copies on the executor
    (None: a thread each, at most os.cpu_count(); the core releases the GIL), their outputs one
    after another, and what follows from them in one call of the core (api_results: the
    statistics combined, the loads with standard errors from the copies' spread, the extremes
    and RMS, the warnings; spline_run::run_results, as spline-dyn): _simulate's tuple.
    On threads (None, a ThreadPoolExecutor or a SerialExecutor) each copy writes its rows of one
    set of output arrays (_outputs) in place; another executor's copies return theirs, copied
    in; sections, face and tilt are each copy's own, concatenated.
    max_seconds > 0: the wall-time bound of the transient and the copies together (each copy
    gets what is left when it starts: _copy)."""
    k = model.case["realisations"]
    end = time.time() + max_seconds if max_seconds > 0 else 0.0
    ya, ierr, msg = bridge.start_state(model.bytes, 1, max_seconds)
    raise_for(ierr, msg)
    own = executor is None
    if own:
        executor = cf.ThreadPoolExecutor(min(k, os.cpu_count() or 1))
    shared = own or isinstance(executor, (cf.ThreadPoolExecutor, SerialExecutor))
    out = _outputs(model, k)
    try:
        outs = list(executor.map(_copy, [model] * k, range(1, k + 1), [ya] * k, [end] * k,
                                 [out if shared else None] * k))
    finally:
        if own:
            executor.shutdown()
    for o in outs:
        raise_for(o[-2], o[-1])              # the first failed copy raises
    if not shared:                           # each copy's rows, one after another
        for i, a in enumerate(out):
            np.concatenate([o[i] for o in outs], axis=1 if i == 1 else 0, out=a)
    t, y, tooth, tm = out
    nqw, consts = outs[0][11], outs[0][12]
    st, loads, tload, ext, warned, ierr, msg = bridge.results(
        model.bytes, len(LOAD_QUANTITIES), len(TOOTH_LOAD_QUANTITIES), len(EXTREMES), t, y,
        tooth[:, :, :nqw], tm, np.stack([o[4] for o in outs], axis=1), consts)
    raise_for(ierr, msg)
    said = "\n".join(decode(o[-1]) for o in outs)     # each copy's SUNDIALS warnings
    cat = [np.concatenate([o[i] for o in outs]) for i in (5, 6, 7, 8, 9, 10)]  # sections, face
    return (t, y, tooth, tm, st, *cat, nqw, consts, loads, tload, ext, warned, 0, said)


def run(model, executor=None, max_seconds: float = 0.0) -> Result:
    """Run a loaded Model (pyspline.simulate: any case) and return a Result. Raises CaseError, SolverError or ThermalInterferenceError with a message naming the
    case; KeyboardInterrupt if SIGINT arrives during the run. Releases the GIL while it runs.
    One call of the core (api_simulate) gives the outputs, the loads, the extremes and the
    run's warnings. realisations = K > 1: the copies run on `executor` (None: threads), their
    outputs one after another in the Result (t restarts at each copy's start), the loads,
    extremes and warnings from them together (one more call: api_results). max_seconds > 0:
    the run's wall-time bound (past it a SolverError naming it; 0: none)."""
    q, s = _names("tooth"), _names("stats")
    t0 = time.perf_counter()
    out = (_copies(model, executor, max_seconds) if model.case["realisations"] > 1
           else _simulate(model, max_seconds=max_seconds))
    (t, ycol, tooth, tm, stats, sec_t, sec_y, lyap_t, lyap_g, face, tilt, nqw, consts, loads,
     tload, ext, warned, ierr, msg) = out
    wall = time.perf_counter() - t0
    run_outcome(ierr, msg)
    y = ycol.T                # (nt, 14), a view of the core's columns (no transposed copy)
    st = {n: (float(v) if unit else int(v)) for (n, unit, _), v in zip(s, stats)}  # counts: int
    st["wall_s"] = wall
    _warn(warned, 4)          # the run's and its loads', attributed to pyspline.simulate's caller
    lyap = None
    if model.n_lyapunov:
        span = lyap_t - (t[0] if len(t) else 0.0)
        lyap = dict(t=lyap_t, log_growth=lyap_g, exponent=float(lyap_g[-1] / span[-1]))
    # a level without flash temperature or slices writes F, Fx, Fy, dn only (nqw = 4): its
    # c, Tf, rc1, rc2 are constants, given once (consts) and broadcast (read-only views)
    tooth = tooth[:, :, :nqw]
    per = {n: (tooth[:, :, i] if i < nqw else np.broadcast_to(consts[i - 4], tooth.shape[:2]))
           for i, (n, *_) in enumerate(q)}
    out = {n: float(v) for n, v in zip(LOAD_QUANTITIES, loads)}
    out.update({n: tload[:, i] for i, n in enumerate(TOOTH_LOAD_QUANTITIES)})
    return Result(case=model.case, t=t, y=y, tooth=per, Tm=tm, stats=st,
                  section_t=sec_t, section_y=sec_y, lyapunov=lyap,
                  face=face if model.n_slices else None, tilt=tilt if model.n_slices else None,
                  loads=out, extremes={n: float(v) for n, v in zip(EXTREMES, ext)},
                  spacing_error=model.info()["spacing_error"],
                  warnings=model.warnings + warning_lines(msg) + warning_lines(warned))
