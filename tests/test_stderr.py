"""Standard errors of a non-periodic run's statistics (docs/model.md section 15): on the chaotic
cases/chaos_z24.nml (100 revolutions a second), T_m RMS over a 0.5 s window after the
engagement differs between tolerances by a sampling error of a few per cent, since the
trajectories part within milliseconds; the batch-means standard error `Tm_rms_se` must cover that
spread, and shrink about as 1/sqrt(window) over a window 8 times as long. Consecutive revolutions
of this run can be correlated (lag-1 correlation of the per-revolution RMS about 0.2 on one
realisation): standard errors over single revolutions then come out small, the overlapping
batches of sqrt(revolutions) revolutions do not. Measured (rtol 1e-6, 1e-7): T_m RMS 3.78 and 3.71 N m over
0.5 s with standard errors 0.09-0.12 N m; 0.026-0.027 N m over 8 s."""
import numpy as np
import pytest

import pyspline
from conftest import CASES, PAPER_SHAFTS, DEMONSTRATION_SCENES

pytestmark = [PAPER_SHAFTS, DEMONSTRATION_SCENES]   # expected warnings (conftest)

RTOLS = (1e-6, 1e-7)
REV_OUT = 20                       # outputs per revolution: T_m RMS needs no more


def run(rtol, window):
    case = pyspline.load_case(CASES / "chaos_z24.nml", lyapunov=False, rtol=rtol, atol=rtol * 1e-2)
    case = case.replace(t_end=case["t_transient"] + window, n_out=int(round(window * 100 * REV_OUT)) + 1)
    return pyspline.simulate(case)


@pytest.fixture(scope="module")
def short():
    return [run(r, 0.5) for r in RTOLS]


def obm_se(x):
    """Overlapping batch means (Meketon & Schmeiser 1984), batches of floor(sqrt(n)) values."""
    n = len(x)
    m = int(np.sqrt(n))
    means = np.convolve(x, np.ones(m) / m, mode="valid")
    return np.sqrt(m * np.sum((means - x.mean()) ** 2) / ((n - m) * (n - m + 1)))


def test_se_is_overlapping_batch_means_of_revolutions(short):
    res = short[0]
    ld = res.loads
    omega = res.case["speed_rpm"] * 2 * np.pi / 60
    rev = np.floor(omega * (res.t - res.t[0]) / (2 * np.pi)).astype(int)   # as the core rounds
    nb = int(ld["batches"])
    assert nb == 50 and int(np.sqrt(nb)) > 1
    rms = np.array([np.sqrt(np.mean(res.Tm[rev == b] ** 2)) for b in range(nb)])
    assert ld["Tm_rms_se"] == pytest.approx(obm_se(rms), rel=1e-9)
    # and not the naive standard error of single revolutions, which differs by the correlation
    # of consecutive revolutions (by 5-20 % on realisations of this run; its sign varies)
    assert ld["Tm_rms_se"] != pytest.approx(rms.std(ddof=1) / np.sqrt(nb), rel=1e-3)


def test_se_covers_the_spread_between_tolerances(short):
    a, b = short
    rms = [np.sqrt(np.mean(r.Tm ** 2)) for r in short]
    se = np.hypot(a.loads["Tm_rms_se"], b.loads["Tm_rms_se"])
    assert rms[0] != rms[1]                                       # chaotic: not the same numbers
    assert abs(rms[0] - rms[1]) < 3 * se, (rms, se)
    assert se < 0.05 * np.mean(rms)                               # and it says something


def test_se_shrinks_as_the_window_grows(short):
    long = run(RTOLS[0], 4.0)
    ratio = long.loads["Tm_rms_se"] / short[0].loads["Tm_rms_se"]
    assert 0.5 / np.sqrt(8) < ratio < 2 / np.sqrt(8), ratio        # about 1/sqrt(8) = 0.35
