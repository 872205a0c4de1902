"""Small Hermitian LMI problems posed for Clarabel directly (no modelling layer).

D-G-K's optimal G-scalings (:func:`~lmi_suspension.mu.gfit.optimal_gscales`) solve one
SDP over the grid per basis size and fit, a problem of the same shape each time with
new data.  Through CVXPY every one was compiled afresh, and the compilation was most of
the fits' time (a profile of the seat over m3 and k1, ``complex_candidate="start"``:
23.5 of 31.4 s, 2026-12-02); assembled with numpy and handed to Clarabel, the solver
CVXPY called, the two-mass plant's took 0.31 s of CPU instead of 3.37 s for the same
level (2.1099312 against 2.1099170).  The per-frequency problems of
:func:`~lmi_suspension.mu.gfit.central_dg` stay on CVXPY: their DPP form is compiled
once per call, and their optimum is not unique (the margin is capped), so a different
formulation moves the point the interior-point method returns, and D-G-K's path with it.

A Hermitian ``H = X + jY ⪰ 0`` is posed as its real embedding ``[[X, -Y], [Y, X]] ⪰ 0``
in Clarabel's ``PSDTriangleConeT`` (the upper triangle stacked by columns, off-diagonal
entries scaled by √2).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import SolverError

logger = logging.getLogger(__name__)

__all__ = ["LmiSolution", "solve_lmi"]


@dataclass(frozen=True)
class LmiSolution:
    """Clarabel's solution: ``x``, and ``status`` ``"optimal"`` or ``"optimal_inaccurate"``
    (Clarabel's ``AlmostSolved``)."""

    x: np.ndarray
    status: str


def _triu(n: int):
    """Row and column indices of the upper triangle stacked by columns, and the √2
    scaling of its off-diagonal entries (Clarabel's ``PSDTriangleConeT`` order)."""
    lower_r, lower_c = np.tril_indices(n)  # row-major lower triangle, transposed:
    rows, cols = lower_c, lower_r  # column j's rows i <= j, column after column
    scale = np.where(rows == cols, 1.0, np.sqrt(2.0))
    return rows, cols, scale


def _embed(H: np.ndarray) -> np.ndarray:
    """``[[Re H, -Im H], [Im H, Re H]]`` of a stack of matrices (last two axes)."""
    X, Y = H.real, H.imag
    top = np.concatenate([X, -Y], axis=-1)
    bottom = np.concatenate([Y, X], axis=-1)
    return np.concatenate([top, bottom], axis=-2)


def solve_lmi(c, F0, F, *, G=None, h=None, E=None, f=None, what: str = "LMI") -> LmiSolution:
    """Minimise ``c·x`` subject to ``F0[k] + Σ_i x_i F[k, i] ⪰ 0`` for every ``k``
    (Hermitian), ``G x <= h`` and ``E x = f``.

    Parameters
    ----------
    c : array_like, shape (n,)
        Objective.
    F0 : array_like, shape (K, m, m)
        Constant terms of the ``K`` LMIs (Hermitian; their Hermitian part is used).
    F : array_like, shape (K, n, m, m)
        Coefficients of the variables in each LMI.
    G, h : array_like, optional
        Linear inequalities.
    E, f : array_like, optional
        Linear equalities.
    what : str
        What is solved, for the messages.

    Returns
    -------
    LmiSolution

    Raises
    ------
    SolverError
        Where Clarabel ends without a solution (infeasible, iteration limit, numerical
        failure).

    Examples
    --------
    The smallest ``t`` with ``[[t, 1], [1, t]] ⪰ 0``:

    >>> import numpy as np
    >>> sol = solve_lmi([1.0], [[[0, 1], [1, 0]]], [[[[1, 0], [0, 1]]]])
    >>> round(float(sol.x[0]), 6)
    1.0
    """
    import clarabel

    c = np.asarray(c, dtype=float).ravel()
    n = c.size
    F0 = np.asarray(F0, dtype=complex)
    F = np.asarray(F, dtype=complex)
    K, m = F0.shape[0], F0.shape[1]
    if F.shape != (K, n, m, m):
        raise ValueError(f"F must have shape {(K, n, m, m)}, got {F.shape}")
    F0 = (F0 + np.conj(np.swapaxes(F0, -1, -2))) / 2
    F = (F + np.conj(np.swapaxes(F, -1, -2))) / 2
    real = not (np.any(F0.imag) or np.any(F.imag))
    if real:
        E0, Ei = F0.real, F.real
    else:
        E0, Ei = _embed(F0), _embed(F)
    N = E0.shape[-1]
    ri, ci, scale = _triu(N)
    blocks_A, blocks_b, cones = [], [], []
    if E is not None:
        E = np.atleast_2d(np.asarray(E, dtype=float))
        blocks_A.append(E)
        blocks_b.append(np.asarray(f, dtype=float).ravel())
        cones.append(clarabel.ZeroConeT(E.shape[0]))
    if G is not None:
        G = np.atleast_2d(np.asarray(G, dtype=float))
        blocks_A.append(G)
        blocks_b.append(np.asarray(h, dtype=float).ravel())
        cones.append(clarabel.NonnegativeConeT(G.shape[0]))
    # s = b - A x = svec(F0 + Σ x_i F_i)  ->  b = svec(F0), A = -svec(F_i)
    b_psd = (E0[:, ri, ci] * scale).reshape(-1)  # (K * len)
    A_psd = -(Ei[:, :, ri, ci] * scale)  # (K, n, len)
    A_psd = np.moveaxis(A_psd, 1, 2).reshape(-1, n)
    blocks_A.append(A_psd)
    blocks_b.append(b_psd)
    cones += [clarabel.PSDTriangleConeT(N) for _ in range(K)]
    A = sp.csc_matrix(np.vstack(blocks_A))
    b = np.concatenate(blocks_b)
    P = sp.csc_matrix((n, n))
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    solver = clarabel.DefaultSolver(P, c, A, b, cones, settings)
    sol = solver.solve()
    status = str(sol.status)
    x = np.asarray(sol.x, dtype=float)
    if status.endswith("AlmostSolved"):
        logger.info("%s: Clarabel's solution is inaccurate (%s); used as it is", what, status)
        return LmiSolution(x, "optimal_inaccurate")
    if not status.endswith("Solved") or not np.all(np.isfinite(x)):
        raise SolverError(f"{what}: Clarabel status {status}")
    return LmiSolution(x, "optimal")
