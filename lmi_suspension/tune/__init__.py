"""Structured H∞ tuning for any plant: tunable blocks (a static gain, a PID, a
fixed-order state space, a gain surface scheduled on measured parameters) and :func:`hinfstruct`, which minimises the closed loop's H∞
norm over their parameters by nonsmooth BFGS from several seeded starts, and certifies
the result with :func:`~lmi_suspension.lti.hinfnorm` as :func:`~lmi_suspension.hinfsyn`
does.

This package sits above :mod:`lmi_suspension.lti` and :mod:`lmi_suspension.synthesis`;
neither imports it.
"""

from .blocks import TunableBlock, block_diagonal, tunable_gain, tunable_pid, tunable_ss
from .hinfstruct import HinfstructOptions, HinfstructResult, StartRecord, hinfstruct
from .surface import GainSurface, ScheduledBlock, tunable_surface

__all__ = [
           "GainSurface",
           "HinfstructOptions",
           "HinfstructResult",
           "ScheduledBlock",
           "StartRecord",
           "TunableBlock",
           "block_diagonal",
           "hinfstruct",
           "tunable_gain",
           "tunable_pid",
           "tunable_ss",
           "tunable_surface",
]
