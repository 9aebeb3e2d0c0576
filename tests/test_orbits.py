"""Periodic orbits (pyspline.periodic_orbit, docs/orbits.md): Newton on the core's period map,
the monodromy by central differences. Held against the closed form of the linear full-contact
drive (its forced response and exp(lambda T) of its matrix), and bad input."""
import numpy as np
import pytest

import pyspline
from conftest import CASES, jacobian

# the paper's aligned drive in full contact, lateral supports damped (every mode decays): a
# linear, time-invariant system forced by the torque ripple T_d a sin(n omega t)
BASE = pyspline.load_case(CASES / "paper_ideal.nml", start="equilibrium", method="bdf",
                          rtol=1e-11, atol=1e-13, t_end=0.05, n_out=201, roots=True,
                          c_p1=500.0, c_p2=500.0)
A_RIPPLE = 0.02


def linear_scene(order):
    """(case, y_eq, A, Y): the ripple case, its static equilibrium, the Jacobian of the
    right-hand side there and the complex amplitude of the forced response
    y_p(t) = Re[Y exp(i n omega t)] (tests/test_extensions.py's construction)."""
    model0 = BASE.model
    y_eq = model0.start_state()
    A = jacobian(model0, y_eq)
    info = model0.info()
    B = np.zeros(14, complex)                 # D1'' gets -r_b dT/J_M; sin = Re[-i e^ix]
    B[11] = -1j * (-info["r_b"] * BASE["t_d"] * A_RIPPLE / BASE["j_m"])
    Y = np.linalg.solve(1j * order * info["omega"] * np.eye(14) - A, B)
    case = BASE.replace(ripple_order=[order, 0, 0, 0], ripple_amp=[A_RIPPLE, 0, 0, 0])
    return case, y_eq, A, Y


def scale_of(case):
    info = case.model.info()
    return np.r_[np.full(7, info["l_ref"]), np.full(7, info["l_ref"] * info["w_ref"])]


def assert_multipliers(orbit, A, tol):
    want = np.exp(np.linalg.eigvals(A) * orbit.period)
    got = orbit.multipliers
    # pair each exp(lambda T) with the nearest multiplier
    err = max(np.abs(got - w).min() for w in want)
    assert err < tol, (err, np.sort(np.abs(got)), np.sort(np.abs(want)))


def test_full_contact_orbit_is_the_forced_response():
    """The orbit through t0 = 0 is y_eq + Re Y (closed form); its multipliers are
    exp(lambda_i T), lambda_i the eigenvalues of the linearised system's matrix."""
    case, y_eq, A, Y = linear_scene(2.0)
    orbit = pyspline.periodic_orbit(case)
    s = scale_of(case)
    assert orbit.residual <= 100 * case["rtol"]
    assert orbit.period == pytest.approx(2 * np.pi / case.model.info()["omega"], rel=1e-15)
    # the fixed point is off the closed form by at most |(I - M)^-1| times the residual, plus
    # the map's own error (a few rtol per period)
    bound = np.linalg.norm(np.linalg.inv(np.eye(14) - orbit.monodromy), np.inf) * \
        (orbit.residual + 10 * case["rtol"])
    err = np.abs((orbit.y0 - (y_eq + Y.real)) / s).max()
    assert np.abs(Y / s).max() > 1e3 * bound             # a response well above the error
    assert err < bound, (err, bound)
    # multipliers: central differences with h = rtol^(1/3): error ~ rtol / h ~ 5e-8
    assert_multipliers(orbit, A, 1e-6)
    assert orbit.stable and np.abs(orbit.multipliers).max() < 0.9
    tr = orbit.trajectory                                 # one period from (t0, y0)
    assert tr.t[0] == orbit.t0 and tr.t[-1] == pytest.approx(orbit.t0 + orbit.period)
    assert np.abs((tr.y[-1] - tr.y[0]) / s).max() < 10 * orbit.residual + 10 * case["rtol"]
    assert (np.abs(tr.dn) > tr.c).all()                  # every tooth in contact throughout


def test_newton_lands_in_one_step_on_the_linear_map():
    """An affine map: Newton with the right monodromy lands from the static equilibrium (off
    the orbit by the whole forced response) in one step, its residual falling by > 1e5
    (the differences' error); a wrong M would converge linearly at best."""
    case, y_eq, _, _ = linear_scene(2.0)
    orbit = pyspline.periodic_orbit(case, guess=y_eq)
    r = orbit.residuals
    assert orbit.iterations == 1 and len(r) == 2
    assert r[0] > 1e-3 and r[1] < 1e-5 * r[0], r


def test_fractional_order_needs_n_revolutions():
    """Ripple of order 1/3 repeats every third revolution: n = 1 is refused naming the field
    and the n that does; the period-3 orbit is the closed form, multipliers exp(lambda 3T)."""
    case, y_eq, A, Y = linear_scene(1 / 3)
    with pytest.raises(pyspline.CaseError, match=r"ripple_order = 0.333333.*n = 3 revolutions"):
        pyspline.periodic_orbit(case)
    orbit = pyspline.periodic_orbit(case, n=3)
    assert orbit.period == pytest.approx(3 * 2 * np.pi / case.model.info()["omega"])
    s = scale_of(case)
    bound = np.linalg.norm(np.linalg.inv(np.eye(14) - orbit.monodromy), np.inf) * \
        (orbit.residual + 10 * case["rtol"])
    assert np.abs((orbit.y0 - (y_eq + Y.real)) / s).max() < bound
    assert_multipliers(orbit, A, 1e-6)


def test_torsional_level_restricts_the_map_to_its_states():
    """dof 3: the lateral states are frozen, so the map (and M) acts on the torsional six."""
    case, *_ = linear_scene(2.0)
    orbit = pyspline.periodic_orbit(case.replace(dof=3))
    assert orbit.states == ("D1", "D2", "D3", "vD1", "vD2", "vD3")
    assert orbit.monodromy.shape == (6, 6) and len(orbit.multipliers) == 6
    assert orbit.stable


@pytest.mark.parametrize("n", [0, -1, 1.5, True])
def test_bad_n(n):
    with pytest.raises(pyspline.CaseError, match="n = .*whole number >= 1"):
        pyspline.periodic_orbit(BASE, n=n)


def test_bad_guess():
    with pytest.raises(pyspline.CaseError, match=r"guess has shape \(7,\): a state has 14"):
        pyspline.periodic_orbit(BASE, guess=np.zeros(7))
    with pytest.raises(pyspline.CaseError, match="guess is not finite"):
        pyspline.periodic_orbit(BASE, guess=np.full(14, np.nan))


def test_no_forcing_period():
    with pytest.raises(pyspline.CaseError, match="speed_rpm = 0.*no forcing period"):
        pyspline.periodic_orbit(BASE.replace(speed_rpm=0.0))


def test_newton_failure_says_what_was_tried():
    case, y_eq, _, _ = linear_scene(2.0)
    with pytest.raises(pyspline.OrbitError, match=r"no period-1 orbit found .*max_iter.*after 0 "
                       r"Newton step\(s\); scaled residual .*wanted 1e-09"):
        pyspline.periodic_orbit(case, guess=y_eq, max_iter=0)
    assert issubclass(pyspline.OrbitError, pyspline.SplineError)


def test_newton_converges_quadratically_on_a_switching_orbit():
    """cases/chaos_z24.nml with 10 times its mesh damping (zeta_m = 0.1) settles on a period-1
    orbit on which teeth leave contact and strike the back flank every revolution: a nonlinear,
    piecewise-smooth map. From the end of a 0.1 s run, Newton's residual falls quadratically,
    r_(k+1) <= 100 r_k^2, down to the tolerance (a linear rate would stall above it)."""
    case = pyspline.load_case(CASES / "chaos_z24.nml", zeta_m=0.1, t_transient=0.0, t_end=0.1,
                              n_out=101, section="none", lyapunov=False)
    orbit = pyspline.periodic_orbit(case, tol=1e-6)
    r = orbit.residuals
    assert len(r) >= 3 and r[-1] <= 1e-6, r
    for a, b in zip(r, r[1:]):
        assert b <= 100 * a**2, r
    tr = orbit.trajectory
    free = (np.abs(tr.dn) <= tr.c).mean()
    assert 0.5 < free < 1 and (tr.dn > tr.c).any()       # free flights and back-flank strikes
    s = scale_of(case)
    assert np.abs((tr.y[-1] - tr.y[0]) / s).max() < 10 * orbit.residual + 10 * case["rtol"]
    assert orbit.stable
