"""Benchmarks of pyspline (not installed with the package): run from a checkout,
    python bench/run.py wp|race|stability|ladder|anatomy|parallel|bifurcation|continuation
                        [--out DIR] [--quick]
wp: work-precision chart against scipy and numbalsoda peers; race: issue 25's table against the
numba peer (bench/race.py); stability: where methods fail;
ladder: model levels and fidelity = auto; anatomy: where a run's time goes; parallel: scenes
serially, on threads and on processes, fixed cost per call, RHS call cost; bifurcation: a
1000-point sweep serially, on threads, processes and Dask; continuation: continuation of
periodic orbits with the exact monodromy against central differences (bench/continuation.py).
Each writes a PNG and/or CSV into --out (default out/bench) and prints a table."""
from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))


def cmd_bench(args) -> int:
    import speed as bench
    from pyspline.core import cvode_library
    out = Path(args.out)
    lib = cvode_library()
    print(f"CVODE library: {lib}")
    if lib.endswith("(debian)"):
        print("note: Debian's SUNDIALS is compiled without optimisation; runs take up to 2.4x "
              "longer than on the optimised build that scripts/setup.sh makes")
    if args.what == "wp":
        rows, notes = bench.work_precision(out, quick=args.quick, cases=args.cases)
        for n in notes:
            print(n)
        print(f"{'case':14s} {'method':30s} {'rtol':>7s} {'time [s]':>9s} {'RHS':>8s} "
              f"{'err':>9s} {'scd':>5s}  status")
        for r in rows:
            err = max(r["err_Tm"], r["err_F"])
            print(f"{r['case']:14s} {r['method']:30s} {r['rtol']:7.0e} {r['time_s']:9.4f} "
                  f"{r['rhs_evals']:8d} {err:9.1e} {r['scd']:5.1f}  {r['status']}")
        for r in bench.speed_ratios(rows):
            if r["ratio"] is None:
                print(f"{r['case']}: at error <= {r['accuracy']:g} no {r['peer_rhs']}-RHS peer "
                      f"(or no CVODE run) reached it")
            else:
                print(f"{r['case']}: at error <= {r['accuracy']:g}, {r['cvode']} (rtol "
                      f"{r['cvode_rtol']:g}) {r['cvode_s']:.4f} s vs {r['peer']} (rtol "
                      f"{r['peer_rtol']:g}) {r['peer_s']:.4f} s: {r['ratio']:.1f}x")
        print(f"wrote {out}/work_precision.png, work_precision.csv and speed_ratios.csv")
    elif args.what == "ladder":
        import ladder
        rows = ladder.ladder(out, quick=args.quick)
        print("\n".join(ladder.format_rows(rows)))
        missed = [r for r in rows if r.get("within_tol") is False]
        print(f"auto: {sum('picked' in r for r in rows) - len(missed)} of "
              f"{sum('picked' in r for r in rows)} picks within tolerance")
        print(f"wrote {out}/ladder.png and ladder.csv")
        return 1 if missed else 0
    elif args.what == "anatomy":
        import anatomy
        rows = anatomy.anatomy(out, quick=args.quick)
        print("\n".join(anatomy.format_rows(rows)))
        print(f"wrote {out}/anatomy.png and anatomy.csv")
        from pyspline import load_case
        from pyspline.paper import cases_dir
        case = load_case(cases_dir() / "paper_lx1e-4.nml")
        if args.quick:
            case = case.replace(t_end=0.1, n_out=641)
        cost = anatomy.output_cost(case, repeat=5 if args.quick else 15)
        print(anatomy.format_output_cost(case.name, case, cost))
        cost = anatomy.output_cost(case, repeat=5 if args.quick else 15, clock=time.process_time)
        print(anatomy.format_output_cost(case.name, case, cost, ", CPU time"))
    else:
        rows = bench.stability_map(out, quick=args.quick)
        for r in rows:
            print(f"{r['damping']:12s} k_m {r['k_m']:8.1e} {r['method']:24s} "
                  f"{r['time_s']:8.3f} s  {r.get('rhs_evals', -1):>8}  {r['status']}")
        print(f"wrote {out}/stability.png and stability.csv")
    return 0



def main(argv=None) -> int:
    # the benchmarks run CVODE with roots over loose tolerances on purpose: its restart warning
    # (spline_run::restart_warning) would print once per run, with each run's count of switches
    warnings.filterwarnings("ignore", message=r"case .* CVODE restarts at order 1")
    p = argparse.ArgumentParser(prog="bench/run.py", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("what", choices=["wp", "race", "stability", "ladder", "anatomy", "parallel",
                                    "bifurcation", "continuation"])
    p.add_argument("--points", type=int, help="bifurcation: number of points (default 1000)")
    p.add_argument("--cases", nargs="+", help="wp, race: the scenes (default: paper_lx1e-4 paper_T100 "
                   "rattle_z24 physical_z24; --quick: the two paper scenes)")
    p.add_argument("--rtol", type=float, help="bifurcation: tolerance (default: the case's)")
    p.add_argument("--repeats", type=int, help="continuation: interleaved runs per monodromy "
                   "(default 3, --quick 1); race: timed rounds (default 5, --quick 2); bifurcation: run the whole sweep this many "
                   "times per executor, in rotating order; medians and ranges (default 1)")
    p.add_argument("--blocks", type=int, help="bifurcation: run the sweep as this many "
                   "interleaved blocks, the executors in rotating order (default 1: each "
                   "executor runs the whole sweep once, one after the other)")
    p.add_argument("--scaling", action="store_true", help="bifurcation: also run each parallel "
                   "executor with one worker (speed-up from 1 to 2 workers)")
    p.add_argument("--host", action="store_true", help="bifurcation: the host's own 2-way "
                   "speed-up, from runs of the standalone executable one and two at a time")
    p.add_argument("--accuracy", action="store_true", help="bifurcation: the diagram's section "
                   "error, periods, steps and wall time over rtol (every 10th point)")
    p.add_argument("--figure", action="store_true", help="bifurcation: the diagram only "
                   "(bifurcation.png, its sweep on 2 threads; no timing)")
    from speed import PYSPLINE_VARIANTS
    p.add_argument("--variants", nargs="+", choices=PYSPLINE_VARIANTS, help="race: only these "
                   "of pyspline's setting families (default: all; the accuracy and goal settings "
                   "always run)")
    p.add_argument("--no-tail", action="store_true", help="race: no closed-form tail on either "
                   "side (pyspline's linear_tail = .false., the peer without bench/peer_tail.py)")
    p.add_argument("--growth", action="store_true", help="race: only what outputs cost, the "
                   "time of paper_lx1e-4 with 6401 outputs less that with 101, both sides (race."
                   "output_growth)")
    p.add_argument("--out", default="out/bench", help="output directory (default out/bench)")
    p.add_argument("--quick", action="store_true", help="small sizes (for CI)")
    args = p.parse_args(argv)
    if args.what == "race":
        import race
        from speed import build
        print(f"race of {build()}; {race.load()}", flush=True)
        if args.growth:
            print(race.output_growth(repeat=args.repeats or (2 if args.quick else 7)))
            print(f"{race.load()} (at the end)")
            return 0
        rows, runs = race.race(quick=args.quick, repeat=args.repeats or (2 if args.quick else 5),
                               cases=args.cases, variants=args.variants, tail=not args.no_tail,
                               progress=lambda m: print(m, flush=True))
        print(f"{race.load()} (at the end)")
        print("\n".join(race.format_rows(rows)))
        from speed import _write_csv
        Path(args.out).mkdir(parents=True, exist_ok=True)
        _write_csv(Path(args.out) / "race.csv", [
            {k: (" ".join(f"{x:.6g}" if isinstance(x, float) else str(x) for x in v)
                 if isinstance(v, list) else v)
             for k, v in r.items()} for r in runs])
        print(f"wrote {args.out}/race.csv")
        return 0
    if args.what == "parallel":
        import parallel
        return parallel.main(args)
    if args.what == "bifurcation":
        import bifurcation
        return bifurcation.main(args)
    if args.what == "continuation":
        import continuation
        return continuation.main(args)
    return cmd_bench(args)


if __name__ == "__main__":
    sys.exit(main())
