"""Speed against accuracy (`python bench/run.py wp`) and where methods fail (`python bench/run.py
stability`). Each writes a PNG and a CSV into --out; --quick is small enough for CI.

Errors are the max relative error of T_m(t) and of the per-tooth F_j at the output times
against a reference computed by CVODE BDF at rtol 1e-12 with root finding, itself checked against
a different method (DOP853 on the Fortran RHS at rtol 1e-12). Significant correct digits
scd = -log10(error). A failed run is recorded with its reason, never dropped.
"""
from __future__ import annotations

import csv
import importlib.util
import statistics
import time
from pathlib import Path

import numpy as np

from pyspline import SplineError, load, load_case, simulate, start_state
from pyspline.paper import cases_dir

SCIPY_METHODS = ("RK45", "DOP853", "Radau", "BDF", "LSODA")


class Budget(Exception):
    """A peer used up its RHS evaluation budget (counted as a failure: too much work)."""


class FortranRHS:
    """The project's Fortran right-hand side (SI) of a loaded case as a callable f(t, y) for
    solvers driven from Python (scipy.integrate.solve_ivp), counting its calls."""

    def __init__(self, case):
        self.model = load(case)
        self.calls = 0

    def __call__(self, t, y):
        self.calls += 1
        return self.model.rhs(t, y)


def _oracle():
    """tests/oracle.py of this checkout (the numpy RHS peer), or None."""
    path = Path(__file__).resolve().parent.parent / "tests" / "oracle.py"
    if not path.is_file():
        return None
    spec = importlib.util.spec_from_file_location("pyspline_oracle", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _peer_fields(case) -> dict:
    """The case's fields for an independent right-hand side (oracle, numba peer), with the
    k_m and c_m the core uses (a computed k_m and zeta_m are the core's; the peers take values)."""
    info = load(case).info()
    return {**dict(case), "k_m": info["k_m"], "c_m": info["c_m"], "zeta_m": 0.0}


def _scaled_atol(case, rtol):
    """atol = 1e-2 rtol on the states scaled as in Eq. 25 (the core's scales)."""
    info = load(case).info()
    l, w = info["l_ref"], info["w_ref"]
    return rtol * 1e-2 * np.r_[np.full(7, l), np.full(7, l * w)]


def _mesh_outputs(case, t, y):
    """T_m and F_j from states (Fortran core, contact states from the state)."""
    model = load(case)
    tm, F = np.empty(len(t)), np.empty((len(t), case["z"]))
    for k, (tk, yk) in enumerate(zip(t, y)):
        _, mesh, tm[k] = model.rhs_mesh(tk, yk)
        F[k] = mesh["F"]
    return tm, F


#: the pyspline settings the benchmarks try (a new integrator method: add it here and in _cvode_kw)
PYSPLINE_VARIANTS = ("bdf", "adams", "adams-fixedpoint", "erk", "auto")


def _cvode_kw(variant):
    """Case fields of a pyspline variant: 'bdf', 'adams', 'adams-fixedpoint' (functional
    iteration, no Jacobian), 'bdf-stald' (stability-limit detection), 'erk' or 'auto'."""
    if variant == "adams-fixedpoint":
        return dict(method="adams", nonlinear="fixedpoint")
    if variant == "bdf-stald":
        return dict(method="bdf", stald=True)
    if variant in PYSPLINE_LABEL:                 # 'erk', 'auto': as the case would run them
        return dict(method=variant)
    return dict(method=variant, nonlinear="newton", stald=False)


def run_scipy(case, method, rtol, rhs_kind, oracle, budget):
    """solve_ivp on the Fortran RHS (through f2py) or the numpy oracle RHS."""
    from scipy.integrate import solve_ivp
    if rhs_kind == "fortran":
        f = FortranRHS(case)
    else:
        p = oracle.prepare(_peer_fields(case))
        f = lambda t, y: oracle.rhs(t, y, p)  # noqa: E731
    calls = [0]

    def counted(t, y):
        calls[0] += 1
        if calls[0] > budget:
            raise Budget(f"more than {budget} RHS evaluations")
        return f(t, y)

    t_eval = load(case).output_times()
    t0 = time.perf_counter()
    sol = solve_ivp(counted, (case["t0"], case["t_end"]), start_state(case), method=method,
                    rtol=rtol, atol=_scaled_atol(case, rtol), t_eval=t_eval)
    wall = time.perf_counter() - t0
    if not sol.success:
        raise SplineError(f"solve_ivp {method}: {sol.message}")
    return wall, sol.t, sol.y.T, calls[0]


def _numba_peer():
    """bench/numba_peer.py (compiled LSODA from numbalsoda on a numba RHS), or None without
    numba/numbalsoda."""
    if importlib.util.find_spec("numbalsoda") is None:   # not imported: numba_peer._driver
        return None
    try:
        import numba_peer
    except ImportError:
        return None
    return numba_peer


def run_numbalsoda(case, rtol, peer, method="LSODA"):
    """numbalsoda LSODA or DOP853 on the numba peer's strengthened entry (numba_peer.Setup: its
    fast RHS where the scene has one, scaled states, atol = 1e-2 rtol as for CVODE), T_m and F
    formed by the peer's own compiled forces (the Fortran core's per output for a scene without
    the fast RHS); the compilation and packing are done before the clock starts (a warm-up
    solve). Returns (wall, T_m, F, RHS calls)."""
    setup = peer.Setup(_peer_fields(case))
    y0 = start_state(case)
    t_out = load(case).output_times()
    t_eval = np.r_[case["t0"], t_out] if t_out[0] > case["t0"] else t_out
    mx = 10**8 if method == "DOP853" else 10**6     # DOP853's budget is for the whole run
    u, _ = setup.integrate(y0, t_eval[:3], rtol, rtol * 1e-2, method.lower(), mx)  # compile
    if setup.kind == "fast":
        setup.forces(t_eval[:3], u)                                 # compile the forces too
    t0 = time.perf_counter()
    u, ok = setup.integrate(y0, t_eval, rtol, rtol * 1e-2, method.lower(), mx)
    u = u[len(t_eval) - len(t_out):]
    if setup.kind == "fast":
        tm, F = setup.forces(t_out, u)
    wall = time.perf_counter() - t0
    if not ok:
        raise SplineError(f"numbalsoda {method} failed at rtol {rtol:g}")
    if setup.kind != "fast":
        tm, F = _mesh_outputs(case, t_out, u * setup.scale)
    return wall, tm, F, int(setup.data[0])


def _errors(tm, F, ref_tm, ref_F):
    e_tm = np.abs(tm - ref_tm).max() / np.abs(ref_tm).max()
    e_f = np.abs(F - ref_F).max() / np.abs(ref_F).max()
    return e_tm, e_f


def reference(case):
    ref = simulate(case.replace(method="bdf", roots=True, rtol=1e-12, atol=1e-14,
                                max_steps=10**7))
    wall, t, y, _ = run_scipy(case, "DOP853", 1e-12, "fortran", None, 10**9)
    tm2, F2 = _mesh_outputs(case, t, y)
    agree = _errors(tm2, F2, ref.Tm, ref.F)
    return ref, agree


#: the work-precision scenes and their simulated time [s]: the paper's mechanical and coupled
#: scenes, the rattling scene over its engagement and first impacts (it is chaotic: far beyond
#: its predictability horizon of about 20 ms no two runs agree pointwise), and the physically
#: damped Z = 24 scene over its engagement (its impacts, before it settles)
WP_CASES = {"paper_lx1e-4": 0.3, "paper_T100": 0.3, "rattle_z24": 0.05, "physical_z24": 0.1}


#: labels of the pyspline settings that are not CVODE's (method = 'erk': ARKODE ERKStep)
PYSPLINE_LABEL = {"erk": "ARKODE", "auto": "pyspline"}


def work_precision(out, quick=False, progress=True, cases=None):
    """The work-precision chart and table (WP_CASES; quick: the two paper scenes, 0.01 s, the
    scipy peers at one rtol)."""
    from tqdm import tqdm
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    oracle = _oracle()
    peer = _numba_peer()
    rtols_cv = [1e-3, 1e-5, 1e-7] if quick else [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10]
    rtols_sp = [1e-3] if quick else [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]   # quick: each runs
    budget = 20_000 if quick else 400_000
    repeat = 1 if quick else 3
    rows, notes = [], []
    names = cases or (("paper_lx1e-4", "paper_T100") if quick else tuple(WP_CASES))
    for name in names:
        t_end = 0.01 if quick else WP_CASES[name]
        case = load_case(cases_dir() / f"{name}.nml", t_end=t_end, t_transient=0.0,
                         section="none", n_out=int(round(640 * t_end)) + 1,
                         linear_tail=False)      # integrators compared: no closed-form tail
        ref, agree = reference(case)
        notes.append(f"{name}: reference (CVODE BDF + roots, rtol 1e-12) vs DOP853 rtol 1e-12 on "
                     f"the Fortran RHS: T_m {agree[0]:.1e}, F_j {agree[1]:.1e}")
        jobs = [("cvode", m, r, rt) for m in PYSPLINE_VARIANTS
                for r in (False, True) for rt in rtols_cv]
        jobs += [("scipy", m, kind, rt) for m in SCIPY_METHODS for kind in ("fortran", "numpy")
                 for rt in rtols_sp if kind == "fortran" or oracle is not None]
        if peer is not None:
            jobs += [("numbalsoda", m, "numba", rt) for m in ("LSODA", "DOP853")
                     for rt in rtols_cv]
        for solver, method, opt, rtol in tqdm(jobs, desc=f"work-precision {name}",
                                              disable=not progress):
            label = (f"{PYSPLINE_LABEL.get(method, 'CVODE')} {method}{' + roots' if opt else ''}"
                     if solver == "cvode"
                     else f"{solver} {method} ({opt} RHS)")
            row = dict(case=name, method=label, rtol=rtol)
            try:
                if solver == "cvode":
                    c = case.replace(roots=opt, rtol=rtol, atol=rtol * 1e-2, **_cvode_kw(method))
                    times = []
                    for _ in range(repeat):
                        t0 = time.perf_counter()
                        res = simulate(c)
                        times.append(time.perf_counter() - t0)
                    wall, tm, F, nfev = statistics.median(times), res.Tm, res.F, \
                        res.stats["rhs_evals"]
                elif solver == "numbalsoda":
                    wall, tm, F, nfev = run_numbalsoda(case, rtol, peer, method)
                else:
                    wall, t, y, nfev = run_scipy(case, method, rtol, opt, oracle, budget)
                    tm, F = _mesh_outputs(case, t, y)
                e_tm, e_f = _errors(tm, F, ref.Tm, ref.F)
                row.update(status="ok", time_s=wall, rhs_evals=nfev, err_Tm=e_tm, err_F=e_f,
                           scd=-np.log10(max(e_tm, e_f, 1e-16)))
            except (SplineError, Budget) as exc:
                row.update(status=f"FAILED: {str(exc)[:120]}", time_s=float("nan"),
                           rhs_evals=-1, err_Tm=float("nan"), err_F=float("nan"),
                           scd=float("nan"))
            rows.append(row)
    _write_csv(out / "work_precision.csv", rows)
    _write_csv(out / "speed_ratios.csv", speed_ratios(rows))
    _plot_wp(rows, notes, out / "work_precision.png")
    return rows, notes


def speed_ratios(rows, accuracy=1e-6):
    """At equal accuracy (the cheapest run of each method whose error is at most `accuracy`;
    1e-6 is what CVODE reaches at rtol 1e-8), the time of the fastest scipy peer on each RHS
    over the time of the fastest CVODE variant, per case. None where no run reached it."""
    out = []
    for name in dict.fromkeys(r["case"] for r in rows):
        good = [r for r in rows if r["case"] == name and r["status"] == "ok"
                and max(r["err_Tm"], r["err_F"]) <= accuracy]

        def best(pred):
            cand = [r for r in good if pred(r["method"])]
            return min(cand, key=lambda r: r["time_s"]) if cand else None
        cv = best(lambda m: m.startswith(tuple(set(PYSPLINE_LABEL.values()) | {"CVODE"})))
        for kind in ("numpy", "fortran", "numba"):
            peer = best(lambda m, k=kind: f"({k} RHS)" in m)
            out.append(dict(case=name, accuracy=accuracy, peer_rhs=kind,
                            cvode=cv and cv["method"], cvode_rtol=cv and cv["rtol"],
                            cvode_s=cv and cv["time_s"], peer=peer and peer["method"],
                            peer_rtol=peer and peer["rtol"], peer_s=peer and peer["time_s"],
                            ratio=(peer["time_s"] / cv["time_s"]) if cv and peer else None))
    return out


def build() -> str:
    """The pyspline build being measured: the commit it was built from, what its core is
    compiled for and where it is installed (the working tree's commit can differ from the build
    on PYTHONPATH)."""
    import pyspline
    from pyspline._build_info import BUILD, COMMIT
    return (f"pyspline {COMMIT or '(commit unknown)'}, {BUILD} build, at "
            f"{Path(pyspline.__file__).parent}")


def _write_csv(path, rows):
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)


def decade_axis(axis):
    """A log axis with a labelled decade and no minor tick labels (2x10^-2, 3x10^-2 ... crowd
    one another): limits at least a decade apart around the data's."""
    from matplotlib.ticker import NullFormatter
    lo, hi = sorted(axis.get_view_interval())
    if hi < 10 * lo:
        axis.set_view_interval(np.sqrt(lo * hi) / 3.2, np.sqrt(lo * hi) * 3.2, ignore=True)
    axis.set_minor_formatter(NullFormatter())


def _plot_wp(rows, notes, path=None):
    """Error against wall time per method and case, one panel per case; one legend for all
    (a method keeps its colour); failed runs are named in their panel's title, not drawn."""
    from matplotlib import colormaps
    from matplotlib.figure import Figure
    from pyspline.plots import style as ps
    cases = list(dict.fromkeys(r["case"] for r in rows))
    methods = list(dict.fromkeys(r["method"] for r in rows))
    colours = colormaps["tab20"].colors + colormaps["tab20b"].colors   # 40, none twice
    fig = Figure(figsize=(8 * len(cases), 8.5), layout="constrained")
    for ax, name in zip(fig.subplots(1, len(cases), squeeze=False)[0], cases):
        sub = [r for r in rows if r["case"] == name]
        for i, method in enumerate(methods):
            ok = [r for r in sub if r["method"] == method and r["status"] == "ok"]
            style = "-" if "CVODE" in method else ("--" if "fortran" in method else ":")
            ax.plot([r["time_s"] for r in ok], [max(r["err_Tm"], r["err_F"]) for r in ok],
                    style, marker="o", ms=3, label=method, color=colours[i % len(colours)])
        bad = {}
        for r in sub:
            if r["status"] != "ok":
                bad.setdefault(r["method"], []).append(f"{r['rtol']:g}")
        bad = [f"{m} at rtol {', '.join(rt)}" for m, rt in bad.items()]
        ax.set_xscale("log")
        ax.set_yscale("log")
        decade_axis(ax.xaxis)
        ax.set_xlabel("wall time of a run [s]")
        ax.set_ylabel("max relative error of T_m and F_j")
        ax.set_title(ps.wrap(f"{name}; failed, not drawn: {', '.join(bad)}" if bad else name,
                             7.5, 10), fontsize=10)
        ax.grid(True, which="both", lw=0.3)
    fig.legend(*fig.axes[0].get_legend_handles_labels(), loc="outside lower center", ncol=4,
               fontsize=7)
    fig.suptitle("\n".join(ps.wrap(n, 8 * len(cases) - 0.5, 8)
                           for n in ["Work-precision against a reference run:", *notes]),
                 fontsize=8)
    return ps.finish(fig, path)


def stability_map(out, quick=False, progress=True):
    """Sweep the mesh stiffness from the paper's calibrated value to the physical one and beyond,
    with c_m as given and as a damping ratio, and record which methods succeed."""
    from tqdm import tqdm
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    kms = [1e5, 1e7, 1e9] if quick else list(np.logspace(5, 10, 11))
    t_end = 0.004 if quick else 0.05
    budget = 20_000 if quick else 200_000
    base = load_case(cases_dir() / "paper_lx1e-4.nml", t_end=t_end,
                     n_out=int(round(6400 * t_end)) + 1, rtol=1e-6, atol=1e-8,
                     max_steps=budget, linear_tail=False)
    r_b = load(base).info()["r_b"]
    m_e = base["j_1"] * base["j_2"] / (base["j_1"] + base["j_2"]) / (base["z"] * r_b ** 2)
    methods = [("cvode", "bdf", False), ("cvode", "adams", False), ("cvode", "bdf", True),
               ("cvode", "bdf-stald", False), ("cvode", "adams-fixedpoint", False)] + \
              [("scipy", m, "fortran") for m in SCIPY_METHODS]
    rows = []
    jobs = [(d, k, m) for d in ("as given", "zeta = 0.05") for k in kms for m in methods]
    for damping, km, (solver, method, opt) in tqdm(jobs, desc="stability map",
                                                   disable=not progress):
        c_m = base["c_m"] if damping == "as given" else 2 * 0.05 * np.sqrt(km * m_e)
        case = base.replace(k_m=float(km), c_m=float(c_m))
        label = (f"CVODE {method}{' + roots' if opt is True else ''}" if solver == "cvode"
                 else f"scipy {method}")
        row = dict(damping=damping, k_m=km, c_m=c_m, method=label)
        t0 = time.perf_counter()
        try:
            if solver == "cvode":
                res = simulate(case.replace(roots=bool(opt), **_cvode_kw(method)))
                row.update(status="ok", steps=res.stats["steps"], rhs_evals=res.stats["rhs_evals"],
                           err_test_fails=res.stats["err_test_fails"],
                           conv_fails=res.stats["nonlin_conv_fails"])
            else:
                _, _, _, nfev = run_scipy(case, method, 1e-6, "fortran", None, budget)
                row.update(status="ok", steps=-1, rhs_evals=nfev)
        except (SplineError, Budget) as exc:
            msg = str(exc)
            flag = next((w for w in msg.replace("(", " ").split() if w.startswith("CV_")), None)
            row.update(status=f"FAILED: {flag or msg[:100]}")
        row["time_s"] = time.perf_counter() - t0
        rows.append(row)
    _write_csv(out / "stability.csv", rows)
    _plot_stability(rows, out / "stability.png")
    return rows


def _plot_stability(rows, path=None):
    """log10 of each run's wall time per method and k_m, one panel per damping, on one colour
    scale; X: a failed run."""
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure
    from pyspline.plots import style as ps
    dampings = list(dict.fromkeys(r["damping"] for r in rows))
    methods = list(dict.fromkeys(r["method"] for r in rows))
    kms = sorted({r["k_m"] for r in rows})
    logt = [np.log10(r["time_s"]) for r in rows if r["status"] == "ok"]
    norm = Normalize(min(logt, default=0.0), max(logt, default=1.0))
    fig = Figure(figsize=(7.5 * len(dampings) + 1, 5), layout="constrained")
    axs = fig.subplots(1, len(dampings), squeeze=False, sharey=True)[0]
    for ax, d in zip(axs, dampings):
        grid = np.full((len(methods), len(kms)), np.nan)
        failed = [r for r in rows if r["damping"] == d and r["status"] != "ok"]
        for r in rows:
            if r["damping"] == d and r["status"] == "ok":
                grid[methods.index(r["method"]), kms.index(r["k_m"])] = np.log10(r["time_s"])
        im = ax.imshow(grid, aspect="auto", cmap="viridis", origin="upper", norm=norm)
        for r in failed:
            ax.text(kms.index(r["k_m"]), methods.index(r["method"]), "X", ha="center",
                    va="center", color="red", fontsize=11, fontweight="bold")
        ax.set_xticks(range(len(kms)), [f"{k:.0e}" for k in kms], fontsize=7,
                      rotation=60 if len(kms) > 6 else 0)
        ax.set_yticks(range(len(methods)), methods, fontsize=7)
        ax.set_xlabel("mesh stiffness k_m [N/m]")
        ax.set_title(f"c_m {d}: {len(failed)} of {len(kms) * len(methods)} runs failed (X)",
                     fontsize=9)
    fig.colorbar(im, ax=axs, label="log10 of the wall time of a run [s]")
    return ps.finish(fig, path)
