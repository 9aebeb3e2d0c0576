"""A bifurcation diagram of paper_lx1e-4 over l_x (issue 11's benchmark), measured side by side
in one run: `python bench/run.py bifurcation [--points N] [--rtol R] [--quick]`.

Each point: 20 shaft revolutions of transient, then 100 revolutions sampled (exact shaft
sections, 8 outputs per revolution for the load statistics). The same sweep runs serially, on 2
threads, on 2 processes and on a Dask LocalCluster of 2 workers (pyspline.local_dask_client:
threads in one process, its default, then processes); the wall time of each and its speed-up
over serial are printed and written to bifurcation.csv, with the figure of the
last run. The case's own tolerance (rtol 1e-9, Adams) unless --rtol is given.
"""
from __future__ import annotations

import concurrent.futures as cf
import os
import subprocess
import time
from pathlib import Path

import numpy as np

import pyspline
from pyspline.paper import cases_dir
from speed import _write_csv


def _warm_up_n(_):
    _warm_up()


def _warm_up():
    """Import pyspline and load a case in a fresh worker process (start-up, not the sweep)."""
    pyspline.sweep(bench_case(), progress=False, l_x=[0.0])


def bench_case(rtol=None):
    case = pyspline.load_case(cases_dir() / "paper_lx1e-4.nml")
    T = 60.0 / case["speed_rpm"]
    kw = dict(t0=0.0, t_transient=20 * T, t_end=120 * T, n_out=100 * 8 + 1)
    if rtol:
        kw.update(rtol=rtol, atol=rtol * 1e-2)
    return case.replace(**kw)


def main(args) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    n = args.points or (40 if args.quick else 1000)
    case = bench_case(args.rtol)
    l_x = np.linspace(0.0, 3e-4, n)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True, cwd=Path(__file__).parent).stdout.strip()
    print(f"commit {commit}, {os.cpu_count()} cores; {n} points of paper_lx1e-4 over l_x, "
          f"120 revolutions each (20 transient), rtol {case['rtol']:g}")
    rows = []

    def timed(label, executor):
        t0 = time.perf_counter()
        ds = pyspline.sweep(case, executor=executor, progress=False, l_x=l_x)
        wall = time.perf_counter() - t0
        bad = int(ds.attrs.get("n_failed", 0))
        rows.append(dict(executor=label, points=n, wall_s=wall, failed=bad))
        print(f"{label:32s} {wall:8.2f} s  speed-up {rows[0]['wall_s'] / wall:5.2f}x"
              f"{f'  ({bad} failed points)' if bad else ''}", flush=True)
        return ds

    pyspline.sweep(case, progress=False, l_x=l_x[:2])            # imports, first load
    ds = timed("serial", None)
    with cf.ThreadPoolExecutor(2) as ex:
        timed("2 threads", ex)
    with cf.ProcessPoolExecutor(2) as ex:
        list(ex.map(_warm_up_n, range(2)))                       # start the workers
        timed("2 processes", ex)
    # Dask: pyspline.local_dask_client, a LocalCluster set up for sweeps (DASK_SWEEP_CONFIG);
    # its default layout, 2 worker threads in this process, then 2 worker processes
    for processes, label in ((False, "Dask LocalCluster, 2 workers"),
                             (True, "Dask LocalCluster, 2 worker procs")):
        with pyspline.local_dask_client(2, processes=processes) as client:
            client.run(_warm_up)          # import pyspline in the workers (as the pools above)
            timed(label, client.get_executor())
    _write_csv(out / "bifurcation.csv", rows)
    from pyspline import plots
    plots.bifurcation(ds, "l_x", path=out / "bifurcation.png")
    periods = ds["period"].values
    print(f"periods: {dict(zip(*np.unique(periods[np.isfinite(periods)], return_counts=True)))}")
    print(f"wrote {out}/bifurcation.csv and bifurcation.png")
    return 0
