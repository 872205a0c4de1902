"""The occupant subsets (seat.occupant_subset) and the certificate of a seat controller
scheduled on the estimated mass (seat.scheduled).

The independent reference of the certificate is today's, :func:`certify_occupants` on
the same samples: a schedule with the shipped controller at every mass must give its
figures bit for bit; a schedule whose controller changes with the mass must give, per
sample, the figures of the controller at that sample's estimate computed here by
:class:`BumpResponse` directly.
"""

import math

import control
import numpy as np
import pytest

from lmi_suspension.errors import DimensionError, ParameterError
from lmi_suspension.lti.gridded import GriddedController
from lmi_suspension.seat.multimodel import SHIPPED_OCCUPANTS
from lmi_suspension.seat.occupant_subset import OccupantSubset
from lmi_suspension.seat.occupants import (OccupantSet, certify_occupants, occupant_mu,
                                           occupant_samples)
from lmi_suspension.seat.loop import BumpResponse
from lmi_suspension.seat.refine import load_refined
from lmi_suspension.seat.scheduled import (certify_scheduled, schedule_estimates,
                                           scheduling_subset)


@pytest.fixture(scope="module")
def shipped():
    return load_refined(SHIPPED_OCCUPANTS)[0]


@pytest.fixture(scope="module")
def samples():
    # 2 performance samples: 3 limit LPs of about 0.7 s
    return occupant_samples(rng=np.random.default_rng(11), n_stability=30, n_performance=2)


def _constant(K):
    """The trivial schedule: ``K`` at every mass."""
    return GriddedController.from_controllers({"m3": [30.0, 70.0]}, [K, K])


# ----------------------------------------------------------------------- subsets
def test_subset_samples_are_the_whole_sets_with_the_group_fixed():
    whole, _ = OccupantSet().sample(12, np.random.default_rng(3))
    sub, _ = OccupantSubset(fixed=("k1", "c1")).sample(12, np.random.default_rng(3))
    for w, s in zip(whole, sub):
        assert (s.k1, s.c1) == (31000.0, 830.0)          # the nominal seat's (Table 1)
        assert (s.m3, s.k2, s.k3, s.c2, s.c3) == (w.m3, w.k2, w.k3, w.c2, w.c3)


def test_subset_structure_and_corners():
    s = OccupantSubset(fixed=("m3", "k2"))
    opts = s.mu_design()
    assert opts.m3_range is None and "k2" not in opts.stiffness and "k1" in opts.stiffness
    assert s.varying() == ("k1", "k3", "c1", "c2", "c3")
    assert len(s.corners(("m3", "k1"))) == 2          # m3 has one end
    assert OccupantSubset(m3=(50.0, 50.0)).fixed == ("m3",)
    assert OccupantSubset(m3=(50.0, 50.0)).nominal.m3 == 50.0
    # a mass fixed by a range of zero width: no mass scalar in µ (the µ model refuses a
    # range of zero width; this failed before 2026-12-02)
    assert OccupantSubset(m3=(50.0, 50.0)).mu_design().m3_range is None
    with pytest.raises(ParameterError, match="unknown"):
        OccupantSubset(fixed=("k4",))
    with pytest.raises(ParameterError, match="twice"):
        OccupantSubset(fixed=("k1", "k1"))
    with pytest.raises(ParameterError, match="tuple"):
        OccupantSubset(fixed="m3")


def test_scheduling_subset():
    s = scheduling_subset(OccupantSet(), 68.0, 5.0)
    assert s.m3 == (63.0, 70.0) and s.nominal.m3 == 68.0 and s.fixed == ()
    with pytest.raises(ParameterError, match="outside"):
        scheduling_subset(OccupantSet(), 75.0, 5.0)
    with pytest.raises(ParameterError, match="error"):
        scheduling_subset(OccupantSet(), 50.0, -1.0)


def test_scheduling_subset_of_a_bin():
    # a bin of estimates [a, b] meets the true masses [a - e, b + e] (within the set's)
    s = scheduling_subset(OccupantSet(), (40.0, 50.0), 5.0)
    assert s.m3 == (35.0, 55.0) and s.nominal.m3 == 45.0 and s.fixed == ()
    assert scheduling_subset(OccupantSet(), (30.0, 40.0), 5.0).m3 == (30.0, 45.0)
    assert scheduling_subset(OccupantSet(), (50.0, 50.0), 0.0).fixed == ("m3",)
    with pytest.raises(ParameterError, match="lo <= hi"):
        scheduling_subset(OccupantSet(), (50.0, 40.0), 5.0)
    with pytest.raises(ParameterError, match="outside"):
        scheduling_subset(OccupantSet(), (60.0, 75.0), 5.0)
    with pytest.raises(ParameterError, match="pair"):
        scheduling_subset(OccupantSet(), (40.0, 45.0, 50.0), 5.0)


# ----------------------------------------------------------------------- estimates
def test_estimates_drawn_within_the_error_and_the_range(shipped):
    Ks = _constant(shipped)
    true = np.linspace(30.0, 70.0, 401)
    est = schedule_estimates(true, Ks, 5.0, np.random.default_rng(0))
    assert np.all(np.abs(est - true) <= 5.0) and np.all((30.0 <= est) & (est <= 70.0))
    again = schedule_estimates(true, Ks, 5.0, np.random.default_rng(0))
    assert np.array_equal(est, again)                 # seeded: reproducible
    given = schedule_estimates([32.0, 68.0], Ks, [-4.0, 4.0])
    assert given.tolist() == [30.0, 70.0]             # held inside the schedule's range
    with pytest.raises(DimensionError):
        schedule_estimates([32.0, 68.0], Ks, [1.0])
    with pytest.raises(ParameterError, match="Generator"):
        schedule_estimates([32.0], Ks, 5.0)


# ----------------------------------------------------------------------- certificate
def test_constant_schedule_gives_todays_certificate(shipped, samples):
    # one time-domain re-simulation per figure (1.7 s each)
    ref = certify_occupants(shipped, samples, confirm=1)
    got = certify_scheduled(_constant(shipped), samples, rng=np.random.default_rng(0),
                            confirm=1, mu=False, search=False, grid=[30.0, 50.0, 70.0])
    assert got.unstable == ref.unstable and got.n_stability == ref.n_stability
    for name in ("ratio", "u_peak", "x1_peak"):
        assert np.array_equal(getattr(got, name), getattr(ref, name)), name
    assert (got.worst_ratio, got.u_max, got.x1_max, got.nominal_ratio) == \
        (ref.worst_ratio, ref.u_max, ref.x1_max, ref.nominal_ratio)
    assert got.confirmed == ref.confirmed
    assert (got.controller_radius, got.loop_radius) == (ref.controller_radius, ref.loop_radius)
    assert math.isnan(got.rs_mu_max) and math.isnan(got.u_searched)


def test_the_controller_is_scheduled_on_the_estimate(shipped, samples):
    # a schedule whose gain falls with the mass: each sample's figures are those of the
    # controller at *its estimate*, computed here directly
    weak = control.ss(shipped.A, shipped.B, 0.8 * shipped.C, 0.8 * shipped.D)
    Ks = GriddedController.from_controllers({"m3": [30.0, 70.0]}, [shipped, weak])
    n_s, n_p = len(samples.stability), len(samples.performance)
    errors = (np.full(n_s, 3.0), np.array([-5.0, 5.0, 0.0])[:n_p])
    got = certify_scheduled(Ks, samples, rng=np.random.default_rng(0), errors=errors,
                            confirm=0, mu=False, search=False, grid=[])
    est = np.clip([p.m3 for p in samples.performance] + errors[1], 30.0, 70.0)
    assert np.array_equal(got.performance_estimates, est) and got.error is None
    for i, (p, m) in enumerate(zip(samples.performance, est)):
        z, u, _ = BumpResponse(road=samples.road, delays=got.delays, params=p).peaks(
            Ks.at(m3=m))
        assert np.array_equal(got.ratio[i], z / samples.limits[i])
        assert np.array_equal(got.u_peak[i], u)
    # the true mass would give other figures (the test can tell the two apart)
    p0 = samples.performance[0]
    z_true = BumpResponse(road=samples.road, delays=got.delays, params=p0).peaks(
        Ks.at(m3=p0.m3))[0]
    assert not np.array_equal(got.ratio[0], z_true / samples.limits[0])


def test_a_table_of_bins_is_certified_per_bin(shipped, samples):
    # two bins, the second controller weaker: every sample's figures are those of the
    # controller of its estimate's bin, computed here directly; the certificate's values
    # are the bins, each over its estimates widened by the error
    weak = control.ss(shipped.A, shipped.B, 0.8 * shipped.C, 0.8 * shipped.D)
    Ks = GriddedController.from_controllers({"m3": [30.0, 50.0, 70.0]}, [shipped, weak],
                                            interpolation="bins")
    n_s, n_p = len(samples.stability), len(samples.performance)
    errors = (np.full(n_s, -2.0), np.array([-5.0, 5.0, 0.0])[:n_p])
    got = certify_scheduled(Ks, samples, rng=np.random.default_rng(0), errors=errors,
                            confirm=0, mu=False, search=False)
    assert [v.estimates for v in got.values] == [(30.0, 50.0), (50.0, 70.0)]
    assert [v.occupants.m3 for v in got.values] == [(30.0, 55.0), (45.0, 70.0)]
    assert [v.m3_hat for v in got.values] == [40.0, 60.0]
    est = np.clip([p.m3 for p in samples.performance] + errors[1], 30.0, 70.0)
    for i, (p, m) in enumerate(zip(samples.performance, est)):
        K = shipped if m < 50.0 else weak
        z = BumpResponse(road=samples.road, delays=got.delays, params=p).peaks(K)[0]
        assert np.array_equal(got.ratio[i], z / samples.limits[i])
    with pytest.raises(ParameterError, match="not one bin"):
        certify_scheduled(Ks, samples, rng=np.random.default_rng(0), mu=False,
                          search=False, grid=[(40.0, 60.0)])


def test_bad_input(shipped, samples):
    rng = np.random.default_rng(0)
    with pytest.raises(ParameterError, match="scheduled on 'm3'"):
        certify_scheduled(shipped, samples, rng=rng)          # not a schedule
    two = GriddedController.from_controllers({"m3": [30.0, 70.0], "k1": [2e4, 4e4]},
                                             [shipped] * 4)
    with pytest.raises(ParameterError, match="scheduled on 'm3'"):
        certify_scheduled(two, samples, rng=rng)
    with pytest.raises(ParameterError, match="occupant_samples"):
        certify_scheduled(_constant(shipped), None, rng=rng)
    with pytest.raises(ParameterError, match="outside"):
        certify_scheduled(_constant(shipped), samples, rng=rng, mu=False, search=False,
                          grid=[80.0])


@pytest.mark.slow  # 317 s on Zen 1 at load 8-9 (2026-12-02): the second tier
def test_mu_at_a_scheduling_value_is_the_sets_for_the_whole_range(shipped, samples):
    # an error that covers every mass: the set at each scheduling value is the whole
    # set, and µ is occupant_mu's on it; a smaller error certifies a subset, whose
    # bound cannot exceed the whole set's by more than the bounds' grid tolerance
    omega = np.logspace(-1.0, 3.5, 40)
    ref = occupant_mu(shipped, OccupantSet(), omega=omega, rng=np.random.default_rng(5))
    got = certify_scheduled(_constant(shipped), samples, rng=np.random.default_rng(5),
                            error=40.0, errors=([0.0] * 30, [0.0] * 2), grid=[50.0],
                            search=False, omega=omega)
    assert got.values[0].occupants.m3 == (30.0, 70.0)
    assert got.values[0].rs_mu == pytest.approx(ref.rs_sup, rel=1e-9)
    small = certify_scheduled(_constant(shipped), samples, rng=np.random.default_rng(5),
                              error=5.0, grid=[50.0], search=False, omega=omega)
    assert small.values[0].occupants.m3 == (45.0, 55.0)
    assert small.rs_mu_max <= ref.rs_sup * (1 + 1e-3)   # a subset: 0.1 % for the bounds
