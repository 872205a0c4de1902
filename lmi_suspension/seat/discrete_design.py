"""The seat designed at its sample rate: µ-synthesis on the augmented plant sampled at
1 kHz, certified against the actuator delay in whole samples.

Every other seat route designs in continuous time and discretises the controller
afterwards (:mod:`.sampled`); here the augmented plant of Fig. 2
(:func:`~.augmented.seat_augmented_plant`) is sampled behind a zero-order hold on the
force, and D-K runs on the sampled plant (:func:`~lmi_suspension.mu.musyn` on a discrete
plant: on its bilinear image, every result mapped back).  The controller is then what the
board runs, with no bound on its poles but the unit circle.

At ``dt`` the delays a board can have are whole samples, ``z⁻ᵏ`` for ``k = 0 … 25`` at
1 kHz, a finite set.  The design keeps the continuous delay cover (its envelope covers
every ``e^{-jωd}``, ``0 <= d <= 25`` ms, so every ``z⁻ᵏ`` on the unit circle, and the
hold's half sample); the certificate checks that finite set exactly:
:func:`integer_delay_radii` closes the sampled seat with ``z⁻ᵏ`` on the force and the
controller, for every ``k``, and returns each loop's spectral radius.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import control
import numpy as np

from ..errors import ParameterError
from ..lti.bilinear import tustin_image
from ..lti.checks import as_statespace, positive_scalar, sample_time
from ..mu import MusynOptions, MusynResult, musyn
from .augmented import (
    DEFAULT_DESIGN,
    SeatAugmentedPlant,
    SeatDesignOptions,
    seat_augmented_plant,
)
from .design import DEFAULT_MUSYN, DEFAULT_OMEGA
from .model import seat_model
from .params import SeatParameters
from .sampled import DEFAULT_SAMPLE_TIME

__all__ = ["DiscreteMuRoute", "SHIPPED_DISCRETE", "SeatDiscreteDesign",
           "design_discrete_mu_controller", "integer_delay_radii", "sampled_augmented_plant"]

#: the shipped design (``DiscreteMuRoute().design`` at the nominal seat, seed 0; its D-K
#: takes about a minute, so ``reproduce`` loads and re-certifies it)
SHIPPED_DISCRETE = Path(__file__).parent / "data" / "mu_1khz.json"

logger = logging.getLogger(__name__)

#: the design grid stops this fraction of the Nyquist rate short of it: DEFAULT_OMEGA
#: reaches 3162 rad/s, beyond π/dt at 1 kHz
_NYQUIST_FRACTION = 0.9


@dataclass(frozen=True)
class SeatDiscreteDesign:
    """A seat controller designed at its sample rate.

    Attributes
    ----------
    K : control.StateSpace
        Discrete controller (sample time ``dt``) from ``y = [x1, x3]`` (m) to ``u`` (N).
    aug : SeatAugmentedPlant
        The augmented plant sampled at ``dt`` (zero-order hold).
    musyn : MusynResult
        The D-K run (discrete throughout, see :mod:`lmi_suspension.mu.discrete`).
    mu_peak, mu_lower_peak : float
        µ bounds of the sampled loop over the dense grid (robust performance over the
        delay cover).
    delay_radii : tuple of float
        Spectral radius of the nominal sampled seat's loop with the force delayed by
        ``k`` whole samples, ``k = 0, 1, …`` up to the cover's largest delay: all below 1
        means stable at every delay the board can have.
    dt, seconds : float
    """

    K: control.StateSpace
    aug: SeatAugmentedPlant
    musyn: MusynResult
    mu_peak: float
    mu_lower_peak: float
    delay_radii: tuple
    dt: float
    seconds: float

    def __iter__(self):
        return iter((self.K, self.musyn.CL, self.mu_peak, self))


def sampled_augmented_plant(dt: float = DEFAULT_SAMPLE_TIME,
                            design: SeatDesignOptions | None = None,
                            params: SeatParameters | None = None) -> SeatAugmentedPlant:
    """The augmented seat plant sampled at ``dt`` behind a zero-order hold (on every
    input: the force is held by the board; the disturbance and noise channels are
    design signals, held likewise).

    Examples
    --------
    >>> aug = sampled_augmented_plant(1e-3)
    >>> aug.P.dt, aug.blk.tolist()
    (0.001, [[1, 1], [3, 3]])
    """
    dt = positive_scalar(dt, "dt")
    aug = seat_augmented_plant(DEFAULT_DESIGN if design is None else design, params)
    Pd = control.sample_system(aug.P, dt, method="zoh")
    Pd = control.ss(Pd.A, Pd.B, Pd.C, Pd.D, dt, inputs=aug.P.input_labels,
                    outputs=aug.P.output_labels, name="P_seat_sampled")
    return SeatAugmentedPlant(P=Pd, nmeas=aug.nmeas, ncon=aug.ncon, blk=aug.blk,
                              block_names=aug.block_names, options=aug.options,
                              params=aug.params, delay=aug.delay)


def integer_delay_radii(Kd, delays, params: SeatParameters | None = None) -> np.ndarray:
    """Spectral radius of the nominal seat sampled at ``Kd.dt`` (zero-order hold on the
    force) in the loop ``u = Kd y`` with the force delayed by ``k`` samples, for each
    ``k`` of ``delays`` (whole numbers of samples).

    Examples
    --------
    >>> import control
    >>> Kd = control.ss([], [], [], [[0.0, 0.0]], 1e-3)   # the passive seat
    >>> bool(integer_delay_radii(Kd, [0, 25]).max() < 1)
    True
    """
    Kd = as_statespace(Kd, "Kd", discrete=True)
    dt = sample_time(Kd, "Kd")
    if not dt:
        raise ParameterError("integer_delay_radii needs a discrete controller (Kd.dt > 0)")
    ks = np.asarray(delays)
    if ks.ndim != 1 or np.any(ks < 0) or np.any(ks != np.round(ks)):
        raise ParameterError(f"delays must be whole numbers of samples >= 0, got {delays!r}")
    G = seat_model(params)
    Gd = control.sample_system(control.ss(G.A, G.B[:, 1:], G.C[3:5], np.zeros((2, 1))), dt,
                               method="zoh")
    radii = []
    for k in ks.astype(int):
        # a k-sample shift register on the force, then the seat, closed by u = Kd y
        if k:
            S = control.ss(np.eye(k, k, -1), np.eye(k, 1), np.eye(1, k, k - 1),
                           np.zeros((1, 1)), dt)
            L = control.series(S, Gd)
        else:
            L = Gd
        CL = control.feedback(L, Kd, sign=+1)
        A = np.asarray(CL.A)
        radii.append(float(np.max(np.abs(np.linalg.eigvals(A)))) if A.size else 0.0)
    return np.asarray(radii)


def design_discrete_mu_controller(dt: float = DEFAULT_SAMPLE_TIME,
                                  design: SeatDesignOptions | None = None, *,
                                  params: SeatParameters | None = None,
                                  musyn_options: MusynOptions | None = None, omega=None,
                                  rng: np.random.Generator | None = None) -> SeatDiscreteDesign:
    """Robust seat controller by µ-synthesis on the augmented plant sampled at ``dt``.

    Parameters
    ----------
    dt : float
        Sample time, s (1 kHz by default).
    design, params, musyn_options, rng
        As :func:`~.design.design_mu_controller` (the continuous design's defaults).
    omega : array_like, optional
        Design grid, rad/s, below ``π/dt`` (default: the continuous design's grid up to
        ``0.9 π/dt``).

    Returns
    -------
    SeatDiscreteDesign
    """
    t0 = time.perf_counter()
    dt = positive_scalar(dt, "dt")
    aug = sampled_augmented_plant(dt, design, params)
    w = DEFAULT_OMEGA[DEFAULT_OMEGA < _NYQUIST_FRACTION * np.pi / dt] if omega is None \
        else np.asarray(omega, dtype=float)
    res = musyn(aug.P, aug.nmeas, aug.ncon, aug.blk, omega=w,
                options=DEFAULT_MUSYN if musyn_options is None else musyn_options,
                rng=np.random.default_rng(0) if rng is None else rng)
    K = control.ss(res.K.A, res.K.B, res.K.C, res.K.D, dt, inputs=["x1", "x3"],
                   outputs=["u"], name="K_seat_discrete")
    d_max = aug.delay.d_max if aug.delay is not None else 0.0
    radii = integer_delay_radii(K, np.arange(int(round(d_max / dt)) + 1), aug.params)
    seconds = time.perf_counter() - t0
    logger.info("discrete seat µ design at %g s: µ %.4f, K order %d, largest radius over "
                "the integer delays %.6f, %.1f s", dt, res.mu_peak, K.nstates,
                float(np.max(radii)), seconds)
    return SeatDiscreteDesign(K=K, aug=aug, musyn=res, mu_peak=res.mu_peak,
                              mu_lower_peak=res.mu_lower_peak,
                              delay_radii=tuple(float(r) for r in radii), dt=dt,
                              seconds=seconds)


@dataclass(frozen=True)
class DiscreteMuRoute:
    """µ-synthesis at the board's sample rate (:func:`design_discrete_mu_controller`) as a
    :class:`~.routes.SeatRoute`; the design's ``Kd`` is the controller, ``K`` its bilinear
    image (``primary == "discrete"``).

    Examples
    --------
    >>> DiscreteMuRoute().name, DiscreteMuRoute().dt
    ('discrete', 0.001)
    """

    name: ClassVar[str] = "discrete"
    dt: float = DEFAULT_SAMPLE_TIME
    design_options: SeatDesignOptions | None = None
    musyn_options: MusynOptions | None = None

    def design(self, params: SeatParameters, *, rng: np.random.Generator, progress=None):
        """:func:`design_discrete_mu_controller` at ``params``, as a
        :class:`~.record.SeatDesign`."""
        from .record import seat_design_from

        d = design_discrete_mu_controller(self.dt, self.design_options, params=params,
                                          musyn_options=self.musyn_options, rng=rng)
        if progress is not None:
            progress(f"µ {d.mu_peak:.4f} at {1 / d.dt:g} Hz, K order {d.K.nstates}")
        return seat_design_from(
            self.name, tustin_image(d.K), Kd=d.K, primary="discrete", params=params,
            weights=d.aug.options, seconds=d.seconds, detail=d,
            description=f"µ-synthesis at {1 / d.dt:g} Hz (D-K on the sampled plant): "
                        "y = [x1, x3] (m) -> u (N)",
            figures={"mu_peak_upper": d.mu_peak, "mu_peak_lower": d.mu_lower_peak,
                     "stop_reason": d.musyn.stop_reason,
                     "delay_radius_max": float(max(d.delay_radii)),
                     "delay_samples": len(d.delay_radii) - 1})
