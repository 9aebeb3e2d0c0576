"""The Fortran right-hand side against the independent numpy oracle (tests/oracle.py), written
from docs/model.md by someone who did not read the Fortran."""
import zlib

import numpy as np
import pytest

import oracle
import pyspline
from conftest import PAPER, PAPER_SHAFTS, random_states

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)


CASES = {
    "aligned": dict(PAPER),
    "misaligned": dict(PAPER, l_x=1e-4, l_y=-3e-5),
    "bulk": dict(PAPER, l_x=1e-4, thermal="bulk", t_bulk=100.0),
    "oneway": dict(PAPER, l_x=1e-4, thermal="oneway", t_bulk=50.0),
    "coupled": dict(PAPER, l_x=1e-4, thermal="coupled", t_bulk=100.0, f_m=0.3),
    "slow_z7": dict(PAPER, z=7, speed_rpm=300.0, l_x=5e-5, l_y=5e-5, grav=0.0),
    # tooth spacing errors up to 0.9 c0 of either sign (docs/model.md s.11)
    "spacing": dict(PAPER, l_x=1e-4, thermal="bulk", t_bulk=20.0,
                    spacing_error=list(0.9e-4 * np.sin(np.arange(1, 17) * 2.3))),
    "spacing_seeded": dict(PAPER, l_y=5e-5, spacing_error=[3e-5, -2e-5],
                           spacing_error_amp=1.2e-4, spacing_error_seed=20261124),
    "spacing_oneway": dict(PAPER, z=7, thermal="oneway", t_bulk=50.0,
                           spacing_error=[1.5e-4, -1.2e-4, 0.0, 5e-5, -1e-5, 1.8e-4, -1.9e-4]),
    # a shift of up to 1.9 mm moves the contact point past both tip circles: radii held there
    "oneway_clipped": dict(PAPER, l_x=1.9e-3, thermal="oneway"),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_rhs_matches_oracle(name):
    case = pyspline.load_case(dict(CASES[name], name=name))
    model = pyspline.load(case)
    p = oracle.prepare(dict(case))
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    n_free = n_contact = 0
    n_clipped = np.zeros(2, int)
    for y in random_states(case["c0"], 40, rng):
        t = rng.uniform(0, 0.05)
        f, mesh, tm = model.rhs_mesh(t, y)
        np.testing.assert_array_equal(model.rhs(t, y), f)     # the fast path is the same RHS
        o = oracle.mesh(t, y, p)
        fo = oracle.rhs(t, y, p)
        scale_f = case["k_m"] * case["c0"]
        np.testing.assert_allclose(f, fo, rtol=1e-12, atol=1e-12 * np.abs(fo).max())
        for q in ("F", "Fx", "Fy"):
            np.testing.assert_allclose(mesh[q], o[q], rtol=1e-12, atol=1e-12 * scale_f)
        for q in ("dn", "c"):
            np.testing.assert_allclose(mesh[q], o[q], rtol=1e-12, atol=1e-12 * case["c0"])
        np.testing.assert_allclose(tm, o["Tm"], rtol=1e-12, atol=1e-12 * scale_f * 0.02)
        if case["thermal"] in ("oneway", "coupled"):
            np.testing.assert_allclose(mesh["rc1"], o["rc1"], rtol=1e-12)
            np.testing.assert_allclose(mesh["rc2"], o["rc2"], rtol=1e-12)
            np.testing.assert_allclose(mesh["Tf"], o["Tf"], rtol=1e-10, atol=1e-12)
            n_clipped += [(o["rc1"] == p.r_lo).sum(), (o["rc1"] == p.r_hi).sum()]
        contact = np.abs(o["dn"]) > o["c"]
        n_contact += contact.sum()
        n_free += (~contact).sum()
    # the random states exercised both sides of the dead zone
    assert n_contact > 20 and n_free > 20
    if name == "oneway_clipped":      # ... and both ends of the active profile
        assert n_clipped.min() > 20
