"""Multi-model, multi-requirement structured tuning (MATLAB's ``systune``).

``systune`` minimises the largest *soft* requirement value over every model subject to
every *hard* requirement value ``≤ 1``, over the free parameters θ shared by all models
(a gain surface is evaluated at each model's scheduling point, so one θ tunes it across
the models)::

    minimise   f(θ) = max_{m, i} soft_i(loop_m(θ))
    subject to g(θ) = max_{m, j} hard_j(loop_m(θ)) ≤ 1

Both are maxima of nonsmooth functions; their Clarke subgradient at a point is that of
an active term (a model, a requirement, a peak frequency or pole), so the nonsmooth BFGS
of :func:`~lmi_suspension.tune.hinfstruct` (Lewis & Overton's weak Wolfe line search)
serves them unchanged, as a larger maximum.

**The constraint: a progress function** (Apkarian, Noll & Rondepierre, SIAM J. Control
Optim. 47(3), 2008; the approach behind MATLAB's ``systune``, Apkarian, Gahinet & Buhr,
ECC 2014).  Each outer iteration ``k`` minimises, from ``θ_k``,

    F(θ; θ_k) = max( f(θ) - μ [g_k]₊ ,  f_k + (g(θ) - 1) - [g_k]₊ )

(``f_k = f(θ_k)``, ``g_k = g(θ_k) - 1``, ``μ = 1``, written shifted by ``f_k`` so the
stall test is relative to the soft level), and takes the end point as ``θ_{k+1}``.
``F(θ_k; θ_k) = f_k``; a decrease of ``F`` decreases the infeasibility where ``θ_k`` is
infeasible, and decreases ``f`` while staying feasible where it is feasible, so the
iterates stay feasible once they are; a point where ``F`` cannot decrease is a
Fritz-John point of the problem.  Why this and not an exact penalty ``f + c [g - 1]₊``:
a penalty needs a weight ``c`` above the (unknown) multiplier, found by an outer loop
that reruns the search, and lets the iterates wander outside the feasible set; the
progress function needs no weight and keeps feasibility.  The outer loop is bounded
(``max_outer``), and all its BFGS runs share one iteration budget (``max_iter``).  The
hard target is ``1 - 1e-6`` (:data:`_HARD_TARGET`), so that the certificate, computed by
another route, does not land a rounding error above 1.

Without hard requirements ``systune`` minimises ``f`` by one BFGS run (as
``hinfstruct``); without soft ones it minimises ``g``.  Each start first finds a point
that stabilises every model (BFGS on the largest spectral abscissa over the models, as
``hinfstruct`` does for one), from the blocks' start and ``starts - 1`` random
perturbations of it drawn from the seeded ``Generator``.

**The SLSQP route** (``SystuneOptions(method="slsqp")``, :mod:`~lmi_suspension.tune.stages`):
for requirements that give every term of their maximum (a method ``terms(loop)`` for a
soft one, ``margins(loop, tighten)`` for a hard one; any other requirement counts as its
value alone), SLSQP in trust-region stages on the epigraph form, with finite-difference
Jacobians, from the first start only, which must stabilise every model (no
stabilisation phase), within the blocks' ``lower``/``upper`` bounds where they have them.
A requirement with a method ``refresh(loop)`` refreshes what it holds fixed through a stage
at each accepted stage's start.  The seat's refinement
(:func:`~lmi_suspension.seat.refine.refine_seat_controller`) runs on it.

The result is certified: every requirement is recomputed on ``lft(P_m, K_m)`` of the
returned numbers by its ``certify`` (``hinfnorm`` with a dense σ̄ sweep,
``numpy.linalg.eigvals``, a sensitivity built by ``control.feedback``); ``feasible`` and
the reported values are those recomputed ones.
"""

from __future__ import annotations

import logging
import numbers
import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import scipy.optimize

from ..errors import IllPosedLoopError, IterationLimitError, ParameterError
from ..lti.norms import is_stable
from ..lti.plant import lft
from .blocks import block_diagonal
from .closedloop import ClosedLoop
from .hinfstruct import _bfgs, _Loop, _plant, _starts
from .stages import TrustRegionOptions, trust_region_slsqp

__all__ = ["SystuneOptions", "SystuneResult", "SystuneStart", "systune"]

logger = logging.getLogger(__name__)

#: the optimiser's level for the hard requirements: a hair under 1, so that the
#: certificate (another realization, hinfnorm's relative accuracy 1e-9, eigenvalues of
#: another matrix to ~1e-12) does not put a requirement met at 1 a rounding error above it
_HARD_TARGET = 1.0 - 1e-6
#: the progress function's weight on the infeasibility (Apkarian, Noll & Rondepierre
#: 2008 allow any μ > 0): with normalised values, 1 lets f rise by as much as the
#: infeasibility falls
_MU = 1.0
#: terms of a maximum within this (relative) of the largest count as active together
#: (exact ties, as between mirror-image models, differ by round-off only).  With the
#: largest term's gradient alone, the docstring's example (models b = ±1, start K = 0)
#: stopped at its start, 1.0 against 1/√5 = 0.447214 (measured 2026-12-02)
_TIE = 1e-9


@dataclass(frozen=True)
class SystuneOptions:
    """Options of :func:`systune` (frozen; copy with :func:`dataclasses.replace`).

    Attributes
    ----------
    max_iter : int
        BFGS iterations per start after stabilisation, over all outer iterations.
    max_outer : int
        Outer iterations of the progress function (with hard requirements).
    stab_max_iter : int
        BFGS iterations per start in the stabilisation phase.
    ftol, stall_iter : float, int
        A BFGS run ends when its objective decreased by less than ``ftol`` (relative)
        over ``stall_iter`` iterations; the outer loop ends when a run decreased the
        progress function by less than ``ftol`` (relative).
    perturbation : float
        Size of the random starts, as in :class:`~lmi_suspension.tune.HinfstructOptions`.
    on_unstable : {"raise", "return"}
        No start stabilised every model: raise
        :class:`~lmi_suspension.errors.IterationLimitError`, or return a result that
        says so.
    method : {"bfgs", "slsqp"}
        The nonsmooth BFGS with the progress function, or SLSQP in trust-region stages
        (module docstring; ``max_iter`` and the other BFGS options do not apply to it).
    trust_region : TrustRegionOptions, optional
        The SLSQP route's options (its defaults when omitted).
    """

    max_iter: int = 300
    max_outer: int = 20
    stab_max_iter: int = 200
    ftol: float = 1e-7
    stall_iter: int = 10
    perturbation: float = 0.5
    on_unstable: str = "raise"
    method: str = "bfgs"
    trust_region: TrustRegionOptions | None = None

    def __post_init__(self):
        for name in ("max_iter", "max_outer", "stab_max_iter", "stall_iter"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (numbers.Integral, np.integer)) or v < 1:
                raise ParameterError(f"{name} must be a positive integer, got {v!r}")
        for name in ("ftol", "perturbation"):
            v = getattr(self, name)
            if not (isinstance(v, numbers.Real) and np.isfinite(v) and v >= 0):
                raise ParameterError(f"{name} must be finite and >= 0, got {v!r}")
        if self.on_unstable not in ("raise", "return"):
            raise ParameterError(f"on_unstable must be 'raise' or 'return', got "
                                 f"{self.on_unstable!r}")
        if self.method not in ("bfgs", "slsqp"):
            raise ParameterError(f"method must be 'bfgs' or 'slsqp', got {self.method!r}")
        if self.trust_region is not None and not isinstance(self.trust_region,
                                                            TrustRegionOptions):
            raise ParameterError(f"trust_region must be TrustRegionOptions, got "
                                 f"{type(self.trust_region).__name__}")


@dataclass(frozen=True)
class SystuneStart:
    """What one start did: where it began and ended, the optimiser's (not certified)
    soft and hard levels there, its iterations (stabilisation, BFGS, outer) and why it
    stopped."""

    index: int
    theta0: np.ndarray
    theta: np.ndarray
    soft: float
    hard: float
    stab_iterations: int
    iterations: int
    outer: int
    stop: str
    seconds: float
    evaluations: int = 0


@dataclass(frozen=True)
class SystuneResult:
    """Result of :func:`systune`; every value is recomputed on ``lft(P_m, K_m)`` of the
    returned numbers.

    Attributes
    ----------
    values : dict
        The tuned free parameters by name.
    theta : numpy.ndarray
        The same, as a vector.
    K : tuple of control.StateSpace
        The tuned controller of each model (the blocks, block-diagonal, with every gain
        surface at the model's scheduling point).
    blocks : tuple of dict
        Per model, each tuned block by name as a :class:`control.StateSpace` (a gain
        surface at the model's point).
    CL : tuple of control.StateSpace
        ``lft(P_m, K_m)`` of each model.
    soft, hard : float
        The largest certified soft and hard values (``0.0`` when there is none).
    soft_values, hard_values : numpy.ndarray
        Certified values, one row per model, one column per requirement, in the order
        given.
    feasible : bool
        Every model's loop stable and every certified hard value ``≤ 1``.
    stable : bool
        Every model's loop stable.
    starts : tuple of SystuneStart
    best : int
        The start that gave the result.
    seconds : float
    warnings : tuple of str
        What was asked and not obtained (a hard requirement not met, no stabilising
        point, a best start stopped by its iteration bound).
    stages : tuple of TrustRegionStage
        The SLSQP route's stages (empty for BFGS).
    """

    values: dict
    theta: np.ndarray
    K: tuple
    CL: tuple
    blocks: tuple
    soft: float
    hard: float
    soft_values: np.ndarray
    hard_values: np.ndarray
    feasible: bool
    stable: bool
    starts: tuple = ()
    best: int = 0
    seconds: float = 0.0
    warnings: tuple = field(default_factory=tuple)
    stages: tuple = ()


# ------------------------------------------------------------------------------ inputs
def _models(models):
    items = models if isinstance(models, (list, tuple)) and not (
        len(models) == 2 and isinstance(models[1], Mapping)) else [models]
    if not items:
        raise ParameterError("systune needs at least one model")
    out = []
    for k, item in enumerate(items):
        if isinstance(item, tuple) and len(item) == 2 and isinstance(item[1], Mapping):
            out.append((item[0], dict(item[1])))
        elif isinstance(item, tuple):
            raise ParameterError(f"models[{k}] must be a plant or (plant, {{parameter: "
                                 f"value}}), got a tuple of {len(item)}")
        else:
            out.append((item, {}))
    return out


def _block_at(blocks, point, k):
    """The blocks of model ``k`` as one TunableBlock: each gain surface at the model's
    scheduling point."""
    items = [blocks] if not isinstance(blocks, (list, tuple)) else list(blocks)
    if not items:
        raise ParameterError("no tunable block given")
    used, out = set(), []
    for b in items:
        if hasattr(b, "scheduling") and hasattr(b, "at"):
            missing = [n for n in b.scheduling if n not in point]
            if missing:
                raise ParameterError(f"model {k} gives no value of {', '.join(missing)} "
                                     f"for gain surface {b.name!r}: pass (plant, "
                                     f"{{{', '.join(repr(n) + ': ...' for n in b.scheduling)}}})")
            out.append(b.at(**{n: point[n] for n in b.scheduling}))
            used.update(b.scheduling)
        else:
            out.append(b)
    unused = [n for n in point if n not in used]
    if unused:
        raise ParameterError(f"model {k}: no gain surface is scheduled on "
                             f"{', '.join(map(repr, unused))}")
    return block_diagonal(out)


def _requirements(reqs, label):
    if reqs is None:
        return []
    items = [reqs] if not isinstance(reqs, (list, tuple)) else list(reqs)
    for r in items:
        missing = [a for a in ("name", "bind", "value", "certify") if not hasattr(r, a)]
        if missing:
            raise ParameterError(f"{label}: {r!r} is not a requirement: it lacks "
                                 f"{', '.join(missing)}")
    return items


# ------------------------------------------------------------------------------ problem
class _Problem:
    """Every model's loop and bound requirements; values and subgradients in the search
    coordinates ``z`` (``ln θ`` for a parameter that must stay positive)."""

    def __init__(self, loops, soft, hard):
        self.loops, self.soft, self.hard = loops, soft, hard
        self._cache = (None, None)
        self.evaluations = 0

    def theta(self, z):
        return self.loops[0].theta(z)

    def z(self, theta):
        return self.loops[0].z(theta)

    def terms(self, z):
        """``(soft, hard)``: every model's requirement values with their gradients in
        ``z``, as lists of ``(v, ∇v)``; ``None`` where a model's loop is unstable or
        ill-posed."""
        key = np.asarray(z, dtype=float).tobytes()
        if self._cache[0] == key:
            return self._cache[1]
        self.evaluations += 1
        theta = self.theta(z)
        out = self._terms(theta) if np.all(np.isfinite(theta)) else None
        self._cache = (key, out)
        return out

    def _terms(self, theta):
        closed = _closed_loops(self, theta)
        if closed is None:
            return None
        out = []
        for reqs in (self.soft, self.hard):
            terms = []
            for cl, model_reqs in zip(closed, reqs):
                for r in model_reqs:
                    v, g = r.value(cl)
                    if not np.isfinite(v) or g is None:
                        return None
                    terms.append((float(v), self._chain(theta, np.asarray(g, dtype=float))))
            out.append(terms)
        return tuple(out)

    def levels(self, z):
        """``(f, g)``: the largest soft and hard values (``-inf`` where there is none;
        ``inf`` on an unstable model)."""
        t = self.terms(z)
        if t is None:
            return np.inf, np.inf
        return tuple(max((v for v, _ in ts), default=-np.inf) for ts in t)

    def _chain(self, theta, g):
        return np.where(self.loops[0].positive, g * theta, g)

    def abscissa_fz(self, z):
        theta = self.theta(z)
        best = (-np.inf, None)
        for loop in self.loops:
            a, g = loop.abscissa_fg(theta)
            if g is None:
                return np.inf, None
            if a > best[0]:
                best = (a, g)
        return best[0], self._chain(theta, best[1])


def _active_max(terms, n, tie):
    """``(max v, a subgradient)`` of the maximum of ``terms = [(v, ∇v), ...]``: the
    gradient of the largest term, or, where several are within ``tie`` (relative) of
    it, the least-norm element of the convex hull of theirs -- the steepest-descent
    direction of the maximum of those terms.  With one gradient only, a line search from
    an exact tie (two mirror-image models at a symmetric start) finds no decrease: the
    step that lowers one term raises the other."""
    if not terms:
        return -np.inf, np.zeros(n)
    top = max(v for v, _ in terms)
    active = [g for v, g in terms if v >= top - tie * max(1.0, abs(top))]
    if len(active) == 1:
        return top, active[0]
    G = np.column_stack(active)
    # min |G λ| over the simplex, as a nonnegative least-squares problem with the sum
    # of λ held at 1 by a heavily weighted row
    rho = 1e3 * max(1.0, float(np.max(np.abs(G))))
    lam, _ = scipy.optimize.nnls(np.vstack([G, rho * np.ones((1, G.shape[1]))]),
                                 np.r_[np.zeros(n), rho], maxiter=50 * G.shape[1])
    lam = lam / lam.sum() if lam.sum() > 0 else np.full(lam.size, 1.0 / lam.size)
    return top, G @ lam


def _descend(terms, z, budget, opts, state):
    """Minimise ``max`` of ``terms(z)`` (a list of ``(v, ∇v)``, or ``None`` where
    undefined) by BFGS from ``z``, ``state`` carrying its inverse Hessian.  Returns
    ``(z, f, iterations, why it stopped)``."""
    n = z.size

    def fg(y):
        t = terms(y)
        return (np.inf, None) if t is None else _active_max(t, n, _TIE)

    f, g = fg(z)
    z, f, _, it, why = _bfgs(fg, z, f, g, budget, ftol=opts.ftol,
                             stall_iter=opts.stall_iter, state=state)
    return z, f, it, why


def _run_start(prob: _Problem, index, theta0, opts, has_soft, has_hard) -> SystuneStart:
    t0, n0 = time.perf_counter(), prob.evaluations
    z = prob.z(theta0)
    stab_it = 0
    if prob.terms(z) is None:
        a, ga = prob.abscissa_fz(z)
        if ga is None:
            return SystuneStart(index, theta0, theta0.copy(), np.inf, np.inf, 0, 0, 0,
                                "ill-posed start", time.perf_counter() - t0,
                                prob.evaluations - n0)
        z, a, _, stab_it, why = _bfgs(prob.abscissa_fz, z, a, ga, opts.stab_max_iter,
                                      done=lambda zk, _a: prob.terms(zk) is not None)
        if prob.terms(z) is None:
            logger.info("start %d: no point stabilises every model (%s)", index, why)
            return SystuneStart(index, theta0, prob.theta(z), np.inf, np.inf, stab_it, 0, 0,
                                f"not stabilised: {why}", time.perf_counter() - t0,
                                prob.evaluations - n0)
    outer = 0
    if not has_hard or not has_soft:
        k = 0 if has_soft else 1
        z, _, it, why = _descend(lambda y: _pick(prob.terms(y), k), z, opts.max_iter, opts, {})
    else:
        z, it, outer, why = _progress(prob, z, opts)
    f, g = prob.levels(z)
    logger.info("start %d: soft %.6g, hard %.6g after %d + %d iterations, %d outer (%s)",
                index, f, g, stab_it, it, outer, why)
    return SystuneStart(index, theta0, prob.theta(z), f, g, stab_it, it, outer, why,
                        time.perf_counter() - t0, prob.evaluations - n0)


def _pick(terms, k):
    return None if terms is None else terms[k]


def _progress(prob: _Problem, z, opts):
    """The progress-function outer loop (module docstring).  Returns ``(z, iterations,
    outer iterations, why it stopped)``."""
    used, why = 0, "outer iteration bound"
    # the inverse Hessian, kept across outer iterations: the test's three-model surface
    # problem took 101 iterations (658 evaluations) with it, 192 (1303) when each outer
    # iteration started afresh, to the same optimum (+2.2e-8 and +2.1e-8, 2026-12-02)
    state = {}
    for outer in range(1, opts.max_outer + 1):
        fk, gk = prob.levels(z)
        gplus = max(gk - _HARD_TARGET, 0.0)

        def F(y, fk=fk, gplus=gplus):
            t = prob.terms(y)
            if t is None:
                return None
            return ([(v - _MU * gplus, g) for v, g in t[0]]
                    + [(fk + v - _HARD_TARGET - gplus, g) for v, g in t[1]])

        Fk = _active_max(F(z), z.size, _TIE)[0]
        z, Fn, it, stop = _descend(F, z, opts.max_iter - used, opts, state)
        used += it
        if Fk - Fn <= opts.ftol * max(abs(Fk), 1e-12):
            why = f"progress function stationary ({stop})"
            break
        if used >= opts.max_iter:
            why = "iteration bound"
            break
    return z, used, outer, why


# ------------------------------------------------------------------------------ SLSQP
def _soft_terms(r, cl):
    if hasattr(r, "terms"):
        out = r.terms(cl)
        return None if out is None else np.atleast_1d(np.asarray(out, dtype=float))
    v, _ = r.value(cl)
    return np.array([float(v)]) if np.isfinite(v) else None


def _hard_margins(r, cl, tighten):
    if hasattr(r, "margins"):
        out = r.margins(cl, tighten)
        return None if out is None else np.atleast_1d(np.asarray(out, dtype=float))
    v, _ = r.value(cl)
    return np.array([1.0 - float(v) / tighten]) if np.isfinite(v) else None


def _closed_loops(prob: _Problem, theta):
    """Every model's closed loop at ``theta``; None where one is ill-posed or unstable."""
    closed = []
    for loop in prob.loops:
        try:
            cl = ClosedLoop(loop, theta)
        except (np.linalg.LinAlgError, IllPosedLoopError):
            return None
        if not cl.stable:
            return None
        closed.append(cl)
    return closed


def _run_slsqp(prob: _Problem, theta0, opts: SystuneOptions, callback):
    """The SLSQP route from ``theta0`` (module docstring): ``(SystuneStart, stages)``."""
    t0, n0 = time.perf_counter(), prob.evaluations
    tr = TrustRegionOptions() if opts.trust_region is None else opts.trust_region
    block = prob.loops[0].block
    positive = prob.loops[0].positive

    def evaluate(z):
        prob.evaluations += 1
        theta = prob.theta(z)
        if not np.all(np.isfinite(theta)):
            return None
        closed = _closed_loops(prob, theta)
        if closed is None:
            return None
        soft, margins = [], []
        for out, reqs, terms in ((soft, prob.soft, _soft_terms),
                                 (margins, prob.hard, _hard_margins)):
            for cl, model_reqs in zip(closed, reqs):
                for r in model_reqs:
                    v = terms(r, cl) if terms is _soft_terms else terms(r, cl, tr.tighten)
                    if v is None:
                        return None
                    out.append(v)
        return (np.concatenate(soft) if soft else np.zeros(1),
                np.concatenate(margins) if margins else np.zeros(0))

    fresh = [r for reqs in prob.soft + prob.hard for r in reqs if hasattr(r, "refresh")]

    def refresh(z):
        closed = _closed_loops(prob, prob.theta(z))
        if closed is None:
            raise ParameterError("the loop is unstable where the requirements refresh")
        for cl, reqs in zip(closed, [s + h for s, h in zip(prob.soft, prob.hard)]):
            for r in reqs:
                if hasattr(r, "refresh"):
                    r.refresh(cl)

    with np.errstate(divide="ignore", invalid="ignore"):
        bound = (lambda name, fill: np.where(
            positive, np.log(np.maximum(getattr(block, name, fill), 0.0)),
            getattr(block, name, fill)) * np.ones(block.n_params))
        lower, upper = bound("lower", -np.inf), bound("upper", np.inf)
    try:
        z, soft, violation, stages, it = trust_region_slsqp(
            evaluate, prob.z(theta0), tr, lower=lower, upper=upper,
            refresh=refresh if fresh else None, callback=callback)
    except ParameterError as exc:
        logger.info("SLSQP route: %s", exc)
        return SystuneStart(0, theta0, theta0.copy(), np.inf, np.inf, 0, 0, 0,
                            f"not stabilised: {exc}", time.perf_counter() - t0,
                            prob.evaluations - n0), ()
    why = ("converged in a stage" if stages and stages[-1].iterations < tr.stage_iter
           and stages[-1].accepted else "iteration bound" if it >= tr.max_iter
           else "trust region below its minimum")
    logger.info("SLSQP route: soft %.6g, violation %.2g after %d iterations in %d stages "
                "(%s)", soft, violation, it, len(stages), why)
    return SystuneStart(0, theta0, prob.theta(z), soft, 1.0 + violation, 0, it, len(stages),
                        why, time.perf_counter() - t0, prob.evaluations - n0), stages


# ------------------------------------------------------------------------------ systune
def systune(models, blocks, soft=(), hard=(), *, nmeas: int | None = None,
            ncon: int | None = None, starts=1,
            rng: np.random.Generator | None = None,
            options: SystuneOptions | None = None, callback=None) -> SystuneResult:
    """Tune the blocks against soft and hard requirements over several models.

    Parameters
    ----------
    models : plant, or sequence of plants or ``(plant, {parameter: value})``
        Continuous-time generalized plants (``StateSpace`` with the controls last and
        the measurements last, sized by the blocks; or
        :class:`~lmi_suspension.lti.GeneralizedPlant`), each with the scheduling point
        at which its gain surfaces are evaluated.
    blocks : TunableBlock, ScheduledBlock or a sequence of them
        The controller's structure, ``K = diag(K_1, K_2, ...)``; the same parameters
        in every model.
    soft, hard : Requirement or sequence of Requirement
        Applied to every model.  ``systune`` minimises the largest soft value subject
        to every hard value ``≤ 1`` (see the module docstring for how).
    nmeas, ncon : int, optional
        Numbers of measurements and controls of every plant; by default those of the
        blocks.
    starts : int or sequence
        As for :func:`~lmi_suspension.tune.hinfstruct`.
    rng : numpy.random.Generator, optional
        Source of the random starts (``default_rng(0)`` when omitted).
    options : SystuneOptions, optional
    callback : callable, optional
        The SLSQP route calls it with each
        :class:`~lmi_suspension.tune.stages.TrustRegionStage` (progress); the BFGS route
        with each start's :class:`SystuneStart`.

    Returns
    -------
    SystuneResult
        Certified: every value recomputed on ``lft(P_m, K_m)`` of the returned numbers.

    Raises
    ------
    ParameterError
        No requirement, not a requirement, a model without the scheduling values its
        gain surfaces need (or with values none uses), bad ``starts``/``rng``/``options``.
    DimensionError
        A requirement on a channel a plant does not have; a partition that does not fit.
    IterationLimitError
        No start stabilised every model (``options.on_unstable="raise"``).

    Examples
    --------
    A static gain ``k`` on ``x' = -x + w + b u``, ``y = x``, ``z = [x; u/2]``, scheduled
    on the measured input gain ``b`` (the best gain changes sign with ``b``: no fixed
    gain serves ``b = ±1``):

    >>> import numpy as np, control
    >>> from lmi_suspension.tune import systune, tunable_surface, HinfBound
    >>> def plant(b):
    ...     return control.ss([[-1.0]], [[1.0, b]], [[1.0], [0.0], [1.0]],
    ...                       [[0.0, 0.0], [0.0, 0.5], [0.0, 0.0]])
    >>> K = tunable_surface("K", {"b": [-1.0, 1.0]}, lambda b: [b])
    >>> res = systune([(plant(b), {"b": b}) for b in (-1.0, 1.0)], K, soft=HinfBound())
    >>> round(res.soft, 6), round(res.values["K.K1"], 4), abs(res.values["K.K0"]) < 1e-6
    (0.447214, -4.0, True)
    >>> K.gain({"b": 0.5}, res.values).round(4).tolist()     # K0 + 0.5 K1, off the grid
    [[-2.0]]

    (Each model at its own optimum ``k = -4 b``, ``‖T‖∞ = 1/√5``.)
    """
    t_start = time.perf_counter()
    opts = SystuneOptions() if options is None else options
    if not isinstance(opts, SystuneOptions):
        raise ParameterError(f"options must be SystuneOptions, got {type(opts).__name__}")
    if rng is None:
        rng = np.random.default_rng(0)
    if not isinstance(rng, np.random.Generator):
        raise ParameterError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    items = _models(models)
    soft_reqs, hard_reqs = _requirements(soft, "soft"), _requirements(hard, "hard")
    if not soft_reqs and not hard_reqs:
        raise ParameterError("systune needs at least one soft or hard requirement")
    model_blocks = [_block_at(blocks, point, k) for k, (_, point) in enumerate(items)]
    plants = [_plant(P, nmeas, ncon, b) for (P, _), b in zip(items, model_blocks)]
    soft_b = [[r.bind(G) for r in soft_reqs] for G in plants]
    hard_b = [[r.bind(G) for r in hard_reqs] for G in plants]
    points = _starts(model_blocks[0], starts, rng, opts)
    prob = _Problem([_Loop(G, b) for G, b in zip(plants, model_blocks)], soft_b, hard_b)

    stages = ()
    if opts.method == "slsqp":
        record, stages = _run_slsqp(prob, points[0], opts, callback)
        records = [record]
    else:
        records = []
        for k, t in enumerate(points):
            records.append(_run_start(prob, k, t, opts, bool(soft_reqs), bool(hard_reqs)))
            if callback is not None:
                callback(records[-1])
    best, warnings = _choose(records, opts)
    return _certified(plants, model_blocks, soft_b, hard_b, best, records, warnings,
                      t_start, opts, stages)


def _choose(records, opts):
    warnings = []
    finite = [r for r in records if r.soft < np.inf and r.hard < np.inf]   # stabilised
    if not finite:
        best = records[0]
        msg = (f"no start stabilised every model ({len(records)} starts, at most "
               f"{opts.stab_max_iter} iterations each)")
        if opts.on_unstable == "raise":
            raise IterationLimitError(msg)
        logger.warning(msg)
        return best, [msg]
    feasible = [r for r in finite if r.hard <= 1.0]
    best = (min(feasible, key=lambda r: (r.soft, r.hard)) if feasible
            else min(finite, key=lambda r: r.hard))
    if best.stop == "iteration bound":
        warnings.append(f"the best start (#{best.index}) stopped at its iteration bound "
                        f"({opts.max_iter}): the values may still decrease")
        logger.info(warnings[-1])
    return best, warnings


def _each_block(block, theta) -> dict:
    """``{name: StateSpace}`` of the blocks that make up ``block`` at ``theta``."""
    parts = getattr(block, "blocks", None)
    if parts is None:
        return {block.name: block.ss(theta)}
    return {b.name: b.ss(t) for b, t in zip(parts, block._split(theta))}


def _certified(plants, model_blocks, soft_b, hard_b, best, records, warnings, t_start,
               opts, stages=()) -> SystuneResult:
    theta = best.theta
    Ks, CLs, stable = [], [], True
    soft_v = np.full((len(plants), len(soft_b[0])), np.inf)
    hard_v = np.full((len(plants), len(hard_b[0])), np.inf)
    for m, (G, block) in enumerate(zip(plants, model_blocks)):
        K = block.ss(theta)
        Ks.append(K)
        try:
            CL = lft(G, K)
        except IllPosedLoopError:
            CLs.append(None)
            stable = False
            continue
        CLs.append(CL)
        stable = stable and is_stable(CL)
        for values, reqs in ((soft_v, soft_b[m]), (hard_v, hard_b[m])):
            for i, r in enumerate(reqs):
                values[m, i] = float(r.certify(CL, G, K))
    hard = float(hard_v.max()) if hard_v.size else 0.0
    feasible = bool(stable and hard <= 1.0)
    if stable and not feasible:
        m, i = np.unravel_index(int(np.argmax(hard_v)), hard_v.shape)
        msg = (f"hard requirement {hard_b[m][i].name!r} not met on model {m}: certified "
               f"value {hard_v[m, i]:.6g} > 1")
        logger.warning(msg)
        warnings.append(msg)
    return SystuneResult(
        values=model_blocks[0].values(theta), theta=theta.copy(), K=tuple(Ks), CL=tuple(CLs),
        blocks=tuple(_each_block(b, theta) for b in model_blocks),
        soft=float(soft_v.max()) if soft_v.size else 0.0, hard=hard,
        soft_values=soft_v, hard_values=hard_v, feasible=feasible, stable=stable,
        starts=tuple(records), best=best.index, seconds=time.perf_counter() - t_start,
        warnings=tuple(warnings), stages=tuple(stages))
