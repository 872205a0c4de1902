"""LMI vs Riccati H∞ synthesis: wall time and certified γ on seeded random plants.

Run: ``python -m pytest benchmarks/bench_hinfsyn.py --benchmark-only``.
Each case runs once (pedantic, one round): the solves take seconds, and the certified
γ, the LMI lower bound and the controller's fastest pole are stored in ``extra_info``.
"""

import numpy as np
import pytest

from lmi_suspension.errors import LmiSuspensionError
from lmi_suspension.synthesis import hinfsyn
from lmi_suspension.synthesis.examples import random_plant

ORDERS = [4, 8, 16, 22, 30, 40]


def plant(n):
    # 4 disturbances, 4 controls... the n = 22 case is the 4-in/4-out target plant
    return random_plant(n, 4, 4, 4, 4, rng=np.random.default_rng(1000 + n), d11=False)


@pytest.mark.parametrize("method", ["lmi", "riccati"])
@pytest.mark.parametrize("n", ORDERS)
def test_hinfsyn(benchmark, n, method):
    P = plant(n)
    benchmark.extra_info.update(n=n, method=method)

    def run():
        try:
            return hinfsyn(P, P.ny, P.nu, method=method)
        except LmiSuspensionError as exc:  # record failures instead of aborting the run
            return exc

    res = benchmark.pedantic(run, rounds=1, iterations=1, warmup_rounds=0)
    if isinstance(res, Exception):
        benchmark.extra_info.update(error=f"{type(res).__name__}: {res}"[:200])
        return
    benchmark.extra_info.update(
        gamma=res.gamma, gamma_solver=res.gamma_solver, gamma_lower=res.gamma_lower,
        fastest_controller_pole=res.controller_fastest_pole, warnings=len(res.warnings),
        timings=dict(setup=res.timings.setup, solve=res.timings.solve,
                     reconstruct=res.timings.reconstruct, certify=res.timings.certify))
