"""realisations = K (docs/accuracy.md): K perturbed copies after the transient read the statistics
one long run reads, with standard errors from their spread; spline-dyn gives Python's numbers."""
import concurrent.futures as cf
import re
import subprocess
import warnings

import numpy as np
import pytest

import pyspline
from conftest import CASES, assert_executable_matches_python
from pyspline.cli import _summary


def chaos(**fields):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)   # the case's soft shafts
        return pyspline.load_case(CASES / "chaos_z24.nml",
                                  **{"goal": "statistics", "lyapunov": False, **fields})


def simulate(case, executor=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        return pyspline.simulate(case, executor)


def rms(res):
    """T_m RMS of a result, or of an array of T_m"""
    tm = res if isinstance(res, np.ndarray) else res.Tm
    return float(np.sqrt(np.mean(tm ** 2)))


def test_realisations_combine_to_one_long_runs_statistics():
    """chaos_z24 after its engagement, 30 revolutions sampled: one run against 3 copies of 10
    revolutions each; T_m RMS, free teeth and impacts per revolution agree within 3 combined
    standard errors (the copies' from their spread), and the copies' trajectories part."""
    case = chaos(t_end=0.6, n_out=3001)
    one, three = simulate(case), simulate(case.replace(realisations=3))
    assert len(three.t) == 3000 and np.count_nonzero(three.t == three.t[0]) == 3
    n = 1000
    assert three.t[n - 1] == pytest.approx(0.3 + 0.1, abs=1e-3)
    assert np.max(np.abs(three.Tm[n - 100:n] - three.Tm[2 * n - 100:2 * n])) > 0.1  # parted
    assert three.loads["revolutions"] == pytest.approx(30, abs=0.1)
    for value, se in ((rms, "Tm_rms_se"), (lambda r: r.loads["teeth_free_mean"],
                                            "teeth_free_mean_se"),
                      (lambda r: r.loads["impacts_per_rev"], "impacts_per_rev_se")):
        assert 0 < three.loads[se] < np.inf, se
        spread = np.hypot(one.loads[se], three.loads[se])
        assert abs(value(three) - value(one)) <= 3 * spread, se
    assert "; 3 realisations, standard errors from their spread, at least their batch means'" in \
        _summary(three)


def test_copies_that_do_not_part_keep_their_batch_means_error():
    """A settled (periodic) drive's copies stay together: their spread is no error (a Z = 20
    drive read T_m RMS 80.2 +- 0.001 with 2 copies against 80.1 +- 0.067 from one run). The
    combined standard error is never below the copies' batch-means errors combined,
    sqrt(SE_1^2 + SE_2^2) / 2 >= SE_1 / 2 (copy 1 alone: the 15 revolutions after the transient)."""
    case = pyspline.load_case(CASES / "template.nml", z=20, s=3.1416e-3, b=0.025, c0=1.2e-4,
                              speed_rpm=4500.0, t_d=80.0, t_l=80.0, l_x=4e-5, l_y=1e-5,
                              k_t1=9000.0, k_t2=9000.0, zeta_m=0.02, start="rest",
                              spacing_error=[0, 2e-5, 0, -1e-5, 0, 0, 3e-5], goal="statistics",
                              revolutions=40, transient_revolutions=10, outputs_per_revolution=100)
    one, two = simulate(case), simulate(case.replace(realisations=2))
    copy1 = simulate(case.replace(revolutions=25))
    n = len(two.t) // 2
    spread = abs(rms(two.Tm[:n]) - rms(two.Tm[n:])) / 2           # sd / sqrt(2) of 2 copies
    assert spread < 0.05 * one.loads["Tm_rms_se"]                  # the copies did not part
    for se in ("Tm_rms_se", "load_sharing_rev_se", "F_rms_se"):
        assert two.loads[se] >= copy1.loads[se] / 2, se
        assert two.loads[se] > one.loads[se] / 2, se


def test_executable_gives_the_realisations_of_python(exe, tmp_path):
    """Two copies on spline-dyn's OpenMP threads and on Python's default threads: the same
    outputs, loads and statistics, bit for bit."""
    case = chaos(t_transient=0.05, t_end=0.15, n_out=1001, realisations=2, section="shaft")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        *_, res = assert_executable_matches_python(case, exe, tmp_path)
    nml = tmp_path / "k2.nml"
    case.to_namelist(nml)
    subprocess.run([exe, str(nml), "--summary", str(tmp_path / "k2.summary")], check=True,
                   capture_output=True, env={"OMP_NUM_THREADS": "2"})
    text = (tmp_path / "k2.summary").read_text()
    for name in ("Tm_rms_se", "impacts_per_rev", "impacts_per_rev_se", "teeth_free_mean_se",
                 "revolutions", "load_sharing"):
        got = float(re.search(rf"loads\.{name} \[.*\] = +(\S+)", text).group(1))
        assert got == res.loads[name], name
    got = float(re.search(r"stats\.rhs_evals \[.*\] = +(\S+)", text).group(1))
    assert got == res.stats["rhs_evals"]
    assert len(res.section_t) == 2 * pyspline.load(case).n_section > 0


class Apart(cf.Executor):
    """Each call at once in the caller, as an executor whose workers do not share the caller's
    memory (a process pool): the copies write arrays of their own, concatenated after."""

    def submit(self, fn, /, *args, **kwargs):
        f = cf.Future()
        f.set_result(fn(*args, **kwargs))
        return f


def test_copies_in_place_give_the_numbers_of_copies_run_apart():
    """realisations = 2 on threads, each copy writing its rows of one set of output arrays in
    place (pyspline.result._copies), gives to the bit what the copies give run one after another
    in one thread, each into arrays of its own, concatenated: every output, section point, load,
    extreme and statistic."""
    case = chaos(t_transient=0.05, t_end=0.1, n_out=501, realisations=2, section="shaft")
    threads, apart = simulate(case), simulate(case, Apart())
    assert np.count_nonzero(threads.t == threads.t[0]) == 2 and len(threads.section_t) == 4
    for name in ("t", "y", "Tm", "section_t", "section_y"):
        np.testing.assert_array_equal(getattr(threads, name), getattr(apart, name), name)
    assert threads.tooth.keys() == apart.tooth.keys()
    for name in threads.tooth:
        np.testing.assert_array_equal(threads.tooth[name], apart.tooth[name], name)
    for name in threads.loads:
        np.testing.assert_array_equal(threads.loads[name], apart.loads[name], name)
    assert threads.extremes == apart.extremes
    assert ({k: v for k, v in threads.stats.items() if "wall" not in k}
            == {k: v for k, v in apart.stats.items() if "wall" not in k})


@pytest.mark.parametrize("fields, message", [
    (dict(realisations=0), r"field realisations = 0 must be at least 1"),
    (dict(realisations=1.5), r"field realisations = 1\.5 must be a whole number"),
    (dict(realisations=2, goal="trajectory"), r"field realisations = 2 runs perturbed copies "
     r"whose trajectories part: it reads statistics, set goal = 'statistics'"),
    (dict(realisations=2, lyapunov=True), r"field realisations = 2 with lyapunov = \.true\."),
    (dict(realisations=5000), r"field realisations = 5000 leaves fewer than 2 of the 8001 "
     r"outputs to each copy: at most 4000")])
def test_bad_realisations_are_refused_naming_the_field(fields, message):
    with pytest.raises(pyspline.CaseError, match=message):
        chaos(**fields).model


def test_sweep_points_run_their_copies():
    """A sweep's point runs its copies one after another: the numbers of simulate's threads."""
    case = chaos(t_transient=0.05, t_end=0.15, n_out=1001, realisations=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        ds = pyspline.sweep(case, l_x=[1.5e-4, 2e-4], progress=False)
    one = simulate(case.replace(l_x=2e-4))
    for name in ("Tm_rms_se", "impacts_per_rev"):
        assert ds[name].sel(l_x=2e-4).item() == one.loads[name], name


def test_section_instants_of_one_run_and_of_copies():
    """The transient ends on a section instant (chaos_z24's shaft period is 0.01 s): one run keeps
    it, a copy starts there and leaves it out; the arrays hold exactly the points run."""
    case = chaos(t_transient=0.05, t_end=0.1, n_out=101, section="shaft")
    one, two = simulate(case), simulate(case.replace(realisations=2))
    assert len(one.section_t) == pyspline.load(case).n_section == 6
    assert one.section_t[0] == pytest.approx(0.05)
    np.testing.assert_allclose(two.section_t, [0.06, 0.07, 0.06, 0.07])


def test_statistics_transient_runs_at_its_settings():
    """goal = 'statistics' runs the transient (no outputs) with ERK's Cash-Karp table without
    roots at rtol 3e-2, atol 3e-4, the window at 1e-2, 1e-4 (docs/accuracy.md; at rtol 1e-1 its
    other dynamics opened a third of chaos_z24's windows off the attractor): one run's window
    and realisations = 2's copies start from the state, to the bit, of such a run over the 0.3 s
    engagement, and not from one at the window's settings nor from Dormand-Prince at rtol 1e-1
    (each differs by far more than round-off). No sections: their instants stop the
    integrator, and the transient has none."""
    def transient_end(rtol, table):
        return simulate(chaos(goal="trajectory", method="erk", erk_table=table, roots=False,
                              rtol=rtol, atol=1e-2 * rtol, t_transient=0.0, t_end=0.3, n_out=1,
                              section="none")).y[-1]
    start = transient_end(3e-2, "cash_karp")
    for other in (transient_end(1e-2, "cash_karp"), transient_end(1e-1, "dormand_prince")):
        assert np.abs(other - start).max() > 1e-6 * np.abs(start).max()
    for k in (1, 2):
        res = simulate(chaos(t_end=0.31, n_out=22, realisations=k, section="none"))
        assert res.t[0] == pytest.approx(0.3, abs=1e-12)
        np.testing.assert_array_equal(res.y[0], start)
