"""Parameter sweeps: one case run over a line or a grid of values of one or two fields, each
run reduced to a small summary (Poincare section, period, Lyapunov exponent, load statistics,
solver statistics, spectrum of T_m in shaft orders), gathered into an xarray.Dataset.

``sweep(case, l_x=np.linspace(0, 3e-4, 61))`` runs serially; any concurrent.futures.Executor
runs the points in parallel (threads: the core releases the GIL; processes; Dask's
``distributed.Client(...).get_executor()``). With ``out=DIR`` every finished point is saved at
once as ``DIR/points/<index>.<hash>.npz`` and all of them are merged into ``DIR/sweep.nc``
(NetCDF-4, engine netcdf4) at the end, also after a crash or Ctrl-C; a rerun into the same
directory computes only the points whose file is missing (a point is known by its grid index
and a hash of its case text, so a changed case is never served from a stale file).

A point's summary is pyspline.summary's; the Dataset and its NetCDF file are built in
pyspline.dataset, a local Dask cluster in
pyspline.cluster, the figures in pyspline.plots, the command line in pyspline.cli.
"""
from __future__ import annotations

import concurrent.futures as cf
import datetime
import hashlib
import itertools
import os
import sys
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ._build_info import provenance
from .case import Case, defaults, load_case
from .cluster import local_dask_client
from .dataset import MERGED, build_dataset, open_sweep, write_netcdf
from .errors import CaseError
from .summary import _stat_names, _template, failed_summary, summarise
from .warned import warn_grouped

__all__ = ["local_dask_client", "open_sweep", "parse_values", "point_cases", "read_table",
           "run_point", "summarise", "sweep", "table_cases", "task_points", "write_netcdf"]

#: Bump when the content of a point summary changes: older point files are then recomputed.
#: 2: the default Benettin separation (lyapunov_d0 = 0: 1e4 rtol, was 1e-8) changed exponents.
#: 4: a point keeps its warnings.
#: 5: chaotic asks the slope of the Benettin record too (analysis.is_chaotic).
#: 6: period -1, not settled: not periodic with a negative Lyapunov exponent.
SUMMARY_VERSION = 6
#: Step of the common shaft-order axis of the T_m spectra [shaft orders].
ORDER_STEP = 0.05
SECTIONS = ("shaft", "tooth", "none")
POINTS_DIR = "points"


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


def _as_values(field: str, values, where: str = "sweep") -> np.ndarray:
    """The swept values of `field` as a 1-D numpy array (any sequence or iterable); else a
    CaseError naming the argument (`where`: 'sweep' or the design table)."""
    if isinstance(values, (str, bytes, Mapping)) or not hasattr(values, "__iter__"):
        raise CaseError(f"{where}: the values of {field} must be a sequence, got {values!r:.60}")
    try:
        arr = np.asarray(values if isinstance(values, np.ndarray) else list(values))
    except ValueError as exc:            # ragged lists
        raise CaseError(f"{where}: the values of {field} are no 1-D sequence: {exc}") from None
    if arr.ndim != 1 or arr.size == 0:
        raise CaseError(f"{where}: the values of {field} must be a non-empty 1-D sequence, got "
                        f"shape {arr.shape}")
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


def read_table(table) -> dict:
    """A design table as {field: 1-D array of values, one per point}: a CSV file (a header row
    of case fields, then one row per point, values as in a case file: 1e-4, 16, true, 'adams'),
    a mapping {field: sequence} or a pandas DataFrame. Typed like the fields' defaults."""
    if isinstance(table, (str, os.PathLike)):
        import csv
        try:            # utf-8-sig: also Excel's "CSV UTF-8" (a byte-order mark first)
            with open(table, newline="", encoding="utf-8-sig") as f:
                rows = [r for r in csv.reader(f) if r and any(x.strip() for x in r)]
        except (OSError, UnicodeDecodeError) as exc:
            raise CaseError(f"design table {os.fspath(table)}: cannot read it: {exc}") from None
        if len(rows) < 2:
            raise CaseError(f"design table {os.fspath(table)}: needs a header row of case "
                            "fields and at least one row of values")
        header = [h.strip().lower() for h in rows[0]]
        for k, r in enumerate(rows[1:], start=2):
            if len(r) != len(header):
                raise CaseError(f"design table {os.fspath(table)}: row {k} has {len(r)} values "
                                f"for {len(header)} fields")
        columns = {h: [r[i] for r in rows[1:]] for i, h in enumerate(header)}
        if len(columns) != len(header):
            raise CaseError(f"design table {os.fspath(table)}: a field is given twice")
        for h in columns:
            if h not in defaults():
                raise CaseError(f"design table {os.fspath(table)}: unknown field '{h}' (see "
                                "cases/template.nml)")
        try:
            return {h: np.asarray([_typed(h, x) for x in v]) for h, v in columns.items()}
        except CaseError as exc:
            raise CaseError(f"design table {os.fspath(table)}: {exc}") from None
    if hasattr(table, "columns") and hasattr(table, "to_dict"):      # a pandas DataFrame
        table = {str(c): table[c].to_numpy() for c in table.columns}
    if not isinstance(table, Mapping):
        raise CaseError(f"table: a design table is a CSV path, a mapping or a DataFrame, not "
                        f"{type(table).__name__}")
    out = {str(k).lower(): _as_values(k, v, "table") for k, v in table.items()}
    if len({len(v) for v in out.values()}) > 1:
        raise CaseError("table: the columns of a design table must have the same length, got "
                        + ", ".join(f"{k} {len(v)}" for k, v in out.items()))
    return out


def table_cases(case, columns: Mapping) -> dict:
    """{(row,): Case or CaseError} for every row of a design table (columns: read_table)."""
    n = len(next(iter(columns.values())))
    out = {}
    for i in range(n):
        try:
            out[(i,)] = case.replace(**{f: _py(v[i]) for f, v in columns.items()})
        except CaseError as exc:
            out[(i,)] = exc
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

def run_point(case: Case, options: dict) -> dict:
    """The task of one sweep point (module level, picklable arguments and result): simulate
    the point's case and return its summary. A failure of the case (any Exception: CaseError,
    SolverError, ThermalInterferenceError, ...) is returned as a summary with NaN values and the
    message in 'error' and the class name in 'error_class'; KeyboardInterrupt propagates.
    The point's warnings (the core's lines) go to 'warnings', not raised: the sweep says each
    kind once (pyspline.warned).
    A case with realisations > 1 runs its copies one after another (the sweep's workers are the
    parallelism)."""
    from .core import simulate
    from .result import SerialExecutor, collected
    with collected() as said:             # the point's warnings: in its summary, not raised
        try:
            return summarise(simulate(case, SerialExecutor()), options)
        except Exception as exc:          # noqa: BLE001 -- a failed point is a result
            return dict(failed_summary(exc, options), warnings="\n".join(said))


class PointSummaries:
    """The summaries of a chunk of points, as one object. Dask sends it back as one pickle (its
    arrays as out-of-band buffers); a bare list of dicts of arrays it walks item by item, which
    cost 7-11 ms per task of 15 points, as much as two of the points themselves."""
    __slots__ = ("items",)

    def __init__(self, items: list):
        self.items = items


def run_points(cases: list, options: dict) -> PointSummaries:
    """A chunk of sweep points as one task (fewer round trips through a process pool or a
    Dask scheduler): run_point for each."""
    return PointSummaries([run_point(case, options) for case in cases])


#: Most points in one task on processes and Dask: what a Ctrl-C or a crash loses per worker
#: (a task's points are saved when it ends).
MAX_TASK_POINTS = 32


def task_points(n: int, workers: int) -> int:
    """Points in each task of a sweep of `n` points on `workers` processes or Dask workers: a
    quarter of a worker's share, ceil(n / (4 workers)), so that a task's fixed cost (a few ms on
    Dask) is spread over several points and the workers still finish close together; at least
    1, at most MAX_TASK_POINTS."""
    return max(1, min(MAX_TASK_POINTS, -(-n // (4 * max(1, workers)))))


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


# --------------------------------------------------------------------------- sweep

def _default_orders(cases) -> np.ndarray:
    z = max([c["z"] for c in cases if isinstance(c, Case)] or [defaults()["z"]])
    n = int(round((2 * z + 2) / ORDER_STEP))
    return np.round(np.arange(n + 1) * ORDER_STEP, 10)



def sweep(case, executor=None, progress=True, out=None, section="shaft", lyapunov=False, *,
          spectrum=None, orders=None, command=None, chunk=None, workers=None, table=None,
          follow=None, finals=None, **fields):
    """Run `case` (a Case, dict of fields or namelist path) over one or two swept fields, or
    over the rows of a design table, and return an xarray.Dataset of the per-point summaries.

    ``sweep(case, l_x=np.linspace(0, 3e-4, 61))`` sweeps one field; two keywords sweep their
    grid (first field varies slowest; dims in keyword order). Values: any 1-D sequence.
    ``sweep(case, table="design.csv")`` runs one point per row of a table of case fields
    (read_table: CSV path, mapping or DataFrame): dim 'point' (the row), the fields as
    coordinates along it.

    executor : None (serial, in this process) or a concurrent.futures.Executor
        (ThreadPoolExecutor, ProcessPoolExecutor, ``distributed.Client(...).get_executor()``).
        The caller keeps ownership: it is not shut down here.
    chunk : points per task; all tasks are submitted at once. Default: on threads one point
        per task; on processes and Dask task_points(points to compute, workers): four tasks
        per worker, at most MAX_TASK_POINTS points each.
    workers : how many tasks the executor runs at once, for the default chunk (default
        os.cpu_count(), a ProcessPoolExecutor's default; on a Dask cluster pass its
        ``sum(client.nthreads().values())``).
    progress : bool, tqdm progress bar on stderr.
    out : directory or None. Each finished point is written to ``out/points/`` at once; the
        merge goes to ``out/sweep.nc`` (NetCDF-4, netcdf4), also when the sweep is stopped by
        an exception or KeyboardInterrupt (pending points are cancelled, the exception is
        re-raised). A rerun into the same directory reuses every point file whose index and
        hash (case text + summary options) match and computes the rest.
    section : 'shaft' | 'tooth' | 'none', the Poincare section (case field section).
    lyapunov : bool, compute the largest Lyapunov exponent (case field lyapunov).
    spectrum : bool or None; the T_m spectrum on a common shaft-order axis. Default: when
        speed_rpm is swept.
    orders : shaft-order axis of the spectrum (default 0 .. 2Z+2 in steps of 0.05).
    command : text stored in attrs['command'] (default: this call, abbreviated).
    follow : None, 'up', 'down' or 'both' (one swept field): run the points in order of the
        value (up: increasing), each from the previous point's final state (pyspline.follow),
        so hysteresis and coexisting attractors show; 'both' adds a dim 'direction' (up,
        down). Chains are serial: an executor runs one chain per direction; `out` gets
        sweep.nc only (no point files: a point depends on the one before).
    finals : with follow, a dict filled with {direction: [(final state (14,), SI, its time) or
        None (a failed point), by index of the swept values]} (pyspline.branches' seeds).

    Dataset: coordinates = the swept values (units from the core's field table); per point
    section_t/section_D2/section_vD2 (dim 'section_point', NaN-padded), period and
    period_residual; lyapunov, lyapunov_spread, lyapunov_rel_spread, lyapunov_slope,
    predictability_horizon, chaotic (analysis.is_chaotic: 1 if the exponent and the slope exceed
    the spread; if lyapunov);
    Tm_/kv_/F_ max, min, rms, Tf_max, D2_max, D2_min, D2_rms; the loads (SWEEP_LOADS:
    load_sharing, free_frac_max, back_frac_max, teeth_free_mean, teeth_back, impacts_per_rev,
    closing_speed_max, the stresses, the per-revolution means load_sharing_rev, Tf_max_rev,
    and the batch-means standard errors NAME_se of Tm_rms, kv_rms, F_rms, D2_rms,
    teeth_free_mean, free_frac_max, back_frac_max, impacts_per_rev, load_sharing_rev,
    Tf_max_rev; docs/model.md section 15);
    solver statistics (steps, rhs_evals, ..., core_wall_s, wall_s); Tm_spectrum (dim 'order');
    error, error_class ('' if ok), point_hash. A failed point has NaN values and its error.
    attrs: case (namelist text of the base case), pyspline_version, pyspline_build, command, swept, section,
    lyapunov, created, out, and the counts n_points, n_ok, n_failed (incl. executor errors),
    n_missing (not run: the sweep stopped), n_computed (by this call), n_reused (from point
    files), n_executor_errors (the executor, not the case, failed: not saved, so a rerun tries
    those points again).
    """
    base = load_case(case)
    if section not in SECTIONS:
        raise CaseError(f"section must be one of {', '.join(SECTIONS)}, got {section!r}")
    if table is not None:
        if fields:
            raise CaseError("sweep: give a design table or fields to sweep, not both")
        fields = read_table(table)
        if not fields or not len(next(iter(fields.values()))):
            raise CaseError("table: the design table has no fields or no rows")
    elif not fields:
        raise CaseError("sweep: no field to sweep given, e.g. l_x=[0, 1e-4, 2e-4]")
    elif len(fields) > 2:
        raise CaseError(f"sweep takes one or two fields, got {len(fields)}: {', '.join(fields)}")
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
        raise CaseError("sweep: the same field is swept twice")
    base = base.replace(section=section, lyapunov=bool(lyapunov))
    point_fields = None
    if table is not None:     # one dim 'point', the table's fields as its coordinates
        point_fields, grid = grid, {"point": np.arange(len(next(iter(grid.values()))))}
        cases = table_cases(base, point_fields)
    else:
        cases = point_cases(base, grid)
    if spectrum is None:
        spectrum = "speed_rpm" in (point_fields or grid)
    if spectrum and orders is None:
        orders = _default_orders(cases.values())
    options = dict(section=section, lyapunov=bool(lyapunov),
                   orders=None if not spectrum else [float(o) for o in np.asarray(orders)])
    keys = list(_template(options, _stat_names()))

    if follow is not None:
        return _follow(base, grid, cases, keys, options, follow, point_fields, executor, progress,
                       out, command, section, lyapunov, finals)
    hashes, summaries, todo, n_reused = {}, {}, [], 0
    points_dir = None
    if out is not None:
        out = Path(out)
        points_dir = out / POINTS_DIR
        points_dir.mkdir(parents=True, exist_ok=True)
    for index, c in cases.items():
        if isinstance(c, Exception):       # rejected at once: a result, nothing to run
            summaries[index] = failed_summary(c, options)
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
        if point_fields is not None:
            spec = f"table=[{len(grid['point'])} rows of {', '.join(point_fields)}]"
        command = f"pyspline.sweep({base.name!r}, {spec}, section={section!r}, " \
                  f"lyapunov={bool(lyapunov)})"
    attrs = dict(case=base.text(), **provenance(), command=command,
                 swept=" ".join(point_fields or grid), section=section, lyapunov=int(bool(lyapunov)),
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
    if executor is not None and not chunk:
        threads = isinstance(executor, cf.ThreadPoolExecutor)
        chunk = 1 if threads else task_points(len(todo), workers or os.cpu_count() or 1)

    def submit():
        """All tasks at once: chunks of `chunk` points, in grid order."""
        for k in range(0, len(todo), chunk):
            indices = todo[k:k + chunk]
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
        else:
            for fut in cf.as_completed(list(futures)):
                take(fut)
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
            ds = build_dataset(grid, keys, summaries, hashes, options, attrs, point_fields)
            if out is not None:
                write_netcdf(ds, out / MERGED)
        except Exception as merge_exc:     # noqa: BLE001 -- keep the original exception
            print(f"pyspline sweep: could not merge the finished points: {merge_exc}",
                  file=sys.stderr)
        raise
    bar.close()
    attrs.update(n_computed=computed, n_executor_errors=executor_errors)
    ds = build_dataset(grid, keys, summaries, hashes, options, attrs, point_fields)
    if out is not None:
        write_netcdf(ds, out / MERGED)
    warn_grouped(ds)
    return ds


def _follow(base, grid, cases, keys, options, follow, point_fields, executor, progress, out,
            command, section, lyapunov, finals=None):
    """sweep(..., follow=...): chains of points (pyspline.follow), one Dataset per direction
    ('both': concatenated along 'direction')."""
    from tqdm import tqdm
    from .follow import DIRECTIONS, follow_sweep
    if follow not in DIRECTIONS:
        raise CaseError(f"follow must be one of {', '.join(DIRECTIONS)} or None, got {follow!r}")
    if point_fields is not None or len(grid) != 1:
        raise CaseError("follow= needs exactly one swept field (a line of values), not a grid "
                        "or a design table")
    (name, values), = grid.items()
    hashes = {i: point_hash(c, options) for i, c in cases.items() if isinstance(c, Case)}
    if command is None:
        command = f"pyspline.sweep({base.name!r}, {name}=[{len(values)} values], " \
                  f"section={section!r}, lyapunov={bool(lyapunov)}, follow={follow!r})"
    attrs = dict(case=base.text(), **provenance(), command=command, swept=name,
                 section=section, lyapunov=int(bool(lyapunov)), follow=follow,
                 created=datetime.datetime.now(datetime.timezone.utc).isoformat(
                     timespec="seconds"), n_reused=0, out="" if out is None else str(out),
                 n_executor_errors=0)
    total = len(values) * (2 if follow == "both" else 1)
    with tqdm(total=total, desc=f"sweep {name} (follow {follow})", unit="run",
              disable=not progress, dynamic_ncols=True) as bar:
        runs = follow_sweep(cases, values, follow, options if finals is None else
                            dict(options, final_state=True), executor, bar)
    if finals is not None:      # {direction: [(state, time) or None by index]}
        finals.update({d: [r[(i,)].get("final") for i in range(len(values))]
                       for d, r in runs.items()})
    if follow == "both":     # one grid (direction, field): the dataset builder pads sections
        dgrid = {"direction": np.array(["up", "down"]), **grid}
        summaries = {(k,) + i: s for k, d in enumerate(("up", "down")) for i, s in runs[d].items()}
        hashes = {(k,) + i: h for k in range(2) for i, h in hashes.items()}
    else:
        dgrid, summaries = grid, runs[follow]
    attrs.update(n_computed=len(summaries))
    ds = build_dataset(dgrid, keys, summaries, hashes, options, attrs)
    if out is not None:
        write_netcdf(ds, Path(out) / MERGED)
    warn_grouped(ds, 4)
    return ds
