"""What each cone of the LMI route's γ minimisation costs Clarabel (issue 39).

Run: ``python benchmarks/gamma_cones.py N`` (N = the order of ``bench_hinfsyn.plant``).
It poses the first γ minimisation of ``hinfsyn(method="lmi")`` on the scaled plant as
``lmi._gamma_lmi`` does (identity frame, sparse form, ``clarabel_settings``), then the
same problem with one change each: the coupling cone ``[[R, M], [Mᵀ, S]] >= 0`` replaced
by ``R >= 0, S >= 0`` (a relaxation, solved for its cost only, its γ meaningless) and
Clarabel settings.  It prints the seconds per interior-point iteration of each.  The
figures of 2026-11-28 are in benchmarks/HISTORY.md.
"""

import sys
import time
import warnings
from pathlib import Path

import cvxpy as cp

from lmi_suspension.lti.scaling import scale_plant
from lmi_suspension.synthesis import HinfsynOptions
from lmi_suspension.synthesis import lmi

sys.path.insert(0, str(Path(__file__).parent))
from bench_hinfsyn import plant  # noqa: E402


def problem(Ps, n: int, opts: HinfsynOptions, coupling: bool = True):
    Rt = cp.Variable((n, n), symmetric=True)
    St = cp.Variable((n, n), symmetric=True)
    g = cp.Variable(nonneg=True)
    frame = lmi.Frame.identity(n)
    proj_r, proj_s = lmi._projections(*frame.plants(Ps), True)
    cons = [p.lmi(V, g, opts.margin) for p, V in ((proj_r, Rt), (proj_s, St))]
    if coupling:
        M = (proj_r.T.T / frame.scale[None, :] ** 2) @ proj_s.T
        cons.append(lmi._sym(cp.bmat([[Rt, M], [M.T, St]])) >> 0)
    else:
        cons += [Rt >> 0, St >> 0]
    cons.append(cp.trace(Rt) + cp.trace(St) <= opts.xy_bound * n)
    return cp.Problem(cp.Minimize(g), cons)


def main(n: int) -> None:
    # the status is printed; CVXPY's warning of an inaccurate solution adds nothing
    warnings.filterwarnings("ignore", message="Solution may be inaccurate")
    Ps, _ = scale_plant(plant(n))
    opts = HinfsynOptions()
    variants = [("as posed (faer, 1 thread)", True, {}),
                ("coupling as two n cones (relaxation)", False, {}),
                ("faer, 2 threads", True, dict(max_threads=2)),
                ("tol_gap_rel 1e-5, tol_gap_abs 1e-6", True,
                 dict(tol_gap_rel=1e-5, tol_gap_abs=1e-6)),
                ("no equilibration", True, dict(equilibrate_enable=False)),
                ("no chordal decomposition", True, dict(chordal_decomposition_enable=False))]
    if n <= 30:  # 13 times slower than faer at n = 30
        variants.insert(2, ("qdldl", True, dict(direct_solve_method="qdldl")))
    for label, coupling, over in variants:
        prob = problem(Ps, n, opts, coupling)
        kw = {**lmi.clarabel_settings(opts), **over}
        t = time.perf_counter()
        try:
            prob.solve(solver=cp.CLARABEL, **kw)
        except cp.error.SolverError:
            print(f"{label:40s} Clarabel failed after {time.perf_counter() - t:.2f} s")
            continue
        st = prob.solver_stats
        print(f"{label:40s} {st.solve_time / max(st.num_iters, 1):.3f} s/iteration "
              f"({st.num_iters} iterations, {st.solve_time:.2f} s) {prob.status}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 30)
