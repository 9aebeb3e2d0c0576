"""The documents hold: every link and repository path named in README.md and docs/ exists, and
the README's quick start runs as written, from a directory outside the checkout."""
import os
import re
import shlex
import subprocess
import sys

import pytest

from conftest import ROOT

DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
TOP = ("cases/", "fortran/", "pyspline/", "tests/", "bench/", "docs/", "scripts/", ".ci/")


def named_paths(doc):
    text = doc.read_text()
    links = [m for m in re.findall(r"\]\(([^)#\s]+)\)", text) if "://" not in m]
    for target in links:
        yield target, (doc.parent / target)
    for code in re.findall(r"`([^`\s]+)`", text):
        path = code.split("::")[0]
        if path.startswith(TOP) and "*" not in path and "<" not in path:
            yield path, ROOT / path


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: p.name)
def test_every_named_path_exists(doc):
    missing = sorted({name for name, path in named_paths(doc) if not path.exists()})
    assert not missing, f"{doc.name} names paths that do not exist: {missing}"


def test_docs_name_the_routines_that_exist():
    """Every `module::name` named in README.md and docs/ is defined in fortran/: a routine, a
    type or a named constant (a table such as `spline_accuracy::rules`)."""
    source = "\n".join(p.read_text().lower() for p in (ROOT / "fortran").rglob("*.f90"))
    defined = set(re.findall(r"(?:(?:subroutine|function)\s+|type :: |parameter :: )(\w+)", source))
    for doc in DOCS:
        for mod, routine in re.findall(r"`(spline_\w+)::(\w+)`", doc.read_text()):
            assert f"module {mod}" in source, (doc.name, mod)
            assert routine.lower() in defined, (doc.name, mod, routine)


def readme_block(lang):
    text = (ROOT / "README.md").read_text()
    start = text.index("## Quick start")
    block = re.search(rf"```{lang}\n(.*?)```", text[start:], re.S)
    return block.group(1)


#: Runs the command lines in argv[2:] in order, in this one interpreter: `pyspline ARGS` as the
#: console script does (pyspline.cli:main), any other command as a process; stops at the first
#: that fails, naming it; then the Python code argv[1] as a script of its own (its own
#: globals, __name__ "__main__"), whose imports of pyspline, xarray and Dask are then loaded.
QUICK_START = """
import shlex, subprocess, sys
from pyspline.cli import main
for line in sys.argv[2:]:
    cmd = shlex.split(line)
    if cmd[0] == "pyspline":
        try:
            code = main(cmd[1:])
        except SystemExit as exc:
            code = exc.code
    else:
        code = subprocess.run(cmd).returncode
    if code:
        sys.exit(f"{line!r} exited with {code}")
exec(compile(sys.argv[1], "README.md's Python block", "exec"), {"__name__": "__main__"})
"""


def test_readme_quick_start_runs(tmp_path):
    """Every line of the quick start: the first through the installed `pyspline` script, the
    rest and then the Python block in one interpreter (QUICK_START: the imports of xarray,
    matplotlib and Dask once, not per command)."""
    exe = os.environ.get("SPLINE_DYN")
    lines = [line.split("#")[0].strip() for line in readme_block("bash").splitlines()]
    lines = [shlex.join([exe, *shlex.split(line)[1:]]) if exe and line.startswith("spline-dyn ")
             else line for line in lines if line]
    assert shlex.split(lines[0])[0] == "pyspline"
    run = subprocess.run(shlex.split(lines[0]), cwd=tmp_path, capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, (lines[0], run.stdout[-2000:], run.stderr[-2000:])
    run = subprocess.run([sys.executable, "-P", "-c", QUICK_START, readme_block("python"),
                          *lines[1:]], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, (run.stdout[-2000:], run.stderr[-3000:])
    for path in ("mycase.nml", "results/paper_lx1e-4.npz", "figs/paper_lx1e-4.png",
                 "sweep/sweep.nc", "sweep/bifurcation.png", "mycase.csv"):
        assert (tmp_path / path).stat().st_size > 0, path


def test_readme_run_answers_as_written(tmp_path, capsys):
    """The commands of README's 'What one run answers' print its block, line for line, from a
    directory outside the checkout (the block said 'no plausibility warning' where the run
    gives the support warning, and the run needs the case copied first)."""
    from pyspline.cli import main
    text = (ROOT / "README.md").read_text()
    head, block = re.search(r"## What one run answers \((.*?)\)\n```text\n(.*?)```", text,
                            re.S).groups()
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        for cmd in re.findall(r"`pyspline ([^`]+)`", head):
            assert main(shlex.split(cmd)) == 0, cmd
    finally:
        os.chdir(cwd)
    assert capsys.readouterr().out.splitlines()[2:] == block.splitlines()


def test_readme_opens_with_the_two_commands():
    lines = (ROOT / "README.md").read_text().splitlines()
    block = lines[lines.index("```bash") + 1:lines.index("```bash") + 3]
    assert block == ["bash scripts/setup.sh && pyspline reproduce --out out",
                     "bash scripts/setup.sh --tests && pytest -q -n 2 tests"]
    ci = (ROOT / ".ci" / "run").read_text().splitlines()
    for part in block[1].split(" && "):          # CI runs the README's test command
        assert part in ci, part
    assert len(lines) <= 160
