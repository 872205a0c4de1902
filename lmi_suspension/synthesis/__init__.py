"""Controller synthesis: certified H∞ by LMIs (Clarabel) or Riccati (python-control).

Every method returns the same :class:`HinfsynResult`; its ``gamma`` is always the
certified closed-loop norm ``hinfnorm(lft(P, K))``.
"""

from .hinfsyn import hinfsyn
from .result import HinfsynOptions, HinfsynResult, Timings

__all__ = ["hinfsyn", "HinfsynOptions", "HinfsynResult", "Timings"]
