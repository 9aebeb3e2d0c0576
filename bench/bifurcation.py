"""A bifurcation diagram of paper_lx1e-4 over l_x (issue 11's benchmark), measured side by side
in one run: `python bench/run.py bifurcation [--points N] [--rtol R] [--blocks K] [--quick]`.

Each point: 20 shaft revolutions of transient, then 100 revolutions sampled (exact shaft
sections, 8 outputs per revolution for the load statistics). The same sweep runs serially, on 2
threads, on 2 processes and on a Dask LocalCluster of 2 workers (pyspline.local_dask_client:
threads in one process, its default, then processes); the wall time of each and its speed-up
over serial are printed and written to bifurcation.csv, with the figure of the serial run. The
case's own tolerance (rtol 1e-9, Adams) unless --rtol is given.

With --blocks K the sweep is cut into K interleaved subsets (l_x[b::K]); every executor runs
each subset, in an order that rotates from subset to subset, and its times are summed. On a
machine whose speed drifts (a shared host: the same serial sweep took 35-42 s within an hour),
the executors then share the drift, and the ratios mean something; the per-block speed-ups show
the spread that remains.
"""
from __future__ import annotations

import concurrent.futures as cf
import contextlib
import os
import subprocess
import time
from pathlib import Path

import numpy as np

import pyspline
from pyspline.sweep import _chunk_size
from pyspline.paper import cases_dir
from speed import _write_csv


def _warm_up_n(_):
    _warm_up()


def _warm_up():
    """Import pyspline and load a case in a fresh worker process (start-up, not the sweep)."""
    pyspline.sweep(bench_case(), progress=False, l_x=[0.0])


def _start(label, stack):
    """The executor named `label`, started and warmed up (pyspline imported in its workers), its
    shutdown registered on `stack`. Dask through pyspline.local_dask_client (DASK_SWEEP_CONFIG):
    its default layout, worker threads in this process, and worker processes."""
    if label == "serial":
        return None
    if label == "2 threads":
        return stack.enter_context(cf.ThreadPoolExecutor(2))
    if label == "2 processes":
        pool = stack.enter_context(cf.ProcessPoolExecutor(2))
        list(pool.map(_warm_up_n, range(2)))                     # start the workers
        return pool
    client = stack.enter_context(pyspline.local_dask_client(2, processes="procs" in label))
    client.run(_warm_up)
    return client.get_executor()


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
    blocks = max(1, args.blocks or 1)
    case = bench_case(args.rtol)
    l_x = np.linspace(0.0, 3e-4, n)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True, cwd=Path(__file__).parent).stdout.strip()
    print(f"commit {commit}, {os.cpu_count()} cores; {n} points of paper_lx1e-4 over l_x, "
          f"120 revolutions each (20 transient), rtol {case['rtol']:g}"
          + (f"; {blocks} interleaved blocks" if blocks > 1 else ""))
    pyspline.sweep(case, progress=False, l_x=l_x[:2])            # imports, first load
    labels = ["serial", "2 threads", "2 processes", "Dask LocalCluster, 2 workers",
              "Dask LocalCluster, 2 worker procs"]
    wall = {label: [] for label in labels}
    failed = dict.fromkeys(labels, 0)
    ds = None
    # blocks > 1: every executor runs the same interleaved subsets l_x[b::blocks], in an order
    # that rotates from block to block, so that a machine whose speed drifts during the
    # benchmark slows all of them alike (chunks as for the whole sweep); the executors then stay
    # up together. blocks = 1: each executor exists only for its own run (an idle Dask cluster
    # costs 0.05-0.07 s of CPU a second, measured).
    with contextlib.ExitStack() as keep:
        started = {}
        if blocks > 1:
            started = {label: _start(label, keep) for label in labels}
        for b in range(blocks):
            values = l_x[b::blocks]
            for label in labels[b % len(labels):] + labels[:b % len(labels)]:
                with contextlib.ExitStack() as this_run:
                    ex = started[label] if blocks > 1 else _start(label, this_run)
                    t0 = time.perf_counter()
                    part = pyspline.sweep(case, executor=ex, progress=False, l_x=values,
                                          chunk=_chunk_size(ex, n))
                    wall[label].append(time.perf_counter() - t0)
                failed[label] += int(part.attrs.get("n_failed", 0))
                if blocks == 1:
                    ds = part if label == "serial" else ds
                    print(f"{label:34s} {wall[label][0]:8.2f} s  speed-up "
                          f"{wall['serial'][0] / wall[label][0]:5.2f}x", flush=True)
    rows = []
    for label in labels:
        total = sum(wall[label])
        ratio = [s_ / w for s_, w in zip(wall["serial"], wall[label])]
        rows.append(dict(executor=label, points=n, blocks=blocks, wall_s=total,
                         speed_up=sum(wall["serial"]) / total,
                         block_speed_up_min=min(ratio), block_speed_up_median=float(
                             np.median(ratio)), block_speed_up_max=max(ratio),
                         failed=failed[label]))
    if blocks > 1:
        print(f"{'executor':34s} {'wall':>8s}   {'speed-up':>8s}   per block: min / median / max")
        for r in rows:
            print(f"{r['executor']:34s} {r['wall_s']:8.2f} s {r['speed_up']:8.2f}x   "
                  f"{r['block_speed_up_min']:.2f} / {r['block_speed_up_median']:.2f} / "
                  f"{r['block_speed_up_max']:.2f}", flush=True)
    if any(failed.values()):
        print(f"failed points: {failed}")
    _write_csv(out / "bifurcation.csv", rows)
    if ds is not None:              # the figure of the serial sweep (one block only)
        from pyspline import plots
        plots.bifurcation(ds, "l_x", path=out / "bifurcation.png")
        periods = ds["period"].values
        print(f"periods: {dict(zip(*np.unique(periods[np.isfinite(periods)], return_counts=True)))}")
        print(f"wrote {out}/bifurcation.csv and bifurcation.png")
    else:
        print(f"wrote {out}/bifurcation.csv")
    return 0
