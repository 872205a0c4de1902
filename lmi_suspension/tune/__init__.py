"""Structured H∞ tuning for any plant.

* Tunable blocks: a static gain, a PID, a fixed-order state space
  (:mod:`~lmi_suspension.tune.blocks`) and a gain surface scheduled on measured
  parameters (:mod:`~lmi_suspension.tune.surface`).
* :func:`hinfstruct`: minimises one plant's closed-loop H∞ norm over the blocks'
  parameters by nonsmooth BFGS from several seeded starts, certified with
  :func:`~lmi_suspension.lti.hinfnorm` as :func:`~lmi_suspension.hinfsyn` is.
* Requirements behind one protocol (:mod:`~lmi_suspension.tune.requirements`: an H∞
  bound on a weighted channel, a pole region, disk margins) and :func:`systune`, which
  minimises the soft ones subject to the hard ones over several models, every value
  recomputed on the returned controller; its SLSQP route
  (:mod:`~lmi_suspension.tune.stages`, trust-region stages on the epigraph form) for
  requirements that give every term of their maximum, with :func:`tunable_modal`, a
  stable modal block in normalised parameters, to refine a given controller (the
  seat's refinement runs on it).

This package sits above :mod:`lmi_suspension.lti` and :mod:`lmi_suspension.synthesis`;
neither imports it.
"""

from .blocks import (
                     TunableBlock,
                     block_diagonal,
                     tunable_gain,
                     tunable_modal,
                     tunable_pid,
                     tunable_ss,
)
from .closedloop import ClosedLoop
from .hinfstruct import HinfstructOptions, HinfstructResult, StartRecord, hinfstruct
from .requirements import HinfBound, Margins, PoleRegion, Requirement
from .stages import TrustRegionOptions, TrustRegionStage, trust_region_slsqp
from .surface import GainSurface, ScheduledBlock, tunable_surface
from .systune import SystuneOptions, SystuneResult, SystuneStart, systune

__all__ = [
    "ClosedLoop",
    "GainSurface",
    "HinfBound",
    "HinfstructOptions",
    "HinfstructResult",
    "Margins",
    "PoleRegion",
    "Requirement",
    "ScheduledBlock",
    "StartRecord",
    "SystuneOptions",
    "SystuneResult",
    "SystuneStart",
    "TrustRegionOptions",
    "TrustRegionStage",
    "TunableBlock",
    "block_diagonal",
    "hinfstruct",
    "systune",
    "trust_region_slsqp",
    "tunable_gain",
    "tunable_modal",
    "tunable_pid",
    "tunable_ss",
    "tunable_surface",
]
