"""The robust µ design of the seat suspension (and its nominal H∞ comparison controller).

:func:`design_mu_controller` runs D-K iteration (:func:`~lmi_suspension.mu.musyn`) on the
augmented plant of Fig. 2 (:func:`~lmi_suspension.seat.augmented.seat_augmented_plant`;
by default with the delay cover, 0–25 ms, as its uncertainty) and re-evaluates µ of the
returned controller on a dense grid.  :func:`analyse_uncertainty` computes that
controller's µ with the paper's norm-bounded blocks added.  :func:`design_nominal_hinf`
is the comparison controller: H∞ on the same performance weights with an ideal actuator
and no uncertainty.

Status of the tuning (measured 2026-11-23, see tests/test_design.py and the notes of
issue 6): the default design certifies robust performance, µ = 0.854 < 1 (upper = lower
bound on the dense grid), for the structure it is synthesised on — the delay cover
(0–25 ms) and the performance block — and keeps the bump peak z̈3 within 1.5 × the
physical limit (6.164 m/s²) at every delay 0–25 ms (7.35–9.07 m/s², 1.19–1.47 × the
limit, checked every 2.5 ms; passive 26.5) with a delay margin of 0.216 s. µ < 1 is a
statement about the weights and about energy: for every delay in the cover and every
floor velocity ``W_d w`` plus sensor noise with ``‖[w; n]‖₂ ≤ 1`` (``W_d`` shaped like
the bump's spectrum, see :data:`DEFAULT_DESIGN`), the stacked error
``[W_k z̈3 / acc_ref; u / u_max; x1 / z_max]`` has ``‖·‖₂ < 1``. The peak (time-domain)
targets do not follow from it; they are checked by exact-delay simulation.
Two uncertainty channels are left out of the synthesis. The complex cover of the
occupant mass m3 ∈ [30, 70] kg destabilises the lightly damped body mode (µ ≈ 3.5
whatever the controller). The paper's norm-bounded blocks, with the reconstructed
``E_B = δ e2`` acting on the force in newtons, give the first K-step γ ≈ 160 (4.3
without them) and D-K ends at µ 2.20 with a controller that uses ≤ 634 N on the bump
(peaks 23–25 m/s²); even with that channel scaled like the delay channel D-K ends at
µ 1.008. Through L1 (rows 2, 4, 6) that E_B lets up to 3 % of the actuator force act on
the upper body directly, a path the actuator does not have, and the default controller
gives µ 3.20 on it. With E_B = 0 (printed empty in the paper) the default controller
certifies µ = 0.901 (upper = lower bound) on the structure with all paper blocks, but
synthesising on that structure leads D-K to a controller with a 10.6 m/s² peak at
25 ms. Occupant-mass and stiffness variation is checked instead by Monte-Carlo
simulation (reproduce).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, replace
from typing import ClassVar

import control
import numpy as np

from ..mu import MusynOptions, MusynResult, musyn
from .augmented import SeatAugmentedPlant, SeatDesignOptions, seat_augmented_plant
from .params import SeatParameters

__all__ = ["DEFAULT_DESIGN", "DEFAULT_MUSYN", "DEFAULT_OMEGA", "MuCheck", "MuRoute",
           "SeatMuDesign", "analyse_uncertainty", "design_mu_controller",
           "design_nominal_hinf"]

logger = logging.getLogger(__name__)

#: Weights of the robust design. The disturbance model is shaped like the bump it has to
#: reject: ``w_scale s/(s + w_corner) · ω_r²/(s² + √2 ω_r s + ω_r²)`` m/s per unit ``w``
#: follows the velocity spectrum ``|Ẑ0(jω)|`` of eq. (32) over 1–30 rad/s and falls off
#: with it above its main lobe (≈ 45 rad/s), where a flat design disturbance made µ peak
#: (65 rad/s) in a band in which the 25 ms delay forbids control and the bump has no
#: energy. Measured 2026-11-23 (seed 0, idle 2-core machine, ≈ 3 s with the bisection
#: Riccati K-step): certified µ = 0.854 (upper = lower bound) over the delay cover; bump
#: peak z̈3 9.06 / 8.42 / 7.87 / 7.34 / 7.79 / 9.03 m/s² at 0 / 5 / … / 25 ms, i.e. 1.47 / 1.37 /
#: 1.28 / 1.19 / 1.26 / 1.46 × the physical limit 6.164 (at most 1.471 on a 2.5 ms grid
#: over 0–25 ms; was 1.25–1.60 with acc_ref 3, u_max 3000, z_max 0.10, noise 0.5 mm,
#: w_corner 13.5, w_rolloff 45, delay_order 2: 9.86 m/s² at 0 ms, 9.71 at 25 ms); peak
#: x1 0.060 m (≤ 0.08); delay margin 0.216 s. What limits the two ends is different:
#: at 0 ms the controller commands up to 2830 N and the 1500 N saturation sets the peak
#: (3.3 m/s² without saturation); at 25 ms the peak is the linear loop's (8.2 m/s²
#: unsaturated). Larger force scales lower the 25 ms peak, more x1 noise and a lower
#: floor-velocity corner lower the 0 ms peak (≈ 100 trials, the report on issue 6).
DEFAULT_DESIGN = SeatDesignOptions(
    # Wk-weighted z̈3 of 3.14 m/s² per unit w (with the force and stroke scales below;
    # 3.0: µ 0.874 and 9.17 / 8.87 m/s² at 0 / 25 ms; 3.3: µ 0.832 and 8.98 / 9.19).
    acc_ref=3.14,
    # Second-order Wk: the fourth-order fit's slow poles make the LMI K-step's controller
    # reconstruction fail (SolverError) even on the nominal plant; order 2 solves.
    wk_order=2,
    # Force and stroke scales of the error (tuning knobs, not the limits): 7000 N and
    # 0.114 m. A smaller force scale does not lower the force the controller asks for on
    # the bump (≈ 2500 N at 1000–1500 N scales, measured) but makes the loop less
    # tolerant of the delay (25 ms peak 11.2–14.8 m/s²); with the other weights below,
    # 3000 → 7000 N takes the 25 ms peak from 10.09 to 9.02 m/s² (0 ms: 8.85 → 9.07).
    # The limits themselves are checked by the exact-delay simulation, which saturates
    # the force at params.u_max = 1500 N and keeps |x1| ≤ 0.060 m on the bump.
    u_max=7000.0,
    z_max=0.114,
    # Sensor noise per unit n: 1.7 mm on x1 and 0.1 mm on x3. More noise on x1 lowers
    # the (saturation-limited) 0 ms peak and raises the 25 ms one; less on x3 lowers
    # the 25 ms peak (0.5 mm on x3: 9.07 / 9.44 m/s² at 0 / 25 ms). Both keep D21 full
    # rank (regular H∞ problem).
    noise=(1.7e-3, 1e-4),
    # Level, corner and roll-off of the bump-shaped floor velocity (see above): the
    # corner is near the bump's low-frequency slope (|Ẑ0| ≈ 0.012 m·s × ω, area of the
    # 0.1 m × 0.24 s raised cosine, against its peak 0.162 m at ≈ 21 rad/s; 13.5 rad/s
    # matches it but gives 9.32 / 8.71 m/s² at 0 / 25 ms, 12.5 gives 9.19 / 8.86); the
    # roll-off at 42.3 rad/s gives up the band above the main lobe (60 → 45 lowered µ
    # from 0.976 to 0.879 with earlier weights; 45 here: 9.11 / 8.87 m/s²).
    w_scale=0.45,
    w_corner=11.5,
    w_rolloff=42.3,
    force_rolloff_ratio=1.0,
    # Third-order delay cover: tighter than order 2, which with the weights above ends at
    # µ 0.927 and 9.34 / 8.80 m/s² at 0 / 25 ms (over 1.5 × the limit at 0 ms).
    delay_order=3,
    # Synthesised uncertainty: the delay cover only (see the module docstring).
    include_parametric=False,
    include_paper=False,
    parametric_complex=True,
)

#: D-K settings: each K-step runs the certified Riccati γ search (plant as given and
#: balanced) and, on the first iteration or when Riccati does not beat the previous
#: controller, the LMI route, and keeps the lowest certified γ; constant D-scales
#: (measured 2026-11-23: order-1 fits ended at µ 1.05–1.11 instead of 0.94–0.98, and with
#: order-2 fits the second K-step ran > 80 s); four iterations (µ 4.277, 1.447, 0.984,
#: 0.851 on the design grid; 0.854 on the dense one) take ≈ 3 s on the idle 2-core
#: machine.  With method="lmi" alone: µ 0.827 in 46 s, but a bump peak of 10.2 m/s² at
#: 25 ms (1.66 × the limit); with "riccati" alone: the same controller as "best" in 1.5 s.
#: A fifth iteration is not taken: it lowers µ to 0.811 but raises the bump peaks to
#: 9.15 / 9.22 m/s² at 0 / 25 ms and the design time to ≈ 30 s (measured).  Plain D-K
#: steps (no over-relaxation of the D-scales): the design and its figures were tuned so.
DEFAULT_MUSYN = MusynOptions(method="best", max_iter=4, patience=1, max_dfit_order=0,
                             n_dense=120, dscale_overrelax=1.0)

#: Design grid, rad/s: 0.1 rad/s (below the Wk band) to ≈ 3000 rad/s (above 1/(25 ms)).
DEFAULT_OMEGA = np.logspace(-1.0, 3.5, 50)


@dataclass(frozen=True)
class SeatMuDesign:
    """A robust seat controller and its certificate.

    Attributes
    ----------
    K : control.StateSpace
        Controller from ``y = [x1, x3]`` (m) to ``u`` (N, sign of eq. 1); inputs
        ``['x1', 'x3']``, output ``['u']``.
    aug : SeatAugmentedPlant
        The plant it was designed on.
    musyn : MusynResult
        The full D-K result (history, stop reason, dense-grid bounds).
    mu_peak, mu_lower_peak : float
        Peaks of the µ upper and lower bounds on the dense grid.
    omega, mu_upper, mu_lower : ndarray
        The dense grid (rad/s) and the bounds on it.
    seconds : float
        Wall time of the design.
    """

    K: control.StateSpace
    aug: SeatAugmentedPlant
    musyn: MusynResult
    mu_peak: float
    mu_lower_peak: float
    omega: np.ndarray
    mu_upper: np.ndarray
    mu_lower: np.ndarray
    seconds: float

    def __iter__(self):
        # Like musyn: K, CL, mu_peak, info.
        return iter((self.K, self.musyn.CL, self.mu_peak, self))


def _named(K: control.StateSpace) -> control.StateSpace:
    """The controller with the seat's physical signal names (y1 = x1, y2 = x3)."""
    return control.ss(K.A, K.B, K.C, K.D, inputs=["x1", "x3"], outputs=["u"], name="K_seat")


def design_mu_controller(design: SeatDesignOptions | None = None, *,
                         params: SeatParameters | None = None,
                         musyn_options: MusynOptions | None = None, omega=None,
                         callback=None, rng: np.random.Generator | None = None) -> SeatMuDesign:
    """Robust seat controller by µ-synthesis (D-K iteration).

    Parameters
    ----------
    design : SeatDesignOptions, optional
        Weights and uncertainty (default :data:`DEFAULT_DESIGN`).
    params : SeatParameters, optional
        Physical parameters (Table 1).
    musyn_options : MusynOptions, optional
        D-K settings (default :data:`DEFAULT_MUSYN`).
    omega : array_like, optional
        Design grid, rad/s (default :data:`DEFAULT_OMEGA`).
    callback : callable, optional
        Passed to :func:`musyn` (one call per iteration).
    rng : numpy.random.Generator, optional
        Seeds the µ lower-bound search (default ``default_rng(0)``).

    Returns
    -------
    SeatMuDesign

    Examples
    --------
    >>> from lmi_suspension.seat.design import DEFAULT_DESIGN
    >>> DEFAULT_DESIGN.include_delay and not DEFAULT_DESIGN.include_parametric
    True
    """
    t0 = time.perf_counter()
    design = DEFAULT_DESIGN if design is None else design
    opts = DEFAULT_MUSYN if musyn_options is None else musyn_options
    omega = DEFAULT_OMEGA if omega is None else np.asarray(omega, dtype=float)
    rng = np.random.default_rng(0) if rng is None else rng
    aug = seat_augmented_plant(design, params)
    res = musyn(aug.P, aug.nmeas, aug.ncon, aug.blk, omega=omega, options=opts,
                callback=callback, rng=rng)
    dense = np.asarray(res.mu.omega) if getattr(res.mu, "omega", None) is not None else None
    seconds = time.perf_counter() - t0
    logger.info("seat µ design: µ %.4f (lower %.4f), K order %d, %.1f s", res.mu_peak,
                res.mu_lower_peak, res.K.nstates, seconds)
    return SeatMuDesign(K=_named(res.K), aug=aug, musyn=res, mu_peak=res.mu_peak,
                        mu_lower_peak=res.mu_lower_peak,
                        omega=dense if dense is not None else np.zeros(0),
                        mu_upper=np.asarray(res.mu.upper), mu_lower=np.asarray(res.mu.lower),
                        seconds=seconds)


@dataclass(frozen=True)
class MuCheck:
    """µ of a fixed seat controller over one uncertainty structure.

    Attributes
    ----------
    structure : str
        What the structure holds.
    block_names : tuple of str
        Its blocks, as in :attr:`SeatAugmentedPlant.block_names`.
    mu_peak, mu_lower_peak : float
        Peaks of the µ upper and lower bounds over ``omega``.
    peak_omega : float
        Frequency of the upper-bound peak, rad/s.
    """

    structure: str
    block_names: tuple
    mu_peak: float
    mu_lower_peak: float
    peak_omega: float


def analyse_uncertainty(K: control.StateSpace, design: SeatDesignOptions | None = None, *,
                        params: SeatParameters | None = None, omega=None,
                        rng: np.random.Generator | None = None) -> tuple[MuCheck, ...]:
    """Robust-performance µ of ``K`` beyond the structure it was designed for.

    The paper's norm-bounded uncertainty (δ = 0.02; the A/B, C1 and C3 blocks) is added
    to the design's delay cover and performance block, once with ``E_B = 0`` (as printed:
    empty) and once with the reconstructed ``E_B``.  µ < 1 on a structure certifies
    robust performance for every perturbation in that set.

    Parameters
    ----------
    K : control.StateSpace
        Controller from ``y = [x1, x3]`` to ``u`` (as :func:`design_mu_controller` returns).
    design : SeatDesignOptions, optional
        The design's weights (default :data:`DEFAULT_DESIGN`).
    params : SeatParameters, optional
    omega : array_like, optional
        Analysis grid, rad/s (default: 300 points over :data:`DEFAULT_OMEGA`'s range).
    rng : numpy.random.Generator, optional
        Seeds the µ lower-bound search.

    Returns
    -------
    tuple of MuCheck
        The design's own structure first, then the two extended ones.
    """
    from ..mu import mussv
    from ..lti import freqresp, lft

    design = DEFAULT_DESIGN if design is None else design
    omega = (np.logspace(np.log10(DEFAULT_OMEGA[0]), np.log10(DEFAULT_OMEGA[-1]), 300)
             if omega is None else np.asarray(omega, dtype=float))
    rng = np.random.default_rng(0) if rng is None else rng
    variants = (
        ("as designed", design),
        ("+ paper norm-bounded, E_B = 0 (as printed)",
         replace(design, include_paper=True, paper_input_uncertainty=False)),
        ("+ paper norm-bounded, E_B reconstructed",
         replace(design, include_paper=True, paper_input_uncertainty=True)),
    )
    checks = []
    for label, opts in variants:
        aug = seat_augmented_plant(opts, params)
        CL = lft(aug.P, control.ss(K.A, K.B, K.C, K.D), aug.nmeas, aug.ncon)
        bounds = mussv(freqresp(CL, omega), aug.blk, omega=omega, rng=rng)
        upper = np.asarray(bounds.upper)
        k = int(np.argmax(upper))
        checks.append(MuCheck(structure=label, block_names=tuple(aug.block_names),
                              mu_peak=float(upper[k]),
                              mu_lower_peak=float(np.max(bounds.lower)),
                              peak_omega=float(omega[k])))
        logger.info("seat µ analysis (%s): %.4f (lower %.4f)", label, upper[k],
                    np.max(bounds.lower))
    return tuple(checks)


def _dk_line(rec) -> str:
    """One line of progress for a D-K record (an iteration, or a D-scale search record)."""
    what = "D-K iteration" if rec.stage == "dk" else "D-scale search, record"
    seconds = rec.seconds_k + rec.seconds_d + rec.seconds_fit
    return (f"{what} {rec.index}: gamma {rec.gamma:.4f}, µ upper {rec.mu_peak:.4f}, "
            f"lower {rec.mu_lower_peak:.4f} ({seconds:.1f} s)")


@dataclass(frozen=True)
class MuRoute:
    """The paper's route: µ-synthesis by D-K iteration (:func:`design_mu_controller`) as
    a :class:`~.routes.SeatRoute`.  Unset fields take that function's defaults.

    Examples
    --------
    >>> MuRoute().name
    'mu'
    """

    name: ClassVar[str] = "mu"
    design_options: SeatDesignOptions | None = None
    musyn_options: MusynOptions | None = None

    def design(self, params: SeatParameters, *, rng: np.random.Generator, progress=None):
        """:func:`design_mu_controller` at ``params``, as a :class:`~.routes.SeatDesign`."""
        from .routes import seat_design_from

        cb = None if progress is None else (lambda rec: progress(_dk_line(rec)))
        d = design_mu_controller(self.design_options, params=params,
                                 musyn_options=self.musyn_options, callback=cb, rng=rng)
        return seat_design_from(
            self.name, d.K, params=params, weights=d.aug.options, seconds=d.seconds,
            detail=d, description="µ-synthesis seat controller (D-K iteration): "
                                  "y = [x1, x3] (m) -> u (N)",
            figures={"mu_peak_upper": d.mu_peak, "mu_peak_lower": d.mu_lower_peak,
                     "stop_reason": d.musyn.stop_reason})


def design_nominal_hinf(design: SeatDesignOptions | None = None, *,
                        params: SeatParameters | None = None,
                        method: str = "best") -> control.StateSpace:
    """Nominal H∞ controller for the same performance weights (no delay, no uncertainty).

    Parameters
    ----------
    design : SeatDesignOptions, optional
        Weights (default :data:`DEFAULT_DESIGN`); the ``include_*`` flags are switched off.
    params : SeatParameters, optional
    method : {"best", "lmi", "riccati"}
        Route of :func:`~lmi_suspension.synthesis.hinfsyn` with its default options
        ("riccati": python-control as users call it). "best" takes the LMI and, should
        its reconstruction fail, the balanced Riccati controller; either way γ is the
        certified closed-loop norm.  The controller is near-optimal for the nominal
        plant (within 0.1–0.3 % of the LMI optimum), as a designer who ignores the delay
        would have it; such a controller loses stability within a few milliseconds of
        delay (measured 2026-11-23: 0.53 ms, Riccati 0.33 ms, with the default weights;
        1.7 ms and 2.5 ms with earlier weights, against 206 ms for a 5 % relaxed one).

    Returns
    -------
    control.StateSpace
        Inputs ``['x1', 'x3']`` (m), output ``['u']`` (N).

    Examples
    --------
    >>> from lmi_suspension.seat.design import design_nominal_hinf
    >>> K = design_nominal_hinf()
    >>> K.input_labels, K.output_labels
    (['x1', 'x3'], ['u'])
    """
    from ..synthesis import hinfsyn

    design = DEFAULT_DESIGN if design is None else design
    nominal = replace(design, include_delay=False, include_parametric=False,
                      include_paper=False)
    aug = seat_augmented_plant(nominal, params)
    from ..errors import LmiSuspensionError
    from ..synthesis import HinfsynOptions

    if method != "best":
        return _named(hinfsyn(aug.P, aug.nmeas, aug.ncon, method=method).K)
    try:
        res = hinfsyn(aug.P, aug.nmeas, aug.ncon, method="lmi")
    except LmiSuspensionError as exc:
        # a fallback: the Riccati controller is certified as the LMI's would be
        logger.info("nominal H∞: LMI route failed (%s); using the balanced Riccati route",
                    exc)
        res = hinfsyn(aug.P, aug.nmeas, aug.ncon, method="riccati",
                      options=HinfsynOptions(riccati_scale=True))
    return _named(res.K)
