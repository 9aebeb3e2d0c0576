"""Convergence, root finding, methods, and the executable against Python."""

import warnings

import numpy as np
import pytest

import pyspline
from conftest import (CASES, DEMONSTRATION_SCENES, PAPER, PAPER_SHAFTS, PAPER_SUPPORTS,
                      assert_executable_matches_python)

pytestmark = [PAPER_SHAFTS, PAPER_SUPPORTS]   # expected warnings (conftest)

SHORT = dict(t_end=0.1, n_out=401)


def run(**kw):
    return pyspline.simulate(dict(PAPER, name="conv", l_x=1e-4, start="rest", **SHORT) | kw)


def err(a, b):
    return np.abs(a.Tm - b.Tm).max() / np.abs(b.Tm).max()


def test_converges_as_rtol_tightens():
    ref = run(rtol=1e-12, atol=1e-14, roots=True)
    errs = [err(run(rtol=r, atol=r * 1e-2), ref) for r in (1e-5, 1e-7, 1e-9)]
    assert errs[0] > errs[1] > errs[2]
    assert errs[2] < 1e-6


@pytest.mark.parametrize("method,roots", [("bdf", True), ("adams", False), ("adams", True)])
def test_methods_agree(method, roots):
    ref = run(rtol=1e-11, atol=1e-13)
    res = run(rtol=1e-9, atol=1e-11, method=method, roots=roots)
    assert err(res, ref) < 1e-5


def test_root_finding_locates_switches():
    """From rest the teeth engage: root finding sees the engagement and restarts there."""
    res = run(rtol=1e-8, roots=True)
    assert res.stats["roots_found"] >= res.case["z"]
    assert res.stats["mode_resyncs"] == 0


@pytest.mark.parametrize("name", ["paper_ideal", "paper_lx5e-5", "paper_lx1e-4"])
def test_executable_matches_python(name, exe, tmp_path):
    case = pyspline.load_case(CASES / f"{name}.nml", t_end=0.1, n_out=641)
    header, col, data, res = assert_executable_matches_python(case, exe, tmp_path)
    assert header[0] == "t [s]" and "F_16 [N]" in header and "Tm [N m]" in header
    np.testing.assert_array_equal(data[:, col["kv"]], res.kv)


def test_physical_impacting_scene_statistics_agree_across_solvers():
    """cases/physical_z24 (computed stiffness, zeta_m = 0.01) engages from rest with hundreds of
    impacts, then settles. Its statistics after the engagement are the same for the defaults
    (method auto: ERK, switches located, rtol 1e-8), for Adams with fixed-point iteration and
    no root finding (the defaults before), for BDF + Newton with the contact switches located,
    and for a tight Adams + Newton run: the numbers a user reads do not depend on the solver
    (unlike rattle_z24's at a damping ratio of 2e-7)."""
    case = pyspline.load_case(CASES / "physical_z24.nml", t_end=0.6, n_out=2401)
    runs = {"defaults": pyspline.simulate(case),
            "adams": pyspline.simulate(case.replace(method="adams", roots=False)),
            "bdf+roots": pyspline.simulate(case.replace(method="bdf", roots=True, rtol=1e-6,
                                                        atol=1e-8)),
            "tight": pyspline.simulate(case.replace(method="adams", roots=False,
                                                    nonlinear="newton", rtol=1e-11,
                                                    atol=1e-13))}
    assert runs["bdf+roots"].stats["roots_found"] > 100            # it does impact
    assert runs["defaults"].stats["roots_found"] > 100             # defaults: located
    assert runs["adams"].stats["roots_found"] == 0

    def stats(r):
        late = r.t >= 0.3
        kv = r.kv[late]
        return np.r_[np.quantile(kv, [0.05, 0.5, 0.95]), np.sqrt(np.mean(r.Tm[late] ** 2)),
                     r.tooth["F"][late].max()]

    ref = stats(runs["tight"])
    for name in ("defaults", "adams", "bdf+roots"):
        np.testing.assert_allclose(stats(runs[name]), ref, rtol=1e-4, err_msg=name)


CHAOS = dict(section="none", lyapunov=False)


def tm_rms(res):
    return float(np.sqrt(np.mean(res.Tm ** 2)))


@DEMONSTRATION_SCENES
def test_multistep_restarts_at_loose_rtol_falsify_rattle_and_warn():
    """CVODE restarts at order 1 after every contact switch it locates. On the rattling
    chaos_z24 (50 revolutions sampled) Adams with roots at rtol 1e-2 (atol 1e-4) reads T_m RMS
    a third low (2.3-2.7 N m against 3.5-3.8 measured over tolerances and methods that agree),
    finding 2-3 times the switches; at rtol 1e-4 it agrees with ERK's at 1e-2, which restarts
    with the step that crossed. The loose run warns (run_warnings), naming rtol and its switches;
    the agreeing runs do not."""
    case = pyspline.load_case(CASES / "chaos_z24.nml", **CHAOS)
    with pytest.warns(pyspline.SplineWarning, match=r"rtol = 1\.000E-02 with method = 'adams' "
                      r"and \d+ contact switches located: CVODE restarts at order 1"):
        loose = pyspline.simulate(case.replace(rtol=1e-2, atol=1e-4))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tight = pyspline.simulate(case.replace(rtol=1e-4, atol=1e-6))
        erk = pyspline.simulate(case.replace(method="erk", rtol=1e-2, atol=1e-4))
        free = pyspline.simulate(case.replace(roots=False, rtol=1e-2, atol=1e-4))
    assert not [w for w in caught if "restarts at order 1" in str(w.message)]
    assert tm_rms(loose) < 0.8 * tm_rms(tight)
    assert loose.stats["roots_found"] > 1.5 * tight.stats["roots_found"]
    for res in (erk, free):
        assert abs(tm_rms(res) / tm_rms(tight) - 1) < 0.1


@DEMONSTRATION_SCENES
def test_executable_prints_the_restart_warning(exe, tmp_path):
    """spline-dyn prints the restart warning as Python raises it, the same words."""
    import subprocess
    case = pyspline.load_case(CASES / "chaos_z24.nml", **CHAOS, t_end=0.32, n_out=41,
                              rtol=1e-2, atol=1e-4)
    case.to_namelist(tmp_path / "loose.nml")
    run = subprocess.run([exe, str(tmp_path / "loose.nml"), "-o", str(tmp_path / "out.csv")],
                         capture_output=True, text=True, check=True)
    with pytest.warns(pyspline.SplineWarning, match="restarts at order 1") as rec:
        pyspline.simulate(case)
    said = [str(w.message) for w in rec if "restarts at order 1" in str(w.message)]
    assert len(said) == 1 and f"spline-dyn: warning: {said[0]}" in run.stderr.splitlines()


# A state on the periodic orbit of the Z16 drive of tests/test_cont_drives.py with the order-1
# ripple at 0.13, at 2488.47 r/min (pyspline.continuation over 2300-2650 r/min reached it), SI:
# x1 y1 x2 y2 D1 D2 D3 [m], their velocities [m/s]. Its period is one of the aligned drive's
# grazing contacts: every tooth opens and closes within 1e-13 s of the others, split by round-off.
GRAZING_Y0 = np.array([
    -6.806181792828899e-19, -3.923999999999805e-06, 6.806205563914763e-19, -3.92400000000018e-06,
    -0.00012950613884059645, 0.00017992683777840837, 0.0001287048488843166,
    -3.5463502337578286e-16, 2.1317722072931414e-16, 3.546192960824782e-16,
    -2.373171762308127e-16, -0.07373123213643412, 0.05940836230047624, 0.06285891968201351])
GRAZING = pyspline.load_case(CASES / "paper_ideal.nml", rtol=1e-8, atol=1e-10, roots=True, dof=7,
                             k_t1=1e3, k_t2=1e3, zeta_m=0.01, ripple_order=[1, 0, 0, 0],
                             ripple_amp=[0.13, 0, 0, 0], speed_rpm=2488.469669472484)


@pytest.mark.parametrize("method", ["adams", "bdf"])
def test_period_run_through_a_grazing_cluster_of_switches(method):
    """The state run over one forcing period from GRAZING_Y0 (what orbits._trajectory runs for
    a branch point) passes a free tooth whose switch function is at round-off level (exactly 0
    at a restart). Located crossing back the way that changes nothing, it would restart CVODE
    at one instant, each restart cutting the first step tenfold, until the step fell below
    round-off of t and CVODE 'reached' the next output without a state there (CV_ILL_INPUT
    "tout too far back" with Adams and BDF; BDF's period map 'succeeded' that way, 6 % of the
    state off its orbit). Only the crossings that change a contact state are located
    (spline_mesh::eq16_root_directions): the run succeeds, its end state is the period map's
    to the continuation's tolerance (100 rtol on the scaled states of Eq. 25), and CVODE says
    nothing."""
    from pyspline.orbits import _period_map
    from test_orbits import scale_of
    case = GRAZING.replace(method=method)
    period = 60 / case["speed_rpm"]
    run = case.replace(start="rest", dq0=list(GRAZING_Y0[:7]), dv0=list(GRAZING_Y0[7:]),
                       t0=0.0, t_end=period, t_transient=0.0, n_out=1001)
    with warnings.catch_warnings():
        warnings.simplefilter("error", pyspline.SplineWarning)
        res = pyspline.simulate(run)
        y1 = _period_map(case.model, 0.0, period, GRAZING_Y0[:, None])[0][:, 0]
    s = scale_of(case)
    tol = 100 * case["rtol"] * max(1.0, np.abs(GRAZING_Y0 / s).max())
    assert res.t[-1] == period and res.stats["roots_found"] > 32
    assert np.abs((res.y[-1] - y1) / s).max() < tol
    assert np.abs((y1 - GRAZING_Y0) / s).max() < tol        # the orbit closes: on the branch
