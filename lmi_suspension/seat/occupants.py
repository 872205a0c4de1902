"""The seats one controller must serve, and a controller's certificate over them.

A seat in service meets occupants of 30 to 70 kg (upper-body mass ``m3``), springs and
dampers that age or were built off nominal (``k1..k3``, ``c1..c3`` within ±20 %) and an
actuator delay of 0 to 25 ms.  :class:`OccupantSet` is that set; :func:`occupant_samples`
draws it as a Latin hypercube (every parameter's range cut into as many equal strata as
samples, one sample in each) and computes each performance sample's own physical limit,
the clairvoyant LP of :func:`~.limit.bump_limit` for *its* parameters; and
:func:`certify_occupants` measures a controller on those samples by routes that do not
take part in any design of this package:

* **stability** of the linear loop with the exact delay ``e^{-sτ}``, by a Nyquist count
  (:func:`~.simulate.closed_loop_stable`) at each stability sample's own delay;
* **the road requirements** at every performance sample and every delay of
  ``delays``: peak ``|z̈3|`` over the sample's own limit, commanded ``|u|`` (unclipped)
  and ``|x1|``, in closed form in the frequency domain (:class:`~.loop.BumpResponse`),
  the worst few re-simulated in the time domain (:func:`~.simulate.simulate`, exact
  delay) and the larger of the two figures reported;
* **mixed µ** (:func:`occupant_mu`): the set's parameters as real scalars with the
  design's delay cover, robust stability and robust performance, upper and lower bounds
  of :func:`~lmi_suspension.mu.mussv` on a grid and over every frequency, and the seat
  the lower bound points to.

:class:`MixedRsBound` is the set's robust stability for a *search*: the D-G bound with
its scalings held fixed, a smooth function of the controller that
:func:`~.refine.refine_seat_controller` takes as a requirement
(``RefineOptions(occupants=...)``).

Examples
--------
>>> import numpy as np
>>> from lmi_suspension.seat.occupants import OccupantSet
>>> s = OccupantSet()
>>> [(n, round(lo, 1), round(hi, 1)) for n, lo, hi in s.ranges()][:3]
[('m3', 30.0, 70.0), ('k1', 24800.0, 37200.0), ('k2', 14400.0, 21600.0)]
>>> params, delays = s.sample(4, np.random.default_rng(0))
>>> len(params), bool(np.all((0.0 <= delays) & (delays <= 0.025)))
(4, True)
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field, replace
from itertools import product
from typing import Callable

import control
import numpy as np

from ..errors import DimensionError, ParameterError
from .params import SeatParameters
from .roads import RoadInput, bump

__all__ = ["OccupantSet", "OccupantSamples", "OccupantCheck", "MixedMuCheck",
           "MixedRsBound", "RsScalings", "occupant_samples", "certify_occupants",
           "occupant_mu"]

logger = logging.getLogger(__name__)

#: the springs and dampers of the set, in the order of :meth:`OccupantSet.ranges`
_ELEMENTS = ("k1", "k2", "k3", "c1", "c2", "c3")


def _interval(value, name: str, *, positive: bool) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a pair (lo, hi), got {value!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi
            and (lo > 0 if positive else lo >= 0)):
        raise ParameterError(f"{name} must satisfy {'0 <' if positive else '0 <='} lo <= hi "
                             f"and be finite, got {value!r}")
    return lo, hi


@dataclass(frozen=True)
class OccupantSet:
    """Occupants, springs, dampers and delays a seat controller must serve.

    Attributes
    ----------
    nominal : SeatParameters
        The seat the ranges are relative to (Table 1).
    m3 : (float, float)
        Upper-body mass of the occupant, kg.
    stiffness_rel, damping_rel : float
        ``k1..k3`` within ``(1 ± stiffness_rel)`` of nominal, ``c1..c3`` within
        ``(1 ± damping_rel)``; in [0, 1).
    delay : (float, float)
        Actuator delay, s.
    k1_rel : float, optional
        ``k1`` within ``(1 ± k1_rel)`` of nominal instead of ``stiffness_rel``, in
        [0, 1): a seat that estimates its spring from the static deflection under the
        measured load knows ``k1`` better than the body's springs.  ``None`` (default)
        takes ``stiffness_rel``.
    """

    nominal: SeatParameters = field(default_factory=SeatParameters)
    m3: tuple = (30.0, 70.0)
    stiffness_rel: float = 0.2
    damping_rel: float = 0.2
    delay: tuple = (0.0, 0.025)
    k1_rel: float | None = None

    def __post_init__(self):
        if not isinstance(self.nominal, SeatParameters):
            raise ParameterError(f"nominal must be a SeatParameters, got "
                                 f"{type(self.nominal).__name__}")
        object.__setattr__(self, "m3", _interval(self.m3, "m3", positive=True))
        object.__setattr__(self, "delay", _interval(self.delay, "delay", positive=False))
        for name in ("stiffness_rel", "damping_rel", "k1_rel"):
            v = getattr(self, name)
            if name == "k1_rel" and v is None:
                continue
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 <= v < 1:
                raise ParameterError(f"{name} must lie in [0, 1), got {v!r}")

    def _rel(self, name: str) -> float:
        """The relative range of the spring or damper ``name``."""
        if name == "k1" and self.k1_rel is not None:
            return self.k1_rel
        return self.stiffness_rel if name.startswith("k") else self.damping_rel

    def ranges(self) -> tuple:
        """``(name, lo, hi)`` of every uncertain parameter: ``m3``, ``k1..k3``, ``c1..c3``."""
        out = [("m3",) + tuple(self.m3)]
        for name in _ELEMENTS:
            rel = self._rel(name)
            nom = getattr(self.nominal, name)
            out.append((name, nom * (1 - rel), nom * (1 + rel)))
        return tuple(out)

    def at(self, values: dict) -> SeatParameters:
        """The seat with ``values`` (name → value) replacing the nominal ones."""
        return replace(self.nominal, **{k: float(v) for k, v in values.items()})

    def sample(self, n: int, rng: np.random.Generator, *, method: str = "lhs"
               ) -> tuple[tuple[SeatParameters, ...], np.ndarray]:
        """``n`` seats and delays: a Latin hypercube over the parameters and the delay
        (``method="lhs"``) or independent uniform draws (``"uniform"``).

        Returns
        -------
        (tuple of SeatParameters, ndarray)
            The seats and their delays, s.
        """
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise ParameterError(f"n must be a positive integer, got {n!r}")
        if not isinstance(rng, np.random.Generator):
            raise ParameterError("rng must be a numpy.random.Generator (seeded by the caller)")
        bounds = self.ranges() + (("delay",) + tuple(self.delay),)
        lo = np.array([b[1] for b in bounds])
        hi = np.array([b[2] for b in bounds])
        if method == "lhs":
            from scipy.stats import qmc

            unit = qmc.LatinHypercube(d=lo.size, seed=rng).random(int(n))
        elif method == "uniform":
            unit = rng.random((int(n), lo.size))
        else:
            raise ParameterError(f"method must be 'lhs' or 'uniform', got {method!r}")
        points = lo + unit * (hi - lo)
        names = [b[0] for b in bounds[:-1]]
        seats = tuple(self.at(dict(zip(names, row[:-1]))) for row in points)
        return seats, points[:, -1].copy()

    def corners(self, names=("m3", "k1")) -> tuple[SeatParameters, ...]:
        """The seats at every combination of the ends of ``names``' ranges, the other
        parameters nominal (``2**len(names)`` seats)."""
        ranges = {r[0]: r[1:] for r in self.ranges()}
        unknown = [n for n in names if n not in ranges]
        if unknown:
            raise ParameterError(f"unknown parameters {unknown}; choose from {list(ranges)}")
        return tuple(self.at(dict(zip(names, ends)))
                     for ends in product(*(ranges[n] for n in names)))

    def mu_design(self, design=None):
        """The µ weights of ``design`` (the seat design's by default) with this set's
        parameters as real scalars ``[-1, 0]`` and its delay range: the mixed-µ
        structure of :func:`occupant_mu`."""
        from .augmented import DEFAULT_DESIGN

        design = DEFAULT_DESIGN if design is None else design
        damping = _ELEMENTS[3:] if self.damping_rel > 0 else ()
        stiffness = tuple(n for n in _ELEMENTS[:3] if self._rel(n) > 0)
        # a k1 range of its own reaches the µ model's k1 scalar (None: stiffness_rel's)
        k1_rel = self.k1_rel if self.k1_rel is not None and self.k1_rel > 0 else None
        return replace(design, include_parametric=True, parametric_complex=False,
                       m3_range=tuple(self.m3), stiffness=stiffness,
                       stiffness_rel=self.stiffness_rel or design.stiffness_rel, k1_rel=k1_rel,
                       damping=damping, damping_rel=self.damping_rel or design.damping_rel,
                       delay_min=self.delay[0], delay_max=self.delay[1])


@dataclass(frozen=True)
class OccupantSamples:
    """Samples of an :class:`OccupantSet` shared by every controller certified on them.

    Attributes
    ----------
    occupants : OccupantSet
    stability : tuple of SeatParameters
        The stability samples (Latin hypercube over the parameters and the delay).
    stability_delays : ndarray
        Their delays, s.
    performance : tuple of SeatParameters
        The performance samples (another hypercube), each met at every delay of
        :func:`certify_occupants`.
    limits : ndarray
        Each performance sample's own physical limit on the road, m/s² (certified
        peak of :func:`~.limit.bump_limit`; nan where its LP failed).
    nominal_limit : float
        The nominal seat's.
    road : RoadInput
    """

    occupants: OccupantSet
    stability: tuple
    stability_delays: np.ndarray
    performance: tuple
    limits: np.ndarray
    nominal_limit: float
    road: RoadInput


def occupant_samples(occupants: OccupantSet | None = None, *, rng: np.random.Generator,
                     n_stability: int = 10_000, n_performance: int = 200,
                     road: RoadInput | None = None,
                     progress: Callable[[str], None] | None = None) -> OccupantSamples:
    """Draw the samples of a certificate and compute each performance sample's limit
    (about 0.7 s of LP per sample).

    Parameters
    ----------
    occupants : OccupantSet, optional
    rng : numpy.random.Generator
        Seeds both hypercubes (stability first).
    n_stability, n_performance : int
    road : RoadInput, optional
        The paper's bump by default.
    progress : callable, optional
        Called with a line of text every 20 limits.
    """
    from .limit import bump_limit
    from .loop import _LIMIT_DT

    occupants = OccupantSet() if occupants is None else occupants
    road = bump() if road is None else road
    if not isinstance(road, RoadInput):
        raise ParameterError(f"road must be a RoadInput, got {type(road).__name__}")
    stab, delays = occupants.sample(n_stability, rng)
    perf, _ = occupants.sample(n_performance, rng)

    def limit(p):
        try:
            return float(bump_limit(road, p, dt=_LIMIT_DT).certified_peak)
        except Exception as exc:  # an infeasible or failed LP: no ratio for that sample
            logger.warning("limit LP failed for %s: %s", p, exc)
            return math.nan

    limits = []
    for k, p in enumerate(perf):
        limits.append(limit(p))
        if progress is not None and (k + 1) % 20 == 0:
            progress(f"limits: {k + 1} of {len(perf)}")
    return OccupantSamples(occupants=occupants, stability=stab, stability_delays=delays,
                           performance=perf, limits=np.array(limits),
                           nominal_limit=limit(occupants.nominal), road=road)


@dataclass(frozen=True)
class OccupantCheck:
    """A controller's figures over an :class:`OccupantSet` (:func:`certify_occupants`).

    Attributes
    ----------
    n_stability : int
    unstable : int
        Stability samples whose exact-delay loop is unstable.
    unstable_samples : tuple of (SeatParameters, float)
        The first of them (at most 20) with their delays.
    delays : tuple of float
        The delays every performance sample is met at, s.
    ratio, u_peak, x1_peak : ndarray
        Per performance sample (rows) and delay (columns): peak ``|z̈3|`` over the
        sample's own limit, commanded ``|u|`` (N, unclipped), ``|x1|`` (m); ``inf``
        where the loop is unstable at that delay.
    worst_ratio : float
    worst_sample : SeatParameters
    worst_delay : float
        The largest ratio, its sample and delay (nan, None, nan without performance
        samples).
    u_max, x1_max : float
        Largest commanded ``|u|`` and ``|x1|`` over every sample and delay (-inf without
        performance samples).
    nominal_ratio : float
        The nominal seat's worst over the delays (inf if its loop is unstable at one).
    confirmed : tuple of (int, float, str, float, float)
        The time-domain re-simulations: ``(sample, delay, figure, frequency-domain value,
        time-domain value)``; the reported figures are the larger of the two.
    controller_radius, loop_radius : float
        Largest controller pole and largest loop pole magnitude (over the performance
        samples), rad/s.
    seconds : float
    """

    n_stability: int
    unstable: int
    unstable_samples: tuple
    delays: tuple
    ratio: np.ndarray
    u_peak: np.ndarray
    x1_peak: np.ndarray
    worst_ratio: float
    worst_sample: SeatParameters
    worst_delay: float
    u_max: float
    x1_max: float
    nominal_ratio: float
    confirmed: tuple
    controller_radius: float
    loop_radius: float
    seconds: float


def road_figures(controllers, samples: OccupantSamples, delays, confirm: int):
    """``(ratio, u, x1, confirmed, loop_radius)`` of the performance samples, the ``i``-th
    with ``controllers[i]`` (one controller for all in :func:`certify_occupants`, each
    at its estimated mass in :func:`~.scheduled.certify_scheduled`): the bump figures
    per sample and delay (``inf`` where that loop is unstable), the ``confirm`` worst of
    each re-simulated by time stepping (the exact delay, no clip) and raised to it."""
    from .loop import BumpResponse, loop_poles
    from .simulate import closed_loop_stable, simulate

    road = samples.road
    n, m = len(samples.performance), len(delays)
    ratio, u, x1 = (np.full((n, m), np.inf) for _ in range(3))
    loop_radius = 0.0
    for i, (p, K) in enumerate(zip(samples.performance, controllers)):
        ok = np.array([closed_loop_stable(K, d, p) for d in delays])
        loop_radius = max(loop_radius, float(np.max(np.abs(loop_poles(K, p)))))
        if not ok.any():
            continue
        z, ui, xi = BumpResponse(road=road, delays=delays, params=p).peaks(K)
        ratio[i, ok] = z[ok] / samples.limits[i]
        u[i, ok], x1[i, ok] = ui[ok], xi[ok]
    confirmed = []
    for name, table in (("ratio", ratio), ("u", u), ("x1", x1)):
        finite = np.where(np.isfinite(table), table, -np.inf)
        for flat in np.argsort(-finite, axis=None, kind="stable")[:confirm]:
            i, j = divmod(int(flat), m)
            if not np.isfinite(table[i, j]):
                continue
            met = simulate(controllers[i], road, delay=delays[j],
                           params=samples.performance[i], u_max=np.inf).metrics()
            value = {"ratio": met.peak_z3dd / samples.limits[i], "u": met.peak_u_command,
                     "x1": met.peak_x1}[name]
            confirmed.append((i, delays[j], name, float(table[i, j]), float(value)))
            table[i, j] = max(table[i, j], value)
    return ratio, u, x1, tuple(confirmed), loop_radius


def certify_occupants(K, samples: OccupantSamples, *, delays=None, confirm: int = 3,
                      progress: Callable[[str], None] | None = None) -> OccupantCheck:
    """Stability and road figures of a seat controller over the samples of a set.

    Parameters
    ----------
    K : control.StateSpace
        Continuous-time controller ``y = [x1, x3]`` (m) to ``u`` (N).
    samples : OccupantSamples
    delays : sequence of float, optional
        Delays every performance sample is met at, s (0, 5, …, 25 ms by default).
    confirm : int
        The worst this many (sample, delay) pairs of each figure (ratio, ``|u|``,
        ``|x1|``) are re-simulated in the time domain.
    progress : callable, optional
        Called with a line of text every 1000 stability samples.

    Returns
    -------
    OccupantCheck
    """
    from .loop import REFINE_DELAYS, BumpResponse
    from .simulate import closed_loop_stable

    t0 = time.perf_counter()
    if not isinstance(samples, OccupantSamples):
        raise ParameterError("samples must come from occupant_samples")
    if not isinstance(K, control.StateSpace) or K.isdtime(strict=True) \
            or K.ninputs != 2 or K.noutputs != 1:
        raise ParameterError("K must be a continuous-time StateSpace from y = [x1, x3] to u")
    if isinstance(confirm, bool) or not isinstance(confirm, int) or confirm < 0:
        raise ParameterError(f"confirm must be a non-negative int, got {confirm!r}")
    delays = tuple(float(d) for d in (REFINE_DELAYS if delays is None else delays))
    if not delays or any(not math.isfinite(d) or d < 0 for d in delays):
        raise ParameterError(f"delays must be finite and non-negative, got {delays!r}")
    unstable = []
    for k, (p, d) in enumerate(zip(samples.stability, samples.stability_delays)):
        if not closed_loop_stable(K, float(d), p):
            unstable.append((p, float(d)))
        if progress is not None and (k + 1) % 1000 == 0:
            progress(f"stability: {k + 1} of {len(samples.stability)}, "
                     f"{len(unstable)} unstable")
    road = samples.road
    n = len(samples.performance)
    ratio, u, x1, confirmed, loop_radius = road_figures([K] * n, samples, delays, confirm)
    nom = samples.occupants.nominal
    nominal_ratio = (float(np.max(BumpResponse(road=road, delays=delays, params=nom)
                                  .peaks(K)[0])) / samples.nominal_limit
                     if all(closed_loop_stable(K, d, nom) for d in delays) else math.inf)
    if n:
        i, j = np.unravel_index(int(np.argmax(np.where(np.isnan(ratio), -np.inf, ratio))),
                                ratio.shape)
        worst = (float(ratio[i, j]), samples.performance[i], delays[j])
    else:                                   # stability samples only
        worst = (math.nan, None, math.nan)
    return OccupantCheck(
        n_stability=len(samples.stability), unstable=len(unstable),
        unstable_samples=tuple(unstable[:20]), delays=delays, ratio=ratio, u_peak=u,
        x1_peak=x1, worst_ratio=worst[0], worst_sample=worst[1], worst_delay=worst[2],
        u_max=float(np.max(u, initial=-np.inf)), x1_max=float(np.max(x1, initial=-np.inf)),
        nominal_ratio=nominal_ratio,
        confirmed=confirmed,
        controller_radius=float(np.max(np.abs(np.linalg.eigvals(K.A)), initial=0.0)),
        loop_radius=loop_radius, seconds=time.perf_counter() - t0)


@dataclass(frozen=True)
class MixedMuCheck:
    """Mixed µ of a seat controller over an :class:`OccupantSet` (:func:`occupant_mu`).

    Attributes
    ----------
    block_names : tuple of str
        The structure's blocks (parameters real, the delay cover and the performance
        block complex).
    rs_upper, rs_lower : float
        Robust stability: peaks of the upper and lower bounds over the grid, the
        performance block left out.  ``rs_upper < 1`` certifies stability for every
        parameter value in the set and every delay the cover holds.
    rp_upper, rp_lower : float
        Robust performance, the performance block in.
    rs_omega, rp_omega : float
        Frequencies of the upper bounds' peaks, rad/s.
    rs_sup, rp_sup : float
        The upper bounds over every frequency, not only the grid's
        (:func:`~lmi_suspension.mu.interval_bound` with the grid's scalings): ``rs_sup
        < 1`` certifies robust stability between the grid points too.
    omega : ndarray
    rs_worst : SeatParameters or None
        The seat of the robust-stability lower bound's perturbation (its real scalars,
        at the grid frequency of the largest lower bound): where ``rs_lower >= 1`` a
        seat of the set at which a perturbation of the delay cover no larger than
        ``1 / rs_lower`` destabilises the loop; below 1, that perturbation scaled onto
        the set's boundary (the direction closest to instability).  None where the
        lower bound is 0.
    rs_worst_omega : float
        Its frequency, rad/s.
    """

    block_names: tuple
    rs_upper: float
    rs_lower: float
    rp_upper: float
    rp_lower: float
    rs_omega: float
    rp_omega: float
    omega: np.ndarray
    rs_sup: float
    rp_sup: float
    rs_worst: SeatParameters | None = None
    rs_worst_omega: float = math.nan


def _lower_bound_seat(aug, rs) -> tuple[SeatParameters | None, float]:
    """``(seat, ω)`` of the robust-stability lower bound's perturbation (see
    :attr:`MixedMuCheck.rs_worst`)."""
    from ..umodel.blocks import BlockStructure
    from .uncertainty import parametric_uncertainty

    lower = np.asarray(rs.lower, dtype=float).ravel()
    k = int(np.argmax(lower))
    if not lower[k] > 0:
        return None, math.nan
    Delta = np.asarray(rs.delta)[..., k] if np.ndim(rs.delta) == 3 else np.asarray(rs.delta)
    struct = BlockStructure.coerce(np.asarray(aug.blk)[:-1])
    # a block of Δ sits at M's column rows and row columns (Δ is n_in × n_out)
    delta = {name: float(np.real(Delta[rows, cols][0, 0])) for name, rows, cols
             in zip(aug.block_names, struct.col_slices(), struct.row_slices())}
    o = aug.options
    pu = parametric_uncertainty(aug.params, o.m3_range, o.stiffness_rel, stiffness=o.stiffness,
                                damping=o.damping, damping_rel=o.damping_rel, k1_rel=o.k1_rel)
    scale = min(1.0, float(lower[k]))
    d = [float(np.clip(delta[name] * scale, -1.0, 1.0)) for name in pu.names]
    omega = rs.omega[k] if rs.omega is not None else math.nan
    return pu.params_at(d), float(omega)


def occupant_mu(K, occupants: OccupantSet | None = None, *, design=None, omega=None,
                rng: np.random.Generator) -> MixedMuCheck:
    """Mixed real/complex µ of ``K`` over the set: the parameters as real scalars, the
    delay cover and performance block of ``design`` (:data:`~.augmented.DEFAULT_DESIGN` by
    default) complex; upper bounds of :func:`~lmi_suspension.mu.mussv` (SLICOT's AB13MD
    on the default structure, its scalings checked; the LMI where a design has blocks
    AB13MD does not take) on the grid and over every frequency
    (:func:`~lmi_suspension.mu.interval_bound`), lower bounds of its power iteration.

    Parameters
    ----------
    K : control.StateSpace
    occupants : OccupantSet, optional
    design : SeatDesignOptions, optional
    omega : array_like, optional
        Grid, rad/s (default 120 points over 0.1–3000 rad/s).
    rng : numpy.random.Generator
        Seeds the lower-bound search.
    """
    from ..lti import freqresp, lft
    from ..mu import interval_bound, mussv
    from .augmented import seat_augmented_plant

    occupants = OccupantSet() if occupants is None else occupants
    opts = occupants.mu_design(design)
    omega = np.logspace(-1.0, 3.5, 120) if omega is None else np.asarray(omega, dtype=float)
    aug = seat_augmented_plant(opts, occupants.nominal)
    names = tuple(aug.block_names)
    if names[-1] != "performance":
        raise ParameterError("the design's structure must end with the performance block")
    CL = lft(aug.P, control.ss(K.A, K.B, K.C, K.D), aug.nmeas, aug.ncon)
    if CL.nstates and np.max(np.linalg.eigvals(np.asarray(CL.A)).real) >= 0:
        raise ParameterError("the nominal µ loop is unstable: no µ bound certifies it")
    M = freqresp(CL, omega)
    blk = np.asarray(aug.blk)
    # Δ_perf is blk[-1, 0] × blk[-1, 1]: M's last blk[-1, 1] rows and blk[-1, 0] columns
    rows, cols = int(blk[-1, 1]), int(blk[-1, 0])
    # "auto": AB13MD on the occupant structure; the LMI where a design's blocks are
    # ones AB13MD does not take (the paper's non-square norm-bounded blocks)
    rs = mussv(M[:-rows, :-cols], blk[:-1], omega=omega, rng=rng)
    rp = mussv(M, blk, omega=omega, rng=rng)
    rs_sup = interval_bound(CL[:CL.noutputs - rows, :CL.ninputs - cols], rs, omega)
    rp_sup = interval_bound(CL, rp, omega)
    rsu, rpu = np.asarray(rs.upper), np.asarray(rp.upper)
    worst, worst_omega = _lower_bound_seat(aug, rs)
    return MixedMuCheck(block_names=names, rs_upper=float(rsu.max()),
                        rs_lower=float(np.max(rs.lower)), rp_upper=float(rpu.max()),
                        rp_lower=float(np.max(rp.lower)), rs_omega=float(omega[rsu.argmax()]),
                        rp_omega=float(omega[rpu.argmax()]), omega=omega,
                        rs_sup=rs_sup.bound, rp_sup=rp_sup.bound, rs_worst=worst,
                        rs_worst_omega=worst_omega)


# ------------------------------------------------------- robust stability inside a search

#: Frequencies a search's scalings are also held at besides its grid: the points where
#: :func:`~lmi_suspension.mu.interval_bound` split an interval (the sharp peaks of real
#: parameters, which a grid misses), the highest first.  The first multi-seat design's
#: 200-point grid read 0.869 where the sup over every frequency was 1.048, at one such
#: point (2026-11-27).
_RS_EXTRA = 6


@dataclass(frozen=True)
class RsScalings:
    """D-G scalings of the set's robust-stability µ held fixed at frequencies
    (:meth:`MixedRsBound.scalings`).

    Attributes
    ----------
    omega : ndarray
        The frequencies, rad/s: the grid, then the split points of
        :func:`~lmi_suspension.mu.interval_bound` (:data:`_RS_EXTRA` of them, the
        highest bounds first; the grid's peak repeated where there are fewer).
    XL, G : ndarray
        ``(F, n, n)``: ``X_L = D_Lᴴ D_L`` and ``G`` at each frequency.
    Linv : ndarray
        ``(F, n, n)``: the inverse of the Cholesky factor of ``X_R``.
    upper : ndarray
        The µ upper bound those scalings were found for at each frequency.
    sup : float
        The bound over every frequency for the controller they were found for.
    """

    omega: np.ndarray
    XL: np.ndarray
    G: np.ndarray
    Linv: np.ndarray
    upper: np.ndarray
    sup: float
    _blocks: tuple = field(repr=False)


class MixedRsBound:
    """Robust stability over an :class:`OccupantSet` as a smooth function of the
    controller, for searches.

    The D-G upper bound of mixed µ holds for *any* admissible scalings ``(X_L, X_R, G)``:
    ``β(ω) = min{β : M* X_L M + j(G M - M* Gᴴ) ⪯ β² X_R}`` bounds µ of ``M(jω)``.  With
    the scalings held fixed, ``β`` is a smooth function of the controller (where the
    largest generalized eigenvalue is simple), whereas the optimised bound is not (its
    scalings jump).  :meth:`scalings` optimises them for one controller (SLICOT's
    AB13MD through :func:`~lmi_suspension.mu.mussv`, certified) on the grid and at the
    points where :func:`~lmi_suspension.mu.interval_bound` had to split;
    :meth:`levels` evaluates ``β`` for another controller at those scalings, an upper
    bound of its µ at those frequencies: the classical D-K alternation, with the K-step a
    local search (:func:`~.refine.refine_seat_controller` with
    ``RefineOptions(occupants=...)``).

    Parameters
    ----------
    occupants : OccupantSet, optional
    design : SeatDesignOptions, optional
        The delay cover (:data:`~.augmented.DEFAULT_DESIGN` by default).
    omega : array_like, optional
        Grid, rad/s (200 points over 0.1–3162 rad/s by default).

    Examples
    --------
    >>> from lmi_suspension.seat.refine import load_refined
    >>> K = load_refined()[0]
    >>> rs = MixedRsBound(omega=np.logspace(-1, 3.5, 40))
    >>> scal = rs.scalings(K)
    >>> bool(np.allclose(rs.levels(K, scal), scal.upper, rtol=1e-6))
    True
    """

    def __init__(self, occupants: OccupantSet | None = None, design=None, omega=None):
        from ..umodel.blocks import BlockStructure
        from .augmented import seat_augmented_plant

        occupants = OccupantSet() if occupants is None else occupants
        if not isinstance(occupants, OccupantSet):
            raise ParameterError(f"occupants must be an OccupantSet, got "
                                 f"{type(occupants).__name__}")
        omega = np.logspace(-1.0, 3.5, 200) if omega is None else \
            np.asarray(omega, dtype=float).ravel()
        if omega.size < 2 or not np.all(np.isfinite(omega)) or np.any(omega <= 0) \
                or np.any(np.diff(omega) <= 0):
            raise ParameterError("omega must hold increasing positive finite frequencies")
        aug = seat_augmented_plant(occupants.mu_design(design), occupants.nominal)
        blk = np.asarray(aug.blk)
        if tuple(aug.block_names)[-1] != "performance":
            raise ParameterError("the design's structure must end with the performance block")
        nz, nw = BlockStructure.coerce(blk).shape_M
        self.occupants, self.omega, self.blk = occupants, omega, blk[:-1]
        if aug.ncon != 1:
            raise DimensionError(f"a seat controller has one output, the design {aug.ncon}")
        self._P, self._ny, self._nu = aug.P, aug.nmeas, aug.ncon
        self._nz, self._nw = nz, nw
        # the robust-stability loop leaves out the performance block's rows and columns
        self._nq, self._np = nz - int(blk[-1, 1]), nw - int(blk[-1, 0])

    def _blocks(self, omega):
        from ..lti import freqresp

        Pw = freqresp(self._P, omega)
        nz, nw, nq, n_p = self._nz, self._nw, self._nq, self._np
        return (Pw[:nq, :n_p], Pw[:nq, nw:nw + self._nu][:, 0], Pw[nz:nz + self._ny, :n_p],
                Pw[nz:nz + self._ny, nw:nw + self._nu][:, 0])

    def loop(self, K) -> control.StateSpace:
        """The robust-stability loop ``M(s)`` (the performance channels left out)."""
        from ..lti import lft

        CL = lft(self._P, control.ss(K.A, K.B, K.C, K.D), self._ny, self._nu)
        return CL[:self._nq, :self._np]

    def loop_poles(self, K) -> np.ndarray:
        """Poles of the loop (the weights' and the delay cover's included)."""
        from .loop import interconnection_poles

        return interconnection_poles(self._P, K, self._nw, self._nu, self._nz, self._ny)

    def scalings(self, K) -> RsScalings:
        """Optimal scalings for ``K`` on the grid and at the points between grid points
        where the bound over every frequency needed them.

        Raises
        ------
        ParameterError
            ``K``'s loop is unstable (no µ bound certifies it).
        """
        from ..lti import freqresp
        from ..mu import MussvOptions, interval_bound, mussv
        from ..mu.interval import _scalings

        if np.max(self.loop_poles(K).real, initial=-np.inf) >= 0:
            raise ParameterError("the controller's µ loop is unstable")
        CL = self.loop(K)
        only_upper = MussvOptions(compute_lower=False)
        mu = mussv(freqresp(CL, self.omega), self.blk, omega=self.omega, options=only_upper)
        sup = interval_bound(CL, mu, self.omega)
        grid = set(self.omega.tolist())
        # the split points, and the point that sets the bound where an interval got its
        # own level (it lies inside the interval, not at an edge)
        split = np.array(sorted({float(w) for w in np.append(sup.edges, sup.omega)
                                 if 0 < w < np.inf and w not in grid}))
        scal = [_scalings(mu, k) for k in range(self.omega.size)]
        upper = list(np.asarray(mu.upper, dtype=float))
        extra_w: list = []
        if split.size:
            at = mussv(freqresp(CL, split), self.blk, omega=split, options=only_upper)
            order = np.argsort(-np.asarray(at.upper), kind="stable")[:_RS_EXTRA]
            extra_w = [float(split[k]) for k in order]
            scal += [_scalings(at, int(k)) for k in order]
            upper += [float(np.asarray(at.upper)[k]) for k in order]
        top = int(np.argmax(mu.upper))
        while len(extra_w) < _RS_EXTRA:    # a fixed count: the search's constraints need it
            extra_w.append(float(self.omega[top]))
            scal.append(scal[top])
            upper.append(upper[top])
        omega = np.concatenate([self.omega, extra_w])
        XL = np.array([s[0] for s in scal])
        XR = np.array([(s[1] + s[1].conj().T) / 2 for s in scal])
        try:
            Linv = np.linalg.inv(np.linalg.cholesky(XR))
        except np.linalg.LinAlgError as exc:
            raise ParameterError(f"the µ scalings are not positive definite ({exc})") from exc
        return RsScalings(omega=omega, XL=XL, G=np.array([s[2] for s in scal]), Linv=Linv,
                          upper=np.array(upper), sup=float(sup.bound),
                          _blocks=self._blocks(omega))

    def levels(self, K, scal: RsScalings) -> np.ndarray:
        """``β`` at each of ``scal``'s frequencies for ``K``: upper bounds of its µ there
        (``K``'s loop must be stable; :meth:`loop_poles` tells)."""
        from .loop import loop_response

        M = loop_response(K, scal.omega, scal._blocks)                  # (F, nq, np)
        MH = np.conj(np.swapaxes(M, 1, 2))
        GM = scal.G @ M
        H = MH @ scal.XL @ M + 1j * (GM - np.conj(np.swapaxes(GM, 1, 2)))
        S = scal.Linv @ H @ np.conj(np.swapaxes(scal.Linv, 1, 2))
        S = (S + np.conj(np.swapaxes(S, 1, 2))) / 2
        return np.sqrt(np.maximum(np.linalg.eigvalsh(S)[:, -1], 0.0))
