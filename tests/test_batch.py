"""Batch runs that end in one dataset: spline-dyn --summary, pyspline merge (against the sweep of
the same points), sweeps over a design table, and the batch recipes of docs/building.md (the
Slurm array script run locally, dask-jobqueue's job script rendered)."""
import os
import re
import shlex
import stat
import subprocess

import numpy as np
import pytest

import pyspline
from conftest import ROOT, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)
from pyspline.batch import merge, read_summary, summary_point
from pyspline.cli import main
from pyspline.summary import summarise

CASE = ROOT / "cases" / "paper_lx1e-4.nml"
SHORT = dict(t_end=0.05, n_out=401)          # 5 revolutions: fast, sections and a Benettin record
TIMINGS = ("core_wall_s", "wall_s")


def building_block(marker):
    """The first fenced block of docs/building.md that contains `marker`."""
    text = (ROOT / "docs" / "building.md").read_text()
    for lang, body in re.findall(r"```(\w+)\n(.*?)```", text, re.S):
        if marker in body:
            return body
    raise AssertionError(f"no block with {marker!r} in docs/building.md")


def assert_same_points(merged, swept, exact=True):
    """Every variable of the sweep is in the merge, equal bit for bit (NaN = NaN), except the
    timings and the spectrum (not in a summary)."""
    assert "Tm_spectrum" not in merged
    for k, v in swept.data_vars.items():
        if k in TIMINGS or k == "Tm_spectrum":
            continue
        a, b = v.values, merged[k].values
        if a.dtype.kind == "f":
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
    assert all(v["run." + k][0] == x for k, x in res.extremes.items())
    np.testing.assert_allclose(res.extremes["Tm_rms"], np.sqrt(np.mean(res.Tm**2)), rtol=1e-13)
    assert sm["units"]["run.Tm_max"] == "N m" and sm["units"]["loads.closing_speed_max"] == "m/s"
    # with -o as well: the CSV as before, and the same summary
    both = subprocess.run([exe, str(CASE), "-o", "b.csv", "--summary", "b.summary", "--set",
                           "section='tooth'", *[f"--set={k}={v}" for k, v in SHORT.items()]],
                          cwd=tmp_path, capture_output=True, text=True)
    assert both.returncode == 0 and (tmp_path / "b.csv").stat().st_size > 0
    vb = read_summary(tmp_path / "b.summary")["values"]
    assert all(np.array_equal(vb[k], v[k], equal_nan=True) for k in v
               if k.split(".")[-1] not in TIMINGS)


@pytest.mark.parametrize("name", ["paper_flash_lx1e-4", "physical_tilt", "physical_lx1e-4"])
def test_summary_is_the_sweep_point_of_shipped_cases(tmp_path, exe, name):
    """spline-dyn's summary of a shipped case (one-way T_f; face slices; coupled T_f from the
    static equilibrium), read as a sweep point, equals Python's per-point summary of the same
    run bit for bit: the extremes and RMS, loads and statistics come from one code path."""
    out = tmp_path / "s.summary"
    run = subprocess.run([exe, str(ROOT / "cases" / f"{name}.nml"), "--summary", str(out),
                          "--set", "section='shaft'"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    options = dict(section="shaft", lyapunov=False, orders=None)
    res = pyspline.simulate(pyspline.load_case(ROOT / "cases" / f"{name}.nml", section="shaft"))
    swept, merged = summarise(res, options), summary_point(read_summary(out), options)
    assert set(swept) == set(merged) and np.isfinite(swept["period_residual"])
    for k, x in swept.items():
        if isinstance(x, str):
            assert x == merged[k] and (x == "" or k == "warnings"), k
        elif k not in TIMINGS:
            assert np.array_equal(x, merged[k], equal_nan=True), (k, x, merged[k])


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
    with pytest.raises(pyspline.CaseError, match="not both"):
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


def dyn(exe, cwd, summary, *sets, expect=0):
    """spline-dyn on CASE (SHORT) with --set options, writing `summary`; its exit status checked."""
    run = subprocess.run([exe, str(CASE), "--summary", str(summary),
                          *[f"--set={k}={v}" for k, v in SHORT.items()],
                          *[f"--set={s}" for s in sets]], cwd=cwd, capture_output=True, text=True)
    assert run.returncode == expect, run.stderr
    return run


def test_every_run_asked_writes_its_summary_and_merge_keeps_it(tmp_path, exe):
    """A bad value (exit 2), thermal interference at the build (exit 4), a solver failure
    (exit 3) and a --set the reader refuses (exit 2, no case) each write a summary with the
    error, its class and exit code; merge records them as failed points beside the good one,
    with the messages Python's own errors carry."""
    runs = tmp_path / "runs"
    runs.mkdir()
    dyn(exe, runs, "0.summary")
    dyn(exe, runs, "1.summary", "speed_rpm=-5", expect=2)
    dyn(exe, runs, "2.summary", "thermal='bulk'", "t_bulk=3100", expect=4)
    dyn(exe, runs, "3.summary", "max_steps=5", expect=3)
    dyn(exe, runs, "4.summary", "speed_rpm=fast", expect=2)
    sm = [read_summary(runs / f"{k}.summary") for k in range(5)]
    assert [s["error_class"] for s in sm] == ["", "CaseError", "ThermalInterferenceError",
                                              "SolverError", "CaseError"]
    assert [s["values"].get("exit_code", [0])[0] for s in sm] == [0, 2, 4, 3, 2]
    assert sm[1]["case"]["speed_rpm"] == -5.0 and sm[4]["case"] is None
    assert sm[4]["sets"][-1] == "speed_rpm=fast" and "speed_rpm = fast" in sm[4]["error"]
    for k, fields in ((1, dict(speed_rpm=-5.0)), (2, dict(thermal="bulk", t_bulk=3100.0)),
                      (3, dict(max_steps=5))):
        with pytest.raises(pyspline.SplineError) as err:
            pyspline.simulate(pyspline.load_case(CASE, **SHORT, **fields))
        assert sm[k]["error"] == str(err.value) and sm[k]["error_class"] == type(err.value).__name__
    assert main(["merge", str(runs), "--out", str(tmp_path / "m")]) == 0
    ds = pyspline.open_sweep(tmp_path / "m")
    assert ds.attrs["n_points"] == 5 and ds.attrs["n_ok"] == 1 and ds.attrs["n_failed"] == 4
    assert list(ds["error_class"].values) == [s["error_class"] for s in sm]
    assert [os.path.basename(f) for f in ds["summary"].values] == [f"{k}.summary" for k in range(5)]
    assert ds["speed_rpm"].values[1] == -5.0 and np.isnan(ds["speed_rpm"].values[4])
    assert np.isfinite(ds["Tm_max"].values[0]) and np.isnan(ds["Tm_max"].values[1:]).all()


def test_summary_takes_a_regular_file_or_a_new_path_once(tmp_path, exe):
    """--summary and -o onto a FIFO, a character device (a null device of the test's own, as
    root: never the system's) or a directory: exit 2, the node left as it was; a second
    --summary: exit 2; the same file under two names: exit 2, nothing lost."""
    fifo, dev = tmp_path / "fifo", tmp_path / "null"
    os.mkfifo(fifo)
    (tmp_path / "dir").mkdir()
    nodes = [(fifo, "a FIFO"), (tmp_path / "dir", "a directory")]
    if os.geteuid() == 0:
        os.mknod(dev, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
        nodes.append((dev, "a character device"))
    for opt in ("--summary", "-o"):
        for node, what in nodes:
            run = subprocess.run([exe, str(CASE), opt, str(node)], capture_output=True,
                                 text=True, cwd=tmp_path, timeout=60)
            assert run.returncode == 2 and f"{node} is {what}" in run.stderr, run.stderr
    assert fifo.is_fifo() and (os.geteuid() != 0 or stat.S_ISCHR(dev.stat().st_mode))
    for n in (fifo, dev):
        n.unlink(missing_ok=True)
    twice = subprocess.run([exe, str(CASE), "--summary", "a", "--summary=b"], cwd=tmp_path,
                           capture_output=True, text=True)
    assert twice.returncode == 2 and "--summary given twice" in twice.stderr
    (tmp_path / "x.csv").write_text("kept\n")
    for a, b in (("x.csv", "./x.csv"), ("y.csv", "./dir/../y.csv")):
        same = subprocess.run([exe, str(CASE), "--summary", a, "-o", b], cwd=tmp_path,
                              capture_output=True, text=True)
        assert same.returncode == 2 and "are the same file" in same.stderr, same.stderr
    assert (tmp_path / "x.csv").read_text() == "kept\n" and not (tmp_path / "y.csv").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dir", "x.csv"]


@pytest.fixture(scope="module")
def good(tmp_path_factory, exe):
    """Two finished runs' summaries (l_x = 0 and 1e-4) with a section."""
    d = tmp_path_factory.mktemp("good")
    for k, lx in enumerate(("0", "1e-4")):
        dyn(exe, d, f"{k}.summary", f"l_x={lx}", "section='shaft'")
    return d


def edited(good, tmp_path, name, change):
    """A copy of good/0.summary with change(lines) applied, as tmp_path/name."""
    lines = (good / "0.summary").read_text().splitlines()
    out = tmp_path / name
    out.write_text("\n".join(change(lines)) + "\n")
    return out


def test_merge_refuses_duplicates_mixed_cases_and_damage_naming_the_file(tmp_path, good):
    """The same point twice, summaries of two cases (unless mixed=True), a field given twice in
    fields, a missing key, a NaN,
    a section shorter than its times and an invalid case: CaseError naming the file."""
    a, b = good / "0.summary", good / "1.summary"
    with pytest.raises(pyspline.CaseError, match=r"0\.summary and .*dup\.summary are the same "
                                                 r"point"):
        merge([a, b, edited(good, tmp_path, "dup.summary", lambda ls: ls)])
    other = edited(good, tmp_path, "other.summary",
                   lambda ls: [re.sub(r"^(\s*NAME\s*=).*", r'\1"other",', x, flags=re.I)
                               for x in ls])
    with pytest.raises(pyspline.CaseError, match="2 cases .*--mixed"):
        merge([a, b, other])
    assert merge([a, b, other], mixed=True).attrs["n_ok"] == 3
    with pytest.raises(pyspline.CaseError, match="fields: l_x given twice"):   # an IndexError
        merge([a, b], fields=["l_x", "L_X"])
    damage = {
        "missing": (lambda ls: [x for x in ls if not x.startswith("loads.Tm_rms_se ")],
                    "no loads.Tm_rms_se"),
        "nan": (lambda ls: [re.sub(r"^(run\.Tm_max \[N m\] =).*", r"\1 nan", x) for x in ls],
                "run.Tm_max = nan is not finite"),
        "short": (lambda ls: [re.sub(r"^(section\.D2 \[m\] = [^,]*),.*", r"\1", x) for x in ls],
                  r"section.D2 has 1 values, \d+ expected"),
        "case": (lambda ls: [re.sub(r"^(\s*SPEED_RPM\s*=).*", r"\1 -5,", x, flags=re.I)
                             for x in ls], "its case: .*speed_rpm"),
    }
    for name, (change, why) in damage.items():
        bad = edited(good, tmp_path, f"{name}.summary", change)
        assert bad.read_text() != a.read_text(), name
        with pytest.raises(pyspline.CaseError, match=rf"summary .*{name}\.summary: {why}"):
            merge([bad, b])


def test_merge_gives_each_warning_once_with_its_count(good):
    """The paper's shafts draw one plausibility warning per case: merged, it is given once."""
    with pytest.warns(pyspline.SplineWarning) as rec:
        merge([good / "0.summary", good / "1.summary"])
    msgs = [str(w.message) for w in rec if issubclass(w.category, pyspline.SplineWarning)]
    assert len(msgs) == 1 and "winds its shaft" in msgs[0], msgs
    assert "[2 of 2 points; l_x = " in msgs[0], msgs
