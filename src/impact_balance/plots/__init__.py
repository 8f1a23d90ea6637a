"""Figures of an analysis (matplotlib on an Agg canvas; nothing is shown, pyplot is not used).

Every function returns a :class:`matplotlib.figure.Figure`; :func:`save_figures` writes all
the figures of one analysis as PNG files named after its scenario.

- :func:`plot_areas`: ZMP support area and CoM velocity area with the post-impact sets
  (paper Fig. solving-opt).
- :func:`plot_impulse_set`: 3D impulse set with the friction cone, and the CoM velocity jump
  set (paper Fig. impulse_set).
- :func:`plot_friction_comparison`: post-impact sets and maximum contact velocities for
  several impact frictions (paper Fig. miu-compare).
- :func:`plot_phase_portrait`: LIPM phase portrait with the stable standing region (paper
  Fig. lipm-pplane); :func:`analysis_phase_portrait` builds one from an analysis.
- :func:`plot_stance`: top and side views of the stance.
"""

from impact_balance.plots.areas import plot_areas
from impact_balance.plots.friction import plot_friction_comparison
from impact_balance.plots.impulse import plot_impulse_set
from impact_balance.plots.phase import analysis_phase_portrait, plot_phase_portrait
from impact_balance.plots.save import save_figures
from impact_balance.plots.stance import plot_stance

__all__ = [
    "analysis_phase_portrait",
    "plot_areas",
    "plot_friction_comparison",
    "plot_impulse_set",
    "plot_phase_portrait",
    "plot_stance",
    "save_figures",
]
