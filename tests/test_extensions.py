"""Beyond the paper (issue 12, docs/model.md section 11 as docs/model.md states it): torque ripple,
mass unbalance, angular misalignment with face slices, mesh damping as a ratio. Each term is
held against a closed form, a limit it must reproduce, or a convergence check."""
import numpy as np
import pytest

import pyspline
from conftest import CASES, jacobian, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

# the paper's aligned drive in full contact: its mesh is a linear isotropic spring, so the
# whole system is linear and time invariant about its static equilibrium
BASE = pyspline.load_case(CASES / "paper_ideal.nml", start="equilibrium", method="bdf",
                          rtol=1e-11, atol=1e-13, t_end=0.2, n_out=201, roots=False)


def forced_response(A, B, omega):
    """Steady response y_p(t) = Re[Y exp(i omega t)] of dy/dt = A y + Re[B exp(i omega t)]."""
    Y = np.linalg.solve(1j * omega * np.eye(14) - A, B)
    return lambda t: np.real(np.outer(np.exp(1j * omega * t), Y))


def run_on_the_orbit(case, y_eq, yp):
    """Simulate from y_eq + y_p(0) (start = rest plus offsets): no transient is excited. A
    start in the loaded mesh overlaps the teeth by its static deflection, which the model says
    (it cannot tell a loaded start from an impact)."""
    y0 = y_eq + yp(np.array([0.0]))[0]
    with pytest.warns(pyspline.SplineWarning, match=r"start = 'rest' .* overlapping its backlash"):
        res = pyspline.simulate(case.replace(start="rest", dq0=list(y0[:7]), dv0=list(y0[7:])))
    return res, res.y - y_eq, yp(res.t)


def assert_away_from_resonance(A, omega):
    freqs = np.abs(np.linalg.eigvals(A).imag)
    assert np.min(np.abs(freqs - omega)) > 0.2 * omega, (omega, np.sort(freqs))


def test_torque_ripple_forced_response():
    """T_d(t) = T_d (1 + a sin(n omega t)): the response of the linear full-contact system is
    its frequency response at n omega, to 1e-6 of its amplitude."""
    a, n = 0.01, 1.5
    model0 = BASE.model
    y_eq = model0.start_state()
    A = jacobian(model0, y_eq)
    info = model0.info()
    Omega = n * info["omega"]
    assert_away_from_resonance(A, Omega)
    B = np.zeros(14, complex)
    # sin(x) = Re[-i exp(ix)]; the ripple torque enters the motor equation: D1'' gets -r_b dT/J_M
    B[11] = -1j * (-info["r_b"] * BASE["t_d"] * a / BASE["j_m"])
    yp = forced_response(A, B, Omega)
    case = BASE.replace(ripple_order=[n, 0, 0, 0], ripple_amp=[a, 0, 0, 0])
    res, dy, ref = run_on_the_orbit(case, y_eq, yp)
    scale = np.abs(ref).max(axis=0)
    for k in (4, 5, 6, 11, 12, 13):                     # the torsional states respond
        assert scale[k] > 0
        err = np.abs(dy[:, k] - ref[:, k]).max() / scale[k]
        assert err < 1e-6, (k, err)
    assert (np.abs(res.dn) > res.c).all()               # full contact throughout


def test_unbalance_forced_response():
    """m_u e omega^2 (cos, sin)(omega t + beta) on spline 1: the linear response, to 1e-6."""
    u, beta = 2e-6, 0.3
    case0 = BASE.replace(speed_rpm=3000.0)
    model0 = case0.model
    y_eq = model0.start_state()
    A = jacobian(model0, y_eq)
    w = model0.info()["omega"]
    assert_away_from_resonance(A, w)
    B = np.zeros(14, complex)
    f = u * w**2 / case0["m_1"] * np.exp(1j * beta)
    B[7], B[8] = f, -1j * f                            # cos -> Re[e^ix], sin -> Re[-i e^ix]
    yp = forced_response(A, B, w)
    case = case0.replace(unbalance=[u, 0.0], unbalance_phase_deg=[np.degrees(beta), 0.0])
    res, dy, ref = run_on_the_orbit(case, y_eq, yp)
    scale = np.abs(ref).max(axis=0)
    for k in (0, 1, 2, 3, 7, 8):                        # the lateral states respond
        err = np.abs(dy[:, k] - ref[:, k]).max() / scale[k]
        assert err < 1e-6, (k, err)


def test_unbalance_builds_up_at_the_lateral_critical_speed():
    """At the first lateral critical speed (the splines moving together on their supports,
    damping ratio 8e-4) unbalance builds the response up over 1/(zeta omega) = 0.8 s. Started at
    its static equilibrium (which holds the unbalance force at t = 0), the run follows the
    closed form of the linear system, y_p(t) + exp(A t) (y(0) - y_p(0)), to 1e-6 of its
    amplitude, while that amplitude grows past 50 times the static deflection."""
    from scipy.linalg import expm
    lateral = np.abs(np.linalg.eigvals(jacobian(BASE.model, BASE.model.start_state())).imag)
    w = lateral[lateral > 1000].min()                  # the first lateral natural frequency
    case0 = BASE.replace(speed_rpm=w * 30 / np.pi, t_end=0.2, n_out=401)
    model0 = case0.model
    y_eq = model0.start_state()
    A = jacobian(model0, y_eq)
    assert model0.info()["omega"] == pytest.approx(w, rel=1e-12)
    ev = np.linalg.eigvals(A)
    mode = ev[np.argmin(np.abs(ev.imag - w))]
    assert mode.imag == pytest.approx(w, rel=1e-9)     # still the critical speed at this speed
    # equal splines moving together: the mesh does not stretch, the supports carry them
    assert (BASE["m_1"], BASE["k_p1"], BASE["c_p1"]) == (BASE["m_2"], BASE["k_p2"], BASE["c_p2"])
    assert -mode.real == pytest.approx(BASE["c_p1"] / (2 * BASE["m_1"]), rel=1e-6)
    assert abs(mode) == pytest.approx(np.sqrt(BASE["k_p1"] / BASE["m_1"]), rel=1e-6)
    assert -mode.real / abs(mode) < 1e-3               # lightly damped: a sharp resonance
    u = 2e-6
    B = np.zeros(14, complex)
    f = u * w**2 / case0["m_1"]
    B[7], B[8] = f, -1j * f
    yp = forced_response(A, B, w)
    case = case0.replace(unbalance=[u, 0.0])
    res = pyspline.simulate(case)
    c0 = case.model.start_state() - y_eq - yp(np.array([0.0]))[0]
    ref = yp(res.t) + np.array([expm(A * t) @ c0 for t in res.t])
    dy = res.y - y_eq
    scale = np.abs(ref).max(axis=0)
    for k in (0, 1, 2, 3, 7, 8, 9, 10):                 # the lateral states
        err = np.abs(dy[:, k] - ref[:, k]).max() / scale[k]
        assert err < 1e-6, (k, err)
    last_turns = res.t > res.t[-1] - 4 * np.pi / w
    assert np.abs(dy[last_turns, 0]).max() > 50 * f / w**2    # resonance, not just forcing
    assert (np.abs(res.dn) > res.c).all()               # full contact: the linear regime


def test_untilted_slices_reproduce_the_whole_face():
    """gamma = 0: n slices of k_m / n each are the whole face. The right-hand side agrees to
    round-off at any state (in and out of contact); trajectories agree to the integrator's
    tolerance (its step choices see the round-off)."""
    whole = BASE.replace(l_x=1e-4, t_end=0.05, n_out=51, start="rest")
    sliced = whole.replace(n_slices=5)
    rng = np.random.default_rng(12)
    y0 = whole.model.start_state()
    n_free = 0
    for _ in range(40):
        y = y0 + rng.normal(size=14) * np.r_[np.full(7, 3e-4), np.full(7, 0.2)]
        t = rng.uniform(0, 0.05)
        f1, m1, tm1 = whole.model.rhs_mesh(t, y)
        f5, m5, tm5 = sliced.model.rhs_mesh(t, y)
        np.testing.assert_allclose(f5, f1, rtol=1e-13, atol=1e-13 * np.abs(f1).max())
        np.testing.assert_allclose(m5["F"], m1["F"], rtol=1e-13, atol=1e-10)
        n_free += (np.abs(m1["dn"]) <= m1["c"]).sum()
    assert n_free > 20                                  # out-of-contact teeth were exercised
    a, b = pyspline.simulate(whole), pyspline.simulate(sliced)
    np.testing.assert_allclose(b.F, a.F, rtol=0, atol=1e-7 * np.abs(a.F).max())
    np.testing.assert_allclose(b.face.sum(axis=2), b.F, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(b.tilt, 0.0, atol=1e-9 * np.abs(a.F).max() * BASE["b"])


def test_face_load_is_linear_in_z_in_full_contact():
    """At the static equilibrium of a tilted spline in full contact, slice s of tooth j carries
    F_js = F_j / n_s + z_s / n_s (k_m (gamma_y sin(phi_j) + gamma_x cos(phi_j))
    + c_m omega (gamma_y cos(phi_j) - gamma_x sin(phi_j))) (Eqs. 11, 15-17 with the tilted
    centre; the second term is the mesh damping of the tilt's rotation, present at rest)."""
    gx, gy, ns = 3e-4, -5e-4, 6
    case = BASE.replace(gamma_x=gx, gamma_y=gy, n_slices=ns, t_end=1e-6, n_out=2)
    res = pyspline.simulate(case)
    F, face = res.F[0], res.face[0]                    # (Z,), (Z, n_s)
    sphi, cphi = res.Fx[0] / F, res.Fy[0] / F
    zs = BASE["b"] * ((np.arange(ns) + 0.5) / ns - 0.5)
    k, c, w = case["k_m"] / ns, case["c_m"] / ns, case.model.info()["omega"]
    slope = k * (gy * sphi + gx * cphi) + c * w * (gy * cphi - gx * sphi)
    expect = F[:, None] / ns + zs[None, :] * slope[:, None]
    np.testing.assert_allclose(face, expect, rtol=1e-9, atol=1e-9 * np.abs(F).max())
    # the tilting moment is the first moment of the face loads (docs/model.md section 11)
    np.testing.assert_allclose(res.tilt[0], [-(zs * face * cphi[:, None]).sum(),
                                             -(zs * face * sphi[:, None]).sum()], rtol=1e-9)


def test_slices_converge_with_edge_contact():
    """With the computed (stiff) mesh a tilt loads one end of the face only: the equilibrium's
    tilting moment and peak tooth load converge as n_slices doubles."""
    base = BASE.replace(k_m=0.0, gamma_y=2e-4, t_end=1e-6, n_out=2)
    out = []
    for ns in (4, 8, 16, 32, 64):
        r = pyspline.simulate(base.replace(n_slices=ns))
        out.append(np.r_[r.tilt[0], np.abs(r.F[0]).max()])
    d = np.abs(np.diff(out, axis=0)).max(axis=1) / np.abs(out[-1]).max()
    assert (np.diff(d) < 0).all(), d
    assert d[-1] < 0.2 * d[0], d


@pytest.mark.parametrize("extra", [
    dict(ripple_order=[2, 0.5, 0, 0], ripple_amp=[0.05, 0.02, 0, 0], ripple_phase_deg=[30, 80, 0, 0]),
    dict(unbalance=[1e-4, 2e-4], unbalance_phase_deg=[10.0, 200.0]),
    dict(gamma_x=2e-4, gamma_y=-1e-4, n_slices=8),
    dict(zeta_m=0.05),
])
def test_static_equilibrium_with_the_new_terms(extra):
    case = BASE.replace(l_x=5e-5, **extra)
    y = case.model.start_state()
    a = case.model.rhs(case["t0"], y)[7:]
    scale = case.model.info()["l_ref"] * case.model.info()["w_ref"] ** 2
    assert np.abs(a).max() < 1e-8 * scale, a
    assert np.abs(y[7:]).max() == 0.0


def test_mesh_damping_ratio():
    case = pyspline.load_case(dict(name="z", k_m=0.0, zeta_m=0.05))
    info = case.model.info()
    r_b = info["r_b"]
    m_e = 1 / (r_b**2 / case["j_1"] + r_b**2 / case["j_2"])
    np.testing.assert_allclose(info["m_e"], m_e, rtol=1e-14)
    np.testing.assert_allclose(info["c_m"], 2 * 0.05 * np.sqrt(info["k_m"] * m_e), rtol=1e-14)
    with pytest.raises(pyspline.CaseError, match="zeta_m"):
        pyspline.load(dict(name="both", zeta_m=0.05, c_m=10.0))


def test_auto_fidelity_keeps_the_terms_that_matter():
    """Unbalance and tilt drive the lateral motion: auto keeps 7 DOF and stays within its
    tolerance; a ripple alone is torsional: auto drops to 3 DOF, exactly."""
    short = BASE.replace(t_end=0.05, n_out=51, rtol=1e-9, atol=1e-11)
    for extra, dof in ((dict(unbalance=[1e-4, 0.0]), 7), (dict(gamma_y=1e-3, n_slices=4), 7),
                       (dict(ripple_order=[1, 0, 0, 0], ripple_amp=[0.05, 0, 0, 0]), 3)):
        case = short.replace(**extra)
        full = pyspline.simulate(case)
        auto = pyspline.simulate(case.replace(fidelity="auto", fidelity_tol=1e-3))
        assert auto.stats["dof"] == dof, extra
        err = np.abs(auto.Tm - full.Tm).max() / np.abs(full.Tm).max()
        assert err < 1e-3, (extra, err)


def test_slices_refuse_the_flash_levels():
    with pytest.raises(pyspline.CaseError, match="n_slices"):
        pyspline.load(dict(name="s", n_slices=4, thermal="oneway"))
    with pytest.raises(pyspline.CaseError, match="n_slices"):
        pyspline.load(dict(name="s", gamma_x=1e-3))


@pytest.mark.parametrize("order,period", [(2.0, 1), (1 / 3, 3), (2 ** -0.5, 0)])
def test_sections_classify_constructed_scenes(order, period):
    """Scenes built to a known motion: the linear full-contact drive driven by a torque ripple
    of order n, started on its forced orbit. n = 2 repeats every revolution (period 1), n = 1/3
    every third (period 3), n = 1/sqrt(2) never (quasi-periodic: 0). The exact shaft sections,
    classified with the solver's tolerance, say so."""
    from pyspline.analysis import classify_period
    a = 0.02
    case0 = BASE.replace(c_p1=500.0, c_p2=500.0)
    y_eq = case0.model.start_state()
    A = jacobian(case0.model, y_eq)
    info = case0.model.info()
    B = np.zeros(14, complex)
    B[11] = -1j * (-info["r_b"] * BASE["t_d"] * a / BASE["j_m"])
    yp = forced_response(A, B, order * info["omega"])
    case = case0.replace(ripple_order=[order, 0, 0, 0], ripple_amp=[a, 0, 0, 0], t_end=0.6,
                         n_out=3, section="shaft")
    res, _, _ = run_on_the_orbit(case, y_eq, yp)
    pts = res.section_y[:, [5, 12]]
    scale = [case["c0"], case["c0"] * info["omega"]]
    got, info_p = classify_period(pts, case["rtol"], scale=scale, max_period=12)
    assert got == period, info_p["residual"]
