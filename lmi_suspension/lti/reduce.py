"""Balanced truncation of a system's stable part, the modes near and right of the
imaginary axis kept whole.

One routine for the two reductions of µ-synthesis: the D-G-K scaled plant before its
K-step (:func:`~lmi_suspension.mu.steps.fit.reduced_for_kstep`, by an error bound) and
the returned controller (``MusynOptions.reduce_order``, to an order).  The stable part is
split off by an ordered real Schur form and a Sylvester equation, and truncated by
SLICOT AB09AD (square-root balanced truncation with scaling), whose error bound is
``2 Σ σ_dropped`` of the stable part's Hankel singular values.
"""

from __future__ import annotations

import warnings

import control
import numpy as np

__all__ = ["stable_split", "balanced_truncation"]

#: a mode with real part above ``-_AXIS_REL * max(1, |λ|)`` stays out of the truncation
#: (the rigid-body double pole of the two-mass plant sits at ±2e-8)
_AXIS_REL = 1e-6


def stable_split(sys: control.StateSpace):
    """``(stable, rest)`` with ``sys = stable + rest``: ordered real Schur form and a
    Sylvester equation; ``rest`` holds the modes near and right of the axis, and D.

    Examples
    --------
    >>> import control
    >>> s, r = stable_split(control.ss([[-1.0, 0.0], [0.0, 2.0]], [[1.0], [1.0]],
    ...                                [[1.0, 1.0]], [[0.5]]))
    >>> s.nstates, r.nstates, float(r.D[0, 0])
    (1, 1, 0.5)
    """
    from scipy.linalg import schur, solve_sylvester

    A, B, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C, sys.D))
    T, Q, k = schur(A, output="real",
                    sort=lambda x, y: x < -_AXIS_REL * max(1.0, float(np.hypot(x, y))))
    T11, T12, T22 = T[:k, :k], T[:k, k:], T[k:, k:]
    X = solve_sylvester(T11, -T22, -T12)
    QB, CQ = Q.T @ B, C @ Q
    stable = control.ss(T11, QB[:k] - X @ QB[k:], CQ[:, :k], np.zeros_like(D))
    rest = control.ss(T22, QB[k:], CQ[:, :k] @ X + CQ[:, k:], D)
    return stable, rest


def balanced_truncation(sys: control.StateSpace, *, order: int | None = None,
                        tol: float | None = None):
    """``(reduced, bound)``: ``sys`` with its stable part balanced-truncated (SLICOT
    AB09AD, square-root method with scaling), the rest (:func:`stable_split`) kept whole,
    and the error bound ``2 Σ σ_dropped`` of the truncation (0 where nothing is dropped).

    Exactly one of ``order`` (the order of the result; the rest's states count in it)
    and ``tol`` (the least order whose error bound is at most ``tol``) is given.

    Raises
    ------
    ValueError
        Neither or both of ``order`` and ``tol``; an order below the rest's states; and
        what slycot or scipy raise where the reduction fails (plain ``ValueError`` or
        ``ArithmeticError`` kinds, which callers catch to keep the system whole).

    Examples
    --------
    >>> import control
    >>> G = control.ss(control.tf([1.0], [1.0, 1.0]) + control.tf([1e-3], [1.0, 10.0]))
    >>> Gr, bound = balanced_truncation(G, order=1)
    >>> Gr.nstates, bool(0 < bound < 1e-3)
    (1, True)
    """
    from slycot import ab09ad

    if (order is None) == (tol is None):
        raise ValueError("give exactly one of order and tol")
    stable, rest = stable_split(sys)
    n, m, p = stable.nstates, stable.ninputs, stable.noutputs
    if order is not None and int(order) < rest.nstates:
        raise ValueError(f"order {order} is below the {rest.nstates} states kept whole "
                         "(on or near the imaginary axis, or unstable)")
    if n < 2:
        return sys, 0.0
    A, B, C = (np.asarray(x, dtype=float) for x in (stable.A, stable.B, stable.C))
    with warnings.catch_warnings():
        # slycot warns where the stable part is not minimal (the order is then its
        # minimal one, and the dropped singular values are zeros)
        warnings.simplefilter("ignore")
        *_, hsv = ab09ad("C", "B", "S", n, m, p, A.copy(), B.copy(), C.copy(), nr=n)
    hsv = np.sort(np.asarray(hsv, dtype=float))[::-1]
    if not np.all(np.isfinite(hsv)):
        raise ValueError(f"Hankel singular values {hsv}")
    tail = np.append(2.0 * np.cumsum(hsv[::-1])[::-1], 0.0)  # tail[r]: drop r..n-1
    if order is not None:
        r = min(int(order) - rest.nstates, n)
    else:
        r = int(next(k for k in range(n + 1) if tail[k] <= tol))
    if r >= n:
        return sys, 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        nr, Ar, Br, Cr, _ = ab09ad("C", "B", "S", n, m, p, A.copy(), B.copy(), C.copy(),
                                   nr=r)
    reduced = control.ss(Ar[:nr, :nr], Br[:nr], Cr[:, :nr], np.zeros((p, m)))
    if not rest.nstates:
        return control.ss(reduced.A, reduced.B, reduced.C, np.asarray(rest.D)), float(tail[nr])
    return control.parallel(reduced, rest), float(tail[nr])
