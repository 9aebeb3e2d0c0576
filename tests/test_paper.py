"""The main job: reproduce (quick), Poincare point counting, calibration."""
import json
import re
import warnings

import numpy as np
import pytest

import pyspline
from pyspline import paper
from conftest import CASES, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)


def strobe(x, v):
    return np.c_[x, v]


def test_poincare_period_1_3_and_quasiperiodic():
    n = np.arange(300)
    # period-1: a fixed point (with round-off noise)
    p1 = strobe(1.0 + 1e-12 * np.sin(n), 0.5 + 1e-12 * np.cos(n))
    assert paper.count_distinct(p1, scale=[1.0, 1.0]) == 1
    # period-3: x_n = cos(2 pi n / 3)
    p3 = strobe(np.cos(2 * np.pi * n / 3), np.sin(2 * np.pi * n / 3))
    assert paper.count_distinct(p3) == 3
    # quasi-periodic: irrational rotation on a circle fills it
    w = 2 * np.pi * (np.sqrt(5) - 1) / 2
    pq = strobe(np.cos(w * n), np.sin(w * n))
    assert paper.count_distinct(pq) > 250


def test_poincare_of_a_simulated_periodic_orbit():
    """Sampled once per revolution, a response at the shaft frequency is a single point."""
    class R:  # a minimal Result stand-in
        pass
    r = R()
    r.case = {"speed_rpm": 6000.0}
    r.t = np.linspace(0, 1, 64001)
    w = 2 * np.pi * 100
    r.D2 = -8e-4 + 1e-5 * np.sin(w * r.t)
    r.vD2 = 1e-5 * w * np.cos(w * r.t)
    assert paper.poincare_count(r) == 1
    r.D2 = -8e-4 + 1e-5 * np.sin(w * r.t / 3)       # subharmonic: period-3
    r.vD2 = 1e-5 * w / 3 * np.cos(w * r.t / 3)
    assert paper.poincare_count(r) == 3


def test_reproduce_quick_writes_every_figure_and_row(tmp_path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", pyspline.SplineWarning)
        s = paper.reproduce(tmp_path, quick=True, directory=CASES, progress=False)
    # the section runs' two outputs are not read: their peak loads are not warned about
    assert not [w for w in caught if "tooth-passing" in str(w.message)]
    for name in ("fig4_ideal", "fig5_6_misalignment", "fig7_8_bulk_temperature",
                 "fig9_10_flash_temperature", "physical_lx1e-4"):
        png = tmp_path / f"{name}.png"
        assert png.stat().st_size > 20_000, name
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    md = (tmp_path / "verification.md").read_text()
    assert "QUICK RUN" in md
    csv = (tmp_path / "verification.csv").read_text().splitlines()
    assert len(csv) == 1 + len(paper.ROWS)                   # no row hidden
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert len(summary["rows"]) == len(paper.ROWS)
    assert all(v == "identical" for v in summary["executable_check"].values())
    assert summary["k_m"]["ratio"] > 1000
    for row in summary["rows"]:
        assert np.isfinite(row["ours"])
        assert row["status"] == "ok" or row["why"], row     # every miss says why


def test_a_miss_quotes_its_runs_static_share():
    """The paper_ideal force row's reason quotes the run's static share T_d/(Z r_b) (the loads'
    F_static), so it follows the case: twice the paper's T_d, twice the number."""
    key = "paper_ideal/tooth force F_j at the largest load (mean over teeth)"
    assert set(paper.WHY) <= {f"{r.case}/{r.quantity}" for r in paper.ROWS}   # every reason has its row
    base = pyspline.load_case(CASES / "paper_ideal.nml").replace(t_end=0.005, n_out=33)
    said = [paper.why(key, pyspline.simulate(c)) for c in (base, base.replace(t_d=2 * base["t_d"]))]
    share = base["t_d"] / (base["z"] * base.model.info()["r_b"])
    assert f"{share:.4g}" == "138.5"                                     # the paper's drive
    assert [s.split(";")[0] for s in said] == [f"the static share T_d/(Z r_b) is {f:.4g} N"
                                               for f in (share, 2 * share)]


def test_the_misses_quote_their_runs_numbers():
    """What the misses mean quotes the runs' own k_v swing and peak tooth forces beside the
    paper's (ROWS), and each start-up row's reason its run's largest k_v after the engagement:
    twice the paper's T_d changes the runs (twice T_d and T_l would not: k_v is relative to the
    static share) and so the words."""
    names = {r.case for r in paper.ROWS}
    said = []
    for factor in (1, 2):
        cases = {n: paper.load_paper_case(n, CASES, quick=True) for n in names}
        res = {n: pyspline.simulate(c.replace(t_d=factor * c["t_d"]))
               for n, c in cases.items()}
        by = {f"{r['case']}/{r['quantity']}": r for r in paper.verification_rows(res)}
        text = paper.meaning(by.values(), res)
        kv_max, kv_min = (by[k]["ours"] for k in (paper.KV_MAX, paper.KV_MIN))
        forces = [abs(by[k]["ours"]) for k in paper.PEAK_FORCES]
        words = " ".join(text.split())
        assert (f"overshoots to k_v = {kv_max:.3g} (paper 1.225); its low side reaches "
                f"k_v = {kv_min:.3g} (paper 0.69)") in words
        assert f"its 170-183 N (ours {min(forces):.0f}-{max(forces):.0f} N) peak forces" in words
        run = res["paper_lx1e-4"]
        reason = paper.why("paper_lx1e-4/meshing torque |T_m| min (t > 0.1 s)", run)
        assert f"overshoots to k_v = {run.kv[run.t > 0.1].max():.3g} (the paper's" in reason
        said.append((text, reason))
    assert said[0][0] != said[1][0] and said[0][1] != said[1][1]


def test_the_calibrated_values_are_the_cores():
    """The calibrated values' words (paper.calibrated_values) quote the case files' k_m and f_m
    and what the core computes: the k_m a run uses with k_m = 0 (Eq. 18 without and with the
    fillet foundation) and the ratio of two runs' largest flash temperatures at the case's f_m
    and at the default f_m (one-way level: proportional). docs/verification.md says the same."""
    km, fm = (pyspline.load_case(CASES / f"{r.case}.nml") for r in (paper.CAL_KM, paper.CAL_FM))
    text = paper.calibrated_values(km, fm)
    said = re.fullmatch(
        r"k_m = (\S+) N/m is (\d+) times softer than the potential-energy value of the same "
        r"tooth pair by Eq. 18 \((\S+) N/m\), consistent with N/mm read as N/m, and still (\d+) "
        r"times softer than Eq. 18 with the fillet foundation \((\S+) N/m, docs/stiffness.md\); "
        r"f_m = (\S+) is no friction coefficient: the paper's largest flash temperature is "
        r"(\d+) times what Eqs. 3-7 give with f_m = (\S+) \(T_f is proportional to f_m\).",
        text)
    assert said, text
    k, ratio_bare, bare, ratio_fillet, fillet, f_m, ratio_flash, f0 = map(float, said.groups())
    used = [km.replace(k_m=0.0, fillet=f).model.info()["k_m"] for f in (False, True)]
    assert (k, bare, fillet) == pytest.approx((km["k_m"], *used), rel=5e-4)
    assert ratio_bare == pytest.approx(used[0] / km["k_m"], abs=0.5)
    assert ratio_fillet == pytest.approx(used[1] / km["k_m"], abs=0.5)
    short = fm.replace(t_end=0.02, n_out=41)
    t_f = [pyspline.simulate(short.replace(f_m=f)).Tf.max() for f in (fm["f_m"], f0)]
    assert f_m == pytest.approx(fm["f_m"], rel=5e-3) and t_f[1] > 0
    assert ratio_flash == pytest.approx(t_f[0] / t_f[1], abs=0.5)
    doc = " ".join((CASES.parent / "docs" / "verification.md").read_text().split())
    assert f"**Calibrated values.** {text}" in doc
    # docs/model.md explains the same deviations in words with the same numbers
    model = " ".join((CASES.parent / "docs" / "model.md").read_text().split())
    about = re.search(r"k_m is about ([\d ]+) times softer", model).group(1)
    assert float(about.replace(" ", "")) == pytest.approx(ratio_bare, rel=0.02)
    fitted = re.search(r"it is (\S+) N/m; Eq. 18 gives (\S+) N/m", model).groups()
    assert tuple(map(float, fitted)) == pytest.approx((k, bare), rel=5e-4)
    falls = re.search(r"k_m falls from (\S+) to (\S+) N/m", model).groups()
    assert tuple(map(float, falls)) == pytest.approx((bare, fillet), rel=5e-3)
    flash = re.search(r"flash temperatures are about (\d+) times what Eqs. 3-7 give\.\*\* With a "
                      r"physical f_m = (\S+) the largest T_f at l_x = \S+ m is (\S+) degC against "
                      r"the paper's (\S+) degC", model).groups()
    times, f_phys, t_phys, t_paper = map(float, flash)
    assert times == pytest.approx(ratio_flash, rel=0.02) and f_phys == f0
    assert t_paper == paper.CAL_FM.paper
    assert t_phys == pytest.approx(t_paper / ratio_flash, abs=5e-4)


def test_the_ideal_poincare_miss_quotes_its_spread():
    """The ideal drive's Poincare row misses (5 points, not the paper's 1) because its strobed
    points have not settled within the run: the reason quotes their spread, which is beyond the
    count's tolerance (and below it the count is one); docs/verification.md quotes the run."""
    case = paper.load_paper_case("paper_ideal", CASES, quick=False)
    res = pyspline.simulate(case)
    sec = pyspline.simulate(case.replace(section="shaft", n_out=2,
                                         max_steps=case["max_total_steps"]))
    res.section_t, res.section_y = sec.section_t, sec.section_y
    spread = paper.poincare_spread(res)
    assert spread > paper.POINCARE_TOL and paper.poincare_count(res) > 1
    assert paper.poincare_count(res, tol=1.01 * spread) == 1
    reason = paper.why("paper_ideal/Poincare map: distinct points", res)
    said = float(re.search(r"spread over (\S+) of the trajectory's extent", reason).group(1))
    assert said == pytest.approx(spread, rel=0.05)
    doc = " ".join((CASES.parent / "docs" / "verification.md").read_text().split())
    assert f"as the paper says), {paper._unsettled(res)}." in doc


def test_calibration_recovers_known_parameters(tmp_path):
    """Simulate with known k_m and f_m, then fit them back from the two calibration rows."""
    truth = {"k_m": 3.1e5, "f_m": 0.37}
    targets = {}
    for row, key in ((paper.CAL_KM, "D2max"), (paper.CAL_FM, "Tfmax")):
        case = paper.load_paper_case(row.case, CASES, quick=True).replace(**truth)
        targets[key] = float(row.extract(pyspline.simulate(case)))
    with warnings.catch_warnings():     # the search's trial k_m are not the user's: no warning
        warnings.filterwarnings("error", message=".*k_m", category=pyspline.SplineWarning)
        fit = paper.calibrate(CASES, quick=True, targets=targets, progress=False)
    assert fit["k_m"] == pytest.approx(truth["k_m"], rel=1e-6)
    assert fit["f_m"] == pytest.approx(truth["f_m"], rel=1e-6)


def test_write_calibration_keeps_comments(tmp_path):
    for name in ("paper_ideal", "paper_T100"):
        (tmp_path / f"{name}.nml").write_text((CASES / f"{name}.nml").read_text())
    changed = paper.write_calibration(tmp_path, {"k_m": 1.5e5, "f_m": 0.2})
    assert sorted(changed) == ["paper_T100.nml", "paper_ideal.nml"]
    ideal = pyspline.load_case(tmp_path / "paper_ideal.nml")
    hot = pyspline.load_case(tmp_path / "paper_T100.nml")
    assert ideal["k_m"] == 1.5e5 and hot["k_m"] == 1.5e5 and hot["f_m"] == 0.2
    assert "fitted by 'pyspline calibrate'" in (tmp_path / "paper_T100.nml").read_text()


@pytest.mark.parametrize("command", [["reproduce", "--quick"], ["calibrate", "--quick"],
                                     ["check-exe"]])
def test_cases_option_names_the_missing_directory_or_file(command, tmp_path, capsys):
    """--cases of a directory that does not exist, or lacks a case the command reads: one
    error line naming --cases and what is missing, exit 2 (it said 'case file
    nodir/paper_ideal.nml does not exist'), before any run."""
    from pyspline.cli import main
    nodir = tmp_path / "nodir"
    out = ["--out", str(tmp_path / "out")] if command[0] == "reproduce" else []
    assert main(command + ["--cases", str(nodir)] + out) == 2
    assert capsys.readouterr().err == f"error: CaseError: --cases {nodir}: no such directory\n"
    partial = tmp_path / "partial"
    partial.mkdir()
    (partial / "paper_ideal.nml").write_text((CASES / "paper_ideal.nml").read_text())
    assert main(command + ["--cases", str(partial)] + out) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: CaseError: --cases {partial}: the directory lacks ")
    assert "paper_lx1e-4.nml" in err and "paper_ideal.nml" not in err
