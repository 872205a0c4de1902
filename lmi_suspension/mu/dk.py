"""µ-synthesis by D-K iteration (paper eqs. 23–31).

:func:`musyn` is a short loop over three exchangeable steps (:mod:`.steps`, each behind
a small protocol, built from the run's setup):

1. **K-step** — H∞ synthesis on the scaled plant ``P_D`` (:mod:`.steps.kstep`: LMI by
   default, Riccati, or the multi-objective LMI with constraints);
2. **D/G-step** — µ bounds of ``F_l(P, K)`` over the frequency grid and their optimal
   scalings (:mod:`.steps.dgstep`, :func:`mussv`);
3. **fit** — stable, minimum-phase rational fits of those scalings, absorbed into the
   next ``P_D`` (:mod:`.steps.fit`: D scalings for D-K; D and G scalings, realized
   exactly, for D-G-K).

The loop owns what compares iterates: the best one (lowest µ peak meeting every
constraint), patience, the stopping rules, and the certificates of each iterate (its
closed-loop poles, µ lower bound against its γ, constraints recomputed).  After the
first iterate, a direct search on the D-scale fit parameters with the K-step inside
(:mod:`.dsearch`), started from that iterate's D-step, goes on to a local minimum of the
bound where D-K stalls; the D-K iterations after it go on as without it, and stop once
``patience`` of them have not beaten the best so far, the search's included
(``dscale_search``).  The best iterate is returned, never a worse last one; its µ is certified on
a dense grid with the true structure (real blocks real), the grid peak refined with the
LMI bound (:func:`_final_bounds`) and bounded between grid points (``mu_bound``).
``MusynOptions(complexify=True)`` covers real blocks by complex discs in the loop.
"""

from __future__ import annotations

import copy
import logging
import time
from dataclasses import dataclass, field, replace
from typing import Callable

import control
import numpy as np

from ..errors import DimensionError, InfeasibleError, LmiSuspensionError, ParameterError
from ..lti.checks import as_finite_array, sample_time
from ..lti.norms import freqresp, hinfnorm
from ..lti.plant import GeneralizedPlant, lft
from ..lti.reduce import balanced_truncation
from ..lti.scaling import balanced_statespace
from ..umodel.blocks import BlockStructure
from .dsearch import search_dscales
from .interval import interval_bound
from .steps import DKSteps, block_sizes, certificates, mu_part
from .steps.kstep import (_CHECK_LEVEL, _KSTEP_RTOL, _SEARCH_LEVELS, _best_certified,
                          _gramian_balanced, _kstep_options)

logger = logging.getLogger(__name__)

__all__ = ["MusynOptions", "MusynIteration", "MusynResult", "musyn", "default_omega"]

#: slack of the check µ lower bound <= certified γ of an iterate (the µ bounds are
#: computed to about 1e-4 on the grid, and γ to 1e-9 by hinfnorm)
_BOUNDS_RTOL = 1e-3
#: the same for the returned loop on the dense grid, whose response is evaluated on a
#: balanced realization: on distillation it agreed with a 40-digit evaluation to 4e-5 at
#: 1.6e-8 rad/s, where the search's scaled loop was off by 0.4 % and its certified γ
#: 0.966751 fell below the loop's µ 0.967552 (``method="best"``, SkylakeX kernel, 2
#: threads; measured 2026-11-26)
_DENSE_BOUNDS_RTOL = 2e-4
#: slack of the interval certificate of the returned µ over its dense-grid peak
#: (``MusynResult.mu_bound``): on the distillation loops a fixed scaling certifies a
#: level 0.6 % above µ 1 % of frequency away from its point, so each 0.1 % of slack
#: saves splits (one LMI bound each)
_SUP_RTOL = 1e-3
#: splits of that certificate, where the scaled loop's γ does not already bound µ within
#: _SUP_RTOL: on distillation's returned loop 100 splits (12 s) left it 1.3 % above
#: the grid peak, where γ was 8e-5 above (measured 2026-11-27), so few are spent
_SUP_SPLITS = 20


def _bound_check(gamma: float, mu_lower: float, what: str,
                 rtol: float = _BOUNDS_RTOL) -> tuple[str, ...]:
    """A warning where the µ lower bound of an iterate exceeds the γ certified for it on
    its scaled plant: both cannot hold, so one certificate is wrong.  (A D-scale search
    certified 1.34 on a wrongly reduced scaled plant for a loop whose µ lower bound was
    50, 2026-11-25; that reduction is now refused, and this check stays as the
    independent witness.)"""
    if np.isfinite(gamma) and mu_lower > gamma * (1.0 + rtol):
        msg = (f"{what}: µ lower bound {mu_lower:.6g} exceeds the certified γ {gamma:.6g} "
               "on the scaled plant; one of the two certificates is wrong")
        logger.warning("musyn: %s", msg)
        return (msg,)
    return ()


@dataclass(frozen=True)
class MusynOptions:
    """Options of :func:`musyn` (frozen; derive variants with :func:`dataclasses.replace`).

    Attributes
    ----------
    max_iter : int
        Largest number of D-K iterations (each = one K-step, one D-step, one D-fit).
        The D-scale search (``dscale_search``) is not counted.
    mu_target : float
        Stop as soon as the µ peak falls below this value (``0`` never stops early).
    patience : int
        Stop after this many iterations without a relative improvement of at least
        ``min_improvement`` over the best peak so far, the D-scale search's included:
        by default D-K stops once ``patience`` iterates in a row have not beaten the
        search by ``min_improvement`` (an iterate's fast bound against the search's
        LMI-refined one, which can sit up to 0.06 % lower; ``dscale_search=0`` runs D-K
        alone, as MATLAB's ``musyn`` does).
    min_improvement : float
        Relative improvement that counts as progress.
    method : {"lmi", "riccati", "best"}
        K-step method of :func:`hinfsyn`; ``"best"`` runs the Riccati route on the scaled
        plant as given and balanced, then -- on the first iteration, or when no Riccati
        controller certifies at or below the previous controller's level on the new
        scaled plant -- the Riccati route on a Gramian-balanced realization and the LMI
        route (abandoned when its γ minimisation stops above
        twice a certified Riccati γ, and skipped on scaled plants of more than 30 states
        once Riccati has a controller), and keeps the controller with the lowest
        certified closed-loop γ.  From the second iteration on, the LMI K-step is
        posed at a level fixed in advance, 0.3 % above the norm certified for SLICOT's
        controller on the scaled plant (a feasibility problem only, then, under the
        default ``hinfsyn_options``, the explicit controller formulas, with the
        controller LMI where they fail their certificate or pole cap).  Where the LMI
        finds none there, the K-step fails.  Where SLICOT
        finds none at all, it minimises γ, knowing the previous controller's level on
        the new scaled plant: the minimisation starts in the frame of the Riccati
        solutions at that level and gives up where it stops above it (``gamma_abort``,
        unless the options set one).  Where a K-step fails on an
        over-relaxed plant, the plain D-step's plant is used instead (and the
        over-relaxation is halved, ``dscale_overrelax``); elsewhere D-K ends at the
        best iterate.  With
        ``"lmi"`` and no ``constraints`` or ``K0``, the first iterate is the central
        controller at 1 % above the level the first LMI K-step certified (SLICOT
        ``sb10ad`` at that fixed γ, certified on the plant; the LMI's own controller
        where it does not certify there): the D-K path depends on the controller the
        first D-step sees, and on the distillation problem this start led the LMI
        K-steps to µ 0.974-0.981 against 1.03 from the LMI's own.
    hinfsyn_options : HinfsynOptions or None
        Options passed to every K-step (default: ``HinfsynOptions`` with
        ``riccati_search = "bisection"``, ``gamma_solver = "clarabel"`` and
        ``controller = "sdp"`` for a γ minimisation, whose D-K path was the more
        reproducible across OpenBLAS kernels; the LMI K-step at a fixed level builds its
        controller by the explicit formulas where they pass their certificate and pole
        cap; the Riccati K-steps also try the suboptimal levels
        ``KSTEP_RICCATI_PROBES``).  Given options are used as they are: their
        ``controller`` (``"explicit"`` unless set) applies to every LMI K-step.
    max_dfit_order : int
        Largest order of each D-scale fit.
    dfit_rtol : float
        Automatic D-fit order selection: the lowest order whose rational scalings keep the
        scaled peak ``max_ω σ̄(D̂ M D̂⁻¹)`` within this relative tolerance of the µ peak.
    n_dense : int
        Number of frequencies over the design range of the dense grid on which the
        returned controller's µ is re-computed (the reported ``mu_peak``); the grid also
        extends, 4 points per decade, to three decades below the closed loop's slowest
        pole and two above its fastest, and holds 41 points around the design grid's
        peak and 8 between each of its three highest local maxima and their neighbours
        (added once the grid's bounds are known).  The default was 400 until
        2026-12-02: on default ``musyn``'s distillation loop 200 give the same peak
        (0.959582, a flat µ) at 1.7 s of CPU instead of 2.6 s.
    reduce_order : int, "auto" or None
        If an order, try a balanced truncation of the best controller to this order
        (its modes near and right of the axis kept whole) and keep it when its loop is
        stable, meets the constraints, and its µ stays within ``reduce_mu_tol``
        (relative) of the full-order dense-grid peak.  ``"auto"`` (the default): the
        least such order (found by bisection), so that the controller returned is one a
        loop can run.  In D-K without constraints an order is judged by the truncated
        controller's H∞ norm on the best iterate's D-scaled plant, one ``hinfnorm``
        each: the fitted D scalings are feasible at every frequency, so that norm bounds
        the truncated loop's µ at every frequency and is returned as ``mu_bound``.  It
        is conservative (the scalings are the full loop's), so the order below the
        least one it passes is judged by µ on the dense grid too, and the search goes on
        by µ where that passes; where no order passes the norm, and in D-G-K or with
        constraints, orders are judged by µ alone (an order kept by µ has its scaled
        norm as ``mu_bound`` where it was computed, else the interval bound's).  On
        dkpy's distillation example 15 states instead of 22 at µ 0.960037 (scaled norm
        0.960861) instead of 0.958751; the order search, the reduced loop's dense-grid µ
        and its all-frequency bound took 0.61 s of CPU where the dense-grid judgement and
        an interval bound took 2.6 s (a bound of 1.0239; measured 2026-12-02).  Twelve
        states cost more than 1 %: balanced truncation +2.76 % (µ on the dense grid),
        frequency-weighted truncations +2.3 % and more, a truncation polished on the
        scaled plant with its D scalings held +1.60 % (83 s of CPU); the trade-off is in
        ``docs/guide/dk.md``.  With real blocks (mixed µ) on the seat over m3 and k1
        (:data:`~lmi_suspension.seat.design.MIXED_MUSYN`, 2026-12-03): D-G-K's 31-state
        controller to 8 states at +0.12 % (OpenBLAS Haswell), the complexified run's
        13-state one to 7 at +0.70 % (SkylakeX), about 3 s of CPU for the search and the
        reduced loop's mixed certificate.  ``None``: the full-order controller.  The
        full-order controller is kept in :attr:`MusynResult.K_full` (and its µ in
        ``mu_peak_full``) whenever a reduction is kept.
    reduce_mu_tol : float
        Relative µ increase tolerated by the order reduction (default 1 %).
    stop_on_kstep_regression : bool
        Stop when a K-step's controller is worse on the scaled plant ``P_D`` than the
        previous controller (``gamma > gamma_prev`` by more than 0.1 %): an exact K-step
        never is, so the K-step has lost accuracy there and D-scales fitted to its
        controller lead away from the optimum.  The best iterate is returned either way.
    dscale_overrelax : float
        Over-relaxation ``α >= 1`` of the D-step: the D-scales fitted for the next K-step
        are ``|D̂_prev| (d / |D̂_prev|)^α`` (per block and frequency, ``d`` the µ
        upper bound's optimal scalings of the current loop, ``D̂_prev`` the fit the
        current controller was designed with).  Plain D-K iteration (``α = 1``) creeps
        along when the K-step leaves σ̄ of the scaled loop flat over a wide band
        (distillation: 0.2-0.5 % per iteration); extrapolating the change of the
        scalings moves faster.  Any stable, minimum-phase fit is a valid scaling, so the
        certificates are unchanged.  When an iterate is not the best so far, the next
        D-step starts again from the best iterate's own scalings (``α = 1`` once) and
        ``α`` is halved towards 1; if that restart does not beat the best iterate either,
        the step after it is a plain one from where the loop is.  ``α`` is halved as well
        where the K-step fails on an over-relaxed plant: on the distillation problem the
        LMI K-step failed on 3 over-relaxed plants in a row there, 2-3 s each (default
        ``musyn`` in 15-26 s with the halving, 18-32 s without, over 4 OpenBLAS kernels
        and 1 and 2 threads; measured 2026-11-26).
    dscale_search : int
        Right after the first D-K iterate, at most this many points (a K-step's level
        each) of a direct search on the parameters of the D-scale fits (order
        ``max_dfit_order``), started from the D-step of that iterate: a
        descent method for the piecewise-smooth level
        SLICOT's Riccati synthesis achieves on each scaled plant (BFGS on difference
        quotients, least-norm steps at kinks, every accepted point checked by a
        certified controller; :mod:`.dsearch`), the best point's controller certified at
        the end.  D-K stops where neither of its partial steps improves the bound,
        which is not a minimum of the bound over both (distillation: D-K settles near
        0.99-1.003, the book's optimal third-order scalings give 0.974).  The first
        iterate is the same on every machine, later ones are not (the LMI K-steps'
        controllers are not unique), and the search ends near a local minimum, which
        small differences of its path mostly lead back to: default ``musyn`` on
        distillation gave µ 0.959417-0.959536 under four OpenBLAS kernels and 1 and 2
        threads (the previous Nelder-Mead search from the best iterate:
        0.9636-0.9716).  Mostly, not always: on 51- and 71-point grids the Haswell and
        Sandybridge kernels ended in different local minima, 0.2 % and 0.5 % apart
        (measured 2026-11-26).  Blocks whose optimal scalings coincide share one fit.
        The search starts from the first iterate's D-step whatever D-K does after it,
        so it runs right then, and the D-K iterations after it go on as without it (it
        draws from its own copy of ``rng``) but measure their progress against it: D-K
        stops once ``patience`` iterates in a row have not beaten the best so far, the
        search's included, by ``min_improvement``.  So D-K goes on where it can still
        beat the search, and stops early where it cannot: on distillation the D-K
        iterates after the first never ended below the search (best recorded 0.9784
        and 0.9806 against 0.9594-0.9595, 2026-11-28) while their LMI K-steps cost
        1.1-14.8 s per run; on the seat's µ problem with fourth-order fits D-K's third
        iterate beat the search (design grid 0.6998 against 0.7024; dense grid 0.69996
        against 0.70450) and is returned (2026-11-29; benchmarks/HISTORY.md and
        ``benchmarks/musyn_problems.py``).  The search's record follows the D-K
        iterations, and the lowest µ of the loop is returned.  With ``complexify=True``
        that is complex µ, what the loop iterates on; the µ reported is mixed µ, which
        can order the candidates otherwise (complexified oscillator: the search's
        controller 1.1309, D-K alone's 1.1120).  ``0`` turns the search off.  Skipped
        for constant scalings (``max_dfit_order = 0``), with constraints, with real
        blocks kept real (D-G-K), and once ``mu_target`` is met; it stops as soon as an
        accepted level is below ``mu_target``, and where its best level has not fallen
        by 0.01 % over the points of three gradients (:mod:`.dsearch`; on distillation
        from dkpy's realization: 157 points, level 0.959188, where the 200 points of
        the bound reached 0.958984; measured 2026-12-02).  A level
        costs 11 (difference quotient) to 18 (trial step) syntheses of 2.5 ms on
        distillation's 22-state scaled plants, a trial point found above the current
        level one (measured 2026-11-28 and 2026-12-02).  Repeated-scalar blocks are searched with
        scalings ``d(s) I``, a restriction of their D matrices (still a valid bound).
    complexify : bool
        Treat real scalar blocks (``[-r, 0]``) as complex in the loop (complex D-K, the
        conservative cover of a real parameter by a disc), for comparison.  By default
        (``False``) they stay real: each D-step takes the central D-scalings of the
        mixed-µ bound at the peak level, fits them, and then chooses rational G-scalings
        of the real blocks for the bound itself (one SDP over the grid with the fitted D
        applied, :func:`~lmi_suspension.mu.gfit.optimal_gscales`), realized exactly and
        absorbed into the scaled plant (D-G-K, Young 1996; :mod:`.gfit`).  Either way
        the returned bounds use the true structure.  In D-G-K an iterate's ``gamma`` is
        the H∞ norm of its D-G-scaled plant, normalised by the level of those scalings
        (below 1 certifies that level; it is not itself a bound of µ), the D-steps are
        plain (``dscale_overrelax`` is not used) and there is no D-scale search; the
        per-frequency µ bounds with real blocks are LMIs, and each real block adds
        states to the scaled plant (three per basis pole, 9 to 30), so each iteration
        costs more than a complex one.  The K-step sees that plant balanced-truncated
        (error bound 0.01, where the previous controller's level on it stays within 2 %
        of the full plant's; :func:`.steps.fit.reduced_for_kstep`): on the two-mass
        plant its 34-38 states went to 23-30, the default run from 70 s to 37 s of CPU
        (µ 1.6089 with 25 states against 1.6140 with 36; 2026-12-02).  Measured on the oscillator of
        ``tests/test_dgk.py`` (±50 % real stiffness, 40-point grid, no D-scale search;
        2026-11-27): complex D-K ends at mixed µ 1.1326, D-G-K at 1.0069 (iteration 5;
        ``benchmarks/bench_dgk.py``, figures in ``docs/guide/dk.md``).
    complex_candidate : {"auto", "keep", "start"} or None
        D-G-K only (real blocks kept real): first run the complexified D-K
        (``complexify=True``, the same options; its D-scale search included, its
        dense-grid certificate not), then D-G-K, and return whichever controller
        certifies the lower mixed µ on the dense grid (the complexified one's mixed µ is
        first taken on the design grid, and on the dense grid only where D-G-K's
        certified peak is above its lower bound there).  The complex D is a feasible
        mixed scaling with G = 0, so the returned mixed µ is no higher than the
        complexified run's controller certifies.  ``"keep"``: D-G-K starts as without
        it (from the central controller, or ``K0``); ``"start"``: D-G-K starts from the
        complexified run's controller (its first iterate, as ``K0``).  Neither start wins
        everywhere (2026-12-03, ``docs/guide/dk.md``): on the two-mass plant
        (:func:`~lmi_suspension.examples.uncertain_two_mass`) D-G-K from the central
        controller reaches 1.6236 where from the complexified one no iterate beats that
        controller (1.7820 returned); on the seat over m3 and k1 the start from the
        complexified controller reaches 2.6063 against 2.7546 from the beginning; on the
        oscillator of ``tests/test_dgk.py`` both reach 0.9926 (complexified D-K: 1.7820,
        2.6760 and 1.1165).  ``stop_reason`` says which
        controller is returned (``best_iteration`` 0: the complexified run's; 1 where
        D-G-K started from it) and
        :attr:`MusynResult.complex_run` holds that run (its records do not go to
        ``callback``).  ``None``: D-G-K alone, which
        can end above complex D-K (the seat over m3 and k1: 2.734 against 2.671,
        2026-11-27; 2.7407 against 2.6711 on 2026-12-02, where ``"start"`` reaches
        2.6646 with 31 states; the two-mass plant weighted 1 and 1, with 10 G poles: 2.7340 against
        2.6355, its second K-step failing, 2026-12-02).  Re-measured with the reduced
        K-step plants and the direct G-scaling SDP (2026-12-02, ``benchmarks/HISTORY.md``):
        two-mass ``"keep"`` 1.6089 (25 states), ``"start"`` 1.7779 (the complexified
        controller; D-G-K's second iterate 1.8110); seat ``"keep"`` 2.6711 (the
        complexified controller; D-G-K's own 2.7546), ``"start"`` 2.6063 (31 states).
        Neither start wins on both.  ``"auto"`` (the default): D-G-K starts from the
        complexified controller, and goes on from there where one of its first
        ``_TRIAL_ITERATIONS`` iterates improves on that controller's mixed µ by
        ``min_improvement`` on the design grid.  That start is abandoned at once where
        the controller's mixed µ is not below its complex µ by ``min_improvement`` (G = 0
        is then optimal at its peak, and the first D-G-K plant is the one complex D-K
        stalled on), or after those iterates where none improved; its records are then
        in ``complex_run.start_history`` (not reported to ``callback``; a kept start's
        are reported once it is decided), and D-G-K starts as with ``"keep"``.  The seat:
        start kept, 2.6063 (31 states) in about 2.2 times the complexified run's CPU
        (re-measured 2026-12-03 on 4ec07eb, full order: kept under OpenBLAS Haswell and
        Sandybridge, 2.5802 and 2.5814 with 31 states; abandoned under SkylakeX, which
        returns the complexified controller, 2.6630 with 13 states: the K-steps' paths
        split by kernel since 0f73eaf); the
        two-mass plant: abandoned at once (mixed 1.7779, complex 1.7787), 1.6089
        (2026-12-02, ``benchmarks/HISTORY.md``).  With ``K0``, the complexified
        run and the start of ``"keep"`` are from it.
    max_gfit_poles : int or None
        D-G-K: the largest basis of the G-scalings (poles per real block; each adds
        three states to the scaled plant per real channel, so this bounds the order of
        the plant every K-step sees, as MATLAB's ``FitOrder`` does).  None: as many as
        keep those states within 30 (10 poles for one real channel, 3 for two; the
        basis sizes tried are 3, 6 and 10).  On the two-mass plant
        (:func:`~lmi_suspension.examples.uncertain_two_mass`) with 10 poles (60 states)
        the second K-step's LMI filled a 4 GB address space (``ulimit -v``; the
        issue measured 9 GB resident on its plant); with 3 (a 38-state scaled plant) it
        took 13-16 s and the run 811 MB (2026-12-02).
    time_budget : float or None
        Seconds of wall time for the iterations (the complexified run of
        ``complex_candidate`` included): after an iterate, where the time spent plus one
        more iteration as long as the last would pass it, the run stops and returns the
        best iterate so far, certified as ever, and ``stop_reason`` says so.  The unit
        is the iteration (a K-step is not interrupted, at least one iterate is made),
        the D-scale search is skipped where the budget ends the run at the first
        iterate, and the dense-grid certificate of the returned controller comes after
        the budget (on the two-mass plant, AB13MD's D-G bound at about 400 frequencies
        and the mixed lower bound at the highest of them: :func:`.steps.dgstep.mixed_bounds`).
    """

    max_iter: int = 8
    mu_target: float = 0.0
    patience: int = 2
    min_improvement: float = 5e-3
    method: str = "lmi"
    hinfsyn_options: object | None = None
    max_dfit_order: int = 4
    dfit_rtol: float = 0.03
    n_dense: int = 200
    reduce_order: int | str | None = "auto"
    reduce_mu_tol: float = 0.01
    stop_on_kstep_regression: bool = True
    dscale_overrelax: float = 2.0
    dscale_search: int = 200
    complexify: bool = False
    complex_candidate: str | None = "auto"
    max_gfit_poles: int | None = None
    time_budget: float | None = None

    def __post_init__(self):
        if int(self.max_iter) < 1 or int(self.patience) < 1:
            raise ParameterError("max_iter and patience must be >= 1")
        if self.method not in ("lmi", "riccati", "best"):
            raise ParameterError(
                f"method must be 'lmi', 'riccati' or 'best', got {self.method!r}")
        if not (self.mu_target >= 0 and self.min_improvement >= 0 and self.dfit_rtol > 0):
            raise ParameterError("mu_target, min_improvement must be >= 0 and dfit_rtol > 0")
        if int(self.max_dfit_order) < 0 or int(self.n_dense) < 10:
            raise ParameterError("max_dfit_order must be >= 0 and n_dense >= 10")
        if self.reduce_order is not None and self.reduce_order != "auto" and (
                isinstance(self.reduce_order, (str, bool)) or int(self.reduce_order) < 0):
            raise ParameterError(f"reduce_order must be None, 'auto' or an order >= 0, "
                                 f"got {self.reduce_order!r}")
        if not (np.isfinite(self.reduce_mu_tol) and self.reduce_mu_tol >= 0):
            raise ParameterError(f"reduce_mu_tol must be >= 0, got {self.reduce_mu_tol!r}")
        if not (np.isfinite(self.dscale_overrelax) and 1.0 <= self.dscale_overrelax <= 4.0):
            raise ParameterError("dscale_overrelax must be in [1, 4], got "
                                 f"{self.dscale_overrelax!r}")
        if int(self.dscale_search) < 0:
            raise ParameterError(f"dscale_search must be >= 0, got {self.dscale_search!r}")
        if self.complex_candidate not in ("auto", "keep", "start", None):
            raise ParameterError(f"complex_candidate must be 'auto', 'keep', 'start' or None, "
                                 f"got {self.complex_candidate!r}")
        if self.max_gfit_poles is not None and int(self.max_gfit_poles) < 1:
            raise ParameterError(f"max_gfit_poles must be >= 1, got {self.max_gfit_poles!r}")
        if self.time_budget is not None and not (
                isinstance(self.time_budget, (int, float)) and not isinstance(
                    self.time_budget, bool) and self.time_budget > 0):
            raise ParameterError(f"time_budget must be None or a positive number of "
                                 f"seconds, got {self.time_budget!r}")


@dataclass(frozen=True)
class MusynIteration:
    """Diagnostics of one D-K iteration.

    Attributes
    ----------
    index : int
        1-based iteration number.
    gamma : float
        Certified H∞ norm of the D-scaled closed loop (an upper bound of µ at every
        frequency, not just on the grid, for the fitted D-scales).
    gamma_prev : float
        Certified H∞ norm of the *previous* controller on this iteration's scaled plant
        (``nan`` on the first iteration): the level an exact K-step matches or beats.
        After a restart (``dscale_overrelax``) it is the best iterate's controller, the
        one the scaled plant was built around.
    mu_peak, mu_lower_peak : float
        Peaks of the µ upper and lower bounds on the design grid (the lower one is a
        lower bound of the peak µ).
    peak_omega : float
        Frequency of the upper-bound peak (rad/s).
    dfit_orders : tuple of int
        Order of the D-scale fit of each block used in the *next* K-step (empty on the
        last iteration if no fit was made).
    controller_order : int
        Number of controller states.
    seconds_k, seconds_d, seconds_fit : float
        Wall time of the K-step, the D-step and the D-fit.
    warnings : tuple of str
        Warnings of the K-step (recoveries, certificate disagreements).
    K : control.StateSpace or None
        This iteration's controller.
    stage : str
        ``"dk"`` for a D-K iteration, ``"dscale_search"`` for the direct search from
        the first iterate's D-step (``seconds_k`` is then its wall time, K-steps and scaled plants,
        ``seconds_fit`` zero and ``gamma_prev`` its γ at the starting scalings).
    certificates : tuple of SpecificationCertificate
        With ``constraints``: each constraint recomputed on ``F_l(P, K)`` (the plant as
        given, not the scaled one) for this iteration's controller.
    PD : control.StateSpace or None
        The scaled plant the controller was synthesized on (``gamma`` is its norm there;
        the plant as given at the first iteration).  In D-K its fitted D scalings are
        feasible at every frequency, so ``‖F_l(PD, K')‖∞`` bounds µ of any controller
        ``K'``'s loop: the order reduction's certificate (``MusynOptions.reduce_order``).
        In D-G-K it also holds the G scalings and its norm is not a bound of µ.
    """

    index: int
    gamma: float
    mu_peak: float
    mu_lower_peak: float
    peak_omega: float
    dfit_orders: tuple
    controller_order: int
    seconds_k: float
    seconds_d: float
    seconds_fit: float
    warnings: tuple = ()
    gamma_prev: float = float("nan")
    K: control.StateSpace | None = field(default=None, repr=False, compare=False)
    stage: str = "dk"
    certificates: tuple = ()
    PD: control.StateSpace | None = field(default=None, repr=False, compare=False)


@dataclass(frozen=True)
class MusynResult:
    """Result of :func:`musyn`; unpacks as ``K, CL, mu_peak, info = musyn(...)``.

    Attributes
    ----------
    K : control.StateSpace
        The best controller found (lowest µ peak).
    CL : control.StateSpace
        ``F_l(P, K)``.
    mu_peak : float
        Peak of the µ upper bound of ``CL`` over the dense grid (see
        ``MusynOptions.n_dense``), with the true (mixed) block structure; its largest
        values are the LMI bound (exact to 1e-6; SLICOT AB13MD's on structures of square
        full blocks), elsewhere the fast bound (no smaller).
    peak_omega : float
        Frequency of that peak, rad/s.
    mu_bound : float
        An upper bound of µ of ``CL`` at **every** frequency, ``0`` to ``∞``: the lower
        of (a) the dense grid's bounds certified over each interval between and beyond
        its points (:func:`~lmi_suspension.mu.interval_bound`, at most 0.1 % above
        ``mu_peak`` where its splits suffice) and (b) the H∞ norm certified for the
        returned controller on its D-scaled plant (the iterate's ``gamma``), where that
        is consistent with the dense grid (no lower bound above it, no grid peak above
        it).  ``mu_bound / mu_peak - 1`` says how far off the grid µ may rise.  For a
        reduced controller whose norm on the best iterate's scaled plant the order
        search computed (``MusynOptions.reduce_order``), that norm, and no interval
        bound.
    mu_lower_peak : float
        Peak of the µ lower bound over the dense grid (a lower bound of ``sup_ω µ``).
    mu : MussvResult
        The bounds over the dense grid.
    history : tuple of MusynIteration
        One record per iteration, each the object the callback received (records are
        complete when reported and never amended).
    warnings : tuple of str
        Findings of the checks of the returned loop made after the loop (a µ lower bound
        on the dense grid above the γ certified for that controller on its scaled
        plant: one of the two certificates is then wrong).
    best_iteration : int
        Index of the iteration whose controller is returned; 0 where it is the
        complexified run's (``MusynOptions.complex_candidate``, ``complex_run.K``), or 1
        where D-G-K started from that controller (``"start"``, or ``"auto"`` with the
        start kept: its first iterate).
    stop_reason : str
        Why the loop stopped.
    reduced_from : int or None
        Order before a successful order reduction, else ``None``.
    K_full, mu_peak_full : control.StateSpace or None, float or None
        After an order reduction: the full-order controller and its µ peak on the
        dense grid (``mu_peak`` is the reduced one's).
    seconds : float
        Total wall time.
    omega : numpy.ndarray
        The design grid, rad/s.
    certificates : tuple of SpecificationCertificate
        With ``constraints``: each constraint recomputed on ``F_l(P, K)`` for the
        returned controller (every one met).
    complex_run : object or None
        D-G-K with ``MusynOptions.complex_candidate``: the complexified D-K run whose
        controller was a candidate (``K``, ``history``, ``stop_reason``, ``seconds``, and
        ``mu_peak``, its mixed µ on the dense grid where the choice needed it).
    """

    K: control.StateSpace
    CL: control.StateSpace
    mu_peak: float
    mu_lower_peak: float
    peak_omega: float
    mu: object
    history: tuple
    best_iteration: int
    stop_reason: str
    reduced_from: int | None = None
    K_full: control.StateSpace | None = None
    mu_peak_full: float | None = None
    seconds: float = 0.0
    omega: np.ndarray = field(default_factory=lambda: np.zeros(0))
    certificates: tuple = ()
    warnings: tuple = ()
    mu_bound: float = float("nan")
    complex_run: _ComplexRun | None = field(default=None, repr=False)

    def __iter__(self):
        return iter((self.K, self.CL, self.mu_peak, self))


@dataclass(frozen=True)
class _ComplexRun:
    """The complexified D-K run whose controller D-G-K must beat
    (``MusynOptions.complex_candidate``).

    Attributes
    ----------
    K : control.StateSpace
        Its best controller (lowest complex µ on the design grid): a candidate for the
        returned controller (and D-G-K's first iterate with ``"start"``).
    history : tuple of MusynIteration
        Its iterations (complex µ) and D-scale search.
    stop_reason : str
        Why it stopped.
    seconds : float
        Its wall time.
    mu_peak : float or None
        Its controller's mixed µ peak on the dense grid, where the final comparison
        computed it (None where D-G-K's result was already no higher than that
        controller's mixed µ lower bound on the design grid).
    start_history : tuple of MusynIteration
        ``complex_candidate="auto"``: the records of D-G-K from this controller where
        that start was abandoned (its first record is this controller's mixed µ on the
        design grid; not reported to ``callback``), else empty.
    start_stop : str or None
        Why that start was abandoned.
    """

    K: control.StateSpace
    history: tuple
    stop_reason: str
    seconds: float
    mu_peak: float | None = None
    start_history: tuple = ()
    start_stop: str | None = None


def default_omega(P, n: int = 60) -> np.ndarray:
    """A log-spaced grid two decades around the plant's poles (rad/s).

    Examples
    --------
    >>> import control
    >>> w = default_omega(control.ss([[-10.0]], [[1.0]], [[1.0]], [[0.0]]), n=5)
    >>> float(w[0]), float(w[-1])
    (0.1, 1000.0)
    """
    G = P.sys if isinstance(P, GeneralizedPlant) else P
    mags = np.abs(np.asarray(G.poles()))
    mags = mags[mags > 1e-8]
    lo, hi = (mags.min(), mags.max()) if mags.size else (1.0, 1.0)
    return np.logspace(np.log10(lo) - 2, np.log10(hi) + 2, int(n))


def _complexified(struct: BlockStructure) -> BlockStructure:
    """Real repeated scalars treated as complex ones (D-K with D scalings only).

    A 1×1 scalar block is written as the full block ``[1, 1]`` (the same set), so that
    structures of scalars and full blocks stay on mussv's fast path.
    """
    rows = []
    for r, c in struct.to_blk():
        r, c = abs(int(r)), int(c)
        rows.append([1, 1] if (r, c) == (1, 0) else [r, c])
    return BlockStructure.from_blk(rows)


#: ``complex_candidate="auto"``: the iterates of D-G-K from the complexified controller
#: (the first is that controller) within which one must improve on it, or that start is
#: abandoned for D-G-K from the beginning.  Its second iterate is its first K-step: on
#: the seat over m3 and k1 it went from 2.6704 to 2.5827, where the run ended (2.6063 on
#: the dense grid); on the two-mass plant from 1.7779 to 1.8110, and D-G-K from the
#: beginning reached 1.6085 (design grid, 2026-12-02, ``benchmarks/musyn_mixed.py``).
#: Before that K-step the start is abandoned where the first iterate's mixed µ is not
#: below the controller's complex µ by ``min_improvement``: where they are equal at the
#: peak, G = 0 is already an optimal scaling there and the first D-G-K plant is the one
#: complex D-K stalled on.  The two-mass controller: complex 1.7787, mixed 1.7779 (0.04 %
#: below; its K-step then went up to 1.8110); the seat's: 2.6975 and 2.6704 (1.0 % below;
#: down to 2.5827)
_TRIAL_ITERATIONS = 2
#: D-G-K stops after an iterate whose µ peak is this much above the best iterate's
#: (:func:`_regressed`).  Measured 2026-12-02 (``benchmarks/musyn_mixed.py``): the
#: two-mass plant's iterates 1.6085 (best), 1.7507 (+8.8 %), 1.7018; the seat's from
#: the complexified controller 2.5827 (best), 2.6512 (+2.7 %), 2.7123: patience (2)
#: spent one more iterate each, 7 and 2 s of CPU, and the regressions were 2.7 % and
#: more, the small steps of a converging path (seat from the beginning: 0.1-1.2 %)
#: below them
_DGK_REGRESSION = 0.02

#: frequencies whose upper bound the final µ refines at a time (see _final_bounds)
_REFINE_BATCH = 8
#: iteration bound of the fast bound's BFGS in the first pass of :func:`_final_bounds`
#: (``MussvOptions.fast_maxiter``, 400 by default): the pass only has to order the
#: frequencies, the largest are refined after it.  On the 531-point dense grid of
#: default ``musyn``'s distillation loop, whose µ is flat at 0.959582 over 3e-5-0.6
#: rad/s, 400 iterations took 3.55 s, 100 took 2.38 s with the same bound at every
#: frequency (40: 2.10 s, 2.7e-5 above at two of them; one thread, measured 2026-12-02)
_FINAL_FAST_MAXITER = 100


def _final_bounds(CL, struct: BlockStructure, omega: np.ndarray, rng, seed=None, *,
                  lower: bool = True):
    """µ bounds of ``CL`` over ``omega``, the upper bound's peak exact.

    ``mussv``'s fast upper bound minimises ``σ̄(D M D⁻¹)`` by BFGS, which stalls short
    of the minimum where singular values coalesce, as they do across the flat µ of an
    optimised loop: on the distillation loop of the D-scale search it read
    0.95947-0.96010 under four OpenBLAS kernels and 1 and 2 threads, where the LMI
    upper bound (a convex problem solved to its optimum) read 0.959465-0.959531, equal
    to the lower bound (measured 2026-11-26).  So the frequencies are refined with the
    LMI bound in falling order of the fast bound, until no unrefined one is above the
    largest refined bound; elsewhere the fast bound stays (it is no smaller).  The
    refinement is SLICOT AB13MD's bound where the structure is one it takes (square
    full blocks): on that loop it agreed with the LMI's to 2e-11 at the 64 largest
    frequencies, in 0.16 s per batch of 8 against 0.55 s (measured 2026-12-02); its
    scalings are certified by :func:`mussv` as the LMI's are.

    ``seed``, bounds of a nearby loop on the same grid (the full-order loop of a
    truncated controller), replaces the fast bound's BFGS: its scalings are feasible
    for any loop, so one generalized eigenvalue problem per frequency bounds this loop's
    µ there (the ordering pass; ``fast_maxiter`` 1, the lower bound as ever).  On
    default ``musyn``'s distillation loop truncated to 12, 14 and 15 states it gave the
    same peaks as the fast bound in 0.54-0.83 s of CPU instead of 1.6-1.9 s (measured
    2026-12-02).  With real blocks the seed's D-G scalings do the same for AB13MD's
    bound, which is then computed only where they may set the peak: on the seat's
    mixed controller truncated to 9 states (``benchmarks/musyn_mixed.py seat``) the
    order's dense certificate went from 2.1 to 0.8 s under cProfile, µ 2.6007 and its
    lower bound 2.5968 as before (2026-12-03).

    ``lower=False`` (real blocks only; ignored otherwise): AB13MD's upper bound alone,
    the lower bound left at zero (:func:`_dense_certificate` takes it once the peaks
    are refined).  With a seed and real blocks, ``upper`` away from the peak is the
    seed's certified bound, not AB13MD's (``method`` names the refinement's); the
    scalings returned beside it are the ones that certify it at each frequency.
    """
    from .bounds import MussvOptions, MussvTimings, _ab13md_blocks, _certify, mussv
    from .steps.dgstep import (lower_where_it_counts, mixed_bounds,
                               with_lower_where_it_counts)

    t0 = time.perf_counter()
    if seed is not None and (seed.omega is None or not np.array_equal(
            np.asarray(seed.omega, dtype=float), np.asarray(omega, dtype=float))):
        raise ValueError("the seed's bounds must be on the same frequency grid")
    M = freqresp(CL, omega)
    mixed = lower_where_it_counts(struct)  # real blocks: AB13MD's upper bound
    if mixed and seed is None:
        if not lower:
            return mussv(M, struct, omega=omega, options=MussvOptions(compute_lower=False))
        return mixed_bounds(M, struct, omega, rng)
    names = ("D_left", "D_right", "G", "d_blocks")
    if mixed:
        # the seed's D-G scalings bound this loop's mixed µ everywhere; AB13MD only
        # where that bound could be the peak (below)
        mu = seed
        upper = np.full(omega.size, np.inf)
        fields = {k: np.array(getattr(seed, k)) for k in names}
    else:
        mu = mussv(M, struct, omega=omega, rng=rng, options=MussvOptions(
            fast_maxiter=_FINAL_FAST_MAXITER if seed is None else 1))
        if mu.method != "fast":         # the LMI's or AB13MD's: the D-G bound already
            return mu
        upper, fields = np.array(mu.upper), {k: np.array(getattr(mu, k)) for k in names}
    refine = ("ab13md" if struct.n_in == struct.n_out and _ab13md_blocks(struct) is not None
              else "lmi")
    if seed is not None:
        XL = np.einsum("jik,jlk->ilk", seed.D_left.conj(), seed.D_left)
        XR = np.einsum("jik,jlk->ilk", seed.D_right.conj(), seed.D_right)
        beta = np.array([_certify(M[:, :, k], XL[:, :, k], XR[:, :, k], seed.G[:, :, k])
                         for k in range(omega.size)])
        kept = beta < upper
        upper[kept] = beta[kept]
        for k, v in fields.items():
            v[..., kept] = np.asarray(getattr(seed, k))[..., kept]
    order = np.argsort(-upper, kind="stable")
    top = 0.0
    for start in range(0, order.size, _REFINE_BATCH):
        batch = order[start:start + _REFINE_BATCH]
        if upper[batch[0]] <= top:
            break
        exact = mussv(M[:, :, batch], struct, method=refine, omega=omega[batch],
                      options=MussvOptions(compute_lower=False))
        kept = np.asarray(exact.upper) < upper[batch]  # the fast or seed's bound elsewhere
        better = batch[kept]
        upper[better] = np.asarray(exact.upper)[kept]
        for k, v in fields.items():
            v[..., better] = np.asarray(getattr(exact, k))[..., kept]
        top = max(top, float(np.max(upper[batch])))
    k_peak = int(np.argmax(upper))
    if mixed:
        spent = time.perf_counter() - t0
        bounds = replace(mu, upper=upper, omega=omega, peak=float(upper[k_peak]),
                         peak_omega=float(omega[k_peak]), method=refine, warnings=(),
                         blk=struct, lower=np.zeros_like(upper),
                         delta=np.zeros((*struct.shape_delta, omega.size), dtype=complex),
                         timings=MussvTimings(upper=spent, lower=0.0, total=spent), **fields)
        if not lower:
            return bounds
        return with_lower_where_it_counts(bounds, M, struct, omega, rng)
    # (equal bounds can cross by roundoff once the upper one is exact)
    return replace(mu, upper=upper, lower=np.minimum(mu.lower, upper), peak=float(upper[k_peak]),
                   peak_omega=float(omega[k_peak]), **fields)


def _dense_grid(omega: np.ndarray, n: int, peak: float, CL) -> np.ndarray:
    """The grid of the reported µ: ``n`` points over the design range, 41 around the
    peak, and 4 per decade from three decades below the loop's slowest pole to two above
    its fastest, where those lie outside the design range (a weight pole at 1e-6 rad/s
    keeps µ rising below a grid that starts at 1e-3: measured 1.022025 at 1e-9 rad/s
    against a grid peak of 1.021897, and 1.022024 at 1e-7, on the distillation
    problem)."""
    base = np.logspace(np.log10(omega[0]), np.log10(omega[-1]), n)
    near = peak * np.logspace(-0.15, 0.15, 41)  # resolve a sharp peak
    mags = np.abs(np.linalg.eigvals(CL.A)) if CL.nstates else np.zeros(0)
    mags = mags[mags > 0]
    parts = [base, near, omega]
    if mags.size:
        lo, hi = 1e-3 * mags.min(), 1e2 * mags.max()
        if lo < omega[0]:
            k = int(np.ceil(4 * np.log10(omega[0] / lo)))
            parts.append(np.logspace(np.log10(lo), np.log10(omega[0]), k + 1))
        if hi > omega[-1]:
            k = int(np.ceil(4 * np.log10(hi / omega[-1])))
            parts.append(np.logspace(np.log10(omega[-1]), np.log10(hi), k + 1))
    return np.unique(np.concatenate(parts))


def musyn(P, nmeas: int, ncon: int, blk=None, *, omega=None, options: MusynOptions | None = None,
          callback: Callable[[MusynIteration], None] | None = None,
          rng: np.random.Generator | None = None, constraints=(),
          lyapunov_scales=None, K0=None, steps: DKSteps | None = None) -> MusynResult:
    """µ-synthesis by D-K iteration.

    Parameters
    ----------
    P : control.StateSpace, GeneralizedPlant or lmi_suspension.uncertain.USS
        Generalized plant with inputs ``[w; u]`` and outputs ``[z; y]``, continuous- or
        discrete-time (a discrete plant is designed on its bilinear image and every
        result mapped back exactly: :mod:`lmi_suspension.mu.discrete`); ``w`` and ``z``
        hold the uncertainty channels followed by the performance channels, in the order
        of ``blk``.  An uncertain plant (``uss``, inputs ``[d; u]``, outputs
        ``[e; y]``) carries its uncertainty: ``blk`` is then its :func:`lftdata`
        structure followed by the full performance block ``[n_d, n_e]``, as MATLAB's
        ``musyn(P, nmeas, ncon)`` (robust H∞ performance: µ < 1 means
        ``‖e/d‖∞ < 1`` for every parameter value in its range).
    nmeas, ncon : int
        Number of measurements (last outputs) and controls (last inputs).
    blk : array_like or BlockStructure
        MATLAB-style block structure; the last block is usually the fictitious full
        performance block. ``F_l(P, K)`` must be ``(Σ c_i) × (Σ r_i)``.  Required for
        a certain plant, not given for an uncertain one.
    omega : array_like, optional
        Design frequency grid, rad/s (default :func:`default_omega`).
    options : MusynOptions, optional
        Iteration bounds, stopping rules, K-step method, D-fit and reduction settings.
    callback : callable, optional
        Called with each :class:`MusynIteration` as soon as it is complete (progress);
        the first iterate's record comes once the D-scale search that starts from it
        has ended (about 10 s on distillation), the search's after the last D-K
        iteration.
    rng : numpy.random.Generator, optional
        Seeds the µ lower-bound restarts (default ``np.random.default_rng(0)``).
    constraints : sequence of Specification, optional
        Requirements every K-step meets besides the scaled H∞ level, as in
        :func:`~lmi_suspension.synthesis.msyn` (generalized-H2 peak bounds, H2 and H∞
        bounds, pole regions, one's own): each K-step is then that multi-objective LMI
        synthesis on the scaled plant (``method="lmi"``).  Their channels index ``P``'s
        ``w`` and ``z``; inputs and outputs beyond those ``blk`` covers (after them, in
        front of ``u`` and ``y``) are seen by the constraints only, not by µ -- the
        channels of hard time-domain bounds.  D-K scales only the channels of ``blk``
        and normalises the last full block to ``d = 1``, so a constraint on the
        performance channels or on those extra ones refers to the nominal closed loop.
        Every iterate is certified on each constraint on ``F_l(P, K)`` itself; the best
        iterate that meets them all is returned.
    lyapunov_scales : sequence of float, optional
        With ``constraints``: :func:`~lmi_suspension.synthesis.msyn`'s Lyapunov scales
        for the first K-step (searched when not given, about 15 minimisations); every
        later K-step starts from the previous one's, and searches again only if they
        fail.
    K0 : control.StateSpace or array_like, optional
        A controller (``u = K0 y``) to start from: the first iteration takes it instead
        of a K-step (its ``gamma`` is then its certified norm on the unscaled plant)
        and D-K goes on from its D-step.  It must stabilise
        ``P`` and, with ``constraints``, meet them.  The D-K path depends on the
        controller its first D-step sees, not only on its level: on the distillation
        problem, the central (Riccati) controller at the LMI's own certified level
        1.180247 led the default LMI K-steps to µ 0.976 at iteration 5, and at 1.18025
        to 0.994 at iteration 4, where the LMI's own first controller, certified at
        the same level, leads them to 1.04 (measured 2026-11-25; the path is sensitive
        to its start).  A previous design, or one of another method, is a natural
        start.  Without it, ``method="lmi"`` starts from such a central controller by
        itself (see ``MusynOptions.method``).
    steps : DKSteps, optional
        Factories of the three steps (:mod:`lmi_suspension.mu.steps`): the K-step, the
        D/G-step and the fit, each built once for the run from its
        :class:`~lmi_suspension.mu.steps.DKSetup`.  The defaults are
        ``MusynOptions.method``'s H∞ synthesis (the multi-objective LMI with
        ``constraints``), :func:`mussv` on the grid, and the D (D-K) or D-G (D-G-K) fit.
        Every iterate is certified by this loop whatever the steps: its closed loop's
        poles, µ bounds, and each constraint recomputed.

    Returns
    -------
    MusynResult
        ``CL`` is the ``w -> z`` part that ``blk`` covers.

    Raises
    ------
    DimensionError
        If ``blk`` does not fit the ``w``/``z`` partition of ``P``.
    InfeasibleError
        If the first K-step finds no stabilising controller, or no controller meets the
        constraints.
    ParameterError
        If constraints are given with a K-step method other than ``"lmi"``, or ``K0``
        does not stabilise ``P`` or violates a constraint (``DimensionError`` if its
        size is not ``ncon x nmeas``, ``DiscreteTimeError`` if it is discrete).
    """
    from ..synthesis.hinfsyn import _hinfsyn as hinfsyn  # the D-scale search's
    from .steps.kstep import _GivenController

    G_d = _discrete_plant(P, nmeas, ncon)
    if G_d is not None:
        from .discrete import musyn_discrete

        return musyn_discrete(musyn, G_d, nmeas, ncon, blk, omega=omega, options=options,
                              callback=callback, rng=rng, constraints=constraints,
                              lyapunov_scales=lyapunov_scales, K0=K0, steps=steps)
    t_start = time.perf_counter()
    setup, given = _setup(P, nmeas, ncon, blk, omega, options, rng, constraints,
                          lyapunov_scales, K0)
    steps = steps if steps is not None else DKSteps()
    rival = None
    mode = setup.options.complex_candidate
    if setup.mixed and mode is not None:
        # the complex D is a feasible mixed scaling with G = 0: the complexified run's
        # controller is a candidate D-G-K must beat ("start": D-G-K starts from it)
        cx_setup = replace(setup, mixed=False, dk_struct=_complexified(setup.struct),
                           options=replace(setup.options, complexify=True))
        cx_best, cx_history, cx_stop, _ = _dk_loop(cx_setup, steps, given, None, hinfsyn,
                                                   t_start)
        rival = _ComplexRun(K=cx_best[1], history=tuple(cx_history), stop_reason=cx_stop,
                              seconds=time.perf_counter() - t_start)
        logger.info("musyn: complexified D-K ended at complex µ %.4f in %.1f s (%s)",
                    cx_best[0], rival.seconds, cx_stop)
    started = rival is not None and mode in ("start", "auto")
    if started:
        from_complex = _GivenController(
            rival.K, float(hinfnorm(mu_part(lft(setup.G, rival.K), setup.struct))[0]),
            ("the complexified D-K's controller: no K-step",))
        best, history, stop_reason, abandoned = _dk_loop(
            setup, steps, from_complex, callback, hinfsyn, t_start,
            trial=_complex_peak(rival) if mode == "auto" else None)
        if abandoned:
            # the start from the complexified controller did not improve on it: D-G-K
            # from the beginning (its own first K-step, or K0); the complexified
            # controller's mixed µ on the design grid is the trial's first iterate
            rival = replace(rival, start_history=tuple(history), start_stop=stop_reason)
            started = False
            best, history, stop_reason, _ = _dk_loop(setup, steps, given, callback, hinfsyn,
                                                     t_start)
    else:
        best, history, stop_reason, _ = _dk_loop(setup, steps, given, callback, hinfsyn,
                                                 t_start)
    return _certified(setup, best, history, stop_reason, t_start, rival=rival,
                      started=started)


def _dk_loop(setup, steps: DKSteps, given, callback, hinfsyn, t_start: float, *,
             trial: float | None = None):
    """The D-K (or D-G-K) iterations and the D-scale search of one run:
    ``(best, history, stop_reason, abandoned)``, ``best = (mu_peak, K, index)`` on the
    design grid (``setup.dk_struct``'s µ), nothing certified on the dense grid yet.

    ``trial`` (D-G-K from the complexified controller, ``complex_candidate="auto"``:
    that controller's complex µ peak on the design grid): the records of the first
    ``_TRIAL_ITERATIONS`` iterations are held back from ``callback`` until the start
    is decided, and the loop is ``abandoned`` (its records never reported) where the
    first iterate's mixed µ is not below ``trial`` by ``min_improvement`` (at the
    complex design's peak the real structure leaves the G scalings nothing to take,
    :data:`_TRIAL_ITERATIONS`), or none of those iterates has improved on the first by
    ``min_improvement``."""
    from .steps import NextPlant
    from .steps.dgstep import MussvStep
    from .steps.fit import default_fit
    from .steps.kstep import GivenFirst, default_kstep

    opts, rng, omega, struct, constraints, mixed, G = (
        setup.options, setup.rng, setup.omega, setup.struct, setup.constraints,
        setup.mixed, setup.G)
    nmeas, ncon = setup.nmeas, setup.ncon
    kstep = (steps.kstep or default_kstep)(setup)
    if given is not None:
        kstep = GivenFirst(given, kstep)
    dgstep = (steps.dgstep or MussvStep)(setup)
    fitstep = (steps.fit or default_fit)(setup)

    history: list[MusynIteration] = []
    held: list[MusynIteration] = []  # a trial's records, until it is decided
    abandoned = False
    best = None  # (mu_peak, K, index)
    searched = None  # the D-scale search's record, from iteration 1's D-step
    stop_reason = f"reached max_iter={opts.max_iter}"
    since_best = 0
    t_last = None  # start of the previous iteration (the time budget's estimate)
    nxt = NextPlant(PD=G.sys, orders=(), K_ref=None)  # the plant of the next K-step
    for it in range(1, int(opts.max_iter) + 1):
        t0 = time.perf_counter()
        syn, nxt, gamma_prev, failure = _k_step_on(kstep, nxt, it, setup,
                                                   first=best is None)
        if failure is not None:
            stop_reason = f"K-step failed at iteration {it}: {failure}"
            # a stop, told in ``stop_reason``; the best iterate is certified as ever
            logger.info("musyn: %s; keeping the best so far", stop_reason)
            break
        K = syn.K
        t1 = time.perf_counter()
        CL_full = lft(G, K)
        CL = mu_part(CL_full, struct)
        certs = certificates(constraints, CL_full)
        if not np.all(np.real(CL.poles()) < 0):
            if best is None:
                raise InfeasibleError("the first K-step did not give a stabilising controller")
            stop_reason = f"K-step at iteration {it} returned a non-stabilising controller"
            break
        here = dgstep(CL, K)
        t2 = time.perf_counter()
        mu_peak = here.mu_peak

        # progress is judged against the best so far, the D-scale search's included: D-K
        # goes on while it may still beat the search (see ``dscale_search``)
        bar = np.inf if best is None else best[0]
        if searched is not None:
            bar = min(bar, searched.mu_peak)
        improved = mu_peak < bar * (1 - opts.min_improvement)
        if (best is None or mu_peak < best[0]) and all(c.met for c in certs):
            best = (mu_peak, K, it)
        elif best is None:
            raise InfeasibleError("the first K-step's controller violates " + "; ".join(
                f"{c.name} ({c.achieved:.6g})" for c in certs if not c.met))
        since_best = 0 if improved else since_best + 1

        # over-relaxed scalings can give a plant the K-step handles badly; the next
        # D-step then restarts from the best iterate instead
        excused = getattr(fitstep, "restarts_from_best", False) and best[2] != it
        done = _done(setup, it, mu_peak, float(syn.gamma), gamma_prev, since_best,
                     excused=excused)
        over = _over_budget(opts, t_start, t0 if t_last is None else t_last, it, best[2])
        t_last = t0
        done = done if done is not None or over is None else over
        if done is None and mixed:
            done = _regressed(it, mu_peak, best)
        if trial is not None and it == 1 and over is None and \
                not mu_peak < trial * (1 - opts.min_improvement):
            abandoned = True
            done = (f"D-G-K from the complexified controller abandoned at iteration 1: its "
                    f"mixed µ {mu_peak:.4f} is not below its complex µ {trial:.4f} by "
                    f"{opts.min_improvement:.1%}")
            logger.info("musyn: %s", done)
        elif trial is not None and it == _TRIAL_ITERATIONS and over is None and not (
                best[2] != 1 and best[0] < history[0].mu_peak * (1 - opts.min_improvement)):
            abandoned = True
            done = (f"D-G-K from the complexified controller abandoned at iteration {it}: "
                    f"µ {mu_peak:.4f} against its start's {history[0].mu_peak:.4f}")
            logger.info("musyn: %s", done)

        # the D-scale search starts from this D-step, so it runs now, and the D-K
        # iterations after it measure their progress against it; its own copy of the
        # generator leaves them as they are without it
        if it == 1 and over is None and _search_applies(setup, best):
            searched = _search_stage(G, nmeas, ncon, setup.dk_struct, omega,
                                     (here.d_blocks, here.upper), opts, copy.deepcopy(rng),
                                     index=0, hinfsyn=hinfsyn)
            if searched is not None and searched.mu_peak < opts.mu_target and done is None:
                done = f"the D-scale search reached mu_target={opts.mu_target:g}"
        orders: tuple = ()
        t3 = time.perf_counter()
        if done is None:
            try:
                nxt = fitstep(here, iteration=it, best_iteration=best[2])
                orders = nxt.orders
            except LmiSuspensionError as exc:
                # no usable scaled plant for the next K-step: end with the best iterate
                done = f"D-fit failed after iteration {it}: {exc}"
                logger.info("musyn: %s; keeping iteration %d", done, best[2])
        t4 = time.perf_counter()
        record = MusynIteration(
            index=it, gamma=float(syn.gamma), mu_peak=mu_peak,
            mu_lower_peak=here.lower_peak, peak_omega=here.peak_omega,
            dfit_orders=orders, controller_order=K.nstates, seconds_k=t1 - t0,
            seconds_d=t2 - t1, seconds_fit=t4 - t3,
            warnings=tuple(syn.warnings) + (() if mixed and it > 1 else _bound_check(
                float(syn.gamma), here.lower_peak, f"iteration {it}")),
            gamma_prev=gamma_prev, K=K, certificates=certs, PD=nxt.PD)
        history.append(record)
        logger.info("musyn iteration %d: gamma=%.4f (previous K %.4f) mu=%.4f (lower %.4f) "
                    "K order %d D orders %s [K %.2fs, D %.2fs, fit %.2fs]", it, record.gamma,
                    gamma_prev, mu_peak, record.mu_lower_peak, K.nstates, orders,
                    record.seconds_k,
                    record.seconds_d, record.seconds_fit)
        if callback is not None and not abandoned:
            if trial is not None and it < _TRIAL_ITERATIONS and done is None:
                held.append(record)  # the start is not decided yet
            else:
                for rec in held + [record]:
                    callback(rec)
                held = []
        if done is not None:
            stop_reason = done
            break

    if searched is not None:  # recorded after the D-K iterations it ran beside
        history.append(replace(searched, index=len(history) + 1))
        if callback is not None:
            callback(history[-1])
        if _search_wins(searched, history[best[2] - 1], setup):
            best = (searched.mu_peak, searched.K, len(history))
            stop_reason += f"; D-scale search to µ {searched.mu_peak:.4f}"
    return best, history, stop_reason, abandoned


def _complex_peak(rival: _ComplexRun) -> float:
    """The complex µ peak on the design grid of the complexified run's controller (its
    record's: a D-K iterate's, or the D-scale search's)."""
    return min((rec.mu_peak for rec in rival.history if rec.K is rival.K), default=np.inf)


def _regressed(it: int, mu_peak: float, best) -> str | None:
    """Why D-G-K stops after iterate ``it``, or None: its µ is more than
    ``_DGK_REGRESSION`` above the best iterate's.  D-G-K's next plant is built around
    the loop it has (no restart from the best, as D-K's over-relaxation has), and after
    such a step none of the measured paths came back below its best
    (:data:`_DGK_REGRESSION`)."""
    if best[2] == it or not mu_peak > best[0] * (1.0 + _DGK_REGRESSION):
        return None
    done = (f"D-G-K iterate {it} (µ {mu_peak:.4f}) is more than {_DGK_REGRESSION:.0%} above "
            f"the best, iterate {best[2]} ({best[0]:.4f})")
    logger.info("musyn: %s", done)
    return done


def _search_wins(searched: MusynIteration, dk_best: MusynIteration, setup) -> bool:
    """Whether the D-scale search's peak is below the best D-K iterate's, like with like:
    the search's is the LMI-refined bound (:func:`_final_bounds`), an iterate's the fast
    one, which can stall above it (up to 0.06 % on distillation's flat loops).  The
    iterate's bound is refined only where its lower bound leaves the question open (µ
    lies between the two)."""
    if searched.mu_peak >= dk_best.mu_peak:
        return False
    if searched.mu_peak <= dk_best.mu_lower_peak:
        return True
    refined = _final_bounds(lft(setup.G, dk_best.K), setup.dk_struct, setup.omega,
                            copy.deepcopy(setup.rng))
    return searched.mu_peak < float(np.max(refined.upper))


def _search_applies(setup, best) -> bool:
    """Whether the D-scale search runs after the first iterate (``dscale_search``)."""
    opts = setup.options
    if not opts.dscale_search or best[0] < opts.mu_target:
        return False
    if setup.constraints:
        logger.info("musyn: no D-scale search with constraints (its K-step is Riccati's)")
        return False
    if setup.mixed:
        logger.info("musyn: no D-scale search with real blocks (it searches D alone)")
        return False
    return True


def _certified(setup, best, history, stop_reason: str, t_start: float,
               rival: _ComplexRun | None = None, started: bool = False) -> MusynResult:
    """The best iterate's result: its µ on a dense grid with the true structure (the
    peak refined with the LMI bound, bounded between grid points), its controller
    reduced where asked and µ allows, its constraints recomputed."""
    _, K, best_it = best
    omega, rng, constraints, mixed = setup.omega, setup.rng, setup.constraints, setup.mixed
    if rival is None:
        CL_full, CL, dense, final = _dense_certificate(setup, K, history[best_it - 1].peak_omega)
    else:
        (K, best_it, CL_full, CL, dense, final, stop_reason,
         rival) = _against_complex(setup, rival, history, best, stop_reason, started)
    checks: tuple = ()
    mu_bound = float("inf")
    scaled = None  # the best iterate's scaled plant, where its γ bounds µ
    # (a D-G-K iterate's γ is the norm of a G-scaled plant, not a bound of µ)
    if not (mixed and best_it != 1):
        # the dense grid reaches below the design grid, where a certificate computed on
        # the scaled plant can fail: the full-order loop's µ is the witness.  Its record
        # was reported already, so the finding goes to the result, not into the record.
        gamma = history[best_it - 1].gamma
        checks = _bound_check(gamma, float(np.max(final.lower)),
                              f"iteration {best_it} on the dense grid (at "
                              f"{float(dense[int(np.argmax(final.lower))]):.3g} rad/s)",
                              rtol=_DENSE_BOUNDS_RTOL)
        if not checks and not constraints and not mixed and np.max(final.upper) <= gamma:
            mu_bound = gamma  # the scaled loop's norm: a bound at every frequency
            scaled = history[best_it - 1].PD
    reduced_from, K_full, mu_full = None, None, None
    reduced = _reduction(setup, K, final, dense, rng, scaled)
    if reduced is not None:
        reduced_from, K_full, mu_full = K.nstates, K, float(np.max(final.upper))
        K, CL, CL_full, final, gamma_red = reduced
        # γ bounded the full order's loop; the reduced one's own norm on the same scaled
        # plant bounds its µ where the search computed it (and the dense grid agrees)
        mu_bound = (gamma_red if np.isfinite(gamma_red) and np.max(final.upper) <= gamma_red
                    and np.max(final.lower) <= gamma_red * (1.0 + _DENSE_BOUNDS_RTOL)
                    else float("inf"))
    upper = np.asarray(final.upper)
    k_peak = int(np.argmax(upper))
    # a reduced loop's scaled norm is kept as it is (a bound at every frequency; within
    # reduce_mu_tol of the full order's µ where it chose the order): 20 splits of the
    # interval bound did not come near it on distillation (1.0760 against 1.0475 after
    # two D-K iterations, 1.0239 against 0.9609 after the default run; 2026-12-02)
    if not mu_bound <= upper[k_peak] * (1.0 + _SUP_RTOL) and (
            reduced is None or not np.isfinite(mu_bound)):
        mu_bound = min(mu_bound, interval_bound(CL, final, dense, rtol=_SUP_RTOL,
                                                max_splits=_SUP_SPLITS).bound)
    return MusynResult(
        K=K, CL=CL, mu_peak=float(upper[k_peak]), mu_lower_peak=float(np.max(final.lower)),
        peak_omega=float(dense[k_peak]), mu_bound=float(mu_bound), mu=final,
        history=tuple(history),
        best_iteration=best_it, stop_reason=stop_reason, reduced_from=reduced_from,
        K_full=K_full, mu_peak_full=mu_full,
        seconds=time.perf_counter() - t_start, omega=omega,
        certificates=certificates(constraints, CL_full), warnings=checks,
        complex_run=rival)


def _dense_certificate(setup, K, peak_omega: float):
    """``(CL_full, CL, dense, final)``: ``K``'s loop and its µ bounds on the dense grid
    (:func:`_dense_grid`, :func:`_final_bounds`), its highest local maxima refined
    (:func:`_refine_peaks`).  With real blocks the lower bound is taken once, on the
    refined grid (:func:`~.steps.dgstep.with_lower_where_it_counts`): taken on the
    grid and again on the points added around its peaks, the refinement of the seat's
    mixed loop took 0.80 s under cProfile, 0.14 s without it, the certificate 2.7 s
    against 2.0 s, with the same µ and lower bound (2026-12-03)."""
    from .steps.dgstep import lower_where_it_counts, with_lower_where_it_counts

    CL_full = lft(setup.G, K)
    CL = balanced_statespace(mu_part(CL_full, setup.struct))
    dense = _dense_grid(setup.omega, int(setup.options.n_dense), peak_omega, CL)
    mixed = lower_where_it_counts(setup.struct)
    final = _final_bounds(CL, setup.struct, dense, setup.rng, lower=not mixed)
    dense, final = _refine_peaks(CL, setup.struct, dense, final, setup.rng, lower=not mixed)
    if mixed:
        final = with_lower_where_it_counts(final, freqresp(CL, dense), setup.struct, dense,
                                           setup.rng)
    return CL_full, CL, dense, final


#: local maxima of the dense grid's upper bound refined by :func:`_refine_peaks`, and the
#: points added between each and its two neighbours
_PEAKS_REFINED = 3
_PEAK_POINTS = 8


def _refine_peaks(CL, struct: BlockStructure, omega: np.ndarray, mu, rng, *,
                  lower: bool = True):
    """``(omega, mu)`` with ``_PEAK_POINTS`` more frequencies between each of the
    ``_PEAKS_REFINED`` highest local maxima of ``mu.upper`` and its neighbours, their
    bounds by :func:`_final_bounds`: a peak sharper than the grid is resolved where
    it shows, at a few dozen points instead of a finer grid everywhere (the grid's
    fast bound is most of a default run's certificate: 2.6 s of CPU on distillation's
    531 points, 1.7 s on 333, measured 2026-12-02)."""
    upper = np.asarray(mu.upper)
    if upper.size < 3:
        return omega, mu
    inner = np.flatnonzero((upper[1:-1] >= upper[:-2]) & (upper[1:-1] >= upper[2:])) + 1
    ends = [k for k in (0, upper.size - 1)
            if upper[k] >= upper[1 if k == 0 else upper.size - 2]]
    peaks = np.concatenate([inner, np.asarray(ends, dtype=int)])
    peaks = peaks[np.argsort(-upper[peaks], kind="stable")][:_PEAKS_REFINED]
    extra = []
    for k in peaks:
        lo, hi = omega[max(k - 1, 0)], omega[min(k + 1, upper.size - 1)]
        extra.append(np.logspace(np.log10(lo), np.log10(hi), _PEAK_POINTS + 2)[1:-1])
    extra = np.setdiff1d(np.concatenate(extra), omega)
    if not extra.size:
        return omega, mu
    more = _final_bounds(CL, struct, extra, rng, lower=lower)
    grid = np.concatenate([omega, extra])
    order = np.argsort(grid, kind="stable")

    def merged(a, b):
        return np.concatenate([np.asarray(a), np.asarray(b)], axis=-1)[..., order]

    fields = {k: merged(getattr(mu, k), getattr(more, k)) for k in
              ("upper", "lower", "D_left", "D_right", "G", "d_blocks", "delta")}
    k_peak = int(np.argmax(fields["upper"]))
    timings = type(mu.timings)(**{k: getattr(mu.timings, k) + getattr(more.timings, k)
                                  for k in ("upper", "lower", "total")})
    return grid[order], replace(mu, omega=grid[order], peak=float(fields["upper"][k_peak]),
                                peak_omega=float(grid[order][k_peak]), timings=timings,
                                warnings=tuple(mu.warnings) + tuple(more.warnings), **fields)


def _against_complex(setup, rival: _ComplexRun, history, best, stop_reason: str,
                     started: bool):
    """D-G-K's best controller against the complexified D-K's (``complex_candidate``),
    both certified with mixed µ on the dense grid: the lower is returned.  Returns
    ``(K, best_iteration, CL_full, CL, dense, final, stop_reason, rival)`` of the chosen
    one (``best_iteration`` 0 for the complexified run's, unless it is D-G-K's first
    iterate), ``stop_reason`` saying which, ``rival`` with its µ where computed.

    The dense certificate (a mixed-µ upper bound at 400+ frequencies) is the costly
    part, so the controller with the lower µ on the design grid is certified first, and
    the other only where that certified peak is above the other's µ lower bound on the
    design grid (below it, the other's µ cannot be lower)."""
    _, K, best_it = best
    mine = history[best_it - 1]
    if started:
        theirs = history[0]  # D-G-K's first iterate is the complexified run's controller
    elif rival.start_history:  # the abandoned start's first iterate: the same loop
        theirs = replace(rival.start_history[0], index=0)
        stop_reason += f"; {rival.start_stop}"
    else:  # its mixed µ on the design grid, as D-G-K's D/G-step takes it
        from .steps.dgstep import MussvStep

        here = MussvStep(setup)(mu_part(lft(setup.G, rival.K), setup.struct), rival.K)
        theirs = MusynIteration(index=0, gamma=float("nan"), mu_peak=here.mu_peak,
                                mu_lower_peak=here.lower_peak, peak_omega=here.peak_omega,
                                dfit_orders=(), controller_order=rival.K.nstates,
                                seconds_k=0.0, seconds_d=0.0, seconds_fit=0.0)
    if started and best_it == 1:
        cert = _dense_certificate(setup, K, mine.peak_omega)
        peak = float(np.max(cert[3].upper))
        why = ("; the complexified D-K's controller is returned (D-G-K's first iterate: "
               f"mixed µ {peak:.4f}; no D-G-K iterate beat it)")
        return (K, 1, *cert, stop_reason + why, replace(rival, mu_peak=peak))
    dgk = (K, best_it, mine, "D-G-K's best iterate")
    cpx = (rival.K, 1 if started else 0, theirs, "the complexified D-K's controller")
    first, second = (cpx, dgk) if theirs.mu_peak < mine.mu_peak else (dgk, cpx)
    cert1 = _dense_certificate(setup, first[0], first[2].peak_omega)
    peak1 = float(np.max(cert1[3].upper))
    peaks = {first[3]: peak1}
    chosen, cert = first, cert1
    if peak1 > second[2].mu_lower_peak:
        cert2 = _dense_certificate(setup, second[0], second[2].peak_omega)
        peak2 = float(np.max(cert2[3].upper))
        peaks[second[3]] = peak2
        if peak2 < peak1 or (peak2 == peak1 and second is dgk):
            chosen, cert = second, cert2
    other = cpx if chosen is dgk else dgk
    said = (f"{peaks[other[3]]:.4f}" if other[3] in peaks
            else f"at least {other[2].mu_lower_peak:.4f} on the design grid")
    name = ("D-G-K's controller" if chosen is dgk else "the complexified D-K's controller")
    why = f"; {name} is returned (mixed µ {peaks[chosen[3]]:.4f}; {other[3]}: {said})"
    if chosen is cpx:
        logger.info("musyn: %s", why[2:])
    if cpx[3] in peaks:
        rival = replace(rival, mu_peak=peaks[cpx[3]])
    return (chosen[0], chosen[1], *cert, stop_reason + why, rival)


def _discrete_plant(P, nmeas: int, ncon: int) -> GeneralizedPlant | None:
    """``P`` as a plant when it is a discrete-time system (µ-synthesis then runs on its
    bilinear image, :mod:`.discrete`), else None."""
    sys = P.sys if isinstance(P, GeneralizedPlant) else P
    if not isinstance(sys, (control.StateSpace, control.TransferFunction)):
        return None  # an uncertain model: continuous time only
    if not sample_time(sys, "P"):
        return None
    return GeneralizedPlant.from_statespace(P, nmeas, ncon, discrete=True)


def _setup(P, nmeas, ncon, blk, omega, options, rng, constraints, lyapunov_scales, K0):
    """``musyn``'s arguments checked and gathered: ``(DKSetup, K0 checked or None)``."""
    from .steps import DKSetup
    from .steps.kstep import initial_controller

    opts = options if options is not None else MusynOptions()
    rng = rng if rng is not None else np.random.default_rng(0)
    P, blk = _with_uncertainty(P, blk, nmeas, ncon)
    G = GeneralizedPlant.from_statespace(P, nmeas, ncon)
    struct = BlockStructure.coerce(blk)
    constraints = tuple(constraints)
    nz_mu, nw_mu = struct.shape_M
    if constraints:
        fits = nz_mu <= G.nz and nw_mu <= G.nw
        if opts.method != "lmi":
            raise ParameterError("constraints ride in the LMI K-step: they need "
                                 f"method='lmi', got {opts.method!r}")
    else:
        fits = (nz_mu, nw_mu) == (G.nz, G.nw)
    if not fits:
        raise DimensionError(
            f"block structure needs F_l(P, K) of size {nz_mu}x{nw_mu} "
            f"(Σc x Σr); the plant's w -> z part is {G.nz}x{G.nw}")
    if lyapunov_scales is not None and len(tuple(lyapunov_scales)) != len(constraints):
        raise ParameterError(f"lyapunov_scales must hold one scale per constraint "
                             f"({len(constraints)}), got {lyapunov_scales!r}")
    # D-G-K keeps real blocks real (their G scalings absorbed into the scaled plant,
    # :mod:`.gfit`); complexify=True treats them as complex discs, as D-K always did
    mixed = not opts.complexify and any(b.is_real for b in struct.blocks)
    given = None if K0 is None else initial_controller(K0, G, struct, constraints)
    omega = default_omega(G) if omega is None else as_finite_array(omega, "omega").ravel()
    if omega.size < 3 or np.any(omega <= 0) or np.any(np.diff(omega) <= 0):
        raise ParameterError("omega must hold at least 3 strictly increasing positive frequencies")
    setup = DKSetup(G=G, struct=struct, dk_struct=struct if mixed else _complexified(struct),
                    mixed=mixed, free=(G.nw - nw_mu, G.nz - nz_mu), omega=omega,
                    options=opts, rng=rng, constraints=constraints,
                    lyapunov_scales=None if lyapunov_scales is None else tuple(lyapunov_scales))
    return setup, given


def _done(setup, it: int, mu_peak: float, gamma: float, gamma_prev: float,
          since_best: int, *, excused: bool) -> str | None:
    """Why D-K stops after iteration ``it``, or None: µ below target; a K-step worse on
    its scaled plant than the previous controller (it has lost accuracy, unless
    ``excused``; a constrained K-step's common Lyapunov matrix may well not reach the
    previous controller's level); patience; ``max_iter``."""
    opts = setup.options
    regressed = (opts.stop_on_kstep_regression and np.isfinite(gamma_prev)
                 and not setup.constraints and not excused
                 and gamma > gamma_prev * (1 + _KSTEP_RTOL))
    if mu_peak < opts.mu_target:
        return f"µ peak {mu_peak:.4f} below target {opts.mu_target}"
    if regressed:
        done = (f"the K-step at iteration {it} is worse on the scaled plant than the "
                f"previous controller (gamma {gamma:.4f} > {gamma_prev:.4f}): it has lost "
                "accuracy on this scaled plant")
        logger.info("musyn: %s", done)
        return done
    if since_best >= opts.patience:
        return f"no improvement of {opts.min_improvement:.1%} in {opts.patience} iterations"
    if it == opts.max_iter:
        return f"reached max_iter={opts.max_iter}"
    return None


def _over_budget(opts, t_start: float, t_prev: float, it: int, best_it: int) -> str | None:
    """Why the run stops for its ``time_budget`` after iteration ``it``, or None: where
    the time spent plus one more iteration as long as the last one (``t_prev`` its start)
    would pass the budget.  The iterations are the unit: a K-step is not interrupted."""
    if opts.time_budget is None:
        return None
    now = time.perf_counter()
    spent = now - t_start
    if spent + (now - t_prev) <= opts.time_budget:
        return None
    done = (f"time budget of {opts.time_budget:g} s: {spent:.1f} s spent after iteration "
            f"{it}, another would not fit; ending with the best iterate so far ({best_it})")
    logger.info("musyn: %s", done)
    return done


def _k_step_on(kstep, nxt, it: int, setup, *, first: bool):
    """The K-step of iteration ``it`` on ``nxt``'s plant: ``(syn, nxt, gamma_prev,
    failure)``.  Where it fails and the fit step left a plainer plant (over-relaxation's
    fallback), it runs once more on that one; ``failure`` is the error that ends D-K
    (raised instead at the first iteration, where there is no iterate to keep)."""
    gamma_prev = _previous_level(nxt, setup)
    while True:
        try:
            return kstep(nxt.PD, iteration=it, gamma_prev=gamma_prev), nxt, gamma_prev, None
        except LmiSuspensionError as exc:
            if first:
                raise
            if nxt.fallback is None:
                return None, nxt, gamma_prev, exc
            logger.info("musyn: K-step failed on the plant of iteration %d (%s); the fit "
                        "step's plainer plant instead", it, exc)
            try:
                nxt = nxt.fallback()
            except LmiSuspensionError as fit_exc:
                return None, nxt, gamma_prev, fit_exc
            gamma_prev = _previous_level(nxt, setup)


def _previous_level(nxt, setup) -> float:
    """The previous controller's norm on the next scaled plant (NaN before the first
    K-step): where a K-step that does not reach it has lost accuracy.  The fit step may
    have computed it already."""
    if nxt.gamma is not None:
        return nxt.gamma
    if nxt.K_ref is None:
        return float("nan")
    return float(hinfnorm(mu_part(lft(nxt.PD, nxt.K_ref, setup.nmeas, setup.ncon),
                                  setup.struct))[0])


def _with_uncertainty(P, blk, nmeas: int, ncon: int):
    """``(P, blk)`` of a certain plant as given; of an uncertain one, its ``lftdata``
    with the full performance block appended."""
    from ..umodel.lfr import _Uncertain
    from ..umodel.uss import lftdata

    if not isinstance(P, _Uncertain):
        if blk is None:
            raise ParameterError("blk is required for a certain plant (only an uncertain "
                                 "one carries its block structure)")
        return P, blk
    if blk is not None:
        raise ParameterError("an uncertain plant carries its block structure: do not "
                             "give blk with it")
    data = lftdata(P)
    nd = data.M.ninputs - data.nw - int(ncon)
    ne = data.M.noutputs - data.nz - int(nmeas)
    if nd < 1 or ne < 1:
        raise DimensionError(f"the uncertain plant has {nd} performance inputs and {ne} "
                             f"performance outputs besides ncon={ncon} and nmeas={nmeas}; "
                             "musyn needs at least one of each")
    rows = ([] if data.blk is None else data.blk.to_blk().tolist()) + [[nd, ne]]
    return data.M, rows


def _search_stage(G, nmeas, ncon, struct, omega, dstep, opts, rng, *, index, hinfsyn):
    """The direct D-scale search from a D-step (:mod:`.dsearch`), as one more record;
    None where it does not apply or finds no controller."""
    d_blocks, upper = dstep
    d_blocks = np.asarray(d_blocks)
    if d_blocks.ndim != 2 or int(opts.max_dfit_order) < 1:
        return None  # per-block magnitudes expected; constant scalings requested
    from ..synthesis.hinfsyn import riccati_achieves, riccati_level

    # the bisection search at free γ, whatever the loop's K-steps were given
    options = replace(_kstep_options(opts), riccati_search="bisection", gamma=None)

    def level(PD, bracket, rtol):
        return riccati_level(PD, nmeas, ncon, replace(options, riccati_rtol=rtol),
                             bracket=bracket)

    def achieves(PD, g):  # the test riccati_level bisects (it too ignores riccati_scale)
        return riccati_achieves(PD, nmeas, ncon, g)

    def check(PD, g):
        return hinfsyn(PD, nmeas, ncon, method="riccati",
                       options=replace(options, gamma=g * (1.0 + _CHECK_LEVEL))).gamma

    def controller(PD, g):
        balanced = _gramian_balanced(PD)
        realizations = (PD,) if balanced is None else (balanced, PD)
        return _best_certified(hinfsyn, PD, realizations, nmeas, ncon, options,
                               [g * (1.0 + r) for r in _SEARCH_LEVELS])[0]

    t0 = time.perf_counter()
    found = search_dscales(G.sys, nmeas, ncon, block_sizes(struct), omega, d_blocks,
                           0.2 + upper / np.max(upper), int(opts.max_dfit_order), level,
                           controller, check=check, achieves=achieves,
                           max_evals=int(opts.dscale_search),
                           target=float(opts.mu_target))
    if found is None:
        logger.info("musyn: D-scale search found no controller from the first iterate")
        return None
    t1 = time.perf_counter()
    CL = lft(G, found.K)
    if not np.all(np.real(CL.poles()) < 0):
        return None
    mu = _final_bounds(CL, struct, omega, rng)
    lower_peak = float(np.max(mu.lower))
    upper = np.asarray(mu.upper)
    k_peak = int(np.argmax(upper))
    logger.info("musyn: D-scale search, %d points in %.1f s: level %.5f -> %.5f, "
                "certified %.5f, mu %.4f", found.evaluations, found.seconds,
                found.level_start, found.level, found.gamma, upper[k_peak])
    return MusynIteration(
        index=index, gamma=found.gamma, mu_peak=float(upper[k_peak]),
        mu_lower_peak=lower_peak, peak_omega=float(omega[k_peak]),
        dfit_orders=tuple(max(o) for o in found.dfit.orders),
        controller_order=found.K.nstates, seconds_k=t1 - t0,
        seconds_d=time.perf_counter() - t1, seconds_fit=0.0,
        warnings=(f"D-scale search: {found.evaluations} points, Riccati level "
                  f"{found.level_start:.6g} -> {found.level:.6g}, controller certified "
                  f"{found.gamma:.6g}",)
        + _bound_check(found.gamma, lower_peak, "D-scale search"),
        gamma_prev=found.level_start, K=found.K, stage="dscale_search", PD=found.PD)


def _reduction(setup, K, final, dense, rng, scaled=None):
    """The returned controller's order reduction (``reduce_order``): ``(K, CL, CL_full,
    final, gamma)`` of the balanced truncation kept, or None.  A truncation is kept where
    its loop is stable, meets the constraints, and its µ is within ``reduce_mu_tol`` of
    the full order's dense-grid peak.  With ``"auto"`` the least such order is found by
    bisection between 1 and the full order (µ of a balanced truncation falls nearly
    monotonically with its order).

    Where the best iterate's scaled plant ``scaled`` is known (D-K, no constraints, its
    γ consistent with the dense grid), an order is judged first by the truncated
    controller's norm on it (:func:`_scaled_norm`): its fitted D scalings are feasible
    at every frequency, so that norm ``gamma`` bounds the truncated loop's µ at every
    frequency, one ``hinfnorm`` per order.  It is conservative (the scalings are the full
    loop's), so the order below the least one it passes is judged by µ on the dense grid
    too (where µ passes it, the bisection goes on by µ below it), and where no order
    below the full one passes the norm, the orders are judged by µ (:func:`_within`: the full loop's scalings at each dense
    frequency bound the truncated loop's µ there in one eigenvalue problem, and µ itself
    is computed only where that bound is above the limit; ``gamma`` is then inf).  The
    chosen order's µ on the whole dense grid is computed once, at the end.  On default
    ``musyn``'s distillation loop both judge the same order (15 of 22 states; 14 fails
    both); the order search took 0.61 s of CPU with the chosen order's dense µ, where
    the dense-grid judgement alone took 1.4 s (measured 2026-12-02)."""
    opts = setup.options
    if opts.reduce_order is None:
        return None
    limit = float(np.max(final.upper)) * (1.0 + opts.reduce_mu_tol)

    def truncated(order: int):
        K_red = _try_reduce(K, order)
        if K_red is None:
            return None
        CL_red_full = lft(setup.G, K_red)
        CL_red = balanced_statespace(mu_part(CL_red_full, setup.struct))
        if not (np.all(np.real(CL_red.poles()) < 0) and all(
                c.met for c in certificates(setup.constraints, CL_red_full))):
            logger.info("musyn: order %d: unstable loop or a constraint missed", order)
            return None
        return K_red, CL_red, CL_red_full

    def by_norm(order: int) -> float:
        loop = truncated(order)
        return np.inf if loop is None else _scaled_norm(scaled, loop[0], setup)

    def by_mu(order: int) -> bool:
        loop = truncated(order)
        return loop is not None and _within(loop[1], setup.struct, final, dense, limit, rng)

    def least(accepted, hi: int) -> int:
        lo = 1  # ``hi`` is acceptable; the least acceptable order is sought
        while lo < hi:
            mid = (lo + hi) // 2
            if accepted(mid):
                hi = mid
            else:
                lo = mid + 1
        return hi

    gammas: dict[int, float] = {}

    def norm_passes(order: int) -> bool:
        gammas[order] = by_norm(order)
        return gammas[order] <= limit

    if opts.reduce_order != "auto":
        order = int(opts.reduce_order)
        candidates = [order] if order < K.nstates and (
            (scaled is not None and norm_passes(order)) or by_mu(order)) else []
    else:
        hi = least(norm_passes, K.nstates) if scaled is not None else K.nstates
        if hi == K.nstates:
            hi = least(by_mu, K.nstates)
        elif hi > 1 and by_mu(hi - 1):  # the norm is conservative: µ may allow less
            hi = least(by_mu, hi - 1)
        candidates = list(range(hi, K.nstates))
    for order in candidates:  # the first, unless the dense µ disagrees with the judgement
        loop = truncated(order)
        if loop is None:
            continue
        K_red, CL_red, CL_red_full = loop
        final_red = _final_bounds(CL_red, setup.struct, dense, rng, seed=final)
        peak = float(np.max(final_red.upper))
        gamma = gammas.get(order, np.inf)
        logger.info("musyn: order %d: µ %.4f, scaled norm %.4f (full order %d: %.4f)", order,
                    peak, gamma, K.nstates, float(np.max(final.upper)))
        if peak <= limit or gamma <= limit:
            return K_red, CL_red, CL_red_full, final_red, gamma
    return None


def _scaled_norm(PD, K_red, setup) -> float:
    """``‖F_l(PD, K_red)‖∞`` on the µ channels: with ``PD`` a D-K scaled plant, an upper
    bound of µ of ``K_red``'s loop at every frequency."""
    return float(hinfnorm(mu_part(lft(PD, K_red, setup.nmeas, setup.ncon),
                                  setup.struct))[0])


def _within(CL_red, struct, final, dense, limit: float, rng) -> bool:
    """Whether µ of ``CL_red`` stays at or below ``limit`` on ``dense``.  The full loop's
    scalings (``final``) are feasible for any loop, so ``_certify`` with them bounds the
    truncated loop's µ at each frequency; where that bound exceeds ``limit``, µ's upper
    bound is computed (by :func:`_final_bounds`; with real blocks AB13MD's alone, no
    lower bound), in falling order of the bound, until one is above the limit.  The
    verdict is the dense grid's: on default ``musyn``'s distillation loop the order
    search found the same order (15) and µ (0.960037) as computing µ on the whole dense
    grid for every order tried, in 1.4 s of CPU instead of 5.8 s, the chosen order's
    dense µ included (measured 2026-12-02)."""
    from .bounds import _certify

    M = freqresp(CL_red, dense)
    XL = np.einsum("jik,jlk->ilk", final.D_left.conj(), final.D_left)
    XR = np.einsum("jik,jlk->ilk", final.D_right.conj(), final.D_right)
    beta = np.array([_certify(M[:, :, k], XL[:, :, k], XR[:, :, k], final.G[:, :, k])
                     for k in range(dense.size)])
    over = np.flatnonzero(beta > limit)
    over = over[np.argsort(-beta[over], kind="stable")]  # highest first
    for start in range(0, over.size, _REFINE_BATCH):
        batch = over[start:start + _REFINE_BATCH]
        # the verdict needs the upper bound alone (with real blocks no lower bound)
        mu = _final_bounds(CL_red, struct, dense[batch], rng, lower=False)
        if float(np.max(mu.upper)) > limit:
            return False
    return True


def _try_reduce(K: control.StateSpace, order: int):
    """Balanced truncation of ``K`` to ``order`` states, its modes near and right of the
    axis kept whole (:func:`~lmi_suspension.lti.reduce.balanced_truncation`); None where
    that fails or cannot reach ``order``."""
    try:
        K_red = balanced_truncation(K, order=order)[0]
    except Exception as exc:  # slycot and scipy raise plain ValueError/ArithmeticError kinds
        logger.info("musyn: order reduction to %d failed: %s", order, exc)
        return None
    return K_red if K_red.nstates <= order else None
