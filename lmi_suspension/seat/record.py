"""What every seat design route returns and how any seat controller is certified.

:class:`SeatDesign` is the one result type of every route (:mod:`.routes` holds the
table of routes and :func:`~.routes.design_seat`); a route's ``design`` ends with
:func:`seat_design_from`.  :func:`certify_seat` checks a controller by computations no
route uses to produce it (time simulation of the exact-delay loop, the 1 kHz
sampled-data loop, µ bounds of :func:`~lmi_suspension.mu.mussv` on a dense grid,
worst-case peaks from the closed loop's Gramian, and, given samples of a set of seats,
stability and road figures over them and their mixed µ) and judges the figures against
:class:`SeatRequirements` (issue 38's targets by default).

This module sits below every route module and imports none of them: the routes import
it, and :mod:`.routes` alone imports the routes.

Examples
--------
>>> import control
>>> d = seat_design_from("mine", control.ss([], [], [], [[0.0, 0.0]]), params=None,
...                      weights=None, figures={}, description="passive", seconds=0.0)
>>> d.route, d.K.input_labels, d.Kd.dt
('mine', ['x1', 'x3'], 0.001)
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field

import control
import numpy as np

from ..errors import ParameterError
from .augmented import DEFAULT_DESIGN, SeatDesignOptions
from .loop import _LIMIT_DT, REFINE_DELAYS, TwoBlockMu, loop_poles
from .params import SeatParameters

__all__ = ["SeatCertificate", "SeatDesign", "SeatRequirements", "certify_seat",
           "seat_design_from"]


@dataclass(frozen=True, eq=False)
class SeatDesign:
    """A seat controller, whatever route made it.

    Attributes
    ----------
    route : str
        The route's name.
    K : control.StateSpace
        Continuous-time controller from ``y = [x1, x3]`` (m) to ``u`` (N, sign of eq. 1),
        inputs ``['x1', 'x3']``, output ``['u']``; for a design made in discrete time
        (``primary == "discrete"``), the bilinear image of ``Kd``
        (:func:`~lmi_suspension.lti.tustin_image`), whose Tustin map is ``Kd``.
    Kd : control.StateSpace
        Its 1 kHz realization (Tustin, :func:`~.sampled.discretise_controller`), the one
        a seat's controller runs; the design itself where ``primary == "discrete"``.
    params : SeatParameters
        The seat it was designed for.
    weights : SeatDesignOptions
        The µ weights and delay cover the route's µ figures refer to, and
        :meth:`certify` takes.
    figures : Mapping
        What the route claims of its controller, in JSON-ready values (µ bounds, worst
        cases, whether its requirements were met, ...): the route's own figures, which
        :func:`certify_seat` does not reuse.
    description : str
        One line: the route and what it asked for.
    seconds : float
        Wall time of the design (as saved, for a loaded design).
    primary : str
        ``"continuous"`` (designed in continuous time, ``Kd`` its Tustin map) or
        ``"discrete"`` (designed at ``Kd.dt``, ``K`` its bilinear image).
    detail : object
        The route's own result (:class:`~.design.SeatMuDesign`, ...): its history and
        everything only that route has; None for a design read from a file.

    Two designs are equal only if they are the same object (python-control's
    ``StateSpace`` has no value equality); compare a saved and a loaded one field by
    field.
    """

    route: str
    K: control.StateSpace
    Kd: control.StateSpace
    params: SeatParameters
    weights: SeatDesignOptions
    figures: Mapping = field(default_factory=dict)
    description: str = ""
    seconds: float = 0.0
    detail: object = field(default=None, compare=False, repr=False)
    primary: str = "continuous"

    def metadata(self) -> dict:
        """What :func:`save_seat_design` writes beside the controller: the figures, the
        route, the description, the seat, the µ weights, the design time and the
        discretisation."""
        return {**self.figures, "route": self.route, "description": self.description,
                "params": asdict(self.params), "weights": asdict(self.weights),
                "design_seconds": self.seconds, "primary": self.primary,
                "discretisation": (f"Tustin, dt = {self.Kd.dt} s" if self.primary ==
                                   "continuous" else f"designed at dt = {self.Kd.dt} s; A, B, "
                                   "C, D are its bilinear image")}

    def certify(self, **kwargs) -> SeatCertificate:
        """:func:`certify_seat` of this design's controllers at its seat, with its µ
        weights."""
        kwargs.setdefault("params", self.params)
        kwargs.setdefault("design", self.weights)
        return certify_seat(self.K, Kd=self.Kd, **kwargs)


def seat_design_from(route: str, K: control.StateSpace, *, params: SeatParameters | None,
                     weights: SeatDesignOptions | None, figures: Mapping, description: str,
                     seconds: float, detail=None,
                     Kd: control.StateSpace | None = None,
                     primary: str = "continuous") -> SeatDesign:
    """A :class:`SeatDesign` with the controller named as the seat's and its 1 kHz
    realization (a route's ``design`` ends with it)."""
    from .sampled import discretise_controller

    K = control.ss(K.A, K.B, K.C, K.D, inputs=["x1", "x3"], outputs=["u"],
                   name=f"K_{route}")
    if Kd is None:
        # a pole above the 1 kHz Nyquist rate is a fact about the design, which the
        # certificate judges (SeatRequirements.pole_radius) and reproduce reports; a
        # design made, not a discretisation gone wrong, so no warning here
        Kd = discretise_controller(K, warn_unresolved=False)
    return SeatDesign(route=route, K=K, Kd=Kd,
                      params=SeatParameters() if params is None else params,
                      weights=DEFAULT_DESIGN if weights is None else weights,
                      figures=_jsonable(dict(figures)), description=description,
                      seconds=float(seconds), detail=detail, primary=primary)


# ----------------------------------------------------------------------------- certificate

@dataclass(frozen=True)
class SeatRequirements:
    """What a seat controller must achieve (issue 38's targets by default).

    Attributes
    ----------
    u_max : float
        Commanded ``|u|`` on the bump, N (eq. 12), unclipped, at every delay.
    z_max : float
        ``|x1|`` on the bump, m (eq. 13).
    nominal_ratio : float
        Peak ``|z̈3|`` over the seat's own physical limit, at the design seat.
    worst_ratio : float
        The same over a set of seats (judged where the certificate has one).
    pole_radius : float
        Every controller and loop pole below this magnitude, rad/s.
    delay_max : float
        The loop stable for every delay up to this, s (its delay margin above it).
    sampled_tolerance : float
        The 1 kHz sampled-data loop's peak within this fraction of the continuous one's.
    """

    # the paper's limits are the seat's own (eqs. 12-13, the delay range): one source
    u_max: float = SeatParameters.u_max
    z_max: float = SeatParameters.z_max
    nominal_ratio: float = 1.3
    worst_ratio: float = 1.5
    pole_radius: float = 1900.0
    delay_max: float = SeatParameters.delay_max
    sampled_tolerance: float = 0.01

    def __post_init__(self):
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, bool) or not (isinstance(v, (int, float)) and v > 0):
                raise ParameterError(f"SeatRequirements.{f.name} must be positive, got {v!r}")


@dataclass(frozen=True)
class SeatCertificate:
    """A seat controller's figures, recomputed from the controller alone
    (:func:`certify_seat`).

    Attributes
    ----------
    delays : tuple of float
        The delays the bump is met at, s.
    peak, u_peak, x1_peak : tuple of float
        Per delay, from the exact-delay time simulation of the linear loop (unclipped:
        the requirements bound what the controller commands): peak ``|z̈3|`` (m/s²),
        largest commanded ``|u|`` (N), peak ``|x1|`` (m).
    sampled_peak : tuple of float
        Peak ``|z̈3|`` of the 1 kHz sampled-data loop (zero-order hold), unclipped.
    mu : ConstrainedCheck
        µ bounds on the dense grid (delay cover and performance,
        :func:`~.mucheck.certify_constrained`), worst-case peaks over every floor
        velocity of the bump's energy, and pole magnitudes.
    delay_margin : float
        Smallest destabilising delay of the linear loop, s (0 where the loop is unstable
        without delay).
    loop_radius : float
        Largest pole magnitude of the seat's loop (controller and seat, no delay), rad/s.
    limit : float
        The seat's own physical limit on the bump (certified peak of
        :func:`~.limit.bump_limit`), m/s²; nan without delays.
    occupants : OccupantCheck or None
        Stability and road figures over the samples of a set of seats.
    worst_seats : tuple of WorstSeat
        The seats of that set where the commanded force and the stroke were found
        largest by search (:func:`~.worstcase.worst_bump_seats`; empty without the set):
        the set's corners and a climb, which samples rarely come near.
    mixed_mu : MixedMuCheck or None
        Mixed µ over that set (robust stability and performance).
    requirements : SeatRequirements
    """

    delays: tuple
    peak: tuple
    u_peak: tuple
    x1_peak: tuple
    sampled_peak: tuple
    mu: object
    delay_margin: float
    loop_radius: float
    limit: float = math.nan
    occupants: object = None
    mixed_mu: object = None
    requirements: SeatRequirements = field(default_factory=SeatRequirements)
    worst_seats: tuple = ()

    @property
    def nominal_ratio(self) -> float:
        """The design seat's worst peak over its own limit over the delays (a nan
        anywhere stays nan: ``np.max``, not ``max``, which would drop it)."""
        return float(np.max(self.peak)) / self.limit if self.peak else math.nan

    @property
    def sampled_gap(self) -> float:
        """The largest relative difference of the 1 kHz loop's peak from the continuous
        loop's, over the delays."""
        if not self.peak:
            return math.nan
        s, p = np.asarray(self.sampled_peak, float), np.asarray(self.peak, float)
        return float(np.max(np.abs(s - p) / p))

    def failures(self) -> tuple[str, ...]:
        """The requirements the figures do not meet, one line each (empty: all met).
        Only what was certified is judged: without delays the bump is not, without
        occupant samples the set is not."""
        r = self.requirements
        out = []
        if not self.delay_margin > r.delay_max:
            out.append(f"delay margin {self.delay_margin * 1e3:.1f} ms, not above "
                       f"{r.delay_max * 1e3:g} ms")
        fastest = float(np.max([self.loop_radius, self.mu.controller_fastest_pole]))
        if not fastest < r.pole_radius:
            out.append(f"poles: fastest {fastest:.0f} rad/s (controller or loop), not below "
                       f"{r.pole_radius:g}")
        if self.delays:
            checks = (("commanded |u|", float(np.max(self.u_peak)), r.u_max, "N"),
                      ("|x1|", float(np.max(self.x1_peak)), r.z_max, "m"),
                      ("peak / own limit at the design seat", self.nominal_ratio,
                       r.nominal_ratio, "×"),
                      ("1 kHz loop's peak against the continuous one", self.sampled_gap,
                       r.sampled_tolerance, "(relative)"))
            for what, value, bound, unit in checks:
                if not value <= bound:
                    out.append(f"{what}: {value:.4g} {unit}, above {bound:g}")
        if self.occupants is not None:
            o = self.occupants
            if o.unstable:
                out.append(f"set: {o.unstable} of {o.n_stability} samples unstable")
            for what, value, bound in (("set: worst peak / own limit", o.worst_ratio,
                                        r.worst_ratio),
                                       ("set: the nominal seat's peak / own limit",
                                        o.nominal_ratio, r.nominal_ratio),
                                       ("set: commanded |u|", o.u_max, r.u_max),
                                       ("set: |x1|", o.x1_max, r.z_max)):
                if not value <= bound:
                    out.append(f"{what}: {value:.4g}, above {bound:g}")
            if not o.loop_radius < r.pole_radius:
                out.append(f"set: fastest loop pole {o.loop_radius:.0f} rad/s, not below "
                           f"{r.pole_radius:g}")
        for w in self.worst_seats:
            bound = {"u": r.u_max, "x1": r.z_max}[w.figure]
            if not w.value <= bound:
                out.append(f"set, searched: {w.label} {w.describe()}, above {bound:g}"
                           if w.value != math.inf else
                           f"set, searched: the loop is {w.describe()}")
        if self.mixed_mu is not None and not self.mixed_mu.rs_sup < 1.0:
            out.append(f"set: robust-stability mixed µ {self.mixed_mu.rs_sup:.4f}, not below 1")
        return tuple(dict.fromkeys(out))      # one unstable seat found for both figures: once

    @property
    def met(self) -> bool:
        """Every requirement that was certified is met."""
        return not self.failures()


def certify_seat(K, *, Kd=None, params: SeatParameters | None = None,
                 delays=REFINE_DELAYS, design=None, occupants=None, mixed_mu: bool = False,
                 requirements: SeatRequirements | None = None, search: bool = True,
                 rng: np.random.Generator | None = None,
                 progress: Callable[[str], None] | None = None) -> SeatCertificate:
    """Certify a seat controller by routes no design uses to produce it.

    The bump at each delay by time simulation of the exact-delay loop, and of the 1 kHz
    sampled-data loop; µ upper and lower bounds by :func:`~lmi_suspension.mu.mussv` on a
    dense grid refined at the loop's resonances; worst-case force and stroke over every
    floor velocity of the bump's energy (Gramian); pole magnitudes; the delay margin;
    the seat's own physical limit (LP).  Given samples of a set of seats, stability and
    road figures over them (:func:`~.occupants.certify_occupants`), the seats of the
    set where force and stroke are worst (:func:`~.worstcase.worst_bump_seats`) and,
    with ``mixed_mu``, the set's mixed µ (:func:`~.occupants.occupant_mu`).

    Parameters
    ----------
    K : control.StateSpace
        Continuous-time controller ``y = [x1, x3]`` (m) to ``u`` (N).
    Kd : control.StateSpace, optional
        Its discrete realization (Tustin at 1 kHz by default).
    params : SeatParameters, optional
        The design seat (Table 1 by default).
    delays : sequence of float
        Delays the bump is met at, s (issue 38's 0, 5, ..., 25 ms by default); ``()``
        leaves the bump out (µ, poles and worst cases only, a second or two).
    design : SeatDesignOptions, optional
        µ weights and delay cover (:data:`~.augmented.DEFAULT_DESIGN` by default).
    occupants : OccupantSamples, optional
        Samples of a set of seats (:func:`~.occupants.occupant_samples`).
    mixed_mu : bool
        Also the set's mixed µ (needs ``occupants``; about a minute).
    requirements : SeatRequirements, optional
    search : bool
        With ``occupants``, also search the set for its worst force and stroke (about
        15 s): its corners, 200 samples of its own and a climb from the worst.
    rng : numpy.random.Generator, optional
        Seeds the µ lower bounds and the search (``default_rng(0)`` by default): three
        streams spawned from it, for the seat's µ, the set's µ and the search.
    progress : callable, optional
        Called with a line of text per part.

    Returns
    -------
    SeatCertificate

    Examples
    --------
    >>> import control
    >>> passive = control.ss([], [], [], [[0.0, 0.0]])
    >>> c = certify_seat(passive, delays=(0.0,))
    >>> c.u_peak, round(c.nominal_ratio, 2), round(c.delay_margin, 1)
    ((0.0,), 4.27, inf)
    """
    from ..lti import lft
    from ..mu.steps.dgstep import resonances
    from .augmented import seat_augmented_plant
    from .limit import bump_limit
    from .mucheck import certify_constrained
    from .roads import bump
    from .sampled import discretise_controller, simulate_sampled
    from .simulate import simulate, stability_delay_margin

    say = progress if progress is not None else (lambda line: None)
    if not isinstance(K, control.StateSpace) or K.isdtime(strict=True):
        raise ParameterError("K must be a continuous-time control.StateSpace")
    if K.ninputs != 2 or K.noutputs != 1:
        raise ParameterError(f"K must map y = [x1, x3] to u (2 inputs, 1 output), got "
                             f"{K.ninputs} inputs, {K.noutputs} outputs")
    if not isinstance(search, bool):
        raise ParameterError(f"search must be True or False, got {search!r}")
    if mixed_mu and occupants is None:
        raise ParameterError("mixed_mu needs the set: pass occupants=occupant_samples(...)")
    params = SeatParameters() if params is None else params
    requirements = SeatRequirements() if requirements is None else requirements
    rng = np.random.default_rng(0) if rng is None else rng
    if not isinstance(rng, np.random.Generator):
        raise ParameterError("rng must be a numpy.random.Generator")
    # one stream per part, so that adding a part does not move another's lower bound
    # (spawn's children are numbered: the first two are those of spawn(2))
    rng_mu, rng_set, rng_search = rng.spawn(3)
    design = DEFAULT_DESIGN if design is None else design
    delays = tuple(float(d) for d in delays)
    Kd = discretise_controller(K) if Kd is None else Kd
    road = bump()
    say(f"bump at {len(delays)} delays (exact-delay and 1 kHz loops)")
    runs = [simulate(K, road, delay=d, params=params, u_max=np.inf).metrics() for d in delays]
    sampled = tuple(float(np.max(np.abs(simulate_sampled(Kd, road, delay=d, params=params,
                                                         u_max=np.inf).z3dd)))
                    for d in delays)
    say("µ bounds on a dense grid, worst cases and poles")
    aug = seat_augmented_plant(design, params)
    omega = np.logspace(-3.0, 4.0, 300)
    # the grid and the loop's lightly damped poles' frequencies, where a µ peak is sharp;
    # on the two full blocks of the delay cover and performance, also the refined maxima
    # of their µ formula (other structures have none)
    extra = [resonances(lft(aug.P, control.ss(K.A, K.B, K.C, K.D), aug.nmeas, aug.ncon),
                        omega)]
    if np.asarray(aug.blk).shape[0] == 2:
        extra.append(TwoBlockMu(design, omega, params).peaks(K, 8)[2])
    omega = np.unique(np.concatenate([omega, *extra]))
    mu = certify_constrained(K, design=design, params=params, omega=omega, rng=rng_mu)
    limit = float(bump_limit(road, params, dt=_LIMIT_DT).certified_peak) if delays \
        else math.nan
    check = occ_mu = None
    worst = ()
    if occupants is not None:
        from .occupants import certify_occupants, occupant_mu

        say(f"the set: {len(occupants.stability)} stability and "
            f"{len(occupants.performance)} performance samples")
        check = certify_occupants(K, occupants, progress=progress)
        if search:
            from .worstcase import worst_bump_seats

            say("the set's worst force and stroke, by search")
            worst = worst_bump_seats(K, occupants.occupants, rng=rng_search,
                                     road=occupants.road)
        if mixed_mu:
            say("the set's mixed µ")
            occ_mu = occupant_mu(K, occupants.occupants, design=design, rng=rng_set)
    return SeatCertificate(delays=delays, peak=tuple(m.peak_z3dd for m in runs),
                           u_peak=tuple(m.peak_u_command for m in runs),
                           x1_peak=tuple(m.peak_x1 for m in runs), sampled_peak=sampled,
                           mu=mu, delay_margin=float(stability_delay_margin(K, params)),
                           loop_radius=float(np.max(np.abs(loop_poles(K, params)))),
                           limit=limit, occupants=check, mixed_mu=occ_mu,
                           requirements=requirements, worst_seats=worst)


def _jsonable(obj):
    """Plain JSON values: numpy to Python, tuples to lists, dataclasses to dicts."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return _jsonable(asdict(obj))
    if isinstance(obj, Mapping):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, (np.integer, int)):
        return int(obj)
    if isinstance(obj, (np.floating, float)):
        return float(obj)
    return obj
