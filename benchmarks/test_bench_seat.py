"""Benchmarks of the seat simulation and the physical-limit LP (run: pytest benchmarks/)."""

import numpy as np
import pytest

from lmi_suspension.seat.limit import bump_limit
from lmi_suspension.seat.roads import bump
from lmi_suspension.seat.simulate import simulate, stability_delay_margin

pytest.importorskip("pytest_benchmark")

K_SPRING = np.array([[60000.0, 0.0]])


def test_bench_simulate_bump_3s(benchmark):
    road = bump(t_end=3.0, dt=1e-3)
    res = benchmark(simulate, K_SPRING, road, delay=0.01)
    assert res.stable


def test_bench_delay_margin(benchmark):
    assert 0 < benchmark(stability_delay_margin, K_SPRING) < 0.1


def test_bench_bump_limit_2ms(benchmark):
    road = bump(t_end=3.0, dt=1e-3)
    res = benchmark.pedantic(bump_limit, args=(road,), kwargs={"dt": 2e-3}, rounds=1,
                             iterations=1)
    assert res.status == "optimal"
