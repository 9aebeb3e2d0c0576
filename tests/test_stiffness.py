"""Mesh stiffness by the potential energy method (Eq. 18; fortran/physics/stiffness.f90)."""
import numpy as np
import pytest
from scipy.integrate import quad

import pyspline
from conftest import PAPER, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)


def spline_terms(**kw):
    return pyspline.mesh_stiffness(dict(PAPER, name="k", **kw))


def test_hertz_closed_form():
    k = spline_terms()
    np.testing.assert_allclose(k["k_h"], np.pi * 2.1e11 * 0.03 / (4 * (1 - 0.3**2)), rtol=1e-14)


def test_combination_is_eq18():
    """Eq. 18: the pair's compliance is the sum of its terms; the fillet-foundation terms count
    when fillet is on (the default), and are reported as 0 and left out when it is off."""
    base = ("k_h", "k_b1", "k_s1", "k_a1", "k_b2", "k_s2", "k_a2")
    k = spline_terms()
    inv = sum(1 / k[n] for n in base + ("k_f1", "k_f2"))
    np.testing.assert_allclose(k["k_m"], 1 / inv, rtol=1e-14)
    k0 = spline_terms(fillet=False)
    assert k0["k_f1"] == k0["k_f2"] == 0.0
    np.testing.assert_allclose(k0["k_m"], 1 / sum(1 / k0[n] for n in base), rtol=1e-14)
    for n in base:                                  # the other terms do not depend on it
        assert k0[n] == k[n], n
    assert 2 < k0["k_m"] / k["k_m"] < 3             # the foundation is the softest part


def test_computed_k_m_counts_the_fillet_by_default():
    used = pyspline.mesh_stiffness(dict(name="c", k_m=0.0))
    assert used["computed"] and used["k_m_used"] == used["k_m"] and used["k_f1"] > 0
    off = pyspline.mesh_stiffness(dict(name="c", k_m=0.0, fillet=False))
    assert off["k_m_used"] == off["k_m"] > used["k_m_used"]


def test_linear_in_face_width():
    k1, k2 = spline_terms(b=0.03, k_m=0.0), spline_terms(b=0.045, k_m=0.0)   # no case k_m to judge
    for n in ("k_h", "k_b1", "k_s1", "k_a1", "k_f1", "k_b2", "k_s2", "k_a2", "k_f2", "k_m"):
        np.testing.assert_allclose(k2[n] / k1[n], 1.5, rtol=1e-13, err_msg=n)


@pytest.mark.parametrize("internal", [False, True])
def test_quadrature_converged(internal):
    """Gauss-Legendre in the roll parameter: the result stops moving as the rule is refined."""
    kw = dict(z=16, module=2e-3, alpha_deg=30, b=0.03, r_contact=16e-3, internal=internal)
    kw.update(r_root=17.5e-3, r_tip=15e-3) if internal else kw.update(r_root=14.5e-3)
    k8, k16, k64 = (pyspline.tooth_stiffness(nquad=n, **kw) for n in (8, 16, 64))
    for n in ("k_b", "k_s", "k_a"):
        assert abs(k16[n] / k64[n] - 1) < 1e-12, n
        assert abs(k8[n] / k64[n] - 1) < 1e-7, n


def rack_tooth(m, alpha_deg, b, e, nu):
    """Closed-form limit z -> infinity: a straight-flanked (trapezoidal) cantilever of
    dedendum 1.25 m, half thickness pi m / 4 at the pitch line, loaded there at the pressure
    angle (beta = alpha), with the same energy integrals (Tian 2004): an independent evaluation."""
    a = np.radians(alpha_deg)
    g = e / (2 * (1 + nu))
    xc, hc = 1.25 * m, np.pi * m / 4
    h = lambda x: hc + (xc - x) * np.tan(a)                     # x from the root line up
    kb = quad(lambda x: (np.cos(a) * (xc - x) - np.sin(a) * hc) ** 2
              / (e * 2 / 3 * h(x) ** 3 * b), 0, xc, epsabs=0, epsrel=1e-13)[0]
    ks = quad(lambda x: 1.2 * np.cos(a) ** 2 / (g * 2 * h(x) * b), 0, xc, epsrel=1e-13)[0]
    ka = quad(lambda x: np.sin(a) ** 2 / (e * 2 * h(x) * b), 0, xc, epsrel=1e-13)[0]
    return {"k_b": 1 / kb, "k_s": 1 / ks, "k_a": 1 / ka}


@pytest.mark.parametrize("internal", [False, True])
def test_rack_limit(internal):
    """Both the external and the internal tooth tend to the rack tooth as 1/z."""
    m, ref = 2e-3, rack_tooth(2e-3, 30, 0.03, 2.1e11, 0.3)
    devs = []
    for z in (1e3, 1e4, 1e5):
        r = m * z / 2
        kw = dict(r_root=r + 1.25 * m, r_tip=r - m) if internal else dict(r_root=r - 1.25 * m)
        k = pyspline.tooth_stiffness(z, m, 30, 0.03, r_contact=r, internal=internal, **kw)
        devs.append(max(abs(k[n] / ref[n] - 1) for n in ref))
    assert devs[2] < 3e-4
    assert devs[0] / devs[1] > 5 and devs[1] / devs[2] > 5          # O(1/z)


def test_spline_order_of_magnitude():
    """A short (1.25 m deep), wide (30 mm) steel tooth pair: between 1e8 and 3e9 N/m (docs/model.md
    Section 7); the paper's forces imply about 2.3e5 N/m (a unit slip, see the README)."""
    k = spline_terms()
    assert 1e8 < k["k_m"] < 3e9
    assert k["k_m_used"] == 2.3e5 and not k["computed"]


def test_case_without_k_m_uses_the_computed_value():
    k = pyspline.mesh_stiffness({"name": "phys"})
    assert k["computed"] and k["k_m_used"] == k["k_m"]


def test_root_circle_inside_and_outside_base_circle():
    """Z = 19 / 48, m = 3.2 mm, 20 deg (the gear data of Tian 2004 and Chen & Shao 2011): the
    pinion's root circle lies inside its base circle, the gear's outside. Both evaluate, and a
    tooth is stiffer in bending the more teeth it has (a thicker root)."""
    m = 3.2e-3
    pin = pyspline.tooth_stiffness(19, m, 20, 0.016, m * (19 / 2 - 1.25), m * 19 / 2, 2.068e11)
    gear = pyspline.tooth_stiffness(48, m, 20, 0.016, m * (48 / 2 - 1.25), m * 48 / 2, 2.068e11)
    assert m * (19 / 2 - 1.25) < m * 19 / 2 * np.cos(np.radians(20))
    assert m * (48 / 2 - 1.25) > m * 48 / 2 * np.cos(np.radians(20))
    assert gear["k_b"] > pin["k_b"] and gear["k_s"] > pin["k_s"]


def test_bad_geometry_is_an_error():
    with pytest.raises(pyspline.CaseError, match="r_contact"):
        pyspline.tooth_stiffness(16, 2e-3, 30, 0.03, r_root=16.5e-3, r_contact=16e-3)
