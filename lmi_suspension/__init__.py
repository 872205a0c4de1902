"""lmi_suspension: robust controller synthesis by convex optimisation.

Data flow: model (:mod:`lmi_suspension.seat`) -> generalized plant
(:mod:`lmi_suspension.lti`) -> H∞ synthesis, LMI or Riccati
(:mod:`lmi_suspension.synthesis`) -> µ analysis and D-K iteration
(:mod:`lmi_suspension.mu`) -> simulation and report.
"""

from . import errors
from .errors import LmiSuspensionError
from .lti import GeneralizedPlant, lft

__version__ = "0.1.0"

__all__ = ["GeneralizedPlant", "lft", "LmiSuspensionError", "errors", "__version__"]
