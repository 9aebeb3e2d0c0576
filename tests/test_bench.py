"""The speed/accuracy commands in quick mode: they write their chart and table, record
failures as failures, and their reference is checked against a second method."""
import csv
import importlib.util
import sys

import numpy as np
import pytest

import pyspline
from conftest import CASES, DEMONSTRATION_SCENES, PAPER_SHAFTS, ROOT

sys.path.insert(0, str(ROOT / "bench"))
import speed as bench  # noqa: E402  (bench/ is not installed)

pytestmark = [PAPER_SHAFTS, DEMONSTRATION_SCENES]   # expected warnings (conftest)
#: what a sweep of the paper drive over l_x says of its points past the 0.2 mm backlash
PAST_BACKLASH = r"case paper_lx1e-4: start = 'rest' with l_x = .* overlapping its backlash"


def test_budget_failure_is_reported_not_dropped():
    case = pyspline.load_case(CASES / "paper_lx1e-4.nml", t_end=0.01, n_out=11)
    with pytest.raises(bench.Budget):
        bench.run_scipy(case, "RK45", 1e-6, "fortran", None, budget=5)


def test_stability_quick(tmp_path):
    with pytest.warns(pyspline.SplineWarning, match=r"field k_m = 1\.000E\+05 N/m is .* times below"):
        rows = bench.stability_map(tmp_path, quick=True, progress=False)   # k_m from 1e5 on purpose
    assert (tmp_path / "stability.png").stat().st_size > 10_000
    table = list(csv.DictReader(open(tmp_path / "stability.csv")))
    methods = {r["method"] for r in table}
    assert len(table) == len(rows) == 2 * 3 * len(methods)          # every cell is a row
    assert {"CVODE bdf", "CVODE adams", "scipy LSODA"} <= methods
    assert all(r["status"] == "ok" or r["status"].startswith("FAILED") for r in table)
    assert all(r["status"] == "ok" for r in table if r["method"].startswith("CVODE"))


def test_work_precision_quick(tmp_path):
    rows, notes = bench.work_precision(tmp_path, quick=True, progress=False)
    assert (tmp_path / "work_precision.png").stat().st_size > 20_000
    assert len(notes) == 2
    for note in notes:   # the reference agrees with DOP853 on the Fortran RHS
        agree = float(note.split("T_m ")[1].split(",")[0])
        assert agree < 1e-6, note
    ok = [r for r in rows if r["status"] == "ok"]
    assert {r["case"] for r in ok} == {"paper_lx1e-4", "paper_T100"}
    assert any("numpy RHS" in r["method"] for r in ok)           # run from a checkout
    for name in ("paper_lx1e-4", "paper_T100"):                  # tighter rtol, smaller error
        cv = sorted((r for r in ok if r["case"] == name and r["method"] == "CVODE bdf"),
                    key=lambda r: -r["rtol"])
        errs = [max(r["err_Tm"], r["err_F"]) for r in cv]
        assert errs[0] > errs[-1]


def test_ladder_quick(tmp_path):
    """Every level of every quick case is a row; each case's own level has error 0; the
    torsional level is exact on the aligned case and misses on the misaligned one; every auto
    pick is within its tolerance (the CSV says so, and the error column agrees)."""
    import ladder
    rows = ladder.ladder(tmp_path, quick=True, progress=False)
    assert (tmp_path / "ladder.png").stat().st_size > 20_000
    table = list(csv.DictReader(open(tmp_path / "ladder.csv")))
    assert len(table) == len(rows) == len(ladder.QUICK_CASES) * (8 + len(ladder.TOLS))
    by = {(r["case"], r["level"]): r for r in rows}
    for name in ladder.QUICK_CASES:
        own = [r for r in rows if r["case"] == name and r["own"]]
        assert len(own) == 1 and own[0]["error"] == 0.0
    assert by[("paper_ideal", "3-DOF none")]["error"] < 1e-6
    assert by[("paper_lx1e-4", "3-DOF none")]["error"] > 1e-2
    picks = [r for r in rows if "picked" in r]
    assert len(picks) == len(ladder.QUICK_CASES) * len(ladder.TOLS)
    assert all(r["within_tol"] and r["error"] <= r["tol"] for r in picks)
    assert by[("paper_ideal", "auto 0.01")]["picked"] == "3-DOF none"


def test_anatomy_quick(tmp_path):
    """The cost anatomy: positive costs, the shares of one run (parts timed apart fitted into
    the run's core time, whatever the host's load) add up to 1, and the flop count of the
    floor grows with the number of teeth."""
    import anatomy
    rows = anatomy.anatomy(tmp_path, quick=True, cases=("paper_lx1e-4",))
    assert (tmp_path / "anatomy.png").stat().st_size > 10_000
    (r,) = rows
    assert r["rhs_ns"] > 0 and r["floor_ns"] > 0 and r["us_per_step"] > 0
    shares = [r[k] for k in r if k.startswith("share_")]
    assert len(shares) == 5 and all(s >= 0 for s in shares)
    assert sum(shares) == pytest.approx(1.0, abs=1e-12)
    case = pyspline.load_case(CASES / "paper_lx1e-4.nml")
    assert anatomy.rhs_cost(case.replace(z=32), n=10, repeat=1)[2] > \
        anatomy.rhs_cost(case, n=10, repeat=1)[2]
    cost = anatomy.output_cost(case.replace(t_end=0.05, n_out=321), repeat=1)
    assert cost[1] <= cost[0] <= cost[2] and cost[3] > 0 and cost[4] > 0
    assert "target 0.1 us" in anatomy.format_output_cost("paper_lx1e-4", case, cost)


def test_bifurcation_accuracy_quick(tmp_path):
    """The diagram's accuracy chart: every rtol a row, the section error falls as rtol tightens,
    and at the case's rtol every period is the reference's."""
    import bifurcation
    with pytest.warns(pyspline.SplineWarning, match=PAST_BACKLASH):
        rows = bifurcation.accuracy(tmp_path, 30)                   # l_x[::10]: 3 points
    assert [r["rtol"] for r in rows] == sorted(bifurcation.ACCURACY_RTOLS)     # tightest first
    err = {r["rtol"]: r["section_error_of_range"] for r in rows}
    assert err[1e-10] < err[1e-8] < err[1e-6] < 1e-3
    assert next(r for r in rows if r["rtol"] == 1e-9)["period_differs"] == 0
    assert (tmp_path / "bifurcation_accuracy.png").stat().st_size > 10_000
    assert len(list(csv.DictReader(open(tmp_path / "bifurcation_accuracy.csv")))) == len(rows)


def test_bifurcation_figure_only(tmp_path, capsys):
    """--figure: the diagram alone (docs/bifurcation.png's command), no timing table."""
    import argparse

    import bifurcation
    args = argparse.Namespace(out=str(tmp_path), accuracy=False, figure=True, points=3,
                              blocks=None, repeats=None, rtol=None, quick=False)
    with pytest.warns(pyspline.SplineWarning, match=PAST_BACKLASH):
        assert bifurcation.main(args) == 0
    assert (tmp_path / "bifurcation.png").stat().st_size > 10_000
    assert not (tmp_path / "bifurcation.csv").exists()
    assert "periods: {" in capsys.readouterr().out


def test_bifurcation_scaling_labels():
    """--scaling pairs each 2-worker executor with the same executor on one worker."""
    import bifurcation
    assert [label(2) for label in bifurcation.KINDS.values()] == [
        "2 threads", "2 processes", "Dask LocalCluster, 2 worker procs",
        "Dask LocalCluster, 2 worker threads"]
    assert [label(1) for label in bifurcation.KINDS.values()] == [
        "1 thread", "1 process", "Dask LocalCluster, 1 worker proc",
        "Dask LocalCluster, 1 worker thread"]


def test_bifurcation_repeats_quick(tmp_path, exe, monkeypatch):
    """--repeats: every executor's walls per repeat (summed over --blocks, the executors started
    once for all of them) and medians; --host: the standalone executable's runs one and two at
    a time beside them."""
    import argparse

    import bifurcation
    monkeypatch.setenv("SPLINE_DYN", exe)
    args = argparse.Namespace(out=str(tmp_path), accuracy=False, points=2, blocks=2, repeats=2,
                              rtol=1e-6, quick=True, scaling=False, host=True, figure=False)
    with pytest.warns(pyspline.SplineWarning, match=PAST_BACKLASH):
        assert bifurcation.main(args) == 0
    table = list(csv.DictReader(open(tmp_path / "bifurcation.csv")))
    host = table[-2:]
    assert [r["executor"] for r in host] == list(bifurcation.HOST)
    assert float(host[0]["speed_up_median"]) == 1.0             # one at a time against itself
    assert float(host[1]["speed_up_median"]) > 0                 # a ratio of timings: no bound
    assert host[1]["ceiling"] == ""                              # no points, no core time
    table = table[:-2]
    assert len(table) == 5 and {r["failed"] for r in table} == {"0"}
    for r in table:
        walls = [float(w) for w in r["walls_s"].split()]
        assert len(walls) == 2 and float(r["wall_min_s"]) == pytest.approx(min(walls), abs=0.01)
    assert float(table[0]["speed_up_median"]) == 1.0                 # serial against itself
    # the core's time for the same points over the serial sweep's, and 2 workers over it
    assert float(table[0]["core_time_over_serial_median"]) == 1.0
    for r in table[1:]:
        assert float(r["core_time_over_serial_median"]) > 0      # timings: no bound (noisy host)
        assert float(r["ceiling"]) == pytest.approx(2 / float(r["core_time_over_serial_median"]))


def test_race_statistics_standard_error_is_the_cores():
    """bench/race.py's standard errors (numpy, per revolution, overlapping batch means) against
    the core's Tm_rms_se (spline_loads::batch_means) on a short chaotic run."""
    import race
    case = pyspline.load_case(CASES / "chaos_z24.nml", t_transient=0.02, t_end=0.12, n_out=2001,
                              lyapunov=False, section="none")
    res = pyspline.simulate(case)
    stat, se = race.statistics_of(case, res.t, res.Tm)
    assert res.loads["batches"] == 10
    assert se[0] == pytest.approx(res.loads["Tm_rms_se"], rel=1e-9)
    assert se[0] > 0 and np.all(np.isfinite(stat)) and np.all(np.isfinite(se))


def test_race_candidate_is_the_loosest_rung_that_passes_twice():
    """The race takes, per family and accuracy, the loosest rtol rung that reaches the accuracy
    and whose next tighter rung does too: a lucky pass just above a failing rung is skipped,
    and a family that never passes twice has no candidate."""
    import race
    errs = [1e-4, 5e-7, 2e-6, 4e-7, 1e-7, 3e-9, 1e-9]
    assert race._candidates(errs, (1e-6, 1e-8)) == {1e-6: 3, 1e-8: 5}
    assert race._candidates([1e-4, np.inf, 1e-7, np.inf], (1e-6,)) == {}
    rungs = np.log10(race.RUNGS)
    assert rungs[0] == pytest.approx(-4) and rungs[-1] == pytest.approx(-12)
    assert np.allclose(np.diff(rungs), -0.25)          # quarter decades, both sides alike


def test_race_statistics_level_needs_the_spread_too():
    """A rung at the statistics level has its means within 3 standard errors and its spread
    within the F bound, and so has its next tighter rung: a noisy rung (z 1, spread 9x the
    reference's against a bound of 6.4) is not taken, nor the rung above it."""
    import race

    def rec(rtol, z, spread):
        return dict(side="pyspline", setting="ERK", atol_ratio=1e-2, rtol=rtol, z_max=z,
                    spread=spread, spread_bound=6.4)
    recs = [rec(3e-2, 1.0, 2.0), rec(1e-2, 1.0, 9.0), rec(3e-3, 1.0, 1.5), rec(1e-3, 0.5, 1.0)]
    assert [r["rtol"] for r in race._robust(recs)] == [3e-3]


def test_race_quick_times_the_peer_with_its_forces(tmp_path):
    """A quick race of the paper scene: both sides (the peer with and without its closed-form
    tail) reach each accuracy with a candidate timed in every round, the peer's error from its
    own forces, and the ratio is of their medians."""
    if importlib.util.find_spec("numbalsoda") is None:   # not imported: its import compiles
        pytest.skip("numbalsoda is not installed")
    import race
    rows, runs = race.race(quick=True, repeat=2, progress=lambda m: None,
                           cases=["paper_lx1e-4"])
    assert [r["accuracy"] for r in rows] == [1e-6, 1e-8, 1e-6]
    for r in rows:
        for side in ("pyspline", "dop853", "tailed"):
            assert r[side]["err"] <= r["accuracy"] and len(r[side]["cpu_runs"]) == 2
        fastest = min((b for b in (r["dop853"], r["lsoda"], r["tailed"]) if b),
                      key=lambda b: b["cpu_s"])
        assert r["ratio"] == pytest.approx(fastest["cpu_s"] / r["pyspline"]["cpu_s"])
    assert {r["kind"] for r in runs} == {"scan", "timed"}
    assert race.format_rows(rows)[1].startswith("paper_lx1e-4, 1 s, 6401 outputs | F error")
