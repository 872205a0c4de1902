"""``hinfsyn`` by the LMI (defaults) and by python-control's Riccati route on one
``bench_hinfsyn.plant(n)``, several rounds alternating, one line: the medians of the
process's CPU time and of the wall time, their LMI/Riccati ratios, and each route's
certified γ (``hinfnorm(lft(P, K))``, ``inf`` for an unstable loop).
``bench_hinfsyn.py`` runs each case once; where the two routes are within that round's
noise (n = 30), this is the measurement that decides (issue 39:
``python benchmarks/hinfsyn_rounds.py 30 7``; benchmarks/HISTORY.md, H∞ synthesis).
CPU time is the figure compared on a shared machine (issue 64: ``python
benchmarks/hinfsyn_rounds.py 60 3``): the wall time there counts the other processes.
A third argument ``identity`` adds the LMI route started in the identity frame
(``HinfsynOptions(start="identity")``, the default until 2026-12-02) to the rounds.
"""

import logging
import statistics
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_hinfsyn import plant  # noqa: E402

from lmi_suspension.synthesis import HinfsynOptions, hinfsyn  # noqa: E402

if __name__ == "__main__":
    warnings.filterwarnings("ignore")
    logging.disable(logging.WARNING)
    n, rounds = int(sys.argv[1]), int(sys.argv[2])
    P = plant(n)
    methods = ("lmi", "riccati") + (("identity",) if sys.argv[3:] == ["identity"] else ())
    cpu = {m: [] for m in methods}
    wall = {m: [] for m in methods}
    gamma = {m: [] for m in methods}
    for _ in range(rounds):
        for method in methods:  # alternating, so that a change of load hits both
            t, c = time.perf_counter(), time.process_time()
            if method == "identity":
                res = hinfsyn(P, P.ny, P.nu, options=HinfsynOptions(start="identity"))
            else:
                res = hinfsyn(P, P.ny, P.nu, method=method)
            cpu[method].append(time.process_time() - c)
            wall[method].append(time.perf_counter() - t)
            gamma[method].append(res.gamma)
    lmi, ric = (statistics.median(cpu[m]) for m in ("lmi", "riccati"))
    wl, wr = (statistics.median(wall[m]) for m in ("lmi", "riccati"))
    print(f"n {n} rounds {rounds} median CPU lmi {lmi:.3f} s riccati {ric:.3f} s "
          f"ratio {lmi / ric:.2f}; wall lmi {wl:.3f} s riccati {wr:.3f} s ratio {wl / wr:.2f}; "
          f"certified gamma lmi {min(gamma['lmi']):.7g}-{max(gamma['lmi']):.7g} riccati "
          f"{min(gamma['riccati']):.7g}-{max(gamma['riccati']):.7g}")
    if "identity" in methods:
        wi = statistics.median(cpu["identity"])
        print(f"  identity start: median CPU {wi:.3f} s (ratio to riccati {wi / ric:.2f}), "
              f"wall {statistics.median(wall['identity']):.3f} s, certified gamma "
              f"{min(gamma['identity']):.7g}-{max(gamma['identity']):.7g}")
