"""µ-synthesis of a discrete-time plant on its bilinear image.

The bilinear (Tustin) map (:mod:`lmi_suspension.lti.bilinear`) carries the unit circle onto
the imaginary axis, frequency by frequency: the D-scaled closed loop of a discrete plant at
``exp(jω dt)`` is the image's at ``jω_c``, ``ω_c = (2/dt) tan(ω dt/2)``.  µ, its bounds,
the D (and G) scalings and the scaled H∞ norms of every D-K step are therefore the same
numbers on the plant and on its image, and stability is the same property.  So D-K runs on
the image, its D-scales are fitted there as continuous stable minimum-phase filters (their
discrete counterparts are their exact Tustin maps), and every controller it returns is
mapped back by :func:`~lmi_suspension.lti.bilinear.tustin`.  Only the frequency grid is
warped; the returned result is in the plant's time base throughout (its controllers, its
closed loop, its frequencies in rad/s up to ``π/dt``), and its µ peak is recomputed on the
discrete closed loop by :func:`~lmi_suspension.mu.mussv` as a certificate of the mapping.
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

from ..errors import NotBuiltError, ParameterError
from ..lti.bilinear import image_frequency, tustin, tustin_frequency, tustin_image
from ..lti.checks import as_finite_array
from ..lti.norms import freqresp
from ..lti.plant import GeneralizedPlant, lft

logger = logging.getLogger(__name__)

#: relative disagreement between the image's µ peak and the discrete loop's own, beyond
#: which the result carries a warning: both are one upper bound at the same frequency of
#: one transfer function, so they differ by the roundoff of two realizations (6e-10 on the
#: Tustin image of the distillation problem at 0.1 s, 2026-12-02)
_MAPPING_RTOL = 1e-6


def musyn_discrete(musyn, G: GeneralizedPlant, nmeas: int, ncon: int, blk, *, omega,
                   options, callback, rng, constraints, lyapunov_scales, K0, steps):
    """:func:`~lmi_suspension.mu.musyn` for a discrete-time plant ``G`` (``musyn`` is the
    continuous routine, passed in to keep this module below it)."""
    from .bounds import mussv

    if constraints:
        raise NotBuiltError("musyn with constraints is built for continuous-time plants only "
                            "(an H2 or peak bound is not preserved by the bilinear map)")
    dt = G.dt
    Gc = tustin_image(G.sys)
    omega_c = None
    if omega is not None:
        w = as_finite_array(omega, "omega").ravel()
        if np.any(w <= 0) or np.any(w >= np.pi / dt):
            raise ParameterError(f"omega of a discrete plant must lie in (0, pi/dt) = "
                                 f"(0, {np.pi / dt:.6g}) rad/s")
        omega_c = image_frequency(w, dt)
    K0c = None if K0 is None else tustin_image(K0)

    def to_discrete(rec):
        K = None if rec.K is None else tustin(rec.K, dt)
        PD = None if rec.PD is None else tustin(rec.PD, dt)  # F_l commutes with the map
        return dataclasses.replace(rec, K=K, PD=PD, peak_omega=float(_back(rec.peak_omega, dt)))

    res = musyn(Gc, nmeas, ncon, blk, omega=omega_c, options=options,
                callback=None if callback is None else (lambda rec: callback(to_discrete(rec))),
                rng=rng, lyapunov_scales=lyapunov_scales, K0=K0c, steps=steps)
    K = tustin(res.K, dt)
    CL = lft(G.sys, K, nmeas, ncon)
    nz, nw = res.CL.noutputs, res.CL.ninputs
    CL = CL[:nz, :nw] if (CL.noutputs, CL.ninputs) != (nz, nw) else CL
    peak_omega = float(_back(res.peak_omega, dt))
    warnings = list(res.warnings)
    # the certificate of the mapping: µ of the discrete loop at the peak's own frequency
    check = mussv(freqresp(CL, [min(peak_omega, np.pi / dt * (1 - 1e-12))]), res.mu.blk,
                  method="lmi")
    again = float(np.max(np.atleast_1d(check.upper)))
    if abs(again - res.mu_peak) > _MAPPING_RTOL * max(1.0, res.mu_peak):
        warnings.append(f"the discrete closed loop's µ bound at the peak, {again:.9g}, differs "
                        f"from its bilinear image's {res.mu_peak:.9g}")
    mu = dataclasses.replace(res.mu, omega=None if res.mu.omega is None
                             else _back(res.mu.omega, dt),
                             peak_omega=None if res.mu.peak_omega is None
                             else float(_back(res.mu.peak_omega, dt)))
    return dataclasses.replace(
        res, K=K, CL=CL, peak_omega=peak_omega, mu=mu, omega=_back(res.omega, dt),
        K_full=None if res.K_full is None else tustin(res.K_full, dt),
        history=tuple(to_discrete(r) for r in res.history), warnings=tuple(warnings),
        complex_run=None if res.complex_run is None else dataclasses.replace(
            res.complex_run, K=tustin(res.complex_run.K, dt),
            history=tuple(to_discrete(r) for r in res.complex_run.history)))


def _back(omega_c, dt: float):
    w = np.asarray(omega_c, dtype=float)
    return np.where(np.isinf(w), np.pi / dt, tustin_frequency(np.where(np.isinf(w), 0, w), dt))
