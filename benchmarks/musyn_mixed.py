"""Mixed µ-synthesis on the two-mass plant, the stiffness oscillator and the seat over m3
and k1 (issue 64, items 2 and 3): µ upper and lower bound, controller order, seconds,
peak memory, stop reason.

``python benchmarks/musyn_mixed.py two_mass complexify=True`` -- the first argument
the problem (``two_mass``: :func:`~lmi_suspension.examples.uncertain_two_mass`,
``musyn(P, 1, 1)`` on the default grid; ``oscillator``:
:func:`~lmi_suspension.examples.stiffness_oscillator` on ``bench_dgk.py``'s 40-point
grid without the D-scale search; ``seat``: the seat over m3 and k1 of
``bench_dgk.py``, ``seat_augmented_plant(SeatDesignOptions(include_paper=False))`` on
``DEFAULT_OMEGA`` with :data:`~lmi_suspension.seat.design.MIXED_MUSYN`, i.e.
``replace(DEFAULT_MUSYN, max_iter=6, patience=2, reduce_order="auto")``: ``seat`` and
``seat complexify=True``; ``seat reduce_order=None`` for the full order), the others
``MusynOptions`` keywords (for ``seat``, these three included).  For ``oscillator`` and
``seat`` the returned loop (and a reduced one's full-order loop) is certified again by
AB13MD's scalings on ``CHECK`` (:func:`musyn_vs_dkpy.certified_mu`, independent of
``musyn``; its time not counted).  ``--orders`` (``oscillator``, ``seat``): the run at
full order (``reduce_order=None``), then for each lower order the balanced truncation of
its controller: mixed µ on the result's dense grid (upper, lower) and by AB13MD's
scalings on 800 frequencies over 1e-2..3e4 rad/s (independent of ``musyn``), relative to
the full order's, and the closed loop's largest pole real part
(:func:`musyn_orders.tradeoff`; the seconds printed then include the table).
``--ratio=N``: the mixed route and the complexified run, ``N`` rounds alternating
which goes first, CPU of each ``musyn`` call and the ratio of the medians (issue 64's
time targets; :func:`ratio`), each call's time split by phase (:func:`phases`), and the
floor under the ratio that the mixed route's complexified run and K-steps set.
``--store=PATH``: the full-order controller written
to ``PATH`` (``lmi_suspension.io.save_controller``, how it was made in its metadata;
``tests/data/seat_m3_k1_mixed_K.json``).  Run it under
``ulimit -v 4000000`` and ``timeout``: D-G-K with 10 G poles on the two-mass plant
(``complex_candidate=None, max_gfit_poles=10``) filled a 4 GB address space at its
second K-step (2026-12-02).
"""

import ast
import logging
from dataclasses import replace
import os
import resource
import sys
import time

import control
import numpy as np

from lmi_suspension.examples import stiffness_oscillator, uncertain_two_mass
from lmi_suspension.mu import MusynOptions, musyn

#: the grid of ``--orders``'s independent certificate, rad/s: the seat's design grid
#: (0.1-3162 rad/s) and its dense grid's extensions, a decade beyond each end
CHECK = np.logspace(-2, 4.5, 800)


def problem(name: str, kw: dict):
    """``(P, nmeas, ncon, blk, omega, options)`` of ``oscillator`` and ``seat``."""
    if name == "oscillator":
        ex = stiffness_oscillator()
        return (ex.P, ex.nmeas, ex.ncon, ex.blk, np.logspace(-2, 1.5, 40),
                MusynOptions(max_iter=8, dscale_search=0, **kw))
    if name == "seat":
        from lmi_suspension.seat.augmented import SeatDesignOptions, seat_augmented_plant
        from lmi_suspension.seat.design import DEFAULT_OMEGA, MIXED_MUSYN

        aug = seat_augmented_plant(SeatDesignOptions(include_paper=False))
        return (aug.P, aug.nmeas, aug.ncon, aug.blk, DEFAULT_OMEGA,
                replace(MIXED_MUSYN, **kw))
    raise SystemExit(f"--orders takes oscillator or seat, not {name}")


def _cpu() -> float:
    """CPU seconds of this process and its finished children (AB13MD's)."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def phases(res) -> str:
    """Where a ``musyn`` call's wall time went, from its own records: the complexified
    run inside a mixed route, the K-steps, D/G steps and fits of its iterations, and the
    rest (an abandoned start from the complexified controller, the order search, the
    dense certificate, the interval bound)."""
    k = sum(h.seconds_k for h in res.history)
    d = sum(h.seconds_d for h in res.history)
    f = sum(h.seconds_fit for h in res.history)
    cx = res.complex_run.seconds if res.complex_run is not None else 0.0
    head = f"complexified run {cx:.1f} s, " if res.complex_run is not None else ""
    return (f"{head}K-steps {k:.1f} s, D/G steps {d:.1f} s, fits {f:.1f} s, rest "
            f"{res.seconds - cx - k - d - f:.1f} s (wall)")


def ratio(name: str, kw: dict, rounds: int) -> None:
    """``--ratio=N``: the mixed route (the problem's options) and the complexified run
    (``complexify=True`` besides) in ``N`` rounds, their order alternating; CPU seconds
    of each ``musyn`` call, µ, and the ratio mixed / complexified per round and of the
    medians (issue 64 asks at most 1.5)."""
    def run(complexify: bool):
        extra = dict(kw, complexify=True) if complexify else kw
        if name == "two_mass":
            P, nmeas, ncon, blk, omega = uncertain_two_mass(), 1, 1, None, None
            options = MusynOptions(**extra)
        else:
            P, nmeas, ncon, blk, omega, options = problem(name, extra)
        c0 = _cpu()
        res = musyn(P, nmeas, ncon, blk, omega=omega, options=options)
        return _cpu() - c0, res

    rows = []
    for r in range(rounds):
        order = (True, False) if r % 2 == 0 else (False, True)
        got = {c: run(c) for c in order}
        rows.append((got[False][0], got[True][0]))
        for c in order:
            cpu, res = got[c]
            print(f"round {r + 1} {'complexified' if c else 'mixed       '}: CPU {cpu:5.1f} s, "
                  f"µ {res.mu_peak:.4f} (lower {res.mu_lower_peak:.4f}), {res.K.nstates} "
                  f"states; {phases(res)}", flush=True)
        mixed_res, cx_res = got[False][1], got[True][1]
        if mixed_res.complex_run is not None:
            k_steps = sum(h.seconds_k for h in mixed_res.history)
            print(f"round {r + 1} floor: (the mixed route's complexified run + its D-G-K "
                  f"K-steps) / the complexified call = "
                  f"{(mixed_res.complex_run.seconds + k_steps) / cx_res.seconds:.2f} (wall)")
    mixed, cx = (np.array(v) for v in zip(*rows))
    print(f"{name} {kw}: median CPU mixed {np.median(mixed):.1f} s, complexified "
          f"{np.median(cx):.1f} s, ratio of medians {np.median(mixed) / np.median(cx):.2f} "
          f"(per round {', '.join(f'{m / c:.2f}' for m, c in zip(mixed, cx))})")


if __name__ == "__main__":
    logging.basicConfig(level=logging.INFO, format="%(relativeCreated)7.0f %(message)s")
    for name in ("lmi_suspension.synthesis", "lmi_suspension.lti", "lmi_suspension.mu.dfit",
                 "lmi_suspension.mu.dsearch", "lmi_suspension.mu.bounds",
                 "lmi_suspension.mu.gfit"):
        logging.getLogger(name).setLevel(logging.WARNING)
    orders = "--orders" in sys.argv
    store = next((a.split("=", 1)[1] for a in sys.argv if a.startswith("--store=")), None)
    rounds = next((int(a.split("=", 1)[1]) for a in sys.argv if a.startswith("--ratio=")),
                  None)
    args = [a for a in sys.argv[1:] if a != "--orders" and not a.startswith(("--store=",
                                                                            "--ratio="))]
    problem_name = args[0] if args else "two_mass"
    kw = {k.strip(): ast.literal_eval(v) for k, v in
          (item.split("=", 1) for item in args[1:])}
    if rounds is not None:
        logging.getLogger("lmi_suspension").setLevel(logging.WARNING)
        ratio(problem_name, kw, rounds)
        sys.exit(0)
    t0, c0 = time.perf_counter(), os.times()
    if orders:
        from musyn_orders import tradeoff

        P, nmeas, ncon, blk, omega, options = problem(problem_name, kw)
        print(f"{problem_name} {kw}, full order (reduce_order=None), then each order:")
        res = tradeoff(control.ss(P), nmeas, ncon, blk, omega, options, None, check=CHECK)
    elif problem_name in ("oscillator", "seat"):
        P, nmeas, ncon, blk, omega, options = problem(problem_name, kw)
        res = musyn(P, nmeas, ncon, blk, omega=omega, options=options)
    else:
        res = musyn(uncertain_two_mass(), 1, 1, options=MusynOptions(**kw))
    seconds = time.perf_counter() - t0
    c1 = os.times()  # CPU of this process and its finished children (AB13MD's)
    cpu = sum(getattr(c1, k) - getattr(c0, k) for k in
              ("user", "system", "children_user", "children_system"))
    print(f"{problem_name} {kw}: µ {res.mu_peak:.4f} (lower {res.mu_lower_peak:.4f}), "
          f"K order {res.K.nstates}, {seconds:.1f} s (CPU {cpu:.1f} s), best iteration "
          f"{res.best_iteration}, "
          f"peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB")
    print("stop:", res.stop_reason)
    print(f"all-frequency bound {res.mu_bound:.4f}; closed loop's largest pole real part "
          f"{np.max(np.real(np.linalg.eigvals(np.asarray(res.CL.A)))):.3g}")
    if res.reduced_from is not None:
        print(f"reduced from {res.reduced_from} states (full-order µ {res.mu_peak_full:.4f})")
    if problem_name in ("oscillator", "seat"):
        from musyn_vs_dkpy import certified_mu

        from lmi_suspension.mu.bounds import _ab13md_blocks
        from lmi_suspension.umodel.blocks import BlockStructure

        nblock, itype = _ab13md_blocks(BlockStructure.from_blk(blk))
        grid = np.append(CHECK, res.peak_omega)
        for name, K in (("returned", res.K), ("full-order", res.K_full)):
            if K is not None:
                ab = certified_mu(control.ss(P), K, nmeas, ncon, nblock=nblock, itype=itype,
                                  omega=grid)
                print(f"{name} controller ({K.nstates} states): AB13MD's µ {ab:.4f} on "
                      f"CHECK and the peak frequency")
    if store is not None:
        import datetime
        import subprocess

        from lmi_suspension.io import save_controller

        K_full = res.K if res.K_full is None else res.K_full
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                                text=True).stdout.strip()
        save_controller(store, K_full, metadata={
            "made": f"python benchmarks/musyn_mixed.py {' '.join(sys.argv[1:])} (commit "
                    f"{commit}, {datetime.date.today()}, OpenBLAS "
                    f"{os.environ.get('OPENBLAS_CORETYPE', 'native kernel')}): the "
                    "full-order controller",
            "mu_peak_full": res.mu_peak if res.K_full is None else res.mu_peak_full,
            "problem": problem_name, "options": repr(kw)})
        print(f"full-order controller ({K_full.nstates} states) written to {store}")
    if res.complex_run is not None:
        print(f"complexified run: {res.complex_run.seconds:.1f} s (wall), complex µ per iterate "
              f"{[round(h.mu_peak, 4) for h in res.complex_run.history]}, its mixed µ "
              f"{res.complex_run.mu_peak}")
        if res.complex_run.start_history:
            print(f"D-G-K from the complexified controller, abandoned: µ per iterate "
                  f"{[round(h.mu_peak, 4) for h in res.complex_run.start_history]}")
    for h in res.history:
        print(h.index, h.stage, f"µ {h.mu_peak:.4f}", f"K {h.controller_order}",
              f"fits {h.dfit_orders}", f"[K {h.seconds_k:.1f} s, D {h.seconds_d:.1f} s, "
              f"fit {h.seconds_fit:.1f} s]")
