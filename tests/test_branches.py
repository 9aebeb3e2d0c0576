"""pyspline.branches and pyspline.fold_curve (docs/continuation.md) on the 7-DOF Z16 drive of
tests/test_cont_drives.py: every branch of its band from one call, held against the follow
sweeps' jumps and values; the folds followed in the ripple amplitude, held against the
verdicts of follow sweeps."""
import warnings

import numpy as np
import pytest

import pyspline
from pyspline.diagram import coexistence
from test_cont_drives import (BAND, DRIVE, every_branch_of_the_band, folds,  # noqa: F401
                              follow_sweeps)                                 # (a fixture)

SETTLED = DRIVE.replace(t_end=2.0, t_transient=1.0, n_out=8001)  # the seeding sweep's runs
TOL = 100 * DRIVE["rtol"]       # continuation's corrector's tol, branches' to tell points apart
#: the whole module runs on the worker that computes the band's branches (test_cli_fold_input
#: holds the fold curves' command against them)
pytestmark = pytest.mark.xdist_group("z16_band")


@pytest.fixture
def every_branch():
    """Every branch over 2250-2480 r/min, seeded by follow sweeps (runs of SETTLED) at 10 r/min
    steps, computed once per process (tests/test_cont_drives.py holds its S-curve too)."""
    return every_branch_of_the_band()


def test_branches_finds_both_orbits_of_the_band_and_no_third(every_branch):
    """Both stable orbits the seeding follow sweeps find inside the hysteresis (runs of 2 s,
    the last 1 s at 200 samples a revolution; 10 r/min steps: the full-contact orbit up, the
    contact-loss one down) lie on the branches (T_m peak-to-peak to 0.5 %: the largest of 200
    samples a revolution of an impacting orbit's torque, on either side; the two orbits are a
    factor 2 apart), joined through the unstable middle into one S-curve; at every speed of
    the hysteresis the branches cross it three times (two stable, one saddle), outside it
    once: no spurious third orbit, no branch twice."""
    ds, sw = every_branch
    assert ds.attrs["status"] == "complete" and ds.attrs["no_period"] == ""
    p, pp, stable = ds.speed_rpm.values, ds.Tm_pp.values, ds.stable.values.astype(bool)
    lo, hi = folds(ds)
    assert len(folds(ds)) == 2
    speeds, swept = sw.speed_rpm.values, (sw.Tm_max - sw.Tm_min).values
    for x in (2370.0, 2400.0, 2420.0, 2300.0, 2470.0):
        cross = [k for b in np.unique(ds.branch) for k in np.flatnonzero(ds.branch == b)[:-1]
                 if ds.branch[k + 1] == b and (p[k] - x) * (p[k + 1] - x) <= 0]
        assert len(cross) == (3 if lo < x < hi else 1), (x, cross)
        got = np.sort([np.interp(x, sorted(p[[k, k + 1]]), pp[[k, k + 1]][np.argsort(
            p[[k, k + 1]])]) for k in cross if stable[k] and stable[k + 1]])
        up, down = swept[:, speeds == x].ravel()
        want = [up, down] if coexistence(sw)[speeds == x][0] else [up]
        assert len(got) == len(want) == (2 if lo < x < hi else 1), (x, got, want)
        assert got == pytest.approx(np.sort(want), rel=5e-3), x


def test_pieces_of_the_same_branch_are_merged(every_branch):
    """A piece of a branch (points 30-70 of the S-curve) is the same branch and goes; two
    pieces that share no orbit (the points before 30 and after 70) are both kept; a piece
    moved off the branch by 5 % of each state's swing along it is another branch."""
    from pyspline.diagram import merged
    from test_orbits import scale_of
    ds, _ = every_branch
    s = scale_of(DRIVE)
    mid = ds.isel(point=slice(30, 70))
    a, b = ds.isel(point=slice(0, 30)), ds.isel(point=slice(70, None))
    assert merged([mid, ds], "speed_rpm", s, TOL) == [1]
    assert sorted(merged([a, b], "speed_rpm", s, TOL)) == [0, 1]
    off = mid.copy(deep=True)
    swing = np.ptp(ds.y0.values, axis=0)
    off["y0"] = off.y0 + 0.05 * swing
    assert sorted(merged([off, ds], "speed_rpm", s, TOL)) == [0, 1]


def test_a_branch_traced_twice_goes(every_branch):
    """Two seeds' pieces (the S-curve, and points 30-70 of it as another seed's): one branch
    is left, the first seed's; a piece off the branch stays, renumbered."""
    from pyspline.diagram import _concat, _distinct
    from test_orbits import scale_of
    ds, s = every_branch[0], scale_of(DRIVE)
    mid = ds.isel(point=slice(30, 70))
    out, kept = _distinct(_concat([ds, mid]), "speed_rpm", s, TOL)
    assert list(kept) == [0] and (out.branch == 0).all() and out.sizes["point"] == ds.sizes["point"]
    off = mid.copy(deep=True)
    off["y0"] = off.y0 + 0.05 * np.ptp(ds.y0.values, axis=0)
    out, kept = _distinct(_concat([mid, off, ds]), "speed_rpm", s, TOL)
    assert list(kept) == [1, 2] and sorted(set(out.branch.values)) == [0, 1]
    assert set(out.seed.values) == {0, 1}


def test_a_stretch_without_a_period_is_shaded(every_branch):
    """Sweep points whose sections give no period (n = 0: chaotic, quasi-periodic or not
    settled) form their own stretch, none is split from its neighbours' periods; the figure
    shades a stretch that seeded nothing (no_period_range) and says what it is."""
    import matplotlib
    matplotlib.use("Agg")
    from pyspline.diagram import _stretches
    from pyspline.plots import frequency_response
    assert _stretches([1, 1, np.nan, np.nan, 2, 2, 1]) == [(0, 1, 1), (2, 3, 0), (4, 5, 2),
                                                           (6, 6, 1)]
    ds = every_branch[0].copy()
    ds["no_period_range"] = (("stretch", "end"), [[2250.0, 2280.0]])
    ax = frequency_response(ds, sweep=every_branch[1]).axes[0]
    spans = [pt for pt in ax.patches if pt.get_x() == 2250.0 and pt.get_width() == 30.0]
    assert len(spans) == 1
    assert any(t.get_text().startswith("no periodic attractor") and "chaotic" in t.get_text()
               for t in ax.figure.legends[0].get_texts())
    # told apart (branches' no_period_chaotic): chaotic darker, each said once
    ds["no_period_range"] = (("stretch", "end"), [[2250.0, 2260.0], [2260.0, 2280.0],
                                                  [2400.0, 2410.0]])
    ds["no_period_chaotic"] = ("stretch", [0, 1, 1])
    ax = frequency_response(ds, sweep=every_branch[1]).axes[0]
    grey = {pt.get_x(): pt.get_facecolor()[0] for pt in ax.patches if pt.get_x() in
            (2250.0, 2260.0, 2400.0)}
    assert grey[2260.0] == grey[2400.0] < grey[2250.0]
    texts = [t.get_text() for t in ax.figure.legends[0].get_texts() if "attractor" in t.get_text()]
    assert len(texts) == 2 and "not chaotic" in texts[0] and "chaotic (largest Lyapunov" in \
        texts[1]


def test_branches_folds_where_the_follow_sweeps_jump(every_branch, follow_sweeps):
    """The folds of the branches within 0.5 % of the 1 r/min follow sweeps' jumps, and the
    seeding sweep's own jumps (10 r/min steps) bracket them."""
    ds, sw = every_branch
    lo, hi = folds(ds)
    speeds, pp = follow_sweeps
    up = speeds[np.argmax(np.diff(pp[0])) + 1]
    down = speeds[np.argmax(np.diff(pp[1]))]
    assert hi == pytest.approx(up, rel=5e-3) and lo == pytest.approx(down, rel=5e-3)
    assert not coexistence(sw)[sw.speed_rpm.values < lo - 10].any()
    assert coexistence(sw)[(sw.speed_rpm.values > lo + 1) & (sw.speed_rpm.values < hi - 1)].all()


#: the fold curve's values of the ripple amplitude a: four with a fold pair in 2300-2500 r/min,
#: values of a with a fold pair in the band 2300-2500 r/min (docs/continuation.md)
AMPS = [0.25, 0.22, 0.2, 0.18]
FAST = DRIVE.replace(rtol=1e-7, atol=1e-9)   # the folds within 1e-4 r/min of rtol 1e-8


@pytest.fixture(scope="module")
def fold_command(tmp_path_factory):
    """The folds of a = 0.25 over 2300-2500 r/min followed in a down to 0.18 by the extended
    system, at rtol 1e-7 with steps up to twice the default's, from `pyspline continue --fold`
    with the follow sweeps' verdict at a = 0.25 (3 speeds; runs of 80 revolutions, the last
    40 at 200 samples a revolution: the revolution fields, which the orbits' own runs do not
    use): (its fold_curve.nc, the command's outcome, its directory)."""
    import xarray as xr
    from test_continuation import cli
    tmp = tmp_path_factory.mktemp("fold")
    (tmp / "drive.nml").write_text(FAST.replace(revolutions=80, transient_revolutions=40,
                                                outputs_per_revolution=200).text())
    run = cli(tmp, "continue", "drive.nml", "--field", "speed_rpm", "--start", "2300",
              "--stop", "2500", "--fold", "ripple_amp(1)=" + ",".join(map(str, AMPS)),
              "--check", "0.25", "--sweep", "3", "--ds-max", "0.5", "--max-angle", "0.3",
              "--out", "fold", "--quiet")
    assert run.returncode == 0, run.stderr
    with xr.open_dataset(tmp / "fold" / "fold_curve.nc", engine="netcdf4") as fc:
        return fc.load(), run, tmp


@pytest.fixture
def fold_curves(fold_command):
    return fold_command[0]


def test_fold_curve_against_follow_sweeps(fold_curves):
    """At each of the four values of a, follow sweeps up and down say two orbits between its
    folds and one outside: at a with a fold pair (lo, hi), the speeds lo - 30, lo - 15 and
    hi + 15 (one orbit) and lo + 10, the middle and hi - 10 (two: the up chain stays on the
    full-contact branch, the down chain on the contact-loss one; 10 r/min of margin: runs
    next to a fold do not settle). The folds move up in speed as a falls; the curve is one
    per fold of the seed, each complete (it leaves the rectangle), and every point of it has
    a multiplier at +1 and its others inside the unit circle."""
    fc = fold_curves
    assert (fc.status == "complete").all() and fc.attrs["status"] == "complete", fc.status.values
    assert fc.attrs["curve_status"] == "; ".join(["complete"] * 4), fc.attrs["curve_status"]
    f = fc.fold.values
    assert f.shape == (4, 2) and np.isfinite(f).all(), f
    assert (np.diff(f[:, 0]) > 0).all() and (np.diff(f[:, 1]) > 0).all()
    assert set(fc.curve.values) == {0, 1} and fc.curve_stable.all() and fc.sizes["cusp"] == 0
    for a, (lo, hi) in zip(AMPS, f):
        speeds = np.array([lo - 30, lo - 15, lo + 10, (lo + hi) / 2, hi - 10, hi + 15])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pyspline.SplineWarning)
            sw = pyspline.sweep(SETTLED.replace(ripple_amp=[a, 0, 0, 0], n_out=2001),
                                speed_rpm=speeds, follow="both", progress=False, spectrum=False)
        assert (sw.error == "").all()
        assert list(coexistence(sw)) == [False, False, True, True, True, False], (a, lo, hi)


def test_fold_curve_grazing_below_the_upper_fold(fold_curves):
    """Along the seed's branch (a = 0.25) from the band's start the first grazing (where the
    full-contact orbit opens its teeth) lies just below the upper fold (within 4 r/min), the
    other grazings on the S-curve's span, between the folds' neighbourhoods; the extended
    system gives no whole branch's grazings at the other values. The grazing nearest each
    fold (fold_grazing, from the fold's own orbit) is, at a = 0.25, one of the continuation's
    (to 0.05 r/min: the continuation bisects its step 8 times, fold_grazing 12 times; measured
    0.01 and 0.035), and at every value the upper fold's lies 0-4 r/min below it: the
    grazing curve follows the upper fold's."""
    g, f = fold_curves.grazing.values, fold_curves.fold.values
    assert 0 < f[0, 1] - g[0, 0] < 4, (g[0], f[0])
    rest = g[0][1:][np.isfinite(g[0][1:])]
    assert ((rest > f[0, 0] - 5) & (rest < f[0, 1] + 5)).all(), (g[0], f[0])
    assert np.isnan(g[1:]).all()
    near = fold_curves.fold_grazing.values
    assert fold_curves.attrs["fold_grazing_status"] == "complete" and np.isfinite(near).all()
    assert np.abs(near[0][:, None] - g[0][None, :]).min(axis=1).max() < 0.05, (near[0], g[0])
    assert ((f[:, 1] - near[:, 1] > 0) & (f[:, 1] - near[:, 1] < 4)).all(), (near, f)


@pytest.fixture(scope="module")
def cusp_curve():
    """The fold pair of a = 0.085 over 2575-2600 r/min (docs: 1.5 r/min wide) followed in a
    over 0.08-0.0875 (the folds also at 0.0865, inside), and the grazing nearest its folds
    followed in a over the same range."""
    return pyspline.fold_curve(FAST, "speed_rpm", 2575, 2600, "ripple_amp(1)", CUSP_AMPS,
                               progress=False, ds_max=0.5, max_angle=0.3, graze_curves=True)


CUSP_AMPS = [0.085, 0.0875, 0.08, 0.0865]


@pytest.fixture(scope="module")
def cusp_repeated():
    """method='repeated' at the three values of a with a fold pair (0.085, 0.0875, 0.0865): a
    one-parameter continuation at each over 2575-2600 r/min, bisecting grazings 8 times."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        return pyspline.fold_curve(FAST, "speed_rpm", 2575, 2600, "ripple_amp(1)",
                                   [CUSP_AMPS[i] for i in (0, 1, 3)], method="repeated",
                                   progress=False, ds_max=0.5, max_angle=0.3)


def test_fold_curve_through_its_cusp(cusp_curve, cusp_repeated):
    """From a = 0.085 the curve of the lower fold goes down in a, turns at the cusp between
    a = 0.08 and 0.085 (docs: the pair 1.5 r/min wide at 0.085, none at 0.08) and comes back
    up as the upper fold: one curve, traced through the cusp (points either side of it, their
    speeds higher past it). Its folds at a = 0.0875 equal those of the one-parameter
    continuation there (measured 1.1e-4 and 1.2e-4 r/min at rtol 1e-7: both correctors stop
    at the scaled residual tol = 1e-5, and the secant of the one-parameter location stops on
    the arclength to 1e-6 of the step);
    none at 0.08 (the one-parameter continuation: cusp_repeated's at 0.0875, its band
    narrowed around the folds predicted from 0.085). Follow sweeps at the middle of the 0.085
    pair and 8 r/min either side say
    two orbits there and one outside; at 0.08, at the same speeds, the up and the down chains
    end on the same orbit (T_m peak-to-peak to 0.5 %): no hysteresis past the cusp."""
    fc = cusp_curve
    assert fc.sizes["cusp"] == 1 and fc.attrs["cusp"].startswith("speed_rpm = "), fc.attrs
    a_c, p_c = float(fc.cusp_field2[0]), float(fc.cusp_field[0])
    assert 0.08 < a_c < 0.085, a_c
    f = fc.fold.values
    assert np.isfinite(f[:2, :2]).all() and np.isnan(f[2]).all(), f
    on = fc.curve.values == fc.curve.values[np.argmin(fc.curve_field2.values)]
    x, y = fc.curve_field.values[on], fc.curve_field2.values[on]
    k = np.argmin(y)
    assert 0 < k < len(y) - 1 and y[k] == pytest.approx(a_c, abs=2e-4)
    assert x[:k].min() > f[1, 0] - 1e-6 and x[k] == pytest.approx(p_c, abs=1)
    assert np.isclose(x, f[1, 0], atol=1e-3).any() and np.isclose(x, f[1, 1], atol=1e-3).any()
    one = cusp_repeated.fold.values[1]
    assert cusp_repeated.value2[1] == 0.0875 and np.isfinite(one).sum() == 2, one
    assert np.abs(f[1, :2] - one).max() < 5e-4, (f[1], one)
    lo, hi = f[0, :2]
    speeds = [lo - 8, (lo + hi) / 2, hi + 8]
    pp = {}
    for amp in (0.085, 0.08):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pyspline.SplineWarning)
            sw = pyspline.sweep(SETTLED.replace(ripple_amp=[amp, 0, 0, 0], n_out=2001),
                                speed_rpm=speeds, follow="both", progress=False,
                                spectrum=False)
        assert (sw.error == "").all()
        pp[amp] = (sw.Tm_max - sw.Tm_min).values
        assert list(coexistence(sw)) == ([False, True, False] if amp == 0.085 else
                                         [False] * 3), (amp, pp[amp])
    assert (np.abs(pp[0.08][0] - pp[0.08][1]) < 5e-3 * pp[0.08].max(0)).all(), pp[0.08]


def test_fold_grazings_are_the_repeated_methods(cusp_curve, cusp_repeated):
    """At the three values of a with a fold pair (0.085, 0.0875, 0.0865) the extended system's
    grazing nearest each fold (the branch at that value walked from the fold's orbit both
    ways, the grazing bisected 12 times) is the grazing of `method='repeated'` (a
    continuation at each value, bisected 8 times) to 0.03 r/min (measured 0.004-0.016), both
    folds reach the same one (the pair is 1.5-4.3 r/min wide, the grazing 1.2-1.6 r/min below
    its upper fold, on the full-contact branch) to their brackets' sum; none at 0.08 (no
    fold)."""
    fc, rep = cusp_curve, cusp_repeated
    near, width = fc.fold_grazing.values[[0, 1, 3], :2], fc.fold_grazing_bracket.values
    g = rep.grazing.values
    assert np.isfinite(near).all() and np.isnan(fc.fold_grazing.values[2]).all(), near
    assert np.abs(near - g[:, :1]).max() < 0.03, (near, g)
    assert (np.abs(near[:, 0] - near[:, 1]) <= width[[0, 1, 3], :2].sum(axis=1)).all(), near
    upper = fc.fold.values[[0, 1, 3], 1:2]
    assert ((near < upper) & (near > upper - 2)).all(), (near, upper)


#: how well a grazing is located in speed (r/min): next to it the contact signature depends on
#: the orbit to within the corrector's residual (100 rtol), coarser than the bisection's
#: bracket (1e-4 to 1.5e-3 r/min): orbits either side converged to that residual differ in
#: signature 3e-3 r/min beyond the bracket of every point (docs/branches.md, measured)
GRAZE_PRECISION = 5e-3


def test_grazing_curve_through_the_sampled_grazings(cusp_curve):
    """The grazing nearest the folds (the same one for both folds at each value) followed in a
    is one curve over the whole range, 0.08-0.0875, both ways complete, through the cusp's
    value without meeting a fold (its field2 past the cusp, 0.08, where there is no fold); it
    has a point at each value of a, there within the located precision of each fold's
    `fold_grazing` (measured 1.4e-3 r/min), and falls in speed as a rises (the full-contact
    orbit opens its teeth at lower speed with more ripple)."""
    fc = cusp_curve
    assert set(fc.graze_curve.values) == {0}, fc.graze_curve.values
    assert list(fc.graze_curve_status.values) == ["down: complete; up: complete"]
    x, a = fc.graze_curve_field.values, fc.graze_curve_field2.values
    assert a.min() == 0.08 and a.max() == 0.0875 and (np.diff(a) > 0).all(), a
    assert (np.diff(x) < 0).all(), x
    for v, near in zip(fc.value2.values, fc.fold_grazing.values):
        on = np.flatnonzero(a == v)
        assert len(on) == 1, (v, a)
        ok = np.isfinite(near)
        assert ok.any() == (v != 0.08), (v, near)
        assert (np.abs(near[ok] - x[on]) < GRAZE_PRECISION).all(), (v, near, x[on])


def test_every_grazing_curve_point_is_a_grazing(cusp_curve):
    """At every point of the grazing curve the periodic orbits (Newton from the point's orbit)
    at the speeds either side of it, its bracket widened by the located precision, have
    different contact signatures: a grazing lies between them; 0.1 r/min off the curve they
    have the same."""
    from pyspline.specials import contact_measures
    fc = cusp_curve

    def signature(p, a, y):
        case = FAST.replace(speed_rpm=p, ripple_amp=[a, 0, 0, 0])
        return contact_measures(pyspline.periodic_orbit(case, guess=y).trajectory)["signature"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        for (lo, hi), a, y in zip(np.sort(fc.graze_curve_ends.values, axis=1),
                                  fc.graze_curve_field2.values, fc.graze_curve_y0.values):
            assert hi - lo < GRAZE_PRECISION
            assert signature(lo - GRAZE_PRECISION, a, y) != signature(hi + GRAZE_PRECISION, a, y)
        assert signature(lo - 0.1, a, y) == signature(lo - 0.1 + 2 * GRAZE_PRECISION, a, y)


def test_a_grazing_curve_stopped_keeps_its_points(cusp_curve):
    """A direction cut by max_points keeps its points and says so; one whose prediction is
    never close enough (move 1e-9) halves its step below ds_min (here at once) and keeps the
    start, saying where the grazing was lost and why."""
    from pyspline.arclength import parse_field
    from pyspline.foldcurve import FoldSystem
    from pyspline.grazecurve import STEPS, fold_grazing, trace
    from pyspline.orbits import _scale
    fc = cusp_curve
    i = np.flatnonzero(fc.curve_field2.values == 0.085)[0]      # the seed, a fold at 0.085
    p = np.array([float(fc.curve_field[i]), 0.085])
    y = fc.curve_y0.values[i]
    d0 = _scale(FAST.replace(speed_rpm=p[0], ripple_amp=[p[1], 0, 0, 0]).model)
    fs = FoldSystem(FAST, parse_field(FAST, "speed_rpm"), parse_field(FAST, "ripple_amp(1)"),
                    1, p, (260.0, 0.00875), np.ones(14, bool), d0, 1e-5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        g, why = fold_grazing(fs, np.r_[y / d0, 0.0, 0.0], y)
        assert why == "found" and abs(g["p"] - fc.fold_grazing.values[0, 0]) < GRAZE_PRECISION
        pts, why = trace(fs, g, 0.0, y, [], (-1.0, 1.0), 1, **(STEPS | dict(max_points=2)))
        assert len(pts) == 2 and pts[1]["q"][1] > 0, pts
        assert why.startswith("max_points = 2 reached at speed_rpm = "), why
        pts, why = trace(fs, g, 0.0, y, [], (-1.0, 1.0), -1, **(STEPS | dict(move=1e-9, ds_min=0.1)))
    assert len(pts) == 1 and why.startswith("the grazing is lost past speed_rpm = "), why
    assert "from the prediction (move 1e-09)" in why, why


def test_g_derivatives_against_differences(cusp_curve):
    """At a point of the fold curve the extended system's last Jacobian row, g's gradient
    (from two variational runs along v for the states, M(p +- h) v for the fields), equals
    central differences of g itself (b and c held; steps 1e-4 in the scaled unknowns),
    component by component, to 1e-4 of the gradient's size (measured 5e-6); F = 0 and g = 0
    there."""
    from pyspline.arclength import parse_field
    from pyspline.foldcurve import FoldSystem
    from pyspline.orbits import _scale
    fc = cusp_curve
    i = fc.sizes["curve_point"] // 3
    p = np.array([float(fc.curve_field[i]), float(fc.curve_field2[i])])
    y = fc.curve_y0.values[i]
    case = FAST.replace(speed_rpm=p[0], ripple_amp=[p[1], 0, 0, 0])
    d0 = _scale(case.model)
    fs = FoldSystem(FAST, parse_field(FAST, "speed_rpm"), parse_field(FAST, "ripple_amp(1)"),
                    1, p, (260.0, 0.00875), np.ones(14, bool), d0, 1e-5)
    u = np.r_[y / d0, 0.0, 0.0]
    fs.border(fs.run(u, y)[1])
    F, g, J, M = fs.evaluate(u, y)
    assert np.abs(F).max() < 1e-5 and abs(g) < 1e-5, (np.abs(F).max(), g)
    h = 1e-4 * np.maximum(1, np.abs(u))
    fd = np.array([(fs.g(u + h[j] * np.eye(16)[j], y) - fs.g(u - h[j] * np.eye(16)[j], y))
                   / (2 * h[j]) for j in range(16)])
    assert np.abs(J[-1] - fd).max() < 1e-4 * np.abs(fd).max(), np.c_[J[-1], fd]


def test_bad_input_is_a_case_error(monkeypatch):
    """A CaseError naming the argument before anything runs (no sweep, no continuation),
    continuation's keywords handed on included."""
    import sys

    def never(*a, **k):
        raise AssertionError("ran before the arguments were checked")
    monkeypatch.setattr(sys.modules["pyspline.sweeps"], "sweep", never)
    monkeypatch.setattr(sys.modules["pyspline.diagram"], "continuation", never)
    for kw in (dict(points=2), dict(points=1.5), dict(max_n=0), dict(ds=0.0), dict(bogus=1),
               dict(guess=np.zeros(14)), dict(stop="x")):
        args = dict(stop=BAND[1]) | kw
        with pytest.raises(pyspline.CaseError, match=list(kw)[0]):
            pyspline.branches(DRIVE, "speed_rpm", BAND[0], progress=False, **args)
    for kw in (dict(values2=[np.nan]), dict(values2="x"), dict(values2=[0.2, 1e9]),
               dict(check=[np.nan]), dict(check="x"), dict(check_points=1),
               dict(check_points=2.5), dict(ds_min=0.5), dict(bogus=1), dict(method="x"),
               dict(graze_curves="x"), dict(graze_curves=True, method="repeated")):
        args = dict(values2=[0.2]) | kw
        with pytest.raises(pyspline.CaseError, match=list(kw)[0]):
            pyspline.fold_curve(DRIVE, "speed_rpm", *BAND, "ripple_amp(1)", progress=False,
                                **args)
    for kw, key in ((dict(ds=-0.1), "ds"), (dict(move=np.nan), "move"),
                    (dict(ds_max=np.inf), "ds_max"), (dict(max_points=1), "max_points"),
                    (dict(max_points=2.0), "max_points"), (dict(bogus=1), "bogus"),
                    (dict(ds_min=1.0), "ds_min <= ds")):
        with pytest.raises(pyspline.CaseError, match=rf"graze_curves(\['{key}'\]|: {key})"):
            pyspline.fold_curve(DRIVE, "speed_rpm", *BAND, "ripple_amp(1)", [0.2],
                                progress=False, graze_curves=kw)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(pyspline.CaseError, match="scalar field"):
            pyspline.branches(DRIVE, "ripple_amp(1)", 0.1, 0.2, progress=False)


def test_cli_all(tmp_path):
    """`pyspline continue --all` writes what pyspline.branches returns, bit for bit: the
    branches, the seeding sweep (3 speeds over 2200-2300 r/min, below the hysteresis: one
    orbit, seeded up and down, continued once) and the figure, exit 0 (the branches of the
    S-curve and its folds: the tests above)."""
    import xarray as xr
    from test_continuation import cli
    path = tmp_path / "drive.nml"
    path.write_text(SETTLED.text())
    run = cli(tmp_path, "continue", str(path), "--field", "speed_rpm", "--start", "2200",
              "--stop", "2300", "--all", "--sweep", "3", "--out", "out", "--quiet")
    assert run.returncode == 0, run.stderr
    ds = xr.open_dataset(tmp_path / "out" / "branches.nc", engine="netcdf4")
    sw = xr.open_dataset(tmp_path / "out" / "sweep.nc", engine="netcdf4")
    want, want_sw = pyspline.branches(SETTLED, "speed_rpm", 2200, 2300, points=3,
                                      progress=False)
    assert ds.attrs["n_branches"] == 1 and ds.attrs["seeds"] == want.attrs["seeds"]
    assert ds.attrs["command"].startswith("pyspline continue") and "--all" in ds.attrs["command"]
    for got, ref in ((ds, want), (sw, want_sw)):
        for v in ref.data_vars:
            if v not in ("wall_s", "core_wall_s"):
                assert np.array_equal(got[v].values, ref[v].values,
                                      equal_nan=ref[v].dtype.kind == "f"), v
    assert (tmp_path / "out" / "branches.png").stat().st_size > 10_000


def test_cli_fold_input(tmp_path, every_branch, fold_command, monkeypatch):
    """`pyspline continue --fold` (the fold curves' command above) writes the folds at a =
    0.25 (the Python --all call's, to 0.01 r/min) with the follow sweeps' verdict (2300, 2400,
    2500 r/min: two orbits exactly between the folds, 2354.6 and 2439.3), exit 0; a --fold
    without numbers, or --repeated or --graze-curves without --fold, is a CaseError naming it,
    exit 2; --graze-curves asks fold_curve for the grazing curves."""
    from test_continuation import cli
    fc, run, out = fold_command
    assert "wrote fold/fold_curve.nc" in run.stdout
    assert fc.fold.values[0] == pytest.approx(folds(every_branch[0]), abs=1e-2)
    lo, hi = fc.fold.values[0]
    x, two = fc.check_field.values, fc.coexist.values[0].astype(bool)
    assert len(x) == 3 and (two == ((x > lo) & (x < hi))).all(), (x[two], lo, hi)
    assert (out / "fold" / "fold_curve.png").stat().st_size > 10_000
    path = tmp_path / "drive.nml"
    path.write_text(SETTLED.text())
    run = cli(tmp_path, "continue", str(path), "--field", "speed_rpm", "--start", "2200",
              "--stop", "2500", "--fold", "ripple_amp(1)=0.2,x")
    assert run.returncode == 2 and "--fold ripple_amp(1)=" in run.stderr, run.stderr
    run = cli(tmp_path, "continue", str(path), "--field", "speed_rpm", "--start", "2200",
              "--stop", "2500", "--repeated")
    assert run.returncode == 2 and "--repeated: an option of --fold" in run.stderr, run.stderr
    run = cli(tmp_path, "continue", str(path), "--field", "speed_rpm", "--start", "2200",
              "--stop", "2500", "--graze-curves")
    assert run.returncode == 2 and "--graze-curves: an option of --fold" in run.stderr, \
        run.stderr
    import pyspline.diagram

    def asked(*args, **kw):            # the flag's way into fold_curve, without the computing
        raise pyspline.CaseError(f"graze_curves={kw['graze_curves']}")
    monkeypatch.setattr(pyspline.diagram, "fold_curve", asked)
    for flags, said in (((), "graze_curves=False"), (("--graze-curves",), "graze_curves=True")):
        run = cli(tmp_path, "continue", str(path), "--field", "speed_rpm", "--start", "2200",
                  "--stop", "2500", "--fold", "ripple_amp(1)=0.2", *flags)
        assert run.returncode == 2 and said in run.stderr, run.stderr


def test_a_doubling_on_two_branches_is_reported_once():
    """branches: a period doubling located on the period-1 branch (0) and again where the
    period-2 branch (1) ends at it (its merge: special_n 1 on a period-2 branch, at the same
    field value and state to within sqrt(tol)) is one special point, on branch 0, listing
    branch 1 in special_merge; a merge record that is another point (its state 0.01 scaled
    away) and the fold stay. Made-up records."""
    import xarray as xr
    from pyspline.diagram import one_doubling
    scale, y = np.full(14, 1e-3), np.full(14, 1e-3)
    ds = xr.Dataset({
        "speed_rpm": ("point", [1600.0, 1620.0, 1615.0, 1623.0]),
        "branch": ("point", [0, 0, 1, 1]), "n": ("point", [1, 1, 2, 2]),
        "special_type": ("special", ["period_doubling", "fold", "period_doubling",
                                     "period_doubling"]),
        "special_speed_rpm": ("special", [1623.614, 1618.4, 1623.614 + 1e-5, 1623.624]),
        "special_branch": ("special", [0, 1, 1, 1]), "special_n": ("special", [1, 2, 1, 1]),
        "special_y0": (("special", "state"), np.array([y, 2 * y, y * (1 + 1e-5), y * 1.01])),
    }, attrs={"field": "speed_rpm"})
    out = one_doubling(ds, "speed_rpm", scale, TOL)
    assert list(out.special_type.values) == ["period_doubling", "fold", "period_doubling"]
    assert list(out.special_branch.values) == [0, 1, 1]
    assert list(out.special_merge.values) == [1, -1, -1]
    assert out.special_speed_rpm.values[-1] == 1623.624
