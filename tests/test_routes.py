"""One entry for the seat's designs: routes, SeatDesign, certify_seat, the files.

The routes' algorithms have their own tests (test_design, test_constrained_seat,
test_refine, test_multimodel, test_bounded); here: that every route runs through the one
entry alike, that the certificate recomputes the figures by its own computations, that
a design round-trips through its file exactly, and that bad input is refused.
"""

import dataclasses
import math

import control
import numpy as np
import pytest

from lmi_suspension.errors import InputError, ParameterError
from lmi_suspension.io import load_controller, save_controller
from lmi_suspension.seat import (SeatParameters, bump, bump_limit, closed_loop_stable,
                                 seat_matrices, simulate)
from lmi_suspension.seat.bounded import PeakBoundedRoute, design_peak_bounded
from lmi_suspension.seat.augmented import CONSTRAINED_DESIGN, DEFAULT_DESIGN
from lmi_suspension.seat.constrained import ConstrainedRoute
from lmi_suspension.seat.design import MuRoute
from lmi_suspension.seat.multimodel import OccupantRoute
from lmi_suspension.seat.occupants import OccupantSet, occupant_samples
from lmi_suspension.seat.loop import _LIMIT_DT, REFINE_DELAYS
from lmi_suspension.seat.refine import RefineRoute, certify_refined
from lmi_suspension.seat.discrete_design import DiscreteMuRoute
from lmi_suspension.seat.record import (SeatCertificate, SeatDesign, SeatRequirements,
                                        certify_seat, seat_design_from)
from lmi_suspension.seat.routes import (ROUTE_NAMES, SHIPPED_DESIGNS, SeatRoute, design_seat,
                                        load_seat_design, route_named, save_seat_design)
from lmi_suspension.seat.sampled import discretise_controller
from lmi_suspension.seat.worstcase import worst_bump_seats

PASSIVE = control.ss([], [], [], [[0.0, 0.0]])


@pytest.fixture(scope="module")
def peak_bounded():
    """The fast route (an LMI, a few seconds) through the one entry."""
    return design_seat("peak_bounded", rng=np.random.default_rng(0))


def test_every_route_name_gives_its_route():
    for name in ROUTE_NAMES:
        route = route_named(name)
        assert isinstance(route, SeatRoute) and route.name == name
    assert {type(route_named(n)) for n in ROUTE_NAMES} == {
        MuRoute, ConstrainedRoute, RefineRoute, OccupantRoute, PeakBoundedRoute,
        DiscreteMuRoute}


def test_a_route_design_is_the_routes_own_controller_named_and_discretised(peak_bounded):
    d = peak_bounded
    assert isinstance(d, SeatDesign) and d.route == "peak_bounded"
    assert d.K.input_labels == ["x1", "x3"] and d.K.output_labels == ["u"]
    # the route's own function, called directly, gives the same controller
    direct = design_peak_bounded(1500.0, 0.08)
    for a, b in zip((d.K.A, d.K.B, d.K.C, d.K.D), (direct.K.A, direct.K.B, direct.K.C,
                                                   direct.K.D)):
        np.testing.assert_allclose(a, b, rtol=1e-6, atol=1e-9 * np.max(np.abs(b)))
    Kd = discretise_controller(d.K)
    assert d.Kd.dt == 1e-3 and np.array_equal(d.Kd.A, Kd.A) and np.array_equal(d.Kd.B, Kd.B)
    assert d.figures["u_peak"] == pytest.approx(direct.u_peak, rel=1e-6)
    assert d.weights == DEFAULT_DESIGN and isinstance(d.detail, type(direct))


def test_the_certificate_bounds_the_bump_by_the_routes_own_guarantee(peak_bounded):
    """The route guarantees |u| <= u_peak and |x1| <= x1_peak for every floor velocity of
    the bump's energy (its Gramian); the certificate's time simulation of the bump itself
    (no delay, the loop the route designed for) must stay below both."""
    c = peak_bounded.certify(delays=(0.0,))
    assert isinstance(c, SeatCertificate)
    assert c.u_peak[0] <= peak_bounded.figures["u_peak"] * (1 + 1e-9)
    assert c.x1_peak[0] <= peak_bounded.figures["x1_peak"] * (1 + 1e-9)
    # the certificate's own figures, recomputed here by the simulator and the LP
    m = simulate(peak_bounded.K, bump(), delay=0.0, u_max=np.inf).metrics()
    assert c.peak[0] == m.peak_z3dd and c.u_peak[0] == m.peak_u_command
    assert c.limit == pytest.approx(bump_limit(bump(), dt=_LIMIT_DT).certified_peak,
                                    rel=1e-12)
    assert c.nominal_ratio == pytest.approx(m.peak_z3dd / c.limit, rel=1e-12)
    # µ bounds of a certificate: lower <= upper, and poles counted on the loop
    assert c.mu.mu_lower_peak <= c.mu.mu_upper.max() * (1 + 1e-6)
    assert c.mu.controller_fastest_pole == pytest.approx(
        np.max(np.abs(np.linalg.eigvals(peak_bounded.K.A))), rel=1e-9)


@pytest.mark.slow  # 18 s on Zen 1 (2026-12-02): the second tier
def test_the_mu_route_through_the_entry_is_the_paper_design():
    """The µ route (seconds) through design_seat: the controller of design_mu_controller
    called directly with the same seed, bit for bit, and its figures."""
    from lmi_suspension.seat.design import design_mu_controller

    lines = []
    d = design_seat("mu", rng=np.random.default_rng(3), progress=lines.append)
    direct = design_mu_controller(rng=np.random.default_rng(3))
    assert all(np.array_equal(getattr(d.K, m), getattr(direct.K, m)) for m in "ABCD")
    assert d.figures["mu_peak_upper"] == direct.mu_peak and d.weights == DEFAULT_DESIGN
    assert len(lines) == len(direct.musyn.history) and lines[0].startswith("D-K iteration 1:")


def test_a_nan_figure_is_a_failure_not_a_pass():
    """``max`` drops a nan that does not come first; the judgement must not."""
    base = certify_seat(PASSIVE, delays=(0.0, 0.025))
    nan = math.nan
    for field, value in (("u_peak", (0.0, nan)), ("x1_peak", (0.03, nan)),
                         ("peak", (base.peak[0], nan)),
                         ("sampled_peak", (base.sampled_peak[0], nan))):
        bad = dataclasses.replace(base, **{field: value},
                                  requirements=SeatRequirements(nominal_ratio=100.0))
        assert bad.failures(), field
    bad = dataclasses.replace(base, loop_radius=nan)
    assert any(f.startswith("poles") for f in bad.failures())
    # the boundaries: |u| at the bound passes, a pole at the radius does not
    edge = dataclasses.replace(base, u_peak=(1500.0, 0.0), loop_radius=1900.0,
                               requirements=SeatRequirements(nominal_ratio=100.0))
    assert [f.split(":")[0] for f in edge.failures()] == ["poles"]


def test_the_searched_worst_seats_are_judged():
    """The set's searched force and stroke: at the bound passes, above it fails with the
    seat named, an unstable seat fails, a nan fails."""
    from lmi_suspension.seat.worstcase import WorstSeat

    base = dataclasses.replace(certify_seat(PASSIVE, delays=()), loop_radius=0.0)
    assert base.worst_seats == () and base.met

    def judged(u, x1):
        seats = tuple(WorstSeat(figure=f, value=v, seat=SeatParameters(m3=30.0),
                                delay=0.0, evaluations=1)
                      for f, v in (("u", u), ("x1", x1)))
        return dataclasses.replace(base, worst_seats=seats).failures()

    assert judged(1500.0, 0.08) == ()
    assert judged(1501.0, 0.08) == ("set, searched: commanded |u| 1501.0 N at m3 30.0 kg, "
                                    "k1 31000, k2 18000, k3 44130 N/m, c1 830, c2 200, "
                                    "c3 1485 N s/m, 0 ms, above 1500",)
    assert [f[:22] for f in judged(1500.0, 0.0801)] == ["set, searched: |x1| 0."]
    unstable = judged(math.inf, math.inf)       # the same seat for both figures: one line
    assert len(unstable) == 1 and unstable[0].startswith("set, searched: the loop is "
                                                         "unstable at m3 30.0 kg")
    assert judged(math.nan, 0.0)[0].startswith("set, searched: commanded |u| nan N")
    assert judged(1500.0, 0.0801) == ("set, searched: |x1| 0.08010 m at m3 30.0 kg, k1 "
                                      "31000, k2 18000, k3 44130 N/m, c1 830, c2 200, "
                                      "c3 1485 N s/m, 0 ms, above 0.08",)


def test_the_sets_mixed_mu_is_judged_against_one():
    """The set's mixed µ (constructed, no design run): ``rs_sup < 1`` certifies robust
    stability over the set (MixedMuCheck), so just below 1 passes, 1 itself and above
    fail, and a nan fails; the performance figure is not judged (rp_sup 5 passes)."""
    from types import SimpleNamespace

    from lmi_suspension.seat.occupants import MixedMuCheck

    # a certificate that meets everything else: no delays (the bump not judged), a
    # delay margin above 25 ms, no pole
    base = SeatCertificate(delays=(), peak=(), u_peak=(), x1_peak=(), sampled_peak=(),
                           mu=SimpleNamespace(controller_fastest_pole=0.0),
                           delay_margin=math.inf, loop_radius=0.0)
    assert base.mixed_mu is None and base.met

    def judged(rs_sup):
        check = MixedMuCheck(block_names=("m3", "delay", "performance"), rs_upper=rs_sup,
                             rs_lower=0.5, rp_upper=5.0, rp_lower=4.0, rs_omega=10.0,
                             rp_omega=10.0, omega=np.array([1.0, 10.0]), rs_sup=rs_sup,
                             rp_sup=5.0)
        return dataclasses.replace(base, mixed_mu=check).failures()

    assert judged(0.999) == () and judged(0.5) == ()
    assert judged(1.0) == ("set: robust-stability mixed µ 1.0000, not below 1",)
    assert judged(1.01) == ("set: robust-stability mixed µ 1.0100, not below 1",)
    assert judged(math.nan) == ("set: robust-stability mixed µ nan, not below 1",)


def test_the_passive_seat_is_judged_against_the_requirements():
    """The passive seat: no force, its bump peak 4.3 × the limit (the limit is a lower
    bound for every force history, the passive one's included)."""
    c = certify_seat(PASSIVE, delays=(0.0, 0.025))
    assert c.u_peak == (0.0, 0.0) and math.isinf(c.delay_margin)
    # no controller: the loop's poles are the seat's own (Table 1's model)
    assert c.loop_radius == pytest.approx(
        np.max(np.abs(np.linalg.eigvals(seat_matrices().A))), rel=1e-9)
    assert 1.0 <= c.nominal_ratio
    failures = c.failures()
    assert len(failures) == 1 and "own limit" in failures[0] and not c.met
    # the same figures, judged against looser requirements: met
    loose = certify_seat(PASSIVE, delays=(0.0, 0.025),
                         requirements=SeatRequirements(nominal_ratio=c.nominal_ratio * 1.01))
    assert loose.met and loose.peak == c.peak
    # without delays, the bump is not judged (and no limit is computed)
    bare = certify_seat(PASSIVE, delays=())
    assert bare.delays == () and math.isnan(bare.limit) and bare.met
    # a negative spring softer than k1 (31 kN/m) removed: unstable without delay, which
    # the certificate says whatever else it measures
    soft = control.ss([], [], [], [[-40000.0, 0.0]])
    assert not closed_loop_stable(soft, 0.0)
    unstable = certify_seat(soft, delays=())
    assert unstable.delay_margin == 0.0 and math.isinf(unstable.mu.u_peak)
    assert any(f.startswith("delay margin") for f in unstable.failures())


@pytest.mark.slow  # 16 s on Zen 1 (2026-12-02): the second tier
def test_certify_refined_is_the_one_certificate_with_the_refinements_delays():
    K = control.ss([[-200.0]], [[200.0, 0.0]], [[15000.0]], [[0.0, 2000.0]])
    a = certify_refined(K, rng=np.random.default_rng(0))
    b = certify_seat(K, delays=REFINE_DELAYS, rng=np.random.default_rng(0))
    assert isinstance(a, SeatCertificate) and a.delays == REFINE_DELAYS
    assert a.peak == b.peak and a.sampled_peak == b.sampled_peak
    assert a.mu.mu_peak == b.mu.mu_peak


def test_a_design_round_trips_through_its_file_exactly(peak_bounded, tmp_path):
    path = save_seat_design(tmp_path / "d.json", peak_bounded)
    e = load_seat_design(path)
    for name in ("A", "B", "C", "D"):
        assert np.array_equal(getattr(e.K, name), getattr(peak_bounded.K, name))
        assert np.array_equal(getattr(e.Kd, name), getattr(peak_bounded.Kd, name))
    assert e.Kd.dt == peak_bounded.Kd.dt
    # every field but the route's in-memory result
    for f in dataclasses.fields(SeatDesign):
        if f.name not in ("K", "Kd", "detail"):
            assert getattr(e, f.name) == getattr(peak_bounded, f.name), f.name
    # a seat and weights that are not the defaults survive too
    other = dataclasses.replace(peak_bounded, params=SeatParameters(m3=61.5),
                                weights=CONSTRAINED_DESIGN)
    e2 = load_seat_design(save_seat_design(tmp_path / "o.json", other))
    assert e2.params == other.params and e2.weights == CONSTRAINED_DESIGN


def test_shipped_designs_load_by_name_with_their_weights():
    for name, path in SHIPPED_DESIGNS.items():
        d = load_seat_design(name)
        K, meta = load_controller(path)
        assert d.route == name and np.array_equal(d.K.A, K.A) and d.Kd.dt == 1e-3
        assert d.description == meta["description"]
        assert d.weights == (CONSTRAINED_DESIGN if name == "constrained" else DEFAULT_DESIGN)


def test_a_file_without_a_route_needs_one(tmp_path, peak_bounded):
    path = save_controller(tmp_path / "k.json", peak_bounded.K, discrete=peak_bounded.Kd)
    with pytest.raises(InputError, match="route"):
        load_seat_design(path)
    assert load_seat_design(path, route="peak_bounded").route == "peak_bounded"
    bare = save_controller(tmp_path / "c.json", peak_bounded.K)
    with pytest.raises(InputError, match="discrete"):
        load_seat_design(bare, route="peak_bounded")
    # a file's own route is not overridden, and a route without a shipped design says so
    saved = save_seat_design(tmp_path / "d.json", peak_bounded)
    with pytest.raises(InputError, match="not 'refined'"):
        load_seat_design(saved, route="refined")
    with pytest.raises(InputError, match="no shipped design"):
        load_seat_design("mu")


@dataclasses.dataclass(frozen=True)
class _StaticRoute:
    """A user's route in a few lines: a static gain on the seat deflection."""

    name = "static"
    gain: float = 2000.0

    def design(self, params, *, rng, progress=None):
        if progress is not None:
            progress("static gain")
        K = control.ss([], [], [], [[self.gain, 0.0]])
        return seat_design_from(self.name, K, params=params, weights=None,
                                figures={"gain": self.gain}, description="static gain",
                                seconds=0.0)


def test_a_users_route_is_one_class_passed_to_the_entry(tmp_path):
    lines = []
    d = design_seat(_StaticRoute(), params=SeatParameters(m3=50.0), progress=lines.append)
    assert d.route == "static" and lines == ["static gain"]
    assert d.params.m3 == 50.0 and d.K.D[0, 0] == 2000.0
    e = load_seat_design(save_seat_design(tmp_path / "s.json", d))
    assert e.route == "static" and e.figures == {"gain": 2000.0}


def test_bad_input_is_refused_with_typed_errors():
    with pytest.raises(ParameterError, match="unknown seat design route"):
        design_seat("nope")
    with pytest.raises(ParameterError, match="SeatRoute"):
        design_seat(object())
    with pytest.raises(ParameterError, match="params"):
        design_seat(_StaticRoute(), params={"m3": 50.0})
    with pytest.raises(ParameterError, match="rng"):
        design_seat(_StaticRoute(), rng=42)

    @dataclasses.dataclass(frozen=True)
    class Liar:
        name = "liar"

        def design(self, params, *, rng, progress=None):   # another route's design
            return _StaticRoute().design(params, rng=rng)

    with pytest.raises(ParameterError, match="not its own"):
        design_seat(Liar())
    with pytest.raises(ParameterError, match="continuous"):
        certify_seat(discretise_controller(control.ss([[-1.0]], [[1.0, 0.0]], [[1.0]],
                                                      [[0.0, 0.0]])))
    with pytest.raises(ParameterError, match="2 inputs"):
        certify_seat(control.ss([], [], [], [[1.0]]))
    with pytest.raises(ParameterError, match="occupants"):
        certify_seat(PASSIVE, delays=(), mixed_mu=True)
    for bad in (-1.0, True, math.nan):
        with pytest.raises(ParameterError, match="u_max"):
            SeatRequirements(u_max=bad)
    with pytest.raises(ParameterError, match="SeatDesign"):
        save_seat_design("x.json", object())
    with pytest.raises(ParameterError, match="nominal"):
        OccupantRoute(occupants=OccupantSet()).design(SeatParameters(m3=50.0),
                                                      rng=np.random.default_rng(0))


@pytest.mark.slow  # 60 s on Zen 1 (2026-12-02): the second tier
def test_the_set_is_certified_and_judged_when_samples_are_given(peak_bounded):
    """A few samples of the set (the occupant figures have their own tests): the
    certificate carries them and judges the set's worst ratio and force."""
    S = occupant_samples(rng=np.random.default_rng(1), n_stability=20, n_performance=2)
    c = peak_bounded.certify(delays=(0.0,), occupants=S)
    o = c.occupants
    assert o is not None and o.n_stability == 20 and o.ratio.shape[0] == 2
    failures = c.failures()
    assert any(f.startswith("set: worst peak / own limit") for f in failures) == (
        o.worst_ratio > c.requirements.worst_ratio)
    assert c.mixed_mu is None
    # the search over the set's corners, on the third stream spawned from the default
    # generator (the first two are the µ lower bounds'), judged like the samples
    u, x1 = c.worst_seats
    assert (u.figure, x1.figure) == ("u", "x1")
    again = worst_bump_seats(peak_bounded.K, S.occupants,
                             rng=np.random.default_rng(0).spawn(3)[2])
    assert (u.value, u.seat, x1.value) == (again[0].value, again[0].seat, again[1].value)
    r = c.requirements
    assert sum(f.startswith("set, searched:") for f in failures) == (
        (not u.value <= r.u_max) + (not x1.value <= r.z_max))


# ---------------------------------------------------------------- mutation pass (issue 59)
def test_the_requirement_edges_are_judged_as_stated():
    """SeatRequirements' docstring at its edges (constructed certificates, no design
    run): the delay margin must lie above ``delay_max`` (equal fails); every pole of the
    controller or the loop below ``pole_radius`` (the controller's alone at it fails);
    the 1 kHz loop's peak within ``sampled_tolerance`` of the continuous one's, either
    side (5 % below fails); the set's fastest loop pole below ``pole_radius`` too."""
    from types import SimpleNamespace

    r = SeatRequirements(nominal_ratio=100.0)
    base = SeatCertificate(delays=(0.0,), peak=(10.0,), u_peak=(0.0,), x1_peak=(0.0,),
                           sampled_peak=(10.0,),
                           mu=SimpleNamespace(controller_fastest_pole=0.0),
                           delay_margin=math.inf, loop_radius=0.0, limit=5.0,
                           requirements=r)
    assert base.failures() == ()

    def failed(**changes):
        """The requirements the changed certificate fails, by their lines' openings."""
        return [f.split(":")[0] if ":" in f else " ".join(f.split()[:2])
                for f in dataclasses.replace(base, **changes).failures()]

    assert failed(delay_margin=r.delay_max * (1 + 1e-9)) == []
    assert failed(delay_margin=r.delay_max) == ["delay margin"]
    assert failed(mu=SimpleNamespace(controller_fastest_pole=r.pole_radius)) == ["poles"]
    assert failed(sampled_peak=(10.0 * (1 - 0.99 * r.sampled_tolerance),)) == []
    assert failed(sampled_peak=(9.5,)) == ["1 kHz loop's peak against the continuous one"]
    occupants = SimpleNamespace(unstable=0, n_stability=10, worst_ratio=1.0,
                                nominal_ratio=1.0, u_max=0.0, x1_max=0.0,
                                loop_radius=r.pole_radius * (1 - 1e-9))
    assert failed(occupants=occupants) == []
    occupants.loop_radius = r.pole_radius
    assert failed(occupants=occupants) == ["set"]
