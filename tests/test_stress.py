"""Nominal tooth stresses of a run (spline_loads::tooth_stresses, docs/model.md section 15,
"Tooth stresses") against the stated formulas computed here from the case's fields and the
ISO 4156 geometry; their scaling with the load and the face width; their warnings
(spline_loads::stress_warnings): none for the shipped physical cases, all three for a torque
typed in N mm, the same words from the executable."""
from __future__ import annotations

import math
import re
import subprocess
import warnings

import numpy as np
import pytest

import pyspline as ps
from conftest import CASES, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

#: The limits docs/model.md section 15 states [MPa].
LIMITS = {"sigma_root": 400.0, "sigma_flank": 310.0, "tau_pitch": 345.0}
WORDS = {"sigma_root": "root bending stress", "sigma_flank": "flank bearing stress",
         "tau_pitch": "shear stress at the pitch circle"}


def stated(case, f) -> dict:
    """The stresses of docs/model.md section 15 for a tooth load f [N] along the line of
    action: f_t = f cos(alpha) at the pitch circle R = m Z / 2, root circle m (Z - 1.5) / 2,
    straight flanks at alpha, working depth from m (Z - 1) / 2 to m (Z + 1) / 2."""
    g = case.get
    m, z, b, s, alpha = g("module_m"), g("z"), g("b"), g("s"), math.radians(g("alpha_deg"))
    ft = abs(f) * math.cos(alpha)
    h_f = m * z / 2 - m * (z - 1.5) / 2
    t_f = s + 2 * h_f * math.tan(alpha)
    h_w = m * (z + 1) / 2 - m * (z - 1) / 2
    return {"sigma_root": 6 * ft * h_f / (b * t_f ** 2), "sigma_flank": ft / (b * h_w),
            "tau_pitch": ft / (b * s)}


def full_contact(**kw):
    """The template drive without gravity and mesh damping over one revolution from its
    equilibrium: every tooth carries F_s = T_d / (Z r_b) throughout (tests/test_loads.py)."""
    kw = {"t_end": 0.01, "n_out": 241, **kw}
    return ps.load_case(CASES / "template.nml", name="full", grav=0.0, c_m=0.0, **kw)


def stress_messages(fields, key="MPa at the peak load") -> tuple[list[str], ps.Result]:
    """The run's SplineWarnings that contain key (the stresses', or another kind's), and it."""
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        res = ps.simulate(fields)
    return [str(w.message) for w in rec if issubclass(w.category, ps.SplineWarning)
            and key in str(w.message)], res


@pytest.mark.parametrize("kw", [{}, {"z": 24, "module_m": 1.25e-3, "s": 1.7e-3, "b": 0.012,
                                     "alpha_deg": 37.5}])
def test_stresses_of_full_contact_follow_the_stated_formulas(kw):
    """In static full contact the most loaded tooth carries F_s exactly; the stresses are the
    stated formulas at that load (and at the run's own F_peak, to round-off)."""
    case = full_contact(**kw)
    ld = ps.simulate(case).loads
    fs = case["t_d"] / (case["z"] * case.model.info()["r_b"])
    at_peak, at_fs = stated(case, ld["F_peak"].max()), stated(case, fs)
    for n in LIMITS:
        assert ld[n] == pytest.approx(at_peak[n], rel=1e-13), n
        assert ld[n] == pytest.approx(at_fs[n], rel=1e-8), n
    if not kw:          # the paper's spline: t_f = (pi/2 + 1.5 tan 30) m, sigma_b = 0.76 F_t/(b m)
        ft = fs * math.cos(math.radians(30))
        assert ld["sigma_root"] * case["b"] * case["module_m"] / ft == pytest.approx(
            4.5 / (math.pi / 2 + 1.5 * math.tan(math.radians(30))) ** 2, rel=1e-3)


def test_stresses_scale_with_the_load_and_inversely_with_the_face_width():
    base = ps.simulate(full_contact()).loads
    twice = ps.simulate(full_contact(t_d=61.4, t_l=61.4)).loads
    wide = ps.simulate(full_contact(b=0.06)).loads
    for n in LIMITS:
        assert twice[n] == pytest.approx(2 * base[n], rel=1e-8), n
        assert wide[n] == pytest.approx(base[n] / 2, rel=1e-8), n


PHYSICAL = sorted(CASES.glob("physical_*.nml"))


@pytest.mark.parametrize("path", PHYSICAL, ids=lambda p: p.stem)
def test_shipped_physical_cases_warn_no_stress_but_the_torque_in_n_mm_does(path):
    msgs, res = stress_messages(path)
    assert msgs == []
    for n, limit in LIMITS.items():
        assert 0 < res.loads[n] < limit * 1e6, n
    case = ps.load_case(path)
    msgs, res = stress_messages(case.replace(t_d=1000 * case["t_d"], t_l=1000 * case["t_l"]))
    assert len(msgs) == 3, msgs
    for n, msg in zip(LIMITS, msgs):
        assert WORDS[n] in msg and f"exceeds {LIMITS[n]:.0f} MPa" in msg, msg
        assert msg.endswith("the static load alone is beyond it (a torque in N mm?). Run as "
                            "given"), msg
        assert res.loads[n] > LIMITS[n] * 1e6
        got = float(re.search(r"= ([0-9.]+) MPa", msg).group(1))
        assert got == pytest.approx(res.loads[n] * 1e-6, abs=0.051), msg
        tooth = int(re.search(r"tooth (\d+)", msg).group(1))
        assert res.loads["F_peak"][tooth - 1] == res.loads["F_peak"].max()


def exe_warnings(exe, case, tmp_path, key="MPa at the peak load"):
    """spline-dyn's warning lines that contain key, without their prefix, and the run."""
    path = tmp_path / "case.nml"
    case.to_namelist(path)
    run = subprocess.run([exe, str(path), "-o", str(tmp_path / "out.csv")], capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    prefix = "spline-dyn: warning: "
    return [ln[len(prefix):] for ln in run.stderr.splitlines()
            if ln.startswith(prefix) and key in ln], run


def test_executable_prints_the_same_stress_warnings(exe, tmp_path):
    case = ps.load_case(CASES / "physical_lx1e-4.nml", t_d=30700.0, t_l=30700.0, t_end=0.02)
    py, res = stress_messages(case)
    lines, run = exe_warnings(exe, case, tmp_path)
    assert len(py) == 3 and lines == py
    shown = re.search(r"shear at pitch \[MPa\]:\s+(\S+)\s+(\S+)\s+(\S+)", run.stdout).groups()
    np.testing.assert_allclose([float(v) for v in shown],
                               [res.loads[n] * 1e-6 for n in LIMITS], atol=0.006)


FLASH = "contact temperature T_M + T_f"


def test_flash_temperature_beyond_scuffing_and_tempering_warns(exe, tmp_path):
    """The contact temperature of Blok's criterion, T_B = T_M + max T_f (Eq. 1), beyond 400 degC
    (the top of typical scuffing temperatures) warns of scuffing, beyond 650 degC (steel's
    tempering range) more strongly; the calibrated paper_T100 is silent. One-way, T_f is
    proportional to f_m (Eq. 3, the loads do not see it), so f_m is chosen here to put T_B at
    500 and 2000 degC from the calibrated run; the executable prints the same lines."""
    case = ps.load_case(CASES / "paper_T100.nml", thermal="oneway", t_end=0.02, n_out=161)
    msgs, res = stress_messages(case, FLASH)
    tf0, f_m0, t_m = res.loads["Tf_max"], case["f_m"], case["t_bulk"]
    assert msgs == [] and 0 < t_m + tf0 < 400
    for target, words in ((500.0, "exceeds 400 degC, the top of typical scuffing temperatures"),
                          (2000.0, "exceeds 650 degC, past steel's tempering range")):
        fields = case.replace(f_m=f_m0 * (target - t_m) / tf0)
        msgs, res = stress_messages(fields, FLASH)
        assert len(msgs) == 1 and words in msgs[0], msgs
        assert res.loads["Tf_max"] == pytest.approx(target - t_m, rel=1e-9)
        assert f"T_M + T_f = {t_m:.1f} + {target - t_m:.1f} degC" in msgs[0], msgs
        assert f"tooth {int(res.loads['Tf_max_tooth'])} at t" in msgs[0]
    assert exe_warnings(exe, fields, tmp_path, FLASH)[0] == msgs
    msgs, _ = stress_messages(fields.replace(t_bulk=0.0), FLASH)      # no bulk rise: '0.0 + '
    assert len(msgs) == 1 and "T_M + T_f = 0.0 + " in msgs[0], msgs
