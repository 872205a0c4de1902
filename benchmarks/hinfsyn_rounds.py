"""``hinfsyn`` by the LMI (defaults) and by python-control's Riccati route on one
``bench_hinfsyn.plant(n)``, several rounds alternating, one line: the medians and their
ratio.  ``bench_hinfsyn.py`` runs each case once; where the two routes are within that
round's noise (n = 30), this is the measurement that decides (issue 39:
``python benchmarks/hinfsyn_rounds.py 30 7``; benchmarks/HISTORY.md, H∞ synthesis).
"""

import logging
import statistics
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_hinfsyn import plant  # noqa: E402

from lmi_suspension.synthesis import hinfsyn  # noqa: E402

if __name__ == "__main__":
    warnings.filterwarnings("ignore")
    logging.disable(logging.WARNING)
    n, rounds = int(sys.argv[1]), int(sys.argv[2])
    P = plant(n)
    seconds = {"lmi": [], "riccati": []}
    for _ in range(rounds):
        for method in seconds:  # alternating, so that a change of load hits both
            t = time.perf_counter()
            hinfsyn(P, P.ny, P.nu, method=method)
            seconds[method].append(time.perf_counter() - t)
    lmi, ric = (statistics.median(seconds[m]) for m in ("lmi", "riccati"))
    print(f"n {n} rounds {rounds} median lmi {lmi:.3f} s riccati {ric:.3f} s "
          f"ratio {lmi / ric:.2f}")
