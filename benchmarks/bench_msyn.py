"""Multi-objective synthesis (``msyn``): wall time against the number of constraints and of
states, beside plain ``hinfsyn`` (LMI) on the same plant.

Run: ``python -m pytest benchmarks/bench_msyn.py --benchmark-only -p no:cacheprovider``.
One round per case (the solves take seconds).  Plants: ``random_plant(n, 3, 1, 4, 2)``,
seeded; the H∞ objective on performance outputs 0-1 and, as constraints are added in this
order, a peak bound on output 2, an H2 bound on output 3, a half-plane and a sector.  The
bounds are set from the H∞-optimal controller's own values (its peak and H2 norm times
0.9, its decay rate times 0.5), so that each constraint is active or close to it.  Every
result's certificates are stored in ``extra_info``; a failure is recorded, not raised.
"""

import numpy as np
import pytest

from lmi_suspension.errors import LmiSuspensionError
from lmi_suspension.synthesis import hinfsyn, msyn
from lmi_suspension.synthesis.constraints import (Channel, H2Bound, HalfPlane, HinfBound,
                                                  PeakBound, Sector)
from lmi_suspension.synthesis.examples import random_plant

ORDERS = [6, 12, 20, 30]
#: (states, constraints): all four constraints up to 12 states; above, one (the search of
#: each norm constraint's Lyapunov scale costs about 18 minimisations; 12 states with four
#: constraints took 182 s on 2026-11-26)
CASES = [(6, 0), (6, 1), (6, 2), (6, 4), (12, 0), (12, 1), (12, 2), (12, 4),
         (20, 0), (20, 1), (30, 0), (30, 1)]


def plant(n):
    return random_plant(n, 3, 1, 4, 2, rng=np.random.default_rng(2000 + n), d11=False)


def _constraints(P, count):
    """The first ``count`` constraints, bounds from the unconstrained optimum."""
    free = msyn(P, P.ny, P.nu, HinfBound(Channel(outputs=(0, 1))),
                [PeakBound(Channel(outputs=(2,)), (1e6,)),
                 H2Bound(Channel(outputs=(3,)), 1e6)])
    peak = PeakBound(Channel(outputs=(2,)), (1.0,)).peaks(free.CL)[0]
    h2 = H2Bound(Channel(outputs=(3,))).certify(free.CL)
    decay = -float(np.max(free.poles.real))
    specs = [PeakBound(Channel(outputs=(2,)), (0.9 * peak,)),
             H2Bound(Channel(outputs=(3,)), 0.9 * h2),
             HalfPlane(alpha=0.5 * decay), Sector(theta=1.2)]
    return specs[:count]


@pytest.mark.parametrize("n,count", CASES)
def test_msyn(benchmark, n, count):
    P = plant(n)
    benchmark.extra_info.update(n=n, constraints=count)
    try:
        specs = _constraints(P, count) if count else []
    except LmiSuspensionError as exc:
        benchmark.extra_info.update(error=f"bounds: {type(exc).__name__}: {exc}"[:200])
        pytest.skip("no reference controller for the bounds")

    def run():
        try:
            return msyn(P, P.ny, P.nu, HinfBound(Channel(outputs=(0, 1))), specs)
        except (LmiSuspensionError, ValueError, np.linalg.LinAlgError) as exc:
            return exc

    res = benchmark.pedantic(run, rounds=1, iterations=1, warmup_rounds=0)
    if isinstance(res, Exception):
        benchmark.extra_info.update(error=f"{type(res).__name__}: {res}"[:200])
        return
    benchmark.extra_info.update(
        objective=res.objective, objective_lmi=res.objective_lmi,
        certificates=[(c.name, c.achieved, c.met) for c in res.certificates],
        lyapunov_scales=list(res.lyapunov_scales), warnings=len(res.warnings))


@pytest.mark.parametrize("n", ORDERS)
def test_hinfsyn_beside(benchmark, n):
    """Plain hinfsyn (LMI) on the objective channel alone, for the ratio."""
    P = plant(n)
    b = P.blocks()
    from lmi_suspension.lti import GeneralizedPlant

    Q = GeneralizedPlant.from_matrices(A=b["A"], B1=b["B1"], B2=b["B2"], C1=b["C1"][:2],
                                       C2=b["C2"], D11=b["D11"][:2], D12=b["D12"][:2],
                                       D21=b["D21"])
    benchmark.extra_info.update(n=n)
    res = benchmark.pedantic(lambda: hinfsyn(Q, Q.ny, Q.nu), rounds=1, iterations=1,
                             warmup_rounds=0)
    benchmark.extra_info.update(gamma=res.gamma, gamma_lower=res.gamma_lower)
