"""lmi_suspension: robust controller synthesis by convex optimisation.

Data flow: model (:mod:`lmi_suspension.seat`) -> generalized plant
(:mod:`lmi_suspension.lti`) -> H∞ synthesis, LMI or Riccati
(:mod:`lmi_suspension.synthesis`) -> µ analysis and D-K iteration
(:mod:`lmi_suspension.mu`) -> simulation (:mod:`lmi_suspension.seat`) -> report.
"""

from . import errors, uncertain
from .errors import LmiSuspensionError
from .lti import GeneralizedPlant, freqresp, hinfnorm, lft
from .mu import MusynOptions, MussvOptions, mussv, musyn
from .synthesis import HinfsynOptions, HinfsynResult, hinfsyn

__version__ = "0.1.0"

__all__ = ["GeneralizedPlant", "lft", "hinfnorm", "freqresp", "hinfsyn", "HinfsynOptions", "HinfsynResult",
           "mussv", "MussvOptions", "musyn", "MusynOptions", "LmiSuspensionError", "errors", "uncertain",
           "__version__"]
