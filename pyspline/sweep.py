"""Parameter sweeps: one case run over a line or a grid of values of one or two fields, each
run reduced to a small summary (Poincare section, period, Lyapunov exponent, load statistics,
solver statistics, spectrum of T_m in shaft orders), gathered into an xarray.Dataset.

``sweep(case, l_x=np.linspace(0, 3e-4, 61))`` runs serially; any concurrent.futures.Executor
runs the points in parallel (threads: the core releases the GIL; processes; Dask's
``distributed.Client(...).get_executor()``). With ``out=DIR`` every finished point is saved at
once as ``DIR/points/<index>.<hash>.npz`` and all of them are merged into ``DIR/sweep.nc``
(NetCDF-4, engine h5netcdf) at the end, also after a crash or Ctrl-C; a rerun into the same
directory computes only the points whose file is missing (a point is known by its grid index
and a hash of its case text, so a changed case is never served from a stale file).

The command line (``pyspline sweep``, ``pyspline plot``) is here too: `cli_sweep`, `cli_plot`.
"""
from __future__ import annotations

import concurrent.futures as cf
import datetime
import functools
import hashlib
import itertools
import os
import re
import shlex
import sys
import time
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from . import analysis
from .case import Case, defaults, load_case
from .core import STATE_NAMES
from .errors import CaseError, SplineError

__all__ = ["DASK_SWEEP_CONFIG", "local_dask_client", "open_sweep", "parse_values",
           "point_cases", "run_point", "summarise", "sweep", "sweep_figures", "task_size",
           "write_netcdf"]

#: Bump when the content of a point summary changes: older point files are then recomputed.
#: 2: the default Benettin separation (lyapunov_d0 = 0: 1e4 rtol, was 1e-8) changed exponents.
SUMMARY_VERSION = 2
#: Step of the common shaft-order axis of the T_m spectra [shaft orders].
ORDER_STEP = 0.05
SECTIONS = ("shaft", "tooth", "none")
ENGINE = "h5netcdf"
POINTS_DIR = "points"
MERGED = "sweep.nc"

_I_D2 = STATE_NAMES.index("D2")     # column of D2 in Result.y / section_y; dD2/dt is 7 later


# --------------------------------------------------------------------------- field metadata

@functools.cache
def field_meta() -> dict:
    """{field: (long_name, units)} from the comments of cases/template.nml (empty when the
    template is not found): e.g. 'l_x' -> ('parallel misalignment of spline 1 in x', 'm')."""
    here = Path(__file__).resolve().parent
    for path in (here / "cases" / "template.nml", here.parent / "cases" / "template.nml"):
        if path.is_file():
            break
    else:
        return {}
    meta = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        m = re.match(r"\s*(\w+)\s*=[^!]*!\s*(.*)$", line)
        if not m:
            continue
        comment = m.group(2)
        u = re.search(r"\[([^\],]*)\]", comment)      # a unit has no comma
        long = (comment[:u.start()] if u else comment).strip().rstrip(":;,").strip()
        if "|" in long or ":" in long:      # a list of choices, not a description
            long = m.group(1)
        unit = u.group(1).strip() if u else ""
        meta[m.group(1).lower()] = (long or m.group(1), "1" if unit == "-" else unit)
    return meta


def _field_attrs(name: str) -> dict:
    long, units = field_meta().get(name, (name, ""))
    return {"long_name": long, "units": units} if units else {"long_name": long}


# --------------------------------------------------------------------------- values

def _typed(field: str, text: str):
    """One value of `field` given as text, typed like the field's default."""
    default = defaults()[field]
    t = text.strip()
    if isinstance(default, bool):
        low = t.lower().strip(".")
        if low in ("true", "t", "1", "yes"):
            return True
        if low in ("false", "f", "0", "no"):
            return False
        raise CaseError(f"field {field}: {text!r} is not a logical (true/false)")
    if isinstance(default, str):
        return t.strip("'\"")
    try:
        v = float(t.replace("d", "e").replace("D", "e"))
    except ValueError:
        raise CaseError(f"field {field}: {text!r} is not a number") from None
    if isinstance(default, int) and v.is_integer():
        return int(v)
    return v


def parse_values(field: str, spec: str) -> np.ndarray:
    """Values of a swept field from text: ``start:stop:num`` (numpy.linspace, num points, both
    ends included) or a comma list ``10,20,30`` (also one value). Typed like the field's
    default (numbers, whole numbers, logicals, strings)."""
    field = field.strip().lower()
    if field not in defaults():
        raise CaseError(f"unknown field '{field}' (see cases/template.nml)")
    spec = spec.strip()
    if not spec:
        raise CaseError(f"field {field}: no values given")
    parts = spec.split(":")
    if len(parts) == 3 and "," not in spec:
        start, stop = (_typed(field, p) for p in parts[:2])
        try:
            num = int(parts[2])
        except ValueError:
            raise CaseError(f"field {field}: {spec!r}: num in start:stop:num must be a whole "
                            "number") from None
        if num < 1:
            raise CaseError(f"field {field}: {spec!r}: num must be >= 1")
        if isinstance(start, (bool, str)):
            raise CaseError(f"field {field}: start:stop:num needs numbers, got {spec!r}")
        values = np.linspace(float(start), float(stop), num)
        if isinstance(defaults()[field], int) and np.all(values == np.round(values)):
            values = values.astype(np.int64)
        return values
    if len(parts) != 1:
        raise CaseError(f"field {field}: {spec!r} is neither start:stop:num nor a comma list")
    return np.asarray([_typed(field, p) for p in spec.split(",")])


def _as_values(field: str, values) -> np.ndarray:
    """The swept values of `field` as a 1-D numpy array (any sequence or iterable)."""
    if isinstance(values, (str, bytes, Mapping)) or not hasattr(values, "__iter__"):
        raise TypeError(f"sweep values of {field} must be a sequence, got {values!r}")
    arr = np.asarray(values if isinstance(values, np.ndarray) else list(values))
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError(f"sweep values of {field} must be a non-empty 1-D sequence, got shape "
                         f"{arr.shape}")
    return arr


def _py(v):
    """numpy scalar -> Python scalar (for Case fields and for text)."""
    return v.item() if hasattr(v, "item") else v


# --------------------------------------------------------------------------- points

def point_cases(case, grid: Mapping) -> dict:
    """{index tuple: Case or CaseError} for every point of the grid (the first field varies
    slowest). A point whose values the case rejects at once (wrong type) maps to the error."""
    names = list(grid)
    out = {}
    for index in itertools.product(*(range(len(grid[n])) for n in names)):
        point = {n: _py(grid[n][i]) for n, i in zip(names, index)}
        try:
            out[index] = case.replace(**point)
        except CaseError as exc:
            out[index] = exc
    return out


def _options_key(options: dict) -> str:
    o = dict(options)
    if o.get("orders") is not None:
        o["orders"] = hashlib.sha256(np.asarray(o["orders"], float).tobytes()).hexdigest()[:16]
    return repr(sorted(o.items()))


def point_hash(case: Case, options: dict) -> str:
    """Hash of what a point's summary depends on: its case text and the summary options."""
    h = hashlib.sha256()
    h.update(f"pyspline sweep summary v{SUMMARY_VERSION}\n".encode())
    h.update(case.text().encode("utf-8"))
    h.update(_options_key(options).encode())
    return h.hexdigest()[:16]


def point_filename(index: tuple, digest: str) -> str:
    return "_".join(f"{i:05d}" for i in index) + f".{digest}.npz"


# --------------------------------------------------------------------------- one point

def _template(options: dict, stat_names: Sequence[str]) -> dict:
    """The summary of a point that produced nothing (all NaN), with every key a summary has."""
    nan = np.nan
    s = {}
    if options["section"] != "none":
        empty = np.zeros(0)
        s.update(section_t=empty, section_D2=empty, section_vD2=empty, period=nan,
                 period_residual=nan)
    if options["lyapunov"]:
        s.update(lyapunov=nan, lyapunov_spread=nan, lyapunov_rel_spread=nan,
                 lyapunov_slope=nan, predictability_horizon=nan, chaotic=nan)
    for q in ("Tm", "kv", "F"):
        s.update({f"{q}_max": nan, f"{q}_min": nan, f"{q}_rms": nan})
    s.update(Tf_max=nan, D2_max=nan, D2_min=nan)
    s.update({k: nan for k in stat_names})
    if options.get("orders") is not None:
        s["Tm_spectrum"] = np.full(len(options["orders"]), nan)
    s.update(error="", error_class="")
    return s


@functools.cache
def _stat_names() -> tuple:
    from .core import _names
    return tuple(n for n, _ in _names("stats")) + ("wall_s",)


def _binned_spectrum(t, x, speed_rpm, orders_axis) -> np.ndarray:
    """Amplitude spectrum of x (Hann window, mean removed) on the order axis: in each bin
    (centre +- step/2) the largest amplitude of the FFT lines in it (peak heights survive a
    coarser axis); a bin with no line (finer axis than the FFT) interpolated; NaN beyond the
    Nyquist frequency and at zero speed."""
    o_axis = np.asarray(orders_axis, dtype=float)
    out = np.full(o_axis.shape, np.nan)
    if speed_rpm == 0 or len(t) < 4:
        return out
    f, a = analysis.amplitude_spectrum(t, x)
    o = analysis.orders(f, speed_rpm)
    step = np.diff(o_axis).min() if len(o_axis) > 1 else 1.0
    k = np.floor((o - o_axis[0]) / step + 0.5).astype(np.int64)
    ok = (k >= 0) & (k < len(o_axis))
    np.fmax.at(out, k[ok], a[ok])
    empty = np.isnan(out) & (o_axis <= o[-1])
    out[empty] = np.interp(o_axis[empty], o, a)
    return out


def summarise(res, options: dict) -> dict:
    """The summary of one Result (see `sweep` for the keys), all numbers in SI units."""
    s = _template(options, _stat_names())
    case = res.case
    if options["section"] != "none" and res.section_y is not None:
        sy = np.asarray(res.section_y, dtype=float).reshape(-1, 14)
        D2s, vD2s = sy[:, _I_D2], sy[:, 7 + _I_D2]
        s.update(section_t=np.asarray(res.section_t, dtype=float), section_D2=D2s,
                 section_vD2=vD2s)
        if len(D2s) >= 4:     # classify_period needs 2 points in the tail (the last half)
            # what the solver's tolerance is relative to: the trajectory's RMS, but at least
            # the scales of Eq. 25 (its atol acts on states scaled by them), so that a fixed
            # point whose dD2/dt is zero up to solver noise counts as period 1
            info = res.case.model.info()
            scale = [max(np.sqrt(np.mean(res.D2**2)), info["l_ref"]),
                     max(np.sqrt(np.mean(res.vD2**2)), info["l_ref"] * info["w_ref"])]
            period, info = analysis.classify_period(np.c_[D2s, vD2s], case["rtol"],
                                                    scale=scale)
            s["period"] = float(period)
            r = info["residual"]
            s["period_residual"] = r[period] if period else (min(r.values()) if r else np.nan)
    if options["lyapunov"] and res.lyapunov is not None:
        ly = res.lyapunov
        lam = float(ly["exponent"])
        s.update(lyapunov=lam, predictability_horizon=analysis.predictability_horizon(lam))
        if len(ly["t"]) >= 3 and np.isfinite(ly["log_growth"]).all():
            fit = analysis.largest_lyapunov_fit(ly["t"], ly["log_growth"], t0=float(res.t[0]))
            s.update(lyapunov_spread=fit.spread, lyapunov_rel_spread=fit.rel_spread,
                     lyapunov_slope=fit.slope,
                     chaotic=float(analysis.is_chaotic(lam, fit.spread)))
    for q, arr in (("Tm", res.Tm), ("kv", res.kv), ("F", res.tooth["F"])):
        st = analysis.stats(arr, quantiles=False)
        s.update({f"{q}_max": st["max"], f"{q}_min": st["min"], f"{q}_rms": st["rms"]})
    s["Tf_max"] = float(np.max(res.tooth["Tf"]))
    s.update(D2_max=float(res.D2.max()), D2_min=float(res.D2.min()))
    for k in _stat_names():
        if k in res.stats:
            s[k] = float(res.stats[k])
    if options.get("orders") is not None:
        s["Tm_spectrum"] = _binned_spectrum(res.t, res.Tm, case["speed_rpm"], options["orders"])
    return s


def run_point(case: Case, options: dict) -> dict:
    """The task of one sweep point (module level, picklable arguments and result): simulate
    the point's case and return its summary. A failure of the case (any Exception: CaseError,
    SolverError, ThermalInterferenceError, ...) is returned as a summary with NaN values and the
    message in 'error' and the class name in 'error_class'; KeyboardInterrupt propagates."""
    from .core import simulate
    try:
        return summarise(simulate(case), options)
    except Exception as exc:              # noqa: BLE001 -- a failed point is a result
        s = _template(options, _stat_names())
        s.update(error=str(exc) or repr(exc), error_class=type(exc).__name__)
        return s


class PointSummaries:
    """The summaries of a chunk of points, as one object, and the seconds the chunk took in the
    worker. Dask sends it back as one pickle (its arrays as out-of-band buffers); a bare list of
    dicts of arrays it walks item by item, which cost 7-11 ms per task of 15 points, as much as
    two of the points themselves."""
    __slots__ = ("items", "seconds")

    def __init__(self, items: list, seconds: float):
        self.items, self.seconds = items, seconds


def run_points(cases: list, options: dict) -> PointSummaries:
    """A chunk of sweep points as one task (fewer round trips through a process pool or a
    Dask scheduler): run_point for each."""
    t0 = time.perf_counter()
    items = [run_point(case, options) for case in cases]
    return PointSummaries(items, time.perf_counter() - t0)


#: Dask settings for a cluster that runs long CPU-bound sweep tasks on a few cores, where every
#: cycle Dask spends on itself is taken from a run (docs/performance.md measures them). Each
#: turns off or slows a service such sweeps do not use: the statistical profiler (a sample of
#: every worker thread each 10 ms), work stealing (a rebalance each 100 ms; a sweep's tasks are
#: equal chunks handed out as workers free up), the system and memory monitors (each 500 and
#: 100 ms; a point holds a few MB), and the event-loop health check of the scheduler and of every
#: worker (each 20 ms: most of an idle cluster's CPU, and a wake-up that preempts a run; a loop
#: blocked for 3 s is still reported). Last, the worker processes' malloc: the nanny sets
#: MALLOC_TRIM_THRESHOLD_=64 KiB, which also turns off glibc's adaptive mmap threshold, so every
#: block over 128 KiB a run allocates (its outputs, CVODE's memory) is mapped anew and faulted in,
#: page by page: 0.6-0.8 ms a point, a sixth of its cost. A point's memory is a few MB, so
#: keeping up to 64 MiB of free heap per worker costs nothing.
DASK_SWEEP_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.scheduler.work-stealing": False,
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.admin.tick.interval": "1s",
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": 64 << 20,
    "distributed.nanny.pre-spawn-environ.MALLOC_MMAP_THRESHOLD_": 32 << 20,
}


def local_dask_client(n_workers: int = 2, processes: bool = True, **kwargs):
    """A ``distributed.Client`` on a new LocalCluster of `n_workers` single-threaded workers,
    set up for sweeps (DASK_SWEEP_CONFIG; its HTTP server on a free port, so that two clusters do
    not warn about port 8787); closing the client closes the cluster:

        if __name__ == "__main__":          # in a script: each worker process imports it
            with pyspline.local_dask_client(2) as client:
                ds = pyspline.sweep(case, executor=client.get_executor(), l_x=values)

    processes : True (default, as Dask's LocalCluster): one process per worker, with a nanny
        each, the layout of a multi-node cluster. The worker processes start by importing the
        script that starts them, so in a script the cluster must start under
        ``if __name__ == "__main__":``; without the guard this raises a RuntimeError that says
        so, as it does for a script read from standard input (no file to import). False: the
        workers are threads of this process (the core releases the GIL): they start in 0.03 s
        instead of 1-2 s and need no guard, but Dask's event loop then shares the GIL and the
        cores with them: on sweeps of cheap points (5 ms each, 2 cores) they scaled less than
        worker processes in five of six runs: medians of 1.47-1.66x against 1.57-1.92x
        (docs/performance.md, sessions 9 and 10).
    kwargs : passed to LocalCluster (e.g. dashboard_address=':8787' to watch the sweep: the
        dashboard needs bokeh)."""
    import multiprocessing

    import dask
    from distributed import Client
    if processes:
        if getattr(multiprocessing.current_process(), "_inheriting", False):
            # a new process still importing the script of its parent (multiprocessing's test)
            raise RuntimeError(
                "pyspline.local_dask_client was called while a Dask worker process imported the "
                "script that starts the cluster: in a script, start the cluster under `if "
                "__name__ == \"__main__\":`, or pass processes=False for worker threads")
        script = getattr(sys.modules.get("__main__"), "__file__", None)
        if script is not None and not os.path.isfile(script):
            raise RuntimeError(
                f"pyspline.local_dask_client: worker processes start by importing the script "
                f"that starts them, and {script} is not a file (a script read from standard "
                f"input?): save the script to a file, or pass processes=False for worker "
                f"threads in this process")
    options = dict(n_workers=n_workers, threads_per_worker=1, processes=processes,
                   dashboard_address=":0")
    options.update(kwargs)
    with dask.config.set(DASK_SWEEP_CONFIG):
        try:
            return Client(**options)
        except Exception as exc:
            if not processes:
                raise
            raise RuntimeError(
                f"pyspline.local_dask_client: the Dask worker processes did not start "
                f"({str(exc).rstrip('.')}). "
                "If a script starts the cluster, it must do so under `if __name__ == "
                "\"__main__\":`, because each worker process imports the script (Dask's log "
                "above shows each worker's error); or pass processes=False for worker threads "
                "in this process") from exc


def _workers(executor) -> int:
    """How many tasks `executor` runs at once: a process pool's workers, a Dask client's threads
    (at the time of the call), else 2."""
    if isinstance(executor, cf.ProcessPoolExecutor):
        return executor._max_workers
    client = getattr(executor, "_client", None)        # distributed.client.ClientExecutor
    if client is not None:
        try:
            return max(1, sum(client.nthreads().values()))
        except Exception:                  # noqa: BLE001 -- a guess is enough here
            pass
    return 2


class PointCost:
    """The cost of a sweep point so far: seconds per point over the finished tasks (None before
    any). A task whose points all failed does not count: a case refused at once costs nothing,
    and would make the next tasks huge."""

    def __init__(self):
        self._total, self._points = 0.0, 0

    @property
    def seconds(self) -> float | None:
        return self._total / self._points if self._points else None

    def add(self, done: PointSummaries) -> None:
        if done.items and not all(item["error"] for item in done.items):
            self._total += done.seconds
            self._points += len(done.items)


#: Seconds of work a task aims at on processes and Dask, and the least it shrinks to at the
#: end of a sweep (see task_size).
TASK_SECONDS, TAIL_SECONDS = 0.5, 0.05


def task_size(seconds_per_point: float | None, remaining: int, workers: int) -> int:
    """Points in the next task of a sweep on processes or Dask, from the cost of a point measured
    so far (None: nothing measured yet, one point).

    A task costs the executor a fixed time (on a 2-worker Dask cluster 5-6 ms of CPU: the
    scheduler, the client's fetch, the worker's event loop), so cheap points go in bundles that
    take about TASK_SECONDS. That also bounds what a Ctrl-C or a crash loses (a chunk is saved
    when it finishes). No task takes more than its share of the rest, remaining / (2 workers),
    so tasks shrink towards the end and the workers finish together (guided scheduling), but
    not below TAIL_SECONDS of work: a Dask task's round trip (10-30 ms) must stay shorter than
    the task a worker holds in reserve, or the worker waits."""
    if seconds_per_point is None:
        return 1
    cost = max(seconds_per_point, 1e-6)
    share = max(-(-remaining // (2 * workers)), int(TAIL_SECONDS / cost))
    return max(1, min(int(TASK_SECONDS / cost), share))


# --------------------------------------------------------------------------- files

def _save_point(path: Path, summary: dict) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    arrays = {k: np.asarray(v) for k, v in summary.items()}
    with open(tmp, "wb") as f:
        np.savez(f, **arrays)
    os.replace(tmp, path)


def _load_point(path: Path, keys) -> dict | None:
    """A saved summary, or None if the file is unreadable or lacks a key (then recompute)."""
    try:
        with np.load(path, allow_pickle=False) as z:
            s = {k: z[k] for k in z.files}
    except Exception:                      # noqa: BLE001 -- a broken file is recomputed
        return None
    if not set(keys) <= set(s):
        return None
    for k, v in s.items():
        s[k] = v.item() if v.ndim == 0 else v
    return s


# --------------------------------------------------------------------------- dataset

_VAR_ATTRS = {
    "section_t": ("time of the Poincare section point", "s"),
    "section_D2": ("D_2 on the Poincare section", "m"),
    "section_vD2": ("dD_2/dt on the Poincare section", "m/s"),
    "period": ("period of the section sequence (0: not periodic; NaN: no result)", ""),
    "period_residual": ("largest relative mismatch of the section at the period found (at the "
                        "best period tested if none)", ""),
    "lyapunov": ("largest Lyapunov exponent", "1/s"),
    "lyapunov_spread": ("spread (max - min) of the running Lyapunov estimate over the last "
                        "third of the window", "1/s"),
    "lyapunov_rel_spread": ("lyapunov_spread / |lyapunov| (small: converged)", ""),
    "lyapunov_slope": ("slope of the log growth over the last two thirds of the window", "1/s"),
    "predictability_horizon": ("predictability horizon 1/lambda (inf: lambda <= 0)", "s"),
    "chaotic": ("1: the exponent is positive beyond its own spread (chaos: read statistics, "
                "not trajectories); 0: not; NaN: no converged estimate", ""),
    "Tm_max": ("max of the meshing torque T_m", "N m"),
    "Tm_min": ("min of the meshing torque T_m", "N m"),
    "Tm_rms": ("RMS of the meshing torque T_m", "N m"),
    "kv_max": ("max of the dynamic load coefficient k_v", ""),
    "kv_min": ("min of the dynamic load coefficient k_v", ""),
    "kv_rms": ("RMS of the dynamic load coefficient k_v", ""),
    "F_max": ("max of the tooth loads F_j over all teeth", "N"),
    "F_min": ("min of the tooth loads F_j over all teeth", "N"),
    "F_rms": ("RMS of the tooth loads F_j over all teeth", "N"),
    "Tf_max": ("max of the flash temperatures T_f over all teeth", "degC"),
    "D2_max": ("max of D_2", "m"),
    "D2_min": ("min of D_2", "m"),
    "Tm_spectrum": ("amplitude spectrum of T_m (Hann window, mean removed; max over each order "
                    "bin)", "N m"),
    "wall_s": ("wall time of the run (Python call)", "s"),
    "error": ("error message of the point ('' if it ran)", ""),
    "error_class": ("exception class of the point's error ('' if it ran)", ""),
    "point_hash": ("hash of the point's case text and summary options (point file name)", ""),
}


def _stat_attrs(name: str) -> tuple:
    if name in _VAR_ATTRS:
        return _VAR_ATTRS[name]
    unit = "s" if name.endswith("_s") else ("degC" if name.endswith("_degC") else "")
    return (f"solver statistic {name}", unit)


def _build_dataset(grid: dict, summaries: dict, hashes: dict, options: dict, attrs: dict):
    import xarray as xr

    names = list(grid)
    shape = tuple(len(grid[n]) for n in names)
    keys = list(_template(options, _stat_names()))
    ragged = [k for k in keys if k.startswith("section_")]
    n_sec = max([len(np.atleast_1d(s[k])) for s in summaries.values() for k in ragged] or [0])
    data = {}
    for k in keys:
        if k in ("error", "error_class"):
            data[k] = np.full(shape, "", dtype=object)
        elif k in ragged:
            data[k] = np.full(shape + (n_sec,), np.nan)
        elif k == "Tm_spectrum":
            data[k] = np.full(shape + (len(options["orders"]),), np.nan)
        else:
            data[k] = np.full(shape, np.nan)
    data["point_hash"] = np.full(shape, "", dtype=object)
    for index in itertools.product(*(range(n) for n in shape)):
        data["point_hash"][index] = hashes.get(index, "")
        s = summaries.get(index)
        if s is None:
            data["error"][index] = "not computed (the sweep stopped before this point)"
            data["error_class"][index] = "NotComputed"
            continue
        for k in keys:
            v = s[k]
            if k in ragged:
                v = np.atleast_1d(np.asarray(v, dtype=float))
                data[k][index + (slice(0, len(v)),)] = v
            elif k in ("error", "error_class"):
                data[k][index] = str(v)
            else:
                data[k][index] = v
    variables = {}
    for k, v in data.items():
        dims = tuple(names)
        if k in ragged:
            dims += ("section_point",)
        elif k == "Tm_spectrum":
            dims += ("order",)
        if v.dtype == object:
            v = v.astype(str)
        long, units = _stat_attrs(k)
        a = {"long_name": long}
        if units:
            a["units"] = units
        variables[k] = (dims, v, a)
    coords = {n: (n, np.asarray(grid[n]), _field_attrs(n)) for n in names}
    if options.get("orders") is not None:
        coords["order"] = ("order", np.asarray(options["orders"], dtype=float),
                           {"long_name": "shaft order (frequency / shaft rotation frequency)",
                            "units": "1"})
    ds = xr.Dataset(variables, coords=coords, attrs=attrs)
    failed = (ds["error"] != "").values
    ds.attrs.update(n_points=int(np.prod(shape)), n_ok=int((~failed).sum()),
                    n_failed=int((failed & (ds["error_class"] != "NotComputed").values).sum()),
                    n_missing=int((ds["error_class"] == "NotComputed").values.sum()))
    return ds


def write_netcdf(ds, path) -> Path:
    """Write a dataset to NetCDF-4 (engine h5netcdf, float arrays compressed) through a
    temporary file and os.replace, so a reader never sees half a file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    enc = {k: {"zlib": True, "complevel": 4} for k, v in ds.data_vars.items()
           if v.dtype.kind == "f" and v.size > 1}
    try:
        ds.to_netcdf(tmp, engine=ENGINE, encoding=enc)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def open_sweep(path):
    """Read a sweep written by `sweep` (DIR/sweep.nc or DIR) fully into memory."""
    import xarray as xr
    path = Path(path)
    if path.is_dir():
        path = path / MERGED
    with xr.open_dataset(path, engine=ENGINE) as ds:
        return ds.load()


# --------------------------------------------------------------------------- sweep

def _default_orders(cases) -> np.ndarray:
    z = max([c["z"] for c in cases if isinstance(c, Case)] or [defaults()["z"]])
    n = int(round((2 * z + 2) / ORDER_STEP))
    return np.round(np.arange(n + 1) * ORDER_STEP, 10)


def _version() -> str:
    from . import __version__
    return __version__


def sweep(case, executor=None, progress=True, out=None, section="shaft", lyapunov=False, *,
          spectrum=None, orders=None, command=None, chunk=None, **fields):
    """Run `case` (a Case, dict of fields or namelist path) over one or two swept fields and
    return an xarray.Dataset of the per-point summaries.

    ``sweep(case, l_x=np.linspace(0, 3e-4, 61))`` sweeps one field; two keywords sweep their
    grid (first field varies slowest; dims in keyword order). Values: any 1-D sequence.

    executor : None (serial, in this process) or a concurrent.futures.Executor
        (ThreadPoolExecutor, ProcessPoolExecutor, ``distributed.Client(...).get_executor()``).
        The caller keeps ownership: it is not shut down here.
    chunk : points per task, all submitted at once. Default: on threads one point per task; on
        processes and Dask tasks of about TASK_SECONDS of work (from the measured cost of a
        point), shrinking towards the end of the sweep, two per worker in flight (task_size).
    progress : bool, tqdm progress bar on stderr.
    out : directory or None. Each finished point is written to ``out/points/`` at once; the
        merge goes to ``out/sweep.nc`` (NetCDF-4, h5netcdf), also when the sweep is stopped by
        an exception or KeyboardInterrupt (pending points are cancelled, the exception is
        re-raised). A rerun into the same directory reuses every point file whose index and
        hash (case text + summary options) match and computes the rest.
    section : 'shaft' | 'tooth' | 'none', the Poincare section (case field section).
    lyapunov : bool, compute the largest Lyapunov exponent (case field lyapunov).
    spectrum : bool or None; the T_m spectrum on a common shaft-order axis. Default: when
        speed_rpm is swept.
    orders : shaft-order axis of the spectrum (default 0 .. 2Z+2 in steps of 0.05).
    command : text stored in attrs['command'] (default: this call, abbreviated).

    Dataset: coordinates = the swept values (units from cases/template.nml); per point
    section_t/section_D2/section_vD2 (dim 'section_point', NaN-padded), period and
    period_residual; lyapunov, lyapunov_spread, lyapunov_rel_spread, lyapunov_slope,
    predictability_horizon, chaotic (1 if the exponent exceeds its spread; if lyapunov);
    Tm_/kv_/F_ max, min, rms, Tf_max, D2_max, D2_min;
    solver statistics (steps, rhs_evals, ..., core_wall_s, wall_s); Tm_spectrum (dim 'order');
    error, error_class ('' if ok), point_hash. A failed point has NaN values and its error.
    attrs: case (namelist text of the base case), pyspline_version, command, swept, section,
    lyapunov, created, out, and the counts n_points, n_ok, n_failed (incl. executor errors),
    n_missing (not run: the sweep stopped), n_computed (by this call), n_reused (from point
    files), n_executor_errors (the executor, not the case, failed: not saved, so a rerun tries
    those points again).
    """
    base = load_case(case)
    if section not in SECTIONS:
        raise CaseError(f"section must be one of {', '.join(SECTIONS)}, got {section!r}")
    if not fields:
        raise TypeError("sweep needs at least one field to sweep, e.g. l_x=[0, 1e-4, 2e-4]")
    if len(fields) > 2:
        raise TypeError(f"sweep takes one or two fields, got {len(fields)}: {', '.join(fields)}")
    known = defaults()
    grid = {}
    for name, values in fields.items():
        key = name.lower()
        if key not in known:
            raise CaseError(f"case {base.name}: unknown field '{name}' to sweep (see "
                            "cases/template.nml)")
        if key in ("section", "lyapunov", "name"):
            raise CaseError(f"field {key} cannot be swept (use the sweep argument)"
                            if key != "name" else "field name cannot be swept")
        grid[key] = _as_values(key, values)
    if len(grid) != len(fields):
        raise TypeError("the same field is swept twice")
    base = base.replace(section=section, lyapunov=bool(lyapunov))
    cases = point_cases(base, grid)
    if spectrum is None:
        spectrum = "speed_rpm" in grid
    if spectrum and orders is None:
        orders = _default_orders(cases.values())
    options = dict(section=section, lyapunov=bool(lyapunov),
                   orders=None if not spectrum else [float(o) for o in np.asarray(orders)])
    keys = list(_template(options, _stat_names()))

    hashes, summaries, todo, n_reused = {}, {}, [], 0
    points_dir = None
    if out is not None:
        out = Path(out)
        points_dir = out / POINTS_DIR
        points_dir.mkdir(parents=True, exist_ok=True)
    for index, c in cases.items():
        if isinstance(c, Exception):       # rejected at once: a result, nothing to run
            s = _template(options, _stat_names())
            s.update(error=str(c), error_class=type(c).__name__)
            summaries[index] = s
            continue
        if points_dir is not None:     # (without `out`, hashed while the first tasks run)
            hashes[index] = point_hash(c, options)
            saved = _load_point(points_dir / point_filename(index, hashes[index]), keys)
            if saved is not None:
                summaries[index] = saved
                n_reused += 1
                continue
        todo.append(index)

    if command is None:
        spec = ", ".join(f"{k}=[{len(v)} values]" for k, v in grid.items())
        command = f"pyspline.sweep({base.name!r}, {spec}, section={section!r}, " \
                  f"lyapunov={bool(lyapunov)})"
    attrs = dict(case=base.text(), pyspline_version=_version(), command=command,
                 swept=" ".join(grid), section=section, lyapunov=int(bool(lyapunov)),
                 created=datetime.datetime.now(datetime.timezone.utc).isoformat(
                     timespec="seconds"),
                 n_reused=n_reused, out="" if out is None else str(out))
    computed = 0

    def record(index, summary):
        nonlocal computed
        summaries[index] = summary
        computed += 1
        if points_dir is not None:
            _save_point(points_dir / point_filename(index, hashes[index]), summary)

    from tqdm import tqdm
    failed = executor_errors = 0
    futures, bar = {}, None
    pending = list(todo)                # not yet submitted, in grid order
    # on processes and Dask without a fixed chunk: tasks sized from the measured cost of a point
    # (task_size), two per worker in flight; on threads, or with `chunk`, all submitted at once
    guided = executor is not None and not chunk and not isinstance(executor, cf.ThreadPoolExecutor)
    workers = 1
    cost = PointCost()

    def submit():
        nonlocal workers
        if guided:          # asked each time: a Dask cluster may grow or shrink during a sweep
            workers = _workers(executor)
        while pending and (not guided or len(futures) < 2 * workers):
            if not guided:
                size = chunk or 1
            elif cost.seconds is None and len(pending) > len(todo) - workers:
                size = 1                 # one probe per worker for the cost of a point ...
            elif cost.seconds is None:   # ... and work for the worker till the probe is back
                size = max(1, min(32, len(todo) // (16 * workers)))
            else:
                size = task_size(cost.seconds, len(pending), workers)
            indices = pending[:size]
            del pending[:size]
            futures[executor.submit(run_points, [cases[i] for i in indices], options)] = indices

    def take(fut):
        """Record a finished task's points (or the executor's failure), then forget the task."""
        nonlocal failed, executor_errors
        chunk_indices = futures[fut]
        try:
            exc = fut.exception()
        except cf.CancelledError as cancelled:    # cancelled by someone else
            exc = cancelled
        if isinstance(exc, KeyboardInterrupt):
            raise exc
        if exc is None:
            res = fut.result()
            cost.add(res)
        for k, index in enumerate(chunk_indices):
            if exc is not None:      # the executor failed, not the case: not saved,
                s = _template(options, _stat_names())   # a rerun tries it again
                s.update(error=f"the executor failed: {type(exc).__name__}: {exc}",
                         error_class=type(exc).__name__)
                summaries[index] = s
                executor_errors += 1
            else:
                record(index, res.items[k])
            failed += bool(summaries[index]["error"])
        del futures[fut]
        bar.update(len(chunk_indices))
        bar.set_postfix(failed=failed, refresh=False)

    try:
        if executor is not None:       # before the bar's thread: a fork pool forks here
            submit()
        hashes.update((i, point_hash(cases[i], options)) for i in todo if i not in hashes)
        bar = tqdm(total=len(todo), desc=f"sweep {' x '.join(grid)}", unit="run",
                   disable=not progress, dynamic_ncols=True)
        if executor is None:
            for index in todo:
                record(index, run_point(cases[index], options))
                failed += bool(summaries[index]["error"])
                bar.update(1)
                bar.set_postfix(failed=failed, refresh=False)
        elif not guided:
            for fut in cf.as_completed(list(futures)):
                take(fut)
        else:
            while futures:
                done, _ = cf.wait(list(futures), return_when=cf.FIRST_COMPLETED)
                for fut in done:
                    take(fut)
                submit()
    except BaseException:
        for fut in futures:
            fut.cancel()
        for fut, chunk_indices in futures.items():   # finished but not yet taken: keep them
            try:
                if fut.done() and not fut.cancelled() and fut.exception() is None:
                    for k, index in enumerate(chunk_indices):
                        if index not in summaries:
                            record(index, fut.result().items[k])
            except BaseException:              # noqa: BLE001 -- keep the original exception
                pass
        if bar is not None:
            bar.close()
        attrs.update(n_computed=computed, n_executor_errors=executor_errors)
        try:
            ds = _build_dataset(grid, summaries, hashes, options, attrs)
            if out is not None:
                write_netcdf(ds, out / MERGED)
        except Exception as merge_exc:     # noqa: BLE001 -- keep the original exception
            print(f"pyspline sweep: could not merge the finished points: {merge_exc}",
                  file=sys.stderr)
        raise
    bar.close()
    attrs.update(n_computed=computed, n_executor_errors=executor_errors)
    ds = _build_dataset(grid, summaries, hashes, options, attrs)
    if out is not None:
        write_netcdf(ds, out / MERGED)
    return ds


# --------------------------------------------------------------------------- figures

def sweep_figures(ds, out) -> list[Path]:
    """The figures of a sweep dataset into directory `out`: bifurcation.png (and for a grid
    period_map.png), lyapunov.png (if computed), waterfall*.png (if speed_rpm was swept).
    The horizontal axis is the first swept field with numeric values (a field of text values,
    e.g. thermal, becomes the panels or the map's other axis). Returns the paths written."""
    from . import plots
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    names = list(ds["error"].dims)
    numeric = [n for n in names if ds[n].dtype.kind in "biuf"]
    written = []
    title_case = _case_name(ds)
    section = ds.attrs.get("section", "")
    if not numeric:
        print(f"no figures: no swept field has numeric values ({', '.join(names)})",
              file=sys.stderr)
        return written
    x = numeric[0]
    other = [n for n in names if n != x]
    if "section_D2" in ds:
        path = out / "bifurcation.png"
        if not other:
            plots.bifurcation(ds, x, path=path,
                              title=f"{title_case}: D_2 on the {section} section vs {x}")
        else:
            plots.bifurcation_grid(ds, x, other[0], path=path,
                                   title=f"{title_case}: D_2 on the {section} section")
            plots.param_map(ds, "period", x, other[0], path=out / "period_map.png",
                            title=f"{title_case}: period of the {section} section sequence")
        written.append(path)
        if other:
            written.append(out / "period_map.png")
    if "lyapunov" in ds:
        path = out / "lyapunov.png"
        if not other:
            plots.lyapunov_vs_param(ds, x, path=path,
                                    title=f"{title_case}: largest Lyapunov exponent vs {x}")
        else:
            plots.param_map(ds, "lyapunov", x, other[0], path=path,
                            title=f"{title_case}: largest Lyapunov exponent")
        written.append(path)
    if "Tm_spectrum" in ds and "speed_rpm" in numeric:
        written += _waterfalls(ds, out, title_case)
    return written


def _case_name(ds) -> str:
    m = re.search(r"name\s*=\s*'([^']*)'", ds.attrs.get("case", ""))
    return m.group(1) if m else "sweep"


def _waterfall_ds(sub):
    import xarray as xr
    spd = sub["speed_rpm"]
    freq = np.abs(spd.values)[:, None] * sub["order"].values[None, :] / 60.0
    return xr.Dataset({"amplitude": (("speed_rpm", "order"),
                                     sub["Tm_spectrum"].transpose("speed_rpm", "order").values,
                                     {"units": "N m", "long_name": "amplitude of T_m"}),
                       "freq_hz": (("speed_rpm", "order"), freq,
                                   {"units": "Hz", "long_name": "frequency"})},
                      coords={"speed_rpm": spd})


def _z(ds) -> int | None:
    m = re.search(r"\bz\s*=\s*(\d+)", ds.attrs.get("case", ""))
    return int(m.group(1)) if m else defaults()["z"]


def _waterfalls(ds, out, title_case) -> list[Path]:
    from . import plots
    names = list(ds["error"].dims)
    z = None if "z" in names else _z(ds)
    if len(names) == 1:
        path = out / "waterfall.png"
        plots.waterfall(_waterfall_ds(ds), z=z, path=path,
                        title=f"{title_case}: spectrum of T_m vs speed (dashed: shaft and "
                              "tooth-pass orders)")
        return [path]
    other = names[0] if names[1] == "speed_rpm" else names[1]
    values = ds[other].values
    pick = np.unique(np.linspace(0, len(values) - 1, min(len(values), 6)).round().astype(int))
    paths = []
    for i in pick:
        v = values[i]
        sub = ds.isel({other: i})
        path = out / f"waterfall_{other}={_fmt(v)}.png"
        plots.waterfall(_waterfall_ds(sub), z=z, path=path,
                        title=f"{title_case}, {other} = {_fmt(v)}: spectrum of T_m vs speed")
        paths.append(path)
    return paths


def _fmt(v) -> str:
    v = _py(v)
    return f"{v:g}" if isinstance(v, float) else str(v)


# --------------------------------------------------------------------------- command line

def _assignments(items, what) -> dict:
    out = {}
    for item in items or ():
        if "=" not in item:
            raise CaseError(f"{what} {item!r}: expected FIELD=VALUES")
        k, v = item.split("=", 1)
        k = k.strip().lower()
        if k in out:
            raise CaseError(f"{what}: field {k} given twice")
        out[k] = v
    return out


def _fixed(items) -> dict:
    """--fix FIELD=VALUE pairs -> {field: typed value}."""
    out = {}
    for k, v in _assignments(items, "--fix").items():
        vals = parse_values(k, v)
        if len(vals) != 1:
            raise CaseError(f"--fix {k}={v}: one value expected")
        out[k] = _py(vals[0])
    return out


def _make_executor(args):
    """(executor or None, closer) for --workers/--threads/--scheduler."""
    if args.scheduler:
        from distributed import Client
        client = Client(args.scheduler)
        return client.get_executor(), client.close
    if args.workers > 1:
        ex = (cf.ThreadPoolExecutor(args.workers) if args.threads
              else cf.ProcessPoolExecutor(args.workers))
        return ex, lambda: ex.shutdown(wait=False, cancel_futures=True)
    return None, lambda: None


def _command(args) -> str:
    """The command line of a parsed `pyspline sweep`, for attrs['command']."""
    parts = ["pyspline", "sweep", args.case]
    parts += [f"--set={v}" for v in args.set] + [f"--fix={v}" for v in args.fix or ()]
    parts += [f"--section={args.section}", f"--out={args.out}"]
    if args.lyapunov:
        parts.append("--lyapunov")
    if args.scheduler:
        parts.append(f"--scheduler={args.scheduler}")
    elif args.workers > 1:
        parts += [f"--workers={args.workers}"] + (["--threads"] if args.threads else [])
    return " ".join(shlex.quote(a) for a in parts)


def cli_sweep(args) -> int:
    try:
        grid = {k: parse_values(k, v) for k, v in _assignments(args.set, "--set").items()}
        if not 1 <= len(grid) <= 2:
            raise CaseError("give one or two --set FIELD=VALUES to sweep")
        case = load_case(args.case, **_fixed(args.fix))
    except SplineError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    out = Path(args.out)
    executor, close = _make_executor(args)
    try:
        ds = sweep(case, executor=executor, progress=not args.quiet, out=out,
                   section=args.section, lyapunov=args.lyapunov, command=_command(args),
                   **grid)
    except KeyboardInterrupt:
        print(f"\ninterrupted: the finished points are in {out / POINTS_DIR}/ and merged into "
              f"{out / MERGED}; run the same command again to compute the rest",
              file=sys.stderr)
        return 130
    finally:
        close()
    a = ds.attrs
    print(f"{a['n_points']} points: {a['n_ok']} ran, {a['n_failed']} failed, "
          f"{a['n_missing']} missing; {a['n_computed']} computed now, {a['n_reused']} reused "
          f"from {out / POINTS_DIR}/")
    if "chaotic" in ds:
        n_chaos = int((ds["chaotic"] == 1).sum())
        print(f"{n_chaos} of {a['n_ok']} points chaotic (Lyapunov exponent positive beyond its "
              "spread): read their statistics, sections and spectra, not their trajectories")
    if a["n_failed"] or a["n_missing"]:
        errors = [e for e in ds["error"].values.ravel() if e]
        print(f"first error: {errors[0]}", file=sys.stderr)
    print(f"wrote {out / MERGED} (xarray.open_dataset(path, engine='h5netcdf') or "
          "pyspline.open_sweep)")
    for path in sweep_figures(ds, out):
        print(f"wrote {path}")
    # failed cases are results; points the executor lost or never ran are not
    return 1 if a["n_missing"] or a["n_executor_errors"] else 0


def cli_plot(args) -> int:
    from . import plots
    from .core import simulate
    out = Path(args.out)
    status = 0
    try:
        fixed = _fixed(args.fix)
    except SplineError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    for path in args.cases:
        try:
            case = load_case(path, **fixed).replace(section="shaft")
            res = simulate(case)
        except SplineError as exc:
            print(f"error: {exc}", file=sys.stderr)
            status = 1
            continue
        spectrum = analysis.amplitude_spectrum(res.t, res.Tm) if len(res.t) >= 4 else None
        sec = None
        if res.section_y is not None and len(res.section_y):
            sec = np.c_[res.section_y[:, _I_D2], res.section_y[:, 7 + _I_D2]]
        thermal = case["thermal"] != "none"
        target = out / f"{case.name}.png"
        plots.scene(res.t, res.D2, res.vD2, res.Tm, res.tooth["F"],
                    Tf=res.tooth["Tf"] if thermal else None, section=sec, spectrum=spectrum,
                    speed_rpm=case["speed_rpm"], z=case["z"], path=target,
                    title=f"{case.name}: {res.level}, {case['speed_rpm']:g} rpm, "
                          f"T_d = {case['t_d']:g} N m, l_x = {case['l_x']:g} m, "
                          f"l_y = {case['l_y']:g} m; section points once per revolution")
        print(f"wrote {target}")
    return status


SWEEP_HELP = """\
Run CASE over one field (--set FIELD=VALUES) or a grid of two (two --set), each point reduced
to a summary: Poincare section of D2 and dD2/dt, its period, the largest Lyapunov exponent
(--lyapunov), max/min/RMS of T_m, k_v and F_j, max T_f, solver statistics, the error of a
failed point, and for a speed_rpm sweep the spectrum of T_m in shaft orders.

VALUES: start:stop:num (numpy.linspace, both ends included) or a comma list (10,20,30).

Writes into --out DIR:
  DIR/points/<index>.<hash>.npz   one file per finished point, written as it finishes
  DIR/sweep.nc                    all points merged (NetCDF-4; xarray.open_dataset(path,
                                  engine='h5netcdf') or pyspline.open_sweep(DIR))
  DIR/bifurcation.png             section D2 against the first field, coloured by period
                                  (two fields: one panel per value of the second, and
                                  DIR/period_map.png, the period over the grid)
  DIR/lyapunov.png                with --lyapunov: the exponent against the first field
                                  (two fields: a map over the grid)
  DIR/waterfall.png               when speed_rpm is swept: spectrum of T_m against speed
                                  (two fields: waterfall_FIELD=VALUE.png for up to 6 values)
Ctrl-C or a crash keeps the finished points (merged into sweep.nc); running the same command
again computes only the points that are missing (a changed case is recomputed: files are
known by index and by a hash of the point's case). With --workers (processes) or --scheduler
(Dask), cheap points travel in tasks of about 0.5 s of work, written when their task ends: a
Ctrl-C loses at most the tasks running then.

example: pyspline sweep cases/paper_lx1e-4.nml --set l_x=0:3e-4:61 --workers 2 --out out/lx
"""

PLOT_HELP = """\
Run each CASE (with the Poincare section once per shaft revolution) and draw one page per
case into DIR/CASENAME.png: D2(t), T_m(t), the phase plane (D2, dD2/dt) with the exact
section points, the tooth x time map of the tooth loads F_j, the flash temperatures T_f (thermal
cases), and the spectrum of T_m with shaft orders (1x, 2x) and tooth-pass orders (Zx, 2Zx).
"""


def _at_least_one(text: str) -> int:
    import argparse
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 1, got {text!r}")
    return n


def add_parsers(sub) -> None:
    """Add the `sweep` and `plot` subcommands to the argparse subparsers of pyspline.cli."""
    import argparse
    fmt = argparse.RawDescriptionHelpFormatter
    r = sub.add_parser("sweep", help="sweep one or two case fields: sweep.nc, bifurcation, "
                       "Lyapunov and waterfall figures in --out", description=SWEEP_HELP,
                       formatter_class=fmt)
    r.add_argument("case", metavar="CASE", help="case file (namelist)")
    r.add_argument("--set", action="append", required=True, metavar="FIELD=VALUES",
                   help="a swept field: start:stop:num or v1,v2,...; give one or two")
    r.add_argument("--fix", action="append", metavar="FIELD=VALUE",
                   help="change a field of the case for every point (e.g. t_end=0.5)")
    r.add_argument("--out", required=True, metavar="DIR", help="output directory")
    r.add_argument("--section", choices=("shaft", "tooth"), default="shaft",
                   help="Poincare section once per shaft revolution (default) or tooth pass")
    r.add_argument("--lyapunov", action="store_true",
                   help="largest Lyapunov exponent of every point (a second, perturbed "
                        "trajectory: about 4x the run time on paper_lx1e-4)")
    r.add_argument("--workers", type=_at_least_one, default=1, metavar="N",
                   help="N processes (default 1: serial, in this process)")
    r.add_argument("--threads", action="store_true",
                   help="with --workers N: N threads instead of processes")
    r.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on a Dask cluster (distributed scheduler at ADDRESS, e.g. "
                        "tcp://host:8786)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.set_defaults(func=cli_sweep)
    r = sub.add_parser("plot", help="one page of figures per case: DIR/CASENAME.png",
                       description=PLOT_HELP, formatter_class=fmt)
    r.add_argument("cases", nargs="+", metavar="CASE", help="case file(s)")
    r.add_argument("--out", default=".", metavar="DIR",
                   help="output directory (default: the current one)")
    r.add_argument("--fix", action="append", metavar="FIELD=VALUE",
                   help="change a field of the case (e.g. t_end=0.5)")
    r.set_defaults(func=cli_plot)
