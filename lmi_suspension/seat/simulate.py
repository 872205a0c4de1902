"""Time simulation of the seat suspension with an exact actuator delay and saturation.

The loop is ``y = [x1, x3] -> K -> u_command -> delay d -> saturation ±u_max -> u_applied``,
and ``u_applied`` acts on the seat as in eq. (1) (``-u`` on m1, ``B = [0, -1/m1, 0, ...]``).

Discretisation (fixed step ``h``):

* plant **and** controller states are propagated together by the exact matrix exponential
  of the continuous-time interconnection, so fast (stiff) controller poles are harmless;
* the floor velocity ``w`` is taken as piecewise linear between samples (first-order hold,
  exact for linear ``w``);
* the applied force is held constant over each step (zero-order hold) at the value
  ``sat(u_command(t_k - d))``; the delay is a delay line of ``d/h`` steps (an integer), so
  the delay is exact, not a Padé model. The hold adds an ``O(h)`` error only
  (``h <= 1e-4`` s by default).

Frequency-domain stability with the exact delay uses the Nyquist criterion on
``det(1 - L(s))``, ``L(s) = K(s) G_yu(s) e^{-s d}`` (a scalar: K is 1×2, G_yu is 2×1).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import control
import numpy as np
import scipy.linalg
from scipy.optimize import brentq

from ..errors import DimensionError, IterationLimitError, NonFiniteError, ParameterError
from ..lti.checks import as_statespace
from .comfort import comfort_metrics
from .model import SeatMatrices, seat_matrices
from .params import SeatParameters
from .roads import RoadInput

__all__ = ["SimulationMetrics", "SimulationResult", "simulate", "simulate_force",
           "loop_transfer", "closed_loop_stable", "stability_delay_margin",
           "MonteCarloResult", "monte_carlo"]

logger = logging.getLogger(__name__)

_DEFAULT_STEP = 1e-4


@dataclass(frozen=True)
class SimulationMetrics:
    """Figures of one simulation (all in SI units).

    Attributes
    ----------
    peak_z3dd, rms_z3dd : float
        Peak ``|z3''|`` and RMS of the upper-body acceleration, m/s².
    weighted_rms_z3dd : float
        ISO 2631-1 Wk-weighted RMS, m/s².
    vdv_z3dd : float
        Vibration dose value (Wk-weighted), m/s^1.75.
    peak_x1 : float
        Peak suspension deflection ``|x1|``, m.
    x1_within_limit : bool
        ``peak_x1 <= z_max``.
    z_max : float
        The deflection limit used, m.
    peak_u : float
        Peak applied force ``|u_applied|``, N.
    peak_u_command : float
        Peak commanded force ``|u_command|``, N (before the delay and the clipping: above
        ``u_max`` the actuator clips and the loop is not the linear one designed).
    saturation_time : float
        Time spent in saturation, s.
    stable : bool
        The simulation's divergence test passed.
    """

    peak_z3dd: float
    rms_z3dd: float
    weighted_rms_z3dd: float
    vdv_z3dd: float
    peak_x1: float
    x1_within_limit: bool
    z_max: float
    peak_u: float
    peak_u_command: float
    saturation_time: float
    stable: bool


@dataclass(frozen=True)
class SimulationResult:
    """Time histories of a seat simulation.

    Attributes
    ----------
    t : ndarray (N,)
        Time, s (the simulation grid; shorter than the road if the run diverged).
    x : ndarray (N, 6)
        Plant states ``x1 … x6``.
    xk : ndarray (N, nk)
        Controller states.
    z3dd, x1, x3 : ndarray (N,)
        Upper-body acceleration (m/s²), suspension and cushion deflections (m).
    u_command : ndarray (N,)
        Controller output before delay and saturation, N.
    u_applied : ndarray (N,)
        Delayed and saturated force, held over ``[t_k, t_k + h)``, N.
    delay : float
        Actuator delay, s.
    u_max : float
        Saturation level, N (``inf`` if disabled).
    saturated_fraction : float
        Fraction of the steps in which the applied force was clipped.
    stable : bool
        ``False`` if the plant states left ``divergence_bound`` (the run then stops early)
        or the state energy grew over the last window; a divergence test, not a proof.
    params : SeatParameters
        Parameters used (for the limits).
    """

    t: np.ndarray
    x: np.ndarray
    xk: np.ndarray
    z3dd: np.ndarray
    x1: np.ndarray
    x3: np.ndarray
    u_command: np.ndarray
    u_applied: np.ndarray
    delay: float
    u_max: float
    saturated_fraction: float
    stable: bool
    params: SeatParameters = field(repr=False)

    @property
    def dt(self) -> float:
        """Simulation step ``h``, s."""
        return float(self.t[1] - self.t[0])

    def metrics(self) -> SimulationMetrics:
        """Comfort, deflection and force figures of the run (see :class:`SimulationMetrics`).

        Examples
        --------
        >>> from lmi_suspension.seat.roads import bump
        >>> from lmi_suspension.seat.simulate import simulate
        >>> m = simulate(None, bump(t_end=2.0)).metrics()
        >>> m.x1_within_limit, m.peak_u
        (True, 0.0)
        """
        comfort = comfort_metrics(self.t, self.z3dd)  # filters through Wk once
        z_max = self.params.z_max
        peak_x1 = float(np.max(np.abs(self.x1)))
        return SimulationMetrics(
            peak_z3dd=comfort.peak,
            rms_z3dd=comfort.rms,
            weighted_rms_z3dd=comfort.weighted_rms,
            vdv_z3dd=comfort.vdv,
            peak_x1=peak_x1,
            x1_within_limit=bool(peak_x1 <= z_max),
            z_max=z_max,
            peak_u=float(np.max(np.abs(self.u_applied))),
            peak_u_command=float(np.max(np.abs(self.u_command))),
            saturation_time=float(self.saturated_fraction * (self.t[-1] - self.t[0])),
            stable=self.stable,
        )


# ----------------------------------------------------------------------------- helpers

def _params(params) -> SeatParameters:
    if params is None:
        return SeatParameters()
    if not isinstance(params, SeatParameters):
        raise ParameterError(f"params must be a SeatParameters, got {type(params).__name__}")
    return params


def _plant(plant, params: SeatParameters) -> SeatMatrices:
    if plant is None:
        return seat_matrices(params)
    if not isinstance(plant, SeatMatrices):
        raise ParameterError(f"plant must be a SeatMatrices, got {type(plant).__name__}")
    for name in ("A", "B", "Bw", "C1", "C2", "C3"):
        if not np.all(np.isfinite(getattr(plant, name))):
            raise NonFiniteError(f"plant.{name} contains NaN or infinite entries")
    return plant


def _controller(controller) -> control.StateSpace | None:
    if controller is None:
        return None
    K = as_statespace(controller, "controller")
    if K.ninputs != 2 or K.noutputs != 1:
        raise DimensionError(
            "controller must map y = [x1, x3] (2 inputs) to u (1 output); "
            f"got {K.ninputs} inputs and {K.noutputs} outputs")
    return K


def _scalar(value, name: str, *, allow_inf: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ParameterError(f"{name} must be a real number, got {value!r}")
    value = float(value)
    if math.isnan(value) or (math.isinf(value) and not allow_inf):
        raise NonFiniteError(f"{name} must be finite, got {value!r}")
    return value


def _step_and_delay(delay: float, dt: float | None) -> tuple[float, int]:
    """The step ``h`` and the delay in steps; ``delay / h`` must be an integer."""
    if delay < 0:
        raise ParameterError(f"delay must be >= 0 s, got {delay!r}")
    if dt is None:
        if delay == 0:
            return _DEFAULT_STEP, 0
        steps = math.ceil(delay / _DEFAULT_STEP - 1e-9)
        return delay / steps, steps
    h = _scalar(dt, "dt")
    if h <= 0:
        raise ParameterError(f"dt must be positive, got {dt!r}")
    ratio = delay / h
    steps = round(ratio)
    if abs(ratio - steps) > 1e-6 * max(1.0, ratio):
        raise ParameterError(
            f"delay {delay} s is not an integer number of steps dt={h} s (ratio {ratio:.6g})")
    return h, int(steps)


def _discretise(A: np.ndarray, Bu: np.ndarray, Bw: np.ndarray, h: float):
    """Exact ZOH (for ``Bu``) and FOH (for ``Bw``) discretisation by one block exponential.

    Returns ``Phi, Gu, Gw0, Gw1`` with
    ``x_{k+1} = Phi x_k + Gu u_k + Gw0 w_k + Gw1 (w_{k+1} - w_k)``.
    """
    n, nu, nw = A.shape[0], Bu.shape[1], Bw.shape[1]
    size = n + nu + 2 * nw
    M = np.zeros((size, size))
    M[:n, :n] = A * h
    M[:n, n:n + nu] = Bu * h
    M[:n, n + nu:n + nu + nw] = Bw * h
    M[n + nu:n + nu + nw, n + nu + nw:] = np.eye(nw)
    E = scipy.linalg.expm(M)
    return (E[:n, :n], E[:n, n:n + nu], E[:n, n + nu:n + nu + nw], E[:n, n + nu + nw:])


def _road_on_grid(road: RoadInput, h: float):
    if not isinstance(road, RoadInput):
        raise ParameterError(f"road must be a RoadInput, got {type(road).__name__}")
    t0, t1 = float(road.t[0]), float(road.t[-1])
    n = int(math.floor((t1 - t0) / h + 1e-9)) + 1
    if n < 2:
        raise ParameterError(f"road ({t1 - t0} s) is shorter than one step ({h} s)")
    if n > 20_000_000:
        raise ParameterError(f"{n} simulation steps is too many; increase dt")
    t = t0 + h * np.arange(n)
    return t, np.interp(t, road.t, road.w)  # linear interpolation = the FOH reading of w


def _energy_growing(x: np.ndarray, window: int, factor: float) -> bool:
    """Did the plant-state energy grow by more than ``factor`` from one window to the next?"""
    if window < 10 or x.shape[0] < 2 * window:
        return False
    last = float(np.sum(x[-window:] ** 2))
    prev = float(np.sum(x[-2 * window:-window] ** 2))
    return bool(last > factor * prev and last > 1e-24 * window)


# ----------------------------------------------------------------------------- simulation

def _run(M: SeatMatrices, K, road: RoadInput, *, h: float, delay_steps: int, u_max: float,
         force=None, divergence_bound: float, growth_factor: float):
    """Shared propagation kernel of :func:`simulate` and :func:`simulate_force`."""
    t, w = _road_on_grid(road, h)
    N = t.size
    n = M.A.shape[0]
    if K is None:
        Ak = np.zeros((0, 0))
        Bk = np.zeros((0, 2))
        Ck = np.zeros((1, 0))
        Dk = np.zeros((1, 2))
    else:
        Ak, Bk, Ck, Dk = (np.asarray(m, dtype=float) for m in (K.A, K.B, K.C, K.D))
    nk = Ak.shape[0]
    C3 = M.C3
    Acl = np.block([[M.A, np.zeros((n, nk))], [Bk @ C3, Ak]])
    Bu = np.vstack([M.B, np.zeros((nk, 1))])
    Bw = np.vstack([M.Bw, np.zeros((nk, 1))])
    Phi, Gu, Gw0, Gw1 = _discretise(Acl, Bu, Bw, h)
    gu = Gu[:, 0]
    # The floor's contribution to every step does not depend on the loop: compute it at once.
    wc = np.outer(w[:-1], Gw0[:, 0]) + np.outer(np.diff(w), Gw1[:, 0])
    Ky = (Dk @ C3).ravel()
    ck = Ck.ravel()
    xi = np.zeros((N, n + nk))
    u_cmd = np.zeros(N)
    u_app = np.zeros(N)
    clipped = np.zeros(N, dtype=bool)
    state = np.zeros(n + nk)
    stable = True
    last = N - 1
    check_every = 200
    for k in range(N):
        xi[k] = state
        if force is None:
            u_cmd[k] = Ky @ state[:n] + ck @ state[n:]
            # Commands issued before t0 are zero (the loop starts at rest).
            raw = u_cmd[k - delay_steps] if k >= delay_steps else 0.0
        else:
            raw = force[k]
            u_cmd[k] = raw
        ua = min(max(raw, -u_max), u_max)
        clipped[k] = ua != raw
        u_app[k] = ua
        if k == N - 1:
            break
        state = Phi @ state + gu * ua + wc[k]
        if k % check_every == 0 and not np.all(np.abs(state[:n]) < divergence_bound):
            stable = False
            last = k + 1
            logger.info("simulation diverged at t = %.4g s; stopped early", t[last])
            xi[last] = state
            break
    if not stable:
        sl = slice(0, last + 1)
        t, xi, u_cmd, u_app, clipped = t[sl], xi[sl], u_cmd[sl], u_app[sl], clipped[sl]
        with np.errstate(over="ignore", invalid="ignore"):
            u_cmd[-1] = Ky @ xi[-1, :n] + ck @ xi[-1, n:]
    elif growth_factor is not None:
        window = max(int(0.2 * N), 1)
        stable = not _energy_growing(xi[:, :n], window, growth_factor)
    x = xi[:, :n]
    return t, x, xi[:, n:], u_cmd, u_app, clipped, stable


def simulate(controller, road: RoadInput, *, delay: float = 0.0,
             params: SeatParameters | None = None, u_max: float | None = None,
             dt: float | None = None, plant: SeatMatrices | None = None,
             divergence_bound: float = 1e2, growth_factor: float | None = 4.0
             ) -> SimulationResult:
    """Simulate the seat under ``road`` with controller ``K``, exact delay and saturation.

    Parameters
    ----------
    controller : control.StateSpace or None
        Continuous-time controller from ``y = [x1, x3]`` (m) to ``u`` (N), sign as in
        eq. (1); a transfer function or a 1×2 static gain also works. ``None``: passive.
    road : RoadInput
        Floor excitation; ``w`` is read as piecewise linear between its samples and
        resampled on the simulation grid (keep ``dt`` at or below the road's sample period).
    delay : float
        Actuator delay ``d >= 0``, s; must be an integer number of steps.
    params : SeatParameters, optional
        Parameters (Table 1 by default); also gives ``u_max`` and ``z_max``.
    u_max : float, optional
        Saturation level, N (``params.u_max`` by default; ``numpy.inf`` disables it).
    dt : float, optional
        Step ``h``, s. By default ``h <= 1e-4`` s, chosen so that ``delay / h`` is an integer.
    plant : SeatMatrices, optional
        Use these matrices instead of ``seat_matrices(params)`` (e.g. a perturbed model).
    divergence_bound : float
        The run stops with ``stable=False`` once a plant state exceeds this (m or m/s).
    growth_factor : float or None
        ``stable=False`` also if the plant-state energy of the last 20 % of the run exceeds
        ``growth_factor`` times that of the 20 % before; ``None`` skips that test.

    Returns
    -------
    SimulationResult

    Raises
    ------
    ParameterError
        Negative delay, delay not a multiple of ``dt``, bad ``u_max`` or ``dt``.
    DiscreteTimeError, DimensionError, NonFiniteError
        Discrete-time controller, wrong controller size, NaN data.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.roads import bump
    >>> from lmi_suspension.seat.simulate import simulate
    >>> res = simulate(np.array([[20000.0, 0.0]]), bump(t_end=2.0), delay=0.01)
    >>> res.stable, res.dt
    (True, 0.0001)
    >>> bool(np.allclose(res.u_applied[100:], np.clip(res.u_command[:-100], -1500, 1500)))
    True
    """
    p = _params(params)
    M = _plant(plant, p)
    K = _controller(controller)
    delay = _scalar(delay, "delay")
    h, delay_steps = _step_and_delay(delay, dt)
    u_max = p.u_max if u_max is None else _scalar(u_max, "u_max", allow_inf=True)
    if u_max <= 0:
        raise ParameterError(f"u_max must be positive, got {u_max!r}")
    divergence_bound = _scalar(divergence_bound, "divergence_bound")
    if growth_factor is not None:
        growth_factor = _scalar(growth_factor, "growth_factor")
    t, x, xk, u_cmd, u_app, clipped, stable = _run(
        M, K, road, h=h, delay_steps=delay_steps, u_max=u_max,
        divergence_bound=divergence_bound, growth_factor=growth_factor)
    return SimulationResult(
        t=t, x=x, xk=xk, z3dd=x @ M.C1.ravel(), x1=x @ M.C2.ravel(), x3=x @ M.C3[1],
        u_command=u_cmd, u_applied=u_app, delay=delay, u_max=u_max,
        saturated_fraction=float(np.mean(clipped)), stable=stable, params=p)


def simulate_force(force, road: RoadInput, *, dt: float, params: SeatParameters | None = None,
                   plant: SeatMatrices | None = None, u_max: float = np.inf) -> SimulationResult:
    """Open-loop simulation with a prescribed force ``u`` held constant over each step.

    Parameters
    ----------
    force : array_like
        Force samples ``u_k`` on the simulation grid ``t0 + k dt`` (N), one per step of
        the road's duration (missing tail samples are zero).
    road : RoadInput
        Floor excitation.
    dt : float
        Simulation step, s.
    u_max : float
        Saturation (none by default).

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.roads import bump
    >>> from lmi_suspension.seat.simulate import simulate, simulate_force
    >>> r = bump(t_end=1.0)
    >>> a = simulate_force(np.zeros(10001), r, dt=1e-4)
    >>> bool(np.allclose(a.z3dd, simulate(None, r, dt=1e-4).z3dd))
    True
    """
    p = _params(params)
    M = _plant(plant, p)
    h, _ = _step_and_delay(0.0, dt)
    n_grid = _road_on_grid(road, h)[0].size
    f = np.zeros(n_grid)
    force = np.asarray(force, dtype=float).ravel()
    if not np.all(np.isfinite(force)):
        raise NonFiniteError("force contains NaN or infinite entries")
    if force.size > n_grid:
        raise DimensionError(f"force has {force.size} samples, the grid only {n_grid}")
    f[:force.size] = force
    t, x, xk, u_cmd, u_app, clipped, _ = _run(
        M, None, road, h=h, delay_steps=0, u_max=float(u_max), force=f,
        divergence_bound=np.inf, growth_factor=None)
    return SimulationResult(
        t=t, x=x, xk=xk, z3dd=x @ M.C1.ravel(), x1=x @ M.C2.ravel(), x3=x @ M.C3[1],
        u_command=u_cmd, u_applied=u_app, delay=0.0, u_max=float(u_max),
        saturated_fraction=float(np.mean(clipped)), stable=True, params=p)


# ----------------------------------------------------------------------------- stability

def loop_transfer(controller, params: SeatParameters | None = None,
                  plant: SeatMatrices | None = None) -> control.StateSpace:
    """The delay-free loop ``L0(s) = K(s) G_yu(s)`` (SISO), broken at the force.

    With the delay the loop is ``L(s) = L0(s) e^{-s d}`` and, since ``u_command = K y`` is
    fed back without sign change, closed-loop poles are the roots of ``1 - L(s) = 0``.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.simulate import loop_transfer
    >>> L0 = loop_transfer(np.array([[1000.0, 0.0]]))
    >>> L0.ninputs, L0.noutputs, L0.nstates
    (1, 1, 6)
    """
    p = _params(params)
    M = _plant(plant, p)
    K = _controller(controller)
    if K is None:
        raise ParameterError("the passive seat (controller=None) has no loop")
    G_yu = control.ss(M.A, M.B, M.C3, np.zeros((2, 1)))
    return control.series(G_yu, K)


def _freq_resp(L0: control.StateSpace, s: np.ndarray) -> np.ndarray:
    """``L0(s)`` at many points via one eigen-decomposition (A is small and diagonalisable
    generically; falls back to direct solves when it is not)."""
    A, B, C, D = (np.asarray(m, dtype=float) for m in (L0.A, L0.B, L0.C, L0.D))
    if A.shape[0] == 0:
        return np.full(s.shape, D[0, 0], dtype=complex)
    lam, V = np.linalg.eig(A)
    if np.linalg.cond(V) < 1e8:
        cb = (C @ V).ravel() * np.linalg.solve(V, B).ravel()
        return D[0, 0] + (cb[None, :] / (s[:, None] - lam[None, :])).sum(axis=1)
    eye = np.eye(A.shape[0])
    return np.array([D[0, 0] + (C @ np.linalg.solve(si * eye - A, B))[0, 0] for si in s])


def _nyquist_count(L0: control.StateSpace, delay: float, *, max_rounds: int = 40,
                   max_points: int = 400_000) -> tuple[int, float]:
    """Number of closed-loop RHP roots of ``1 - L0(s) e^{-sd}`` and ``min |1 - L|``."""
    A = np.asarray(L0.A, dtype=float)
    poles = np.linalg.eigvals(A) if A.shape[0] else np.zeros(0)
    scale = max([1.0] + [abs(p) for p in poles])
    on_axis = np.abs(poles.real) <= 1e-9 * np.maximum(1.0, np.abs(poles))
    # Open-loop poles on the axis: move the contour a hair to the right of them.
    sigma = 1e-7 * scale if np.any(on_axis) else 0.0
    P = int(np.sum(poles.real > sigma))

    def F(omega):
        s = sigma + 1j * omega
        return 1.0 - _freq_resp(L0, s) * np.exp(-s * delay)

    w_hi = 1e3 * scale
    for _ in range(30):
        if np.abs(_freq_resp(L0, np.array([1j * w_hi])))[0] < 1e-3:
            break
        w_hi *= 4.0
    else:
        raise IterationLimitError("loop gain does not roll off; is the controller proper?")
    nonzero = np.abs(poles[np.abs(poles) > 0])
    w_lo = 1e-4 * (nonzero.min() if nonzero.size else 1.0)
    extra = np.abs(poles.imag[(poles.imag > w_lo) & (poles.imag < w_hi)])
    omega = np.unique(np.concatenate([[0.0], np.geomspace(w_lo, w_hi, 4000), extra]))
    values = F(omega)
    for _ in range(max_rounds):
        step = np.abs(np.angle(values[1:] / values[:-1]))
        bad = np.nonzero(step > 0.2)[0]
        if bad.size == 0:
            break
        if omega.size + bad.size > max_points:
            raise IterationLimitError("Nyquist grid refinement did not converge")
        mid = 0.5 * (omega[bad] + omega[bad + 1])
        omega = np.concatenate([omega, mid])
        order = np.argsort(omega)
        omega = omega[order]
        values = np.concatenate([values, F(mid)])[order]
    else:
        raise IterationLimitError("Nyquist grid refinement did not converge")
    dphase = float(np.sum(np.angle(values[1:] / values[:-1])))
    # Beyond w_hi, |L| < 1e-3 so 1 - L stays near 1: no further phase change to count.
    Z = P - dphase / math.pi
    return int(round(Z)), float(np.min(np.abs(values)))


def closed_loop_stable(controller, delay: float = 0.0, params: SeatParameters | None = None,
                       *, plant: SeatMatrices | None = None) -> bool:
    """Stability of the linear loop with the exact delay ``e^{-sd}`` (no saturation).

    Nyquist criterion for ``1 - L0(s) e^{-sd}``: with ``P`` open-loop poles of the loop's
    realisation in the right half-plane and ``N`` the clockwise encirclements of the origin
    by ``1 - L(jw)``, the closed loop has ``Z = P + N`` right-half-plane roots. The
    frequency grid is refined adaptively until the phase of ``1 - L`` moves by less than
    0.2 rad between neighbouring points (bounded number of rounds).

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.simulate import closed_loop_stable
    >>> closed_loop_stable(np.array([[1000.0, 0.0]]), 0.01)
    True
    """
    delay = _scalar(delay, "delay")
    if delay < 0:
        raise ParameterError(f"delay must be >= 0 s, got {delay!r}")
    L0 = loop_transfer(controller, params, plant)
    Z, fmin = _nyquist_count(L0, delay)
    if fmin < 1e-9:
        return False  # a closed-loop root on the imaginary axis: not asymptotically stable
    return Z == 0


def stability_delay_margin(controller, params: SeatParameters | None = None, *,
                           d_max: float = 1.0, plant: SeatMatrices | None = None,
                           n_grid: int = 20000) -> float:
    """Smallest actuator delay at which the closed loop loses stability, s.

    Roots of ``1 - L0(s) e^{-sd}`` can only cross the imaginary axis at ``s = jw`` with
    ``|L0(jw)| = 1`` and ``w d = arg L0(jw) (mod 2 pi)``. The crossover frequencies are
    bracketed on a dense logarithmic grid and refined by Brent's method; the margin is the
    smallest ``d = (arg L0(jw) mod 2 pi) / w``.

    Returns
    -------
    float
        0.0 if the loop is unstable without delay, ``inf`` if no crossing below ``d_max``.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.simulate import stability_delay_margin
    >>> K = np.array([[60000.0, 0.0]])   # a stiff spring in parallel with k1
    >>> bool(0 < stability_delay_margin(K) < 0.1)
    True
    """
    d_max = _scalar(d_max, "d_max")
    if d_max <= 0:
        raise ParameterError(f"d_max must be positive, got {d_max!r}")
    if not closed_loop_stable(controller, 0.0, params, plant=plant):
        return 0.0
    L0 = loop_transfer(controller, params, plant)
    A = np.asarray(L0.A, dtype=float)
    poles = np.linalg.eigvals(A) if A.shape[0] else np.zeros(0)
    scale = max([1.0] + [abs(p) for p in poles])
    w_hi = 1e3 * scale
    for _ in range(30):
        if abs(_freq_resp(L0, np.array([1j * w_hi]))[0]) < 1e-2:
            break
        w_hi *= 4.0
    nonzero = np.abs(poles[np.abs(poles) > 0])
    w_lo = 1e-4 * (nonzero.min() if nonzero.size else 1.0)
    omega = np.geomspace(w_lo, w_hi, n_grid)
    with np.errstate(divide="ignore"):   # a zero loop (no controller): -inf, no crossing
        gain = np.log(np.abs(_freq_resp(L0, 1j * omega)))
    margin = math.inf
    idx = np.nonzero(np.sign(gain[1:]) != np.sign(gain[:-1]))[0]
    def log_gain(w):
        return math.log(abs(_freq_resp(L0, np.array([1j * w]))[0]))

    for i in idx:
        wc = brentq(log_gain, omega[i], omega[i + 1], xtol=1e-12, rtol=1e-12, maxiter=200)
        phase = float(np.angle(_freq_resp(L0, np.array([1j * wc]))[0]))
        d = (phase % (2 * math.pi)) / wc
        margin = min(margin, d)
    return margin if margin <= d_max else math.inf


# ----------------------------------------------------------------------------- Monte Carlo

@dataclass(frozen=True)
class MonteCarloResult:
    """Per-sample results of :func:`monte_carlo`.

    Attributes
    ----------
    params : tuple of SeatParameters
        The sampled parameter sets.
    delays : ndarray
        The delay of each sample, s.
    metrics : tuple of SimulationMetrics
        One per sample.
    worst_index : int
        Sample with the largest peak ``|z3''|`` (an unstable sample counts as worst).
    """

    params: tuple
    delays: np.ndarray
    metrics: tuple
    worst_index: int

    @property
    def worst(self) -> SimulationMetrics:
        """Metrics of the worst sample."""
        return self.metrics[self.worst_index]

    @property
    def peak_z3dd(self) -> np.ndarray:
        """Peak ``|z3''|`` of every sample, m/s²."""
        return np.array([m.peak_z3dd for m in self.metrics])


def monte_carlo(controller, road: RoadInput, *, n: int = 20, rng: np.random.Generator,
                delay=0.0, m3_range=(30.0, 70.0), stiffness_rel: float = 0.2,
                params: SeatParameters | None = None, u_max: float | None = None,
                dt: float | None = None) -> MonteCarloResult:
    """Simulations over random occupants and stiffnesses.

    Each sample draws ``m3 ~ U(m3_range)`` and scales ``k1, k2, k3`` independently by
    ``U(1 - stiffness_rel, 1 + stiffness_rel)``; ``delay`` is a fixed value or a
    ``(d_lo, d_hi)`` range sampled uniformly (rounded to the step grid of ``dt`` when
    ``dt`` is given).

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.roads import bump
    >>> from lmi_suspension.seat.simulate import monte_carlo
    >>> mc = monte_carlo(None, bump(t_end=1.0), n=2, rng=np.random.default_rng(0))
    >>> len(mc.metrics), bool(mc.worst.peak_z3dd == mc.peak_z3dd.max())
    (2, True)
    """
    if not isinstance(rng, np.random.Generator):
        raise ParameterError("rng must be a numpy.random.Generator")
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ParameterError(f"n must be a positive integer, got {n!r}")
    base = _params(params)
    lo, hi = (_scalar(v, "m3_range") for v in m3_range)
    if not 0 < lo <= hi:
        raise ParameterError(f"m3_range must be increasing and positive, got {m3_range!r}")
    rel = _scalar(stiffness_rel, "stiffness_rel")
    if not 0 <= rel < 1:
        raise ParameterError(f"stiffness_rel must be in [0, 1), got {stiffness_rel!r}")
    if np.ndim(delay) == 0:
        d_lo = d_hi = _scalar(delay, "delay")
    else:
        d_lo, d_hi = (_scalar(v, "delay") for v in delay)
    if d_lo < 0 or d_hi < d_lo:
        raise ParameterError(f"delay must be >= 0 (and an increasing range), got {delay!r}")
    samples, delays, metrics = [], [], []
    fields_ = {f: getattr(base, f) for f in base.__dataclass_fields__}
    for _ in range(n):
        draw = dict(fields_)
        draw["m3"] = float(rng.uniform(lo, hi))
        for k in ("k1", "k2", "k3"):
            draw[k] = float(fields_[k] * rng.uniform(1 - rel, 1 + rel))
        p = SeatParameters(**draw)
        d = float(rng.uniform(d_lo, d_hi)) if d_hi > d_lo else d_lo
        if dt is not None:
            d = round(d / dt) * dt
        res = simulate(controller, road, delay=d, params=p, u_max=u_max, dt=dt)
        samples.append(p)
        delays.append(d)
        metrics.append(res.metrics())
    score = [m.peak_z3dd if m.stable else math.inf for m in metrics]
    return MonteCarloResult(params=tuple(samples), delays=np.array(delays),
                            metrics=tuple(metrics), worst_index=int(np.argmax(score)))
