"""A scheduled seat controller in use: the controller a seat runs for the occupant it
measured, its 1 kHz loop at every scheduling value, its comfort over the occupant's
mass, and what an error of the mass estimate does to it.

A *scheduled* controller is anything with ``names`` (the scheduling parameters, fields
of :class:`~.params.SeatParameters` such as ``m3`` and ``k1``), ``bounds`` (each one's
range) and ``at(**values)`` returning a continuous-time ``StateSpace`` from
``y = [x1, x3]`` (m) to ``u`` (N): a :class:`~lmi_suspension.lti.gridded.GriddedController`
(``seat/data/mu_scheduled.json``), lpvsyn's ``ScheduledController``.  Nothing here
assumes which parameters it is scheduled on or where its nodes lie.

* :func:`controller_for_seat`: the controller a seat runs, scheduled on its measured
  values (the true ones plus an estimate error, held inside the schedule's range, as a
  seat saturates an estimate to what its schedule covers); an unscheduled controller is
  returned unchanged.  The CLI's ``simulate --m3`` and every sweep case use it.
* :func:`sampled_schedule_check`: at every scheduling node, the controller discretised
  at 1 kHz (Tustin, :func:`~.sampled.discretise_controller`) in the sampled-data loop
  (:func:`~.sampled.simulate_sampled`) against the continuous loop
  (:func:`~.simulate.simulate`), peak ``|z̈3|`` on the bump (issue 62's "the 1 kHz loop
  within 0.5 % of the continuous one").
* :func:`ratio_over_mass`: peak ``|z̈3|`` on the bump over each seat's own clairvoyant
  limit (:func:`~.limit.bump_limit`) along the occupant's mass, for any controllers.
* :func:`inject_mass_error`: the scheduled certificate
  (:func:`~.scheduled.certify_scheduled`) with every seat's estimate off by the same
  error, per error; :func:`first_broken` says which requirement fails first as the
  error grows.

Examples
--------
>>> import control
>>> from lmi_suspension.lti.gridded import GriddedController
>>> from lmi_suspension.seat.params import SeatParameters
>>> K30 = control.ss([], [], [], [[0.0, -1e4]])
>>> K70 = control.ss([], [], [], [[0.0, -3e4]])
>>> Ks = GriddedController.from_controllers({"m3": [30.0, 70.0]}, [K30, K70])
>>> schedule_point(Ks, SeatParameters(m3=50.0), {"m3": -5.0})
{'m3': 45.0}
>>> schedule_point(Ks, SeatParameters(m3=80.0))       # held at the schedule's end
{'m3': 70.0}
>>> float(controller_for_seat(Ks, SeatParameters(m3=50.0)).D[0, 1])
-20000.0
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import control
import numpy as np

from ..errors import ParameterError
from ..lti.checks import finite_scalar
from .params import SeatParameters

__all__ = ["SHIPPED_AT_MASS", "SHIPPED_SCHEDULED", "MassErrorRow", "MassRatioCurve",
           "SampledNodeCheck", "SampledScheduleCheck", "controller_for_seat",
           "first_broken", "inject_mass_error", "is_scheduled", "ratio_over_mass",
           "sampled_schedule_check", "schedule_nodes", "schedule_point"]

_DATA = Path(__file__).parent / "data"
#: the seat controller scheduled on what the seat measures (issue 62): what ``reproduce``
#: exports as ``controller.json``
SHIPPED_SCHEDULED = _DATA / "mu_scheduled.json"
#: controllers each tuned for exactly one occupant mass, at their masses (a
#: GriddedController over ``m3``): the best a controller scheduled on the mass could do
SHIPPED_AT_MASS = _DATA / "mu_at_mass.json"
#: the seat's parameters a schedule may be on (what a seat could measure or be told)
_SEAT_FIELDS = tuple(f.name for f in dataclasses.fields(SeatParameters))
#: issue 62's requirements on the seat (issue 38's force and stroke; its comfort targets)
DEFAULT_REQUIREMENTS = {"unstable": 0, "u_max": 1500.0, "x1_max": 0.08,
                        "worst_ratio": 1.8, "nominal_ratio": 1.5}


def is_scheduled(K) -> bool:
    """Whether ``K`` is a scheduled controller (``names``, ``bounds`` and ``at``), not one
    ``StateSpace``."""
    return (not isinstance(K, control.StateSpace) and callable(getattr(K, "at", None))
            and hasattr(K, "names") and hasattr(K, "bounds"))


def schedule_point(Ks, seat: SeatParameters, errors: Mapping | None = None) -> dict:
    """The values ``Ks`` is scheduled on for ``seat``: each scheduling parameter's true
    value (``seat``'s field of that name) plus its estimate error (``errors``, 0 where
    not given), held inside the schedule's range.

    Errors of parameters the schedule is not on are ignored (the seat does not measure
    them); the caller refuses them where that is a user's mistake.

    Raises
    ------
    ParameterError
        ``Ks`` not scheduled, scheduled on a name that is not a seat parameter, an error
        that is not a finite number.
    """
    if not is_scheduled(Ks):
        raise ParameterError(f"not a scheduled controller: {type(Ks).__name__}")
    if not isinstance(seat, SeatParameters):
        raise ParameterError(f"seat must be SeatParameters, got {type(seat).__name__}")
    errors = dict(errors or {})
    point = {}
    for name, (lo, hi) in zip(Ks.names, Ks.bounds):
        if name not in _SEAT_FIELDS:
            raise ParameterError(f"the schedule is on {name!r}, not a seat parameter "
                                 f"({', '.join(_SEAT_FIELDS)})")
        value = getattr(seat, name) + finite_scalar(errors.get(name, 0.0), f"error of {name}")
        point[name] = float(min(max(value, float(lo)), float(hi)))
    return point


def controller_for_seat(K, seat: SeatParameters, errors: Mapping | None = None):
    """The controller a seat runs: ``K`` itself when it is one ``StateSpace`` (or None,
    the passive seat), else ``K.at(...)`` at :func:`schedule_point`."""
    if K is None or not is_scheduled(K):
        return K
    return K.at(**schedule_point(K, seat, errors))


def schedule_nodes(Ks) -> tuple[dict, ...]:
    """The scheduling values ``Ks`` was built at, each as ``{name: value}``: its
    ``nodes`` (a GriddedController's grid, or whatever values a schedule says it holds
    controllers at), else the product of its ``axes``.

    Raises
    ------
    ParameterError
        ``Ks`` says neither.
    """
    import itertools

    if not is_scheduled(Ks):
        raise ParameterError(f"not a scheduled controller: {type(Ks).__name__}")
    nodes = getattr(Ks, "nodes", None)
    if nodes is None and getattr(Ks, "axes", None) is not None:
        nodes = tuple(itertools.product(*(np.asarray(a, float).tolist() for a in Ks.axes)))
    if nodes is None:
        raise ParameterError("the schedule names no nodes; give the points to check")
    return tuple({n: float(v) for n, v in zip(Ks.names, node)} for node in nodes)


# ------------------------------------------------------------------ the 1 kHz loop
@dataclass(frozen=True)
class SampledNodeCheck:
    """The 1 kHz loop against the continuous one at one scheduling value.

    Attributes
    ----------
    point : dict
        The scheduling value ``{name: value}``; the seat is the nominal one with these
        values (the controller meets the seat it was scheduled for).
    delays : tuple of float
    continuous_peak, sampled_peak : tuple of float
        Peak ``|z̈3|`` on the bump per delay, m/s²: the exact-delay continuous loop and
        the sampled-data loop (zero-order hold), both unclipped (the requirements bound
        what the controller commands).
    fastest_pole : float
        The controller's largest pole magnitude there, rad/s (above ``π/dt`` the discrete
        controller does not resolve it).
    """

    point: dict
    delays: tuple
    continuous_peak: tuple
    sampled_peak: tuple
    fastest_pole: float

    @property
    def gap(self) -> float:
        """The largest relative difference of the sampled peak from the continuous one
        over the delays (inf where a loop diverged)."""
        c, s = np.asarray(self.continuous_peak), np.asarray(self.sampled_peak)
        if not (np.all(np.isfinite(c)) and np.all(np.isfinite(s))):
            return math.inf
        return float(np.max(np.abs(s - c) / c))


@dataclass(frozen=True)
class SampledScheduleCheck:
    """:func:`sampled_schedule_check`'s result: one :class:`SampledNodeCheck` per
    scheduling value, the sample time and the tolerance."""

    nodes: tuple
    dt: float
    tolerance: float

    @property
    def gap(self) -> float:
        """The largest gap over the scheduling values."""
        return max(n.gap for n in self.nodes)

    @property
    def passed(self) -> bool:
        """Every scheduling value's gap within the tolerance."""
        return self.gap <= self.tolerance


def sampled_schedule_check(Ks, *, dt: float = 1e-3, delays: Sequence = (0.0, 0.025),
                           tolerance: float = 0.005, points=None,
                           params: SeatParameters | None = None, road=None,
                           sim_dt: float = 1e-4) -> SampledScheduleCheck:
    """The scheduled controller at 1 kHz against its continuous loop, at every
    scheduling value (issue 62, item 3).

    At each point the controller ``Ks.at(point)`` is discretised by Tustin's map at
    ``dt`` (:func:`~.sampled.discretise_controller`, the route every shipped controller's
    discrete realization takes) and run in the sampled-data loop
    (:func:`~.sampled.simulate_sampled`: continuous seat, zero-order hold, exact delay)
    on the seat with the point's values; its peak ``|z̈3|`` on the bump is compared with
    the continuous exact-delay loop's (:func:`~.simulate.simulate`), both unclipped, as
    :func:`~.record.certify_seat`'s ``sampled_peak`` is.

    Parameters
    ----------
    Ks : scheduled controller
    dt : float
        Sample time, s (1 kHz).
    delays : sequence of float
        Actuator delays, s (multiples of ``sim_dt``).
    tolerance : float
        The relative gap allowed (0.5 %).
    points : sequence of dict, optional
        Scheduling values; by default the schedule's nodes (:func:`schedule_nodes`).
    params : SeatParameters, optional
        The seat's other values (Table 1 by default).
    road : RoadInput, optional
        The paper's bump by default.
    sim_dt : float
        Step of both simulations, s.

    Raises
    ------
    ParameterError
        ``Ks`` not scheduled, no points, bad ``dt``, delays or tolerance.
    """
    from .roads import bump
    from .sampled import discretise_controller, fastest_pole, simulate_sampled
    from .simulate import simulate

    points = schedule_nodes(Ks) if points is None else tuple(dict(p) for p in points)
    if not points:
        raise ParameterError("no scheduling values to check")
    dt = finite_scalar(dt, "dt")
    tolerance = finite_scalar(tolerance, "tolerance")
    if dt <= 0 or tolerance < 0:
        raise ParameterError(f"dt must be > 0 and tolerance >= 0, got {dt}, {tolerance}")
    delays = tuple(finite_scalar(d, "a delay") for d in delays)
    if not delays or min(delays) < 0:
        raise ParameterError(f"delays must be non-empty and >= 0, got {delays!r}")
    params = SeatParameters() if params is None else params
    road = bump() if road is None else road
    out = []
    for point in points:
        K = Ks.at(**point)
        seat = dataclasses.replace(params, **{n: v for n, v in point.items()
                                              if n in _SEAT_FIELDS})
        # the fact of an unresolved pole is the result's (fastest_pole), not a warning
        Kd = discretise_controller(K, dt, warn_unresolved=False)
        cont = tuple(float(np.max(np.abs(simulate(K, road, delay=d, params=seat,
                                                  u_max=np.inf, dt=sim_dt).z3dd)))
                     for d in delays)
        samp = tuple(float(np.max(np.abs(simulate_sampled(Kd, road, delay=d, params=seat,
                                                          u_max=np.inf, dt=sim_dt).z3dd)))
                     for d in delays)
        out.append(SampledNodeCheck(point=dict(point), delays=delays, continuous_peak=cont,
                                    sampled_peak=samp, fastest_pole=fastest_pole(K)))
    return SampledScheduleCheck(nodes=tuple(out), dt=dt, tolerance=tolerance)


# ------------------------------------------------------------ comfort over the mass
@dataclass(frozen=True)
class MassRatioCurve:
    """One controller's peak ratio along the occupant's mass (:func:`ratio_over_mass`).

    Attributes
    ----------
    label : str
    m3 : tuple of float
        The true masses, kg.
    ratio : tuple of float
        Worst over the delays of peak ``|z̈3|`` over that seat's own limit (inf where a
        loop is unstable, nan where the limit's LP failed).
    peak_u : tuple of float
        Largest commanded ``|u|`` over the delays, N.
    scheduled_on : tuple of dict or None
        The values a scheduled controller ran at (None for an unscheduled one).
    """

    label: str
    m3: tuple
    ratio: tuple
    peak_u: tuple
    scheduled_on: tuple | None = None


def ratio_over_mass(controllers: Mapping, masses: Sequence, *, delays=(0.0, 0.025),
                    params: SeatParameters | None = None, road=None, dt: float | None = None,
                    limit_dt: float = 2e-3, limits: Mapping | None = None,
                    at_nodes: Sequence = ()) -> tuple[MassRatioCurve, ...]:
    """Peak ``|z̈3|`` on the bump over each seat's own clairvoyant limit, along the
    occupant's mass, for every controller of ``controllers`` (``{label: K}``; a
    scheduled one runs at each seat's true values, :func:`controller_for_seat`).

    The seat is ``params`` (Table 1) with ``m3`` set; each loop is the exact-delay linear
    one (:func:`~.simulate.simulate`, unclipped: the requirements bound what the
    controller commands) and, where the Nyquist count (:func:`~.simulate.closed_loop_stable`)
    finds it unstable at a delay, its ratio is inf.

    Parameters
    ----------
    controllers : mapping of str to controller
        Evaluated at every mass of ``masses``.
    masses : sequence of float
        kg.
    delays : sequence of float
        s; the worst is taken.
    params, road, dt
        The seat's other values, the road (the bump) and the simulation step.
    limit_dt : float
        The limit LP's step (:func:`~.limit.bump_limit`).
    limits : mapping of float to float, optional
        Limits already computed, by mass (the others are computed and not returned).
    at_nodes : sequence of str
        Labels of ``controllers`` that are scheduled controllers evaluated only at their
        own nodes' masses (each node's controller at the seat it was tuned for: "a
        controller tuned for exactly that mass"), not at ``masses``.

    Raises
    ------
    ParameterError
        No masses, a mass that is not positive, a label of ``at_nodes`` not scheduled.
    """
    from .limit import bump_limit
    from .roads import bump
    from .simulate import closed_loop_stable, simulate

    params = SeatParameters() if params is None else params
    road = bump() if road is None else road
    masses = tuple(finite_scalar(m, "a mass") for m in masses)
    if not masses or min(masses) <= 0:
        raise ParameterError(f"masses must be non-empty and positive, got {masses!r}")
    delays = tuple(finite_scalar(d, "a delay") for d in delays)
    cache = {float(k): float(v) for k, v in (limits or {}).items()}

    def limit(m):
        if m not in cache:
            try:
                cache[m] = float(bump_limit(road, dataclasses.replace(params, m3=m),
                                            dt=limit_dt).certified_peak)
            except Exception:  # noqa: BLE001 - a failed LP: no ratio at this mass
                cache[m] = math.nan
        return cache[m]

    curves = []
    for label, K in controllers.items():
        if label in at_nodes:
            if not is_scheduled(K):
                raise ParameterError(f"{label}: at_nodes needs a scheduled controller")
            points = [p for p in schedule_nodes(K)]
            ms = tuple(p.get("m3", params.m3) for p in points)
        else:
            points, ms = None, masses
        ratio, peak_u, on = [], [], []
        for i, m in enumerate(ms):
            seat = dataclasses.replace(params, m3=m)
            if points is not None:
                Km = K.at(**points[i])
                seat = dataclasses.replace(seat, **{n: v for n, v in points[i].items()
                                                    if n in _SEAT_FIELDS})
                on.append(dict(points[i]))
            else:
                Km = controller_for_seat(K, seat)
                on.append(schedule_point(K, seat) if is_scheduled(K) else None)
            lim = limit(float(m))
            if Km is not None and not all(closed_loop_stable(Km, d, seat) for d in delays):
                ratio.append(math.inf)
                peak_u.append(math.inf)
                continue
            mets = [simulate(Km, road, delay=d, params=seat, u_max=np.inf, dt=dt).metrics()
                    for d in (delays if Km is not None else delays[:1])]
            ratio.append(max(r.peak_z3dd for r in mets) / lim)
            peak_u.append(max(r.peak_u_command for r in mets))
        curves.append(MassRatioCurve(label=str(label), m3=tuple(float(m) for m in ms),
                                     ratio=tuple(ratio), peak_u=tuple(peak_u),
                                     scheduled_on=tuple(on) if is_scheduled(K) else None))
    return tuple(curves)


# ------------------------------------------------------- the mass estimate's error
@dataclass(frozen=True)
class MassErrorRow:
    """The certificate's sampled figures with every estimate off by ``error`` kg
    (:func:`inject_mass_error`): ``unstable`` of ``n_stability`` loops, the worst and
    the nominal peak ratio, the largest commanded force (N) and stroke (m) over the
    performance samples and delays; ``check`` the whole
    :class:`~.scheduled.ScheduledCheck`."""

    error: float
    unstable: int
    n_stability: int
    worst_ratio: float
    nominal_ratio: float
    u_max: float
    x1_max: float
    check: object = dataclasses.field(repr=False, default=None)


def inject_mass_error(Ks, samples, errors: Sequence, *, rng: np.random.Generator,
                      delays=None, confirm: int = 0) -> tuple[MassErrorRow, ...]:
    """Evaluate a controller scheduled on the occupant's mass with the estimate off by
    each error of ``errors`` (kg, the same for every seat; the estimate held inside the
    schedule's range): :func:`~.scheduled.certify_scheduled` with those errors given,
    its sampled part only (stability of every stability sample by the exact-delay
    Nyquist count; the road figures of every performance sample and delay).

    ``nominal_ratio`` is the nominal seat's at its *true* mass (certify_scheduled's), the
    same in every row.

    Raises
    ------
    ParameterError
        No errors, an error that is not finite, and what certify_scheduled refuses.
    """
    from .scheduled import certify_scheduled

    errors = tuple(finite_scalar(e, "an error") for e in errors)
    if not errors:
        raise ParameterError("give at least one error")
    ns, npf = len(samples.stability), len(samples.performance)
    rows = []
    for e in errors:
        c = certify_scheduled(Ks, samples, rng=rng, error=abs(e),
                              errors=(np.full(ns, e), np.full(npf, e)), grid=(),
                              delays=delays, confirm=confirm, mu=False, search=False)
        rows.append(MassErrorRow(error=e, unstable=c.unstable, n_stability=c.n_stability,
                                 worst_ratio=c.worst_ratio, nominal_ratio=c.nominal_ratio,
                                 u_max=c.u_max, x1_max=c.x1_max, check=c))
    return tuple(rows)


def first_broken(rows: Sequence[MassErrorRow], requirements: Mapping | None = None
                 ) -> list[tuple[str, float | None]]:
    """Each requirement and the smallest ``|error|`` of ``rows`` at which it fails
    (None: met at every error), the first to break first; requirements that fail at the
    smallest error of the rows are already broken there.

    ``requirements``: ``{"unstable": 0, "u_max": N, "x1_max": m, "worst_ratio": r,
    "nominal_ratio": r}`` upper bounds (issue 62's by default).

    Examples
    --------
    >>> rows = [MassErrorRow(0.0, 0, 10, 1.2, 1.1, 1400.0, 0.05),
    ...         MassErrorRow(5.0, 0, 10, 1.5, 1.1, 1490.0, 0.05),
    ...         MassErrorRow(10.0, 1, 10, 1.9, 1.1, 1550.0, 0.06)]
    >>> first_broken(rows)[:3]
    [('unstable', 10.0), ('u_max', 10.0), ('worst_ratio', 10.0)]
    """
    req = dict(DEFAULT_REQUIREMENTS if requirements is None else requirements)
    unknown = set(req) - set(DEFAULT_REQUIREMENTS)
    if unknown:
        raise ParameterError(f"unknown requirements {sorted(unknown)}; the figures are "
                             f"{list(DEFAULT_REQUIREMENTS)}")
    order = sorted(rows, key=lambda r: abs(r.error))
    out = []
    for name, bound in req.items():
        broke = next((abs(r.error) for r in order
                      if not getattr(r, name) <= bound), None)   # nan or inf fails
        out.append((name, broke))
    # broken first first, then in the order given; never broken last
    return sorted(out, key=lambda x: math.inf if x[1] is None else x[1])
