"""Thermal physics (Eqs. 1-7, 12-13): flash temperature, thermal backlash, coupling."""
import numpy as np
import pytest

import pyspline
from conftest import CASES, PAPER, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

HOT = dict(PAPER, l_x=1e-4, start="rest", t_end=0.1, n_out=641)


def test_backlash_shift_exact():
    T = 50.0
    res = pyspline.simulate(dict(HOT, name="bulk", thermal="bulk", t_bulk=T))
    c = res.case
    expect = c["c0"] - 2 * c["lambda_th"] * c["s"] * T * np.cos(np.radians(c["alpha_deg"]))
    np.testing.assert_allclose(res.tooth["c"], expect, rtol=1e-15)
    assert (res.tooth["Tf"] == 0).all()                          # bulk only: no flash computed


def test_no_sliding_no_flash():
    """Aligned, no gravity, at equilibrium: both contact points stay on the pitch circle
    (to the round-off of the equilibrium solve), so no sliding and no flash."""
    res = pyspline.simulate(dict(PAPER, name="still", thermal="oneway", grav=0.0))
    assert (np.abs(res.tooth["F"]) > 100).all()
    assert np.abs(res.tooth["rc1"] - res.tooth["rc2"]).max() < 1e-15
    assert res.tooth["Tf"].max() < 1e-9


def test_no_load_no_flash():
    """Lateral motion but every tooth free (inside the dead zone): no load, no flash."""
    case = pyspline.load_case(dict(PAPER, name="free", thermal="coupled", t_bulk=20.0))
    y = np.zeros(14)
    y[0], y[2], y[7], y[9] = 5e-5, -3e-5, 0.02, -0.01              # D2 = 0: all teeth free
    _, mesh, tm = pyspline.rhs(case, 0.003, y)
    assert (mesh["F"] == 0).all() and tm == 0
    assert (mesh["Tf"] == 0).all()
    assert (mesh["rc1"] != mesh["rc2"]).any()                      # they do slide


def test_flash_closed_form():
    """Eqs. 3-7 by hand from the contact radii the core reports."""
    res = pyspline.simulate(dict(HOT, name="hand", thermal="oneway", f_m=0.2))
    c = res.case
    k, j = len(res.t) // 2, 3
    F, r1, r2 = res.F[k, j], res.rc1[k, j], res.rc2[k, j]
    a = np.radians(c["alpha_deg"])
    w = c["speed_rpm"] * np.pi / 30
    rb = c["module_m"] * c["z"] / 2 * np.cos(a)
    R1, R2 = r1 * np.sin(np.arccos(rb / r1)), r2 * np.sin(np.arccos(rb / r2))
    fe = abs(F) / c["b"]
    B = c["eta_hertz"] * np.sqrt(2 * (1 - c["nu"] ** 2) / c["e_mod"] * fe * R1 * R2 / (R1 + R2))
    v1, v2 = w * r1 * np.cos(a), w * r2 * np.cos(a)
    grc = c["k_cond"] * c["rho"] * c["c_heat"]
    tf = c["u_flash"] * c["f_m"] * fe * abs(v1 - v2) / (np.sqrt(B) * (np.sqrt(grc * v1) + np.sqrt(grc * v2)))
    assert tf > 1e-3
    np.testing.assert_allclose(res.Tf[k, j], tf, rtol=1e-13)


def test_contact_radius_first_order():
    """Eq. 13: r_c = R - Delta cos(alpha) + O(Delta^2), within |Delta| of the pitch circle."""
    res = pyspline.simulate(dict(HOT, name="rc", thermal="oneway"))
    R = res.case["module_m"] * res.case["z"] / 2
    a = np.radians(res.case["alpha_deg"])
    dev = np.abs(res.rc1 - R)
    assert dev.max() < 2e-4 and dev.max() > 1e-6
    # |r_c - R| stays within |Delta| (cos(alpha) < 1), Delta <= |centre offset|
    off = np.hypot(res.x1 + res.case["l_x"], res.y1)
    assert (dev.max(axis=1) <= off * np.cos(a) * 1.01 + 1e-9).all()


def parting(one, two):
    """Measured and predicted relative force difference between the one-way and the coupled
    level. The feedback shifts the backlash by kappa T_f (Eq. 2), hence the force by about
    k_m kappa T_f: predicted = k_m kappa max(T_f) / max|F|."""
    c = one.case
    kappa = 2 * c["lambda_th"] * c["s"] * np.cos(np.radians(c["alpha_deg"]))
    k_m = pyspline.mesh_stiffness(c)["k_m_used"]
    scale = np.abs(one.F).max()
    return np.abs(one.F - two.F).max() / scale, k_m * kappa * one.Tf.max() / scale


def test_oneway_and_coupled_agree_when_coupling_is_weak():
    """Paper k_m: the feedback moves the forces by k_m kappa T_f ~ 1e-3 N (6e-6 relative)."""
    one = pyspline.simulate(dict(HOT, name="one", thermal="oneway", t_bulk=100.0))
    two = pyspline.simulate(dict(HOT, name="two", thermal="coupled", t_bulk=100.0))
    measured, predicted = parting(one, two)
    assert measured < 2e-5
    assert 0.3 < measured / predicted < 3
    assert np.abs(one.Tf - two.Tf).max() < 1e-4 * one.Tf.max()      # T_f ~ |F|^(3/4)
    assert two.stats["coupling_residual_degC"] < 1e-12


@pytest.mark.parametrize("f_m", [0.6, 5.0])
def test_where_oneway_and_coupled_part(f_m):
    """They part in proportion to k_m kappa T_f / |F|: with the physical k_m (8400 x stiffer)
    and growing friction the difference grows as predicted. They part by 1 % once
    k_m kappa T_f reaches 1 % of the tooth force (T_f ~ 14 degC for the physical k_m)."""
    kw = dict(PAPER, k_m=0.0, l_x=1e-4, t_bulk=100.0, f_m=f_m, t_end=0.02, n_out=81)
    one = pyspline.simulate(dict(kw, name="one", thermal="oneway"))
    two = pyspline.simulate(dict(kw, name="two", thermal="coupled"))
    measured, predicted = parting(one, two)
    assert measured > 1e-5
    assert 0.3 < measured / predicted < 3


def test_coupled_with_and_without_roots_agree():
    """The contact radii are continuous (docs/model.md s.6): the coupled level locates only the
    contact switches, and stepping onto them changes nothing beyond the tolerance."""
    base = dict(HOT, name="br", thermal="coupled", t_bulk=100.0, rtol=1e-10, atol=1e-12)
    a = pyspline.simulate(base)
    b = pyspline.simulate(dict(base, roots=True))
    assert b.stats["roots_found"] > 0                    # contact switches of the start located
    np.testing.assert_allclose(a.Tm, b.Tm, rtol=1e-7)
    np.testing.assert_allclose(a.Tf, b.Tf, rtol=1e-5, atol=1e-9)


def test_thermal_cases_run(tmp_path):
    for name in ("paper_T50", "paper_T100", "paper_flash_lx1e-4", "physical_lx1e-4"):
        res = pyspline.simulate(pyspline.load_case(CASES / f"{name}.nml", t_end=0.02, n_out=129))
        assert np.isfinite(res.Tf).all() and np.isfinite(res.F).all()


@pytest.mark.parametrize("fields,words,err", [
    (dict(f_m=-0.1), ["f_m", "negative"], pyspline.CaseError),
    (dict(lambda_th=1.0), ["lambda_th"], pyspline.CaseError),
    (dict(k_cond=0.0), ["k_cond", "positive"], pyspline.CaseError),
    (dict(eta_hertz=-1.0), ["eta_hertz"], pyspline.CaseError),
    (dict(t_bulk=3100.0), ["thermal interference", "t_bulk"], pyspline.ThermalInterferenceError),
])
def test_bad_thermal_fields(fields, words, err):
    with pytest.raises(err) as exc:
        pyspline.simulate(dict(HOT, name="badtherm", thermal="coupled", **fields))
    for w in words:
        assert w in str(exc.value)


def test_flash_closing_the_backlash_is_an_error():
    """Runaway: with huge friction the flash temperature closes the backlash during the run."""
    with pytest.raises(pyspline.ThermalInterferenceError) as exc, \
            pytest.warns(pyspline.SplineWarning, match=r"case runaway: start = 'rest' .* "
                         r"overlapping its backlash c = 4\.209E-06 m"):   # 3000 degC closes it
        pyspline.simulate(dict(HOT, name="runaway", thermal="coupled", t_bulk=3000.0, f_m=1e5))
    msg = str(exc.value)
    assert "case runaway" in msg and "tooth" in msg and "t =" in msg
