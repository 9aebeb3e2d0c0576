"""The per-tooth outputs of a run (fortran/run.f90 tooth_outputs): formed after the integration
from the stored states, they are the mesh (mesh_eval, Model.rhs_mesh) at those states to the bit,
whichever way the core forms them (one pass per tooth at thermal none and bulk)."""
import numpy as np
import pytest

import pyspline
from conftest import CASES, PAPER_SHAFTS, PAPER_SUPPORTS

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
