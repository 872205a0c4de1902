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
``OPENBLAS_NUM_THREADS=1 python benchmarks/musyn_kernels.py``.
"""

import logging
import time
import warnings

import control

from musyn_vs_dkpy import certified_mu, run_musyn

from lmi_suspension.examples import skogestad_distillation

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
    t0 = time.perf_counter()
    K, seconds, cpu, own = run_musyn(P, nmeas, ncon)
    print(f"{source}: certified µ {certified_mu(P, K, nmeas, ncon):.6f} (own "
          f"{own:.6f}), order {K.nstates}, CPU {cpu:.1f} s, wall {seconds:.1f} s",
          flush=True)
