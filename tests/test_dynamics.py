"""Nonlinear-dynamics outputs of the core (issue 11): exact Poincare sections and the largest
Lyapunov exponent (Benettin), checked against closed forms and the linearised system."""
import numpy as np
import pytest

import pyspline
from pyspline.analysis import classify_period
from conftest import CASES, jacobian, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

LX = pyspline.load_case(CASES / "paper_lx1e-4.nml")


def test_section_times_are_whole_revolutions_and_tooth_passes():
    case = LX.replace(t_end=0.1, t_transient=0.0305, n_out=5)
    T = 60.0 / case["speed_rpm"]
    shaft = pyspline.simulate(case.replace(section="shaft"))
    k = np.arange(4, 11)                                   # 0.04 .. 0.1 s
    np.testing.assert_allclose(shaft.section_t, k * T, rtol=1e-14)
    tooth = pyspline.simulate(case.replace(section="tooth"))
    assert len(tooth.section_t) == 160 - 49 + 1            # k T/16 in [0.0305, 0.1] s: k = 49..160
    np.testing.assert_allclose(np.diff(tooth.section_t), T / 16, rtol=1e-9)
    assert pyspline.simulate(case).section_t.shape == (0,)


def test_section_states_are_the_states_at_those_instants():
    """Against a tight reference sampled at the same times: the section state is the state at
    the instant, as accurate as the integrator's own output at that instant (its global error
    over 20 revolutions), with no interpolation between output samples."""
    case = LX.replace(t_end=0.2, n_out=3, rtol=1e-7, atol=1e-9, section="shaft")
    res = pyspline.simulate(case)
    ts = res.section_t
    at_ts = dict(section="none", t_transient=ts[0], t_end=ts[-1], n_out=len(ts))
    ref = pyspline.simulate(case.replace(rtol=1e-12, atol=1e-14, **at_ts))
    out = pyspline.simulate(case.replace(**at_ts))          # same rtol, output at the instants
    np.testing.assert_allclose(ref.t, ts, rtol=1e-13)
    scale = np.abs(ref.y).max(axis=0)
    err = (np.abs(res.section_y - ref.y).max(axis=0) / scale).max()
    err_out = (np.abs(out.y - ref.y).max(axis=0) / scale).max()
    assert err < 1e-4 and err < 3 * err_out, (err, err_out)


def test_settled_scene_is_period_one():
    """From its static equilibrium the misaligned paper drive runs in full contact: a linear,
    isotropic spring (docs/model.md), so the shaft section is a fixed point."""
    res = pyspline.simulate(LX.replace(start="equilibrium", t_end=0.5, n_out=3,
                                       section="shaft"))
    period, info = classify_period(res.section_y[:, [5, 12]], LX["rtol"],
                                   scale=[LX["c0"], LX["c0"] * 628.3])
    assert period == 1, info


def linearised_rates(model):
    """Eigenvalues of the Jacobian of the SI right-hand side at the start state."""
    return np.linalg.eigvals(jacobian(model, model.start_state()))


@pytest.mark.parametrize("l_x", [0.0, 5e-5])
def test_lyapunov_equals_the_linearised_decay_rate(l_x):
    """At the static equilibrium with every tooth in contact the mesh is linear and time
    invariant (isotropic spring), so the largest exponent is the largest real part of the
    Jacobian's eigenvalues. Lateral damping c_p = 500 N s/m makes the slowest mode a single
    torsional pair (with the paper's c_p, four lateral modes share -1.25 1/s and Benettin's
    average converges only like 1/t)."""
    case = pyspline.load_case(CASES / "paper_ideal.nml", l_x=l_x, c_p1=500.0, c_p2=500.0,
                              start="equilibrium", t_end=4.0, n_out=3, lyapunov=True,
                              method="bdf", rtol=1e-10, atol=1e-12)
    _, mesh, _ = case.model.rhs_mesh(0.0, case.model.start_state())
    assert (np.abs(mesh["dn"]) > mesh["c"]).all()            # full contact
    lam = linearised_rates(case.model).real.max()
    res = pyspline.simulate(case)
    assert res.lyapunov["exponent"] < 0
    assert abs(res.lyapunov["exponent"] / lam - 1) < 0.03, (res.lyapunov["exponent"], lam)
    # the renormalisation interval is one shaft revolution
    np.testing.assert_allclose(np.diff(res.lyapunov["t"]), 0.01, rtol=1e-9)


def test_lyapunov_fields_are_checked():
    with pytest.raises(pyspline.CaseError, match="lyapunov_interval"):
        pyspline.simulate(LX.replace(lyapunov=True, lyapunov_interval=0.0))
    with pytest.raises(pyspline.CaseError, match="speed_rpm"):
        pyspline.simulate(LX.replace(section="shaft", speed_rpm=0.0))
    with pytest.raises(pyspline.CaseError, match="section"):
        pyspline.simulate(LX.replace(section="gear"))
