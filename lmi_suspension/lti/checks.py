"""Input validation shared by every module: finite, continuous-time, sized right."""

from __future__ import annotations

import numbers

import control
import numpy as np

from ..errors import (DimensionError, DiscreteTimeError, InputError, NonFiniteError,
                      ParameterError, SampleTimeError)

__all__ = ["as_finite_array", "as_statespace", "common_sample_time", "finite_scalar",
           "positive_scalar", "require_continuous", "require_finite_system", "sample_time"]


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


def sample_time(sys, name: str = "system") -> float:
    """The sample time of ``sys`` in seconds: ``0.0`` for a continuous-time system (and for
    python-control's "unspecified" ``dt=None`` of static gains), a positive finite number
    for a discrete-time one.

    Raises
    ------
    SampleTimeError
        For ``dt=True`` (discrete with an unspecified sample time: frequencies in rad/s
        need one) and for a sample time that is not a positive finite number (python-control
        accepts ``dt=nan``).

    Examples
    --------
    >>> import control
    >>> sample_time(control.tf([1], [1, 1])), sample_time(control.tf([1], [1, -0.5], 0.01))
    (0.0, 0.01)
    """
    dt = getattr(sys, "dt", 0)
    if dt is None:
        return 0.0
    if dt is True:
        raise SampleTimeError(f"{name} is discrete-time with an unspecified sample time "
                              "(dt=True); give it one in seconds")
    if isinstance(dt, bool) or not isinstance(dt, numbers.Real):
        raise SampleTimeError(f"{name} has a sample time {dt!r} that is not a number")
    dt = float(dt)
    if not (np.isfinite(dt) and dt >= 0):
        raise SampleTimeError(f"{name} has sample time dt={dt!r}: it must be positive and "
                              "finite (or 0 for continuous time)")
    return dt


def common_sample_time(*named) -> float:
    """The one time base of several systems, given as ``(name, system)`` pairs; a static
    gain (no states) fits any time base.

    Raises
    ------
    SampleTimeError
        If two of them differ (continuous and discrete, or two sample times), naming both.

    Examples
    --------
    >>> import control
    >>> P = control.ss([[0.5]], [[1.0]], [[1.0]], [[0.0]], 0.1)
    >>> common_sample_time(("P", P), ("K", control.ss([], [], [], [[2.0]])))
    0.1
    """
    seen = None
    for name, sys in named:
        dt = sample_time(sys, name)
        if getattr(sys, "nstates", 1) == 0 and getattr(sys, "dt", 0) in (None, 0):
            continue  # a static gain is the same operator in either time base
        if seen is None:
            seen = (name, dt)
        elif dt != seen[1]:
            def kind(t):
                return "continuous-time" if t == 0 else f"discrete-time (dt={t!r})"
            raise SampleTimeError(f"{seen[0]} is {kind(seen[1])} and {name} is {kind(dt)}: "
                                  "systems of different time bases cannot be combined")
    return 0.0 if seen is None else seen[1]


def require_continuous(sys, name: str = "system") -> None:
    """Raise :class:`DiscreteTimeError` unless ``sys`` is a continuous-time system."""
    dt = getattr(sys, "dt", 0)
    if dt is None:
        # python-control uses dt=None for "unspecified"; treat as continuous.
        return
    if isinstance(dt, numbers.Number) and not isinstance(dt, bool) and dt != dt:
        raise SampleTimeError(f"{name} has sample time dt=nan")
    if dt is True or (isinstance(dt, numbers.Number) and dt != 0):
        raise DiscreteTimeError(f"{name} must be continuous-time (dt=0), got dt={dt!r}")


def require_finite_system(sys, name: str = "system") -> None:
    """Raise :class:`NonFiniteError` if any state-space matrix of ``sys`` is not finite."""
    for label in ("A", "B", "C", "D"):
        mat = np.asarray(getattr(sys, label))
        if mat.size and not np.all(np.isfinite(mat)):
            raise NonFiniteError(f"{name}.{label} contains NaN or infinite entries")


def as_statespace(sys, name: str = "system", *, discrete: bool = False
                  ) -> control.StateSpace:
    """Return ``sys`` as a finite :class:`control.StateSpace`, continuous-time unless
    ``discrete`` allows a discrete-time one (with a positive finite sample time).

    Transfer functions and static gains are converted; discrete-time systems (where not
    allowed), invalid sample times and non-finite matrices raise typed errors.
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
    if discrete:
        sample_time(ss, name)
    else:
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
