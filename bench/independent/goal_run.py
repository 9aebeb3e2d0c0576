"""One simulate of chaos_z24 with goal = 'statistics' (the callgrind target of claim 1).

usage: python -P bench/independent/goal_run.py CASE.nml lyap|nolyap|real2|empty
lyap: the case as shipped (lyapunov = .true.), nolyap: lyapunov off, real2: lyapunov off and
realisations = 2, empty: nolyap's model loaded but not run (a whole process's baseline).
Prints the RHS calls.
"""
import sys
import warnings

import pyspline

warnings.simplefilter("ignore")
fields = {"goal": "statistics"}
if sys.argv[2] != "lyap":
    fields["lyapunov"] = False
if sys.argv[2] == "real2":
    fields["realisations"] = 2
case = pyspline.load_case(sys.argv[1], **fields)
model = case.model
if sys.argv[2] == "empty":
    sys.exit(0)
res = pyspline.simulate(model)
print("rhs_evals", res.stats["rhs_evals"], "steps", res.stats["steps"], "Tm_rms", repr(res.extremes["Tm_rms"]))
