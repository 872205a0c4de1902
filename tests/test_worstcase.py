"""The worst seats of a set by search (issue 38): what the search returns is checked by
routes it does not take: the exact-delay time simulation at the seat it names, the
delay-free loop's poles, every corner and a dense line scan met here, and samples of
the set, which it must beat.

The controller is the multi-seat design shipped on 2026-11-27 (kept as
``tests/data/multiseat_v2.json``): on 200 Latin-hypercube samples it asks 1559 N at
most (the note of issue 38), at the set's corner 30 kg, springs stiff, 1777 N."""

import json
from dataclasses import replace
from itertools import product
from pathlib import Path

import control
import numpy as np
import pytest

from lmi_suspension.errors import ParameterError
from lmi_suspension.seat.loop import BumpResponse, loop_poles
from lmi_suspension.seat.occupants import OccupantSet
from lmi_suspension.seat.params import SeatParameters
from lmi_suspension.seat.refine import load_refined
from lmi_suspension.seat.roads import bump
from lmi_suspension.seat.simulate import simulate
from lmi_suspension.seat.worstcase import WorstSeat, worst_bump_seats

V2 = Path(__file__).parent / "data" / "multiseat_v2.json"


@pytest.fixture(scope="module")
def K():
    return load_refined(V2)[0]


@pytest.fixture(scope="module")
def found(K):
    return worst_bump_seats(K, rng=np.random.default_rng(3), n=50)


def _figures(K, seat):
    _, u, x1 = BumpResponse(params=seat).peaks(K)
    return float(np.max(u)), float(np.max(x1))


def test_force_at_the_worst_corner_beats_every_sample(K, found):
    """The force the search reports is the time simulation's at its seat (exact delay,
    unclipped), and the closed-form figure it ranked the seats by agrees with it to 1 %
    (0.1-0.5 % measured); it is at least every corner's (all 128 met here) and above
    every one of 200 fresh samples', the certificate that samples alone gave before."""
    u, _ = found
    assert u.figure == "u" and u.evaluations >= 128 + 50
    m = simulate(K, bump(), delay=u.delay, params=u.seat, u_max=np.inf).metrics()
    assert u.value == m.peak_u_command
    assert u.frequency_value == pytest.approx(u.value, rel=0.01)
    occ = OccupantSet()
    ranges = occ.ranges()
    corners = [occ.at({r[0]: r[1 + b] for r, b in zip(ranges, c)})
               for c in product((0, 1), repeat=7)]
    assert u.frequency_value >= max(_figures(K, p)[0] for p in corners)
    seats, _ = occ.sample(200, np.random.default_rng(2026))
    sampled = max(_figures(K, p)[0] for p in seats)
    assert u.value > 1.05 * sampled          # 1777 N against 1559 N on 2026-11-28


def test_climb_finds_the_stroke_between_corners(K, found):
    """The stroke peaks inside the box (k1 between its ends): the search's value is
    above every corner's and at least the largest of a 41-point scan of k1 through its
    seat, the other parameters held."""
    _, x1 = found
    occ = OccupantSet()
    ranges = occ.ranges()
    corners = [occ.at({r[0]: r[1 + b] for r, b in zip(ranges, c)})
               for c in product((0, 1), repeat=7)]
    best_corner = max(_figures(K, p)[1] for p in corners)
    assert x1.frequency_value > best_corner   # 0.06983 m against 0.06965 m
    lo, hi = ranges[1][1:]
    scan = [_figures(K, replace(x1.seat, k1=float(k)))[1]
            for k in np.linspace(lo, hi, 41)]
    # where a climb on a kinked surface stops depends on roundoff: 1e-3 is ten times the
    # largest difference between scan neighbours near the peak (measured 2026-11-28)
    assert x1.frequency_value >= max(scan) * (1 - 1e-3)
    assert lo < x1.seat.k1 < hi


def test_a_seat_where_the_loop_is_unstable_is_found():
    """A negative spring of 28 kN/m: stable at the nominal seat (k1 = 31 kN/m), unstable
    once k1 is below it.  The search reports inf at a seat whose delay-free loop has a
    pole in the right half-plane."""
    soft = control.ss([], [], [], [[-28000.0, 0.0]])
    assert np.max(loop_poles(soft, SeatParameters()).real) < 0
    u, x1 = worst_bump_seats(soft, rng=np.random.default_rng(0), n=0, starts=1)
    assert u.value == np.inf and x1.value == np.inf
    assert np.max(loop_poles(soft, u.seat).real) > 0 and u.seat.k1 < 28000.0
    assert u.describe().startswith("unstable at m3")


def test_an_instability_at_the_longer_delays_names_the_first_unstable_delay():
    """A stiff static gain (60 kN/m on x1): the nominal loop is stable up to 28 ms, a
    seat with soft c1 only up to 20 ms (the delay margin, computed here by its own
    routine).  The search reports inf at the first delay where its seat's loop is
    unstable, the one before it stable."""
    from lmi_suspension.seat.loop import REFINE_DELAYS
    from lmi_suspension.seat.simulate import closed_loop_stable, stability_delay_margin

    stiff = control.ss([], [], [], [[60000.0, 0.0]])
    assert stability_delay_margin(stiff) > REFINE_DELAYS[-1]
    u, x1 = worst_bump_seats(stiff, rng=np.random.default_rng(0), n=0, starts=1)
    assert u.value == x1.value == np.inf and np.isnan(u.frequency_value)
    k = REFINE_DELAYS.index(u.delay)
    assert k > 0 and not closed_loop_stable(stiff, u.delay, u.seat)
    assert closed_loop_stable(stiff, REFINE_DELAYS[k - 1], u.seat)
    assert REFINE_DELAYS[k - 1] < stability_delay_margin(stiff, u.seat) <= u.delay


def test_a_fixed_mass_is_the_searched_mass():
    heavy = OccupantSet(m3=(70.0, 70.0), damping_rel=0.0)
    u, x1 = worst_bump_seats(control.ss([], [], [], [[0.0, 0.0]]), heavy,
                             rng=np.random.default_rng(0), n=0, starts=0, delays=0.0)
    assert u.seat.m3 == x1.seat.m3 == 70.0 and u.evaluations == 8   # k1..k3 corners


def test_the_passive_seat_commands_nothing_and_a_fixed_set_is_one_seat():
    passive = control.ss([], [], [], [[0.0, 0.0]])
    fixed = OccupantSet(m3=(43.3, 43.3), stiffness_rel=0.0, damping_rel=0.0)
    u, x1 = worst_bump_seats(passive, fixed, rng=np.random.default_rng(0), n=2)
    assert u.value == 0.0 and u.seat == fixed.nominal
    m = simulate(passive, bump(), delay=x1.delay, params=fixed.nominal).metrics()
    assert x1.value == pytest.approx(m.peak_x1, rel=1e-3)


@pytest.mark.parametrize("kwargs", [dict(rng=0), dict(n=-1), dict(starts=1.5),
                                    dict(delays=(np.nan,)), dict(delays=()),
                                    dict(occupants="set"), dict(road="bump"), dict(K="K"),
                                    dict(K=control.ss([], [], [], [[np.nan, 0.0]]))])
def test_bad_input_raises(kwargs):
    args = dict(K=control.ss([], [], [], [[0.0, 0.0]]), rng=np.random.default_rng(0))
    args.update(kwargs)
    with pytest.raises(ParameterError):
        worst_bump_seats(args.pop("K"), **args)


def test_a_discrete_controller_is_refused():
    with pytest.raises(ParameterError, match="continuous"):
        worst_bump_seats(control.ss([], [], [], [[0.0, 0.0]], 1e-3),
                         rng=np.random.default_rng(0))


def test_worst_seat_describes_where_and_knows_its_figures():
    w = WorstSeat(figure="u", value=1500.4, seat=SeatParameters(), delay=0.025,
                  evaluations=1)
    assert w.describe().startswith("1500.4 N at m3 43.3 kg") and w.describe().endswith("25 ms")
    d = w.as_dict()
    assert d["value"] == 1500.4 and d["label"] == "commanded |u|" and d["text"] == w.describe()
    assert d["seat"]["m3"] == 43.3 and d["frequency_value"] is None
    assert json.loads(json.dumps(d, allow_nan=False)) == d
    gone = WorstSeat(figure="x1", value=np.inf, seat=SeatParameters(), delay=0.0,
                     evaluations=1).as_dict()
    assert gone["value"] is None and gone["label"] == "|x1|"
    assert gone["text"].startswith("unstable at")
    with pytest.raises(ParameterError, match="figure"):
        WorstSeat(figure="z", value=1.0, seat=SeatParameters(), delay=0.0, evaluations=1)


# ---------------------------------------------------------------- mutation pass (issue 59)
def test_the_climb_reaches_an_interior_maximum_of_constructed_figures(monkeypatch):
    """The climbs must go uphill from the worst seats.  Constructed figures (the road
    figures, the loop's poles, the stability check and the time simulation injected):
    the force is 1000 - 500 (t - 0.6)² N, t the unit coordinate of k1 in its range, so
    its maximum, 1000 N at t = 0.6, lies inside the box, where no corner (920 N at most)
    nor a corner's finite-difference probe comes near it; the stroke is largest at the corner
    m3 = 70 kg (0.06 m).  Reference: these closed forms; the climb met the force's peak
    to 9e-10 and its k1 to 2e-5 (measured 2026-12-01, Haswell and Sandybridge kernels),
    1e-6 and 1e-3 allowed."""
    import importlib
    from types import SimpleNamespace

    loop = importlib.import_module("lmi_suspension.seat.loop")
    simulation = importlib.import_module("lmi_suspension.seat.simulate")
    occ = OccupantSet()
    _, lo, hi = occ.ranges()[1]
    assert occ.ranges()[1][0] == "k1"

    def force(p):
        return 1000.0 - 500.0 * ((p.k1 - lo) / (hi - lo) - 0.6) ** 2

    def stroke(p):
        return 0.05 + 0.01 * (p.m3 - 30.0) / 40.0

    class Response:
        def __init__(self, road, delays, params):
            self.p, self.n = params, len(delays)

        def peaks(self, K):
            return (np.zeros(self.n), np.full(self.n, force(self.p)),
                    np.full(self.n, stroke(self.p)))

    def simulate(K, road, *, delay, params, u_max):
        figures = SimpleNamespace(peak_u_command=force(params), peak_x1=stroke(params))
        return SimpleNamespace(metrics=lambda: figures)

    monkeypatch.setattr(loop, "BumpResponse", Response)
    monkeypatch.setattr(loop, "loop_poles", lambda K, p: np.array([-1.0]))
    monkeypatch.setattr(simulation, "closed_loop_stable", lambda K, d, p: True)
    monkeypatch.setattr(simulation, "simulate", simulate)
    u, x1 = worst_bump_seats(control.ss([], [], [], [[0.0, 0.0]]), occ,
                             rng=np.random.default_rng(0), n=0, starts=1, delays=0.0)
    assert u.value == pytest.approx(1000.0, rel=1e-6) and u.frequency_value == u.value
    assert u.seat.k1 == pytest.approx(lo + 0.6 * (hi - lo), rel=1e-3)
    assert x1.value == pytest.approx(0.06, rel=1e-12) and x1.seat.m3 == 70.0
