"""Ride-comfort metrics of ISO 2631-1:1997 (vertical, seated): Wk weighting, weighted RMS, VDV.

Reference: ISO 2631-1:1997, "Mechanical vibration and shock — Evaluation of human exposure
to whole-body vibration — Part 1: General requirements", Annex A (Table A.1: parameters of
the transfer functions of the frequency weightings) and Table 3 (tabulated Wk values).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control
import numpy as np

from ..errors import DimensionError
from ..lti.checks import as_finite_array
from .roads import require_uniform_time

__all__ = ["WK_PARAMETERS", "wk_filter", "wk_gain", "weighted_acceleration", "weighted_rms",
           "rms", "vdv", "ComfortMetrics", "comfort_metrics"]

#: Wk parameters of ISO 2631-1:1997 Table A.1: band limiting f1, f2 (Q1 = Q2 = 1/sqrt(2)),
#: a-v transition f3, f4, Q4, upward step f5, Q5, f6, Q6. Frequencies in Hz.
WK_PARAMETERS = {"f1": 0.4, "f2": 100.0, "f3": 12.5, "f4": 12.5, "Q4": 0.63,
                 "f5": 2.37, "Q5": 0.91, "f6": 3.35, "Q6": 0.91}


def wk_filter(band_limited: bool = True) -> control.TransferFunction:
    """The ISO 2631-1 Wk frequency weighting (vertical, seated) as a continuous-time filter.

    ``Wk(s) = Hh(s) Hl(s) Ht(s) Hs(s)`` with (ISO 2631-1:1997, Annex A, ``w_i = 2 pi f_i``)

    * high-pass band limit ``Hh = s² / (s² + w1 s/Q1 + w1²)``, ``Q1 = 1/sqrt(2)``,
    * low-pass band limit ``Hl = w2² / (s² + w2 s/Q2 + w2²)``, ``Q2 = 1/sqrt(2)``,
    * a-v transition ``Ht = (1 + s/w3) / (1 + s/(Q4 w4) + s²/w4²)``,
    * upward step ``Hs = (1 + s/(Q5 w5) + s²/w5²) / (1 + s/(Q6 w6) + s²/w6²) · (w5/w6)²``.

    Parameters
    ----------
    band_limited : bool
        Include the band-limiting filters ``Hh Hl`` (default). Without them the result
        is the weighting proper ``Ht Hs``, the shape used as a design weight.

    Returns
    -------
    control.TransferFunction
        Input: unweighted acceleration, m/s²; output: weighted acceleration, m/s².

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.comfort import wk_filter
    >>> W = wk_filter()
    >>> round(float(abs(W(2j * np.pi * 1.0))), 3)   # ISO 2631-1 Table 3: 0.482 at 1 Hz
    0.482
    """
    p = WK_PARAMETERS
    w1, w2, w3, w4, w5, w6 = (2.0 * math.pi * p[k] for k in ("f1", "f2", "f3", "f4", "f5", "f6"))
    q12 = 1.0 / math.sqrt(2.0)
    tf = control.tf
    Hh = tf([1.0, 0.0, 0.0], [1.0, w1 / q12, w1 ** 2])
    Hl = tf([w2 ** 2], [1.0, w2 / q12, w2 ** 2])
    Ht = tf([w4 ** 2 / w3, w4 ** 2], [1.0, w4 / p["Q4"], w4 ** 2])
    Hs = tf([1.0, w5 / p["Q5"], w5 ** 2], [1.0, w6 / p["Q6"], w6 ** 2])
    # Hs already equals (w5/w6)^2 * (1 + s/(Q5 w5) + s^2/w5^2)/(1 + s/(Q6 w6) + s^2/w6^2).
    return Hh * Hl * Ht * Hs if band_limited else Ht * Hs


def wk_gain(f_hz) -> np.ndarray:
    """``|Wk(j 2 pi f)|`` at the frequencies ``f_hz`` (Hz).

    Examples
    --------
    >>> from lmi_suspension.seat.comfort import wk_gain
    >>> round(float(wk_gain(5.0)), 3)   # Table 3: 1.039 at 5 Hz
    1.039
    """
    f = as_finite_array(f_hz, "f_hz")
    W = wk_filter()
    return np.abs(W(2j * np.pi * f))


def _signal(t, a):
    t = as_finite_array(t, "t", ndim=1)
    a = as_finite_array(a, "a", ndim=1)
    if t.shape != a.shape:
        raise DimensionError(f"t and a must have the same length, got {t.shape} and {a.shape}")
    require_uniform_time(t, "t")
    return t, a


def weighted_acceleration(t, a) -> np.ndarray:
    """Wk-weighted acceleration ``a_w(t)``, starting from rest.

    The filter is simulated exactly for a piecewise-linear input (``control.forced_response``
    interpolates linearly between samples). Sample fast enough for the 100 Hz band limit.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.comfort import weighted_acceleration
    >>> t = np.arange(0, 10, 1e-3)
    >>> aw = weighted_acceleration(t, np.sin(2 * np.pi * 5 * t))
    >>> round(float(np.abs(aw[t > 5]).max()), 2)
    1.04
    """
    t, a = _signal(t, a)
    resp = control.forced_response(control.ss(wk_filter()), T=t - t[0], U=a)
    return np.asarray(resp.outputs, dtype=float).ravel()


def rms(t, a) -> float:
    """Root mean square ``sqrt(1/T ∫ a² dt)`` over the record (trapezoidal rule).

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.comfort import rms
    >>> t = np.linspace(0, 1, 1001)
    >>> round(rms(t, 2 * np.sin(2 * np.pi * 3 * t)), 6)   # A / sqrt(2)
    1.414214
    """
    t, a = _signal(t, a)
    return float(math.sqrt(np.trapezoid(a ** 2, t) / (t[-1] - t[0])))


def weighted_rms(t, a) -> float:
    """ISO 2631-1 frequency-weighted RMS acceleration ``a_w`` (Wk), m/s².

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.comfort import weighted_rms
    >>> t = np.arange(0, 20, 1e-3)
    >>> round(float(weighted_rms(t, np.sin(2 * np.pi * t)) * np.sqrt(2)), 2)   # ≈ |Wk(1 Hz)|
    0.48
    """
    t, a = _signal(t, a)
    return rms(t, weighted_acceleration(t, a))


def vdv(t, a, *, weighted: bool = True) -> float:
    """Fourth-power vibration dose value ``(∫ a_w⁴ dt)^(1/4)``, m/s^1.75 (ISO 2631-1, 6.3.2).

    Parameters
    ----------
    t, a : array_like
        Uniform time grid (s) and acceleration (m/s²).
    weighted : bool
        Apply Wk first (the standard's definition); ``False`` integrates ``a`` as given.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.comfort import vdv
    >>> t = np.linspace(0, 2, 20001)
    >>> round(vdv(t, np.sin(2 * np.pi * t), weighted=False), 4)   # (3 T / 8)^(1/4)
    0.9306
    """
    t, a = _signal(t, a)
    x = weighted_acceleration(t, a) if weighted else a
    return float(np.trapezoid(x ** 4, t) ** 0.25)


@dataclass(frozen=True)
class ComfortMetrics:
    """Comfort figures of an acceleration record.

    Attributes
    ----------
    peak : float
        Peak ``|a|`` (unweighted), m/s².
    rms : float
        RMS of ``a`` (unweighted), m/s².
    weighted_rms : float
        ISO 2631-1 Wk-weighted RMS, m/s².
    vdv : float
        Vibration dose value of the Wk-weighted signal, m/s^1.75.
    crest_factor : float
        Peak of the weighted signal over its RMS (ISO 2631-1, 6.2.1); ``nan`` for a zero signal.
    """

    peak: float
    rms: float
    weighted_rms: float
    vdv: float
    crest_factor: float


def comfort_metrics(t, z3dd) -> ComfortMetrics:
    """Peak, RMS, weighted RMS, VDV and crest factor of an upper-body acceleration record.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.comfort import comfort_metrics
    >>> t = np.arange(0, 10, 1e-3)
    >>> m = comfort_metrics(t, np.sin(2 * np.pi * 4 * t))
    >>> round(m.peak, 3), round(m.rms, 3)
    (1.0, 0.707)
    """
    t, a = _signal(t, z3dd)
    aw = weighted_acceleration(t, a)
    w_rms = rms(t, aw)
    crest = float(np.max(np.abs(aw)) / w_rms) if w_rms > 0 else float("nan")
    return ComfortMetrics(peak=float(np.max(np.abs(a))), rms=rms(t, a), weighted_rms=w_rms,
                          vdv=float(np.trapezoid(aw ** 4, t) ** 0.25), crest_factor=crest)
