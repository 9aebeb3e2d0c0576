"""Bad input: a clear error naming the field (or the CVODE flag, the time and the case)."""
import json
import math
import os
import re
import subprocess
from pathlib import Path

import f90nml
import pytest

import pyspline
from conftest import CASES, PAPER, PAPER_SHAFTS, PAPER_SUPPORTS, DEMONSTRATION_SCENES

pytestmark = [PAPER_SHAFTS, PAPER_SUPPORTS, DEMONSTRATION_SCENES]   # expected warnings (conftest)


@pytest.mark.parametrize("fields,words", [
    (dict(k_mesh=1.0), ["unknown field", "k_mesh"]),
    (dict(z=2), ["field z", "at least 3"]),
    (dict(module_m=2.0), ["module_m", "metres"]),
    (dict(alpha_deg=0.5236), ["alpha_deg", "degrees"]),
    (dict(k_p1=-5e6), ["k_p1", "negative"]),
    (dict(m_1=-2.0), ["m_1", "positive"]),
    (dict(j_2=0.0), ["j_2", "positive"]),
    (dict(t_end=0.0), ["t_end", "greater than t0"]),
    (dict(t_end=math.nan), ["t_end", "finite"]),
    (dict(c0=math.inf), ["c0", "finite"]),
    (dict(thermal="hot"), ["thermal", "none, bulk, oneway or coupled"]),
    (dict(method="rk4"), ["method", "bdf, adams, erk or auto"]),
    (dict(erk_table="verner"), ["field erk_table", "dormand_prince or cash_karp"]),
    (dict(z=16.5), ["z", "whole number"]),
    (dict(dq0=[0.0, 1.0]), ["dq0", "7 numbers"]),
    (dict(speed_rpm=-100.0), ["speed_rpm"]),
    (dict(dof=5), ["field dof", "7 (bending-torsion) or 3"]),
    (dict(fidelity="fast"), ["field fidelity", "given or auto"]),
    (dict(fidelity_tol=0.0), ["fidelity_tol", "relative error"]),
])
def test_bad_field(fields, words):
    with pytest.raises(pyspline.CaseError) as exc:
        pyspline.simulate(dict(PAPER, name="badcase", **fields))
    msg = str(exc.value)
    for w in words:
        assert w in msg, msg


def test_bad_field_in_file_names_case_and_field(tmp_path, exe):
    """The executable reads the file itself: its own error names the field too."""
    path = tmp_path / "broken.nml"
    path.write_text("&spline_case\n  k_m = 2.3e5\n  b = -0.03\n/\n")
    with pytest.raises(pyspline.CaseError, match=r"case broken: field b "):
        pyspline.simulate(path)
    run = subprocess.run([exe, str(path)], capture_output=True, text=True)
    assert run.returncode != 0
    assert "case broken: field b = -3.000E-02 is outside" in " ".join(run.stderr.split())


def test_unknown_field_in_file(tmp_path, exe):
    path = tmp_path / "typo.nml"
    path.write_text("&spline_case\n  k_m = 2.3e5\n  backlash = 1e-4\n/\n")
    with pytest.raises(pyspline.CaseError, match="unknown field 'backlash'"):
        pyspline.load_case(path)
    run = subprocess.run([exe, str(path)], capture_output=True, text=True)
    assert run.returncode != 0 and "backlash" in run.stderr.lower()


def test_cvode_failure_names_flag_time_and_case():
    with pytest.raises(pyspline.SolverError) as exc:
        pyspline.simulate(dict(PAPER, name="starved", start="rest", max_steps=20, t_end=0.1,
                               n_out=3))
    msg = str(exc.value)
    assert "CV_TOO_MUCH_WORK" in msg and "case starved" in msg and "t =" in msg


def test_closed_backlash_is_an_error():
    # kappa = 2 lambda s cos(alpha) = 6.5e-8 m/degC: 3100 degC closes a 0.2 mm backlash
    with pytest.raises(pyspline.ThermalInterferenceError, match="thermal interference"):
        pyspline.simulate(dict(PAPER, name="hot", thermal="bulk", t_bulk=3100.0))


def test_no_unique_equilibrium_is_an_error():
    with pytest.raises(pyspline.SolverError, match="start = 'rest'"):
        pyspline.simulate(dict(PAPER, name="idle", t_d=0.0, t_l=0.0, grav=0.0))


def test_template_lists_every_field_with_the_core_defaults():
    tpl = f90nml.read(str(CASES / "template.nml"))["spline_case"]
    defaults = pyspline.defaults()
    assert set(tpl) == set(defaults)
    for k, v in defaults.items():
        assert tpl[k] == v, k


def _table_units():
    """Field name -> unit, from the core's one field table (fortran/input/case_type.f90 `fields`,
    through api_names('fields'))."""
    from pyspline.core import _names
    return {name: unit for name, unit, _ in _names("fields")}


def test_template_gives_each_field_the_unit_of_the_core_table():
    """cases/template.nml's comment of each field names its unit in brackets, [unit], as the
    core's field table has it (no brackets where the table has no unit)."""
    units = _table_units()
    assert set(units) == set(pyspline.defaults())
    seen = set()
    for line in (CASES / "template.nml").read_text().splitlines():
        m = re.match(r"\s*(\w+)\s*=[^!]*!(.*)", line)
        if not m:
            continue
        name, comment = m.group(1).lower(), m.group(2)
        brackets = re.findall(r"\[([^\]]*)\]", comment)
        assert (brackets[0] if brackets else "") == units[name], (name, comment)
        seen.add(name)
    assert seen == set(units)


# ------------------------------------------------------------------ one reader, one diagnosis

CORPUS = Path(__file__).resolve().parent / "corpus"
_MANIFEST = json.loads((CORPUS / "manifest.json").read_text(encoding="utf-8"))
BAD_FILES = sorted({e["file"] for e in _MANIFEST if e["kind"] == "file" and e["expect"] == "CaseError"})


def _exe_error(exe, args, tmp_path):
    run = subprocess.run([exe, *args, "-o", str(tmp_path / "out.csv")], capture_output=True,
                         text=True, timeout=60, stdin=subprocess.DEVNULL)
    lines = run.stderr.splitlines()
    assert lines and lines[0].startswith("spline-dyn: error: "), run.stderr
    assert not (tmp_path / "out.csv").exists()
    return run.returncode, lines[0].removeprefix("spline-dyn: error: ")


@pytest.mark.parametrize("name", BAD_FILES)
def test_python_and_executable_say_the_same(name, exe, tmp_path):
    """A bad case file gets the same message, word for word, from pyspline and spline-dyn:
    the file is parsed by one reader (fortran/input/case_parse.f90 case_parse) and validated by one check."""
    path = str(CORPUS / name)
    with pytest.raises(pyspline.CaseError) as exc:
        pyspline.simulate(pyspline.load_case(path))
    code, msg = _exe_error(exe, [path], tmp_path)
    assert code == 2
    assert msg == str(exc.value)


def _not_a_file(kind, tmp_path):
    if kind == "directory":
        (tmp_path / "d.nml").mkdir()
        return tmp_path / "d.nml"
    if kind == "missing":
        return tmp_path / "missing.nml"
    if kind == "dangling":
        (tmp_path / "dangling.nml").symlink_to(tmp_path / "gone.nml")
        return tmp_path / "dangling.nml"
    if kind == "loop":
        (tmp_path / "a.nml").symlink_to(tmp_path / "b.nml")
        (tmp_path / "b.nml").symlink_to(tmp_path / "a.nml")
        return tmp_path / "a.nml"
    if kind == "fifo":
        os.mkfifo(tmp_path / "f.nml")
        return tmp_path / "f.nml"
    if kind == "too_big":
        with open(tmp_path / "big.nml", "wb") as f:
            f.truncate(2 * 1024 * 1024)
        return tmp_path / "big.nml"
    if kind == "nul_inside":
        (tmp_path / "nul.nml").write_bytes(b"&spline_case\n  t_end = 1e-3\x00\n/\n")
        return tmp_path / "nul.nml"
    if kind == "not_a_dir":
        (tmp_path / "plain").write_text("x")
        return tmp_path / "plain" / "case.nml"
    raise ValueError(kind)


@pytest.mark.parametrize("kind", ["directory", "missing", "dangling", "loop", "fifo", "too_big",
                                  "nul_inside", "not_a_dir"])
def test_not_a_case_file_same_words(kind, exe, tmp_path):
    """Paths that are no case file: refused before any open (a FIFO would block), in the same
    words by Python (os.stat) and the executable (stat(2) in fortran/interface/fileinfo.c)."""
    path = str(_not_a_file(kind, tmp_path))
    with pytest.raises(pyspline.CaseError) as exc:
        pyspline.load_case(path)
    code, msg = _exe_error(exe, [path], tmp_path)
    assert code == 2
    assert msg == str(exc.value)


def test_field_table_matches_the_defaults():
    """The reader's table of fields (type and size) agrees with case_t's defaults."""
    from pyspline.core import _names
    table = {name: layout for name, layout, _ in _names("layout")}
    defaults = pyspline.defaults()
    assert set(table) == set(defaults)
    for name, v in defaults.items():
        kind = table[name]
        if isinstance(v, bool):
            assert kind == "l", name
        elif isinstance(v, int):
            assert kind == "i", name
        elif isinstance(v, float):
            assert kind == "r", name
        elif isinstance(v, list):
            assert kind == f"r{len(v)}", name
        else:
            assert kind.startswith("c"), name


@pytest.mark.parametrize("body,expected", [
    ("dq0(6) = 1e-6", {"dq0": [0, 0, 0, 0, 0, 1e-6, 0]}),
    ("dq0(2:3) = 1e-6, 2e-6", {"dq0": [0, 1e-6, 2e-6, 0, 0, 0, 0]}),
    ("dv0 = 3*0.0, 4*1e-6", {"dv0": [0, 0, 0, 1e-6, 1e-6, 1e-6, 1e-6]}),
    ("dq0 = , 1e-6", {"dq0": [0, 1e-6, 0, 0, 0, 0, 0]}),
    ("roots = T, stald = .False.", {"roots": True, "stald": False}),
    ("ROOTS = .t", {"roots": True}),
    ("c0 = 2.0d-4, module_m = 2.0D-3", {"c0": 2e-4, "module_m": 2e-3}),
    ("method = 'adams'   , t_end = 1e-3", {"method": "adams", "t_end": 1e-3}),
    ("name = 'it''s \"q\" / ! & z = 2'", {"name": "it's \"q\" / ! & z = 2", "z": 16}),
    ("thermal = 'none                         '", {"thermal": "none"}),
    ("t_end =", {"t_end": 0.1}),
    ("n_out = +0003", {"n_out": 3}),
])
def test_reader_accepts_fortran_forms(tmp_path, body, expected):
    path = tmp_path / "forms.nml"
    path.write_text(f"&spline_case\n  {body}\n/\n")
    case = pyspline.load_case(path)
    for k, v in expected.items():
        assert case[k] == (pytest.approx(v) if not isinstance(v, (str, bool)) else v), k


@pytest.mark.parametrize("body,words", [
    ("t_end = 1e-3\n  t_end = 2e-3", ["field t_end is given twice", "lines 2 and 3"]),
    ("z = 16.0", ["field z = 16.0", "whole number"]),
    ("t_end = 1e400", ["t_end = 1e400", "largest number"]),
    ("dq0(0) = 1.0", ["dq0(0)", "outside 1 to 7"]),
    ("t_end(2) = 1.0", ["t_end is not an array"]),
    ("z = 3*16", ["field z: more than one value"]),
    ("roots = yes", ["roots = yes", ".true. or .false."]),
    ("name = '" + "x" * 129 + "'", ["field name", "longer than 128 characters"]),
    ("lyapunov_int = 2.0", ["unknown field 'lyapunov_int'", "did you mean lyapunov_interval?"]),
    ("k_mesh = 1.0", ["unknown field 'k_mesh'", "template.nml"]),
    ("= 3", ["'=' without a field name"]),
    ("t_end = 1e-3;", ["unexpected ';'"]),
])
def test_reader_refuses_with_line_and_field(tmp_path, body, words):
    path = tmp_path / "bad.nml"
    path.write_text(f"&spline_case\n  {body}\n/\n")
    with pytest.raises(pyspline.CaseError) as exc:
        pyspline.load_case(path)
    msg = str(exc.value)
    assert msg.startswith(f"case bad ({path}, line "), msg
    for w in words:
        assert w in msg, msg


def test_dict_fields_get_the_core_suggestion():
    with pytest.raises(pyspline.CaseError, match="unknown field 'l_xx': did you mean l_x?"):
        pyspline.load_case({"l_xx": 1e-4})
    with pytest.raises(pyspline.CaseError, match="field l_x = 1000.* beyond the largest number"):
        pyspline.load_case({"l_x": 10 ** 400})


def test_numpy_values_in_dicts():
    import numpy as np
    case = pyspline.load_case(dict(z=np.int64(20), module_m=np.float32(2e-3), roots=np.bool_(True),
                                   dq0=np.zeros(7), method=np.str_("adams")))
    assert case["z"] == 20 and case["roots"] is True and case["method"] == "adams"
    assert case["module_m"] == pytest.approx(2e-3)


def test_memory_is_checked_before_allocating():
    with pytest.raises(pyspline.CaseError, match=r"field n_out = 100000000 with z = 1000 teeth needs "
                       r"13\.2 TB of memory"):
        pyspline.load(dict(z=1000, n_out=10 ** 8, t_end=1e-3))


def test_static_equilibrium_of_large_misaligned_splines():
    """Z = 200 .. 1000 with the computed k_m and a misalignment: the frozen-contact Newton
    (fortran/physics/dynamics.f90 static_equilibrium) converges where a plain difference Jacobian stalled."""
    import numpy as np
    for z in (200, 400, 1000):
        y = pyspline.start_state(dict(z=z, l_x=1e-4, l_y=-3e-5, k_m=0.0, t_end=1e-3, n_out=3))
        model = pyspline.load(dict(z=z, l_x=1e-4, l_y=-3e-5, k_m=0.0, t_end=1e-3, n_out=3))
        acc = model.rhs(0.0, y)[7:]
        assert np.all(np.isfinite(y))
        assert np.abs(acc).max() < 1e-6 * model.info()["k_m"] * 1e-4, (z, acc)


def test_total_work_bound_names_the_field():
    with pytest.raises(pyspline.SolverError, match="max_total_steps = 200 CVODE steps in all"):
        pyspline.simulate(dict(PAPER, name="bounded", l_x=1e-4, roots=True, start="rest",
                               max_total_steps=200, t_end=0.05, n_out=3))


# --------------------------------------------------------------------------- the executable

def test_executable_sigint_exits_130_and_leaves_no_file(exe, tmp_path):
    """SIGINT during a run: exit status 130, the partial output never appears (the CSV is
    written to a temporary name and renamed only when complete). SIGINT's default action in
    the child, also when pytest was started with it ignored (nohup, `&` in a script)."""
    import signal
    import time
    out = tmp_path / "out.csv"
    proc = subprocess.Popen([exe, str(CASES / "paper_T100.nml"), "--set", "t_end=30.0", "-o", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(1.0)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "interrupted" in err
    assert os.listdir(tmp_path) == []


def test_executable_version_matches_the_package(exe):
    # the version and the build (portable or host-tuned): the executable's and the package's
    from pyspline._build_info import BUILD
    run = subprocess.run([exe, "--version"], capture_output=True, text=True)
    assert run.returncode == 0
    assert run.stdout == f"spline-dyn (pyspline) {pyspline.__version__}, {BUILD} build\n"


# ------------------------------------------------------------------------------------ the CLI

def test_cli_run_goes_on_after_a_failure_and_keeps_every_result(tmp_path, capsys):
    from pyspline.cli import main
    out = tmp_path / "out"
    out.mkdir()
    (out / "ok_minimal.npz").write_text("not ours")
    a = tmp_path / "a.nml"
    b = tmp_path / "b.nml"
    for p in (a, b):
        p.write_text((CORPUS / "ok_minimal.nml").read_text())
    status = main(["run", str(a), str(CORPUS / "syntax_misspelt_lx.nml"), "/dev/zero", str(b),
                   "--out", str(out)])
    err = capsys.readouterr().err
    assert status == 2           # the first failure is a CaseError (README: exit code 2)
    assert sum(line.startswith("error: ") for line in err.splitlines()) == 2
    assert (out / "ok_minimal.npz").read_text() == "not ours"          # never replaced
    assert sorted(p.name for p in out.iterdir()) == ["ok_minimal-2.npz", "ok_minimal-3.npz",
                                                    "ok_minimal.npz"]
    # a second run replaces its own earlier results, still not the foreign file
    assert main(["run", str(a), "--out", str(out)]) == 0
    assert (out / "ok_minimal.npz").read_text() == "not ours"
    assert len(list(out.iterdir())) == 3


def test_cli_reproduce_refuses_files_it_did_not_write(tmp_path, capsys):
    from pyspline.cli import main
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text("{}")
    assert main(["reproduce", "--out", str(out), "--quick"]) == 2
    assert "summary.json" in capsys.readouterr().err
    assert (out / "summary.json").read_text() == "{}"


def test_cli_cases_copy_and_scheduler_errors_name_the_argument(tmp_path, capsys):
    """A copy into a folder that does not exist and a --scheduler that is no address: one
    error line naming it and why, exit 2 (they were a FileNotFoundError and a ValueError
    traceback, exit 1); --threads without --workers likewise (it was ignored)."""
    from pyspline.cli import main
    dest = tmp_path / "no" / "such.nml"
    assert main(["cases", "copy", "template", str(dest)]) == 2
    err = capsys.readouterr().err
    assert f"cannot write {dest}: No such file or directory" in err and "Traceback" not in err
    assert main(["sweep", str(CORPUS / "ok_minimal.nml"), "--set", "l_x=0,1e-5",
                 "--scheduler", "nohost", "--out", str(tmp_path / "s"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "--scheduler nohost: no Dask scheduler reached" in err and "port" in err, err
    assert main(["sweep", str(CORPUS / "ok_minimal.nml"), "--set", "l_x=0,1e-5", "--threads",
                 "--out", str(tmp_path / "s"), "--quiet"]) == 2       # ran serially, exit 0
    assert "--threads: an option of --workers N >= 2" in capsys.readouterr().err


def test_cli_plot_writes_inside_out_whatever_the_case_name(tmp_path, capsys):
    """`pyspline plot` names its PNG as `run --out` names its .npz: a case name with '/' wrote
    to out/../../NAME.png, outside --out; a second case of the same name overwrote the first."""
    from pyspline.cli import main
    (tmp_path / "a" / "b").mkdir(parents=True)
    path = tmp_path / "a" / "odd.nml"
    path.write_text((CORPUS / "ok_minimal.nml").read_text().replace("'ok_minimal'", "'../../x y'"))
    assert main(["plot", str(path), str(path), "--out", str(tmp_path / "a" / "b")]) == 0
    assert sorted(p.name for p in tmp_path.rglob("*.png")) == ["_.._x_y-2.png", "_.._x_y.png"]
    assert (tmp_path / "a" / "b" / "_.._x_y-2.png").is_file()


def test_byte_order_mark_is_accepted(tmp_path, exe):
    """A case file that starts with a UTF-8 byte-order mark (EF BB BF, which some editors
    write) is read as without it, by pyspline and by spline-dyn, to the same numbers."""
    body = "&spline_case\n  t_end = 2e-3, n_out = 5\n  c0 = 1.5e-4\n/\n"
    plain, marked = tmp_path / "plain.nml", tmp_path / "marked.nml"
    plain.write_bytes(body.encode())
    marked.write_bytes(b"\xef\xbb\xbf" + body.encode())
    case = pyspline.load_case(marked)
    assert case["c0"] == 1.5e-4 and case["n_out"] == 5 and case["name"] == "marked"
    assert dict(case.replace(name="plain")) == dict(pyspline.load_case(plain))
    outs = []
    for path in (plain, marked):
        out = tmp_path / (path.stem + ".csv")
        run = subprocess.run([exe, str(path), "-o", str(out)], capture_output=True, text=True,
                             timeout=60, stdin=subprocess.DEVNULL)
        assert run.returncode == 0, run.stderr
        outs.append([ln for ln in out.read_text().splitlines() if not ln.startswith("#")])
    assert outs[0] == outs[1] and len(outs[0]) == 6


@pytest.mark.parametrize("name", [k for k, v in pyspline.defaults().items()
                                  if isinstance(v, float) or (isinstance(v, list)
                                                              and isinstance(v[0], float))])
def test_non_finite_real_field_is_named(name):
    """Every real field is checked finite under its own name (the paper's fields and those
    after gamma_y; those beyond the paper up to gamma_y together): the validation's values line
    up with the field table."""
    d = pyspline.defaults()[name]
    value = [math.nan] * len(d) if isinstance(d, list) else math.nan
    with pytest.raises(pyspline.CaseError) as exc:
        pyspline.load_case(dict(PAPER, name="nan", **{name: value})).model
    beyond = list(pyspline.defaults()).index("fillet")
    last = list(pyspline.defaults()).index("gamma_y")     # later fields: each by its own name
    if beyond < list(pyspline.defaults()).index(name) <= last:
        assert "field fillet_radius .. gamma_y (the fields beyond the paper) must be finite" \
            in str(exc.value)
    else:
        assert str(exc.value) == f"case nan: field {name} is not a finite number"


# ------------------------------------------------------------------ one core call per case file

@pytest.mark.parametrize("name", ["paper_lx1e-4.nml", "physical_z24.nml", "chaos_z24.nml"])
def test_file_load_builds_the_model_its_fields_build(name):
    """load_case(path) reads, validates and builds in one core call; that model is the one
    the case's fields build when handed back (api_load_fields) and the one its text builds
    (the reader again): the same sizes, derived quantities, start state and right-hand side."""
    from pyspline import core
    case = pyspline.load_case(CASES / name)
    built, fields = case.model, core.Model(dict(case))
    model, sizes, warn, ierr, msg = pyspline.bridge._api.api_load_text(case.text().encode(), pyspline.bridge.MODEL_BYTES)
    assert ierr == 0
    text = core.Model.__new__(core.Model)
    for k, v in dict(case=case, bytes=model, z=sizes[0], n_out=sizes[1], n_section=sizes[2],
                     n_lyapunov=sizes[3], n_slices=sizes[4]).items():
        object.__setattr__(text, k, v)
    y = built.start_state()
    said = [((m.z, m.n_out, m.n_section, m.n_lyapunov, m.n_slices),
             dict(m.info(), spacing_error=m.info()["spacing_error"].tolist()),
             m.start_state().tolist(), m.rhs(1e-3, y).tolist()) for m in (built, fields, text)]
    assert said[0] == said[1] == said[2]
    assert built.case is case and case.model is built


def test_file_strings_read_as_python_holds_them(tmp_path):
    """A string Python reads differently from the core's bytes (a leading blank, stripped) is
    the case Python holds: its model names the case as Python does."""
    path = tmp_path / "lead.nml"
    path.write_text("&spline_case\n  name = '  lead'\n  b = -0.03\n/\n")
    case = pyspline.load_case(path)
    assert case.name == "lead"
    with pytest.raises(pyspline.CaseError, match=r"^case lead: field b "):
        case.model


@pytest.mark.parametrize("path,words", [
    ("a\0b.nml", "embedded null byte"),
    ("/nonexistent/" + "x" * 5000 + ".nml", "File name too long"),
    ("", "does not exist"),
])
def test_odd_paths_are_clear_case_errors(path, words):
    with pytest.raises(pyspline.CaseError, match=words) as exc:
        pyspline.load_case(path)
    assert str(exc.value).startswith("case file ") and len(str(exc.value)) < 300


def test_values_a_value_array_cannot_carry_get_the_reader_s_message():
    """An integer beyond 32 bits or a string longer than its field goes to the core as text,
    so the reader says what is wrong, as it does in a file."""
    with pytest.raises(pyspline.CaseError, match="does not fit a 32-bit integer"):
        pyspline.load(dict(PAPER, name="big", n_out=2 ** 40))
    with pytest.raises(pyspline.CaseError, match="is longer than 16 characters"):
        pyspline.load(dict(PAPER, name="long", method="adams" * 4))


def test_reader_puts_every_element_in_its_field(tmp_path):
    """The reader puts each checked value at its own element's place (fortran/input/case_parse.f90,
    by case_value_offset and case_put_value of case_values.f90, computed from the field table):
    a file giving every element of every field a different value reads back, through the
    core's value arrays (walk, the list of case_t's components), as written. Not validated (stage 1: read only), so the values need not make a model."""
    from pyspline import case as pc
    rows, nv, nc = pc._layout()
    lines, want = ["&spline_case"], {}
    for k, (name, kind, _, n) in enumerate(rows, start=1):
        if kind == "c":
            want[name] = f"s{k}" if name != "name" else "every element"
            lines.append(f"  {name} = '{want[name]}'")
        elif kind == "i":
            want[name] = 100 + k
            lines.append(f"  {name} = {want[name]}")
        elif kind == "l":
            want[name] = k % 2 == 0
            lines.append(f"  {name} = {'.true.' if want[name] else '.false.'}")
        else:
            x = [k + j / 8 for j in range(1, n + 1)]
            if n == 1:
                want[name] = x[0]
                lines.append(f"  {name} = {x[0]!r}")
            else:
                want[name] = x
                lines += [f"  {name}({j}) = {v!r}" for j, v in enumerate(x, start=1)]
    path = tmp_path / "every.nml"
    path.write_text("\n".join(lines + ["/", ""]))
    _, _, values, chars, _, stage, ierr, msg = pyspline.bridge._api.api_load_file(
        os.fsencode(path), 0, pyspline.bridge.MODEL_BYTES, nv, nc)
    assert stage == 1 and ierr == 0, msg
    assert pc._fields_of(values, chars)[0] == want
