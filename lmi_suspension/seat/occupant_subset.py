"""An occupant set with some of its parameters held at their value: the seats a
controller serves when it knows (measures, or is scheduled on) those parameters.

:class:`OccupantSubset` is an :class:`~.occupants.OccupantSet` whose ``fixed``
parameters (any of ``m3``, ``k1..k3``, ``c1..c3``) keep the ``nominal`` seat's value:
its :meth:`~OccupantSubset.ranges` give them a range of zero width, so every consumer of
a set (:func:`~.occupants.occupant_samples`, :func:`~.occupants.occupant_mu`,
:class:`~.occupants.MixedRsBound`, :func:`~.worstcase.worst_bump_seats`,
:func:`~.multimodel.refine_for_occupants`) meets only the others.  Sampled with the same
generator as the whole set, a subset's samples are the whole set's with the fixed
parameters replaced by their value (the Latin hypercube draws the same unit points), so
designs over different subsets are measured on the same seats.

Its mixed-µ structure (:meth:`~OccupantSubset.mu_design`) has a real scalar only for
each parameter that varies: a fixed ``m3`` is the nominal seat's mass in the µ model,
not the centre of a range.

Examples
--------
>>> import numpy as np
>>> from lmi_suspension.seat.occupant_subset import OccupantSubset
>>> s = OccupantSubset(fixed=("k1", "c1"))
>>> [r for r in s.ranges() if r[1] == r[2]]
[('k1', 31000.0, 31000.0), ('c1', 830.0, 830.0)]
>>> s.mu_design().stiffness, s.mu_design().damping
(('k2', 'k3'), ('c2', 'c3'))
>>> seats, _ = s.sample(3, np.random.default_rng(0))
>>> {p.k1 for p in seats}
{31000.0}
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from itertools import product

from ..errors import ParameterError
from .occupants import OccupantSet

__all__ = ["OccupantSubset", "PARAMETERS"]

#: the parameters an :class:`~.occupants.OccupantSet` ranges over, in its order
PARAMETERS = ("m3", "k1", "k2", "k3", "c1", "c2", "c3")


@dataclass(frozen=True)
class OccupantSubset(OccupantSet):
    """An :class:`~.occupants.OccupantSet` with the parameters ``fixed`` held at the
    ``nominal`` seat's values.

    Attributes
    ----------
    fixed : tuple of str
        Names among ``m3``, ``k1..k3``, ``c1..c3``.  An ``m3`` range of zero width
        (``m3=(m, m)``) counts as fixed too, at ``m`` (the nominal seat's mass is then
        ``m``).

    Raises
    ------
    ParameterError
        An unknown or repeated name, or ``m3`` fixed while the nominal mass lies
        outside ``m3``'s range.
    """

    fixed: tuple = ()

    def __post_init__(self):
        super().__post_init__()
        fixed = self.fixed
        if isinstance(fixed, str) or not isinstance(fixed, (tuple, list)):
            raise ParameterError(f"fixed must be a tuple of parameter names, got {fixed!r}")
        fixed = tuple(fixed)
        unknown = [n for n in fixed if n not in PARAMETERS]
        if unknown:
            raise ParameterError(f"unknown parameters {unknown}; choose from {PARAMETERS}")
        if len(set(fixed)) != len(fixed):
            raise ParameterError(f"a parameter is fixed twice: {fixed!r}")
        lo, hi = self.m3
        if lo == hi and "m3" not in fixed:
            if self.nominal.m3 != lo:       # the seat must be the one the range holds
                object.__setattr__(self, "nominal", replace(self.nominal, m3=float(lo)))
            fixed = ("m3",) + fixed
        if "m3" in fixed and not lo <= self.nominal.m3 <= hi:
            raise ParameterError(f"m3 is fixed at the nominal {self.nominal.m3:g} kg, "
                                 f"outside the range [{lo:g}, {hi:g}]")
        object.__setattr__(self, "fixed", tuple(n for n in PARAMETERS if n in fixed))

    def ranges(self) -> tuple:
        """``(name, lo, hi)`` of every parameter; a fixed one has ``lo == hi``, its
        nominal value."""
        return tuple((name, getattr(self.nominal, name), getattr(self.nominal, name))
                     if name in self.fixed else (name, lo, hi)
                     for name, lo, hi in super().ranges())

    def varying(self) -> tuple:
        """The names of the parameters with a range of positive width."""
        return tuple(name for name, lo, hi in self.ranges() if hi > lo)

    def corners(self, names=("m3", "k1")) -> tuple:
        """As :meth:`OccupantSet.corners`, each seat once (a fixed parameter has one end)."""
        ranges = {r[0]: r[1:] for r in self.ranges()}
        unknown = [n for n in names if n not in ranges]
        if unknown:
            raise ParameterError(f"unknown parameters {unknown}; choose from {list(ranges)}")
        seats = (self.at(dict(zip(names, ends)))
                 for ends in product(*(sorted(set(ranges[n])) for n in names)))
        return tuple(dict.fromkeys(seats))

    def mu_design(self, design=None):
        """The whole set's structure (:meth:`OccupantSet.mu_design`) without the real
        scalars of the fixed parameters."""
        # a mass range of zero width is no range for the µ model (it refuses one); the
        # mass is fixed then, and its scalar left out below in any case
        lo, hi = self.m3
        base = self if hi > lo else replace(self, m3=(lo, lo + 1.0))
        opts = super(OccupantSubset, base).mu_design(design)
        varying = set(self.varying())
        return replace(opts, m3_range=None if "m3" not in varying else opts.m3_range,
                       stiffness=tuple(n for n in opts.stiffness if n in varying),
                       damping=tuple(n for n in opts.damping if n in varying))
