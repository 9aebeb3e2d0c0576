"""The reentrant core (issue 10): loaded cases never alias, scenes run in parallel threads with
the same numbers as serially, the GIL is released during a run, SIGINT stops a long run, and
case names may hold any characters."""
import concurrent.futures as cf
import re
import subprocess
import os
import pickle
import random
import signal
import threading
import time

import numpy as np
import pytest

import pyspline
from conftest import CASES, PAPER, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

SHORT = dict(t_end=0.02, n_out=81)
SCENES = {   # one of each: mechanical, coupled flash temperature, a mid-run failure, Z = 7
    "lx1e-4": pyspline.load_case(CASES / "paper_lx1e-4.nml", **SHORT),
    "T100 coupled": pyspline.load_case(CASES / "paper_T100.nml", **SHORT),
    "runaway": pyspline.load_case(dict(PAPER, name="runaway", l_x=1e-4, start="rest",
                                       thermal="coupled", t_bulk=3000.0, f_m=1e5, t_end=0.1,
                                       n_out=641)),
    "physical z7": pyspline.load_case(CASES / "physical_lx1e-4.nml", z=7, name="physical z7",
                                      **SHORT),
}
TIMING = ("wall_s", "core_wall_s")


def outcome(case):
    """Everything a run returns (arrays, statistics but the timings), or its error."""
    try:
        r = pyspline.simulate(case)
    except pyspline.SplineError as exc:
        return (type(exc).__name__, str(exc))
    stats = {k: v for k, v in r.stats.items() if k not in TIMING}
    return (r.t, r.y, r.Tm, {k: v.copy() for k, v in r.tooth.items()}, stats)


def same(a, b):
    if isinstance(a[0], str):
        return a == b
    return (all(np.array_equal(x, y) for x, y in zip(a[:3], b[:3]))
            and all(np.array_equal(a[3][k], b[3][k]) for k in a[3]) and a[4] == b[4])


def test_scenes_in_threads_equal_serial_runs():
    with pytest.warns(pyspline.SplineWarning, match=r"case runaway: start = 'rest' with l_x = "
                      r"1\.000E-04, .* overlapping its backlash"):   # its hot, closed backlash
        serial = {name: outcome(c) for name, c in SCENES.items()}
    assert serial["runaway"][0] == "ThermalInterferenceError"
    assert "tooth" in serial["runaway"][1]
    assert serial["T100 coupled"][4]["coupling_iterations"] > 0       # the coupled level ran
    jobs = [name for name in SCENES for _ in range(6)]
    random.Random(1).shuffle(jobs)
    with cf.ThreadPoolExecutor(4) as pool:
        results = list(pool.map(lambda n: (n, outcome(SCENES[n])), jobs))
    for name, res in results:
        assert same(res, serial[name]), name


def test_cases_load_in_parallel_threads():
    """Two threads parsing and loading cases at once (api_load_text, like api_load_file, runs
    with the GIL released) get exactly the models a lone load gives, and no error. libgfortran's
    reads from internal files are not thread-safe; without the core's lock (fortran/interface/iolock.c)
    6400 such loads gave 12 refusals and 4 silently different models. A model is compared by
    what it says (its sizes, derived quantities and right-hand side): the padding between the
    components of its bytes is not defined."""
    from pyspline import core
    base = pyspline.load_case(CASES / "paper_lx1e-4.nml")
    texts = [base.replace(l_x=v, n_out=801 + i, name=f"p{i}").text().encode()
             for i, v in enumerate(np.linspace(0.0, 3e-4, 40))]
    y = base.model.start_state()

    def said(model, sizes):
        info, terms, spacing, ierr, msg = pyspline.bridge._api.api_model_info(model, base.model.z)
        ydot, ierr2 = pyspline.bridge._api.api_rhs(model, 1e-3, y)
        return (sizes.tolist(), info.tolist(), terms.tolist(), spacing.tolist(), ydot.tolist(),
                int(ierr), int(ierr2))

    alone = [said(*pyspline.bridge._api.api_load_text(t, pyspline.bridge.MODEL_BYTES)[:2]) for t in texts]
    bad = []

    def load_all(first):
        for _ in range(100):
            for i in range(first, len(texts), 2):
                model, sizes, warn, ierr, msg = pyspline.bridge._api.api_load_text(texts[i], pyspline.bridge.MODEL_BYTES)
                if ierr or sizes[1] != 801 + i or said(model, sizes) != alone[i]:
                    bad.append((i, int(ierr), bytes(msg).decode(errors="replace").strip()))

    threads = [threading.Thread(target=load_all, args=(k,)) for k in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert bad == []


def test_loaded_cases_never_alias():
    a = pyspline.load(dict(PAPER, name="a", l_x=1e-4))
    y = a.start_state()
    before = a.rhs(1e-3, y).copy()
    b = pyspline.load(dict(PAPER, name="b", l_x=0.0, t_d=10.0))
    assert not np.array_equal(b.rhs(1e-3, y), before)
    np.testing.assert_array_equal(a.rhs(1e-3, y), before)
    np.testing.assert_array_equal(a.rhs_mesh(1e-3, y)[0], before)


def test_loaded_model_survives_pickling():
    """A loaded case is caller-owned bytes: it crosses to another process (Dask, pools)."""
    case = SCENES["lx1e-4"]
    m2 = pickle.loads(pickle.dumps(case.model))
    assert same(outcome(m2), outcome(case))
    with cf.ProcessPoolExecutor(1) as pool:
        res = pool.submit(pyspline.simulate, case.model).result()
    np.testing.assert_array_equal(res.Tm, pyspline.simulate(case).Tm)


def test_bytes_that_are_no_model_are_refused():
    m = pyspline.load(SCENES["lx1e-4"])
    bad = pickle.loads(pickle.dumps(m))
    object.__setattr__(bad, "bytes", np.zeros_like(m.bytes))
    with pytest.raises(pyspline.CaseError, match="not a loaded case"):
        pyspline.simulate(bad)


def test_heartbeat_ticks_during_a_simulate(sigint_raises, monkeypatch):
    """The GIL is released while the core runs: a heartbeat thread ticks 50 times (1 ms sleeps)
    while the core is inside a long run (LONG), then stops it with SIGINT. Counted by where the
    main thread is, not by the clock: a held GIL lets the thread run only around the core's
    call (a tick or two), the run then goes its whole length and ends without an interrupt."""
    case = pyspline.load_case(CASES / "paper_T100.nml", **LONG)
    case.model
    inside, ticks = threading.Event(), []
    core = pyspline.bridge.simulate

    def entered(*args):
        inside.set()
        try:
            return core(*args)
        finally:
            inside.clear()

    def beat():
        inside.wait()
        while len(ticks) < 50:
            time.sleep(0.001)
            if not inside.is_set():
                return
            ticks.append(1)
        os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(pyspline.bridge, "simulate", entered)
    th = threading.Thread(target=beat)
    th.start()
    with pytest.raises(KeyboardInterrupt):
        pyspline.simulate(case)
    th.join()
    assert len(ticks) == 50


@pytest.fixture
def sigint_raises():
    """SIGINT acts as in an interactive Python (KeyboardInterrupt) during the test, also when
    pytest was started with SIGINT ignored (nohup, `&` in a non-interactive shell, a batch
    system), which the core's watch respects (fortran/integration/interrupt.c)."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)


LONG = dict(t_end=60.0, n_out=3, max_steps=10**8)   # about 20 s of work (max_steps: 30 s between
# outputs): a lost SIGINT lets it finish, and the test fails by no KeyboardInterrupt


def _stopped_early(exc) -> float:
    """The simulated time a run interrupted by SIGINT stopped at (its message), checked to be
    before LONG's end: the run stopped, it did not finish."""
    t = float(re.search(r"interrupted \(SIGINT\) at t = +(\S+) s", str(exc.value)).group(1))
    assert 0 <= t < LONG["t_end"], str(exc.value)
    return t


def _sigint_inside(monkeypatch, runs=1):
    """A thread that sends SIGINT once `runs` calls have entered the core (and 0.3 s more, so
    that the core watches for it), not at a guessed time after their start."""
    entered, core = threading.Semaphore(0), pyspline.bridge.simulate

    def enter(*args):
        entered.release()
        return core(*args)

    def kill():
        for _ in range(runs):
            entered.acquire()
        time.sleep(0.3)
        os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(pyspline.bridge, "simulate", enter)
    th = threading.Thread(target=kill)
    th.start()
    return th


def test_sigint_stops_a_long_run(sigint_raises, monkeypatch):
    """A SIGINT during a run raises KeyboardInterrupt, saying the time the run stopped at, before
    its end; the core is usable afterwards, and a run without SIGINT gives the numbers of the
    same run before the interrupt (nothing of the interrupted run is left in it)."""
    before = pyspline.simulate(SCENES["lx1e-4"])
    case = pyspline.load_case(CASES / "paper_T100.nml", **LONG)
    case.model
    th = _sigint_inside(monkeypatch)
    with pytest.raises(KeyboardInterrupt, match="interrupted") as exc:
        pyspline.simulate(case)
    th.join()
    _stopped_early(exc)
    after = pyspline.simulate(SCENES["lx1e-4"])
    np.testing.assert_array_equal(after.y, before.y)
    assert after.stats["steps"] == before.stats["steps"]


def test_sigint_stops_runs_in_worker_threads(sigint_raises, monkeypatch):
    """One SIGINT stops both runs of a thread pool, each before its end."""
    case = pyspline.load_case(CASES / "paper_T100.nml", **LONG)
    case.model
    with cf.ThreadPoolExecutor(2) as pool:
        th = _sigint_inside(monkeypatch, runs=2)
        futs = [pool.submit(pyspline.simulate, case) for _ in range(2)]
        for f in futs:
            with pytest.raises(KeyboardInterrupt) as exc:
                f.result()
            _stopped_early(exc)
        th.join()


@pytest.mark.parametrize("name", ["run/one", "with spaces", "Zähne – 齿轮", "it's \"quoted\""])
def test_any_case_name(name):
    r = pyspline.simulate(dict(PAPER, name=name, t_end=1e-3, n_out=3))
    assert r.case.name == name and np.isfinite(r.Tm).all()
    with pytest.raises(pyspline.CaseError) as exc:
        pyspline.simulate(dict(PAPER, name=name, b=-1.0))
    assert f"case {name}: field b" in str(exc.value)


def test_a_name_longer_than_the_core_holds_is_refused():
    with pytest.raises(pyspline.CaseError, match="field name is longer than 128 bytes"):
        pyspline.load_case(dict(PAPER, name="ü" * 65))


def test_executable_csv_columns_are_unpadded(exe, tmp_path):
    """Every column of spline-dyn's CSV is 'NAME [UNIT]', with no padding."""
    out = tmp_path / "c.csv"
    run = subprocess.run([exe, str(CASES / "paper_ideal.nml"), "--set", "t_end=0.001",
                          "--set", "n_out=2", "-o", str(out)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    header, data = pyspline.core.read_csv(out)
    assert len(header) == data.shape[1] == 1 + 14 + 2 + 8 * 16
    for name in header:
        assert re.fullmatch(r"[A-Za-z0-9_]+ \[[^\]]*\]", name), repr(name)
