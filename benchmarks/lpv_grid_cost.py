"""What one grid point costs in ``lpvsyn`` (issue 61, item 5), against one ``hinfsyn`` LMI.

Run: ``python benchmarks/lpv_grid_cost.py msd|seat`` (from the repository root, with
``MPLBACKEND=Agg OPENBLAS_NUM_THREADS=1``).  ``msd`` is the 2-state mass-spring-damper of
``tests/test_lpv.py`` (mass in [1, 4]), ``seat`` the nominal 10-state augmented seat
plant of ``docs/guide/lpv.md`` (occupant mass in [30, 70] kg).  Prints:

- the first γ minimisation of ``hinfsyn`` on the scaled plant at the middle of the range,
  by the structured CVXOPT route and by Clarabel (the best of three runs);
- ``lpvsyn``'s SDP time (``seconds_lmi``) on grids of 3 to 33 (msd) or 9 (seat) points,
  basis ``[1, p, 1/p]``, and per grid point; then, for the same grids, CVXPY's compilation
  time, Clarabel's solve time and its iterations (of the last solve: after a recovery
  the compilation is cached).
"""

import sys
import time
from pathlib import Path

import numpy as np

from lmi_suspension.lpv import lpvsyn
from lmi_suspension.lti import GeneralizedPlant
from lmi_suspension.lti.scaling import scale_plant
from lmi_suspension.synthesis import HinfsynOptions, lmi
from lmi_suspension.synthesis import lpv as _lpv
from lmi_suspension.synthesis.hinfsyn import _without_d22

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))


def problem(which):
    if which == "msd":
        from test_lpv import msd

        return msd, (1.0, 4.0), 1, 1, (3, 5, 9, 17, 33)
    from lmi_suspension.seat.augmented import SeatDesignOptions, seat_augmented_plant
    from lmi_suspension.seat.params import SeatParameters

    opts = SeatDesignOptions(include_delay=False, include_parametric=False,
                             include_paper=False)
    return (lambda m3: seat_augmented_plant(opts, SeatParameters(m3=m3)).P,
            (30.0, 70.0), 2, 1, (3, 5, 9))


def main(which="msd"):
    plant, (lo, hi), nmeas, ncon, sizes = problem(which)
    basis = lambda p: [1.0, p, 1.0 / p]
    mid = 0.5 * (lo + hi)
    G = _without_d22(GeneralizedPlant.from_statespace(plant(mid), nmeas, ncon))
    Ps, _ = scale_plant(G)
    for solver in ("structured", "clarabel"):
        ts = []
        for _ in range(3):
            t = time.perf_counter()
            lmi.gamma_lmi(Ps, HinfsynOptions(gamma_solver=solver))
            ts.append(time.perf_counter() - t)
        print(f"{which} n={G.nstates}: one hinfsyn LMI ({solver}) at p={mid:g}: "
              f"best {min(ts):.3f} s of 3")
    for N in sizes:
        res = lpvsyn(plant, {"p": np.linspace(lo, hi, N)}, nmeas, ncon, basis=basis,
                     check_density=1)
        print(f"{which}: {N} points: SDP {res.seconds_lmi:.3f} s = "
              f"{res.seconds_lmi / N:.3f} s/point; check {res.seconds_check:.2f} s for "
              f"{res.gamma_check.size} points; warnings {len(res.warnings)}")
    # where the SDP's time goes
    orig, stats = _lpv._lmi._solve, []

    def spy(prob, *a, **k):
        out = orig(prob, *a, **k)
        stats.append((getattr(prob, "_compilation_time", None) or float("nan"),
                      prob.solver_stats.solve_time, prob.solver_stats.num_iters))
        return out

    _lpv._lmi._solve = spy
    try:
        for N in sizes:
            stats.clear()
            res = lpvsyn(plant, {"p": np.linspace(lo, hi, N)}, nmeas, ncon, basis=basis,
                         check_density=1)
            print(f"{which}: {N} points: SDP {res.seconds_lmi:.3f} s; (compile, solve, "
                  f"iterations): {[(round(c, 3), round(s, 3), it) for c, s, it in stats]}")
    finally:
        _lpv._lmi._solve = orig


if __name__ == "__main__":
    main(*sys.argv[1:2])
