"""Periodic orbits (pyspline.periodic_orbit, docs/orbits.md): Newton on the core's period map,
the monodromy by central differences. Held against the closed form of the linear full-contact
drive (its forced response and exp(lambda T) of its matrix), and bad input."""
import re

import numpy as np
import pytest

import pyspline
from scipy.linalg import expm

from conftest import CASES, DEMONSTRATION_SCENES, PAPER_SHAFTS, jacobian

pytestmark = [PAPER_SHAFTS, DEMONSTRATION_SCENES]   # expected warnings (conftest)

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


def closes(orbit, tr, s, case):
    """The trajectory (simulate, its own integration: the map's run carries the tangents in its
    error control, so its steps differ) closes on y0 within the residual and the integrations'
    relative error rtol |y| (the scaled D1, a shaft's twist, reaches hundreds here)."""
    gap = np.abs((tr.y[-1] - tr.y[0]) / s).max()
    bound = 10 * orbit.residual + 10 * case["rtol"] * max(1.0, np.abs(orbit.y0 / s).max())
    return gap < bound or print(gap, bound)


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
    # multipliers from the exact M: its error is the integration's (a few 1e-9 measured), the
    # 1e-6 central differences with h = rtol^(1/3) reach (error ~ rtol / h ~ 5e-8) would miss it
    assert_multipliers(orbit, A, 1e-7)
    assert orbit.stable and np.abs(orbit.multipliers).max() < 0.9
    tr = orbit.trajectory                                 # one period from (t0, y0)
    assert tr.t[0] == orbit.t0 and tr.t[-1] == pytest.approx(orbit.t0 + orbit.period)
    assert closes(orbit, tr, s, case)
    assert (np.abs(tr.dn) > tr.c).all()                  # every tooth in contact throughout


@pytest.mark.parametrize("monodromy, drop", [("exact", 1e-8), ("fd", 1e-5)])
def test_newton_lands_in_one_step_on_the_linear_map(monodromy, drop):
    """An affine map: Newton with the right monodromy lands from the static equilibrium (off
    the orbit by the whole forced response) in one step, its residual falling by the error of
    M: > 1e5 with central differences, > 1e8 with the exact M (measured 6e-11 and 5e-7); a
    wrong M would converge linearly at best."""
    case, y_eq, _, _ = linear_scene(2.0)
    orbit = pyspline.periodic_orbit(case, guess=y_eq, monodromy=monodromy)
    r = orbit.residuals
    assert orbit.iterations == 1 and len(r) == 2 and orbit.method == monodromy
    assert r[0] > 1e-3 and r[1] < drop * r[0], r


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
    assert_multipliers(orbit, A, 1e-7)


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
    assert orbit.method == "exact"
    tr = orbit.trajectory
    free = (np.abs(tr.dn) <= tr.c).mean()
    assert 0.5 < free < 1 and (tr.dn > tr.c).any()       # free flights and back-flank strikes
    s = scale_of(case)
    assert closes(orbit, tr, s, case)
    assert orbit.stable


def test_default_guess_settles_within_the_cases_step_bound():
    """The default guess settles the case as its own run does, max_steps bounding each period's
    steps (a map run per period), not the whole settling run's: a run with one output per
    revolution within max_steps = 5000 but 37815 steps in all finds its orbit (it was a
    SolverError 'max_steps = 5000 ... raise max_steps or n_out')."""
    case = pyspline.load_case(CASES / "chaos_z24.nml", zeta_m=0.1, t_transient=0.0, t_end=0.1,
                              n_out=11, section="none", lyapunov=False, max_steps=5000)
    assert pyspline.simulate(case).stats["steps"] > 5 * case["max_steps"]
    orbit = pyspline.periodic_orbit(case, tol=1e-6)
    assert orbit.residual <= 1e-6 and orbit.stable


def test_period_map_beyond_max_steps_says_what_helps():
    """A period map is one run over a period (n_out does not split it): beyond max_steps it
    says so and to raise max_steps (it said 'between two output times ... raise max_steps or
    n_out', the state run's advice)."""
    case = pyspline.load_case(CASES / "chaos_z24.nml", zeta_m=0.1, t_transient=0.0, t_end=0.1,
                              n_out=11, section="none", lyapunov=False, max_steps=2000)
    with pytest.raises(pyspline.SolverError, match=r"chaos_z24: the period map took max_steps "
                       r"= 2000 CVODE steps without reaching its end, at t = .*: raise max_steps "
                       r"\(it bounds this run as a whole: n_out does not split it\)$"):
        pyspline.periodic_orbit(case, tol=1e-6)


def test_exact_monodromy_is_the_matrix_exponential():
    """Full contact: the variational equations give M = exp(A T) in the scaled states (A the
    Jacobian of Model.rhs, central differences: conftest), to the integration's error, and
    central differences of the map (h = rtol^(1/3)) agree to theirs; the map's end state is
    the map's (period_map). At dof 3 M is the torsional block."""
    case, y_eq, A, Y = linear_scene(2.0)
    model = pyspline.load(case)
    period = 2 * np.pi / model.info()["omega"]
    y0 = y_eq + Y.real
    s = scale_of(case)
    y1, M, free = pyspline.orbits.map_and_monodromy(model, 0.0, period, y0)
    assert free.all() and M.shape == (14, 14)
    want = expm(A * period) * s[None, :] / s[:, None]
    assert np.abs(M - want).max() < 1e-7, np.abs(M - want).max()       # measured 2.6e-9
    y1f, Mf, _ = pyspline.orbits.fd_monodromy(model, 0.0, period, y0)
    assert np.abs(Mf - M).max() < 1e-6                                 # measured 1.1e-7
    assert np.abs((y1 - y1f) / s).max() < 10 * case["rtol"] * np.abs(y0 / s).max()
    y1, M3, free = pyspline.orbits.map_and_monodromy(case.replace(dof=3), 0.0, period, y0)
    assert np.flatnonzero(free).tolist() == [4, 5, 6, 11, 12, 13] and M3.shape == (6, 6)
    i = np.flatnonzero(free)
    assert np.abs(M3 - M[np.ix_(i, i)]).max() < 1e-7     # aligned: the torsion does not move the rest


@pytest.fixture(scope="module")
def impacting():
    """chaos_z24 with ten times its mesh damping: a period-1 orbit on which teeth fly free and
    strike (roots, rtol 1e-7), and the model."""
    case = pyspline.load_case(CASES / "chaos_z24.nml", zeta_m=0.1, t_transient=0.0, t_end=0.1,
                              n_out=101, section="none", lyapunov=False)
    return pyspline.periodic_orbit(case, tol=1e-6), pyspline.load(case)


def test_saltation_makes_the_monodromy_right_across_impacts(impacting):
    """On the impacting orbit the vector field jumps at every contact switch (the mesh damping
    acts only in contact): M from the variational equations agrees with central differences
    of the map only with the saltation matrices applied (measured 3.5e-5 with, 0.28 without,
    against entries up to 4.8). The step h = 1e-5 stays away from grazing: h >= 1e-3 in D2
    changes the contact sequence of the differenced runs (0.19 off)."""
    orbit, model = impacting
    t0, t1 = orbit.t0, orbit.t0 + orbit.period
    _, M, _ = pyspline.orbits.map_and_monodromy(model, t0, t1, orbit.y0)
    _, M0, _ = pyspline.orbits.map_and_monodromy(model, t0, t1, orbit.y0, saltation=False)
    _, Mf, _ = pyspline.orbits.fd_monodromy(model, t0, t1, orbit.y0, h=1e-5)
    assert np.abs(Mf - M).max() < 1e-3, np.abs(Mf - M).max()
    assert np.abs(Mf - M0).max() > 0.1, np.abs(Mf - M0).max()
    assert np.abs(M - orbit.monodromy).max() < 1e-12      # the orbit's M is this one


def test_saltation_of_a_single_switch(impacting):
    """Across one located contact switch (an output interval of the orbit in which exactly one
    tooth changes contact; the core counts one switch): the flow's sensitivity from the
    variational equations with the saltation matrix agrees with central differences of the
    flow across it (h = 1e-5: measured 1.3e-4 and 1.8e-5 on two such switches, against
    entries up to 15); without the saltation matrix it is off by more than 1 (3.4-3.7). Over an
    interval without a switch the saltation changes nothing."""
    from pyspline.bridge import _api
    orbit, model = impacting
    tr = orbit.trajectory
    pos = np.abs(tr.dn) - tr.c > 0
    changes = (pos[1:] != pos[:-1]).sum(axis=1)
    one, none = np.flatnonzero(changes == 1)[:2], np.flatnonzero(changes == 0)[:1]
    assert len(one) == 2 and len(none) == 1
    for i in np.r_[one, none]:
        t0, t1, y = tr.t[i], tr.t[i + 1], tr.y[i]
        nsw = _api.api_map_monodromy(model.bytes, t0, t1, y, 1)[3]
        assert nsw == changes[i]
        _, M, _ = pyspline.orbits.map_and_monodromy(model, t0, t1, y)
        _, M0, _ = pyspline.orbits.map_and_monodromy(model, t0, t1, y, saltation=False)
        if nsw == 0:
            assert np.array_equal(M, M0)
            continue
        _, Mf, _ = pyspline.orbits.fd_monodromy(model, t0, t1, y, h=1e-5)
        assert np.abs(M - Mf).max() < 1e-3, np.abs(M - Mf).max()
        assert np.abs(M0 - Mf).max() > 1, np.abs(M0 - Mf).max()


def test_variational_run_is_bounded_by_max_total_steps(impacting):
    """The variational run restarts at every switch: its work is bounded over the restarts by
    max_total_steps (a grazing touch whose root finding chatters cannot run on without end):
    a SolverError naming the field, where one revolution of this orbit needs more steps."""
    orbit, model = impacting
    case = model.case.replace(max_total_steps=200)
    with pytest.raises(pyspline.SolverError, match="variational run took max_total_steps = 200 "
                       "CVODE steps in all by t = .*raise max_total_steps"):
        pyspline.orbits.map_and_monodromy(case, orbit.t0, orbit.t0 + orbit.period, orbit.y0)


def test_variational_run_of_erk_is_cvode_adams(impacting):
    """docs/orbits.md: with method = 'erk' the variational run (the exact monodromy) is CVODE's
    Adams, not ERKStep: the exact map's end state and M are those of the same case with
    method = 'adams', bit for bit, and its work bound names CVODE's steps; ERK's own period map
    (the state run: dF/dp, the trajectories, monodromy = 'fd') ends elsewhere (by about rtol:
    measured 7e-9 scaled at rtol 1e-7)."""
    from pyspline.orbits import _period_map, _scale, map_and_monodromy
    orbit, model = impacting
    t0, t1 = orbit.t0, orbit.t0 + orbit.period
    erk, adams = (model.case.replace(method=m) for m in ("erk", "adams"))
    y1, M, free = map_and_monodromy(erk, t0, t1, orbit.y0)
    ya, Ma, _ = map_and_monodromy(adams, t0, t1, orbit.y0)
    assert np.array_equal(y1, ya) and np.array_equal(M, Ma)
    ym = _period_map(erk.model, t0, t1, orbit.y0[:, None])[0][:, 0]
    off = np.abs((ym - y1)[free] / _scale(erk.model)[free]).max()
    assert 0 < off < 1e-7, off
    with pytest.raises(pyspline.SolverError, match="variational run took max_total_steps = 200 "
                       "CVODE steps"):
        map_and_monodromy(erk.replace(max_total_steps=200), t0, t1, orbit.y0)


def test_coupled_thermal_level_is_not_covered():
    case, y_eq, _, _ = linear_scene(2.0)
    with pytest.raises(pyspline.CaseError, match="thermal = 'coupled'.*variational equations.*fd"):
        pyspline.orbits.map_and_monodromy(case.replace(thermal="coupled"), 0.0, 0.01, y_eq)
    with pytest.raises(pyspline.CaseError, match="monodromy = 'newton'"):
        pyspline.periodic_orbit(case, monodromy="newton")
    with pytest.raises(pyspline.CaseError, match=r"y \(shape \(6,\)\) must be a state of 14"):
        pyspline.orbits.map_and_monodromy(case, 0.0, 0.01, y_eq[:6])


def test_step_bound_says_where_the_run_stopped():
    """A run cut by its step bounds says where it stopped, not where it last restarted, and
    names its own integrator's flag: the linear scene (full contact: no switch, no restart,
    where the time said was 0 for every bound) stops later with twice the steps, inside its
    period; ERK's state run names ARK_TOO_MUCH_WORK, CVODE's CV_TOO_MUCH_WORK."""
    from pyspline.orbits import _period_map, map_and_monodromy
    case, y_eq, _, _ = linear_scene(2.0)
    t1 = 60 / case["speed_rpm"]

    def stopped(run, *args):
        with pytest.raises(pyspline.SolverError) as err:
            run(*args)
        t = re.search(r"t = +(\S+) s \(flag (\w+)\)", str(err.value))
        assert t, err.value
        return float(t.group(1)), t.group(2)
    var = [stopped(map_and_monodromy, case.replace(max_total_steps=n), 0.0, t1, y_eq)
           for n in (20, 40)]
    assert 0 < var[0][0] < var[1][0] < t1 and {f for _, f in var} == {"CV_TOO_MUCH_WORK"}
    for method, flag in (("erk", "ARK_TOO_MUCH_WORK"), ("bdf", "CV_TOO_MUCH_WORK")):
        t, said = stopped(_period_map, case.replace(method=method, max_steps=20).model, 0.0, t1,
                          y_eq[:, None])
        assert 0 < t < t1 and said == flag, (method, said)
