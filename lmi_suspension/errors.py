"""Typed errors of :mod:`lmi_suspension`.

Every error the package raises on purpose derives from :class:`LmiSuspensionError`;
errors about bad *input* also derive from :class:`ValueError`, so callers that
already catch ``ValueError`` keep working.
"""

from __future__ import annotations

__all__ = [
    "LmiSuspensionError",
    "InputError",
    "NonFiniteError",
    "DimensionError",
    "ParameterError",
    "TimebaseError",
    "DiscreteTimeError",
    "SampleTimeError",
    "IllPosedLoopError",
    "AssumptionError",
    "InfeasibleError",
    "SolverError",
    "IterationLimitError",
    "NotBuiltError",
    "NyquistError",
]


class LmiSuspensionError(Exception):
    """Base class of every error raised on purpose by this package."""


class InputError(LmiSuspensionError, ValueError):
    """Base class of errors caused by invalid arguments."""


class NonFiniteError(InputError):
    """A matrix or parameter holds NaN or infinity."""


class DimensionError(InputError):
    """Sizes do not fit: a partition, a block structure, a matrix shape."""


class ParameterError(InputError):
    """A physical or numerical parameter is outside its admissible range."""


class TimebaseError(InputError):
    """Systems' time bases do not fit: a continuous-time system where a discrete-time one
    is required or the converse, two different sample times, or a sample time that is not
    a positive finite number."""


class DiscreteTimeError(TimebaseError):
    """A continuous-time system was required and a discrete-time one was given."""


class SampleTimeError(TimebaseError):
    """A sample time that is not positive and finite (or unspecified, ``dt=True``), or
    systems of different time bases combined (a continuous plant with a discrete
    controller, two sample times)."""


class IllPosedLoopError(InputError):
    """A feedback interconnection is not well posed (``I - D22 Dk`` is singular)."""


class AssumptionError(InputError):
    """A method's standing assumption is violated (e.g. rank of D12 for Riccati H∞).

    The message names the violated assumption.
    """


class InfeasibleError(LmiSuspensionError):
    """The problem has no solution (e.g. no stabilizing controller, γ too small)."""


class SolverError(LmiSuspensionError):
    """A numerical solver failed and no recovery succeeded.

    Attributes
    ----------
    status : str or None
        The solver's own status string, when there is one.
    """

    def __init__(self, message: str, status: str | None = None):
        super().__init__(message)
        self.status = status


class IterationLimitError(LmiSuspensionError):
    """An iterative routine reached its iteration bound without meeting its test."""


class NotBuiltError(LmiSuspensionError, NotImplementedError):
    """A documented capability that is not built yet; the message says which, and what
    works instead."""


class NyquistError(ParameterError):
    """A discrete realization was asked at a sample time whose Nyquist rate ``π/dt`` lies
    below a pole of the controller: the sampled controller would not resolve it."""
