"""One seat controller for a set of seats: the refinement over several plants, with a
worst-case search that adds the seats it fails on (the multi-model tuning of MATLAB's
``systune`` with uncertain parameters: tune on a finite set, search the continuum for a
violation, add it, tune again).

Each round refines the controller (:func:`~.refine.refine_seat_controller` with
``RefineOptions.plants``) on the current seats: the road requirements (force, stroke,
every delay), stability and robust stability against the delay cover hold at each, and
the worst of each seat's peak ``|z̈3|`` over its own physical limit is minimised.  With
``RefineOptions.occupants``, robust stability over the whole set (mixed µ,
:class:`~.occupants.MixedRsBound`) is required as well.  Then
``n_search`` Latin-hypercube samples of the :class:`~.occupants.OccupantSet` are met by
the result, and the set's corners and a climb from the worst of them look for the
largest force and stroke (:func:`~.worstcase.worst_bump_seats`: samples rarely come near
a corner, where the force peaks); the seats that violate a requirement, or whose ratio
exceeds the rounds' worst over its seats, are added (at most ``add`` per round,
violations first, the worst first), and the next round starts from the result.  The
loop ends when a search finds nothing to add, finds a seat where the loop is unstable
(reported, not added: a refinement starts from a loop that is stable at every seat it
serves), or after ``rounds`` rounds.

The answer is certified by :func:`~.occupants.certify_occupants` on samples the search
did not draw and by :func:`~.occupants.occupant_mu`.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable, ClassVar, Mapping

import control
import numpy as np

from ..errors import ParameterError
from .augmented import SeatDesignOptions
from .loop import _LIMIT_DT, BumpResponse, loop_poles
from .occupants import OccupantSet
from .refine import RefinedDesign, RefineOptions, refine_seat_controller
from .roads import RoadInput, bump
from .worstcase import worst_bump_seats

__all__ = ["OccupantRound", "OccupantDesign", "OccupantRoute", "SHIPPED_OCCUPANTS",
           "SHIPPED_OCCUPANT_TRADEOFF", "OccupantTradeoffPoint", "load_occupant_tradeoff",
           "refine_for_occupants"]

logger = logging.getLogger(__name__)

#: the multi-seat design of 2026-11-28 with the set's mixed µ as a requirement, refined
#: at the corners where :func:`~.worstcase.worst_bump_seats` found the force above 1500 N
#: (its metadata's ``made`` says how; read it with :func:`~.refine.load_refined`): mixed
#: µ of robust stability 0.987 over every frequency, stable on 10 000 sampled seats,
#: 1497 N at the set's worst seat found, 2.88 × each seat's own limit at worst on 200
#: (the note of issue 38), not yet the issue's comfort targets
SHIPPED_OCCUPANTS = Path(__file__).parent / "data" / "mu_occupants.json"

#: the trade-off of the force bound over the set: designs of this route at higher bounds,
#: each measured on the set with its corners searched (read by
#: :func:`load_occupant_tradeoff`; the designs ship beside it)
SHIPPED_OCCUPANT_TRADEOFF = Path(__file__).parent / "data" / "tradeoff_occupants.json"

#: a search sample joins the seats when its ratio exceeds the round's worst by more than
#: this fraction (below it, the FFT's and the search's own margins decide, not the seat)
_ADD_TOL = 0.01


@dataclass(frozen=True)
class OccupantRound:
    """One round of :func:`refine_for_occupants` (progress record).

    Attributes
    ----------
    index : int
    plants : tuple of SeatParameters
        The seats the round refined on, besides the design seat.
    design : RefinedDesign
    worst_found : float
        The largest ratio (peak over own limit) among the search samples.
    violations_found : int
        Search samples, and worst seats of the corner search (``worst_seats``), that
        violate force, stroke or stability.
    added : tuple of SeatParameters
        The seats added for the next round.
    unstable : tuple of SeatParameters
        Search samples and corner-search seats whose loop is unstable with the round's
        controller.  They are not added: a refinement starts from a controller whose
        loop is stable at every seat it serves.  The loop stops after a round that
        finds one (a user decides: another start, a smaller set).
    seconds : float
    worst_seats : tuple of WorstSeat
        The largest force and stroke found over the set's corners and a climb.
    """

    index: int
    plants: tuple
    design: RefinedDesign
    worst_found: float
    violations_found: int
    added: tuple
    unstable: tuple
    seconds: float
    worst_seats: tuple = ()


@dataclass(frozen=True)
class OccupantDesign:
    """The result of :func:`refine_for_occupants`.

    Attributes
    ----------
    K : control.StateSpace
        The last round's controller ``y = [x1, x3]`` (m) to ``u`` (N).
    design : RefinedDesign
        The last round's refinement (its ``options.plants`` are the final seats).
    rounds : tuple of OccupantRound
    seconds : float
    """

    K: control.StateSpace
    design: RefinedDesign
    rounds: tuple
    seconds: float


def _search(K, seats, opts: RefineOptions, road: RoadInput) -> list:
    """``(violation, ratio, seat)`` of each search seat: violation is the largest relative
    excess over the force or stroke bound (inf where the loop is unstable without delay
    or at one of ``opts.delays``)."""
    from .limit import bump_limit

    from .simulate import closed_loop_stable

    out = []
    for p in seats:
        if np.max(loop_poles(K, p).real) >= 0 \
                or not all(closed_loop_stable(K, float(d), p) for d in opts.delays):
            out.append((np.inf, np.inf, p))
            continue
        z, u, x1 = BumpResponse(road=road, delays=tuple(opts.delays), params=p).peaks(K)
        limit = bump_limit(road, p, dt=_LIMIT_DT).certified_peak
        violation = max(float(np.max(u)) / opts.u_bound - 1, float(np.max(x1)) / opts.z_bound - 1)
        out.append((violation, float(np.max(z)) / limit, p))
    return out


def _corner_search(K, occupants: OccupantSet, opts: RefineOptions, road: RoadInput,
                   rng: np.random.Generator, plants) -> tuple[tuple, list]:
    """The set's largest force and stroke over its corners and a climb
    (:func:`~.worstcase.worst_bump_seats`, no samples: ``_search`` has met them), and
    ``(violation, nan, seat)`` for each that exceeds its bound: violations rank by their
    excess, so the seat's ratio is not needed.  The excess is the frequency-domain
    figure's, the one the refinement bounds at its seats and ``_search`` reads, so that
    a seat the refinement serves is never a violation here; such a seat is not added
    again in any case."""
    worst_seats = worst_bump_seats(K, occupants, rng=rng, n=0, delays=opts.delays,
                                   road=road)
    violations = []
    for w in worst_seats:
        figure = w.value if w.value == math.inf else w.frequency_value
        excess = figure / (opts.u_bound if w.figure == "u" else opts.z_bound) - 1
        if excess > 0 and w.seat not in plants:
            violations.append((excess, math.nan, w.seat))
    return worst_seats, violations


def refine_for_occupants(K0, occupants: OccupantSet | None = None,
                         options: RefineOptions | None = None, *, rng: np.random.Generator,
                         rounds: int = 3, n_search: int = 40, add: int = 2,
                         corners=("m3", "k1"), design=None, road: RoadInput | None = None,
                         progress: Callable[[OccupantRound], None] | None = None
                         ) -> OccupantDesign:
    """Refine a seat controller for every seat of a set (see the module docstring).

    Parameters
    ----------
    K0 : control.StateSpace
        Start controller whose loop is stable at the design seat.
    occupants : OccupantSet, optional
        The set (30–70 kg, springs and dampers ±20 %, delay 0–25 ms by default).
    options : RefineOptions, optional
        The requirements; ``options.plants``, if any, are the first round's seats, else
        the corners of ``corners``' ranges (:meth:`~.occupants.OccupantSet.corners`).
        ``options.max_iter`` is per round.
    rng : numpy.random.Generator
        Draws the search samples (the corners' search draws none).
    rounds, n_search, add : int
        Bounds of the loop: rounds, search samples per round, seats added per round.
    corners : tuple of str
    design : SeatDesignOptions, optional
        The µ weights and delay cover of the refinement.
    road : RoadInput, optional
        The paper's bump by default.
    progress : callable, optional
        Called with each :class:`OccupantRound`.

    Returns
    -------
    OccupantDesign
    """
    t0 = time.perf_counter()
    occupants = OccupantSet() if occupants is None else occupants
    opts = RefineOptions() if options is None else options
    if not isinstance(opts, RefineOptions):
        raise ParameterError(f"options must be a RefineOptions, got {type(opts).__name__}")
    for name, v in (("rounds", rounds), ("n_search", n_search), ("add", add)):
        if isinstance(v, bool) or not isinstance(v, int) or v < 1:
            raise ParameterError(f"{name} must be a positive int, got {v!r}")
    if not isinstance(rng, np.random.Generator):
        raise ParameterError("rng must be a numpy.random.Generator (seeded by the caller)")
    road = bump() if road is None else road
    plants = opts.plants or occupants.corners(tuple(corners))
    K, history = K0, []
    for index in range(1, rounds + 1):
        t_round = time.perf_counter()
        d = refine_seat_controller(K, replace(opts, plants=tuple(plants)), design=design,
                                   params=occupants.nominal, road=road)
        K = d.K
        seats, _ = occupants.sample(n_search, rng)
        found = _search(K, seats, opts, road)
        worst_found = max(f[1] for f in found)
        worst_seats, violations = _corner_search(K, occupants, opts, road, rng,
                                                 (occupants.nominal, *plants))
        found = list(found) + violations
        worst = float(np.max(d.peak))
        unstable = tuple(p for v, _, p in found if v == np.inf)
        # violations first, the largest first; then the seats that meet the bounds, by
        # ratio, where it exceeds the seats' worst
        ranked = sorted((f for f in found if f[0] < np.inf),
                        key=lambda f: (0, -f[0]) if f[0] > 0 else (1, -f[1]))
        added = tuple(dict.fromkeys(p for v, r, p in ranked     # a seat once
                                    if v > 0 or r > worst * (1 + _ADD_TOL)))[:add]
        rec = OccupantRound(index=index, plants=tuple(plants), design=d,
                            worst_found=worst_found,
                            violations_found=sum(f[0] > 0 for f in found), added=added,
                            unstable=unstable, seconds=time.perf_counter() - t_round,
                            worst_seats=worst_seats)
        history.append(rec)
        logger.info("occupant round %d: %d seats, worst ratio %.3f on them, %.3f on the "
                    "search (%d violations), %d added (%.0f s)", index, len(plants) + 1,
                    worst, rec.worst_found, rec.violations_found, len(added), rec.seconds)
        if progress is not None:
            progress(rec)
        if unstable:
            logger.warning("occupant round %d: the loop is unstable at %d search seats; "
                           "stopping (see OccupantRound.unstable)", index, len(unstable))
        if not added or unstable:
            break
        plants = tuple(plants) + added
    return OccupantDesign(K=K, design=history[-1].design, rounds=tuple(history),
                          seconds=time.perf_counter() - t0)


def _round_line(r: OccupantRound) -> str:
    """One line of progress for a round."""
    return (f"round {r.index}: {len(r.plants) + 1} seats, worst peak/limit "
            f"{np.max(r.design.peak):.3f}, |u| {np.max(r.design.u_peak):.0f} N, met "
            f"{r.design.met}; search: worst {r.worst_found:.3f}, "
            + "".join(f"{w.figure} {w.value:.4g}, " for w in r.worst_seats)
            + f"{r.violations_found} violations, {len(r.added)} seats added "
            f"({r.seconds:.0f} s)")


@dataclass(frozen=True)
class OccupantRoute:
    """The refinement over a set of seats with a worst-case search
    (:func:`refine_for_occupants`) as a :class:`~.routes.SeatRoute`.

    Attributes
    ----------
    occupants : OccupantSet, optional
        The set (30–70 kg, springs and dampers ±20 %, delay 0–25 ms around the seat
        designed for, by default).
    options : RefineOptions, optional
        The requirements; by default those of :class:`~.refine.RefineOptions` with the
        set's mixed µ of robust stability required and the µ of robust performance
        replaced by the delay cover's gain (``mu_performance=False``), as the shipped
        design was made.
    start : SeatRoute or control.StateSpace, optional
        The start controller or the route that designs it (the µ route by default).
    rounds, n_search, add : int
        As :func:`refine_for_occupants`.
    design_options : SeatDesignOptions, optional
        The µ weights and delay cover of the refinement
        (:data:`~.augmented.DEFAULT_DESIGN` by default).

    Examples
    --------
    >>> OccupantRoute().name
    'occupants'
    """

    name: ClassVar[str] = "occupants"
    occupants: OccupantSet | None = None
    options: RefineOptions | None = None
    start: object = None
    rounds: int = 3
    n_search: int = 40
    add: int = 2
    design_options: SeatDesignOptions | None = None

    def design(self, params, *, rng: np.random.Generator, progress=None):
        """The start (given or designed), refined for the set around ``params``; two
        streams spawned from ``rng``: the start's route's and the worst-case search's."""
        from .augmented import DEFAULT_DESIGN
        from .design import MuRoute
        from .record import seat_design_from
        from .refine import _description, _figures, _start

        occupants = OccupantSet(nominal=params) if self.occupants is None else self.occupants
        if params != occupants.nominal:
            raise ParameterError("the occupant route designs for its set's nominal seat; "
                                 "params differ from occupants.nominal")
        opts = (RefineOptions(mu_performance=False, occupants=occupants)
                if self.options is None else self.options)
        # one stream each: the start's draws do not move the search's samples
        rng_start, rng_search = rng.spawn(2)
        start = (MuRoute(design_options=self.design_options) if self.start is None
                 else self.start)
        K0 = _start(start, params, rng_start, progress)
        weights = DEFAULT_DESIGN if self.design_options is None else self.design_options
        d = refine_for_occupants(K0, occupants, opts, rng=rng_search, rounds=self.rounds,
                                 n_search=self.n_search, add=self.add, design=weights,
                                 progress=None if progress is None
                                 else (lambda r: progress(_round_line(r))))
        return seat_design_from(self.name, d.K, params=params, weights=weights,
                                seconds=d.seconds, detail=d,
                                description=_description(d.design),
                                figures={**_figures(d.design), "rounds": len(d.rounds)})


class _ReadOnly(Mapping):
    """A read-only copy of a mapping, nested mappings included (other values as they
    are); it pickles, and compares equal to a dict of the same items."""

    def __init__(self, items: Mapping):
        self._items = {k: _ReadOnly(v) if isinstance(v, Mapping) else v
                       for k, v in items.items()}

    def __getitem__(self, key):
        return self._items[key]

    def __iter__(self):
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def __repr__(self) -> str:
        return repr(self._items)

    def __reduce__(self):
        return _ReadOnly, (self._items,)


@dataclass(frozen=True)
class OccupantTradeoffPoint:
    """One design of the force bound's trade-off over the set, as ``lmi-suspension
    occupants FILE --mu`` measured it.

    Attributes
    ----------
    u_bound : float
        The force bound the design held at its seats, N.
    design : str
        Its file (a name beside the table, or a path).
    unstable, n_stability : int
        Sampled seats (with delays) where the loop is unstable, of how many.
    worst_ratio, nominal_ratio : float
        Peak ``|z̈3|`` on the bump over each seat's own limit: the worst over the
        performance samples and delays, and at the nominal seat.
    u_samples, x1_samples : float
        The largest commanded force (N) and stroke (m) on those samples.
    searched_u, searched_x1 : mapping
        :meth:`~.worstcase.WorstSeat.as_dict` of the set's worst force and stroke found by
        :func:`~.worstcase.worst_bump_seats` (``value``, ``delay``, ``seat``).
    rs_mu, rp_mu : float
        Mixed µ of robust stability and of robust performance over the set, bounded
        between the grid's points (:func:`~.occupants.occupant_mu`).
    rs_lower, rp_lower : float
        Their lower bounds on the frequency grid: µ is certainly at least these.
    """

    u_bound: float
    design: str
    unstable: int
    n_stability: int
    worst_ratio: float
    nominal_ratio: float
    u_samples: float
    x1_samples: float
    searched_u: Mapping
    searched_x1: Mapping
    rs_mu: float
    rp_mu: float
    rs_lower: float
    rp_lower: float

    def __post_init__(self):
        # read-only, nested included, so that a frozen point cannot be changed through
        # its mappings (and still pickles, for Dask)
        object.__setattr__(self, "searched_u", _ReadOnly(self.searched_u))
        object.__setattr__(self, "searched_x1", _ReadOnly(self.searched_x1))

    @property
    def u_searched(self) -> float:
        """The largest commanded force found over the set, N."""
        return float(self.searched_u["value"])

    @property
    def x1_searched(self) -> float:
        """The largest stroke found over the set, m."""
        return float(self.searched_x1["value"])


def load_occupant_tradeoff(path: str | Path | None = None,
                           ) -> tuple[tuple[OccupantTradeoffPoint, ...], dict]:
    """The force bound's trade-off of the occupant route over the set.

    Parameters
    ----------
    path : str or Path, optional
        A table written like :data:`SHIPPED_OCCUPANT_TRADEOFF` (the default, the shipped
        measurement).

    Returns
    -------
    points : tuple of OccupantTradeoffPoint
        By rising ``u_bound``; each ``design`` is an absolute path (a relative name in the
        table is beside the table).  Read a design with
        ``load_seat_design(p.design, route="occupants")`` (:func:`~.routes.load_seat_design`)
        or :func:`~.refine.load_refined`.
    table : dict
        The whole table: ``table["command"]`` measured the points, ``table["made"]``
        says how the designs were made and ``table["seconds"]`` what the command took.

    Raises
    ------
    ParameterError
        The file is not JSON, has no ``points``, or a point lacks a field of
        :class:`OccupantTradeoffPoint`.

    See Also
    --------
    lmi_suspension.report.figures.plot_occupant_tradeoff : draws the points.

    Examples
    --------
    >>> points, table = load_occupant_tradeoff()
    >>> [p.u_bound for p in points]
    [1500.0, 1750.0, 2000.0]
    >>> all(p.unstable == 0 for p in points)
    True
    """
    import json

    path = Path(SHIPPED_OCCUPANT_TRADEOFF if path is None else path).resolve()
    try:
        table = json.loads(path.read_text())
        rows = table["points"]
    except (json.JSONDecodeError, KeyError, TypeError) as exc:
        raise ParameterError(f"{path}: not a trade-off table ({exc!r})") from exc
    fields = OccupantTradeoffPoint.__dataclass_fields__
    points = []
    for i, p in enumerate(rows):
        if not isinstance(p, Mapping):
            raise ParameterError(f"{path}: point {i} is not a mapping")
        missing = [k for k in fields if k not in p]
        if missing:
            raise ParameterError(f"{path}: point {i} lacks {', '.join(missing)}")
        design = Path(p["design"])
        values = {k: v for k, v in p.items() if k in fields}
        values["design"] = str(design if design.is_absolute() else path.parent / design)
        points.append(OccupantTradeoffPoint(**values))
    return tuple(sorted(points, key=lambda q: q.u_bound)), table
