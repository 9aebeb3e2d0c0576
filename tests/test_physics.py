"""Physical checks of the core: energy, symmetry, static equilibrium, closed forms."""
import numpy as np
import pytest

import oracle
import pyspline
from conftest import PAPER, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)


def conservative_case(**kw):
    """No damping, gravity or torques, shaft at rest: the mechanical energy is conserved. Its
    start overlaps a tooth (the impacts the tests want), which its model says."""
    case = pyspline.load_case({**dict(
        PAPER, name="conservative", speed_rpm=0.0, grav=0.0, t_d=0.0, t_l=0.0,
        c_p1=0.0, c_p2=0.0, c_t1=0.0, c_t2=0.0, c_m=0.0, l_x=5e-5, l_y=0.0,
        start="rest", dq0=[1e-4, -5e-5, 0, 0, 0, 1e-4, 0], dv0=[0.6, 0, 0, -0.4, 0, 0.5, 0],
        t_end=0.5, n_out=2001, rtol=1e-10, atol=1e-12, roots=True), **kw})
    with pytest.warns(pyspline.SplineWarning, match=r"case conservative: start = 'rest' .* "
                      r"starts tooth \d+ overlapping its backlash"):
        case.model
    return case


def test_energy_conserved_over_thousands_of_switches():
    case = conservative_case()
    res = pyspline.simulate(case)
    p = oracle.prepare(dict(case))
    e = np.array([oracle.energy(y, p) for y in res.y])
    drift = np.abs(e / e[0] - 1).max()
    assert res.stats["roots_found"] > 2000, res.stats      # thousands of contact switches
    assert drift < 1e-6, drift
    # and tightening the tolerance shrinks the drift (it is integration error, not physics)
    res2 = pyspline.simulate(conservative_case(rtol=1e-7, atol=1e-9))
    e2 = np.array([oracle.energy(y, p) for y in res2.y])
    assert np.abs(e2 / e2[0] - 1).max() > drift


def test_energy_without_root_finding():
    res = pyspline.simulate(conservative_case(roots=False, t_end=0.2, n_out=801))
    p = oracle.prepare(dict(res.case))
    e = np.array([oracle.energy(y, p) for y in res.y])
    assert np.abs(e / e[0] - 1).max() < 1e-5


def test_aligned_uniform_forces_and_fx_sum_zero():
    """Aligned and weightless, the drive is symmetric: every tooth carries the same load and
    the lateral forces cancel, so the splines stay centred. Numerically, the lateral states
    are zero up to the solver's absolute tolerance (atol on states scaled by l_ref, Eq. 25),
    which the support spring k_p1 turns into a force: the bound below."""
    atol = 1e-12
    res = pyspline.simulate(dict(PAPER, name="aligned", grav=0.0, start="rest", t_end=0.05,
                                 n_out=401, rtol=1e-10, atol=atol))
    F = res.tooth["F"]
    scale = np.abs(F).max()
    assert scale > 100.0                                    # it did transmit load
    np.testing.assert_allclose(F, F[:, :1].repeat(F.shape[1], 1), atol=1e-9 * scale)
    bound = 10 * res.case["k_p1"] * atol * res.case.model.info()["l_ref"]   # 1e-8 N
    np.testing.assert_allclose(res.tooth["Fx"].sum(axis=1), 0.0, atol=bound)
    np.testing.assert_allclose(res.tooth["Fy"].sum(axis=1), 0.0, atol=bound)


def test_misaligned_fx_sum_equals_lateral_mesh_force():
    """F_jx do not sum to zero under misalignment, but balance the support of spline 1."""
    case = pyspline.load_case(dict(PAPER, name="mis", l_x=1e-4, grav=0.0))
    res = pyspline.simulate(case)
    sum_fx = res.tooth["Fx"].sum(axis=1)
    # static equilibrium: -sum F_jx (= F_x1) is carried by the support spring of spline 1
    np.testing.assert_allclose(-sum_fx, case["k_p1"] * res.x1, rtol=1e-8)
    assert np.abs(sum_fx).max() > 1.0


@pytest.mark.parametrize("speed", [0.0, 6000.0])
def test_static_equilibrium_closed_form(speed):
    """Aligned, every tooth in contact: F_j = -T_d / (Z r_b), and zero accelerations."""
    case = pyspline.load_case(dict(PAPER, name="static", grav=0.0, speed_rpm=speed))
    y = pyspline.start_state(case)
    ydot, mesh, tm = pyspline.rhs(case, 0.0, y)
    fj = -oracle.static_torsion(dict(case))
    np.testing.assert_allclose(mesh["F"], fj, rtol=1e-10)
    np.testing.assert_allclose(tm, -case["t_d"], rtol=1e-10)
    assert np.abs(ydot[7:]).max() < 1e-8 * case["c0"] * (2 * np.pi * 100) ** 2


def test_static_equilibrium_misaligned_with_gravity():
    case = pyspline.load_case(dict(PAPER, name="static2", l_x=1e-4, l_y=2e-5))
    y = pyspline.start_state(case)
    ydot, mesh, tm = pyspline.rhs(case, 0.0, y)
    assert np.abs(ydot[7:]).max() < 1e-8 * case["c0"] * (2 * np.pi * 100) ** 2
    assert (np.abs(mesh["dn"]) > mesh["c"]).all()           # every tooth carries load here
    np.testing.assert_allclose(tm, -case["t_d"], rtol=1e-10)


def test_full_contact_is_an_isotropic_spring():
    """With every tooth in contact the mesh is a linear isotropic spring K = Z k_m / 2 between
    the centres (sum sin^2 = Z/2): a misaligned drive started at equilibrium stays there, and the
    tooth force is F_j = -T_d/(Z r_b) + k_m e sin(phi_j) with e = l_x / (1 + K/k_p1 + K/k_p2)."""
    case = pyspline.load_case(dict(PAPER, name="iso", l_x=1e-4, grav=0.0, c_m=0.0,
                                   t_end=0.05, n_out=101))
    res = pyspline.simulate(case)
    p = oracle.prepare(dict(case))
    K = case["z"] * case["k_m"] / 2
    e = case["l_x"] / (1 + K / case["k_p1"] + K / case["k_p2"])
    phi = np.array([oracle.mesh(t, y, p)["phi"] for t, y in zip(res.t, res.y)])
    expected = -oracle.static_torsion(dict(case)) + case["k_m"] * e * np.sin(phi)
    np.testing.assert_allclose(res.tooth["F"], expected, rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(res.Tm, -case["t_d"], rtol=1e-9)


def test_results_are_finite_and_si():
    res = pyspline.simulate(dict(PAPER, name="fin", l_x=1e-4, start="rest", t_end=0.05,
                                 n_out=201))
    for arr in (res.y, res.Tm, *res.tooth.values()):
        assert np.isfinite(arr).all()
    assert res.t[0] == 0.0 and res.t[-1] == 0.05
    assert 1e-4 < np.abs(res.D2).max() < 5e-3             # metres, not scaled units
