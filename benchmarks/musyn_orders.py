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

The same table for another problem (mixed µ included: the columns on the D-scaled plant
are then left out, and AB13MD's certificate of each truncation is added):
:func:`tradeoff`, e.g. ``python benchmarks/musyn_mixed.py seat --orders``.

``--dkpy``: then default ``musyn`` and forced orders (``reduce_order=k``,
``reduce_mu_tol=0.05``) beside one dkpy run, with their CPU seconds and the ratio to
dkpy's (see ``musyn_vs_dkpy.py``).

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/musyn_orders.py [--dkpy]``.
"""

import logging
import sys
import warnings
from dataclasses import replace

import control
import numpy as np
import scipy.linalg

from lmi_suspension.examples import skogestad_distillation
from lmi_suspension.lti.norms import hinfnorm
from lmi_suspension.lti.plant import GeneralizedPlant, lft
from lmi_suspension.lti.reduce import balanced_truncation
from lmi_suspension.lti.scaling import balanced_statespace
from lmi_suspension.mu import MusynOptions, musyn
from lmi_suspension.mu.bounds import _ab13md_blocks
from lmi_suspension.mu.dk import _final_bounds
from lmi_suspension.mu.steps import mu_part
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


def tradeoff(P, nmeas, ncon, blk=BLK, omega=OMEGA, options=MusynOptions(reduce_order=None),
             orders=ORDERS, check=None):
    """Run ``musyn`` (``options``, full order) and print, for each order, µ of the
    truncations of its controller relative to the full order's dense-grid µ.

    Columns: the balanced truncation's norm on the best D-K iterate's D-scaled plant
    (a µ bound at every frequency; ``--`` where the structure has real blocks, whose
    scaled plant holds G scalings, or where the complexified run's controller is
    returned) and its µ on the result's dense grid (``dk._final_bounds``, mixed µ with
    real blocks; its lower bound too), the same two for Enns' output-weighted truncation
    (D-K only), and, with ``check`` (a grid, rad/s), the truncation's µ by AB13MD's
    scalings on it and at the loop's dense-grid peak (:func:`certified_mu`, independent
    of ``musyn``), and its closed loop's largest pole real part.  ``orders`` None: every
    order below the full one.  Returns the result."""
    from musyn_vs_dkpy import certified_mu

    res = musyn(P, nmeas, ncon, blk, omega=omega, options=replace(options, reduce_order=None))
    K, mu = res.K, res.mu_peak
    G = GeneralizedPlant.from_statespace(P, nmeas, ncon)
    struct = BlockStructure.from_blk(blk)
    best = res.history[res.best_iteration - 1] if res.best_iteration >= 1 else None
    PD = None if struct.has_real or best is None else best.PD
    V = None if PD is None else output_weight(PD, K, nmeas, ncon)
    ab_blocks = _ab13md_blocks(struct)
    print(f"full order {K.nstates}: µ {mu:.6f} (lower {res.mu_lower_peak:.6f})"
          + ("" if PD is None else f", norm on its scaled plant {best.gamma:.6f}"))

    def judged(K_red):
        CL = lft(G, K_red)
        if np.any(np.real(CL.poles()) >= 0):
            return np.inf, np.inf, np.inf, None
        norm = np.nan if PD is None else float(hinfnorm(lft(PD, K_red, nmeas, ncon))[0])
        bounds = _final_bounds(balanced_statespace(mu_part(CL, struct)), struct,
                               res.mu.omega, np.random.default_rng(0))
        return norm / mu - 1, float(np.max(bounds.upper)) / mu - 1, \
            float(np.max(bounds.lower)) / mu - 1, bounds

    def independent(K_red, bounds) -> str:
        if check is None or ab_blocks is None:
            return ""
        peak = float(res.mu.omega[int(np.argmax(bounds.upper))]) if bounds else 1.0
        ab = certified_mu(P, K_red, nmeas, ncon, nblock=ab_blocks[0], itype=ab_blocks[1],
                          omega=np.append(check, peak))
        pole = float(np.max(np.real(lft(G, K_red).poles())))
        return f" | {ab / mu - 1:+8.2%} {pole:9.3g}"

    def pct(x) -> str:
        return "      --" if np.isnan(x) else f"{x:+8.2%}"

    print("order | truncation: norm, µ, µ lower" + (" | weighted truncation: norm, µ"
                                                    if V is not None else "")
          + (" | AB13MD's µ, largest pole real part" if check is not None else ""))
    print(f"{K.nstates:5d} | {pct(np.nan)} {0.0:+8.2%} {res.mu_lower_peak / mu - 1:+8.2%}"
          + (" |" + " " * 18 if V is not None else "") + independent(K, res.mu), flush=True)
    for order in range(1, K.nstates) if orders is None else orders:
        try:
            K_bt = balanced_truncation(K, order=order)[0]
        except ValueError as exc:  # an order below the modes kept whole
            print(f"{order:5d} | no truncation: {exc}", flush=True)
            continue
        bt = judged(K_bt)
        line = f"{order:5d} | {pct(bt[0])} {pct(bt[1])} {pct(bt[2])}"
        if V is not None:
            fw = judged(weighted_truncation(K, V, order))
            line += f" | {pct(fw[0])} {pct(fw[1])}"
        print(line + independent(K_bt, bt[3]), flush=True)
    return res


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
