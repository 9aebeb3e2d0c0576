"""Bad input: a clear error naming the field (or the CVODE flag, the time and the case)."""
import math
import subprocess

import f90nml
import pytest

import pyspline
from conftest import CASES, PAPER


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
    (dict(method="rk4"), ["method", "bdf or adams"]),
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
