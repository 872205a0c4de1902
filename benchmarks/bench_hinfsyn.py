"""LMI vs Riccati (python-control) vs dkpy H∞ synthesis: wall time and certified γ.

The LMI route three ways: ``lmi``, the defaults (the structured γ minimisation, the
explicit controller where it passes its checks); ``lmi_sdp``, the same γ minimisation
with the controller LMI (``controller="sdp"``); ``lmi_clarabel``, the γ minimisation by
Clarabel and the controller LMI (``gamma_solver="clarabel", controller="sdp"``, the
defaults until 2026-11-29).

Run: ``python -m pytest benchmarks/bench_hinfsyn.py --benchmark-only -p no:cacheprovider``.
Each case runs once (pedantic, one round): the solves take seconds.  Every controller,
ours or a peer's, is certified the same way, by ``hinfnorm(lft(P, K))`` (``inf`` when the
closed loop is unstable); the certified γ, the solver's own γ, the LMI lower bound and the
controller's fastest pole are stored in ``extra_info``.  dkpy is measured where installed.
"""

import numpy as np
import pytest

from lmi_suspension.errors import LmiSuspensionError
from lmi_suspension.lti import hinfnorm, lft
from lmi_suspension.synthesis import HinfsynOptions, hinfsyn
from lmi_suspension.synthesis.examples import random_plant

ORDERS = [4, 8, 16, 22, 30, 40, 60]
#: dkpy is not run above this order: it returned no controller from 16 states on and took
#: 66-343 s at 40 (benchmarks/HISTORY.md, H∞ synthesis, 2026-11-26 and 2026-11-27), so at
#: 60 it would only cost time
DKPY_MAX_ORDER = 40


def plant(n):
    # 4 disturbances, 4 controls, 4 errors, 4 measurements: n = 22 is the target size
    return random_plant(n, 4, 4, 4, 4, rng=np.random.default_rng(1000 + n), d11=False)


def _fastest_pole(K):
    return float(np.max(np.abs(np.linalg.eigvals(K.A)))) if K.nstates else 0.0


def _run_dkpy(P):
    dkpy = pytest.importorskip("dkpy")
    K, _CL, gam, info = dkpy.HinfSynLmi(solver_params=dict(solver="CLARABEL")).synthesize(
        P.sys, P.ny, P.nu)
    if K is None:
        raise LmiSuspensionError(f"dkpy returned no controller: {info.get('status')}")
    return K, float(gam)


#: the LMI variants' options (``lmi``: the defaults)
LMI_VARIANTS = {"lmi": HinfsynOptions(),
                "lmi_sdp": HinfsynOptions(controller="sdp"),
                "lmi_clarabel": HinfsynOptions(gamma_solver="clarabel", controller="sdp")}


@pytest.mark.parametrize("method", [*LMI_VARIANTS, "riccati", "dkpy"])
@pytest.mark.parametrize("n", ORDERS)
def test_hinfsyn(benchmark, n, method):
    if method == "dkpy" and n > DKPY_MAX_ORDER:
        pytest.skip(f"dkpy is not run above {DKPY_MAX_ORDER} states (DKPY_MAX_ORDER)")
    P = plant(n)
    benchmark.extra_info.update(n=n, method=method)

    def run():
        try:
            if method == "dkpy":
                return _run_dkpy(P)
            if method in LMI_VARIANTS:
                return hinfsyn(P, P.ny, P.nu, method="lmi", options=LMI_VARIANTS[method])
            return hinfsyn(P, P.ny, P.nu, method=method)
        except (LmiSuspensionError, ValueError, np.linalg.LinAlgError) as exc:
            # record failures instead of aborting the run
            return exc

    res = benchmark.pedantic(run, rounds=1, iterations=1, warmup_rounds=0)
    if isinstance(res, Exception):
        benchmark.extra_info.update(error=f"{type(res).__name__}: {res}"[:200])
        return
    if method == "dkpy":
        K, gamma_solver = res
        benchmark.extra_info.update(gamma=hinfnorm(lft(P, K))[0], gamma_solver=gamma_solver,
                                    fastest_controller_pole=_fastest_pole(K))
        return
    benchmark.extra_info.update(
        gamma=res.gamma, gamma_solver=res.gamma_solver, gamma_lower=res.gamma_lower,
        fastest_controller_pole=res.controller_fastest_pole, warnings=len(res.warnings),
        status=res.status,
        timings=dict(setup=res.timings.setup, solve=res.timings.solve,
                     reconstruct=res.timings.reconstruct, certify=res.timings.certify))
