"""Load sharing under tooth spacing errors against the sequential-engagement model of Chase,
Sorensen & DeCaires ("Variation analysis of tooth engagement and load sharing in involute
splines", Gear Technology, June 2010), written here from the paper, not from the Fortran: with
the hub held centred the teeth engage in order of their clearance c_i, all engaged teeth share a
common deflection delta, each carries k (delta - c_i), and the loads add up to T / r_b. A tooth
j of spline 1 ahead by e_j along +dn (docs/model.md section 11) has the clearance c_j = e_j on
the loaded flank (under drive at dn_j = -c, a tooth ahead has the wider gap), so the settled
tooth loads of a run from its static equilibrium must be the closed form's. The hub is centred
by supports of 1e12 N/m (the case's upper bound), at dof 3 and dof 7; the model's lateral
compliance moves a tooth load by about k_m / k_p of it, so the mesh is soft here (k_m = 2e4 N/m,
T = 0.02 N m: a static tooth deflection of 4.5 um, errors up to 60 um).

`python tests/test_load_sharing.py docs/load_sharing.png` draws docs/verification.md's figure.
"""
from __future__ import annotations

import sys

import numpy as np
import pytest

import pyspline
from conftest import PAPER, PAPER_SHAFTS

#: expected warnings: the paper's shafts (conftest) and the soft mesh, chosen (module docstring)
pytestmark = [PAPER_SHAFTS, pytest.mark.filterwarnings(
    r"ignore:case chase. field k_m = 2\.000E\+04 N/m is .* times below:pyspline.SplineWarning")]

Z, K_M, T_D = 16, 2e4, 0.02
BASE = dict(PAPER, name="chase", z=Z, k_m=K_M, t_d=T_D, t_l=T_D, grav=0.0, k_p1=1e12,
            k_p2=1e12, start="equilibrium", t_end=0.002, n_out=5)


def sequential_engagement(c, k, w):
    """Chase, Sorensen & DeCaires: the tooth loads (and how many teeth engage) of clearances c
    under the total load w on teeth of stiffness k. With the n smallest clearances engaged,
    w = k sum_{i <= n} (delta - c_(i)) gives delta = (w / k + sum_{i <= n} c_(i)) / n; n is the
    first count whose delta does not reach the next clearance."""
    cs = np.sort(c)
    for n in range(1, len(c) + 1):
        delta = (w / k + cs[:n].sum()) / n
        if n == len(c) or delta <= cs[n]:
            break
    return np.where(c < delta, k * (delta - c), 0.0), n


def _ramp() -> np.ndarray:
    """Clearances 2 um apart in a scrambled order (tooth 7 j mod 16): about half engage."""
    return 2e-6 * ((7 * np.arange(Z)) % Z - 7.5)


def _three() -> np.ndarray:
    e = np.full(Z, 50e-6)
    e[[0, 5, 10]] = [-50e-6, -45e-6, -40e-6]
    return e


#: deterministic error sets and how many teeth each engages (the closed form's count)
SETS = {"all": (0.5e-6 * np.cos(2.3 * np.arange(1, Z + 1)), Z), "half": (_ramp(), 9),
        "three": (_three(), 3)}


def settled_loads(e, **fields):
    """The tooth loads |F_j| of a run from its static equilibrium at its last output."""
    res = pyspline.simulate(dict(BASE, spacing_error=list(e), **fields))
    return -res.F[-1], res.case.model.info()["r_b"]


@pytest.mark.parametrize("dof", [3, 7])
@pytest.mark.parametrize("name", list(SETS))
def test_deterministic_sets_follow_sequential_engagement(name, dof):
    e, engaged = SETS[name]
    f, r_b = settled_loads(e, dof=dof)
    closed, n = sequential_engagement(e, K_M, T_D / r_b)
    assert n == engaged
    np.testing.assert_array_equal(f > 0, closed > 0)
    np.testing.assert_allclose(f, closed, rtol=0, atol=1e-6 * closed.max())
    assert f.sum() == pytest.approx(T_D / r_b, rel=1e-6)


def test_random_sets_follow_sequential_engagement():
    """40 random error sets (uniform, amplitudes 1-60 um) at dof 3 and 7: from 1 tooth engaged
    to all of them."""
    counts = set()
    for seed in range(40):
        rng = np.random.default_rng(seed)
        e = rng.uniform(-1, 1, Z) * rng.uniform(1e-6, 60e-6)
        for dof in (3, 7):
            f, r_b = settled_loads(e, dof=dof)
            closed, n = sequential_engagement(e, K_M, T_D / r_b)
            np.testing.assert_allclose(f, closed, rtol=0, atol=1e-6 * closed.max())
            counts.add(n)
    assert min(counts) <= 3 and max(counts) == Z and len(counts) >= 8, counts


def draw(path) -> None:
    """The figure of docs/verification.md: each deterministic set's tooth loads, the run's
    (dof 7, supports 1e12 N/m) over the closed form's, per tooth."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(SETS), figsize=(11, 3.8), sharey=False)
    tooth = np.arange(1, Z + 1)
    for ax, (name, (e, engaged)) in zip(axes, SETS.items()):
        f, r_b = settled_loads(e, dof=7)
        closed, _ = sequential_engagement(e, K_M, T_D / r_b)
        err = np.abs(f - closed).max() / closed.max()
        ax.bar(tooth, 1e3 * closed, color="0.8", label="sequential engagement (closed form)")
        ax.plot(tooth, 1e3 * f, "o", color="C0", ms=5, label="pyspline, settled")
        ax.set_title(f"{engaged} of {Z} teeth engaged: differ by {err:.0e} of the peak",
                     fontsize=9)
        ax.set_xlabel("tooth j")
        ax.set_xticks(tooth[::3])
    axes[0].set_ylabel("tooth load |F_j| [mN]")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=9, frameon=False)
    fig.suptitle(f"Load sharing under spacing errors, centred hub: Z = {Z}, T = {T_D} N m, "
                 f"k_m = {K_M:.0e} N/m (Chase, Sorensen & DeCaires 2010)", fontsize=10)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    import warnings
    warnings.simplefilter("ignore", pyspline.SplineWarning)   # as pytestmark
    draw(sys.argv[1] if len(sys.argv) > 1 else "load_sharing.png")
