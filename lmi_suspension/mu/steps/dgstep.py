"""The D/G-step of D-K: µ bounds of the closed loop on the grid, and their scalings.

:class:`MussvStep` runs :func:`~lmi_suspension.mu.mussv` with the run's D/G-step
structure (``DKSetup.dk_struct``): D scalings for complex blocks, D and G scalings where
real blocks stay real (D-G-K).  With constraints it also takes µ at the loop's lightly
damped poles, whose sharp peaks a design grid steps over.  With real blocks (an AB13MD
structure) the µ lower bound is taken at the highest upper bounds only
(:func:`mixed_bounds`, also the dense certificate's).
"""

from __future__ import annotations

from dataclasses import replace

import control
import numpy as np

from ...lti.norms import freqresp
from . import DKSetup, LoopAnalysis

__all__ = ["MussvStep", "mixed_bounds", "lower_where_it_counts",
           "with_lower_where_it_counts"]


#: the mixed-µ lower bound of :func:`mixed_bounds` is computed at this many frequencies
#: of the highest upper bound, and at the ``_LOWER_PEAKS`` highest local maxima.  The
#: lower bound of a structure with real blocks (power iteration with the real blocks'
#: root finding) was 92 % of ``mussv``'s time on the two-mass plant's central loop
#: (60 points: upper 2.4 s, lower 38.1 s of wall time on a loaded machine; complex cover
#: 1.0 s for both, 2026-12-02), and the certificates need its peak, not its value
#: everywhere: the largest lower bound found anywhere is a lower bound of sup µ
_LOWER_POINTS = 6
_LOWER_PEAKS = 3


def lower_where_it_counts(struct) -> bool:
    """Whether :func:`mixed_bounds` applies: a structure with real blocks whose upper
    bound is SLICOT AB13MD's (square full blocks and single scalars), which needs no
    lower bound to bracket it (the LMI bound's bisection uses one)."""
    from ..bounds import _ab13md_blocks

    return bool(struct.has_real) and struct.n_in == struct.n_out and \
        _ab13md_blocks(struct) is not None


def mixed_bounds(M, struct, omega, rng, options=None):
    """``mussv``'s bounds of ``M`` for a structure of :func:`lower_where_it_counts`: the
    upper bound and its scalings at every frequency, the lower bound only at the
    frequencies of the highest upper bounds (``_LOWER_POINTS``) and the highest local
    maxima (``_LOWER_PEAKS``), zero elsewhere (still a lower bound of µ there).  The
    upper bounds, the scalings and the peak are ``mussv``'s own."""
    from ..bounds import MussvOptions, MussvTimings, mussv

    opts = MussvOptions() if options is None else options
    mu = mussv(M, struct, omega=omega, rng=rng, options=replace(opts, compute_lower=False))
    upper = np.asarray(mu.upper, dtype=float)
    if upper.ndim == 0 or upper.size == 0:
        return mussv(M, struct, omega=omega, rng=rng, options=opts)
    return with_lower_where_it_counts(mu, M, struct, omega, rng, opts)


def with_lower_where_it_counts(mu, M, struct, omega, rng, options=None):
    """``mu`` (upper bounds of ``M`` over ``omega`` and their scalings) with ``mussv``'s
    lower bound at the frequencies of the highest upper bounds (``_LOWER_POINTS``) and
    the highest local maxima (``_LOWER_PEAKS``), zero elsewhere; its ``lower`` and
    ``delta`` are replaced, its timings and warnings extended.  ``options``: ``mussv``'s
    for the lower bound (default :class:`~lmi_suspension.mu.bounds.MussvOptions`)."""
    from ..bounds import MussvOptions, MussvTimings, mussv

    opts = MussvOptions() if options is None else options
    upper = np.asarray(mu.upper, dtype=float)
    idx = list(np.argsort(-upper, kind="stable")[:_LOWER_POINTS])
    if upper.size >= 3:
        inner = np.flatnonzero((upper[1:-1] >= upper[:-2]) & (upper[1:-1] >= upper[2:])) + 1
        idx += list(inner[np.argsort(-upper[inner], kind="stable")][:_LOWER_PEAKS])
    idx = np.unique(np.asarray(idx, dtype=int))
    sub = mussv(np.asarray(M)[:, :, idx], struct, omega=np.asarray(omega)[idx], rng=rng,
                options=opts)
    lower = np.zeros_like(upper)
    lower[idx] = np.minimum(np.asarray(sub.lower), upper[idx])
    delta = np.zeros((*struct.shape_delta, upper.size), dtype=complex)
    delta[..., idx] = np.asarray(sub.delta)
    timings = MussvTimings(upper=mu.timings.upper, lower=sub.timings.total,
                           total=mu.timings.total + sub.timings.total)
    return replace(mu, lower=lower, delta=delta, timings=timings,
                   warnings=tuple(mu.warnings) + tuple(sub.warnings))


def _mu_bounds(CL, struct, omega, rng, M=None):
    """µ bounds of ``CL`` over ``omega``; pass its frequency response ``M`` if known.
    Returns ``(result, lower_peak)``; with real blocks the lower bound at the top
    frequencies only (:func:`mixed_bounds`)."""
    from ..bounds import mussv

    M = freqresp(CL, omega) if M is None else M
    if lower_where_it_counts(struct):
        mu = mixed_bounds(M, struct, omega, rng)
    else:
        mu = mussv(M, struct, omega=omega, rng=rng)
    return mu, float(np.max(mu.lower))


def resonances(CL: control.StateSpace, omega: np.ndarray) -> np.ndarray:
    """Frequencies (rad/s) of the loop's lightly damped poles (damping ζ below 0.3)
    within the design range: each pole's |p| and |Im p|, and the edges ``|p| (1 ± ζ)`` of
    its half-power band."""
    p = np.linalg.eigvals(np.asarray(CL.A)) if CL.nstates else np.zeros(0)
    p = p[p.imag > 0]
    w = np.abs(p)
    z = -p.real / w
    keep = (z < 0.3) & (w >= omega[0]) & (w <= omega[-1])
    p, w, z = p[keep], w[keep], z[keep]
    if not w.size:
        return np.zeros(0)
    pts = np.concatenate([w, w * (1 - z), w * (1 + z), p.imag])
    return np.unique(pts[pts > 0])


class MussvStep:
    """µ upper and lower bounds of the loop on the design grid (:func:`mussv`), and its
    optimal scalings.

    With constraints, a constrained K-step's loops can have lightly damped poles whose
    sharp µ peak falls between grid points (the seat: 1.22 on a 50-point grid, 2.36 on
    the dense one, 2026-11-25); µ is then also taken at those poles' frequencies
    (:func:`resonances`), and the peak is the larger.

    Parameters
    ----------
    setup : DKSetup
    """

    def __init__(self, setup: DKSetup):
        self.setup = setup

    def __call__(self, CL: control.StateSpace, K: control.StateSpace) -> LoopAnalysis:
        s = self.setup
        M = freqresp(CL, s.omega)  # one response for the D-step and the D-fit check
        mu, lower_peak = _mu_bounds(CL, s.dk_struct, s.omega, s.rng, M)
        upper = np.asarray(mu.upper)
        k_peak = int(np.argmax(upper))
        mu_peak, peak_omega = float(upper[k_peak]), float(s.omega[k_peak])
        if s.constraints:
            res_w = resonances(CL, s.omega)
            if res_w.size:
                from ..bounds import mussv

                at = mussv(freqresp(CL, res_w), s.dk_struct, omega=res_w, rng=s.rng)
                k_res = int(np.argmax(at.upper))
                if at.upper[k_res] > mu_peak:
                    mu_peak, peak_omega = float(at.upper[k_res]), float(res_w[k_res])
                lower_peak = max(lower_peak, float(np.max(at.lower)))
        return LoopAnalysis(M=M, mu=mu, upper=upper, mu_peak=mu_peak, peak_omega=peak_omega,
                            lower_peak=lower_peak, K=K)
