import gc
import os
import shutil
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CASES = ROOT / "cases"
sys.path.insert(0, str(Path(__file__).resolve().parent))   # the oracle


@pytest.fixture(scope="session")
def exe():
    """The spline-dyn executable installed with the package (or SPLINE_DYN)."""
    path = os.environ.get("SPLINE_DYN") or shutil.which("spline-dyn")
    if not path:
        pytest.fail("spline-dyn is not on PATH: pip install . installs it")
    return path


def assert_executable_matches_python(case, exe, tmp_path):
    """spline-dyn on `case` (written as a namelist) gives what pyspline.simulate gives, bit for
    bit: t, D2, T_m and every tooth's F. Returns the CSV's header, its columns by name, its data
    and the Result, for further checks."""
    import subprocess

    import numpy as np
    import pyspline
    nml = tmp_path / f"{case['name']}.nml"
    case.to_namelist(nml)
    out = tmp_path / "out.csv"
    subprocess.run([exe, str(nml), "-o", str(out)], check=True, capture_output=True)
    header, data = pyspline.core.read_csv(out)
    res = pyspline.simulate(case)
    col = {h.split(" [")[0]: i for i, h in enumerate(header)}
    np.testing.assert_array_equal(data[:, col["t"]], res.t)
    np.testing.assert_array_equal(data[:, col["D2"]], res.D2)
    np.testing.assert_array_equal(data[:, col["Tm"]], res.Tm)
    np.testing.assert_array_equal(data[:, col["F_1"]:col["F_1"] + case["z"]], res.tooth["F"])
    return header, col, data, res


PAPER = dict(k_m=2.3e5, m_1=2.0, m_2=2.0)


def random_states(c0, n, rng):
    """n states of the drive (SI) around a backlash c0 for right-hand-side checks: lateral
    states in and out of contact, a large shaft twist, D2 across the dead zone."""
    import numpy as np
    ys = []
    for _ in range(n):
        q = np.r_[rng.uniform(-2, 2, 4) * c0,              # lateral: in and out of contact
                  rng.uniform(-300, 300) * c0,             # D1 (shaft twist is large)
                  rng.uniform(-6, 6) * c0,                 # D2 across the dead zone
                  rng.uniform(-300, 300) * c0]
        ys.append(np.r_[q, rng.uniform(-0.2, 0.2, 7)])
    return ys

#: Warnings a test module expects from the shipped cases it uses and declares with pytestmark
#: (never filtered for the whole suite; tests/test_warnings.py checks that they are raised):
#: the wind-up of the paper's shafts, k_T = 7.855 N m/rad, in the paper cases, the template and
#: cases built on its defaults; all warnings of the constructed demonstration scenes chaos_z24
#: and rattle_z24 (their header comments say which); the support warning of the paper's
#: 5e6 N/m supports, which physical_z24 keeps. Patterns without ':' (the filter syntax).
PAPER_SHAFTS = pytest.mark.filterwarnings(
    r"ignore:case .*. field k_t[12] = 7\.85[56]0 N m/rad winds its shaft:pyspline.SplineWarning")
PAPER_SUPPORTS = pytest.mark.filterwarnings(
    r"ignore:case .*. fields k_p1 = 5\.000E\+06, k_p2 = 5\.000E\+06 N/m. the supports"
    r":pyspline.SplineWarning")
DEMONSTRATION_SCENES = pytest.mark.filterwarnings(
    r"ignore:case (chaos_z24|rattle_z24)\b:pyspline.SplineWarning")


def jacobian(model, y0, t=0.0):
    """The Jacobian of a loaded model's SI right-hand side at (t, y0) by central differences
    (exact to round-off where the system is linear: every tooth in contact)."""
    import numpy as np
    h = 1e-6 * np.r_[np.full(7, 2e-4), np.full(7, 2e-4 * 628.3)]
    A = np.empty((14, 14))
    for k in range(14):
        e = np.zeros(14)
        e[k] = h[k]
        A[:, k] = (model.rhs(t, y0 + e) - model.rhs(t, y0 - e)) / (2 * h[k])
    return A


def pytest_collection_finish(session):
    """The objects of the imports and of the collection (modules, functions, test items: about
    200 000 in a worker) live to the end of the session; gc.freeze() moves them out of the
    cyclic collector's view, so its full passes during the tests scan only what the tests
    made."""
    gc.freeze()


@pytest.fixture(autouse=True)
def dev_null_stays_a_device():
    """No test may replace /dev/null (run as root, a rename onto an output path given as
    /dev/null did: spline-dyn refuses devices since, and every test is held to it here)."""
    import stat
    yield
    if os.path.exists("/dev/null") and not stat.S_ISCHR(os.stat("/dev/null").st_mode):
        pytest.fail("this test replaced /dev/null with a regular file "
                    "(restore it: rm /dev/null && mknod -m 666 /dev/null c 1 3)")


#: how SUNDIALS prints its own messages; its error handler routes them into errors and
#: SplineWarnings (spline_integrator::lib_handler), so none may reach fd 1 or 2
SUNDIALS_RAW = ("[CVODE", "[ARKODE", "[KINSOL", "[SUNDIALS")


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """No SUNDIALS text on stdout or stderr in any test's setup, call or teardown, as pytest
    captures them: at the file-descriptor level (its default; `-s` turns this check off)."""
    outcome = yield
    rep = outcome.get_result()
    text = "".join(c for key, c in rep.sections if key in (f"Captured stdout {rep.when}",
                                                            f"Captured stderr {rep.when}"))
    if rep.passed and any(r in text for r in SUNDIALS_RAW):
        rep.outcome = "failed"
        rep.longrepr = f"SUNDIALS' own text on stdout or stderr:\n{text[:2000]}"


#: fixtures whose result is computed once per process for tests in more than one module
#: (functools.cache in tests/test_cont_drives.py: the Z16 S-curve, its follow sweeps), and the
#: xdist group of the tests that use them
SHARED_ACROSS_MODULES = {"every_branch": "z16_band", "s_curve": "z16_band",
                         "follow_sweeps": "z16_band"}


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(items):
    """With `--dist loadgroup` (pyproject.toml), every xdist worker computes a shared result
    only if a test that uses it is sent to it: the tests that share one go to one worker as a
    group. A test that uses a fixture of its module that is not function-scoped joins its
    module's group, one that uses a fixture of SHARED_ACROSS_MODULES that group; a module may
    name its own group (pytestmark = pytest.mark.xdist_group(...)). The other tests are handed
    out one by one to the worker that is free, so both finish together."""
    for item in items:
        if item.get_closest_marker("xdist_group"):
            continue
        module = item.nodeid.split("::")[0]
        defs = item._fixtureinfo.name2fixturedefs
        group = next((SHARED_ACROSS_MODULES[n] for n in item.fixturenames
                      if n in SHARED_ACROSS_MODULES), None)
        if group is None and any(d[-1].scope != "function"
                                 and d[-1].baseid.split("::")[0] == module
                                 for d in defs.values()):
            group = Path(module).stem
        if group:
            item.add_marker(pytest.mark.xdist_group(group))
