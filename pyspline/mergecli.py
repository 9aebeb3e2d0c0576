"""`pyspline merge`: the command line of pyspline.batch (docs/building.md: Slurm arrays)."""
from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

import numpy as np

from .batch import merge
from .dataset import MERGED
from .errors import CaseError


def _main_paths(items) -> list:
    """Summary paths from the command line: files, and directories (every *.summary in them)."""
    paths = []
    for item in items:
        p = Path(item)
        paths += sorted(p.glob("*.summary")) if p.is_dir() else [p]
    return paths


def cmd_merge(args) -> int:
    """`pyspline merge SUMMARY... --out DIR`."""
    paths = _main_paths(args.summaries)
    if not paths:
        raise CaseError(f"merge: no summary in {', '.join(args.summaries)} (a directory stands "
                        "for its *.summary files)")
    fields = [f for f in (args.fields or "").split(",") if f.strip()] or None
    cmd = " ".join(shlex.quote(a) for a in ["pyspline", "merge", *args.summaries,
                                            f"--out={args.out}"])
    ds = merge(paths, out=args.out, fields=fields, command=cmd, mixed=args.mixed)
    a = ds.attrs
    print(f"{a['n_points']} points from {len(paths)} summaries ({a['swept'] or 'no field'} "
          f"varying): {a['n_ok']} ran, {a['n_failed']} failed")
    if a["n_failed"]:
        failed = ds["error"].values.ravel() != ""
        k = int(np.argmax(failed))
        print(f"first error ({ds['summary'].values.ravel()[k]}): "
              f"{ds['error_class'].values.ravel()[k]}: {ds['error'].values.ravel()[k]}",
              file=sys.stderr)
    print(f"wrote {Path(args.out) / MERGED} (pyspline.open_sweep)")
    return 0


MERGE_HELP = """\
Merge the summaries of spline-dyn runs (spline-dyn CASE --summary FILE, e.g. one per Slurm
array task) into the sweep dataset DIR/sweep.nc, the one `pyspline sweep` writes for the same
points (without the spectrum of T_m, which needs the time series). The fields that differ
between the runs' cases are the coordinates: one or two fields forming a full grid become its
dims; anything else a dim 'point' with the fields as coordinates. A directory argument stands
for every *.summary file in it. A failed run is a failed point (error, error_class; variable
'summary' names each point's file); the same point twice, or summaries of different cases
(unless --mixed), are refused; a plausibility warning is printed once, with its count.

example: pyspline merge runs/*.summary --out out/lx
"""


def add_merge(sub) -> None:
    """The `merge` subcommand."""
    r = sub.add_parser("merge", help="merge spline-dyn --summary files into DIR/sweep.nc",
                       description=MERGE_HELP,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    r.add_argument("summaries", nargs="+", metavar="SUMMARY", help="summary files or directories")
    r.add_argument("--out", required=True, metavar="DIR", help="output directory")
    r.add_argument("--fields", metavar="F1,F2",
                   help="the varying fields (default: those that differ between the cases)")
    r.add_argument("--mixed", action="store_true",
                   help="merge summaries of different cases (refused by default)")
    r.set_defaults(func=cmd_merge)
