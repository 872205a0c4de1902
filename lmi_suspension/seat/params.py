"""Parameters of the 3-DOF seat + seated-human model (Table 1 of the paper) and its limits."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from ..errors import NonFiniteError, ParameterError

__all__ = ["SeatParameters"]


@dataclass(frozen=True)
class SeatParameters:
    """Physical parameters and limits of the seat suspension (Table 1 and the design section).

    The defaults are the paper's values. ``m2`` is not a field: it is built as
    ``m21 + m22`` (Table 1 prints "1+7.8"; see ``shared/paper/ERRATA.md``).

    Attributes
    ----------
    m1 : float
        Seat-frame mass, kg (15).
    m21 : float
        Thighs-and-buttocks mass, kg (1).
    m22 : float
        Mass of the thighs and buttocks at the cushion, kg (7.8).
    m3 : float
        Upper-body mass of the occupant, kg (43.3).
    c1, c2, c3 : float
        Damping of the seat suspension, cushion and spine, N·s/m (830, 200, 1485).
    k1, k2, k3 : float
        Stiffness of the seat suspension, cushion and spine, N/m (31000, 18000, 44130).
    z_max : float
        Suspension-deflection limit on ``|x1|``, m (0.08).
    u_max : float
        Actuator-force limit, N (1500).
    delay_min, delay_max : float
        Bounds of the actuator delay, s (0 and 0.025).

    Examples
    --------
    >>> from lmi_suspension.seat import SeatParameters
    >>> p = SeatParameters()
    >>> p.m2
    8.8
    >>> SeatParameters(m3=70.0).m3
    70.0
    """

    m1: float = 15.0
    m21: float = 1.0
    m22: float = 7.8
    m3: float = 43.3
    c1: float = 830.0
    c2: float = 200.0
    c3: float = 1485.0
    k1: float = 31000.0
    k2: float = 18000.0
    k3: float = 44130.0
    z_max: float = 0.08
    u_max: float = 1500.0
    delay_min: float = 0.0
    delay_max: float = 0.025

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ParameterError(f"{f.name} must be a real number, got {value!r}")
            if not math.isfinite(value):
                raise NonFiniteError(f"{f.name} must be finite, got {value!r}")
            if f.name == "delay_min":
                if value < 0:
                    raise ParameterError(f"delay_min must be >= 0 s, got {value!r}")
            elif f.name in ("c1", "c2", "c3"):
                if value < 0:
                    raise ParameterError(f"{f.name} (damping) must be >= 0 N*s/m, got {value!r}")
            elif value <= 0:
                raise ParameterError(f"{f.name} must be positive, got {value!r}")
        if self.delay_max < self.delay_min:
            raise ParameterError(
                f"delay_max ({self.delay_max} s) must not be below delay_min ({self.delay_min} s)")

    @property
    def m2(self) -> float:
        """Lumped thigh/buttock mass ``m21 + m22``, kg."""
        return self.m21 + self.m22
