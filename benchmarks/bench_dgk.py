"""Mixed-µ synthesis (D-G-K, real parameters kept real) against complex D-K (the real
parameter covered by a disc), in one run, on the stiffness oscillator of
:func:`lmi_suspension.examples.stiffness_oscillator` (±50 % real stiffness).

Run: ``python -m pytest benchmarks/bench_dgk.py -p no:cacheprovider``; each design's
certified mixed µ (upper and lower bound on the dense grid, and the all-frequency bound)
goes to ``benchmark.extra_info``.  Both designs are certified with the real structure.
"""

import numpy as np
import pytest

from lmi_suspension.examples import stiffness_oscillator
from lmi_suspension.mu import MusynOptions, musyn

OMEGA = np.logspace(-2, 1.5, 40)


@pytest.mark.parametrize("complexify", [True, False], ids=["complex-DK", "mixed-DGK"])
def test_bench_dgk_oscillator(benchmark, complexify):
    ex = stiffness_oscillator()
    res = benchmark.pedantic(
        musyn, args=(ex.P, ex.nmeas, ex.ncon, ex.blk),
        kwargs=dict(omega=OMEGA, options=MusynOptions(max_iter=8, complexify=complexify,
                                                      dscale_search=0)),
        rounds=1, iterations=1)
    benchmark.extra_info.update(
        mu_per_iteration=[h.mu_peak for h in res.history], mu_peak_dense=res.mu_peak,
        mu_lower_peak_dense=res.mu_lower_peak, mu_bound=res.mu_bound,
        stop_reason=res.stop_reason, controller_order=res.K.nstates)
    assert res.mu_lower_peak <= res.mu_peak <= res.mu_bound
