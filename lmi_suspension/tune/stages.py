"""SLSQP in trust-region stages: :func:`~lmi_suspension.tune.systune`'s route for
requirements given as vectors of smooth terms (``systune(..., options=SystuneOptions(
method="slsqp"))``).

The nonsmooth BFGS of :func:`~lmi_suspension.tune.systune` sees a requirement through
its largest term (a maximum over frequencies, delays, poles) and that term's gradient.
Where a requirement can give *every* term (each a smooth function of θ: a bump peak per
delay, µ per frequency point, a margin per pole), the maximum need not be formed: the
problem

    minimise t   subject to   soft_i(θ) ≤ t,   margin_j(θ) ≥ 0   (every term)

is smooth, and SciPy's SLSQP solves it with finite-difference Jacobians of the terms,
which need no analytic derivative (Apkarian & Noll's epigraph form of the same
minimax; the seat's refinement, :mod:`lmi_suspension.seat.refine`, was built so).

Two guards make it reliable on such problems (both measured on the seat, 2026-11-26):

* a **trust region**: each stage of at most ``stage_iter`` SLSQP iterations is confined
  to a box of half-width ``trust`` around its start (plain SLSQP wandered to µ 2.3 and
  back); a stage's end is kept only if it is *better* -- less violation of the hard
  terms, or, once they are met, a lower soft maximum -- else the box is halved; the
  search ends when a kept stage converged (SLSQP's success, fewer iterations than the
  stage allows, the hard terms met) strictly inside its box;
* the **best evaluated point**, not the last: every evaluation (SLSQP's iterates and
  its difference probes alike) is a parameter vector with exact figures, and the best
  one is kept.

The hard terms are aimed at with a margin (each bound tightened by ``2 margin``, an
excess below ``margin`` counts as met): SLSQP ends on the constraints' boundary, a
little outside.  A requirement whose terms depend on something held fixed through a
stage (a µ upper bound's D-G scalings) refreshes it at each accepted stage's start
(``refresh``), as the D-step of an alternation.
"""

from __future__ import annotations

import logging
import numbers
import time
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from ..errors import ParameterError

__all__ = ["TrustRegionOptions", "TrustRegionStage", "trust_region_slsqp"]

logger = logging.getLogger(__name__)

#: an end point within this fraction of the trust radius of the box's edge is on it
#: (SLSQP ends on an active bound to round-off; a stage that ends there has not converged
#: but met the box: a smooth minimax test stopped at its first box, 2026-12-02)
_BOX_EDGE = 1e-6


@dataclass(frozen=True)
class TrustRegionOptions:
    """Options of the SLSQP route (:func:`trust_region_slsqp`).

    Attributes
    ----------
    max_iter : int
        SLSQP iterations in all (every stage counts).
    stage_iter : int
        SLSQP iterations per stage (each stage restarts SLSQP's quasi-Newton matrix, so
        stages should not be short).
    trust_start, trust_min : float
        First box half-width in the parameters, and the width below which the search
        ends (the box is halved after a stage that found nothing better).
    margin : float
        The hard terms are aimed at ``margin ≥ 2 · margin`` of their bound (tightened by
        that fraction), and an excess below ``margin`` counts as met.
    ftol : float
        SLSQP's ``ftol``.
    """

    max_iter: int = 600
    stage_iter: int = 60
    trust_start: float = 0.5
    trust_min: float = 1e-3
    margin: float = 3e-3
    ftol: float = 1e-6

    def __post_init__(self):
        for name in ("max_iter", "stage_iter"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (numbers.Integral, np.integer)) or v < 1:
                raise ParameterError(f"{name} must be a positive integer, got {v!r}")
        for name in ("trust_start", "trust_min", "ftol"):
            v = getattr(self, name)
            if not (isinstance(v, numbers.Real) and np.isfinite(v) and v > 0):
                raise ParameterError(f"{name} must be positive and finite, got {v!r}")
        if not (isinstance(self.margin, numbers.Real) and 0 <= self.margin < 0.5):
            raise ParameterError(f"margin must be in [0, 0.5), got {self.margin!r}")

    @property
    def tighten(self) -> float:
        """The factor every hard bound is multiplied by: ``1 - 2 margin``."""
        return 1.0 - 2 * self.margin


@dataclass(frozen=True)
class TrustRegionStage:
    """One stage (progress record): its SLSQP iterations, the box half-width after it,
    whether its end was kept, the best point's soft maximum and violation, and the best
    parameters."""

    index: int
    iterations: int
    trust: float
    accepted: bool
    soft: float
    violation: float
    seconds: float
    theta: np.ndarray


@dataclass(frozen=True)
class _Point:
    """One parameter vector's soft terms and hard margins."""

    soft: np.ndarray
    margins: np.ndarray

    @property
    def objective(self) -> float:
        return float(np.max(self.soft))

    @property
    def violation(self) -> float:
        return max(0.0, float(-np.min(self.margins))) if self.margins.size else 0.0

    def better_than(self, other: _Point, tol: float) -> bool:
        if self.violation > tol or other.violation > tol:
            return self.violation < other.violation - tol
        return self.objective < other.objective * (1 - 1e-6)


class _Search:
    """The evaluations, cached per parameter vector, and the best one seen."""

    def __init__(self, evaluate, tol):
        self._evaluate, self.tol = evaluate, tol
        self._cache: dict = {}
        self.best: _Point | None = None
        self.best_y: np.ndarray | None = None
        self.size = 0

    def forget(self):
        self._cache.clear()
        self.best = self.best_y = None

    def evaluate(self, y: np.ndarray) -> _Point | None:
        key = y.tobytes()
        if key not in self._cache:
            out = self._evaluate(y)
            p = None if out is None else _Point(np.asarray(out[0], dtype=float),
                                                np.asarray(out[1], dtype=float))
            self._cache[key] = p
            if p is not None and (self.best is None or p.better_than(self.best, self.tol)):
                self.best, self.best_y = p, np.array(y, dtype=float)
        return self._cache[key]

    def constraints(self, z: np.ndarray) -> np.ndarray:
        """Normalised margins (``>= 0`` where met): the soft terms under the epigraph
        variable ``z[0]``, then the hard margins."""
        t, rest = z[0], z[1:]
        p = self.evaluate(rest)
        if p is None:
            return -np.ones(self.size)
        return np.concatenate([(t - p.soft) / max(t, 1e-9), p.margins])


def _slsqp(z0, grad, bounds, constraints, maxiter: int, ftol: float):
    """One stage's SLSQP: minimise the epigraph variable ``z[0]`` (tests replace it)."""
    with np.errstate(all="ignore"):
        return optimize.minimize(lambda v: v[0], z0, jac=lambda v: grad, method="SLSQP",
                                 bounds=bounds,
                                 constraints=[{"type": "ineq", "fun": constraints}],
                                 options={"maxiter": maxiter, "ftol": ftol})


def trust_region_slsqp(evaluate, theta0, options: TrustRegionOptions | None = None, *,
                       lower=None, upper=None, refresh=None, callback=None) -> tuple:
    """Minimise the largest soft term subject to every hard margin ``>= 0`` by SLSQP in
    trust-region stages (module docstring).

    Parameters
    ----------
    evaluate : callable
        ``evaluate(theta) -> (soft terms, hard margins)`` (1-D arrays of fixed sizes; the
        margins ``>= 0`` where met, for bounds already tightened by
        ``options.tighten``), or None where undefined (an unstable loop).
    theta0 : array_like
        Start, where ``evaluate`` is defined.
    options : TrustRegionOptions, optional
    lower, upper : array_like, optional
        Bounds of the parameters (``-inf``/``inf`` by default).
    refresh : callable, optional
        ``refresh(theta)``: called at the start and at each accepted stage's start,
        before the stage's evaluations (every cached evaluation is forgotten after it).
    callback : callable, optional
        Called with each :class:`TrustRegionStage`.

    Returns
    -------
    theta : numpy.ndarray
        The best point.
    soft, violation : float
        Its soft maximum and its violation (``<= options.margin`` counts as met).
    stages : tuple of TrustRegionStage
    iterations : int

    Raises
    ------
    ParameterError
        ``evaluate`` is undefined at ``theta0``.
    """
    opts = TrustRegionOptions() if options is None else options
    y = np.array(theta0, dtype=float)
    lower = np.full(y.size, -np.inf) if lower is None else np.asarray(lower, dtype=float)
    upper = np.full(y.size, np.inf) if upper is None else np.asarray(upper, dtype=float)
    search = _Search(evaluate, opts.margin)

    def fresh(y):
        refresh(y)
        search.forget()
        return search.evaluate(y)

    best = fresh(y) if refresh is not None else search.evaluate(y)
    if best is None:
        raise ParameterError("the requirements are undefined at the start (an unstable loop)")
    search.size = search.constraints(np.concatenate([[best.objective], y])).size
    trust, iterations, stages = opts.trust_start, 0, []
    while iterations < opts.max_iter and trust >= opts.trust_min:
        t0 = time.perf_counter()
        if refresh is not None and stages and stages[-1].accepted:
            best = fresh(y)
        z0 = np.concatenate([[best.objective], y])
        box_lo, box_hi = np.maximum(lower, y - trust), np.minimum(upper, y + trust)
        grad = np.zeros(z0.size)
        grad[0] = 1.0
        res = _slsqp(z0, grad, list(zip(np.concatenate([[0.0], box_lo]),
                                        np.concatenate([[np.inf], box_hi]))),
                     search.constraints, min(opts.stage_iter, opts.max_iter - iterations),
                     opts.ftol)
        iterations += int(res.nit)
        end = np.clip(res.x[1:], box_lo, box_hi)
        search.evaluate(end)
        # on the box's edge where the box is tighter than the bounds: stopped by the trust
        # region, not at a local optimum
        edge = _BOX_EDGE * trust
        on_edge = bool(np.any((end <= box_lo + edge) & (box_lo > lower))
                       or np.any((end >= box_hi - edge) & (box_hi < upper)))
        accepted = search.best is not best
        if accepted:
            y, best = search.best_y, search.best
        else:
            trust /= 2
        rec = TrustRegionStage(index=len(stages) + 1, iterations=int(res.nit), trust=trust,
                               accepted=accepted, soft=best.objective,
                               violation=best.violation, seconds=time.perf_counter() - t0,
                               theta=y.copy())
        stages.append(rec)
        logger.debug("trust-region stage %d: %s, soft %.6g, violation %.2g (%d iterations)",
                     rec.index, "accepted" if accepted else "rejected", rec.soft,
                     rec.violation, rec.iterations)
        if callback is not None:
            callback(rec)
        if accepted and best.violation <= opts.margin and res.success \
                and res.nit < opts.stage_iter and not on_edge:
            break        # SLSQP converged inside the box: a local optimum
    return y, best.objective, best.violation, tuple(stages), iterations
