"""Routes around the cost of the LMI route's γ minimisation and controller LMI (issue 39).

Run: ``python benchmarks/gamma_alternatives.py [N [PART ...]]`` with N the order of
``bench_hinfsyn.plant`` (22 by default) and PART among ``accuracy``, ``solvers``,
``early``, ``controller``, ``cuts``, ``structured`` (the first five by default).  Each
part poses what ``hinfsyn(method="lmi")`` poses on the scaled plant and prints seconds,
interior-point iterations and, where a controller is formed, its certified γ
(``hinfnorm(lft(P, K))``) and fastest pole:

``accuracy``
    The first γ minimisation (identity frame), one round in the frame of its solution,
    and the same problem solved by CVXOPT where installed, with the explicit controller
    formed from CVXOPT's ``(R, S)`` and certified; then ``hinfsyn``'s certified γ, LMI
    optimum and warnings: is the γ minimisation's optimum the LMI optimum?
``solvers``
    The first γ minimisation as ``benchmarks/gamma_cones.py`` poses it, solved by Clarabel
    (faer, the default), by Clarabel with MKL PARDISO (``direct_solve_method="mkl"``:
    Clarabel loads ``libmkl_rt.so`` at run time, e.g. from ``pip install mkl`` with its
    ``lib`` on ``LD_LIBRARY_PATH`` and ``MKL_THREADING_LAYER=SEQUENTIAL``, the one
    threading layer that did not fail or crash here), and by CVXOPT and SDPA through
    CVXPY where they are installed (``pip install cvxopt sdpa-python``); a route not
    available here is said so and skipped.
``early``
    The γ minimisation stopped early (``tol_gap_rel`` 1e-6, the default, then 1e-4 and
    1e-3), the explicit controller formed from its ``(R, S)``: does an interior-point
    iterate short of the optimum give a better-conditioned controller than the optimum?
``controller``
    The controller LMI of the default reconstruction at ``(1 + gamma_relax) γ``, with the
    gap tolerance 1e-6 (the default), 1e-4 and 1e-3: how many of its iterations are spent
    closing the gap?
``structured``
    The first γ minimisation (``gamma_lmi``) solved by the structured KKT solver (the
    default since 2026-11-29) and by Clarabel: seconds, optimum, status.
``cuts``
    The coupling ``[[R, I], [I, S]] >= 0`` imposed only on a subspace ``V`` (a cone of the
    subspace's dimension instead of 2n), ``V`` grown by the eigenvectors of the coupling's
    negative eigenvalues at each solution (cutting planes with PSD blocks).

The figures of 2026-11-29 are in benchmarks/HISTORY.md ("routes around the γ
minimisation's cost").
"""

import importlib
import sys
import time
import warnings
from dataclasses import replace
from pathlib import Path

import cvxpy as cp
import numpy as np

from lmi_suspension.lti import hinfnorm, lft
from lmi_suspension.lti.scaling import scale_plant
from lmi_suspension.synthesis import HinfsynOptions, hinfsyn
from lmi_suspension.synthesis import lmi

sys.path.insert(0, str(Path(__file__).parent))
from bench_hinfsyn import plant  # noqa: E402
from gamma_cones import problem  # noqa: E402

# the module, not the function the package exports under the same name
_H = importlib.import_module("lmi_suspension.synthesis.hinfsyn")


def _certified(G, Ks, sc):
    """Certified γ and fastest pole of the controller ``Ks`` of the scaled plant."""
    K = _H._undo_loop_shift(sc.controller_to_original(Ks), G.D22)
    gamma, _ = hinfnorm(lft(G, K))
    return gamma, float(np.max(np.abs(np.linalg.eigvals(K.A)))) if K.nstates else 0.0


def _identity_problem(Ps, n: int, opts: HinfsynOptions):
    """The first γ minimisation in the identity frame, with its variables: ``(problem,
    R̃, S̃, γ, U_R, U_S)``, ``R = U_R R̃ U_Rᵀ`` and ``S = U_S S̃ U_Sᵀ``."""
    proj_r, proj_s = lmi._projections(*lmi.Frame.identity(n).plants(Ps), True)
    Rt = cp.Variable((n, n), symmetric=True)
    St = cp.Variable((n, n), symmetric=True)
    g = cp.Variable(nonneg=True)
    M = proj_r.T.T @ proj_s.T
    cons = [p.lmi(W, g, opts.margin) for p, W in ((proj_r, Rt), (proj_s, St))]
    cons += [lmi._sym(cp.bmat([[Rt, M], [M.T, St]])) >> 0,
             cp.trace(Rt) + cp.trace(St) <= opts.xy_bound * n]
    return cp.Problem(cp.Minimize(g), cons), Rt, St, g, proj_r.T, proj_s.T


def accuracy(n: int) -> None:
    G, Ps, sc = _scaled(n)
    opts = HinfsynOptions(gamma_solver="clarabel")  # the route these figures measured
    unit = 1.0 / sc.gamma_factor  # scaled units to the plant's
    first = lmi.gamma_lmi(Ps, opts)
    again = lmi.gamma_lmi(Ps, opts, frame=lmi.Frame.from_lyapunov(first.R, first.S))
    print(f"Clarabel, identity frame: {first.gamma * unit:.7g} ({first.status}); one round "
          f"in its frame: {again.gamma * unit:.7g} ({again.status}), "
          f"{first.gamma / again.gamma - 1:.2e} above it")
    if cp.CVXOPT in cp.installed_solvers():
        prob, Rt, St, g, U_r, U_s = _identity_problem(Ps, n, opts)
        t = time.perf_counter()
        try:
            prob.solve(solver=cp.CVXOPT, kktsolver="qr")
        except cp.error.SolverError as exc:
            print(f"CVXOPT failed after {time.perf_counter() - t:.1f} s ({exc})")
        else:
            sol = lmi.LmiSolution(float(g.value), lmi._sym(U_r @ Rt.value @ U_r.T),
                                  lmi._sym(U_s @ St.value @ U_s.T), prob.status)
            P2, sc2, g2, (s2,) = _H._unit_gamma(Ps, sc, sol.gamma, [sol])
            c = np.sqrt(1.0 + 2e-4)
            head = f"CVXOPT ({time.perf_counter() - t:.1f} s): {sol.gamma * unit:.7g} " \
                   f"({prob.status}); the explicit controller from its (R, S) at 2e-4 above"
            try:
                Ks, _cond = lmi.decoupled_controller(P2, c * s2.R, c * s2.S,
                                                     g2 * (1 + 2e-4))
            except Exception as exc:  # noqa: BLE001 - a measurement: say and go on
                print(head, "failed:", exc)
            else:
                gamma, fastest = _certified(G, Ks, sc2)
                print(head, f"certifies {gamma:.7g} (fastest pole {fastest:.4g})")
    else:
        print("CVXOPT not installed")
    t = time.perf_counter()
    res = hinfsyn(plant(n), 4, 4, method="lmi")
    lower = "not reported" if res.gamma_lower is None else f"{res.gamma_lower:.7g}"
    print(f"hinfsyn: {time.perf_counter() - t:.2f} s, certified {res.gamma:.7g}, LMI optimum "
          f"{lower}, fastest pole {res.controller_fastest_pole:.4g}")
    for w in res.warnings:
        print("   ", w)


def solvers(n: int) -> None:
    Ps, _ = scale_plant(plant(n))
    opts = HinfsynOptions()
    routes = [("Clarabel, faer (as posed)", cp.CLARABEL, lmi.clarabel_settings(opts)),
              ("Clarabel, MKL PARDISO", cp.CLARABEL,
               {**lmi.clarabel_settings(opts), "direct_solve_method": "mkl"}),
              ("CVXOPT (kktsolver qr)", cp.CVXOPT, dict(kktsolver="qr")),
              ("SDPA (lambdaStar 1e4)", cp.SDPA, dict(lambdaStar=1e4))]
    for label, solver, kw in routes:
        if solver not in cp.installed_solvers():
            print(f"{label:28s} not installed")
            continue
        prob = problem(Ps, n, opts)
        t = time.perf_counter()
        try:
            prob.solve(solver=solver, **kw)
        except cp.error.SolverError as exc:
            print(f"{label:28s} failed after {time.perf_counter() - t:.2f} s ({exc})")
            continue
        except Exception as exc:  # noqa: BLE001 - Clarabel raises a bare Exception
            # for a linear solver it cannot load; anything else is said as it is
            print(f"{label:28s} {type(exc).__name__} after {time.perf_counter() - t:.2f} s: "
                  f"{exc}")
            continue
        st = prob.solver_stats
        its = f"{st.num_iters} iterations" if st.num_iters else "iterations not reported"
        print(f"{label:28s} {time.perf_counter() - t:.2f} s ({its}), {prob.status}, "
              f"γ {prob.value:.8g}")


def _scaled(n: int):
    G = _H._as_plant(plant(n), 4, 4)
    Ps, sc = scale_plant(_H._without_d22(G))
    return G, Ps, sc


def early(n: int) -> None:
    G, Ps, sc = _scaled(n)
    opts = HinfsynOptions()
    t = time.perf_counter()
    ref = hinfsyn(plant(n), 4, 4, method="lmi")
    print(f"default hinfsyn: {time.perf_counter() - t:.2f} s, certified {ref.gamma:.7g}, "
          f"fastest pole {ref.controller_fastest_pole:.4g}")
    for tol in (1e-6, 1e-4, 1e-3):
        t = time.perf_counter()
        # the absolute gap tolerance the default's, or as loose as a tenth of the relative
        sol = lmi.gamma_lmi(Ps, replace(opts, tol_gap_rel=tol,
                                        tol_gap_abs=max(opts.tol_gap_abs, tol / 10)))
        ts = time.perf_counter() - t
        P2, sc2, g2, (s2,) = _H._unit_gamma(Ps, sc, sol.gamma, [sol])
        for relax in (0.0, 2e-4):
            c = np.sqrt(1.0 + relax)
            head = f"tol_gap_rel {tol:g} ({ts:.2f} s, γ {sol.gamma / sc.gamma_factor:.7g}), " \
                   f"relax {relax:g}:"
            try:
                Ks, cond = lmi.decoupled_controller(P2, c * s2.R, c * s2.S, g2 * (1 + relax))
            except Exception as exc:  # noqa: BLE001 - a measurement: say and go on
                print(head, "explicit controller failed:", exc)
                continue
            gamma, fastest = _certified(G, Ks, sc2)
            print(head, f"certified {gamma:.7g}, fastest pole {fastest:.4g}, "
                  f"cond(I - XY) {cond:.3g}")


def controller(n: int) -> None:
    G, Ps, sc = _scaled(n)
    opts = HinfsynOptions()
    sol = lmi.gamma_lmi(Ps, opts)
    P2, sc2, g2, (s2,) = _H._unit_gamma(Ps, sc, sol.gamma, [sol])
    for tol in (1e-6, 1e-4, 1e-3):
        cl = lmi.ControllerLmi(P2, lmi.Frame.from_lyapunov(s2.R, s2.S))
        t = time.perf_counter()
        Ks, _cond, status, _w = cl.controller(
            g2 * (1 + opts.gamma_relax), _H._CENTER_TRACE * cl.frame.trace,
            # the absolute gap tolerance kept at its default: the relative one alone is
            # what is loosened here (as measured on 2026-11-29)
            replace(opts, tol_gap_rel=tol, tol_gap_abs=min(opts.tol_gap_abs, tol / 10)),
            refine=False)
        dt = time.perf_counter() - t
        gamma, fastest = _certified(G, Ks, sc2)
        print(f"controller LMI, tol_gap_rel {tol:g}: {dt:.2f} s "
              f"({cl.problem.solver_stats.num_iters} iterations), {status}, "
              f"certified {gamma:.7g}, fastest pole {fastest:.4g}")


def cuts(n: int, add: int = 4, rounds: int = 12) -> None:
    Ps, _ = scale_plant(plant(n))
    opts = HinfsynOptions()
    proj_r, proj_s = lmi._projections(*lmi.Frame.identity(n).plants(Ps), True)
    M = proj_r.T.T @ proj_s.T
    V = np.zeros((2 * n, 0))
    total = 0.0
    for k in range(rounds):
        Rt = cp.Variable((n, n), symmetric=True)
        St = cp.Variable((n, n), symmetric=True)
        g = cp.Variable(nonneg=True)
        cons = [p.lmi(W, g, opts.margin) for p, W in ((proj_r, Rt), (proj_s, St))]
        if V.shape[1]:
            cons.append(lmi._sym(V.T @ cp.bmat([[Rt, M], [M.T, St]]) @ V) >> 0)
        cons.append(cp.trace(Rt) + cp.trace(St) <= opts.xy_bound * n)
        prob = cp.Problem(cp.Minimize(g), cons)
        t = time.perf_counter()
        prob.solve(solver=cp.CLARABEL, **lmi.clarabel_settings(opts))
        total += time.perf_counter() - t
        C = np.block([[Rt.value, M], [M.T, St.value]])
        w, U = np.linalg.eigh((C + C.T) / 2)
        neg = int(np.sum(w < 0))
        print(f"round {k}: subspace {V.shape[1]} of {2 * n}, γ {g.value:.6g} ({prob.status}, "
              f"{prob.solver_stats.num_iters} iterations), coupling's least eigenvalue "
              f"{w[0]:.3g} ({neg} negative), {total:.2f} s so far")
        if w[0] >= -1e-9 * max(1.0, w[-1]):
            break
        V = np.linalg.qr(np.hstack([V, U[:, :min(add, max(neg, 1))]]))[0]


def structured(n: int) -> None:
    Ps, sc = scale_plant(plant(n))
    for gs in ("structured", "clarabel"):
        t = time.perf_counter()
        sol = lmi.gamma_lmi(Ps, HinfsynOptions(gamma_solver=gs))
        print(f"{gs:10s} {time.perf_counter() - t:6.2f} s  γ {sol.gamma:.8g} (scaled), "
              f"{sol.gamma / sc.gamma_factor:.8g} (plant), {sol.status}")


def main(argv: list[str]) -> None:
    # statuses are printed; CVXPY's warning of an inaccurate solution adds nothing
    warnings.filterwarnings("ignore", message="Solution may be inaccurate")
    n = int(argv[0]) if argv else 22
    parts = argv[1:] or ["accuracy", "solvers", "early", "controller", "cuts"]
    for part in parts:
        print(f"== {part}, n = {n}")
        {"accuracy": accuracy, "solvers": solvers, "early": early, "controller": controller,
         "cuts": cuts, "structured": structured}[part](n)


if __name__ == "__main__":
    main(sys.argv[1:])
