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

* ``ĝ`` is fitted by an odd rational function ``z(ω) = Σ a_k ω / (c_k² + ω²)``
  (linear least squares in ``a_k``, fixed poles ``c_k`` spread over the band), so
  ``Z(s) = Σ a_k s / (c_k² - s²)`` has ``Z(jω) = j z(ω)`` and poles at ``±c_k``;
* ``H = H_m A`` with ``H_m`` stable and minimum phase, ``|H_m| ≈ (1 + z²)^(-1/2)``
  (:func:`~lmi_suspension.mu.fit_magnitude`), and the all-pass
  ``A(s) = Π (c_k - s)/(c_k + s)``, whose zeros cancel ``Z``'s unstable poles;
* ``T = Z H = H_m Σ a_k s/(c_k + s)² Π_{j≠k} (c_j - s)/(c_j + s)``, stable.

Any such pair gives a valid bound; the fit only decides how close to the pointwise
optimum the K-step's objective is.  Every iterate of D-G-K is certified by the mixed-µ
bounds of its true closed loop, not by the fitted scalings.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import control
import numpy as np

from ..errors import DimensionError, SolverError
from .blocks import BlockStructure
from .dfit import fit_magnitude

logger = logging.getLogger(__name__)

__all__ = ["GScaleFit", "central_dg", "fit_gscales", "gscaled_plant"]

#: poles of the odd basis of ĝ's fit: this many, log-spaced over the design grid.  Not
#: yet chosen by a measurement: on the lightly damped oscillator of tests/test_dgk.py
#: they fitted ĝ only to 76-106 % of its peak (2026-11-27), which is why D-G-K is
#: still experimental
_G_POLES = 3
#: order of the minimum-phase magnitude factor H_m
_H_ORDER = 2
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
    """

    blocks: tuple
    T: tuple
    H: tuple
    poles: tuple
    coefficients: tuple
    errors: tuple
    beta: float

    def z(self, i: int, omega) -> np.ndarray:
        """The fitted ``z_i(ω)``."""
        w = np.asarray(omega, dtype=float)[:, None]
        c, a = self.poles[i], self.coefficients[i]
        return (w / (c[None, :] ** 2 + w**2)) @ a


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
        prob.solve(solver=cp.CLARABEL)
        if prob.status not in ("optimal", "optimal_inaccurate") or x.value is None:
            raise SolverError(f"central D-G scalings: solver status {prob.status} at "
                              f"frequency index {k}")
        xv = np.maximum(np.asarray(x.value), 1e-12)
        d[:, k] = np.sqrt(xv)
        g[:, k] = [float(gv.value[i]) / (xv[i] * beta) for i in real]
        margin[k] = float(t.value)
    return d, g, margin


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


def _odd_fit(omega: np.ndarray, g: np.ndarray, weights: np.ndarray):
    """``(c, a)`` of ``z(ω) = Σ a_k ω/(c_k² + ω²)`` fitted to ``g`` by weighted least
    squares with a small ridge."""
    lo, hi = np.log10(omega[0]), np.log10(omega[-1])
    c = np.logspace(lo + 0.5 * (hi - lo) / _G_POLES, hi - 0.5 * (hi - lo) / _G_POLES, _G_POLES)
    basis = omega[:, None] / (c[None, :] ** 2 + omega[:, None] ** 2)
    scale = np.max(np.abs(basis), axis=0)  # columns of equal size before the ridge
    W = np.sqrt(weights)[:, None]
    A = np.vstack([W * basis / scale, np.sqrt(_RIDGE) * np.eye(c.size)])
    b = np.concatenate([np.sqrt(weights) * g, np.zeros(c.size)])
    a = np.linalg.lstsq(A, b, rcond=None)[0] / scale
    return c, a


def _allpass(c: np.ndarray) -> control.StateSpace:
    """``Π (c_k - s)/(c_k + s)`` as a cascade of first-order sections."""
    sys = control.ss([], [], [], [[1.0]])
    for ck in c:
        sys = control.ss([[-ck]], [[1.0]], [[2.0 * ck]], [[-1.0]]) * sys  # (c - s)/(c + s)
    return sys


def _t_factor(c: np.ndarray, a: np.ndarray) -> control.StateSpace:
    """``Z A = Σ a_k s/(c_k + s)² Π_{j≠k} (c_j - s)/(c_j + s)``, stable."""
    total = control.ss([], [], [], [[0.0]])
    for k, (ck, ak) in enumerate(zip(c, a)):
        # s/(c + s)²: companion form of s/(s² + 2cs + c²)
        term = control.ss([[0.0, 1.0], [-ck**2, -2.0 * ck]], [[0.0], [1.0]], [[0.0, ak]], [[0.0]])
        total = total + _allpass(np.delete(c, k)) * term
    return total


def fit_gscales(omega, g, struct: BlockStructure, beta: float, *,
                weights=None) -> GScaleFit:
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

    Returns
    -------
    GScaleFit

    Examples
    --------
    An odd ``ĝ`` that the basis holds exactly is fitted to roundoff, and ``T = j ĝ H``:

    >>> import numpy as np
    >>> from lmi_suspension.mu import BlockStructure
    >>> w = np.logspace(-1, 1, 41)
    >>> s = BlockStructure.from_blk([[-1, 0]])
    >>> fit = fit_gscales(w, [0.5 * w / (1 + w**2)], s, 1.0)
    >>> x = 1j * w
    >>> ratio = fit.T[0](x) / fit.H[0](x)
    >>> bool(np.allclose(ratio, 1j * 0.5 * w / (1 + w**2), atol=1e-3))
    True
    """
    omega = np.asarray(omega, dtype=float).ravel()
    real = _real_slices(struct)
    g = np.asarray(g, dtype=float).reshape(len(real), -1)
    if g.shape[1] != omega.size:
        raise DimensionError(f"g has {g.shape[1]} frequencies, omega {omega.size}")
    w = np.ones(omega.size) if weights is None else np.asarray(weights, dtype=float).ravel()
    T, H, poles, coefs, errors = [], [], [], [], []
    for gi in g:
        c, a = _odd_fit(omega, gi, w)
        z = (omega[:, None] / (c[None, :] ** 2 + omega[:, None] ** 2)) @ a
        Hm = fit_magnitude(omega, 1.0 / np.sqrt(1.0 + z**2), _H_ORDER, weights=w)
        H.append(Hm * _allpass(c))
        T.append(Hm * _t_factor(c, a))
        poles.append(c)
        coefs.append(a)
        errors.append(float(np.max(np.abs(z - gi)) / max(np.max(np.abs(gi)), 1e-300)))
    return GScaleFit(blocks=tuple(i for i, _, _ in real), T=tuple(T), H=tuple(H),
                     poles=tuple(poles), coefficients=tuple(coefs), errors=tuple(errors),
                     beta=float(beta))


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
    # input side: 1/β on the µ blocks' w, H_i on the real blocks' w, identity elsewhere
    diag_in = [control.ss([], [], [], [[1.0 / gfit.beta if k < nw_mu else 1.0]])
               for k in range(nin)]
    real = _real_slices(struct)
    for (i, rl, cl), Hi in zip(real, gfit.H):
        for k in range(rl.start, rl.stop):
            diag_in[k] = Hi * (1.0 / gfit.beta)
    right = control.append(*diag_in)
    scaled = PD * right
    # T_i subtracted from P11's (z_i, w_i) diagonal entries: a parallel system from the
    # w inputs to the z outputs
    Tsys = []
    for (i, rl, cl), Ti in zip(real, gfit.T):
        for kz, kw in zip(range(cl.start, cl.stop), range(rl.start, rl.stop)):
            Tsys.append((kz, kw, Ti))
    if Tsys:
        blocks = [control.ss([], [], [], np.zeros((nout, nin)))]
        for kz, kw, Ti in Tsys:
            Bsel = np.zeros((1, nin))
            Bsel[0, kw] = 1.0
            Csel = np.zeros((nout, 1))
            Csel[kz, 0] = -1.0
            blocks.append(control.ss([], [], [], Csel) * Ti * control.ss([], [], [], Bsel))
        extra = blocks[0]
        for b in blocks[1:]:
            extra = extra + b
        scaled = scaled + extra
    return scaled
