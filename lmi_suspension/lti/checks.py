"""Input validation shared by every module: finite, continuous-time, sized right."""

from __future__ import annotations

import numbers

import control
import numpy as np

from ..errors import (DimensionError, DiscreteTimeError, InputError, NonFiniteError,
                      ParameterError)

__all__ = ["as_finite_array", "as_statespace", "finite_scalar", "positive_scalar",
           "require_continuous", "require_finite_system"]


def as_finite_array(value, name: str, *, ndim: int | None = None, dtype=float) -> np.ndarray:
    """Return ``value`` as a finite numpy array (a copy), or raise a typed error.

    Parameters
    ----------
    value : array_like
        The data to check.
    name : str
        Name used in error messages.
    ndim : int, optional
        Required number of dimensions (scalars and vectors are promoted to 2-D when
        ``ndim == 2``).
    dtype : numpy dtype
        Target dtype (``float`` or ``complex``).

    Raises
    ------
    NonFiniteError
        If any entry is NaN or infinite.
    DimensionError
        If the number of dimensions does not fit.
    """
    try:
        arr = np.array(value, dtype=dtype, copy=True)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be numeric: {exc}") from exc
    if ndim == 2 and arr.ndim < 2:
        arr = np.atleast_2d(arr)
    if ndim is not None and arr.ndim != ndim:
        raise DimensionError(f"{name} must have {ndim} dimensions, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise NonFiniteError(f"{name} contains NaN or infinite entries")
    return arr


def require_continuous(sys, name: str = "system") -> None:
    """Raise :class:`DiscreteTimeError` unless ``sys`` is a continuous-time system."""
    dt = getattr(sys, "dt", 0)
    if dt is None:
        # python-control uses dt=None for "unspecified"; treat as continuous.
        return
    if dt is True or (isinstance(dt, numbers.Number) and dt != 0):
        raise DiscreteTimeError(f"{name} must be continuous-time (dt=0), got dt={dt!r}")


def require_finite_system(sys, name: str = "system") -> None:
    """Raise :class:`NonFiniteError` if any state-space matrix of ``sys`` is not finite."""
    for label in ("A", "B", "C", "D"):
        mat = np.asarray(getattr(sys, label))
        if mat.size and not np.all(np.isfinite(mat)):
            raise NonFiniteError(f"{name}.{label} contains NaN or infinite entries")


def as_statespace(sys, name: str = "system") -> control.StateSpace:
    """Return ``sys`` as a continuous-time, finite :class:`control.StateSpace`.

    Transfer functions and static gains are converted; discrete-time systems and
    non-finite matrices raise typed errors.
    """
    if isinstance(sys, control.StateSpace):
        ss = sys
    elif isinstance(sys, control.TransferFunction):
        ss = control.ss(sys)
    elif hasattr(sys, "sys") and isinstance(getattr(sys, "sys"), control.StateSpace):
        ss = sys.sys  # GeneralizedPlant and similar wrappers
    else:
        gain = as_finite_array(sys, name, ndim=2)
        ss = control.ss([], [], [], gain)
    require_continuous(ss, name)
    require_finite_system(ss, name)
    return ss


def finite_scalar(value, name: str) -> float:
    """``value`` as a finite float, or a typed error naming ``name`` (a bool or a
    non-real is a :class:`ParameterError`, NaN or infinity a :class:`NonFiniteError`).

    Examples
    --------
    >>> finite_scalar(-2, "kp")
    -2.0
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ParameterError(f"{name} must be a real number, got {value!r}")
    value = float(value)
    if not np.isfinite(value):
        raise NonFiniteError(f"{name} must be finite, got {value!r}")
    return value


def positive_scalar(value, name: str) -> float:
    """``value`` as a positive finite float, or a typed error naming ``name``.

    Examples
    --------
    >>> positive_scalar(2, "dt")
    2.0
    """
    value = finite_scalar(value, name)
    if value <= 0:
        raise ParameterError(f"{name} must be positive, got {value!r}")
    return value
