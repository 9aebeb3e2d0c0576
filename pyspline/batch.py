"""Batch runs that end in one dataset: the summaries `spline-dyn CASE --summary FILE` writes (one
per run, e.g. one per Slurm array task; no time series) read back exactly and merged into the
xarray.Dataset `pyspline.sweep` builds for the same points (`merge`, `pyspline merge`).

A summary (app/spline_dyn.f90 write_summary) has lines ``NAME [UNIT] = VALUES`` (numbers
comma-separated, 17 significant digits: every double reads back exactly), ``NAME = 'TEXT'``
lines, and the case as a namelist (every field). What a sweep point keeps comes from it as
follows: the statistics, the loads, the max/min of T_m, k_v, F, T_f, D2 and the Poincare
section are the core's numbers, bit for bit; the RMS values are the executable's
sqrt(sum(x**2)/n) (numpy sums pairwise: equal to about 1e-15 relative); the period of the
section and the Lyapunov exponent and its fit are computed here from the section points and
the Benettin record, as `summarise` does; wall_s is the executable's time of the run. Not
available from a summary: the spectrum of T_m (it needs the time series): a merged dataset
has no Tm_spectrum.
"""
from __future__ import annotations

import datetime
import re
import tempfile
from pathlib import Path

import numpy as np

from .case import defaults, load_case
from .dataset import MERGED, build_dataset, write_netcdf
from .errors import BY_NAME, CaseError, SplineError
from .sweep import (SWEEP_LOADS, _stat_names, _template, _version, lyapunov_summary,
                    point_hash, section_summary)

__all__ = ["merge", "read_summary", "summary_point"]

FORMAT = "pyspline-summary 1"
_NUMBERS = re.compile(r"^(\S+) \[([^\]]*)\] =(.*)$")
_TEXT = re.compile(r"^(\S+) = '(.*)'$")


def _unquote(text: str) -> str:
    return text.replace("''", "'").replace("\\n", "\n")


def read_summary(path) -> dict:
    """A summary file of spline-dyn: {'values': {name: float array}, 'units': {name: unit},
    'case': the Case of the run (its namelist read by the core's reader), 'case_file',
    'error' ('' if the run finished), 'error_class' ('' or the exception class name)}."""
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise CaseError(f"summary {path}: cannot read it: {exc}") from None
    if f"format = '{FORMAT}'" not in lines[:5]:
        raise CaseError(f"summary {path}: not a summary of spline-dyn --summary ({FORMAT})")
    values, units, text = {}, {}, {}
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
        text[m.group(1)] = _unquote(m.group(2))
    else:
        case_text = ""
    if not case_text:
        raise CaseError(f"summary {path}: no case (&spline_case) at its end")
    with tempfile.TemporaryDirectory() as tmp:     # the core's reader reads files
        nml = Path(tmp) / "case.nml"
        nml.write_text(case_text, encoding="utf-8")
        case = load_case(nml)
    case.source = text.get("case_file")
    kind = text.get("error_kind", "")
    return dict(values=values, units=units, case=case, case_file=text.get("case_file", ""),
                error=text.get("error", ""),
                error_class=BY_NAME.get(kind, SplineError).__name__ if kind else "")


def summary_point(summary: dict, options: dict) -> dict:
    """The sweep point (the keys of `summarise`, without the spectrum) of a read summary."""
    s = _template(options, _stat_names())
    if summary["error"]:
        s.update(error=summary["error"], error_class=summary["error_class"])
        return s
    v = summary["values"]

    def one(name):
        return float(v[name][0])

    if options["section"] != "none":
        section_summary(s, summary["case"], v["section.t"], v["section.D2"], v["section.vD2"],
                        (one("run.D2_rms"), one("run.vD2_rms")))
    if options["lyapunov"] and len(v["lyapunov.t"]):
        lt, lg = v["lyapunov.t"], v["lyapunov.log_growth"]
        t0 = one("run.t_first")
        lyapunov_summary(s, lt, lg, float(lg[-1] / (lt - t0)[-1]), t0)
    for q in ("Tm", "kv", "F"):
        s.update({f"{q}_{w}": one(f"run.{q}_{w}") for w in ("max", "min", "rms")})
    s.update(Tf_max=one("run.Tf_max"), D2_max=one("run.D2_max"), D2_min=one("run.D2_min"),
             D2_rms=one("run.D2_rms"))
    s.update({k: one("loads." + k) for k in SWEEP_LOADS})
    for k in _stat_names():
        if "stats." + k in v:
            s[k] = one("stats." + k)
    s["wall_s"] = one("run.wall_s")
    return s


def _scalar(x):
    return tuple(x) if isinstance(x, list) else x


def merge(summaries, out=None, fields=None, command=None):
    """The sweep dataset of spline-dyn summary files (paths; `pyspline merge`), the same Dataset
    `pyspline.sweep` builds for the same points, without the spectrum of T_m.

    fields : the fields that vary between the points (default: every case field whose value
        differs between the summaries). One or two fields whose values form a full grid, each
        point once: dims are the fields, values ascending (the grid of ``sweep(case, F=...)``
        for ascending values); else dim 'point' (the summaries in the order given) with the
        fields as coordinates along it, like a design table.
    out : directory for DIR/sweep.nc (NetCDF-4), or None.
    The points' section (shaft, tooth, none) and lyapunov must be the same in all summaries.
    """
    paths = [Path(p) for p in summaries]
    if not paths:
        raise CaseError("merge needs at least one summary file")
    read = [read_summary(p) for p in paths]
    cases = [r["case"] for r in read]
    options = {}
    for key in ("section", "lyapunov"):
        vals = {c[key] for c in cases}
        if len(vals) > 1:
            raise CaseError(f"the summaries mix {key} = {', '.join(map(str, sorted(vals)))}: "
                            "merge points of one kind")
        options[key] = vals.pop()
    options["orders"] = None
    if fields is None:
        fields = [f for f in defaults() if f != "name" and
                  len({_scalar(c[f]) for c in cases}) > 1]
    else:
        fields = [f.strip().lower() for f in fields]
        for f in fields:
            if f not in defaults():
                raise CaseError(f"unknown field '{f}' (see cases/template.nml)")
    for f in fields:
        if isinstance(cases[0][f], list):
            raise CaseError(f"field {f} differs between the summaries but has several values: "
                            "it cannot be a coordinate")
    columns = {f: [c[f] for c in cases] for f in fields}
    uniq = {f: sorted(set(v)) for f, v in columns.items()}
    index_of = [tuple(uniq[f].index(c[f]) for f in fields) for c in cases]
    point_fields = None
    if 1 <= len(fields) <= 2 and len(set(index_of)) == len(cases) == \
            int(np.prod([len(u) for u in uniq.values()])):
        grid = {f: np.asarray(u) for f, u in uniq.items()}
    else:
        grid = {"point": np.arange(len(cases))}
        point_fields = {f: np.asarray(v) for f, v in columns.items()}
        index_of = [(i,) for i in range(len(cases))]
    keys = list(_template(options, _stat_names()))
    points = {i: summary_point(r, options) for i, r in zip(index_of, read)}
    hashes = {i: point_hash(c, options) for i, c in zip(index_of, cases)}
    attrs = dict(case=cases[0].text(), pyspline_version=_version(),
                 command=command or f"pyspline.merge([{len(paths)} spline-dyn summaries])",
                 swept=" ".join(fields), section=options["section"],
                 lyapunov=int(options["lyapunov"]),
                 created=datetime.datetime.now(datetime.timezone.utc).isoformat(
                     timespec="seconds"),
                 n_reused=0, out="" if out is None else str(out), n_computed=len(paths),
                 n_executor_errors=0, source="spline-dyn --summary")
    ds = build_dataset(grid, keys, points, hashes, options, attrs, point_fields)
    if out is not None:
        write_netcdf(ds, Path(out) / MERGED)
    return ds


def _main_paths(items) -> list:
    """Summary paths from the command line: files, and directories (every *.summary in them)."""
    paths = []
    for item in items:
        p = Path(item)
        paths += sorted(p.glob("*.summary")) if p.is_dir() else [p]
    return paths


def cmd_merge(args) -> int:
    """`pyspline merge SUMMARY... --out DIR`."""
    import shlex
    import sys
    paths = _main_paths(args.summaries)
    fields = [f for f in (args.fields or "").split(",") if f.strip()] or None
    cmd = " ".join(shlex.quote(a) for a in ["pyspline", "merge", *args.summaries,
                                            f"--out={args.out}"])
    ds = merge(paths, out=args.out, fields=fields, command=cmd)
    a = ds.attrs
    print(f"{a['n_points']} points from {len(paths)} summaries ({a['swept'] or 'no field'} "
          f"varying): {a['n_ok']} ran, {a['n_failed']} failed")
    if a["n_failed"]:
        errors = [e for e in ds["error"].values.ravel() if e]
        print(f"first error: {errors[0]}", file=sys.stderr)
    print(f"wrote {Path(args.out) / MERGED} (pyspline.open_sweep)")
    return 0


MERGE_HELP = """\
Merge the summaries of spline-dyn runs (spline-dyn CASE --summary FILE, e.g. one per Slurm
array task) into the sweep dataset DIR/sweep.nc, the one `pyspline sweep` writes for the same
points (without the spectrum of T_m, which needs the time series). The fields that differ
between the runs' cases are the coordinates: one or two fields forming a full grid become its
dims; anything else a dim 'point' with the fields as coordinates. A directory argument stands
for every *.summary file in it.

example: pyspline merge runs/*.summary --out out/lx
"""


def add_merge(sub) -> None:
    """The `merge` subcommand."""
    import argparse
    r = sub.add_parser("merge", help="merge spline-dyn --summary files into DIR/sweep.nc",
                       description=MERGE_HELP,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    r.add_argument("summaries", nargs="+", metavar="SUMMARY", help="summary files or directories")
    r.add_argument("--out", required=True, metavar="DIR", help="output directory")
    r.add_argument("--fields", metavar="F1,F2",
                   help="the varying fields (default: those that differ between the cases)")
    r.set_defaults(func=cmd_merge)
