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


def test_extremes_in_xarray_round_trip(tmp_path):
    """Result.extremes (the core's run_extremes) in to_xarray as run_<name>, with units, through
    a netCDF file and back; the largest, smallest and RMS are those of the outputs themselves."""
    import xarray as xr
    from pyspline.result import EXTREMES, cf_units
    res = pyspline.simulate(pyspline.load_case(CASES / "paper_flash_lx1e-4.nml", t_end=0.02,
                                               n_out=81))
    path = tmp_path / "run.nc"
    res.to_xarray().to_netcdf(path, engine="netcdf4")
    with xr.open_dataset(path, engine="netcdf4") as ds:
        assert {n: float(ds["run_" + n]) for n in EXTREMES} == res.extremes
        for n, (long, unit) in EXTREMES.items():
            assert ds["run_" + n].dims == () and ds["run_" + n].attrs["long_name"] == long
            assert ds["run_" + n].attrs.get("units", "") == cf_units(unit), n
        for q in ("Tm", "kv", "F", "Tf", "D2", "vD2"):
            v = ds[q].values.ravel()
            assert float(ds[f"run_{q}_max"]) == v.max() and float(ds[f"run_{q}_min"]) == v.min()
            np.testing.assert_allclose(float(ds[f"run_{q}_rms"]), np.sqrt(np.mean(v**2)),
                                       rtol=1e-12, err_msg=q)
        assert float(ds["run_Tf_max"]) > 0 and float(ds["run_Tm_min"]) < float(ds["run_Tm_max"])
