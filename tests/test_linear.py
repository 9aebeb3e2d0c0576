"""The linear tail (fortran/integration/linear.f90, docs/running.md section 4): once every tooth is proven to
stay in contact on one flank, the rest of a run is the closed-form solution of the affine,
time-invariant full-contact system."""
import numpy as np
import pytest

import pyspline
from conftest import CASES, PAPER_SHAFTS, DEMONSTRATION_SCENES

pytestmark = [PAPER_SHAFTS, DEMONSTRATION_SCENES]   # expected warnings (conftest)


def paper(**kw):
    return pyspline.load_case(CASES / "paper_lx1e-4.nml", **kw)


def scaled_error(res, ref):
    """Largest error of any state over the run, against the largest magnitude of any state of
    its kind (displacements, velocities)."""
    err = np.abs(res.y - ref.y)
    return max(err[:, :7].max() / np.abs(ref.y[:, :7]).max(),
               err[:, 7:].max() / np.abs(ref.y[:, 7:]).max())


def test_tail_is_more_accurate_than_the_integrator_it_replaces():
    """paper_lx1e-4 from rest: the tail starts within the first revolutions, and its outputs
    and sections agree with a CVODE run at rtol 1e-12 better than CVODE at the case's own
    rtol (1e-9) does: the closed form adds no error of its own beyond the hand-over state."""
    case = paper(t_end=0.3, n_out=241, section="shaft")
    tail = pyspline.simulate(case)
    plain = pyspline.simulate(case.replace(linear_tail=False))
    ref = pyspline.simulate(case.replace(linear_tail=False, rtol=1e-12, atol=1e-14))
    assert 0.0 < tail.stats["linear_tail_t_s"] < 0.1
    assert plain.stats["linear_tail_t_s"] == -1.0
    assert tail.stats["steps"] < 0.3 * plain.stats["steps"]
    e_tail, e_plain = scaled_error(tail, ref), scaled_error(plain, ref)
    assert e_tail < e_plain and e_tail < 1e-5
    sec = np.abs(np.asarray(tail.section_y) - np.asarray(ref.section_y)).max()
    assert sec < 1e-5 * np.abs(ref.section_y).max()


def test_tail_decays_to_the_static_equilibrium():
    """10^4 revolutions (100 s) in one output interval: with the tail the run ends at once, at
    the static equilibrium of the drive (every mode decayed: exp(-1.25 * 100)), which the core
    computes independently by Newton's method (start = 'equilibrium'). Without root finding:
    with it the tail is tried only at output times (spline_solver::next_stop)."""
    case = paper(start="rest", t_end=100.0, n_out=2, roots=False)
    res = pyspline.simulate(case)
    assert 0.0 < res.stats["linear_tail_t_s"] < 0.1
    q_eq = case.replace(start="equilibrium").model.start_state()[:7]
    assert np.allclose(res.y[-1, :7], q_eq, rtol=0, atol=1e-9 * np.abs(q_eq).max())
    assert np.abs(res.y[-1, 7:]).max() < 1e-12


def test_tail_never_taken_changes_nothing():
    """chaos_z24 rattles (contact lost and regained): the tail is never taken, and the run is
    bit-identical to one with linear_tail off (the tries return on CVODE's interpolant).
    Without its Lyapunov copy: the tail is tried only for a single copy."""
    case = pyspline.load_case(CASES / "chaos_z24.nml", t_end=0.6, lyapunov=False)
    a = pyspline.simulate(case)
    b = pyspline.simulate(case.replace(linear_tail=False))
    assert a.stats["linear_tail_t_s"] == -1.0
    assert np.array_equal(a.y, b.y) and a.stats["steps"] == b.stats["steps"]


@pytest.mark.parametrize("fields", [
    dict(c_m=0.0, c_p1=0.0, c_p2=0.0, c_t1=0.0, c_t2=0.0),   # undamped: cannot be proven
    dict(ripple_order=[2.0, 0, 0, 0], ripple_amp=[0.05, 0, 0, 0]),  # time-varying torque
    dict(unbalance=[1e-5, 0.0]),                               # rotating force
], ids=["undamped", "ripple", "unbalance"])
def test_tail_refused_where_it_does_not_hold(fields):
    """Without damping no mode decays (Re lambda = 0) and nothing proves the contact lasts;
    torque ripple and unbalance make the system time-varying."""
    res = pyspline.simulate(paper(t_end=0.2, n_out=161, **fields))
    assert res.stats["linear_tail_t_s"] == -1.0
