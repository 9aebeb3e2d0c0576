"""The build links the SUNDIALS it was configured with, and the optimised CVODE that
scripts/setup.sh builds gives the same numbers as Debian's unoptimised one."""
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

import pyspline
from pyspline._build_info import SUNDIALS_LIBDIR
from pyspline.core import cvode_library
from conftest import CASES, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

DEBIAN_LIBDIR = "/usr/lib/x86_64-linux-gnu"


def test_loaded_cvode_is_the_configured_one():
    pyspline.simulate(pyspline.load_case(CASES / "paper_lx1e-4.nml", t_end=1e-3, n_out=2))
    path = cvode_library()
    if SUNDIALS_LIBDIR:
        assert path.startswith(SUNDIALS_LIBDIR) and path.endswith("(optimised)"), path
    else:
        assert "libsundials_cvode.so" in path and path.endswith("(debian)"), path


@pytest.mark.skipif(not SUNDIALS_LIBDIR or not Path(DEBIAN_LIBDIR, "libsundials_cvode.so.6").exists(),
                    reason="needs both the optimised CVODE and Debian's")
def test_optimised_cvode_gives_bit_identical_numbers(exe, tmp_path):
    # LD_LIBRARY_PATH outranks the executable's RUNPATH: the same binary on Debian's libraries.
    case = pyspline.load_case(CASES / "paper_T100.nml", t_end=0.02, n_out=41)
    case.to_namelist(tmp_path / "c.nml")
    outs = []
    for name, env in (("opt", {}), ("deb", {"LD_LIBRARY_PATH": DEBIAN_LIBDIR})):
        out = tmp_path / f"{name}.csv"
        subprocess.run([exe, str(tmp_path / "c.nml"), "-o", str(out)], check=True,
                       capture_output=True, env={**os.environ, **env})
        lines = out.read_text().splitlines()
        outs.append([ln for ln in lines if not ln.startswith("# stats")])   # stats hold the time
    assert len(outs[0]) > 41
    assert outs[0] == outs[1]


def test_every_module_of_the_source_tree_is_installed():
    """meson.build lists the Python sources it installs: a module added to pyspline/ but not to
    that list imports from the source tree and fails from an installed package."""
    src = Path(__file__).resolve().parents[1] / "pyspline"
    installed = Path(pyspline.__file__).parent
    for path in src.rglob("*.py"):
        rel = path.relative_to(src)
        assert (installed / rel).exists(), f"{rel} is not in meson.build's py.install_sources"


@pytest.mark.skipif(shutil.which("nm") is None, reason="needs nm (binutils)")
def test_the_build_names_what_its_core_is_compiled_for(exe, tmp_path, capsys):
    """pyspline --version, spline-dyn's summary and a run's dataset name one build: portable
    (any x86-64: SSE2, so glibc's SSE2 vector sin and cos only) or host-tuned (meson option
    host_tuned: -march=native, named with the CPU gcc took the host for; docs/building.md)."""
    from pyspline._build_info import BUILD
    from pyspline.cli import main
    assert BUILD == "portable" or re.fullmatch(r"host-tuned \(-march=native = [\w.-]+\)", BUILD)
    with pytest.raises(SystemExit):
        main(["--version"])
    assert capsys.readouterr().out == f"pyspline {pyspline.__version__}, {BUILD} build\n"
    case = pyspline.load_case(CASES / "paper_lx1e-4.nml", t_end=1e-3, n_out=2)
    case.to_namelist(tmp_path / "c.nml")
    subprocess.run([exe, str(tmp_path / "c.nml"), "--summary", str(tmp_path / "s")], check=True,
                   capture_output=True)
    assert (tmp_path / "s").read_text().startswith(
        f"# spline-dyn summary (pyspline {pyspline.__version__}, {BUILD} build): ")
    assert pyspline.simulate(case).to_xarray().attrs["pyspline_build"] == BUILD
    core = next(Path(pyspline.__file__).parent.glob("_core*.so"))
    symbols = subprocess.run(["nm", "-D", str(core)], capture_output=True, text=True,
                             check=True).stdout.split()
    wide = [s for s in symbols if s.startswith(("_ZGVc", "_ZGVd", "_ZGVe"))]   # AVX, AVX2, AVX-512
    assert BUILD != "portable" or not wide, wide


@pytest.mark.skipif(shutil.which("nm") is None, reason="needs nm (binutils)")
def test_the_core_keeps_no_text_length_in_a_static_variable(exe):
    """gfortran 12 keeps the length of every call of a function with a deferred-length character
    result (character(len=:), allocatable) in a static variable slen.N, one for all threads: two
    threads building texts at once spliced them (issue 33; test_sweep_warnings, docs/developing.md
    "Thread safety"). The core (the extension and spline-dyn) has none left."""
    core = next(Path(pyspline.__file__).parent.glob("_core*.so"))
    for binary in (core, Path(exe)):
        symbols = subprocess.run(["nm", str(binary)], capture_output=True, text=True,
                                 check=True).stdout.split()
        assert "__spline_errors_MOD_err_exit_code" in symbols, f"{binary}: no symbols to read"
        static = [s for s in symbols if s.startswith("slen.")]
        assert not static, f"{binary}: {len(static)} static lengths ({static[0]}, ...)"


@pytest.mark.xdist_group("grouping_check")
def test_xdist_groups_reach_the_workers(request):
    """The shared fixtures are computed once because `--dist loadgroup` (pyproject.toml) sends a
    group's tests to one worker; the group travels in the node id ("...@group"). Under pytest
    9.2 with pytest-xdist 3.8 it no longer does (pytest-xdist issue 1386): nothing fails, but
    every group fixture runs on both workers (a fresh machine's tests took 368 s of CPU against
    about 320), which is why setup.sh installs pytest < 9.2."""
    if not hasattr(request.config, "workerinput"):
        pytest.skip("not under pytest-xdist")
    assert request.node.nodeid.endswith("@grouping_check"), request.node.nodeid
