"""Plausibility warnings of the core (spline_model::model_warnings, docs/model.md section 12,
"Plausibility warnings"): each fires on the issue's real spline, names the field and the number
that raised it (checked against a closed form computed here), and is silent once the input is
made plausible; the shipped cases raise exactly the kinds their fields call for; the
executable prints the same lines as Python's SplineWarning."""
from __future__ import annotations

import math
import subprocess
import warnings

import numpy as np
import pytest

import oracle
import pyspline as ps
from conftest import CASES

#: The issue's spline: Z 26, module 1.5875 mm, 30 deg, face 25 mm, 12 000 r/min, 150 N m,
#: c0 60 um, l_x 80 um, from rest, with the paper's defaults for the rest (k_p, k_t).
EXAMPLE = dict(name="real_spline", z=26, module_m=1.5875e-3, alpha_deg=30.0, b=0.025,
               speed_rpm=12000.0, t_d=150.0, t_l=150.0, c0=60e-6, l_x=80e-6, start="rest",
               t_end=1e-3, n_out=3)
#: The same made plausible: stiff supports and shafts, the offset within the backlash
#: (start from rest then overlaps nothing), the torque in N m.
PLAUSIBLE = dict(EXAMPLE, k_p1=1e12, k_p2=1e12, k_t1=1e5, k_t2=1e5, l_x=50e-6)

KINDS = {"supports": "fields k_p1 =", "windup": "winds its shaft", "start": "start = 'rest'",
         "load": "loads each tooth", "k_m": "potential-energy mesh stiffness",
         "separation": "below the default separation"}


def messages(fields) -> list[str]:
    """The SplineWarning messages of loading a case (dict or file)."""
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        ps.load(ps.load_case(fields))
    return [str(w.message) for w in rec if issubclass(w.category, ps.SplineWarning)]


def kinds(msgs) -> set[str]:
    return {k for m in msgs for k, key in KINDS.items() if key in m}


def one(msgs, kind) -> str:
    found = [m for m in msgs if KINDS[kind] in m]
    assert len(found) == 1, (kind, msgs)                  # one line per kind
    return found[0]


def closed_forms(case) -> dict:
    """The numbers each warning tests, from the case's fields by the formulas of docs/model.md
    (independent of the core's code): the offset the supports leave at the mesh over the static
    tooth deflection (seen; inf where the warning does not apply), the shafts' wind-up,
    the largest tooth overlap at a start from rest (Eq. 11 with the spacing errors e_j), the
    static tooth deflection / module."""
    g = case.get
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ps.SplineWarning)
        stiff = ps.mesh_stiffness(case)
        info = ps.load(case).info()
    c, e_j = info["c_bulk"], info["spacing_error"]
    z, alpha = g("z"), math.radians(g("alpha_deg"))
    r_b = g("module_m") * z / 2 * math.cos(alpha)
    k_mesh = z * stiff["k_m_used"] / 2
    k_s = 1 / (1 / g("k_p1") + 1 / g("k_p2")) if min(g("k_p1"), g("k_p2")) > 0 else 0.0
    l = math.hypot(g("l_x"), g("l_y"))
    # the offset the supports leave at the mesh, against the static tooth deflection
    e = l * k_s / (k_mesh + k_s)
    delta = abs(g("t_d")) / (z * r_b * stiff["k_m_used"])
    seen = e / delta if (g("dof") == 7 and k_s > 0 and delta > 0 and l > delta) else math.inf
    windup = max(abs(g("t_d")) / g("k_t1") if g("k_t1") > 0 else 0.0,
                 abs(g("t_l")) / g("k_t2") if g("k_t2") > 0 else 0.0)
    overlap = -1.0
    if g("start") == "rest":
        dq = g("dq0")
        ex, ey = dq[0] + g("l_x") - dq[2], dq[1] + g("l_y") - dq[3]
        omega = g("speed_rpm") * 2 * math.pi / 60
        phi = [2 * math.pi * j / z + omega * g("t0") + math.pi / (2 * z) - alpha
               for j in range(1, z + 1)]
        dn = [abs(ex * math.sin(p) - ey * math.cos(p) + dq[5] + ej) for p, ej in zip(phi, e_j)]
        j = max(range(z), key=lambda i: dn[i])
        overlap = dn[j] - c
    force = max(abs(g("t_d")), abs(g("t_l"))) / (z * r_b)
    deflection = force / stiff["k_m"] if stiff["k_m"] > 0 else 0.0
    return dict(seen=seen, e=e, delta=delta, l=l, k_s=k_s, windup=windup, overlap=overlap, c=c, force=force,
                deflection=deflection, rel=deflection / g("module_m"))


def expected_kinds(case) -> set[str]:
    f = closed_forms(case)
    return {k for k, on in (("supports", f["seen"] <= 0.1), ("windup", f["windup"] > 0.2),
                            ("start", f["overlap"] > 0), ("load", f["rel"] > 0.05)) if on}


def test_supports_taking_the_offset():
    case = ps.load_case(EXAMPLE)
    f = closed_forms(case)
    msg = one(messages(EXAMPLE), "supports")
    assert f["seen"] < 0.1                                 # 5e6 N/m against Z k_m / 2 ~ 8e9
    for number in ("k_p1 = 5.000E+06", "k_p2 = 5.000E+06", f"{f['k_s']:.3E} N/m",
                   f"e = {f['e']:.3E} m", f"|l| = {f['l']:.3E} m", f"{100 * f['seen']:.4f} %",
                   f"= {f['delta']:.3E} m", "(limit 10 %)", f"factor to 1 + e / delta = {1 + f['seen']:.4f}"):
        assert number in msg, (number, msg)
    assert "supports" not in kinds(messages(dict(EXAMPLE, k_p1=1e12, k_p2=1e12)))
    assert "supports" not in kinds(messages(dict(EXAMPLE, l_x=0.4e-6)))  # below the deflection
    assert "supports" not in kinds(messages(dict(EXAMPLE, dof=3)))       # lateral frozen
    assert "supports" not in kinds(messages(dict(EXAMPLE, t_d=0.0)))     # no static deflection
    # within the backlash too: under torque the mesh resists the offset from zero
    assert "supports" in kinds(messages(dict(EXAMPLE, l_x=50e-6)))
    # its load-sharing factor is the misalignment's: with spacing errors it says so (a Z20 case
    # with them ran at 11.7 under a warning that said 1.0446)
    assert "alone" not in msg
    spaced = one(messages(dict(EXAMPLE, spacing_error=[0.0, -10e-6])), "supports")
    assert spaced.endswith(f"= {1 + f['seen']:.4f} from the misalignment alone (the spacing "
                           "errors add their own). Run as given"), spaced


#: The issue's aero spline from its equilibrium (the start warning aside), stiff shafts: on the
#: paper's 5e6 N/m supports and on 2e8 N/m, the issue's, where the run's load-sharing factor is
#: 4.6 with 17 of 26 teeth free.
AERO = dict(EXAMPLE, name="aero", start="equilibrium", k_t1=1e5, k_t2=1e5, t_end=0.02,
            n_out=801)


@pytest.mark.parametrize("k_p", [5e6, 2e8])
def test_support_warning_agrees_with_the_runs_load_sharing(k_p):
    """The support warning says the teeth barely see the misalignment exactly when the run's
    load-sharing factor is near 1: on soft supports it fires, and the run's factor is its
    1 + e / delta (full contact: e below delta, tooth loads F0 (1 + (e / delta) sin)); on the
    issue's 2e8 N/m it is silent, and the run's factor is far above 1 with teeth free."""
    fields = dict(AERO, k_p1=k_p, k_p2=k_p)
    f = closed_forms(ps.load_case(fields))
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        loads = ps.simulate(fields).loads
    got = kinds([str(w.message) for w in rec if issubclass(w.category, ps.SplineWarning)])
    if k_p == 5e6:
        assert "supports" in got and f["seen"] < 0.1
        assert loads["load_sharing"] == pytest.approx(1 + f["seen"], rel=1e-3)
        assert loads["teeth_free_mean"] == 0
    else:
        assert "supports" not in got and f["seen"] > 1
        assert loads["load_sharing"] > 4 and loads["teeth_free_mean"] > 15


def test_shaft_windup():
    msg = one(messages(EXAMPLE), "windup")
    for number in ("k_t1 = 7.8550", f"{150 / 7.855:.3f} rad under t_d = 150.00 N m",
                   "k_t2 = 7.8560", f"{150 / 7.856:.3f} rad under t_l", "(limit 0.20 rad"):
        assert number in msg, (number, msg)
    assert "k_t2" not in one(messages(dict(EXAMPLE, k_t2=1e5)), "windup")
    assert "windup" not in kinds(messages(dict(EXAMPLE, k_t1=1e5, k_t2=1e5)))
    assert "windup" not in kinds(messages(dict(EXAMPLE, k_t1=0.0, k_t2=0.0)))   # free shafts
    # the limit: 0.2 rad
    assert "windup" in kinds(messages(dict(EXAMPLE, k_t1=149.0, k_t2=1e5, t_d=30.0)))
    assert "windup" not in kinds(messages(dict(EXAMPLE, k_t1=151.0, k_t2=1e5, t_d=30.0)))


def test_start_with_teeth_overlapping():
    case = ps.load_case(EXAMPLE)
    f = closed_forms(case)
    msg = one(messages(EXAMPLE), "start")
    assert f["overlap"] > 0
    for number in ("l_x = 8.000E-05", f"backlash c = {f['c']:.3E} m", f"by {f['overlap']:.3E} m"):
        assert number in msg, (number, msg)
    assert "start" not in kinds(messages(dict(EXAMPLE, start="equilibrium")))
    assert "start" not in kinds(messages(dict(EXAMPLE, l_x=50e-6)))
    # a start kick dq0 that cancels the offset (x1 = -l_x) starts the teeth clear
    assert "start" not in kinds(messages(dict(EXAMPLE, dq0=[-80e-6, 0, 0, 0, 0, 0, 0])))


def test_start_overlap_made_by_a_spacing_error():
    """Eq. 11 with the tooth's spacing error e_j: the plausible spline (l_x 50 um, every |dn_j|
    at t0 within c = 60 um; teeth 8 and 21 nearest, +-49.75 um) with e_21 = -15 um overlaps
    tooth 21 by about 4.75 um, the tooth and overlap of the oracle's dn_j at the core's start
    state; e_21 = +15 um moves that tooth away from its flank: no overlap."""
    fields = dict(PLAUSIBLE, spacing_error=[0.0] * 20 + [-15e-6])
    assert messages(PLAUSIBLE) == []
    case = ps.load_case(fields)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ps.SplineWarning)
        model = ps.load(case)
    dn = np.abs(oracle.mesh(case["t0"], model.start_state(), case)["dn"])
    j, c = int(np.argmax(dn)), model.info()["c_bulk"]
    assert j + 1 == 21 and dn[j] - c == pytest.approx(4.75e-6, rel=0.01)
    assert closed_forms(case)["overlap"] == pytest.approx(dn[j] - c, rel=1e-9)
    msg = one(messages(fields), "start")
    for number in ("starts tooth 21 overlapping", f"backlash c = {c:.3E} m", f"by {dn[j] - c:.3E} m"):
        assert number in msg, (number, msg)
    assert messages(dict(PLAUSIBLE, spacing_error=[0.0] * 20 + [15e-6])) == []


def _start_dn(fields) -> tuple:
    """|dn_j| of the oracle's Eq. 11 at the core's start state of a case, and its backlash."""
    case = ps.load_case(fields)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ps.SplineWarning)
        model = ps.load(case)
    return np.abs(oracle.mesh(case["t0"], model.start_state(), case)["dn"]), model.info()["c_bulk"]


def test_start_overlap_names_dq0_when_it_moves_the_tooth():
    """An overlap made by the initial displacement dq0 names dq0 (its entries that enter Eq. 11)
    and what it adds to the tooth's |dn_j|, not the misalignment: aligned, x2 = 90 um and
    D2 = 2 um overlap tooth 21; on the plausible l_x = 50 um (clear by itself), x1 = 30 um
    overlaps tooth 8, and both are named. The oracle's dn_j with and without dq0 give the
    numbers; a dq0 in D1 only (no term of Eq. 11) leaves the misalignment's words."""
    for fields, tooth, names in ((dict(PLAUSIBLE, l_x=0.0, dq0=[0, 0, 90e-6, 0, 0, 2e-6, 0]), 21,
                                  "with dq0 (x2 = 9.000E-05, D2 = 2.000E-06 m, adding"),
                                 (dict(PLAUSIBLE, dq0=[30e-6, 0, 0, 0, 0, 0, 0]), 8,
                                  "with l_x = 5.000E-05, l_y = 0.000E+00 m and dq0 (x1 = "
                                  "3.000E-05 m, adding")):
        dn, c = _start_dn(fields)
        dn0, _ = _start_dn(dict(fields, dq0=[0.0] * 7))
        j = int(np.argmax(dn))
        assert j + 1 == tooth and dn0[j] <= c < dn[j]                 # dq0 made the overlap
        msg = one(messages(fields), "start")
        for words in (names, f"adding {dn[j] - dn0[j]:.3E} m to its |dn_j|) starts tooth {tooth} ",
                      f"by {dn[j] - c:.3E} m"):
            assert words in msg, (words, msg)
        assert ("l_x" in msg) == (fields["l_x"] != 0), msg
    msg = one(messages(dict(EXAMPLE, dq0=[0, 0, 0, 0, 1e-3, 0, 0])), "start")
    assert "dq0" not in msg and "with l_x = 8.000E-05, l_y = 0.000E+00 m starts tooth 8" in msg


def test_tooth_load_of_a_torque_in_n_mm():
    fields = dict(EXAMPLE, t_d=150e3, t_l=150e3)
    f = closed_forms(ps.load_case(fields))
    msg = one(messages(fields), "load")
    assert f["force"] == pytest.approx(3.22e5, rel=0.01) and f["rel"] > 0.3
    for number in ("t_d = 1.500E+05 N m", f"{f['force']:.3E} N", f"{f['deflection']:.3E} m",
                   f"{100 * f['rel']:.3f} % of the module", "(limit 5 %)"):
        assert number in msg, (number, msg)
    assert "load" not in kinds(messages(EXAMPLE))          # 150 N m: 0.5 um, 0.03 %


def test_benettin_separation_below_the_default_where_switches_are_not_located():
    """A given lyapunov_d0 below the default 1e4 rtol (within [1e-8, 1e-3]) warns with the copy
    that does not locate its own switches (roots off, with any method); with roots (CVODE or
    ERK), the tangent, or the default d0 it does not. tests/test_chaos.py shows what it reads
    there."""
    fields = dict(PLAUSIBLE, lyapunov=True, lyapunov_d0=1e-8, rtol=1e-8, atol=1e-10)
    default = min(1e-3, max(1e-8, 1e4 * fields["rtol"]))
    for method in ("adams", "erk"):
        msg = one(messages(dict(fields, roots=False, method=method)), "separation")
        for number in ("lyapunov_d0 = 1.000E-08", f"default separation {default:.3E}",
                       "roots = .false."):
            assert number in msg, (number, msg)
    for quiet in (dict(roots=True, method="adams"), dict(roots=True, method="erk"),
                  dict(roots=False, lyapunov_method="tangent"),
                  dict(roots=False, lyapunov_d0=0.0), dict(roots=False, lyapunov_d0=default),
                  dict(roots=False, lyapunov=False)):
        assert messages(dict(fields, **quiet)) == [], quiet


def test_plausible_input_warns_nothing():
    assert messages(PLAUSIBLE) == []


#: What the constructed demonstration scenes raise, and why (their header comments say so):
#: rattle_z24 keeps the paper's shafts (k_T 7.855 N m/rad) and supports; chaos_z24 also
#: (k_p 5e6 N/m) and starts from rest with its offset twice the backlash (under its light 2 N m the
#: supports leave the mesh far more than a tooth deflection: no support warning). Their physics is the
#: measured one of the chaos and benchmark scenes (tests/test_chaos.py, bench/), kept as it is.
DEMONSTRATION = {"rattle_z24": {"windup", "supports"}, "chaos_z24": {"windup", "start"}}


@pytest.mark.parametrize("path", sorted(CASES.glob("*.nml")), ids=lambda p: p.stem)
def test_shipped_cases_raise_what_their_fields_call_for(path):
    """Each shipped case raises exactly the kinds the closed forms predict, one line each. The
    physical cases (steel shafts, k_T = G J / L) raise none; the demonstration scenes what
    DEMONSTRATION says; the paper's k_T = 7.855 N m/rad winds every shaft that keeps it (the
    paper cases, the template) beyond 0.2 rad, and nothing else."""
    case = ps.load_case(path)
    msgs = messages(path)
    got = kinds(msgs)
    assert got - {"k_m"} == expected_kinds(case), msgs
    for kind in got:
        one(msgs, kind)
    if path.stem == "physical_z24":       # the paper's 5e6 N/m supports hold its 50 um offset
        assert got == {"supports"}, msgs
    elif path.stem.startswith("physical_"):
        assert msgs == []
    elif path.stem in DEMONSTRATION:
        assert got == DEMONSTRATION[path.stem], msgs
    else:                                                   # the paper's cases, the template
        assert got - {"k_m"} == {"windup"}, msgs


def test_executable_prints_the_same_lines(exe, tmp_path):
    fields = dict(EXAMPLE, t_d=150e3, t_l=150e3)
    py = messages(fields)
    assert kinds(py) == {"windup", "start", "load"}   # 150 kN m: the offset within a deflection
    path = tmp_path / "real_spline.nml"
    ps.load_case(fields).to_namelist(path)
    run = subprocess.run([exe, str(path), "-o", str(tmp_path / "out.csv")], capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    prefix = "spline-dyn: warning: "
    lines = [ln[len(prefix):] for ln in run.stderr.splitlines() if ln.startswith(prefix)]
    with warnings.catch_warnings(record=True) as rec:      # and the run's: the stresses' too
        warnings.simplefilter("always")
        ps.simulate(fields)
    assert lines == [str(w.message) for w in rec if issubclass(w.category, ps.SplineWarning)]
    assert lines[:len(py)] == py


def test_reproduce_reports_a_kind_once_for_all_its_cases():
    """pyspline reproduce runs many cases with the paper's shafts: each kind is one line naming
    its cases (pyspline.paper.warn_once), not one line per case."""
    from pyspline.paper import warn_once
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for name in ("a", "b", "a"):
            ps.load(ps.load_case(dict(name=name)))               # the defaults: the paper's k_T
        ps.load(ps.load_case(dict(name="c", t_d=60.0)))           # another wind-up
    with warnings.catch_warnings(record=True) as again:
        warnings.simplefilter("always")
        warn_once(caught)
    msgs = [str(w.message) for w in again]
    assert len(msgs) == 2 and msgs[0].startswith("case a, b: field k_t1 = 7.8550")
    assert msgs[1].startswith("case c: field k_t1") and kinds(msgs) == {"windup"}
