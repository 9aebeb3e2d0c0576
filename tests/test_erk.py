"""method = 'erk': ARKODE's ERKStep (Dormand-Prince 5(4), fortran/integration/integrator.f90) against the independent oracle,
against CVODE at tight tolerance on every shipped case, converging as rtol tightens, with the
contact switches located, and the executable equal to Python."""

import numpy as np
import pytest

import oracle
import pyspline
from conftest import (CASES, DEMONSTRATION_SCENES, PAPER, PAPER_SHAFTS, PAPER_SUPPORTS,
                      assert_executable_matches_python)

pytestmark = [PAPER_SHAFTS, PAPER_SUPPORTS, DEMONSTRATION_SCENES]   # expected warnings (conftest)

SHIPPED = sorted(p.stem for p in CASES.glob("*.nml") if p.stem != "template")


def f_error(res, ref):
    """Largest per-tooth force error over the run, relative to the largest force."""
    return np.abs(res.F - ref.F).max() / np.abs(ref.F).max()


def test_erk_agrees_with_the_oracle():
    """An engagement from rest with contact switches (misaligned paper drive): ERK with the
    switches located against scipy's LSODA on the numpy oracle (tests/oracle.py)."""
    from scipy.integrate import solve_ivp
    case = pyspline.load_case(dict(PAPER, name="erk_oracle", l_x=1e-4, l_y=-3e-5, start="rest",
                                   t_end=0.01, n_out=41, method="erk", roots=True,
                                   rtol=1e-10, atol=1e-12, linear_tail=False))
    res = pyspline.simulate(case)
    assert res.stats["roots_found"] > 0 and res.stats["steps"] > 100
    p = oracle.prepare(dict(case))
    c0, omega = case["c0"], case["speed_rpm"] * np.pi / 30
    sc = np.r_[np.full(7, c0), np.full(7, c0 * omega)]
    ref = solve_ivp(lambda t, y: oracle.rhs(t, y, p), (0.0, res.t[-1]), res.y[0], method="LSODA",
                    rtol=1e-10, atol=1e-12 * sc, t_eval=res.t)
    assert ref.success
    err = np.abs(res.y - ref.y.T).max(axis=0) / np.abs(ref.y).max(axis=1)
    assert err.max() < 1e-6, err
    tm = np.array([oracle.mesh(t, y, p)["Tm"] for t, y in zip(res.t, ref.y.T)])
    assert np.abs(res.Tm - tm).max() < 1e-6 * np.abs(tm).max()


@pytest.mark.parametrize("name", SHIPPED)
def test_erk_agrees_with_cvode_on_every_shipped_case(name):
    """A short run of every shipped case (its own physics, sections, level) by ERK and by CVODE
    BDF, both with the switches located at rtol 1e-11: the same switches are located, and the
    per-tooth forces agree to 1e-6, or, in the impacting scenes (physical_z24, chaos_z24), to
    within 5 times what CVODE's own Adams and BDF differ by (7e-6 and 4e-5 of F in 10 ms)."""
    case = pyspline.load_case(CASES / f"{name}.nml", t_transient=0.0, lyapunov=False)
    case = case.replace(t_end=min(case["t_end"], 0.01), n_out=81, roots=True, rtol=1e-11,
                        atol=1e-13)
    erk = pyspline.simulate(case.replace(method="erk"))
    cv = pyspline.simulate(case.replace(method="bdf"))
    adams = pyspline.simulate(case.replace(method="adams"))
    assert erk.stats["jac_evals"] == 0 and erk.stats["steps"] > 0
    assert erk.stats["roots_found"] == cv.stats["roots_found"]
    assert f_error(erk, cv) < max(1e-6, 5 * f_error(adams, cv))


@pytest.fixture(scope="module")
def z24():
    """physical_z24 over the first 30 ms of its engagement (hundreds of impacts) and a tight
    reference (CVODE BDF, switches located, rtol 1e-12)."""
    case = pyspline.load_case(CASES / "physical_z24.nml", t_end=0.03, n_out=121, t_transient=0.0,
                              section="none")
    ref = pyspline.simulate(case.replace(method="bdf", roots=True, rtol=1e-12, atol=1e-14,
                                         max_steps=10**7))
    return case, ref


def test_erk_converges_as_rtol_tightens(z24):
    """Down to the floor of this impacting scene: CVODE Adams and BDF at rtol 1e-12 differ by
    8e-7 of F after its hundreds of impacts."""
    case, ref = z24
    errs = [f_error(pyspline.simulate(case.replace(method="erk", roots=True, rtol=rt,
                                                   atol=rt * 1e-2)), ref)
            for rt in (1e-7, 1e-8, 1e-9)]
    assert errs[1] < errs[0] / 3 and errs[2] < errs[1] / 3 and errs[2] < 2e-6, errs


def test_roots_located_with_erk(z24):
    """Located switches make ERK accurate where teeth impact: at the same rtol, with roots the
    force error is far below the one with the switches stepped over (a kink inside a step)."""
    case, ref = z24
    on = pyspline.simulate(case.replace(method="erk", roots=True, rtol=1e-9, atol=1e-11))
    off = pyspline.simulate(case.replace(method="erk", roots=False, rtol=1e-9, atol=1e-11))
    assert on.stats["roots_found"] > 100 and off.stats["roots_found"] == 0
    assert f_error(on, ref) < 1e-4 and f_error(on, ref) < 0.1 * f_error(off, ref)



# Adams' reference orbit: CVODE steps to t + h = t in the clustered switches (said, not a fault of the test)
@pytest.mark.filterwarnings(r"ignore:case paper_ideal. SUNDIALS warned \d+ time\(s\) in this run"
                            r".*t \+ h = t:pyspline.SplineWarning")
def test_every_switch_of_a_cluster_is_located_with_erk():
    """The aligned Z16 drive of tests/test_cont_drives.py on its contact-loss orbit at 2480
    r/min: four times a period its 16 teeth switch together (1e-11 apart on the scaled time).
    ERK's root finding reports them a few at a time on its interpolant while the state it lands
    on has crossed more; those must switch too (spline_solver::settle_roots), or their teeth
    stay in the wrong contact state, the orbit's symmetry breaks and the map jumps (so
    continuing this drive with ERK stalled at 2356.01 r/min). ERK's orbit is Adams' with its
    64 switches, and ERK's map from it moved by 1e-9 to 1e-3 (scaled) along each state is its
    linearisation by the exact monodromy (the variational run) to 1e-5: the lost teeth left
    an orbit of 57 switches and 225 of 364 such runs off by up to 68."""
    from test_cont_drives import DRIVE
    from test_orbits import scale_of
    from pyspline.orbits import _period_map, map_and_monodromy
    case = DRIVE.replace(speed_rpm=2480.0)
    erk, adams = (pyspline.periodic_orbit(case.replace(method=m)) for m in ("erk", "adams"))
    assert erk.trajectory.stats["roots_found"] == adams.trajectory.stats["roots_found"] == 64
    d = scale_of(case)
    assert np.abs((erk.y0 - adams.y0) / d).max() < 1e-5
    model = pyspline.load(case.replace(method="erk"))
    t1 = erk.t0 + erk.period
    M = map_and_monodromy(model, erk.t0, t1, erk.y0)[1]
    moves = [(i, s * a) for i in range(14) for a in 10.0 ** np.arange(-9.0, -2.0) for s in (1, -1)]
    ys = np.array([erk.y0] + [erk.y0 + np.eye(14)[i] * a * d for i, a in moves]).T
    y1 = _period_map(model, erk.t0, t1, ys)[0]
    lin = np.array([M[:, i] * a for i, a in moves]).T
    off = np.abs((y1[:, 1:] - y1[:, :1]) / d[:, None] - lin).max(axis=0)
    assert off.max() < 1e-5, (off > 1e-5).sum()

def test_outputs_cost_no_rhs_at_loose_rtol(z24):
    """ERKStep's dense output: the cubic Hermite interpolant at rtol >= 1e-5 needs no
    right-hand side (the steps do not depend on the outputs after the first, which sets the
    initial step: 121 outputs cost what 2 do), the quartic at tighter rtol one per step that
    holds an output."""
    case = z24[0].replace(method="erk", roots=False, linear_tail=False, t_transient=0.01)
    rhs = {(rt, n): pyspline.simulate(case.replace(rtol=rt, atol=rt * 1e-2, n_out=n))
           .stats["rhs_evals"] for rt in (1e-5, 1e-6) for n in (2, 121)}
    assert rhs[1e-5, 121] == rhs[1e-5, 2], rhs
    assert rhs[1e-6, 2] < rhs[1e-6, 121] <= rhs[1e-6, 2] + 120, rhs


@pytest.mark.parametrize("name, rtol", [("physical_z24", None), ("paper_lx1e-4", None),
                                        ("physical_z24", 1e-4)])   # 1e-4: the cubic interpolant
def test_executable_matches_python_with_erk(name, rtol, exe, tmp_path):
    case = pyspline.load_case(CASES / f"{name}.nml", t_end=0.05, n_out=321, method="erk")
    if rtol:
        case = case.replace(rtol=rtol, atol=rtol * 1e-2)
    assert_executable_matches_python(case, exe, tmp_path)


def test_erk_failure_names_arkode():
    """A work bound met by ERKStep names ARKODE, the field and the time."""
    case = pyspline.load_case(CASES / "physical_z24.nml", t_end=0.01, method="erk", max_steps=20)
    with pytest.raises(pyspline.SolverError, match="ARKODE took max_steps = 20 steps"):
        pyspline.simulate(case)


def test_default_on_physical_z24_is_accurate():
    """physical_z24 with its own settings (method and roots by default: auto picks ERK from
    rest, with the switches located) over its engagement: per-tooth force error at most 1e-4
    against a tight reference with located switches (CVODE BDF, rtol 1e-12)."""
    case = pyspline.load_case(CASES / "physical_z24.nml", t_end=0.1, n_out=401)
    assert case["method"] == "auto" and case["roots"] is True
    res = pyspline.simulate(case)
    ref = pyspline.simulate(case.replace(method="bdf", rtol=1e-12, atol=1e-14, max_steps=10**7))
    assert res.stats["roots_found"] == ref.stats["roots_found"] > 100
    assert f_error(res, ref) <= 1e-4
    # its exact Poincare sections (whole shaft revolutions) too, against the states' range
    assert len(res.section_t) == 5 and np.array_equal(res.section_t, ref.section_t)
    span = np.ptp(ref.y, axis=0)
    assert (np.abs(res.section_y - ref.section_y).max(axis=0) <= 1e-4 * span).all()


@pytest.mark.parametrize("name,picked", [("physical_z24", "erk"), ("physical_ripple", "bdf"),
                                         ("paper_lx1e-4", "adams"), ("physical_tilt", "adams")])
def test_auto_is_the_method_it_picks(name, picked):
    """method = 'auto' runs bit for bit as the method docs/model.md says it picks."""
    case = pyspline.load_case(CASES / f"{name}.nml", t_end=0.01, n_out=41, t_transient=0.0,
                              method="auto")
    a, b = pyspline.simulate(case), pyspline.simulate(case.replace(method=picked))
    np.testing.assert_array_equal(a.y, b.y)
    assert a.stats["steps"] == b.stats["steps"]
