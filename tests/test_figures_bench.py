"""What the benchmarks' own figures show (bench/: work-precision, stability map, fidelity
ladder, cost anatomy, the bifurcation diagram's accuracy), drawn from small hand-made rows of
the shape each benchmark makes (its runs are benchmarks, not tests): the data inside the
limits, failures named and not drawn as data, one colour per method, colour scales shared
where panels are compared, legends over no marker, texts inside their axes and the figure."""
import sys

import numpy as np
import pytest

from conftest import ROOT  # noqa: E402
from figtools import (_covered, _crowded, _cut_off, _inside, _legend_over_words,
                     _markers, _renderer, _words)  # noqa: E402

sys.path.insert(0, str(ROOT / "bench"))
import speed  # noqa: E402  (bench/ is not installed)


def _texts_inside_axes(ax) -> list:
    """The texts on the axes (annotations, marks) that reach past the axes' box."""
    r = _renderer(ax.figure)
    box = ax.get_window_extent(r)
    return [t.get_text() for t in ax.texts
            if not (lambda b: b.x0 >= box.x0 - 1 and b.x1 <= box.x1 + 1 and b.y0 >= box.y0 - 1
                    and b.y1 <= box.y1 + 1)(t.get_window_extent(r))]


def test_work_precision_one_colour_a_method_and_failures_named():
    """22 methods (more than one colour cycle of tab20), two rtols each, the last failing at
    both: every method its own colour, one legend for the page, over no marker; the failed
    runs in the panel's title, not drawn."""
    methods = [f"method {i}" for i in range(22)]
    rows = [dict(case="paper_lx1e-4", method=m, rtol=rt, status="ok", time_s=1e-3 * (i + 1) / rt
                 ** 0.1, err_Tm=rt * (i + 1), err_F=rt) for i, m in enumerate(methods)
            for rt in (1e-3, 1e-5)]
    for r in rows[-2:]:                                    # the last method fails at both
        r.update(status="FAILED: budget", time_s=float("nan"), err_Tm=float("nan"),
                 err_F=float("nan"))
    fig = speed._plot_wp(rows, ["paper_lx1e-4: reference agrees with DOP853 to 1e-9"])
    (ax,) = fig.axes
    lines = ax.get_lines()
    assert [ln.get_label() for ln in lines] == methods
    assert len({ln.get_color() for ln in lines}) == len(methods)          # none twice
    ok = [r for r in rows if r["status"] == "ok"]
    assert sum(len(ln.get_xdata()) for ln in lines) == len(ok)              # failures not drawn
    assert _inside(ax, [r["time_s"] for r in ok], [max(r["err_Tm"], r["err_F"]) for r in ok])
    assert "failed, not drawn: method 21 at rtol 0.001, 1e-05" in ax.get_title().replace("\n", " ")
    assert ax.get_xlabel() == "wall time of a run [s]" and ax.get_legend() is None
    (legend,) = fig.legends
    assert [t.get_text() for t in legend.get_texts()] == methods
    assert _covered(ax, legend) == []
    assert "reference agrees with DOP853" in fig._suptitle.get_text()
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


def test_stability_map_one_colour_scale_and_failures_marked():
    """Two dampings, three k_m, two methods, one failure: both panels on one colour scale (the
    slowest and fastest run over both), one colour bar with its unit, an X on the failed cell."""
    rows = [dict(damping=d, k_m=k, method=m, status="ok", time_s=t)
            for d, scale in (("as given", 1.0), ("zeta = 0.05", 10.0))
            for k in (1e5, 1e7, 1e9) for m, t in (("CVODE bdf", 1e-3), ("scipy RK45", 1e-1))
            for t in [t * scale * k ** 0.05]]
    rows[3].update(status="FAILED: CV_TOO_MUCH_WORK")              # as given, 1e7, scipy RK45
    fig = speed._plot_stability(rows)
    a, b, bar = fig.axes
    logt = np.log10([r["time_s"] for r in rows if r["status"] == "ok"])
    for ax in (a, b):
        (im,) = ax.get_images()
        assert im.norm.vmin == logt.min() and im.norm.vmax == logt.max()    # shared
        assert ax.get_xlabel() == "mesh stiffness k_m [N/m]"
    grid = a.get_images()[0].get_array()
    assert np.ma.getmaskarray(grid)[1, 1]                          # the failed cell: no colour
    assert grid[0, 1] == pytest.approx(np.log10(rows[2]["time_s"]))
    (x,) = a.texts
    assert x.get_text() == "X" and x.get_position() == (1, 1)
    assert "1 of 6 runs failed" in a.get_title() and "0 of 6 runs failed" in b.get_title()
    assert bar.get_ylabel() == "log10 of the wall time of a run [s]"
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


def test_ladder_holds_every_level_and_marks_auto_by_tolerance():
    """One case: levels from exact (drawn at the 1e-16 floor) to an error of 10, costs within
    one decade, a failed level, auto's two picks at the dearest level: every marker inside the
    limits, the picks told apart by marker (no annotation past the panel), the failure in the
    title, the time axis' labels apart."""
    import ladder
    rows = [dict(case="paper_T100", level=f"{d}-DOF {th}", dof=d, thermal=th, own=own,
                 eligible=True, status="ok", cost_s=c, error=e)
            for d, th, own, c, e in ((7, "coupled", True, 0.1, 0.0), (3, "coupled", False, 0.02,
                                     10.0), (7, "oneway", False, 0.05, 1e-3),
                                     (3, "oneway", False, 0.03, 0.5))]
    rows.append(dict(rows[1], level="3-DOF bulk", thermal="bulk", status="FAILED: x",
                     cost_s=float("nan"), error=float("nan")))
    rows += [dict(rows[0], level=f"auto {tol:g}", own=False, tol=tol) for tol in ladder.TOLS]
    fig = ladder._plot(rows, ["paper_T100"])
    ax = fig.axes[0]
    xy = _markers(ax)
    assert len(xy) == len(rows) - 1
    assert _inside(ax, xy[:, 0], xy[:, 1]) and xy[:, 1].min() == 1e-16 and xy[:, 1].max() == 10
    picks = [ln.get_marker() for ln in ax.get_lines() if ln.get_color() == "k"]
    assert sorted(picks) == sorted(ladder.AUTO_MARKERS.values()) and len(set(picks)) == 2
    assert "failed, not drawn: 3-DOF bulk" in ax.get_title().replace("\n", " ")
    legend = _words(fig, ["legend"])
    assert "fidelity = auto, tol 0.01" in legend and "fidelity = auto, tol 0.001" in legend
    assert _texts_inside_axes(ax) == [] and _covered(ax, fig.legends[0]) == []
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


def test_anatomy_shares_and_costs_inside_their_axes():
    """Three cases: the shares of a run (each case's add up to 1) and the RHS cost against the
    floor as markers on the log axis (no bars from an arbitrary bottom); legends over no data."""
    import anatomy
    shares = ("rhs", "jacobian", "roots", "solver", "python")
    rows = [dict(case=c, rhs_ns=ns, floor_ns=100.0, **{f"share_{k}": v for k, v in zip(shares, s)})
            for c, ns, s in (("paper_lx1e-4", 270.0, (0.1, 0, 0.05, 0.8, 0.05)),
                             ("paper_T100", 8e3, (0.85, 0, 0.01, 0.13, 0.01)),
                             ("physical_lx1e-4", 7e3, (0.57, 0.12, 0.01, 0.29, 0.01)))]
    fig = anatomy._plot(rows)
    a1, a2 = fig.axes
    assert len(a1.patches) == 15 and max(p.get_x() + p.get_width() for p in a1.patches) == \
        pytest.approx(1.0)
    assert _inside(a1, [p.get_x() + p.get_width() for p in a1.patches], [0, 2])
    assert a2.get_yscale() == "log" and len(a2.patches) == 0
    xy = _markers(a2)
    assert sorted(xy[:, 1]) == sorted([r["rhs_ns"] for r in rows] + [100.0] * 3)
    assert _inside(a2, xy[:, 0], xy[:, 1]) and a2.get_ylabel() == "ns per call"
    assert [t.get_text() for t in a2.get_xticklabels()] == [r["case"] for r in rows]
    assert _covered(a1) == [] and _covered(a2) == []
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


def test_bifurcation_accuracy_holds_every_rtol():
    """Four rtols, the loosest with an error above 1e-2 of the range and a different period: all
    inside the limits, each point labelled with its rtol inside the panel, the title whole."""
    import bifurcation
    rtols = [1e-4, 1e-6, 1e-8, 1e-10]
    rows = [dict(rtol=rt, points=100, steps_per_point=1000 * (1 + k),
                 section_error_of_range=3e-2 * 10.0 ** (-2 * k), period_differs=int(k == 0))
            for k, rt in enumerate(rtols)]
    fig = bifurcation._plot_accuracy(rows)
    (ax,) = fig.axes
    x, y = [r["steps_per_point"] for r in rows], [r["section_error_of_range"] for r in rows]
    assert _inside(ax, x, y)
    (odd,) = [ln for ln in ax.get_lines() if ln.get_linestyle() == "None"]
    assert odd.get_xdata().tolist() == [1000]
    assert [t.get_text() for t in ax.texts] == [f"{rt:g}" for rt in rtols]
    assert _texts_inside_axes(ax) == [] and _covered(ax) == []
    assert "the sweep at each rtol against rtol" in ax.get_title().replace("\n", " ")
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []
