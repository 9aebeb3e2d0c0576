"""The loads of a run (fortran/physics/loads.f90, docs/model.md section 15): load sharing against the
closed form of static full contact (aligned and with parallel misalignment), free and
back-flank fractions and contact onsets against a count from Result.F and Result.dn, the closing
speed against the oracle's d(dn)/dt, and the executable's numbers against Python's."""
import subprocess
import warnings

import numpy as np
import pytest

import oracle
import pyspline
from pyspline.core import LOAD_QUANTITIES, TOOTH_LOAD_QUANTITIES
from pyspline.summary import SWEEP_LOADS
from conftest import CASES, PAPER_SHAFTS, PAPER_SUPPORTS

#: the offset scenes below are built to impact (offset beyond the backlash, from rest): their
#: supports, start and stress warnings are expected
pytestmark = [PAPER_SHAFTS, PAPER_SUPPORTS, pytest.mark.filterwarnings(
    r"ignore:case offset\w*:pyspline.SplineWarning")]

REV_OUT = 721       # outputs in one revolution: each tooth's angle sweeps 2 pi in 0.5 deg steps


def full_contact(**kw):
    """The template drive (Z 16, 30.7 N m, 6000 r/min) without gravity and mesh damping, from
    its static equilibrium, over one revolution (unless kw say otherwise): every tooth stays on
    its drive flank."""
    kw = {"t_end": 0.01, "n_out": REV_OUT, **kw}
    return pyspline.load_case(CASES / "template.nml", name="full", grav=0.0, c_m=0.0, **kw)


def test_aligned_full_contact_shares_the_load_equally():
    """docs/model.md section 15: an aligned drive in static full contact has F_j = -T_d/(Z r_b)
    on every tooth: load factor 1, no tooth free or on its back flank, no onset."""
    case = full_contact()
    res = pyspline.simulate(case)
    ld, info = res.loads, case.model.info()
    fs = case["t_d"] / (case["z"] * info["r_b"])
    assert ld["F_static"] == pytest.approx(fs, rel=1e-14)
    assert ld["F_static"] == pytest.approx(138.5, abs=0.05)      # the paper's tooth load
    np.testing.assert_allclose(ld["load_factor"], 1.0, rtol=1e-8)
    assert ld["load_sharing"] == pytest.approx(1.0, rel=1e-8)
    for n in ("free_frac", "back_frac", "onsets"):
        assert not ld[n].any(), n
    assert ld["impacts_per_rev"] == 0 and ld["teeth_back"] == 0 and ld["teeth_free_mean"] == 0
    assert ld["revolutions"] == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize("l_x, l_y", [(1e-4, 0.0), (6e-5, -8e-5)])
def test_misaligned_full_contact_load_sharing_closed_form(l_x, l_y):
    """Parallel misalignment in full contact (Z >= 3, c_m = 0, no gravity): summing
    F_j = k_m (dn_j + c) over the teeth gives F_j = -F_s + k_m (e_x sin phi_j - e_y cos phi_j)
    and a mesh that acts on the centre offset e as an isotropic spring K = k_m Z / 2, so the
    supports hold e = (l_x, l_y) / (1 + K/k_p1 + K/k_p2). As each tooth turns through a
    revolution its load peaks at F_s + k_m |e|: every load factor is 1 + k_m |e| / F_s."""
    case = full_contact(l_x=l_x, l_y=l_y, k_p2=8e6)
    res = pyspline.simulate(case)
    info = case.model.info()
    k_m, z = info["k_m"], case["z"]
    K = k_m * z / 2
    e = np.hypot(l_x, l_y) / (1 + K / case["k_p1"] + K / case["k_p2"])
    fs = case["t_d"] / (z * info["r_b"])
    expected = 1 + k_m * e / fs
    assert 1.05 < expected < 1.5                           # the misalignment term is seen
    ld = res.loads
    assert ld["load_sharing"] == pytest.approx(expected, rel=2e-5)
    np.testing.assert_allclose(ld["load_factor"], expected, rtol=2e-5)
    assert not ld["free_frac"].any() and not ld["back_frac"].any() and not ld["onsets"].any()


def independent_count(res, drive=-1):
    """Free, back-flank and onset counts from Result.F and Result.dn (a tooth is free where
    F_j = 0, else on the flank of the sign of dn_j)."""
    flank = np.where(res.F == 0, 0, np.sign(res.dn)).astype(int)
    onset = (flank[1:] != 0) & (flank[1:] != flank[:-1])
    return flank, onset


@pytest.fixture(scope="module")
def offset_scene():
    """A light drive (2 N m) whose spline 1 sits 0.4 mm off centre against 0.2 mm backlash,
    started at rest: teeth hit both flanks, some never touch, with the one-way flash temperature."""
    case = pyspline.load_case(CASES / "template.nml", name="offset", t_d=2.0, t_l=2.0, l_x=4e-4,
                              grav=0.0, start="rest", thermal="oneway", t_end=0.03, n_out=1201)
    return case, pyspline.simulate(case)


def test_free_back_flank_and_onsets_against_a_count(offset_scene):
    case, res = offset_scene
    ld = res.loads
    flank, onset = independent_count(res)
    nt, z = res.F.shape
    np.testing.assert_array_equal(ld["free_frac"], (flank == 0).sum(0) / nt)
    np.testing.assert_array_equal(ld["back_frac"], (flank == 1).sum(0) / nt)
    np.testing.assert_array_equal(ld["onsets"], onset.sum(0))
    np.testing.assert_array_equal(ld["F_peak"], np.abs(res.F).max(0))
    assert ld["teeth_back"] == ((flank == 1).any(0)).sum() > 0         # the scene has them
    assert ld["teeth_unloaded"] == ((flank == 0).all(0)).sum() > 0
    assert ld["teeth_free_mean"] == pytest.approx((flank == 0).sum(1).mean(), rel=1e-14)
    revs = case["speed_rpm"] / 60 * (res.t[-1] - res.t[0])
    assert ld["revolutions"] == pytest.approx(revs, rel=1e-12)
    assert onset.sum() > 0
    assert ld["impacts_per_rev"] == pytest.approx(onset.sum() / revs, rel=1e-12)
    fs = case["t_d"] / (case["z"] * case.model.info()["r_b"])
    assert ld["load_sharing"] == pytest.approx(np.abs(res.F).max() / fs, rel=1e-14)
    # the closing speed: |d dn_j/dt| at the output before each onset, from the oracle's Eq. 11
    p = oracle.prepare({**dict(case), "k_m": case.model.info()["k_m"]})
    speeds = [abs(oracle.mesh(res.t[k], res.y[k], p)["ddn"][j]) for k, j in zip(*onset.nonzero())]
    assert ld["closing_speed_max"] == pytest.approx(max(speeds), rel=1e-9)
    # the flash temperature's peak, its tooth and time
    k, j = np.unravel_index(np.argmax(res.Tf), res.Tf.shape)
    assert res.Tf[k, j] > 0
    assert (ld["Tf_max"], ld["Tf_max_tooth"], ld["Tf_max_t_s"]) == (res.Tf[k, j], j + 1, res.t[k])


def test_no_drive_torque_has_no_load_factor():
    """T_d = 0: the static tooth load is 0, load factors are NaN (undefined), not infinite;
    the counts remain."""
    case = pyspline.load_case(CASES / "template.nml", name="offset0", t_d=0.0, t_l=0.0,
                              l_x=4e-4, grav=0.0, start="rest", t_end=0.005, n_out=201)
    ld = pyspline.simulate(case).loads
    assert ld["F_static"] == 0 and np.isnan(ld["load_sharing"])
    assert np.isnan(ld["load_factor"]).all() and ld["onsets"].sum() > 0


def test_loads_in_xarray_and_npz(offset_scene, tmp_path):
    case, res = offset_scene
    ds = res.to_xarray()
    for n, (d, u) in {**LOAD_QUANTITIES, **TOOTH_LOAD_QUANTITIES}.items():
        v = ds[n]
        assert v.dims == (("tooth",) if n in TOOTH_LOAD_QUANTITIES else ()), n
        assert v.attrs["long_name"] == d and v.attrs.get("units", "") == {"-": "1"}.get(u, u), n
        np.testing.assert_array_equal(v.values, res.loads[n])
    from pyspline.cli import _summary, main
    line = _summary(res)
    assert f"load sharing {res.loads['load_sharing']:.3f}" in line and "impacts/rev" in line
    nml = tmp_path / "offset.nml"
    case.replace(section="shaft").to_namelist(nml)
    assert main(["run", str(nml), "--out", str(tmp_path / "out")]) == 0
    with np.load(tmp_path / "out" / "offset.npz") as f:
        for n in ("kv", "section_t", "section_y", "stat_steps", *LOAD_QUANTITIES,
                  *TOOTH_LOAD_QUANTITIES):
            assert n in f.files, n
        np.testing.assert_array_equal(f["kv"], np.abs(f["Tm"]) / case["t_d"])


def test_k_v_takes_the_magnitude_of_a_reversed_or_zero_drive_torque(tmp_path, exe):
    """k_v = |T_m| / |T_d|: a reversed drive in static full contact has k_v = 1, not -1, in
    Python, the core's extremes and spline-dyn's CSV. At T_d = 0 k_v and the load sharing are
    NaN (README) without a numpy warning, `pyspline run` says the load sharing is undefined, and
    merge takes spline-dyn's summary of it as sweep takes the point (it refused kv_max = nan)."""
    import warnings
    from pyspline.batch import merge
    from pyspline.cli import _summary
    from conftest import assert_executable_matches_python
    case = full_contact(t_d=-30.7, t_l=-30.7, n_out=11)
    _, col, data, res = assert_executable_matches_python(case, exe, tmp_path)
    np.testing.assert_allclose(res.kv, 1.0, rtol=1e-8)
    np.testing.assert_array_equal(data[:, col["kv"]], res.kv)
    assert res.extremes["kv_max"] == res.kv.max() and res.extremes["kv_min"] == res.kv.min()
    zero = full_contact(t_d=0.0, t_l=0.0, n_out=11, start="rest")
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        res = pyspline.simulate(zero)
        assert np.isnan(res.kv).all() and np.isnan(res.loads["load_sharing"])
        assert "load sharing undefined (T_d = 0" in _summary(res)
    zero.to_namelist(tmp_path / "zero.nml")
    subprocess.run([exe, str(tmp_path / "zero.nml"), "--summary", str(tmp_path / "zero.summary")],
                   check=True, capture_output=True)
    ds = merge([tmp_path / "zero.summary"])
    assert ds.attrs["n_ok"] == 1 and np.isnan(ds["kv_max"].values).all()
    # a driveless drive that still moves (chaos_z24's excitation): T_m != 0, k_v still NaN
    moving = pyspline.load_case(CASES / "chaos_z24.nml", t_d=0.0, t_l=0.0, start="rest",
                                t_transient=0.0, t_end=0.02, n_out=41, lyapunov=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        res = pyspline.simulate(moving)
    assert np.abs(res.Tm).max() > 1.0
    assert np.isnan(res.kv).all() and np.isnan([res.extremes[k] for k in ("kv_max", "kv_rms")]).all()
    moving.to_namelist(tmp_path / "moving.nml")
    subprocess.run([exe, str(tmp_path / "moving.nml"), "-o", str(tmp_path / "moving.csv"),
                    "--summary", str(tmp_path / "moving.summary")], check=True, capture_output=True)
    with warnings.catch_warnings():          # the case's start and stress warnings, again
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        assert merge([tmp_path / "moving.summary"]).attrs["n_ok"] == 1


def read_csv_loads(path) -> dict:
    """The loads spline-dyn writes in its CSV's comment lines."""
    out = {}
    for line in open(path):
        if not line.startswith("#"):
            break
        if line.startswith("# loads:"):
            out.update((k, float(v)) for k, v in (w.split("=") for w in line[8:].split()))
        elif line.startswith("# tooth loads "):
            head, values = line[14:].split(":")
            out[head.split()[0]] = np.array(values.split(), dtype=float)
    return out


@pytest.mark.parametrize("scene", ["offset", "paper_flash_lx1e-4"])
def test_executable_writes_the_same_loads(exe, offset_scene, scene, tmp_path):
    case = offset_scene[0] if scene == "offset" else \
        pyspline.load_case(CASES / f"{scene}.nml", t_end=0.02, n_out=401)
    nml, out = tmp_path / "c.nml", tmp_path / "c.csv"
    case.to_namelist(nml)
    run = subprocess.run([exe, str(nml), "-o", str(out)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "load sharing factor" in run.stdout
    assert "standard errors (overlapping batch means" in run.stdout
    assert "largest stress over its typical allowable" in run.stdout
    # a summary-only run (batch) prints the same answers
    quiet = subprocess.run([exe, str(nml), "--summary", str(tmp_path / "c.summary")],
                           capture_output=True, text=True)
    assert quiet.returncode == 0, quiet.stderr
    answers = run.stdout[run.stdout.index("  load sharing factor"):]
    assert quiet.stdout.endswith(answers[:answers.index("\n  " + "steps")] + "\n")
    got = read_csv_loads(out)
    res = pyspline.simulate(case)
    assert set(got) == set(res.loads)
    for n, v in res.loads.items():
        np.testing.assert_array_equal(got[n], v, err_msg=n)      # bit for bit


def test_sweep_keeps_the_loads(offset_scene):
    """The sweep dataset's loads are the points' Result.loads (units from the core's table)."""
    case = offset_scene[0].replace(t_end=0.02, n_out=801, thermal="none")
    ds = pyspline.sweep(case, progress=False, l_x=[2e-4, 4e-4])
    for i, lx in enumerate([2e-4, 4e-4]):
        ld = pyspline.simulate(case.replace(l_x=lx)).loads
        for n in SWEEP_LOADS + ("Tf_max",):
            assert ds[n].values[i] == ld[n] and np.isfinite(ld[n]), n
    assert ds["closing_speed_max"].attrs["units"] == "m/s"
    assert ds["load_sharing"].attrs["units"] == "1"


def test_batch_means_against_a_count(offset_scene):
    """Standard errors by batch means over whole revolutions, recomputed from Result.Tm and
    Result.F: per revolution the RMS of T_m and the load-sharing factor."""
    case, res = offset_scene
    ld = res.loads
    rev = np.floor(case["speed_rpm"] / 60 * (res.t - res.t[0])).astype(int)
    nb = int(np.floor(case["speed_rpm"] / 60 * (res.t[-1] - res.t[0])))
    assert ld["batches"] == nb >= 2
    fs = ld["F_static"]
    rms = np.array([np.sqrt(np.mean(res.Tm[rev == b] ** 2)) for b in range(nb)])
    share = np.array([np.abs(res.F[rev == b]).max() / fs for b in range(nb)])
    assert ld["Tm_rms_se"] == pytest.approx(rms.std(ddof=1) / np.sqrt(nb), rel=1e-9)
    assert ld["load_sharing_rev"] == pytest.approx(share.mean(), rel=1e-12)
    assert ld["load_sharing_rev_se"] == pytest.approx(share.std(ddof=1) / np.sqrt(nb), rel=1e-9)
    assert ld["load_sharing_rev_se"] > 0


def test_batch_means_of_a_periodic_run_vanish():
    """Full contact with misalignment repeats every revolution: the standard errors are round-off
    and solver noise, the mean per-revolution load sharing is the run's."""
    res = pyspline.simulate(full_contact(l_x=1e-4, t_end=0.03, n_out=3 * (REV_OUT - 1) + 1))
    ld = res.loads
    assert ld["batches"] == 3
    assert ld["Tm_rms_se"] < 1e-8 * 30.7                 # T_d
    assert ld["load_sharing_rev"] == pytest.approx(ld["load_sharing"], rel=1e-6)
    assert ld["load_sharing_rev_se"] < 1e-6
    one = pyspline.simulate(full_contact(t_end=0.015, n_out=1081)).loads
    assert one["batches"] == 1 and np.isnan(one["Tm_rms_se"]) and np.isnan(one["load_sharing_rev"])


def obm_se(x):
    """Overlapping batch means (Meketon & Schmeiser 1984), batches of floor(sqrt(n)) values,
    written from the formula of docs/model.md section 15 (not the core's loop)."""
    x = np.asarray(x, dtype=float)
    n = len(x)
    m = int(np.sqrt(n))
    means = np.convolve(x, np.ones(m) / m, mode="valid")
    return np.sqrt(m * np.sum((means - x.mean()) ** 2) / ((n - m) * (n - m + 1)))


def test_batch_means_of_every_statistic_against_a_count():
    """Batches of m = 3 revolutions (10 whole revolutions of the offset scene, which keeps
    impacting): every standard error, recomputed here per revolution from Result.Tm, kv, F, dn,
    D2 and Tf with the flank count of independent_count, and the standard error of the tooth
    with the largest fraction for free_frac_max_se / back_frac_max_se."""
    case = pyspline.load_case(CASES / "template.nml", name="offset10", t_d=2.0, t_l=2.0,
                              l_x=4e-4, grav=0.0, start="rest", thermal="oneway", t_end=0.1,
                              n_out=1999)
    res = pyspline.simulate(case)
    ld = res.loads
    omega = case["speed_rpm"] * 2 * np.pi / 60
    rev = np.floor(omega * (res.t - res.t[0]) / (2 * np.pi)).astype(int)   # as the core rounds
    nb = int(ld["batches"])
    assert nb == 10 and int(np.sqrt(nb)) == 3
    flank, onset = independent_count(res)
    onset = np.vstack([np.zeros((1, flank.shape[1]), bool), onset])          # at output k
    by = [rev == b for b in range(nb)]
    rms = lambda x: np.sqrt(np.mean(x ** 2))                                  # noqa: E731
    per_rev = {
        "Tm_rms_se": [rms(res.Tm[k]) for k in by],
        "kv_rms_se": [rms(res.kv[k]) for k in by],
        "F_rms_se": [rms(res.F[k]) for k in by],
        "D2_rms_se": [rms(res.D2[k]) for k in by],
        "teeth_free_mean_se": [(flank[k] == 0).sum(1).mean() for k in by],
        "impacts_per_rev_se": [onset[k].sum() for k in by],
        "Tf_max_rev_se": [res.Tf[k].max() for k in by],
        "load_sharing_rev_se": [np.abs(res.F[k]).max() / ld["F_static"] for k in by],
    }
    for n, x in per_rev.items():
        assert ld[n] == pytest.approx(obm_se(x), rel=1e-9, abs=1e-300), n
        assert ld[n] > 0, n                                    # the scene varies between revolutions
    assert ld["Tf_max_rev"] == pytest.approx(np.mean(per_rev["Tf_max_rev_se"]), rel=1e-12)
    assert ld["load_sharing_rev"] == pytest.approx(np.mean(per_rev["load_sharing_rev_se"]), rel=1e-12)
    free = np.array([(flank[k] == 0).mean(0) for k in by])                    # (nb, Z)
    back = np.array([(flank[k] == 1).mean(0) for k in by])
    np.testing.assert_allclose(ld["free_frac_se"], [obm_se(c) for c in free.T], rtol=1e-9)
    np.testing.assert_allclose(ld["back_frac_se"], [obm_se(c) for c in back.T], rtol=1e-9)
    assert ld["free_frac_max_se"] == ld["free_frac_se"][np.argmax(ld["free_frac"])]
    assert ld["back_frac_max_se"] == ld["back_frac_se"][np.argmax(ld["back_frac"])]
    assert (ld["free_frac_se"] > 0).any() and (ld["back_frac_se"] > 0).any()
    # the standard error of a mean of correlated batches is not the naive one
    naive = np.std(per_rev["Tm_rms_se"], ddof=1) / np.sqrt(nb)
    assert ld["Tm_rms_se"] != pytest.approx(naive, rel=1e-3)


def test_run_answers_the_engineers_questions(capsys):
    """`pyspline run CASE` answers, one line each: which teeth carry what, does it rattle, how
    hot, how close to the limits, how far to trust it, is the input plausible (README). --fix
    changes a field; the numbers are the run's loads."""
    from pyspline.cli import main
    path = CASES / "physical_z24.nml"
    assert main(["run", str(path), "--fix", "t_end=0.1", "--fix", "n_out=401",
                 "--fix", "thermal=oneway"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert [ln.split(":")[0].strip() for ln in out[1:]] == ["teeth", "rattle", "heat", "limits",
                                                             "trust", "input"]
    ld = pyspline.simulate(pyspline.load_case(path, t_end=0.1, n_out=401, thermal="oneway")).loads
    assert f"load sharing {ld['load_sharing']:.3f} (tooth {ld['load_sharing_tooth']:.0f}" in out[1]
    assert f"T_f max {ld['Tf_max']:.3g} degC (tooth {ld['Tf_max_tooth']:.0f}" in out[3]
    assert f"{100 * ld['stress_ratio']:.0f} % of the typical allowable" in out[4]
    assert f"{ld['revolutions']:.1f} revolutions" in out[5] and "+-" in out[5]
    # physical_z24 keeps the paper's 5e6 N/m supports: the support warning (tests/test_warnings.py)
    assert out[6].endswith("1 plausibility warning (the warning: lines)")
    assert main(["run", str(CASES / "physical_ripple.nml"), "--fix", "t_end=0.11"]) == 0
    assert capsys.readouterr().out.splitlines()[-1].endswith("no plausibility warning")
    # the stress ratio is the largest stress over its limit (docs/model.md section 15)
    limits = {"sigma_root": 400e6, "sigma_flank": 310e6, "tau_pitch": 345e6}
    assert ld["stress_ratio"] == pytest.approx(max(ld[n] / v for n, v in limits.items()), rel=1e-14)


def test_sparse_outputs_warn_that_the_peaks_read_low():
    """The peaks (load sharing, tooth forces, root stresses) are taken at the output times
    (spline_run::output_warning). Measured on this Z = 20 drive (40 revolutions after 10, load
    sharing k_v / root stress at outputs per tooth-passing period 60/(Z n)): 0.025: 10.03 /
    30.40 MPa, 0.1: 11.29 / 34.22, 0.25-1: 11.62 / 35.23, 2: 11.674 / 35.39, 3 and up to 100:
    11.68 / 35.42 MPa. Fewer than 2 per period is warned, naming the number."""
    case = dict(name="z20", z=20, module_m=2e-3, s=3.1416e-3, b=0.025, c0=1.2e-4,
                speed_rpm=4500.0, t_d=80.0, t_l=80.0, l_x=4e-5, l_y=1e-5, zeta_m=0.02,
                k_t1=9000.0, k_t2=9000.0, spacing_error=[0, 2e-5, 0, -1e-5, 0, 0, 3e-5],
                start="rest", revolutions=40, transient_revolutions=10)

    def run(per_rev):
        with pytest.warns() as rec:
            warnings.simplefilter("always")
            ld = pyspline.simulate(pyspline.load_case(
                case, outputs_per_revolution=per_rev)).loads
        return ld, [str(w.message) for w in rec if "tooth-passing period" in str(w.message)]

    sparse, said = run(0.5)
    dense, quiet = run(60)
    assert quiet == [] and len(said) == 1
    assert "0.0250 outputs per tooth-passing period 60/(Z n) = 6.667E-04 s (limit 2)" in said[0]
    assert "outputs_per_revolution >= 40?" in said[0]
    assert sparse["load_sharing"] < 0.9 * dense["load_sharing"]
    assert sparse["sigma_root"] < 0.9 * dense["sigma_root"]
