"""Full-order H∞ synthesis by LMIs (projection lemma): the γ minimisation by CVXOPT with a
KKT solver for its structure (:mod:`.structured`), every other LMI by Clarabel through CVXPY.

The existence of a controller with ``||F_l(P, K)||_∞ < γ`` (Gahinet & Apkarian 1994,
Theorem 4.3; ``D22 = 0``) is equivalent to symmetric ``R`` and ``S`` with::

    W_R^T [[A R + R A^T, R C1^T, B1], [C1 R, -γ I, D11], [B1^T, D11^T, -γ I]] W_R < 0
    W_S^T [[A^T S + S A, S B1, C1^T], [B1^T S, -γ I, D11^T], [C1, D11, -γ I]] W_S < 0
    [[R, I], [I, S]] >= 0

with ``W_R = diag(N_R, I)``, ``N_R`` a basis of ``ker [B2^T D12^T]`` and
``W_S = diag(N_S, I)``, ``N_S`` a basis of ``ker [C2 D21]``.  Only ``R``, ``S`` and γ
are unknowns, which keeps the SDP small.  The outer factors are multiplied out by hand
so CVXPY sees a few affine matrix products, symmetric by construction (``E + E^T``), in
a basis of each null space and rotated state coordinates of each Lyapunov variable
that make every entry depend on one column of it (:class:`_Projection`).

Conditioning: the plants D-K produces have poles from 1e-6 to 1e3 rad/s and ``D12``
of 0.002, and their γ-optimal ``R`` and ``S`` span ten decades; written as they are, an
interior-point method's endpoint is set by roundoff (the same plant gave certified γ
1.37, 1.50 and 8933 under three OpenBLAS kernels).  Every LMI here can therefore be
posed in a :class:`Frame` taken from an earlier solution: the coordinates that balance
it, and the Lyapunov variables relative to it, so that they are of order one and every
slack is relative.  The γ minimisation is repeated in the frame of its own solution
where that solution is suspect (``hinfsyn``'s frame rounds), and the controller LMI is
always solved in the frame of the γ-optimal solution.

Reconstruction: in that frame, at a slightly relaxed γ, the change-of-variables LMI
(:class:`ControllerLmi`) returns a central solution from which the controller follows
by exact formulas.  The static case (no plant states) uses the explicit all-solutions
formula of the bounded-real inequality (:func:`explicit_controller`).

References
----------
P. Gahinet, P. Apkarian, "A linear matrix inequality approach to H∞ control",
Int. J. Robust Nonlinear Control 4 (1994) 421-448.
"""

from __future__ import annotations

import logging
import warnings as warnings_module
from dataclasses import dataclass, replace

import control
import cvxpy as cp
import numpy as np
import scipy.linalg

from ..errors import InfeasibleError, SolverError
from ..lti.plant import GeneralizedPlant
from . import structured
from .result import HinfsynOptions

__all__ = ["gamma_lmi", "balancing_transform", "ControllerLmi", "explicit_controller",
           "decoupled_controller",
           "Frame", "LmiSolution", "riccati_frame", "riccati_start"]

logger = logging.getLogger(__name__)

_OK = (cp.OPTIMAL,)
_INACCURATE = (cp.OPTIMAL_INACCURATE,)
_INFEASIBLE = (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE)
#: weight of the bounded-real slack against the coupling slack in the controller LMI: the
#: coupling margin is what keeps I - XY (and so the controller) well conditioned, while
#: the bounded-real inequality at a relaxed γ only has a margin of the order of the
#: relaxation to give (measured on COMPleib AC3, AC4, AC6: 1 fails where 0.1 succeeds)
_BRL_SLACK_WEIGHT = 0.1
#: Clarabel's static regularisation in the controller LMI at least (see
#: :meth:`ControllerLmi.controller`)
_CONTROLLER_STATIC_REG = 1e-8
#: static regularisation of the first recovery of a failed solve, tenfold on each next
#: one: the controller LMI of a D-scaled distillation plant (relative variables with
#: sigma up to 1.3e7, data from 1e-12 to 4e4) failed at 1e-8 and 1e-7 and was solved at
#: 1e-6 (measured 2026-11-25)
_RECOVERY_STATIC_REG = 1e-7
#: Clarabel's KKT factorisation: the supernodal, multithreaded "faer" was about twice as
#: fast as "qdldl" on the dense KKT systems of these SDPs (measured 2026-11-24)
_DIRECT_SOLVE_METHOD = "faer"
#: threads of that factorisation: one was the fastest on the project's 2-core machines
#: (γ minimisation of the 22-state benchmark plant: 1.18 s on one thread, 1.25 s on two,
#: 1.23 s automatic; measured 2026-11-24, benchmarks/HISTORY.md)
_MAX_THREADS = 1
#: Clarabel's static regularisation in the γ minimisation (its own default is 1e-8).  These
#: SDPs are nearly degenerate near the optimal γ and the regularisation decides how close
#: the solver gets: with 1e-8 the controller LMI of COMPleib AC6 stopped at a common slack
#: 0.0112 where 0.0128 is feasible (certified γ 0.27 % above the LMI optimum instead of
#: 0.06 %, measured 2026-11-24); recoveries raise it (_RECOVERY_STATIC_REG)
_STATIC_REG = 1e-10
#: how the warning of an active trace bound in the γ minimisation begins
TRACE_BOUND_ACTIVE = "the bound trace(X) + trace(Y)"


@dataclass(frozen=True)
class LmiSolution:
    """Solution of the elimination LMIs at level ``gamma`` (scaled plant)."""

    gamma: float
    R: np.ndarray
    S: np.ndarray
    status: str
    warnings: tuple = ()
    #: why a better-conditioned frame may move the optimum: a recovery or the plain form
    #: (an "almost solved" first attempt is not a reason: its γ is within the reduced
    #: tolerances)
    suspect: tuple = ()

    @property
    def clean(self) -> bool:
        """Nothing suggests that a better-conditioned frame would move the optimum."""
        return not self.suspect


def _null(M: np.ndarray) -> np.ndarray:
    if M.shape[0] == 0:
        return np.eye(M.shape[1])
    return scipy.linalg.null_space(M, rcond=1e-10)


def _sym(E):
    return (E + E.T) / 2


@dataclass(frozen=True)
class Frame:
    """Coordinates and variable scalings in which an H∞ LMI is well conditioned.

    From a preliminary solution ``(R, S)`` of the projected LMIs: the state coordinates
    ``x = T x_b`` that balance it (``T⁻¹ R T⁻ᵀ = Tᵀ S T = diag(sigma)``,
    :func:`balancing_transform`) and, in them, the Lyapunov variables written relative
    to it, ``R_b = D R̂ D``, ``S_b = D Ŝ D`` with ``D = diag(sqrt(sigma))``.  Near that
    solution ``R̂ ≈ Ŝ ≈ I``: every variable is of order one and every slack is relative,
    whatever the decades between the plant's fast and slow modes.  Each inequality is
    then the one of the plant in its own coordinates (``x_b = D x̂`` for the ``R``
    inequality, ``x_b = D⁻¹ x̂`` for the ``S`` one) and the coupling reads
    ``[[R̂, Σ⁻¹], [Σ⁻¹, Ŝ]] >= 0``.

    Measured on COMPleib HE1 (2026-11-25): in the balanced coordinates alone
    (``sigma`` 1 ... 1.8e4) the controller LMI's optimal slack at 0.08 % above the
    optimum was +1.4e-3, -3.6e-3 or -1.6e-2 depending on Clarabel's static
    regularisation (1e-10, 1e-8, 1e-7) and failed outright under OpenBLAS's SkylakeX
    kernel; written relative to ``sigma`` it gave the same controller (certified
    0.073648 at 0.05 % above the optimum) under every regularisation and kernel.
    """

    T: np.ndarray
    sigma: np.ndarray
    #: ``D = diag(sqrt(min(sigma, cap)))``: directions with larger ``sigma`` keep
    #: relative variables of order ``sigma / cap``
    cap: float = float("inf")

    @property
    def scale(self) -> np.ndarray:
        """``D``'s diagonal."""
        return np.sqrt(np.minimum(self.sigma, self.cap))

    @property
    def trace(self) -> float:
        """``trace(R̂) + trace(Ŝ)`` of the solution the frame was built from."""
        return float(2.0 * np.sum(self.sigma / self.scale**2))

    @classmethod
    def identity(cls, n: int) -> "Frame":
        return cls(np.eye(n), np.ones(n))

    @classmethod
    def from_lyapunov(cls, R: np.ndarray, S: np.ndarray) -> "Frame":
        """The frame that balances ``(R, S)`` (see :func:`balancing_transform`)."""
        T, sigma = balancing_transform(R, S)
        return cls(T, sigma)

    def plants(self, P: GeneralizedPlant):
        """``P`` in the coordinates of the ``R`` and of the ``S`` inequality."""
        from ..lti.scaling import transform_states

        d = self.scale
        return (transform_states(P, self.T * d[None, :]),
                transform_states(P, self.T / d[None, :]))

    def lyapunov(self, Rh: np.ndarray, Sh: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(R, S)`` of the plant's own coordinates from the relative ``(R̂, Ŝ)``."""
        d = self.scale
        Rb, Sb = d[:, None] * Rh * d[None, :], d[:, None] * Sh * d[None, :]
        Ti = np.linalg.inv(self.T)
        return _sym(self.T @ Rb @ self.T.T), _sym(Ti.T @ Sb @ Ti)


@dataclass(frozen=True)
class _Projection:
    """One projected bounded-real LMI in a basis that makes its data sparse.

    With ``N`` an orthonormal basis of the null space whose state part has orthogonal
    columns (``N_x = U Σ``, from the SVD of the state part of any orthonormal basis) and
    the Lyapunov variable written ``R = T R̃ Tᵀ`` with ``T = U``, the projected LMI is::

        [[E + Eᵀ - γ Q, H], [Hᵀ, -γ I]] < 0,   E = [F R̃[:, :r] diag(s), 0]

    (``s`` the ``r`` nonzero singular values).  Every orthonormal basis gives the same
    eigenvalues, so margins mean what they meant; but each entry of ``E`` now depends on
    one column of ``R̃`` instead of on all of ``R``, and Clarabel's KKT system has 6
    times fewer nonzeros: the γ minimisation of the 22-state benchmark plant took 0.80 s
    instead of 1.12 s (19 and 20 iterations, both with iterative refinement), and HE1 of COMPleib, where the dense form
    stopped 0.3 % short, is solved to 0.07 %.  (A basis with ``N_x = [I, 0]`` keeps the
    coupling ``[[R, I], [I, S]]`` sparse and was faster still, 0.57 s, but it is not
    orthonormal and lost the optimum of a D-scaled distillation plant: 1.31 against
    1.166, measured 2026-11-24.)
    """

    T: np.ndarray
    F: np.ndarray
    s: np.ndarray
    Q: np.ndarray
    H: np.ndarray
    #: the dense form's state part of the basis (``E = F R N_x``, ``T = I``), else None
    Nx: np.ndarray | None = None

    @classmethod
    def build(cls, A, B2, C1, D12, B1, D11, sparse: bool = True) -> "_Projection | None":
        """For ``ker [B2ᵀ D12ᵀ]`` (the ``S`` inequality passes the dual data); None when
        the null space is empty (nothing to constrain).  ``sparse=False`` gives the
        plain form: any orthonormal basis, ``T = I``."""
        n = A.shape[0]
        N = _null(np.hstack([B2.T, D12.T]))
        if not N.shape[1]:
            return None
        if not sparse:
            Nx, Nz = N[:n], N[n:]
            return cls(np.eye(n), Nx.T @ A + Nz.T @ C1, np.ones(0), Nz.T @ Nz,
                       Nx.T @ B1 + Nz.T @ D11, Nx)
        U, sv, Vt = np.linalg.svd(N[:n])
        r = int(np.sum(sv > 1e-10))  # sv <= 1: N is orthonormal
        N = N @ Vt.T
        k = N.shape[1]
        Nx = U[:, :r] @ np.hstack([np.diag(sv[:r]), np.zeros((r, k - r))])  # = N[:n], exactly
        Nz = N[n:]
        F = (Nx.T @ A + Nz.T @ C1) @ U
        return cls(U, F, sv[:r], Nz.T @ Nz, Nx.T @ B1 + Nz.T @ D11)

    def lmi(self, Rt, gamma, margin):
        """The inequality in ``R̃`` as a CVXPY constraint, symmetric by construction."""
        L = self.matrix(Rt, gamma)
        return L << -margin * np.eye(L.shape[0])

    def matrix(self, Rt, gamma):
        """The projected bounded-real matrix (affine CVXPY expression in ``R̃`` and γ)."""
        k, r = self.F.shape[0], self.s.size
        if self.Nx is not None:
            E = self.F @ Rt @ self.Nx
        else:
            # multiply (not @ diag(s)): CVXPY keeps a dense factor's zeros as coefficients
            E = cp.multiply(self.F @ Rt[:, :r], self.s[None, :])
            if k > r:
                E = cp.hstack([E, np.zeros((k, k - r))])
        nw = self.H.shape[1]
        return _sym(cp.bmat([[E + E.T - gamma * self.Q, self.H],
                             [self.H.T, -gamma * np.eye(nw)]]))


def _projections(P_r: GeneralizedPlant, P_s: GeneralizedPlant, sparse: bool = True):
    """The ``R`` inequality's projection for ``P_r`` and the ``S`` inequality's for
    ``P_s`` (the same plant in the coordinates of each, ``D22 = 0``)."""
    r, s = P_r.blocks(), P_s.blocks()
    return (_Projection.build(r["A"], r["B2"], r["C1"], r["D12"], r["B1"], r["D11"], sparse),
            _Projection.build(s["A"].T, s["C2"].T, s["B1"].T, s["D21"].T, s["C1"].T,
                              s["D11"].T, sparse))


def clarabel_settings(opts: HinfsynOptions, *, refine: bool = False,
                      static_reg: float = _STATIC_REG) -> dict:
    """Keyword arguments of ``problem.solve(solver=cvxpy.CLARABEL, ...)``: the tolerances
    and iteration bound of ``opts``, and this module's solver constants.  ``refine``
    turns on Clarabel's iterative refinement of each KKT solve: off in the γ
    minimisation (22-state benchmark plant: 0.53 s instead of 0.86 s, 19 iterations
    either way, optimum 0.006 % higher; measured 2026-11-24), on in the controller LMI
    and in every recovery."""
    return dict(tol_gap_abs=opts.tol_gap_abs, tol_gap_rel=opts.tol_gap_rel,
                tol_feas=opts.tol_feas, max_iter=int(opts.max_iter),
                reduced_tol_gap_abs=opts.reduced_tol_gap_abs,
                reduced_tol_gap_rel=opts.reduced_tol_gap_rel,
                reduced_tol_feas=opts.reduced_tol_feas,
                direct_solve_method=_DIRECT_SOLVE_METHOD, max_threads=_MAX_THREADS,
                iterative_refinement_enable=bool(refine),
                static_regularization_constant=float(static_reg))


def _solve(prob: cp.Problem, opts: HinfsynOptions, what: str, warnings: list, *,
           refine: bool = False, static_reg: float | None = None):
    """Solve with explicit Clarabel settings (:func:`clarabel_settings`); recover from
    inaccurate/failed solves.

    Returns the status and the number of recoveries it took (0: the first attempt).

    Each recovery loosens the tolerances tenfold, doubles the iteration bound, raises
    the static regularisation (1e-7, 1e-6, ...) and refines every KKT solve
    iteratively; every recovery is recorded in ``warnings``.
    """
    settings = clarabel_settings(opts, refine=refine,
                                 static_reg=_STATIC_REG if static_reg is None else static_reg)
    attempts = [settings]
    for i in range(int(opts.max_recoveries)):
        kw = dict(settings)
        f = 10.0 ** (i + 1)
        kw.update(tol_gap_rel=settings["tol_gap_rel"] * f, tol_gap_abs=settings["tol_gap_abs"] * f,
                  reduced_tol_gap_rel=min(1e-2, settings["reduced_tol_gap_rel"] * f),
                  reduced_tol_gap_abs=min(1e-2, settings["reduced_tol_gap_abs"] * f),
                  reduced_tol_feas=min(1e-4, settings["reduced_tol_feas"] * f),
                  max_iter=int(settings["max_iter"]) * 2,
                  static_regularization_constant=max(settings["static_regularization_constant"],
                                                     _RECOVERY_STATIC_REG * 10.0 ** i),
                  iterative_refinement_enable=True)
        attempts.append(kw)
    status = None
    for k, kw in enumerate(attempts):
        try:
            with warnings_module.catch_warnings():
                # CVXPY warns on "optimal_inaccurate"; the status is handled (and
                # recorded in ``warnings``) here
                warnings_module.filterwarnings("ignore", message="Solution may be inaccurate")
                prob.solve(solver=cp.CLARABEL, **kw)
            status = prob.status
        except cp.error.SolverError as exc:
            status = f"solver_error: {exc}"
        except BaseException as exc:  # noqa: B036 - see below
            # Clarabel's Rust core can panic (an index out of bounds in its chordal decomposition
            # on a D-scaled distillation plant under OpenBLAS's Nehalem kernel, measured
            # 2026-11-25); pyo3 raises that as PanicException, a BaseException: a failed
            # attempt like any other, never a crash of the caller
            if type(exc).__name__ != "PanicException":
                raise
            status = f"solver_panic: {exc}"
        if status in _INFEASIBLE:
            return status, k
        if status in _OK or status in _INACCURATE:
            if k:
                warnings.append(f"{what}: recovered (attempt {k + 1}) with looser Clarabel "
                                f"tolerances, status {status!r}")
            elif status in _INACCURATE:
                warnings.append(f"{what}: Clarabel status {status!r} (almost solved); "
                                "the result is certified independently")
            return status, k
        logger.info("%s: Clarabel status %r, trying recovery %d", what, status, k + 1)
    raise SolverError(f"{what}: Clarabel failed after {opts.max_recoveries} recoveries "
                      f"(last status {status!r})", status=str(status))


def gamma_lmi(P: GeneralizedPlant, opts: HinfsynOptions, gamma: float | None = None,
              frame: Frame | None = None) -> LmiSolution:
    """Minimise γ over the elimination LMIs (or test feasibility at fixed ``gamma``).

    ``P`` must have ``D22 = 0`` and should be scaled.  With a ``frame`` (from an earlier
    solution) the Lyapunov variables are written relative to it (:class:`Frame`); the
    bound ``trace + trace <= xy_bound n`` then applies to the relative variables.  The
    minimisation is solved by :func:`.structured.minimise_gamma` (``opts.gamma_solver ==
    "structured"``), by Clarabel where that fails (said in ``warnings``) or where asked
    to, and every fixed-level problem by Clarabel.  The sparse form (:class:`_Projection`)
    is solved first; where both fail on it, the plain form.  ``R`` and ``S`` are returned
    in the coordinates of ``P``.

    Raises
    ------
    InfeasibleError
        If no controller achieves the fixed ``gamma`` (or none stabilises ``P``).
    SolverError
        If Clarabel fails after ``opts.max_recoveries`` recoveries on both forms (the
        structured solve having failed before it).
    """
    frame = Frame.identity(P.nstates) if frame is None else frame
    try:
        return _gamma_lmi(P, opts, gamma, frame, sparse=True)
    except SolverError as exc:
        # a D-scaled distillation plant (D12 = 0.002) gave null-space bases whose state
        # parts have singular values from 7e-6 to 1: Clarabel's first KKT factorisation
        # failed on the sparse form and not on the plain one (measured 2026-11-24)
        logger.info("gamma_lmi: sparse form failed (%s); plain form", exc)
        sol = _gamma_lmi(P, opts, gamma, frame, sparse=False)
        note = f"sparse form failed ({exc}); solved in the plain form"
        return replace(sol, warnings=(note,) + sol.warnings, suspect=(note,) + sol.suspect)


def _gamma_lmi(P: GeneralizedPlant, opts: HinfsynOptions, gamma: float | None,
               frame: Frame, sparse: bool) -> LmiSolution:
    n = P.nstates
    # R̃, S̃: the relative Lyapunov variables in the rotated coordinates of their projections
    Rt = cp.Variable((n, n), symmetric=True)
    St = cp.Variable((n, n), symmetric=True)
    g = cp.Variable(nonneg=True) if gamma is None else float(gamma)
    P_r, P_s = frame.plants(P)
    proj_r, proj_s = _projections(P_r, P_s, sparse)
    # [[R, I], [I, S]] >= 0 becomes [[R̂, Σ⁻¹], [Σ⁻¹, Ŝ]] >= 0 in the frame, and with
    # R̂ = U_R R̃ U_Rᵀ, Ŝ = U_S S̃ U_Sᵀ (orthogonal) the coupling block is U_Rᵀ Σ⁻¹ U_S
    U_r, U_s = (np.eye(n) if p is None else p.T for p in (proj_r, proj_s))
    M = (U_r.T / frame.scale[None, :] ** 2) @ U_s
    fallback = ()
    if gamma is None and opts.gamma_solver == "structured" and n:
        try:
            found = structured.minimise_gamma([(proj_r, False), (proj_s, True)], M,
                                              opts.xy_bound * n, opts.margin, opts)
        except SolverError as exc:
            logger.info("gamma_lmi: %s; Clarabel", exc)
            fallback = (f"{exc}; solved by Clarabel",)
        else:
            # the interior-point limit is the centre of the optimal face, which reaches
            # the trace bound wherever the infimum is approached only as R, S grow: the
            # bound's multiplier says what it costs, and only a cost above a tenth of
            # gamma_relax is worth a warning (4-16-state benchmark plants: 9e-6 - 5e-5
            # of γ against a measured 3.9e-5 for a bound ten times wider, 2026-11-29)
            bound = opts.xy_bound * n
            costly = found.trace_multiplier * bound > 0.1 * opts.gamma_relax * found.gamma
            said = [] if found.status == "optimal" else [
                f"gamma minimisation: CVXOPT stopped short of its tolerances ({found.status!r}, "
                "within the reduced ones); the result is certified independently"]
            return _lmi_solution(found.gamma, found.Rt, found.St, U_r, U_s, frame, opts,
                                 found.status, said, trace_active=costly)
    cons = [p.lmi(V, g, opts.margin) for p, V in ((proj_r, Rt), (proj_s, St)) if p is not None]
    cons += [_sym(cp.bmat([[Rt, M], [M.T, St]])) >> 0,
             cp.trace(Rt) + cp.trace(St) <= opts.xy_bound * n]  # rotations keep traces
    prob = cp.Problem(cp.Minimize(g) if gamma is None else cp.Minimize(0), cons)
    warnings: list[str] = []
    status, recoveries = _solve(prob, opts, "gamma minimisation" if gamma is None else
                                f"feasibility at gamma={gamma:.6g}", warnings)
    if status in _INFEASIBLE:
        if gamma is None:
            raise InfeasibleError("the H∞ LMIs are infeasible for every γ: no stabilising "
                                  "controller within the bound trace(X) + trace(Y) <= xy_bound n")
        raise InfeasibleError(f"no controller achieves gamma = {gamma:.6g} "
                              "(the H∞ LMIs are infeasible)")
    gval = float(g.value) if gamma is None else float(gamma)
    suspect = [warnings[-1]] if recoveries else []
    return _lmi_solution(gval, Rt.value, St.value, U_r, U_s, frame, opts, status,
                         list(fallback) + warnings, suspect)


def _lmi_solution(gval: float, Rt: np.ndarray, St: np.ndarray, U_r: np.ndarray,
                  U_s: np.ndarray, frame: Frame, opts: HinfsynOptions, status,
                  warnings: list, suspect: list = (),
                  trace_active: bool | None = None) -> LmiSolution:
    """The solution in the coordinates of the plant from the relative ``(R̃, S̃)`` of
    the projections' coordinates; says when the trace bound is active (``trace_active``,
    or where None, when the trace is within 1 % of it)."""
    n = Rt.shape[0]
    Rh, Sh = U_r @ Rt @ U_r.T, U_s @ St @ U_s.T
    if trace_active is None:
        trace_active = np.trace(Rh) + np.trace(Sh) > 0.99 * opts.xy_bound * n
    if trace_active:
        # said, but not a reason for a frame round by itself: where the bound held the
        # optimum up, the controller certifies below it and hinfsyn refines then (a
        # round on the 30-state benchmark plant gained 2e-4 for 2.5 s, measured
        # 2026-11-25)
        warnings.append(f"{TRACE_BOUND_ACTIVE} <= {opts.xy_bound:g} n is active; "
                        "the LMI optimum may be above the true infimum")
    Rv, Sv = frame.lyapunov(_sym(Rh), _sym(Sh))
    return LmiSolution(gval, Rv, Sv, str(status), tuple(warnings), tuple(suspect))


def _elimination_solution(Psi: np.ndarray, U: np.ndarray, V: np.ndarray,
                          what: str) -> np.ndarray:
    """One ``Omega`` with ``Psi + Uᵀ Omega V + Vᵀ Omegaᵀ U < 0``: Iwasaki & Skelton's
    all-solutions formula (Automatica 30 (1994) 1307-1317) with ``L = 0``,
    ``Omega = -rho U Phi Vᵀ (V Phi Vᵀ)⁻¹``, ``Phi = (rho Uᵀ U - Psi)⁻¹``, ``rho`` twice its
    smallest admissible value.  Raises :class:`SolverError` where ``Psi`` is not negative
    definite on the null space of ``U`` (the projected inequality fails)."""
    # smallest rho with rho U^T U - Psi > 0: split along range(U^T) and its complement
    Q, Rq = np.linalg.qr(U.T, mode="complete")
    k = np.linalg.matrix_rank(U.T)
    Psi_t = Q.T @ Psi @ Q
    P11, P12, P22 = Psi_t[:k, :k], Psi_t[:k, k:], Psi_t[k:, k:]
    if P22.size and np.linalg.eigvalsh(P22)[-1] >= 0:
        raise SolverError(f"{what}: projected inequality not negative definite "
                          "(X, Y inaccurate)")
    Sch = P11 - (P12 @ np.linalg.solve(P22, P12.T) if P22.size else 0)
    G = Rq[:k, :] @ Rq[:k, :].T  # U U^T expressed in range coordinates
    L = np.linalg.cholesky(G)
    Li = np.linalg.inv(L)
    rho_min = max(float(np.linalg.eigvalsh(Li @ _sym(Sch) @ Li.T)[-1]), 0.0)
    rho = 2.0 * rho_min + 1e-6 * max(1.0, np.abs(Psi).max())
    Phi = _sym(np.linalg.inv(rho * (U.T @ U) - Psi))
    return -rho * U @ Phi @ V.T @ np.linalg.inv(_sym(V @ Phi @ V.T))


def _central_solution(Psi: np.ndarray, K: np.ndarray, Dt: np.ndarray, n: int, terms,
                      what: str) -> np.ndarray:
    """``Ω`` minimising, in the Loewner order, the Schur complement on the ``(w, z)``
    block of ``Ψ`` with ``Ω Kᵀ + K Ωᵀ`` added to its state block and ``Ω Dt`` to its
    ``(state, (w, z))`` block; then checked with each of ``terms`` added to the state
    block (the ``∓`` derivative of the Lyapunov matrix at each vertex of a rate box).

    With ``Ψ = [[P0, Q], [Qᵀ, E]]`` (``E < 0`` iff ``‖D11‖ < γ``) and ``Z = -E⁻¹`` the
    complement is ``P0 + Ω Kᵀ + K Ωᵀ + (Q + Ω Dt) Z (Q + Ω Dt)ᵀ = (Ω - Ω*) W (Ω - Ω*)ᵀ +
    const`` with ``W = Dt Z Dtᵀ`` (positive definite when ``D12`` has full column rank,
    resp. ``D21`` full row rank) and ``Ω* = -(Q Z Dtᵀ + K) W⁻¹``: it satisfies every
    vertex wherever any ``Ω`` satisfies each."""
    P0, Q, E = Psi[:n, :n], Psi[:n, n:], Psi[n:, n:]
    Zm = -np.linalg.inv(_sym(E))
    W = _sym(Dt @ Zm @ Dt.T)
    if W.size and np.linalg.eigvalsh(W)[0] <= 1e-12 * max(1.0, np.abs(W).max()):
        raise SolverError(f"{what}: D12 (resp. D21) is not of full rank (a singular "
                          "problem): no ṗ-independent central gain")
    Om = -np.linalg.solve(W, (Q @ Zm @ Dt.T + K).T).T
    Qc = Q + Om @ Dt
    base = P0 + Om @ K.T + K @ Om.T + Qc @ Zm @ Qc.T
    for D in terms:
        top = float(np.linalg.eigvalsh(_sym(base + D))[-1])
        if top >= 0.0:
            raise SolverError(f"{what}: the inequality fails at a vertex of the rate box "
                              f"(largest eigenvalue {top:.3g})")
    return Om


def decoupled_controller(P: GeneralizedPlant, R: np.ndarray, S: np.ndarray, gamma: float,
                         *, dR=(), dS=(), T: np.ndarray | None = None):
    """Controller from ``(R, S)`` without an SDP: the explicit route of Gahinet (1996).

    With ``Y = R``, ``X = S`` fixed and ``D_K = 0``, the bounded-real inequality in the
    variables of Scherer, Gahinet & Chilali (1997) splits: ``Ĉ`` solves the ``R``
    inequality and ``B̂`` the ``S`` inequality, each a small problem of size
    ``n + n_w + n_z`` solved by :func:`_elimination_solution`, and ``Â`` is the block the
    elimination lemma removes, in closed form; the controller follows from
    ``M Nᵀ = I - XY`` (``N = I``).  The structure is that of Gahinet's "Explicit
    controller formulas for LMI-based H∞ synthesis" (Automatica 32(7), 1996; the LMI
    Toolbox's ``klmi``), with Iwasaki-Skelton solutions for ``B_K`` and ``C_K``.

    Evaluated in the balanced frame of ``(R, S)`` (:class:`Frame`), where ``R = S =
    diag(sigma)``: in the coordinates of the plant, the closed loop's Lyapunov matrix
    had condition numbers 1e6-4e10 near the optimum, and the closed-loop formula
    (:func:`explicit_controller`) failed its certificate on 15 of 18 plants, where this
    one certified on all 18 (COMPleib and ``bench_hinfsyn.py`` plants, (R, S) of the
    γ-optimal solve scaled by ``sqrt(1 + r)``, ``r >= 5e-4``; measured 2026-11-27).

    Rate-bounded gain scheduling (:func:`~lmi_suspension.lpv.lpvsyn` with ν > 0) passes
    a frame ``T`` fixed over the parameter range and either ``dR``, the values of
    ``Ṙ = Σ_k ṗ_k ∂R/∂p_k`` at the vertices of the rate box (``S`` constant), or ``dS``
    (``R`` constant).  The ``R`` inequality then carries ``-Ṙ`` in its state block at
    every vertex (resp. the ``S`` one ``+Ṡ``), and its gain ``Ĉ`` (resp. ``B̂``) must
    not depend on ``ṗ``: it is the Loewner minimiser of the inequality's Schur
    complement (:func:`_central_solution`), which satisfies every vertex wherever any
    gain satisfies each (the ``ṗ`` terms sit in the state block); each vertex is
    checked.  In the variables of Scherer, Gahinet & Chilali, the closed loop's
    Lyapunov derivative adds ``-(X Ẏ + N Ṁᵀ)`` to the block of ``Â``: it vanishes when
    ``S`` (here ``X``) and ``N`` are constant (``N = I`` in the frame, ``Mᵀ = I - XY``),
    resp. when ``R`` and ``M`` are (``M = I``, ``N = I - XY``), so the controller
    does not depend on ``ṗ`` (Apkarian & Adams 1998, §3).

    Returns ``(K, cond_xy)``; raises :class:`SolverError` where a projected inequality
    fails at ``gamma`` or ``‖D11‖ >= gamma``.
    """
    from ..lti.scaling import transform_states

    if T is None:
        frame = Frame.from_lyapunov(R, S)
        Pb = transform_states(P, frame.T)
        Y = X = np.diag(frame.sigma)
    else:
        T = np.asarray(T, dtype=float)
        Pb = transform_states(P, T)
        Ti = np.linalg.inv(T)
        Y, X = _sym(Ti @ R @ Ti.T), _sym(T.T @ S @ T)
        dR = [_sym(Ti @ np.asarray(D, dtype=float) @ Ti.T) for D in dR]
        dS = [_sym(T.T @ np.asarray(D, dtype=float) @ T) for D in dS]
    b = Pb.blocks()
    A, B1, B2, C1, C2 = b["A"], b["B1"], b["B2"], b["C1"], b["C2"]
    D11, D12, D21 = b["D11"], b["D12"], b["D21"]
    n, nw, nu, nz, ny = Pb.nstates, Pb.nw, Pb.nu, Pb.nz, Pb.ny
    g = float(gamma)
    if D11.size and np.linalg.norm(D11, 2) >= g:
        raise SolverError(f"explicit controller: ‖D11‖ >= gamma = {g:.6g}")
    I, Z = np.eye, np.zeros
    Psi_R = np.block([[A @ Y + Y @ A.T, B1, Y @ C1.T], [B1.T, -g * I(nw), D11.T],
                      [C1 @ Y, D11, -g * I(nz)]])
    if len(dR):
        Ch = _central_solution(Psi_R, B2, np.hstack([Z((nu, nw)), D12.T]), n,
                               [-D for D in dR], "rate-bounded controller (R)").T
    else:
        Ch = _elimination_solution(Psi_R, np.hstack([B2.T, Z((nu, nw)), D12.T]),
                                   np.hstack([I(n), Z((n, nw + nz))]),
                                   "explicit controller (R)")
    Psi_S = np.block([[X @ A + A.T @ X, X @ B1, C1.T], [B1.T @ X, -g * I(nw), D11.T],
                      [C1, D11, -g * I(nz)]])
    if len(dS):
        Bh = _central_solution(Psi_S, C2.T, np.hstack([D21, Z((ny, nz))]), n, dS,
                               "rate-bounded controller (S)")
    else:
        Bh = _elimination_solution(Psi_S, np.hstack([I(n), Z((n, nw + nz))]),
                                   np.hstack([C2, D21, Z((ny, nz))]),
                                   "explicit controller (S)")
    # Â: the block the elimination lemma removes, for D_K = 0
    E = np.block([[-g * I(nw), D11.T], [D11, -g * I(nz)]])
    left = np.vstack([(X @ B1 + Bh @ D21).T, C1])
    right = np.vstack([B1.T, C1 @ Y + D12 @ Ch])
    Ah = left.T @ np.linalg.solve(E, right) - A.T
    IXY = I(n) - X @ Y
    sv = np.linalg.svd(IXY, compute_uv=False)
    cond_xy = float(sv[0] / sv[-1]) if n and sv[-1] > 0 else float("inf")
    if len(dS):
        # N = I - XY, M = I: B_K = N⁻¹ B̂, C_K = Ĉ, A_K = N⁻¹ (Â - B̂ C2 Y - X B2 Ĉ - X A Y)
        Bk = np.linalg.solve(IXY, Bh)
        Ak = np.linalg.solve(IXY, Ah - Bh @ C2 @ Y - X @ B2 @ Ch - X @ A @ Y)
        return control.ss(Ak, Bk, Ch, np.zeros((nu, ny))), cond_xy
    MT = IXY
    Ck = np.linalg.solve(MT.T, Ch.T).T
    Ak = np.linalg.solve(MT.T, (Ah - X @ B2 @ Ck @ MT - Bh @ C2 @ Y - X @ A @ Y).T).T
    return control.ss(Ak, Bh, Ck, np.zeros((nu, ny))), cond_xy


def explicit_controller(P: GeneralizedPlant, sol: LmiSolution, gamma: float):
    """Controller from ``(R, S)`` by the explicit solution of the closed-loop BRL.

    With the closed-loop Lyapunov matrix fixed, the bounded-real inequality reads
    ``Psi + U^T Omega V + V^T Omega^T U < 0``; one solution is
    ``Omega = -rho U Phi V^T (V Phi V^T)^-1`` with ``Phi = (rho U^T U - Psi)^-1 > 0``
    (Iwasaki & Skelton, Automatica 30 (1994) 1307-1317, all-solutions formula with
    ``L = 0``).  ``rho`` is taken twice its smallest admissible value.
    """
    b = P.blocks()
    A, B1, B2, C1, C2 = b["A"], b["B1"], b["B2"], b["C1"], b["C2"]
    D11, D12, D21 = b["D11"], b["D12"], b["D21"]
    n, nw, nu, nz, ny = P.nstates, P.nw, P.nu, P.nz, P.ny
    R, S = sol.R, sol.S
    U_, sv, Vt = np.linalg.svd(np.eye(n) - R @ S)
    cond_xy = float(sv[0] / sv[-1]) if n and sv[-1] > 0 else float("inf")
    M = U_ * np.sqrt(sv)[None, :]
    N = Vt.T * np.sqrt(sv)[None, :]
    lhs = np.block([[R, np.eye(n)], [M.T, np.zeros((n, n))]])
    rhs = np.block([[np.eye(n), S], [np.zeros((n, n)), N.T]])
    Xcl = np.linalg.solve(lhs.T, rhs.T).T
    Xcl = (Xcl + Xcl.T) / 2
    ev = np.linalg.eigvalsh(Xcl)
    cond_lyap = float(ev[-1] / ev[0]) if ev[0] > 0 else float("inf")
    A0 = np.block([[A, np.zeros((n, n))], [np.zeros((n, 2 * n))]])
    B0 = np.block([[np.zeros((n, n)), B2], [np.eye(n), np.zeros((n, nu))]])
    C0 = np.block([[np.zeros((n, n)), np.eye(n)], [C2, np.zeros((ny, n))]])
    B10 = np.vstack([B1, np.zeros((n, nw))])
    C10 = np.hstack([C1, np.zeros((nz, n))])
    D0w = np.vstack([np.zeros((n, nw)), D21])
    D0z = np.hstack([np.zeros((nz, n)), D12])
    XA = Xcl @ A0
    XB = Xcl @ B10
    g = float(gamma)
    Psi = np.block([[XA + XA.T, XB, C10.T],
                    [XB.T, -g * np.eye(nw), D11.T],
                    [C10, D11, -g * np.eye(nz)]])
    U = np.hstack([B0.T @ Xcl, np.zeros((n + nu, nw)), D0z.T])
    V = np.hstack([C0, D0w, np.zeros((n + ny, nz))])
    Om = _elimination_solution(Psi, U, V, "explicit reconstruction")
    Ak, Bk, Ck, Dk = Om[:n, :n], Om[:n, n:], Om[n:, :n], Om[n:, n:]
    return control.ss(Ak, Bk, Ck, Dk), cond_xy, cond_lyap


#: floor ``ε ‖X‖`` on the eigenvalues of the Riccati solutions before they are inverted
#: into a frame (:func:`riccati_frame`; their null directions, states no error sees, would
#: otherwise give infinite ``R``).  On the scaled plants of a distillation D-K run, the
#: first γ minimisation in the frame came within 1 % of the optimum on 4 of 5 plants with
#: 1e-6 (against 60-1000 times the optimum in the identity frame), on 3 with 1e-9 and on
#: 1 with 1e-3 (measured 2026-11-25)
_ARE_FRAME_REG = 1e-6
#: negative eigenvalues of a Riccati solution tolerated as roundoff (relative)
_ARE_PSD_RTOL = 1e-5


def riccati_frame(P: GeneralizedPlant, gamma: float) -> "Frame | None":
    """A frame from the solutions of the two H∞ Riccati equations at an achievable
    level ``gamma`` (scaled units, ``D22 = 0``), or None where scipy finds none, or
    they are not positive semidefinite, or they violate the coupling
    ``ρ(X∞ Y∞) < γ²`` (``gamma`` at or below the optimum, or numerically too close).

    They are not checked to be the stabilising solutions: on D-K plants with a pole at
    -1e-6 rad/s scipy returned solutions whose closed loop had a pole at +0.0057, and
    with that check the frame failed over whole ranges of achievable levels (measured
    2026-11-25).  The frame is only where the γ minimisation starts; the LMI decides
    the level, and a frame that does not help falls back to the identity frame.

    ``X∞`` (full information) and ``Y∞`` (filtering) bound the Lyapunov variables of
    the projected LMIs: ``R = γ X∞⁻¹`` and ``S = γ Y∞⁻¹`` satisfy them at ``γ``, and
    at a level near the optimum they have the scales of the optimal ``R`` and ``S``.
    The frame they balance is a cheap start for the γ minimisation, which in the
    identity frame stops far above the optimum on the plants D-K produces (see
    :class:`Frame`).  The equations are solved by scipy (``solve_continuous_are``,
    indefinite weight); no controller is formed from them.

    Examples
    --------
    >>> from lmi_suspension.examples import skogestad_distillation
    >>> from lmi_suspension.lti.scaling import scale_plant
    >>> from lmi_suspension.lti import GeneralizedPlant
    >>> ex = skogestad_distillation()
    >>> Ps, sc = scale_plant(GeneralizedPlant.from_statespace(ex.P, 2, 2))
    >>> riccati_frame(Ps, 1.5 * sc.gamma_factor).sigma.size     # above γ_opt = 1.18
    6
    >>> riccati_frame(Ps, 1.0 * sc.gamma_factor) is None         # below it
    True
    """
    b = P.blocks()
    A, B1, B2, C1, C2 = b["A"], b["B1"], b["B2"], b["C1"], b["C2"]
    D11, D12, D21 = b["D11"], b["D12"], b["D21"]
    g = float(gamma)
    nw, nu, nz, ny = P.nw, P.nu, P.nz, P.ny
    if not (np.isfinite(g) and g > 0 and P.nstates):
        return None
    D1, Dc = np.hstack([D11, D12]), np.vstack([D11, D21])
    R1 = D1.T @ D1 - np.diag(np.r_[np.full(nw, g * g), np.zeros(nu)])
    R2 = Dc @ Dc.T - np.diag(np.r_[np.full(nz, g * g), np.zeros(ny)])

    def care(*args, s):
        # scipy's balancing of the pencil can make its reordering fail (a 22-state
        # D-scaled distillation plant, 2026-11-25); without it the solve goes through
        for balanced in (True, False):
            try:
                M = scipy.linalg.solve_continuous_are(*args, s=s, balanced=balanced)
            except (np.linalg.LinAlgError, ValueError):
                continue
            return _sym(M) if np.all(np.isfinite(M)) else None
        return None

    X = care(A, np.hstack([B1, B2]), C1.T @ C1, R1, s=C1.T @ D1)
    Y = care(A.T, np.vstack([C1, C2]).T, B1 @ B1.T, R2, s=B1 @ Dc.T)
    # the coupling condition: below it no controller achieves the level
    if X is None or Y is None or np.max(np.abs(np.linalg.eigvals(X @ Y))) >= g * g:
        return None
    out = []
    for M in (X, Y):
        w, V = np.linalg.eigh(M)
        top = max(w[-1], 0.0)
        # the stabilising solution at an achievable level is positive semidefinite (up
        # to roundoff: -5e-7 relative on a D-scaled distillation plant, 2026-11-25)
        if top == 0.0 or w[0] < -_ARE_PSD_RTOL * top:
            return None
        # γ M⁻¹ with the eigenvalues raised to at least ε ‖M‖: positive definite
        out.append(_sym((V * (g / np.maximum(w, _ARE_FRAME_REG * top))[None, :]) @ V.T))
    return Frame.from_lyapunov(out[0], out[1])


#: :func:`riccati_start`: the factor between the levels of its bracket search, and the
#: bound on its steps in each direction from 1 (``4**20`` is about 1e12)
_START_GROWTH = 4.0
_START_STEPS = 20
#: :func:`riccati_start`: halvings (in log scale) of the bracket's factor of 4, which
#: leave the level at most ``4**(1/4)`` (1.41) times the least level with a frame.  On
#: the 60-state plant of ``bench_hinfsyn.py`` the γ minimisation in the frame at 1.2
#: and 3 times the optimum took 17 and 16 iterations (identity frame: 22), at 22
#: states 17 at 1.01, 1.1 and 1.5 times (identity: 21) (measured 2026-12-02), so a
#: finer level only costs Riccati solves (40 ms a pair at 60 states)
_START_BISECTIONS = 2


def riccati_start(P: GeneralizedPlant, floor: float = 0.0) -> "tuple[float, Frame] | None":
    """A level (scaled units) at which :func:`riccati_frame` exists, at most
    ``4**(1/4)`` times the least such level found, and its frame; None where the plant
    is singular (``D12`` without full column rank or ``D21`` without full row rank:
    the Riccati equations are not defined), where no level in ``4**±20`` has a frame,
    or where one exists at or below ``floor`` (an optimum of about 0: the identity
    frame serves as well).

    The γ minimisation in the identity frame ends where its trace bound holds the
    Lyapunov variables, which on plants whose optimal ``R`` and ``S`` grow without
    bound costs iterations and optimum: on the 60-state plant of ``bench_hinfsyn.py``
    22 iterations and 29.84497, in the frame of this level (with ``hinfsyn``'s bound
    there, ``_START_XY_BOUND``) 17 and 29.83953; at 22 states 21 and 8.17204 against
    15 and 8.17175, at 40 states 23 and 68.8980 against 16 and 68.8848 (measured
    2026-12-02).  Only the frame is
    taken from the Riccati solutions: the LMI decides the level.  A bracket search by
    factors of 4 from 1, then :data:`_START_BISECTIONS` halvings; every step solves the
    two Riccati equations.

    Parameters
    ----------
    P : GeneralizedPlant
        Scaled plant with ``D22 = 0``.
    floor : float
        Least level (scaled units) worth a frame.

    Returns
    -------
    tuple of (float, Frame) or None
        The level and the frame of the Riccati solutions there.

    Examples
    --------
    >>> from lmi_suspension.examples import skogestad_distillation
    >>> from lmi_suspension.lti.scaling import scale_plant
    >>> from lmi_suspension.lti import GeneralizedPlant
    >>> ex = skogestad_distillation()
    >>> Ps, sc = scale_plant(GeneralizedPlant.from_statespace(ex.P, 2, 2))
    >>> level, frame = riccati_start(Ps)
    >>> bool(1.18 < level / sc.gamma_factor < 1.18 * 4 ** 0.25)
    True
    """
    b = P.blocks()
    D12, D21 = b["D12"], b["D21"]
    if not P.nstates or np.linalg.matrix_rank(D12) < P.nu or \
            np.linalg.matrix_rank(D21) < P.ny:
        return None
    lo, hi, frame = None, None, None
    g = 1.0
    for _ in range(_START_STEPS + 1):
        f = riccati_frame(P, g)
        if f is not None:
            hi, frame = g, f
            if lo is not None:
                break
            if g / _START_GROWTH <= floor:
                return None
            g /= _START_GROWTH
        else:
            lo = g
            if hi is not None:
                break
            g *= _START_GROWTH
    if frame is None or lo is None:
        return None
    for _ in range(_START_BISECTIONS):
        mid = float(np.sqrt(lo * hi))
        f = riccati_frame(P, mid)
        if f is None:
            lo = mid
        else:
            hi, frame = mid, f
    return hi, frame


def balancing_transform(R: np.ndarray, S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Contragredient state transformation that balances the two Lyapunov matrices.

    Returns ``T`` and ``sigma`` with ``T⁻¹ R T⁻ᵀ = Tᵀ S T = diag(sigma)`` (the
    coordinates of a balanced realisation, with ``R``, ``S`` in the roles of the
    controllability and observability Gramians).  In these coordinates the γ-optimal
    ``X`` and ``Y`` of the change-of-variables LMI have equal, ordered spectra, so one
    absolute slack and one trace box mean the same thing for both; the raw solutions
    of a plant with fast and slow modes can differ by ten decades, and a slack that is
    large for one is below the solver's tolerance for the other.

    Examples
    --------
    >>> import numpy as np
    >>> R, S = np.diag([4.0, 1.0]), np.array([[2.0, 0.5], [0.5, 1.0]])
    >>> T, sigma = balancing_transform(R, S)
    >>> bool(np.allclose(np.linalg.solve(T, np.linalg.solve(T, R).T), np.diag(sigma)))
    True
    >>> bool(np.allclose(T.T @ S @ T, np.diag(sigma)))
    True
    """
    def sqrtm_psd(M):
        w, V = np.linalg.eigh(_sym(M))
        # the γ-optimal R, S are positive definite (R >= S⁻¹ > 0); clip what an
        # inaccurate solve leaves at or below zero
        w = np.maximum(w, 1e-12 * max(w[-1], 1e-300))
        return V * np.sqrt(w)[None, :]

    Lr, Ls = sqrtm_psd(R), sqrtm_psd(S)
    _U, sigma, Vt = np.linalg.svd(Ls.T @ Lr)
    return Lr @ Vt.T / np.sqrt(sigma)[None, :], sigma


class ControllerLmi:
    """The change-of-variables bounded-real LMI of a plant, built once.

    Scherer, Gahinet & Chilali (IEEE TAC 42 (1997) 896-911) make the closed-loop
    bounded-real inequality affine in ``(X, Y, Â, B̂, Ĉ, D̂)``; the controller then
    follows from those variables by exact formulas.  ``Â`` is eliminated (it fills one
    free off-diagonal block) and recovered in closed form, which leaves two inequalities
    of size ``n + nw + nz`` instead of one of size ``2n + nw + nz``: on the 22-state
    benchmark plant the solve took 5.2 s instead of 7.7 s (loaded machine), same
    certified γ.  Near the optimal γ the solution degenerates (``X -> Y⁻¹``, so
    ``I - XY`` is singular and the controller gets absurdly fast poles).  At a given
    (relaxed) γ we therefore take the point of largest common slack ``t`` of the
    bounded-real inequalities (``<= -0.1 t I``) and of the coupling ``>= t I``, inside
    ``trace(X̂) + trace(Ŷ) <= trace_bound``.

    The variables are written relative to a :class:`Frame` taken from the γ-optimal
    ``(R, S)``: ``Y = D Ŷ D`` and ``X = D X̂ D`` in the frame's balanced coordinates,
    so that the slack ``t`` is a relative margin and ``X̂ ≈ Ŷ ≈ I`` near the optimum.

    γ and the trace bound are CVXPY Parameters, so a re-solve at another level reuses
    the compiled problem.  ``P`` must have ``D22 = 0`` and should be scaled;
    ``P.nstates`` must be positive.
    """

    def __init__(self, P: GeneralizedPlant, frame: Frame | None = None):
        from ..lti.scaling import transform_states

        n, nw, nu, nz, ny = P.nstates, P.nw, P.nu, P.nz, P.ny
        self.frame = Frame.identity(n) if frame is None else frame
        self.Pb = transform_states(P, self.frame.T)  # the controller is built here
        # the Y inequality in the coordinates of Ŷ, the X inequality in those of X̂
        br, bs = (Q.blocks() for Q in self.frame.plants(P))
        D11, D12, D21 = br["D11"], br["D12"], br["D21"]
        self.X = cp.Variable((n, n), symmetric=True)  # X̂
        self.Y = cp.Variable((n, n), symmetric=True)  # Ŷ
        self.Bh = cp.Variable((n, ny))  # B̂ in the X̂ coordinates
        self.Ch = cp.Variable((nu, n))  # Ĉ in the Ŷ coordinates
        self.Dh = cp.Variable((nu, ny))
        self.gamma = cp.Parameter(nonneg=True)
        self.trace_bound = cp.Parameter(nonneg=True)
        self.t = cp.Variable()
        X, Y, Bh, Ch, Dh, g, t = self.X, self.Y, self.Bh, self.Ch, self.Dh, self.gamma, self.t
        # Blocks of the inequality in the order (Y, X, [w; z]); Â enters only the (X, Y)
        # block, freely, so it is eliminated: the inequality holds for some Â iff its two
        # principal parts without that block hold (Scherer et al. 1997, Sec. IV), and
        # Â is then recovered in closed form (:meth:`controller`).  Two LMIs of size
        # n + nw + nz replace one of size 2n + nw + nz.
        AY = br["A"] @ Y + br["B2"] @ Ch
        XA = X @ bs["A"] + Bh @ bs["C2"]
        E = cp.bmat([[-g * np.eye(nw), (D11 + D12 @ Dh @ D21).T],
                     [D11 + D12 @ Dh @ D21, -g * np.eye(nz)]])
        self._c = cp.vstack([(br["B1"] + br["B2"] @ Dh @ D21).T, br["C1"] @ Y + D12 @ Ch])
        self._d = cp.vstack([(X @ bs["B1"] + Bh @ D21).T, bs["C1"] + D12 @ Dh @ bs["C2"]])
        self._e = E
        m = n + nw + nz
        slack = _BRL_SLACK_WEIGHT * t
        Sinv = np.diag(1.0 / self.frame.scale**2)
        cons = [_sym(cp.bmat([[AY + AY.T, self._c.T], [self._c, E]])) << -slack * np.eye(m),
                _sym(cp.bmat([[XA + XA.T, self._d.T], [self._d, E]])) << -slack * np.eye(m),
                _sym(cp.bmat([[Y, Sinv], [Sinv, X]])) >> t * np.eye(2 * n),
                cp.trace(X) + cp.trace(Y) <= self.trace_bound,
                t <= 1.0]
        self.problem = cp.Problem(cp.Maximize(self.t), cons)

    def controller(self, gamma: float, trace_bound: float, opts: HinfsynOptions,
                   refine: bool = True):
        """The controller at the centre of the feasible set at level ``gamma``.

        ``refine`` turns on Clarabel's iterative refinement of each KKT solve.

        Returns
        -------
        K : control.StateSpace
        cond_xy : float
            Condition number of ``I - XY``.
        status : str
        warnings : tuple of str

        Raises
        ------
        InfeasibleError
            If no strictly feasible point exists inside the trace box.
        SolverError
            If Clarabel fails after ``opts.max_recoveries`` recoveries.
        """
        b = self.Pb.blocks()
        A, B2, C2 = b["A"], b["B2"], b["C2"]
        n = self.Pb.nstates
        self.gamma.value = float(gamma)
        self.trace_bound.value = float(trace_bound)
        warnings: list[str] = []
        # Clarabel's default static regularisation at least: with 1e-10 its first KKT
        # factorisation failed on the relative form of COMPleib HE1, while 1e-8 and 1e-7
        # gave the same controller (measured 2026-11-25)
        status, _ = _solve(self.problem, opts, f"controller LMI at gamma={gamma:.6g}",
                           warnings, refine=refine,
                           static_reg=max(_STATIC_REG, _CONTROLLER_STATIC_REG))
        t = self.t.value
        if status in _INFEASIBLE or t is None or t <= 0.0:
            raise InfeasibleError(
                f"no controller achieves gamma = {gamma:.6g} with trace(X̂) + trace(Ŷ) <= "
                f"{trace_bound:.3g}")
        # back to the balanced coordinates: Y = D Ŷ D, X = D X̂ D, Ĉ_b = Ĉ D, B̂_b = D B̂,
        # and the state columns of c and d scale by D
        d = self.frame.scale
        Xv, Yv = _sym(d[:, None] * self.X.value * d[None, :]), \
            _sym(d[:, None] * self.Y.value * d[None, :])
        Bhv, Chv, Dk = d[:, None] * self.Bh.value, self.Ch.value * d[None, :], self.Dh.value
        # the eliminated block: with the slack shifted into the diagonal blocks, choosing
        # the (X, Y) block as d^T e^-1 c makes the Schur complement on [w; z]
        # block-diagonal, and each diagonal block is one of the two solved inequalities
        shift = _BRL_SLACK_WEIGHT * float(t) * np.eye(self._e.shape[0])
        c, dd = self._c.value * d[None, :], self._d.value * d[None, :]
        e = _sym(self._e.value) + shift
        Ahv = dd.T @ np.linalg.solve(e, c) - (A + B2 @ Dk @ C2).T
        # N M^T = I - X Y with N = I; M^{-T} applied by solves, never by explicit inverses.
        MT = np.eye(n) - Xv @ Yv
        sv = np.linalg.svd(MT, compute_uv=False)
        cond_xy = float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")
        Bk = Bhv - Xv @ B2 @ Dk
        Ck = np.linalg.solve(MT.T, (Chv - Dk @ C2 @ Yv).T).T
        inner = Ahv - Xv @ B2 @ Ck @ MT - Bk @ C2 @ Yv - Xv @ (A + B2 @ Dk @ C2) @ Yv
        Ak = np.linalg.solve(MT.T, inner.T).T
        return control.ss(Ak, Bk, Ck, Dk), cond_xy, str(status), tuple(warnings)
