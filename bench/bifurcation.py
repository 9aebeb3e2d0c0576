"""A bifurcation diagram of paper_lx1e-4 over l_x (issue 11's benchmark), measured side by side
in one run: `python bench/run.py bifurcation [--points N] [--rtol R] [--repeats R] [--blocks K]
[--scaling] [--host] [--accuracy] [--figure] [--quick]`.

Each point: 20 shaft revolutions of transient, then 100 revolutions sampled (exact shaft
sections, 8 outputs per revolution for the load statistics). The same sweep runs serially, on 2
threads, on 2 processes and on a Dask LocalCluster of 2 workers (pyspline.local_dask_client:
worker processes, its default, then worker threads in one process); the wall time of each and
its speed-up over serial are printed and written to bifurcation.csv, with the figure of the
serial run. The case's own tolerance (rtol 1e-9, Adams) unless --rtol is given.

With --repeats R every executor runs the whole sweep R times, in an order that rotates from
repeat to repeat; the median wall time and the median of the speed-ups within each repeat are
printed, with their ranges.

With --blocks K the sweep is cut into K interleaved subsets (l_x[b::K]); every executor runs
each subset, in an order that rotates from subset to subset, and its times are summed; the
executors are started once and stay up together for every block and repeat. On a
machine whose speed drifts (a shared host: the same serial sweep took 35-42 s within an hour),
the executors then share the drift, and the ratios mean something; the per-block speed-ups show
the spread that remains.

With --scaling every parallel executor also runs with one worker, and the speed-up from its 1 to
its 2 workers is printed beside the speed-up over the serial sweep (what the executor itself
costs shows as the difference).

Every executor's row also gives the time its points spent inside the core (Fortran: no GIL, no
messages), summed, over the serial sweep's: how much slower a core computes while the other
core is busy too. On 2 processes this is the host's contention (their main process waits); on
Dask it also holds the time Dask's threads took the core from a run. 2 over it is the speed-up
if every part of a point slowed alike and the executor cost nothing (an estimate of the
host's ceiling; --host measures it).

With --host two more rows take their turns with the executors: in every block, 4 runs of the
standalone executable (cases/chaos_z24.nml: no Python, separate processes, nothing shared) one at
a time, and the same two at a time. Their speed-up is what the host itself gives to two workers:
on a shared virtual machine the two cores need not compute as fast together as one alone, and
then no executor above can beat it.

With --accuracy the question is what tolerance a diagram needs: every 10th point (100 points)
is swept on 2 threads at rtol 1e-5 ... 1e-10 and compared with the same sweep at rtol 1e-11: the
largest error of a section point (D2 at whole revolutions) as a fraction of the diagram's range
of D2, the points whose period differs, the largest relative error of the RMS of T_m, the
steps per point and the wall time (bifurcation_accuracy.csv; the figure charts the error against
the steps, which unlike the wall time do not depend on the host's load).

With --figure only the diagram is drawn (bifurcation.png; no timing, no table), its sweep on 2
threads: `OPENBLAS_NUM_THREADS=1 python bench/run.py bifurcation --figure --out docs` makes
docs/bifurcation.png (14 s of CPU; 41 s wall on 2 cores under a load of 8).
"""
from __future__ import annotations

import concurrent.futures as cf
import contextlib
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

import pyspline
from pyspline.paper import cases_dir
from speed import _write_csv, build


def _warm_up_n(_):
    _warm_up()


def _warm_up():
    """Import pyspline and load a case in a fresh worker process (start-up, not the sweep)."""
    pyspline.sweep(bench_case(), progress=False, l_x=[0.0])


#: The parallel executors, by kind: the label of n workers.
KINDS = {
    "threads": lambda n: f"{n} thread{'s' * (n > 1)}",
    "processes": lambda n: f"{n} process{'es' * (n > 1)}",
    "dask": lambda n: f"Dask LocalCluster, {n} worker proc{'s' * (n > 1)}",
    "dask threads": lambda n: f"Dask LocalCluster, {n} worker thread{'s' * (n > 1)}",
}


def _start(kind, n, stack):
    """The executor of `kind` with `n` workers (kind None: serial; "host": none), started and
    warmed up (pyspline imported in its workers), its shutdown registered on `stack`. Dask
    through pyspline.local_dask_client (DASK_SWEEP_CONFIG): its default layout, worker
    processes, and worker threads in this process."""
    if kind in (None, "host"):
        return None
    if kind == "threads":
        return stack.enter_context(cf.ThreadPoolExecutor(n))
    if kind == "processes":
        pool = stack.enter_context(cf.ProcessPoolExecutor(n))
        list(pool.map(_warm_up_n, range(n)))                     # start the workers
        return pool
    client = stack.enter_context(pyspline.local_dask_client(n, processes=kind == "dask"))
    client.run(_warm_up)
    return client.get_executor()


def bench_case(rtol=None):
    case = pyspline.load_case(cases_dir() / "paper_lx1e-4.nml")
    T = 60.0 / case["speed_rpm"]
    kw = dict(t0=0.0, t_transient=20 * T, t_end=120 * T, n_out=100 * 8 + 1)
    if rtol:
        kw.update(rtol=rtol, atol=rtol * 1e-2)
    return case.replace(**kw)


HOST = ("spline-dyn, 1 at a time", "spline-dyn, 2 at a time")    # --host: (kind "host", 1 | 2)
HOST_RUNS = 4          # runs of the standalone executable per block and width


def host_command(quick: bool = False) -> list[str]:
    """The standalone executable on cases/chaos_z24.nml (about 0.5 s; quick: 0.01 s) for
    --host, with two outputs: the integration, not the CSV's formatting (its 8001 rows of 209
    numbers take about as long as the run)."""
    exe = os.environ.get("SPLINE_DYN") or shutil.which("spline-dyn")
    if not exe:
        raise RuntimeError("--host needs the executable: put spline-dyn on PATH or set SPLINE_DYN")
    cmd = [exe, str(cases_dir() / "chaos_z24.nml"), "--set", "n_out=2"]
    return cmd + (["--set", "t_transient=0", "--set", "t_end=0.02"] if quick else [])


def host_runs(cmd: list[str], runs: int, width: int) -> None:
    """`runs` runs of `cmd`, `width` at a time: separate processes, nothing shared (each its
    own CSV: spline-dyn refuses -o onto a device such as /dev/null)."""
    with tempfile.TemporaryDirectory() as tmp, cf.ThreadPoolExecutor(width) as pool:
        for run in pool.map(lambda i: subprocess.run(cmd + ["-o", f"{tmp}/{i}.csv"],
                                                     capture_output=True, text=True),
                            range(runs)):
            if run.returncode:
                raise RuntimeError(f"{' '.join(cmd)} failed: {run.stderr.strip()}")


ACCURACY_RTOLS = (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
REFERENCE_RTOL = 1e-11


def accuracy(out: Path, n: int) -> list[dict]:
    """The diagram's error, steps and wall time per rtol (the module docstring's --accuracy)."""
    l_x = np.linspace(0.0, 3e-4, n)[::10]
    rows, ref = [], None
    with cf.ThreadPoolExecutor(2) as ex:
        pyspline.sweep(bench_case(), executor=ex, progress=False, l_x=l_x[:2])
        for rtol in (REFERENCE_RTOL,) + ACCURACY_RTOLS[::-1]:
            t0 = time.perf_counter()
            ds = pyspline.sweep(bench_case(rtol), executor=ex, progress=False, l_x=l_x)
            wall = time.perf_counter() - t0
            if int(ds.attrs.get("n_failed", 0)):
                raise RuntimeError(f"rtol {rtol:g}: {ds.attrs['n_failed']} points failed")
            if ref is None:
                ref = ds
                continue
            d2, d2_ref = ds["section_D2"].values, ref["section_D2"].values
            span = np.nanmax(d2_ref) - np.nanmin(d2_ref)
            rows.append(dict(
                rtol=rtol, points=len(l_x), wall_s=wall,
                section_error_of_range=float(np.nanmax(np.abs(d2 - d2_ref)) / span),
                period_differs=int((ds["period"].values != ref["period"].values).sum()),
                periods=" ".join(f"{int(k)}:{int(c)}" for k, c in zip(
                    *np.unique(ds["period"].values, return_counts=True))),
                tm_rms_rel_error=float(np.max(np.abs(ds["Tm_rms"].values / ref["Tm_rms"].values
                                                     - 1))),
                steps_per_point=float(ds["steps"].values.mean())))
            print(f"rtol {rtol:7.0e}: {wall:6.2f} s for {len(l_x)} points on 2 threads, section "
                  f"error {rows[-1]['section_error_of_range']:.1e} of the range, period differs "
                  f"at {rows[-1]['period_differs']} points, T_m RMS error "
                  f"{rows[-1]['tm_rms_rel_error']:.1e}", flush=True)
    _write_csv(out / "bifurcation_accuracy.csv", rows)
    _plot_accuracy(rows, out / "bifurcation_accuracy.png")
    return rows


def _plot_accuracy(rows, path=None):
    from matplotlib.figure import Figure
    from pyspline.plots import style as ps
    fig = Figure(figsize=(6, 4.3), layout="constrained")
    ax = fig.subplots()
    x = [r["steps_per_point"] for r in rows]       # the cost without the host's noise
    y = [r["section_error_of_range"] for r in rows]
    ax.loglog(x, y, "o-", label="every period as at the reference")
    odd = [k for k, r in enumerate(rows) if r["period_differs"]]
    ax.loglog([x[k] for k in odd], [y[k] for k in odd], "o", color="C3",
              label="periods differ from the reference")
    for r, xi, yi in zip(rows, x, y):
        ax.annotate(f"{r['rtol']:g}", (xi, yi), textcoords="offset points", xytext=(5, 4),
                    fontsize=8)
    ax.axhline(1e-3, color="0.6", lw=0.8, ls="--", label="1/1000 of the range")
    ax.set_ylim(top=max(1e-2, 3 * max(y)))      # room above each point for its rtol
    ax.legend(fontsize=8)
    ax.set_xlabel("CVODE steps per point (wall times: bifurcation_accuracy.csv)")
    ax.set_ylabel("largest section error / range of D2")
    ax.set_title(ps.wrap(f"paper_lx1e-4 bifurcation diagram ({int(rows[0]['points'])} points): "
                         f"the sweep at each rtol against rtol {REFERENCE_RTOL:g}", 5.6, 9),
                 fontsize=9)
    ax.set_xlim(right=max(x) * 1.3)
    return ps.finish(fig, path)


def main(args) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.accuracy:
        accuracy(out, args.points or 1000)
        print(f"wrote {out}/bifurcation_accuracy.csv and bifurcation_accuracy.png")
        return 0
    n = args.points or (40 if args.quick else 1000)
    blocks = max(1, args.blocks or 1)
    repeats = max(1, args.repeats or 1)
    case = bench_case(args.rtol)
    l_x = np.linspace(0.0, 3e-4, n)
    if args.figure:
        with cf.ThreadPoolExecutor(2) as pool:
            draw(pyspline.sweep(case, executor=pool, progress=False, l_x=l_x), out)
        return 0
    print(f"{build()}, {os.cpu_count()} cores; {n} points of paper_lx1e-4 over l_x, "
          f"120 revolutions each (20 transient), rtol {case['rtol']:g}"
          + (f"; {blocks} interleaved blocks" if blocks > 1 else "")
          + (f"; {repeats} repeats" if repeats > 1 else ""))
    pyspline.sweep(case, progress=False, l_x=l_x[:2])            # imports, first load
    executors = {"serial": (None, 0)}       # label: (kind, workers)
    executors.update({label(2): (kind, 2) for kind, label in KINDS.items()})
    if args.scaling:          # each parallel executor also with one worker
        executors.update({label(1): (kind, 1) for kind, label in KINDS.items()})
    host = host_command(args.quick) if args.host else None
    if host:                  # the host's own 2-way speed-up, beside the executors'
        executors.update({HOST[0]: ("host", 1), HOST[1]: ("host", 2)})
    labels = list(executors)
    wall = {label: np.zeros(repeats) for label in labels}       # per repeat, summed over blocks
    core = {label: np.zeros(repeats) for label in labels}       # summed core_wall_s of the points
    failed, first_error = dict.fromkeys(labels, 0), {}
    ds = None
    # Every repeat and every block runs the executors in an order that rotates, so that a
    # machine whose speed drifts during the benchmark slows all of them alike. blocks > 1: every
    # executor runs the same interleaved subsets l_x[b::blocks] (each sizes its own tasks),
    # and the executors stay up together, started once for all repeats. blocks = 1: each
    # executor exists only for its own run (an idle Dask cluster takes CPU from the others:
    # docs/performance.md).
    with contextlib.ExitStack() as keep:
        started = {}
        if blocks > 1:
            started = {label: _start(*executors[label], keep) for label in labels}
        for rep in range(repeats):
            for b in range(blocks):
                values = l_x[b::blocks]
                turn = (rep * blocks + b) % len(labels)
                for label in labels[turn:] + labels[:turn]:
                    with contextlib.ExitStack() as this_run:
                        ex = (started[label] if blocks > 1
                              else _start(*executors[label], this_run))
                        t0 = time.perf_counter()
                        if executors[label][0] == "host":
                            host_runs(host, HOST_RUNS, executors[label][1])
                            wall[label][rep] += time.perf_counter() - t0
                            continue
                        part = pyspline.sweep(case, executor=ex, progress=False, l_x=values)
                        wall[label][rep] += time.perf_counter() - t0
                    core[label][rep] += float(np.nansum(part["core_wall_s"].values))
                    failed[label] += int(part.attrs.get("n_failed", 0))
                    errors = part["error"].values[part["error"].values != ""]
                    if len(errors) and label not in first_error:
                        first_error[label] = str(errors[0])
                    if blocks == 1 and label == "serial" and ds is None:
                        ds = part
            print(f"repeat {rep + 1}: " + ", ".join(f"{label} {wall[label][rep]:.2f} s"
                                                    for label in labels), flush=True)
    rows = []
    for label in labels:
        kind, workers = executors[label]
        # within each repeat; the standalone runs two at a time against one at a time
        ratio = wall[HOST[0] if kind == "host" else "serial"] / wall[label]
        one = KINDS[kind](1) if kind in KINDS else None
        scaling = wall[one] / wall[label] if one in wall and workers > 1 else None
        # the wall time inside the core (Fortran, no GIL, no messages) for the same points,
        # against the serial sweep's: how much slower the core computes while the other core is
        # busy too (host contention; on Dask also its threads taking turns with the runs).
        # `workers` over it is the speed-up if all work slowed alike and nothing else cost.
        inflation = float(np.median(core[label] / core["serial"])) if kind != "host" else None
        rows.append(dict(executor=label, points=n, blocks=blocks, repeats=repeats,
                         rtol=case["rtol"], wall_median_s=float(np.median(wall[label])),
                         wall_min_s=float(wall[label].min()),
                         wall_max_s=float(wall[label].max()),
                         speed_up_median=float(np.median(ratio)),
                         speed_up_min=float(ratio.min()), speed_up_max=float(ratio.max()),
                         walls_s=" ".join(f"{w:.2f}" for w in wall[label]),
                         scaling_median=(float(np.median(scaling)) if scaling is not None
                                         else ""),
                         scaling_min=float(scaling.min()) if scaling is not None else "",
                         scaling_max=float(scaling.max()) if scaling is not None else "",
                         core_time_over_serial_median=inflation or "",
                         ceiling=max(workers, 1) / inflation if inflation else "",
                         failed=failed[label]))
    print(f"{'executor':34s} {'wall: median':>12s} {'(min-max)':>15s}   speed-up: median "
          f"(min-max), within each repeat; core time over serial's -> speed-up if all work "
          f"slowed alike")
    for r in rows:
        print(f"{r['executor']:34s} {r['wall_median_s']:10.2f} s ({r['wall_min_s']:5.2f}-"
              f"{r['wall_max_s']:5.2f})   {r['speed_up_median']:5.2f}x ({r['speed_up_min']:.2f}-"
              f"{r['speed_up_max']:.2f})"
              + (f"   core {r['core_time_over_serial_median']:.2f}x -> {r['ceiling']:.2f}x"
                 if r["ceiling"] != "" else f"   ({HOST_RUNS} runs of chaos_z24 a block, "
                                            "over one at a time)")
              + (f"   over 1 worker: {r['scaling_median']:.2f}x ({r['scaling_min']:.2f}-"
                 f"{r['scaling_max']:.2f})" if r["scaling_median"] != "" else ""), flush=True)
    if any(failed.values()):
        print(f"failed points: {failed}")
        for label, message in first_error.items():
            print(f"  first error on {label}: {message}")
    _write_csv(out / "bifurcation.csv", rows)
    print(f"wrote {out}/bifurcation.csv")
    if ds is not None:              # the figure of the serial sweep (one block only)
        draw(ds, out)
    return 0


def draw(ds, out: Path) -> None:
    """The diagram of the sweep `ds` into out/bifurcation.png, its periods counted."""
    from pyspline import plots
    plots.bifurcation(ds, "l_x", path=out / "bifurcation.png")
    periods = ds["period"].values
    print(f"periods: {dict(zip(*np.unique(periods[np.isfinite(periods)], return_counts=True)))}")
    print(f"wrote {out}/bifurcation.png")
