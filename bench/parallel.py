"""Scenes in parallel and the fixed costs of a call (issue 10's benchmark), measured side by
side in one run: `python bench/run.py parallel [--quick]`.

- 8 runs of paper_lx1e-4 (1 s simulated each): serially, on 2 threads, on 2 processes;
- simulate's fixed cost per call: a case with t_end tiny, both for a loaded model and for a
  fresh Case (which includes loading: the fields handed to the core as values, Eq. 18);
- loading a shipped case file with its model built, `load_case(path).model` (one core call:
  check, read, parse, validate, build): the median of single calls;
- one RHS call from Python through a loaded model (api_rhs).
Medians of `repeat` repetitions; writes parallel.csv into --out.
"""
from __future__ import annotations

import concurrent.futures as cf
import os
import statistics
import time
from pathlib import Path

import numpy as np

import pyspline
from pyspline.paper import cases_dir
from speed import _write_csv, build


def _wall(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _median_call(fn, k):
    """The median time of k single calls of fn (a load is too short to time in a batch: the
    median drops the calls another process interrupted)."""
    fn()
    times = []
    for _ in range(k):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _run(case):
    return pyspline.simulate(case).stats["steps"]


def measure(quick=False):
    case = pyspline.load_case(cases_dir() / "paper_lx1e-4.nml", linear_tail=False)  # CVODE runs
    if quick:
        case = case.replace(t_end=0.1, n_out=641)
    n, repeat = 8, (1 if quick else 3)
    case.model
    rows = []
    serial = _wall(lambda: [_run(case) for _ in range(n)], repeat)
    rows.append(dict(what=f"{n} runs serially", seconds=serial, ratio=1.0))
    with cf.ThreadPoolExecutor(2) as pool:
        list(pool.map(_run, [case] * 2))                       # warm the threads
        th = _wall(lambda: list(pool.map(_run, [case] * n)), repeat)
    rows.append(dict(what=f"{n} runs on 2 threads", seconds=th, ratio=serial / th))
    with cf.ProcessPoolExecutor(2) as pool:
        list(pool.map(_run, [case] * 2))                       # start the workers
        pr = _wall(lambda: list(pool.map(_run, [case] * n)), repeat)
    rows.append(dict(what=f"{n} runs on 2 processes", seconds=pr, ratio=serial / pr))

    tiny = case.replace(t_end=case["t0"] + 1e-6, n_out=2, name="tiny")
    k = 200 if quick else 2000
    loaded = tiny.model
    pyspline.simulate(loaded)
    fixed = _wall(lambda: [pyspline.simulate(loaded) for _ in range(k)], 3) / k
    rows.append(dict(what="simulate, fixed cost per call (loaded model)", seconds=fixed,
                     ratio=float("nan")))
    fresh = [tiny.replace(l_x=1e-4 * (1 + i / k)) for i in range(k)]
    t0 = time.perf_counter()
    for c in fresh:
        pyspline.simulate(c)
    rows.append(dict(what="simulate, fixed cost per call (new Case: load + run)",
                     seconds=(time.perf_counter() - t0) / k, ratio=float("nan")))
    for name in ("paper_lx1e-4.nml", "physical_z24.nml"):
        path = cases_dir() / name
        per = _median_call(lambda: pyspline.load_case(path).model, 200 if quick else 2000)
        rows.append(dict(what=f"load_case(path).model, {name} (median)", seconds=per,
                         ratio=float("nan")))
    y = loaded.start_state()
    m = 20_000 if quick else 200_000
    rhs = loaded.rhs
    per = _wall(lambda: [rhs(1e-3, y) for _ in range(m)], 3) / m
    rows.append(dict(what="one RHS call from Python (loaded model)", seconds=per,
                     ratio=float("nan")))
    return rows


def main(args) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"{build()}, {os.cpu_count()} cores, CVODE {pyspline.core.cvode_library()}")
    rows = measure(args.quick)
    for r in rows:
        sec = r["seconds"]
        val = f"{sec:9.3f} s" if sec > 1e-2 else f"{sec * 1e6:9.2f} us"
        ratio = "" if np.isnan(r["ratio"]) else f"  speed-up {r['ratio']:.2f}x"
        print(f"{r['what']:55s} {val}{ratio}")
    _write_csv(out / "parallel.csv", rows)
    print(f"wrote {out}/parallel.csv")
    return 0
