"""The speed/accuracy commands in quick mode: they write their chart and table, record
failures as failures, and their reference is checked against a second method."""
import csv

import pytest

import pyspline
from pyspline import bench
from conftest import CASES


def test_budget_failure_is_reported_not_dropped():
    case = pyspline.load_case(CASES / "paper_lx1e-4.nml", t_end=0.01, n_out=11)
    with pytest.raises(bench.Budget):
        bench.run_scipy(case, "RK45", 1e-6, "fortran", None, budget=5)


def test_stability_quick(tmp_path):
    rows = bench.stability_map(tmp_path, quick=True, progress=False)
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
