"""Continuation with the exact monodromy against monodromy by central differences (issue 24's
benchmark): `python bench/run.py continuation [--quick]`.

Two scenes of docs/continuation.md, each continued in speed_rpm with monodromy='exact'
(variational equations + saltation: one run per corrector iteration) and monodromy='fd'
(central differences of the map: 2k + 1 runs), interleaved (exact, fd, fd, exact, ...):
- resonance: the backlash resonance (paper_ideal at dof 3, k_t = 1000 N m/rad, ripple of
  order 1, a = 0.15; rtol 1e-9, n_out 201), 2300 to 2530 r/min: full contact, then teeth
  opening and striking the back flank, two folds, grazings;
- impacting: the same drive with a = 2 (double-sided impacts, 64 switches a revolution),
  1600 to 1650 r/min: a period doubling and the doubled branch.
Beside them (the issue's comparison), on the resonance: one orbit with its multipliers
(periodic_orbit from a settled 1 s run), the exact continuation, and the peer, a follow-up and
follow-down brute-force sweep of 200 speeds over the same range (1 s runs, the last 0.2 s kept;
it finds the stable branches only). Per scene and monodromy: the medians of the wall time of the whole continuation, per branch
point, and per Newton step (one evaluation of the residual, M and dF/dp: timed around each
call), their ratios fd / exact, and how the two branches agree (special points matched by
type; the state and multipliers at the last point). Writes continuation.csv into --out.
"""
from __future__ import annotations

import importlib
import os
import statistics
import time
import warnings
from pathlib import Path

import numpy as np

import pyspline
from pyspline.orbits import _scale
from pyspline.paper import cases_dir
from speed import _write_csv, build

cont = importlib.import_module("pyspline.arclength")   # the module of pyspline.continuation
MONODROMY = ("exact", "fd")


def scenes(quick: bool) -> list[tuple[str, pyspline.Case, float, float]]:
    base = pyspline.load_case(cases_dir() / "paper_ideal.nml", start="equilibrium",
                              method="bdf", rtol=1e-9, atol=1e-11, t_end=0.05, n_out=201,
                              roots=True, dof=3, k_t1=1e3, k_t2=1e3,
                              ripple_order=[1, 0, 0, 0], ripple_amp=[0.15, 0, 0, 0])
    res = (2508.0, 2512.0) if quick else (2300.0, 2530.0)   # quick: the grazing and the fold
    imp = (1622.5, 1625.0) if quick else (1600.0, 1650.0)   # quick: the period doubling
    return [("resonance", base.replace(speed_rpm=res[0]), *res),
            ("impacting", base.replace(ripple_amp=[2.0, 0, 0, 0], speed_rpm=imp[0]), *imp)]


def run_one(case, start, stop, monodromy):
    """One continuation, each evaluation (a Newton step's residual, M and dF/dp) timed."""
    steps = []
    evaluate = cont._Problem.evaluate

    def timed(self, *a):
        t = time.perf_counter()
        try:
            return evaluate(self, *a)
        finally:
            steps.append(time.perf_counter() - t)
    cont._Problem.evaluate = timed
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pyspline.SplineWarning)
            t = time.perf_counter()
            ds = pyspline.continuation(case, "speed_rpm", start, stop, monodromy=monodromy,
                                       progress=False)
            wall = time.perf_counter() - t
    finally:
        cont._Problem.evaluate = evaluate
    return dict(wall=wall, points=ds.attrs["n_points"], steps=len(steps),
                step_s=statistics.median(steps), ds=ds)


def agreement(case, a, b) -> dict:
    """How the fd continuation b agrees with the exact one a: their branches and special points
    (those of branch 0 matched by type, the offset in r/min and the critical multipliers), the
    state (scaled by Eq. 25) and multipliers at branch 0's last point."""
    out = dict(branches=f"{a.attrs['n_branches']}/{b.attrs['n_branches']}", specials=[])
    for i in np.flatnonzero(a.special_branch.values == 0):
        kind = a.special_type.values[i]
        same = np.flatnonzero((b.special_type.values == kind) & (b.special_branch.values == 0))
        if not len(same):
            out["specials"].append(f"{kind} missing")
            continue
        j = same[np.argmin(np.abs(b.special_speed_rpm.values[same] - a.special_speed_rpm[i].item()))]
        mu = [complex(d.special_mu_real[k], d.special_mu_imag[k]) for d, k in ((a, i), (b, j))]
        out["specials"].append(
            f"{kind} {float(a.special_speed_rpm[i]):.2f}/{float(b.special_speed_rpm[j]):.2f} "
            + ("" if kind == "grazing" else f"mu {mu[0].real:.4f}/{mu[1].real:.4f}"))
    ia, ib = int((a.branch.values == 0).sum() - 1), int((b.branch.values == 0).sum() - 1)
    s = _scale(case.replace(speed_rpm=float(a.speed_rpm[ia])).model)
    out["d_last_y0"] = float(np.abs((a.y0.values[ia] - b.y0.values[ib]) / s).max())
    mua = np.sort_complex(a.mu_real.values[ia] + 1j * a.mu_imag.values[ia])
    mub = np.sort_complex(b.mu_real.values[ib] + 1j * b.mu_imag.values[ib])
    out["d_last_mu"] = float(np.abs(mua - mub).max())
    return out


def measure(quick: bool, repeat: int):
    rows, summary = [], []
    name, case, start, stop = scenes(True)[0]       # untimed: imports (xarray, tqdm), caches
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        pyspline.continuation(case, "speed_rpm", start, stop, max_points=3, progress=False)
    for name, case, start, stop in scenes(quick):
        runs = {m: [] for m in MONODROMY}
        for r in range(repeat):
            for m in (MONODROMY if r % 2 == 0 else MONODROMY[::-1]):
                runs[m].append(run_one(case, start, stop, m))
                rr = runs[m][-1]
                rows.append(dict(scene=name, monodromy=m, round=r, wall_s=rr["wall"],
                                 points=rr["points"], steps=rr["steps"],
                                 step_median_s=rr["step_s"]))
        med = {m: dict(wall=statistics.median(x["wall"] for x in runs[m]),
                       point=statistics.median(x["wall"] / x["points"] for x in runs[m]),
                       step=statistics.median(x["step_s"] for x in runs[m]),
                       points=runs[m][0]["points"], steps=runs[m][0]["steps"])
               for m in MONODROMY}
        summary.append(dict(scene=name, range=f"{start:g}-{stop:g}", med=med,
                            agree=agreement(case, runs["exact"][0]["ds"], runs["fd"][0]["ds"])))
    return rows, summary


def beside_sweep(quick: bool, repeat: int) -> dict:
    """Medians of: one periodic orbit (with its multipliers) of the resonance at its start
    speed, from a settled 1 s run; the exact continuation over the range; a follow='both'
    sweep of 200 speeds (24 with quick) over it, interleaved."""
    name, case, start, stop = scenes(quick)[0]
    npts = 24 if quick else 200
    settled = case.replace(t_end=1.0, t_transient=0.8, n_out=1001)
    times = {"orbit": [], "continuation": [], "sweep": []}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        for _ in range(repeat):
            t = time.perf_counter()
            orbit = pyspline.periodic_orbit(settled)
            times["orbit"].append(time.perf_counter() - t)
            t = time.perf_counter()
            ds = pyspline.continuation(case, "speed_rpm", start, stop, progress=False)
            times["continuation"].append(time.perf_counter() - t)
            t = time.perf_counter()
            pyspline.sweep(settled, speed_rpm=np.linspace(start, stop, npts), follow="both",
                           progress=False, spectrum=False)
            times["sweep"].append(time.perf_counter() - t)
    return dict(scene=name, range=f"{start:g}-{stop:g}", sweep_points=npts,
                points=ds.attrs["n_points"], special=ds.attrs["n_special"],
                largest_mu=float(abs(orbit.multipliers[0])),
                **{k: statistics.median(v) for k, v in times.items()})


def format_beside(b) -> list[str]:
    return [f"{b['scene']} {b['range']} r/min: one orbit with its multipliers (max |mu| "
            f"{b['largest_mu']:.4f}) {b['orbit']:.2f} s; continuation ({b['points']} points, "
            f"{b['special']} special) {b['continuation']:.2f} s; follow sweep up and down, "
            f"{b['sweep_points']} speeds of 1 s runs, {b['sweep']:.2f} s "
            f"(continuation / sweep {b['continuation'] / b['sweep']:.2f}x)"]


def format_summary(summary, repeat) -> list[str]:
    lines = [f"medians of {repeat} interleaved runs; per point = whole continuation / points, "
             "per step = one Newton step's residual + M + dF/dp",
             f"{'scene':10s} {'speed_rpm':>11s} {'monodromy':9s} {'points':>6s} {'steps':>5s} "
             f"{'wall [s]':>8s} {'per point':>9s} {'per step':>9s}"]
    for s in summary:
        for m in MONODROMY:
            d = s["med"][m]
            lines.append(f"{s['scene']:10s} {s['range']:>11s} {m:9s} {d['points']:6d} "
                         f"{d['steps']:5d} {d['wall']:8.2f} {d['point']:9.4f} {d['step']:9.4f}")
        e, f = s["med"]["exact"], s["med"]["fd"]
        a = s["agree"]
        lines.append(f"{'':10s} fd / exact: wall {f['wall'] / e['wall']:.2f}x, per point "
                     f"{f['point'] / e['point']:.2f}x, per step {f['step'] / e['step']:.2f}x")
        lines.append(f"{'':10s} exact/fd: branches {a['branches']}; branch 0's special points "
                     f"(r/min): {'; '.join(a['specials']) or 'none'}; its last point: y0 "
                     f"{a['d_last_y0']:.2g} apart (scaled), multipliers {a['d_last_mu']:.2g}")
    return lines


def main(args) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"{build()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f}, "
          f"CVODE {pyspline.core.cvode_library()}")
    repeat = args.repeats or (1 if args.quick else 3)
    rows, summary = measure(args.quick, repeat)
    print("\n".join(format_summary(summary, repeat)))
    print("\n".join(format_beside(beside_sweep(args.quick, repeat))))
    _write_csv(out / "continuation.csv", rows)
    print(f"wrote {out}/continuation.csv")
    return 0
