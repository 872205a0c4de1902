"""Gain-scheduled H∞ synthesis: :func:`lpvsyn` (gridded, see
:mod:`lmi_suspension.synthesis.lpv`) and :func:`hinfgs` (polytopic, see
:mod:`lmi_suspension.synthesis.hinfgs`), and their results."""

from .errors import NyquistError
from .synthesis.hinfgs import HinfgsResult, PolytopicController, hinfgs
from .synthesis.lpv import LpvsynResult, ScheduledController, lpvsyn

__all__ = ["lpvsyn", "LpvsynResult", "ScheduledController", "NyquistError", "hinfgs",
           "HinfgsResult", "PolytopicController"]
