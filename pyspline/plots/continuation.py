"""Figures of continuation and follow sweeps (docs/continuation.md): the frequency-response
curve (a response measure of the orbits against the field: stable solid, unstable dashed,
special points marked, follow-up / follow-down sweep points over it) and the bifurcation
diagram of a follow='both' sweep (both directions overlaid)."""
from __future__ import annotations

import textwrap

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from . import style as ps

#: measures of a branch point and of a sweep point: name -> (label, unit, sweep expression)
MEASURES = {"Tm_pp": ("T_m peak-to-peak", "N m", lambda d: d["Tm_max"] - d["Tm_min"]),
            "F_max": ("largest tooth load", "N",      # abs: F_j's sign is the flank's
                      lambda d: np.maximum(np.abs(d["F_max"]), np.abs(d["F_min"]))),
            "D2_pp": ("D_2 peak-to-peak", "m", lambda d: d["D2_max"] - d["D2_min"])}
SPECIAL_MARKS = {"fold": ("o", "#D55E00", "fold (mu = +1)"),
                 "period_doubling": ("s", "#009E73", "period doubling (mu = -1)"),
                 "neimark_sacker": ("D", "#CC79A7", "Neimark-Sacker (|mu| = 1, complex)"),
                 "grazing": ("X", "0.15", "grazing (contact sequence changes)"),
                 "nonsmooth_fold": ("P", "#0072B2", "non-smooth fold (turns at a grazing)")}
DIRECTION_MARKS = {"up": ("^", "#56B4E9", "follow up"), "down": ("v", "#E69F00", "follow down")}


def _runs(mask):
    """(start, stop) index pairs of the runs of equal values of a boolean array."""
    edges = np.flatnonzero(np.diff(mask.astype(int))) + 1
    bounds = np.r_[0, edges, len(mask)]
    return list(zip(bounds[:-1], bounds[1:]))


def _sweep_runs(sweep, field, from_sweep) -> list:
    """(direction, field values, measure) of each direction of a follow sweep's points."""
    sx = sweep.attrs.get("swept", "").split()
    key = sx[-1] if sx else field
    dirs = list(sweep["direction"].values) if "direction" in sweep.dims else \
        [sweep.attrs.get("follow") or "runs"]
    subs = [(d, sweep.sel(direction=d) if "direction" in sweep.dims else sweep) for d in dirs]
    return [(d, np.asarray(sub[key], float), np.asarray(from_sweep(sub), float))
            for d, sub in subs]


def frequency_response(branch, measure: str = "Tm_pp", sweep=None, path=None,
                       title: str | None = None) -> Figure:
    """A response measure ('Tm_pp', 'F_max', 'D2_pp') of a continuation Dataset against its
    field: each branch (period n) stable solid, unstable dashed, special points marked; the
    points of a follow sweep (one direction or 'both', same field) overlaid."""
    if measure not in MEASURES:
        raise ValueError(f"measure must be one of {', '.join(MEASURES)}, got {measure!r}")
    field = branch.attrs["field"]
    name, unit, from_sweep = MEASURES[measure]
    p = np.asarray(branch[field], float)
    y = np.asarray(branch[measure], float)
    runs = [] if sweep is None else _sweep_runs(sweep, field, from_sweep)
    fy, uy = ps.prefix(np.concatenate([y, *(v for _, _, v in runs)]), unit)  # all drawn
    fx, ux = ps.prefix(p, ps.unit_of(branch, field))
    fig = Figure(figsize=(9, 5.5), layout="constrained")
    ax = fig.add_subplot()
    handles = []
    for b in np.unique(branch["branch"]):
        rows = np.flatnonzero(branch["branch"].values == b)
        n = int(branch["n"].values[rows[0]])
        colour = ps.PERIOD_COLOURS[min(n, 5)]
        stable = branch["stable"].values[rows].astype(bool)
        for i, j in _runs(stable):
            seg = rows[max(i - 1, 0):j]      # overlap one point: the line has no gaps
            ax.plot(p[seg] / fx, y[seg] / fy, color=colour, lw=1.6,
                    ls="-" if stable[i] else (0, (4, 2.5)), zorder=3)
        if stable.any():
            handles.append(Line2D([], [], color=colour, lw=1.6,
                                  label=f"period-{n} orbits, stable"))
        if not stable.all():
            handles.append(Line2D([], [], color=colour, lw=1.6, ls=(0, (4, 2.5)),
                                  label=f"period-{n} orbits, unstable"))
    kinds = branch["special_type"].values.astype(str) if "special_type" in branch else []
    for kind, (mk, colour, label) in SPECIAL_MARKS.items():
        sel = kinds == kind
        if np.any(sel):
            ax.plot(branch[f"special_{field}"].values[sel] / fx,
                    branch[f"special_{measure}"].values[sel] / fy if f"special_{measure}" in
                    branch else np.full(sel.sum(), np.nan), ls="", marker=mk, ms=8, mfc=colour,
                    mec="k", mew=0.6, zorder=5)
            handles.append(Line2D([], [], ls="", marker=mk, ms=7, mfc=colour, mec="k",
                                  label=f"{label} ({int(sel.sum())})"))
    for d, sx, sy in runs:
        mk, colour, label = DIRECTION_MARKS.get(str(d), ("o", "0.4", "runs"))
        label += (" (runs, each from the one before)" if str(d) in DIRECTION_MARKS else
                  " (each from the case's start)")
        ax.plot(sx / fx, sy / fy, ls="", marker=mk, ms=6, mfc="none", mec=colour, mew=1.2,
                zorder=4)
        handles.append(Line2D([], [], ls="", marker=mk, ms=6, mfc="none", mec=colour,
                              mew=1.2, label=label))
    ranges = branch["no_period_range"].values if "no_period_range" in branch else []
    chaotic = branch["no_period_chaotic"].values if "no_period_chaotic" in branch else \
        [-1] * len(ranges)                # pyspline.branches: no seed there; -1: not told
    said = {1: ("0.7", "no periodic attractor: chaotic (largest Lyapunov exponent and "
                  "its slope positive beyond the spread)"),
            0: ("0.85", "no periodic attractor (n <= max_n): not settled, quasi-periodic or a "
                "longer period; not chaotic"),
            -1: ("0.85", "no periodic attractor (n <= max_n): chaotic, quasi-periodic or not "
                 "settled")}
    shown = set()
    for (a, b), kind in zip(ranges, map(int, chaotic)):
        colour, label = said[kind]
        ax.axvspan(a / fx, b / fx, color=colour, zorder=0)
        if kind not in shown:
            shown.add(kind)
            handles.append(Patch(color=colour, label=label))
    ax.set_xlabel(ps.label(branch, field, factor_unit=ux))
    ax.set_ylabel(f"{name} [{uy}]" if uy else name)
    ax.grid(alpha=0.3, lw=0.5)
    # below the panel: a dense diagram fills it (no 'best' place covers none), in two columns
    fig.legend(handles, [ps.wrap(h.get_label(), 4.0, 8) for h in handles], fontsize=8,
               loc="outside lower center", ncols=2, frameon=False)
    ax.set_title(title or f"frequency response: {name} of the periodic orbits vs {field}")
    return ps.finish(fig, path)


def bifurcation_follow(ds, param: str, coord: str = "section_D2", path=None,
                       title: str | None = None) -> Figure:
    """The bifurcation diagram of a follow='both' sweep: the section coordinate against the
    field, the up and the down direction overlaid (markers ^ and v)."""
    fig = Figure(figsize=(9, 5.5), layout="constrained")
    ax = fig.add_subplot()
    y_all = np.asarray(ds[coord], float)
    fy, uy = ps.prefix(y_all[np.isfinite(y_all)] if np.isfinite(y_all).any() else y_all,
                       ps.unit_of(ds, coord, "m"))
    px = np.asarray(ds[param], float)
    fx, ux = ps.prefix(px, ps.unit_of(ds, param))
    handles = []
    for d in ds["direction"].values:
        sub = ds.sel(direction=d)
        y = np.asarray(sub[coord], float).reshape(len(px), -1)
        xs = np.repeat(px, y.shape[1])
        ok = np.isfinite(y.ravel())
        mk, colour, label = DIRECTION_MARKS.get(str(d), ("o", "0.4", str(d)))
        ax.scatter(xs[ok] / fx, y.ravel()[ok] / fy, marker=mk, s=16, facecolors="none",
                   edgecolors=colour, lw=0.9, rasterized=True)
        handles.append(Line2D([], [], ls="", marker=mk, mfc="none", mec=colour, label=label))
    ax.set_xlabel(ps.label(ds, param, factor_unit=ux))
    ax.set_ylabel(f"{coord} [{uy}]")
    ax.grid(alpha=0.3, lw=0.5)
    fig.legend(handles=handles, fontsize=8, loc="outside lower center", ncols=len(handles),
               title="each run from the one before", title_fontsize=8)
    ax.set_title(ps.wrap(title or f"bifurcation diagram: {ps.long_name(ds, coord)} vs {param}, "
                         "both directions", 8.5, 12))
    return ps.finish(fig, path)


def _field_label(field: str) -> str:
    """'long name (field) [unit]' of a case field, an array element as NAME(i)."""
    from ..dataset import _field_attrs
    a = _field_attrs(field.split("(")[0].strip())
    return f"{a['long_name']} ({field})" + (f" [{a['units']}]" if a.get("units") else "")


def fold_plane(fc, path=None, title: str | None = None) -> Figure:
    """The folds and grazings of pyspline.fold_curve in the (field, field2) plane:
    the band between the two folds shaded (two orbits coexist there), the brute-force
    verdicts of follow sweeps (one orbit / two coexisting) overlaid."""
    field, field2 = fc.attrs["field"], fc.attrs["field2"]
    v = fc.value2.values
    folds = fc.fold.values      # at least two columns (NaN: no fold found)
    folds = np.c_[folds, np.full((len(v), max(0, 2 - folds.shape[1])), np.nan)]
    fig = Figure(figsize=(12, 5.5), layout="constrained")
    ax = fig.add_subplot()
    pair = np.isfinite(folds[:, :2]).all(axis=1)
    if pair.any():
        ax.fill_betweenx(v[pair], folds[pair, 0], folds[pair, 1], color="#D55E00", alpha=0.12,
                         lw=0, label="between the folds: two stable orbits coexist")
    curve = "curve_field" in fc and fc.sizes["curve_point"] > 0
    for j, name in enumerate(["lower fold", "upper fold"] + [f"fold {j + 1}" for j in
                                                            range(2, folds.shape[1])]):
        ok = np.isfinite(folds[:, j])
        ax.plot(folds[ok, j], v[ok], "o" if curve else "o-", color="#D55E00",
                mfc="white" if j else "#D55E00", ms=5, lw=1.4,
                label=None if j >= 2 or not ok.any() else f"{name} (mu = +1)" + (
                    f" at the values of {field2}" if curve else ""))
    if curve:       # the extended system's curves, their ends and cusps
        for i in np.unique(fc.curve.values):
            on = fc.curve.values == i
            x, y = fc.curve_field.values[on], fc.curve_field2.values[on]
            ax.plot(x, y, "-", color="#D55E00", lw=1.4,
                    label=None if i else "fold curve (extended system)")
        if fc.sizes["stop"]:
            ax.plot(fc.stop_field.values, fc.stop_field2.values, "x", color="#D55E00", ms=9,
                    mew=2, label="the curve stops: its contact sequence changes (stop_status)")
        if fc.sizes["cusp"]:
            ax.plot(fc.cusp_field.values, fc.cusp_field2.values, "*", color="k", ms=12,
                    label="cusp (the two folds meet)")
    g = fc.grazing.values[:, 0]
    ok = np.isfinite(g)
    if ok.any():
        ax.plot(g[ok], v[ok], "x" if curve else "x--", color="0.3", lw=1,
                label="first grazing along the branch (its contact sequence changes)")
    rest = fc.grazing.values[:, 1:]
    ok = np.isfinite(rest)
    if ok.any():
        ax.plot(rest[ok], np.broadcast_to(v[:, None], rest.shape)[ok], "x", color="0.55", ms=4,
                label="the other grazings along the branch")
    if "fold_grazing" in fc:       # the extended system's grazing nearest each fold
        _grazing_curves(ax, fc, v)
    if "coexist" in fc:
        xs, ys = np.meshgrid(fc.check_field.values, fc.check_value.values)
        two, one = fc.coexist.values == 1, fc.coexist.values == 0   # -1: not run (time)
        ax.plot(xs[two], ys[two], "s", color="#0072B2", ms=5,
                label="follow sweeps up and down differ: two orbits")
        ax.plot(xs[one], ys[one], "s", mfc="none", mec="0.5", ms=5,
                label="follow sweeps agree: one orbit")
    if not np.isfinite(folds).any():    # nothing to draw: the band and what stopped it
        ax.set_xlim(np.nanmin(fc.band.values), np.nanmax(fc.band.values))
        ax.set_ylim(v.min() - 0.5 * (np.ptp(v) or abs(v[0]) or 1),
                    v.max() + 0.5 * (np.ptp(v) or abs(v[0]) or 1))
        ax.text(0.5, 0.5, "no fold found\n" + textwrap.fill(fc.attrs.get("status", ""), 90),
                transform=ax.transAxes, ha="center", va="center", fontsize=9)
    ax.set_xlabel(_field_label(field))
    ax.set_ylabel(_field_label(field2))
    ax.grid(alpha=0.3, lw=0.5)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1), framealpha=0.9)
    ax.set_title(title or f"folds of the periodic orbits in ({field}, {field2}): the region "
                          "of coexistence")
    return ps.finish(fig, path)


def _grazing_curves(ax, fc, v):
    """fold_grazing per fold column, through the values of field2 in order (the line broken
    between two values with another number of folds: the columns pair other folds there), or,
    where the grazing curves were followed (graze_curve), those curves through them."""
    o = np.argsort(v)
    count = np.isfinite(fc.fold.values).sum(axis=1)[o]
    cut = np.flatnonzero(count[1:] != count[:-1]) + 1
    followed = "graze_curve" in fc and fc.sizes["graze_point"] > 0
    for j, x in enumerate(fc.fold_grazing.values[o].T):
        ok = np.isfinite(x)
        if ok.any():
            ax.plot(np.insert(x, cut, np.nan), np.insert(v[o], cut, np.nan),
                    "d" if followed else "d--", color="#009E73", ms=4, lw=1, label=None if j
                    else "grazing nearest each fold (its contact sequence changes): "
                         "fold_grazing")
    for i in np.unique(fc.graze_curve.values) if followed else ():
        on = fc.graze_curve.values == i
        ax.plot(fc.graze_curve_field.values[on], fc.graze_curve_field2.values[on], "-",
                color="#009E73", lw=1.2, label=None if i else "grazing curve (followed in "
                f"{fc.attrs['field2']}: graze_curve)")
