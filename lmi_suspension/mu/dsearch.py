"""Direct search on the D-scale parameters with the K-step in the loop.

D-K iteration alternates two partial minimisations of the same bound and stops where
neither step alone improves it; on Skogestad & Postlethwaite's distillation problem that
is at µ ≈ 1.003, while the book's µ-optimal scalings give 0.974 (measured: along the
log-linear path from the D-K scalings to those, the K-step's γ falls steadily).  This
stage minimises what D-K minimises alternately, ``γ(θ) = min_K ‖D_θ F_l(P, K) D_θ⁻¹‖∞``,
over the parameters ``θ`` of the rational fits themselves (poles, zeros and gain of each
scaling, in the stable minimum-phase parametrisation of :mod:`.dfit`).

The function searched is the level a Riccati synthesis achieves on the scaled plant, not
the certified norm of its controller: the level is a reproducible function of ``θ``,
while near the optimum the controllers are ill-conditioned and their certified norms
carry rounding noise.  The level is piecewise smooth in ``θ`` (a maximum of smooth
conditions), so the search is a descent method for such functions: BFGS on
forward-difference gradients with a weak Wolfe line search (Lewis & Overton, "Nonsmooth
optimization via quasi-Newton methods", Math. Programming 141, 2013), and where the line
search fails at a kink, a step along the least-norm convex combination of the gradients
sampled near the point (as in gradient sampling).  It stops where that combination
vanishes, at a local minimum, which small perturbations of the path (another OpenBLAS
kernel) mostly lead back to; not always, as the level has more than one (on 51- and
71-point distillation grids two kernels ended 0.2 % and 0.5 % apart).  Nelder-Mead,
which this replaced, never got there: its
end point was a chaotic function of its path (µ 0.965-0.976 over four OpenBLAS kernels
and 1 and 2 threads; this search: levels 0.95917-0.95924 from the same starts, measured
2026-11-26).  Every point the search accepts is checked: a controller designed just
above its level must certify within 1 % of it (elsewhere SLICOT's level can be far
below what any controller achieves).  The controller of the best point is certified at
the end, so the controller returned has ``µ <= γ`` at every frequency, ``γ`` its
certified norm.
"""

from __future__ import annotations

import logging
import time
import warnings
from dataclasses import dataclass, field

import control
import numpy as np
import scipy.optimize

from ..errors import LmiSuspensionError
from ..lti.norms import hinfnorm
from ..lti.plant import lft
from .dfit import DScaleFit, _canonical, _fit_sequence, _to_statespace, scaled_plant

__all__ = ["DScaleSearchResult", "search_dscales"]

logger = logging.getLogger(__name__)

#: blocks whose optimal scalings agree this closely share one fit, at every frequency
#: but a fraction ``_TIE_OUTLIERS`` of the grid: where µ's scalings are not unique the
#: fast bound's minimiser can stop at other ones at a frequency or two.  On dkpy's
#: realization of the distillation plant the first iterate's scalings of the two
#: input blocks agreed to 1e-10 at 60 of the 61 frequencies and differed by 1.4 % at
#: 0.95 rad/s (1e-7 everywhere on the project's realization): searched apart, the two
#: blocks doubled the cost of a gradient, and after the 200 points of the default
#: search the level was 0.96497 against 0.95925 searched together (default ``musyn``,
#: measured 2026-12-02, benchmarks/musyn_vs_dkpy.py)
_TIE_RTOL = 1e-3
_TIE_OUTLIERS = 0.05
#: forward-difference step in the log-parameters, and the relative width of the level's
#: bisection (its noise must stay well below the step's change of the level).  With a
#: step of 1e-4 and the level to 1e-8, two OpenBLAS kernels (Haswell, Sandybridge)
#: ended one start's search 7.7e-4 apart; with 1e-3 and 1e-7, at the same point to
#: all digits, and 20 % faster (distillation, measured 2026-11-26).  The level to 4e-7
#: with the difference quotients' brackets ±4e-4 (below): 11 halvings per quotient instead
#: of 15, two fewer per trial point.  Default ``musyn`` on dkpy's and the
#: project's realization of distillation, native (SkylakeX) and Sandybridge kernels: the
#: search's syntheses 2118 -> 1786, 2257 -> 1958, 2061 -> 1752, 2237 -> 2372 (a longer
#: search), µ 0.958778 -> 0.958751, 0.959508 -> 0.959402, 0.959361 -> 0.958973,
#: 0.959548 -> 0.958286 (measured 2026-12-02)
_FD_STEP = 1e-3
_LEVEL_RTOL = 4e-7
#: half-widths (relative) of the brackets the level is bisected from: around the
#: point's own level for a difference quotient, around the current one for a trial step.
#: A difference quotient moved the level by at most 6e-4 (2026-11-28); 4e-4 is the
#: widest half-width bisected to ``_LEVEL_RTOL`` in 11 halvings, and a quotient outside
#: it costs a widening (:func:`~lmi_suspension.synthesis.hinfsyn.riccati_level`)
_FD_BRACKET = 4e-4
_TRIAL_BRACKET = 3e-2
#: line search: sufficient decrease and weak curvature (Lewis & Overton's 1e-4, 0.9),
#: and a bound on its trial steps
_ARMIJO = 1e-4
_WOLFE = 0.9
_TRIALS = 20
#: gradients sampled within this distance (log-parameters) of a kink define the descent
#: direction there; below this norm of their least-norm combination the point counts as
#: stationary
_SAMPLE_RADIUS = 0.05
_STATIONARY = 1e-3
#: a trial point is accepted only if SLICOT's controller at 1e-3 above its level
#: certifies within this (relative) of the level: without the check, a search on
#: distillation ran on one kernel into scalings with levels 0.68-0.72 whose controllers
#: certify far above (measured 2026-11-26)
_CHECK_RTOL = 1e-2
#: the search ends once its best level has not fallen by ``_STALL_RTOL`` (relative) over
#: the points of ``_STALL_STEPS`` gradients (a difference quotient per parameter and a
#: trial point each): near its end it creeps.  Default ``musyn`` on distillation: the
#: level reached 0.959440 at point 117 and 0.959249 at the bound of 200 (0.02 % lower,
#: 6 s), from dkpy's realization 0.959212 at point 127 and 0.958984 at 200 (measured
#: 2026-12-02, benchmarks/musyn_vs_dkpy.py).  With three gradients (30 points here) the
#: search ends at point 157 from dkpy's realization, level 0.959188 (µ 0.959476 for the
#: returned loop; 0.959272 after the 200 points), and at point 168 from the project's,
#: level 0.959294 (µ 0.959582, as after the 200); with two, at point 137 there, level
#: 0.959440 (µ 0.959728), at 0.4 s less CPU (17.1 s against 17.5 s)
_STALL_RTOL = 1e-4
_STALL_STEPS = 3
#: what a point's synthesis may raise (slycot raises plain ValueError/ArithmeticError)
_FAILED_POINT = (LmiSuspensionError, ValueError, ArithmeticError, np.linalg.LinAlgError)


@dataclass(frozen=True)
class DScaleSearchResult:
    """Outcome of :func:`search_dscales`.

    Attributes
    ----------
    K : control.StateSpace
        Controller of the best scalings found.
    gamma : float
        Its certified norm on the scaled plant (an upper bound of µ at every frequency).
    level : float
        The searched level at the best scalings.
    level_start : float
        The same at the starting scalings.
    dfit : DScaleFit
        The best scalings.
    evaluations : int
        Points evaluated, besides the final controller: a level each (one bisection of
        the K-step's synthesis), except a line-search trial found above the current
        level by ``achieves``, which costs one synthesis.
    seconds : float
        Wall time.
    PD : control.StateSpace or None
        The scaled plant of the best scalings, on which ``gamma`` is certified.
    """

    K: control.StateSpace
    gamma: float
    level: float
    level_start: float
    dfit: DScaleFit
    evaluations: int
    seconds: float
    PD: control.StateSpace | None = field(default=None, repr=False, compare=False)


def _equal_scalings(d_blocks: np.ndarray, free: list[int], rtol: float = _TIE_RTOL
                    ) -> list[list[int]]:
    """Free blocks grouped by equal optimal scalings (within ``rtol`` at every frequency
    but a fraction ``_TIE_OUTLIERS`` of them); each group is searched as one function."""
    groups: list[list[int]] = []
    n_freq = d_blocks.shape[1]
    for i in free:
        for g in groups:
            off = ~np.isclose(d_blocks[i], d_blocks[g[0]], rtol=rtol, atol=0.0)
            if np.count_nonzero(off) <= _TIE_OUTLIERS * n_freq:
                g.append(i)
                break
        else:
            groups.append([i])
    return groups


class _Stop(Exception):
    """The target level is reached, or the bound on levels: end the search."""


def _least_norm(gradients: np.ndarray) -> np.ndarray:
    """The least-norm point of the convex hull of ``gradients`` (rows): non-negative
    least squares with the weights' sum as one more, heavily weighted, equation."""
    k, n = gradients.shape
    heavy = 1e3 * max(1.0, float(np.max(np.abs(gradients))))
    A = np.vstack([gradients.T, np.full((1, k), heavy)])
    weights, _ = scipy.optimize.nnls(A, np.concatenate([np.zeros(n), [heavy]]))
    return gradients.T @ (weights / np.sum(weights))


def search_dscales(P, nmeas: int, ncon: int, block_sizes, omega, d_blocks, weights,
                   order: int, level, controller, *, check=None, achieves=None,
                   max_evals: int = 300, target: float = 0.0) -> DScaleSearchResult | None:
    """Minimise the level an H∞ synthesis achieves over the parameters of the D-scale
    fits; return the best point's controller, certified.

    Parameters
    ----------
    P : control.StateSpace
        Generalized plant.
    nmeas, ncon : int
        Partition.
    block_sizes : sequence of (int, int)
        ``(r_i, c_i)`` of each Δ block.
    omega : ndarray
        Frequencies of ``d_blocks`` (rad/s).
    d_blocks : ndarray, shape (n_blocks, n_freq)
        Scalar D magnitudes per block (the starting point, fitted at ``order``); a block
        equal to 1 everywhere (the normalised one) stays 1.
    weights : ndarray or None
        Weights of the starting fit (None: uniform).
    order : int
        Order of every searched scaling (>= 1).
    level : callable
        ``level(PD, bracket, rtol) -> float``: the level an H∞ synthesis achieves on
        the scaled plant to relative accuracy ``rtol`` (the function searched; it should
        be reproducible, see the module's notes), ``bracket`` a ``(lo, hi)`` guess or
        None; any error counts as a failed point.
    controller : callable
        ``controller(PD, level) -> K``: a controller of the scaled plant at about that
        level; run once, at the best point, and certified here.
    check : callable or None
        ``check(PD, level) -> float``: the certified norm of a controller at about that
        level; a trial point whose check exceeds its level by more than 1 % is rejected.
    achieves : callable or None
        ``achieves(PD, g) -> bool``: whether the synthesis of ``level`` reaches ``g`` on
        the scaled plant (one step of its bisection).  Its contract: False (or an error)
        must imply that ``level(PD, ...)`` is above ``g``, which holds when ``level``
        returns a level passing the same test and reaching a level is monotone in it,
        as any bisection assumes.  Where given, a line search's trial point is first
        tested at the current level and, where that is not reached, rejected without
        its level being bisected or checked: such a point fails the sufficient decrease
        and cannot be the best, so the search takes the same path, at one synthesis
        instead of about twenty for the point.
    max_evals : int
        Bound on the number of points evaluated (difference quotients included; see
        ``DScaleSearchResult.evaluations``).
    target : float
        Stop as soon as an accepted level falls below this one.

    Returns
    -------
    DScaleSearchResult or None
        None when no block has a scaling to search, the start has no level, or the best
        point's controller does not stabilise its loop.

    Examples
    --------
    Forty levels from the D-step of the distillation problem's plain H∞ controller
    (Skogestad & Postlethwaite 2005, Table 8.1):

    >>> import numpy as np
    >>> from lmi_suspension import hinfsyn, lft, mussv, freqresp
    >>> from lmi_suspension.examples import skogestad_distillation
    >>> from lmi_suspension.synthesis import HinfsynOptions
    >>> from lmi_suspension.synthesis.hinfsyn import riccati_level
    >>> ex, w = skogestad_distillation(), np.logspace(-3, 3, 61)
    >>> opts = HinfsynOptions(riccati_search="bisection")
    >>> K1 = hinfsyn(ex.P, 2, 2, method="riccati", options=opts).K
    >>> mu = mussv(freqresp(lft(ex.P, K1), w), ex.blk)
    >>> def level(PD, bracket, rtol):
    ...     o = HinfsynOptions(riccati_search="bisection", riccati_rtol=rtol)
    ...     return riccati_level(PD, 2, 2, o, bracket=bracket)
    >>> def controller(PD, g):
    ...     return hinfsyn(PD, 2, 2, method="riccati", options=HinfsynOptions(gamma=1.01 * g)).K
    >>> found = search_dscales(ex.P, 2, 2, [(1, 1), (1, 1), (2, 2)], w, mu.d_blocks,
    ...                        np.ones(w.size), 2, level, controller, max_evals=40)
    >>> found.evaluations <= 40 and found.level < found.level_start < mu.peak
    True
    >>> # SLICOT's controller at a fixed γ certifies within roundoff of it: 3.2e-5 above
    >>> # under OpenBLAS Sandybridge, 9e-5 below under SkylakeX (2026-12-02)
    >>> bool(found.gamma <= 1.01 * found.level * (1 + 1e-4))
    True
    """
    t0 = time.perf_counter()
    d_blocks = np.asarray(d_blocks, dtype=float)
    free = [i for i in range(d_blocks.shape[0]) if not np.allclose(d_blocks[i], 1.0, rtol=1e-12)]
    if not free or order < 1 or max_evals < 1:
        return None
    weights = np.ones(omega.size) if weights is None else np.asarray(weights, dtype=float)
    groups = _equal_scalings(d_blocks, free)
    starts = [_fit_sequence(omega, d_blocks[g[0]], weights, order)[-1] for g in groups]
    omega0 = [o for _, o in starts]
    theta0 = np.concatenate([_canonical(t, order) for t, _ in starts])
    size = theta0.size // len(groups)
    one = control.ss([], [], [], [[1.0]])
    evals = [0]
    stall = max(1, _STALL_STEPS * (theta0.size + 1))
    best: dict = {}
    progress = {"level": np.inf, "at": 0}  # the last 1e-4 fall of the best level
    sampled: list = []  # (θ, gradient) of every difference quotient

    def scalings(theta):
        fits = [one] * d_blocks.shape[0]
        for j, group in enumerate(groups):
            d = _to_statespace(theta[j * size:(j + 1) * size], order, omega0[j])
            for i in group:
                fits[i] = d
        orders = tuple((f.nstates,) for f in fits)
        return DScaleFit(tuple(fits), orders, (0.0,) * len(fits), omega, "search", True)

    def value(theta, near: float | None, width: float, accept: bool,
              ceiling: float | None = None) -> float:
        """The level at θ; inf where it fails, or where ``achieves`` says that
        ``ceiling`` is not reached.  An accepted point is checked first."""
        if evals[0] >= max_evals:
            raise _Stop
        if evals[0] - progress["at"] >= stall:
            raise _Stop(f"no fall of {_STALL_RTOL:g} in {stall} points")
        evals[0] += 1
        bracket = None if near is None else (near * (1 - width), near * (1 + width))
        try:
            dfit = scalings(theta)
            PD = scaled_plant(P, nmeas, ncon, dfit, block_sizes)
            if ceiling is not None and achieves is not None and not achieves(PD, ceiling):
                return np.inf
            v = float(level(PD, bracket, _LEVEL_RTOL))
            if accept and check is not None and np.isfinite(v):
                achieved = float(check(PD, v))
                if not achieved <= v * (1 + _CHECK_RTOL):
                    logger.debug("D-scale search: level %.6f rejected (certified %.6f)",
                                 v, achieved)
                    return np.inf
        except _FAILED_POINT as exc:
            logger.debug("D-scale search: point failed (%s)", exc)
            return np.inf
        if accept and np.isfinite(v) and v < best.get("level", np.inf):
            best.update(level=v, dfit=dfit, PD=PD)
            logger.info("D-scale search: level %.6f after %d points", v, evals[0])
            if v < progress["level"] * (1.0 - _STALL_RTOL):
                progress.update(level=v, at=evals[0])
            if v < target:
                raise _Stop(f"level below the target {target:g}")
        return v

    def gradient(theta, f):
        g = np.empty(theta.size)
        for i in range(theta.size):
            step = np.zeros(theta.size)
            step[i] = _FD_STEP
            g[i] = (value(theta + step, f, _FD_BRACKET, False) - f) / _FD_STEP
        if not np.all(np.isfinite(g)):
            return None
        sampled.append((theta, g))
        return g

    def line_search(x, f, slope, d, wolfe: bool):
        """``(x', f', g')`` along ``d`` (``slope`` the predicted rate of decrease), with
        sufficient decrease and, if ``wolfe``, weak curvature; None if none found."""
        lo, hi, t = 0.0, np.inf, 1.0
        for _ in range(_TRIALS):
            x_t = x + t * d
            # a trial above the current level fails the sufficient decrease and cannot
            # be the best point: one synthesis at that level tells (default musyn on
            # distillation: 45 of the search's 61 trials were above it, each ~22
            # syntheses when bisected; measured 2026-11-28)
            f_t = value(x_t, f, _TRIAL_BRACKET, True, ceiling=f)
            if f_t <= f + _ARMIJO * t * slope:
                g_t = gradient(x_t, f_t)
                if g_t is not None and (not wolfe or g_t @ d >= _WOLFE * slope):
                    return x_t, f_t, g_t
                if g_t is None:
                    hi = t
                else:
                    lo = t
            else:
                hi = t
            t = 2.0 * lo if np.isinf(hi) else 0.5 * (lo + hi)
        return None

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # slycot's balancing notes, one per point
        reason, level_start = "bound on points", None
        try:
            level_start = value(theta0, None, 0.0, True)
            if not np.isfinite(level_start):
                return None
            x, f = theta0, level_start
            g = gradient(x, f)
            H = np.eye(x.size)
            if g is None:
                reason = "no gradient at the start"
            while g is not None:
                d = -H @ g
                if g @ d >= 0:
                    H, d = np.eye(x.size), -g
                step = line_search(x, f, g @ d, d, True)
                if step is None:  # a kink: descend along the sampled gradients
                    near = [gs for xs, gs in sampled if np.linalg.norm(xs - x) <= _SAMPLE_RADIUS]
                    d = -_least_norm(np.array(near))
                    if np.linalg.norm(d) <= _STATIONARY:
                        reason = "stationary"
                        break
                    step = line_search(x, f, -(d @ d), d, False)
                    if step is None:
                        reason = "no descent"
                        break
                    H = np.eye(x.size)
                else:  # BFGS update of the inverse Hessian, where the curvature allows
                    s, y = step[0] - x, step[2] - g
                    if s @ y > 0:
                        r = 1.0 / (s @ y)
                        V = np.eye(x.size) - r * np.outer(y, s)
                        H = V.T @ H @ V + r * np.outer(s, s)
                x, f, g = step
        except _Stop as stop:
            reason = str(stop) or reason
            if level_start is None:  # the start itself is below the target
                level_start = best["level"]
        if "level" not in best:
            return None
        logger.info("D-scale search ended (%s) after %d points at level %.6f", reason,
                    evals[0], best["level"])
        try:
            K = controller(best["PD"], best["level"])
            gamma = float(hinfnorm(lft(best["PD"], K, nmeas, ncon))[0])
        except _FAILED_POINT as exc:
            logger.info("D-scale search: no controller at the best point (%s)", exc)
            return None
    if not np.isfinite(gamma):
        return None
    return DScaleSearchResult(K=K, gamma=gamma, level=best["level"], level_start=level_start,
                              dfit=best["dfit"], evaluations=evals[0],
                              seconds=time.perf_counter() - t0, PD=best["PD"])
