"""Figures like the paper's (matplotlib, PNG): one file per paper figure group."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

from ..plots import style as ps  # noqa: E402
from ..plots import eng  # noqa: E402
from . import SETTLE, poincare, poincare_count  # noqa: E402


def _time_panel(ax, res, y, label, unit):
    """y(t); a y that is round-off (plots.style.roundoff_span) on +-1 % around its value, noted."""
    ax.plot(res.t, y, lw=0.7)
    ax.ticklabel_format(axis="y", useOffset=False)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel(f"{label} [{unit}]")
    span = ps.roundoff_span(y, rtol=res.case["rtol"])
    if span is not None:
        ax.set_ylim(*ps.flat_limits(float(np.mean(y)), 0.0))
        ps.note(ax, ps.no_content(span, unit))


def _tooth_bars(ax_f, ax_fx, res):
    """F_j and F_jx at the instant of largest load, with max/min envelopes over t > SETTLE."""
    k = int(np.argmax(np.abs(res.Tm)))
    j = np.arange(1, res.F.shape[1] + 1)
    late = res.t > SETTLE
    for ax, q, name in ((ax_f, res.F, "F_j"), (ax_fx, res.Fx, "F_jx")):
        ax.bar(j, q[k], color="tab:blue", label=f"at t = {res.t[k]:.4f} s (largest load)")
        if late.any():
            ax.plot(j, q[late].max(axis=0), "v", color="tab:red", ms=4, label="max over time")
            ax.plot(j, q[late].min(axis=0), "^", color="tab:green", ms=4, label="min over time")
        ax.set_xlabel("tooth j")
        ax.set_ylabel(f"{name} [N]")
        ax.xaxis.set_major_locator(MaxNLocator(nbins=9, integer=True))   # 16 numbers crowd
        ax.axhline(0, color="k", lw=0.5)
    ax_f.legend(fontsize=7, loc="lower right")
    total, scale = res.Fx[k].sum(), np.abs(res.Fx[k]).sum()
    # a balanced sum is round-off of the teeth's forces: say so, not its digits
    said = (f"0 to round-off (sum of |F_jx| {eng(scale, 3)} N)" if abs(total) <= 1e-9 * scale
            else f"{eng(total, 3)} N")
    ax_fx.set_title(f"sum of F_jx at that instant: {said}", fontsize=8)


def dynamics_figure(res, path, title):
    """Relative displacement, phase plane, Poincare map, per-tooth F_j and F_jx, T_m(t)."""
    fig, axs = plt.subplots(2, 3, figsize=(15, 8.5))
    axs = axs.ravel()
    _time_panel(axs[0], res, res.D2 * 1e3, "relative displacement D_2 (line of action)", "mm")
    axs[1].plot(res.D2 * 1e3, res.vD2, lw=0.5)
    axs[1].set_xlabel("D_2 [mm]")
    axs[1].set_ylabel("dD_2/dt [m/s]")
    axs[1].set_title("phase plane")
    p = poincare(res)
    nd = poincare_count(res)
    axs[2].plot(p[:, 0] * 1e3, p[:, 1], "o", ms=3)
    axs[2].set_xlabel("D_2 [mm]")
    axs[2].set_ylabel("dD_2/dt [m/s]")
    axs[2].set_title(ps.wrap(f"Poincare map (once per revolution, t > {SETTLE} s); second half: "
                             f"{nd} distinct point{'s' if nd != 1 else ''}", 4.2, 9), fontsize=9)
    axs[2].xaxis.set_major_locator(MaxNLocator(nbins=5))
    _tooth_bars(axs[3], axs[4], res)
    _time_panel(axs[5], res, res.Tm, "meshing torque T_m", "N m")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def misalignment_figure(results, names, path):
    fig, axs = plt.subplots(len(names), 4, figsize=(18, 4.2 * len(names)), squeeze=False)
    for row, name in zip(axs, names):
        res = results[name]
        lx = res.case["l_x"]
        _time_panel(row[0], res, res.D2 * 1e3, f"D_2, l_x = {eng(lx)} m", "mm")
        p = poincare(res)
        row[1].plot(res.D2 * 1e3, res.vD2, lw=0.4, color="0.6")
        row[1].plot(p[:, 0] * 1e3, p[:, 1], "o", ms=3, color="tab:red",
                    label=f"Poincare (second half): {poincare_count(res)} distinct")
        row[1].set_xlabel("D_2 [mm]")
        row[1].set_ylabel("dD_2/dt [m/s]")
        row[1].legend(fontsize=7)
        _tooth_bars(row[2], row[3], res)
        ax = row[0].twinx()
        ax.plot(res.t, res.kv, lw=0.5, color="tab:orange")
        ax.set_ylabel("k_v [-] (orange)")
    fig.suptitle("Parallel misalignment (paper Figs. 5-6)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def temperature_figure(results, names, path, title=None):
    fig, axs = plt.subplots(len(names), 4, figsize=(18, 4.2 * len(names)), squeeze=False)
    for row, name in zip(axs, names):
        res = results[name]
        _tooth_bars(row[0], row[1], res)
        row[0].set_title(f"{name}: T_M = {eng(res.case['t_bulk'])} degC, "
                         f"l_x = {eng(res.case['l_x'])} m",
                         fontsize=9)
        _time_panel(row[2], res, res.Tm, "meshing torque T_m", "N m")
        _time_panel(row[3], res, res.kv, "dynamic load coefficient k_v", "-")
    fig.suptitle(title or "Bulk temperature, contact temperature coupled into the backlash "
                 "(paper Figs. 7-8)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def flash_figure(results, names, path):
    fig, axs = plt.subplots(1, 3, figsize=(17, 4.8))
    last = results[names[-1]]
    for j in range(last.Tf.shape[1]):
        axs[0].plot(last.t, last.Tf[:, j], lw=0.5)
    axs[0].set_xlabel("time t [s]")
    axs[0].set_ylabel("flash temperature T_fj [degC]")
    axs[0].set_title(f"every tooth, l_x = {eng(last.case['l_x'])} m", fontsize=9)
    for name in names:
        res = results[name]
        axs[1].plot(res.t, res.Tf.max(axis=1), lw=0.6, label=f"l_x = {eng(res.case['l_x'])} m")
    axs[1].set_xlabel("time t [s]")
    axs[1].set_ylabel("max over teeth of T_fj [degC]")
    axs[1].set_yscale("symlog", linthresh=1e-6)
    axs[1].legend(fontsize=7)
    lx = [results[n].case["l_x"] for n in names]
    tmax = [results[n].Tf.max() for n in names]
    axs[2].plot(np.array(lx) * 1e3, tmax, "o-")
    axs[2].set_xlabel("misalignment l_x [mm]")
    axs[2].set_ylabel("largest flash temperature [degC]")
    fig.suptitle(f"Flash temperature (paper Figs. 9-10), f_m = {eng(last.case['f_m'])}")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def draw_all(results, out, groups):
    out = Path(out)
    drawn = [
        dynamics_figure(results["paper_ideal"], out / "fig4_ideal.png",
                        "Ideal spline pair: no misalignment, no thermal effects (paper Fig. 4)"),
        misalignment_figure(results, groups["fig5_6_misalignment"], out / "fig5_6_misalignment.png"),
        temperature_figure(results, groups["fig7_8_bulk_temperature"],
                           out / "fig7_8_bulk_temperature.png"),
        flash_figure(results, groups["fig9_10_flash_temperature"],
                     out / "fig9_10_flash_temperature.png"),
    ]
    if "physical_lx1e-4" in results:
        drawn.append(temperature_figure(results, ["physical_lx1e-4"], out / "physical_lx1e-4.png",
                                        "Physical k_m = 1.92e9 N/m (potential energy method), "
                                        "started at its static equilibrium: steady"))
    return drawn
