"""Figures of parameter sweeps: bifurcation diagrams (one field, or one panel per value of a
second), maps of a quantity over a two-field grid, Lyapunov exponents, waterfalls of spectra,
and `sweep_figures`, which draws them for a sweep dataset into a directory (`pyspline sweep`).

Each function takes numpy arrays, or an xarray.Dataset (any mapping from names to arrays works
the same way; with a Dataset the units come from each variable's ``attrs['units']``), returns a
matplotlib Figure and, when given `path`, writes it there as PNG (Agg, no pyplot). Spectra,
periods and exponents are computed by pyspline.analysis and passed in as arrays.
"""
from __future__ import annotations

import re
import sys
import warnings
from pathlib import Path

import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm, TwoSlopeNorm
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from .. import analysis
from . import style as ps

__all__ = ["bifurcation", "bifurcation_grid", "lyapunov_vs_param", "param_map",
           "sweep_figures", "waterfall"]


def _peak_hold(f, a, f_max, columns=500):
    """Keep the bins up to f_max; when there are more than `columns`, merge neighbours into
    `columns` groups keeping the largest amplitude, so that narrow tones stay visible at screen
    resolution. f, a: (rows, bins)."""
    keep = (f <= f_max).any(axis=0)
    f, a = f[:, keep], a[:, keep]
    g = int(np.ceil(f.shape[1] / columns))
    if g <= 1:
        return f, a
    pad = (-f.shape[1]) % g
    f = np.pad(f, ((0, 0), (0, pad)), constant_values=np.nan)
    a = np.pad(a, ((0, 0), (0, pad)), constant_values=np.nan)
    shape = (f.shape[0], f.shape[1] // g, g)
    with warnings.catch_warnings():       # all-NaN groups (beyond a run's Nyquist) stay NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmean(f.reshape(shape), axis=2), np.nanmax(a.reshape(shape), axis=2)


# --------------------------------------------------------------------------- bifurcation

def bifurcation(ds, param: str, coord: str = "section_D2", period: str = "period",
                path=None, title: str | None = None, units: dict | None = None) -> Figure:
    """Bifurcation diagram: the section coordinate ``ds[coord]`` (dims (param,
    'section_point'), NaN-padded) against the swept ``ds[param]`` (dim (param,)), each point
    coloured by ``ds[period]`` (dim (param,)): period 1, 2, 3, 4, > 4 in distinct colours, not
    periodic (0, negative or NaN) in grey. Units come from each variable's attrs['units'] or
    from `units` ({name: unit}, for a dict of arrays; the coordinate defaults to m). Axes in
    m, m/s, N or N m get a readable SI prefix (um, mm/s, kN)."""
    p = ps.array(ds, param)
    y = ps.array(ds, coord, dims=(param, "section_point") if hasattr(ds, "dims") else None)
    per = ps.array(ds, period)
    if y.ndim == 1:
        y = y[:, None]
    if y.shape[0] != p.shape[0] or per.shape != p.shape:
        raise ValueError(f"{coord} must have shape ({len(p)}, n_points) and {period} ({len(p)},),"
                         f" got {y.shape} and {per.shape}")
    factor, unit = ps.prefix(y, ps.unit_of(ds, coord, "m", units))
    px, ux = ps.prefix(p, ps.unit_of(ds, param, "", units))
    long = ps.long_name(ds, coord)
    fig = Figure(figsize=(9, 5.5), layout="constrained")
    ax = fig.add_subplot()
    handles = _bifurcation_points(ax, p / px, y / factor, per)
    ax.set_xlabel(ps.label(ds, param, factor_unit=ux))
    ax.set_ylabel(ps.wrap(ps.label(ds, coord, factor_unit=unit), 4.5))
    # beside the panel: a sweep's points can fill it (no 'best' place covers none)
    fig.legend(handles=handles, fontsize=8, loc="outside lower center", ncols=len(handles),
               title="runs by period", title_fontsize=8)
    ax.set_title(ps.wrap(title or f"bifurcation diagram: {long} vs {ps.long_name(ds, param)}",
                         8.5, 12))
    return ps.finish(fig, path)


#: a section sequence not periodic while the Lyapunov exponent is negative (summary.NOT_SETTLED)
NOT_SETTLED_NAME = "not settled (exponent < 0: lengthen t_transient)"


def _period_class(per) -> np.ndarray:
    """0: not periodic (0, NaN); 1..4: the period; 5: period > 4; 6: not settled (negative:
    summary.NOT_SETTLED)."""
    per = np.asarray(per, dtype=float)
    cls = np.where(np.isfinite(per) & (per > 0), np.minimum(np.nan_to_num(per), 5), 0)
    return np.where(per < 0, 6, cls).astype(int)


def _period_name(c: int) -> str:
    return {0: "not periodic", 5: "period > 4", 6: NOT_SETTLED_NAME}.get(c, f"period {c}")


def _bifurcation_points(ax, x, y, per, counts=True, ms=9) -> list:
    """Scatter y (n, n_points) against x (n,) on ax, coloured by period class; legend handles."""
    cls = _period_class(per)
    handles = []
    drawn = np.isfinite(y).any(axis=1)      # a point that did not run has nothing to show
    for c in (0, 6, 1, 2, 3, 4, 5):
        rows = (cls == c) & drawn
        if not rows.any():
            continue
        xs = np.repeat(x[rows], y.shape[1])
        ys = y[rows].ravel()
        ok = np.isfinite(ys)
        colour = ps.NOT_PERIODIC if c == 0 else ps.PERIOD_COLOURS[c]    # 6: not settled
        ax.scatter(xs[ok], ys[ok], s=ms / 3 if c == 0 else ms, c=colour, lw=0,
                   alpha=0.6 if c == 0 else 1.0, zorder=1 if c == 0 else 2, rasterized=True)
        label = f"{_period_name(c)} ({rows.sum()})" if counts else _period_name(c)
        handles.append(Line2D([], [], ls="", marker="o", ms=6, color=colour, label=label))
    ax.grid(alpha=0.3, lw=0.5)
    if not drawn.all():                     # say it: an empty stretch is no finding
        ps.note(ax, f"{(~drawn).sum()} of {len(drawn)} runs without a result", loc="lower right")
    return handles


def _axis_values(ds, name, units=None):
    """(numeric positions, tick labels or None, factor, unit) of a coordinate; text values
    (e.g. thermal = 'none', 'bulk') are placed at 0, 1, 2 ... and labelled."""
    raw = np.asarray(ds[name])
    if raw.dtype.kind in "biuf":
        v = raw.astype(float)
        factor, unit = ps.prefix(v, ps.unit_of(ds, name, "", units))
        return v / factor, None, factor, unit
    return (np.arange(len(raw), dtype=float), [str(r) for r in raw], 1.0,
            ps.unit_of(ds, name, "", units))


def bifurcation_grid(ds, param: str, by: str, coord: str = "section_D2",
                     period: str = "period", max_panels: int = 12, path=None,
                     title: str | None = None, units: dict | None = None) -> Figure:
    """Bifurcation diagrams of a two-field sweep: one panel per value of ``ds[by]`` (at most
    `max_panels`, evenly chosen, first and last included), each showing ``ds[coord]`` (dims
    (param, by, 'section_point')) against ``ds[param]``, coloured by ``ds[period]`` (dims
    (param, by)) as in `bifurcation`. Panels share both axes; one legend for all."""
    p = ps.array(ds, param)
    b = np.asarray(ds[by])
    y = ps.array(ds, coord, dims=(param, by, "section_point") if hasattr(ds, "dims") else None)
    per = ps.array(ds, period, dims=(param, by) if hasattr(ds, "dims") else None)
    if y.ndim == 2:
        y = y[:, :, None]
    if y.shape[:2] != (len(p), len(b)) or per.shape != (len(p), len(b)):
        raise ValueError(f"{coord} must have shape ({len(p)}, {len(b)}, n_points) and {period} "
                         f"({len(p)}, {len(b)}), got {y.shape} and {per.shape}")
    pick = np.unique(np.linspace(0, len(b) - 1, min(len(b), max(1, max_panels)))
                     .round().astype(int))
    factor, unit = ps.prefix(y, ps.unit_of(ds, coord, "m", units))
    px, ux = ps.prefix(p, ps.unit_of(ds, param, "", units))
    bv, blabels, bf, bu = _axis_values(ds, by, units)
    n = len(pick)
    ncols = min(4, int(np.ceil(np.sqrt(n))))
    nrows = int(np.ceil(n / ncols))
    fig = Figure(figsize=(3.6 * ncols + 1.0, 2.9 * nrows + 1.2), layout="constrained")
    axes = fig.subplots(nrows, ncols, sharex=True, sharey=True, squeeze=False)
    seen = {}
    for k, j in enumerate(pick):
        ax = axes.flat[k]
        for h in _bifurcation_points(ax, p / px, y[:, j, :] / factor, per[:, j], counts=False,
                                     ms=6):
            seen.setdefault(h.get_label(), h)
        value = blabels[j] if blabels else ps.eng(bv[j]) + (f" {bu}" if bu else "")
        ax.set_title(f"{by} = {value}", fontsize=9)
    for ax in axes.flat[n:]:
        ax.set_axis_off()
    for k in range(max(0, n - ncols), n):     # the lowest panel of each column
        axes.flat[k].tick_params(labelbottom=True)
        axes.flat[k].set_xlabel(ps.label(ds, param, factor_unit=ux), fontsize=9)
    for ax in axes[:, 0]:
        ax.set_ylabel(ps.wrap(ps.label(ds, coord, factor_unit=unit), 2.5, 9), fontsize=9)
    order = [_period_name(c) for c in (1, 2, 3, 4, 5, 0)]
    handles = [seen[name] for name in order if name in seen]
    fig.legend(handles=handles, fontsize=8, loc="outside lower center", ncols=len(handles),
               frameon=False)
    shown = "" if n == len(b) else f" ({n} of {len(b)} values of {by})"
    fig.suptitle(ps.wrap((title or f"bifurcation diagrams: {ps.long_name(ds, coord)} vs "
                          f"{ps.long_name(ds, param)}") + shown, 3.6 * ncols + 0.5, 12))
    return ps.finish(fig, path)


def param_map(ds, var: str, x: str, y: str, path=None, title: str | None = None,
              units: dict | None = None) -> Figure:
    """A quantity of a two-field sweep as a map over the grid: ``ds[var]`` (dims (x, y))
    with ``ds[x]`` across and ``ds[y]`` up, one cell per run. A period (`var` named
    'period...') is drawn in the period colours of `bifurcation` (not periodic grey, no result
    white); a quantity of both signs (e.g. a Lyapunov exponent) on a blue-red scale centred on
    zero; anything else on viridis. Cells without a value (NaN: failed runs) are hatched (white
    is a colour of the blue-red scale: zero)."""
    v = ps.array(ds, var, dims=(x, y) if hasattr(ds, "dims") else None)
    xv, xlab, _, xu = _axis_values(ds, x, units)
    yv, ylab, _, yu = _axis_values(ds, y, units)
    if v.shape != (len(xv), len(yv)):
        raise ValueError(f"{var} must have shape ({len(xv)}, {len(yv)}), got {v.shape}")
    fig = Figure(figsize=(9, 6.5), layout="constrained")
    ax = fig.add_subplot()
    ax.set_facecolor("white")
    ax.patch.set(hatch="xx", edgecolor="0.75")     # shows where a cell has no value
    X, Y = np.meshgrid(xv, yv, indexing="ij")
    if var.startswith("period"):
        cls = np.where(np.isfinite(v), _period_class(v), -1).astype(float)
        cls[cls < 0] = np.nan
        colours = [ps.NOT_PERIODIC] + [ps.PERIOD_COLOURS[c] for c in (1, 2, 3, 4, 5, 6)]
        mesh = ax.pcolormesh(X, Y, np.ma.masked_invalid(cls), shading="nearest",
                             cmap=ListedColormap(colours),
                             norm=BoundaryNorm(np.arange(-0.5, 7.5), 7), edgecolors="w",
                             linewidth=0.3 if max(v.shape) <= 30 else 0, rasterized=True)
        cb = fig.colorbar(mesh, ax=ax, pad=0.01, ticks=np.arange(7))
        cb.ax.set_yticklabels(["not periodic", "1", "2", "3", "4", "> 4", "not settled"])
        cb.set_label("period of the section sequence (hatched: no result)")
    else:
        finite = v[np.isfinite(v)]
        lo, hi = (finite.min(), finite.max()) if finite.size else (0.0, 1.0)
        if lo < 0 < hi:
            norm, cmap = TwoSlopeNorm(0.0, lo, hi), "RdBu_r"
        else:
            norm, cmap = None, "viridis"
        mesh = ax.pcolormesh(X, Y, np.ma.masked_invalid(v), shading="nearest", cmap=cmap,
                             norm=norm, rasterized=True)
        cb = fig.colorbar(mesh, ax=ax, pad=0.01)
        cb.set_label(ps.label(ds, var, units=units)
                     + (" (hatched: no result)" if np.isnan(v).any() else ""))
    for lab, set_ticks, set_labels, pos in ((xlab, ax.set_xticks, ax.set_xticklabels, xv),
                                            (ylab, ax.set_yticks, ax.set_yticklabels, yv)):
        if lab:
            set_ticks(pos)
            set_labels(lab)
    ax.set_xlabel(ps.label(ds, x, factor_unit=xu))
    ax.set_ylabel(ps.label(ds, y, factor_unit=yu))
    ax.set_title(ps.wrap(title or f"{ps.long_name(ds, var)} over {x} and {y}", 8.5, 12))
    return ps.finish(fig, path)


# --------------------------------------------------------------------------- Lyapunov

def _chaotic_stretches(x, chaotic) -> list:
    """(from, to) of each run of neighbouring chaotic points in x order, each point's stretch
    reaching half-way to its neighbours (half the nearest step at the ends)."""
    order = np.argsort(x)
    xs, c = x[order], chaotic[order]
    if len(xs) < 2:
        return [(xs[0], xs[0])] if c.any() else []
    mid = (xs[1:] + xs[:-1]) / 2
    edges = np.r_[2 * xs[0] - mid[0], mid, 2 * xs[-1] - mid[-1]]
    runs = np.flatnonzero(np.diff(np.r_[0, c.astype(int), 0]))      # starts, ends alternate
    return [(edges[i], edges[j]) for i, j in zip(runs[::2], runs[1::2])]


def lyapunov_vs_param(ds, param: str, var: str = "lyapunov", path=None,
                      title: str | None = None, units: dict | None = None) -> Figure:
    """Largest Lyapunov exponent ``ds[var]`` [1/s] against the swept ``ds[param]``, with a zero
    line, each point's verdict (`analysis.is_chaotic`: filled red markers on a shaded stretch of
    x for chaotic points, hollow markers for the others) and, on the right axis (log scale), the
    predictability horizon 1/lambda [s] of the chaotic points. The verdict uses the spread
    ``ds[var + '_spread']`` (error bars of half of it) and the slope ``ds[var + '_slope']`` of
    the Benettin record when the dataset has them (a sweep's do; without a slope the verdict is
    lambda > spread, without a spread lambda > 0), so an estimate of +2 1/s with a spread of
    20 is not called chaos, nor a chaotic transient that died out within the window.
    `units` as in `bifurcation`."""
    p = ps.array(ds, param)
    lam = ps.array(ds, var)
    unit = ps.unit_of(ds, var, "1/s", units)
    px, ux = ps.prefix(p, ps.unit_of(ds, param, "", units))
    x = p / px
    fig = Figure(figsize=(9, 5.5), layout="constrained")
    ax = fig.add_subplot()
    ax.axhline(0, color="k", lw=0.8)
    spread = ps.array(ds, var + "_spread") if var + "_spread" in ds else None
    slope = ps.array(ds, var + "_slope") if var + "_slope" in ds else lam
    chaos = analysis.is_chaotic(lam, 0.0 if spread is None else spread, slope)
    ax.errorbar(x, lam, yerr=None if spread is None else spread / 2, fmt="-", lw=1,
                color="tab:blue", ecolor="0.5", capsize=2)
    for a, b in _chaotic_stretches(x, chaos):
        ax.axvspan(a, b, color="tab:red", alpha=0.12, lw=0)
    marks = dict(ls="", marker="o", ms=6)
    ordered = dict(marks, mfc="w", mec="tab:blue", label="not chaotic")
    chaotic = dict(marks, color="tab:red", label="chaotic: lambda and the slope of its log "
                   "separation > the spread (shaded)")
    ax.plot(x[~chaos], lam[~chaos], **ordered)
    ax.plot(x[chaos], lam[chaos], **chaotic)
    ax.set_xlabel(ps.label(ds, param, factor_unit=ux))
    ax.set_ylabel(f"largest Lyapunov exponent lambda [{unit}]")
    ax.grid(alpha=0.3, lw=0.5)
    h_unit = "s" if unit == "1/s" else f"1/({unit})"
    handles = [Line2D([], [], **chaotic), Line2D([], [], **ordered)]
    if spread is not None:
        handles.append(Line2D([], [], color="0.5", marker="|", ms=8, ls="",
                              label="error bar: spread of the running estimate"))
    if chaos.any():
        ax2 = ax.twinx()
        ax2.plot(x[chaos], 1.0 / lam[chaos], "s", mfc="none", mec="tab:orange", ms=6)
        ax2.set_yscale("log")
        ax2.set_ylabel(f"predictability horizon 1/lambda [{h_unit}]", color="tab:orange")
        ax2.tick_params(axis="y", colors="tab:orange", which="both")
        handles.append(Line2D([], [], ls="", marker="s", mfc="none", mec="tab:orange",
                              label="horizon 1/lambda of the chaotic points (right axis)"))
    fig.legend(handles=handles, fontsize=8, loc="outside lower center", ncols=2, frameon=False)
    ax.set_title(title or f"largest Lyapunov exponent vs {ps.long_name(ds, param)}")
    return ps.finish(fig, path)


# --------------------------------------------------------------------------- waterfall

def waterfall(ds, speed: str = "speed_rpm", freq: str = "freq_hz", amp: str = "amplitude",
              z: int | None = None, max_order: float | None = None, path=None,
              style: str = "map", floor: float = 1e-4, title: str | None = None,
              units: dict | None = None, duration: float | None = None,
              scale: float | None = None, rtol: float = 1e-8) -> Figure:
    """Spectra against speed: frequency [Hz] on x, speed [rpm] on y.

    ``ds[amp]`` has dims (speed, freq); ``ds[freq]`` is 1-D (one frequency grid for all) or
    (speed, freq). Amplitudes are on a log scale from `floor` times the largest one up: as
    colour (style 'map', default) or as the height of one line per speed above its speed
    (style 'lines', full height 0.9 of the smallest speed step). Neighbouring bins are merged
    keeping the largest (peak hold) down to about 500 columns, so narrow tones stay visible.
    Shaft orders 1x, 2x (grey/white) and, given `z`, the tooth-pass orders Zx, 2Zx (red) are
    dashed diagonal lines f = k rpm / 60. The frequency axis ends at `max_order` shaft orders of
    the highest speed (default 2.5 Z if `z` is given), and never beyond the data: the highest
    frequency of any speed with a finite amplitude (its Nyquist frequency; amplitudes beyond it
    are NaN). A tooth pass Z x |rpm| / 60 above the data of its speed is named on the figure
    and warned about (SplineWarning); given `duration`, the sampled time [s] of each run
    (t_end - t0 - t_transient), with the n_out that resolves it. Given `scale`, the signal's
    size (e.g. the largest RMS of T_m), a map whose largest amplitude is round-off by the rule
    of the run plots (`style.roundoff_amplitude`, with the runs' `rtol`) says so on it."""
    rpm = ps.array(ds, speed)
    a = ps.array(ds, amp, dims=(speed, freq) if hasattr(ds, "dims") else None)
    f = ps.array(ds, freq)
    if f.ndim == 1:
        f = np.broadcast_to(f, a.shape)
    if a.shape != f.shape or a.ndim != 2 or a.shape[0] != rpm.shape[0]:
        raise ValueError(f"{amp} must have shape ({len(rpm)}, n_freq) matching {freq}, got "
                         f"{a.shape} and {f.shape}")
    if style not in ("map", "lines"):
        raise ValueError(f"style must be 'map' or 'lines', got {style!r}")
    order = np.argsort(rpm)
    rpm, a, f = rpm[order], a[order], f[order]
    if max_order is None and z:
        max_order = 2.5 * z
    f_end = _data_end(f, a)
    f_max = np.nanmax(f_end)
    if max_order is not None:
        f_max = min(f_max, max_order * np.abs(rpm).max() / 60.0)
    words = _beyond_data(z, rpm, f_end, duration)
    f, a = _peak_hold(f, a, f_max)
    amp_unit = ps.unit_of(ds, amp, "", units)
    top = np.nanmax(a)
    top = top if top > 0 else 1.0
    fig = Figure(figsize=(10, 6.5), layout="constrained")
    ax = fig.add_subplot()
    dark = style == "map"
    if dark:
        rr = np.broadcast_to(rpm[:, None], a.shape)
        if len(rpm) == 1:               # one speed: a band of +- 2 % around it
            half = 0.02 * max(abs(rpm[0]), 1.0)
            f, a, rr = np.vstack([f, f]), np.vstack([a, a]), np.vstack([rr - half, rr + half])
        mesh = ax.pcolormesh(f, rr, np.clip(a, top * floor, None), shading="nearest",
                             norm=LogNorm(vmin=top * floor, vmax=top), cmap="magma",
                             rasterized=True)
        cb = fig.colorbar(mesh, ax=ax, pad=0.01)
        cb.set_label(f"amplitude [{amp_unit}]" if amp_unit else "amplitude")
    else:
        step = np.diff(rpm).min() if len(rpm) > 1 else 1.0
        decades = -np.log10(floor)
        for r, fi, ai in zip(rpm, f, a):
            h = np.clip(np.log10(np.clip(ai, top * floor, None) / top) / decades + 1, 0, 1)
            ax.fill_between(fi, r, r + 0.9 * step * h, color="tab:blue", alpha=0.25, lw=0)
            ax.plot(fi, r + 0.9 * step * h, lw=0.7, color="tab:blue")
        ax.text(0.99, 0.01, f"line height: log scale, {top * floor:.2g} to {top:.3g} "
                f"{amp_unit}".rstrip(), transform=ax.transAxes, ha="right", va="bottom",
                fontsize=8, bbox=dict(fc="w", ec="none", alpha=0.8))
    ax.set_xlim(0, f_max)
    y_lo, y_hi = ax.get_ylim()
    for k, text, st in ps.order_marks(z):
        colour = "w" if dark and st is ps.SHAFT_STYLE else st["color"]
        ax.plot([0.0, k * y_hi / 60.0], [0.0, y_hi], **dict(st, color=colour))
        # label where the line leaves the plot, centred above its top; near or past the right
        # edge, right-aligned at it (never over the edge, towards the colour bar)
        if k * y_hi / 60.0 <= 0.96 * f_max:
            ax.text(k * y_hi / 60.0, y_hi, text, ha="center", va="bottom", fontsize=8,
                    color=st["color"])
        else:                             # through the right edge (at the corner: inside)
            y = 60.0 * f_max / k
            ax.text(f_max, min(y, y_hi), text + " ", ha="right", va="top" if y >= y_hi else
                    "bottom", fontsize=8, color=colour, fontweight="bold")
    ax.set_ylim(y_lo, y_hi)
    if words:
        ps.note(ax, words, loc="lower right")
    if scale is not None and ps.roundoff_amplitude(top, scale, rtol):
        ps.note(ax, ps.no_content(2.0 * top, amp_unit) + ":\nthese amplitudes are round-off")
    ax.set_xlabel(ps.label(ds, freq, units=units) if ps.unit_of(ds, freq, "", units)
                  else "frequency [Hz]")
    ax.set_ylabel(ps.label(ds, speed, units=units) if ps.unit_of(ds, speed, "", units)
                  else "shaft speed [rpm]")
    what = "" if not z else f", tooth pass {z}x"
    ax.set_title(title or f"spectra vs speed (dashed: shaft orders 1x, 2x{what})", pad=16)
    return ps.finish(fig, path)


def _data_end(f, a) -> np.ndarray:
    """Per row, the highest frequency with a finite amplitude (NaN: the row has none)."""
    finite = np.isfinite(a)
    last = f.shape[1] - 1 - np.argmax(finite[:, ::-1], axis=1)
    return np.where(finite.any(axis=1), f[np.arange(f.shape[0]), last], np.nan)


def _beyond_data(z, rpm, f_end, duration) -> str:
    """'' or the words (and a SplineWarning) for the speeds whose tooth pass is beyond their
    data: the numbers of the fastest such speed (the n_out it needs covers the others)."""
    if not z:
        return ""
    f_tp = z * np.abs(rpm) / 60.0
    beyond = np.flatnonzero(np.isfinite(f_end) & (f_tp > f_end))
    if beyond.size == 0:
        return ""
    i = beyond[np.argmax(f_tp[beyond])]
    text = ps.nyquist_note(z, f_tp[i], f_end[i], rpm[i], duration, warn=False)
    if beyond.size > 1:
        text += (f"; so are the tooth passes of {beyond.size - 1} slower speeds down to "
                 f"{ps.eng(np.abs(rpm[beyond]).min())} rpm")
    warnings.warn(f"waterfall: {text}", ps.SplineWarning, stacklevel=3)
    return text.replace(" is above", "\nis above", 1).replace(": ", ":\n", 1).replace(
        " (n_out", "\n(n_out", 1).replace("; ", ";\n", 1)


# --------------------------------------------------------------------------- sweep figures

def sweep_figures(ds, out) -> list[Path]:
    """The figures of a sweep dataset into directory `out`: bifurcation.png (and for a grid
    period_map.png), lyapunov.png (if computed), waterfall*.png (if speed_rpm was swept).
    The horizontal axis is the first swept field with numeric values (a field of text values,
    e.g. thermal, becomes the panels or the map's other axis); points at a non-finite value of
    a field are left out, and a sweep of which no point ran has no figures (a note on stderr).
    Returns the paths written."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    names = list(ds["error"].dims)
    numeric = [n for n in names if ds[n].dtype.kind in "biuf"]
    written = []
    title_case = _case_name(ds)
    section = ds.attrs.get("section", "")
    if not numeric:
        print(f"no figures: no swept field has numeric values ({', '.join(names)})",
              file=sys.stderr)
        return written
    for n in numeric:                   # a point at a NaN value has no place on an axis
        ds = ds.isel({n: np.isfinite(ds[n].values.astype(float))})
    empty = [n for n in names if not ds.sizes[n]]
    if empty or not (ds["error"] == "").any():
        print("no figures: " + (f"no finite value of {', '.join(empty)}" if empty else
                                "no point ran (their errors are in sweep.nc)"), file=sys.stderr)
        return written
    x = numeric[0]
    other = [n for n in names if n != x]
    if "direction" in other and "section_D2" in ds:     # follow='both': overlay the two
        from .continuation import bifurcation_follow
        path = out / "bifurcation.png"
        bifurcation_follow(ds, x, path=path, title=f"{title_case}: D_2 on the {section} "
                           f"section vs {x}, followed up and down")
        written.append(path)
        other = []
        ds = ds.sel(direction="up")        # the other figures: the up direction
    if "section_D2" in ds and not written:
        path = out / "bifurcation.png"
        if not other:
            bifurcation(ds, x, path=path,
                        title=f"{title_case}: D_2 on the {section} section vs {x}")
        else:
            bifurcation_grid(ds, x, other[0], path=path,
                             title=f"{title_case}: D_2 on the {section} section")
            param_map(ds, "period", x, other[0], path=out / "period_map.png",
                      title=f"{title_case}: period of the {section} section sequence")
        written.append(path)
        if other:
            written.append(out / "period_map.png")
    if "lyapunov" in ds:
        path = out / "lyapunov.png"
        if not other:
            lyapunov_vs_param(ds, x, path=path,
                              title=f"{title_case}: largest Lyapunov exponent vs {x}")
        else:
            param_map(ds, "lyapunov", x, other[0], path=path,
                      title=f"{title_case}: largest Lyapunov exponent")
        written.append(path)
    if "Tm_spectrum" in ds and "speed_rpm" in numeric:
        written += _waterfalls(ds, out, title_case)
    return written


def _case_name(ds) -> str:
    m = re.search(r"name\s*=\s*'([^']*)'", ds.attrs.get("case", ""))
    return m.group(1) if m else "sweep"


def _waterfall_ds(sub):
    import xarray as xr
    spd = sub["speed_rpm"]
    freq = np.abs(spd.values)[:, None] * sub["order"].values[None, :] / 60.0
    return xr.Dataset({"amplitude": (("speed_rpm", "order"),
                                     sub["Tm_spectrum"].transpose("speed_rpm", "order").values,
                                     {"units": "N m", "long_name": "amplitude of T_m"}),
                       "freq_hz": (("speed_rpm", "order"), freq,
                                   {"units": "Hz", "long_name": "frequency"})},
                      coords={"speed_rpm": spd})


def _case_value(ds, key) -> float:
    """A number field of the sweep's case (attrs['case'], as Case.text writes it: the fields
    that differ from the defaults), else its default."""
    from ..case import defaults
    m = re.search(rf"^\s*{key}\s*=\s*([-+.\w]+)", ds.attrs.get("case", ""), re.M)
    return float(m.group(1)) if m else float(defaults()[key])


def _z(ds) -> int | None:
    return int(_case_value(ds, "z"))


def _waterfalls(ds, out, title_case) -> list[Path]:
    names = list(ds["error"].dims)
    z = None if "z" in names else _z(ds)
    duration = _duration(ds)
    rtol = _case_value(ds, "rtol")

    def size(d):                       # T_m's size, against which round-off is judged
        return float(np.nanmax(np.abs(d["Tm_rms"].values))) if "Tm_rms" in d else None

    def ran(d):                        # the speeds with a spectrum (a point that ran)
        return d.isel(speed_rpm=np.isfinite(d["Tm_spectrum"].values).any(axis=-1))

    if len(names) == 1:
        path = out / "waterfall.png"
        if not ran(ds).sizes["speed_rpm"]:
            print("no waterfall.png: no point has a spectrum of T_m (none ran)", file=sys.stderr)
            return []
        waterfall(_waterfall_ds(ran(ds)), z=z, path=path, duration=duration,
                  scale=size(ran(ds)), rtol=rtol,
                  title=f"{title_case}: spectrum of T_m vs speed (dashed: shaft and "
                        "tooth-pass orders)")
        return [path]
    other = names[0] if names[1] == "speed_rpm" else names[1]
    values = ds[other].values
    pick = np.unique(np.linspace(0, len(values) - 1, min(len(values), 6)).round().astype(int))
    paths = []
    for i in pick:
        v = values[i]
        sub = ran(ds.isel({other: i}).transpose("speed_rpm", ...))
        path = out / f"waterfall_{other}={_fmt(v)}.png"
        if not sub.sizes["speed_rpm"]:
            print(f"no {path.name}: no point has a spectrum of T_m (none ran)", file=sys.stderr)
            continue
        waterfall(_waterfall_ds(sub), z=z, path=path, duration=duration, scale=size(sub),
                  rtol=rtol,
                  title=f"{title_case}, {other} = {_fmt(v)}: spectrum of T_m vs speed")
        paths.append(path)
    return paths


def _fmt(v) -> str:
    v = v.item() if hasattr(v, "item") else v
    return ps.eng(v) if isinstance(v, float) else str(v)


def _duration(ds) -> float | None:
    """t_end - t0 - t_transient of the sweep's case [s] (None if one of them is swept, or if
    the case gives the run in shaft revolutions: then it differs with the speed)."""
    keys = ("t_end", "t0", "t_transient")
    revs = ("revolutions", "transient_revolutions")
    if any(k in ds["error"].dims for k in keys + revs) or any(_case_value(ds, k) for k in revs):
        return None
    t_end, t0, t_tr = (_case_value(ds, k) for k in keys)
    return t_end - t0 - t_tr
