"""Weighting functions for the seat design: MATLAB-style ``makeweight`` and ISO 2631-1 Wk.

``makeweight`` follows MATLAB's documented semantics: ``W(0) = dc``, ``W(inf) = hf``
and ``|W(j*freq)| = mag`` (``mag = 1`` for a crossover frequency), with poles and
zeros in a Butterworth pattern for orders above one.

The Wk weighting is the frequency weighting for vertical whole-body vibration of a
seated person, ISO 2631-1:1997 (Mechanical vibration and shock -- Evaluation of human
exposure to whole-body vibration -- Part 1: General requirements), Annex A, Table A.2:
band limiting (f1 = 0.4 Hz, f2 = 100 Hz, Q = 1/sqrt(2)), acceleration-velocity
transition (f3 = f4 = 12.5 Hz, Q4 = 0.63) and upward step (f5 = 2.37 Hz, Q5 = 0.91,
f6 = 3.35 Hz, Q6 = 0.91), gain K = 1.
"""

from __future__ import annotations

import logging
import numbers

import control
import numpy as np
from scipy import optimize, signal

from ..errors import ParameterError
from ..lti.checks import as_finite_array
from .comfort import WK_PARAMETERS, wk_filter

__all__ = ["makeweight", "iso2631_wk", "wk_weight", "WK_PARAMETERS"]

logger = logging.getLogger(__name__)

#: ISO 2631-1:1997 Annex A, Table A.2, row Wk (frequencies in Hz).
# ISO 2631-1 Wk lives in comfort.py (one definition for metrics and design weights).



def _real_scalar(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ParameterError(f"{name} must be a real number, got {value!r}")
    return float(as_finite_array(value, name))


def _butter_poly(order: int) -> np.ndarray:
    """Coefficients of the normalised Butterworth polynomial B_N (|B_N(jx)|^2 = 1 + x^2N)."""
    _, poles, _ = signal.buttap(order)
    return np.real(np.poly(poles))


def makeweight(dc, crossover, hf, order: int = 1, *, mag: float = 1.0) -> control.StateSpace:
    """Weight with gain ``dc`` at 0, ``mag`` at ``crossover`` rad/s and ``hf`` at infinity.

    Same semantics as MATLAB's ``makeweight(dcgain, [freq, mag], hfgain, 0, N)``: a
    stable, minimum-phase weight whose gain changes monotonically from ``dc`` to
    ``hf``.  For ``order > 1`` poles and zeros lie in a Butterworth pattern, so that
    ``|W(jω)|² = (dc² + hf² (ω/ω0)^(2N)) / (1 + (ω/ω0)^(2N))``.

    Parameters
    ----------
    dc, hf : float
        Gains at ω = 0 and ω → ∞ (non-negative, not both on the same side of ``mag``).
    crossover : float
        Frequency (rad/s) where ``|W| = mag``.
    order : int
        Order N of the weight (1 to 10).
    mag : float
        Gain at ``crossover``; 1 by default (crossover frequency).

    Returns
    -------
    control.StateSpace
        SISO weight of ``order`` states.

    Raises
    ------
    ParameterError
        If ``mag`` is not strictly between ``dc`` and ``hf``, a gain is negative, the
        frequency is not positive or the order is not an integer in 1..10.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.weights import makeweight
    >>> W = makeweight(100, 10, 0.1)     # MATLAB: (0.1 s + 9.95)/(s + 0.0995)
    >>> round(float(W.dcgain()), 6), round(abs(complex(W(10j))), 6)
    (100.0, 1.0)
    """
    dc = _real_scalar(dc, "dc")
    hf = _real_scalar(hf, "hf")
    wc = _real_scalar(crossover, "crossover")
    mag = _real_scalar(mag, "mag")
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or not 1 <= order <= 10:
        raise ParameterError(f"order must be an integer in 1..10, got {order!r}")
    if dc < 0 or hf < 0:
        raise ParameterError(f"gains must be non-negative, got dc={dc}, hf={hf}")
    if wc <= 0:
        raise ParameterError(f"crossover must be a positive frequency in rad/s, got {wc}")
    if mag <= 0:
        raise ParameterError(f"mag must be positive, got {mag}")
    if not (min(dc, hf) < mag < max(dc, hf)):
        raise ParameterError(
            f"the gain {mag} at the crossover must lie strictly between dc={dc} and hf={hf}")
    n = int(order)
    # |W(j wc)|^2 = mag^2 fixes the corner w0 of the Butterworth pattern.
    ratio = (dc ** 2 - mag ** 2) / (mag ** 2 - hf ** 2)
    w0 = wc * ratio ** (-1.0 / (2 * n))
    # Monic coefficients of w0^N * B_N(s / w0): the s^(N-i) coefficient scales by w0^i.
    den = _butter_poly(n) * w0 ** np.arange(n + 1)
    if dc > 0 and hf > 0:
        # zeros in a Butterworth pattern of radius wz: W = dc * B_N(s/wz) / B_N(s/w0)
        wz = w0 * (dc / hf) ** (1.0 / n)
        num = dc * (w0 / wz) ** n * _butter_poly(n) * wz ** np.arange(n + 1)
    elif dc == 0:
        num = np.zeros(n + 1)
        num[0] = hf
    else:  # hf == 0
        num = np.zeros(n + 1)
        num[-1] = dc * w0 ** n
    return control.ss(control.tf(num, den))


def iso2631_wk() -> control.StateSpace:
    """The full 8th-order ISO 2631-1:1997 Wk weighting (Annex A), ω in rad/s.

    Product of the band limiting high pass (0.4 Hz) and low pass (100 Hz), the
    acceleration-velocity transition ``H_t`` and the upward step ``H_s``.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.weights import iso2631_wk
    >>> Wk = iso2631_wk()
    >>> round(abs(complex(Wk(2j * np.pi * 6.3))), 2)   # ISO 2631-1 Table 3: 1.054
    1.05
    """
    return control.ss(wk_filter())


def _wk_transition_step() -> control.TransferFunction:
    return wk_filter(band_limited=False)


def _fit_low_order(order: int) -> control.TransferFunction:
    """Least-squares fit (log magnitude, 0.5–80 Hz) of a stable minimum-phase weight."""
    f = np.logspace(np.log10(0.5), np.log10(80.0), 200)
    w = 2 * np.pi * f
    target = np.log(np.abs(_wk_transition_step()(1j * w)))

    def build(theta):
        k, z1, wn, zeta = np.exp(theta[:4])
        num = k * np.array([1 / z1, 1.0])
        den = np.array([1 / wn ** 2, 2 * zeta / wn, 1.0])
        if order == 3:
            z2, p1 = np.exp(theta[4:6])
            num = np.polymul(num, [1 / z2, 1.0])
            den = np.polymul(den, [1 / p1, 1.0])
        return num, den

    def residual(theta):
        num, den = build(theta)
        s = 1j * w
        return np.log(np.abs(np.polyval(num, s) / np.polyval(den, s))) - target

    # Start from the shape of H_s * H_t: DC 0.5, a rise near 2-3 Hz (f5, f6), the
    # roll-off at 12.5 Hz (f3, f4).
    hz = 2 * np.pi
    theta0 = np.log([0.5, 3.0 * hz, 12.5 * hz, 0.6])
    if order == 3:
        theta0 = np.log([0.5, 2.0 * hz, 12.5 * hz, 0.6, 12.5 * hz, 3.35 * hz])
    sol = optimize.least_squares(residual, theta0, method="lm", max_nfev=5000, xtol=1e-12)
    num, den = build(sol.x)
    return control.tf(num, den)


def wk_weight(order: int = 4, *, acc_ref: float = 1.0) -> control.StateSpace:
    """Low-order ISO 2631-1 Wk weight for the z̈3 channel, scaled by ``1/acc_ref``.

    The band-limiting filters of :func:`iso2631_wk` act outside 0.4–100 Hz, where the
    seat dynamics have no influence on comfort; the weights here keep the part that
    gives Wk its 4–12.5 Hz emphasis.

    Parameters
    ----------
    order : {2, 3, 4}
        4: the exact product ``H_t · H_s`` of ISO 2631-1:1997 (no band limiting);
        2 or 3: a least-squares fit of that product over 0.5–80 Hz.
    acc_ref : float
        Frequency-weighted acceleration (m/s²) that maps to a unit error.

    Returns
    -------
    control.StateSpace
        SISO weight from z̈3 (m/s²) to a normalised error.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.weights import wk_weight
    >>> W = wk_weight(acc_ref=0.5)
    >>> round(abs(complex(W(2j * np.pi * 6.3))) * 0.5, 2)
    1.05
    """
    acc_ref = _real_scalar(acc_ref, "acc_ref")
    if acc_ref <= 0:
        raise ParameterError(f"acc_ref must be positive (m/s^2), got {acc_ref}")
    if isinstance(order, bool) or order not in (2, 3, 4):
        raise ParameterError(f"order must be 2, 3 or 4, got {order!r}")
    tf = _wk_transition_step() if order == 4 else _fit_low_order(int(order))
    return control.ss(tf * (1.0 / acc_ref))
