"""Uncertain elements (atoms): ``ureal``, ``ucomplex`` and ``ultidyn``.

Each atom is a frozen dataclass with a *normalised* uncertainty ``δ`` and a map from
``δ`` to its physical value:

* :func:`ureal`: a real parameter with ``δ ∈ [-1, 1]``.  A range symmetric about the
  nominal value is mapped affinely, ``p = nominal + h δ`` (``δ = 0`` is the nominal,
  ``δ = ±1`` the range ends).  An asymmetric range ``[lo, hi]`` is mapped by the linear
  fractional function ``p(δ) = nominal + c δ / (1 - a δ)`` with
  ``a = (dh - dl) / (dh + dl)``, ``c = 2 dh dl / (dh + dl)``, ``dh = hi - nominal``,
  ``dl = nominal - lo``: it sends ``-1, 0, 1`` to ``lo, nominal, hi``, is increasing on
  ``[-1, 1]`` (its pole ``1/a`` lies outside), and is still one LFT channel.  MATLAB's
  ``ureal`` uses a different (not affine either) normalisation for asymmetric ranges,
  so its stability margins for such ranges can differ from these.
  Scaling the box ``δ ∈ [-α, α]`` (a *margin* ``α``) moves the physical range to
  ``[p(-α), p(α)]``.
* :func:`ucomplex`: ``p = nominal + radius δ`` with complex ``|δ| <= 1`` (real nominal).
* :func:`ultidyn`: an unknown stable LTI system ``Δ(s)`` of size ``ny × nu`` with
  ``‖Δ‖∞ <= bound``; its normalised form is ``Δ / bound``.

Two atoms are the same uncertainty when they are equal (same name and definition);
two *different* atoms with one name in one model raise
:class:`~lmi_suspension.errors.ParameterError`.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from ..errors import DimensionError, NonFiniteError, ParameterError
from .lfr import _Atom

__all__ = ["UReal", "UComplex", "ULTIDyn", "ureal", "ucomplex", "ultidyn"]


def _name(name) -> str:
    if not isinstance(name, str) or not name.strip():
        raise ParameterError(f"an uncertain element needs a non-empty string name, got {name!r}")
    return name


def _real(value, what: str, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ParameterError(f"{what} of uncertain parameter {name!r} must be a real number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise NonFiniteError(f"{what} of uncertain parameter {name!r} is not finite ({value!r})")
    return value


@dataclass(frozen=True, eq=True)
class UReal(_Atom):
    """Uncertain real parameter (build it with :func:`ureal`).

    Attributes
    ----------
    name : str
    nominal, lo, hi : float
        Nominal value and range (``lo < nominal < hi``, or the symmetric case).
    """

    kind = "real"  # not a field: what the LFR asks of an atom (see lfr._Atom)
    name: str
    nominal: float
    lo: float
    hi: float

    @property
    def symmetric(self) -> bool:
        """True when the range is symmetric about the nominal (affine normalisation)."""
        dh, dl = self.hi - self.nominal, self.nominal - self.lo
        return abs(dh - dl) <= 1e-12 * max(dh, dl)

    @property
    def lfr_coefficients(self) -> tuple[float, float]:
        """``(a, c)`` of ``p(δ) = nominal + c δ / (1 - a δ)``."""
        dh, dl = self.hi - self.nominal, self.nominal - self.lo
        if self.symmetric:
            return 0.0, dh
        return (dh - dl) / (dh + dl), 2.0 * dh * dl / (dh + dl)

    def value(self, delta):
        """Physical value at the normalised ``δ`` (array-friendly)."""
        a, c = self.lfr_coefficients
        delta = np.asarray(delta, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            out = self.nominal + c * delta / (1.0 - a * delta)
        return float(out) if out.ndim == 0 else out

    def normalise(self, value: float) -> float:
        """Normalised ``δ`` of a physical value (the inverse of :meth:`value`)."""
        value = _real(value, "substituted value", self.name)
        a, c = self.lfr_coefficients
        dp = value - self.nominal
        den = c + a * dp
        if den == 0:
            raise ParameterError(
                f"value {value!r} of uncertain parameter {self.name!r} is the pole of its "
                "linear fractional normalisation and cannot be represented")
        return dp / den


@dataclass(frozen=True, eq=True)
class UComplex(_Atom):
    """Uncertain complex parameter ``nominal + radius δ``, ``|δ| <= 1`` (see :func:`ucomplex`)."""

    kind = "complex"
    name: str
    nominal: float
    radius: float

    def value(self, delta):
        """Physical value at the normalised ``δ``."""
        return self.nominal + self.radius * delta

    def normalise(self, value) -> complex:
        """Normalised ``δ`` of a value."""
        if isinstance(value, bool) or not isinstance(value, numbers.Number):
            raise ParameterError(f"value of uncertain parameter {self.name!r} must be a number, got {value!r}")
        if not np.isfinite(value):
            raise NonFiniteError(f"value of uncertain parameter {self.name!r} is not finite ({value!r})")
        return (value - self.nominal) / self.radius


@dataclass(frozen=True, eq=True)
class ULTIDyn(_Atom):
    """Uncertain stable LTI dynamics, ``ny × nu``, ``‖Δ‖∞ <= bound`` (see :func:`ultidyn`)."""

    kind = "dynamic"
    name: str
    ny: int
    nu: int
    bound: float = 1.0


def ureal(name: str, nominal: float, *, range=None, percent=None, plusminus=None) -> UReal:
    """Uncertain real parameter.

    Give exactly one of ``range``, ``percent`` and ``plusminus``.  The normalised
    ``δ ∈ [-1, 1]`` is affine in the value for ranges symmetric about the nominal and
    linear fractional otherwise (see :mod:`lmi_suspension.umodel.atoms`).

    Parameters
    ----------
    name : str
        Name of the parameter (the key of :func:`usubs` and of ``worst`` results).
    nominal : float
        Nominal value, strictly inside the range.
    range : (float, float), optional
        ``(lo, hi)`` with ``lo < nominal < hi``.
    percent : float or (float, float), optional
        ``p`` gives ``nominal ± |nominal| p / 100``; a pair ``(p_lo, p_hi)`` gives
        ``[nominal - |nominal| p_lo/100, nominal + |nominal| p_hi/100]``.
    plusminus : float or (float, float), optional
        ``d`` gives ``nominal ± d``; a pair ``(d_lo, d_hi)`` gives
        ``[nominal - d_lo, nominal + d_hi]``.

    Returns
    -------
    UReal

    Raises
    ------
    ParameterError
        Not exactly one range argument, a zero-width range, or a range that excludes
        the nominal (the message names the parameter).
    NonFiniteError
        A NaN or infinite nominal or range.

    Examples
    --------
    >>> from lmi_suspension.uncertain import ureal
    >>> k = ureal("k", 2.0, percent=10)
    >>> k.lo, k.hi
    (1.8, 2.2)
    >>> m = ureal("m", 1.0, range=(0.5, 3.0))   # asymmetric: linear fractional map
    >>> [round(m.value(d), 12) for d in (-1, 0, 1)]
    [0.5, 1.0, 3.0]
    """
    name = _name(name)
    nominal = _real(nominal, "nominal value", name)
    given = [(k, v) for k, v in (("range", range), ("percent", percent), ("plusminus", plusminus)) if v is not None]
    if len(given) != 1:
        raise ParameterError(
            f"ureal {name!r}: give exactly one of range=, percent=, plusminus= (got "
            f"{[k for k, _ in given] or 'none'})")
    kind, spec = given[0]

    def pair(spec):
        if isinstance(spec, (tuple, list, np.ndarray)):
            if len(spec) != 2:
                raise ParameterError(f"ureal {name!r}: {kind} must be a number or a pair, got {spec!r}")
            return _real(spec[0], kind, name), _real(spec[1], kind, name)
        v = _real(spec, kind, name)
        return v, v

    if kind == "range":
        if not isinstance(spec, (tuple, list, np.ndarray)) or len(spec) != 2:
            raise ParameterError(f"ureal {name!r}: range must be a pair (lo, hi), got {spec!r}")
        lo, hi = _real(spec[0], "range", name), _real(spec[1], "range", name)
    elif kind == "percent":
        p_lo, p_hi = pair(spec)
        lo, hi = nominal - abs(nominal) * p_lo / 100.0, nominal + abs(nominal) * p_hi / 100.0
    else:
        d_lo, d_hi = pair(spec)
        lo, hi = nominal - d_lo, nominal + d_hi
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise NonFiniteError(f"ureal {name!r}: the range [{lo}, {hi}] is not finite")
    if hi - lo <= 0 or hi == nominal or lo == nominal:
        if hi - lo <= 0 and not lo > hi:
            raise ParameterError(f"ureal {name!r}: the range [{lo}, {hi}] has zero width")
        if lo > hi:
            raise ParameterError(f"ureal {name!r}: the range [{lo}, {hi}] is empty (lo > hi)")
        raise ParameterError(
            f"ureal {name!r}: the nominal value {nominal} must lie strictly inside the range "
            f"[{lo}, {hi}]")
    if not (lo < nominal < hi):
        raise ParameterError(
            f"ureal {name!r}: the range [{lo}, {hi}] excludes the nominal value {nominal}")
    return UReal(name, nominal, lo, hi)


def ucomplex(name: str, nominal: float, radius: float) -> UComplex:
    """Uncertain complex parameter ``nominal + radius δ`` with ``|δ| <= 1``.

    The nominal value must be real (python-control systems have real coefficients);
    substituting a non-real value is only possible in the analysis functions.

    Examples
    --------
    >>> from lmi_suspension.uncertain import ucomplex
    >>> ucomplex("g", 1.0, 0.2).value(1j)
    (1+0.2j)
    """
    name = _name(name)
    nominal = _real(nominal, "nominal value", name)
    radius = _real(radius, "radius", name)
    if radius <= 0:
        raise ParameterError(f"ucomplex {name!r}: radius must be positive, got {radius}")
    return UComplex(name, nominal, radius)


def ultidyn(name: str, shape=(1, 1), *, bound: float = 1.0) -> ULTIDyn:
    """Uncertain stable LTI dynamics ``Δ(s)`` (``ny × nu``, ``‖Δ‖∞ <= bound``).

    Enters a model as an uncertain system with ``nu`` inputs and ``ny`` outputs; in
    :func:`lftdata` it is a full complex block ``[ny, nu]``.

    Examples
    --------
    >>> from lmi_suspension.uncertain import ultidyn
    >>> ultidyn("D", (1, 2), bound=0.5)
    ULTIDyn(name='D', ny=1, nu=2, bound=0.5)
    """
    name = _name(name)
    try:
        ny, nu = (int(v) for v in shape)
    except (TypeError, ValueError) as exc:
        raise DimensionError(f"ultidyn {name!r}: shape must be (ny, nu), got {shape!r}") from exc
    if ny < 1 or nu < 1:
        raise DimensionError(f"ultidyn {name!r}: shape must be positive, got {shape!r}")
    bound = _real(bound, "bound", name)
    if bound <= 0:
        raise ParameterError(f"ultidyn {name!r}: bound must be positive, got {bound}")
    return ULTIDyn(name, ny, nu, bound)
