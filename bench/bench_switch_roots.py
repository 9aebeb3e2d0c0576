"""What locating the contact switches costs and buys, on paper_T100 (coupled flash temperature):
CVODE with and without root finding, at several tolerances, against a reference with root
finding at rtol 1e-11.

    python bench/bench_switch_roots.py [--t-end 0.3] [--repeat 3]
"""
import argparse
import statistics
import time
from pathlib import Path

import numpy as np

import pyspline

ROOT = Path(__file__).resolve().parent.parent


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=0.3)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    case = pyspline.load_case(ROOT / "cases" / "paper_T100.nml", t_end=args.t_end,
                              n_out=int(6400 * args.t_end) + 1)
    ref = pyspline.simulate(case.replace(method="bdf", roots=True, rtol=1e-11, atol=1e-13))
    sc_tm, sc_tf = np.abs(ref.Tm).max(), ref.Tf.max()
    print(f"paper_T100, {args.t_end} s, reference: BDF + roots, rtol 1e-11 "
          f"({ref.stats['roots_found']} switches located)")
    print(f"{'method':6s} {'roots':>5s} {'rtol':>6s} {'time [s]':>9s} {'steps':>8s} "
          f"{'switches':>8s} {'err T_m':>9s} {'err T_f':>9s}")
    for method in ("adams", "bdf"):
        for rtol in (1e-6, 1e-8):
            for roots in (False, True):
                c = case.replace(method=method, roots=roots, rtol=rtol, atol=rtol * 1e-2)
                times = []
                for _ in range(args.repeat):
                    t0 = time.perf_counter()
                    r = pyspline.simulate(c)
                    times.append(time.perf_counter() - t0)
                print(f"{method:6s} {str(roots):>5s} {rtol:6.0e} {statistics.median(times):9.3f} "
                      f"{r.stats['steps']:8d} {r.stats['roots_found']:8d} "
                      f"{np.abs(r.Tm - ref.Tm).max() / sc_tm:9.1e} "
                      f"{np.abs(r.Tf - ref.Tf).max() / sc_tf:9.1e}")


if __name__ == "__main__":
    main()
