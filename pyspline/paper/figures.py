"""Figures like the paper's (matplotlib, PNG): one file per paper figure group. Each `*_figure`
returns its Figure (no pyplot state); `draw_all` writes them."""
from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from ..plots import style as ps
from ..plots import eng
from . import SETTLE, poincare, poincare_count

LEGEND_ROOM = 0.3   # the share of a bar panel's height kept free of data for its legend


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


def tooth_axis(ax, z):
    """Teeth 1..z on the x axis: ticks at tooth 1 and every step-th tooth (at most 9), none at
    0 or past z."""
    step = -(-z // 8)
    ax.set_xticks(np.unique(np.r_[1, np.arange(step, z + 1, step)]))
    ax.set_xlim(0.4, z + 0.6)
    ax.set_xlabel("tooth j")


def _legend_in_room(ax):
    """The legend in room added beyond the data, on the side the bars leave free (they grow
    from 0 toward the larger of the limits' magnitudes): it covers no bar and no marker."""
    lo, hi = ax.get_ylim()
    room = LEGEND_ROOM / (1 - LEGEND_ROOM) * (hi - lo)
    down = abs(hi) <= abs(lo)
    ax.set_ylim(lo, hi + room) if down else ax.set_ylim(lo - room, hi)
    ax.legend(fontsize=7, loc="upper right" if down else "lower right")


def _tooth_bars(ax_f, ax_fx, res):
    """F_j and F_jx at the instant of largest load, with max/min envelopes over t > SETTLE."""
    k = int(np.argmax(np.abs(res.Tm)))
    z = res.F.shape[1]
    j = np.arange(1, z + 1)
    late = res.t > SETTLE
    for ax, q, name in ((ax_f, res.F, "F_j"), (ax_fx, res.Fx, "F_jx")):
        ax.bar(j, q[k], color="tab:blue", label=f"at t = {res.t[k]:.4f} s (largest load)")
        if late.any():
            ax.plot(j, q[late].max(axis=0), "v", color="tab:red", ms=4,
                    label=f"max over t > {SETTLE} s")
            ax.plot(j, q[late].min(axis=0), "^", color="tab:green", ms=4,
                    label=f"min over t > {SETTLE} s")
        ax.set_ylabel(f"{name} [N]")
        tooth_axis(ax, z)
        ax.axhline(0, color="k", lw=0.5)
    _legend_in_room(ax_f)
    total, scale = res.Fx[k].sum(), np.abs(res.Fx[k]).sum()
    # a balanced sum is round-off of the teeth's forces: say so, not its digits
    said = (f"0 to round-off (sum of |F_jx| {eng(scale, 3)} N)" if abs(total) <= 1e-9 * scale
            else f"{eng(total, 3)} N")
    ax_fx.set_title(f"sum of F_jx at that instant: {said}", fontsize=8)


def _panels(nrows, ncols, width, height):
    fig = Figure(figsize=(width, height), layout="constrained")
    return fig, fig.subplots(nrows, ncols, squeeze=False)


def dynamics_figure(res, title) -> Figure:
    """Relative displacement, phase plane, Poincare map, per-tooth F_j and F_jx, T_m(t)."""
    fig, axs = _panels(2, 3, 15, 8.5)
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
    return fig


def misalignment_figure(results, names) -> Figure:
    fig, axs = _panels(len(names), 4, 18, 4.2 * len(names))
    for row, name in zip(axs, names):
        res = results[name]
        _time_panel(row[0], res, res.D2 * 1e3, "D_2 (blue)", "mm")
        row[0].set_title(f"{name}: l_x = {eng(res.case['l_x'])} m", fontsize=9)
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
    return fig


def temperature_figure(results, names, title=None) -> Figure:
    fig, axs = _panels(len(names), 4, 18, 4.2 * len(names))
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
    return fig


def flash_figure(results, names) -> Figure:
    fig, axs = _panels(1, 3, 17, 4.8)
    axs = axs[0]
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
    top = max(float(results[n].Tf.max()) for n in names)
    if top > 0:     # log over the two decades below the largest, linear below them
        axs[1].set_yscale("symlog", linthresh=10.0 ** np.floor(np.log10(top)) / 100)
    axs[1].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    lx = [results[n].case["l_x"] for n in names]
    tmax = [results[n].Tf.max() for n in names]
    axs[2].plot(np.array(lx) * 1e3, tmax, "o-")
    axs[2].set_xlabel("misalignment l_x [mm]")
    axs[2].set_ylabel("largest flash temperature [degC]")
    fig.suptitle(f"Flash temperature (paper Figs. 9-10), f_m = {eng(last.case['f_m'])}")
    return fig


def figures(results, groups) -> dict:
    """The paper's figures of `results` by file name (without .png)."""
    figs = {
        "fig4_ideal": dynamics_figure(results["paper_ideal"], "Ideal spline pair: no "
                                      "misalignment, no thermal effects (paper Fig. 4)"),
        "fig5_6_misalignment": misalignment_figure(results, groups["fig5_6_misalignment"]),
        "fig7_8_bulk_temperature": temperature_figure(results, groups["fig7_8_bulk_temperature"]),
        "fig9_10_flash_temperature": flash_figure(results, groups["fig9_10_flash_temperature"]),
    }
    if "physical_lx1e-4" in results:
        figs["physical_lx1e-4"] = temperature_figure(
            results, ["physical_lx1e-4"], "Physical k_m = 1.92e9 N/m (potential energy method), "
            "started at its static equilibrium: steady")
    return figs


def draw_all(results, out, groups) -> list[Path]:
    out = Path(out)
    drawn = []
    for name, fig in figures(results, groups).items():
        ps.finish(fig, out / f"{name}.png")
        drawn.append(out / f"{name}.png")
    return drawn
