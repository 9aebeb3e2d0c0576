"""Benchmark: 1 s of paper_lx1e-4 with pyspline (CVODE + Fortran RHS) against
scipy.integrate.solve_ivp(LSODA) driven by the numpy oracle RHS (tests/oracle.py: the
"write it yourself with scipy" baseline), at the same rtol, side by side in one run.

Accuracy of both is the max relative error of T_m(t) at the output times against a CVODE
reference at rtol 1e-12 with root finding, itself checked against DOP853 (rtol 1e-12) on the
oracle. Times are medians of repeated runs (wall clock; the machine is noisy, compare ratios).

    python bench/bench_core.py [--rtol 1e-8] [--repeat 5] [--t-end 1.0]
"""
import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
import oracle  # noqa: E402
import pyspline  # noqa: E402


def median_time(fn, repeat):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def scipy_run(case, method, rtol, t_eval):
    p = oracle.prepare(dict(case))
    y0 = pyspline.start_state(case)
    info = pyspline.load(case).info()                 # the core's Eq. 25 scales
    l, w = info["l_ref"], info["w_ref"]
    atol = case["atol"] * np.r_[np.full(7, l), np.full(7, l * w)]   # the same scaled atol
    sol = solve_ivp(lambda t, y: oracle.rhs(t, y, p), (case["t0"], case["t_end"]), y0,
                    method=method, rtol=rtol, atol=atol, t_eval=t_eval)
    if not sol.success:
        raise RuntimeError(f"solve_ivp {method}: {sol.message}")
    tm = np.array([oracle.mesh(t, y, p)["Tm"] for t, y in zip(sol.t, sol.y.T)])
    return tm, sol.nfev


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--t-end", type=float, default=1.0)
    args = ap.parse_args(argv)

    case = pyspline.load_case(ROOT / "cases" / "paper_lx1e-4.nml", t_end=args.t_end,
                              n_out=int(round(640 * args.t_end)) + 1,
                              linear_tail=False)      # the integrator itself is measured
    ref = pyspline.simulate(case.replace(rtol=1e-12, atol=1e-14, roots=True))
    ref2, _ = scipy_run(case, "DOP853", 1e-12, ref.t)
    scale = np.abs(ref.Tm).max()
    print(f"reference CVODE rtol 1e-12 + roots vs DOP853 rtol 1e-12 (oracle): "
          f"max rel diff of T_m {np.abs(ref.Tm - ref2).max() / scale:.2e}")

    rows = []
    for rtol in (args.rtol, args.rtol / 10):
        for method in ("adams", "bdf"):
            c = case.replace(rtol=rtol, atol=rtol * 1e-2, method=method)
            t, res = median_time(lambda: pyspline.simulate(c), args.repeat)
            rows.append((f"pyspline CVODE {method} (Fortran RHS)", rtol, t,
                         res.stats["rhs_evals"], np.abs(res.Tm - ref.Tm).max() / scale))
        c = case.replace(rtol=rtol, atol=rtol * 1e-2)
        t, (tm, nfev) = median_time(lambda: scipy_run(c, "LSODA", rtol, ref.t),
                                    max(1, args.repeat // 2))
        rows.append(("scipy LSODA (numpy oracle RHS)", rtol, t, nfev,
                      np.abs(tm - ref.Tm).max() / scale))
    print(f"{'solver':36s} {'rtol':>7s} {'time [s]':>9s} {'RHS evals':>10s} {'max rel err T_m':>16s}")
    for name, rtol, t, n, e in rows:
        print(f"{name:36s} {rtol:7.0e} {t:9.4f} {n:10d} {e:16.2e}")
    print()
    for rtol in (args.rtol, args.rtol / 10):
        lsoda = next(r for r in rows if r[1] == rtol and "LSODA" in r[0])
        best = min((r for r in rows if r[1] == rtol and "CVODE" in r[0]), key=lambda r: r[2])
        print(f"same rtol {rtol:.0e}: {best[0]} is {lsoda[2] / best[2]:.1f}x faster than LSODA; "
              f"error {best[4]:.1e} vs {lsoda[4]:.1e} "
              f"({'equal or better' if best[4] <= lsoda[4] else 'worse'})")
    for lsoda in (r for r in rows if "LSODA" in r[0]):
        ok = [r for r in rows if "CVODE" in r[0] and r[4] <= lsoda[4]]
        if ok:
            best = min(ok, key=lambda r: r[2])
            print(f"matched accuracy (error <= LSODA's {lsoda[4]:.1e} at rtol {lsoda[1]:.0e}): "
                  f"{best[0]} at rtol {best[1]:.0e} is {lsoda[2] / best[2]:.1f}x faster")


if __name__ == "__main__":
    main()
