"""The routes tried for ``hinfsyn`` on a discrete plant (issue 63: within 1e-4 of the
continuous optimum on the Tustin images of the plants of tests/test_discrete.py), as a
markdown table: certified γ relative to the continuous LMI optimum, seconds, and whether
a lower bound came back.

* ``direct r``: the discrete bounded-real LMI on the discrete data (the ``msyn`` engine,
  one H∞ objective), reconstructed ``r`` above its optimum (``hinfsyn`` until 2026-12-02
  with ``r = gamma_relax = 5e-4``);
* ``msyn continuous``: the same engine on the continuous plant, the bound on what any
  reformulation of the discrete data (δ operator, scaling) can reach with that engine;
* ``image capped r``: the continuous route on the exact bilinear image with its pole cap
  on the explicit controller, reconstructed ``r`` above the optimum, mapped back by Tustin;
* ``image uncapped 5e-5``: the same without the pole cap;
* ``image fixed 5e-5``: the continuous route's fixed-level LMI at 1 + 5e-5 times the image's
  optimum (the feasibility step of a γ bisection);
* ``hinfsyn``: what ``hinfsyn(Pd)`` does now (the image at 5e-5 with the cap, without it
  where that is more than 1e-4 above the lower bound; the lower kept).

Run: ``python benchmarks/discrete_routes.py [dt] [problem ...]`` (default 0.01 s and the
eight plants of ``benchmarks/discrete_table.py``).
"""
import sys
import time
import warnings
from dataclasses import replace

import control
import numpy as np

warnings.simplefilter("ignore")
from discrete_table import NAMES, plant  # noqa: E402

from lmi_suspension.lti import GeneralizedPlant, hinfnorm, lft, tustin, tustin_image  # noqa: E402
from lmi_suspension.synthesis import HinfsynOptions, hinfsyn  # noqa: E402
from lmi_suspension.synthesis.constraints import HinfBound  # noqa: E402
from lmi_suspension.synthesis.hinfsyn import (  # noqa: E402
    _hinfsyn_lmi,
    _undo_loop_shift,
    _without_d22,
)
from lmi_suspension.synthesis.multiobjective import _OUTPUT_FEEDBACK, _synthesise  # noqa: E402


def direct(G, relax):
    res = _synthesise(_without_d22(G), HinfBound(), (), HinfsynOptions(), None,
                      _OUTPUT_FEEDBACK, time.perf_counter(), level_relax=relax)
    return _undo_loop_shift(res.K, G.D22), np.isfinite(res.objective_lmi)


def image(G, opts, pole_cap=None):
    Gc = GeneralizedPlant.from_statespace(tustin_image(G.sys), G.ny, G.nu)
    if pole_cap is None:
        r = hinfsyn(Gc, G.ny, G.nu, options=opts)
    else:
        r = _hinfsyn_lmi(Gc, opts, time.perf_counter(), pole_cap=pole_cap)
    return tustin(r.K, G.dt), r.gamma_lower is not None


def main():
    dt = float(sys.argv[1]) if len(sys.argv) > 1 else 0.01
    names = sys.argv[2:] or NAMES
    routes = ["direct 5e-4", "direct 2e-5", "msyn continuous", "image capped 2e-5",
              "image capped 5e-5", "image uncapped 5e-5", "image fixed 5e-5", "hinfsyn"]
    print(f"Tustin images at dt = {dt} s: certified γ / continuous optimum - 1, seconds, "
          "L = a lower bound came back\n")
    print("| problem | " + " | ".join(routes) + " |")
    print("|---" * (len(routes) + 1) + "|")
    for name in names:
        P = plant(name)
        lower = hinfsyn(P, P.ny, P.nu).gamma_lower
        Pd = control.sample_system(P.sys, dt, method="tustin")
        G = GeneralizedPlant.from_statespace(Pd, P.ny, P.nu, discrete=True)
        cells = []
        for route in routes:
            t = time.perf_counter()
            try:
                if route.startswith("direct"):
                    K, low = direct(G, float(route.split()[1]))
                elif route == "msyn continuous":
                    res = _synthesise(_without_d22(P), HinfBound(), (), HinfsynOptions(),
                                      None, _OUTPUT_FEEDBACK, t, level_relax=5e-4)
                    K, low = res.K, np.isfinite(res.objective_lmi)
                elif route.startswith("image capped"):
                    K, low = image(G, HinfsynOptions(gamma_relax=float(route.split()[2])))
                elif route == "image uncapped 5e-5":
                    K, low = image(G, HinfsynOptions(gamma_relax=5e-5), pole_cap=np.inf)
                elif route == "image fixed 5e-5":
                    _, low0 = image(G, HinfsynOptions())
                    Gc = GeneralizedPlant.from_statespace(tustin_image(G.sys), G.ny, G.nu)
                    opt = hinfsyn(Gc, G.ny, G.nu).gamma_lower
                    K, low = image(G, replace(HinfsynOptions(), gamma=opt * (1 + 5e-5)))
                    low = low0
                else:
                    r = hinfsyn(Pd, P.ny, P.nu)
                    K, low = r.K, r.gamma_lower is not None
                plant_ = P if route == "msyn continuous" else G
                g = hinfnorm(lft(plant_, K))[0]
                cells.append(f"{g / lower - 1:+.1e} {time.perf_counter() - t:.1f}s"
                             f"{' L' if low else ''}")
            except Exception as exc:
                cells.append(f"{type(exc).__name__} {time.perf_counter() - t:.1f}s")
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
