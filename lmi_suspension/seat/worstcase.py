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
(L-BFGS-B, finite differences, inside the box) and confirms the worst seat by an
exact-delay time simulation.  What it returns is a *lower bound* on the set's worst
figure, attained at a seat it names: a search, not a proof; a figure above a bound is a
certified violation.  A seat where the loop is unstable at one of the delays is a
finding as well (value ``inf``).

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
#: within 24 evaluations (2026-11-28); the bound keeps a climb on a rough surface finite
_CLIMB_EVALUATIONS = 80
#: finite-difference step of a climb in the box's unit coordinates (a 1e-4 step moves a
#: 40 kg mass range by 4 g: the figures' FFT noise is far below the change)
_CLIMB_STEP = 1e-4


@dataclass(frozen=True)
class WorstSeat:
    """The worst seat found for one road figure (:func:`worst_bump_seats`).

    Attributes
    ----------
    figure : str
        ``"u"``: commanded force ``|u|`` (N, unclipped); ``"x1"``: stroke ``|x1|`` (m).
    value : float
        The figure at ``seat`` and ``delay``: the larger of the frequency-domain value
        and the time simulation's; ``inf`` where the loop is unstable at a delay.
    seat : SeatParameters
    delay : float
        The delay it is attained at, s.
    evaluations : int
        Seats met by the search (shared by both figures).
    """

    figure: str
    value: float
    seat: SeatParameters
    delay: float
    evaluations: int

    @property
    def where(self) -> str:
        """The seat's uncertain parameters and the delay, in words."""
        s = self.seat
        return (f"m3 {s.m3:.1f} kg, k1 {s.k1:.0f}, k2 {s.k2:.0f}, k3 {s.k3:.0f} N/m, "
                f"c1 {s.c1:.0f}, c2 {s.c2:.0f}, c3 {s.c3:.0f} N s/m, "
                f"{self.delay * 1e3:.0f} ms")

    def describe(self) -> str:
        """One line: the value and where it is attained."""
        if self.value == math.inf:
            return f"unstable at {self.where}"
        return f"{self.value:.4g} {'N' if self.figure == 'u' else 'm'} at {self.where}"


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

    from .refine import REFINE_DELAYS, BumpResponse, loop_poles
    from .simulate import closed_loop_stable, simulate

    if not isinstance(K, control.StateSpace) or K.isdtime(strict=True) \
            or K.ninputs != 2 or K.noutputs != 1:
        raise ParameterError("K must be a continuous-time StateSpace from y = [x1, x3] to u")
    occupants = OccupantSet() if occupants is None else occupants
    if not isinstance(occupants, OccupantSet):
        raise ParameterError(f"occupants must be an OccupantSet, got "
                             f"{type(occupants).__name__}")
    if not isinstance(rng, np.random.Generator):
        raise ParameterError("rng must be a numpy.random.Generator (seeded by the caller)")
    for name, v, least in (("n", n, 0), ("starts", starts, 0)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < least:
            raise ParameterError(f"{name} must be an int >= {least}, got {v!r}")
    delays = tuple(float(d) for d in (REFINE_DELAYS if delays is None else delays))
    if not delays or any(not math.isfinite(d) or d < 0 for d in delays):
        raise ParameterError(f"delays must be finite and non-negative, got {delays!r}")
    road = bump() if road is None else road
    if not isinstance(road, RoadInput):
        raise ParameterError(f"road must be a RoadInput, got {type(road).__name__}")

    ranges = [r for r in occupants.ranges() if r[2] > r[1]]
    names = [r[0] for r in ranges]
    lo = np.array([r[1] for r in ranges])
    hi = np.array([r[2] for r in ranges])

    def seat(x) -> SeatParameters:
        return occupants.at(dict(zip(names, lo + np.clip(x, 0.0, 1.0) * (hi - lo))))

    met: dict = {}

    def figures(x) -> np.ndarray:
        """``[[|u| per delay], [|x1| per delay]]`` at the seat, inf where unstable."""
        key = tuple(np.round(np.clip(x, 0.0, 1.0), 12))
        if key not in met:
            p = seat(key)
            if np.max(loop_poles(K, p).real) >= 0 \
                    or not all(closed_loop_stable(K, d, p) for d in delays):
                met[key] = np.full((2, len(delays)), np.inf)
            else:
                _, u, x1 = BumpResponse(road=road, delays=delays, params=p).peaks(K)
                met[key] = np.vstack([u, x1])
        return met[key]

    points = [np.array(c, dtype=float) for c in product((0.0, 1.0), repeat=len(names))]
    if n:
        samples, _ = occupants.sample(int(n), rng)
        points += [(np.array([getattr(p, k) for k in names]) - lo) / (hi - lo)
                   for p in samples]
    values = np.array([np.max(figures(x), axis=1) for x in points])   # (points, 2)
    found = []
    for row, figure in enumerate(("u", "x1")):
        order = np.argsort(-values[:, row], kind="stable")
        best = points[int(order[0])]
        if names and np.isfinite(values[order[0], row]):
            for i in order[:starts]:
                if not np.isfinite(values[i, row]):
                    continue
                # the figure is a max over delays and time: piecewise smooth, and the
                # climb only has to improve on its start (the start is kept otherwise)
                r = minimize(lambda x: -float(np.max(figures(x)[row])), points[int(i)],
                             method="L-BFGS-B", bounds=[(0.0, 1.0)] * len(names),
                             options=dict(maxfun=_CLIMB_EVALUATIONS, eps=_CLIMB_STEP))
                if np.max(figures(r.x)[row]) > np.max(figures(best)[row]):
                    best = np.clip(r.x, 0.0, 1.0)
        table = figures(best)[row]
        j = int(np.argmax(table))
        value = float(table[j])
        p = seat(best)
        if np.isfinite(value):
            # the frequency-domain figure confirmed by time stepping (exact delay, no clip)
            m = simulate(K, road, delay=delays[j], params=p, u_max=np.inf).metrics()
            value = max(value, float(m.peak_u_command if figure == "u" else m.peak_x1))
        found.append((figure, value, p, delays[j]))
    u, x1 = (WorstSeat(figure=f, value=v, seat=p, delay=d, evaluations=len(met))
             for f, v, p, d in found)
    logger.info("worst_bump_seats: %d seats met; |u| %.4g, |x1| %.4g", len(met), u.value,
                x1.value)
    return u, x1
