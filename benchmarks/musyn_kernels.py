"""Default ``musyn`` on dkpy's distillation example, one line for the kernel table of
issue 64: µ certified independently, controller order, CPU and wall seconds.

The plant and grid are those of ``benchmarks/musyn_vs_dkpy.py`` (dkpy's
``example_skogestad2006_p325()["P"]`` where dkpy is installed, dkpy itself not run;
else the project's :func:`~lmi_suspension.examples.skogestad_distillation`; 61 points
over 1e-3..1e3 rad/s) and so is the certificate (closed-loop poles, then SLICOT
AB13MD's D scalings with ``σ̄(D M D⁻¹)`` recomputed on 200 frequencies; its time is not
counted).

Run under every OpenBLAS kernel and 1 and 2 threads:
``/work/shared/tools/kernels python benchmarks/musyn_kernels.py``; alone:
``OPENBLAS_NUM_THREADS=1 python benchmarks/musyn_kernels.py``.  Arguments
``name=value`` are ``MusynOptions`` keywords (e.g. ``"reduce_order='auto'"
reduce_mu_tol=0.01``: the line then also gives the order and certified µ before the
reduction).
"""

import ast
import logging
import sys
import time
import warnings

import control
from musyn_vs_dkpy import BLK, OMEGA, _cpu, certified_mu

from lmi_suspension.examples import skogestad_distillation
from lmi_suspension.mu import MusynOptions, musyn

if __name__ == "__main__":
    warnings.filterwarnings("ignore")
    logging.disable(logging.WARNING)
    try:
        import dkpy

        eg = dkpy.example_skogestad2006_p325()
        P, nmeas, ncon, source = eg["P"], eg["n_y"], eg["n_u"], "dkpy's plant"
    except ImportError:
        ex = skogestad_distillation()
        P, nmeas, ncon, source = ex.P, ex.nmeas, ex.ncon, "project's plant"
    P = control.ss(P)
    kw = {k.strip(): ast.literal_eval(v) for k, v in
          (item.split("=", 1) for item in sys.argv[1:])}
    t0, c0 = time.perf_counter(), _cpu()
    res = musyn(P, nmeas, ncon, BLK, omega=OMEGA, options=MusynOptions(**kw))
    seconds, cpu = time.perf_counter() - t0, _cpu() - c0
    line = (f"{source}{' ' + str(kw) if kw else ''}: certified µ "
            f"{certified_mu(P, res.K, nmeas, ncon):.6f} (own {res.mu_peak:.6f}), order "
            f"{res.K.nstates}, CPU {cpu:.1f} s, wall {seconds:.1f} s")
    if res.K_full is not None:
        line += (f"; before reduction: order {res.K_full.nstates}, certified µ "
                 f"{certified_mu(P, res.K_full, nmeas, ncon):.6f}")
    print(line, flush=True)
