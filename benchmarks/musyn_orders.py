"""The order-µ trade-off of default ``musyn``'s controller on dkpy's distillation example
(issue 64, item 4): for each order, µ of two truncations of the full-order controller.

The full-order design is default ``musyn`` with ``reduce_order=None`` on dkpy's
``example_skogestad2006_p325()`` plant (the project's
:func:`~lmi_suspension.examples.skogestad_distillation` where dkpy is not installed), on
dkpy's 61-point grid.  For each order: the balanced truncation
(:func:`~lmi_suspension.lti.reduce.balanced_truncation`, the default reduction's) and
Enns' frequency-weighted balanced truncation with the full loop's ``T_zu`` (from the
controller's output to the scaled errors) as output weight; for each, its H∞ norm on the
best iterate's D-scaled plant (a µ bound at every frequency: the default order search's
judgement) and µ on the result's dense grid (``dk._final_bounds``), relative to the full
order's dense-grid µ.

``--dkpy``: then default ``musyn`` and forced orders (``reduce_order=k``,
``reduce_mu_tol=0.05``) beside one dkpy run, with their CPU seconds and the ratio to
dkpy's (see ``musyn_vs_dkpy.py``).

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/musyn_orders.py [--dkpy]``.
"""

import logging
import sys
import warnings

import control
import numpy as np
import scipy.linalg

from lmi_suspension.examples import skogestad_distillation
from lmi_suspension.lti.norms import hinfnorm
from lmi_suspension.lti.plant import GeneralizedPlant, lft
from lmi_suspension.lti.reduce import balanced_truncation
from lmi_suspension.lti.scaling import balanced_statespace
from lmi_suspension.mu import MusynOptions, musyn
from lmi_suspension.mu.dk import _final_bounds
from lmi_suspension.umodel.blocks import BlockStructure

OMEGA = np.logspace(-3, 3, 61)
BLK = [[1, 1], [1, 1], [2, 2]]
ORDERS = range(8, 16)


def plant():
    try:
        import dkpy
    except ImportError:
        ex = skogestad_distillation()
        return control.ss(ex.P), ex.nmeas, ex.ncon
    eg = dkpy.example_skogestad2006_p325()
    return control.ss(eg["P"]), eg["n_y"], eg["n_u"]


def output_weight(PD, K, nmeas, ncon):
    """``T_zu`` of the scaled loop: from an input added to the controller's output to
    the scaled errors (stable: the closed loop's poles)."""
    nw, nz = PD.ninputs - ncon, PD.noutputs - nmeas
    A, B, C, D = (np.asarray(m) for m in (PD.A, PD.B, PD.C, PD.D))
    aug = control.ss(A, np.hstack([B[:, :nw], B[:, nw:], B[:, nw:]]),
                     C, np.hstack([D[:, :nw], D[:, nw:], D[:, nw:]]))
    return lft(aug, K, nmeas, ncon)[:nz, nw:]


def weighted_truncation(K, V, order):
    """Enns' frequency-weighted balanced truncation of ``K`` with output weight ``V``:
    the controllability Gramian of ``K``, the observability Gramian of ``V K`` restricted
    to ``K``'s states, balanced by the square-root method."""
    Ak, Bk, Ck, Dk = (np.asarray(m) for m in (K.A, K.B, K.C, K.D))
    Av, Bv, Cv, Dv = (np.asarray(m) for m in (V.A, V.B, V.C, V.D))
    n, nv = Ak.shape[0], Av.shape[0]
    P = scipy.linalg.solve_continuous_lyapunov(Ak, -Bk @ Bk.T)
    A = np.block([[Av, Bv @ Ck], [np.zeros((n, nv)), Ak]])
    Cvk = np.hstack([Cv, Dv @ Ck])
    Q = scipy.linalg.solve_continuous_lyapunov(A.T, -Cvk.T @ Cvk)[nv:, nv:]

    def root(X):
        w, U = np.linalg.eigh((X + X.T) / 2)
        return U * np.sqrt(np.maximum(w, 0.0))

    Lp, Lq = root(P), root(Q)
    U, s, Vh = np.linalg.svd(Lq.T @ Lp)
    S = np.diag(s[:order] ** -0.5)
    Tl, Tr = S @ U[:, :order].T @ Lq.T, Lp @ Vh[:order].T @ S
    return control.ss(Tl @ Ak @ Tr, Tl @ Bk, Ck @ Tr, Dk)


def tradeoff(P, nmeas, ncon):
    res = musyn(P, nmeas, ncon, BLK, omega=OMEGA, options=MusynOptions(reduce_order=None))
    best = res.history[res.best_iteration - 1]
    PD, K, mu = best.PD, res.K, res.mu_peak
    G = GeneralizedPlant.from_statespace(P, nmeas, ncon)
    struct = BlockStructure.from_blk(BLK)
    V = output_weight(PD, K, nmeas, ncon)
    print(f"full order {K.nstates}: µ {mu:.6f}, norm on its scaled plant {best.gamma:.6f}")

    def judged(K_red):
        CL = lft(G, K_red)
        if np.any(np.real(CL.poles()) >= 0):
            return np.inf, np.inf
        norm = float(hinfnorm(lft(PD, K_red, nmeas, ncon))[0])
        peak = float(np.max(_final_bounds(balanced_statespace(CL), struct, res.mu.omega,
                                          np.random.default_rng(0)).upper))
        return norm / mu - 1, peak / mu - 1

    print("order | truncation: norm, µ | output-weighted truncation: norm, µ")
    for order in ORDERS:
        bt = judged(balanced_truncation(K, order=order)[0])
        fw = judged(weighted_truncation(K, V, order))
        print(f"{order:5d} | {bt[0]:+8.2%} {bt[1]:+8.2%} | {fw[0]:+8.2%} {fw[1]:+8.2%}",
              flush=True)


def beside_dkpy(P, nmeas, ncon):
    import dkpy
    from musyn_vs_dkpy import _cpu, certified_mu, run_dkpy

    K, _, dk_cpu, own = run_dkpy(dkpy, P, nmeas, ncon)
    print(f"dkpy: CPU {dk_cpu:.1f} s, own µ {own:.4f}, certified "
          f"{certified_mu(P, K, nmeas, ncon):.4f}", flush=True)
    runs = [("full", MusynOptions(reduce_order=None)), ("auto", MusynOptions())]
    runs += [(f"{k}", MusynOptions(reduce_order=k, reduce_mu_tol=0.05)) for k in (14, 13, 12)]
    for label, opts in runs:
        c0 = _cpu()
        res = musyn(P, nmeas, ncon, BLK, omega=OMEGA, options=opts)
        c = _cpu() - c0
        print(f"{label:5s}: order {res.K.nstates:2d}, µ {res.mu_peak:.6f} (dense grid), "
              f"bound at every frequency {res.mu_bound:.6f}, AB13MD on 200 points "
              f"{certified_mu(P, res.K, nmeas, ncon):.6f}, CPU {c:.1f} s, "
              f"ratio {c / dk_cpu:.2f}", flush=True)


if __name__ == "__main__":
    warnings.filterwarnings("ignore")
    logging.disable(logging.WARNING)
    P, nmeas, ncon = plant()
    if "--dkpy" in sys.argv:
        beside_dkpy(P, nmeas, ncon)
    else:
        tradeoff(P, nmeas, ncon)
