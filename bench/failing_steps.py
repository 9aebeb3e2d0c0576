"""A branch whose every step fails, bounded per point (docs/continuation.md, "Failed steps are
bounded per point"): `python bench/failing_steps.py [bound]` (default pyspline.ends'
FAILED_EVALS; 1e9: unbounded). The linear scene (tests/test_orbits.py) continued over
2600-2650 r/min with a wrong dF/dp column for its first method (1e3 times a random vector)
and the fallbacks' own tangents switched off (tests/test_ends.py): the branch is its start
alone. Prints the CPU time of the call (the heavy imports made before), the corrector
iterations and the calls of the core's map, the status and the fallbacks tried."""
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
import pyspline                                         # noqa: E402
import pyspline.arclength as arc                        # noqa: E402
import pyspline.dataset                                 # noqa: E402,F401
import pyspline.orbits as orbits                        # noqa: E402
from pyspline import ends                               # noqa: E402
from test_orbits import linear_scene                    # noqa: E402

if len(sys.argv) > 1:
    ends.FAILED_EVALS = int(float(sys.argv[1]))
case, *_ = linear_scene(2.0)
evaluate, evals, calls = arc._Problem.evaluate, [0], [0]


def wrong(self, y, u, n):
    evals[0] += 1
    F, J, M, yy = evaluate(self, y, u, n)
    if self.how == "exact":
        J = np.c_[J[:, :-1], 1e3 * np.random.default_rng(1).standard_normal(len(F))]
    return F, J, M, yy


def counted(f):
    def call(*args, **kw):
        calls[0] += 1
        return f(*args, **kw)
    return call


arc._Problem.evaluate, arc._retangent = wrong, lambda *args: None
for mod in (arc, orbits):
    for name in ("map_and_monodromy", "_period_map", "_trajectory"):
        if hasattr(mod, name):
            setattr(mod, name, counted(getattr(mod, name)))
with warnings.catch_warnings():
    warnings.simplefilter("ignore", pyspline.SplineWarning)
    import tqdm, xarray                                 # noqa: E401,F401
    t = time.process_time()
    ds = pyspline.continuation(case, "speed_rpm", 2600, 2650, progress=False, ds_min=0.01,
                               max_points=6)
print(f"bound {ends.FAILED_EVALS}: CPU {time.process_time() - t:.2f} s, {evals[0]} corrector "
      f"iterations, {calls[0]} calls of the core, {ds.sizes['point']} point(s)\n"
      f"status: {ds.attrs['status']}\nfallbacks: {ds.attrs['fallbacks']}")
