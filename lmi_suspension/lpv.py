"""Gain-scheduled H∞ synthesis: :func:`lpvsyn` (gridded, see
:mod:`lmi_suspension.synthesis.lpv`) and :func:`hinfgs` (polytopic, see
:mod:`lmi_suspension.synthesis.hinfgs`), and their results; :func:`lpv_robstab` (see :mod:`lmi_suspension.uncertain.scheduled`),
the frozen loops' robust stability against a plant's remaining uncertainty."""

from .errors import NyquistError
from .synthesis.hinfgs import HinfgsResult, PolytopicController, hinfgs
from .synthesis.lpv import LpvsynResult, ScheduledController, lpvsyn
from .uncertain.scheduled import LpvRobstabResult, lpv_robstab

__all__ = ["lpvsyn", "LpvsynResult", "ScheduledController", "NyquistError", "hinfgs",
           "HinfgsResult", "PolytopicController", "lpv_robstab", "LpvRobstabResult"]
