"""The augmented seat plant of Fig. 2 for µ-synthesis: weights, uncertainty channels and
the block structure ``blk`` (MATLAB's convention).

Signal flow (all names are the plant's input/output labels)::

    w  (normalised)  --> w_scale --> ż0 (m/s) ---------------------------+
    u  (N) --+--> W_delay --> q_delay                                     |
             +--(+ p_delay)--> N(s) --> u_act --> [uncertain seat core] <-+
             +--> W_u --> e_force                       |   z3dd --> W_k/acc_ref --> e_acc
                                                        |   x1 --> 1/z_max --> e_defl
    n1, n2 (normalised) --> noise scales --(+)--> y1, y2 (m)

The core is the seat model (eq. 15) with, when selected, the real parametric channels
(:func:`~lmi_suspension.seat.uncertainty.parametric_uncertainty`) and the paper's
norm-bounded channels (:func:`~lmi_suspension.seat.uncertainty.paper_norm_bounded`,
ΔA, ΔB acting on ``[x; u_act]``, ΔC1 on z̈3, ΔC3 on the measurements).
"""

from __future__ import annotations

import logging
import math
import numbers
from dataclasses import dataclass, replace

import control
import numpy as np

from ..errors import NonFiniteError, ParameterError
from .model import seat_model
from .params import SeatParameters
from .uncertainty import (DelayUncertainty, delay_uncertainty, paper_norm_bounded,
                          parametric_uncertainty)
from .weights import wk_weight

__all__ = ["SeatDesignOptions", "SeatAugmentedPlant", "seat_augmented_plant",
           "disturbance_weight", "BUMP_PEAK_VELOCITY", "DEFAULT_DESIGN",
           "CONSTRAINED_DESIGN"]

logger = logging.getLogger(__name__)

#: Peak floor velocity of the bump of eq. (32), ``a π V0 / l`` with a = 0.1 m,
#: V0 = 30 km/h, l = 2 m: about 1.31 m/s.
BUMP_PEAK_VELOCITY = 0.1 * math.pi * (30.0 / 3.6) / 2.0


@dataclass(frozen=True)
class SeatDesignOptions:
    """Every weight and uncertainty choice of the seat µ design in one place.

    Attributes
    ----------
    acc_ref : float
        Wk-weighted z̈3 (m/s²) that counts as a unit error (performance gain 1/acc_ref).
        With the default 10 m/s² the passive seat's peak weighted gain from the
        normalised ``w`` is about 4.2 (42 m/s² at 2.2 Hz): a tuning knob, not a result.
    wk_order : {2, 3, 4}
        Order of the ISO 2631-1 Wk approximation (:func:`~.weights.wk_weight`).
    u_max : float or None
        Force scale of eq. (12), N; ``None`` takes ``params.u_max``.
    force_rolloff_ratio : float
        High-frequency increase of the force weight (1 = static ``1/u_max``); otherwise
        ``(1/u_max)(1 + s/ω_f)/(1 + s/(ratio ω_f))``.
    force_rolloff_corner : float
        ``ω_f`` in rad/s.
    z_max : float or None
        Deflection scale of eq. (13), m; ``None`` takes ``params.z_max``.
    w_scale : float
        Floor-velocity scale, m/s (default: the bump's peak ż0, :data:`BUMP_PEAK_VELOCITY`).
    w_corner : float or None
        If set (rad/s), the floor velocity is shaped ``w_scale s/(s + w_corner)``: below
        the corner a unit ``w`` means a floor *displacement* of ``w_scale/w_corner``
        (e.g. the bump height) instead of an ever larger stroke.
    w_rolloff : float or None
        If set (rad/s), the floor velocity is also low-passed by a second-order
        Butterworth filter ``ω_r²/(s² + √2 ω_r s + ω_r²)``: the bump's velocity spectrum
        ``|Ẑ0(jω)|`` (eq. 32) collapses above its main lobe (≈ 45 rad/s), so a design
        disturbance that stays flat there asks for performance where the bump has no energy
        and where the 25 ms delay makes control impossible.
    noise : tuple of float
        Sensor-noise scales on ``y = [x1, x3]``, m.
    include_delay, include_parametric, include_paper : bool
        Which uncertainty channels the plant carries.
    delay_min, delay_max : float or None
        Delay interval, s; ``None`` takes ``params.delay_min`` / ``params.delay_max``.
    delay_nominal : {"pade", "none"}
    delay_order : int
        Order of the delay weight (1–3).
    delay_margin : float
        Relative safety margin of the delay cover.
    m3_range : (float, float) or None
        Occupant mass range, kg (``None``: m3 fixed).
    stiffness, stiffness_rel, damping, damping_rel
        Uncertain springs/dampers and their relative ranges.
    k1_rel : float, optional
        The seat spring's own relative range in place of ``stiffness_rel`` (see
        :func:`~.uncertainty.parametric_uncertainty`); ``None`` takes ``stiffness_rel``.
    parametric_complex : bool
        Give the parametric scalars complex ``[1, 1]`` rows in ``blk`` (a cover of the
        real ones) instead of real ``[-1, 0]`` rows.
    paper_delta : float
        δ of the paper's norm-bounded uncertainty (0.02).
    paper_input_uncertainty : bool
        Keep ``ΔB`` in the paper's A/B block (``E_B``, printed empty in the paper and
        reconstructed as ``δ [0 1 0 0 0 0]ᵀ`` per newton, see
        :func:`~.uncertainty.paper_norm_bounded`); ``False`` takes ``E_B = 0``.

    Examples
    --------
    >>> from lmi_suspension.seat import augmented
    >>> opts = augmented.SeatDesignOptions(include_paper=False, noise=(1e-4, 1e-4))
    >>> opts.include_delay, opts.noise
    (True, (0.0001, 0.0001))
    """

    acc_ref: float = 10.0
    wk_order: int = 4
    u_max: float | None = None
    force_rolloff_ratio: float = 1.0
    force_rolloff_corner: float = 2 * math.pi * 30.0
    z_max: float | None = None
    w_scale: float = BUMP_PEAK_VELOCITY
    w_corner: float | None = None
    w_rolloff: float | None = None
    noise: tuple[float, float] = (5e-4, 5e-4)
    include_delay: bool = True
    include_parametric: bool = True
    include_paper: bool = True
    delay_min: float | None = None
    delay_max: float | None = None
    delay_nominal: str = "pade"
    delay_order: int = 2
    delay_margin: float = 0.02
    m3_range: tuple[float, float] | None = (30.0, 70.0)
    stiffness: tuple[str, ...] = ("k1",)
    stiffness_rel: float = 0.2
    damping: tuple[str, ...] = ()
    damping_rel: float = 0.2
    k1_rel: float | None = None
    parametric_complex: bool = False
    paper_delta: float = 0.02
    paper_input_uncertainty: bool = True

    def __post_init__(self):
        def num(name, value, *, positive=True, allow_none=False):
            if value is None and allow_none:
                return
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise ParameterError(f"{name} must be a real number, got {value!r}")
            if not math.isfinite(value):
                raise NonFiniteError(f"{name} must be finite, got {value!r}")
            if positive and value <= 0:
                raise ParameterError(f"{name} must be positive, got {value!r}")
            if not positive and value < 0:
                raise ParameterError(f"{name} must be >= 0, got {value!r}")

        for name in ("acc_ref", "force_rolloff_corner", "w_scale"):
            num(name, getattr(self, name))
        for name in ("u_max", "z_max", "w_corner", "w_rolloff"):
            num(name, getattr(self, name), allow_none=True)
        for name in ("delay_min", "delay_max"):
            num(name, getattr(self, name), positive=False, allow_none=True)
        num("paper_delta", self.paper_delta, positive=False)
        num("force_rolloff_ratio", self.force_rolloff_ratio)
        if self.force_rolloff_ratio < 1:
            raise ParameterError("force_rolloff_ratio must be >= 1 (a high-frequency increase)")
        if self.delay_min is not None and self.delay_max is not None \
                and self.delay_max < self.delay_min:
            raise ParameterError(
                f"delay_max ({self.delay_max}) must not be below delay_min ({self.delay_min})")
        noise = tuple(self.noise)
        if len(noise) != 2:
            raise ParameterError(f"noise needs two scales (y1, y2), got {self.noise!r}")
        for i, v in enumerate(noise):
            num(f"noise[{i}]", v)
        object.__setattr__(self, "noise", tuple(float(v) for v in noise))
        for name in ("include_delay", "include_parametric", "include_paper",
                     "parametric_complex", "paper_input_uncertainty"):
            if not isinstance(getattr(self, name), bool):
                raise ParameterError(f"{name} must be True or False")
        if self.wk_order not in (2, 3, 4) or isinstance(self.wk_order, bool):
            raise ParameterError(f"wk_order must be 2, 3 or 4, got {self.wk_order!r}")
        if self.delay_nominal not in ("pade", "none"):
            raise ParameterError("delay_nominal must be 'pade' or 'none'")
        if self.delay_order not in (1, 2, 3) or isinstance(self.delay_order, bool):
            raise ParameterError(f"delay_order must be 1, 2 or 3, got {self.delay_order!r}")
        num("delay_margin", self.delay_margin)
        if self.m3_range is not None:
            lo, hi = self.m3_range
            num("m3_range[0]", lo)
            num("m3_range[1]", hi)
            if hi <= lo:
                raise ParameterError(f"m3_range must be increasing, got {self.m3_range}")
        num("stiffness_rel", self.stiffness_rel)
        num("damping_rel", self.damping_rel)
        num("k1_rel", self.k1_rel, allow_none=True)
        object.__setattr__(self, "stiffness", tuple(self.stiffness))
        object.__setattr__(self, "damping", tuple(self.damping))


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

#: The µ weights of the constrained design: DEFAULT_DESIGN with the force error scaled by
#: 20000 N instead of 7000 N -- the hard bound limits the force now, and the H∞ objective
#: is left to comfort and robustness.  Measured 2026-11-25 on the 50-point grid, bump
#: peak at 0 / 25 ms: 11.8 / 16.9 m/s² with 20000 N (force bound 4000 N, disk 2000
#: rad/s) against 13.9 / 16.5 with 7000 N (4000 N, damping sector 0.05 instead of the
#: disk).
CONSTRAINED_DESIGN = replace(DEFAULT_DESIGN, u_max=20000.0)

@dataclass(frozen=True)
class SeatAugmentedPlant:
    """The generalized plant of Fig. 2 with its block structure.

    Attributes
    ----------
    P : control.StateSpace
        Inputs ``[p_<block>..., 'w', 'n1', 'n2', 'u']``, outputs ``[q_<block>...,
        'e_acc', 'e_force', 'e_defl', 'y1', 'y2']``.
    nmeas, ncon : int
        2 measurements (last outputs) and 1 control (last input).
    blk : ndarray of int, shape (nblocks, 2)
        MATLAB ``mussv`` rows ``[r, c]``: block i is r_i × c_i, maps the plant's c_i
        uncertainty outputs to its r_i uncertainty inputs; ``[-1, 0]`` is a real scalar.
        The last row is the performance block ``[3, 3]`` (errors → disturbances).
        ``M = F_l(P, K)`` is ``(Σ c_i) × (Σ r_i)``.
    block_names : tuple of str
        One name per row of ``blk`` (``'delay'``, ``'m3'``, ``'k1'``, ..., ``'nb_AB'``,
        ``'nb_C1'``, ``'nb_C3'``, ``'performance'``).
    options : SeatDesignOptions
    params : SeatParameters
        Parameters of the nominal model (m3 moved to the range centre when the
        parametric uncertainty is on).
    delay : DelayUncertainty or None
        The delay cover used; ``None`` when ``include_delay`` is False (ideal actuator).
    """

    P: control.StateSpace
    nmeas: int
    ncon: int
    blk: np.ndarray
    block_names: tuple[str, ...]
    options: SeatDesignOptions
    params: SeatParameters
    delay: DelayUncertainty | None

    @property
    def n_unc_inputs(self) -> int:
        """Number of uncertainty inputs ``p`` (first inputs of ``P``)."""
        return int(sum(1 if r == -1 else r for r, _ in self.blk[:-1]))

    @property
    def n_unc_outputs(self) -> int:
        """Number of uncertainty outputs ``q`` (first outputs of ``P``)."""
        return int(sum(1 if r == -1 else c for r, c in self.blk[:-1]))

    def __iter__(self):
        # Unpack like python-control's (P, nmeas, ncon) triple plus the structure.
        return iter((self.P, self.nmeas, self.ncon, self.blk))


def disturbance_weight(options: SeatDesignOptions) -> control.TransferFunction:
    """Floor velocity ż0 (m/s) per unit normalised ``w``: the design disturbance model.

    ``w_scale``, times ``s/(s + w_corner)`` if ``w_corner`` is set, times the second-order
    Butterworth low pass ``ω_r²/(s² + √2 ω_r s + ω_r²)`` if ``w_rolloff`` is set.

    Parameters
    ----------
    options : SeatDesignOptions

    Returns
    -------
    control.TransferFunction

    Examples
    --------
    >>> from lmi_suspension.seat.augmented import SeatDesignOptions, disturbance_weight
    >>> W = disturbance_weight(SeatDesignOptions(w_scale=0.5))
    >>> float(abs(W(1j)))
    0.5
    """
    W = control.tf([options.w_scale], [1.0])
    if options.w_corner is not None:
        W = W * control.tf([1.0, 0.0], [1.0, options.w_corner])
    if options.w_rolloff is not None:
        wr = options.w_rolloff
        W = W * control.tf([wr ** 2], [1.0, math.sqrt(2.0) * wr, wr ** 2])
    return W


def _static(gain, inp, out, name):
    return control.ss([], [], [], np.atleast_2d(gain), inputs=inp, outputs=out, name=name)


def _core(params: SeatParameters, opts: SeatDesignOptions):
    """Uncertain seat core: inputs [p..., 'zdot0', 'u_act'], outputs [q..., 'z3dd', 'x1',
    'y1m', 'y2m'], plus the (names, blk rows) of its blocks."""
    names: list[str] = []
    rows: list[list[int]] = []
    if opts.include_parametric:
        pu = parametric_uncertainty(params, opts.m3_range, opts.stiffness_rel,
                                    stiffness=opts.stiffness, damping=opts.damping,
                                    damping_rel=opts.damping_rel, k1_rel=opts.k1_rel)
        G = pu.G
        nominal = pu.nominal
        npar = len(pu.names)
        names += list(pu.names)
        rows += [[1, 1] if opts.parametric_complex else [-1, 0]] * npar
        A = np.array(G.A)
        Bp, Bw, Bu = (np.array(G.B[:, :npar]), np.array(G.B[:, npar:npar + 1]),
                      np.array(G.B[:, npar + 1:]))
        C = np.array(G.C)
        D = np.array(G.D)
        Cq, Cz = C[:npar], C[npar:]
        Dqp, Dqw, Dqu = D[:npar, :npar], D[:npar, npar:npar + 1], D[:npar, npar + 1:]
        Dzp, Dzw, Dzu = D[npar:, :npar], D[npar:, npar:npar + 1], D[npar:, npar + 1:]
        p_labels = [f"p_{n}" for n in pu.names]
        q_labels = [f"q_{n}" for n in pu.names]
    else:
        nominal = params
        G = seat_model(params)
        A, Bw, Bu = np.array(G.A), np.array(G.B[:, :1]), np.array(G.B[:, 1:])
        Cz, Dzw, Dzu = np.array(G.C), np.array(G.D[:, :1]), np.array(G.D[:, 1:])
        npar = 0
        Bp, Cq = np.zeros((6, 0)), np.zeros((0, 6))
        Dqp, Dqw, Dqu = np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((0, 1))
        Dzp = np.zeros((Cz.shape[0], 0))
        p_labels, q_labels = [], []
    # Seat outputs are ['z3dd', 'x1', 'x3', 'y1', 'y2']; keep z3dd, x1, y1, y2.
    keep = [0, 1, 3, 4]
    Cz, Dzp, Dzw, Dzu = Cz[keep], Dzp[keep], Dzw[keep], Dzu[keep]

    # Paper norm-bounded channels (independent blocks for A/B, C1 and C3).
    extra_B, extra_C, extra_Dzp, extra_Dqu = [], [], [], []
    nb_p, nb_q = [], []
    if opts.include_paper:
        nb = paper_norm_bounded(nominal, opts.paper_delta)
        for key, (left, right) in nb.blocks().items():
            r, c = left.shape[1], right.shape[0]
            names.append(key)
            rows.append([r, c])
            nb_p += [f"p_{key}[{i}]" for i in range(r)]
            nb_q += [f"q_{key}[{i}]" for i in range(c)]
            if key == "nb_AB":
                extra_B.append(left)  # enters the state equation
                extra_Dzp.append(np.zeros((4, r)))
                extra_C.append(right[:, :6])
                extra_Dqu.append(right[:, 6:] if opts.paper_input_uncertainty
                                 else np.zeros_like(right[:, 6:]))
            else:
                extra_B.append(np.zeros((6, r)))
                Dz = np.zeros((4, r))
                if key == "nb_C1":
                    Dz[0:1, :] = left  # z3dd row
                else:
                    Dz[2:4, :] = left  # y1m, y2m rows
                extra_Dzp.append(Dz)
                extra_C.append(right)
                extra_Dqu.append(np.zeros((c, 1)))
    n_nb_p, n_nb_q = len(nb_p), len(nb_q)
    Bnb = np.hstack(extra_B) if extra_B else np.zeros((6, 0))
    Cnb = np.vstack(extra_C) if extra_C else np.zeros((0, 6))
    Dnb_u = np.vstack(extra_Dqu) if extra_Dqu else np.zeros((0, 1))
    Dz_nb = np.hstack(extra_Dzp) if extra_Dzp else np.zeros((4, 0))

    # Assemble [p_par, p_nb, zdot0, u_act] -> [q_par, q_nb, z3dd, x1, y1m, y2m].
    B = np.hstack([Bp, Bnb, Bw, Bu])
    Cfull = np.vstack([Cq, Cnb, Cz])
    D = np.block([
        [Dqp, np.zeros((npar, n_nb_p)), Dqw, Dqu],
        [np.zeros((n_nb_q, npar + n_nb_p)), np.zeros((n_nb_q, 1)), Dnb_u],
        [Dzp, Dz_nb, Dzw, Dzu],
    ])
    core = control.ss(A, B, Cfull, D,
                      inputs=p_labels + nb_p + ["zdot0", "u_act"],
                      outputs=q_labels + nb_q + ["z3dd", "x1", "y1m", "y2m"],
                      states=[f"x{i + 1}" for i in range(6)], name="core")
    return core, nominal, names, rows, p_labels, q_labels, nb_p, nb_q


def seat_augmented_plant(options: SeatDesignOptions | None = None,
                         params: SeatParameters | None = None, *,
                         peak_channels: bool = False) -> SeatAugmentedPlant:
    """Build the augmented seat plant of Fig. 2 for ``musyn``/``mussv``.

    Parameters
    ----------
    options : SeatDesignOptions, optional
        Weights and uncertainty choices (defaults: all three uncertainties on).
    params : SeatParameters, optional
        Physical parameters (Table 1 by default).
    peak_channels : bool
        Also give the plant the channels of hard time-domain bounds, which µ does not
        see (they lie beyond ``blk``, see :func:`~lmi_suspension.mu.musyn`'s
        ``constraints``): the input ``'road'``, a floor velocity in m/s added to the
        shaped one, and the outputs ``'u_cmd'`` (the commanded force, N) and ``'x1_m'``
        (the stroke, m), after the performance channels.

    Returns
    -------
    SeatAugmentedPlant
        Unpacks as ``P, nmeas, ncon, blk``.

    Examples
    --------
    >>> from lmi_suspension.seat.augmented import seat_augmented_plant, SeatDesignOptions
    >>> aug = seat_augmented_plant(SeatDesignOptions(include_paper=False))
    >>> aug.block_names
    ('delay', 'm3', 'k1', 'performance')
    >>> aug.blk.tolist()
    [[1, 1], [-1, 0], [-1, 0], [3, 3]]
    >>> aug.P.input_labels[-4:], aug.P.output_labels[-5:]
    (['w', 'n1', 'n2', 'u'], ['e_acc', 'e_force', 'e_defl', 'y1', 'y2'])
    """
    opts = SeatDesignOptions() if options is None else options
    if not isinstance(opts, SeatDesignOptions):
        raise TypeError(f"options must be a SeatDesignOptions, got {type(opts).__name__}")
    params = SeatParameters() if params is None else params
    if not isinstance(params, SeatParameters):
        raise TypeError(f"params must be a SeatParameters, got {type(params).__name__}")
    u_max = params.u_max if opts.u_max is None else opts.u_max
    z_max = params.z_max if opts.z_max is None else opts.z_max

    core, nominal, names, rows, p_par, q_par, p_nb, q_nb = _core(params, opts)

    systems = [core,
               control.ss(disturbance_weight(opts), inputs=["w"],
                          outputs=["zdot0_w" if peak_channels else "zdot0"], name="w_scale"),
               control.ss(wk_weight(opts.wk_order, acc_ref=opts.acc_ref),
                          inputs=["z3dd"], outputs=["e_acc"], name="W_acc"),
               _static(1.0 / z_max, ["x1"], ["e_defl"], "W_defl"),
               _static(np.diag(opts.noise), ["n1", "n2"], ["nz1", "nz2"], "W_noise"),
               control.summing_junction(["y1m", "nz1"], "y1", name="sum_y1"),
               control.summing_junction(["y2m", "nz2"], "y2", name="sum_y2")]
    if opts.force_rolloff_ratio == 1.0:
        systems.append(_static(1.0 / u_max, ["u"], ["e_force"], "W_force"))
    else:
        wf, ratio = opts.force_rolloff_corner, opts.force_rolloff_ratio
        Wf = control.tf([1 / wf, 1], [1 / (ratio * wf), 1]) * (1.0 / u_max)
        systems.append(control.ss(Wf, inputs=["u"], outputs=["e_force"], name="W_force"))

    p_delay, q_delay, delay = [], [], None
    d_min = params.delay_min if opts.delay_min is None else opts.delay_min
    d_max = params.delay_max if opts.delay_max is None else opts.delay_max
    if opts.include_delay:
        if d_max < d_min:
            raise ParameterError(f"delay_max ({d_max}) must not be below delay_min ({d_min})")
        delay = delay_uncertainty(d_min, d_max, nominal=opts.delay_nominal,
                                  order=opts.delay_order, margin=opts.delay_margin)
        # e^{-sd} u = N (u + p_delay), p_delay = δ W u.  The channel is scaled by u_max
        # (q_delay = W u / u_max, the force enters as u_max p_delay): a constant D-scaling
        # of the 1×1 block, so the Δ-set is unchanged, but the first K-step of D-K then
        # sees the force error and the delay error in the same units instead of newtons.
        systems += [_static(u_max, ["p_delay"], ["p_delay_N"], "delay_in_scale"),
                    control.summing_junction(["u", "p_delay_N"], "u_sum", name="sum_u"),
                    control.ss(delay.N, inputs=["u_sum"], outputs=["u_act"], name="N_delay"),
                    control.ss(delay.W * (1.0 / u_max), inputs=["u"], outputs=["q_delay"],
                               name="W_delay")]
        names = ["delay"] + names
        rows = [[1, 1]] + rows
        p_delay, q_delay = ["p_delay"], ["q_delay"]
    else:
        systems.append(_static(1.0, ["u"], ["u_act"], "ideal_actuator"))

    names.append("performance")
    rows.append([3, 3])
    extra_in, extra_out = [], []
    if peak_channels:
        systems += [control.summing_junction(["zdot0_w", "road"], "zdot0", name="sum_road"),
                    _static(1.0, ["u"], ["u_cmd"], "u_cmd"),
                    _static(1.0, ["x1"], ["x1_m"], "x1_m")]
        extra_in, extra_out = ["road"], ["u_cmd", "x1_m"]
    inplist = p_delay + p_par + p_nb + ["w", "n1", "n2"] + extra_in + ["u"]
    outlist = q_delay + q_par + q_nb + ["e_acc", "e_force", "e_defl"] + extra_out + ["y1", "y2"]
    P = control.interconnect(systems, inplist=inplist, outlist=outlist,
                             inputs=inplist, outputs=outlist, name="P_seat")
    P = control.ss(P.A, P.B, P.C, P.D, inputs=inplist, outputs=outlist, name="P_seat")
    logger.debug("augmented seat plant: %d states, blocks %s", P.nstates, names)
    return SeatAugmentedPlant(P=P, nmeas=2, ncon=1, blk=np.array(rows, dtype=int),
                              block_names=tuple(names), options=opts, params=nominal,
                              delay=delay)
