"""Tooth spacing (index) errors e_j (docs/model.md section 11): tooth j of spline 1 sits e_j
ahead of its place along +dn, so it meets its dead zone at dn_j + e_j. Static full contact
against the closed form (torque balance plus the isotropic spring of the lateral mesh), the
sign of the convention, the input checks and the executable against Python."""
import math
import subprocess

import numpy as np
import pytest

import oracle
import pyspline
from conftest import CASES as CONFTEST_CASES, PAPER, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

#: the paper's 16 teeth at theta_j = 2 pi j / 16
THETA = 2 * np.pi * np.arange(1, 17) / 16
#: spacing-error patterns (shapes, scaled per case): one with no first harmonic in j (no
#: eccentricity: the lateral mesh forces cancel), one with it (it pushes the centres apart)
NO_FIRST = np.cos(2 * THETA) + 0.7 * np.sin(3 * THETA) + 0.4 * np.cos(5 * THETA + 1.0)
WITH_FIRST = np.sin(2.3 * np.arange(1, 17)) + 0.25 * np.cos(5.1 * np.arange(1, 17))


def scaled(shape, k_m, spread=0.6, c0=2e-4):
    """shape scaled so that k_m max(mean(e) - e_j) = spread F0 (load-sharing factor 1 + spread
    in torsion), |e_j| kept below c0 / 2."""
    f0 = 30.7 / (16 * 0.016 * math.cos(math.pi / 6))
    a = spread * f0 / k_m / (shape.mean() - shape).max()
    a = min(a, 0.5 * c0 / np.abs(shape).max())
    return list(a * shape)


def static_mesh(**fields):
    case = pyspline.load_case(dict(PAPER, name="spacing", **fields))
    y = pyspline.start_state(case)
    ydot, mesh, tm = pyspline.rhs(case, 0.0, y)
    return case, y, ydot, mesh, tm


def closed_form(case, y):
    """Static full contact on the loaded flank (dn_j + e_j < -c): torque balance gives
    sum F_j = -T_d / r_b; the lateral mesh is the isotropic spring K = Z k_m / 2 plus the load
    k_m sum_j e_j (sin, -cos)(phi_j) of the errors' first harmonic, against the supports in
    series (C = 1/k_p1 + 1/k_p2), without gravity:
      e_x = (l_x - C k_m E_s) / (1 + K C),  e_y = (l_y + C k_m E_c) / (1 + K C),
      F_j = -T_d/(Z r_b) + k_m (e_j - mean(e)) + k_m (e_x sin(phi_j) - e_y cos(phi_j)),
    with E_s = sum e_j sin(phi_j), E_c = sum e_j cos(phi_j)."""
    p = oracle.prepare(dict(case))
    phi = oracle.mesh(0.0, y, p)["phi"]
    e = p.e
    k_m, z = case["k_m"], case["z"]
    K, C = z * k_m / 2, 1 / case["k_p1"] + 1 / case["k_p2"]
    es, ec = e @ np.sin(phi), e @ np.cos(phi)
    ex = (case["l_x"] - C * k_m * es) / (1 + K * C)
    ey = (case["l_y"] + C * k_m * ec) / (1 + K * C)
    f0 = case["t_d"] / (z * p.r_b)
    return -f0 + k_m * (e - e.mean()) + k_m * (ex * np.sin(phi) - ey * np.cos(phi)), f0, (ex, ey)


@pytest.mark.parametrize("k_m", [2.3e5, 1.0e8, 0.0])
def test_aligned_static_full_contact_closed_form(k_m):
    """Aligned, errors without a first harmonic (no eccentricity): F_j = -T_d/(Z r_b)
    + k_m (e_j - mean(e)), and the load-sharing factor max |F_j| / (T_d/(Z r_b)) =
    1 + k_m max(mean(e) - e_j) / F0. (k_m = 0: the computed 7.8e8 N/m.)"""
    k = pyspline.load_case(dict(PAPER, k_m=k_m)).model.info()["k_m"]
    e = np.array(scaled(NO_FIRST, k))
    case, y, ydot, mesh, tm = static_mesh(k_m=k_m, grav=0.0, spacing_error=list(e))
    p = oracle.prepare(dict(case))
    f0 = case["t_d"] / (case["z"] * p.r_b)
    want = -f0 + k * (e - e.mean())
    assert (want < 0).all() and (np.abs(mesh["dn"]) > mesh["c"]).all()     # full contact
    np.testing.assert_allclose(mesh["F"], want, rtol=0, atol=1e-9 * f0)
    np.testing.assert_allclose(tm, -case["t_d"], rtol=1e-12)
    factor = np.abs(mesh["F"]).max() / f0
    np.testing.assert_allclose(factor, 1 + k * (e.mean() - e).max() / f0, rtol=1e-9)
    assert factor > 1.15               # the errors, not only the torque, decide the sharing


@pytest.mark.parametrize("lx,ly,speed", [(0.0, 0.0, 0.0), (1e-4, -3e-5, 0.0), (5e-5, 2e-5, 6000.0)])
@pytest.mark.parametrize("k_m", [2.3e5, 1.0e8])
def test_static_full_contact_closed_form_with_lateral_spring(lx, ly, speed, k_m):
    """7 DOF: the errors' first harmonic pushes the centres apart like a misalignment, and the
    isotropic spring adds k_m (e_x sin - e_y cos) to every tooth (docs/model.md section 9, with
    e_j). c_m = 0: at speed the turning frame adds no damping force at rest."""
    e = scaled(WITH_FIRST, k_m, spread=0.4)
    case, y, ydot, mesh, tm = static_mesh(k_m=k_m, l_x=lx, l_y=ly, speed_rpm=speed, grav=0.0,
                                          c_m=0.0, spacing_error=e)
    want, f0, (ex, ey) = closed_form(case, y)
    assert (want < 0).all() and (np.abs(mesh["dn"]) > mesh["c"]).all()
    np.testing.assert_allclose(mesh["F"], want, rtol=0, atol=1e-9 * f0)
    np.testing.assert_allclose([y[0] + lx - y[2], y[1] + ly - y[3]], [ex, ey],
                               rtol=0, atol=1e-9 * max(abs(ex), abs(ey)))
    assert np.abs(ydot[7:]).max() < 1e-8 * case["c0"] * (2 * np.pi * 100) ** 2
    if lx == 0.0:                      # aligned: the shift is the errors' alone
        assert k_m * math.hypot(ex, ey) > 1e-3 * case["t_d"] / (16 * 0.0139)


def test_the_sign_a_uniform_error_is_spline_1_ahead_along_dn():
    """The convention (docs/model.md section 11): e_j moves tooth j ahead along +dn, so equal
    errors on every tooth are spline 1 turned by e along +dn, the same as D2 + e (Eq. 11). The
    static equilibrium then sits at D2 - e with the same loads. The formula of the issue's spec,
    dead zone [-c + e_j, c + e_j] (dn_j - e_j), is this with e_j -> -e_j: a tooth behind."""
    e0 = 3e-5
    _, y0, _, m0, _ = static_mesh(grav=0.0)
    case, y1, _, m1, _ = static_mesh(grav=0.0, spacing_error=[e0] * 16)
    np.testing.assert_allclose(y1[5], y0[5] - e0, rtol=1e-12)
    np.testing.assert_allclose(m1["F"], m0["F"], rtol=1e-9)
    # the right-hand side at any state: uniform e equals the error-free mesh at D2 + e
    base = pyspline.load_case(dict(PAPER, name="spacing"))
    rng = np.random.default_rng(5)
    for _ in range(10):
        y = np.r_[rng.uniform(-2e-4, 2e-4, 7), rng.uniform(-0.1, 0.1, 7)]
        shifted = y.copy()
        shifted[5] += e0
        f1, t1, tm1 = pyspline.rhs(case, 0.01, y)
        f0, t0, tm0 = pyspline.rhs(base, 0.01, shifted)
        np.testing.assert_allclose(t1["F"], t0["F"], rtol=1e-9, atol=1e-9 * case["k_m"] * 1e-4)


def test_a_tooth_ahead_carries_less_of_the_drive():
    """Under drive the loaded flank is at dn = -c (docs/model.md section 1): a tooth ahead along
    +dn has a wider gap there and carries less; one behind carries more."""
    e = [0.0] * 16
    e[2], e[9] = 2e-7, -2e-7
    case, y, _, mesh, _ = static_mesh(k_m=1e8, grav=0.0, spacing_error=e)
    f = np.abs(mesh["F"])
    assert f[2] < f[0] < f[9]


def test_zero_errors_change_nothing():
    """Given as zeros, the errors leave every number as it was (the executable path too)."""
    case = dict(PAPER, name="z", l_x=1e-4, start="rest", t_end=0.01, n_out=21)
    a = pyspline.simulate(case)
    b = pyspline.simulate(dict(case, spacing_error=[0.0] * 16))
    np.testing.assert_array_equal(a.y, b.y)
    np.testing.assert_array_equal(a.tooth["F"], b.tooth["F"])


def test_run_keeps_the_torque_and_the_executable_agrees(exe, tmp_path):
    """A run with spacing errors (from rest, rattling into contact) settles to T_m = -T_d and
    the static loads of the closed form; spline-dyn gives Python's numbers bit for bit."""
    case = pyspline.load_case(dict(PAPER, name="sp", k_m=1e7, grav=0.0, c_m=0.0,
                                   spacing_error=scaled(WITH_FIRST, 1e7), spacing_error_amp=2e-6,
                                   spacing_error_seed=99, t_end=0.02, n_out=41))
    res = pyspline.simulate(case)
    assert res.stats["linear_tail_t_s"] == -1.0          # the tail is off with errors
    path = tmp_path / "sp.nml"
    case.to_namelist(path)
    assert "spacing_error" in path.read_text()
    out = tmp_path / "sp.csv"
    run = subprocess.run([exe, str(path), "-o", str(out)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    header, data = pyspline.core.read_csv(out)
    np.testing.assert_array_equal(data[:, 0], res.t)
    np.testing.assert_array_equal(data[:, 1:15], res.y)
    cols = [i for i, h in enumerate(header) if h.startswith("F_") and "[N]" in h][:16]
    assert len(cols) == 16
    np.testing.assert_array_equal(data[:, cols], res.tooth["F"])


@pytest.mark.parametrize("fields,words", [
    (dict(spacing_error=[2e-4]), ["field spacing_error(1)", "c0 = 2.000E-04 m", "tooth 1"]),
    (dict(spacing_error=[0.0, 0.0, -3e-4]), ["field spacing_error(3)", "not smaller"]),
    (dict(spacing_error=[0.0] * 16 + [1e-6]), ["field spacing_error(17)", "beyond z = 16"]),
    (dict(spacing_error=[1e-6, math.nan]), ["field spacing_error", "finite"]),
    (dict(spacing_error=[math.inf]), ["field spacing_error", "finite"]),
    (dict(spacing_error=[0.0] * 1001), ["field spacing_error", "1 to 1000 numbers"]),
    (dict(spacing_error=[]), ["field spacing_error", "1 to 1000 numbers"]),
    (dict(spacing_error=1e-6), ["field spacing_error", "1 to 1000 numbers"]),
    # the bulk temperature shrinks the backlash below the error (Eq. 2)
    (dict(spacing_error=[1.9e-4], thermal="bulk", t_bulk=200.0),
     ["field spacing_error(1)", "at the bulk temperature"]),
    (dict(spacing_error_amp=2e-4), ["field spacing_error_amp", "outside 0 .. c0"]),
    (dict(spacing_error_amp=-1e-6), ["field spacing_error_amp", "outside 0 .. c0"]),
    (dict(spacing_error_amp=math.nan), ["field spacing_error_amp", "finite"]),
    (dict(spacing_error_seed=0), ["field spacing_error_seed", "outside 1 .. 2147483646"]),
    # each part below c0, their sum not (the seeded tooth 1 of seed 1 is positive)
    (dict(spacing_error=[1.5e-4] * 16, spacing_error_amp=1.5e-4),
     ["field spacing_error(", "with spacing_error_amp"]),
])
def test_bad_spacing_errors_are_case_errors(fields, words):
    with pytest.raises(pyspline.CaseError) as exc:
        pyspline.load_case(dict(PAPER, name="bad", **fields)).model
    for w in words:
        assert w in str(exc.value), str(exc.value)


def test_a_shorter_list_gives_the_first_teeth_and_a_file_reads_the_same(tmp_path):
    case = pyspline.load_case(dict(PAPER, name="short", spacing_error=[1e-6, -2e-6]))
    assert case["spacing_error"][:3] == [1e-6, -2e-6, 0.0]
    assert len(case["spacing_error"]) == len(pyspline.defaults()["spacing_error"])
    path = tmp_path / "short.nml"
    path.write_text("&spline_case\n  k_m = 2.3e5\n  spacing_error = 1e-6, -2e-6\n/\n")
    assert pyspline.load_case(path)["spacing_error"] == case["spacing_error"]


@pytest.mark.parametrize("shape,amp,dof", [(NO_FIRST, 0.3e-6, 3), (NO_FIRST, 3e-6, 7),
                                           (WITH_FIRST, 0.3e-6, 7), (WITH_FIRST, 3e-6, 7)])
def test_auto_fidelity_counts_the_lateral_force_of_the_engaged_teeth(shape, amp, dof):
    """fidelity = 'auto' keeps the lateral motion when the errors move the centres: always with
    a first harmonic; without one only once teeth unload (3 um against the static tooth
    deflection F0 / k_m = 1.4 um here: the engaged set pushes sideways), not while every
    tooth is engaged (0.3 um: every tooth pushes the centres equally)."""
    e = list(amp * shape / np.abs(shape).max())
    res = pyspline.simulate(dict(PAPER, name="auto", k_m=1e8, grav=0.0, spacing_error=e,
                                 fidelity="auto", t_end=0.002, n_out=3))
    assert res.stats["dof"] == dof


#: the Z = 24 spline of physical_z24 aligned and without gravity (no other lateral driver), its
#: spacing errors without a first harmonic in j, from its static equilibrium
Z24_THETA = 2 * np.pi * np.arange(1, 25) / 24
Z24_NO_FIRST = np.cos(2 * Z24_THETA) + 0.7 * np.sin(3 * Z24_THETA) + 0.4 * np.cos(5 * Z24_THETA + 1)


@pytest.mark.parametrize("amp", [0.05e-6, 1e-6, 20e-6])
def test_auto_fidelity_under_partial_engagement_keeps_what_the_loads_need(amp):
    """Errors without a first harmonic: with every tooth engaged (0.05 um against a tooth
    deflection of 0.21 um) dof 3 is exact and auto takes it; with 13 or 3 of the 24 teeth
    engaged the engaged set pushes the centres sideways, dof 3's tooth loads are off by far
    more than fidelity_tol within a quarter revolution, and auto keeps dof 7."""
    assert abs(Z24_NO_FIRST @ np.exp(1j * Z24_THETA)) < 1e-13
    base = pyspline.load_case(CONFTEST_CASES / "physical_z24.nml", l_x=0.0, grav=0.0,
                              start="equilibrium",
                              spacing_error=list(amp * Z24_NO_FIRST / np.abs(Z24_NO_FIRST).max()))
    base = base.replace(t_end=15 / base["speed_rpm"], n_out=101)      # a quarter revolution
    runs = {dof: pyspline.simulate(base.replace(dof=dof)) for dof in (3, 7)}
    auto = pyspline.simulate(base.replace(fidelity="auto"))
    f0 = base["t_d"] / (24 * base.model.info()["r_b"])
    error = np.abs(runs[3].F - runs[7].F).max() / f0
    engaged = int((runs[7].F[0] != 0).sum())
    if engaged == 24:
        assert auto.stats["dof"] == 3 and error < 1e-6
    else:
        assert engaged <= 13 and auto.stats["dof"] == 7 and error > 0.1
        np.testing.assert_array_equal(auto.F, runs[7].F)


def seeded_errors(**fields):
    """e_j of a case as the core built them: dn_j at the rest state of an aligned case."""
    case = pyspline.load_case(dict(PAPER, name="seeded", **fields))
    return pyspline.rhs(case, 0.0, np.zeros(14))[1]["dn"]


@pytest.mark.parametrize("z,seed", [(16, 1), (7, 123456789), (1000, 2147483646)])
def test_seeded_errors_are_reproducible_with_mean_zero(z, seed):
    """spacing_error_amp, spacing_error_seed: MINSTD as docs/model.md states it (tests/oracle.py
    from the document), mean 0, largest |e_j| the amplitude; the same seed the same numbers."""
    amp = 3e-5
    e = seeded_errors(z=z, spacing_error_amp=amp, spacing_error_seed=seed)
    np.testing.assert_array_equal(e, seeded_errors(z=z, spacing_error_amp=amp,
                                                   spacing_error_seed=seed))
    np.testing.assert_allclose(e, oracle.random_spacing_errors(z, amp, seed), rtol=0,
                               atol=4e-16 * amp)
    assert abs(e.mean()) < 1e-15 * amp
    np.testing.assert_allclose(np.abs(e).max(), amp, rtol=1e-15)
    assert np.unique(e).size == z                      # no repeats, no constant run
    other = seeded_errors(z=z, spacing_error_amp=amp, spacing_error_seed=seed % 1000 + 1)
    assert not np.allclose(e, other)
    if z == 1000:                                      # uniform: about half the teeth past amp/2
        assert 0.3 < (np.abs(e) > 0.5 * amp).mean() < 0.7


def test_the_errors_in_use_read_back_from_info_result_dataset_and_summary(exe, tmp_path):
    """The spacing errors a run uses, the given list plus the seeded ones (docs/model.md section
    11, tests/oracle.py from the document), read back from Model.info(), the Result, its
    Dataset and spline-dyn's summary, exactly (17 digits in the summary)."""
    given = [1e-6, -2e-6, 0.5e-6]
    case = pyspline.load_case(dict(PAPER, name="inuse", spacing_error=given,
                                   spacing_error_amp=3e-6, spacing_error_seed=42, t_end=0.002,
                                   n_out=5))
    expected = oracle.random_spacing_errors(16, 3e-6, 42)
    expected[:3] += given
    e = case.model.info()["spacing_error"]
    np.testing.assert_allclose(e, expected, rtol=0, atol=1e-21)
    res = pyspline.simulate(case)
    np.testing.assert_array_equal(res.spacing_error, e)
    ds = res.to_xarray()
    np.testing.assert_array_equal(ds["spacing_error"].values, e)
    assert ds["spacing_error"].dims == ("tooth",) and ds["spacing_error"].attrs["units"] == "m"
    path = tmp_path / "inuse.nml"
    case.to_namelist(path)
    subprocess.run([exe, str(path), "--summary", str(tmp_path / "inuse.summary")], check=True,
                   capture_output=True, timeout=120)
    from pyspline.batch import read_summary
    summary = read_summary(tmp_path / "inuse.summary")
    np.testing.assert_array_equal(summary["values"]["model.spacing_error"], e)
    assert summary["units"]["model.spacing_error"] == "m"
    # without errors: zeros, one per tooth
    np.testing.assert_array_equal(pyspline.load_case(dict(PAPER, name="none")).model.info()[
        "spacing_error"], np.zeros(16))
