"""The package's modules import alone, and none imports another that imports it back (issue 33:
no import circles); one module, pyspline.bridge, talks to the compiled core (pyspline._core).
The graph counts every import of a module, at its top or inside a function, since a deferred
import only hides a circle; a module's imports of the packages it is in (``from . import
__version__``) are left out: a package is loaded before any of its modules."""
import ast
import subprocess
import sys
from pathlib import Path

import pytest

import pyspline

ROOT = Path(pyspline.__file__).parent
MODULES = sorted(".".join(("pyspline",) + p.relative_to(ROOT).with_suffix("").parts)
                 .removesuffix(".__init__") for p in ROOT.rglob("*.py"))


def _source(module: str) -> tuple:
    """The parsed source of `module` and the package its relative imports start from."""
    path = ROOT.joinpath(*module.split(".")[1:])
    is_pkg = path.is_dir()
    tree = ast.parse((path / "__init__.py" if is_pkg else path.with_suffix(".py")).read_text())
    return tree, module.split(".") if is_pkg else module.split(".")[:-1]


def _imports(module: str, within: list = MODULES) -> set:
    """The modules of `within` (the package's) that `module` imports, anywhere in its source."""
    tree, here = _source(module)
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = (here[:len(here) - node.level + 1] if node.level else [])
            name = ".".join(base + ([node.module] if node.module else []))
            out.add(name)
            out |= {f"{name}.{a.name}" for a in node.names}      # from . import analysis
    return {m for m in out if m in within and m != module and not module.startswith(m + ".")}


def _core_callers() -> set:
    """The package's modules that import the compiled core or call one of its routines (an
    attribute api_*, the names of fortran/interface/api.f90), anywhere in their source."""
    out = set()
    for m in MODULES:
        calls = any(isinstance(n, ast.Attribute) and n.attr.startswith("api_")
                    for n in ast.walk(_source(m)[0]))
        if calls or _imports(m, ["pyspline._core"]):
            out.add(m)
    return out


def _cycle(graph: dict) -> list:
    """A cycle of the graph as a list of its nodes, or [] if there is none."""
    state, path = {}, []

    def visit(n):
        state[n] = 1
        path.append(n)
        for m in sorted(graph[n]):
            if state.get(m) == 1:
                return path[path.index(m):] + [m]
            if m not in state and (found := visit(m)):
                return found
        state[n] = 2
        path.pop()
        return []

    for n in sorted(graph):
        if n not in state and (found := visit(n)):
            return found
    return []


def test_cycle_finder():
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b", "c"}, "b": {"c"}, "c": set()}) == []


def test_graph_sees_deferred_imports():
    assert "pyspline.core" in _imports("pyspline.summary")
    assert "pyspline.analysis" in _imports("pyspline.summary")     # from . import analysis
    assert "pyspline.paper" in _imports("pyspline.cli")            # inside a function


def test_one_module_talks_to_the_core():
    assert _core_callers() == {"pyspline.bridge"}


def test_no_import_cycle():
    graph = {m: _imports(m) for m in MODULES}
    assert _cycle(graph) == []


#: Imports each module named in argv in a process of its own, forked from one interpreter that
#: has loaded numpy and the three matplotlib modules of pyspline/plots/style.py (every module
#: imports numpy through pyspline/__init__.py, every figure module those through
#: pyspline.plots; third-party modules bind no name in a pyspline module, so they hide no
#: missing import, and each child's matplotlib import cost 0.8-1 s of CPU, 5 s in all): prints
#: each failure's traceback.
ALONE = """
import os, sys, traceback
import numpy
import matplotlib.backends.backend_agg, matplotlib.figure, matplotlib.ticker
for module in sys.argv[1:]:
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(read)
        try:
            __import__(module)
            os._exit(0)
        except BaseException:
            os.write(write, traceback.format_exc().encode())
            os._exit(1)
    os.close(write)
    with os.fdopen(read) as f:
        message = f.read()
    if os.waitpid(pid, 0)[1] != 0:
        print(f"{module} does not import alone:\\n{message}")
"""


def test_imports_alone():
    """Every module imports alone; and the runner sees a failing import (here a missing module,
    run last in the same process) and names it, and only it."""
    modules = [m for m in MODULES if m != "pyspline.__main__"]   # a command
    run = subprocess.run([sys.executable, "-P", "-c", ALONE, *modules, "pyspline.no_such_module"],
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith("pyspline.no_such_module does not import alone"), run.stdout
    assert "ModuleNotFoundError" in run.stdout and run.stdout.count("does not import alone") == 1


def test_import_pyspline_is_light():
    """`import pyspline` (every public name bound) loads none of the heavy packages: figures,
    datasets, clusters and SciPy are imported by the functions that use them (0.13 s of CPU for
    the import against about 2 s with matplotlib, xarray, dask and scipy)."""
    heavy = ("matplotlib", "xarray", "pandas", "dask", "distributed", "scipy", "netCDF4")
    run = subprocess.run([sys.executable, "-P", "-c", "import sys, pyspline; "
                          "[getattr(pyspline, n) for n in pyspline.__all__]; "
                          "print(' '.join(sorted({m.split('.')[0] for m in sys.modules})))"],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert not set(run.stdout.split()) & set(heavy), run.stdout


def test_no_public_name_shadows_a_module():
    """No name the package exports is also one of its modules (issue 33): `pyspline.sweep` is the
    function and pyspline.sweeps its module, `pyspline.branches` the function and
    pyspline.diagram its module; a name that were both would make `import pyspline.X` and
    `pyspline.X` two different things, depending on what was imported first."""
    modules = {m.split(".")[1] for m in MODULES if m.count(".") >= 1}
    assert sorted(set(pyspline.__all__) & modules) == []
    assert all(callable(getattr(pyspline, name)) or isinstance(getattr(pyspline, name), type)
               for name in pyspline.__all__)
