"""Default ``musyn`` against dkpy on dkpy's own distillation example, in one run
(issue 64, item 1): median seconds of each, their ratio, and µ of each controller
certified by a D-scaled upper bound neither library computed.

dkpy's run is its ``examples/1_example_dk_iter_fixed_order.py`` (dkpy 0.1.9):
``DkIterFixedOrder`` with the SLICOT K-step (``HinfSynSlicot``), the LMI bisection µ
(``SsvLmiBisection(n_jobs=1)``, Clarabel), the SLICOT D-fit (``DScaleFitSlicot``), 3
iterations, fit order 4, on ``np.logspace(-3, 3, 61)``.  ``musyn`` runs with its
defaults (the controller reduced to the least order within 1 % of the full order's µ;
both are certified; its own µ is printed with its bound at every frequency,
``MusynResult.mu_bound``) on the same plant (dkpy's ``example_skogestad2006_p325()["P"]``, the
project's :func:`~lmi_suspension.examples.skogestad_distillation` where dkpy is not
installed) and the same grid.  The rounds alternate which one runs first.

The certificate: for each returned controller, the closed loop's poles (all in the
open left half-plane), then at 200 log-spaced frequencies over 1e-3..1e3 rad/s
SLICOT AB13MD's D scalings (slycot, not the µ code of either library) and the largest
``σ̄(D M D⁻¹)`` they give, recomputed here (a Hermitian eigenvalue problem,
:func:`certified_mu`): an upper bound of µ at each frequency whatever AB13MD's own
accuracy.  Its time is not counted.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/musyn_vs_dkpy.py [rounds]`` (default 3;
dkpy is the ``benchmark`` extra, ``pip install -e .[benchmark]``; without it, a line
says so and ``musyn`` runs alone).
"""

import importlib.metadata
import logging
import os
import sys
import time
import warnings

import control
import numpy as np
import scipy.linalg

from lmi_suspension.examples import skogestad_distillation
from lmi_suspension.mu import musyn

OMEGA = np.logspace(-3, 3, 61)  # dkpy's example grid, given to both
CHECK = np.logspace(-3, 3, 200)  # the certificate's grid
BLK = [[1, 1], [1, 1], [2, 2]]


def certified_mu(P, K, nmeas: int, ncon: int, *, nblock=(1, 1, 2), itype=(2, 2, 2),
                 omega=CHECK) -> float:
    """max over ``omega`` of the µ upper bound that SLICOT AB13MD's scalings certify for
    ``M = F_l(P, K)(jω)`` (the loop by python-control, its response by a solve here);
    ``inf`` where the loop is unstable.  ``nblock``, ``itype``: AB13MD's structure
    (default distillation's complex full blocks 1, 1 and 2; ``itype`` 1 a real scalar).

    The bound is recomputed from AB13MD's ``D = diag(d²)`` and ``G = diag(g)`` (``G``
    zeroed off the real scalars, ``d`` made constant on each block, its geometric mean): the
    least ``β`` with ``M* D M + j(G M - M* G) ⪯ β² D`` (Fan, Tits and Doyle 1991), the
    largest generalized eigenvalue; with complex blocks alone ``σ̄(d M d⁻¹)``."""
    from slycot import ab13md

    CL = P.lft(K, nu=ncon, ny=nmeas)  # python-control's, the w -> z loop
    A, B, C, D = (np.asarray(m) for m in (CL.A, CL.B, CL.C, CL.D))
    if np.any(np.real(np.linalg.eigvals(A)) >= 0):
        return float("inf")
    nblock, itype = np.asarray(nblock, dtype=int), np.asarray(itype, dtype=int)
    real = np.repeat(itype == 1, nblock)
    ends = np.cumsum(nblock)
    worst = 0.0
    eye = np.eye(A.shape[0])
    for w in np.asarray(omega, dtype=float):
        M = C @ np.linalg.solve(1j * w * eye - A, B) + D
        _, d, g, _ = ab13md(M.astype(complex), nblock, itype)
        d, g = np.asarray(d, dtype=float), np.where(real, np.asarray(g, dtype=float), 0.0)
        # one d per block, whatever AB13MD returned inside it (on dkpy's controller its
        # 2 x 2 block's entries differ in the last digits): any D constant on each block
        # is a scaling of the structure, so the bound below is valid for it
        for a, b in zip(ends - nblock, ends):
            d[a:b] = np.exp(np.mean(np.log(d[a:b])))
        Dm, Gm = np.diag(d ** 2), np.diag(g)
        H = M.conj().T @ Dm @ M + 1j * (Gm @ M - M.conj().T @ Gm)
        lam = scipy.linalg.eigh((H + H.conj().T) / 2, Dm, eigvals_only=True)[-1]
        worst = max(worst, float(np.sqrt(max(lam, 0.0))))
    return worst


def _cpu() -> float:
    """CPU seconds of this process and its finished children (``mussv`` runs AB13MD in
    a child process): on a shared machine a steadier measure than wall time."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def run_dkpy(dkpy, P, nmeas, ncon):
    dk_iter = dkpy.DkIterFixedOrder(
        controller_synthesis=dkpy.HinfSynSlicot(),
        structured_singular_value=dkpy.SsvLmiBisection(n_jobs=1),
        d_scale_fit=dkpy.DScaleFitSlicot(),
        n_iterations=3,
        fit_order=4,
    )
    blocks = [dkpy.ComplexFullBlock(1, 1), dkpy.ComplexFullBlock(1, 1),
              dkpy.ComplexFullBlock(2, 2)]
    t0, c0 = time.perf_counter(), _cpu()
    K, _, mu, _, _ = dk_iter.synthesize(P, nmeas, ncon, OMEGA, blocks)
    return K, time.perf_counter() - t0, _cpu() - c0, float(np.max(mu))


def run_musyn(P, nmeas, ncon):
    t0, c0 = time.perf_counter(), _cpu()
    res = musyn(P, nmeas, ncon, BLK, omega=OMEGA)
    return (res.K, time.perf_counter() - t0, _cpu() - c0, res.mu_peak, res.K_full,
            res.mu_bound)


if __name__ == "__main__":
    warnings.filterwarnings("ignore")
    logging.disable(logging.WARNING)
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    try:
        import dkpy
    except ImportError:
        dkpy = None
        print("dkpy is not installed (pip install -e .[benchmark]): musyn runs alone")
    if dkpy is not None:
        eg = dkpy.example_skogestad2006_p325()
        P, nmeas, ncon = eg["P"], eg["n_y"], eg["n_u"]
        print(f"dkpy {importlib.metadata.version('dkpy')}: its examples/1 "
              "(DkIterFixedOrder, SLICOT K-step, "
              "3 iterations, fit order 4)")
    else:
        ex = skogestad_distillation()
        P, nmeas, ncon = ex.P, ex.nmeas, ex.ncon
    P = control.ss(P)
    times = {"musyn": [], "dkpy": []}
    cpu = {"musyn": [], "dkpy": []}
    for r in range(rounds):
        order = ["dkpy", "musyn"] if r % 2 == 0 else ["musyn", "dkpy"]
        for name in order:
            if name == "dkpy" and dkpy is None:
                continue
            K, seconds, cpu_s, own, K_full, bound = (
                run_dkpy(dkpy, P, nmeas, ncon) + (None, None) if name == "dkpy"
                else run_musyn(P, nmeas, ncon))
            times[name].append(seconds)
            cpu[name].append(cpu_s)
            print(f"round {r + 1} {name:5s}: {seconds:6.1f} s (CPU {cpu_s:6.1f} s), own µ "
                  f"{own:.4f}" + ("" if bound is None else f" (bound at every frequency "
                                     f"{bound:.4f})") + ", certified µ "
                  f"{certified_mu(P, K, nmeas, ncon):.4f}, controller order {K.nstates}"
                  + ("" if K_full is None else  # musyn's default order reduction
                     f" (full order {K_full.nstates}: certified µ "
                     f"{certified_mu(P, K_full, nmeas, ncon):.4f})"), flush=True)
    for label, table in (("wall", times), ("CPU", cpu)):
        med = {k: float(np.median(v)) for k, v in table.items() if v}
        line = f"median {label} seconds: " + ", ".join(f"{k} {v:.1f}" for k, v in med.items())
        if "dkpy" in med:
            ratios = [m / d for m, d in zip(table["musyn"], table["dkpy"])]
            line += (f"; musyn / dkpy {med['musyn'] / med['dkpy']:.2f} (ratio of medians), "
                     "per round " + ", ".join(f"{x:.2f}" for x in ratios))
        print(line)
