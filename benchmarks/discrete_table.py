"""Discrete-time H∞ synthesis on Tustin images of the COMPleib subset, as a markdown table
(issue 63): the continuous LMI optimum (the discrete optimum of a Tustin image is the
same number), this project's discrete LMI and SB10DD routes, each certified by the
discrete ``hinfnorm`` of ``lft(P, K)``, and what python-control's ``hinfsyn`` (SLICOT
SB10AD, continuous only) does with the discrete plant, in a child process stopped after
``LIMIT`` seconds.

Run: ``python benchmarks/discrete_table.py [dt] [problem ...]`` (default 0.01 s and the
six plants of tests/test_discrete.py).
"""
import multiprocessing as mp
import sys
import time
import warnings

import control

warnings.simplefilter("ignore")
from lmi_suspension.examples import compleib  # noqa: E402
from lmi_suspension.lti import hinfnorm, lft  # noqa: E402
from lmi_suspension.synthesis import hinfsyn  # noqa: E402

LIMIT = 30.0


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


def main():
    dt = float(sys.argv[1]) if len(sys.argv) > 1 else 0.01
    names = sys.argv[2:] or ["AC4", "HE1", "REA1", "AC3", "DIS1", "NN2"]
    print(f"Tustin images at dt = {dt} s; γ relative to the continuous LMI optimum\n")
    print("| problem | n | continuous optimum | discrete LMI certified (lower) | s | "
          "SB10DD scan certified | s | python-control hinfsyn on the discrete plant |")
    print("|---|---|---|---|---|---|---|---|")
    for name in names:
        P = compleib(name)
        Pd = control.sample_system(P.sys, dt, method="tustin")
        lower = hinfsyn(P, P.ny, P.nu).gamma_lower
        t = time.time()
        r = hinfsyn(Pd, P.ny, P.nu)
        t_lmi = time.time() - t
        low = "—" if r.gamma_lower is None else f"{r.gamma_lower:.6g}"
        lmi = f"{r.gamma:.6g} ({r.gamma / lower - 1:+.1e}) ({low}) | {t_lmi:.2f}"
        t = time.time()
        try:
            q = hinfsyn(Pd, P.ny, P.nu, method="riccati")
            ric = f"{q.gamma:.6g} ({q.gamma / lower - 1:+.1e}) | {time.time() - t:.2f}"
        except Exception as exc:
            ric = f"{type(exc).__name__} | {time.time() - t:.2f}"
        print(f"| {name} | {P.nstates} | {lower:.6g} | {lmi} | {ric} | "
              f"{python_control_on(Pd, P.ny, P.nu)} |", flush=True)


if __name__ == "__main__":
    main()
