"""µ bounds, worst-case force and stroke, and pole magnitudes of any seat controller
(:func:`certify_constrained`): the part of every seat certificate
(:func:`~.record.certify_seat`) that the frequency domain gives, recomputed from the
controller alone.  It began as the constrained design's check (:mod:`.constrained`), whose
weights are its default; it holds no design code.
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

from ..synthesis.constraints import Channel, PeakBound
from .augmented import CONSTRAINED_DESIGN, SeatDesignOptions, seat_augmented_plant
from .params import SeatParameters
from .roads import bump, road_energy

__all__ = ["ConstrainedCheck", "certify_constrained"]

#: The default grid, rad/s: the constrained design's range (``CONSTRAINED_OMEGA`` of
#: :mod:`.constrained`, 1e-3 to 10^3.5 rad/s) at 300 points.
_OMEGA = np.logspace(-3.0, 3.5, 300)


@dataclass(frozen=True)
class ConstrainedCheck:
    """What a seat controller achieves against the constrained design's requirements,
    recomputed from the controller alone (:func:`certify_constrained`).

    Attributes
    ----------
    mu_peak, mu_lower_peak : float
        µ bounds' peaks over ``omega`` (delay cover 0–25 ms and performance).
    omega, mu_upper, mu_lower : ndarray
        The grid (rad/s) and the bounds on it.
    u_peak, x1_peak : float
        Worst-case ``|u|`` (N) and ``|x1|`` (m) over every floor velocity of energy
        ``energy`` (closed-loop Gramian).
    energy : float
    fastest_pole, controller_fastest_pole : float
        Largest closed-loop and controller pole magnitudes, rad/s.
    """

    mu_peak: float
    mu_lower_peak: float
    omega: np.ndarray
    mu_upper: np.ndarray
    mu_lower: np.ndarray
    u_peak: float
    x1_peak: float
    energy: float
    fastest_pole: float
    controller_fastest_pole: float


def certify_constrained(K, *, design: SeatDesignOptions | None = None,
                        params: SeatParameters | None = None, energy: float | None = None,
                        omega=None, rng: np.random.Generator | None = None
                        ) -> ConstrainedCheck:
    """µ bounds, worst-case force and stroke, and pole magnitudes of a seat controller
    (any: the µ controller's figures come out the same way).

    Examples
    --------
    >>> import control
    >>> c = certify_constrained(control.ss([], [], [], [[0.0, 0.0]]),
    ...                         omega=np.logspace(-1, 3, 20))
    >>> c.u_peak, round(c.x1_peak, 4)      # the passive seat: no force, 0.064 m
    (0.0, 0.0642)
    """
    from ..lti import freqresp, lft
    from ..mu import mussv
    from ..mu.steps import mu_part as _mu_part
    from ..umodel.blocks import BlockStructure

    E = road_energy(bump()) if energy is None else float(energy)
    aug = seat_augmented_plant(CONSTRAINED_DESIGN if design is None else design, params,
                               peak_channels=True)
    omega = _OMEGA if omega is None else np.asarray(omega, dtype=float)
    K = control.ss(K.A, K.B, K.C, K.D)
    CL = lft(aug.P, K, aug.nmeas, aug.ncon)
    struct = BlockStructure.coerce(aug.blk)
    nz, nw = struct.shape_M
    bounds = mussv(freqresp(_mu_part(CL, struct), omega), aug.blk,
                   omega=omega, rng=np.random.default_rng(0) if rng is None else rng)
    peaks = PeakBound(Channel(outputs=(nz, nz + 1), inputs=(nw,)), (1.0, 1.0)).peaks(CL) * E
    fast = (lambda M: float(np.max(np.abs(np.linalg.eigvals(M)))) if M.size else 0.0)
    return ConstrainedCheck(
        mu_peak=float(np.max(bounds.upper)), mu_lower_peak=float(np.max(bounds.lower)),
        omega=omega, mu_upper=np.asarray(bounds.upper), mu_lower=np.asarray(bounds.lower),
        u_peak=float(peaks[0]), x1_peak=float(peaks[1]), energy=E,
        fastest_pole=fast(np.asarray(CL.A)), controller_fastest_pole=fast(np.asarray(K.A)))
