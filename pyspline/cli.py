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
            f"{res.level}  "
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


def cmd_reproduce(args) -> int:
    from .paper import reproduce
    s = reproduce(args.out, quick=args.quick, directory=args.cases)
    out = Path(args.out)
    print((out / "verification.md").read_text())
    print(f"figures: {', '.join(s['figures'])} in {out}/")
    print(f"executable check (spline-dyn vs Python): {s['executable_check']}")
    print(f"k_m: calibrated {s['k_m']['calibrated']:.4g} N/m, potential energy "
          f"{s['k_m']['potential_energy']:.4g} N/m (ratio {s['k_m']['ratio']:.0f})")
    print(f"Poincare distinct points: {s['poincare_distinct_points']}")
    print(f"simulation time {s['run_time_s']:.1f} s; summary.json, verification.csv in {out}/")
    return 0


def cmd_calibrate(args) -> int:
    from .paper import ROWS, calibrate, cases_dir, sensitivities, write_calibration
    directory = cases_dir(args.cases)
    fit = calibrate(directory, quick=args.quick)
    print(f"fitted k_m = {fit['k_m']:.6g} N/m to max|D2| = {ROWS[0].paper:g} m of {ROWS[0].case}")
    print(f"fitted f_m = {fit['f_m']:.6g} to max T_f = {ROWS[1].paper:g} degC of {ROWS[1].case}")
    print(f"potential-energy k_m = {fit['k_m_potential_energy']:.4g} N/m: "
          f"{fit['k_m_potential_energy'] / fit['k_m']:.0f} times the fitted value")
    if fit["f_m"] > 1:
        print(f"warning: f_m = {fit['f_m']:.3g} is no friction coefficient: the paper's flash "
              "temperatures are far above what Eqs. 3-7 give (see README)")
    sens = sensitivities(directory, quick=args.quick, fitted=fit)
    print("\nsensitivity d ln(value) / d ln(unknown) of every row:")
    print(f"{'case/quantity':78s} {'k_m':>8s} {'f_m':>8s} {'m_1=m_2':>8s}")
    for key, d in sens.items():
        print(f"{key[:78]:78s} " + " ".join(f"{d[p]:8.3f}" for p in ("k_m", "f_m", "m_1=m_2")))
    if args.write:
        changed = write_calibration(directory, fit)
        print(f"\nwrote k_m (and f_m where present) into {len(changed)} case files in {directory}")
    else:
        print("\n(dry run: --write puts the fitted values into the paper cases)")
    return 0


def cmd_check_exe(args) -> int:
    from .paper import ALL_CASES, cases_dir, check_executable
    rep = check_executable(cases_dir(args.cases), ALL_CASES, quick=not args.full)
    for k, v in rep.items():
        print(f"{k:24s} {v}")
    return 0 if all(v == "identical" for v in rep.values()) else 1


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="pyspline", description=__doc__)
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run case files and print a summary")
    r.add_argument("cases", nargs="+")
    r.add_argument("--out", help="directory for .npz results")
    r.set_defaults(func=cmd_run)
    r = sub.add_parser("reproduce", help="run the paper's scenarios: figures, verification "
                       "table, summary.json")
    r.add_argument("--out", default="out", help="output directory (default: out)")
    r.add_argument("--quick", action="store_true", help="0.3 s per case (for CI)")
    r.add_argument("--cases", help="case directory (default: ./cases or the installed copies)")
    r.set_defaults(func=cmd_reproduce)
    r = sub.add_parser("calibrate", help="fit k_m and f_m to the paper's values")
    r.add_argument("--quick", action="store_true")
    r.add_argument("--write", action="store_true", help="write the fitted values into the cases")
    r.add_argument("--cases")
    r.set_defaults(func=cmd_calibrate)
    r = sub.add_parser("check-exe", help="run the paper cases through spline-dyn and compare "
                       "with Python, number for number")
    r.add_argument("--full", action="store_true", help="full length (default: 0.3 s)")
    r.add_argument("--cases")
    r.set_defaults(func=cmd_check_exe)
    args = p.parse_args(argv)
    return args.func(args)
