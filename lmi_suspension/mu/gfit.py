"""G-scalings of real parametric blocks, fitted and absorbed into the plant (D-G-K).

At each frequency the mixed-µ upper bound (Fan, Tits & Doyle 1991) holds with scalings
``X = D*D ≻ 0`` and ``G`` (``mussv``'s ``D_left``, ``D_right``, ``G``)::

    M* X_L M + j(G M - M* G*) ⪯ β² X_R.

With ``N = D_L M D_R⁻¹ / β`` and ``Ĝ = D_L⁻¹ G* D_R⁻¹ / β`` this reads
``(N - jĜ)*(N - jĜ) ⪯ I + Ĝ*Ĝ``, i.e.::

    σ̄((N - jĜ)(I + Ĝ*Ĝ)^(-1/2)) ≤ 1                                          (1)

(Young, "Controller design with real parametric uncertainty", Int. J. Control 65(3),
1996).  ``Ĝ`` is non-zero on the real blocks only, a real number per block (1×1 blocks;
a repeated real block is given ``ĝ I``, a valid restriction) and odd in ω.  For
synthesis, (1) must be the H∞ norm of a plant that is an LFT in the controller:
``N H - T`` with stable ``H`` (on the block's ``w`` channel) and ``T`` (added to the
block's diagonal entry of ``P11``) such that ``T(jω) = j ĝ(ω) H(jω)`` and
``|H(jω)| = (1 + ĝ(ω)²)^(-1/2)``.  A stable transfer function is never purely imaginary
on the axis, but the ratio of two can be, because only ``|H|`` matters in (1):

* ``ĝ`` is an odd rational function ``z(ω) = Σ a_k ω / (c_k² + ω²)`` (fixed poles
  ``c_k`` log-spaced over the band, real, or complex standing for conjugate pairs), so
  ``Z(s) = Σ a_k s / (c_k² - s²)`` has ``Z(jω) = j z(ω)`` and poles at ``±c_k``.  The
  coefficients are linear in the bound: with the fitted D applied (``Mt = D̂ M D̂⁻¹``),
  ``Mt* Mt + j(G Mt - Mt* G) ⪯ β² I`` is an LMI in ``a_k`` at every grid frequency,
  and :func:`optimal_gscales` minimises β over all of them at once.  (Fitting the
  pointwise optimal ``ĝ`` instead, :func:`fit_gscales`, missed it by 58-106 % on the
  oscillator of tests/test_dgk.py and left D-G-K above complex D-K; the pointwise
  optimum is not unique, and where a block does not act it runs off.)
* ``H = W⁻¹ A`` with ``A(s) = Π (c_k - s)/(c_k + s)``, the all-pass whose zeros cancel
  ``Z``'s unstable poles, and ``W`` the stable minimum-phase spectral factor of
  ``1 + Z̃~Z̃``, ``Z̃ = Z A`` (stable, ``|Z̃(jω)| = |z(ω)|``), from a Riccati equation:
  ``|H|² (1 + z²) = 1`` exactly, no magnitude fit;
* ``T = Z H = Z̃ W⁻¹``, stable.

Any such pair gives a valid bound; the choice of ``z`` only decides how close to the
pointwise optimum the K-step's objective is.  Every iterate of D-G-K is certified by the
mixed-µ bounds of its true closed loop, not by the scalings.
"""

from __future__ import annotations

import logging
import warnings
from dataclasses import dataclass

import control
import numpy as np

from ..errors import DimensionError, SolverError
from ..umodel.blocks import BlockStructure

logger = logging.getLogger(__name__)

__all__ = ["GScaleFit", "central_dg", "fit_gscales", "gscaled_plant", "optimal_gscales"]

#: poles of the odd basis of fit_gscales' least-squares fit of a pointwise ĝ (kept for
#: comparison and as a tool; D-G-K uses optimal_gscales).  On the oscillator of
#: tests/test_dgk.py 3 log-spaced poles fitted ĝ only to 58-106 % of its peak and D-G-K
#: ended above complex D-K with them (2026-11-27)
_G_POLES = 3
#: basis sizes :func:`optimal_gscales` tries in turn, and how close to the pointwise
#: mixed-µ peak its level must come.  On the oscillator of tests/test_dgk.py, at the loop
#: of D-G-K's second iterate (µ 1.10643), 3, 6 and 10 log-spaced poles gave levels 1.2056,
#: 1.1092 and 1.10644 (2026-11-27); at the central controller's loop 3 poles already
#: reached µ to 1e-4
_G_POLE_COUNTS = (3, 6, 10)
_G_LEVEL_RTOL = 5e-3
#: relative size of the unstable remainder above which the all-pass is taken not to
#: have cancelled the odd function's unstable poles (roundoff leaves ~1e-12)
_CANCEL_TOL = 1e-6
#: Tikhonov weight on the basis coefficients, relative to the data's scale (keeps
#: coefficients of nearly collinear basis functions from cancelling each other)
_RIDGE = 1e-6


@dataclass(frozen=True, eq=False)
class GScaleFit:
    """Rational G-scalings of the real blocks (see the module docstring).

    Attributes
    ----------
    blocks : tuple of int
        Indices (in the block structure) of the real blocks.
    T, H : tuple of control.StateSpace
        Per real block, the stable SISO ``T_i`` and ``H_i``.
    poles, coefficients : tuple of numpy.ndarray
        Per real block, ``c_k`` and ``a_k`` of ``z_i``.
    errors : tuple of float
        Per real block, ``max |z_i(ω) - ĝ_i(ω)|`` on the grid relative to ``max |ĝ_i|``.
    beta : float
        The level the scalings were taken at.
    HT : tuple of control.StateSpace
        Per real block, ``[H_i; T_i]`` on one set of states (what the plant uses).
    """

    blocks: tuple
    T: tuple
    H: tuple
    poles: tuple
    coefficients: tuple
    errors: tuple
    beta: float
    HT: tuple = ()

    def z(self, i: int, omega) -> np.ndarray:
        """The fitted ``z_i(ω)``."""
        return _z_of(self.poles[i], self.coefficients[i], omega)


def central_dg(M, struct: BlockStructure, beta: float, g_max: float = 5.0):
    """Scalings for D-G-K at a fixed level β: at each frequency, ``x_i > 0`` per block
    (``D = diag(√x_i I)``) and ``g_i`` per real block (``G = diag(g_i I)``) that
    maximise the margin ``t`` of::

        β² X_R - M* X_L M - j(G M - M* G) ⪰ t I,   x_last = 1,   |g_i| ≤ g_max β x_i.

    The optimum of the µ bound is a poor thing to fit: where a real parameter cannot
    act, it drives that block's ``x`` to zero with ``g`` finite, so ``ĝ = g/(x β)`` runs
    off (to 1e6 on the oscillator of tests/test_dgk.py).  Away from the peak the level
    β leaves room, and the central feasible point is regular; the bound on ``|ĝ|``
    keeps it so at the peak (where a larger ``|ĝ|`` would be needed, ``t`` is then
    negative and the K-step's scaled plant peaks above 1 there).

    Parameters
    ----------
    M : array_like, shape (n_out, n_in, n_freq)
        The loop's frequency response.
    struct : BlockStructure
        Full complex blocks and repeated real or complex scalars (each scaled by one
        ``x_i``: a restriction of their full D and G, still a valid bound).
    beta : float
        The level.
    g_max : float
        Bound on ``|ĝ_i|``.

    Returns
    -------
    d : numpy.ndarray, shape (n_blocks, n_freq)
        ``√x_i``.
    g : numpy.ndarray, shape (n_real_blocks, n_freq)
        ``ĝ_i = g_i / (x_i β)``.
    margin : numpy.ndarray, shape (n_freq,)
        ``t`` at each frequency (``>= 0``: the scalings certify µ ≤ β there).
    """
    import cvxpy as cp

    M = np.asarray(M)
    nout, nin, nf = M.shape
    nb = struct.n_blocks
    x = cp.Variable(nb)
    gv = cp.Variable(nb)
    t = cp.Variable()
    zs, ws = struct.row_slices(), struct.col_slices()  # M's rows (z) and columns (w)
    EL = [np.zeros((nout, nout)) for _ in range(nb)]
    ER = [np.zeros((nin, nin)) for _ in range(nb)]
    for i, (z, w) in enumerate(zip(zs, ws)):
        EL[i][z, z] = np.eye(z.stop - z.start)
        ER[i][w, w] = np.eye(w.stop - w.start)
    XR = sum(x[i] * ER[i] for i in range(nb))
    real = [i for i, b in enumerate(struct.blocks) if b.is_real]
    # M* X_L M = Σ x_i M* E_i M and j(G M - M* G*) = Σ g_i j(S_i M - M* S_iᵀ): with
    # these products as the parameters the problem is DPP, compiled once for all ω
    Q = [cp.Parameter((nin, nin), complex=True) for _ in range(nb)]
    S = {i: _selector(ws[i], zs[i], nin, nout) for i in real}
    R = {i: cp.Parameter((nin, nin), complex=True) for i in real}
    H = (beta**2 * XR - sum(x[i] * Q[i] for i in range(nb))
         - sum((gv[i] * R[i] for i in real), np.zeros((nin, nin))) - t * np.eye(nin))
    cons = [(H + H.H) / 2 >> 0, x[nb - 1] == 1, x >= 1e-9, t <= 1.0]
    cons += [cp.abs(gv[i]) <= g_max * beta * x[i] for i in real]
    cons += [gv[i] == 0 for i in range(nb) if i not in real]
    prob = cp.Problem(cp.Maximize(t), cons)
    d = np.empty((nb, nf))
    g = np.empty((len(real), nf))
    margin = np.empty(nf)
    for k in range(nf):
        Mk = M[:, :, k]
        for i in range(nb):
            Q[i].value = Mk.conj().T @ EL[i] @ Mk
        for i in real:
            R[i].value = 1j * (S[i] @ Mk - Mk.conj().T @ S[i].T)
        _solve(prob, f"central D-G scalings at frequency index {k}")
        if prob.status not in ("optimal", "optimal_inaccurate") or x.value is None:
            raise SolverError(f"central D-G scalings: solver status {prob.status} at "
                              f"frequency index {k}")
        xv = np.maximum(np.asarray(x.value), 1e-12)
        d[:, k] = np.sqrt(xv)
        g[:, k] = [float(gv.value[i]) / (xv[i] * beta) for i in real]
        margin[k] = float(t.value)
    return d, g, margin


def _solve(prob, what: str) -> None:
    """Solve with Clarabel.  An inaccurate solution is used as it is: scalings only
    choose the plant of the next K-step, and the µ bound of the loop it leads to is
    computed afresh, so CVXPY's warning is replaced by an INFO record."""
    import cvxpy as cp

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Solution may be inaccurate",
                                category=UserWarning)
        prob.solve(solver=cp.CLARABEL)
    if prob.status == "optimal_inaccurate":
        logger.info("%s: the solver's solution is inaccurate; used as it is", what)


def _selector(rs: slice, cs: slice, nin: int, nout: int) -> np.ndarray:
    """``n_in × n_out`` with ones on the diagonal of the block ``(rs, cs)``."""
    E = np.zeros((nin, nout))
    for a, b in zip(range(rs.start, rs.stop), range(cs.start, cs.stop)):
        E[a, b] = 1.0
    return E


def _real_slices(struct: BlockStructure):
    """``(index, w slice, z slice)`` of each real block."""
    out, r0, c0 = [], 0, 0
    for i, b in enumerate(struct.blocks):
        if b.is_real:
            out.append((i, slice(r0, r0 + b.rows), slice(c0, c0 + b.cols)))
        r0, c0 = r0 + b.rows, c0 + b.cols
    return out


def _basis(omega: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Real basis of ``z`` for the poles ``c`` (``Re c > 0``): ``ω/(c² + ω²)`` for a real
    ``c``; its real and imaginary parts, doubled, for a complex ``c`` (which stands for
    the pair ``c, c̄`` with coefficients ``a, ā``).  Shape ``(n_freq, n_coef)``."""
    w = np.asarray(omega, dtype=float)[:, None]
    cols = []
    for ck in np.asarray(c, dtype=complex):
        phi = (w / (ck**2 + w**2)).ravel()
        if ck.imag == 0:
            cols.append(phi.real)
        else:  # 2 Re(a φ) = 2 Re(a) Re(φ) - 2 Im(a) Im(φ)
            cols += [2 * phi.real, -2 * phi.imag]
    return np.column_stack(cols)


def _complex_coefficients(c: np.ndarray, coef: np.ndarray) -> np.ndarray:
    """The basis coefficients of :func:`_basis` as one complex ``a_k`` per pole."""
    out, j = [], 0
    for ck in c:
        if ck.imag == 0:
            out.append(complex(coef[j]))
            j += 1
        else:
            out.append(complex(coef[j], coef[j + 1]))
            j += 2
    return np.array(out)


def _log_poles(omega: np.ndarray, n: int) -> np.ndarray:
    lo, hi = np.log10(omega[0]), np.log10(omega[-1])
    return np.logspace(lo + 0.5 * (hi - lo) / n, hi - 0.5 * (hi - lo) / n, n).astype(complex)


def _odd_fit(omega: np.ndarray, g: np.ndarray, weights: np.ndarray, c: np.ndarray):
    """Coefficients of ``z(ω) = Σ a_k φ_k(ω)`` (:func:`_basis`) fitted to ``g`` by
    weighted least squares with a small ridge."""
    basis = _basis(omega, c)
    scale = np.max(np.abs(basis), axis=0)  # columns of equal size before the ridge
    W = np.sqrt(weights)[:, None]
    A = np.vstack([W * basis / scale, np.sqrt(_RIDGE) * np.eye(basis.shape[1])])
    b = np.concatenate([np.sqrt(weights) * g, np.zeros(basis.shape[1])])
    return np.linalg.lstsq(A, b, rcond=None)[0] / scale


def _sections(c: np.ndarray, coef: np.ndarray):
    """``Y(s) = -Σ (a_k/2)/(s + c_k)`` over the poles and their conjugates, so that
    ``Z(s) = Y(s) - Y(-s)`` has ``Z(jω) = 2j Im Y(jω) = j z(ω)``, and the all-pass
    ``Π (c_k - s)/(c_k + s)`` with the same poles: both as lists of real sections."""
    Y, Al = [], []
    for ck, ak in zip(c, _complex_coefficients(c, coef)):
        if ck.imag == 0:
            r = ck.real
            Y.append(control.ss([[-r]], [[1.0]], [[-ak.real / 2]], [[0.0]]))
            Al.append(control.ss([[-r]], [[1.0]], [[2.0 * r]], [[-1.0]]))
        else:  # -Re[a (s + c̄)] / ((s + c)(s + c̄)), companion form
            m2, tr = abs(ck) ** 2, 2 * ck.real
            Acomp = [[0.0, 1.0], [-m2, -tr]]
            Y.append(control.ss(Acomp, [[0.0], [1.0]],
                                [[-(ak * np.conj(ck)).real, -ak.real]], [[0.0]]))
            Al.append(control.ss(Acomp, [[0.0], [1.0]], [[0.0, -2.0 * tr]], [[1.0]]))
    return Y, Al


def _stable_part(sys: control.StateSpace) -> tuple[control.StateSpace, float]:
    """Additive stable part of ``sys`` (ordered real Schur form and a Sylvester equation
    that decouples it), with the size of the antistable remainder relative to the
    stable part (``‖C₂‖‖B₂‖ / (‖C₁‖‖B₁‖)``)."""
    from scipy.linalg import schur, solve_sylvester

    A, B, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C, sys.D))
    Ts, Q, k = schur(A, output="real", sort="lhp")
    T11, T12, T22 = Ts[:k, :k], Ts[:k, k:], Ts[k:, k:]
    X = solve_sylvester(T11, -T22, -T12)
    QB, CQ = Q.T @ B, C @ Q
    B1 = QB[:k] - X @ QB[k:]
    C1 = CQ[:, :k]
    B2, C2 = QB[k:], CQ[:, :k] @ X + CQ[:, k:]
    rest = np.linalg.norm(C2) * np.linalg.norm(B2) / max(
        np.linalg.norm(C1) * np.linalg.norm(B1), 1e-300)
    return control.ss(T11, B1, C1, D), float(rest)


def _realize(c: np.ndarray, coef: np.ndarray):
    """Stable ``(H, T, [H; T])`` with ``T(jω) = j z(ω) H(jω)`` and ``|H(jω)|² (1 + z(ω)²) = 1``
    exactly.

    ``Z = Y(s) - Y(-s)`` has ``Z(jω) = j z(ω)``; ``Z̃ = Z A`` (``A`` the all-pass whose
    zeros are ``Z``'s unstable poles) is stable with ``|Z̃(jω)| = |z(ω)|``, and
    ``1 + Z̃~Z̃ = W~W`` with ``W = 1 + F(sI - A_Z̃)⁻¹B`` from the LQR Riccati equation of
    ``Z̃`` (its return difference; ``W`` is stable and minimum phase).  Then
    ``H = W⁻¹ A`` and ``T = Z̃ W⁻¹ = C(sI - A + BF)⁻¹B``; ``[H; T]`` is realized on
    one set of states (``T`` reads ``W⁻¹``'s).
    """
    from scipy.linalg import solve_continuous_are

    Y, Al = _sections(c, coef)
    Ys = Y[0]
    for y in Y[1:]:
        Ys = Ys + y
    Ay, By, Cy = (np.asarray(m, dtype=float) for m in (Ys.A, Ys.B, Ys.C))
    n = Ay.shape[0]
    Z = control.ss(np.block([[Ay, np.zeros((n, n))], [np.zeros((n, n)), -Ay]]),
                   np.vstack([By, By]), np.hstack([Cy, Cy]), [[0.0]])
    allpass = Al[0]
    for a in Al[1:]:
        allpass = allpass * a
    Zt, rest = _stable_part(Z * allpass)
    if not rest < _CANCEL_TOL:
        raise SolverError(f"G-scaling realization: the all-pass did not cancel the "
                          f"unstable poles (remainder {rest:.2g})")
    A, B, C = (np.asarray(m, dtype=float) for m in (Zt.A, Zt.B, Zt.C))
    X = solve_continuous_are(A, B, C.T @ C, np.eye(1))
    F = B.T @ X
    Winv = control.ss(A - B @ F, B, np.vstack([-F, C]), [[1.0], [0.0]])  # [W⁻¹; T]
    # [H; T] shares W⁻¹'s states: 3 per pole instead of 5 in two realizations
    HT = control.append(allpass, control.ss([], [], [], [[1.0]])) * Winv
    return HT[0, 0], HT[1, 0], HT


def _z_of(c: np.ndarray, coef: np.ndarray, omega) -> np.ndarray:
    return _basis(np.asarray(omega, dtype=float).ravel(), c) @ coef


def fit_gscales(omega, g, struct: BlockStructure, beta: float, *,
                weights=None, poles=None) -> GScaleFit:
    """Fit ``T_i``, ``H_i`` of every real block to ``ĝ_i(ω)`` (module docstring).

    Parameters
    ----------
    omega : array_like
        Strictly increasing positive grid, rad/s.
    g : array_like, shape (n_real_blocks, n_freq)
        ``ĝ_i(ω)``, e.g. from :func:`central_dg`.
    struct : BlockStructure
        The block structure (its real blocks, in order, are the rows of ``g``).
    beta : float
        The level ``g`` was taken at (kept with the fit).
    weights : array_like, optional
        Non-negative weights per frequency (emphasise the µ peak).
    poles : array_like, optional
        The ``c_k`` of the basis (``Re c_k > 0``; a complex one stands for a conjugate
        pair); default log-spaced over the grid.

    Returns
    -------
    GScaleFit

    Examples
    --------
    An odd ``ĝ`` that the basis holds exactly is fitted to roundoff, ``T = j ĝ H`` and
    ``|H| = (1 + ĝ²)^(-1/2)``:

    >>> import numpy as np
    >>> from lmi_suspension.mu import BlockStructure
    >>> w = np.logspace(-1, 1, 41)
    >>> s = BlockStructure.from_blk([[-1, 0]])
    >>> g = 0.5 * w / (1 + w**2)
    >>> fit = fit_gscales(w, [g], s, 1.0, poles=[1.0, 3.0])
    >>> x = 1j * w
    >>> ratio = fit.T[0](x) / fit.H[0](x)
    >>> bool(np.allclose(ratio, 1j * g, atol=1e-6))
    True
    >>> bool(np.allclose(abs(fit.H[0](x)), 1 / np.sqrt(1 + g**2)))
    True
    """
    omega = np.asarray(omega, dtype=float).ravel()
    real = _real_slices(struct)
    g = np.asarray(g, dtype=float).reshape(len(real), -1)
    if g.shape[1] != omega.size:
        raise DimensionError(f"g has {g.shape[1]} frequencies, omega {omega.size}")
    w = np.ones(omega.size) if weights is None else np.asarray(weights, dtype=float).ravel()
    c = _log_poles(omega, _G_POLES) if poles is None else _as_poles(poles)
    coefs = [_odd_fit(omega, gi, w, c) for gi in g]
    return _assemble(real, c, coefs, omega, g, beta)


def _as_poles(poles) -> np.ndarray:
    c = np.asarray(poles, dtype=complex).ravel()
    if c.size == 0 or np.any(c.real <= 0) or not np.all(np.isfinite(c)):
        raise DimensionError(f"G-scaling basis poles must have positive real parts, got {c}")
    return np.where(c.imag < 0, np.conj(c), c)


def _assemble(real, c, coefs, omega, g, beta) -> GScaleFit:
    T, H, HT, errors = [], [], [], []
    for k, coef in enumerate(coefs):
        Hk, Tk, HTk = _realize(c, coef)
        H.append(Hk)
        T.append(Tk)
        HT.append(HTk)
        if g is not None:
            z = _z_of(c, coef, omega)
            errors.append(float(np.max(np.abs(z - g[k])) / max(np.max(np.abs(g[k])), 1e-300)))
        else:
            errors.append(0.0)
    return GScaleFit(blocks=tuple(i for i, _, _ in real), T=tuple(T), H=tuple(H),
                     poles=tuple(c for _ in coefs), coefficients=tuple(coefs),
                     errors=tuple(errors), beta=float(beta), HT=tuple(HT))


def optimal_gscales(omega, Mt, struct: BlockStructure, poles=None, *,
                    g_max: float = 5.0, target: float | None = None,
                    max_poles: int | None = None) -> GScaleFit:
    """Rational G-scalings chosen for the bound itself, not fitted to pointwise ones.

    With the D-scales already applied (``Mt = D̂ M D̂⁻¹`` on the grid), the mixed-µ
    condition ``Mt* Mt + j(G Mt - Mt* G) ⪯ β² I`` is linear in ``G``, hence in the
    coefficients of ``z(ω) = Σ a_k φ_k(ω)`` (one ``z_i`` per real block, ``G = z_i I``
    on its channels).  One SDP over the whole grid minimises ``β²``; ``ĝ = z/β`` and
    the exact realization of :func:`_realize` then give
    ``‖(Mt/β) H - T‖ ≤ 1`` at every grid frequency, so the scaled plant's norm with the
    controller of ``Mt`` is 1 up to what happens between grid points.

    Parameters
    ----------
    omega : array_like
        Strictly increasing positive grid, rad/s.
    Mt : array_like, shape (n_out, n_in, n_freq)
        The D-scaled loop's frequency response.
    struct : BlockStructure
        The block structure of ``Mt``.
    poles : array_like, optional
        Basis poles ``c_k`` (as in :func:`fit_gscales`).
    g_max : float
        Bound on ``|ĝ_i|`` at the grid points (keeps the SDP bounded where a real block
        does not act).
    target : float, optional
        Without ``poles``: the pointwise mixed-µ peak of the loop.  The basis grows
        through ``_G_POLE_COUNTS`` log-spaced poles until the level is within
        ``_G_LEVEL_RTOL`` of it (each pole adds three states to ``H`` and two to ``T``).
    max_poles : int, optional
        Without ``poles``: the largest basis tried (sizes of ``_G_POLE_COUNTS`` above it
        are skipped; below the smallest, that many poles): bounds the states the
        G-scalings add to the scaled plant.

    Returns
    -------
    GScaleFit
        ``beta`` is the level reached on the grid (``errors`` are 0: nothing fitted).
    """
    omega = np.asarray(omega, dtype=float).ravel()
    if poles is None and target is not None:
        best = None
        counts = _G_POLE_COUNTS if max_poles is None else (
            tuple(n for n in _G_POLE_COUNTS if n <= max_poles) or (int(max_poles),))
        for n in counts:
            fit = optimal_gscales(omega, Mt, struct, _log_poles(omega, n), g_max=g_max)
            if best is None or fit.beta < best.beta:
                best = fit
            if fit.beta <= target * (1 + _G_LEVEL_RTOL):
                break
        logger.debug("optimal G-scalings: level %.6g with %d poles (target %.6g)",
                     best.beta, best.poles[0].size if best.poles else 0, target)
        return best
    return _optimal_gscales(omega, Mt, struct, poles, g_max)


def _optimal_gscales(omega, Mt, struct, poles, g_max) -> GScaleFit:
    from .lmisolve import solve_lmi

    Mt = np.asarray(Mt)
    nout, nin, nf = Mt.shape
    real = _real_slices(struct)
    c = _log_poles(omega, _G_POLES) if poles is None else _as_poles(poles)
    basis = _basis(omega, c)
    scale = np.max(np.abs(basis), axis=0)
    Bn = basis / scale
    nb = Bn.shape[1]
    nr = len(real)
    beta0 = float(np.sqrt(max(np.max([np.linalg.norm(Mt[:, :, k], 2) for k in range(nf)]) ** 2,
                              1e-300)))
    # variables [a (nr x nb, by rows), λ]: minimise λ subject to, at every grid point,
    # λ I - Mk* Mk - Σ_r (a_r · Bn_k) j(S_r Mk - Mk* S_rᵀ) ⪰ 0, posed for Clarabel directly
    # (:mod:`.lmisolve`; through CVXPY, compiling this problem was most of the fits'
    # time: 2 problems, 23.5 of 31.4 s in a profile of the seat's "start" run, 2026-12-02)
    S = [_selector(rl, cl, nin, nout) for _, rl, cl in real]
    nvar = nr * nb + 1
    F0 = -np.einsum("jik,jlk->kil", Mt.conj(), Mt)  # -Mk* Mk, (nf, nin, nin)
    F = np.zeros((nf, nvar, nin, nin), dtype=complex)
    F[:, -1] = np.eye(nin)
    for r in range(nr):
        SM = np.einsum("ij,jlk->kil", S[r], Mt)  # S_r Mk, (nf, nin, nin)
        R = 1j * (SM - np.conj(np.swapaxes(SM, -1, -2)))
        F[:, r * nb:(r + 1) * nb] = -Bn[:, :, None, None] * R[:, None]
    # |ĝ| = |z|/β <= g_max at the grid points, with β <= beta0 (the unscaled level)
    Gz = np.zeros((2 * nr * nf, nvar))
    for r in range(nr):
        Gz[r * nf:(r + 1) * nf, r * nb:(r + 1) * nb] = Bn
        Gz[(nr + r) * nf:(nr + r + 1) * nf, r * nb:(r + 1) * nb] = -Bn
    cost = np.zeros(nvar)
    cost[-1] = 1.0
    sol = solve_lmi(cost, F0, F, G=Gz, h=np.full(2 * nr * nf, g_max * beta0),
                    what="optimal G-scalings")
    a = sol.x[:-1].reshape(nr, nb)
    beta = float(np.sqrt(max(sol.x[-1], 1e-300)))
    coefs = [np.asarray(a[r]) / scale / beta for r in range(nr)]
    return _assemble(real, c, coefs, omega, None, beta)


def gscaled_plant(PD: control.StateSpace, nmeas: int, ncon: int, struct: BlockStructure,
                  gfit: GScaleFit) -> control.StateSpace:
    """``P_DG``: the D-scaled plant with the G-scalings absorbed.

    ``F_l(P_DG, K) = (D M D⁻¹ / β) H - T`` for ``M = F_l(P, K)``: the ``w`` channels
    of the µ blocks are divided by β, each real block's ``w`` channel passes ``H_i``,
    and ``T_i`` is subtracted from its diagonal entry of ``P11``; ``‖F_l(P_DG, K)‖∞ ≤ 1``
    certifies ``µ ≤ β`` (module docstring).  Performance and constraint channels beyond
    ``struct`` pass unchanged.
    """
    nin, nout = PD.ninputs, PD.noutputs
    nw_mu = sum(b.rows for b in struct.blocks)
    real = _real_slices(struct)
    # every input channel a SISO (1/β on the µ blocks' w, 1 elsewhere) or, on a real
    # block's w, the SIMO [H_i/β; T_i]: its T output is routed to z_i below
    parts, t_routes = [], []  # t_routes: (z index) per T output, in order
    real_w = {}
    for (i, rl, cl), HTi in zip(real, gfit.HT):
        for kz, kw in zip(range(cl.start, cl.stop), range(rl.start, rl.stop)):
            real_w[kw] = (kz, HTi)
    for k in range(nin):
        if k in real_w:
            kz, HTi = real_w[k]
            parts.append(control.ss(HTi.A, HTi.B, np.asarray(HTi.C) * [[1.0 / gfit.beta], [1.0]],
                                    np.asarray(HTi.D) * [[1.0 / gfit.beta], [1.0]]))
            t_routes.append(kz)
        else:
            parts.append(control.ss([], [], [], [[1.0 / gfit.beta if k < nw_mu else 1.0]]))
    stacked = control.append(*parts)  # outputs interleaved: one or two per channel
    nT = len(t_routes)
    perm = np.zeros((nin + nT, nin + nT))
    row, t = 0, 0
    for k in range(nin):
        perm[k, row] = 1.0
        row += 1
        if k in real_w:
            perm[nin + t, row] = 1.0
            row, t = row + 1, t + 1
    right = control.ss([], [], [], perm) * stacked  # [scaled inputs; T outputs]
    L = np.hstack([np.eye(nout), np.zeros((nout, nT))])
    for t, kz in enumerate(t_routes):
        L[kz, nout + t] = -1.0
    through = control.append(PD, control.ss([], [], [], np.eye(nT))) if nT else PD
    return control.ss([], [], [], L) * through * right
