"""What the paper's figures (pyspline reproduce: Figs. 4-10) show, drawn from short runs of the
paper's cases (0.2 s, the quick runs' sampling): each panel holds its data, one bar per tooth on
an axis numbered 1..Z, the legends cover no bar and no marker, the Poincare points and their
count, the words and units, nothing past the figure's edge. A page of one row a case is drawn
with one row (its last case): each row is drawn by the same code (a figure's layout is most of
these tests' time)."""
import numpy as np
import pytest

import pyspline
from pyspline import paper
from pyspline.paper import figures as pf

from conftest import CASES, PAPER_SHAFTS  # noqa: E402
from figtools import (_covered, _crowded, _cut_off, _inside, _legend_over_words,
                     _visible_ticks, _words)  # noqa: E402

pytestmark = PAPER_SHAFTS
T_END = 0.2       # [s]: ten revolutions past paper.SETTLE, the largest load at 0.076 s


@pytest.fixture(scope="module")
def results():
    """The cases drawn here, run to T_END."""
    out = {}
    for name in ["paper_ideal", "paper_lx1e-4", "paper_T100",
                 *paper.FIGURES["fig9_10_flash_temperature"]]:
        case = paper.load_paper_case(name, CASES, quick=True)
        t_end = min(case["t_end"], T_END)
        n = int(round((case["n_out"] - 1) * (t_end - case["t0"]) / (case["t_end"] - case["t0"])))
        out[name] = pyspline.simulate(case.replace(t_end=t_end, n_out=n + 1))
    return out


def _check_tooth_bars(ax_f, ax_fx, res):
    """One bar per tooth at the instant of the largest load, envelopes after paper.SETTLE; the
    tooth axis shows teeth 1..Z only; the legend covers nothing."""
    z = res.F.shape[1]
    k = int(np.argmax(np.abs(res.Tm)))
    late = res.t > paper.SETTLE
    for ax, q in ((ax_f, res.F), (ax_fx, res.Fx)):
        assert [b.get_height() for b in ax.patches] == q[k].tolist()
        ticks = _visible_ticks(ax.xaxis)
        assert ticks[0] == 1 and ticks[-1] == z and len(ticks) <= 10     # no tooth 0 or Z + 1
        assert all(v == int(v) for v in ticks)
        assert _inside(ax, [0.6, z + 0.4], q[k])                            # every bar whole
        if late.any():
            assert _inside(ax, [1, z], np.r_[q[late].max(axis=0), q[late].min(axis=0)])
        assert ax.get_xlabel() == "tooth j"
    assert ax_f.get_ylabel() == "F_j [N]" and ax_fx.get_ylabel() == "F_jx [N]"
    legend = _words(ax_f, ["legend"])
    assert f"at t = {res.t[k]:.4f} s (largest load)" in legend
    assert ("max over t > 0.1 s" in legend) == late.any()
    assert _covered(ax_f) == []


def test_fig4_dynamics_shows_the_run(results):
    """Fig. 4 of paper_ideal: the Poincare panel's points and its count of distinct ones, the
    tooth bars, the time panels."""
    res = results["paper_ideal"]
    fig = pf.dynamics_figure(res, "Ideal spline pair (paper Fig. 4)")
    d, phase, poinc, f, fx, tm = fig.axes
    p, nd = paper.poincare(res), paper.poincare_count(res)
    (pts,) = poinc.get_lines()
    assert len(pts.get_xdata()) == len(p) > 5 and _inside(poinc, p[:, 0] * 1e3, p[:, 1])
    assert f"{nd} distinct point" in poinc.get_title().replace("\n", " ")
    _check_tooth_bars(f, fx, res)
    # the aligned drive's lateral forces balance: the note says so, not round-off digits
    k = int(np.argmax(np.abs(res.Tm)))
    assert abs(res.Fx[k].sum()) <= 1e-9 * np.abs(res.Fx[k]).sum()
    assert fx.get_title().startswith("sum of F_jx at that instant: 0 to round-off (sum of")
    assert d.get_ylabel() == "relative displacement D_2 (line of action) [mm]"
    assert _inside(d, res.t, res.D2 * 1e3) and _inside(tm, res.t, res.Tm)
    assert tm.get_ylabel() == "meshing torque T_m [N m]" and tm.get_xlabel() == "time t [s]"
    assert (phase.get_xlabel(), phase.get_ylabel()) == ("D_2 [mm]", "dD_2/dt [m/s]")
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


def test_figs5_6_misalignment_one_row_per_case(results):
    """Figs. 5-6: per misalignment, D_2 with k_v on its own axis, the phase plane with the
    Poincare points (the legend clear of them), the tooth bars; the lateral sum is said."""
    names = paper.FIGURES["fig5_6_misalignment"][-1:]
    fig = pf.misalignment_figure(results, names)
    rows, twins = np.reshape(fig.axes[:4 * len(names)], (len(names), 4)), fig.axes[4 * len(names):]
    assert len(twins) == len(names)
    for (d, phase, f, fx), kv, name in zip(rows, twins, names):
        res = results[name]
        assert d.get_title() == f"{name}: l_x = {pyspline.plots.eng(res.case['l_x'])} m"
        assert d.get_ylabel() == "D_2 (blue) [mm]" and kv.get_ylabel() == "k_v [-] (orange)"
        assert _inside(d, res.t, res.D2 * 1e3) and _inside(kv, res.t, res.kv)
        p = paper.poincare(res)
        (marks,) = [ln for ln in phase.get_lines() if ln.get_marker() == "o"]
        assert len(marks.get_xdata()) == len(p) and _inside(phase, p[:, 0] * 1e3, p[:, 1])
        assert f"{paper.poincare_count(res)} distinct" in _words(phase, ["legend"])
        assert _covered(phase) == []
        _check_tooth_bars(f, fx, res)
        k = int(np.argmax(np.abs(res.Tm)))
        assert fx.get_title() == (f"sum of F_jx at that instant: "
                                  f"{pyspline.plots.eng(res.Fx[k].sum(), 3)} N")
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


def test_figs7_8_bulk_temperature(results):
    """Figs. 7-8's page: the case in each row's title, the tooth bars, T_m and k_v held."""
    names = paper.FIGURES["fig7_8_bulk_temperature"][-1:]
    fig = pf.temperature_figure(results, names)
    for (f, fx, tm, kv), name in zip(np.reshape(fig.axes, (len(names), 4)), names):
        res = results[name]
        assert f.get_title().startswith(f"{name}: T_M = {res.case['t_bulk']:g} degC, l_x = ")
        _check_tooth_bars(f, fx, res)
        assert _inside(tm, res.t, res.Tm) and _inside(kv, res.t, res.kv)
        assert tm.get_ylabel() == "meshing torque T_m [N m]"
        assert kv.get_ylabel() == "dynamic load coefficient k_v [-]"
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []


def test_figs9_10_flash_temperature_over_misalignment(results):
    """Figs. 9-10: every tooth's T_f, the largest per output for each l_x on a log axis that
    spans the data (not decades below it) with the legend beside the lines, and the largest
    T_f against l_x."""
    names = paper.FIGURES["fig9_10_flash_temperature"]
    fig = pf.flash_figure(results, names)
    each, peak, trend = fig.axes
    last = results[names[-1]]
    assert len(each.get_lines()) == last.Tf.shape[1] and _inside(each, last.t, last.Tf)
    lines = peak.get_lines()
    assert len(lines) == len(names)
    top = max(results[n].Tf.max() for n in names)
    assert peak.get_yscale() == "symlog"
    assert 1e-3 * top <= peak.yaxis.get_transform().linthresh <= top      # no empty decades
    for ln, name in zip(lines, names):
        assert _inside(peak, ln.get_xdata(), ln.get_ydata())
        assert ln.get_ydata().tolist() == results[name].Tf.max(axis=1).tolist()
    assert _covered(peak, lines=True) == []          # the legend over no line's point
    lx = [results[n].case["l_x"] * 1e3 for n in names]
    (curve,) = trend.get_lines()
    assert curve.get_xdata().tolist() == lx and _inside(trend, lx, curve.get_ydata())
    assert trend.get_xlabel() == "misalignment l_x [mm]"
    assert "f_m = " in fig._suptitle.get_text()
    assert _cut_off(fig) == [] and _crowded(fig) == [] and _legend_over_words(fig) == []
