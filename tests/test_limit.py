"""Tests of the physical-limit LP (best peak acceleration any bounded force can reach)."""

import numpy as np
import pytest

from lmi_suspension.errors import InfeasibleError, NonFiniteError, ParameterError
from lmi_suspension.seat.limit import bump_limit
from lmi_suspension.seat.roads import bump
from lmi_suspension.seat.simulate import simulate


@pytest.fixture(scope="module")
def road():
    return bump(t_end=3.0, dt=1e-3)


@pytest.fixture(scope="module")
def limit(road):
    return bump_limit(road, dt=5e-3)


def test_limit_below_passive(limit, road):
    # u = 0 is feasible (passive |x1| stays below z_max), so the LP optimum cannot exceed
    # the passive peak at the LP samples (computed independently by the simulator).
    passive = simulate(None, road, dt=1e-4)
    on_lp_grid = np.interp(limit.t, passive.t, passive.z3dd)
    assert np.max(np.abs(passive.x1)) <= 0.08
    assert limit.peak <= np.max(np.abs(on_lp_grid)) + 1e-6
    assert limit.certified_peak < np.max(np.abs(passive.z3dd))


def test_limit_constraints_hold_in_resimulation(limit):
    sim = limit.simulation
    assert limit.status == "optimal"
    assert np.max(np.abs(limit.force)) <= limit.u_max
    assert np.max(np.abs(sim.u_applied)) <= limit.u_max
    # between the LP samples the re-simulated deflection may exceed z_max only by the
    # intersample/road-interpolation effect: 1 % here
    assert limit.certified_peak_x1 <= 1.01 * limit.z_max
    # the LP's own trajectory satisfies its constraints up to solver tolerance
    assert np.max(np.abs(limit.x1)) <= limit.z_max * (1 + 1e-6)
    assert np.max(np.abs(limit.z3dd)) <= limit.peak * (1 + 1e-6)


def test_resimulation_reproduces_lp_trajectory_at_samples(limit):
    # Independent route: the fine ZOH re-simulation sampled at the LP instants gives the
    # LP states back (only the road's FOH reading differs, 1 ms vs 5 ms samples).
    sim = limit.simulation
    z_at = np.interp(limit.t, sim.t, sim.z3dd)
    assert np.max(np.abs(z_at - limit.z3dd)) < 0.05 * limit.peak
    assert limit.peak <= limit.certified_peak * (1 + 1e-6)
    assert limit.certified_peak < 1.1 * limit.peak


def test_limit_bounds_a_feasible_controller(limit, road):
    # Any controller that keeps within the limits cannot beat the LP bound.
    res = simulate(np.array([[20000.0, 0.0]]), road, delay=0.01)
    m = res.metrics()
    assert m.x1_within_limit and m.peak_u <= 1500
    assert limit.peak <= m.peak_z3dd


def test_force_bound_binds(limit):
    # With the bound halved, the best peak can only get worse (monotone in u_max).
    half = bump_limit(bump(t_end=3.0, dt=1e-3), dt=5e-3, u_max=750.0)
    assert half.peak >= limit.peak - 1e-6
    assert np.max(np.abs(half.force)) <= 750.0


def test_infeasible_deflection_limit(road):
    # The bump lifts the floor by 0.1 m in 0.12 s; keeping |x1| <= 1 mm means dragging the
    # 15 kg seat frame along (peak floor acceleration a/2 (2 pi V0/l)^2 ~ 34 m/s^2), which
    # a 10 N force cannot do.
    with pytest.raises(InfeasibleError):
        bump_limit(road, dt=5e-3, z_max=1e-3, u_max=10.0)


@pytest.mark.parametrize("kwargs, err", [
    (dict(dt=-1e-3), ParameterError),
    (dict(u_max=float("nan")), NonFiniteError),
    (dict(z_max=0.0), ParameterError),
    (dict(refine=0), ParameterError),
    (dict(dt=10.0), ParameterError),
])
def test_bad_arguments(road, kwargs, err):
    with pytest.raises(err):
        bump_limit(road, **kwargs)


def test_road_type_checked():
    with pytest.raises(ParameterError):
        bump_limit(np.zeros(10))


@pytest.mark.slow
def test_limit_converges_as_dt_decreases(road):
    values = [bump_limit(road, dt=dt).certified_peak for dt in (4e-3, 2e-3, 1e-3)]
    # successive differences shrink (the ZOH force converges to a continuous optimum)
    d1, d2 = abs(values[0] - values[1]), abs(values[1] - values[2])
    assert d2 < d1
    assert d2 < 0.02 * values[2]

