"""Continuation of periodic orbits (pyspline.continuation, docs/continuation.md): held against
the closed-form forced response of the linear full-contact drive, the closed-form speed at
which that response first opens a tooth (grazing), folds of the backlash resonance with a
multiplier at +1 and the hysteresis of follow-up / follow-down sweeps between them, the CLI."""
import subprocess
import sys
import warnings

import numpy as np
import pytest

import pyspline
from conftest import CASES, jacobian
from test_orbits import A_RIPPLE, linear_scene, scale_of

# a drive whose ripple reaches the mesh: the paper's aligned drive at dof 3 with shafts of
# k_t = 1000 N m/rad (the paper's 7.9 filter the ripple out); its mesh mode near 45 Hz
# (damping ratio 0.014) is forced by a ripple of order 1, a = 0.15: the linear response would
# open the teeth near 2510 rpm, so the resonance bends over (softening), folds twice and
# hits the back flanks
RESONANCE = pyspline.load_case(CASES / "paper_ideal.nml", start="equilibrium", method="bdf",
                               rtol=1e-9, atol=1e-11, t_end=0.05, n_out=201, roots=True, dof=3,
                               k_t1=1e3, k_t2=1e3, ripple_order=[1, 0, 0, 0],
                               ripple_amp=[0.15, 0, 0, 0])


def forced_response(case, rpm, order, amp):
    """(y_eq, Y, A) of the linear full-contact drive at speed rpm: static equilibrium, complex
    amplitude of the forced response y_eq + Re[Y exp(i order omega t)], and its Jacobian."""
    c = case.replace(speed_rpm=float(rpm))
    model = c.model
    y_eq = model.start_state()
    A = jacobian(model, y_eq)
    info = model.info()
    B = np.zeros(14, complex)
    B[11] = -1j * (-info["r_b"] * c["t_d"] * amp / c["j_m"])
    return y_eq, np.linalg.solve(1j * order * info["omega"] * np.eye(14) - A, B), A


@pytest.fixture(scope="module")
def resonance_branch():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        return pyspline.continuation(RESONANCE, "speed_rpm", 2300, 2530, progress=False)


def test_linear_branch_is_the_closed_form():
    """Full contact: every point of the branch over speed through the mesh resonance is the
    closed-form forced response y_eq + Re Y(omega), its multipliers exp(lambda_i T); all
    stable, no special point."""
    case, *_ = linear_scene(2.0)
    ds = pyspline.continuation(case, "speed_rpm", 2600, 3800, progress=False, ds=0.1)
    s = scale_of(case)
    assert ds.attrs["n_points"] >= 5 and ds.attrs["n_special"] == 0
    assert ds.speed_rpm[0] == 2600 and ds.speed_rpm[-1] == pytest.approx(3800, rel=1e-12)
    assert np.all(np.diff(ds.speed_rpm) > 0)
    amp = []
    for p, y0, mu in zip(ds.speed_rpm.values, ds.y0.values,
                         ds.mu_real.values + 1j * ds.mu_imag.values):
        y_eq, Y, A = forced_response(case, p, 2.0, A_RIPPLE)
        amp.append(np.abs(Y / s).max())
        # the corrector's tol (100 rtol) times |(I - M)^-1| (< 10 here), 1e5 below the response
        assert np.abs((y0 - (y_eq + Y.real)) / s).max() < 1e-7 < 1e-4 * amp[-1]
        want = np.exp(np.linalg.eigvals(A) * 2 * np.pi / (p * np.pi / 30))
        assert max(np.abs(mu - w).min() for w in want) < 1e-5
    assert ds.stable.all() and (ds.switches == 0).all()
    # T_m peak-to-peak peaks at the mesh mode (105 Hz: 3160 rpm at order 2)
    assert 2900 < float(ds.speed_rpm[int(ds.Tm_pp.argmax())]) < 3450
