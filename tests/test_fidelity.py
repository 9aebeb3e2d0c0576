"""The fidelity ladder: the torsional level (dof = 3), and fidelity = 'auto' never picking a
level whose error against the case's own level exceeds the case's fidelity_tol."""
import math

import numpy as np
import pytest

import pyspline
from conftest import CASES, PAPER, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

SHORT = dict(t_end=0.1, n_out=161, start="rest")
MARGIN = 0.5                       # fidelity.f90: auto reduces when estimate <= MARGIN * tol
F0 = 30.7 / (16 * 0.016 * math.cos(math.radians(30)))   # static tooth load |T_d| / (Z r_b)


def err(a, b):
    """Max relative error of T_m and of the per-tooth F_j (as in pyspline bench)."""
    return max(np.abs(a.Tm - b.Tm).max() / np.abs(b.Tm).max(),
               np.abs(a.F - b.F).max() / np.abs(b.F).max())


def test_torsional_level_is_exact_for_an_aligned_scene():
    """Aligned, equal sag: every tooth sees the same dn_j, sum F_j sin(phi_j) = 0, the lateral
    states never move relative to each other, so freezing them changes nothing."""
    base = dict(PAPER, name="aligned", **SHORT)
    full, tors = pyspline.simulate(base), pyspline.simulate(base | dict(dof=3))
    assert (full.stats["dof"], tors.stats["dof"]) == (7, 3)
    assert err(tors, full) < 1e-6
    assert np.ptp(tors.y[:, :4], axis=0).max() == 0 and not tors.y[:, 7:11].any()
    assert tors.stats["steps"] < full.stats["steps"] / 2      # no lateral modes to resolve


def test_torsional_level_misses_when_misaligned():
    base = dict(PAPER, name="misaligned", l_x=1e-4, **SHORT)
    assert err(pyspline.simulate(base | dict(dof=3)), pyspline.simulate(base)) > 1e-2


def boundary_lx(tol):
    """Misalignment whose lateral estimate k_m l_x / F0 is just inside auto's threshold."""
    return 0.9 * MARGIN * tol * F0 / PAPER["k_m"]


SCENES = {
    "aligned": dict(PAPER),
    "misaligned": dict(PAPER, l_x=1e-4),
    "lateral_boundary": dict(PAPER),          # l_x set per tolerance (boundary_lx)
    "bulk_T30": dict(PAPER, l_x=5e-5, thermal="bulk", t_bulk=30.0),
    "bulk_T100": dict(PAPER, l_x=5e-5, thermal="bulk", t_bulk=100.0),
    "coupled_T100": dict(PAPER, l_x=1e-4, thermal="coupled", t_bulk=100.0, f_m=26.069,
                         roots=True),
    "coupled_aligned": dict(PAPER, thermal="coupled", t_bulk=50.0, f_m=26.069),
    "flash_lx0": dict(PAPER, thermal="oneway", f_m=26.069),
}


@pytest.mark.parametrize("tol", [1e-2, 1e-3])
@pytest.mark.parametrize("scene", list(SCENES))
def test_auto_never_picks_a_level_that_misses(scene, tol):
    case = dict(SCENES[scene], name=scene, **SHORT)
    if scene == "lateral_boundary":
        case["l_x"] = boundary_lx(tol)
    own = pyspline.simulate(case)
    auto = pyspline.simulate(case | dict(fidelity="auto", fidelity_tol=tol))
    assert err(auto, own) <= tol, auto.stats
    assert auto.stats["dof"] <= own.stats["dof"]
    if case.get("thermal") in ("oneway", "coupled"):          # T_f is still reported
        assert auto.stats["thermal_level"] >= 2


def test_auto_reduces_where_it_can():
    """Not vacuous: the aligned and boundary scenes run torsional, the weakly coupled flash
    scene runs one-way, a small bulk rise is dropped; the misaligned scene keeps 7 DOF."""
    def level(scene, tol=1e-2, **kw):
        s = pyspline.simulate(dict(SCENES[scene], name=scene, fidelity="auto",
                                   fidelity_tol=tol, **SHORT) | kw).stats
        return s["dof"], s["thermal_level"]
    assert level("aligned") == (3, 0)
    assert level("lateral_boundary", l_x=boundary_lx(1e-2)) == (3, 0)
    assert level("lateral_boundary", l_x=3 * boundary_lx(1e-2)) == (7, 0)
    assert level("misaligned") == (7, 0)
    assert level("bulk_T30") == (7, 0)        # bulk dropped: estimate 3.3e-3 <= 5e-3
    assert level("bulk_T100") == (7, 1)       # kept: estimate 1.1e-2
    assert level("coupled_T100") == (7, 2)    # one-way: flash feedback estimate 2.3e-3
    assert level("coupled_T100", tol=1e-3) == (7, 3)
    assert level("flash_lx0") == (3, 2)


def test_paper_case_auto_from_file():
    """A case file may say auto; the paper's ideal scene then runs torsional."""
    res = pyspline.simulate(pyspline.load_case(CASES / "paper_ideal.nml",
                                               fidelity="auto", t_end=0.05, n_out=33))
    assert res.stats["dof"] == 3 and res.stats["fidelity_eps_lateral"] == 0.0
