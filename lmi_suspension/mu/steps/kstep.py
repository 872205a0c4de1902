"""The K-step of D-K: H∞ synthesis on the scaled plant.

:class:`HinfKStep` is :func:`~lmi_suspension.synthesis.hinfsyn` by ``MusynOptions.method``
with the heuristics that keep it accurate on D-scaled plants (each a named constant below
with the measurement that chose it): the LMI at a level led by SLICOT's certified
controller, the central controller as D-K's first iterate, Riccati on a Gramian-balanced
realization.  :class:`ConstrainedKStep` is the multi-objective LMI of
:func:`~lmi_suspension.synthesis.msyn`, with constraints riding along; :class:`GivenFirst`
puts a user's ``K0`` in the place of the first K-step.
"""

from __future__ import annotations

import logging
import warnings
from dataclasses import replace
from typing import NamedTuple

import control
import numpy as np

from ...errors import (DimensionError, InfeasibleError, LmiSuspensionError, ParameterError,
                       SolverError)
from ...lti.norms import hinfnorm
from ...lti.plant import GeneralizedPlant, lft
from ...umodel.blocks import BlockStructure
from . import DKSetup, KStep, certificates, mu_part

logger = logging.getLogger(__name__)

__all__ = ["HinfKStep", "ConstrainedKStep", "GivenFirst", "default_kstep",
           "KSTEP_RICCATI_PROBES"]

#: Suboptimal levels ``(1 + r) γ`` that the Riccati K-step also tries when its γ-optimal
#: controller certifies above its own γ (the formulas are ill-conditioned at the optimum).
KSTEP_RICCATI_PROBES = (1e-3, 3e-3, 1e-2, 3e-2, 0.1)
#: relative slack before a K-step counts as worse than keeping the previous controller
_KSTEP_RTOL = 1e-3
#: largest scaled plant on which method="best" falls back to the LMI K-step after Riccati
_LMI_FALLBACK_MAX_STATES = 30
#: level of the central controller that starts D-K with the LMI K-step, relative to the
#: first K-step's certified γ (:func:`_central_start`).  Distillation problem, 61-point
#: grid, default options otherwise (measured 2026-11-26, OpenBLAS Haswell / SkylakeX, one
#: thread): from the central controller at 1 % above, µ 0.9786 / 0.9795 after the D-scale
#: search (upper = lower bound), where the LMI's own first controller led to 1.035 /
#: 1.037; the central one at 0 % and 0.8 % above gave 0.9857 and 0.9838 before any search.
#: The whole default run (Haswell, one thread) at 0.3 / 1 / 2 / 5 % above: µ 0.9820 /
#: 0.9786 / 0.9774 / 0.9748 in 77 / 33 / 63 / 65 s: any of them beats the LMI's own
#: start, and 1 % was the fastest
_CENTRAL_START_RELAX = 0.01
#: the level of the LMI K-step above the γ certified for SLICOT's controller
#: (:func:`_level_led_lmi`)
_LEVEL_RELAX = 3e-3
#: Clarabel recoveries and reconstruction levels of that K-step's controller LMI: it
#: succeeded at its second attempt on 5 of 7 plants of a distillation run, and on the
#: other two further recoveries cost 9 s each and ended "infeasible" all the same.  Its
#: feasibility problem gets none: on 14 such plants it solved the same 11 without a
#: recovery, and where it failed (3 plants) it did so in 1.2-1.3 s instead of 4.4-4.8 s
#: with one (measured 2026-11-26)
_LEVEL_LED_RECOVERIES = 1
#: how that K-step builds its controller under the default K-step options.  At a fixed
#: level the feasibility problem's point is interior, and the explicit formulas
#: (``HinfsynOptions(controller="explicit")``) were kept at all 5 such K-steps of a
#: distillation run, each certified at its level, their poles at most 127-1012 rad/s (at
#: the γ optimum of ``hinfsyn``, on the plants of ``bench_hinfsyn.py`` with n = 4-22 at
#: its relaxation 5e-4, they were 490-7800 times the plant's fastest mode, within
#: ``hinfsyn``'s cap but up to 5 times the controller LMI's at n = 22, which is why
#: ``hinfsyn`` keeps the SDP; measured 2026-11-28).  Default
#: ``musyn`` on distillation, under every OpenBLAS kernel this CPU runs (Nehalem,
#: Sandybridge, Haswell, SkylakeX) on 1 and 2 threads: the same µ per row as with the
#: controller LMI (0.959417-0.959536), in 21.9-32.9 s instead of 26.1-44.1 s (measured
#: 2026-11-28, benchmarks/HISTORY.md)
_LEVEL_LED_CONTROLLER = "explicit"
#: the solver of the first LMI K-step's γ minimisation under the default K-step options.
#: With the structured solver (``hinfsyn``'s default since 2026-11-29; measured before
#: its feasibility tolerance, refinement and MINRES run of the next session) default
#: ``musyn`` on distillation ended at µ 0.959009-0.960169 over the 8 OpenBLAS kernel and thread
#: rows (above the 0.9600 target on one, a spread of 1.2e-3), with Clarabel's at
#: 0.959417-0.959536 (stop 54); the K-steps were 0.7 s of its 11-14 s either way
#: (measured 2026-11-29, ``../shared/tools/kernels python benchmarks/musyn_default.py``)
_KSTEP_GAMMA_SOLVER = "clarabel"


class HinfKStep:
    """H∞ synthesis by ``MusynOptions.method`` (:func:`_k_step`); the first iterate of the
    LMI route is the central controller just above its level (:func:`_central_start`).

    Parameters
    ----------
    setup : DKSetup
    """

    def __init__(self, setup: DKSetup):
        from ...synthesis.hinfsyn import _hinfsyn

        self.setup = setup
        self.hinfsyn = _hinfsyn  # hinfsyn with the Riccati search heuristics (probes)

    def __call__(self, PD, *, iteration: int, gamma_prev: float):
        s = self.setup
        syn = _k_step(self.hinfsyn, PD, s.nmeas, s.ncon, s.options, gamma_prev)
        if iteration == 1:
            syn = _central_start(self.hinfsyn, PD, s.nmeas, s.ncon, s.options, syn)
        return syn


class ConstrainedKStep:
    """The multi-objective LMI K-step (:func:`_constrained_k_step`): the Lyapunov scales
    of the first K-step (given or searched) are reused by the next ones."""

    def __init__(self, setup: DKSetup):
        self.setup = setup
        self.scales = setup.lyapunov_scales

    def __call__(self, PD, *, iteration: int, gamma_prev: float):
        s = self.setup
        syn = _constrained_k_step(PD, s.nmeas, s.ncon, s.options, s.struct, s.constraints,
                                  self.scales)
        self.scales = syn.lyapunov_scales
        return syn


def default_kstep(setup: DKSetup) -> KStep:
    """:class:`ConstrainedKStep` with constraints, :class:`HinfKStep` without."""
    return ConstrainedKStep(setup) if setup.constraints else HinfKStep(setup)


class GivenFirst:
    """A given controller in the place of the first K-step, ``kstep`` after it."""

    def __init__(self, given: "_GivenController", kstep: KStep):
        self.given, self.kstep = given, kstep

    def __call__(self, PD, *, iteration: int, gamma_prev: float):
        if iteration == 1:
            return self.given
        return self.kstep(PD, iteration=iteration, gamma_prev=gamma_prev)


class _GivenController(NamedTuple):
    """``musyn``'s ``K0`` in the place of the first K-step's result."""

    K: control.StateSpace
    gamma: float
    warnings: tuple = ("initial controller K0: no K-step",)


def initial_controller(K0, G: GeneralizedPlant, struct: BlockStructure,
                       constraints) -> _GivenController:
    """``K0`` checked against ``G`` (size, stability of the loop, constraints), with its
    certified norm on the µ channels."""
    from ...lti.checks import as_statespace

    K = as_statespace(K0, "K0")
    if (K.noutputs, K.ninputs) != (G.nu, G.ny):
        raise DimensionError(f"K0 must have {G.nu} outputs and {G.ny} inputs (u = K0 y), "
                             f"got {K.noutputs} x {K.ninputs}")
    CL_full = lft(G, K)
    p = np.linalg.eigvals(np.asarray(CL_full.A)) if CL_full.nstates else np.zeros(0)
    if not np.all(np.real(p) < 0):
        raise ParameterError(f"K0 does not stabilise P (closed-loop pole with real part "
                             f"{np.max(np.real(p)):.3g})")
    unmet = [c for c in certificates(constraints, CL_full) if not c.met]
    if unmet:
        raise ParameterError("K0 violates " + "; ".join(
            f"{c.name} ({c.achieved:.6g})" for c in unmet))
    return _GivenController(K, float(hinfnorm(mu_part(CL_full, struct))[0]))



def _constrained_k_step(PD, nmeas, ncon, opts, struct, constraints, scales):
    """The multi-objective LMI K-step: the scaled µ channels' H∞ norm minimised subject
    to ``constraints``.  The Lyapunov scales are searched on the first K-step and reused
    after (the search costs ~15 minimisations), searched again if they fail."""
    from ...synthesis.constraints import Channel, HinfBound
    from ...synthesis.multiobjective import msyn

    nz, nw = struct.shape_M
    objective = HinfBound(Channel(outputs=tuple(range(nz)), inputs=tuple(range(nw))),
                          name="scaled µ channels")
    if scales is not None:
        try:
            return _KStep(msyn(PD, nmeas, ncon, objective, constraints,
                               options=opts.hinfsyn_options, lyapunov_scales=scales))
        except (InfeasibleError, SolverError) as exc:
            logger.info("musyn: constrained K-step with the previous Lyapunov scales "
                        "failed (%s); searching them again", exc)
    return _KStep(msyn(PD, nmeas, ncon, objective, constraints,
                       options=opts.hinfsyn_options))


class _KStep:
    """A constrained K-step's result in the shape the loop reads (``K``, ``gamma``,
    ``warnings``)."""

    def __init__(self, res):
        self.K, self.gamma = res.K, res.objective
        self.warnings = res.warnings
        self.lyapunov_scales = res.lyapunov_scales



def _gramian_balanced(PD: control.StateSpace) -> control.StateSpace | None:
    """A balanced realization of the scaled plant (python-control ``balred`` at full
    order: the stable part balanced, states with negligible Hankel singular values
    dropped), or None when slycot fails.

    SLICOT's Riccati solver works on the realization it is given: on a D-scaled
    distillation plant (poles from 1e-6 to 2e3 rad/s, Riccati rcond ≈ 1e-11) it found no
    controller below γ ≈ 1.3 in the coordinates of the series connection, where the
    previous controller certifies 1.01; in balanced coordinates it returned a controller
    certifying 1.0099 (measured).
    """
    try:
        with warnings.catch_warnings():
            # slycot says when the minimal order is below the requested one
            warnings.simplefilter("ignore")
            return control.balred(PD, PD.nstates, method="truncate")
    except Exception as exc:  # slycot raises plain ValueError/ArithmeticError variants
        logger.info("musyn: no balanced realization of the scaled plant (%s)", exc)
        return None


#: levels, relative to the lowest level SLICOT achieved on a Gramian-balanced realization,
#: whose controllers are judged on the scaled plant itself (see :func:`_riccati_balanced`)
_BALANCED_LEVELS = (0.0, 3e-4, 1e-3, 3e-3)
#: level, relative to a point's own, of the SLICOT controller whose certified norm
#: checks each point the D-scale search accepts (:mod:`.dsearch`)
_CHECK_LEVEL = 1e-3
#: levels above the best point's, relative, whose SLICOT controllers the search certifies
#: (the lowest certified one is returned); at the level itself they are ill-conditioned.
#: They are designed on the scaled plant and on its balanced realization: near the
#: optimum SLICOT's controller misses its own level, by an amount that moves with the
#: OpenBLAS kernel.  At the same best point (level 0.970688, reached from one start on
#: Haswell and Sandybridge), the balanced realization's best controllers certified
#: +0.10 % and +0.99 % above it, the scaled plant's +0.10 % and +0.03 %: 0.9 % apart
#: between the kernels with the balanced realization alone, 0.07 % with both (measured
#: 2026-11-26).  The balanced one stays because on other scaled plants it is the only
#: one SLICOT solves near the optimum (:func:`_gramian_balanced`)
_SEARCH_LEVELS = (3e-4, 1e-3, 3e-3, 1e-2)


def _riccati_balanced(hinfsyn, PD, nmeas: int, ncon: int, options, *, probes: tuple = (),
                      bracket: tuple | None = None):
    """Riccati on a Gramian-balanced realization of ``PD``, judged on ``PD`` itself.

    Returns the balanced realization's :class:`HinfsynResult` with the controller kept,
    its certified γ, closed loop and poles on ``PD`` (``gamma_solver`` stays SLICOT's
    lowest achieved level); None when there is no balanced realization.  The
    bisection's own choice is certified on the balanced realization, which can be off
    near DC where the scaled plant has poles near 1e-6 rad/s: with the book's optimal
    D-scales, the controller at the lowest achieved level certifies 0.97401 on ``PD``
    but 1.0034 on the realization, and the bisection returned one certifying 0.97688
    on ``PD`` (measured 2026-11-24; the same code gave 0.97395 the day before).  So the
    controllers at a few levels just above that level are certified on ``PD`` too
    (SLICOT's suboptimal formulas, ``sb10ad`` job 4: a few milliseconds each) and the
    best one is kept.
    """
    plant = _gramian_balanced(PD)
    if plant is None:
        return None
    res = hinfsyn(plant, nmeas, ncon, method="riccati", options=options, probes=probes,
                  bracket=bracket)
    levels = [] if options.gamma is not None else \
        [res.gamma_solver * (1.0 + r) for r in _BALANCED_LEVELS]
    K, CL, gamma = _best_certified(hinfsyn, PD, (plant,), nmeas, ncon, options, levels,
                                   first=res.K)
    return replace(res, K=K, gamma=gamma, CL=CL, poles=np.linalg.eigvals(np.asarray(CL.A)),
                   controller_fastest_pole=(float(np.max(np.abs(np.linalg.eigvals(K.A))))
                                            if K.nstates else 0.0),
                   warnings=res.warnings + (
                       "Riccati on a Gramian-balanced realization of the scaled plant; "
                       f"certified {gamma:.6g} on the plant itself",))


def _best_certified(hinfsyn, PD, realizations, nmeas: int, ncon: int, options, levels, *,
                    first=None):
    """SLICOT's controllers of each of ``realizations`` (of ``PD``) at fixed ``levels``
    (and ``first``, if given), each certified on ``PD``: ``(K, CL, gamma)`` of the one
    with the lowest certified norm.  Raises the last error if none is found."""
    candidates = [] if first is None else [first]
    error = None
    for plant in realizations:
        for level in levels:
            try:
                candidates.append(hinfsyn(plant, nmeas, ncon, method="riccati",
                                          options=replace(options, gamma=level)).K)
            except LmiSuspensionError as exc:
                error = exc
    if not candidates:
        raise error if error is not None else ParameterError("no level to try")
    loops = [(lft(PD, K, nmeas, ncon), K) for K in candidates]
    gammas = [float(hinfnorm(CL)[0]) for CL, _ in loops]
    k = int(np.argmin(gammas))
    return loops[k][1], loops[k][0], gammas[k]


def _central_start(hinfsyn, P, nmeas: int, ncon: int, opts, syn):
    """The first iterate of D-K with the LMI K-step: the central controller at
    ``(1 + _CENTRAL_START_RELAX)`` times the level the LMI certified (SLICOT ``sb10ad``
    at that fixed γ), certified on ``P``; the LMI's own controller where it is not
    certified at that level or ``method`` is not ``"lmi"`` or γ is fixed.

    Among the controllers that achieve about the optimal γ, the D-step sees a different
    closed loop from each, and the D-K path depends on which (:func:`musyn`'s ``K0``).
    On the distillation problem the central (minimum-entropy) controller just above
    the optimum led the LMI K-steps that follow to µ 0.974-0.981 under every OpenBLAS
    kernel, against 1.035-1.037 from the LMI's own largest-margin controller
    (``_CENTRAL_START_RELAX``).  Every later K-step is the LMI's.
    """
    base = _kstep_options(opts)
    if opts.method != "lmi" or base.gamma is not None or not np.isfinite(syn.gamma):
        return syn
    level = float(syn.gamma) * (1.0 + _CENTRAL_START_RELAX)
    try:
        central = hinfsyn(P, nmeas, ncon, method="riccati", options=replace(base, gamma=level))
    except LmiSuspensionError as exc:
        logger.info("musyn: no central controller at %.6g (%s); the LMI's first controller",
                    level, exc)
        return syn
    if not central.gamma <= level * (1.0 + _KSTEP_RTOL):
        logger.info("musyn: the central controller at %.6g certifies %.6g; the LMI's first "
                    "controller", level, central.gamma)
        return syn
    return replace(central, warnings=tuple(central.warnings) + (
        f"first iterate: the central controller at {level:.6g} "
        f"({_CENTRAL_START_RELAX:.0%} above the LMI's certified {syn.gamma:.6g}), "
        f"certified {central.gamma:.6g}",))


#: where the K-step's γ minimisation starts (``HinfsynOptions.start``): the identity
#: frame, not hinfsyn's default Riccati frame.  On dkpy's distillation example
#: (``benchmarks/musyn_vs_dkpy.py``, default musyn, SkylakeX, 2026-12-03) the D-K path
#: from the Riccati frame ended at µ 0.9712 with 13 states (full order 0.9625, 11.2 s of
#: CPU), from the identity frame at 0.9600 with 15 (full order 0.9588, 12.5 s); on the
#: project's distillation plant (``benchmarks/musyn_default.py``) both 0.9611
_KSTEP_START = "identity"


def _kstep_options(opts):
    """The options of every K-step: the user's, or the bisection Riccati search with
    Clarabel's γ minimisation and the controller LMI after it (:data:`_KSTEP_GAMMA_SOLVER`;
    ``controller="sdp"``: at the γ optimum of a D-scaled plant the explicit formulas'
    poles are fast; the K-step at a fixed level takes ``_LEVEL_LED_CONTROLLER``
    instead)."""
    from ...synthesis import HinfsynOptions

    return (opts.hinfsyn_options if opts.hinfsyn_options is not None
            else HinfsynOptions(riccati_search="bisection", controller="sdp",
                                gamma_solver=_KSTEP_GAMMA_SOLVER, start=_KSTEP_START))


def _level_led_lmi(hinfsyn, PD, nmeas: int, ncon: int, base, controller: str = "sdp"):
    """The LMI K-step at a level fixed in advance: ``(1 + _LEVEL_RELAX)`` times the γ
    certified for SLICOT's controller (Riccati bisection, 0.03-0.15 s here); the
    controller is the LMI's (feasibility, then ``controller``: ``"explicit"``, the
    explicit formulas with the controller LMI where they fail, or ``"sdp"``, the
    controller LMI), certified on ``PD``.  Returns None where SLICOT finds no controller
    (the caller then runs the γ minimisation); raises :class:`SolverError` where the
    LMI finds none at the level within ``_LEVEL_LED_RECOVERIES`` recoveries.

    :func:`_k_step` passes ``controller=_LEVEL_LED_CONTROLLER`` (``"explicit"``) under
    the default K-step options, the user's choice otherwise: a feasibility problem's
    point is interior, not the γ optimum's, and the explicit formulas are well
    conditioned there.

    On the D-scaled plants of the distillation problem the γ minimisation is where the
    LMI K-step loses its time and its reproducibility (9-70 s on 22 states, γ 1.0113 to
    1.0298 on one plant across OpenBLAS kernels, measured 2026-11-26); at a level
    fixed by a certified controller only a feasibility problem is left.  Where even
    that fails, the γ minimisation is not tried: on the same problem it took 10-17 s
    per K-step there, and default ``musyn`` (8 OpenBLAS kernel and thread rows) ended
    at µ 0.9648-0.9772 in 25-75 s with it, at 0.9638-0.9727 in 19-43 s without it
    (D-K then goes on from the plain D-step's plant, or ends; the D-scale search then
    started from the best iterate; measured 2026-11-26).
    """
    try:
        ric = hinfsyn(PD, nmeas, ncon, method="riccati",
                      options=replace(base, riccati_search="bisection"))
    except LmiSuspensionError as exc:
        logger.info("musyn: no Riccati level for the LMI K-step (%s)", exc)
        return None
    if not np.isfinite(ric.gamma):
        return None
    level = float(ric.gamma) * (1.0 + _LEVEL_RELAX)
    try:
        res = hinfsyn(PD, nmeas, ncon, method="lmi",
                      options=replace(base, gamma=level, controller=controller,
                                      max_recoveries=min(int(base.max_recoveries),
                                                         _LEVEL_LED_RECOVERIES)),
                      feasibility_recoveries=0)
    except LmiSuspensionError as exc:
        raise SolverError(f"the LMI found no controller at {level:.6g}, "
                          f"{_LEVEL_RELAX:.1%} above the γ certified for SLICOT's "
                          f"controller ({ric.gamma:.6g}): {exc}") from exc
    return replace(res, warnings=tuple(res.warnings) + (
        f"LMI K-step at {level:.6g}, {_LEVEL_RELAX:.1%} above the γ certified for "
        f"SLICOT's controller ({ric.gamma:.6g})",))


def _k_step(hinfsyn, PD, nmeas: int, ncon: int, opts,
            gamma_prev: float = float("nan")):
    """H∞ synthesis on the scaled plant. With ``method="best"`` the Riccati route runs on
    the plant as given and diagonally balanced; unless one of them already certifies at
    or below ``gamma_prev`` (the previous controller's level), it runs on a
    Gramian-balanced realization and then the LMI route follows; the controller with the
    lowest γ *certified on* ``PD`` is kept: each fails on problems another solves
    (singular D12/D21 for Riccati; D-scaled plants with a slow weight pole, where the
    LMI's γ minimisation stalled (Clarabel's, measured 2026-11-26) and any Riccati
    variant can be the accurate one)."""
    base = _kstep_options(opts)
    probes = KSTEP_RICCATI_PROBES  # used by the Riccati route only
    if opts.method != "best":
        hint = gamma_prev if opts.method == "lmi" and np.isfinite(gamma_prev) else None
        if hint is not None and base.gamma is None and base.gamma_abort is None:
            # the previous controller achieves gamma_prev on PD: a γ minimisation that
            # stops above it has failed, and reconstructing around it only costs time
            # (an over-relaxed distillation plant: 53 s of failing controller LMIs,
            # 2026-11-25)
            base = replace(base, gamma_abort=hint * (1 + _KSTEP_RTOL))
        if opts.method == "lmi" and hint is not None and base.gamma is None:
            led = _level_led_lmi(hinfsyn, PD, nmeas, ncon, base,
                                 controller=_LEVEL_LED_CONTROLLER
                                 if opts.hinfsyn_options is None else base.controller)
            if led is not None:
                return led
        return hinfsyn(PD, nmeas, ncon, method=opts.method, options=base, probes=probes,
                       level_hint=hint)
    results, errors = [], []

    def previous_beaten() -> bool:
        return bool(results) and min(r.gamma for r in results) <= gamma_prev * (1 + _KSTEP_RTOL)

    for method, scale in (("riccati", False), ("riccati", True), ("riccati", "gramian"),
                          ("lmi", None)):
        options = replace(base, riccati_scale=scale is True) if method == "riccati" else base
        if scale == "gramian":
            if previous_beaten():
                continue  # only where the other two did not beat the previous controller
            try:
                found = _riccati_balanced(hinfsyn, PD, nmeas, ncon, options, probes=probes)
            except LmiSuspensionError as exc:
                errors.append(exc)
                continue
            if found is not None:
                results.append(found)
            continue
        if method == "lmi" and results and PD.nstates > _LMI_FALLBACK_MAX_STATES:
            # measured: 29 s at 30 states, 191 s at 40, and gigabytes of KKT data
            logger.info("musyn: no LMI fallback on a %d-state scaled plant", PD.nstates)
            break
        if method == "lmi" and results and base.gamma is None:
            if previous_beaten():
                # Riccati already improves on the previous controller; the LMI is the
                # fallback (on 22-state D-scaled plants its γ minimisation fails and
                # costs more than the rest of the iteration, measured on distillation)
                break
            # an LMI optimum far above a certified Riccati γ is a failed solve: stop early
            options = replace(base, gamma_abort=2.0 * min(r.gamma for r in results))
        try:
            res = hinfsyn(PD, nmeas, ncon, method=method, options=options, probes=probes)
        except LmiSuspensionError as exc:
            errors.append(exc)
            continue
        results.append(res)
    if not results:
        raise errors[0]
    # Riccati-led: a later route replaces an earlier one only when it certifies lower by
    # more than _KSTEP_RTOL (the LMI reconstructs 0.05 % above its optimum and would
    # otherwise win ties on the unscaled distillation plant, where the book's path
    # follows the Riccati controller: 1.0275 at iteration 2 against 1.057)
    best = results[0]
    for res in results[1:]:
        if res.gamma < best.gamma * (1 - _KSTEP_RTOL):
            best = res
    return best
