"""The seat scheduled on the occupant mass (issue 62, item 2, the convex route) against
today's robust controller and the single-seat design, on the same seats.

Run: ``python benchmarks/scheduled_seat.py [--quick] [--design] [--seed N]`` from the
repository root, with ``MPLBACKEND=Agg OPENBLAS_NUM_THREADS=1``.  Prints one markdown
table.  The controllers:

- ``mu_refined.json`` (the single-seat design), ``mu_occupants.json`` (the exported
  robust one): fixed controllers;
- the scheduled controller ``lpv_scheduled.json`` (``--design``: designed anew by
  :func:`~lmi_suspension.seat.scheduled_lpv.design_lpv_seat_controller`, several
  minutes), evaluated at each seat's true mass and at the mass measured ±5 kg (clipped
  to the design interval).

The figures, each by a route that takes no part in any design:

- nominal: the nominal seat's largest peak ``|z̈3|`` over 0, 5, ..., 25 ms, unclipped
  (closed form in the frequency domain, :class:`~lmi_suspension.seat.refine.BumpResponse`),
  over its clairvoyant limit (:func:`~lmi_suspension.seat.limit.bump_limit`);
- worst: the largest peak over its own limit on a seeded Latin hypercube of 40 seats
  (``OccupantSet``: m3 30-70 kg, k1..k3 and c1..c3 ±20 %; 8 with ``--quick``) at 0 and
  25 ms, the worst re-simulated in the time domain (exact delay) and the larger figure
  kept; the largest commanded ``|u|`` over the same runs; the loops that are unstable
  at the exact delay (Nyquist count, ``closed_loop_stable``);
- RS µ: the mixed µ of robust stability over k1..c3 (real) and the delay cover at each
  design mass, upper bound over every frequency
  (:func:`~lmi_suspension.seat.scheduled_lpv.robust_stability_mu`); below 1 certifies
  stability there for every element value of the set and every delay of the cover;
- fastest pole: the largest controller pole magnitude over the masses checked (a 1 kHz
  loop needs it below 1900 rad/s, ``seat/sampled.py``).
"""

import argparse
import time

import numpy as np

from lmi_suspension.io import load_controller
from lmi_suspension.seat.occupants import OccupantSet, occupant_samples
from lmi_suspension.seat.loop import REFINE_DELAYS, BumpResponse
from lmi_suspension.seat.sampled import fastest_pole
from lmi_suspension.seat.scheduled_lpv import (
    SCHEDULED_GRID,
    SHIPPED_SCHEDULED,
    design_lpv_seat_controller,
    load_scheduled_seat,
    named_controller,
    robust_stability_mu,
    save_scheduled_seat,
)
from lmi_suspension.seat.simulate import closed_loop_stable, simulate

DATA = SHIPPED_SCHEDULED.parent
MASSES = tuple(float(m) for m in SCHEDULED_GRID)
EDGE_DELAYS = (0.0, 0.025)


def evaluate(K_of, samples, errors):
    """Figures of a controller ``K_of(m3) -> StateSpace`` over the samples."""
    road = samples.road
    nom = samples.occupants.nominal
    Kn = K_of(nom.m3)
    zn, un, _ = BumpResponse(road=road, delays=REFINE_DELAYS, params=nom).peaks(Kn)
    stable_nom = all(closed_loop_stable(Kn, d, nom) for d in REFINE_DELAYS)
    out = {"nominal": float(np.max(zn)) / samples.nominal_limit if stable_nom else np.inf}
    u_max, unstable, runs = float(np.max(un)), 0, 0
    lo, hi = samples.occupants.m3
    for e in errors:
        worst, where = -np.inf, None
        for i, p in enumerate(samples.performance):
            K = K_of(float(np.clip(p.m3 + e, lo, hi)))
            ok = [closed_loop_stable(K, d, p) for d in EDGE_DELAYS]
            runs += len(ok)
            unstable += len(ok) - sum(ok)
            if not all(ok):
                worst = np.inf
                continue
            z, u, _ = BumpResponse(road=road, delays=EDGE_DELAYS, params=p).peaks(K)
            u_max = max(u_max, float(np.max(u)))
            j = int(np.argmax(z))
            r = float(z[j]) / samples.limits[i]
            if r > worst:
                worst, where = r, (K, p, EDGE_DELAYS[j], samples.limits[i])
        if where is not None and np.isfinite(worst):
            K, p, d, lim = where
            met = simulate(K, road, delay=d, params=p, u_max=np.inf).metrics()
            worst = max(worst, met.peak_z3dd / lim)
            u_max = max(u_max, met.peak_u_command)
        out[f"worst{e:+g}"] = worst
    out["u_max"], out["unstable"], out["runs"] = u_max, unstable, runs
    return out


def rs_mu(K_of, masses, rng, omega):
    return [robust_stability_mu(K_of(m), m, rng=rng, omega=omega).sup for m in masses]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--design", action="store_true")
    ap.add_argument("--seed", type=int, default=62)
    ap.add_argument("--file", default=str(SHIPPED_SCHEDULED))
    ap.add_argument("--no-mu", action="store_true", help="leave out the RS µ column")
    args = ap.parse_args()
    n = 8 if args.quick else 40
    masses = (30.0, 42.0, 70.0) if args.quick else MASSES
    omega = np.logspace(-1.0, 3.5, 60 if args.quick else 120)
    t0 = time.perf_counter()
    samples = occupant_samples(OccupantSet(), rng=np.random.default_rng(args.seed),
                               n_stability=1, n_performance=n)
    t_samples = time.perf_counter() - t0
    if args.design:
        t = time.perf_counter()
        d = design_lpv_seat_controller()
        seconds = time.perf_counter() - t
        save_scheduled_seat(args.file, d)
    Ks, meta = load_scheduled_seat(args.file)
    seconds = meta.get("design_seconds", float("nan")) if not args.design else seconds
    rows = []
    fixed = [("`mu_refined.json` (single seat)", DATA / "mu_refined.json"),
             ("`mu_occupants.json` (exported, robust)", DATA / "mu_occupants.json")]
    for label, path in fixed:
        K, m = load_controller(path)
        rows.append((label, lambda m3, K=K: K, (0,), m.get("design_seconds")))
    rows.append((f"`{SHIPPED_SCHEDULED.name}` (scheduled on m3, lpvsyn D-K)",
                 lambda m3: named_controller(Ks, m3), (0, -5, 5), seconds))
    print(f"seats: {n} (Latin hypercube, seed {args.seed}), limits {t_samples:.0f} s; "
          f"nominal limit {samples.nominal_limit:.4f} m/s²\n")
    print("| controller | nominal / limit | worst / own limit (true m3) | worst, m3 measured "
          "-5 / +5 kg | max commanded \\|u\\| | unstable | RS µ (sup) at m3 = "
          f"{', '.join(f'{m:g}' for m in masses)} | fastest pole | design time |")
    print("|---|---|---|---|---|---|---|---|---|")
    for label, K_of, errors, secs in rows:
        t = time.perf_counter()
        f = evaluate(K_of, samples, errors)
        mu = [] if args.no_mu else rs_mu(K_of, masses, np.random.default_rng(0), omega)
        pole = max(fastest_pole(K_of(m)) for m in np.linspace(30.0, 70.0, 17))
        err = (f"{f['worst-5']:.3f} / {f['worst+5']:.3f}" if "worst-5" in f else "—")
        sec = "—" if secs is None or not np.isfinite(secs) else f"{secs:.0f} s"
        print(f"| {label} | {f['nominal']:.3f} | {f['worst+0']:.3f} | {err} | "
              f"{f['u_max']:.0f} N | {f['unstable']} of {f['runs']} | "
              f"{', '.join(f'{v:.3f}' for v in mu)} | {pole:.0f} rad/s | {sec} |",
              flush=True)
        _ = time.perf_counter() - t


if __name__ == "__main__":
    main()
