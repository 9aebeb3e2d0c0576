"""Command line: ``pyspline run CASE...`` (and ``python -m pyspline``)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np


def _summary(res) -> str:
    F = res.tooth["F"]
    s = res.stats
    return (f"{res.case.name:>16s}  F_j [{F.min():8.2f}, {F.max():8.2f}] N  "
            f"T_m [{res.Tm.min():7.2f}, {res.Tm.max():7.2f}] N m  "
            f"k_v [{res.kv.min():.3f}, {res.kv.max():.3f}]  "
            f"D2 [{res.D2.min():.4e}, {res.D2.max():.4e}] m  "
            f"steps {s['steps']}  {s['wall_s']*1e3:.0f} ms")


def cmd_run(args) -> int:
    from .core import simulate
    from .case import SplineError
    status = 0
    for path in args.cases:
        try:
            res = simulate(path)
        except SplineError as exc:
            print(f"error: {exc}", file=sys.stderr)
            status = 1
            continue
        print(_summary(res))
        if args.out:
            out = Path(args.out)
            out.mkdir(parents=True, exist_ok=True)
            np.savez_compressed(out / f"{res.case.name}.npz", t=res.t, y=res.y, Tm=res.Tm,
                                **res.tooth)
    return status


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="pyspline", description=__doc__)
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run case files and print a summary")
    r.add_argument("cases", nargs="+")
    r.add_argument("--out", help="directory for .npz results")
    r.set_defaults(func=cmd_run)
    args = p.parse_args(argv)
    return args.func(args)
