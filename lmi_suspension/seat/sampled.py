"""The seat controller as a computer runs it: discretised at a sample rate, and the
sampled-data loop simulated against the continuous seat.

Discretisation (:func:`discretise_controller`) is Tustin's bilinear map
``s = (2/T)(z - 1)/(z + 1)`` by default (python-control's ``sample_system``).  It maps
the left half-plane onto the unit disk, so a stable controller stays stable at any
rate, and it keeps the controller's frequency response up to the warping
``ω -> (2/T) tan(ωT/2)``: at 1 kHz that is 0.03 % at 60 rad/s and 0.8 % at 300 rad/s,
negligible over the seat's band (0.5–50 rad/s), so prewarping is offered but not
needed.  Zero-order-hold equivalence is the exact discretisation of a *plant* behind a
hold; for a controller it adds no phase of its own where Tustin adds none, and it
aliases controller poles above the Nyquist rate instead of compressing them.

The sampled-data loop (:func:`simulate_sampled`) keeps the seat continuous: its states
are propagated exactly (matrix exponential, floor velocity piecewise linear) on a fine
step ``h`` that divides both the sample period and the delay.  At each sampling
instant the controller reads ``y = [x1, x3]`` (plus optional sensor noise and
quantisation), updates its state and issues ``u``; a zero-order hold keeps ``u`` until
the next instant; the actuator applies the held command ``d`` later, clipped at
``±u_max``.  The hold is the half-sample delay (0.5 ms at 1 kHz) that the 0–25 ms delay
cover of the µ design already covers.
"""

from __future__ import annotations

import logging
import math

import control
import numpy as np

from ..errors import DimensionError, ParameterError
from ..lti.scaling import balanced_matrices
from .model import SeatMatrices
from .params import SeatParameters
from .roads import RoadInput
from .simulate import (SimulationResult, _discretise, _params, _plant, _road_on_grid,
                       _scalar, _energy_growing)

__all__ = ["discretise_controller", "fastest_pole", "simulate_sampled", "DEFAULT_SAMPLE_TIME"]

logger = logging.getLogger(__name__)

#: 1 kHz: a realistic rate for a seat actuator's controller board
DEFAULT_SAMPLE_TIME = 1e-3
#: fine step of the continuous seat between samples (a divisor of 1 ms and of every
#: delay on a 0.1 ms grid; the road is read piecewise linear on it)
_FINE_STEP = 1e-4


def fastest_pole(K) -> float:
    """Largest pole magnitude of a continuous-time controller, rad/s.

    Parameters
    ----------
    K : control.StateSpace
        Continuous-time controller (a static gain has none: 0).

    Returns
    -------
    float
        ``max |eig(K.A)|``; a sampled controller resolves it if it lies below ``π/dt``.

    Examples
    --------
    >>> import control
    >>> fastest_pole(control.ss([[-10.0, 0.0], [0.0, -5000.0]], [[1.0], [1.0]],
    ...                         [[1.0, 1.0]], [[0.0]]))
    5000.0
    """
    return float(np.max(np.abs(np.linalg.eigvals(np.asarray(K.A))))) if K.nstates else 0.0


def discretise_controller(K, dt: float = DEFAULT_SAMPLE_TIME, *, method: str = "tustin",
                          prewarp: float | None = None,
                          warn_unresolved: bool = True) -> control.StateSpace:
    """The controller at sample time ``dt`` (s).

    Parameters
    ----------
    K : control.StateSpace
        Continuous-time controller.
    dt : float
        Sample time, s.
    method : {"tustin", "zoh"}
        Tustin (bilinear, the default; see the module docstring) or zero-order-hold
        equivalence.
    prewarp : float, optional
        Frequency (rad/s) at which Tustin's map is exact.
    warn_unresolved : bool
        Log a warning when a controller pole lies above the Nyquist rate ``π/dt`` (the
        discrete controller cannot resolve it). A caller that reports the fact itself
        (:func:`~lmi_suspension.report.reproduce`, with :func:`fastest_pole`) passes
        ``False``; it is then logged at debug level.

    Returns
    -------
    control.StateSpace
        Discrete-time, ``dt`` set, same signal names.

    Raises
    ------
    ParameterError
        Non-positive ``dt``, an unknown method, a discrete ``K``, or a prewarp frequency
        at or above the Nyquist rate ``π/dt``.

    Examples
    --------
    >>> import control
    >>> Kd = discretise_controller(control.ss([[-10.0]], [[1.0, 0.0]], [[5.0]], [[0.0, 0.0]]))
    >>> Kd.dt, bool(abs(Kd.poles()[0]) < 1)
    (0.001, True)
    """
    if not isinstance(K, control.StateSpace) or control.isdtime(K, strict=True):
        raise ParameterError("K must be a continuous-time control.StateSpace")
    dt = _scalar(dt, "dt")
    if dt <= 0:
        raise ParameterError(f"dt must be positive, got {dt!r}")
    methods = {"tustin": "bilinear", "zoh": "zoh"}
    if method not in methods:
        raise ParameterError(f"method must be 'tustin' or 'zoh', got {method!r}")
    if prewarp is not None:
        prewarp = _scalar(prewarp, "prewarp")
        if not 0 < prewarp < math.pi / dt:
            raise ParameterError(f"prewarp must lie in (0, π/dt) = (0, {math.pi / dt:.4g}) "
                                 f"rad/s, got {prewarp!r}")
        if method != "tustin":
            raise ParameterError("prewarp applies to the Tustin method only")
    fast = fastest_pole(K)
    if fast > math.pi / dt:
        logger.log(logging.WARNING if warn_unresolved else logging.DEBUG,
                   "controller pole at %.4g rad/s above the Nyquist rate %.4g rad/s: "
                   "the discrete controller does not resolve it", fast, math.pi / dt)
    kw = {"prewarp_frequency": prewarp} if prewarp is not None else {}
    Kd = control.sample_system(_balanced_for_tustin(K, dt) if method == "tustin" else K,
                               dt, method=methods[method], **kw)
    return control.ss(Kd.A, Kd.B, Kd.C, Kd.D, dt, inputs=K.input_labels,
                      outputs=K.output_labels, name=f"{K.name}_d" if K.name else None)


#: condition number of ``I - A dt/2`` above which Tustin's map is taken of the balanced
#: realization: the nominal H∞ LMI controller of ``reproduce`` (11 states, ‖A‖ 8.4e11)
#: gave 9.1e15 and scipy's solve warned on the user's terminal; balanced, 231 (measured
#: 2026-12-03); the shipped µ controllers stay below 1e3 and are mapped as they are
_TUSTIN_COND = 1e10


def _balanced_for_tustin(K: control.StateSpace, dt: float) -> control.StateSpace:
    """``K`` itself, or where ``I - A dt/2`` is ill-conditioned (:data:`_TUSTIN_COND`),
    the same controller after the project's diagonal state balancing
    (:func:`~lmi_suspension.lti.scaling.balanced_matrices`: powers of two, so every entry
    is scaled exactly and the transfer function is the same)."""
    A = np.asarray(K.A, dtype=float)
    if A.size == 0 or np.linalg.cond(np.eye(A.shape[0]) - 0.5 * dt * A) <= _TUSTIN_COND:
        return K
    logger.info("Tustin's map of a badly scaled realization (cond(I - A dt/2) above "
                "%.0e): balanced first", _TUSTIN_COND)
    Ab, Bb, Cb = balanced_matrices(A, np.asarray(K.B, dtype=float),
                                   np.asarray(K.C, dtype=float))
    return control.ss(Ab, Bb, Cb, K.D, inputs=K.input_labels, outputs=K.output_labels,
                      name=K.name)


def simulate_sampled(Kd, road: RoadInput, *, delay: float = 0.0,
                     params: SeatParameters | None = None, u_max: float | None = None,
                     noise: tuple | None = None, quantisation: float | None = None,
                     rng: np.random.Generator | None = None, dt: float = _FINE_STEP,
                     plant: SeatMatrices | None = None, divergence_bound: float = 1e2,
                     growth_factor: float | None = 4.0) -> SimulationResult:
    """Simulate the sampled-data loop: continuous seat, discrete controller, zero-order
    hold, exact delay, clipping.

    Parameters
    ----------
    Kd : control.StateSpace
        Discrete-time controller from ``y = [x1, x3]`` (m) to ``u`` (N), its sample time
        ``Kd.dt`` a multiple of ``dt``.
    road : RoadInput
        Floor excitation.
    delay : float
        Actuator delay, s, a multiple of ``dt``.
    params : SeatParameters, optional
    u_max : float, optional
        Clipping level, N (``params.u_max`` by default; ``numpy.inf``: none).
    noise : (float, float), optional
        Standard deviations of white sensor noise on ``x1`` and ``x3`` at each sample, m.
    quantisation : float, optional
        Sensor resolution, m (each reading rounded to a multiple of it).
    rng : numpy.random.Generator, optional
        The noise's generator (required with ``noise``: reproducible runs).
    dt : float
        Fine step of the continuous seat, s.
    plant : SeatMatrices, optional
        Perturbed seat matrices.
    divergence_bound, growth_factor
        As in :func:`~lmi_suspension.seat.simulate.simulate`.

    Returns
    -------
    SimulationResult
        On the fine grid: ``u_command`` is the held command, ``xk`` the controller state
        held between samples.

    Examples
    --------
    >>> import control
    >>> from lmi_suspension.seat.roads import bump
    >>> Kd = discretise_controller(control.ss([], [], [], [[0.0, 0.0]]))
    >>> r = simulate_sampled(Kd, bump(t_end=1.0))
    >>> r.stable, float(r.u_command.max())
    (True, 0.0)
    """
    params = _params(params)
    M = _plant(plant, params)
    if not isinstance(Kd, control.StateSpace) or not control.isdtime(Kd, strict=True) \
            or Kd.dt is True:
        raise ParameterError("Kd must be a discrete-time control.StateSpace with a "
                             "numeric sample time (see discretise_controller)")
    if Kd.ninputs != 2 or Kd.noutputs != 1:
        raise DimensionError("Kd must map y = [x1, x3] (2 inputs) to u (1 output); got "
                             f"{Kd.ninputs} inputs and {Kd.noutputs} outputs")
    h = _scalar(dt, "dt")
    if h <= 0:
        raise ParameterError(f"dt must be positive, got {dt!r}")
    every = _multiple(float(Kd.dt), h, "the sample time Kd.dt")
    delay_steps = _multiple(_scalar(delay, "delay"), h, "delay", allow_zero=True)
    u_max = params.u_max if u_max is None else _scalar(u_max, "u_max", allow_inf=True)
    if not u_max > 0:
        raise ParameterError(f"u_max must be positive, got {u_max!r}")
    if noise is not None:
        noise = np.asarray(noise, dtype=float)
        if noise.shape != (2,) or not np.all(np.isfinite(noise)) or np.any(noise < 0):
            raise ParameterError(f"noise must be two non-negative standard deviations, "
                                 f"got {noise!r}")
        if rng is None:
            raise ParameterError("noise needs rng (a numpy.random.Generator)")
    if quantisation is not None:
        quantisation = _scalar(quantisation, "quantisation")
        if quantisation <= 0:
            raise ParameterError(f"quantisation must be positive, got {quantisation!r}")

    t, w = _road_on_grid(road, h)
    N, n = t.size, M.A.shape[0]
    Phi, Gu, Gw0, Gw1 = _discretise(M.A, M.B, M.Bw.reshape(n, 1), h)
    gu = Gu[:, 0]
    wc = np.outer(w[:-1], Gw0[:, 0]) + np.outer(np.diff(w), Gw1[:, 0])
    Ad, Bd, Cd, Dd = (np.asarray(m, dtype=float) for m in (Kd.A, Kd.B, Kd.C, Kd.D))
    nk = Ad.shape[0]
    x = np.zeros((N, n))
    xk_hist = np.zeros((N, nk))
    u_cmd = np.zeros(N)  # held command
    u_app = np.zeros(N)
    clipped = np.zeros(N, dtype=bool)
    state, xk, held = np.zeros(n), np.zeros(nk), 0.0
    stable, last = True, N - 1
    for k in range(N):
        x[k] = state
        if k % every == 0:
            y = M.C3 @ state
            if noise is not None:
                y = y + noise * rng.standard_normal(2)
            if quantisation is not None:
                y = quantisation * np.round(y / quantisation)
            held = float((Cd @ xk + Dd @ y)[0]) if nk else float((Dd @ y)[0])
            xk = Ad @ xk + Bd @ y
        u_cmd[k] = held
        xk_hist[k] = xk
        raw = u_cmd[k - delay_steps] if k >= delay_steps else 0.0
        ua = min(max(raw, -u_max), u_max)
        clipped[k], u_app[k] = ua != raw, ua
        if k == N - 1:
            break
        state = Phi @ state + gu * ua + wc[k]
        if k % 200 == 0 and not np.all(np.abs(state) < divergence_bound):
            stable, last = False, k + 1
            x[last] = state
            break
    sl = slice(0, last + 1)
    t, x, xk_hist, u_cmd, u_app, clipped = (a[sl] for a in (t, x, xk_hist, u_cmd, u_app,
                                                            clipped))
    if stable and growth_factor is not None:
        stable = not _energy_growing(x, max(int(0.2 * t.size), 1), growth_factor)
    return SimulationResult(t=t, x=x, xk=xk_hist, z3dd=x @ M.C1.ravel(), x1=x @ M.C2.ravel(),
                            x3=x @ M.C3[1], u_command=u_cmd, u_applied=u_app,
                            delay=float(delay), u_max=float(u_max),
                            saturated_fraction=float(np.mean(clipped)), stable=stable,
                            params=params)


def _multiple(value: float, h: float, what: str, *, allow_zero: bool = False) -> int:
    """``value / h`` as an integer (a ParameterError if it is not one)."""
    if value < 0 or (value == 0 and not allow_zero):
        raise ParameterError(f"{what} must be {'>= 0' if allow_zero else 'positive'}, "
                             f"got {value!r}")
    ratio = value / h
    steps = round(ratio)
    if abs(ratio - steps) > 1e-6 * max(1.0, ratio):
        raise ParameterError(f"{what} ({value} s) is not a multiple of the step {h} s")
    return int(steps)
