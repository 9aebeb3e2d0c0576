"""Names, units and descriptions live once, in the core's tables (fortran/common/quantities.f90: the
output quantities and run statistics; fortran/input/case_type.f90: the case fields), read through
api_names. Every place that shows them says what the tables say: the README's result table,
Result.to_xarray, the sweep dataset, spline-dyn's CSV header (cases/template.nml's units:
tests/test_input.py)."""
import re
import subprocess

import numpy as np
import pytest

import pyspline
from pyspline.core import _names, cf_units
from pyspline.dataset import field_meta
from conftest import CASES, ROOT, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

OUTPUTS = {n: (u, d) for n, u, d in _names("outputs")}
TOOTH = [n for n, *_ in _names("tooth")]
STATES = [n for n, *_ in _names("states")]
STATS = {n: (u, d) for n, u, d in _names("stats")}
FIELD_UNITS = {n: u for n, u, _ in _names("fields")}
LOADS = {n: (u, d) for n, u, d in [*_names("loads"), *_names("tooth_loads")]}


@pytest.fixture(scope="module")
def short():
    return pyspline.load_case(CASES / "paper_lx1e-4.nml", t_end=0.01, n_out=41)


def test_the_tables_are_whole():
    """Every output and statistic has a description; the lists are the parts of 'outputs'
    (t, states, Tm, kv, per tooth: the CSV's order); statistics whose name carries a unit
    (_s, _degC) have that unit."""
    assert all(d for u, d in OUTPUTS.values()) and all(d for u, d in STATS.values())
    assert list(OUTPUTS) == ["t", *STATES, "Tm", "kv", *TOOTH]
    for n, (u, _) in STATS.items():
        for suffix, unit in (("_s", "s"), ("_degC", "degC")):
            if n.endswith(suffix):
                assert u == unit, n
    assert len(STATES) == 14 and STATES[7:] == ["v" + n for n in STATES[:7]]
    assert all(OUTPUTS["v" + n][0] == OUTPUTS[n][0] + "/s" for n in STATES[:7])


def test_readme_result_table_gives_every_quantity_the_core_unit():
    text = (ROOT / "README.md").read_text()
    table = text[text.index("| quantity | unit | meaning |"):]
    table = table[:table.index("\n\n")].splitlines()[2:]
    listed = {}
    for row in table:
        cells = [c.strip() for c in row.strip().strip("|").split("|")]
        for code in re.findall(r"`([^`]+)`", cells[0]):
            for name in code.split():
                listed[name] = cells[1]
    for n, (u, _) in {**OUTPUTS, **LOADS}.items():
        assert n in listed, f"README's result table does not list {n}"
        assert listed[n] == u, (n, listed[n], u)


def test_result_to_xarray_takes_the_core_table(short):
    res = pyspline.simulate(short.replace(section="shaft"))
    ds = res.to_xarray()
    for n, (u, d) in OUTPUTS.items():
        v = ds["time" if n == "t" else n]
        assert v.attrs["long_name"] == d, n
        assert v.attrs.get("units", "") == cf_units(u), n
    assert ds["kv"].attrs["units"] == "1"          # CF: a ratio
    assert len(ds["section_t"]) > 0
    for n in STATES:
        assert ds["section_" + n].attrs["units"] == OUTPUTS[n][0], n
    assert set(res.stats) == set(STATS) | {"wall_s"}
    for n, (u, _) in STATS.items():          # counts are integers, quantities with a unit not
        assert isinstance(res.stats[n], float if u else int), n


def test_sweep_dataset_takes_the_core_tables(short):
    ds = pyspline.sweep(short, progress=False, speed_rpm=[3000.0, 6000.0])
    seen = set()
    for k, v in ds.variables.items():
        unit = v.attrs.get("units", "")
        m = re.fullmatch(r"(\w+?)_(max|min|rms|spectrum)", k)
        if k in STATS:
            expected = STATS[k][0]
        elif k in LOADS and k != "Tf_max":
            expected = LOADS[k][0]
            assert v.attrs["long_name"] == LOADS[k][1], k
        elif m and m.group(1) in OUTPUTS:
            expected = OUTPUTS[m.group(1)][0]
        elif k.startswith("section_") and k[8:] in OUTPUTS:
            expected = OUTPUTS[k[8:]][0]
        elif k in FIELD_UNITS:
            expected = FIELD_UNITS[k]
        else:
            continue
        assert unit == cf_units(expected), (k, unit, expected)
        seen.add(k)
    for k in ("Tm_max", "kv_rms", "F_min", "Tf_max", "D2_max", "section_D2", "section_vD2",
              "Tm_spectrum", "steps", "last_step_s", "coupling_residual_degC", "speed_rpm",
              "load_sharing", "impacts_per_rev", "closing_speed_max", "back_frac_max"):
        assert k in seen, k
    assert ds["speed_rpm"].attrs["long_name"] == "shaft speed"


def test_field_meta_is_the_core_field_table():
    meta = field_meta()
    fields = _names("fields")
    assert list(meta) == [n for n, *_ in fields] and set(meta) == set(pyspline.defaults())
    for n, u, d in fields:
        assert meta[n][1] == cf_units(u), n
        assert meta[n][0] in (d, n), n


def test_executable_csv_header_takes_the_core_table(exe, short, tmp_path):
    nml = tmp_path / "c.nml"
    short.replace(n_out=3).to_namelist(nml)
    out = tmp_path / "c.csv"
    run = subprocess.run([exe, str(nml), "-o", str(out)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    header, data = pyspline.core.read_csv(out)
    z = short["z"]
    expected = [f"{n} [{u}]" for n, (u, _) in OUTPUTS.items() if n not in TOOTH]
    expected += [f"{n}_{j} [{OUTPUTS[n][0]}]" for n in TOOTH for j in range(1, z + 1)]
    assert header == expected
    stats = open(out).read().split("# stats:")[1].splitlines()[0].split()
    assert [s.split("=")[0] for s in stats] == list(STATS)
    res = pyspline.simulate(short.replace(n_out=3))
    np.testing.assert_array_equal(data[:, header.index("kv [-]")], res.kv)
