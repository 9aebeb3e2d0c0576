"""Property-based fuzzing of the input path (hypothesis): whatever a dict of fields or the text
of a case file holds, pyspline.load_case / pyspline.simulate either run (every output finite)
or raise one of pyspline's named errors (CaseError, SolverError, ThermalInterferenceError):
never another exception, a crash or a hang. And a case file the reader refuses gets the same
message from spline-dyn.

Short in CI (50 examples per test, derandomised, so every run tries the same inputs); for a
longer local search set PYSPLINE_FUZZ_EXAMPLES (e.g. 5000: random seeds, a new search each run).
Runs are kept short by the harness (t_end, n_out and max_total_steps are clamped after the
fields are drawn), so the fuzzing is of the input handling and the checks, not of long runs.
"""
from __future__ import annotations

import math
import os
import re
import subprocess
import warnings

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import pyspline  # noqa: E402
from conftest import PAPER_SHAFTS  # noqa: E402

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

EXAMPLES = int(os.environ.get("PYSPLINE_FUZZ_EXAMPLES", "0") or 0)
FUZZ = settings(max_examples=EXAMPLES or 50, deadline=None, derandomize=not EXAMPLES,
                database=None, suppress_health_check=[HealthCheck.too_slow,
                                                      HealthCheck.function_scoped_fixture])
NAMED = (pyspline.CaseError, pyspline.SolverError, pyspline.ThermalInterferenceError)
DEFAULTS = pyspline.defaults()
FIELDS = sorted(DEFAULTS)
NAMES_A_FIELD = re.compile(r"\bfield\b|\b(" + "|".join(map(re.escape, FIELDS)) + r")\b")

# ----------------------------------------------------------------------------------- values

finite_or_not = st.floats(allow_nan=True, allow_infinity=True, allow_subnormal=True)
near_default = st.sampled_from([0.0, -1.0, 1e-300, 5e-324, 1e300, -1e300, 1e-9, 1e9, 0.5, 2.0])
huge_ints = st.integers(min_value=-(2 ** 70), max_value=2 ** 70)
strings = st.text(max_size=40) | st.sampled_from(
    ["none", "bulk", "oneway", "coupled", "bdf", "adams", "newton", "fixedpoint", "equilibrium",
     "rest", "given", "auto", "shaft", "tooth", "dq", "adams           junk", "ADAMS", " bdf "])


def numpy_of(values):
    return values.flatmap(lambda v: st.sampled_from(
        [v, np.float64(v) if isinstance(v, float) else v,
         np.float32(v) if isinstance(v, float) and abs(v) < 3e38 else v]))


def value_for(name: str):
    """Values for field name: mostly of its type (hostile magnitudes), sometimes of another."""
    d = DEFAULTS[name]
    other = st.none() | st.booleans() | strings | st.lists(st.floats(), max_size=8) | huge_ints \
        | st.complex_numbers(allow_nan=False, max_magnitude=10)
    if isinstance(d, bool):
        own = st.booleans() | st.sampled_from([np.bool_(True), np.bool_(False)])
    elif isinstance(d, int):
        own = st.integers(min_value=-5, max_value=2000) | huge_ints \
            | st.integers(-10, 10).map(lambda i: float(i)) | st.sampled_from([np.int64(16), np.int32(7)])
    elif isinstance(d, float):
        scaled = st.floats(min_value=-3.0, max_value=3.0).map(lambda f: d * 10 ** f if d else f)
        own = numpy_of(finite_or_not | near_default | scaled) | huge_ints
    elif isinstance(d, list):
        own = st.lists(finite_or_not | near_default, min_size=7, max_size=7) \
            | st.lists(st.floats(-1e-5, 1e-5), min_size=0, max_size=9) \
            | st.just(np.zeros(7)) | st.just(np.full(7, np.inf))
    else:
        own = strings
    return st.one_of(own, own, own, other)


@st.composite
def case_dicts(draw):
    names = draw(st.lists(st.sampled_from(FIELDS), max_size=6, unique=True))
    fields = {n: draw(value_for(n)) for n in names}
    if draw(st.booleans()):
        key = draw(st.text(min_size=1, max_size=12) | st.sampled_from(["l_xx", "lx", "K_M", "Z"]))
        fields[key] = draw(near_default)
    return fields


def clamp(fields: dict) -> dict:
    """Keep a run short: a short window, few outputs, a small total-work bound."""
    out = dict(fields)
    out["t_end"] = 1e-3
    out.setdefault("t0", 0.0)
    if isinstance(out["t0"], (int, float)) and not isinstance(out["t0"], bool) \
            and math.isfinite(out["t0"]) and abs(out["t0"]) < 1e5:
        out["t_end"] = out["t0"] + 1e-3
    out["n_out"] = 3
    out["max_total_steps"] = 20000
    out["max_steps"] = 5000
    out["lyapunov"] = False
    return out


def check_outcome(source) -> None:
    """Runs with finite outputs, or raises a named error."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        try:
            res = pyspline.simulate(pyspline.load_case(source))
        except NAMED:
            return
    for name, a in [("t", res.t), ("y", res.y), ("Tm", res.Tm), *res.tooth.items()]:
        assert np.all(np.isfinite(a)), f"non-finite {name} returned for {source!r}"


# ------------------------------------------------------------------------------------ tests

@FUZZ
@given(case_dicts())
def test_fuzz_dict_load_and_simulate(fields):
    check_outcome(clamp(fields))


@FUZZ
@given(case_dicts())
def test_fuzz_dict_load_only_any_size(fields):
    """The sizes unclamped (n_out, z, t_end as drawn): loading checks them and allocates nothing
    (no run); a refusal names the field (or the unknown name), a loaded model has the case's
    teeth."""
    try:
        model = pyspline.load(fields)
    except NAMED as exc:
        assert NAMES_A_FIELD.search(str(exc)), str(exc)
        return
    assert model.z == model.case["z"] and model.n_out >= 1


# namelist text: a soup of the tokens a case file holds, and of the mistakes it may hold
TOKENS = st.sampled_from(
    ["&spline_case", "&SPLINE_CASE", "&spline_kase", "$spline_case", "$end", "&end", "/", "=", ",",
     "'", '"', "!", "(", ")", "*", "\n", "\r\n", " ", "\t", "'oneway'", "'adams           junk'",
     ".true.", "T", "F", "1", "0", "-1", "1e-3", "1.0d-4", "NaN", "Inf", "1e400", "2147483648",
     "3*", "7*0.0", "dq0(6)", "dq0(8)", "dq0(2:3)", "lx", "\x00", "\x01", "é", "–", ";"]
    + FIELDS) | st.text(max_size=6)


@st.composite
def case_texts(draw):
    body = "".join(draw(st.lists(TOKENS, max_size=40)))
    if draw(st.booleans()):           # mostly a group around it
        body = "&spline_case\n" + body + ("\n/\n" if draw(st.booleans()) else "")
    return body


@FUZZ
@given(case_texts())
def test_fuzz_case_file_text(tmp_path_factory, text):
    """Any text as a case file: a Case (then a short run) or a CaseError from the reader; the
    executable refuses a refused file in the same words."""
    path = tmp_path_factory.mktemp("fuzz") / "fuzz.nml"
    path.write_bytes(text.encode("utf-8", "surrogatepass"))
    try:
        case = pyspline.load_case(path)
    except pyspline.CaseError as exc:
        exe = os.environ.get("SPLINE_DYN")
        if exe:
            out = path.with_suffix(".csv")
            run = subprocess.run([exe, str(path), "-o", str(out)], capture_output=True, text=True,
                                 errors="replace", timeout=60)
            assert run.returncode == 2, run.stderr
            assert run.stderr.split("\n")[0] == f"spline-dyn: error: {exc}"
        return
    check_outcome(clamp(dict(case)))
