"""Default ``musyn`` on the distillation problem, one line: µ, its lower bound, seconds.

Run under every OpenBLAS kernel with ``../shared/tools/kernels python
benchmarks/musyn_default.py`` (issue 39's target: µ <= 0.9600 in <= 15 s on every row;
benchmarks/HISTORY.md, musyn).
"""

import logging
import time
import warnings

import numpy as np

from lmi_suspension.examples import skogestad_distillation
from lmi_suspension.mu import MusynOptions, musyn

if __name__ == "__main__":
    warnings.filterwarnings("ignore")
    logging.disable(logging.WARNING)
    ex = skogestad_distillation()
    t = time.perf_counter()
    res = musyn(ex.P, ex.nmeas, ex.ncon, ex.blk, omega=np.logspace(-3, 3, 61),
                options=MusynOptions(method="lmi"))
    dt = time.perf_counter() - t
    ks = sum(h.seconds_k for h in res.history if h.stage == "dk")
    ss = sum(h.seconds_k for h in res.history if h.stage != "dk")
    print(f"mu {res.mu_peak:.6f} lower {res.mu_lower_peak:.6f} seconds {dt:.1f} "
          f"dk_k {ks:.1f} search {ss:.1f} iters {len(res.history)}")
