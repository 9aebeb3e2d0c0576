"""The input corpus (tests/corpus/manifest.json): malformed, hostile and edge-case inputs, each
with the outcome it must produce.

Entry kinds:
- "file": tests/corpus/<file>, read with pyspline.load_case and run with pyspline.simulate;
- "dict": a dict of fields (JSON; tagged values are decoded, see `decode`), same calls;
- "special": a path built at run time in tmp_path (directory, FIFO, device, long path, ...),
  named by "make" (and "make_args"), same calls;
- "exe_args": the spline-dyn executable with "args" ({corpus}, {tmp}, {case} are filled in).

Expectations: "CaseError" | "SolverError" | "ThermalInterferenceError" (the exception class, and
str(exc) contains every "mentions" substring, case-insensitive), "ok" (runs; every output is
finite), "warning" (runs, finite outputs, and a pyspline.SplineWarning whose message contains the
mentions). An entry may carry "alt": {"expect", "mentions"}, a second acceptable error outcome
where two designs are both defensible (listed with "unsure": why).

A hang fails: each Python entry runs under signal.alarm(TIMEOUT_S) (restored afterwards) and
must finish within TIMEOUT_S; a hang inside compiled code, where no Python signal handler can
run, is ended by faulthandler after 2 TIMEOUT_S + 10 s (it dumps the stacks and exits pytest),
and a FIFO has a writer process that unblocks a stuck reader after TIMEOUT_S. Executable entries
run with subprocess's timeout.
"""
from __future__ import annotations

import contextlib
import faulthandler
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from conftest import PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

#: Exit status of spline-dyn for each outcome. The one place to adjust them.
EXIT_CODES = {"CaseError": 2, "SolverError": 3, "ThermalInterferenceError": 4, "ok": 0, "usage": 2}

TIMEOUT_S = 30
CORPUS = Path(__file__).resolve().parent / "corpus"
MANIFEST = json.loads((CORPUS / "manifest.json").read_text(encoding="utf-8"))

ERRORS = ("CaseError", "SolverError", "ThermalInterferenceError")
PY_KINDS = ("file", "dict", "special")
CLASSES = ("syntax", "overflow", "magnitude", "cross_field", "nonfinite_thermal", "runaway",
           "valid_accept", "not_a_file", "executable")
MAKERS = ("directory", "device", "fifo", "missing", "dangling_symlink", "symlink_loop",
          "random_bytes", "sparse_nul", "long_path", "copy_as")
STOP_RE = re.compile(r"\bSTOP\b")          # gfortran's "STOP 1" / "ERROR STOP" noise

PY_ENTRIES = [e for e in MANIFEST if e["kind"] in PY_KINDS]
EXE_ENTRIES = [e for e in MANIFEST if e["kind"] == "exe_args"]


def _pyspline():
    import pyspline            # imported here so that the manifest check runs without the build
    return pyspline


# ------------------------------------------------------------------------------ building inputs

def decode(v):
    """JSON value -> Python value. Tags: {"__np__": dtype, "value": v} (a numpy scalar, or an
    array if v is a list), {"__float__": "nan"|"inf"|"-inf"}, {"__int__": "digits"} (a Python
    int of any size), {"__complex__": [re, im]}, {"__tuple__": [...]}."""
    if isinstance(v, list):
        return [decode(x) for x in v]
    if isinstance(v, dict):
        if "__np__" in v:
            dtype = np.dtype(v["__np__"])
            value = decode(v["value"])
            return np.array(value, dtype=dtype) if isinstance(value, list) else dtype.type(value)
        if "__float__" in v:
            return float(v["__float__"])
        if "__int__" in v:
            return int(v["__int__"])
        if "__complex__" in v:
            return complex(*v["__complex__"])
        if "__tuple__" in v:
            return tuple(decode(x) for x in v["__tuple__"])
        raise ValueError(f"unknown tagged value {v!r}")
    return v


_UNBLOCK_FIFO = """
import os, sys, time
path, delay = sys.argv[1], float(sys.argv[2])
time.sleep(delay)
while True:          # a reader stuck in open() gets a writer, then EOF; until the test kills us
    try:
        os.close(os.open(path, os.O_WRONLY | os.O_NONBLOCK))
    except OSError:
        pass
    time.sleep(0.5)
"""


def make_special(make: str, args: dict, tmp: Path, stack: contextlib.ExitStack) -> Path:
    """Build the input a "special" entry names, in tmp; returns the path to hand over."""
    if make == "directory":
        path = tmp / "a_directory.nml"
        path.mkdir()
    elif make == "device":
        path = Path(args["path"])
        if not path.exists():
            pytest.skip(f"{path} does not exist on this system")
    elif make == "fifo":
        path = tmp / "case_fifo.nml"
        os.mkfifo(path)
        writer = subprocess.Popen([sys.executable, "-c", _UNBLOCK_FIFO, str(path), str(TIMEOUT_S + 2)])

        def stop_writer():
            writer.kill()
            writer.wait()
        stack.callback(stop_writer)
    elif make == "missing":
        path = tmp / "no_such_case.nml"
    elif make == "dangling_symlink":
        path = tmp / "dangling.nml"
        path.symlink_to(tmp / "gone.nml")
    elif make == "symlink_loop":
        path = tmp / "loop_a.nml"
        path.symlink_to(tmp / "loop_b.nml")
        (tmp / "loop_b.nml").symlink_to(path)
    elif make == "random_bytes":
        path = tmp / "random_bytes.nml"
        path.write_bytes(random.Random(args["seed"]).randbytes(args["size"]))
    elif make == "sparse_nul":
        path = tmp / "sparse_nul.nml"
        with open(path, "wb") as f:
            f.truncate(args["size"])
    elif make == "long_path":
        directory = tmp
        name = "long_case.nml"
        while len(str(directory)) + 1 + len(name) < args["length"]:
            need = args["length"] - len(str(directory)) - 2 - len(name)
            directory = directory / ("d" * max(1, min(200, need)))
        directory.mkdir(parents=True, exist_ok=True)
        path = directory / name
        shutil.copyfile(CORPUS / args["src"], path)
        assert len(str(path)) >= args["length"], len(str(path))
    elif make == "copy_as":
        path = tmp / args["dest"]
        shutil.copyfile(CORPUS / args["src"], path)
    else:
        raise ValueError(f"unknown construction {make!r}")
    return path


def source_of(entry: dict, tmp: Path, stack: contextlib.ExitStack):
    """What pyspline.load_case gets for a Python entry."""
    if entry["kind"] == "file":
        return str(CORPUS / entry["file"])
    if entry["kind"] == "dict":
        return {k: decode(v) for k, v in entry["fields"].items()}
    return str(make_special(entry["make"], entry.get("make_args", {}), tmp, stack))


# ------------------------------------------------------------------------------------- guards

class CorpusTimeout(BaseException):
    """Raised by SIGALRM. A BaseException, so that a reader's `except Exception` cannot turn a
    hang into an ordinary CaseError."""


@contextlib.contextmanager
def time_limit(what: str):
    """signal.alarm(TIMEOUT_S) for the block (the previous handler and alarm restored after),
    and a faulthandler watchdog for hangs in compiled code that no Python handler can end."""
    if not hasattr(signal, "SIGALRM") or threading.current_thread() is not threading.main_thread():
        yield
        return

    def on_alarm(signum, frame):
        raise CorpusTimeout(f"{what}: did not finish within {TIMEOUT_S} s (a hang or a runaway run)")

    previous = signal.signal(signal.SIGALRM, on_alarm)
    pending = signal.alarm(TIMEOUT_S)
    start = time.monotonic()
    watchdog = sys.__stderr__ is not None
    if watchdog:
        faulthandler.dump_traceback_later(2 * TIMEOUT_S + 10, exit=True, file=sys.__stderr__)
    try:
        yield
    finally:
        signal.alarm(0)
        if watchdog:
            faulthandler.cancel_dump_traceback_later()
        signal.signal(signal.SIGALRM, previous)
        if pending:
            signal.alarm(max(1, pending - int(time.monotonic() - start)))


# ------------------------------------------------------------------------------------- checks

def _msg_has(text: str, mentions) -> list:
    low = text.lower()
    return [m for m in mentions if m.lower() not in low]


def _outputs(res) -> dict:
    arrays = {"res.t": res.t, "res.y": res.y, "res.Tm": res.Tm}
    arrays.update({f"res.tooth[{k!r}]": v for k, v in res.tooth.items()})
    return arrays


def assert_finite(eid: str, res) -> None:
    assert np.size(res.t) > 0, f"{eid}: the run returned no output times"
    for name, a in _outputs(res).items():
        a = np.asarray(a, dtype=float)
        bad = ~np.isfinite(a)
        if bad.any():
            first = np.argwhere(bad)[0].tolist()
            pytest.fail(f"{eid}: {name} has {int(bad.sum())} non-finite values of {a.size} "
                        f"(first at index {first}: {a[tuple(first)]!r}); a run must never return "
                        "NaN/Inf silently")


def assert_checks(eid: str, entry: dict, res) -> None:
    check = entry.get("check", {})
    if "nt" in check:
        assert len(res.t) == check["nt"], \
            f"{eid}: expected {check['nt']} output times, got {len(res.t)} (a field was not honoured)"
    if "nteeth" in check:
        for name, a in res.tooth.items():
            assert np.shape(a)[1] == check["nteeth"], \
                f"{eid}: res.tooth[{name!r}] has {np.shape(a)[1]} teeth, expected {check['nteeth']}"


def run_case(source):
    ps = _pyspline()
    return ps.simulate(ps.load_case(source))


def attempt(source):
    """(result, None) if the case ran, (None, exception) if it raised."""
    try:
        return run_case(source), None
    except Exception as exc:            # any exception class is judged by the caller
        return None, exc


def judge_error(entry: dict, exc: BaseException | None) -> None:
    eid = entry["id"]
    ps = _pyspline()
    options = [(entry["expect"], entry["mentions"])]
    if "alt" in entry:
        options.append((entry["alt"]["expect"], entry["alt"]["mentions"]))
    wanted = " or ".join(e for e, _ in options)
    if exc is None:
        pytest.fail(f"{eid}: expected {wanted}, but the case was accepted and ran ({entry['why']})")
    for expect, mentions in options:
        cls = getattr(ps, expect, None)
        assert cls is not None, f"{eid}: pyspline has no exception class {expect}"
        if isinstance(exc, cls):
            missing = _msg_has(str(exc), mentions)
            assert not missing, (f"{eid}: {type(exc).__name__} raised as expected, but its message "
                                 f"lacks {missing}: {str(exc)!r}")
            return
    pytest.fail(f"{eid}: expected {wanted}, got {type(exc).__module__}.{type(exc).__name__}: "
                f"{exc} ({entry['why']})")


# -------------------------------------------------------------------------------------- tests

def test_manifest_is_complete():
    """Every entry has the keys its kind needs; every corpus file is used; every issue class is
    covered, and at least a third of the entries must be accepted (ok or warning)."""
    ids = [e["id"] for e in MANIFEST]
    assert len(ids) == len(set(ids)), "duplicate ids"
    used = set()
    for e in MANIFEST:
        eid = e.get("id")
        for key in ("id", "kind", "expect", "mentions", "class", "why"):
            assert key in e, f"{eid}: missing key {key}"
        assert isinstance(e["mentions"], list) and all(isinstance(m, str) and m for m in e["mentions"]), eid
        assert e["class"] in CLASSES, f"{eid}: class {e['class']}"
        assert isinstance(e["why"], str) and e["why"] and "\n" not in e["why"], eid
        if e["kind"] == "exe_args":
            assert e["expect"] in EXIT_CODES, f"{eid}: expect {e['expect']}"
            assert isinstance(e["args"], list), eid
            used |= {a.split("/")[-1] for a in e["args"] if a.startswith("{corpus}/")}
            used |= {op["copy"][0] for op in e.get("setup", []) if "copy" in op}
        else:
            assert e["kind"] in PY_KINDS, f"{eid}: kind {e['kind']}"
            assert e["expect"] in ERRORS + ("ok", "warning"), f"{eid}: expect {e['expect']}"
        if e["kind"] == "file":
            assert (CORPUS / e["file"]).is_file(), f"{eid}: {e['file']} is missing"
            used.add(e["file"])
        if e["kind"] == "dict":
            assert isinstance(e["fields"], dict), eid
            for value in e["fields"].values():
                decode(value)
        if "make" in e:
            assert e["make"] in MAKERS, f"{eid}: make {e['make']}"
            if "src" in e.get("make_args", {}):
                used.add(e["make_args"]["src"])
        if "alt" in e:
            assert e["expect"] in ERRORS and e["alt"]["expect"] in ERRORS, f"{eid}: alt is for errors"
            assert "unsure" in e, f"{eid}: an alt needs the reason (unsure)"
        if e["expect"] in ("ok", "warning") and e["kind"] != "exe_args":
            assert e["mentions"] == [] or e["expect"] == "warning", eid
    files = {p.name for p in CORPUS.iterdir() if p.suffix == ".nml"}
    assert files <= used, f"corpus files no entry uses: {sorted(files - used)}"
    assert set(CLASSES) == {e["class"] for e in MANIFEST}
    accepted = sum(e["expect"] in ("ok", "warning") for e in MANIFEST)
    assert 3 * accepted >= len(MANIFEST), f"only {accepted} of {len(MANIFEST)} entries must be accepted"


@pytest.mark.parametrize("entry", PY_ENTRIES, ids=[e["id"] for e in PY_ENTRIES])
def test_python_api(entry, tmp_path):
    """pyspline.load_case + pyspline.simulate give the outcome the manifest states."""
    ps = _pyspline()
    eid, expect = entry["id"], entry["expect"]
    start = time.monotonic()
    with contextlib.ExitStack() as stack:
        source = source_of(entry, tmp_path, stack)
        try:
            with time_limit(eid):
                if expect == "warning":
                    warning_cls = getattr(ps, "SplineWarning", None)
                    if warning_cls is None:
                        pytest.fail(f"{eid}: pyspline.SplineWarning does not exist (needed for "
                                    "'warn, do not refuse' cases)")
                    with pytest.warns(warning_cls) as record:
                        res, exc = attempt(source)
                        if exc is not None:
                            pytest.fail(f"{eid}: expected a SplineWarning and a run, got "
                                        f"{type(exc).__name__}: {exc}")
                else:
                    res, exc = attempt(source)
        except CorpusTimeout as timeout:
            pytest.fail(str(timeout))
    elapsed = time.monotonic() - start
    assert elapsed < TIMEOUT_S, (f"{eid}: took {elapsed:.1f} s (limit {TIMEOUT_S} s): a hang or a "
                                 "runaway run (for a FIFO: ended by the test's writer)")

    if expect in ERRORS:
        judge_error(entry, exc)
        return
    if exc is not None:
        pytest.fail(f"{eid}: must be accepted and run ({entry['why']}), got "
                    f"{type(exc).__name__}: {exc}")
    if expect == "warning":
        messages = [str(w.message) for w in record if issubclass(w.category, warning_cls)]
        assert any(not _msg_has(m, entry["mentions"]) for m in messages), \
            f"{eid}: no SplineWarning mentions {entry['mentions']}; got {messages}"
    assert_finite(eid, res)
    assert_checks(eid, entry, res)


def _spline_dyn() -> str:
    path = os.environ.get("SPLINE_DYN") or shutil.which("spline-dyn")
    if not path:
        pytest.fail("spline-dyn is not on PATH (pip install . installs it; or set SPLINE_DYN)")
    return path


def _apply_setup(op: dict, tmp: Path) -> None:
    if "write" in op:
        name, text = op["write"]
        (tmp / name).write_text(text)
    elif "copy" in op:
        src, name = op["copy"]
        shutil.copyfile(CORPUS / src, tmp / name)
    elif "mkdir" in op:
        (tmp / op["mkdir"]).mkdir(parents=True)
    else:
        raise ValueError(f"unknown setup step {op!r}")


def _csv_rows(eid: str, path: Path) -> int:
    lines = [ln for ln in path.read_text().splitlines() if ln.strip() and not ln.startswith("#")]
    assert lines, f"{eid}: {path} has no header row"
    ncol = len(lines[0].split(","))
    rows = lines[1:]
    for k, row in enumerate(rows):
        cells = row.split(",")
        assert len(cells) == ncol, f"{eid}: row {k} of {path} has {len(cells)} cells, header {ncol}"
        values = np.array([float(c) for c in cells])
        assert np.isfinite(values).all(), f"{eid}: row {k} of {path} has non-finite values"
    return len(rows)


@pytest.mark.parametrize("entry", EXE_ENTRIES, ids=[e["id"] for e in EXE_ENTRIES])
def test_executable(entry, tmp_path):
    """spline-dyn: the exit status of the outcome (EXIT_CODES), messages on stderr, no STOP
    noise, and the output-file rules (refused before the run, atomic, never the case file)."""
    exe = _spline_dyn()
    eid, expect = entry["id"], entry["expect"]
    subst = {"{corpus}": str(CORPUS), "{tmp}": str(tmp_path)}

    def fill(text: str) -> str:
        for key, value in subst.items():
            text = text.replace(key, value)
        return text

    with contextlib.ExitStack() as stack:
        if "make" in entry:
            subst["{case}"] = str(make_special(entry["make"], entry.get("make_args", {}),
                                               tmp_path, stack))
        for op in entry.get("setup", []):
            _apply_setup(op, tmp_path)
        args = [fill(a) for a in entry["args"]]
        before = {p: Path(fill(p)).read_bytes() for p in entry.get("unchanged", [])}
        try:
            run = subprocess.run([exe, *args], cwd=tmp_path, capture_output=True,
                                 stdin=subprocess.DEVNULL, timeout=TIMEOUT_S)
        except subprocess.TimeoutExpired:
            pytest.fail(f"{eid}: spline-dyn {' '.join(args)} did not finish within {TIMEOUT_S} s")
    out = run.stdout.decode("utf-8", "replace")
    err = run.stderr.decode("utf-8", "replace")
    report = (f"\n  command: spline-dyn {' '.join(args)}\n  exit status: {run.returncode}"
              f"\n  stdout: {out[-1500:]!r}\n  stderr: {err[-1500:]!r}")

    code = EXIT_CODES[expect]
    assert run.returncode == code, f"{eid}: expected exit {code} ({expect}), got {run.returncode}{report}"
    assert not STOP_RE.search(out + err), f"{eid}: Fortran STOP noise in the output{report}"
    if expect == "ok":
        missing = _msg_has(out + err, [fill(m) for m in entry["mentions"]])
    else:
        assert err.strip(), f"{eid}: an error must be reported on stderr{report}"
        missing = _msg_has(err, [fill(m) for m in entry["mentions"]])
    assert not missing, f"{eid}: the output lacks {missing}{report}"
    if entry.get("mentions_version"):
        version = _pyspline().__version__
        assert version in out + err, f"{eid}: the version {version} is not printed{report}"
    for p in entry.get("creates", []):
        assert Path(fill(p)).is_file(), f"{eid}: {fill(p)} was not written{report}"
    if "csv_rows" in entry:
        path = Path(fill(entry["creates"][0]))
        rows = _csv_rows(eid, path)
        assert rows == entry["csv_rows"], f"{eid}: {path} has {rows} data rows, expected {entry['csv_rows']}"
    for p, content in before.items():
        assert Path(fill(p)).read_bytes() == content, f"{eid}: {fill(p)} was modified{report}"
    for p in entry.get("absent", []):
        assert not Path(fill(p)).exists(), f"{eid}: {fill(p)} must not be written{report}"
    if "only_files" in entry:
        left = sorted(os.listdir(tmp_path))
        assert left == sorted(entry["only_files"]), \
            f"{eid}: files left in the output directory {left}, expected {sorted(entry['only_files'])} " \
            "(a temporary or partial file was left behind: the CSV must be written atomically)"
