"""Multi-objective output-feedback synthesis by LMIs (Scherer, Gahinet & Chilali 1997).

One Lyapunov matrix is shared by every specification, so that H∞ and H2 norms, peak
(generalized H2) bounds and pole regions, each on its own channel, are jointly convex in
the change of variables ``(X, Y, Â, B̂, Ĉ, D̂)`` (:mod:`.constraints`).  The synthesis:

1. minimises the objective's level subject to every specification (Clarabel through
   CVXPY, on the balanced plant of :func:`~lmi_suspension.lti.scaling.scale_plant`);
2. fixes the level ``(1 + level_relax)`` above that optimum and takes the point of
   largest common margin of all the inequalities inside a trace box: at the optimum
   ``I - XY`` is singular and the controller degenerates;
3. recovers the controller by the exact formulas and **certifies every specification on
   ``lft(P, K)`` alone** (closed-loop poles, ``hinfnorm``, Gramians); a specification
   violated beyond ``cert_rtol`` is an error, never a silent result.

The common Lyapunov matrix makes the result conservative for several specifications (the
price of convexity); for one H∞ objective alone it is :func:`hinfsyn`'s LMI.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, replace

import control
import cvxpy as cp
import numpy as np

from ..errors import InfeasibleError, ParameterError, SolverError
from ..lti.checks import as_statespace
from ..lti.plant import GeneralizedPlant, lft
from ..lti.scaling import scale_plant, transform_states
from . import lmi as _lmi
from .checks import check_stabilizable
from .constraints import Channel, H2Bound, HinfBound, LmiVariables, PeakBound, Specification
from .result import HinfsynOptions

__all__ = ["MultiobjectiveResult", "SpecificationCertificate", "msyn", "h2hinfsyn"]

logger = logging.getLogger(__name__)

#: relative level above the optimum at which the controller is reconstructed (the
#: common-Lyapunov LMIs have no frame machinery yet; 1e-3 reconstructed every test plant)
_LEVEL_RELAX = 1e-3
#: weight of the inequalities' common margin against the coupling's, as in ControllerLmi
_SLACK_WEIGHT = 0.1
#: trace box of the reconstruction, relative to the trace of the minimisation's solution
_TRACE_BOX = 10.0
#: minimisations repeated in the frame of the last one (as hinfsyn's frame rounds)
_FRAME_ROUNDS = 3
#: the cap of the second frame of the reconstruction (hinfsyn's _NARROW_SIGMA_CAP)
_NARROW_SIGMA_CAP = 100.0
#: reconstruction attempts (level relaxed 4x, trace box 10x wider each time)
_RECONSTRUCTION_STEPS = 4
#: the certificate may exceed the LMI level by this much before the result is an error
_CERT_RTOL = 5e-3
#: a reconstruction this far above the optimum gets a warning in the result
_FAR_ABOVE = 1e-2
#: the constraints are reported infeasible when their largest common margin (scaled
#: data, trace box xy_bound) is below this
_FEASIBLE_MARGIN = 1e-7


@dataclass(frozen=True)
class SpecificationCertificate:
    """One specification of a result, certified on the closed loop alone.

    Attributes
    ----------
    name : str
    bound : float or None
        What was asked (``None`` for a pole region, whose value is a signed distance).
    lmi_level : float or None
        The level the LMIs guaranteed (the objective's optimum for the objective).
    achieved : float
        The returned controller's value, computed without the LMI variables (for a peak
        bound: the largest ratio of peak to bound; for a region: the largest signed
        distance of a pole from it, negative inside).
    met : bool
    """

    name: str
    bound: float | None
    lmi_level: float | None
    achieved: float
    met: bool


@dataclass(frozen=True)
class MultiobjectiveResult:
    """Result of :func:`msyn`; unpacks as ``K, CL, objective, info``.

    ``objective`` is the objective's certified value on ``CL`` (for an H2 objective the
    H2 norm, not its square); ``objective_lmi`` is the LMI optimum (same units): the
    lowest level that the common Lyapunov matrix (each norm constraint's scaled by its
    ``lyapunov_scales`` entry) guarantees together with every constraint.  Alone it is
    the objective's optimum; with constraints it is an upper bound on the returned
    controller's value, which may be lower.
    """

    K: control.StateSpace
    CL: control.StateSpace
    objective: float
    objective_lmi: float
    certificates: tuple
    poles: np.ndarray
    status: str
    seconds: float
    warnings: tuple = ()
    lyapunov_scales: tuple = ()

    def __iter__(self):
        return iter((self.K, self.CL, self.objective, self))


def _variables(Ps: GeneralizedPlant, scale=None) -> LmiVariables:
    n, nu, ny = Ps.nstates, Ps.nu, Ps.ny
    return LmiVariables(Xh=cp.Variable((n, n), symmetric=True),
                        Yh=cp.Variable((n, n), symmetric=True),
                        Ah=cp.Variable((n, n)), Bh=cp.Variable((n, ny)),
                        Ch=cp.Variable((nu, n)), Dh=cp.Variable((nu, ny)), data=Ps.blocks(),
                        scale=scale, dt=Ps.dt)


def _controller(v: LmiVariables) -> control.StateSpace:
    """The controller of the change of variables (``N = I``, ``Mᵀ = I - XY``)."""
    d = v.data
    A, B2, C2 = d["A"], d["B2"], d["C2"]
    X, Y, Ah, Bh, Ch, Dk = v.values()
    n = A.shape[0]
    MT = np.eye(n) - X @ Y
    Bk = Bh - X @ B2 @ Dk
    Ck = np.linalg.solve(MT.T, (Ch - Dk @ C2 @ Y).T).T
    inner = Ah - X @ B2 @ Ck @ MT - Bk @ C2 @ Y - X @ (A + B2 @ Dk @ C2) @ Y
    Ak = np.linalg.solve(MT.T, inner.T).T
    return control.ss(Ak, Bk, Ck, Dk, v.dt)


def _level_of(spec) -> str:
    return "squared" if getattr(spec, "squared", False) else "linear"


def msyn(P, nmeas: int, ncon: int, objective: Specification, constraints=(), *,
         options: HinfsynOptions | None = None,
         lyapunov_scales=None) -> MultiobjectiveResult:
    """Multi-objective output-feedback synthesis: minimise one specification's level
    subject to the others.

    Parameters
    ----------
    P : control.StateSpace or GeneralizedPlant
        Generalized plant (controls last inputs, measurements last outputs), continuous-
        or discrete-time (see :mod:`.constraints` for the specifications built in
        discrete time); ``D22`` must be zero.
    nmeas, ncon : int
    objective : HinfBound or H2Bound
        Its ``bound`` is ignored: its level is minimised.
    constraints : sequence of Specification
        :class:`~.constraints.HinfBound`, :class:`~.constraints.H2Bound`,
        :class:`~.constraints.PeakBound`, :class:`~.constraints.HalfPlane`,
        :class:`~.constraints.Disk`, :class:`~.constraints.Sector`, or a class of one's own
        with the same two methods (:class:`~.constraints.Specification`).  Norm bounds
        refer to the plant's own units.
    options : HinfsynOptions, optional
        Clarabel's tolerances and iteration bound, ``xy_bound``, ``max_recoveries``.
    lyapunov_scales : sequence of float, optional
        One per constraint: the scale ``alpha`` of the Lyapunov matrix with which each
        norm constraint enters (``alpha P``, ``P`` the common matrix; ignored for pole
        regions, and for specifications of one's own unless they declare
        ``lyapunov_scalable``).  By default each is searched, over
        six decades, for the lowest objective; a result's ``lyapunov_scales`` can be
        passed back to skip that search in a sweep of nearby problems.

    Returns
    -------
    MultiobjectiveResult

    Raises
    ------
    InfeasibleError
        No controller meets the constraints (naming them).
    SolverError
        Clarabel failed, or a returned controller violates a specification beyond the
        certificate tolerance.

    Examples
    --------
    >>> from lmi_suspension.lti import GeneralizedPlant
    >>> from lmi_suspension.synthesis.constraints import HinfBound, HalfPlane
    >>> P = GeneralizedPlant.from_matrices(A=[[1.0]], B1=[[1.0, 0.0]], B2=[[1.0]],
    ...     C1=[[1.0], [0.0]], C2=[[1.0]], D12=[[0.0], [1.0]], D21=[[0.0, 1.0]])
    >>> K, CL, gamma, info = msyn(P, 1, 1, HinfBound(), [HalfPlane(alpha=0.5)])
    >>> all(c.met for c in info.certificates)
    True
    """
    t0 = time.perf_counter()
    G = GeneralizedPlant.from_statespace(
        P if isinstance(P, GeneralizedPlant) else as_statespace(P, "P", discrete=True),
        nmeas, ncon, discrete=True)
    if np.any(G.blocks()["D22"]):
        raise ParameterError("msyn needs D22 = 0 (loop shifting is not implemented here)")
    return _synthesise(G, objective, constraints, options, lyapunov_scales, _OUTPUT_FEEDBACK,
                       t0)


@dataclass(frozen=True)
class _Form:
    """What distinguishes a controller structure in :func:`_synthesise`: its LMI
    variables (``variables(plant, scale)``, with the interface of
    :class:`~.constraints.LmiVariables`) and the controller of a solution
    (``controller(v, specs)``, of the scaled plant)."""

    variables: object
    controller: object


def _output_feedback_controller(v: LmiVariables, specs) -> control.StateSpace:
    if not v.dt:  # a discrete H2 norm allows a feedthrough
        _zero_feedthrough(v, specs)
    return _controller(v)


_OUTPUT_FEEDBACK = _Form(_variables, _output_feedback_controller)


def _synthesise(G: GeneralizedPlant, objective, constraints, options, lyapunov_scales,
                form: _Form, t0: float, *, level_relax: float = _LEVEL_RELAX
                ) -> MultiobjectiveResult:
    """The body of :func:`msyn` and :func:`~.statefeedback.msfsyn`: minimise, frame
    rounds, reconstruction ladder, certificates; ``level_relax`` is the relative level
    above the optimum of the reconstruction's first rung (``hinfsyn`` on a discrete plant
    passes its ``gamma_relax``)."""
    opts = HinfsynOptions() if options is None else options
    specs = list(constraints)
    for s in [objective, *specs]:
        if not isinstance(s, Specification):
            raise ParameterError(f"{s!r} is not a specification (it needs name, lmis and "
                                 "certify)")
    if not isinstance(objective, (HinfBound, H2Bound)):
        raise ParameterError("the objective must be an HinfBound or an H2Bound")
    for s in specs:
        if isinstance(s, (HinfBound, H2Bound)) and not (s.bound and s.bound > 0):
            raise ParameterError(f"{s.name} constraint needs a positive bound")
    if G.nstates == 0:
        raise ParameterError("msyn needs a plant with states")
    # the balanced plant with its inputs and outputs normalised; every norm scales by the
    # common factor f = cw / cz, which the bounds are converted with
    Ps, sc = scale_plant(G)
    check_stabilizable(Ps)
    n = Ps.nstates
    margin = opts.margin
    # Index 0 is the objective, k the constraint k - 1.  Every norm constraint is written
    # for its channel's outputs divided by their own size in the balanced plant, so that
    # its level is of order one: the plant's common output scaling is set by its largest
    # rows, and on the seat the stroke row is 1e-3 of the acceleration row -- its squared
    # H2 level (4e-10) sat below Clarabel's tolerances and the stroke's peak bound left no
    # strictly feasible point.  The objective keeps the plant's own scaling: its level is
    # a variable, and H∞ alone must stay hinfsyn's LMI (normalised, COMPleib HE1 needed a
    # recovery in every round under OpenBLAS's SkylakeX kernel, 2026-11-26).
    factor = [sc.gamma_factor] + [sc.gamma_factor / _channel_size(Ps, s) for s in specs]

    def scaled_level(k, spec, value):
        x = value * factor[k]
        return x**2 if _level_of(spec) == "squared" else x

    def scaled_spec(k, spec):
        if isinstance(spec, PeakBound):
            return PeakBound(spec.channel, tuple(b * factor[k] for b in spec.bounds),
                             spec.name)
        return spec

    # and each norm constraint's channel gets a scale of its own Lyapunov matrix,
    # alpha P (the common matrix of Scherer et al. is P for every specification, and the
    # levels of different specifications weigh it differently): equivalent to the channel
    # with its inputs times sqrt(alpha) and its outputs divided by it -- the same transfer
    # function, another LMI.  alpha is searched per constraint (_search_alpha) unless
    # given
    alpha = [1.0] + _given_scales(lyapunov_scales, specs)

    def view(v, k, spec):
        if k == 0 or not _scalable(spec):
            return v
        r = np.sqrt(alpha[k])
        return v.with_channel_scaled(spec.channel.rows(Ps.nz),
                                     factor[k] / sc.gamma_factor / r,
                                     spec.channel.cols(Ps.nw), r)

    def build(v, obj_level, slack, coupling, with_constraints=True, with_objective=True,
              only=None):
        cons = list(objective.lmis(view(v, 0, objective), obj_level, slack)) \
            if with_objective else []
        for k, s in enumerate(specs if with_constraints else (), start=1):
            if only is not None and k != only:
                continue
            lv = None if s.bound is None or isinstance(s, PeakBound) else \
                scaled_level(k, s, s.bound)
            cons += scaled_spec(k, s).lmis(view(v, k, s), lv, slack)
        cons.append(v.calX >> coupling * np.eye(v.calX.shape[0]))
        return cons

    def minimise(frame, with_constraints=True):
        """The objective's optimum in ``frame`` (the plant in its coordinates, the
        variables relative to its scale): ``(level, Y, X, clean)`` or None if
        infeasible."""
        Pf = transform_states(Ps, frame.T)
        v = form.variables(Pf, frame.scale)
        level = cp.Variable(nonneg=True)
        cons = build(v, level, margin, margin, with_constraints)
        cons.append(v.lyapunov_trace <= opts.xy_bound * n)
        status, recoveries = _lmi._solve(cp.Problem(cp.Minimize(level), cons), opts,
                                         "multi-objective minimisation", warnings)
        if status in _lmi._INFEASIBLE or level.value is None:
            return None
        # the Lyapunov pair (Y, X) back in the coordinates of Ps, for the next frame
        Xb, Yb = v.values()[:2]
        Ti = np.linalg.inv(frame.T)
        clean = recoveries == 0 and status in _lmi._OK
        return float(level.value), frame.T @ Yb @ frame.T.T, Ti.T @ Xb @ Ti, clean

    def largest_margin(only=None):
        """The largest common margin of the constraints alone (or of constraint ``only``
        alone), None when Clarabel fails."""
        t = cp.Variable()
        v = form.variables(Ps, None)
        cons = build(v, None, _SLACK_WEIGHT * t, t, with_objective=False, only=only)
        cons += [v.lyapunov_trace <= opts.xy_bound * n, t <= 1.0]
        try:
            status, _ = _lmi._solve(cp.Problem(cp.Maximize(t), cons), opts,
                                    "multi-objective feasibility", warnings)
        except SolverError:
            status = None
        logger.info("msyn: constraints alone: status %s, margin %s", status, t.value)
        if status in _lmi._INFEASIBLE:
            return -np.inf
        return None if t.value is None or status not in _lmi._OK else float(t.value)

    def raise_if_infeasible(only=None):
        """InfeasibleError if the constraints alone (or constraint ``only`` alone) have no
        strictly feasible point."""
        tried = [largest_margin(only)]
        met = tried[0] is not None and tried[0] > _FEASIBLE_MARGIN
        if only is not None and _scalable(specs[only - 1]) and not met:
            # a constraint alone is met by the same controllers at every Lyapunov scale,
            # but the margin is not: on the seat's µ plant the stroke's peak bound (met
            # by the passive seat with 20 % to spare) had margin -1.5e-3 at scale 1 and
            # 0.42 at 1e5 (2026-11-25); so other scales are asked before "infeasible"
            kept = alpha[only]
            for a in _alone_scales(scaled_spec(only, specs[only - 1]), factor[only]):
                alpha[only] = a
                tried.append(largest_margin(only))
                if tried[-1] is not None and tried[-1] > _FEASIBLE_MARGIN:
                    break
            alpha[only] = kept
        best = max((m for m in tried if m is not None), default=None)
        if best is None or best > _FEASIBLE_MARGIN:
            return  # feasible, or Clarabel could not tell (the caller goes on)
        raise InfeasibleError(_infeasible_message(specs) + f" (largest common margin of "
                              f"the constraints alone: {best:.3g})")

    warnings: list[str] = []
    identity = _lmi.Frame.identity(n)
    first = identity
    searched = [k for k, s in enumerate(specs, start=1)
                if _scalable(s) and lyapunov_scales is None]
    # a constraint no controller meets fails here in one solve, not after a search or
    # a ladder of failed minimisations (the seat at 1 N / 0.01 m: 12 s before, 0.1 s
    # after, idle 2-core machine, 2026-11-25; with given scales on the seat's µ plant,
    # 165 s before).  Each alone: its own Lyapunov scale does not change its feasible
    # controllers, the relative scales of several do
    for k, s in enumerate(specs, start=1):
        if _scalable(s):
            raise_if_infeasible(only=k)
    if searched:
        # the search runs in the frame of the objective's optimum alone
        alone = minimise(identity, with_constraints=False)
        if alone is not None:
            first = _lmi.Frame.from_lyapunov(alone[1], alone[2])
            again = minimise(first, with_constraints=False)
            if again is not None and again[3]:
                alone = again
        start = -np.log10(alone[0]) if alone is not None and \
            _level_of(objective) == "linear" and alone[0] > 0 else 0.0
        for k in searched:
            outcomes: list = []
            _search_alpha(lambda a, k=k: _level_at(alpha, k, a, minimise, first, outcomes),
                          start)
            if not any(isinstance(x, float) for x in outcomes):
                if "infeasible" in outcomes:
                    raise InfeasibleError(_infeasible_message(specs))
                # Clarabel failed at every scale: whether it reports a far too tight bound
                # infeasible or fails depends on the BLAS kernel (a peak bound of 1e-9
                # under Haswell, 2026-11-25), the largest common margin does not
                raise_if_infeasible()
                raise SolverError(f"multi-objective minimisation: Clarabel failed for every "
                                  f"Lyapunov scale of {specs[k - 1].name}")
    found = minimise(first)
    if found is None and first is not identity:
        found = minimise(identity)
    rounds = [found]
    if found is None:
        raise InfeasibleError(_infeasible_message(specs))
    # frame rounds, as in hinfsyn: the minimisation again in the frame of its own
    # solution, while the optimum goes down by more than the reconstruction's relaxation.
    # A round that needed a recovery is kept as a candidate but not trusted as a bound:
    # on the seat plant (D21 small, cheap control) the second round went 2.42 -> 0.0254
    # after a recovery and is the one that matters; on COMPleib AC2 a recovered round
    # "found" 0.0519 where the optimum is 0.1115
    for _ in range(_FRAME_ROUNDS):
        try:
            nxt = minimise(_lmi.Frame.from_lyapunov(found[1], found[2]))
        except (SolverError, np.linalg.LinAlgError) as exc:
            warnings.append(f"frame round failed ({exc})")
            break
        logger.info("msyn: frame round %s -> %s (clean %s)", found[0],
                    None if nxt is None else nxt[0], None if nxt is None else nxt[3])
        if nxt is None or not nxt[0] < found[0] * (1 - level_relax):
            break
        rounds.append(nxt)
        found = nxt
    # the bound reported: the lowest optimum of a clean round
    clean = [r for r in rounds if r[3]]
    bound_level = min(r[0] for r in clean) if clean else None
    # reconstruction candidates, each with the optimum it reconstructs above and its trace
    # box: the rounds from the lowest optimum up, in their frames (the lowest one also
    # with its scalings capped), then the plant's own coordinates with the first optimum
    frames = []
    for k, (lvl, Y, X, _) in enumerate(sorted(rounds, key=lambda r: r[0])):
        fr = _lmi.Frame.from_lyapunov(Y, X)
        frames.append((fr, lvl, fr.trace))
        if k == 0:
            capped = replace(fr, cap=_NARROW_SIGMA_CAP)
            frames.append((capped, lvl, capped.trace))
    first = rounds[0]
    frames.append((_lmi.Frame.identity(n), first[0],
                   max(float(np.trace(first[1]) + np.trace(first[2])), 2 * n)))
    fo = factor[0]
    unscale = (lambda x: np.sqrt(x) / fo) if _level_of(objective) == "squared" else \
        (lambda x: x / fo)
    t = cp.Variable()
    done = None
    last = "no attempt"
    no_interior = True  # no rung so far found a strictly feasible point (or failed)
    # each rung: a solve, then the controller, its stability and every certificate; a
    # rung that fails any of them hands over to the next (COMPleib AC2 under OpenBLAS's
    # Sandybridge kernel left a closed-loop pole at +3.6e-12 in the first frame)
    for step in range(_RECONSTRUCTION_STEPS):
        for frame, base, trace in frames:
            target = base * (1 + level_relax * 4.0**step) + opts.gamma_atol
            v = form.variables(transform_states(Ps, frame.T), frame.scale)
            box = _TRACE_BOX * 10.0**step * trace
            cons = build(v, target, _SLACK_WEIGHT * t, t)
            cons += [v.lyapunov_trace <= box, t <= 1.0]
            try:
                status, _ = _lmi._solve(cp.Problem(cp.Maximize(t), cons), opts,
                                        "multi-objective reconstruction", warnings, refine=True)
            except SolverError as exc:
                last = f"reconstruction at {target:.6g} (scaled) failed: {exc}"
                warnings.append(last)
                continue
            if status in _lmi._INFEASIBLE or t.value is None or t.value <= 0:
                last = f"reconstruction at {target:.6g} (scaled): no strictly feasible point"
                warnings.append(last)
                continue
            no_interior = False
            K = sc.controller_to_original(form.controller(v, [objective, *specs]))
            CL = lft(G, K)
            poles = np.linalg.eigvals(np.asarray(CL.A))
            if not _stable(poles, Ps.dt):
                last = (f"reconstruction at {target:.6g} (scaled): the controller does not "
                        f"stabilise the plant (poles {_worst(poles, Ps.dt)})")
                warnings.append(last)
                continue
            certs = [_certify(objective, CL, None, unscale(target))]
            certs += [_certify(s, CL, s.bound, s.bound) for s in specs]
            bad = [c for c in certs if not c.met]
            if bad:
                last = "the controller violates " + "; ".join(
                    f"{c.name} (achieved {c.achieved:.6g}, bound "
                    f"{c.bound if c.bound is not None else c.lmi_level:.6g})" for c in bad)
                warnings.append(f"reconstruction at {target:.6g} (scaled): {last}")
                continue
            done = (K, CL, poles, certs, status)
            break
        if done is not None:
            break
    if done is None and no_interior:
        # no rung had a strictly feasible point: ask the constraints alone
        raise_if_infeasible()
    if done is None:
        raise SolverError(f"multi-objective synthesis: no certified controller after "
                          f"{_RECONSTRUCTION_STEPS} relaxations (last: {last})")
    K, CL, poles, certs, status = done
    lmi_level = unscale(bound_level) if bound_level is not None else float("nan")
    if bound_level is None:
        warnings.append("every minimisation needed a solver recovery: no LMI lower bound "
                        "is reported (objective_lmi is nan)")
    elif certs[0].lmi_level > lmi_level * (1 + _FAR_ABOVE):
        # every rung near the optimum failed: typically an infimum that no controller
        # attains (state feedback on COMPleib AC2: a mode at s = 0 that z does not see,
        # the controllers near the optimum leave a closed-loop pole at -7e-7)
        # (an optimum of 0, an H2 level on the discrete plants of tests/test_discrete.py,
        # has no relative distance)
        above = (f"{certs[0].lmi_level / lmi_level - 1:.1%} above" if lmi_level > 0
                 else "above")
        warnings.append(f"the controller was reconstructed at {certs[0].lmi_level:.6g}, "
                        f"{above} the LMI optimum "
                        f"{lmi_level:.6g}: the optimum may not be attained (slowest "
                        f"closed-loop pole {_worst(poles, Ps.dt)})")
    elif not specs and certs[0].achieved < lmi_level * (1 - _CERT_RTOL):
        # (with constraints the controller's own norm may well be below the level that
        # the common Lyapunov matrix guarantees)
        warnings.append(f"the certified objective {certs[0].achieved:.6g} is below the LMI "
                        f"optimum {lmi_level:.6g}: the minimisation was inaccurate")
    return MultiobjectiveResult(K=K, CL=CL, objective=certs[0].achieved,
                                objective_lmi=lmi_level, certificates=tuple(certs),
                                poles=poles, status=str(status),
                                seconds=time.perf_counter() - t0, warnings=tuple(warnings),
                                lyapunov_scales=tuple(float(a) for a in alpha[1:]))


_CHANNEL_SPECS = (HinfBound, H2Bound, PeakBound)


def _stable(poles: np.ndarray, dt: float) -> bool:
    return bool(np.all(np.abs(poles) < 1)) if dt else bool(np.all(poles.real < 0))


def _worst(poles: np.ndarray, dt: float) -> str:
    """The slowest pole, as a figure for a message."""
    if not poles.size:
        return "none"
    return f"max |z| {np.max(np.abs(poles)):.12g}" if dt else f"max Re {np.max(poles.real):.3g}"


def _scalable(spec) -> bool:
    """Whether ``spec`` takes a Lyapunov scale of its own: the norm specifications, and
    one's own with a ``channel`` that declares ``lyapunov_scalable = True``."""
    return isinstance(spec, _CHANNEL_SPECS) or (
        getattr(spec, "lyapunov_scalable", False) and isinstance(getattr(spec, "channel", None),
                                                                 Channel))


#: the Lyapunov scale of a norm constraint is searched over log10(alpha) in
#: start +- _ALPHA_DECADES (start = -log10 of the objective's optimum alone, where the
#: objective's bounded-real inequality, divided by its level, is the constraint's own
#: form): first on a grid of one decade, then by golden section around the best point.
#: On the seat (H∞ of the acceleration, peak bounds 1500 N and 0.08 m, channels in their
#: own units) the LMI optimum was 96 at alpha = 10, 30.4 at 100 and 121 at 1000 (at 1
#: every minimisation needed a solver recovery; its controller certified 52.8), 28.9
#: after the search; the objective alone is 23.2 (2026-11-26)
_ALPHA_DECADES = 3
_ALPHA_GOLDEN_STEPS = 8


def _infeasible_message(specs) -> str:
    def asked(s):
        if isinstance(s, PeakBound):
            return " <= (" + ", ".join(f"{b:g}" for b in s.bounds) + ")"
        return f" <= {s.bound:g}" if s.bound else ""

    names = ", ".join(f"{s.name}{asked(s)}" for s in specs)
    return (f"no controller meets the constraints ({names or 'none'}) with a common "
            "Lyapunov matrix")


#: decades (relative to the level's own scale) at which a constraint alone is asked
#: before it counts as infeasible (see raise_if_infeasible)
_ALONE_DECADES = (0.0, -2.0, 2.0, -4.0, 4.0)


def _alone_scales(spec, factor: float) -> list:
    """Lyapunov scales at which a norm constraint alone is asked: around the one that
    makes its scaled level of order one (``1/b²`` for a peak bound ``b``, ``1/level``
    otherwise), whatever the balanced plant's units."""
    if isinstance(spec, PeakBound):
        centre = 1.0 / min(spec.bounds) ** 2
    else:
        x = spec.bound * factor
        centre = 1.0 / (x**2 if _level_of(spec) == "squared" else x)
    return [centre * 10.0**d for d in _ALONE_DECADES]


def _given_scales(scales, specs) -> list:
    if scales is None:
        return [1.0] * len(specs)
    scales = [float(a) for a in scales]
    if len(scales) != len(specs) or not all(np.isfinite(a) and a > 0 for a in scales):
        raise ParameterError(f"lyapunov_scales must be {len(specs)} positive numbers (one "
                             f"per constraint), got {scales!r}")
    return scales


def _level_at(alpha: list, k: int, a: float, minimise, frame, outcomes: list) -> float:
    """The objective's optimum with constraint ``k``'s Lyapunov scale set to ``a`` (inf when
    infeasible or when the solver fails: ``outcomes`` collects the value, or
    ``"infeasible"``, or ``"failed"``); leaves ``alpha`` at ``a``."""
    alpha[k] = a
    try:
        found = minimise(frame)
    except SolverError:
        outcomes.append("failed")
        return np.inf
    if found is None:
        outcomes.append("infeasible")
        return np.inf
    # a level after a recovery or an inaccurate solve still orders the scales: it only
    # chooses the LMI, whose rounds are graded (and its controller certified) later
    outcomes.append(found[0])
    return found[0]


def _search_alpha(level, start: float) -> float:
    """Minimise ``level(10**x)`` over ``x`` near ``start``; leaves the best ``alpha``
    set (the last call) and returns it."""
    xs = start + np.arange(-_ALPHA_DECADES, _ALPHA_DECADES + 1, dtype=float)
    vals = [level(10.0**x) for x in xs]
    k = int(np.argmin(vals))
    best = (vals[k], xs[k])
    if np.isfinite(best[0]):
        a, b = xs[max(k - 1, 0)], xs[min(k + 1, len(xs) - 1)]
        g = (np.sqrt(5) - 1) / 2
        c1, c2 = b - g * (b - a), a + g * (b - a)
        f1, f2 = level(10.0**c1), level(10.0**c2)
        for _ in range(_ALPHA_GOLDEN_STEPS):
            best = min(best, (f1, c1), (f2, c2))
            if f1 < f2:
                b, c2, f2 = c2, c1, f1
                c1 = b - g * (b - a)
                f1 = level(10.0**c1)
            else:
                a, c1, f1 = c1, c2, f2
                c2 = a + g * (b - a)
                f2 = level(10.0**c2)
        best = min(best, (f1, c1), (f2, c2))
    level(10.0**best[1])
    return 10.0**best[1]


def _channel_size(Ps: GeneralizedPlant, spec) -> float:
    """The size ``‖[C1 D11 D12]‖₂`` of a norm specification's outputs in the balanced
    plant (1 for other specifications and for outputs that are identically zero)."""
    if not _scalable(spec):
        return 1.0
    d = Ps.blocks()
    rows, cols = spec.channel.rows(Ps.nz), spec.channel.cols(Ps.nw)
    size = np.linalg.norm(np.hstack([d["C1"][rows], d["D11"][np.ix_(rows, cols)],
                                     d["D12"][rows]]), 2)
    return float(size) if size > 0 else 1.0


def _zero_feedthrough(v: LmiVariables, specs) -> None:
    """Project ``D̂`` onto ``{D̂ : D12_j D̂ D21_j = 0}`` for every H2 and peak channel: the
    LMIs hold that equality only to the solver's tolerance, and any closed-loop
    feedthrough, however small, makes those norms infinite.  The inequalities have a
    margin, so the projection (of the order of the tolerance) keeps them."""
    d = v.data
    maps = []
    for s in specs:
        if isinstance(s, (H2Bound, PeakBound)):
            rows, cols = s.channel.rows(d["C1"].shape[0]), s.channel.cols(d["B1"].shape[1])
            # vec(D12 D̂ D21) = (D21ᵀ ⊗ D12) vec(D̂)  (column-major vec)
            maps.append(np.kron(d["D21"][:, cols].T, d["D12"][rows]))
    if not maps:
        return
    import scipy.linalg

    N = scipy.linalg.null_space(np.vstack(maps))  # exactly empty when D̂ must be 0
    Dh = np.asarray(v.Dh.value)
    vec = N @ (N.T @ Dh.reshape(-1, order="F")) if N.size else np.zeros(Dh.size)
    v.Dh.value = vec.reshape(Dh.shape, order="F")


def _certify(spec, CL, bound, level) -> SpecificationCertificate:
    achieved = float(spec.certify(CL))
    if isinstance(spec, PeakBound):
        met = achieved <= 1 + _CERT_RTOL  # a ratio to the bounds
    elif getattr(spec, "bound", None) is None and not isinstance(spec, (HinfBound, H2Bound)):
        met = achieved < 0  # a region: signed distance
    else:
        met = achieved <= level * (1 + _CERT_RTOL)
    return SpecificationCertificate(spec.name, bound, level, achieved, bool(met))


def h2hinfsyn(P, nmeas: int, ncon: int, nz2: int, W=(1.0, 0.0), *, regions=(),
              options: HinfsynOptions | None = None):
    """Mixed H2/H∞ synthesis with MATLAB's conventions.

    The last ``nz2`` performance outputs (just above the measurements) form the H2
    channel, the others the H∞ channel, both driven by all of ``w``.  ``W = (w_inf,
    w_2)`` weighs the objective ``w_inf ‖T∞‖∞² + w_2 ‖T2‖₂²`` (squared norms, so that the
    combination stays convex in the LMI levels).  ``regions``: pole regions of the
    closed loop (:class:`~.constraints.HalfPlane`, :class:`~.constraints.Disk`,
    :class:`~.constraints.Sector`).

    Returns
    -------
    K, CL : control.StateSpace
    normz : tuple of float
        ``(‖T∞‖∞, ‖T2‖₂)`` certified on ``CL``.
    info : MultiobjectiveResult
        Of the last solve (its ``certificates`` hold both norms and the regions).
    """
    G = GeneralizedPlant.from_statespace(
        P if isinstance(P, GeneralizedPlant) else as_statespace(P, "P", discrete=True),
        nmeas, ncon, discrete=True)
    nz = G.nz
    if not (isinstance(nz2, (int, np.integer)) and 0 < nz2 < nz):
        raise ParameterError(f"nz2 must be between 1 and {nz - 1} (the H∞ channel needs "
                             f"outputs too), got {nz2!r}")
    w_inf, w_2 = (float(x) for x in W)
    if min(w_inf, w_2) < 0 or w_inf + w_2 <= 0:
        raise ParameterError(f"W must be two non-negative weights, not both zero, got {W!r}")
    inf_ch = Channel(outputs=tuple(range(nz - nz2)))
    h2_ch = Channel(outputs=tuple(range(nz - nz2, nz)))
    if w_2 == 0:
        res = msyn(G, nmeas, ncon, HinfBound(inf_ch), list(regions), options=options)
    elif w_inf == 0:
        res = msyn(G, nmeas, ncon, H2Bound(h2_ch), list(regions), options=options)
    else:
        res = _weighted(G, nmeas, ncon, inf_ch, h2_ch, w_inf, w_2, regions, options)
    CL = res.CL
    normz = (float(HinfBound(inf_ch).certify(CL)), float(H2Bound(h2_ch).certify(CL)))
    return res.K, CL, normz, res


def _weighted(G, nmeas, ncon, inf_ch, h2_ch, w_inf, w_2, regions, options):
    """``min w_inf γ² + w_2 ν²`` as a scalar sweep: the Pareto point of that weighting is
    the minimiser over the H∞ bound γ of ``w_inf γ² + w_2 ν*(γ)²``, ``ν*`` the H2 optimum
    under ``‖T∞‖∞ <= γ`` (convex in γ), found by a bounded golden-section search.  Each
    point is judged by the certified norms of its controller, so the controller returned
    has the lowest certified weighted cost of all points tried."""
    hinf = msyn(G, nmeas, ncon, HinfBound(inf_ch), list(regions), options=options)
    lo = hinf.objective_lmi * (1 + 2 * _LEVEL_RELAX)
    free = msyn(G, nmeas, ncon, H2Bound(h2_ch), list(regions), options=options)
    hi = max(float(HinfBound(inf_ch).certify(free.CL)), lo * 1.01)

    scales: dict = {}  # the H∞ bound's Lyapunov scale, searched once, at the upper end

    def cost(gamma):
        try:
            r = msyn(G, nmeas, ncon, H2Bound(h2_ch), [HinfBound(inf_ch, gamma), *regions],
                     options=options, lyapunov_scales=scales.get("found"))
            scales.setdefault("found", r.lyapunov_scales)
        except (InfeasibleError, SolverError) as exc:
            # near the H∞ optimum the H2 channel's zero feedthrough and the common
            # Lyapunov matrix can leave nothing, or too little for the solver
            logger.info("h2hinfsyn: no point at ‖T∞‖∞ <= %.6g (%s)", gamma, exc)
            return np.inf, None
        # the certified norms of the controller this point returns: what the caller gets,
        # and always finite (objective_lmi is nan where every minimisation needed a solver
        # recovery, and a nan cost left the search at its first point: issue 41)
        g_cert = float(HinfBound(inf_ch).certify(r.CL))
        return w_inf * g_cert**2 + w_2 * float(r.objective)**2, r

    best = cost(hi)
    for _ in range(_BRACKET_DOUBLINGS):  # the common Lyapunov matrix is conservative
        if best[1] is not None:
            break
        hi *= 2.0
        best = cost(hi)
    else:
        raise InfeasibleError(f"no controller has a finite H2 norm with ‖T∞‖∞ <= {hi:.6g} "
                              "under a common Lyapunov matrix")
    best = min((best, cost(lo)), key=_cost_key)
    a, b = lo, hi
    g = (np.sqrt(5) - 1) / 2
    for _ in range(_GOLDEN_STEPS):
        c1, c2 = b - g * (b - a), a + g * (b - a)
        f1, f2 = cost(c1), cost(c2)
        best = min((best, f1, f2), key=_cost_key)
        if f1[0] < f2[0]:
            b = c2
        else:
            a = c1
    return best[1]


def _cost_key(c):
    """Order of ``(cost, result)`` pairs: the lowest cost, a result before none."""
    return (c[0], c[1] is None)


#: doublings of the upper end of that search until the mixed problem is feasible
_BRACKET_DOUBLINGS = 8
#: golden-section steps of the weighted mixed objective (the bracket shrinks to 0.6 %)
_GOLDEN_STEPS = 10
