"""What each figure of pyspline.plots shows, on small hand-built datasets (with the names and
units a sweep gives them, pyspline.dataset's) and one tiny sweep: axis labels with their units,
limits that hold the data, as many markers and curves as the data has points and branches, the
legends' and notes' words (a failed point, chaos, points left out), every label, title,
legend, note and tick label inside the figure (none cut off at its edge), tick labels apart and
no legend over a title, label or the data it explains."""
import warnings

import numpy as np
import pytest
from matplotlib.colors import TwoSlopeNorm

import pyspline
from pyspline import analysis, dataset
from pyspline.plots import continuation as pc
from pyspline.plots import eng
from pyspline.plots import run as pr
from pyspline.plots import sweeps as sw

from conftest import CASES  # noqa: E402
from figtools import (_covered, _crowded, _cut_off, _inside, _legend_over_words,  # noqa: E402
                      _notes_over_data, _points, _words)

xr = pytest.importorskip("xarray")

SPEED = np.array([1000.0, 2000.0, 3000.0, 4000.0, 5000.0])
D2 = np.array([[-800e-6] * 4,                        # period 1
               [-700e-6, -900e-6] * 2,              # period 2
               [-650e-6, -720e-6, -810e-6, -930e-6],  # not periodic
               [np.nan] * 4,                        # failed: no section
               [-750e-6] * 4])                      # period 1
PERIOD = np.array([1.0, 2.0, 0.0, np.nan, 1.0])


def _attrs(name):
    long, units = dataset._stat_attrs(name)
    return {"long_name": long, "units": units} if units else {"long_name": long}


def _var(dims, values, name):
    return (dims, np.asarray(values, float), _attrs(name))


def _coord(name, values):
    return (name, np.asarray(values, float), dataset._field_attrs(name))


# --------------------------------------------------------------------------- sweeps

@pytest.fixture(scope="module")
def line():
    """A one-field sweep over speed_rpm: periods 1, 2, not periodic, a failed point, 1."""
    lam, spread = [-5.0, -2.0, 8.0, np.nan, 0.5], [1.0, 1.0, 2.0, np.nan, 2.0]
    return xr.Dataset({"section_D2": _var(("speed_rpm", "section_point"), D2, "section_D2"),
                       "period": _var("speed_rpm", PERIOD, "period"),
                       "lyapunov": _var("speed_rpm", lam, "lyapunov"),
                       "lyapunov_spread": _var("speed_rpm", spread, "lyapunov_spread")},
                      coords={"speed_rpm": _coord("speed_rpm", SPEED)})


def test_bifurcation_shows_every_section_point_by_period(line):
    fig = sw.bifurcation(line, "speed_rpm")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "shaft speed [r/min]"
    assert ax.get_ylabel().endswith("on the Poincare section [µm]")
    xy = _points(ax)
    ok = np.isfinite(D2)
    assert len(xy) == ok.sum()                                  # every point, once
    assert sorted(xy[:, 1]) == pytest.approx(sorted(D2[ok] * 1e6))
    assert _inside(ax, xy[:, 0], xy[:, 1])
    legend = _words(fig, ["legend"])
    assert "period 1 (2)" in legend and "period 2 (1)" in legend
    assert "not periodic (1)" in legend and "period 3" not in legend
    assert "1 of 5 runs without a result" in _words(fig, ["notes"])    # the failed point
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


def test_bifurcation_legend_covers_no_point():
    """A sweep whose section points fill the panel (20 speeds, 12 levels each, not periodic
    but the last): the legend stands beside them."""
    speed = np.linspace(1000.0, 5000.0, 20)
    y = np.tile(np.linspace(-900e-6, -700e-6, 12), (20, 1))
    per = np.r_[np.zeros(19), 1.0]
    ds = xr.Dataset({"section_D2": _var(("speed_rpm", "section_point"), y, "section_D2"),
                     "period": _var("speed_rpm", per, "period")},
                    coords={"speed_rpm": _coord("speed_rpm", speed)})
    fig = sw.bifurcation(ds, "speed_rpm")
    ax = fig.axes[0]
    assert len(_points(ax)) == y.size and _inside(ax, *_points(ax).T)
    (legend,) = fig.legends or [ax.get_legend()]
    assert _covered(ax, legend) == []
    assert _words(fig, ["legend"]).split(" | ") == ["not periodic (19)", "period 1 (1)",
                                                     "runs by period"]
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


def _marked(ax):
    """The x of the filled (chaotic) and of the hollow (not chaotic) markers, and the shaded
    x-stretches, of a Lyapunov panel."""
    filled, hollow = ([x for ln in ax.get_lines() if ln.get_marker() == "o"
                       and (ln.get_markerfacecolor() == "w") == h
                       for x in ln.get_xdata()] for h in (False, True))
    spans = [tuple(np.round(p.get_x() + np.r_[0, p.get_width()], 6)) for p in ax.patches]
    return filled, hollow, spans


def test_lyapunov_marks_chaotic_points_and_gives_their_horizons(line):
    fig = sw.lyapunov_vs_param(line, "speed_rpm")
    ax, ax2 = fig.axes
    lam = line["lyapunov"].values
    assert _inside(ax, SPEED[np.isfinite(lam)], lam[np.isfinite(lam)])
    assert ax.get_ylabel() == "largest Lyapunov exponent lambda [1/s]"
    assert ax.get_xlabel() == "shaft speed [r/min]"
    filled, hollow, spans = _marked(ax)   # only 8 +- 2 is chaos (0.5 is within its spread of 2)
    assert filled == [3000.0] and hollow == [1000.0, 2000.0, 4000.0, 5000.0]
    assert spans == [(2500.0, 3500.0)]    # half-way to its neighbours, at that x only
    (h,) = ax2.get_lines()
    assert h.get_xdata().tolist() == [3000.0] and h.get_ydata().tolist() == [1 / 8.0]
    assert ax2.get_yscale() == "log" and ax2.get_ylabel().endswith("[s]")
    words = _words(fig, ["legend"])
    assert "chaotic: lambda and the slope" in words and "not chaotic" in words
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


def test_lyapunov_marks_by_the_verdict_of_the_slope_too(line):
    """A point whose running estimate is positive beyond its spread but whose log separation no
    longer grows (a chaotic transient that died out) is drawn not chaotic; neighbouring
    chaotic points share one shaded stretch, from half a step before the first."""
    slope = [-5.0, 9.0, 0.3, np.nan, 3.0]
    lam = [-5.0, 10.0, 8.0, np.nan, 4.0]
    ds = line.assign(lyapunov=("speed_rpm", lam), lyapunov_slope=("speed_rpm", slope))
    filled, hollow, spans = _marked(sw.lyapunov_vs_param(ds, "speed_rpm").axes[0])
    assert filled == [2000.0, 5000.0] and hollow == [1000.0, 3000.0, 4000.0]
    assert spans == [(1500.0, 2500.0), (4500.0, 5500.0)]
    ds = ds.assign(lyapunov_slope=("speed_rpm", lam))
    assert _marked(sw.lyapunov_vs_param(ds, "speed_rpm").axes[0])[2] == [(1500.0, 3500.0),
                                                                          (4500.0, 5500.0)]


def test_lyapunov_without_chaos_has_no_horizon_axis(line):
    calm = line.assign(lyapunov=line["lyapunov"] * 0 - 3.0)
    fig = sw.lyapunov_vs_param(calm, "speed_rpm")
    assert len(fig.axes) == 1 and "horizon" not in _words(fig, ["legend"])


@pytest.fixture(scope="module")
def grid():
    """A two-field sweep: speed_rpm x t_d (3 values), the line's points at each t_d, the last
    value's points all failed."""
    y = np.stack([D2, D2 * 1.1, np.full_like(D2, np.nan)], axis=1)     # (5, 3, 4)
    per = np.stack([PERIOD, PERIOD, np.full(5, np.nan)], axis=1)
    lam = np.where(np.isfinite(per), np.linspace(-4.0, 6.0, 15).reshape(5, 3), np.nan)
    return xr.Dataset({"section_D2": _var(("speed_rpm", "t_d", "section_point"), y,
                                          "section_D2"),
                       "period": _var(("speed_rpm", "t_d"), per, "period"),
                       "lyapunov": _var(("speed_rpm", "t_d"), lam, "lyapunov")},
                      coords={"speed_rpm": _coord("speed_rpm", SPEED),
                              "t_d": _coord("t_d", [20.0, 40.0, 60.0])})


def test_bifurcation_grid_one_panel_per_value(grid):
    fig = sw.bifurcation_grid(grid, "speed_rpm", "t_d")
    panels = [ax for ax in fig.axes if ax.axison]
    assert [ax.get_title() for ax in panels] == ["t_d = 20 N m", "t_d = 40 N m", "t_d = 60 N m"]
    y = grid["section_D2"].values
    assert panels[0].get_ylabel().endswith("[mm]")                 # -1.02 mm at t_d = 40
    for j, ax in enumerate(panels):
        xy = _points(ax)
        assert len(xy) == np.isfinite(y[:, j]).sum()
        if len(xy):
            assert _inside(ax, xy[:, 0], xy[:, 1])
            assert sorted(xy[:, 1]) == pytest.approx(sorted(y[:, j][np.isfinite(y[:, j])] * 1e3))
    assert "1 of 5 runs without a result" in _words(panels[0], ["notes"])
    assert "5 of 5 runs without a result" in _words(panels[2], ["notes"])   # not just empty
    assert panels[-1].get_xlabel() == "shaft speed [r/min]"
    assert _words(fig, ["legend"]).split(" | ") == ["period 1", "period 2", "not periodic"]
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []
    two = sw.bifurcation_grid(grid, "speed_rpm", "t_d", max_panels=2)
    assert "(2 of 3 values of t_d)" in two._suptitle.get_text()
    assert [ax.get_title() for ax in two.axes if ax.axison] == ["t_d = 20 N m", "t_d = 60 N m"]


def test_param_map_of_periods_and_of_an_exponent(grid):
    fig = sw.param_map(grid, "period", "speed_rpm", "t_d")
    ax, cb = fig.axes
    (mesh,) = ax.collections
    cells = mesh.get_array()
    per = grid["period"].values
    assert cells.size == per.size and cells.mask.sum() == np.isnan(per).sum()   # hatched: none
    assert sorted(cells.compressed().tolist()) == sorted(per[np.isfinite(per)].tolist())
    assert [t.get_text() for t in cb.get_yticklabels()] == ["not periodic", "1", "2", "3", "4",
                                                             "> 4", "not settled"]
    assert "hatched: no result" in cb.get_ylabel()
    assert ax.get_xlabel() == "shaft speed [r/min]" and ax.get_ylabel().endswith("[N m]")
    assert _inside(ax, SPEED, [20.0, 60.0])
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []

    fig = sw.param_map(grid, "lyapunov", "speed_rpm", "t_d")
    ax, cb = fig.axes
    (mesh,) = ax.collections
    lam = grid["lyapunov"].values
    assert isinstance(mesh.norm, TwoSlopeNorm) and mesh.norm.vcenter == 0.0   # both signs
    assert mesh.norm.vmin == np.nanmin(lam) and mesh.norm.vmax == np.nanmax(lam)
    assert mesh.get_array().mask.sum() == np.isnan(lam).sum()
    assert cb.get_ylabel() == "largest Lyapunov exponent [1/s] (hatched: no result)"
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


def test_param_map_places_text_values_and_says_no_hatching_without_gaps(grid):
    ds = grid.isel(t_d=[0, 1]).assign_coords(t_d=["bulk", "none"]).fillna(1.0)
    fig = sw.param_map(ds, "lyapunov", "speed_rpm", "t_d")
    ax, cb = fig.axes
    assert [t.get_text() for t in ax.get_yticklabels()] == ["bulk", "none"]
    assert "hatched" not in cb.get_ylabel()


# --------------------------------------------------------------------------- continuation

@pytest.fixture(scope="module")
def follow():
    """A follow='both' sweep: up and down differ at 3000 r/min (two orbits coexist)."""
    y = np.stack([D2, D2[::-1]], axis=1)                         # (speed, direction, point)
    return xr.Dataset({"section_D2": _var(("speed_rpm", "direction", "section_point"), y,
                                          "section_D2")},
                      coords={"speed_rpm": _coord("speed_rpm", SPEED),
                              "direction": ("direction", ["up", "down"])})


def test_bifurcation_follow_overlays_both_directions(follow):
    fig = pc.bifurcation_follow(follow, "speed_rpm")
    ax = fig.axes[0]
    up, down = ax.collections
    y = follow["section_D2"].values
    for c, d in ((up, 0), (down, 1)):
        assert len(c.get_offsets()) == np.isfinite(y[:, d]).sum()
        assert _inside(ax, *np.asarray(c.get_offsets()).T)
    assert sorted(np.asarray(down.get_offsets())[:, 1]) == pytest.approx(
        sorted(y[:, 1][np.isfinite(y[:, 1])] * 1e6))
    assert ax.get_xlabel() == "shaft speed [r/min]" and ax.get_ylabel().endswith("[µm]")
    assert _words(fig, ["legend"]).split(" | ") == ["follow up", "follow down",
                                                     "each run from the one before"]
    (legend,) = fig.legends                                  # beside the panel, over no point
    assert _covered(ax, legend) == []
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


@pytest.fixture(scope="module")
def branch():
    """A continuation Dataset: a period-1 branch stable, unstable between its folds, stable;
    a period-2 branch, all unstable; two folds, one period doubling; a stretch without a
    periodic attractor."""
    p = np.r_[np.linspace(1000, 3000, 5), np.linspace(3000, 2000, 4)[1:],
              np.linspace(2000, 5000, 5)[1:], np.linspace(2500, 3500, 4)]
    y = np.r_[np.linspace(10, 30, 5), np.linspace(30, 40, 4)[1:], np.linspace(40, 60, 5)[1:],
              [20, 22, 24, 26]]
    stable = np.r_[[1] * 5, [0] * 3, [1] * 4, [0] * 4]
    return xr.Dataset({"Tm_pp": ("point", y), "branch": ("point", np.r_[[0] * 12, [1] * 4]),
                       "n": ("point", np.r_[[1] * 12, [2] * 4]),
                       "stable": ("point", stable),
                       "special_type": ("special", ["fold", "fold", "period_doubling"]),
                       "special_speed_rpm": ("special", [3000.0, 2000.0, 2500.0]),
                       "special_Tm_pp": ("special", [30.0, 40.0, 20.0]),
                       "no_period_range": (("stretch", "end"), [[4200.0, 4600.0]])},
                      coords={"speed_rpm": _coord("speed_rpm", p)},
                      attrs={"field": "speed_rpm"})


def test_frequency_response_draws_stability_specials_and_gaps(branch):
    fig = pc.frequency_response(branch)
    ax = fig.axes[0]
    lines = [ln for ln in ax.get_lines() if ln.get_linestyle() != "None"]
    solid = [ln for ln in lines if ln.get_linestyle() == "-"]
    assert len(solid) == 2 and len(lines) == 4               # 2 stable runs, 2 unstable
    p, y = branch["speed_rpm"].values, branch["Tm_pp"].values
    assert _inside(ax, p, y)
    drawn = np.concatenate([ln.get_xdata() for ln in lines])
    assert set(p.tolist()) <= set(drawn.tolist())            # every point on a line
    marks = [ln for ln in ax.get_lines() if ln.get_linestyle() == "None"]
    assert sorted((x, v) for ln in marks for x, v in zip(ln.get_xdata(), ln.get_ydata())) == [
        (2000.0, 40.0), (2500.0, 20.0), (3000.0, 30.0)]
    (gap,) = ax.patches
    assert gap.get_x() == 4200.0 and gap.get_width() == pytest.approx(400.0)
    legend = _words(fig, ["legend"])
    for words in ("period-1 orbits, stable", "period-1 orbits, unstable",
                  "period-2 orbits, unstable", "fold (mu = +1) (2)",
                  "period doubling (mu = -1) (1)", "no periodic attractor"):
        assert words in legend
    assert "period-2 orbits, stable" not in legend
    assert ax.get_xlabel() == "shaft speed [r/min]" and ax.get_ylabel() == "T_m peak-to-peak [N m]"
    (legend,) = fig.legends              # beside the panel: over no line, mark or shaded stretch
    assert _covered(ax, legend, lines=True) == []
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


def test_frequency_response_prefix_fits_the_follow_sweeps_too():
    """The measure's SI prefix is chosen over all it draws: a branch at round-off (1e-14 to
    1e-11 N m) under follow sweeps whose first points hold a start from rest (43 N m), the
    README's `pyspline continue` on paper_lx1e-4, read 'pN m' with a 1e13 offset."""
    p = SPEED[:4]
    br = xr.Dataset({"Tm_pp": ("point", [3e-14, 1e-12, 5e-12, 1.7e-11]),
                     "branch": ("point", [0] * 4), "n": ("point", [1] * 4),
                     "stable": ("point", [1] * 4)},
                    coords={"speed_rpm": _coord("speed_rpm", p)}, attrs={"field": "speed_rpm"})
    tm_max = np.full((4, 2), -30.7)
    tm_max[0, 0] = tm_max[-1, 1] = 12.5                          # 43.2 N m peak-to-peak
    sweep = xr.Dataset({"Tm_max": _var(("speed_rpm", "direction"), tm_max, "Tm_max"),
                        "Tm_min": _var(("speed_rpm", "direction"), np.full((4, 2), -30.7),
                                       "Tm_min")},
                       coords={"speed_rpm": _coord("speed_rpm", p),
                               "direction": ("direction", ["up", "down"])},
                       attrs={"swept": "speed_rpm", "follow": "both"})
    fig = pc.frequency_response(br, sweep=sweep)
    ax = fig.axes[0]
    fig.draw_without_rendering()
    assert ax.get_ylabel() == "T_m peak-to-peak [N m]"
    assert ax.yaxis.get_offset_text().get_text() == ""
    assert _inside(ax, p, br["Tm_pp"].values) and _inside(ax, p[[0, -1]], [43.2, 43.2])


def test_fold_plane_shades_the_band_between_the_folds():
    lx = np.array([0.0, 5e-5, 1e-4, 1.5e-4])
    folds = np.array([[2400.0, 2600.0], [2300.0, 2800.0], [2250.0, 2950.0], [np.nan, np.nan]])
    graze = np.array([[2200.0, 3100.0], [2150.0, np.nan], [np.nan, np.nan], [2100.0, np.nan]])
    coexist = np.array([[1, 0, -1], [0, 0, 1]])          # (check_value, check_field)
    fc = xr.Dataset({"fold": (("value2", "k"), folds), "grazing": (("value2", "g"), graze),
                     "coexist": (("check_value", "check_field"), coexist)},
                    coords={"value2": lx, "check_field": [2500.0, 3500.0, 4000.0],
                            "check_value": [5e-5, 1e-4]},
                    attrs={"field": "speed_rpm", "field2": "l_x"})
    assert "nearest each fold" not in _words(pc.fold_plane(fc), ["legend"])  # none given
    fc["fold_grazing"] = (("value2", "k"), folds - 10)      # the grazing nearest each fold
    shuffled = pc.fold_plane(fc.isel(value2=[0, 3, 2, 1]))  # drawn in the values' order
    near = [x for x in shuffled.axes[0].get_lines() if x.get_color() == "#009E73"]
    assert [x.get_xdata().tolist()[:3] for x in near] == [[2390.0, 2290.0, 2240.0],
                                                          [2590.0, 2790.0, 2940.0]]
    fig = pc.fold_plane(fc)
    ax = fig.axes[0]
    (band,) = ax.collections
    xs = band.get_paths()[0].vertices[:, 0]
    assert xs.min() == 2250.0 and xs.max() == 2950.0         # the widest pair
    lower, upper = ax.get_lines()[:2]
    assert lower.get_xdata().tolist() == [2400.0, 2300.0, 2250.0]
    assert upper.get_xdata().tolist() == [2600.0, 2800.0, 2950.0]
    two, one = ax.get_lines()[-2:]
    assert list(zip(two.get_xdata(), two.get_ydata())) == [(2500.0, 5e-5), (4000.0, 1e-4)]
    assert len(one.get_xdata()) == 3                         # -1: not run, not drawn
    assert _inside(ax, np.r_[folds[:3].ravel(), 2100.0, 4000.0], lx)
    assert ax.get_xlabel() == "shaft speed (speed_rpm) [r/min]"
    assert ax.get_ylabel().endswith("(l_x) [m]")
    legend = _words(fig, ["legend"])
    for words in ("between the folds: two stable orbits coexist", "lower fold (mu = +1)",
                  "first grazing", "the other grazings", "two orbits", "one orbit",
                  "grazing nearest each fold"):
        assert words in legend
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []
    fc["graze_curve"] = ("graze_point", [0, 0, 0, 1])      # the grazing curves followed:
    fc["graze_curve_field"] = ("graze_point", [2390.0, 2340.0, 2290.0, 2590.0])
    fc["graze_curve_field2"] = ("graze_point", [0.0, 2.5e-5, 5e-5, 0.0])
    fig = pc.fold_plane(fc)         # lines through the diamonds, which stand alone
    green = [x for x in fig.axes[0].get_lines() if x.get_color() == "#009E73"]
    assert [x.get_linestyle() for x in green[:2]] == ["None", "None"]
    assert [x.get_xdata().tolist() for x in green[2:]] == [[2390.0, 2340.0, 2290.0], [2590.0]]
    assert "grazing curve" in _words(fig, ["legend"])
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


# --------------------------------------------------------------------------- one run

def test_scene_shows_a_run_with_its_start_transient_left_out():
    """A run's page: D_2 falling from 0 to -0.8 mm in the first 5 % and then ringing 20 um at
    the shaft frequency; 16 teeth; the section once per revolution."""
    rpm, z = 6000.0, 16
    t = np.linspace(0.0, 0.2, 2001)
    w = 2 * np.pi * rpm / 60
    D2 = -8e-4 * (1 - np.exp(-t / 0.01)) + 2e-5 * np.sin(w * t)
    vD2 = np.gradient(D2, t)
    Tm = 40.0 * D2 / 8e-4
    F = Tm[:, None] / z * (1 + 0.1 * np.sin(w * t[:, None] + np.arange(z)))
    k = np.arange(100, 2001, 100)                     # once per revolution (0.01 s)
    fig = pr.scene(t, D2, vD2, Tm, F, Tf=np.abs(F) / 10, section=np.c_[D2[k], vD2[k]],
                   spectrum=analysis.amplitude_spectrum(t, Tm), speed_rpm=rpm, z=z,
                   title="a run: 6000 rpm")
    ax_d, ax_t, ax_p, ax_f, ax_tf, ax_s = fig.axes[:6]
    assert ax_d.get_ylabel() == "D_2 [µm]" and ax_t.get_ylabel() == "T_m [N m]"
    assert ax_t.get_xlabel() == "time t [s]"
    late = t >= 0.02                                  # the first tenth left out ...
    assert _inside(ax_d, t[late], D2[late] * 1e6) and ax_d.get_ylim()[1] < -600   # ... not 0
    assert f"start transient clipped ({eng(D2.min(), 3)} to 0 m)" in _words(ax_d, ["notes"])
    assert _inside(ax_t, t[late], Tm[late]) and "start transient clipped" in _words(ax_t)
    assert (ax_p.get_xlabel(), ax_p.get_ylabel()) == ("D_2 [µm]", "dD_2/dt [mm/s]")
    (marks,) = [ln for ln in ax_p.get_lines() if ln.get_marker() == "o"]
    assert len(marks.get_xdata()) == len(k) and "section points (20)" in _words(ax_p)
    assert "dD_2/dt: range of t >= 0.02 s" in _words(ax_p, ["notes"])
    assert "tooth load F_j [N]" in _words(fig) and "flash temperature T_f [°C]" in _words(fig)
    assert ax_f.get_images()[0].get_array().shape == (z, len(t))
    assert ax_s.get_xlabel() == "frequency [Hz]" and ax_s.get_xlim()[1] == pytest.approx(
        2.5 * z * rpm / 60)                           # up to 2.5 Z shaft orders
    assert _words(ax_s, ["legend"]) == "shaft orders 1x, 2x | tooth pass 16x, 32x"
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []
    assert _notes_over_data(fig) == []      # the clipped transient crosses every corner


# --------------------------------------------------------------------------- a sweep

@pytest.fixture(scope="module")
def tiny_sweep():
    """Three speeds, two bulk temperatures of which the second fails at every speed
    (ThermalInterferenceError); 0.1 s runs with the Lyapunov exponent and the spectrum."""
    case = pyspline.load_case(CASES / "paper_lx1e-4.nml", t_end=0.1, t_transient=0.02,
                              n_out=201, thermal="bulk")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        return pyspline.sweep(case, progress=False, lyapunov=True,
                              speed_rpm=[1500.0, 3000.0, 4500.0], t_bulk=[0.0, 3100.0])


def test_sweep_figures_show_the_sweep(tiny_sweep, tmp_path, monkeypatch, capsys):
    figs = {}
    for name in ("bifurcation_grid", "param_map", "waterfall"):
        def spy(*args, _draw=getattr(sw, name), **kw):
            fig = _draw(*args, **kw)
            figs[kw["path"].name] = fig
            return fig
        monkeypatch.setattr(sw, name, spy)
    ds = tiny_sweep
    paths = sw.sweep_figures(ds, tmp_path)
    assert [p.name for p in paths] == ["bifurcation.png", "period_map.png", "lyapunov.png",
                                       "waterfall_t_bulk=0.png"]
    assert sorted(figs) == sorted(p.name for p in paths)
    assert "no waterfall_t_bulk=3100.png: no point has a spectrum" in capsys.readouterr().err
    hot = [ax for ax in figs["bifurcation.png"].axes if ax.axison][1]
    assert hot.get_title() == "t_bulk = 3100 degC"
    assert len(_points(hot)) == 0 and "3 of 3 runs without a result" in _words(hot, ["notes"])
    cool = [ax for ax in figs["bifurcation.png"].axes if ax.axison][0]
    assert len(_points(cool)) == np.isfinite(ds["section_D2"].sel(t_bulk=0.0).values).sum()
    lyap = figs["lyapunov.png"]
    assert (lyap.axes[0].collections[0].get_array().mask.sum()
            == np.isnan(ds["lyapunov"].values).sum() >= 3)       # the failed points hatched
    assert "hatched: no result" in lyap.axes[1].get_ylabel()
    wf = figs["waterfall_t_bulk=0.png"].axes[0]
    assert wf.get_xlabel() == "frequency [Hz]" and wf.get_ylabel() == "shaft speed [r/min]"
    assert "16x" in _words(wf, ["notes"])          # the tooth pass of the Z = 16 case
    assert _cut_off(figs["bifurcation.png"]) == []        # the sweep's own titles
