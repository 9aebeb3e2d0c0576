"""The numba/numbalsoda peer (bench/numba_peer.py) against the independent numpy oracle
(tests/oracle.py): both compiled RHS (the fast one and the general one) equal oracle.rhs to 1e-12
relative, the forces the race times equal oracle.mesh's, and short numbalsoda LSODA and DOP853
solves agree with scipy's LSODA on the oracle RHS. Does not import pyspline."""
import ctypes
import functools
import importlib.util
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("numba")
if importlib.util.find_spec("numbalsoda") is None:    # not imported here: its import compiles
    pytest.skip("numbalsoda is not installed", allow_module_level=True)  # for 11 s of CPU

import oracle  # noqa: E402
from conftest import random_states  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "bench"))
import numba_peer  # noqa: E402

#: one xdist worker runs them all: numba's import, the RHS loaded from its cache and numbalsoda's
#: drivers compiled once (tests/conftest.py)
pytestmark = pytest.mark.xdist_group("numba_peer")

BASE = dict(k_m=2.3e5, m_1=2.0, m_2=2.0)      # conftest.PAPER, over the core's defaults
CASES = {
    "aligned": dict(BASE),
    "misaligned": dict(BASE, l_x=1e-4),
    "misaligned_xy": dict(BASE, l_x=1e-4, l_y=-3e-5),
    "bulk": dict(BASE, l_x=1e-4, thermal="bulk", t_bulk=100.0),
    "oneway": dict(BASE, l_x=1e-4, thermal="oneway", t_bulk=50.0),
    "coupled": dict(BASE, l_x=1e-4, thermal="coupled", t_bulk=100.0, f_m=0.3),
    "z7": dict(BASE, z=7, l_x=1e-4),
    "slow_z7": dict(BASE, z=7, speed_rpm=300.0, l_x=5e-5, l_y=5e-5, grav=0.0),
    "stiff": dict(BASE, k_m=5e8, l_x=1e-4),
    "spacing": dict(BASE, l_x=5e-5, spacing_error=[3e-5, -2e-5, 0.0, 1e-5], spacing_error_amp=1e-5),
}
#: the cases the general RHS (kept for the coupled level) also runs: all but spacing errors
GENERAL = sorted(set(CASES) - {"spacing"})


@pytest.mark.parametrize("name,kind", [(n, None) for n in sorted(CASES)] +
                         [(n, "general") for n in GENERAL if n != "coupled"])
def test_peer_rhs_matches_oracle(name, kind):
    """kind None: the fast RHS, or the general one for the coupled level."""
    case = numba_peer.load_case(dict(CASES[name], name=name))
    p = oracle.prepare(case)
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    n_free = n_contact = 0
    for y in random_states(case["c0"], 60, rng):
        t = rng.uniform(0, 0.05)
        f = numba_peer.rhs_eval(case, t, y, kind=kind)
        fo = oracle.rhs(t, y, p)
        np.testing.assert_allclose(f, fo, rtol=1e-12, atol=1e-12 * np.abs(fo).max())
        # the scaled form (Eq. 25) used by solve() is the same function in other units
        l, w = case["c0"], p.omega
        sc = np.r_[np.full(7, l), np.full(7, l * w)]
        fs = numba_peer.rhs_eval(case, t * w, y / sc, scaled=True, kind=kind)
        np.testing.assert_allclose(fs * sc * w, fo, rtol=1e-12, atol=1e-12 * np.abs(fo).max())
        m = oracle.mesh(t, y, p)
        contact = np.abs(m["dn"]) > m["c"]
        n_contact += contact.sum()
        n_free += (~contact).sum()
    assert n_contact > 20 and n_free > 20       # both sides of the dead zone exercised


@pytest.mark.parametrize("name", sorted(set(CASES) - {"coupled"}))
def test_forces_match_oracle_mesh(name):
    """The T_m and F_j the race times (Setup.forces, from scaled states) equal oracle.mesh's."""
    case = numba_peer.load_case(dict(CASES[name], name=name))
    p = oracle.prepare(case)
    rng = np.random.default_rng(zlib.crc32(name.encode()) + 1)
    ys = np.array(random_states(case["c0"], 40, rng))
    ts = rng.uniform(0, 0.05, len(ys))
    s = numba_peer.Setup(case)
    tm, F = s.forces(ts, ys / s.scale)
    ref = [oracle.mesh(t, y, p) for t, y in zip(ts, ys)]
    Fo = np.array([m["F"] for m in ref])
    assert np.count_nonzero(Fo) > 20 and np.count_nonzero(Fo == 0) > 20
    np.testing.assert_allclose(F, Fo, rtol=1e-12, atol=1e-12 * np.abs(Fo).max())
    tmo = np.array([m["Tm"] for m in ref])
    np.testing.assert_allclose(tm, tmo, rtol=1e-12, atol=1e-12 * np.abs(tmo).max())


def test_kinds_refuse_what_they_lack():
    coupled = numba_peer.load_case(CASES["coupled"])
    with pytest.raises(ValueError, match="coupled"):
        numba_peer.make_rhs(coupled, kind="fast")
    with pytest.raises(ValueError, match="spacing"):
        numba_peer.make_rhs(numba_peer.load_case(CASES["spacing"]), kind="general")


def test_thermal_interference_is_an_error():
    with pytest.raises(ValueError, match="interference"):
        numba_peer.make_rhs(numba_peer.load_case(BASE, thermal="bulk", t_bulk=1e4))


def test_default_fields_match_template():
    """DEFAULTS (copied from the core's case_defaults) agree with cases/template.nml."""
    f90nml = pytest.importorskip("f90nml")
    tmpl = f90nml.read(str(Path(__file__).resolve().parent.parent / "cases" / "template.nml"))
    tmpl = tmpl["spline_case"]
    for k, v in numba_peer.DEFAULTS.items():
        if k in tmpl and not isinstance(v, (list, str)):
            assert float(tmpl[k]) == float(v), k


Y0 = np.zeros(14)                                 # start from rest: engagement transient
T_EVAL = np.linspace(0.0, 0.01, 41)
RTOL, ATOL = 1e-10, 1e-12                         # atol on the scaled states (Eq. 25)


@functools.cache
def scipy_reference(name):
    """scipy's LSODA on the oracle RHS, and its T_m: one solve serves both peer methods."""
    from scipy.integrate import solve_ivp
    case = numba_peer.load_case(dict(CASES[name], name=name))
    p = oracle.prepare(case)
    sc = np.r_[np.full(7, case["c0"]), np.full(7, case["c0"] * p.omega)]
    ref = solve_ivp(lambda t, yy: oracle.rhs(t, yy, p), (0.0, T_EVAL[-1]), Y0,
                    method="LSODA", rtol=RTOL, atol=ATOL * sc, t_eval=T_EVAL)
    tmr = np.array([oracle.mesh(t, yy, p)["Tm"] for t, yy in zip(T_EVAL, ref.y.T)])
    return case, p, ref, tmr


@pytest.mark.parametrize("method", ["lsoda", "dop853"])
@pytest.mark.parametrize("name", ["misaligned", "z7", "bulk", "coupled", "spacing"])
def test_peer_agrees_with_scipy_lsoda_on_oracle(name, method):
    """numbalsoda's LSODA and DOP853 on the numba RHS against scipy's LSODA on the oracle."""
    case, p, ref, tmr = scipy_reference(name)
    y, ok, nrhs = numba_peer.solve(case, Y0, T_EVAL, rtol=RTOL, atol=ATOL, method=method,
                                   mxstep=10**7)
    assert ok and nrhs > 100
    assert ref.success
    scale = np.abs(ref.y).max(axis=1)             # per state over the run
    err = np.abs(y - ref.y.T).max(axis=0) / scale
    assert err.max() < 1e-6, err
    # tooth load: T_m agrees too
    tm = np.array([oracle.mesh(t, yy, p)["Tm"] for t, yy in zip(T_EVAL, y)])
    assert np.abs(tm - tmr).max() < 1e-6 * np.abs(tmr).max()


def test_race_run_matches_oracle():
    """The race's peer (Setup.run: DOP853 on the case's frozen RHS, numba_peer._frozen, then
    the forces): its RHS equals oracle.rhs in the scaled units of Eq. 25 on both sides of the
    dead zone, and its T_m and F equal scipy's LSODA on the oracle's."""
    case, p, ref, tmr = scipy_reference("spacing")     # misaligned, with spacing errors
    s = numba_peer.Setup(case)
    tm, F, ok = s.run(Y0, T_EVAL, RTOL, ATOL, "dop853", 10**7)
    Fr = np.array([oracle.mesh(t, yy, p)["F"] for t, yy in zip(T_EVAL, ref.y.T)])
    assert ok and np.abs(F - Fr).max() < 1e-6 * np.abs(Fr).max()
    assert np.abs(tm - tmr).max() < 1e-6 * np.abs(tmr).max()
    fn = s._frozen                                      # the cfunc that solve called
    P = ctypes.POINTER(ctypes.c_double)
    rng = np.random.default_rng(7)
    n_contact = 0
    for y in random_states(case["c0"], 60, rng):
        t = rng.uniform(0, 0.05)
        u, du = y / s.scale, np.zeros(14)
        fn.ctypes(t * s.w, u.ctypes.data_as(P), du.ctypes.data_as(P), None)
        fo = oracle.rhs(t, y, p)
        np.testing.assert_allclose(du * s.scale * s.w, fo, rtol=1e-12, atol=1e-12 * np.abs(fo).max())
        n_contact += np.count_nonzero(oracle.mesh(t, y, p)["F"])
    assert 20 < n_contact < 60 * p.z - 20


#: the race's peer with its closed-form tail (bench/peer_tail.py) on the paper drive and a stiff
#: Z = 24 drive with physical mesh damping (physical_z24's numbers, k_m and c_m given)
TAIL_CASES = {"paper": dict(BASE, l_x=1e-4),
              "z24": dict(z=24, module_m=1.25e-3, s=1.963e-3, c0=1e-4, speed_rpm=3000.0,
                          t_d=50.0, t_l=50.0, l_x=5e-5, k_m=7.6e8, c_m=1796.0, k_t1=7744.0,
                          k_t2=7744.0)}


@pytest.mark.parametrize("name", sorted(TAIL_CASES))
def test_tail_system_is_the_oracles_in_full_contact(name):
    """The tail's affine system u' = A u + b (its closed form of the mesh in full contact) equals
    oracle.rhs in the scaled units of Eq. 25 at states with every tooth on flank s, at any
    angle; the drive's own flank (s = -1 under T_d > 0) is provable, the other is not."""
    import peer_tail
    case = numba_peer.load_case(dict(TAIL_CASES[name], name=name))
    p = oracle.prepare(case)
    l, w = p.c0, p.omega                            # Eq. 25's scales (thermal level none)
    scale = np.r_[np.full(7, l), np.full(7, l * w)]
    rng = np.random.default_rng(3)
    for s in (-1.0, 1.0):
        fl = peer_tail.Flank(p, s, p.c0, l, w)
        assert fl.ok == (s < 0)
        for _ in range(30):
            y = np.r_[rng.uniform(-0.3, 0.3, 7) * p.c0, rng.uniform(-0.3, 0.3, 7) * p.c0 * p.omega]
            y[0] -= p.l_x
            y[4] = rng.uniform(-300, 300) * p.c0
            y[5] = s * p.c0 * rng.uniform(2.0, 4.0)
            t = rng.uniform(0, 0.05)
            m = oracle.mesh(t, y, p)
            assert np.all(s * m["dn"] > m["c"])
            fo = oracle.rhs(t, y, p) / scale / w
            np.testing.assert_allclose(fl.A @ (y / scale) + fl.b, fo, rtol=1e-12,
                                       atol=1e-12 * np.abs(fo).max())


@pytest.mark.parametrize("name", sorted(TAIL_CASES))
def test_tailed_peer_is_exact_up_to_its_hand_over(name):
    """From rest the drive engages and settles into full contact: the tailed peer proves it
    inside the run, and its T_m and F over the whole run equal DOP853's at rtol 1e-13 without a
    tail (the RHS held to the oracle above); a window that ends before the proof has no tail
    (DOP853 in chunks); spacing errors turn the tail off."""
    import peer_tail
    case = numba_peer.load_case(dict(TAIL_CASES[name], name=name))
    tp = peer_tail.TailPeer(case)
    t = np.linspace(0.0, 0.1, 801)
    tm0, F0, ok0 = tp.setup.run(Y0, t, 1e-13, 1e-15)
    tm, F, ok = tp.run(Y0, t, 1e-13, 1e-15)
    assert ok and ok0 and 0.0 < tp.tail_t < 0.05
    assert np.abs(F - F0).max() < 1e-9 * np.abs(F0).max()
    assert np.abs(tm - tm0).max() < 1e-9 * np.abs(tm0).max()
    early = t[t <= tp.tail_t / 2]
    F1 = tp.run(Y0, early, 1e-13, 1e-15)[1]
    assert tp.tail_t == -1.0 and np.abs(F1 - F0[:len(early)]).max() < 1e-9 * np.abs(F0).max()
    spaced = numba_peer.load_case(dict(case, spacing_error=[1e-6]))
    assert not peer_tail.TailPeer(spaced).able
