"""Structural checks of a generalized plant before H∞ synthesis."""

from __future__ import annotations

import control
import numpy as np

from ..errors import AssumptionError, InfeasibleError
from ..lti.plant import GeneralizedPlant

__all__ = ["check_stabilizable", "check_riccati_assumptions", "PBH_TOL", "RANK_TOL"]

#: relative tolerance of the PBH rank tests (smallest singular value / matrix norm)
PBH_TOL = 1e-9
#: relative tolerance of the rank tests on D12, D21
RANK_TOL = 1e-10
#: relative distance to the imaginary axis below which an invariant zero counts as on it
AXIS_TOL = 1e-8


def _unstable_modes(A: np.ndarray, dt: float = 0.0) -> np.ndarray:
    ev = np.linalg.eigvals(A)
    if dt:
        return ev[np.abs(ev) >= 1.0 - 1e-12]
    return ev[ev.real >= -1e-12 * np.maximum(1.0, np.abs(ev))]


def check_stabilizable(P: GeneralizedPlant) -> None:
    """PBH tests: ``(A, B2)`` stabilisable and ``(C2, A)`` detectable (modes on or
    outside the unit circle for a discrete-time plant).

    Raises
    ------
    InfeasibleError
        Naming the unstable mode that the controls cannot move or the measurements
        cannot see; no controller stabilises such a plant.

    Examples
    --------
    >>> from lmi_suspension.lti import GeneralizedPlant
    >>> P = GeneralizedPlant.from_matrices(A=[[1.0, 0.0], [0.0, -1.0]], B1=[[1.0], [1.0]],
    ...     B2=[[0.0], [1.0]], C1=[[1.0, 1.0]], C2=[[1.0, 1.0]], D12=[[1.0]], D21=[[1.0]])
    >>> check_stabilizable(P)
    Traceback (most recent call last):
    ...
    lmi_suspension.errors.InfeasibleError: (A, B2) is not stabilisable: the unstable mode s = 1 is uncontrollable from the controls u
    """
    A, B2, C2 = P.A, P.B2, P.C2
    n = A.shape[0]
    if n == 0:
        return
    scale_b = max(1.0, np.linalg.norm(np.hstack([A, B2]), 2))
    scale_c = max(1.0, np.linalg.norm(np.vstack([A, C2]), 2))
    kind = "z" if P.dt else "s"
    if not _unstable_modes(A, P.dt).size:
        return
    # each test on the unstable part alone (ordered Schur form): on the full A, a stable
    # mode next to an unstable one makes A - λI nearly singular whatever B2 and C2 do.
    # A D-scaled two-mass plant (a rigid-body double pole at 0, split by roundoff into
    # ±4.3e-8j, beside stable scaling modes at -4.7e-7 and -4e-6) failed the full-A test
    # (smallest singular value 1.1e-7 against 3.3e-7) though u moves the rigid-body mode
    # (2026-12-02): the controllable and observable parts are exactly those of the
    # unstable block in these coordinates (left eigenvectors [0, w] for T22, right
    # eigenvectors [v; 0] for T11)
    T22, B2u = _unstable_block(A, B2, P.dt)
    for lam in np.linalg.eigvals(T22):
        M = np.hstack([T22 - lam * np.eye(T22.shape[0]), B2u])
        if np.linalg.svd(M, compute_uv=False)[-1] <= PBH_TOL * scale_b:
            raise InfeasibleError(f"(A, B2) is not stabilisable: the unstable mode "
                                  f"{kind} = {_fmt(lam)} is uncontrollable from the controls u")
    T11, C2u = _unstable_block(A.T, C2.T, P.dt)  # (C2, A) by duality
    for lam in np.linalg.eigvals(T11):
        M = np.hstack([T11 - lam * np.eye(T11.shape[0]), C2u])
        if np.linalg.svd(M, compute_uv=False)[-1] <= PBH_TOL * scale_c:
            raise InfeasibleError(f"(C2, A) is not detectable: the unstable mode "
                                  f"{kind} = {_fmt(np.conj(lam))} is unobservable from the "
                                  f"measurements y")


def _unstable_block(A: np.ndarray, B: np.ndarray, dt: float):
    """``(T22, B_u)``: the unstable block of a complex Schur form of ``A`` with the stable
    modes first (``Q* A Q = [[T11, T12], [0, T22]]``) and the rows of ``Q* B`` that
    drive it.  The unstable modes of ``(A, B)`` are controllable iff they are of
    ``(T22, B_u)`` (a left eigenvector of ``A`` for an eigenvalue of ``T22`` is ``[0, w]``)."""
    from scipy.linalg import schur

    if dt:
        def stable(x):
            return np.abs(x) < 1.0 - 1e-12
    else:
        def stable(x):
            return np.real(x) < -1e-12 * np.maximum(1.0, np.abs(x))
    T, Q, k = schur(np.asarray(A, dtype=complex), output="complex", sort=stable)
    return T[k:, k:], (Q.conj().T @ np.asarray(B, dtype=complex))[k:]


def _fmt(lam: complex) -> str:
    return f"{lam.real:.6g}" if abs(lam.imag) == 0 else f"{lam:.6g}"


def check_riccati_assumptions(P: GeneralizedPlant) -> None:
    """Standing assumptions of the Riccati (DGKF / Glover-Doyle) solution.

    1. ``D12`` has full column rank; 2. ``D21`` has full row rank;
    3. ``[[A - jwI, B2], [C1, D12]]`` has full column rank for all real ``w``;
    4. ``[[A - jwI, B1], [C2, D21]]`` has full row rank for all real ``w``
    (for a discrete-time plant, ``exp(jw)`` in place of ``jw``: SLICOT SB10DD's A3, A4).

    Raises
    ------
    AssumptionError
        Naming the first violated assumption.

    Examples
    --------
    >>> from lmi_suspension.lti import GeneralizedPlant
    >>> P = GeneralizedPlant.from_matrices(A=[[-1.0]], B1=[[1.0]], B2=[[1.0]],
    ...     C1=[[1.0], [0.0]], C2=[[1.0]], D12=[[0.0], [1.0]], D21=[[0.0]])
    >>> check_riccati_assumptions(P)
    Traceback (most recent call last):
    ...
    lmi_suspension.errors.AssumptionError: D21 (1x1) must have full row rank 1 for the Riccati method (rank 0); use method='lmi' for singular problems
    """
    b = P.blocks()
    for name, D, full, kind in (("D12", b["D12"], P.nu, "column"),
                                ("D21", b["D21"], P.ny, "row")):
        sv = np.linalg.svd(D, compute_uv=False)
        rank = int(np.sum(sv > RANK_TOL * max(1.0, sv[0] if sv.size else 0.0)))
        if D.shape[0 if kind == "column" else 1] < full or rank < full:
            raise AssumptionError(
                f"{name} ({D.shape[0]}x{D.shape[1]}) must have full {kind} rank {full} for "
                f"the Riccati method (rank {rank}); use method='lmi' for singular problems")
    # j-axis conditions: invariant zeros of (A, B2, C1, D12) and of (A, B1, C2, D21)
    for label, sysargs in (
            ("[[A - jwI, B2], [C1, D12]] must have full column rank for all w",
             (b["A"], b["B2"], b["C1"], b["D12"])),
            ("[[A - jwI, B1], [C2, D21]] must have full row rank for all w",
             (b["A"], b["B1"], b["C2"], b["D21"]))):
        if b["A"].shape[0] == 0:
            continue
        z = control.ss(*sysargs).zeros()
        if P.dt:
            on_axis = z[np.abs(np.abs(z) - 1.0) <= AXIS_TOL]
            where = "z", "the unit circle"
        else:
            on_axis = z[np.abs(np.real(z)) <= AXIS_TOL * np.maximum(1.0, np.abs(z))]
            where = "s", "the imaginary axis"
        if on_axis.size:
            raise AssumptionError(f"{label}; it drops rank at {where[0]} = "
                                  f"{_fmt(complex(on_axis[0]))} (an invariant zero on "
                                  f"{where[1]})")
