"""The one module that talks to the compiled core (pyspline._core, f2py over
fortran/interface/api.f90): every call of the core from Python goes through a name here.

Each name is the core's routine itself (no wrapper: same arguments, same return tuple, same
numbers), named for what it does; f2py's own docstring gives its signature. Whoever calls them
(case.py, result.py, core.py, orbits.py) turns the core's (ierr, message) into exceptions and
its value arrays into Python's. This module imports no other of pyspline's, so every layer can
build on it (tests/test_imports.py holds that no other module imports the extension).
"""
try:
    from . import _core
except ImportError as exc:  # the source tree shadows the installed package
    raise ImportError(
        f"pyspline's compiled core (_core) is not next to {__file__}: this is the source tree, "
        "not the installed package. Run `bash scripts/setup.sh` (pip install .) and import "
        "pyspline from outside the repository root (or use the `pyspline` command).") from exc

_api = _core.spline_api

# the case (fortran/input/): its field table, defaults, reading, and loading into a model
MODEL_BYTES = int(_api.api_model_size())   #: size of a loaded model (model_t) in bytes
name_entry = _api.api_names             #: (kind, i) -> entry i of the core's list `kind`
defaults = _api.api_defaults            #: every field's default as value arrays
field_hint = _api.api_field_hint        #: the field nearest a misspelt name
read_text = _api.api_read_text          #: namelist text -> value arrays (read, not validated)
load_file = _api.api_load_file          #: a case file checked, read, validated, built
load_text = _api.api_load_text          #: namelist text validated and built into a model
load_fields = _api.api_load_fields      #: value arrays validated and built into a model

# a loaded model (its bytes): derived values and the right-hand side
model_info = _api.api_model_info        #: derived quantities, Eq. 18 terms, spacing errors
output_times = _api.api_output_times    #: the run's output times
start_state = _api.api_start_state      #: start state (transient = 1: after the transient)
rhs = _api.api_rhs                      #: dy/dt at (t, y)
rhs_mesh = _api.api_rhs_mesh            #: dy/dt, the per-tooth mesh and T_m at (t, y)
tooth_stiffness = _api.api_tooth_stiffness   #: one tooth's Eq. 18 terms (no model)

# runs
simulate = _api.api_simulate            #: one run: outputs, loads, extremes, warnings
results = _api.api_results              #: the loads, extremes, warnings of copies' outputs
period_map = _api.api_period_map        #: the period map of several start states
map_monodromy = _api.api_map_monodromy  #: the period map and its monodromy
