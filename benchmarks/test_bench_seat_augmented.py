"""Timing of the seat plant builders (run: python -m pytest benchmarks/test_bench_seat_augmented.py)."""

import pytest

from lmi_suspension.seat.augmented import SeatDesignOptions, seat_augmented_plant
from lmi_suspension.seat.uncertainty import delay_uncertainty


@pytest.mark.parametrize("order", [1, 2, 3])
def test_bench_delay_cover_fit(benchmark, order):
    du = benchmark(delay_uncertainty, 0.0, 0.025, nominal="pade", order=order)
    assert du.W.nstates == order


def test_bench_seat_augmented_plant(benchmark):
    aug = benchmark(seat_augmented_plant, SeatDesignOptions())
    assert aug.P.nstates == 13
