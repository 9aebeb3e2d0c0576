"""Batch runs that end in one dataset: spline-dyn --summary, pyspline merge (against the sweep of
the same points), sweeps over a design table, and the batch recipes of docs/building.md (the
Slurm array script run locally, dask-jobqueue's job script rendered)."""
import os
import re
import shlex
import subprocess

import numpy as np
import pytest

import pyspline
from conftest import ROOT, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)
from pyspline.batch import merge, read_summary
from pyspline.cli import main
from pyspline.sweep import summarise

CASE = ROOT / "cases" / "paper_lx1e-4.nml"
SHORT = dict(t_end=0.05, n_out=401)          # 5 revolutions: fast, sections and a Benettin record
TIMINGS = ("core_wall_s", "wall_s")
#: the sweep's RMS is numpy's (pairwise sums), the summary's the executable's sequential sum;
#: period_residual is relative to the RMS of D2 and dD2/dt (sweep.section_summary)
RMS = ("Tm_rms", "kv_rms", "F_rms", "D2_rms", "period_residual")


def building_block(marker):
    """The first fenced block of docs/building.md that contains `marker`."""
    text = (ROOT / "docs" / "building.md").read_text()
    for lang, body in re.findall(r"```(\w+)\n(.*?)```", text, re.S):
        if marker in body:
            return body
    raise AssertionError(f"no block with {marker!r} in docs/building.md")


def assert_same_points(merged, swept, exact=True):
    """Every variable of the sweep is in the merge, equal bit for bit (NaN = NaN), except the
    timings, the RMS values (1e-13 relative) and the spectrum (not in a summary)."""
    assert "Tm_spectrum" not in merged
    for k, v in swept.data_vars.items():
        if k in TIMINGS or k == "Tm_spectrum":
            continue
        a, b = v.values, merged[k].values
        if a.dtype.kind == "f" and k in RMS:
            np.testing.assert_allclose(b, a, rtol=1e-13, err_msg=k)
        elif a.dtype.kind == "f":
            assert np.array_equal(a, b, equal_nan=True), (k, a, b)
        else:
            assert (a == b).all(), (k, a, b)
    assert np.isfinite(merged["wall_s"].values[merged["error"].values == ""]).all()


def slurm_array(tmp_path, exe, design):
    """Run the Slurm script of docs/building.md locally, one task per line of `design`, then
    the merge command it submits; returns the merged dataset."""
    (tmp_path / "case.nml").write_text(CASE.read_text())
    (tmp_path / "design.txt").write_text("".join(line + "\n" for line in design))
    script = building_block("#SBATCH --array")
    env = dict(os.environ)
    bindir = tmp_path / "bin"        # spline-dyn on PATH is the build under test
    bindir.mkdir()
    (bindir / "spline-dyn").symlink_to(exe)
    env["PATH"] = f"{bindir}{os.pathsep}{env['PATH']}"
    for task in range(len(design)):
        run = subprocess.run(["bash", "-c", script], cwd=tmp_path, capture_output=True,
                             text=True, env=dict(env, SLURM_ARRAY_TASK_ID=str(task)), timeout=300)
        assert run.returncode == 0, run.stderr
        assert (tmp_path / "runs" / f"{task}.summary").exists()
    assert not list(tmp_path.glob("*.csv")) and not list((tmp_path / "runs").glob("*.csv"))
    wrap = re.search(r'--wrap "([^"]+)"', building_block("--dependency")).group(1)
    cmd = shlex.split(wrap)
    assert cmd[:2] == ["pyspline", "merge"]
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        assert main(cmd[1:]) == 0
    finally:
        os.chdir(cwd)
    return pyspline.open_sweep(tmp_path / cmd[cmd.index("--out") + 1])


def test_slurm_array_summaries_merge_into_the_sweep(tmp_path, exe):
    """The Slurm array script of docs/building.md on 2 points (with the Lyapunov exponent),
    merged, equals pyspline.sweep over the same points; spline-dyn writes no CSV."""
    fixed = " ".join(f"--set {k}={v}" for k, v in SHORT.items())
    design = [f"--set l_x={x!r} {fixed} --set section='shaft' --set lyapunov=.true."
              for x in (1e-4, 0.0)]
    merged = slurm_array(tmp_path, exe, design)
    swept = pyspline.sweep(pyspline.load_case(CASE, **SHORT), l_x=[0.0, 1e-4], lyapunov=True,
                           progress=False)
    assert list(merged["error"].dims) == ["l_x"] and merged.attrs["swept"] == "l_x"
    assert (merged["l_x"].values == swept["l_x"].values).all()
    assert merged.attrs["n_ok"] == 2 and np.isfinite(merged["lyapunov"]).all()
    assert np.isfinite(merged["period_residual"]).all()
    assert_same_points(merged, swept)


def test_summary_reads_back_the_core_numbers(tmp_path, exe):
    """A summary has the run's statistics, loads and section as Python's Result has them (bit
    for bit), its units from the core's tables, and the case it ran; no CSV without -o."""
    out = tmp_path / "a.summary"
    run = subprocess.run([exe, str(CASE), "--summary", str(out), "--set", "section='tooth'",
                          *[f"--set={k}={v}" for k, v in SHORT.items()]], cwd=tmp_path,
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert list(tmp_path.iterdir()) == [out]
    sm = read_summary(out)
    res = pyspline.simulate(pyspline.load_case(CASE, section="tooth", **SHORT))
    assert sm["case"].text() == res.case.text() and sm["error"] == ""
    v = sm["values"]
    for k, x in res.loads.items():
        assert np.array_equal(np.atleast_1d(x), v[("tooth_loads." if np.ndim(x) else "loads.") + k],
                              equal_nan=True), k
    for k, x in res.stats.items():
        if k not in TIMINGS:
            assert v["stats." + k][0] == x, k
    assert np.array_equal(v["section.t"], res.section_t)
    assert np.array_equal(v["section.D2"], res.section_y[:, 5])
    assert v["run.Tm_min"][0] == res.Tm.min() and v["run.F_max"][0] == res.tooth["F"].max()
    assert sm["units"]["run.Tm_max"] == "N m" and sm["units"]["loads.closing_speed_max"] == "m/s"
    # with -o as well: the CSV as before, and the same summary
    both = subprocess.run([exe, str(CASE), "-o", "b.csv", "--summary", "b.summary", "--set",
                           "section='tooth'", *[f"--set={k}={v}" for k, v in SHORT.items()]],
                          cwd=tmp_path, capture_output=True, text=True)
    assert both.returncode == 0 and (tmp_path / "b.csv").stat().st_size > 0
    vb = read_summary(tmp_path / "b.summary")["values"]
    assert all(np.array_equal(vb[k], v[k], equal_nan=True) for k in v
               if k.split(".")[-1] not in TIMINGS)


def test_summary_keeps_a_long_spacing_error_list(tmp_path, exe):
    """The case at a summary's end is the whole case: 400 distinct spacing errors (about 80
    namelist records, which overflowed the 120-record buffer the case text was written into
    before) read back equal, bit for bit."""
    e = np.random.default_rng(7).normal(0.0, 1e-7, 400)
    base = pyspline.load_case(CASE, z=400, spacing_error=list(e), t_end=2e-4, n_out=3)
    nml = tmp_path / "z400.nml"
    nml.write_text(base.text(), encoding="utf-8")
    run = subprocess.run([exe, str(nml), "--summary", "z.summary"], cwd=tmp_path,
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    case = read_summary(tmp_path / "z.summary")["case"]
    assert case["z"] == 400 and np.array_equal(case["spacing_error"][:400], e)
    assert case.text() == base.text()


def test_failed_run_summary_and_refusals(tmp_path, exe):
    """A run that fails writes a summary with the error and keeps its exit code; merge shows it
    as the sweep shows a failed point. A summary is never the case file."""
    case = pyspline.load_case(CASE, max_steps=5, **SHORT)
    run = subprocess.run([exe, str(CASE), "--summary", "f.summary", "--set", "max_steps=5",
                          *[f"--set={k}={v}" for k, v in SHORT.items()]], cwd=tmp_path,
                         capture_output=True, text=True)
    assert run.returncode == 3
    with pytest.raises(pyspline.SolverError) as err:
        pyspline.simulate(case)
    ds = merge([tmp_path / "f.summary"])
    assert ds["error"].values.tolist() == [str(err.value)]
    assert ds["error_class"].values.tolist() == ["SolverError"]
    assert np.isnan(ds["Tm_max"].values).all() and ds.attrs["n_failed"] == 1
    nml = tmp_path / "c.nml"
    nml.write_text(CASE.read_text())
    same = subprocess.run([exe, str(nml), "--summary", str(nml)], capture_output=True, text=True)
    assert same.returncode == 2 and "is the case file" in same.stderr
    assert nml.read_text() == CASE.read_text()
    bad = subprocess.run([exe, str(CASE), "--summary"], capture_output=True, text=True)
    assert bad.returncode == 2 and "--summary needs a file name" in bad.stderr
    with pytest.raises(pyspline.CaseError, match="not a summary"):
        merge([nml])


def test_merge_of_scattered_points_is_a_point_dim(tmp_path, exe):
    """Points that are no full grid: dim 'point' with the varying fields as coordinates."""
    runs = [("1e-4", "6000"), ("0", "3000"), ("5e-5", "6000")]
    paths = []
    for k, (lx, rpm) in enumerate(runs):
        p = tmp_path / f"{k}.summary"
        r = subprocess.run([exe, str(CASE), "--summary", str(p), f"--set=l_x={lx}",
                            f"--set=speed_rpm={rpm}", *[f"--set={a}={b}" for a, b in SHORT.items()]],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        paths.append(p)
    ds = merge(paths, out=tmp_path / "m")
    assert list(ds["error"].dims) == ["point"]
    assert ds["l_x"].values.tolist() == [1e-4, 0.0, 5e-5]
    assert ds["speed_rpm"].values.tolist() == [6000.0, 3000.0, 6000.0]
    assert (tmp_path / "m" / "sweep.nc").exists()


def test_design_table_equals_single_runs(tmp_path):
    """A design table of 3 rows (two fields, one of them text) gives the summaries of three
    single runs, bit for bit, on a dim 'point' with the fields as coordinates; the command line
    writes the same."""
    table = tmp_path / "design.csv"
    table.write_text("l_x,t_d,method\n1e-4,30.7,adams\n0,20,bdf\n5e-5,30.7,'adams'\n")
    base = pyspline.load_case(CASE, **SHORT)
    ds = pyspline.sweep(base, table=table, progress=False)
    rows = [dict(l_x=1e-4, t_d=30.7, method="adams"), dict(l_x=0.0, t_d=20.0, method="bdf"),
            dict(l_x=5e-5, t_d=30.7, method="adams")]
    assert list(ds["error"].dims) == ["point"] and ds["point"].values.tolist() == [0, 1, 2]
    assert ds["method"].values.tolist() == ["adams", "bdf", "adams"]
    assert ds["l_x"].attrs["units"] == "m" and ds.attrs["swept"] == "l_x t_d method"
    options = dict(section="shaft", lyapunov=False, orders=None)
    for i, row in enumerate(rows):
        s = summarise(pyspline.simulate(base.replace(section="shaft", lyapunov=False, **row)),
                      options)
        for k, x in s.items():
            if k not in TIMINGS:
                got = ds[k].values[i]
                if np.ndim(x):
                    got = got[:len(x)]
                assert np.array_equal(got, x, equal_nan=True) if np.ndim(x) or \
                    isinstance(x, float) else got == x, (i, k)
    out = tmp_path / "cli"
    assert main(["sweep", str(CASE), "--table", str(table), "--out", str(out), "--quiet",
                 *[f"--fix={k}={v}" for k, v in SHORT.items()]]) == 0
    cli = pyspline.open_sweep(out)
    for k in ("Tm_max", "period", "load_sharing", "section_D2"):
        assert np.array_equal(cli[k].values, ds[k].values, equal_nan=True), k
    with pytest.raises(pyspline.CaseError, match="unknown field 'l_z'"):
        table.write_text("l_z\n1\n")
        pyspline.sweep(base, table=table, progress=False)
    with pytest.raises(TypeError, match="not both"):
        pyspline.sweep(base, table={"l_x": [0.0]}, l_x=[1e-4], progress=False)


def test_dask_jobqueue_renders_the_documented_cluster():
    """The SLURMCluster(...) of docs/building.md builds and renders its job script (nothing is
    submitted)."""
    pytest.importorskip("dask_jobqueue")
    from dask_jobqueue import SLURMCluster
    code = building_block("SLURMCluster(")
    call = re.search(r"SLURMCluster\((.*?)\)\n", code, re.S).group(1)
    cluster = eval(f"SLURMCluster({call})", {"SLURMCluster": SLURMCluster})
    try:
        script = cluster.job_script()
    finally:
        cluster.close()
    assert script.startswith("#!/usr/bin/env bash") and "#SBATCH --cpus-per-task=8" in script
    assert "distributed.cli.dask_worker" in script and "--nworkers 8" in script
