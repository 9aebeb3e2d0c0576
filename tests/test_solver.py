"""Convergence, root finding, methods, and the executable against Python."""

import numpy as np
import pytest

import pyspline
from conftest import CASES, PAPER, PAPER_SHAFTS, assert_executable_matches_python

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

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
