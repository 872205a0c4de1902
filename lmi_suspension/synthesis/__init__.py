"""Controller synthesis: certified H∞ by LMIs (CVXOPT, Clarabel) or Riccati (python-control), and
multi-objective LMI synthesis (H∞, H2, peak bounds, pole regions; :func:`msyn`, and
static state feedback :func:`msfsyn`).

Every method returns the same :class:`HinfsynResult`; its ``gamma`` is always the
certified closed-loop norm ``hinfnorm(lft(P, K))``.
"""

from . import constraints
from .hinfsyn import hinfsyn
from .multiobjective import MultiobjectiveResult, SpecificationCertificate, h2hinfsyn, msyn
from .result import HinfsynOptions, HinfsynResult, Timings
from .statefeedback import StateFeedbackResult, msfsyn

__all__ = ["hinfsyn", "HinfsynOptions", "HinfsynResult", "Timings", "msyn", "h2hinfsyn", "msfsyn",
           "StateFeedbackResult",
           "MultiobjectiveResult", "SpecificationCertificate", "constraints"]
