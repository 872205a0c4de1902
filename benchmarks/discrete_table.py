"""Discrete-time H∞ synthesis on Tustin images, as a markdown table (issue 63): the
continuous LMI optimum (the discrete optimum of a Tustin image is the same number),
``hinfsyn``'s discrete LMI (posed on the plant's bilinear image), the discrete LMI posed on
the discrete data directly (``msyn`` with one H∞ objective), SB10DD's scan, each certified
by the discrete ``hinfnorm`` of ``lft(P, K)``, and what python-control's ``hinfsyn``
(SLICOT SB10AD, continuous only) does with the discrete plant, in a child process stopped
after ``LIMIT`` seconds.

Run: ``python benchmarks/discrete_table.py [dt] [problem ...]`` (default 0.01 s, the six
COMPleib plants and the two plants of our own of tests/test_discrete.py: ``scalar``, the
unstable 1/(s - 1) of hinfsyn's docstring, and ``random5``, a seeded random 5-state plant).
"""
import multiprocessing as mp
import sys
import time
import warnings

import control
import numpy as np

warnings.simplefilter("ignore")
from lmi_suspension.examples import compleib  # noqa: E402
from lmi_suspension.lti import GeneralizedPlant, hinfnorm, lft  # noqa: E402
from lmi_suspension.synthesis import hinfsyn  # noqa: E402
from lmi_suspension.synthesis.constraints import HinfBound  # noqa: E402
from lmi_suspension.synthesis.hinfsyn import _undo_loop_shift, _without_d22  # noqa: E402
from lmi_suspension.synthesis.multiobjective import msyn  # noqa: E402

LIMIT = 30.0
NAMES = ["AC4", "HE1", "REA1", "AC3", "DIS1", "NN2", "scalar", "random5"]


def plant(name):
    if name == "scalar":
        return GeneralizedPlant.from_matrices(A=[[1.0]], B1=[[1.0, 0.0]], B2=[[1.0]],
                                              C1=[[1.0], [0.0]], C2=[[1.0]],
                                              D12=[[0.0], [1.0]], D21=[[0.0, 1.0]])
    if name == "random5":
        from lmi_suspension.synthesis.examples import random_plant
        return random_plant(5, 2, 1, 2, 1, rng=np.random.default_rng(63))
    return compleib(name)


def _python_control(Pd, ny, nu, queue):
    t = time.time()
    try:
        K, _, gam, _ = control.hinfsyn(Pd, ny, nu)
        queue.put(("ok", float(gam), K.A, K.B, K.C, K.D, time.time() - t))
    except Exception as exc:  # python-control's or slycot's own error, reported as is
        queue.put(("error", f"{type(exc).__name__}: {str(exc)[:60]}", time.time() - t))


def python_control_on(Pd, ny, nu):
    queue = mp.Queue()
    proc = mp.Process(target=_python_control, args=(Pd, ny, nu, queue))
    proc.start()
    proc.join(LIMIT)
    if proc.is_alive():
        proc.terminate()
        proc.join()
        return f"no return in {LIMIT:.0f} s"
    out = queue.get()
    if out[0] == "error":
        return f"{out[1]} ({out[2]:.2f} s)"
    _, gam, A, B, C, D, secs = out
    K = control.ss(A, B, C, D, Pd.dt)
    cert = hinfnorm(lft(Pd, K, ny, nu))[0]
    return f"reported {gam:.5g}, certified {cert:.5g} ({secs:.2f} s)"


def _rel(g, lower):
    return f"{g:.6g} ({g / lower - 1:+.1e})"


def main():
    dt = float(sys.argv[1]) if len(sys.argv) > 1 else 0.01
    names = sys.argv[2:] or NAMES
    print(f"Tustin images at dt = {dt} s; γ relative to the continuous LMI optimum\n")
    print("| problem | n | continuous optimum | hinfsyn: discrete LMI on the image, certified "
          "(lower bound) | s | closed-loop \\|z\\| nearest -1 | discrete LMI on the data (msyn), "
          "certified | s | SB10DD scan, certified | s | python-control hinfsyn on the "
          "discrete plant |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name in names:
        P = plant(name)
        Pd = control.sample_system(P.sys, dt, method="tustin")
        lower = hinfsyn(P, P.ny, P.nu).gamma_lower
        t = time.time()
        r = hinfsyn(Pd, P.ny, P.nu)
        t_lmi = time.time() - t
        low = "—" if r.gamma_lower is None else _rel(r.gamma_lower, lower)
        left = r.poles[r.poles.real < 0]  # the Nyquist side, where fast image modes go
        near = f"{np.max(np.abs(left)):.6f}" if left.size else "—"
        lmi = f"{_rel(r.gamma, lower)} ({low}) | {t_lmi:.2f} | {near}"
        G = GeneralizedPlant.from_statespace(Pd, P.ny, P.nu, discrete=True)
        t = time.time()
        try:
            m = msyn(_without_d22(G), P.ny, P.nu, HinfBound())
            g = hinfnorm(lft(G, _undo_loop_shift(m.K, G.D22)))[0]
            direct = f"{_rel(g, lower)} | {time.time() - t:.2f}"
        except Exception as exc:
            direct = f"{type(exc).__name__} | {time.time() - t:.2f}"
        t = time.time()
        try:
            q = hinfsyn(Pd, P.ny, P.nu, method="riccati")
            ric = f"{_rel(q.gamma, lower)} | {time.time() - t:.2f}"
        except Exception as exc:
            ric = f"{type(exc).__name__} | {time.time() - t:.2f}"
        print(f"| {name} | {P.nstates} | {lower:.6g} | {lmi} | {direct} | {ric} | "
              f"{python_control_on(Pd, P.ny, P.nu)} |", flush=True)


if __name__ == "__main__":
    main()
