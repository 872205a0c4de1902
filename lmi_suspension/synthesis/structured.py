"""The γ minimisation of :mod:`.lmi` by an interior-point method that uses its structure.

Every constraint of the γ minimisation (:func:`~lmi_suspension.synthesis.lmi.gamma_lmi`)
is a Lyapunov-type map of one of the two symmetric unknowns: each projected bounded-real
inequality reads ``Ū R̃ V̄ᵀ + V̄ R̃ Ūᵀ - γ Q̄ + H̄ <= -margin I`` and the coupling
``[[R̃, M], [Mᵀ, S̃]] >= 0``.  A general conic solver does not see this: Clarabel's KKT
system carries the dense scaling of each PSD cone, ``k(k+1)/2`` square, and the coupling
cone of order ``2n`` made 72 % of every iteration (benchmarks/HISTORY.md, 2026-11-28).

Here CVXOPT's cone LP solver (``conelp``; L. Vandenberghe, "The CVXOPT linear and
quadratic cone program solvers", 2010) runs the interior-point method, with a KKT
solver written for these constraints.  Its only large system is the Schur complement
``Gᵀ W⁻¹ W⁻ᵀ G`` in the ``n(n+1) + 1`` unknowns, and with the cone scaling
``W⁻ᵀ Z = rtiᵀ Z rti`` of each block every entry is a trace of ``n × n`` products::

    tr(X_i X_j),  X_i = Ũ E_i Ṽᵀ + Ṽ E_i Ũᵀ,  Ũ = rtiᵀ Ū,  Ṽ = rtiᵀ V̄
      = 2 tr(E_i B E_j B) + 2 tr(E_i C E_j D),  B = Ṽᵀ Ũ,  C = Ṽᵀ Ṽ,  D = Ũᵀ Ũ

over the basis ``E_i`` of symmetric matrices: the complement is assembled in O(n⁴)
operations instead of being formed from the ``k² × n²`` columns of ``G``, and its
Cholesky factor is the cost of an iteration.  The idea is that of Vandenberghe,
Balakrishnan, Wallin, Hansson & Roh, "Interior-point algorithms for semidefinite
programming problems derived from the KYP lemma" (LNCIS 312, 2005).  Right-hand sides
and the step in ``z`` are formed in the scaled space (``Ũ``, ``Ṽ``), never through
``W⁻¹ W⁻ᵀ``, whose condition number grows without bound near the optimum.

The complement squares the condition number of the scaled constraint map ``G̃ = W⁻ᵀ G``,
and near a degenerate optimum its Cholesky factor no longer resolves the dual equations
``G̃ᵀ (W uz) = bx``: on one small plant in six (33-34 of 212 test problems under three
OpenBLAS kernels) the dual residual stops falling above CVXOPT's tolerance, and the run
ends without a solution.  There a second run solves each KKT system by MINRES,
preconditioned by the same factor, with ``G̃`` and ``G̃ᵀ`` applied apart
(:meth:`_GammaProblem._minres`).  It reached the optimum of CVXOPT's own QR solve to
3e-10 where that was tried (``tests/test_structured.py``); the QR solve does not square
the condition number, but its cost grows with the square of the number of unknowns
times the cone's dimension.

CVXOPT is a dependency of this module alone; every other LMI of the package is posed in
CVXPY and solved by Clarabel, and :func:`~lmi_suspension.synthesis.lmi.gamma_lmi` falls
back to that route wherever this one does not end with an optimal solution.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import cvxopt
import numpy as np
import scipy.linalg
import scipy.sparse.linalg
from cvxopt import misc

from ..errors import SolverError

__all__ = ["StructuredSolution", "minimise_gamma"]

logger = logging.getLogger(__name__)

#: diagonal regularisations of the equilibrated Schur complement, tried in turn where
#: its Cholesky factorisation fails.  Near the optimum the complement is singular to
#: working precision: without regularisation the factorisation failed 2-5 iterations
#: before the optimum on the 4-30-state benchmark plants, with 1e-13 (and the
#: refinement below) every one of them reached CVXOPT's tolerances (measured 2026-11-29)
_REGULARISATION = (0.0, 1e-13, 1e-11, 1e-9, 1e-7)
#: bound on CVXOPT's iterations per run, below ``max_iter`` (Clarabel's bound, 200):
#: the runs that ended optimal took 12-41 (benchmark plants n = 4-60, the 12 COMPleib
#: plants and 200 random plants of 2-8 states), and a run that stalls does not
#: recover: one kept the same residuals from its 20th iteration to its 95th, where
#: CVXOPT divided by zero (measured 2026-11-29)
_MAX_ITERATIONS = 60
#: least feasibility tolerance given to CVXOPT (its own default).  Its dual residual
#: ``||Gᵀz + c||`` is relative to ``||c|| = 1`` and has a floor of 0.9-1.4e-8 on the
#: 40-state benchmark plant, by OpenBLAS kernel: with ``feastol=1e-8`` the kernels whose
#: floor was above it (Sandybridge, Nehalem, SkylakeX) kept iterating at a closed gap
#: until the primal residual grew from 1e-11 to 1e-2 (60 iterations, then Clarabel);
#: with 1e-7 every kernel ends optimal in 23 iterations, γ within 1.6e-5 of each other
#: (measured 2026-11-29, the sixteenth and seventeenth sessions, benchmarks/HISTORY.md)
_FEASTOL = 1e-7
#: MINRES's relative tolerance and iteration bound per KKT solve of the second run
#: (``_GammaProblem._minres``); each iteration costs two triangular solves with the
#: factor and an application of ``G̃`` and of ``G̃ᵀ``.  With these, of 212 problems
#: (the 12 COMPleib plants and 200 random plants of 2-8 states) the Cholesky run failed
#: on 33 under OpenBLAS SkylakeX, and the MINRES run ended optimal on 31 of them (28-31
#: of 31-34 under Haswell, Sandybridge, Nehalem), where Clarabel's γ was up to 1.1 %
#: higher, or lower with its LMIs violated by up to 1e-2 (measured 2026-11-29,
#: benchmarks/HISTORY.md).  On the 40-state benchmark plant it averaged 26 iterations
#: a solve (10 s for the run), which is why it is the second run and not the first
_MINRES_RTOL = 1e-12
_MINRES_ITERATIONS = 50
#: iterative-refinement steps against the unregularised complement, at every solve
#: (each costs an application of ``G̃`` and of ``G̃ᵀ`` and two triangular solves).  Near
#: the optimum the factorisation is inaccurate even where no regularisation was
#: needed: on the property test's plant of seed 2374001, without refinement, the dual
#: residual jumped from 1e-9 to 2e-7 at the 19th iteration under OpenBLAS SkylakeX and
#: the run stalled; with it every kernel ends optimal in 19 (measured 2026-11-29).
#: Since the complement is assembled by ``_Basis.add_pairs`` that plant ends optimal
#: either way, and on the 212 problems of benchmarks/HISTORY.md the unregularised
#: refinement saves 1-3 MINRES runs (33 against 34-36, SkylakeX and Haswell) for about
#: a fifth of the structured route's time on those small plants; on the benchmark
#: plants (30, 40 states) its cost is within the noise
_REFINEMENT_STEPS = 3
#: a refinement step that changed the solution by at most this (relative) ends the
#: refinement: the next one would only move it at the floor of the factor's rounding.
#: On the 30-state benchmark plant, in the iterations that needed no regularisation,
#: the first step moved it by 1e-15-1e-9 and the residual then stayed at 1e-15-1e-11
#: (relative), the second step by 1e-17-1e-13, the third by the same again; near the
#: optimum the three steps moved it by 1e-2-1 each and are all kept.  Skipping the
#: steps below 1e-12 changes no step of conelp beyond that relative size; on the
#: 60-state plant, where most iterations are near the optimum, it saved 42 of 448
#: solves (the same 22 iterations and γ to 7 digits; measured 2026-12-02)
_REFINEMENT_FLOOR = 1e-12


@dataclass(frozen=True)
class StructuredSolution:
    """Optimum of the γ minimisation: ``gamma`` and the relative Lyapunov variables
    ``Rt``, ``St`` of the projections' coordinates, CVXOPT's ``status`` ("optimal", or
    "optimal_inaccurate" for a run that stopped short of its tolerances but within the
    reduced ones, ``reduced_tol_gap_rel`` and ``reduced_tol_feas``: a γ near 0, whose
    relative gap CVXOPT does not define, is never accepted so), and the ``iterations``,
    regularised factorisations and KKT solve of the run that is returned (the MINRES
    run follows a Cholesky run that failed)."""

    gamma: float
    Rt: np.ndarray
    St: np.ndarray
    status: str
    iterations: int
    #: factorisations of the Schur complement that needed a regularisation
    regularised: int
    #: the dual multiplier of the trace bound: doubling the bound lowers γ by at most
    #: ``trace_multiplier * trace_bound`` (convexity)
    trace_multiplier: float
    #: the KKT solve of the run that was returned: "Cholesky" or "MINRES"
    kkt: str = "Cholesky"


@dataclass(frozen=True)
class _Inequality:
    """``Ū X V̄ᵀ + V̄ X Ūᵀ - γ Q̄ + H̄ <= -margin I`` in the unknown ``X`` (``R̃`` or
    ``S̃``; ``of_s``): one projected bounded-real inequality of :class:`.lmi._Projection`."""

    of_s: bool
    U: np.ndarray
    V: np.ndarray
    Q: np.ndarray
    H: np.ndarray

    @classmethod
    def from_projection(cls, p, n: int, of_s: bool) -> "_Inequality":
        k, nw = p.F.shape[0], p.H.shape[1]
        if p.Nx is not None:
            right = p.Nx  # the plain form: E = F X Nx
        else:
            right = np.zeros((n, k))  # E = F X[:, :r] diag(s), padded to k columns
            right[: p.s.size, : p.s.size] = np.diag(p.s)
        H = np.zeros((k + nw, k + nw))
        H[:k, k:] = p.H
        H[k:, :k] = p.H.T
        return cls(of_s, np.vstack([p.F, np.zeros((nw, n))]),
                   np.vstack([right.T, np.zeros((nw, n))]),
                   scipy.linalg.block_diag(p.Q, np.eye(nw)), H)

    @property
    def order(self) -> int:
        return self.Q.shape[0]


@dataclass(frozen=True)
class _Factors:
    """The map ``G`` in factored form, plain or scaled by ``W⁻ᵀ``: the orthant rows
    ``Gl``, ``(Ũ, Ṽ, Q̃)`` of each inequality (``X ↦ Ũ X Ṽᵀ + Ṽ X Ũᵀ - γ Q̃``) and the
    coupling's ``(Ũ_R, Ũ_S)`` (``(R, S) ↦ -(Ũ_R R Ũ_Rᵀ + Ũ_S S Ũ_Sᵀ)``)."""

    Gl: np.ndarray
    blocks: tuple
    Ur: np.ndarray
    Us: np.ndarray


class _Basis:
    """The basis ``E_ab`` (``a >= b``) of symmetric ``n × n`` matrices: ``E_aa = e_a e_aᵀ``,
    ``E_ab = e_a e_bᵀ + e_b e_aᵀ``, with the gathers that evaluate ``tr(E_i P E_j Q)``."""

    def __init__(self, n: int):
        self.n = n
        self.a, self.b = np.tril_indices(n)
        self.size = self.a.size
        self.weight = np.where(self.a == self.b, 0.5, 1.0)
        self.diagonal = np.flatnonzero(self.a == self.b)
        self._ab = self.a * n + self.b  # (r, s) of E_j
        self._rr = np.arange(n) * (n + 1)  # (r, r)

    def matrix(self, x: np.ndarray) -> np.ndarray:
        """``sum_i x_i E_i``."""
        X = np.zeros((self.n, self.n))
        X[self.a, self.b] = x
        X[self.b, self.a] = x
        return X

    def trace(self, Z: np.ndarray) -> np.ndarray:
        """``tr(E_i Z)`` for every ``i``."""
        return self.weight * (Z[self.b, self.a] + Z[self.a, self.b])

    def add_pairs(self, out: np.ndarray, pairs):
        """``out[i, j] += sum_k c_k tr(E_i P_k E_j Q_k)`` for every ``i, j``, over
        ``pairs`` of ``(P_k, Q_k, c_k)``.  With ``E_i`` written as a sum of ``e_p e_qᵀ``,
        a term is ``P[q, r] Q[s, p]``: the terms of each row ``i`` are summed over its
        ``(p, q)`` and over the pairs first, as outer products of rows of ``P_k`` and
        ``Q_kᵀ`` -- one small matrix product per row, ``(n, 4K) @ (4K, n)`` for ``K``
        pairs, batched, whose four outer products per pair make the row symmetric in
        ``(r, s)`` -- and the lower triangle ``(r >= s)`` of each row gathered once.
        Batched products instead of outer products added term by term: 0.20 s against
        0.53 s at 60 states with five pairs (2026-12-02); symmetric rows and one gather
        (twice the flops of the small products) instead of two gathers and a weighted
        sum: 0.058 s against 0.103 s at 60 states with three pairs, equal to 4e-14
        (random matrices, 2026-12-02, ``tests/test_structured.py``)."""
        a, b, n = self.a, self.b, self.n
        # the row weights go into the left factors, the column weights (1/2 for E_rr)
        # into the n diagonal columns (r, r)
        w = self.weight[:, None]
        left = np.empty((self.size, n, 4 * len(pairs)))
        right = np.empty((self.size, 4 * len(pairs), n))
        for k, (P, Q, c) in enumerate(pairs):
            Qt = Q.T
            for j, (lf, rt) in enumerate(((P[b], Qt[a]), (P[a], Qt[b]),
                                          (Qt[a], P[b]), (Qt[b], P[a]))):
                left[:, :, 4 * k + j] = (c * w) * lf
                right[:, 4 * k + j, :] = rt
        rows = np.matmul(left, right).reshape(self.size, n * n)  # rows[i, r * n + s]
        rows[:, self._rr] *= 0.5
        out += np.take(rows, self._ab, axis=1)


class _GammaProblem:
    """``minimise γ`` over ``x = (R̃, S̃, γ)`` in CVXOPT's form ``G x + s = h``, ``s``
    in the product of a nonnegative orthant (the trace bound, ``γ >= 0``) and one PSD
    cone per inequality, the coupling last."""

    def __init__(self, inequalities: list[_Inequality], coupling: np.ndarray,
                 trace_bound: float, margin: float, minres: bool = False):
        n = coupling.shape[0]
        self.n = n
        self.basis = _Basis(n)
        self.ineqs = inequalities
        nv = self.basis.size
        self.nv = nv
        self.m = 2 * nv + 1
        self.dims = {"l": 2, "q": [], "s": [q.order for q in inequalities] + [2 * n]}
        Gl = np.zeros((2, self.m))
        Gl[0, self.basis.diagonal] = 1.0
        Gl[0, nv + self.basis.diagonal] = 1.0
        Gl[1, -1] = -1.0
        self.Gl = Gl
        self._orthant_columns = np.flatnonzero(np.any(Gl != 0.0, axis=0))
        Hc = np.zeros((2 * n, 2 * n))
        Hc[:n, n:] = coupling
        Hc[n:, :n] = coupling.T
        h = [np.array([trace_bound, 0.0])]
        h += [(-q.H - margin * np.eye(q.order)).ravel(order="F") for q in inequalities]
        h.append(Hc.ravel(order="F"))
        self.h = cvxopt.matrix(np.concatenate(h))
        self.c = cvxopt.matrix(np.r_[np.zeros(2 * nv), 1.0])
        I2 = np.eye(2 * n)
        self._plain = _Factors(Gl, tuple((q.U, q.V, q.Q) for q in inequalities),
                               I2[:, :n], I2[:, n:])
        #: the KKT solve: the Cholesky factor of the Schur complement and iterative
        #: refinement (False), or MINRES on the KKT system preconditioned by that factor
        self.minres = minres
        #: MINRES solves that ended at their iteration bound (their step is used)
        self.unconverged = 0
        self.regularised = 0
        self._level = 0

    # ------------------------------------------------------------------ the map G
    def _slices(self, of_s: bool) -> slice:
        return slice(self.nv, 2 * self.nv) if of_s else slice(0, self.nv)

    def _split(self, v: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
        """The orthant part and the symmetric matrices (from their lower triangles, the
        part CVXOPT keeps) of a vector of the cone space."""
        off, out = self.dims["l"], []
        for k in self.dims["s"]:
            Z = np.tril(v[off: off + k * k].reshape(k, k, order="F"))
            out.append(Z + np.tril(Z, -1).T)
            off += k * k
        return v[: self.dims["l"]], out

    def _apply(self, x: np.ndarray, f: _Factors) -> np.ndarray:
        """``G x`` (``f`` plain) or ``W⁻ᵀ G x`` (``f`` scaled)."""
        X = {False: self.basis.matrix(x[: self.nv]), True: self.basis.matrix(x[self.nv: -1])}
        g = x[-1]
        out = [f.Gl @ x]
        for q, (U, V, Qs) in zip(self.ineqs, f.blocks):
            Y = U @ X[q.of_s] @ V.T
            out.append((Y + Y.T - g * Qs).ravel(order="F"))
        out.append((-(f.Ur @ X[False] @ f.Ur.T) - f.Us @ X[True] @ f.Us.T).ravel(order="F"))
        return np.concatenate(out)

    def _apply_T(self, v: np.ndarray, f: _Factors) -> np.ndarray:
        """The adjoint of :meth:`_apply` for the trace inner product of each block."""
        vl, Zs = self._split(v)
        r = f.Gl.T @ vl
        for q, (U, V, Qs), Z in zip(self.ineqs, f.blocks, Zs[:-1]):
            r[self._slices(q.of_s)] += 2.0 * self.basis.trace(V.T @ Z @ U)
            r[-1] -= np.sum(Qs * Z)
        r[: self.nv] -= self.basis.trace(f.Ur.T @ Zs[-1] @ f.Ur)
        r[self.nv: -1] -= self.basis.trace(f.Us.T @ Zs[-1] @ f.Us)
        return r

    def G(self, u, v, alpha=1.0, beta=0.0, trans="N"):
        """CVXOPT's operator form: ``v := alpha G u + beta v`` (or with ``Gᵀ``)."""
        uu = np.array(u).ravel()
        out = self._apply(uu, self._plain) if trans == "N" else self._apply_T(uu, self._plain)
        v[:] = cvxopt.matrix(alpha * out + beta * np.array(v).ravel())

    # ------------------------------------------------------------------ the KKT solver
    def schur(self, W):
        """The Schur complement ``Gᵀ W⁻¹ W⁻ᵀ G`` at CVXOPT's scaling ``W``, and the
        scaled factors of ``G`` (:class:`_Factors`)."""
        basis, nv, n = self.basis, self.nv, self.n
        rti = [np.array(r) for r in W["rti"]]
        f = _Factors(self.Gl * np.array(W["di"]).ravel()[:, None],
                     tuple((r.T @ q.U, r.T @ q.V, r.T @ q.Q @ r)
                           for q, r in zip(self.ineqs, rti)),
                     rti[-1].T[:, :n], rti[-1].T[:, n:])
        # the orthant rows touch the trace's diagonal entries and γ only: a dense
        # product would write the whole (2 nv + 1)² complement
        M = np.zeros((self.m, self.m))
        touched = self._orthant_columns
        M[np.ix_(touched, touched)] = f.Gl[:, touched].T @ f.Gl[:, touched]
        Prr, Pss, Prs = f.Ur.T @ f.Ur, f.Us.T @ f.Us, f.Ur.T @ f.Us
        pairs = {False: [(Prr, Prr, 1.0)], True: [(Pss, Pss, 1.0)]}  # the coupling's
        for q, (U, V, Qs) in zip(self.ineqs, f.blocks):
            sl = self._slices(q.of_s)
            B = V.T @ U
            pairs[q.of_s] += [(B, B, 2.0), (V.T @ V, U.T @ U, 2.0)]
            col = -2.0 * basis.trace(V.T @ Qs @ U)
            M[sl, -1] += col
            M[-1, sl] += col
            M[-1, -1] += np.sum(Qs * Qs)
        basis.add_pairs(M[:nv, :nv], pairs[False])
        basis.add_pairs(M[nv:-1, nv:-1], pairs[True])
        basis.add_pairs(M[:nv, nv:-1], [(Prs, Prs.T, 1.0)])
        M[nv:-1, :nv] = M[:nv, nv:-1].T
        return M, f

    def kktsolver(self, W):
        """Factor the Schur complement at the scaling ``W``; return CVXOPT's solve."""
        M, factors = self.schur(W)
        d = 1.0 / np.sqrt(np.diag(M))
        M *= d[:, None]
        M *= d[None, :]
        # once a regularisation was needed, the later (nearer the optimum) complements
        # start from it: a failed factorisation costs as much as a successful one
        diagonal = np.diag_indices_from(M)
        for k in range(self._level, len(_REGULARISATION)):
            M[diagonal] += _REGULARISATION[k] - (_REGULARISATION[k - 1] if k > self._level else 0.0)
            try:
                cf = scipy.linalg.cho_factor(M, lower=True, overwrite_a=False,
                                             check_finite=False)
                break
            except np.linalg.LinAlgError:
                continue
        else:
            # conelp ends here with its last iterate, status "unknown"
            raise ArithmeticError("Schur complement singular after regularisation")
        self._level = k
        delta = _REGULARISATION[k]
        self.regularised += bool(delta)

        def solve(rhs):
            return d * scipy.linalg.cho_solve(cf, d * rhs, check_finite=False)

        def f(x, y, z):
            misc.scale(z, W, trans="T", inverse="I")  # z := W⁻ᵀ bz, in the scaled space
            bz = np.array(z).ravel()
            vl, Zs = self._split(bz)
            bz = np.concatenate([vl] + [Z.ravel(order="F") for Z in Zs])
            r = np.array(x).ravel() + self._apply_T(bz, factors)
            ux = solve(r)
            if self.minres:
                ux, uz = self._minres(ux, np.array(x).ravel(), bz, factors, solve)
            else:
                for _ in range(_REFINEMENT_STEPS):
                    step = solve(r - self._apply_T(self._apply(ux, factors), factors))
                    ux = ux + step
                    if np.linalg.norm(step) <= _REFINEMENT_FLOOR * np.linalg.norm(ux):
                        break
                uz = self._apply(ux, factors) - bz
            x[:] = cvxopt.matrix(ux)
            z[:] = cvxopt.matrix(uz)
        return f

    def _minres(self, ux, bx, bz, factors, solve):
        """The KKT system in the scaled space, ``[[-I, G̃], [G̃ᵀ, 0]] [W uz; ux] = [W⁻ᵀ bz;
        bx]``, by MINRES from the Cholesky solution ``ux``, preconditioned by
        ``diag(I, M⁻¹)`` with the Schur complement's factor ``M⁻¹`` (``solve``).  With the
        exact complement the preconditioned system has three eigenvalues (Murphy, Golub &
        Wathen, SIAM J. Sci. Comput. 21(6), 2000) and MINRES ends in three iterations;
        where the factor is inaccurate it goes on, working with ``G̃`` and ``G̃ᵀ`` apart,
        never with their product, whose condition number is the square of ``G̃``'s."""
        k, m = bz.size, ux.size

        def kkt(v):
            return np.concatenate([self._apply(v[k:], factors) - v[:k],
                                   self._apply_T(v[:k], factors)])

        def precondition(v):
            return np.concatenate([v[:k], solve(v[k:])])

        shape = (k + m, k + m)
        A = scipy.sparse.linalg.LinearOperator(shape, matvec=kkt, dtype=float)
        P = scipy.sparse.linalg.LinearOperator(shape, matvec=precondition, dtype=float)
        x0 = np.concatenate([self._apply(ux, factors) - bz, ux])
        v, info = scipy.sparse.linalg.minres(A, np.concatenate([bz, bx]), x0=x0, M=P,
                                             rtol=_MINRES_RTOL, maxiter=_MINRES_ITERATIONS)
        if info < 0:
            raise ArithmeticError(f"MINRES broke down (info {info})")
        self.unconverged += info > 0
        return v[k:], v[:k]


def minimise_gamma(projections, coupling: np.ndarray, trace_bound: float, margin: float,
                   options) -> StructuredSolution:
    """Minimise γ over the projected bounded-real inequalities and the coupling.

    Parameters
    ----------
    projections : sequence of (lmi._Projection or None, bool)
        Each projected inequality with whether its unknown is ``S̃`` (None: an empty
        null space, nothing to constrain).
    coupling : ndarray
        ``M`` of the coupling ``[[R̃, M], [Mᵀ, S̃]] >= 0``.
    trace_bound : float
        Bound on ``trace(R̃) + trace(S̃)``.
    margin : float
        Strictness margin of the inequalities.
    options : HinfsynOptions
        ``tol_gap_abs``, ``tol_gap_rel``, ``tol_feas`` (CVXOPT's ``abstol``, ``reltol``,
        ``feastol``, the last at least ``_FEASTOL``), ``max_iter`` (at most
        ``_MAX_ITERATIONS``), and the reduced tolerances within which a run that stops
        short of them is accepted as "optimal_inaccurate".

    Returns
    -------
    StructuredSolution
        γ, the relative Lyapunov variables, the status and the solver's counts.

    Raises
    ------
    SolverError
        Where CVXOPT ends with neither: the caller falls back to Clarabel.

    Examples
    --------
    Through :func:`~lmi_suspension.synthesis.lmi.gamma_lmi`, which poses the problem
    (COMPleib AC4, scaled; SLICOT's controller certifies 0.5572907 in the plant's units):

    >>> from lmi_suspension.examples import compleib
    >>> from lmi_suspension.lti.scaling import scale_plant
    >>> from lmi_suspension.synthesis import HinfsynOptions, lmi
    >>> Ps, sc = scale_plant(compleib("AC4"))
    >>> sol = lmi.gamma_lmi(Ps, HinfsynOptions())
    >>> sol.status, round(sol.gamma / sc.gamma_factor, 5)
    ('optimal', 0.55729)
    """
    n = coupling.shape[0]
    settings = dict(show_progress=False, maxiters=min(int(options.max_iter), _MAX_ITERATIONS),
                    abstol=float(options.tol_gap_abs), reltol=float(options.tol_gap_rel),
                    feastol=max(float(options.tol_feas), _FEASTOL), refinement=1)
    try:
        ineqs = [_Inequality.from_projection(p, n, of_s)
                 for p, of_s in projections if p is not None]
    except ValueError as exc:
        raise SolverError(f"structured γ minimisation: {exc}", status="failed") from exc
    failures, close = [], None
    for minres in (False, True):
        kkt = "MINRES" if minres else "Cholesky"
        try:
            prob = _GammaProblem(ineqs, coupling, trace_bound, margin, minres)
            sol = cvxopt.solvers.conelp(prob.c, prob.G, prob.h, prob.dims,
                                        kktsolver=prob.kktsolver, options=settings)
        except MemoryError as exc:
            # the complement takes 8 n⁴ bytes (0.8 GB at 100 states), which a small
            # machine may not have; the second run would need as much
            failures.append(f"out of memory ({exc!r}) in the {kkt} run")
            break
        except (ArithmeticError, ValueError) as exc:
            # conelp raises ValueError where its first factorisation fails, and scipy's
            # MINRES where the preconditioner is not definite
            failures.append(f"failed ({exc}) in the {kkt} run")
            continue
        status = sol["status"]
        if status == "optimal":
            return _solution(prob, sol, status, kkt, failures)
        gap, pres, dres = (sol.get(k) for k in ("relative gap", "primal infeasibility",
                                                "dual infeasibility"))
        if status == "unknown" and all(v is not None for v in (gap, pres, dres)) and \
                gap <= options.reduced_tol_gap_rel and \
                max(pres, dres) <= options.reduced_tol_feas and \
                (close is None or max(pres, dres) < close[3]):
            close = prob, sol, kkt, max(pres, dres)
        failures.append(f"CVXOPT status {status!r} after {sol['iterations']} iterations "
                        f"(relative gap {gap}, infeasibilities {pres}, {dres}) in the "
                        f"{kkt} run")
    if close is not None:
        return _solution(close[0], close[1], "optimal_inaccurate", close[2], failures)
    raise SolverError("structured γ minimisation: " + "; ".join(failures), status="failed")


def _solution(prob: _GammaProblem, sol: dict, status: str, kkt: str,
              failures: list[str]) -> StructuredSolution:
    x = np.array(sol["x"]).ravel()
    nv = prob.nv
    if failures:
        logger.info("structured γ minimisation: %s", "; ".join(failures))
    logger.info("structured γ minimisation: %s in %d iterations (%d regularised, %s KKT "
                "solve, %d MINRES solves at their iteration bound)", status,
                sol["iterations"], prob.regularised, kkt, prob.unconverged)
    return StructuredSolution(float(x[-1]), prob.basis.matrix(x[:nv]),
                              prob.basis.matrix(x[nv:-1]), status, int(sol["iterations"]),
                              prob.regularised, float(sol["z"][0]), kkt)
