"""Gain-scheduled H∞ synthesis: :func:`lpvsyn` and its results (see
:mod:`lmi_suspension.synthesis.lpv`)."""

from .errors import NyquistError
from .synthesis.lpv import LpvsynResult, ScheduledController, lpvsyn

__all__ = ["lpvsyn", "LpvsynResult", "ScheduledController", "NyquistError"]
