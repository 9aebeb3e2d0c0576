"""The fidelity ladder (`python bench/run.py ladder`): what each model level costs and how far it
is from the level a paper case sets, and what `fidelity = 'auto'` picks.

Levels: dof 3 (torsional only, lateral states frozen at the start state) or 7 (bending-torsion),
times the thermal levels none, bulk, oneway, coupled. A level is *eligible* for a case when it
reports the quantities the case's own level reports (T_f needs oneway or coupled). The error is
the max relative error of T_m(t) and of the per-tooth F_j at the output times against the
case's own level (speed._errors); the cost is the core's median run time. The auto rule lives in
the Fortran core (fortran/physics/fidelity.f90, run.f90); this module measures it.
"""
from __future__ import annotations

import statistics
from pathlib import Path

from pyspline import SplineError, load_case, simulate
from pyspline.core import THERMAL_LEVELS as THERMAL, level_name
from pyspline.paper import cases_dir
from speed import _errors, _write_csv, decade_axis

#: thermal levels that report what a case's own level reports (auto chooses among these)
ELIGIBLE = {"none": ("none",), "bulk": ("none", "bulk"), "oneway": ("oneway",),
            "coupled": ("oneway", "coupled")}
CASES = ("paper_ideal", "paper_lx5e-5", "paper_lx1e-4", "paper_T50", "paper_T100",
         "paper_flash_lx0", "paper_flash_lx5e-5", "paper_flash_lx1e-4", "physical_lx1e-4")
QUICK_CASES = ("paper_ideal", "paper_lx1e-4", "paper_T100")
TOLS = (1e-2, 1e-3)


def _timed(case, repeat):
    runs = [simulate(case) for _ in range(repeat)]
    return runs[-1], statistics.median(r.stats["core_wall_s"] for r in runs)


def _error(res, ref):
    return max(_errors(res.Tm, res.F, ref.Tm, ref.F))


def ladder(out, quick=False, progress=True, cases=None):
    """Run every level of every case, then fidelity = auto at each tolerance in TOLS. Writes
    ladder.csv and ladder.png into out; returns the rows."""
    from tqdm import tqdm
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    names = cases or (QUICK_CASES if quick else CASES)
    repeat = 1 if quick else 3
    levels = [(d, th) for th in THERMAL for d in (3, 7)]
    rows = []
    bar = tqdm(total=len(names) * (len(levels) + len(TOLS)), desc="fidelity ladder",
               disable=not progress)
    for name in names:
        case = load_case(cases_dir() / f"{name}.nml")
        if quick:
            case = case.replace(t_end=min(case["t_end"], 0.1), n_out=65)
        ref, ref_cost = _timed(case, repeat)
        own = (case["dof"], case["thermal"])
        for dof, th in levels:
            row = dict(case=name, level=level_name(dof, th), dof=dof, thermal=th,
                       own=(dof, th) == own,
                       eligible=th in ELIGIBLE[case["thermal"]] and dof <= case["dof"])
            try:
                res, cost = (ref, ref_cost) if row["own"] else _timed(
                    case.replace(dof=dof, thermal=th), repeat)
                row.update(status="ok", cost_s=cost, steps=res.stats["steps"],
                           rhs_evals=res.stats["rhs_evals"], error=_error(res, ref))
            except SplineError as exc:
                row.update(status=f"FAILED: {str(exc)[:120]}", cost_s=float("nan"), steps=-1,
                           rhs_evals=-1, error=float("nan"))
            rows.append(row)
            bar.update()
        for tol in TOLS:
            res, cost = _timed(case.replace(fidelity="auto", fidelity_tol=tol), repeat)
            err = _error(res, ref)
            s = res.stats
            rows.append(dict(case=name, level=f"auto {tol:g}", dof=s["dof"],
                             thermal=THERMAL[s["thermal_level"]], own=False, eligible=True,
                             status="ok", cost_s=cost, steps=s["steps"],
                             rhs_evals=s["rhs_evals"], error=err, tol=tol,
                             picked=res.level,
                             eps_lateral=s["fidelity_eps_lateral"],
                             eps_thermal=s["fidelity_eps_thermal"],
                             within_tol=bool(err <= tol), speedup=ref_cost / cost))
            bar.update()
    bar.close()
    _write_csv(out / "ladder.csv", rows)
    _plot(rows, names, out / "ladder.png")
    return rows


AUTO_MARKERS = dict(zip(TOLS, ("x", "+")))   # fidelity = auto's pick at each tolerance


def _plot(rows, names, path=None):
    """Error against core time of every level, one panel per case; auto's picks marked by
    tolerance (AUTO_MARKERS); errors below 1e-16 at 1e-16."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from pyspline.plots import style as ps
    ncol = 3
    nrow = -(-len(names) // ncol)
    fig = Figure(figsize=(4.2 * ncol, 3.4 * nrow + 0.8), layout="constrained")
    axes = fig.subplots(nrow, ncol, squeeze=False)
    colors = dict(zip(THERMAL, ("tab:blue", "tab:green", "tab:orange", "tab:red")))
    floor = 1e-16
    top = 3 * max([1.0] + [r["error"] for r in rows if r["status"] == "ok"])
    for ax, name in zip(axes.flat, names):
        for r in (r for r in rows if r["case"] == name and r["status"] == "ok"):
            err = max(r["error"], floor)
            if r["level"].startswith("auto"):
                ax.plot(r["cost_s"], err, AUTO_MARKERS[r["tol"]], color="k", ms=10, mew=2)
                continue
            marker = "^" if r["dof"] == 3 else "o"
            face = colors[r["thermal"]] if r["eligible"] else "none"
            ax.plot(r["cost_s"], err, marker, ms=11 if r["own"] else 7, mfc=face,
                    mec=colors[r["thermal"]], ls="none")
        for tol in TOLS:
            ax.axhline(tol, color="0.6", ls="--", lw=0.8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(floor / 3, top)
        bad = [r["level"] for r in rows if r["case"] == name and r["status"] != "ok"]
        ax.set_title(ps.wrap(f"{name}; failed, not drawn: {', '.join(bad)}" if bad else name,
                             3.8, 9), fontsize=9)
        ax.set_xlabel("core time [s]", fontsize=8)
        ax.set_ylabel("error vs the case's level", fontsize=8)
        decade_axis(ax.xaxis)
        ax.tick_params(labelsize=7)
    for ax in list(axes.flat)[len(names):]:
        ax.axis("off")
    handles = [Line2D([], [], marker="o", ls="none", mfc=c, mec=c, label=t)
               for t, c in colors.items()]
    handles += [Line2D([], [], marker="^", ls="none", mfc="k", mec="k", label="3 DOF"),
                Line2D([], [], marker="o", ls="none", mfc="k", mec="k", label="7 DOF"),
                Line2D([], [], marker="o", ls="none", mfc="none", mec="k", label="not eligible")]
    handles += [Line2D([], [], marker=m, ls="none", color="k", mew=2,
                       label=f"fidelity = auto, tol {tol:g}") for tol, m in AUTO_MARKERS.items()]
    fig.legend(handles=handles, loc="outside lower center", ncol=5, fontsize=8)
    fig.suptitle(ps.wrap("Fidelity ladder: cost against error of each model level (large "
                         "marker: the case's own level; dashed: tolerances; errors below 1e-16 "
                         "drawn at 1e-16)", 4.2 * ncol - 0.5, 9), fontsize=9)
    return ps.finish(fig, path)


def format_rows(rows) -> list[str]:
    lines = [f"{'case':20s} {'level':18s} {'elig':>4s} {'cost [s]':>9s} {'steps':>7s} "
             f"{'error':>9s}  note"]
    for r in rows:
        note = r["status"] if r["status"] != "ok" else ""
        if "picked" in r:
            note = (f"picked {r['picked']} (est. lateral {r['eps_lateral']:.1e}, thermal "
                    f"{r['eps_thermal']:.1e}), {'within' if r['within_tol'] else 'MISSES'} "
                    f"tol, {r['speedup']:.1f}x faster")
        elif r["own"]:
            note = "the case's own level"
        lines.append(f"{r['case']:20s} {r['level']:18s} {('yes' if r['eligible'] else 'no'):>4s} "
                     f"{r['cost_s']:9.4f} {r['steps']:7d} {r['error']:9.1e}  {note}")
    return lines
