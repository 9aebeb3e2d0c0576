"""Batch runs that end in one dataset: the summaries `spline-dyn CASE --summary FILE` writes (one
per run, e.g. one per Slurm array task; no time series) read back exactly and merged into the
xarray.Dataset `pyspline.sweep` builds for the same points (`merge`; its command,
`pyspline merge`, is pyspline.mergecli).

A summary (fortran/interface/spline_dyn.f90 write_summary) has lines ``NAME [UNIT] = VALUES`` (numbers
comma-separated, 17 significant digits: every double reads back exactly), ``NAME = 'TEXT'``
lines, and the case as a namelist (every field). What a sweep point keeps comes from it as
follows: the statistics, the loads, the extremes and RMS of T_m, k_v, F, T_f, D2 (the core's
run_results, which Python's Result.extremes come from too) and the Poincare section are the
core's numbers, bit for bit; the period of the
section and the Lyapunov exponent and its fit are computed here from the section points and
the Benettin record, as `summarise` does; wall_s is the executable's time of the run. Not
available from a summary: the spectrum of T_m (it needs the time series): a merged dataset
has no Tm_spectrum.
"""
from __future__ import annotations

import datetime
import hashlib
import re
from pathlib import Path

import numpy as np

from ._build_info import provenance
from .case import case_from_text, defaults
from .dataset import MERGED, build_dataset, write_netcdf
from .errors import BY_NAME, CaseError, SplineError
from .result import collected
from .summary import (SWEEP_EXTREMES, SWEEP_LOADS, _stat_names, _template, lyapunov_summary,
                      section_summary)
from .sweeps import point_hash
from .warned import warn_grouped

__all__ = ["merge", "read_summary", "summary_point"]

FORMAT = "pyspline-summary 1"
_NUMBERS = re.compile(r"^(\S+) \[([^\]]*)\] =(.*)$")
_TEXT = re.compile(r"^(\S+) = '(.*)'$")


def _unquote(text: str) -> str:
    return text.replace("''", "'").replace("\\n", "\n")


def _check_values(path, values: dict, z: int) -> None:
    """Every array of a finished run's summary that merge reads has its shape (one value per
    statistic, load and run value, Z per tooth, a section's and a Benettin record's arrays alike
    long) and is finite (the loads and k_v's extremes may be NaN where the core gives none: a
    standard error of fewer than 2 revolutions, a load sharing or k_v at T_d = 0)."""
    sizes = {"stats": 1, "run": 1, "loads": 1, "tooth_loads": z,
             "section": len(values.get("section.t", ())),
             "lyapunov": len(values.get("lyapunov.t", ()))}
    for name, x in values.items():
        group = name.split(".")[0]
        want = sizes.get(group)
        if want is None:                 # a line merge does not read
            continue
        if x.size != want:
            raise CaseError(f"summary {path}: {name} has {x.size} values, {want} expected")
        nan_ok = group in ("loads", "tooth_loads") or name.startswith("run.kv_")
        bad = np.isinf(x) if nan_ok else ~np.isfinite(x)
        if bad.any():
            raise CaseError(f"summary {path}: {name} = {float(x[bad][0])} is not finite")


def read_summary(path) -> dict:
    """A summary file of spline-dyn: {'values': {name: float array}, 'units': {name: unit},
    'case': the Case of the run (its namelist read in memory by the core's reader; None if a
    failed run wrote none), 'case_file', 'sets' (its --set options), 'error' ('' if the run
    finished), 'error_class' ('' or the exception class name), 'warnings' (the lines spline-dyn
    printed; None from a summary of a version that did not keep them), 'path'}. Every error
    names the file."""
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise CaseError(f"summary {path}: cannot read it: {exc}") from None
    if f"format = '{FORMAT}'" not in lines[:5]:
        raise CaseError(f"summary {path}: not a summary of spline-dyn --summary ({FORMAT})")
    values, units, text, sets = {}, {}, {}, []
    case_text = ""
    for k, line in enumerate(lines):
        if line.startswith("&"):
            case_text = "\n".join(lines[k:]) + "\n"
            break
        if not line.strip() or line.startswith("#"):
            continue
        m = _NUMBERS.match(line)
        if m:
            items = [x for x in m.group(3).split(",") if x.strip()]
            try:
                values[m.group(1)] = np.array([float(x) for x in items])
            except ValueError:
                raise CaseError(f"summary {path}, line {k + 1}: not numbers: "
                                f"{m.group(3).strip()[:60]!r}") from None
            units[m.group(1)] = m.group(2)
            continue
        m = _TEXT.match(line)
        if not m:
            raise CaseError(f"summary {path}, line {k + 1}: neither NAME [UNIT] = VALUES nor "
                            f"NAME = 'TEXT': {line[:60]!r}")
        if m.group(1) == "set":
            sets.append(_unquote(m.group(2)))
        else:
            text[m.group(1)] = _unquote(m.group(2))
    kind = text.get("error_kind", "")
    error = text.get("error", "")
    if kind and not error or error and kind not in BY_NAME:
        raise CaseError(f"summary {path}: an error needs its message and one of the kinds "
                        f"{', '.join(BY_NAME)} (error_kind = {kind!r})")
    if not case_text and not error:
        raise CaseError(f"summary {path}: no case (&spline_case) at its end")
    case = None
    if case_text:
        try:
            case = case_from_text(case_text, source=text.get("case_file"))
            if not error:
                case.model                   # a finished run's case is a valid one
        except SplineError as exc:
            raise CaseError(f"summary {path}: its case: {exc}") from None
    if not error:
        _check_values(path, values, case["z"])
    return dict(values=values, units=units, case=case, case_file=text.get("case_file", ""),
                sets=sets, error=error, path=path, warnings=text.get("warnings"),
                error_class=BY_NAME[kind].__name__ if kind else "")


def summary_point(summary: dict, options: dict) -> dict:
    """The sweep point (the keys of `summarise`, without the spectrum) of a read summary."""
    s = _template(options, _stat_names())
    s["warnings"] = summary.get("warnings") or ""
    if summary["error"]:
        s.update(error=summary["error"], error_class=summary["error_class"])
        return s
    v = summary["values"]

    def one(name):
        if name not in v:
            raise CaseError(f"summary {summary['path']}: no {name} (a run that finished "
                            "writes it)")
        return float(v[name][0])

    if options["section"] != "none":
        section_summary(s, summary["case"], v.get("section.t", []), v.get("section.D2", []),
                        v.get("section.vD2", []), (one("run.D2_rms"), one("run.vD2_rms")))
    if options["lyapunov"] and len(v.get("lyapunov.t", ())):
        lt, lg = v["lyapunov.t"], v["lyapunov.log_growth"]
        t0 = one("run.t_first")
        lyapunov_summary(s, lt, lg, float(lg[-1] / (lt - t0)[-1]), t0)
    s.update({k: one("run." + k) for k in SWEEP_EXTREMES})
    s.update({k: one("loads." + k) for k in SWEEP_LOADS})
    for k in _stat_names():
        if "stats." + k in v:
            s[k] = one("stats." + k)
    s["wall_s"] = one("run.wall_s")
    return s


def _scalar(x):
    return tuple(x) if isinstance(x, list) else x


def _column(values: list) -> np.ndarray:
    """A coordinate along 'point' of values with gaps (None: a point without a case): numbers
    with NaN, else text with ''."""
    known = [v for v in values if v is not None]
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in known):
        return np.array([np.nan if v is None else v for v in values], dtype=float)
    return np.array(["" if v is None else str(v) for v in values])


def merge(summaries, out=None, fields=None, command=None, mixed=False):
    """The sweep dataset of spline-dyn summary files (paths; `pyspline merge`), the same Dataset
    `pyspline.sweep` builds for the same points, without the spectrum of T_m.

    fields : the fields that vary between the points (default: every case field whose value
        differs between the summaries). One or two fields whose values form a full grid, each
        point once: dims are the fields, values ascending (the grid of ``sweep(case, F=...)``
        for ascending values); else dim 'point' (the summaries in the order given) with the
        fields as coordinates along it, like a design table.
    out : directory for DIR/sweep.nc (NetCDF-4), or None.
    mixed : merge summaries of different cases (case names); refused by default.
    A failed run is a failed point (error, error_class); one whose case was not read (its
    file or a --set was refused) has no coordinates: the merge is then along 'point', its
    coordinates NaN (''). The same point twice (by point hash) is refused. The points'
    section and lyapunov must be the same in all summaries. The variable 'summary' names each
    point's file. Each point's 'warnings' are those its run printed (its summary's) and each
    kind is said once (pyspline.warned), as pyspline.sweep does.
    """
    paths = [Path(p) for p in summaries]
    if not paths:
        raise CaseError("merge needs at least one summary file")
    read = []
    for p in paths:
        with collected() as lines:       # the point's warnings, said once below: the summary's
            read.append(read_summary(p))
        if read[-1]["warnings"] is None:  # an older summary's: its case's
            read[-1]["warnings"] = "\n".join(lines)
    cases = [r["case"] for r in read]
    have = [c for c in cases if c is not None]
    names = sorted({c.name for c in have})
    if len(names) > 1 and not mixed:
        raise CaseError(f"the summaries are of {len(names)} cases ({', '.join(names[:4])}"
                        f"{', ...' if len(names) > 4 else ''}): merge one case's points, or "
                        "ask for it (--mixed, mixed=True)")
    options = {}
    for key, default in (("section", "shaft"), ("lyapunov", False)):
        vals = {c[key] for c in have} or {default}
        if len(vals) > 1:
            raise CaseError(f"the summaries mix {key} = {', '.join(map(str, sorted(vals)))}: "
                            "merge points of one kind")
        options[key] = vals.pop()
    options["orders"] = None
    if fields is None:
        fields = [f for f in defaults() if (f != "name" or mixed) and
                  len({_scalar(c[f]) for c in have}) > 1]
    else:
        fields = [f.strip().lower() for f in fields]
        for i, f in enumerate(fields):
            if f not in defaults():
                raise CaseError(f"unknown field '{f}' (see cases/template.nml)")
            if f in fields[:i]:
                raise CaseError(f"fields: {f} given twice")
    for f in fields:
        if have and isinstance(have[0][f], list):
            raise CaseError(f"field {f} differs between the summaries but has several values: "
                            "it cannot be a coordinate")
    columns = {f: [None if c is None else c[f] for c in cases] for f in fields}
    hashes_of = [point_hash(c, options) if c is not None else
                 hashlib.sha256(repr((r["case_file"], r["sets"])).encode()).hexdigest()[:16]
                 for c, r in zip(cases, read)]
    first: dict = {}
    for h, p in zip(hashes_of, paths):
        if h in first:
            raise CaseError(f"summaries {first[h]} and {p} are the same point (hash {h}): "
                            "merge each point once")
        first[h] = p
    point_fields = None
    if len(have) == len(cases):
        uniq = {f: sorted(set(v)) for f, v in columns.items()}
        index_of = [tuple(uniq[f].index(c[f]) for f in fields) for c in cases]
    if len(have) == len(cases) and 1 <= len(fields) <= 2 and len(set(index_of)) == len(cases) \
            == int(np.prod([len(u) for u in uniq.values()])):
        grid = {f: np.asarray(u) for f, u in uniq.items()}
    else:
        grid = {"point": np.arange(len(cases))}
        point_fields = {f: _column(v) for f, v in columns.items()}
        index_of = [(i,) for i in range(len(cases))]
    keys = list(_template(options, _stat_names()))
    points = {}
    with collected():                   # kept above
        for i, r in zip(index_of, read):
            points[i] = summary_point(r, options)
    hashes = dict(zip(index_of, hashes_of))
    attrs = dict(case=(have[0].text() if have else ""), **provenance(),
                 command=command or f"pyspline.merge([{len(paths)} spline-dyn summaries])",
                 swept=" ".join(fields), section=options["section"],
                 lyapunov=int(options["lyapunov"]),
                 created=datetime.datetime.now(datetime.timezone.utc).isoformat(
                     timespec="seconds"),
                 n_reused=0, out="" if out is None else str(out), n_computed=len(paths),
                 n_executor_errors=0, source="spline-dyn --summary")
    ds = build_dataset(grid, keys, points, hashes, options, attrs, point_fields)
    files = np.full(tuple(len(v) for v in grid.values()), "", dtype=object)
    for i, p in zip(index_of, paths):
        files[i] = str(p)
    ds["summary"] = (tuple(grid), files.astype(str), {"long_name": "the point's summary file"})
    if out is not None:
        write_netcdf(ds, Path(out) / MERGED)
    warn_grouped(ds)
    return ds
