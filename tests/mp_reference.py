"""High-precision reference evaluations for tests (mpmath, a test-only dependency)."""

import mpmath as mp
import numpy as np


def freqresp_mp(sys, omega, dps: int = 40) -> np.ndarray:
    """``G(jω)`` (n_out × n_in × n_freq) with ``C (jωI - A)⁻¹ B`` solved in ``dps``-digit
    arithmetic: a reference that does not share the double-precision evaluation it
    checks (only the final rounding to complex128).  For a discrete-time ``sys``,
    ``G(exp(jω dt))``."""
    if getattr(sys, "dt", 0):
        return freqresp_mp_at(sys, np.exp(1j * np.asarray(omega, dtype=float) * sys.dt), dps)
    return freqresp_mp_at(sys, 1j * np.asarray(omega, dtype=float), dps)


def freqresp_mp_at(sys, points, dps: int = 40) -> np.ndarray:
    """``C (zI - A)⁻¹ B + D`` at the complex ``points``, in ``dps``-digit arithmetic."""
    omega = np.asarray(points, dtype=complex)
    with mp.workdps(dps):
        A = mp.matrix(np.asarray(sys.A).tolist())
        C = mp.matrix(np.asarray(sys.C).tolist())
        B, D = np.asarray(sys.B), np.asarray(sys.D)
        out = np.empty((C.rows, B.shape[1], len(omega)), dtype=complex)
        for k, w in enumerate(omega):
            M = mp.mpc(w.real, w.imag) * mp.eye(A.rows) - A
            for j in range(B.shape[1]):
                col = C * mp.lu_solve(M, mp.matrix(B[:, j].tolist()))
                out[:, j, k] = [complex(col[i]) for i in range(C.rows)]
    return out + D[:, :, None]
