"""A sweep's warnings (pyspline.warned, docs/sweeps.md "Warnings"): each kind once, the first
point's words with how many points raised it, over which swept values and the range of its
varying numbers; every point's own lines kept in the dataset; the command line's stderr one line
per kind. Short runs: paper_lx1e-4 over 0.02 s, stiff shafts but where a row makes one soft."""
import concurrent.futures as cf
import re
import warnings

import numpy as np
import pytest

import pyspline
from pyspline.warned import kind

from conftest import CASES

pytest.importorskip("xarray")

#: rows: no warning; the start overlapping the backlash (c = 2e-4 m) at three offsets; a soft
#: shaft at two stiffnesses: two kinds, each with its own numbers per row
ROWS = dict(l_x=[0.0, 2.5e-4, 3e-4, 3.5e-4, 0.0, 0.0], k_t1=[1e4, 1e4, 1e4, 1e4, 5.0, 8.0])


@pytest.fixture(scope="module")
def base():
    return pyspline.load_case(CASES / "paper_lx1e-4.nml", t_end=0.02, t_transient=0.005,
                              n_out=61, start="rest", k_t1=1e4, k_t2=1e4)


def direct(case) -> list[str]:
    """The SplineWarnings of loading and running one case by itself (no sweep)."""
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        pyspline.simulate(case)
    return [str(w.message) for w in rec if issubclass(w.category, pyspline.SplineWarning)]


def test_each_kind_once_with_its_count_range_and_every_points_text(base):
    with warnings.catch_warnings(record=True) as rec, cf.ThreadPoolExecutor(2) as pool:
        warnings.simplefilter("always")
        ds = pyspline.sweep(base, executor=pool, progress=False, table=ROWS)
    said = [str(w.message) for w in rec if issubclass(w.category, pyspline.SplineWarning)]
    assert (ds["error"] == "").all()
    # each point keeps its own lines: those of the same case run by itself
    texts = [str(t) for t in ds["warnings"].values]
    for i, text in enumerate(texts):
        assert text.splitlines() == direct(base.replace(l_x=ROWS["l_x"][i],
                                                        k_t1=ROWS["k_t1"][i])), i
    assert texts[0] == "" and len({kind(t) for t in texts[1:4]}) == 1 != len(set(texts[1:4]))
    assert len(said) == 2, said                       # two kinds: two warnings, not five
    start, shaft = sorted(said, key=lambda m: "start = 'rest'" not in m)
    assert start.startswith(texts[1] + " [3 of 6 points; l_x = 0.00025 to 0.00035; k_t1 = 10000")
    overlaps = [re.search(r"by (\S+) m", t).group(1) for t in texts[1:4]]
    assert float(overlaps[0]) < float(overlaps[1]) < float(overlaps[2])
    assert f"by {overlaps[0]} to {overlaps[2]} (largest at l_x = 0.00035, k_t1 = 10000)" in start
    assert shaft.startswith(texts[4] + " [2 of 6 points; l_x = 0; k_t1 = 5 to 8;")
    assert "(largest at l_x = 0, k_t1 = 5)" in shaft     # the softer shaft winds the most


def test_a_kind_is_the_words_not_the_numbers():
    a = "case x_z24: field k_t1 = 5.0000 N m/rad winds its shaft 6.1400 rad (limit 0.20 rad)"
    b = "case x_z24: field k_t1 = 8.0000 N m/rad winds its shaft 3.8375 rad (limit 0.20 rad)"
    assert kind(a) == kind(b) != kind(b.replace("k_t1", "k_t2"))
    assert kind("load-sharing factor 2852.35. Run") == "load-sharing factor #. Run"
    assert kind("by -1.994E-04 m") == "by # m"


def test_cli_stderr_has_one_line_per_kind_not_per_point(base, tmp_path, capfd):
    from pyspline.cli import main
    path = tmp_path / "short.nml"
    base.to_namelist(path)
    assert main(["sweep", str(path), "--set", "l_x=2.5e-4:3.5e-4:3", "--fix", "k_t1=5",
                 "--workers", "2", "--threads", "--out", str(tmp_path / "out")]) == 0
    err = capfd.readouterr().err                      # with the progress bar's
    lines = [ln for ln in err.splitlines() if "warning:" in ln]
    assert len(lines) == 2 and all(ln.startswith("warning: case ") for ln in lines), err
    assert err.count("[3 of 3 points; l_x = 0.00025 to 0.00035") == 2
    ds = pyspline.open_sweep(tmp_path / "out")
    assert all(len(str(t).splitlines()) == 2 for t in ds["warnings"].values.ravel())


def test_follow_sweep_says_each_kind_once_without_the_chains_start_note(base):
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        ds = pyspline.sweep(base.replace(k_t1=5.0), progress=False, follow="up",
                            l_x=[2.5e-4, 3e-4, 3.5e-4])
    said = [str(w.message) for w in rec if issubclass(w.category, pyspline.SplineWarning)]
    assert (ds["error"] == "").all() and len(said) == 1 and "winds its shaft" in said[0], said
    assert "[3 of 3 points; l_x = 0.00025 to 0.00035]" in said[0]
    assert all(str(t).count("\n") == 0 and "winds its shaft" in str(t)
               for t in ds["warnings"].values)


def test_warning_texts_built_on_two_threads(base):
    """4000 model builds on 2 threads (the core releases the GIL): each warning text equals the
    one the same case gives when built alone. Issue 33: gfortran kept the length of a function's
    deferred-length result in a static variable shared by the threads, so one thread's number
    cut or doubled characters of another's text. l_x changes sign from case to case: its text
    is 9 or 10 characters, so any two builds that overlap there splice (on the old core 6-13 of
    4000 under load, against 0-1 with l_x of one sign)."""
    def built(k):       # a new Case each time: its model is built, not reused
        return k, pyspline.load(base.replace(l_x=(-1) ** k * (2.5e-4 + 1e-6 * k),
                                             k_t1=1e4 if k % 2 else 5.0)).warnings
    with warnings.catch_warnings(), cf.ThreadPoolExecutor(2) as pool:
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        alone = [built(k)[1] for k in range(14)]
        spliced = sum(w != alone[k] for k, w in pool.map(built, [i % 14 for i in range(4000)]))
    assert spliced == 0, f"{spliced} of 4000 texts spliced"
