"""Cost anatomy (`python bench/run.py anatomy`): where the time of a run goes.

For each case: the time per right-hand-side call (ns) measured in a Fortran loop (bench/time_rhs.f90,
the meson target time-rhs, installed beside pyspline's extension; for an editable install built
on demand with meson into bench/build/meson), against the flop floor (bench/floor.f90: a branch-free
kernel doing only the arithmetic the mesh cannot avoid, with its flop count; built here on
demand with f2py into bench/build/); then one run's time per step and its shares: RHS (the
integrator's calls), Jacobian (difference-quotient calls), roots (root-function evaluations,
where the case locates switches), solver (CVODE's own work and the per-tooth outputs: the rest
of the core time) and Python (wall time outside the core: case file, f2py, result arrays).
Then the cost of the outputs (output_cost): the wall time of a run with its n_out output times
less that of a run that integrates the same way with few (see output_cost), per output time,
against the target OUTPUT_TARGET_US (0.1 us at Z = 16).
"""
from __future__ import annotations

import functools
import statistics
import time
from pathlib import Path

from pyspline import load, load_case, simulate
from pyspline.paper import cases_dir
from speed import _write_csv

HERE = Path(__file__).resolve().parent


def _floor_module():
    """bench/floor.f90 compiled with f2py (once, into bench/build/)."""
    import importlib
    import subprocess
    import sys
    build = HERE / "build"
    build.mkdir(exist_ok=True)
    if str(build) not in sys.path:
        sys.path.insert(0, str(build))
    try:
        return importlib.import_module("_floor")
    except ImportError:
        subprocess.run([sys.executable, "-m", "numpy.f2py", "-c", str(HERE / "floor.f90"),
                        "-m", "_floor", "--opt=-O2"], cwd=build, check=True, capture_output=True)
        return importlib.import_module("_floor")


@functools.lru_cache(maxsize=None)
def _time_rhs_exe() -> Path:
    """bench/time_rhs.f90 linked with the core (meson target time-rhs): the one pip installed
    beside pyspline's extension, else (an editable install) built with the SUNDIALS the
    installed pyspline links and for the CPU its core is (host_tuned), into bench/build/meson
    (rebuilt when the sources change)."""
    import subprocess
    import sys
    import pyspline
    from pyspline import _build_info
    installed = Path(pyspline.__file__).with_name("time-rhs")
    if installed.is_file():
        return installed
    build = HERE / "build" / "meson"
    meson = [sys.executable, "-m", "mesonbuild.mesonmain"]
    prefix = (str(Path(_build_info.SUNDIALS_LIBDIR).parent) if _build_info.SUNDIALS_LIBDIR
              else "")
    options = [f"-Dsundials_prefix={prefix}",
               f"-Dhost_tuned={str(_build_info.BUILD != 'portable').lower()}"]
    marker = build / "options.txt"      # a build for another SUNDIALS or CPU is set up anew
    if not (build / "build.ninja").exists() or not marker.exists() or \
            marker.read_text() != " ".join(options):
        wipe = ["--wipe"] if (build / "build.ninja").exists() else []
        subprocess.run(meson + ["setup", *wipe, str(build), str(HERE.parent), *options],
                       check=True, capture_output=True)
        marker.write_text(" ".join(options))
    subprocess.run(meson + ["compile", "-C", str(build), "time-rhs"], check=True,
                   capture_output=True)
    return build / "time-rhs"


def time_rhs(model, n):
    """Seconds per RHS call and per root-function evaluation of a loaded model at its static
    equilibrium (bench/time_rhs.f90)."""
    import subprocess
    import tempfile
    import numpy as np
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "model.bin"
        np.asarray(model.bytes, dtype=np.int32).tofile(path)
        out = subprocess.run([str(_time_rhs_exe()), str(path), str(n)], capture_output=True,
                             text=True)
    if out.returncode != 0:
        raise RuntimeError(f"time-rhs failed ({out.returncode}): {out.stderr.strip()}")
    t_rhs, t_roots = map(float, out.stdout.split())
    return t_rhs, t_roots


CASES = ("paper_lx1e-4", "paper_T100", "physical_lx1e-4")
OUTPUT_TARGET_US = 0.1     # per output time at Z = 16 (issue "Ahead of the strongest peer")


def output_cost(case, repeat=15, clock=time.perf_counter):
    """Wall seconds per output time (clock=time.process_time: CPU seconds, steadier on a shared
    host, which takes the core from a run): the case's run against a run that integrates the same way
    with few output times, alternating, repeat times each. Where the run takes the linear tail
    (paper_lx1e-4), the few-output run is the same case up to the output after the tail's start
    (the integration is what the case's run does, the tail's outputs are what is measured); else
    (and before root finding was on by default: with roots on, tail checks wait for outputs) the
    same span with 2 output times. The few-output run's extra or missing steps are charged at its
    own core time per step. Returns (median, min, max) of the per-pair differences over the
    difference of output times, and the medians of the two runs (s)."""
    r = simulate(case)
    tail_t = r.stats["linear_tail_t_s"]
    if 0.0 < tail_t < case["t_end"]:
        import numpy as np
        k = int(np.searchsorted(r.t, tail_t)) + 1
        few = case.replace(t_end=float(r.t[k]), n_out=k + 1)
    else:
        few = case.replace(n_out=2)
    rf = simulate(few)     # warm-up (page faults of the output arrays, caches)
    extra = r.stats["steps"] - rf.stats["steps"]
    many_s, few_s, step_s = [], [], []
    for _ in range(repeat):
        for c, acc in ((case, many_s), (few, few_s)):
            t0 = clock()
            res = simulate(c)
            acc.append(clock() - t0)
        step_s.append(res.stats["core_wall_s"]/max(res.stats["steps"], 1))
    n = case["n_out"] - few["n_out"]
    per = sorted((a - b - extra*s)/n for a, b, s in zip(many_s, few_s, step_s))
    return (statistics.median(per), per[0], per[-1], statistics.median(many_s),
            statistics.median(few_s), few["n_out"])


def format_output_cost(name, case, cost, what="") -> str:
    med, lo, hi, many, few, n_few = cost
    return (f"outputs {name}{what} (Z = {case['z']}, n_out = {case['n_out']}): {med*1e6:.3f} us per "
            f"output time (range {lo*1e6:.3f}..{hi*1e6:.3f}; runs {many*1e3:.2f} ms against "
            f"{few*1e3:.2f} ms with {n_few}), target {OUTPUT_TARGET_US} us: ratio "
            f"{med*1e6/OUTPUT_TARGET_US:.1f}")


def rhs_cost(case, n=200_000, repeat=5):
    """Median seconds per RHS call, per floor-kernel call and per root-function evaluation,
    and the floor's flop count."""
    model = load(case)
    y = load(case.replace(start="equilibrium", dq0=[0.0] * 7, dv0=[0.0] * 7)).start_state()
    floor = _floor_module()
    samples = []
    for _ in range(repeat):
        t_rhs, t_roots = time_rhs(model, n)
        t_floor, flops = floor.time_floor(case["z"], n, y)
        samples.append((t_rhs, t_floor, t_roots))
    med = [statistics.median(s[i] for s in samples) for i in range(3)]
    return med[0], med[1], flops, med[2]


def anatomy(out, quick=False, cases=CASES):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    n = 20_000 if quick else 200_000
    repeat = 3 if quick else 5
    rows = []
    for name in cases:
        case = load_case(cases_dir() / f"{name}.nml")
        if quick:
            case = case.replace(t_end=min(case["t_end"], 0.1), n_out=65)
        t_rhs, t_floor, flops, t_roots = rhs_cost(case, n, repeat)
        simulate(case)   # warm-up: the first call also pays the page faults of the output arrays
        runs = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            res = simulate(case)
            runs.append((time.perf_counter() - t0, res))
        wall, res = sorted(runs, key=lambda r: r[0])[len(runs) // 2]
        s = res.stats
        core = s["core_wall_s"]
        rhs = s["rhs_evals"] * t_rhs
        jac = s["lin_rhs_evals"] * t_rhs
        roots = s["root_fn_evals"] * t_roots
        # the parts are timed apart (time-rhs); on a shared host, slower than the run went:
        # then fitted into the run's core time, so that the shares add up to 1
        fit = min(1.0, core / max(rhs + jac + roots, 1e-300))
        rhs, jac, roots = rhs * fit, jac * fit, roots * fit
        rows.append(dict(
            case=name, z=case["z"], thermal=case["thermal"], method=case["method"],
            rhs_ns=t_rhs * 1e9, floor_ns=t_floor * 1e9, floor_flops=flops,
            rhs_over_floor=t_rhs / t_floor, steps=s["steps"], rhs_evals=s["rhs_evals"],
            lin_rhs_evals=s["lin_rhs_evals"], wall_s=wall, core_s=core,
            us_per_step=core / max(s["steps"], 1) * 1e6,
            roots_ns=t_roots * 1e9, root_fn_evals=s["root_fn_evals"],
            share_rhs=rhs / wall, share_jacobian=jac / wall, share_roots=roots / wall,
            share_solver=max(core - rhs - jac - roots, 0.0) / wall,
            share_python=max(wall - core, 0.0) / wall))
    _write_csv(out / "anatomy.csv", rows)
    _plot(rows, out / "anatomy.png")
    return rows


def _plot(rows, path=None):
    """The shares of one run's wall time per case; the RHS call against the flop floor."""
    from matplotlib.figure import Figure
    from pyspline.plots import style as ps
    fig = Figure(figsize=(11, 4.2), layout="constrained")
    a1, a2 = fig.subplots(1, 2)
    names = [r["case"] for r in rows]
    left = [0.0] * len(rows)
    for key, color in (("share_rhs", "tab:blue"), ("share_jacobian", "tab:orange"),
                       ("share_roots", "tab:purple"), ("share_solver", "tab:green"),
                       ("share_python", "tab:gray")):
        vals = [r[key] for r in rows]
        a1.barh(names, vals, left=left, color=color, label=key.removeprefix("share_"))
        left = [a + b for a, b in zip(left, vals)]
    a1.set_xlabel("share of the wall time of one run")
    a1.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.18), ncol=5)
    a1.set_title("where a run's time goes", fontsize=10)
    x = range(len(rows))
    # markers, not bars: a bar's length on a log axis starts at an arbitrary bottom
    a2.plot(x, [r["rhs_ns"] for r in rows], "o", ms=8, label="RHS call")
    a2.plot(x, [r["floor_ns"] for r in rows], "s", ms=8, label="flop floor")
    a2.set_xticks(list(x), names, fontsize=8)
    a2.set_xlim(-0.5, len(rows) - 0.5)
    a2.set_ylabel("ns per call")
    a2.set_yscale("log")
    a2.set_title("RHS against the flop-count floor", fontsize=10)
    a2.legend(fontsize=8)
    return ps.finish(fig, path)


def format_rows(rows) -> list[str]:
    lines = [f"{'case':18s} {'RHS ns':>7s} {'floor ns':>8s} {'ratio':>5s} {'flops':>5s} "
             f"{'steps':>7s} {'us/step':>7s} {'RHS':>5s} {'Jac':>5s} {'roots':>5s} {'solver':>6s} "
             f"{'Python':>6s}"]
    for r in rows:
        lines.append(f"{r['case']:18s} {r['rhs_ns']:7.0f} {r['floor_ns']:8.0f} "
                     f"{r['rhs_over_floor']:5.1f} {r['floor_flops']:5.0f} {r['steps']:7d} "
                     f"{r['us_per_step']:7.2f} {r['share_rhs']:5.0%} {r['share_jacobian']:5.0%} "
                     f"{r['share_roots']:5.0%} "
                     f"{r['share_solver']:6.0%} {r['share_python']:6.0%}")
    return lines
