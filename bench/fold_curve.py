"""docs/fold_curve.png and the cost of pyspline.fold_curve (docs/continuation.md): the Z16
drive of tests/test_cont_drives.py (n_out 1001) in speed and the order-1 ripple amplitude a,
by the extended system (default) and, with --repeated, by a continuation per value of a.
CPU seconds of the fold part and of the check sweeps are printed; --graze-curves: the grazing
nearest each fold followed in a too (both calls), each curve's extent and end printed.

    python -P bench/fold_curve.py [--repeated] [--no-check] [--graze-curves] [--unbounded]
        [--png docs/fold_curve.png]
"""
import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import numpy as np                                  # noqa: E402

import pyspline                                     # noqa: E402
from pyspline.plots import fold_plane               # noqa: E402
from test_cont_drives import DRIVE                  # noqa: E402

AMPS = [0.25, 0.22, 0.2, 0.18, 0.15, 0.13, 0.12, 0.11, 0.1, 0.095, 0.09, 0.088, 0.085, 0.08]
CHECK = [0.25, 0.15, 0.1, 0.085]

ap = argparse.ArgumentParser()
ap.add_argument("--repeated", action="store_true")
ap.add_argument("--no-check", action="store_true")
ap.add_argument("--png")
ap.add_argument("--graze-curves", action="store_true")
ap.add_argument("--unbounded", action="store_true", help="max_seconds = inf (both calls)")
args = ap.parse_args()
drive = DRIVE.replace(n_out=1001)
t, w = time.process_time(), time.perf_counter()
fc = pyspline.fold_curve(drive, "speed_rpm", 2300, 2700, "ripple_amp(1)", AMPS, max_points=400,
                         method="repeated" if args.repeated else "extended", progress=False,
                         max_seconds=np.inf if args.unbounded else 300.0,
                         graze_curves=args.graze_curves)
print(f"fold part: {time.process_time() - t:.1f} s CPU, {time.perf_counter() - w:.1f} s wall")
for a, f, g in zip(AMPS, fc.fold.values, fc.get("fold_grazing", fc.fold * np.nan).values):
    print(f"a = {a:g}: folds {np.round(f[np.isfinite(f)], 3)}, the grazing nearest each "
          f"{np.round(g[np.isfinite(f)], 3)}")
print("status:", fc.attrs["status"])
print("cusp:", fc.attrs.get("cusp"), "\ncurves:", fc.attrs.get("curve_status"))
if args.graze_curves:
    for i, why in enumerate(fc.graze_curve_status.values):
        on = fc.graze_curve.values == i
        x, a = fc.graze_curve_field.values[on], fc.graze_curve_field2.values[on]
        print(f"grazing curve {i}: {on.sum()} points, a {a.min():g}-{a.max():g}, speed "
              f"{x.min():.3f}-{x.max():.3f}: {why}")
if not args.no_check:
    t, w = time.process_time(), time.perf_counter()
    fc = pyspline.fold_curve(drive, "speed_rpm", 2300, 2700, "ripple_amp(1)", AMPS,
                             max_points=400, check=CHECK, check_points=41,
                             check_case=drive.replace(t_end=2.0, t_transient=1.0, n_out=8001),
                             method="repeated" if args.repeated else "extended",
                             progress=False, max_seconds=np.inf if args.unbounded else 300.0,
                             graze_curves=args.graze_curves)
    print(f"with the check sweeps: {time.process_time() - t:.1f} s CPU, "
          f"{time.perf_counter() - w:.1f} s wall")
if args.png:
    fold_plane(fc, path=args.png)
