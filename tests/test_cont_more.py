"""pyspline.branches and continuation (docs/continuation.md), the last gaps of their tests: a
chaotic drive's sweep seeds no branch and is reported as such, a period-2 attractor seeds
with the period its sections give, the predictor within a field's range, the command line's
--all and --fold keeping what they have when cut, and the follow sweep's bound on a
realisations run."""
import re
import sys
import warnings

import numpy as np
import pytest

import pyspline
import pyspline.orbits
from conftest import CASES, PAPER_SHAFTS
from test_continuation import DOUBLING

BRANCHES = sys.modules["pyspline.diagram"]     # the module of pyspline.branches


def test_a_stretchs_words_give_the_verdicts_evidence():
    """A stretch without a period is said chaotic or not by analysis.is_chaotic on the running
    estimate, the slope and the spread, and its words quote all three: a separation that grows
    at r = 200 1/s until a quarter of the window, then stays (a chaotic transient that died
    out), reads lam = r/4 but slope 0: not chaotic, and the words say slope 0; growth all
    through is chaotic with both at r."""
    from pyspline.analysis import largest_lyapunov_fit
    t = np.linspace(0, 0.4, 401)
    for growth, chaotic in ((200 * np.minimum(t, 0.1), False), (200 * t, True)):
        fit = largest_lyapunov_fit(t, growth)
        text, verdict = BRANCHES.lyapunov_verdict(fit)
        lam, slope, spread = map(float, re.fullmatch(
            r"largest Lyapunov exponent (\S+) 1/s, slope of the log separation (\S+) 1/s "
            r"\(spread (\S+)\)", text).groups())
        assert verdict == chaotic and (min(lam, slope) > spread) == chaotic, text
        assert (lam, slope) == pytest.approx((fit.lam, fit.slope), rel=1e-3, abs=1e-9)
        assert lam == pytest.approx(50 if not chaotic else 200, rel=1e-3)


def test_chaotic_drive_seeds_no_branch(monkeypatch):
    """chaos_z24 (a vibro-impact drive with a Lyapunov exponent near 900 1/s,
    tests/test_chaos.py) swept up and down over 5900-6100 r/min: no run's sections give a
    period, Newton from its final state finds no stable period-1 orbit, so the whole band is
    one stretch without a period each way, named in the error as chaotic (a run of the same
    length from its middle point's final state has a largest Lyapunov exponent of 300 1/s or
    more, as tests/test_chaos.py measures over 200 revolutions, beyond its estimate's spread),
    and no continuation runs (runs of 5 revolutions after 2: the follow chains carry the
    motion on)."""
    case = pyspline.load_case(CASES / "chaos_z24.nml", lyapunov=False, t_transient=0.02,
                              t_end=0.07, n_out=201)
    tried = []
    orbit = pyspline.orbits.periodic_orbit
    monkeypatch.setattr(pyspline.orbits, "periodic_orbit",
                        lambda c, n=1, **kw: tried.append(n) or orbit(c, n, **kw))
    monkeypatch.setattr(BRANCHES, "continuation", lambda *a, **k: pytest.fail(
        "a branch was continued from a chaotic stretch"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        with pytest.raises(pyspline.SplineError, match=r"no periodic attractor found by the "
                           r"follow sweeps over speed_rpm = 5900..6100 \(stretches without a "
                           r"period: up 5900..6100 \(chaotic: .*\); down 6100..5900 "
                           r"\(chaotic: .*\)\)") as err:
            pyspline.branches(case, "speed_rpm", 5900, 6100, points=3, max_n=1,
                              progress=False)
    assert tried == [1, 1]      # one seed tried per stretch, at its middle
    said = re.findall(r"largest Lyapunov exponent (\S+) 1/s, slope of the log separation (\S+) "
                      r"1/s \(spread ([\d.e+-]+)\)", str(err.value))
    assert len(said) == 2 and all(300 < float(lam) and float(sp) < min(float(lam), float(sl))
                                  for lam, sl, sp in said)


def test_chaotic_stretch_in_a_branches_dataset():
    """chaos_z24 (runs of 5 revolutions after 2) followed in its mesh damping zeta_m over
    0.01-0.1 at 4 values: up, the run at 0.01 (the case's own, chaotic) gives no period and
    its T_m peak-to-peak jumps from 58 to 4.7 N m at the next value, so it is a stretch of its
    own; Newton from its final state finds no stable period-1 orbit, and its Lyapunov run says
    chaotic (a largest exponent of 300 1/s or more, beyond its spread); the damped stretch
    above seeds the stable period-1 orbit at 0.07 (continued 2 points: max_points). The
    Dataset holds the stretch (no_period_range, no_period_chaotic = 1) and the figure shades
    it as chaotic."""
    import matplotlib
    matplotlib.use("Agg")
    from pyspline.plots import frequency_response
    case = pyspline.load_case(CASES / "chaos_z24.nml", lyapunov=False, t_transient=0.02,
                              t_end=0.07, n_out=201)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        ds, sw = pyspline.branches(case, "zeta_m", 0.01, 0.1, points=4, max_n=1,
                                   progress=False, max_points=2)
    assert sw.period.sel(direction="up").values[0] == 0
    assert ds.no_period_range.values.tolist() == [[0.01, 0.01]]
    assert ds.no_period_chaotic.values.tolist() == [1]
    lam, slope, spread = map(float, re.fullmatch(
        r"up 0.01..0.01 \(chaotic: largest Lyapunov exponent (\S+) 1/s, slope of the log "
        r"separation (\S+) 1/s \(spread (\S+)\)\)", ds.attrs["no_period"]).groups())
    assert lam > 300 and spread < min(lam, slope)
    assert ds.attrs["seeds"] == "0.07 up n=1" and (ds.n == 1).all() and ds.stable.all()
    assert "max_points = 2 reached" in ds.attrs["status"]
    ax = frequency_response(ds, sweep=sw).axes[0]
    assert any(t.get_text().startswith("no periodic attractor: chaotic") for t in
               ax.figure.legends[0].get_texts())


def test_unsettled_periodic_drive_is_not_chaos():
    """DOUBLING over 1646-1650 r/min, whose attractor is the stable period-2 orbit (its
    sections give period 2 after 40 revolutions, test_period_two_seed_from_the_sections),
    swept with runs of 5 revolutions after 5 and max_n = 1: the sections give no period
    (not settled) and Newton finds no stable period-1 orbit, so nothing is seeded; each
    stretch is said to have no period within 5 revolutions and not to be chaotic: the largest
    Lyapunov exponent of its run is negative."""
    T = 60 / 1650
    short = DOUBLING.replace(t_end=10 * T, t_transient=5 * T, n_out=201, section="shaft")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        with pytest.raises(pyspline.SplineError, match=r"no periodic attractor") as err:
            pyspline.branches(DOUBLING, "speed_rpm", 1646, 1650, points=3, max_n=1,
                              progress=False, sweep_case=short)
    said = re.findall(r"(up|down) \S+ \(no period found within 5 revolutions, not chaotic: "
                      r"largest Lyapunov exponent (\S+) 1/s", str(err.value))
    assert [d for d, _ in said] == ["up", "down"] and "(chaotic:" not in str(err.value), err.value
    assert all(float(lam) < 0 for _, lam in said), said


def test_period_two_seed_from_the_sections(monkeypatch):
    """DOUBLING above its period doubling (1623.6 r/min; the period-1 orbit unstable, a stable
    period-2 orbit, tests/test_continuation.py): the follow sweeps' runs that settled give
    period 2 from their exact sections, and the seed there is Newton on n = 2 alone (n = 1 not
    tried); a chain's first run, from the equilibrium, has not settled (no period): there the
    first n whose orbit is stable, 1 tried and refused (the unstable period-1 orbit). The
    branches are period 2 and stable over the band."""
    T = 60 / 1650
    settled = DOUBLING.replace(t_end=60 * T, t_transient=40 * T, n_out=201, section="shaft",
                               max_steps=10_000_000)
    tried = []
    orbit = pyspline.orbits.periodic_orbit
    monkeypatch.setattr(pyspline.orbits, "periodic_orbit", lambda c, n=1, **kw: tried.append(
        (c["speed_rpm"], n)) or orbit(c, n, **kw))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        ds, sw = pyspline.branches(DOUBLING, "speed_rpm", 1646, 1650, points=3, max_n=2,
                                   progress=False, sweep_case=settled)
    per = sw.period.values          # (direction up, down) x speed 1646, 1648, 1650
    assert per.tolist() == [[0, 2, 2], [2, 2, 0]], per
    # the middle of each period-2 stretch (1648, both ways): n = 2 only; the unsettled
    # first runs (1646 up, 1650 down): n = 1 refused, then 2
    assert tried == [(1646, 1), (1646, 2), (1648, 2), (1650, 1), (1650, 2), (1648, 2)]
    assert ds.attrs["status"] == "complete" and ds.attrs["no_period"] == ""
    assert (ds.n == 2).all() and ds.stable.all()
    assert float(ds.speed_rpm[0]) == 1646 and float(ds.speed_rpm[-1]) == pytest.approx(1650, rel=1e-12)
    # no point past stop (a corrector that converged there is put onto it)
    assert (ds.speed_rpm >= 1646).all() and (ds.speed_rpm <= 1650).all(), ds.speed_rpm.values


#: the doubling scene at rtol 1e-8 (the band's branches and the tests on them)
DOUBLING8 = DOUBLING.replace(rtol=1e-8, atol=1e-10)


@pytest.fixture(scope="module")
def doubling_band():
    """pyspline.branches of DOUBLING8 over 1617-1626 r/min (steps up to 0.5, follow sweeps of
    runs of 20 revolutions at 3 speeds), once per process."""
    T = 60 / 1650
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        ds, _ = pyspline.branches(DOUBLING8, "speed_rpm", 1617, 1626, points=3, max_n=2,
                                  progress=False, ds_max=0.5, max_angle=0.3,
                                  sweep_case=DOUBLING8.replace(t_end=20 * T, t_transient=10 * T,
                                                               section="shaft"))
    return ds


def test_branches_through_a_period_doubling(doubling_band):
    """DOUBLING over 1617-1626 r/min (rtol 1e-8, steps up to 0.5): the follow sweeps' runs have
    not settled (no period), the seed in the middle is the stable period-1 orbit; its branch
    doubles (a multiplier at -1) and the doubled branch is followed over the whole band, not
    only the seed's half (1621.5-1626): from the doubling down, unstable, to its fold (a
    multiplier of P^2 at +1) below the seed, and back up, stable, to stop. Its points are
    period-2 orbits (P^2(y) = y, P(y) away from y); two branches, none past the band."""
    from pyspline.orbits import _period_map, map_and_monodromy
    from test_orbits import scale_of
    case, ds = DOUBLING8, doubling_band
    assert ds.attrs["status"] == "complete" and ds.attrs["n_branches"] == 2
    p, b, n = ds.speed_rpm.values, ds.branch.values, ds.n.values
    assert ((p >= 1617) & (p <= 1626)).all()
    assert (n[b == 0] == 1).all() and (n[b == 1] == 2).all()
    kind, sp = ds.special_type.values, ds.special_speed_rpm.values
    mu = ds.special_mu_real.values + 1j * ds.special_mu_imag.values
    pd, fold = np.flatnonzero(kind == "period_doubling"), np.flatnonzero(kind == "fold")
    assert len(pd) == 1 and ds.special_branch[pd[0]] == 0 and abs(mu[pd[0]] + 1) < 1e-3
    assert len(fold) == 1 and ds.special_branch[fold[0]] == 1 and abs(mu[fold[0]] - 1) < 1e-2
    two, st = p[b == 1], ds.stable.values[b == 1].astype(bool)
    assert two[0] == pytest.approx(sp[pd[0]], abs=0.1) and two[-1] == pytest.approx(1626)
    assert sp[fold[0]] < 1621.5 and two.min() == pytest.approx(sp[fold[0]], abs=0.5)
    turn = np.argmin(two)
    assert not st[:turn - 1].any() and st[turn + 2:].all()
    y, s = ds.y0.values[b == 1][-1], scale_of(case)
    c = case.replace(speed_rpm=1626.0)
    y2, _, free = map_and_monodromy(c, 0.0, 2 * 60 / 1626, y)
    y1 = _period_map(c.model, 0.0, 60 / 1626, y[:, None])[0][:, 0]
    assert np.abs((y2 - y)[free] / s[free]).max() < 1e-5
    assert np.abs((y1 - y)[free] / s[free]).max() > 0.1


def _other_phase(ds, near):
    """The doubled branch's (branch 1's) stable point nearest `near` r/min: (p, y, P(y), the
    branch), P the map over one revolution."""
    from pyspline.orbits import section_points
    two = ds.isel(point=ds.branch.values == 1)
    k = np.argmin(np.abs(two.speed_rpm.values - near) + 100 * ~two.stable.values.astype(bool))
    p, y = float(two.speed_rpm[k]), two.y0.values[k]
    y_a, y_b = section_points(DOUBLING8.replace(speed_rpm=p).model, 0.0, 2, y)
    assert np.array_equal(y_a, y)
    return p, y, y_b, two


def test_period_two_seed_at_its_other_section_point(doubling_band):
    """A period-2 orbit has two section points, y and P(y): at the doubled branch's stable
    point nearest 1625 r/min, P(y) lies on the branch only through its section points (a seed
    there is the same orbit: branches does not continue it; y alone is a scaled distance of
    0.1 or more from it), and a copy of the whole doubled branch at its other section points
    is merged into it (diagram._distinct with the branches' phases: one seed kept, two
    without them). Tolerance: sqrt(tol), tol the corrector's 100 rtol (specials.same_point)."""
    from pyspline.diagram import _concat, _distinct, _on_branch, _phases
    from pyspline.orbits import section_points
    from test_orbits import scale_of
    s, tol = scale_of(DOUBLING8), 100 * DOUBLING8["rtol"]
    p, y, y_b, two = _other_phase(doubling_band, 1625)
    assert np.abs((y_b - y) / s).max() > 0.1
    assert _on_branch(two, "speed_rpm", p, y, s, tol)
    assert not _on_branch(two, "speed_rpm", p, y_b, s, tol)
    at = section_points(DOUBLING8.replace(speed_rpm=p).model, 0.0, 2, y_b)
    assert any(_on_branch(two, "speed_rpm", p, x, s, tol) for x in at)
    copy = two.copy(deep=True)
    copy["y0"] = (("point", "state"), _phases(DOUBLING8, "speed_rpm", two)[0])
    both = _concat([two, copy])
    assert list(_distinct(both, "speed_rpm", s, tol, lambda piece: _phases(
        DOUBLING8, "speed_rpm", piece))[1]) == [0]
    assert list(_distinct(both, "speed_rpm", s, tol)[1]) == [0, 1]


@pytest.mark.parametrize("phase", [0, 1])
def test_period_two_branch_ends_at_its_doubling(doubling_band, phase):
    """The period-2 orbit at 1625 r/min continued down (band 1615-1630) from its first section
    point y or its other one P(y): stable down to its fold at 1618.409 r/min (multiplier +1),
    back up unstable towards the period doubling (1623.61), where it meets the period-1
    branch: it ends there, its status saying so, and the doubling is located there, as on the
    period-1 branch. Before, from P(y) it went through the
    doubling onto y's half of the same orbit, down to the same fold and back up (traced twice,
    the fold located twice); from y it went on as period-2 points of the period-1 orbit. No
    point is a fixed point of P (P(y) 1e3 tol or more from y: 0.05 at 1623.605, next to the
    doubling, where P(y) - y goes as the root of the distance), the field turns once."""
    from pyspline.orbits import _period_map
    from test_orbits import scale_of
    p, y, y_b, _ = _other_phase(doubling_band, 1625)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        ds = pyspline.continuation(DOUBLING8, "speed_rpm", p, 1615, n=2, guess=(y, y_b)[phase],
                                   band=(1615, 1630), progress=False, ds_max=0.5, max_angle=0.3)
    assert re.fullmatch(r"the period-2 branch reached a period doubling between speed_rpm = "
                        r"\S+ and \S+, where it merges into the period-1 branch .*",
                        ds.attrs["status"]), ds.attrs["status"]
    q = ds.speed_rpm.values
    assert (ds.n == 2).all() and 1623 < q[-1] < 1623.61 and q.min() > 1618.4
    assert ((np.diff(q)[:-1] < 0) & (np.diff(q)[1:] > 0)).sum() == 1
    assert (np.diff(q)[np.argmin(q):] > 0).all() and (np.diff(q)[:np.argmin(q)] < 0).all()
    s = scale_of(DOUBLING8)
    for x, y0 in zip(q, ds.y0.values):
        y1 = _period_map(DOUBLING8.replace(speed_rpm=float(x)).model, 0.0, 60 / x,
                         y0[:, None])[0][:, 0]
        assert np.abs((y1 - y0)[:7] / s[:7]).max() > 1e3 * 100 * DOUBLING8["rtol"], x
    fold = np.flatnonzero(ds.special_type.values == "fold")
    assert len(fold) == 1 and ds.special_speed_rpm[fold[0]] == pytest.approx(1618.409, abs=1e-3)
    assert abs(complex(ds.special_mu_real[fold[0]], ds.special_mu_imag[fold[0]]) - 1) < 1e-2
    # the doubling where it ends, located on the period-1 orbit (ends.merge_doubling): the
    # period-1 branch's own to 1e-4 r/min (the corrector's tol 1e-6 moves a multiplier by
    # about 1e-6, and -1 moves by 0.018 per r/min there), its multiplier at -1
    pd, ref = (np.flatnonzero(d.special_type.values == "period_doubling") for d in
               (ds, doubling_band))
    assert len(pd) == 1 and ds.special_n[pd[0]] == 1 and ds.special_branch[pd[0]] == 0
    assert ds.special_speed_rpm[pd[0]] == pytest.approx(
        float(doubling_band.special_speed_rpm[ref[0]]), abs=1e-4)
    assert abs(complex(ds.special_mu_real[pd[0]], ds.special_mu_imag[pd[0]]) + 1) < 1e-3
    assert ds.special_smooth[pd[0]] == 1 and ds.special_n[fold[0]] == 2
    assert np.abs((ds.special_y0.values[pd[0]] - doubling_band.special_y0.values[ref[0]])
                  / s).max() < 1e-3


@pytest.fixture(scope="module")
def period_four():
    """The doubling scene's stable period-2 orbit at 1723.5 r/min (from a settled run) and its
    branch continued down to 1722.7 r/min, with the period-4 branch from its doubling."""
    from pyspline.orbits import periodic_orbit
    T = 60 / 1723.5
    case = DOUBLING8.replace(speed_rpm=1723.5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        orbit = periodic_orbit(case.replace(t_end=60 * T, t_transient=40 * T), n=2)
        ds = pyspline.continuation(case, "speed_rpm", 1723.5, 1722.7, n=2, guess=orbit.y0,
                                   band=(1722.7, 1725), progress=False, ds_max=0.5,
                                   max_angle=0.3)
    return case, orbit, ds


def test_period_two_branch_doubles_to_period_four(period_four, monkeypatch):
    """The doubling scene's period-2 branch (stable at 1723.5 r/min, from a settled run)
    continued down doubles at 1722.90 r/min (a multiplier of P^2 at -1), and the period-4
    branch is followed from there: its points are fixed points of P^4 (to 1e-5 scaled) and not
    of P^2 (1e3 tol or more away). Continued up, the period-4 branch ends at that doubling."""
    from pyspline.orbits import _period_map, periodic_orbit
    from test_orbits import scale_of
    case, orbit, ds = period_four
    assert orbit.stable and ds.attrs["status"] == "complete", ds.attrs["status"]
    kind, b = ds.special_type.values, ds.branch.values
    pd = np.flatnonzero(kind == "period_doubling")
    assert len(pd) == 1 and ds.special_n[pd[0]] == 2 and ds.special_branch[pd[0]] == 0
    assert abs(complex(ds.special_mu_real[pd[0]], ds.special_mu_imag[pd[0]]) + 1) < 1e-3
    assert 1722.8 < float(ds.special_speed_rpm[pd[0]]) < 1723.0
    assert (ds.n.values[b == 0] == 2).all() and (ds.n.values[b == 1] == 4).all()
    assert (b == 1).sum() >= 2
    s = scale_of(case)
    for x, y in zip(ds.speed_rpm.values[b == 1], ds.y0.values[b == 1]):
        m = case.replace(speed_rpm=float(x)).model
        y2, free = _period_map(m, 0.0, 2 * 60 / x, y[:, None])
        y4, _ = _period_map(m, 0.0, 4 * 60 / x, y[:, None])
        assert np.abs((y4[:, 0] - y)[free] / s[free]).max() < 1e-5, x
        assert np.abs((y2[:, 0] - y)[free] / s[free]).max() > 1e3 * 100 * case["rtol"], x
    # continued up from its orbit at 1722.898 r/min (short steps), the period-4 branch ends at
    # its merge into the period-2 branch: next to it its corrector stalls (steps fail), and
    # the doubling it leads into is located on the period-2 orbit (ends.reached_merge), as on
    # the period-2 branch to 1e-4 r/min. Before, its steps failed there until the bound.
    found, reached = [], pyspline.ends.reached_merge
    monkeypatch.setattr(pyspline.ends, "reached_merge",
                        lambda br, pts: found.append(reached(br, pts)) or found[-1])
    y = periodic_orbit(case.replace(speed_rpm=1722.898), n=4, guess=ds.y0.values[b == 1][0]).y0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        up = pyspline.continuation(case, "speed_rpm", 1722.898, 1722.95, n=4, guess=y,
                                   band=(1722.89, 1723), progress=False, ds=0.005, ds_max=0.01,
                                   max_angle=0.3)
    assert re.fullmatch(r"the period-4 branch reached a period doubling .* merges into the "
                        r"period-2 branch .*", up.attrs["status"]), up.attrs["status"]
    assert found and found[-1] is not None and up.sizes["special"] == 1
    q_d = float(ds.special_speed_rpm[pd[0]])
    assert up.special_type[0] == "period_doubling" and up.special_n[0] == 2
    assert float(up.special_speed_rpm[0]) == pytest.approx(q_d, abs=1e-4)
    assert abs(complex(up.special_mu_real[0], up.special_mu_imag[0]) + 1) < 1e-3
    assert (up.n == 4).all() and (up.speed_rpm < q_d).all()


def test_period_four_branch_turns_at_two_real_folds(period_four):
    """Below its merge the period-4 branch (continued up from its orbit at 1722.891 r/min)
    turns back at a fold near 1722.8935 r/min and up again at one near 1722.8929 r/min, with a
    grazing between (224 to 256 contact switches a period): real folds, not the corrector's.
    Each has its multiplier at +1 to 1e-3, the field turns back between them, where a real
    multiplier is above 1 (a saddle), and at a field value between them Newton at that value
    from the three parts' points nearest it finds three distinct period-4 orbits, the middle
    one unstable (a real multiplier > 1), the outer two stable."""
    from pyspline.orbits import periodic_orbit
    from test_orbits import scale_of
    case, _, ds = period_four
    y0 = ds.y0.values[ds.branch.values == 1][0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        y = periodic_orbit(case.replace(speed_rpm=1722.891), n=4, guess=y0).y0
        up = pyspline.continuation(case, "speed_rpm", 1722.891, 1722.8937, n=4, guess=y,
                                   band=(1722.88, 1722.9), progress=False, ds_max=0.5,
                                   max_angle=0.3)
    assert up.attrs["status"] == "complete", up.attrs["status"]
    kind = up.special_type.values
    assert list(kind) == ["fold", "grazing", "fold"], kind
    f1, g, f2 = up.special_speed_rpm.values
    assert 1722.8925 < f2 < g < f1 < 1722.894
    mu = up.special_mu_real.values + 1j * up.special_mu_imag.values
    assert abs(mu[0] - 1) < 1e-3 and abs(mu[2] - 1) < 1e-3 and (up.special_smooth[::2] == 1).all()
    p, top = up.speed_rpm.values, up.mu_real.values[:, 0]
    i1, i2 = np.flatnonzero(np.diff(np.sign(np.diff(p))) != 0) + 1     # the two turns
    assert p[i1] > p[i2] and (top[i1 + 1:i2] > 1).all()
    mid, parts = (f1 + f2) / 2, (slice(0, i1 + 1), slice(i1, i2 + 1), slice(i2, len(p)))
    orbits = []
    for part in parts:
        k = np.argmin(np.abs(p[part] - mid))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pyspline.SplineWarning)
            orbits.append(periodic_orbit(case.replace(speed_rpm=float(mid)), n=4,
                                         guess=up.y0.values[part][k]))
    s = np.array([o.y0 for o in orbits]) / scale_of(case)
    assert min(np.abs(s[i] - s[j]).max() for i, j in ((0, 1), (1, 2), (0, 2))) > 1e-3
    assert orbits[0].stable and orbits[2].stable and not orbits[1].stable
    assert orbits[1].multipliers[0].real > 1 and abs(orbits[1].multipliers[0].imag) < 1e-9


def test_period_four_branch_jumping_its_folds_is_a_failed_step(period_four, monkeypatch):
    """The period-4 branch continued up from its orbit at 1722.8766 r/min with the default
    first step: that step fails, and its predictor's contact sequence differs (224 to 256
    switches a period), so the failed step is diagnosed; on the bisection's hyperplanes the
    corrector lands past both folds (near 1722.898 r/min, the sequence past the grazing) or
    fails, so no grazing is located (before, the failed midpoints counted as past it and a
    grazing at 1722.8915 was handed on with that point beyond it, the folds skipped). The
    step is halved instead, the step that lands past the folds is rejected (no grazing located
    between), and the branch goes over both folds and the grazing between them."""
    from pyspline import specials
    from pyspline.orbits import periodic_orbit
    case, _, ds = period_four
    said, diagnose = [], specials.diagnose
    monkeypatch.setattr(specials, "diagnose", lambda *a: said.append(diagnose(*a)) or said[-1])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        y = periodic_orbit(case.replace(speed_rpm=1722.8766), n=4,
                           guess=ds.y0.values[ds.branch.values == 1][0]).y0
        up = pyspline.continuation(case, "speed_rpm", 1722.8766, 1723.2, n=4, guess=y,
                                   band=(1722.5, 1723.5), progress=False, ds_max=0.5,
                                   max_angle=0.3, max_points=16)
    assert said[:1] == [None] and up.attrs["diagnosed_grazings"] == 0
    assert up.attrs["rejected_unlocated"] >= 1 and up.attrs["status"].startswith("max_points")
    assert list(up.special_type.values) == ["fold", "grazing", "fold"], up.special_type.values
    f1, g, f2 = up.special_speed_rpm.values
    assert 1722.8925 < f2 < g < f1 < 1722.894
    mu = up.special_mu_real.values + 1j * up.special_mu_imag.values
    assert abs(mu[0] - 1) < 1e-3 and abs(mu[2] - 1) < 1e-3
    p = up.speed_rpm.values                  # up to the first fold, back, up again (a jump:
    turns = np.flatnonzero(np.diff(np.sign(np.diff(p))) != 0) + 1    # straight up)
    assert len(turns) == 2 and p[turns[0]] > p[turns[1]], p


@pytest.mark.parametrize("stop", [1620.085, 1620.1, 1620.12])
def test_switch_crossing_the_section_time(doubling_band, stop):
    """The stable period-2 orbit near 1619.3 r/min continued up past 1620.092 r/min, where its
    16 back flanks' engagement crosses the section time t0 (just before it below, 4.7 us after
    it at 1620.12): the contact sequence is the same either side (no grazing), and the branch
    ends on stop, complete, with the case's own settings (no fallback, no diagnosis), no point
    past it. At 1620.12 the one-output period map of the case's BDF from the last point closes
    on it to the corrector's tol (before the roots were settled on the landed state it closed
    1.5 scaled off: the engagement chattered), and an Adams map from a section 2-4.6 us later
    does too (it did not: 1.4)."""
    from pyspline.orbits import _period_map, _scale
    p, y, _, _ = _other_phase(doubling_band, 1619.3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        ds = pyspline.continuation(DOUBLING8, "speed_rpm", p, stop, n=2, guess=y,
                                   progress=False, ds_max=0.5, max_angle=0.3)
    q = ds.speed_rpm.values
    assert ds.attrs["status"] == "complete" and q[-1] == pytest.approx(stop, abs=1e-9)
    assert (q <= stop + 1e-9).all() and ds.attrs["diagnosed_grazings"] == 0, q
    assert ds.attrs["fallbacks"] == "none" and ds.attrs["rejected_unlocated"] == 0
    assert "grazing" not in ds.special_type.values and (ds.switches == ds.switches[0]).all()
    if stop != 1620.12:
        return
    y, T = ds.y0.values[-1], 2 * 60 / stop
    for method, ts in (("bdf", 0.0), ("adams", 2e-6), ("adams", 4e-6)):
        m = DOUBLING8.replace(speed_rpm=stop, method=method).model
        ys = _period_map(m, 0.0, ts, y[:, None])[0][:, 0] if ts else y
        y1, free = _period_map(m, ts, ts + T, ys[:, None])
        assert np.abs((y1[:, 0] - ys)[free] / _scale(m)[free]).max() < 1e-5, (method, ts)


def test_cli_all_and_fold_keep_what_they_have(tmp_path):
    """`pyspline continue --all` and `--fold` whose continuations stop short (--max-points 3, steps of
    0.23 r/min)
    or whose time bound passes at once (--max-seconds 1e-3) write what they have (the
    Datasets with their status, the figures), say where they stopped and exit 1."""
    import xarray as xr
    from test_continuation import RESONANCE, cli
    path = tmp_path / "drive.nml"
    path.write_text(RESONANCE.text())
    args = ("continue", path, "--field", "speed_rpm", "--start", "2300", "--stop", "2320",
            "--quiet", "--ds", "0.01")
    run = cli(tmp_path, *args, "--max-points", "3", "--all", "--sweep", "3", "--out", "all")
    assert run.returncode == 1, run.stderr
    assert re.search(r"stopped: seed \w+ speed_rpm = 23\d+ to 23\d+: max_points = 3 reached",
                     run.stderr), run.stderr
    ds = xr.open_dataset(tmp_path / "all" / "branches.nc", engine="netcdf4")
    assert ds.attrs["status"] in run.stderr and ds.sizes["point"] >= 3
    assert (tmp_path / "all" / "branches.png").stat().st_size > 10_000
    assert (tmp_path / "all" / "sweep.nc").exists()
    for extra, why in ((("--max-points", "3"), "max_points = 3 reached at speed_rpm"),
                       (("--max-seconds", "1e-3"), "max_seconds = 0.001 s")):
        out = tmp_path / f"fold{len(why)}"
        run = cli(tmp_path, *args, *extra, "--fold", "ripple_amp(1)=0.15", "--out", out)
        assert run.returncode == 1 and "stopped: " in run.stderr and why in run.stderr, \
            run.stderr
        fc = xr.open_dataset(out / "fold_curve.nc", engine="netcdf4")
        assert why in fc.attrs["status"] and np.isnan(fc.fold.values).all()
        assert (out / "fold_curve.png").exists()


def test_predictor_within_the_fields_range(monkeypatch):
    """Continued to the end of its valid range (zeta_m in 0..1) with steps of 0.05 and up to
    0.2 in zeta_m: every map run, predictor or corrector, is at a zeta_m within the range
    (a predictor past stop is put onto it; dF/dzeta_m one-sided at 1), the branch ends on 1,
    complete, no CaseError; and a corrector started outside the range is a rejected step
    (None, its error naming the range), not a CaseError."""
    import pyspline.arclength as arc
    from test_continuation import RESONANCE
    seen, evaluate = [], arc._Problem.evaluate
    monkeypatch.setattr(arc._Problem, "evaluate", lambda self, y, u, n: seen.append(
        self.p_of(u[-1])) or evaluate(self, y, u, n))
    case = RESONANCE.replace(zeta_m=0.9)
    ds = pyspline.continuation(case, "zeta_m", 0.9, 1.0, ds=0.5, ds_max=2.0, progress=False)
    p = ds.zeta_m.values
    assert ds.attrs["status"] == "complete" and ds.attrs["fallbacks"] == "none"
    assert p[0] == 0.9 and p[-1] == 1.0 and (np.diff(p) > 0).all() and len(p) >= 3
    assert len(seen) > len(p) and max(seen) == 1.0 and min(seen) == 0.9
    prob = arc._Problem(case, "zeta_m", None, 1, 0.9, 1.0, 0.0)
    y = ds.y0.values[-1]
    prob.free = arc._map_only(prob.model(1.0), 0.0, prob.t1(1.0, 1), y)[2]
    br = arc._Branch(prob, 1, y, 1e-7, 6)
    u = np.r_[y[prob.free] / prob.d0[prob.free], (1.05 - prob.p0) / prob.pscale]
    assert br.correct(u, np.eye(len(u))[-1], u[-1]) is None
    assert "zeta_m = 1.050E+00 is outside 0.00E+00 .. 1.00E+00" in br.last_error, \
        br.last_error


def test_realisations_transient_within_the_bound():
    """A realisations = 2 case whose transient alone would take minutes (1e5 s of the Z16
    drive, about 3 minutes; max_steps out of the way): a bounded run stops in its transient naming the bound,
    and inside a call's bound (orbits.time_bound, as branches and fold_curve) a follow sweep's
    first run is cut there and the next not run."""
    import time
    from pyspline.result import run
    from test_cont_bounds import SLACK
    from test_cont_drives import DRIVE
    case = DRIVE.replace(realisations=2, goal="statistics", t_transient=1e5,
                         t_end=1e5 + 0.05, n_out=201, linear_tail=False, max_steps=10_000_000)
    t = time.perf_counter()
    with pytest.raises(pyspline.SolverError, match=r"the run took longer than its wall-time "
                       r"bound max_seconds = 5.00E-01 s, at t = +\d"):
        run(case.model, max_seconds=0.5)
    assert time.perf_counter() - t < 0.5 + SLACK
    t = time.perf_counter()
    with pyspline.orbits.time_bound(1.0, "the test"):
        sw = pyspline.sweep(case, speed_rpm=[2200.0, 2210.0], follow="up", progress=False,
                            spectrum=False)
    assert time.perf_counter() - t < 1 + SLACK
    assert "the run took longer than its wall-time bound" in str(sw.error.values[0])
    assert str(sw.error.values[1]) == "the wall-time bound of the test, max_seconds = 1 s, " \
        "was reached before this run"


def test_cli_band(tmp_path):
    """`pyspline continue --band LO HI` is continuation's band: from 1623 to 1626 r/min on the
    doubling scene (the doubling at 1623.61) with --band 1621 1626 the doubled branch goes down
    past --start to 1621 (without it, it stops at 1623); the command says so. A band that is
    not two finite values LO < HI holding --start and --stop, or given with --all, is a
    CaseError naming --band, exit 2, before anything runs."""
    import xarray as xr
    from test_continuation import cli
    path = tmp_path / "doubling.nml"
    path.write_text(DOUBLING.replace(rtol=1e-8, atol=1e-10, speed_rpm=1623.0, n_out=201,
                                         t_end=0.2, t_transient=0.1).text())
    args = ("continue", path, "--field", "speed_rpm", "--start", "1623", "--stop", "1626",
            "--quiet")
    for band, why in ((("1626", "1621"), "two finite values LO < HI"),
                      (("1621", "1621"), "two finite values LO < HI"),
                      (("nan", "1626"), "two finite values LO < HI"),
                      (("1624", "1630"), "does not hold --start 1623"),
                      (("1620", "1625"), "does not hold --stop 1626")):
        run = cli(tmp_path, *args, "--band", *band, "--out", "bad")
        assert run.returncode == 2 and f"--band {float(band[0]):g} {float(band[1]):g}: " \
            f"{why}" in run.stderr, run.stderr
    run = cli(tmp_path, *args, "--band", "1621", "1626", "--all", "--out", "bad")
    assert run.returncode == 2 and "--band: " in run.stderr, run.stderr
    assert not (tmp_path / "bad").exists()
    run = cli(tmp_path, *args, "--band", "1621", "1626", "--out", "out")
    assert run.returncode == 0, run.stderr
    ds = xr.open_dataset(tmp_path / "out" / "continuation.nc", engine="netcdf4")
    p, b = ds.speed_rpm.values, ds.branch.values
    assert "--band 1621 1626" in ds.attrs["command"]
    assert (ds.n.values[b == 1] == 2).all() and p[b == 1].min() == pytest.approx(1621, abs=1e-9)
    assert p[b == 0].min() == 1623 and p.max() == pytest.approx(1626, abs=1e-9)


@PAPER_SHAFTS
def test_fallback_takes_its_own_tangent(monkeypatch):
    """The linear scene (full contact, tests/test_continuation.py) whose first method (the
    exact monodromy) has a wrong dF/dp column (1e3 times a random vector): its null-vector
    tangent at the start is off the branch and every step from it fails, down to ds_min. The
    fallback (differenced M, the same integrator) takes the tangent of its own [M - I, dF/dq]
    at the point, oriented to stop, and traces the branch to stop: every point the
    closed-form forced response. (With the tangent it had, every fallback failed and the
    branch was its start alone.)"""
    import pyspline.arclength as arc
    from test_continuation import forced_response
    from test_orbits import A_RIPPLE, linear_scene, scale_of
    case, *_ = linear_scene(2.0)
    evaluate = arc._Problem.evaluate

    def wrong(self, y, u, n):
        F, J, M, yy = evaluate(self, y, u, n)
        if self.how == "exact":
            J = np.c_[J[:, :-1], 1e3 * np.random.default_rng(1).standard_normal(len(F))]
        return F, J, M, yy
    monkeypatch.setattr(arc._Problem, "evaluate", wrong)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        ds = pyspline.continuation(case, "speed_rpm", 2600, 2650, progress=False, ds_min=0.01,
                                   max_points=6)
    assert ds.attrs["status"] == "complete", ds.attrs["status"]
    assert ds.attrs["fallbacks"].startswith("speed_rpm = 2600: fd monodromy, method bdf")
    p = ds.speed_rpm.values
    assert len(p) >= 2 and p[-1] == pytest.approx(2650) and (np.diff(p) > 0).all(), p
    s = scale_of(case)
    for q, y0 in zip(p, ds.y0.values):
        y_eq, Y, _ = forced_response(case, q, 2.0, A_RIPPLE)
        assert np.abs((y0 - (y_eq + Y.real)) / s).max() < 1e-7


@PAPER_SHAFTS
def test_diagnosed_crossing_past_the_end_is_dropped(monkeypatch):
    """A failed step whose diagnosis (specials.diagnose) hands back a point past stop (its
    corrector's hyperplane lies across the tangent, not across the field: made up here, on the
    linear scene, by a diagnosis that returns the point before it moved 1 r/min past stop, and
    one corrector that fails) does not put it on the branch: the crossing is dropped, the step
    goes on as a failed one, and the branch ends on stop, complete, no point past it."""
    import pyspline.arclength as arc
    import pyspline.specials as specials
    from test_orbits import linear_scene
    case, *_ = linear_scene(2.0)
    correct, failed, handed = arc._Branch.correct, [], []

    def once_failing(self, u, row, target):
        if row[-1] != 1 and not failed:             # the first step off the start fails
            failed.append(True)
            return None
        return correct(self, u, row, target)

    def past_stop(br, a, pred, step):
        u = a["u"].copy()
        u[-1] = (2621 - 2600) / br.prob.pscale
        handed.append(dict(a, u=u, p=2621.0))
        return handed[-1:]
    monkeypatch.setattr(arc._Branch, "correct", once_failing)
    monkeypatch.setattr(specials, "diagnose", past_stop)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        ds = pyspline.continuation(case, "speed_rpm", 2600, 2620, progress=False, max_points=10)
    assert handed and ds.attrs["status"] == "complete" and ds.attrs["diagnosed_grazings"] == 0
    assert (ds.speed_rpm <= 2620).all() and float(ds.speed_rpm[-1]) == pytest.approx(2620)
