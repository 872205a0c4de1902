"""Physical limit of the seat: the best peak acceleration any bounded force could reach.

For a known road, every controller produces some force history ``u(t)`` with
``|u| <= u_max`` that keeps ``|x1| <= z_max``; the smallest peak ``|z3''|`` over all such
histories is therefore a lower bound for every controller (with any delay). With the force
held constant over steps of ``dt`` and the exact discretisation of the seat model, this is a
linear program::

    minimise  t
    s.t.      x_{k+1} = Phi x_k + Gu u_k + Gw0 w_k + Gw1 (w_{k+1} - w_k),  x_0 = 0
              -t <= C1 x_k <= t,  |x1_k| <= z_max,  |u_k| <= u_max      (k = 0..N)

solved by Clarabel through CVXPY. The horizon is the road's duration: give the road a tail
after the bump (``bump(t_end=3.0)``) so the motion has settled. Without a terminal
constraint the optimum is a true lower bound over the horizon; ``terminal_tol`` optionally
also asks for ``|x_N| <= terminal_tol`` (elementwise).

The optimal force is then re-simulated on a 10× finer grid by the ZOH/FOH propagator of
:mod:`lmi_suspension.seat.simulate` (an independent route from the LP's equality
constraints), which certifies the peak between the LP samples as well.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import cvxpy as cp
import numpy as np

from ..errors import InfeasibleError, ParameterError, SolverError
from ..lti.checks import positive_scalar
from .model import seat_matrices
from .params import SeatParameters
from .roads import RoadInput
from .simulate import SimulationResult, _discretise, simulate_force

__all__ = ["LimitResult", "bump_limit"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class LimitResult:
    """Result of :func:`bump_limit`.

    Attributes
    ----------
    peak : float
        LP optimum: smallest peak ``|z3''|`` at the LP samples, m/s².
    certified_peak : float
        Peak ``|z3''|`` of the re-simulated optimal force on the fine grid, m/s².
    certified_peak_x1 : float
        Peak ``|x1|`` of the re-simulation, m.
    certified_peak_u : float
        Peak ``|u|`` of the optimal force, N.
    t : ndarray
        LP time grid, s.
    force : ndarray
        Optimal force, held over ``[t_k, t_k + dt)``, N (sign as in eq. 1).
    z3dd, x1 : ndarray
        LP trajectories at the samples.
    dt : float
        LP step, s.
    u_max, z_max : float
        Limits used.
    status : str
        CVXPY status.
    solve_time : float
        Wall time of the solve (CVXPY compile + Clarabel), s.
    simulation : SimulationResult
        The re-simulation.
    """

    peak: float
    certified_peak: float
    certified_peak_x1: float
    certified_peak_u: float
    t: np.ndarray
    force: np.ndarray
    z3dd: np.ndarray
    x1: np.ndarray
    dt: float
    u_max: float
    z_max: float
    status: str
    solve_time: float
    simulation: SimulationResult = field(repr=False)


_CLARABEL_TOL = {"tol_gap_abs": 1e-9, "tol_gap_rel": 1e-9, "tol_feas": 1e-9,
                 "max_iter": 200}


def bump_limit(road: RoadInput, params: SeatParameters | None = None, *,
               u_max: float | None = None, z_max: float | None = None, dt: float = 2e-3,
               terminal_tol: float | None = None, refine: int = 10,
               solver_options: dict | None = None) -> LimitResult:
    """Smallest peak ``|z3''|`` reachable by any force ``|u| <= u_max`` keeping ``|x1| <= z_max``.

    Parameters
    ----------
    road : RoadInput
        Known floor excitation; its duration is the horizon (leave a settling tail).
    params : SeatParameters, optional
        Seat parameters and default limits.
    u_max, z_max : float, optional
        Force (N) and deflection (m) limits; ``params.u_max`` / ``params.z_max`` by default.
    dt : float
        LP step, s (2 ms: 1500 steps for a 3 s record, well under 10 s to solve).
    terminal_tol : float, optional
        If given, also require ``|x_N| <= terminal_tol`` elementwise (near rest at the end).
    refine : int
        The re-simulation uses steps of ``dt / refine``.
    solver_options : dict, optional
        Clarabel settings overriding the defaults (gap and feasibility tolerances 1e-9,
        at most 200 iterations).

    Returns
    -------
    LimitResult

    Raises
    ------
    InfeasibleError
        No admissible force keeps ``|x1| <= z_max`` (or reaches the terminal set).
    SolverError
        Clarabel did not return an optimal solution.

    Examples
    --------
    >>> from lmi_suspension.seat.roads import bump
    >>> from lmi_suspension.seat.limit import bump_limit
    >>> res = bump_limit(bump(t_end=1.5), dt=5e-3)
    >>> res.status, bool(res.peak <= res.certified_peak < 1.2 * res.peak)
    ('optimal', True)
    """
    if not isinstance(road, RoadInput):
        raise ParameterError(f"road must be a RoadInput, got {type(road).__name__}")
    p = SeatParameters() if params is None else params
    if not isinstance(p, SeatParameters):
        raise ParameterError(f"params must be a SeatParameters, got {type(p).__name__}")
    u_max = p.u_max if u_max is None else positive_scalar(u_max, "u_max")
    z_max = p.z_max if z_max is None else positive_scalar(z_max, "z_max")
    dt = positive_scalar(dt, "dt")
    if isinstance(refine, bool) or not isinstance(refine, (int, np.integer)) or refine < 1:
        raise ParameterError(f"refine must be a positive integer, got {refine!r}")
    if terminal_tol is not None:
        terminal_tol = positive_scalar(terminal_tol, "terminal_tol")

    t0, t1 = float(road.t[0]), float(road.t[-1])
    N = int(math.floor((t1 - t0) / dt + 1e-9))
    if N < 2:
        raise ParameterError(f"the road ({t1 - t0} s) must span at least two LP steps of {dt} s")
    if N > 20000:
        raise ParameterError(f"{N} LP steps is too many; increase dt")
    t = t0 + dt * np.arange(N + 1)
    w = np.interp(t, road.t, road.w)

    M = seat_matrices(p)
    Phi, Gu, Gw0, Gw1 = _discretise(M.A, M.B, M.Bw, dt)
    wc = np.outer(w[:-1], Gw0[:, 0]) + np.outer(np.diff(w), Gw1[:, 0])

    # Decision variables are scaled to O(1): v = u / u_max, states in natural units.
    x = cp.Variable((N + 1, 6))
    v = cp.Variable(N)
    peak = cp.Variable()
    z3dd = x @ M.C1.ravel()
    cons = [
        x[0] == 0,
        x[1:] == x[:-1] @ Phi.T + cp.reshape(v, (N, 1), order="C") @ (u_max * Gu.T) + wc,
        cp.abs(v) <= 1,
        cp.abs(x[:, 0]) <= z_max,
        cp.abs(z3dd) <= peak,
    ]
    if terminal_tol is not None:
        cons.append(cp.abs(x[N]) <= terminal_tol)
    prob = cp.Problem(cp.Minimize(peak), cons)
    opts = dict(_CLARABEL_TOL)
    if solver_options:
        opts.update(solver_options)
    start = time.perf_counter()
    try:
        prob.solve(solver=cp.CLARABEL, **opts)
    except cp.error.SolverError as exc:
        raise SolverError(f"Clarabel failed on the limit LP: {exc}", status=prob.status) from exc
    solve_time = time.perf_counter() - start
    status = prob.status
    if status in (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE):
        raise InfeasibleError(
            f"no force with |u| <= {u_max} N keeps |x1| <= {z_max} m on this road "
            f"(status {status})")
    if status != cp.OPTIMAL:
        raise SolverError(f"limit LP not solved to optimality (status {status})", status=status)

    force = u_max * np.asarray(v.value, dtype=float)
    force = np.clip(force, -u_max, u_max)  # remove solver round-off beyond the bound
    h = dt / refine
    fine = simulate_force(np.repeat(force, refine), road, dt=h, params=p)
    fine_end = min(fine.t.size, N * refine + 1)
    sim_z = fine.z3dd[:fine_end]
    sim_x1 = fine.x1[:fine_end]
    logger.info("limit LP: %d steps, peak %.4g m/s^2, solve %.2f s", N, prob.value, solve_time)
    return LimitResult(
        peak=float(prob.value), certified_peak=float(np.max(np.abs(sim_z))),
        certified_peak_x1=float(np.max(np.abs(sim_x1))),
        certified_peak_u=float(np.max(np.abs(force))), t=t, force=force,
        z3dd=np.asarray(z3dd.value, dtype=float), x1=np.asarray(x.value[:, 0], dtype=float),
        dt=dt, u_max=float(u_max), z_max=float(z_max), status=status, solve_time=solve_time,
        simulation=fine)


