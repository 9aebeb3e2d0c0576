"""Continuation on a 7-DOF drive with clearance (docs/continuation.md): the paper's Z = 16
spline in bending-torsion (dof 7) with shafts of k_t = 1000 N m/rad, a mesh damping ratio of
0.01 per tooth pair and a torque ripple of 25 % at order 1 near the mesh resonance (40 Hz:
2400 r/min). Over 2200-2500 r/min its response is an S-curve: the full-contact branch opens
the teeth at a grazing, folds back unstable, then folds again onto an upper branch that loses
contact every revolution. rtol 1e-8 (the folds move by 1e-5 r/min from rtol 1e-9, the S-curve
takes half the time). Held against the closed-form full-contact response, follow sweeps
at 1 r/min steps and the multipliers' meaning."""
import functools
import importlib
import warnings

import numpy as np
import pytest

import pyspline
from conftest import CASES
from test_continuation import forced_response
from test_orbits import scale_of

DRIVE = pyspline.load_case(CASES / "paper_ideal.nml", start="equilibrium", rtol=1e-8,
                           atol=1e-10, t_end=0.05, n_out=201, roots=True, dof=7,
                           k_t1=1e3, k_t2=1e3, zeta_m=0.01, ripple_order=[1, 0, 0, 0],
                           ripple_amp=[0.25, 0, 0, 0])
BAND = (2200.0, 2500.0)
S_BAND = (2250.0, 2480.0)   # the S-curve of pyspline.branches (every_branch_of_the_band)


def continued(method, band):
    with warnings.catch_warnings():
        warnings.simplefilter("error", pyspline.SplineWarning)   # complete: no warning but
        warnings.filterwarnings(                                  # CVODE's "t + h = t" at a
            "ignore", r"SUNDIALS warned in \d+ of the continuation's map runs",  # grazing,
            pyspline.SplineWarning)                                # said once (attrs)
        return pyspline.continuation(DRIVE.replace(method=method), "speed_rpm", *band,
                                     progress=False)


def grazing_closed_form():
    """The speed at which the closed-form full-contact response's smallest tooth force
    reaches zero: the swing of D2 reaches the static contact deflection |D2_eq| - c0 (every
    tooth at once in the aligned drive)."""
    def margin(p):
        y_eq, Y, _ = forced_response(DRIVE, p, 1.0, 0.25)
        return abs(y_eq[5]) - DRIVE["c0"] - abs(Y[5])
    lo, hi = BAND
    assert margin(lo) > 0 > margin(hi)
    for _ in range(40):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if margin(mid) > 0 else (lo, mid)
    return lo


@pytest.mark.parametrize("method", ["bdf", "adams", "erk"])
def test_full_contact_branch_is_the_closed_form(method):
    """Below the grazing every tooth stays in contact: over 1800-2400 r/min each point of the
    branch is the closed-form forced response y_eq + Re Y(omega), with every integrator."""
    ds = pyspline.continuation(DRIVE.replace(method=method), "speed_rpm", 1800, 2400,
                               progress=False)
    assert ds.attrs["status"] == "complete" and ds.attrs["n_special"] == 0
    assert ds.speed_rpm[-1] == pytest.approx(2400, rel=1e-12) and ds.attrs["n_points"] >= 5
    s = scale_of(DRIVE)
    for p, y0 in zip(ds.speed_rpm.values, ds.y0.values):
        y_eq, Y, _ = forced_response(DRIVE, p, 1.0, 0.25)
        err = np.abs((y0 - (y_eq + Y.real)) / s).max()
        assert err < 1e-4 * np.abs(Y / s).max(), (p, err)
    assert (ds.switches == 0).all() and ds.stable.all()


@functools.cache
def every_branch_of_the_band():
    """pyspline.branches over 2250-2480 r/min (S_BAND), seeded by follow sweeps at 10 r/min
    steps (runs of 2 s, the last 1 s at 200 samples a revolution), once per process: its one
    branch is the S-curve here, the branches' tests in tests/test_branches.py. The up sweep's
    seed (the middle of its stretch, 2340 r/min) lies below the lower fold, so its branch is
    the whole S-curve and the down sweep's seed lies on it (a seed inside the hysteresis would
    trace only the part of the S-curve that stays above it, and the down sweep's the rest)."""
    settled = DRIVE.replace(t_end=2.0, t_transient=1.0, n_out=8001)
    return pyspline.branches(DRIVE, "speed_rpm", *S_BAND, points=24, progress=False,
                             sweep_case=settled)


@pytest.fixture(scope="module")
def s_curve():
    """The whole S-curve over the band with the case's own method (paper_ideal's Adams; 'auto'
    picks it for a given k_m too: test_auto_is_adams_here), continued from the seed at 2340
    r/min down to the band's start and up to its stop, complete: one branch."""
    ds, _ = every_branch_of_the_band()
    assert ds.attrs["status"] == "complete" and ds.attrs["n_branches"] == 1
    return ds


def test_auto_is_adams_here():
    """method = 'auto' picks Adams for a given k_m by its own rule: its continuation is the
    Adams one bit for bit (4 points here; the whole S-curve was bit for bit too)."""
    case = DRIVE.replace(method="auto")
    assert case["method"] == "auto" and DRIVE["method"] == "adams"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)    # max_points reached
        auto, adams = (pyspline.continuation(c, "speed_rpm", *S_BAND, max_points=4,
                                             progress=False) for c in (case, DRIVE))
    assert auto.sizes["point"] == adams.sizes["point"] == 4
    for v in adams.data_vars:
        assert np.array_equal(auto[v].values, adams[v].values), v


@functools.cache
def _follow_sweeps():
    speeds = np.arange(2340.0, 2451.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        sw = pyspline.sweep(DRIVE.replace(t_end=0.3, t_transient=0.2, n_out=401),
                            speed_rpm=speeds, follow="both", progress=False, spectrum=False)
    assert (sw.error == "").all()
    return speeds, (sw.Tm_max - sw.Tm_min).values


@pytest.fixture
def follow_sweeps():
    """Follow sweeps up and down over the hysteresis at 1 r/min steps: (speeds, T_m
    peak-to-peak (direction, speed)). Up from 2340 (below the lower fold: one orbit), down
    from 2450 (above the upper fold: one orbit). Run once per process (tests/test_branches.py
    holds its branches against them too)."""
    return _follow_sweeps()


def folds(ds):
    return np.sort(ds.special_speed_rpm.values[ds.special_type.values == "fold"])


def test_s_curve_folds_where_the_follow_sweeps_jump(s_curve, follow_sweeps):
    """Two folds, each with a multiplier at +1, within 0.5 % of where the follow sweeps jump
    (up: off the full-contact branch at the upper fold; down: off the contact-loss branch at
    the lower fold); the branch is traced from start to stop and turns back only there."""
    folds_at_the_jumps(s_curve, follow_sweeps)


def test_erk_traces_the_s_curve(follow_sweeps):
    """With ERK too: the whole S-curve, folds where the follow sweeps jump, from the band's
    start in one continuation. Over 2330-2470 r/min, where ERK stalled at 2356.01 r/min while
    its map lost switches in the teeth's clusters (test_erk.py::
    test_every_switch_of_a_cluster_is_located_with_erk): dF/dp by differences of that map was
    off by 800 (Adams 4), and the null vector of [M - I, dF/dq] 60 degrees off the branch."""
    band = (2330.0, 2470.0)
    folds_at_the_jumps(continued("erk", band), follow_sweeps, band)


def folds_at_the_jumps(ds, follow_sweeps, band=S_BAND):
    lo, hi = folds(ds)
    speeds, pp = follow_sweeps
    up = speeds[np.argmax(np.diff(pp[0])) + 1]      # the first speed on the upper branch
    down = speeds[np.argmax(np.diff(pp[1]))]        # the last speed on the lower branch
    assert hi == pytest.approx(up, rel=5e-3) and lo == pytest.approx(down, rel=5e-3)
    assert down < lo < hi < up, (down, lo, hi, up)
    p = ds.speed_rpm.values
    assert p[0] == pytest.approx(band[0], rel=1e-12)
    assert p[-1] == pytest.approx(band[1], rel=1e-12)
    turns = p[np.flatnonzero(np.diff(np.sign(np.diff(p)))) + 1]
    assert len(turns) == 2 and np.allclose(turns, [hi, lo], atol=0.5)
    sp = ds.special_type.values == "fold"
    mu = ds.special_mu_real.values[sp] + 1j * ds.special_mu_imag.values[sp]
    assert np.abs(mu - 1).max() < 1e-3 and (ds.special_smooth.values[sp] == 1).all()


def test_s_curve_grazing_where_the_closed_form_opens_a_tooth(s_curve):
    """The first grazing is where the closed-form full-contact response's smallest tooth
    force reaches zero; the full-contact branch below it, contact lost every revolution on
    the upper branch."""
    ds = s_curve
    first = list(ds.special_type.values).index("grazing")
    assert float(ds.special_speed_rpm[first]) == pytest.approx(grazing_closed_form(), abs=0.1)
    p, sw = ds.speed_rpm.values, ds.switches.values
    i_hi = np.flatnonzero(np.diff(p) < 0)[0]      # the upper fold
    assert (sw[:i_hi][p[:i_hi] < grazing_closed_form() - 0.5] == 0).all()
    assert (sw[-5:] > 0).all()


def test_s_curve_middle_branch_has_a_real_multiplier_beyond_one(s_curve):
    """Between the folds (along the branch) the orbit is a saddle: a real multiplier > +1;
    stable before the first fold and after the second."""
    ds = s_curve
    p, stable = ds.speed_rpm.values, ds.stable.values.astype(bool)
    i1, i2 = np.flatnonzero(np.diff(np.sign(np.diff(p)))) + 1
    mu = ds.mu_real.values + 1j * ds.mu_imag.values
    for i in range(i1 + 1, i2):
        real = mu[i][np.abs(mu[i].imag) < 1e-9]
        assert real.real.max() > 1 + 1e-4, (p[i], mu[i])
    assert stable[:i1 - 1].all() and not stable[i1 + 1:i2].any() and stable[i2 + 1:].all()


@pytest.fixture(scope="module")
def upper_orbit(s_curve):
    """An orbit of the upper branch next to 2400 r/min (contact lost every revolution): the
    S-curve's point nearest 2400 r/min after its second fold; the corrector below converges
    from it onto the upper orbit at 2400 r/min."""
    p = s_curve.speed_rpm.values
    i2 = (np.flatnonzero(np.diff(np.sign(np.diff(p)))) + 1)[1]
    k = i2 + 1 + np.argmin(np.abs(p[i2 + 1:] - 2400))
    assert abs(p[k] - 2400) < 2 and s_curve.switches[k] > 0
    return s_curve.y0.values[k]


def onto_the_upper_orbit(monkeypatch, y_up):
    """Makes the first corrector from a predictor within 2395-2415 r/min converge on the upper
    orbit at 2400 r/min (as a long step across a fold can; from y_up, next to it); the speeds
    it did so at."""
    cont = importlib.import_module("pyspline.arclength")
    original, jumped = cont._Branch.correct, []

    def onto_the_upper_branch(self, u_pred, row, target):
        if not jumped and 2395 < self.prob.p_of(u_pred[-1]) < 2415:
            jumped.append(u_pred[-1])       # converges on the upper orbit at 2400 r/min
            q = (2400 - self.prob.p0) / self.prob.pscale
            u_pred, row, target = np.r_[(y_up / self.prob.d0)[self.prob.free], q], 0 * row, q
            row[-1] = 1
        return original(self, u_pred, row, target)
    monkeypatch.setattr(cont._Branch, "correct", onto_the_upper_branch)
    return jumped


def full_contact_to_the_end(ds):
    assert ds.attrs["status"] == "complete" and ds.speed_rpm[-1] == pytest.approx(2420, rel=1e-12)
    assert (ds.switches == 0).all() and np.all(np.diff(ds.speed_rpm) > 0)


def test_a_step_onto_another_branch_is_rejected(monkeypatch, upper_orbit):
    """Inside the hysteresis two orbits coexist. A corrector made to converge on the upper
    branch's orbit lands far from its predictor: the step is rejected
    (attrs['rejected_jumps']), halved, and the full-contact branch is still traced from start
    to stop; without the check the branch would go on along the upper one."""
    jumped = onto_the_upper_orbit(monkeypatch, upper_orbit)
    ds = pyspline.continuation(DRIVE, "speed_rpm", 2380, 2420, progress=False)
    assert jumped and ds.attrs["rejected_jumps"] == 1 and ds.attrs["rejected_unlocated"] == 0
    full_contact_to_the_end(ds)


def test_a_changed_contact_sequence_needs_its_grazing(monkeypatch, upper_orbit):
    """The same jump with the distance check disabled: the converged point's contact sequence
    (32 switches a period, from none) changed with no grazing located between (bisection on
    the step finds the full-contact orbit up to the point, and the two either side of the
    bracket a branch apart), so the step is rejected (attrs['rejected_unlocated']) and the
    full-contact branch traced to the end."""
    spec = importlib.import_module("pyspline.specials")
    jumped = onto_the_upper_orbit(monkeypatch, upper_orbit)
    monkeypatch.setattr(spec, "far", lambda u, pred, ds: False)
    ds = pyspline.continuation(DRIVE, "speed_rpm", 2380, 2420, progress=False, detect=False)
    assert jumped and ds.attrs["rejected_jumps"] == 0 and ds.attrs["rejected_unlocated"] == 1
    full_contact_to_the_end(ds)


def test_a_failed_step_across_the_grazing_is_diagnosed(monkeypatch):
    """A step from the full-contact branch across the grazing (2436.05 r/min) whose corrector
    is made to fail: the predicted orbit loses contact where the last point did not, so the
    grazing is located by bisection on the step and the branch goes on past it
    (attrs['diagnosed_grazings']), not by halving the step; the grazing and the end point are
    those of the undisturbed continuation (whose step across converges, and whose grazing is
    located by the same-branch check)."""
    cont = importlib.import_module("pyspline.arclength")
    original, failed = cont._Branch.correct, []

    def fails_once_past_the_grazing(self, u_pred, row, target):
        if not failed and self.prob.p_of(u_pred[-1]) > 2436.2:
            failed.append(self.prob.p_of(u_pred[-1]))
            self.last_hist = [np.nan]
            return None
        return original(self, u_pred, row, target)

    def graze_to_end():
        ds = pyspline.continuation(DRIVE, "speed_rpm", 2380, 2438, ds=0.25,
                                   progress=False)
        assert ds.attrs["status"] == "complete" and list(ds.special_type.values) == ["grazing"]
        return ds
    plain = graze_to_end()
    monkeypatch.setattr(cont._Branch, "correct", fails_once_past_the_grazing)
    ds = graze_to_end()
    assert failed and ds.attrs["diagnosed_grazings"] == 1 and plain.attrs["diagnosed_grazings"] == 0
    g, g0 = float(ds.special_speed_rpm[0]), float(plain.special_speed_rpm[0])
    assert g == pytest.approx(grazing_closed_form(), abs=0.1) and g == pytest.approx(g0, abs=0.05)
    s = scale_of(DRIVE)
    assert np.abs((ds.y0.values[-1] - plain.y0.values[-1]) / s).max() < 1e-5
