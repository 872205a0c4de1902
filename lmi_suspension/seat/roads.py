"""Road (floor) inputs for the seat suspension: the paper's bump, white noise, ISO 8608 roads.

Every generator returns a :class:`RoadInput` holding the floor displacement ``z0`` (m) and
the disturbance input of the seat model ``w = z0'`` (m/s) on a uniform time grid.

Conventions
-----------
* Between samples ``w`` is meant to be read as piecewise linear (first-order hold); the
  simulator (:func:`lmi_suspension.seat.simulate.simulate`) uses exactly that reading.
* Randomness only comes from the ``numpy.random.Generator`` passed as ``rng``.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import cumulative_trapezoid

from ..errors import DimensionError, ParameterError
from ..lti.checks import as_finite_array, positive_scalar

__all__ = ["RoadInput", "bump", "white_noise", "iso8608_road", "ISO8608_GD_N0",
           "ISO8608_N0", "ISO8608_BAND", "iso8608_psd", "road_energy"]

logger = logging.getLogger(__name__)

#: Reference spatial frequency of ISO 8608:1995, cycles/m.
ISO8608_N0 = 0.1
#: Geometric mean of the displacement PSD Gd(n0) per road class, m^3 (ISO 8608:1995,
#: Table 1 / Annex: class A 16e-6, each next class x4: B 64e-6, C 256e-6, D 1024e-6, ...).
ISO8608_GD_N0 = {cls: 16e-6 * 4.0 ** i for i, cls in enumerate("ABCDEFGH")}
#: Spatial-frequency band over which ISO 8608 specifies the fitted PSD, cycles/m.
ISO8608_BAND = (0.011, 2.83)


@dataclass(frozen=True)
class RoadInput:
    """A floor excitation sampled on a uniform time grid.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Time, s (uniform, increasing).
    z0 : ndarray, shape (N,)
        Floor (road) displacement, m.
    w : ndarray, shape (N,)
        Floor velocity ``z0'``, m/s: the disturbance input ``w`` of the seat model.
    description : str
        Human-readable origin of the signal.
    """

    t: np.ndarray
    z0: np.ndarray
    w: np.ndarray
    description: str = ""

    def __post_init__(self):
        t = as_finite_array(self.t, "road.t", ndim=1)
        z0 = as_finite_array(self.z0, "road.z0", ndim=1)
        w = as_finite_array(self.w, "road.w", ndim=1)
        if not (t.shape == z0.shape == w.shape):
            raise DimensionError(
                f"road t, z0, w must have the same length, got {t.shape}, {z0.shape}, {w.shape}")
        require_uniform_time(t, "road.t")
        for name, arr in (("t", t), ("z0", z0), ("w", w)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    @property
    def dt(self) -> float:
        """Sample period, s."""
        return float(self.t[1] - self.t[0])

    @property
    def t_end(self) -> float:
        """Last sample time, s."""
        return float(self.t[-1])


def require_uniform_time(t: np.ndarray, name: str = "t") -> None:
    """Raise a typed error unless ``t`` has at least two strictly increasing, uniformly
    spaced samples (roads and comfort metrics both assume a fixed step)."""
    if t.size < 2:
        raise DimensionError(f"{name} needs at least two samples")
    steps = np.diff(t)
    if np.any(steps <= 0):
        raise ParameterError(f"{name} must be strictly increasing")
    if np.ptp(steps) > 1e-6 * steps.mean():
        raise ParameterError(f"{name} must be uniformly spaced")


def _time_grid(t_end: float, dt: float) -> np.ndarray:
    t_end = positive_scalar(t_end, "t_end")
    dt = positive_scalar(dt, "dt")
    if dt > t_end:
        raise ParameterError(f"dt ({dt} s) must not exceed t_end ({t_end} s)")
    n = int(round(t_end / dt))
    if n > 50_000_000:
        raise ParameterError(f"t_end/dt = {n} samples is too many")
    return np.arange(n + 1) * dt


def _require_rng(rng) -> np.random.Generator:
    if not isinstance(rng, np.random.Generator):
        raise ParameterError(
            "rng must be a numpy.random.Generator (e.g. numpy.random.default_rng(0)); "
            f"got {type(rng).__name__}")
    return rng


def bump(a: float = 0.1, l: float = 2.0, V0_kmh: float = 30.0, *, t_end: float = 3.0,
         dt: float = 1e-3) -> RoadInput:
    """The paper's single bump, eq. (32), with its exact derivative.

    ``z0(t) = a/2 (1 - cos(2 pi V0 t / l))`` for ``0 <= t <= l/V0``, 0 afterwards, and
    ``w(t) = z0'(t) = (a pi V0 / l) sin(2 pi V0 t / l)`` on the same interval (analytic).

    Parameters
    ----------
    a : float
        Bump height, m (0.1).
    l : float
        Bump length, m (2.0).
    V0_kmh : float
        Vehicle speed, km/h (30). The bump lasts ``l / V0`` (0.24 s with the defaults).
    t_end : float
        Duration of the record, s (the tail lets the seat settle).
    dt : float
        Sample period, s.

    Returns
    -------
    RoadInput

    Examples
    --------
    >>> from lmi_suspension.seat.roads import bump
    >>> r = bump()
    >>> round(float(r.z0.max()), 6), round(float(r.t[r.z0.argmax()]), 3)
    (0.1, 0.12)
    """
    a = positive_scalar(a, "a")
    l = positive_scalar(l, "l")
    V0 = positive_scalar(V0_kmh, "V0_kmh") / 3.6
    t = _time_grid(t_end, dt)
    duration = l / V0
    on = t <= duration
    phase = 2.0 * np.pi * V0 * t / l
    z0 = np.where(on, 0.5 * a * (1.0 - np.cos(phase)), 0.0)
    w = np.where(on, 0.5 * a * (2.0 * np.pi * V0 / l) * np.sin(phase), 0.0)
    return RoadInput(t, z0, w, f"bump a={a} m, l={l} m, V0={V0_kmh} km/h (eq. 32)")


def white_noise(t_end: float, dt: float, *, psd: float = 1.0, bandwidth_hz: float | None = None,
                rng: np.random.Generator) -> RoadInput:
    """Zero-mean band-limited white noise for the floor velocity ``w``.

    Convention: ``psd`` is the **two-sided** power spectral density ``S_w(f)`` of ``w`` in
    (m/s)²/Hz, flat for ``|f| <= bandwidth_hz`` (one-sided density ``2*psd``). Hence the
    variance is ``2 * psd * bandwidth_hz``. With ``bandwidth_hz=None`` the band is the
    Nyquist band ``1/(2 dt)`` and the samples are i.i.d. normal with variance ``psd/dt``:
    the sampled version of continuous white noise of intensity ``psd``
    (``E[w(t)w(s)] = psd * delta(t - s)``), i.e. the paper's "identity power spectral
    density" for ``psd=1`` (Fig. 8). ``z0`` is the trapezoidal integral of ``w``, which is
    exact for the piecewise-linear reading of ``w``.

    Parameters
    ----------
    t_end, dt : float
        Duration and sample period, s.
    psd : float
        Two-sided PSD of ``w``, (m/s)²/Hz.
    bandwidth_hz : float, optional
        Upper band edge, Hz (ideal low-pass applied in the DFT domain); at most ``1/(2 dt)``.
    rng : numpy.random.Generator
        Source of randomness (required).

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.roads import white_noise
    >>> r = white_noise(100.0, 1e-3, psd=1e-4, bandwidth_hz=50.0, rng=np.random.default_rng(1))
    >>> bool(abs(r.w.var() / (2 * 1e-4 * 50.0) - 1) < 0.1)
    True
    """
    rng = _require_rng(rng)
    psd = positive_scalar(psd, "psd")
    t = _time_grid(t_end, dt)
    dt = float(t[1] - t[0])
    nyquist = 0.5 / dt
    w = rng.standard_normal(t.size) * math.sqrt(psd / dt)
    if bandwidth_hz is not None:
        bandwidth_hz = positive_scalar(bandwidth_hz, "bandwidth_hz")
        if bandwidth_hz > nyquist * (1 + 1e-12):
            raise ParameterError(
                f"bandwidth_hz ({bandwidth_hz}) exceeds the Nyquist frequency {nyquist} Hz")
        # Zeroing the DFT bins above the band keeps the in-band density unchanged.
        spec = np.fft.rfft(w)
        freqs = np.fft.rfftfreq(t.size, dt)
        spec[freqs > bandwidth_hz] = 0.0
        w = np.fft.irfft(spec, n=t.size)
    w = w - w.mean()  # zero-mean record: the floor does not drift on average
    z0 = cumulative_trapezoid(w, t, initial=0.0)
    band = "Nyquist" if bandwidth_hz is None else f"{bandwidth_hz} Hz"
    return RoadInput(t, z0, w, f"white noise w, two-sided PSD {psd} (m/s)^2/Hz, band {band}")


def iso8608_psd(n, road_class: str) -> np.ndarray:
    """ISO 8608 fitted displacement PSD ``Gd(n) = Gd(n0) (n/n0)^-2`` in m³ (one-sided).

    Parameters
    ----------
    n : array_like
        Spatial frequency, cycles/m.
    road_class : str
        ``'A'`` … ``'H'``.

    Examples
    --------
    >>> from lmi_suspension.seat.roads import iso8608_psd
    >>> float(iso8608_psd(0.1, 'C'))
    0.000256
    """
    key = _road_class(road_class)
    n = np.asarray(n, dtype=float)
    return ISO8608_GD_N0[key] * (n / ISO8608_N0) ** -2.0


def _road_class(road_class) -> str:
    if not isinstance(road_class, str) or road_class.upper() not in ISO8608_GD_N0:
        raise ParameterError(f"road_class must be one of 'A'..'H', got {road_class!r}")
    return road_class.upper()


def iso8608_road(road_class: str, V_kmh: float, t_end: float, dt: float, *,
                 rng: np.random.Generator, band=ISO8608_BAND) -> RoadInput:
    """Random road profile of ISO 8608 class A–H driven at constant speed.

    ISO 8608:1995 ("Mechanical vibration — Road surface profiles — Reporting of measured
    data") fits the one-sided displacement PSD as ``Gd(n) = Gd(n0) (n/n0)^-w`` with
    ``n0 = 0.1`` cycles/m and waviness ``w = 2``; the geometric mean of ``Gd(n0)`` per class
    is A 16, B 64, C 256, D 1024, E 4096, F 16384, G 65536, H 262144 (×1e-6 m³), valid for
    0.011 ≤ n ≤ 2.83 cycles/m.

    The profile is a sum of cosines with independent uniform random phases at the DFT
    frequencies ``f_k = k/(N dt)`` of the record, ``z0(t) = sum_k A_k cos(2 pi f_k t + phi_k)``
    with ``A_k = sqrt(2 G(f_k) df)``, where ``G(f) = Gd(f/V)/V`` is the temporal one-sided
    PSD and ``df = 1/(N dt)``; components outside ``band`` (cycles/m) are omitted. ``w`` is
    the analytic derivative of that sum (not a finite difference). The record is periodic
    with period ``N dt``. Components above the Nyquist frequency ``1/(2 dt)`` cannot be
    represented and are dropped (logged).

    Since ``Gd ∝ n^-2``, ``w`` is band-limited white noise with one-sided PSD
    ``(2 pi)^2 Gd(n0) n0^2 V``.

    Parameters
    ----------
    road_class : str
        ``'A'`` … ``'H'``.
    V_kmh : float
        Speed, km/h.
    t_end, dt : float
        Duration and sample period, s.
    rng : numpy.random.Generator
        Source of the random phases (required).
    band : (float, float)
        Spatial-frequency band kept, cycles/m (ISO 8608 validity band by default).

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.roads import iso8608_road
    >>> r = iso8608_road('C', 72.0, 10.0, 0.005, rng=np.random.default_rng(0))
    >>> r.t.size, bool(0.001 < r.z0.std() < 0.05)
    (2001, True)
    """
    rng = _require_rng(rng)
    key = _road_class(road_class)
    V = positive_scalar(V_kmh, "V_kmh") / 3.6
    n_lo, n_hi = (positive_scalar(b, "band edge") for b in band)
    if n_hi <= n_lo:
        raise ParameterError(f"band must be increasing, got {band!r}")
    t = _time_grid(t_end, dt)
    dt = float(t[1] - t[0])
    N = t.size
    f = np.fft.rfftfreq(N, dt)
    df = 1.0 / (N * dt)
    n_sp = f / V
    keep = (n_sp >= n_lo) & (n_sp <= n_hi) & (f < 0.5 / dt)
    if n_hi * V >= 0.5 / dt:
        logger.info("ISO 8608 band above %.3g Hz dropped: Nyquist frequency is %.3g Hz",
                    0.5 / dt, n_hi * V)
    if not np.any(keep):
        raise ParameterError("no frequency of the record falls inside the ISO 8608 band; "
                             "increase t_end or decrease dt")
    amp = np.zeros_like(f)
    G = ISO8608_GD_N0[key] * (n_sp[keep] / ISO8608_N0) ** -2.0 / V
    amp[keep] = np.sqrt(2.0 * G * df)
    coef = amp * np.exp(1j * rng.uniform(0.0, 2.0 * np.pi, size=amp.shape))
    # irfft computes (1/N) sum_k X_k e^{2 pi i k m/N} with hermitian completion, so a bin
    # X_k = N/2 * A_k e^{i phi_k} (k not 0 or Nyquist) gives A_k cos(2 pi f_k t + phi_k).
    z0 = np.fft.irfft(coef * (N / 2.0), n=N)
    w = np.fft.irfft(1j * 2.0 * np.pi * f * coef * (N / 2.0), n=N)
    return RoadInput(t, z0, w, f"ISO 8608 class {key} road at {V_kmh} km/h")


def road_energy(road: RoadInput) -> float:
    """``‖w‖₂`` of a floor velocity (trapezoidal rule), m/s·s^½.

    Examples
    --------
    >>> round(road_energy(bump()), 4)
    0.4534
    """
    return float(np.sqrt(np.trapezoid(np.asarray(road.w) ** 2, road.t)))
