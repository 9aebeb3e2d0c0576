"""Continuation on a 7-DOF Z = 24 drive (docs/continuation.md): the Z16 drive of
tests/test_cont_drives.py with 24 teeth (the same stiff shafts k_t = 1000 N m/rad, mesh
damping ratio 0.01 per tooth pair, 25 % torque ripple at order 1; 24 teeth in parallel put
the mesh resonance near 49 Hz, 2950 r/min). Over 2910-2995 r/min the full-contact branch
opens its teeth at a grazing (2971.7 r/min), folds twice within 0.26 r/min (2975.72 and
2975.46: two contact-loss orbits of 48 switches a period coexist there), runs on to the upper
fold (2987.97), back as a saddle to the lower fold (2915.40) and up again on the branch of
96 switches. rtol 1e-7 (the folds move by less than 1e-3 r/min from rtol 1e-8, at two
thirds of the time). Held against follow sweeps at 2 r/min (and at 0.05 r/min across the
narrow pair) and the closed-form full-contact response."""
import warnings

import numpy as np
import pytest
from scipy.optimize import brentq

import pyspline
from test_cont_drives import DRIVE
from test_continuation import forced_response

Z24 = DRIVE.replace(z=24, rtol=1e-7, atol=1e-9)
BAND = (2910.0, 2995.0)


@pytest.fixture(scope="module")
def branch():
    """The whole branch over the band from one call, with the case's own method (Adams);
    ds_max 0.5 (124 points, 5 s of CPU, the same folds as 0.25 to 1e-3 r/min)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", pyspline.SplineWarning)   # complete: no warning but
        warnings.filterwarnings(                                  # CVODE's, said once
            "ignore", r"SUNDIALS warned in \d+ of the continuation's map runs",
            pyspline.SplineWarning)
        return pyspline.continuation(Z24, "speed_rpm", *BAND, ds_max=0.5, progress=False)


def folds(ds):
    return np.sort(ds.special_speed_rpm.values[ds.special_type.values == "fold"])


def chain(case, speeds, start=None):
    """T_m peak-to-peak of a follow chain over `speeds` (in the order given) from the case's
    start, or from the orbit state `start` (SI, at t0) at the first speed."""
    if start is not None:
        case = case.replace(start="rest", dq0=list(start[:7]), dv0=list(start[7:]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        sw = pyspline.sweep(case, speed_rpm=np.asarray(speeds), progress=False, spectrum=False,
                            follow="up" if speeds[-1] > speeds[0] else "down")
    assert (sw.error == "").all()
    return (sw.Tm_max - sw.Tm_min).values.ravel()


def test_outer_folds_where_the_follow_sweeps_jump(branch):
    """Four folds, each with a multiplier at +1 (smooth); the outer two within 0.5 % of where
    follow sweeps at 2 r/min steps over the band jump (up: off the branch below the upper
    fold; down: off the upper branch at the lower fold); the branch from start to stop
    turns back only at the folds."""
    ds = branch
    assert ds.attrs["status"] == "complete"
    f = folds(ds)
    assert len(f) == 4
    speeds = np.arange(*BAND, 2.0)
    settle = Z24.replace(t_end=0.3, t_transient=0.2, n_out=401)
    up, down = chain(settle, speeds), chain(settle, speeds[::-1])[::-1]
    jump_up = speeds[np.argmax(np.diff(up)) + 1]        # the first speed on the upper branch
    jump_down = speeds[np.argmax(np.diff(down))]        # the last speed on the lower branch
    assert f[-1] == pytest.approx(jump_up, rel=5e-3) and f[0] == pytest.approx(jump_down,
                                                                               rel=5e-3)
    assert jump_down < f[0] < f[-1] < jump_up
    p = ds.speed_rpm.values
    i = np.flatnonzero(np.diff(np.sign(np.diff(p)))) + 1    # the sampled turns
    order = np.argsort(p[i])
    step = np.maximum(abs(p[i] - p[i - 1]), abs(p[i + 1] - p[i]))[order]
    assert len(i) == 4 and (abs(p[i][order] - f) <= step).all()   # each fold within a step
    sp = ds.special_type.values == "fold"
    mu = ds.special_mu_real.values[sp] + 1j * ds.special_mu_imag.values[sp]
    assert np.abs(mu - 1).max() < 1e-2 and (ds.special_smooth.values[sp] == 1).all()


def test_the_narrow_fold_pair_is_real(branch):
    """The inner folds, 0.26 r/min apart, bound two coexisting stable orbits: a follow chain
    at 0.05 r/min steps from the branch's orbit below them stays on it past the lower of the
    two and makes its largest step (T_m peak-to-peak up by more than 4 %) within three steps
    above the upper one; from the orbit above them, down, its largest drop comes within three
    steps below the lower one. Runs of 2 s (the multipliers of 0.975 a revolution need about
    40 revolutions a decade; next to a fold the passage is slower: the run one step past it
    is still on its way)."""
    ds = branch
    a, b = folds(ds)[1:3]
    assert 0.1 < b - a < 0.5
    p = ds.speed_rpm.values
    i_below = np.flatnonzero(p < a - 0.2)
    i_below = i_below[i_below < np.argmax(p > b)][-1]           # on the way up, before them
    i_above = np.flatnonzero((p > b + 0.05) & (np.arange(len(p)) > np.argmax(p > b)))[0]
    settle = Z24.replace(t_end=2.0, t_transient=1.8, n_out=801)
    up_speeds = np.round(np.arange(a - 0.2, b + 0.2, 0.05), 3)
    up = chain(settle.replace(speed_rpm=up_speeds[0]), up_speeds, ds.y0.values[i_below])
    k = np.argmax(np.diff(up)) + 1                 # the speed its largest step reaches
    assert np.diff(up).max() > 0.04 * up.max()
    assert b < up_speeds[k] <= b + 0.151, (up_speeds, up)
    down_speeds = up_speeds[::-1]
    down = chain(settle.replace(speed_rpm=down_speeds[0]), down_speeds, ds.y0.values[i_above])
    k = np.argmax(-np.diff(down)) + 1
    assert (-np.diff(down)).max() > 0.02 * down.max()
    assert a - 0.151 <= down_speeds[k] < a, (down_speeds, down)


def test_grazing_where_the_closed_form_opens_a_tooth(branch):
    """The first grazing is where the closed-form full-contact response's smallest tooth force
    reaches zero (the swing of D2 reaches the static contact deflection |D2_eq| - c0: every
    tooth at once in the aligned drive); the branch below it is in full contact."""
    def margin(p):
        y_eq, Y, _ = forced_response(Z24, p, 1.0, 0.25)
        return abs(y_eq[5]) - Z24["c0"] - abs(Y[5])
    assert margin(BAND[0]) > 0 > margin(BAND[1])
    lo = brentq(margin, *BAND, xtol=1e-6)
    ds = branch
    first = list(ds.special_type.values).index("grazing")
    assert float(ds.special_speed_rpm[first]) == pytest.approx(lo, abs=0.1)
    p, sw = ds.speed_rpm.values, ds.switches.values
    before = np.arange(len(p)) < np.argmax(np.diff(p) < 0)
    assert (sw[before & (p < lo - 0.5)] == 0).all() and (sw[-5:] == 96).all()


def test_special_points_lie_on_their_branch(branch):
    """branches' merge criterion (a point within a tenth of a chord of the branch's nearest
    segment) finds every located fold and grazing on the branch: a fold lies beyond the field
    values sampled on either side of it, where interpolating at the same field value found
    no bracket and a seed's branch that ended there was kept as a second branch. Moved off by
    5 % of each state's swing along the branch, none is on it."""
    from pyspline.diagram import _on_branch
    from test_orbits import scale_of
    ds, s = branch, scale_of(Z24)
    swing = np.ptp(ds.y0.values, axis=0)
    for p, y in zip(ds.special_speed_rpm.values, ds.special_y0.values):
        assert _on_branch(ds, "speed_rpm", p, y, s, ds.attrs["tol"]), p
        assert not _on_branch(ds, "speed_rpm", p, y + 0.05 * swing, s, ds.attrs["tol"]), p
