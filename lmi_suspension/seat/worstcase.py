"""The seats of a set where a controller's road figures are worst, found by search.

Random samples of an :class:`~.occupants.OccupantSet` are a weak certificate of a
*bound*: the commanded force of a seat controller on the bump is largest at extreme
occupants and springs (a light occupant on stiff springs), and a Latin hypercube of a
few hundred points in seven dimensions rarely comes near a corner.  On the shipped
multi-seat design of 2026-11-27, 200 samples read 1559 N at worst where the set's corner
(30 kg, every spring stiff, the first two dampers soft) asks 1777 N.

:func:`worst_bump_seats` is the time-domain counterpart of MATLAB's ``wcgain`` for the
road requirements: it meets the controller at every corner of the set's box and at
Latin-hypercube samples, then climbs from the worst few by bounded quasi-Newton steps
(L-BFGS-B, finite differences, inside the box), ranking seats by the closed-form
frequency-domain figures of :class:`~.loop.BumpResponse`; the worst seat's figure is
then the exact-delay time simulation's, a route the ranking does not use.  What it
returns is a *lower bound* on the set's worst figure, attained at a seat it names: a
search, not a proof; a figure above a bound is a violation.  A seat where the loop is
unstable at one of the delays is a finding as well (value ``inf``).

Examples
--------
>>> import control, numpy as np
>>> from lmi_suspension.seat.worstcase import worst_bump_seats
>>> from lmi_suspension.seat.occupants import OccupantSet
>>> K = control.ss([], [], [], [[0.0, 0.0]])          # the passive seat commands nothing
>>> u, x1 = worst_bump_seats(K, OccupantSet(stiffness_rel=0.0, damping_rel=0.0),
...                          rng=np.random.default_rng(0), n=4, starts=1)
>>> u.value, x1.figure, x1.seat.m3 in (30.0, 70.0)
(0.0, 'x1', True)
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from itertools import product

import control
import numpy as np

from ..errors import ParameterError
from .occupants import OccupantSet
from .params import SeatParameters
from .roads import RoadInput, bump

__all__ = ["WorstSeat", "worst_bump_seats"]

logger = logging.getLogger(__name__)

#: evaluations of one climb (L-BFGS-B with forward differences in at most 7 parameters:
#: 8 per gradient).  On the shipped designs every climb from a corner or sample stopped
#: within 24 evaluations (2026-11-28).  L-BFGS-B checks the count at each new iterate,
#: so a climb may overrun it by one line search; it stays finite
_CLIMB_EVALUATIONS = 80
#: finite-difference step of a climb in the box's unit coordinates (a 1e-4 step moves a
#: 40 kg mass range by 4 g: the figures' FFT noise is far below the change)
_CLIMB_STEP = 1e-4
#: what a climb's objective reads at an unstable seat (the figures are divided by the
#: start's, so a stable seat reads about -1): below every stable seat, as an instability
#: is worse than any force, but finite (at -inf L-BFGS-B stops with an ABNORMAL status
#: and a nan gradient); the seat itself stays a finding (inf) in the search's record
_UNSTABLE_PENALTY = -1e3
#: the frequency-domain and time-stepping figures of a seat agree to 0.1-0.5 % on the
#: shipped designs (2026-11-28); beyond this, a warning says which one the value is
_AGREEMENT = 0.01
_FIGURES = ("u", "x1")
#: the parameters an :class:`~.occupants.OccupantSet` ranges over
_PARAMETERS = ("m3", "k1", "k2", "k3", "c1", "c2", "c3")


@dataclass(frozen=True)
class WorstSeat:
    """The worst seat found for one road figure (:func:`worst_bump_seats`).

    Attributes
    ----------
    figure : str
        ``"u"``: commanded force ``|u|`` (N, unclipped); ``"x1"``: stroke ``|x1|`` (m).
    value : float
        The figure at ``seat`` and ``delay`` by time stepping with the exact delay (a
        route the search does not use to rank seats); ``inf`` where the loop is
        unstable at ``delay``.
    seat : SeatParameters
        The seat of the set (every parameter, the fixed ones at their value).
    delay : float
        The delay it is attained at, s (the first unstable one, where unstable).
    evaluations : int
        Seats met by the search (shared by both figures).
    frequency_value : float
        The same figure in closed form in the frequency domain, by which the search
        ranked the seats (nan where unstable).
    """

    figure: str
    value: float
    seat: SeatParameters
    delay: float
    evaluations: int
    frequency_value: float = math.nan

    def __post_init__(self):
        if self.figure not in _FIGURES:
            raise ParameterError(f"figure must be one of {_FIGURES}, got {self.figure!r}")

    @property
    def where(self) -> str:
        """The seat's uncertain parameters and the delay, in words."""
        s = self.seat
        return (f"m3 {s.m3:.1f} kg, k1 {s.k1:.0f}, k2 {s.k2:.0f}, k3 {s.k3:.0f} N/m, "
                f"c1 {s.c1:.0f}, c2 {s.c2:.0f}, c3 {s.c3:.0f} N s/m, "
                f"{self.delay * 1e3:.0f} ms")

    @property
    def label(self) -> str:
        """The figure's name in a sentence: ``commanded |u|`` or ``|x1|``."""
        return {"u": "commanded |u|", "x1": "|x1|"}[self.figure]

    def describe(self) -> str:
        """One line: the value and where it is attained."""
        if self.value == math.inf:
            return f"unstable at {self.where}"
        value = (f"{self.value:.1f} N" if self.figure == "u" else f"{self.value:.5f} m")
        return f"{value} at {self.where}"

    def as_dict(self) -> dict:
        """Plain JSON values (``value`` null where the loop is unstable), the seat's
        uncertain parameters by name, and :meth:`describe`'s line as ``text``."""
        return {"figure": self.figure, "label": self.label,
                "value": self.value if math.isfinite(self.value) else None,
                "delay": self.delay, "evaluations": self.evaluations,
                "frequency_value": (self.frequency_value
                                    if math.isfinite(self.frequency_value) else None),
                "seat": {k: getattr(self.seat, k) for k in _PARAMETERS},
                "text": self.describe()}


def worst_bump_seats(K, occupants: OccupantSet | None = None, *, rng: np.random.Generator,
                     n: int = 200, starts: int = 3, delays=None,
                     road: RoadInput | None = None) -> tuple[WorstSeat, WorstSeat]:
    """The seats of a set where the commanded force and the stroke on the road are
    largest, found by search (see the module docstring).

    Parameters
    ----------
    K : control.StateSpace
        Continuous-time controller ``y = [x1, x3]`` (m) to ``u`` (N).
    occupants : OccupantSet, optional
        The set (30–70 kg, springs and dampers ±20 % by default).  Its delay range is
        not searched: the figures are met at each of ``delays``.
    rng : numpy.random.Generator
        Draws the Latin-hypercube samples.
    n : int
        Samples besides the box's corners (``2**p`` corners of the ``p`` parameters with
        a range).
    starts : int
        Climbs per figure, from its worst seats so far.
    delays : sequence of float, optional
        Delays every seat is met at, s (0, 5, …, 25 ms by default).
    road : RoadInput, optional
        The paper's bump by default.

    Returns
    -------
    (WorstSeat, WorstSeat)
        Force first, then stroke.
    """
    from scipy.optimize import minimize

    from .loop import REFINE_DELAYS, BumpResponse, loop_poles
    from .simulate import closed_loop_stable, simulate

    if not isinstance(K, control.StateSpace) or K.isdtime(strict=True) \
            or K.ninputs != 2 or K.noutputs != 1:
        raise ParameterError("K must be a continuous-time StateSpace from y = [x1, x3] to u")
    if not all(np.all(np.isfinite(np.asarray(m, dtype=float))) for m in (K.A, K.B, K.C, K.D)):
        raise ParameterError("K has a non-finite entry")
    occupants = OccupantSet() if occupants is None else occupants
    if not isinstance(occupants, OccupantSet):
        raise ParameterError(f"occupants must be an OccupantSet, got "
                             f"{type(occupants).__name__}")
    if not isinstance(rng, np.random.Generator):
        raise ParameterError("rng must be a numpy.random.Generator (seeded by the caller)")
    for name, v, least in (("n", n, 0), ("starts", starts, 0)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < least:
            raise ParameterError(f"{name} must be an int >= {least}, got {v!r}")
    delays = tuple(float(d) for d in np.atleast_1d(REFINE_DELAYS if delays is None
                                                   else np.asarray(delays, dtype=float)))
    if not delays or any(not math.isfinite(d) or d < 0 for d in delays):
        raise ParameterError(f"delays must be finite and non-negative, got {delays!r}")
    road = bump() if road is None else road
    if not isinstance(road, RoadInput):
        raise ParameterError(f"road must be a RoadInput, got {type(road).__name__}")

    ranges = [r for r in occupants.ranges() if r[2] > r[1]]
    # a range of zero width is a fixed value (m3 may differ from the nominal seat's)
    fixed = {r[0]: r[1] for r in occupants.ranges() if r[2] <= r[1]}
    names = [r[0] for r in ranges]
    lo = np.array([r[1] for r in ranges])
    hi = np.array([r[2] for r in ranges])

    def seat(key) -> SeatParameters:
        return occupants.at({**fixed, **dict(zip(names, lo + np.asarray(key) * (hi - lo)))})

    met: dict = {}                      # unit point -> (2, delays) figures, inf: unstable

    def figures(x) -> tuple:
        """The key of the seat nearest ``x`` in the box and its figures
        ``[[|u| per delay], [|x1| per delay]]``, inf at each delay where the loop is
        unstable (every delay where it is unstable without delay)."""
        key = tuple(np.round(np.clip(np.asarray(x, dtype=float), 0.0, 1.0), 12))
        if key not in met:
            p = seat(key)
            table = np.full((2, len(delays)), np.inf)
            if np.max(loop_poles(K, p).real) < 0:
                stable = np.array([closed_loop_stable(K, d, p) for d in delays])
                if stable.any():
                    _, u, x1 = BumpResponse(road=road, delays=delays, params=p).peaks(K)
                    table[:, stable] = np.vstack([u, x1])[:, stable]
            met[key] = table
        return key, met[key]

    points = [np.array(c, dtype=float) for c in product((0.0, 1.0), repeat=len(names))]
    if n:
        samples, _ = occupants.sample(int(n), rng)
        points += [(np.array([getattr(p, k) for k in names]) - lo) / (hi - lo)
                   for p in samples]
    values = np.array([np.max(figures(x)[1], axis=1) for x in points])   # (points, 2)
    for row in range(2):
        if not names or not np.all(np.isfinite(values[:, row])):
            continue                    # one seat only, or an unstable seat found already
        for i in np.argsort(-values[:, row], kind="stable")[:starts]:
            scale = values[i, row] if values[i, row] > 0 else 1.0

            def objective(x, row=row, scale=scale):
                v = float(np.max(figures(x)[1][row]))
                # the figures are a max over delays and time, piecewise smooth: the
                # climb has only to improve on its start, which stays in the record
                return -v / scale if math.isfinite(v) else _UNSTABLE_PENALTY

            minimize(objective, points[int(i)], method="L-BFGS-B",
                     bounds=[(0.0, 1.0)] * len(names),
                     options=dict(maxfun=_CLIMB_EVALUATIONS, eps=_CLIMB_STEP))
    # every seat met counts, the other figure's climbs' and the unstable ones included
    keys = list(met)
    worst = np.array([np.max(met[k], axis=1) for k in keys])
    found = []
    for row, figure in enumerate(_FIGURES):
        key = keys[int(np.argmax(worst[:, row]))]
        table, p = met[key][row], seat(key)
        if np.isinf(table).any():
            j = int(np.argmax(np.isinf(table)))          # the first unstable delay
            found.append(WorstSeat(figure=figure, value=math.inf, seat=p, delay=delays[j],
                                   evaluations=len(met)))
            continue
        j = int(np.argmax(table))
        m = simulate(K, road, delay=delays[j], params=p, u_max=np.inf).metrics()
        value = float(m.peak_u_command if figure == "u" else m.peak_x1)
        if abs(value - table[j]) > _AGREEMENT * max(abs(value), abs(table[j])):
            logger.warning("worst_bump_seats: %s by time stepping %.6g, in the frequency "
                           "domain %.6g at %s: the value is the time stepping's", figure,
                           value, table[j], p)
        found.append(WorstSeat(figure=figure, value=value, seat=p, delay=delays[j],
                               evaluations=len(met), frequency_value=float(table[j])))
    u, x1 = found
    logger.info("worst_bump_seats: %d seats met; |u| %.6g, |x1| %.6g", len(met), u.value,
                x1.value)
    return u, x1
