"""One simulate of chaos_z24 with goal = 'statistics' (the callgrind target of claim 1).

usage: python -P check/goal_run.py CASE.nml lyap|nolyap
lyap: the case as shipped (lyapunov = .true.), nolyap: lyapunov off. Prints the RHS calls.
"""
import sys
import warnings

import pyspline

warnings.simplefilter("ignore")
fields = {"goal": "statistics"}
if sys.argv[2] == "nolyap":
    fields["lyapunov"] = False
case = pyspline.load_case(sys.argv[1], **fields)
model = case.model
res = pyspline.simulate(model)
print("rhs_evals", res.stats["rhs_evals"], "steps", res.stats["steps"], "Tm_rms", repr(res.extremes["Tm_rms"]))
