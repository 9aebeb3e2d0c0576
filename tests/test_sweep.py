"""pyspline.sweep: one- and two-field sweeps on every kind of executor (same numbers bit for
bit), failed points, resume, interrupts, Dask, the command line (sweep, plot) and
Result.to_xarray. Short runs: paper_lx1e-4 over 0.25 s (20 shaft revolutions in the window)."""
import concurrent.futures as cf
import multiprocessing as mp
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import pyspline
from pyspline import analysis, summary
from pyspline.core import _names

xr = pytest.importorskip("xarray")
sw = sys.modules["pyspline.sweeps"]

from conftest import CASES, PAPER_SHAFTS  # noqa: E402

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
TIMING = ["wall_s", "core_wall_s"]      # the only numbers that differ between two runs
LX = np.linspace(0.0, 3e-4, 4)
#: what a point past the drive's 0.2 mm backlash says (LX's last): its start overlaps a tooth
PAST_BACKLASH = r"case paper_lx1e-4: start = 'rest' with l_x = 3\.000E-04, .* overlapping its back"


@pytest.fixture(scope="module")
def case():
    return pyspline.load_case(CASES / "paper_lx1e-4.nml", t_end=0.25, t_transient=0.05,
                              n_out=201)


def _same(a, b):
    """Equal data bit for bit (NaN == NaN), coordinates included; timings excluded."""
    xr.testing.assert_equal(a.drop_vars(TIMING), b.drop_vars(TIMING))


def _png(path):
    data = path.read_bytes()
    assert data[:8] == PNG_MAGIC and len(data) > 5000, path


# --------------------------------------------------------------------------- executors

def test_1d_serial_threads_processes_identical(case):
    with pytest.warns(pyspline.SplineWarning, match=PAST_BACKLASH):
        serial = pyspline.sweep(case, progress=False, lyapunov=True, l_x=LX)
    assert serial["section_D2"].dims == ("l_x", "section_point")
    assert serial.sizes["l_x"] == 4 and serial.sizes["section_point"] == 21
    np.testing.assert_array_equal(serial["l_x"], LX)
    assert serial["l_x"].attrs["units"] == "m"
    assert serial["section_D2"].attrs["units"] == "m"
    assert (serial["error"] == "").all() and serial.attrs["n_ok"] == 4
    assert serial.attrs["case"] == case.replace(section="shaft", lyapunov=True).text()
    assert serial.attrs["pyspline_version"] == pyspline.__version__
    assert np.isfinite(serial["period"]).all() and np.isfinite(serial["lyapunov"]).all()
    np.testing.assert_array_equal(serial["predictability_horizon"],
                                  analysis.predictability_horizon(serial["lyapunov"].values))
    assert (serial["steps"] > 0).all() and (serial["rhs_evals"] > 0).all()
    assert "Tm_spectrum" not in serial                       # only for speed sweeps
    with cf.ThreadPoolExecutor(2) as ex, \
            pytest.warns(pyspline.SplineWarning, match=PAST_BACKLASH):
        threads = pyspline.sweep(case, executor=ex, progress=False, lyapunov=True, l_x=LX)
    with cf.ProcessPoolExecutor(1, mp_context=mp.get_context("spawn")) as ex, \
            pytest.warns(pyspline.SplineWarning, match=PAST_BACKLASH):   # said from processes too
        procs = pyspline.sweep(case, executor=ex, progress=False, lyapunov=True, l_x=LX)
    _same(serial, threads)
    _same(serial, procs)


def test_points_equal_direct_runs(case):
    """A grid has both dims in keyword order, and each point is the run of its own case."""
    ds = pyspline.sweep(case, progress=False, l_x=[0.0, 1e-4, 2e-4], t_d=[20.0, 40.0])
    assert ds["section_D2"].dims == ("l_x", "t_d", "section_point")
    assert ds["period"].shape == (3, 2) and ds["Tm_max"].shape == (3, 2)
    assert ds["t_d"].attrs["units"] == "N m"
    assert ds.attrs["swept"] == "l_x t_d" and ds.attrs["n_points"] == 6
    res = pyspline.simulate(case.replace(l_x=2e-4, t_d=20.0, section="shaft"))
    p = ds.sel(l_x=2e-4, t_d=20.0)
    np.testing.assert_array_equal(p["section_D2"], res.section_y[:, 5])
    np.testing.assert_array_equal(p["section_vD2"], res.section_y[:, 12])
    np.testing.assert_array_equal(p["section_t"], res.section_t)
    assert float(p["Tm_max"]) == res.Tm.max() and float(p["Tm_min"]) == res.Tm.min()
    assert float(p["F_max"]) == res.F.max() and float(p["kv_max"]) == res.kv.max()
    assert float(p["Tm_rms"]) == pytest.approx(np.sqrt(np.mean(res.Tm**2)), rel=1e-12)
    assert float(p["steps"]) == res.stats["steps"]


def test_failing_point_is_recorded(case, tmp_path):
    """t_bulk = 3100 degC closes the backlash (ThermalInterferenceError): that point has its
    error and NaN values, the others ran, and the failure is saved like any result."""
    hot = case.replace(thermal="bulk")
    ds = pyspline.sweep(hot, progress=False, out=tmp_path, t_bulk=[0.0, 3100.0, 50.0])
    assert list(ds["error_class"].values) == ["", "ThermalInterferenceError", ""]
    msg = str(ds["error"].sel(t_bulk=3100.0).values)
    assert case.name in msg
    bad = ds.sel(t_bulk=3100.0)
    assert np.isnan(bad["Tm_max"]) and np.isnan(bad["period"]) and np.isnan(bad["steps"])
    assert np.isnan(bad["section_D2"]).all()
    ok = ds.sel(t_bulk=[0.0, 50.0])
    assert np.isfinite(ok["Tm_max"]).all() and np.isfinite(ok["period"]).all()
    assert ds.attrs["n_failed"] == 1 and ds.attrs["n_ok"] == 2 and ds.attrs["n_missing"] == 0
    assert len(list((tmp_path / "points").glob("*.npz"))) == 3
    back = pyspline.open_sweep(tmp_path)
    assert str(back["error_class"].sel(t_bulk=3100.0).values) == "ThermalInterferenceError"


def test_bad_field_fails_at_once(case):
    with pytest.raises(pyspline.CaseError, match="unknown field 'lx'"):
        pyspline.sweep(case, progress=False, lx=[0.0, 1e-4])
    for values, why in ((1e-4, "must be a sequence"), ([], r"shape \(0,\)"),
                        ([[0.0, 1e-4], [2e-4, 3e-4]], r"shape \(2, 2\)")):
        with pytest.raises(pyspline.CaseError, match=f"sweep: the values of l_x .*{why}"):
            pyspline.sweep(case, progress=False, l_x=values)
    with pytest.raises(pyspline.CaseError, match="sweep: no field to sweep"):
        pyspline.sweep(case, progress=False)
    with pytest.raises(pyspline.CaseError, match="table: .* same length, got l_x 2, t_d 1"):
        pyspline.sweep(case, progress=False, table={"l_x": [0.0, 1e-4], "t_d": [1.0]})
    with pytest.raises(pyspline.CaseError, match="table: the values of t_d must be a sequence"):
        pyspline.sweep(case, progress=False, table={"l_x": [0.0], "t_d": 1.0})


# --------------------------------------------------------------------------- files

def _counting(monkeypatch, fail_on=None):
    """Replace the task by a counting one (in-process executors look it up at call time);
    on call number `fail_on` it raises KeyboardInterrupt, as a Ctrl-C during a run does."""
    calls = []
    real = sw.run_point

    def task(point_case, options):
        calls.append(point_case["l_x"])
        if fail_on is not None and len(calls) == fail_on:
            raise KeyboardInterrupt
        return real(point_case, options)

    monkeypatch.setattr(sw, "run_point", task)
    return calls


def test_resume_computes_only_missing_points(case, tmp_path, monkeypatch):
    with pytest.warns(pyspline.SplineWarning, match=PAST_BACKLASH):
        first = pyspline.sweep(case, progress=False, out=tmp_path, l_x=LX)
    files = sorted((tmp_path / "points").glob("*.npz"))
    assert len(files) == 4 and (tmp_path / "sweep.nc").is_file()
    _same(first, pyspline.open_sweep(tmp_path / "sweep.nc"))
    files[2].unlink()
    calls = _counting(monkeypatch)
    with pytest.warns(pyspline.SplineWarning, match=PAST_BACKLASH):   # a reused point's, kept
        again = pyspline.sweep(case, progress=False, out=tmp_path, l_x=LX)
    assert calls == [LX[2]]
    assert again.attrs["n_computed"] == 1 and again.attrs["n_reused"] == 3
    _same(first, again)
    np.testing.assert_array_equal(first["wall_s"][[0, 1, 3]], again["wall_s"][[0, 1, 3]])
    # a changed case is never served from the old files
    calls.clear()
    with pytest.warns(pyspline.SplineWarning, match=PAST_BACKLASH):
        changed = pyspline.sweep(case.replace(t_d=25.0), progress=False, out=tmp_path, l_x=LX)
    assert len(calls) == 4 and changed.attrs["n_reused"] == 0
    assert not np.array_equal(changed["Tm_max"], first["Tm_max"])


@pytest.mark.parametrize("kind", ["serial", "threads"])
def test_interrupt_keeps_finished_points(case, tmp_path, monkeypatch, kind):
    values = np.linspace(0.0, 2e-4, 5)         # within the backlash: no start overlaps a tooth
    _counting(monkeypatch, fail_on=3)
    ex = cf.ThreadPoolExecutor(1) if kind == "threads" else None
    try:
        with pytest.raises(KeyboardInterrupt):
            pyspline.sweep(case, executor=ex, progress=False, out=tmp_path, l_x=values)
    finally:
        if ex is not None:
            ex.shutdown(wait=True, cancel_futures=True)
    saved = sorted(p.name[:5] for p in (tmp_path / "points").glob("*.npz"))
    assert saved[:2] == ["00000", "00001"] and "00002" not in saved
    if kind == "serial":
        assert saved == ["00000", "00001"]
    merged = pyspline.open_sweep(tmp_path)
    assert merged.attrs["n_ok"] == len(saved)
    assert merged.attrs["n_missing"] == 5 - len(saved)
    assert merged["error_class"].values[2] == "NotComputed"
    assert np.isfinite(merged["Tm_max"].values[:2]).all()
    monkeypatch.undo()
    rest = pyspline.sweep(case, progress=False, out=tmp_path, l_x=values)
    assert rest.attrs["n_computed"] == 5 - len(saved) and rest.attrs["n_ok"] == 5


def test_ctrl_c_in_a_real_sweep(case, tmp_path):
    """SIGINT to `pyspline sweep` (serial) during a run: exit 130, finished points kept and
    merged, a rerun reuses them (here over the points that finished: the rest would take 0.2 s
    each; that a rerun then computes only the missing points:
    test_resume_computes_only_missing_points)."""
    path = tmp_path / "long.nml"
    case.replace(t_end=12.0, n_out=1001, name="long", linear_tail=False).to_namelist(path)  # 0.2 s
    # a point (the linear tail would finish a point in a few ms, and the sweep before SIGINT)
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "pyspline", "sweep", str(path), "--set", "l_x=0:3e-4:40",
           "--out", str(out), "--quiet"]
    # SIGINT as in a terminal, also when this process was started with SIGINT ignored (a
    # background job of a non-interactive shell)
    # (cwd: not the checkout, whose source tree would shadow the installed package)
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            cwd=tmp_path,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and len(list(out.glob("points/*.npz"))) < 2:
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, stderr
    assert "interrupted" in stderr
    n = len(list(out.glob("points/*.npz")))
    assert 2 <= n < 40
    merged = pyspline.open_sweep(out)
    assert merged.attrs["n_ok"] == n and merged.attrs["n_missing"] == 40 - n
    rerun = pyspline.sweep(pyspline.load_case(path), progress=False, out=out,
                           l_x=sw.parse_values("l_x", "0:3e-4:40")[:n])
    assert rerun.attrs["n_reused"] == n and rerun.attrs["n_computed"] == 0


# --------------------------------------------------------------------------- Dask

@pytest.mark.parametrize("kwargs", [{}, dict(processes=False)],
                         ids=["worker-processes", "worker-threads"])
def test_dask_executor(case, kwargs):
    """A local Dask cluster (pyspline.local_dask_client: one worker process, its default kind,
    where cases and summaries are pickled, and two worker threads in this process) gives the
    serial numbers (needs `distributed`, which scripts/setup.sh installs: in CI this test
    runs, never skips)."""
    if os.environ.get("CI"):
        import distributed
    else:
        distributed = pytest.importorskip("distributed")
    with pytest.warns(pyspline.SplineWarning, match=PAST_BACKLASH):
        serial = pyspline.sweep(case, progress=False, l_x=LX)
    box = {}
    processes = not kwargs                      # the default: worker processes
    n = 1 if processes else 2                   # a process each costs its imports
    with pyspline.local_dask_client(n, **kwargs) as client:
        assert len(client.scheduler_info()["workers"]) == n
        pids = set(client.run(os.getpid).values())
        assert (os.getpid() not in pids and len(pids) == 1) if processes else pids == {os.getpid()}
        if processes:    # DASK_SWEEP_CONFIG reached the worker processes: no statistical
            import dask  # profiler, no work stealing; malloc keeps freed blocks for the next run
            settings = client.run(lambda: [dask.config.get(k) for k in (
                "distributed.worker.profile.enabled", "distributed.scheduler.work-stealing")])
            assert list(settings.values()) == [[False, False]] * n
            env = client.run(lambda: {k: os.environ.get(k) for k in (
                "MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_")})
            assert list(env.values()) == [{"MALLOC_TRIM_THRESHOLD_": str(64 << 20),
                                           "MALLOC_MMAP_THRESHOLD_": str(32 << 20)}] * n

        def run():      # chunks of 3 and 1 points: each summary must reach its own point
            box["ds"] = pyspline.sweep(case, executor=client.get_executor(), progress=False,
                                       l_x=LX, chunk=3)

        worker = threading.Thread(target=run, daemon=True)
        with pytest.warns(pyspline.SplineWarning, match=PAST_BACKLASH):   # from threads or processes
            worker.start()
            worker.join(timeout=180)
        assert not worker.is_alive(), "the Dask sweep did not finish in 180 s"
    assert box["ds"].attrs["n_ok"] == 4
    _same(serial, box["ds"])


def test_dask_worker_processes_without_main_guard(tmp_path):
    """A script that starts worker processes without `if __name__ == "__main__":` fails with an
    error that names the guard (each worker process imports the script), not only Dask's
    "Nanny failed to start"."""
    pytest.importorskip("distributed")
    script = tmp_path / "no_guard.py"
    script.write_text("import pyspline\n"
                      "with pyspline.local_dask_client(1) as client:\n"
                      "    print(client)\n")
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         timeout=120, cwd=tmp_path)
    assert run.returncode == 1
    last = run.stderr.strip().splitlines()[-1]
    assert last.startswith("RuntimeError: pyspline.local_dask_client: the Dask worker processes "
                           "did not start"), last
    assert 'if __name__ == "__main__":' in last and "processes=False" in last
    # the worker process was stopped by pyspline's own test, before it started processes
    assert "local_dask_client was called while a Dask worker process imported" in run.stderr


def test_dask_worker_processes_from_a_script_on_stdin(tmp_path):
    """Worker processes import the main script, which a script read from standard input does
    not have as a file: a clear error at once, before any process starts."""
    pytest.importorskip("distributed")
    run = subprocess.run([sys.executable, "-"], input="import pyspline\n"
                         "pyspline.local_dask_client(2)\n", capture_output=True, text=True,
                         timeout=120, cwd=tmp_path)        # not the source tree's pyspline/
    assert run.returncode == 1
    last = run.stderr.strip().splitlines()[-1]
    assert last.startswith("RuntimeError: pyspline.local_dask_client: worker processes start by "
                           "importing the script"), last
    assert "<stdin> is not a file" in last and "processes=False" in last
    assert "Nanny" not in run.stderr                    # nothing was started


def test_task_points():
    """Four tasks per worker, within 1 .. MAX_TASK_POINTS points each; the tasks cover the
    sweep."""
    cap = sw.MAX_TASK_POINTS
    for n, workers in [(1, 2), (7, 2), (24, 2), (100, 3), (1000, 2), (5, 64)]:
        size = sw.task_points(n, workers)
        assert 1 <= size <= cap
        tasks = -(-n // size)
        assert tasks >= min(n, 4 * workers)                  # work for every worker
        assert size == cap or tasks <= 4 * workers           # no smaller than that needs


def test_tasks_cover_every_point_once(case):
    """On a process pool without `chunk`, tasks of task_points(n, workers) points: every point
    runs exactly once, with the serial numbers."""
    seen = []

    class Recording(cf.ProcessPoolExecutor):
        def submit(self, fn, *args, **kwargs):
            seen.append(len(args[0]))
            return super().submit(fn, *args, **kwargs)

    values = np.linspace(0.0, 2e-4, 24)
    serial = pyspline.sweep(case, progress=False, l_x=values)
    with Recording(2) as pool:
        ds = pyspline.sweep(case, executor=pool, workers=2, progress=False, l_x=values)
    assert seen == [sw.task_points(24, 2)] * 8 == [3] * 8
    assert ds.attrs["n_ok"] == 24
    _same(serial, ds)


# --------------------------------------------------------------------------- spectrum

def test_binned_spectrum_keeps_tone_heights():
    rpm, z = 6000.0, 16
    t = np.arange(2000) / 10000.0                    # 0.2 s: 20 revolutions
    f1 = rpm / 60
    x = 3.0 + 1.5 * np.sin(2 * np.pi * f1 * t) + 0.25 * np.sin(2 * np.pi * z * f1 * t)
    axis = sw._default_orders([pyspline.load_case({})])
    assert axis[0] == 0 and axis[-1] == pytest.approx(2 * z + 2)
    a = summary._binned_spectrum(t, x, rpm, axis)
    assert a[np.argmin(abs(axis - 1))] == pytest.approx(1.5, rel=1e-9)
    assert a[np.argmin(abs(axis - z))] == pytest.approx(0.25, rel=1e-9)
    assert np.nanmax(a[(axis > 1.5) & (axis < 15)]) < 1e-3


def test_speed_sweep_has_order_spectrum(case):
    ds = pyspline.sweep(case, progress=False, speed_rpm=[3000.0, 6000.0])
    assert ds["Tm_spectrum"].dims == ("speed_rpm", "order")
    assert ds["order"][-1] == pytest.approx(2 * case["z"] + 2)
    dt = (case["t_end"] - case["t_transient"]) / (case["n_out"] - 1)
    f_top = np.fft.rfftfreq(case["n_out"], dt)[-1]          # highest FFT line (~ Nyquist)
    for rpm in (3000.0, 6000.0):
        a = ds["Tm_spectrum"].sel(speed_rpm=rpm)
        below = ds["order"] <= f_top / (rpm / 60) + 0.025       # up to its bin
        assert np.isfinite(a[below]).all() and np.isnan(a[~below]).all()


def test_parse_values():
    np.testing.assert_array_equal(sw.parse_values("l_x", "0:3e-4:61"), np.linspace(0, 3e-4, 61))
    np.testing.assert_array_equal(sw.parse_values("t_d", "10,20,30"), [10.0, 20.0, 30.0])
    assert sw.parse_values("n_out", "101:201:3").dtype.kind == "i"
    assert list(sw.parse_values("thermal", "none,bulk")) == ["none", "bulk"]
    assert list(sw.parse_values("roots", ".true.,false")) == [True, False]
    with pytest.raises(pyspline.CaseError, match="unknown field"):
        sw.parse_values("nope", "1,2")
    with pytest.raises(pyspline.CaseError, match="not a number"):
        sw.parse_values("t_d", "ten")


# --------------------------------------------------------------------------- command line

def test_cli_sweep_and_plot(case, tmp_path, capsys):
    from pyspline.cli import main
    path = tmp_path / "short.nml"
    case.replace(name="short").to_namelist(path)
    out = tmp_path / "speed"
    assert main(["sweep", str(path), "--set", "speed_rpm=3000,6000,9000", "--lyapunov",
                 "--workers", "2", "--threads", "--out", str(out), "--quiet"]) == 0
    printed = capsys.readouterr().out
    for name in ("sweep.nc", "bifurcation.png", "lyapunov.png", "waterfall.png"):
        assert (out / name).is_file() and str(out / name) in printed
        if name.endswith(".png"):
            _png(out / name)
    ds = pyspline.open_sweep(out)
    assert ds.sizes["speed_rpm"] == 3 and ds.attrs["command"].startswith("pyspline sweep ")

    out = tmp_path / "grid"
    assert main(["sweep", str(path), "--set", "l_x=0,2e-4", "--set", "t_d=20,40",
                 "--out", str(out), "--quiet"]) == 0
    _png(out / "bifurcation.png")
    _png(out / "period_map.png")
    assert not (out / "waterfall.png").exists() and not (out / "lyapunov.png").exists()

    assert main(["plot", str(path), "--out", str(tmp_path / "scene")]) == 0
    _png(tmp_path / "scene" / "short.png")
    assert str(tmp_path / "scene" / "short.png") in capsys.readouterr().out

    assert main(["sweep", str(path), "--set", "lx=0,1", "--out", str(out)]) == 2
    assert "unknown field" in capsys.readouterr().err


def test_cli_help_says_what_it_writes(capsys):
    from pyspline.cli import main
    with pytest.raises(SystemExit) as e:
        main(["sweep", "--help"])
    assert e.value.code == 0
    text = capsys.readouterr().out
    for word in ("sweep.nc", "bifurcation.png", "lyapunov.png", "waterfall.png", "points/",
                 "start:stop:num"):
        assert word in text


# --------------------------------------------------------------------------- Result

def test_result_to_xarray_roundtrip(case, tmp_path):
    res = pyspline.simulate(case.replace(section="shaft", lyapunov=True))
    names = dir(res)
    for n in ["F", "D2", "vD2", "Tm", "kv", "x1", "vD3"] + [n for n, *_ in _names("tooth")]:
        assert n in names
    assert res.F is res.tooth["F"]
    np.testing.assert_array_equal(res.vD2, res.y[:, 12])
    ds = res.to_xarray()
    z = case["z"]
    assert ds["F"].dims == ("time", "tooth") and ds["F"].shape == (201, z)
    assert ds["D2"].dims == ("time",) and ds["section_D2"].dims == ("section_point",)
    assert ds["F"].attrs["units"] == "N" and ds["vD2"].attrs["units"] == "m/s"
    assert ds["Tf"].attrs["units"] == "degC" and ds["time"].attrs["units"] == "s"
    assert ds.attrs["case"] == res.case.text()
    assert ds.attrs["stat_steps"] == res.stats["steps"]
    assert ds.attrs["lyapunov_exponent"] == res.lyapunov["exponent"]
    np.testing.assert_array_equal(ds["section_D2"], res.section_y[:, 5])
    path = tmp_path / "run.nc"
    ds.to_netcdf(path, engine="netcdf4")
    with xr.open_dataset(path, engine="netcdf4") as back:
        xr.testing.assert_identical(back.load(), ds)


# --------------------------------------------------------------------------- bad input, empty sweeps

def test_design_table_with_a_byte_order_mark_and_bad_cells_named(tmp_path):
    """Excel's "CSV UTF-8" starts with a byte-order mark: its first field is read as such; a
    cell that is no value names the table's path."""
    table = tmp_path / "excel.csv"
    table.write_text("l_x,t_d\n0,30\n1e-4,20\n", encoding="utf-8-sig")
    assert table.read_bytes()[:3] == b"\xef\xbb\xbf"
    cols = sw.read_table(table)
    assert list(cols) == ["l_x", "t_d"] and cols["l_x"].tolist() == [0.0, 1e-4]
    table.write_text("l_x\nwide\n")
    with pytest.raises(pyspline.CaseError, match=rf"design table {table}: field l_x: 'wide'"):
        sw.read_table(table)


def test_open_sweep_refuses_what_is_no_sweep_naming_the_path(tmp_path):
    """A continuation.nc (or any other netCDF), a damaged file and a missing one: CaseError
    with the path, never a raw netCDF4 error."""
    other = tmp_path / "continuation.nc"
    xr.Dataset({"Tm_pp": ("point", np.arange(3.0))}, attrs={"field": "speed_rpm"}).to_netcdf(
        other, engine="netcdf4")
    with pytest.raises(pyspline.CaseError, match=f"{other} is no sweep of pyspline"):
        pyspline.open_sweep(other)
    damaged = tmp_path / "d" / "sweep.nc"
    damaged.parent.mkdir()
    damaged.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(200))
    with pytest.raises(pyspline.CaseError, match=f"{damaged} cannot be read as a sweep"):
        pyspline.open_sweep(damaged.parent)
    with pytest.raises(pyspline.CaseError, match=f"{tmp_path / 'none'} is no file"):
        pyspline.open_sweep(tmp_path / "none")


def test_sweep_of_failed_points_writes_its_dataset_and_no_plot_crashes(tmp_path):
    """speed_rpm = nan, nan: every point fails; the dataset is written, no figure is drawn (none
    ran), exit 0 (failed cases are results). With one good speed beside a bad one, the
    waterfall draws the speed that ran."""
    from pyspline.cli import main
    args = [str(CASES / "paper_lx1e-4.nml"), "--fix", "t_end=0.05", "--fix", "n_out=401",
            "--quiet"]
    assert main(["sweep", *args, "--set", "speed_rpm=nan,nan", "--out", str(tmp_path / "a")]) == 0
    ds = pyspline.open_sweep(tmp_path / "a")
    assert ds.attrs["n_failed"] == 2 and (ds["error_class"] == "CaseError").all()
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == ["points", "sweep.nc"]
    assert main(["sweep", *args, "--set", "speed_rpm=-5,6000", "--out", str(tmp_path / "b")]) == 0
    assert pyspline.open_sweep(tmp_path / "b").attrs["n_ok"] == 1
    _png(tmp_path / "b" / "waterfall.png")


def test_fix_takes_array_fields():
    """--fix ripple_amp=0.1,0,0,0 sets the array; a per-tooth list may be shorter; a scalar
    field still takes one value."""
    from pyspline.cli import _fixed
    fixed = _fixed(["ripple_amp=0.1,0,0,0", "spacing_error=1e-6,-1e-6"])
    assert fixed["ripple_amp"] == [0.1, 0.0, 0.0, 0.0]
    case = pyspline.load_case(CASES / "paper_lx1e-4.nml", **fixed)
    assert case["ripple_amp"] == [0.1, 0.0, 0.0, 0.0]
    assert case["spacing_error"][:3] == [1e-6, -1e-6, 0.0]
    with pytest.raises(pyspline.CaseError, match="one value expected"):
        _fixed(["l_x=0,1e-4"])


def test_to_xarray_carries_the_sliced_face():
    """n_slices > 1: face (time, tooth, slice) and tilt (time, moment) as the Result has them."""
    res = pyspline.simulate(pyspline.load_case(CASES / "physical_tilt.nml", t_end=0.01,
                                               n_out=11))
    ds = res.to_xarray()
    assert ds["face"].dims == ("time", "tooth", "slice") and ds["face"].attrs["units"] == "N"
    assert np.array_equal(ds["face"].values, res.face) and ds.sizes["slice"] == 8
    assert np.array_equal(ds["tilt"].values, res.tilt) and ds["tilt"].attrs["units"] == "N m"
    assert ds["moment"].values.tolist() == ["M_x", "M_y"]


@pytest.mark.parametrize("command", [
    ["run", "CASE"], ["sweep", "CASE", "--set", "l_x=0,1e-4"], ["merge", "x.summary"],
    ["continue", "CASE", "--field", "speed_rpm", "--start", "10", "--stop", "20"],
    ["sweep", "CASE", "--set", "l_x=0,1e-4", "--follow", "up"], ["plot", "CASE"]])
def test_every_writing_command_checks_its_out_before_running(tmp_path, monkeypatch, capsys,
                                                           command):
    """--out onto a file, or under one (a path that cannot be made): exit 2 naming the path,
    before anything is read or run."""
    from pyspline import cli
    def never(*a, **k):
        raise AssertionError("ran before the output was checked")
    monkeypatch.setattr(cli, "load_case", never)
    monkeypatch.setattr(cli, "sweep", never)
    monkeypatch.setattr(pyspline.core, "simulate", never)
    monkeypatch.setattr(sys.modules["pyspline.batch"], "merge", never)
    monkeypatch.setattr(sys.modules["pyspline.arclength"], "continuation", never)
    afile = tmp_path / "afile"
    afile.write_text("mine\n")
    argv = [str(CASES / "paper_lx1e-4.nml") if a == "CASE" else a for a in command]
    for out, why in ((afile, "exists and is not a directory"),
                     (afile / "sub", f"cannot be made: {afile} is not a directory")):
        assert cli.main([*argv, "--out", str(out)]) == 2
        assert f"--out {out}: {why}" in capsys.readouterr().err
    assert afile.read_text() == "mine\n"
