"""Where the occupant route's comfort goes (issue 62, item 1): designs over the occupant
set with one group of parameters held at its nominal value in turn.

Run: ``python benchmarks/occupant_groups.py [--quick] [--rows a,b,...] [--json FILE]``
(from the repository root, with ``MPLBACKEND=Agg OPENBLAS_NUM_THREADS=1 PYTHONPATH=.``).
Prints a markdown table, one row per set:

- (a) the occupant mass ``m3`` fixed (43.3 kg, the nominal seat's);
- (b) the seat spring and damper ``k1``, ``c1`` fixed; (b') ``k1`` alone (the spring a
  seat can measure at rest by its static deflection under a known load);
- (c) the body's ``k2``, ``c2``, ``k3``, ``c3`` fixed;
- (d) the delay range fixed: 0-1 ms (the route's delay cover refuses a range of zero
  width, ``d_max must be positive``; 1 ms is the smallest cover asked for here), the road
  requirements met at 0 and 1 ms;
- (e) the whole set (30-70 kg, springs and dampers ±20 %, 0-25 ms): today's route;

each designed by :func:`~lmi_suspension.seat.multimodel.refine_for_occupants` as the
occupant route does (``RefineOptions(mu_performance=False, occupants=set)``, corners
``m3``, ``k1``) from the same start (``seat/data/mu_refined.json``, tuned for the nominal
seat) with the same budget (``--quick``: 30 SLSQP iterations, one round, 5 search samples;
default: ``MAX_ITER`` = 40 iterations, ``ROUNDS`` = 1 round, ``N_SEARCH`` = 10 samples).
The budget is the route's default cut down: the shipped ``mu_occupants.json`` took about
49 min of design in four refinements, and one round of 30 iterations on the whole set
took 474 s (``--quick --rows e``, 2026-12-02, a 2-core machine at load 4-5), so a row of
the route's defaults (3 rounds of 600 iterations) would take hours.  With one round the
route refines on its first seats only (the nominal seat and the corners of ``m3``,
``k1`` that the row's set has) and its search adds none: every row is the same local
refinement from the same start, on the seats its set offers.  The shipped design and the
start are measured too (on the whole set's samples).

Each design is measured on its own set by
:func:`~lmi_suspension.seat.occupants.certify_occupants`: its samples are drawn by the
same seeded generator for every row (``SAMPLE_SEED``), so a row's seats are the whole
set's seats with the row's fixed parameters at their nominal value; each seat's peak
``|z̈3|`` on the bump is divided by its own clairvoyant limit.  Columns: the nominal
seat's ratio (worst over the delays), the worst ratio over the performance samples and
delays, the largest commanded ``|u|`` and ``|x1|`` there, unstable stability samples,
mixed µ of robust stability over the row's set (:func:`~.occupants.occupant_mu`, over
every frequency; not with ``--quick``), whether the refinement met its requirements at
its seats, and the design time.
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

from lmi_suspension.seat.multimodel import SHIPPED_OCCUPANTS, refine_for_occupants
from lmi_suspension.seat.occupant_subset import OccupantSubset
from lmi_suspension.seat.occupants import certify_occupants, occupant_mu, occupant_samples
from lmi_suspension.seat.loop import REFINE_DELAYS
from lmi_suspension.seat.refine import RefineOptions, load_refined

#: the sets of the table: (key, label, OccupantSubset keywords, road-requirement delays)
ROWS = (
    ("a", "(a) m3 fixed", {"fixed": ("m3",)}, REFINE_DELAYS),
    ("b", "(b) k1, c1 fixed", {"fixed": ("k1", "c1")}, REFINE_DELAYS),
    ("b1", "(b') k1 fixed", {"fixed": ("k1",)}, REFINE_DELAYS),
    ("c", "(c) k2, c2, k3, c3 fixed", {"fixed": ("k2", "c2", "k3", "c3")}, REFINE_DELAYS),
    ("d", "(d) delay 0-1 ms", {"delay": (0.0, 0.001)}, (0.0, 0.001)),
    ("e", "(e) whole set", {}, REFINE_DELAYS),
    ("f", "(f) m3, k1, c1 fixed (both measurable)", {"fixed": ("m3", "k1", "c1")},
     REFINE_DELAYS),
)
SAMPLE_SEED = 62          # the certificate's samples, the same for every row
DESIGN_SEED = 7           # the route's search samples (as the shipped design's)
MAX_ITER, ROUNDS, N_SEARCH = 40, 1, 10
N_STABILITY, N_PERFORMANCE = 200, 24


def measure(K, occupants, delays, *, n_stability, n_performance, mu):
    """The row's figures of ``K`` on ``occupants``' samples (seeded by SAMPLE_SEED)."""
    samples = occupant_samples(occupants, rng=np.random.default_rng(SAMPLE_SEED),
                               n_stability=n_stability, n_performance=n_performance)
    check = certify_occupants(K, samples, delays=delays)
    rs = (occupant_mu(K, occupants, rng=np.random.default_rng(0)).rs_sup
          if mu else math.nan)
    return {"nominal_ratio": check.nominal_ratio, "worst_ratio": check.worst_ratio,
            "u_max": check.u_max, "x1_max": check.x1_max, "unstable": check.unstable,
            "n_stability": check.n_stability, "rs_mu": rs}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true",
                    help="30 iterations, 1 round, 5 search samples; 8 performance and "
                         "50 stability samples; no mixed µ")
    ap.add_argument("--rows", default="a,b,b1,c,d,e,f,shipped,start")
    ap.add_argument("--json", default=None, help="also write the rows to this file")
    args = ap.parse_args(argv)
    if args.quick:
        budget = {"max_iter": 30, "rounds": 1, "n_search": 5}
        sizes = {"n_stability": 50, "n_performance": 8, "mu": False}
    else:
        budget = {"max_iter": MAX_ITER, "rounds": ROUNDS, "n_search": N_SEARCH}
        sizes = {"n_stability": N_STABILITY, "n_performance": N_PERFORMANCE, "mu": True}
    wanted = args.rows.split(",")
    K0 = load_refined()[0]
    rows = []
    for key, label, kw, delays in ROWS:
        if key not in wanted:
            continue
        occupants = OccupantSubset(**kw)
        opts = RefineOptions(mu_performance=False, occupants=occupants, delays=delays,
                             max_iter=budget["max_iter"])
        t0 = time.perf_counter()
        d = refine_for_occupants(K0, occupants, opts, rng=np.random.default_rng(DESIGN_SEED),
                                 rounds=budget["rounds"], n_search=budget["n_search"])
        seconds = time.perf_counter() - t0
        fig = measure(d.K, occupants, delays, **sizes)
        rows.append({"row": label, "seconds": seconds, "met": bool(d.design.met),
                     "rounds": len(d.rounds), "states": d.K.nstates, **fig})
        print(f"<!-- {label}: {seconds:.0f} s, {fig} -->", flush=True)
    for key, label, path in (("shipped", "shipped mu_occupants.json (whole set)",
                              SHIPPED_OCCUPANTS), ("start", "start mu_refined.json", None)):
        if key in wanted:
            K = load_refined(path)[0]
            fig = measure(K, OccupantSubset(), REFINE_DELAYS, **sizes)
            rows.append({"row": label, "seconds": math.nan, "met": None, "rounds": 0,
                         "states": K.nstates, **fig})
    print(table(rows, budget, sizes))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"budget": budget, "sizes": sizes, "rows": rows}, f, indent=1)


def table(rows, budget, sizes) -> str:
    head = ("| set | nominal / limit | worst / own limit | max \\|u\\| (N) | max \\|x1\\| (m) "
            "| unstable | mixed µ RS | met | design time |\n|---|---|---|---|---|---|---|---|---|")
    lines = [head]
    for r in rows:
        mu = "–" if math.isnan(r["rs_mu"]) else f"{r['rs_mu']:.3f}"
        met = "–" if r["met"] is None else ("yes" if r["met"] else "no")
        secs = "–" if math.isnan(r["seconds"]) else f"{r['seconds']:.0f} s"
        lines.append(f"| {r['row']} | {r['nominal_ratio']:.2f} | {r['worst_ratio']:.2f} | "
                     f"{r['u_max']:.0f} | {r['x1_max']:.4f} | {r['unstable']} of "
                     f"{r['n_stability']} | {mu} | {met} | {secs} |")
    lines.append(f"\nBudget per design: {budget}; samples: {sizes}; sample seed "
                 f"{SAMPLE_SEED}, design seed {DESIGN_SEED}.")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
