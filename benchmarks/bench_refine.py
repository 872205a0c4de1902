"""The refinement's exact evaluations against the routes that certify them, in one run:
the bump at six delays by FFT (``BumpResponse``) vs the time-stepping ``simulate``, and
µ on 150 frequencies by the two-block formula (``TwoBlockMu``) vs ``mussv``.  Each
refinement iteration makes about 60 such evaluations (one per parameter), which is what
made a fixed-order search of the seat controller affordable.

Run: ``python -m pytest benchmarks/bench_refine.py -p no:cacheprovider``.
"""

import numpy as np
import pytest

from lmi_suspension.lti import freqresp, lft
from lmi_suspension.mu import mussv
from lmi_suspension.seat.augmented import DEFAULT_DESIGN, seat_augmented_plant
from lmi_suspension.seat.design import design_mu_controller
from lmi_suspension.seat.loop import REFINE_DELAYS, BumpResponse, TwoBlockMu
from lmi_suspension.seat.refine import _MU_GRID
from lmi_suspension.seat.roads import bump
from lmi_suspension.seat.simulate import simulate


@pytest.fixture(scope="module")
def K():
    return design_mu_controller().K


def test_bench_bump_fft(benchmark, K):
    br = BumpResponse()
    benchmark(br.peaks, K)


def test_bench_bump_simulate(benchmark, K):
    road = bump()
    benchmark.pedantic(lambda: [simulate(K, road, delay=d, u_max=np.inf).metrics()
                                for d in REFINE_DELAYS], rounds=3)


def test_bench_mu_two_block(benchmark, K):
    mu = TwoBlockMu(DEFAULT_DESIGN, _MU_GRID)
    benchmark(mu.curve, K)


def test_bench_mu_mussv(benchmark, K):
    aug = seat_augmented_plant(DEFAULT_DESIGN)
    benchmark.pedantic(lambda: mussv(freqresp(lft(aug.P, K, aug.nmeas, aug.ncon), _MU_GRID),
                                     aug.blk, omega=_MU_GRID), rounds=3)
