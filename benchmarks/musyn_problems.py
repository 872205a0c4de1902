"""Default ``musyn`` against D-K alone (``dscale_search=0``) on two problems besides
distillation: the complexified stiffness oscillator and the seat's µ problem with
fourth-order D fits.  Prints, per run, the dense-grid µ, each record's grid µ, the
stages (d: D-K, d: search last), seconds and the stop reason (benchmarks/HISTORY.md,
musyn, 2026-11-29).  Run: ``python benchmarks/musyn_problems.py``.
"""

import logging
import time
import warnings
from dataclasses import replace

import numpy as np

from lmi_suspension.examples import stiffness_oscillator
from lmi_suspension.mu import MusynOptions, musyn
from lmi_suspension.seat.augmented import DEFAULT_DESIGN, seat_augmented_plant
from lmi_suspension.seat.design import DEFAULT_OMEGA

if __name__ == "__main__":
    warnings.filterwarnings("ignore")
    logging.disable(logging.WARNING)
    osc = stiffness_oscillator()
    aug = seat_augmented_plant(DEFAULT_DESIGN, None)
    cases = [
        ("oscillator, complexified", osc.P, 1, 1, [[-1, 0], [2, 2]],
         np.logspace(-2, 1.5, 25), MusynOptions(complexify=True, n_dense=60)),
        ("seat µ (delay cover), 4th-order fits, method best", aug.P, aug.nmeas, aug.ncon,
         aug.blk, DEFAULT_OMEGA, MusynOptions(method="best", n_dense=120)),
    ]
    for name, P, ny, nu, blk, w, opts in cases:
        for label, o in (("D-K alone", replace(opts, dscale_search=0)), ("default", opts)):
            t = time.perf_counter()
            r = musyn(P, ny, nu, blk, omega=w, options=o, rng=np.random.default_rng(0))
            print(f"{name} | {label}: µ {r.mu_peak:.5f}, records "
                  f"{[round(h.mu_peak, 4) for h in r.history]}, stages "
                  f"{[h.stage for h in r.history]}, {time.perf_counter() - t:.1f} s | "
                  f"{r.stop_reason}", flush=True)
