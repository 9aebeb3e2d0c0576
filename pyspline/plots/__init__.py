"""pyspline's figures: `scene`, one page on one run (`run`, what `pyspline plot` draws); figures
of sweeps (`sweeps`: bifurcation diagrams, maps, Lyapunov exponents, waterfalls, `sweep_figures`,
what `pyspline sweep` draws); figures of continuation (`continuation`: the frequency response,
the follow sweep's bifurcation diagram, fold curves); what they share (`style`: units, `eng`,
the round-off test, colour limits past a start transient).

Each function returns a matplotlib Figure (Agg, no pyplot) and, given `path`, writes it as PNG.
Imports only numpy, matplotlib and pyspline.errors (xarray when a sweep's waterfalls are drawn),
no compiled core."""
from .continuation import bifurcation_follow, fold_plane, frequency_response
from .run import scene
from .style import eng
from .sweeps import (bifurcation, bifurcation_grid, lyapunov_vs_param, param_map, sweep_figures,
                     waterfall)

__all__ = ["bifurcation", "bifurcation_follow", "bifurcation_grid", "eng", "fold_plane",
           "frequency_response", "lyapunov_vs_param", "param_map", "scene", "sweep_figures",
           "waterfall"]
