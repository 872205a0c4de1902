"""The fit step of D-K: rational scalings, absorbed into the next scaled plant.

:class:`DScaleFit` (D-K) fits the D-step's D scalings with stable, minimum-phase
transfer functions (:func:`~.dfit.fit_dscales`, the order chosen by the bound the next
K-step will see) and over-relaxes them (``MusynOptions.dscale_overrelax``,
:class:`_OverRelaxation`).  :class:`DGScaleFit` (D-G-K) fits the central D scalings of
the loop and absorbs the G scalings that are optimal for the previous controller's
D-scaled loop, realized exactly (:mod:`..gfit`).
"""

from __future__ import annotations

import functools
import logging
from dataclasses import replace

import control
import numpy as np

from ...lti.norms import freqresp, hinfnorm
from ...lti.plant import lft
from ...lti.reduce import balanced_truncation
from ...umodel.blocks import BlockStructure
from . import DKSetup, LoopAnalysis, NextPlant, ScaleFit, block_sizes, mu_part

logger = logging.getLogger(__name__)

__all__ = ["DScaleFit", "DGScaleFit", "default_fit"]

#: an over-relaxed D-fit whose scaled loop (previous controller) peaks this much above its
#: grid value is replaced by the plain one
_OFFGRID_RTOL = 0.05

def _scaled_peak(fits, M: np.ndarray, omega: np.ndarray, struct: BlockStructure) -> float:
    """``max_ω σ̄(D̂_L(jω) M(jω) D̂_R(jω)⁻¹)`` for rational D-scale fits: the bound the next
    K-step will actually see, so the D-fit order is chosen by it."""
    s = 1j * omega
    left = np.empty((M.shape[0], omega.size), dtype=complex)
    right = np.empty((M.shape[1], omega.size), dtype=complex)
    row = col = 0
    for block, fit in zip(struct.blocks, fits):
        resp = np.asarray(fit(s)).reshape(fit.noutputs, fit.ninputs, omega.size)
        diag = np.array([resp[k, k] for k in range(fit.noutputs)])  # (1 or r) x nf
        if diag.shape[0] == 1:
            left[row:row + block.cols] = diag[0]
            right[col:col + block.rows] = diag[0]
        else:
            left[row:row + block.cols] = diag
            right[col:col + block.rows] = diag
        row, col = row + block.cols, col + block.rows
    scaled = left[:, None, :] * M / right[None, :, :]
    return float(np.max(np.linalg.norm(np.moveaxis(scaled, -1, 0), ord=2, axis=(1, 2))))


def _fit_magnitudes(dfit, omega: np.ndarray) -> list[np.ndarray]:
    """``|d̂_i(jω)|`` of each block's fit (the first diagonal element of a matrix fit)."""
    s = 1j * omega
    return [np.abs(np.asarray(f(s)).reshape(f.noutputs, f.ninputs, omega.size)[0, 0])
            for f in dfit.fits]


def _overrelaxed(d_blocks, previous: list[np.ndarray], alpha: float) -> list[np.ndarray]:
    """``previous * (d / previous)**alpha`` per block: the D-step's change, extrapolated."""
    return [np.exp(np.log(p) + alpha * (np.log(np.asarray(d, dtype=float)) - np.log(p)))
            for d, p in zip(d_blocks, previous)]


class _OverRelaxation:
    """The D-step's choice of scalings under ``MusynOptions.dscale_overrelax``.

    Holds the fit behind the current scaled plant and the best iterate's D-step.  At the
    best iterate the fitted target is ``|D̂_prev| (d / |D̂_prev|)^α``; after an iterate that
    is not the best, one plain step from the best iterate (α halved towards 1 from then
    on); if that restart does not beat the best either, a plain step from where the loop
    is, since repeating the restart would repeat it exactly.
    """

    def __init__(self, alpha: float):
        self.alpha = alpha
        self._fit_mag = None  # |D̂(jω)| per block of the fit behind the current plant
        self._best = None  # LoopAnalysis of the best iterate
        self._restarted_from = None  # the iterate the previous D-step restarted from

    def step(self, it: int, best_it: int, here: LoopAnalysis):
        """``(source, target)``: the D-step to build the next plant around, and the
        scalings to fit."""
        if self.alpha <= 1.0 and self._best is None:
            return here, here.d_blocks  # plain D-K iteration
        if best_it == it:
            self._best, self._restarted_from = here, None
            if self._fit_mag is None or self.alpha <= 1.0:
                return here, here.d_blocks
            return here, _overrelaxed(here.d_blocks, self._fit_mag, self.alpha)
        if self._restarted_from == best_it:
            self._restarted_from = None
            return here, here.d_blocks
        self._restarted_from = best_it
        self._halve()
        logger.info("musyn: iteration %d is not the best; next D-step from iteration %d, "
                    "over-relaxation %.3g", it, best_it, self.alpha)
        return self._best, self._best.d_blocks

    def plain_from(self, it: int) -> None:
        """The next plant was rebuilt from iterate ``it``'s plain D-step (its K-step
        failed on the over-relaxed one): what a restart from ``it`` would build, so a
        restart is not repeated after it; α is halved towards 1, as after a restart."""
        self._restarted_from = it
        self._halve()

    def _halve(self) -> None:
        """α halved towards 1 (the over-relaxation overshot: a restart, or a failed
        K-step on the over-relaxed plant)."""
        self.alpha = 1.0 + (self.alpha - 1.0) / 2.0

    def fitted(self, magnitudes: list[np.ndarray]) -> None:
        """Record the fit the next scaled plant was built with."""
        self._fit_mag = magnitudes


def _scaled(G, nmeas, ncon, fit, struct, free):
    """The D-scaled plant; the constraint channels (``free`` inputs and outputs beyond
    ``blk``) pass unscaled."""
    from ..dfit import scaled_plant

    sizes = block_sizes(struct)
    if any(free):
        unit = control.ss([], [], [], [[1.0]])
        fit = replace(fit, fits=tuple(fit.fits) + (unit,), orders=tuple(fit.orders) + ((0,),),
                      errors=tuple(fit.errors) + (0.0,))
        sizes = sizes + [free]
    return scaled_plant(G, nmeas, ncon, fit, sizes)


#: states the G-scalings may add to the scaled plant when ``MusynOptions.max_gfit_poles``
#: is None (three per basis pole and real channel, :mod:`..gfit`).  On the oscillator of
#: tests/test_dgk.py (one real channel) 10 poles, 30 states, took D-G-K to 1.0069
#: (2026-11-27); on examples.uncertain_two_mass (two real channels) 10 poles, 60
#: states, the second K-step's LMI filled a 4 GB address space (a 784 MB allocation
#: failed under ``ulimit -v 4000000``), 3 poles, 18 states, kept the run at 811 MB
#: resident (2026-12-02)
_G_STATES_MAX = 30


def gfit_poles(opts, struct: BlockStructure) -> int:
    """The largest G basis D-G-K's fit may use: ``opts.max_gfit_poles``, or where that is
    None, as many as keep the G-scalings' states within ``_G_STATES_MAX``."""
    if opts.max_gfit_poles is not None:
        return int(opts.max_gfit_poles)
    channels = sum(b.rows for b in struct.blocks if b.is_real)
    return max(1, _G_STATES_MAX // (3 * max(channels, 1)))


def _dg_scaled(G, nmeas, ncon, struct, free, M, beta, omega, weights, opts, K_ref):
    """D-G-K's next plant (:mod:`.gfit`): the central D-scalings of the loop ``M`` at
    level ``beta``, fitted; then the G-scalings that minimise the level of ``K_ref``'s
    D-scaled loop on the grid (:func:`~.gfit.optimal_gscales`), absorbed."""
    from ..dfit import fit_dscales
    from ..gfit import central_dg, gscaled_plant, optimal_gscales

    d, _, _ = central_dg(M, struct, beta)
    fit = fit_dscales(omega, d, max_order=opts.max_dfit_order, rtol=opts.dfit_rtol,
                      weights=weights)
    PD = _scaled(G, nmeas, ncon, fit, struct, free)
    Mt = freqresp(mu_part(lft(PD, K_ref, nmeas, ncon), struct), omega)
    gfit = optimal_gscales(omega, Mt, struct, target=beta, max_poles=gfit_poles(opts, struct))
    logger.info("musyn: D-G scalings at level %.5g for the loop at %.5g", gfit.beta, beta)
    return fit, gscaled_plant(PD, nmeas, ncon, struct, gfit)




#: D-G-K's K-step sees the D-G-scaled plant balanced-truncated so that the truncation's
#: error bound (twice the sum of the stable part's dropped Hankel singular values) stays
#: below this, absolute: the scaled plant is normalised to a level of 1, so this is the
#: relative change the reduction can make to any controller's norm on it.  Every iterate
#: is certified on the unscaled closed loop, so the reduction costs no guarantee, only
#: possibly progress.  On the two-mass plant (examples.uncertain_two_mass, default
#: options, D-G-K alone) the scaled plants of 38 states went down to 25-29, its K-step
#: LMIs from 21-22 s to 5-11 s (wall, loaded machine), µ per iterate 1.9196, 1.7854,
#: 1.7282 against 1.9196, 1.7839, 1.7157 on the full plants (2026-12-02)
_KSTEP_REDUCE_TOL = 1e-2
#: largest relative change of the previous controller's norm on the reduced scaled plant
#: (against the full one) for which the reduced plant is used (see DGScaleFit)
_KSTEP_REDUCE_LOOP_RTOL = 2e-2
def reduced_for_kstep(PD: control.StateSpace, tol: float = _KSTEP_REDUCE_TOL):
    """``(PDr, bound)``: ``PD`` with its stable part balanced-truncated (SLICOT AB09AD,
    square-root method; :func:`~lmi_suspension.lti.reduce.balanced_truncation`) to the
    least order whose error bound ``2 Σ σ_dropped`` is at most ``tol``, and that bound
    (0 where nothing is dropped).  ``PD`` itself, bound 0, where the reduction fails
    (logged at INFO)."""
    try:
        return balanced_truncation(PD, tol=tol)
    except Exception as exc:  # slycot and scipy raise plain ValueError/ArithmeticError kinds
        logger.info("musyn: no reduction of the %d-state scaled plant (%s); the K-step sees "
                    "it whole", PD.nstates, exc)
        return PD, 0.0


def _orders(fit) -> tuple:
    return tuple(max(o) for o in fit.orders)


class DScaleFit:
    """D-K's fit step: the D scalings of the iterate :class:`_OverRelaxation` chooses,
    fitted with emphasis on the frequencies that set the peak (weights
    ``0.2 + µ/µ_peak``), their order chosen by the scaled bound on the grid.

    An over-relaxed fit is checked off the grid too: the previous controller's norm on
    the new plant must stay within ``_OFFGRID_RTOL`` of the fit's grid value, or the
    plain fit replaces it.  The plain fit also stays at hand (``NextPlant.fallback``)
    for a K-step that fails on the over-relaxed plant.

    Parameters
    ----------
    setup : DKSetup
    """

    def __init__(self, setup: DKSetup):
        self.setup = setup
        self.relax = _OverRelaxation(float(setup.options.dscale_overrelax))

    @property
    def restarts_from_best(self) -> bool:
        """Whether the next plant may restart from the best iterate (over-relaxation in
        effect): a K-step that does worse than the previous controller is then not
        taken for a loss of accuracy."""
        return self.relax.alpha > 1.0

    def _fitted(self, src: LoopAnalysis, d):
        from ..dfit import fit_dscales

        s, opts = self.setup, self.setup.options
        weights = 0.2 + src.upper / src.mu_peak
        fit = fit_dscales(s.omega, d, max_order=opts.max_dfit_order, rtol=opts.dfit_rtol,
                          weights=weights,
                          mu_check=lambda fits: _scaled_peak(fits, src.M, s.omega, s.dk_struct),
                          mu_peak=src.mu_peak)
        return fit, _scaled(s.G.sys, s.nmeas, s.ncon, fit, s.dk_struct, s.free)

    def __call__(self, here: LoopAnalysis, *, iteration: int, best_iteration: int) -> NextPlant:
        s = self.setup
        src, d_target = self.relax.step(iteration, best_iteration, here)
        d_plain = src.d_blocks
        fit, PD = self._fitted(src, d_target)
        gamma = None
        if d_target is not d_plain:
            # the grid check of the fit cannot see what the fit does between and beyond
            # the grid points; the controller's norm on the new scaled plant can (an
            # extrapolated fit on a coarse grid gave 1739 there against 1.04 on the
            # grid, measured)
            gamma = float(hinfnorm(mu_part(lft(PD, src.K, s.nmeas, s.ncon), s.struct))[0])
            if not gamma <= fit.mu_value * (1 + _OFFGRID_RTOL):
                logger.info("musyn: over-relaxed D-fit peaks off the grid (%.4g against "
                            "%.4g); plain D-step instead", gamma, fit.mu_value)
                fit, PD = self._fitted(src, d_plain)
                gamma = None
        fallback = None
        if d_target is not d_plain and gamma is not None:
            fallback = functools.partial(self._plain, src, iteration)
        self.relax.fitted(_fit_magnitudes(fit, s.omega))
        return NextPlant(PD=PD, orders=_orders(fit), K_ref=src.K, gamma=gamma,
                         fallback=fallback)

    def _plain(self, src: LoopAnalysis, iteration: int) -> NextPlant:
        """The plain D-step's plant of ``iteration``, for a K-step that failed on its
        over-relaxed one (distillation: a controller LMI that failed at every level on
        the plant of iteration 3, 2026-11-25)."""
        fit, PD = self._fitted(src, src.d_blocks)
        self.relax.fitted(_fit_magnitudes(fit, self.setup.omega))
        self.relax.plain_from(iteration)
        return NextPlant(PD=PD, orders=_orders(fit), K_ref=src.K)


class DGScaleFit:
    """D-G-K's fit step (:func:`_dg_scaled`): the central D-G scalings of the loop at its
    peak level, D fitted, G optimal for the previous controller's D-scaled loop and
    realized exactly, both absorbed.

    Parameters
    ----------
    setup : DKSetup
    """

    def __init__(self, setup: DKSetup):
        self.setup = setup

    def __call__(self, here: LoopAnalysis, *, iteration: int, best_iteration: int) -> NextPlant:
        s = self.setup
        weights = 0.2 + here.upper / here.mu_peak
        fit, PD = _dg_scaled(s.G.sys, s.nmeas, s.ncon, s.struct, s.free, here.M, here.mu_peak,
                             s.omega, weights, s.options, here.K)
        PDr, bound = reduced_for_kstep(PD)
        if PDr is PD:
            return NextPlant(PD=PD, orders=_orders(fit), K_ref=here.K)
        # the bound is open-loop: through the loop (I - P22 K)⁻¹ can amplify it, so the
        # reduced plant is kept only where the loop of the controller it was built
        # around has the same norm on both (the seat over m3 and k1: 1.77 on the reduced
        # plant against 1.00 on the full one, and the K-step on it went from µ 2.67 to
        # 3.22; 2026-12-02)
        level = self._level(PD, here.K)
        reduced = self._level(PDr, here.K)
        if not abs(reduced - level) <= _KSTEP_REDUCE_LOOP_RTOL * max(level, 1.0):
            logger.info("musyn: the scaled plant reduced from %d to %d states changes the "
                        "previous controller's level from %.4g to %.4g; the K-step sees it "
                        "whole", PD.nstates, PDr.nstates, level, reduced)
            return NextPlant(PD=PD, orders=_orders(fit), K_ref=here.K, gamma=level)
        logger.info("musyn: the scaled plant of %d states reduced to %d for the K-step "
                    "(error bound %.3g; the previous controller's level %.4g, on the full "
                    "plant %.4g)", PD.nstates, PDr.nstates, bound, reduced, level)
        return NextPlant(PD=PDr, orders=_orders(fit), K_ref=here.K, gamma=reduced)

    def _level(self, PD, K) -> float:
        """``K``'s norm on ``PD`` (its µ channels); inf where the loop is unstable."""
        s = self.setup
        CL = mu_part(lft(PD, K, s.nmeas, s.ncon), s.struct)
        if CL.nstates and not np.all(np.real(np.linalg.eigvals(np.asarray(CL.A))) < 0):
            return float("inf")
        return float(hinfnorm(CL)[0])


def default_fit(setup: DKSetup) -> ScaleFit:
    """:class:`DGScaleFit` where real blocks stay real, :class:`DScaleFit` otherwise."""
    return DGScaleFit(setup) if setup.mixed else DScaleFit(setup)
