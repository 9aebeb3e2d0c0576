"""The per-tooth outputs of a run (fortran/interface/run.f90 tooth_outputs): formed after the integration
from the stored states, they are the mesh (mesh_eval, Model.rhs_mesh) at those states to the bit,
whichever way the core forms them (one pass per tooth at thermal none and bulk)."""
import numpy as np
import pytest

import pyspline
from conftest import CASES, DEMONSTRATION_SCENES, PAPER_SHAFTS, PAPER_SUPPORTS

pytestmark = [PAPER_SHAFTS, PAPER_SUPPORTS]   # expected warnings (conftest)


@pytest.mark.parametrize("name, kw", [
    ("paper_lx1e-4", dict(t_end=0.2, n_out=1281)),                        # thermal none, tail
    ("paper_lx1e-4", dict(t_end=0.05, n_out=321, linear_tail=False)),      # transient, impacts
    ("physical_z24", dict(t_end=0.05, n_out=201, thermal="bulk")),         # bulk backlash, Z = 24
    ("paper_flash_lx1e-4", dict(t_end=0.05, n_out=201)),                   # one-way: flash path
    ("paper_T100", dict(t_end=0.05, n_out=201, thermal="bulk", roots=False)),
    ("paper_lx1e-4", dict(t_end=0.05, n_out=201, spacing_error_amp=5e-5,   # spacing errors
                          spacing_error_seed=3)),
])
def test_tooth_outputs_are_the_mesh_at_the_stored_states(name, kw):
    res = pyspline.simulate(pyspline.load_case(CASES / f"{name}.nml", **kw))
    model = pyspline.load(res.case)
    free = 0
    for k in range(len(res.t)):
        _, mesh, tm = model.rhs_mesh(res.t[k], res.y[k])
        for q, a in res.tooth.items():
            np.testing.assert_array_equal(a[k], mesh[q], err_msg=f"{q} at output {k}")
        assert res.Tm[k] == tm
        free += np.count_nonzero(mesh["F"] == 0.0)
    if not kw.get("linear_tail", True):
        assert free > 0      # the transient has teeth in the dead zone: both branches compared


@DEMONSTRATION_SCENES
@pytest.mark.parametrize("path", sorted(CASES.glob("*.nml")), ids=lambda p: p.stem)
def test_no_output_falls_back_to_mesh_eval(path):
    """Every shipped case, its first 5 ms: the per-tooth outputs come from mesh_outputs, not its
    fallback to mesh_eval (a drift between the two, which would show only as a slowdown; the
    comparison at every output: tests/fortran/test_outputs.f90)."""
    case = pyspline.load_case(path, t0=0.0, t_end=5e-3, n_out=101, t_transient=0.0,
                              revolutions=0.0, transient_revolutions=0.0,
                              outputs_per_revolution=0.0)
    assert pyspline.simulate(case).stats["outputs_fallback"] == 0
