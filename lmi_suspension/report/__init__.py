"""Figures of the paper and the whole reproduction pipeline (``lmi-suspension reproduce``).

The pipeline function is :func:`lmi_suspension.report.reproduce.reproduce` (the submodule
keeps its name here, so ``from lmi_suspension.report import reproduce`` gives the module).
"""

from . import reproduce
from .figures import plot_mu_bounds, plot_peak_vs_delay, plot_responses, plot_road
from .reproduce import (
           CONTROLLER_NAMES,
           ControllerSummary,
           ReproduceSummary,
           comparison_table,
)

__all__ = [
           "CONTROLLER_NAMES",
           "ControllerSummary",
           "ReproduceSummary",
           "comparison_table",
           "plot_mu_bounds",
           "plot_peak_vs_delay",
           "plot_responses",
           "plot_road",
           "reproduce",
]
