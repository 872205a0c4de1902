"""Uncertainty models of the seat suspension: actuator delay, the paper's norm-bounded
perturbations (eqs. 9 and 16) and physical parametric uncertainty in LFT form.

Conventions (MATLAB's, used by ``mussv``/``musyn``): an uncertainty block Δ_i maps the
plant's *uncertainty outputs* ``q_i`` to its *uncertainty inputs* ``p_i`` (``p_i = Δ_i q_i``),
so a block with ``r_i`` inputs ``p`` and ``c_i`` outputs ``q`` is ``r_i × c_i`` and the row
of ``blk`` is ``[r_i, c_i]``; real scalars are ``[-1, 0]``.

Every LFT channel here is *balanced*: ``q`` and ``p`` of a channel are scaled by the same
factor, which leaves the set of closed-loop perturbations unchanged (the scaling commutes
with Δ) but keeps the input and output gains of the channel of the same size.
"""

from __future__ import annotations

import logging
import math
import numbers
from dataclasses import dataclass, replace

import control
import numpy as np
from scipy import optimize

from ..errors import DimensionError, ParameterError
from ..lti.checks import as_finite_array
from ..lti.plant import lft
from .model import OUTPUT_NAMES, seat_matrices
from .params import SeatParameters

__all__ = [
    "DelayUncertainty",
    "delay_uncertainty",
    "delay_envelope",
    "NormBounded",
    "paper_norm_bounded",
    "ParametricUncertainty",
    "parametric_uncertainty",
    "close_upper",
]

logger = logging.getLogger(__name__)


# --------------------------------------------------------------------------- helpers
def _real(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ParameterError(f"{name} must be a real number, got {value!r}")
    return float(as_finite_array(value, name))


def close_upper(sys: control.StateSpace, Delta, n_unc: int | None = None) -> control.StateSpace:
    """Upper LFT ``F_u(sys, Δ)`` for a constant real ``Δ``: close ``p = Δ q``.

    The first ``Δ.shape[0]`` inputs of ``sys`` are ``p`` and its first ``Δ.shape[1]``
    outputs are ``q``; the remaining signals keep their names.

    Raises
    ------
    DimensionError
        If Δ does not fit the system.
    IllPosedLoopError
        If ``I - D_qp Δ`` is singular.

    Examples
    --------
    >>> import control
    >>> from lmi_suspension.seat.uncertainty import close_upper
    >>> G = control.ss([[-1.0]], [[1.0, 1.0]], [[1.0], [1.0]], [[0.0, 0.0], [0.0, 0.0]])
    >>> float(close_upper(G, [[-1.0]]).A[0, 0])
    -2.0
    """
    D = as_finite_array(Delta, "Delta", ndim=2)
    r, c = D.shape
    if r >= sys.ninputs or c >= sys.noutputs:
        raise DimensionError(f"Delta of shape {D.shape} does not fit a {sys.noutputs}x"
                             f"{sys.ninputs} system (needs remaining channels)")
    # Reorder so that p and q are last and reuse the lower LFT.
    ip = list(range(r, sys.ninputs)) + list(range(r))
    op = list(range(c, sys.noutputs)) + list(range(c))
    A, B, C, Dm = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C, sys.D))
    P = control.ss(A, B[:, ip], C[op, :], Dm[np.ix_(op, ip)],
                   inputs=[sys.input_labels[i] for i in ip],
                   outputs=[sys.output_labels[i] for i in op])
    return lft(P, control.ss([], [], [], D), nmeas=c, ncon=r)


def _balance(b: np.ndarray, c: np.ndarray) -> float:
    """Channel scaling α with ||b α|| = ||c / α|| (1 if either side is zero)."""
    nb, nc = np.linalg.norm(b), np.linalg.norm(c)
    if nb == 0 or nc == 0:
        return 1.0
    return math.sqrt(nc / nb)


# --------------------------------------------------------------------------- delay
def delay_envelope(omega, d_min: float, d_max: float, N_resp) -> np.ndarray:
    """Exact ``max_{d in [d_min, d_max]} |e^{-jωd} - N(jω)| / |N(jω)|`` for each ω.

    ``|e^{-jωd} - N|² = 1 + |N|² - 2|N| cos(ωd + arg N)`` is largest where
    ``ωd + arg N`` is closest to an odd multiple of π, so the maximum over the interval
    is attained at an end point unless the interval contains such a multiple.

    Parameters
    ----------
    omega : array_like
        Frequencies, rad/s.
    d_min, d_max : float
        Delay interval, s.
    N_resp : array_like
        Complex frequency response of the nominal model at ``omega``.
    """
    w = np.asarray(omega, dtype=float)
    Nr = np.asarray(N_resp, dtype=complex)
    mag, ph = np.abs(Nr), np.angle(Nr)
    lo, hi = w * d_min + ph, w * d_max + ph
    # smallest odd multiple of pi that is >= lo
    k = np.ceil((lo / np.pi - 1) / 2)
    hits = (2 * k + 1) * np.pi <= hi
    cos_end = np.minimum(np.cos(lo), np.cos(hi))
    cos_min = np.where(hits, -1.0, cos_end)
    sq = np.maximum(1 + mag ** 2 - 2 * mag * cos_min, 0.0)
    return np.sqrt(sq) / mag


@dataclass(frozen=True)
class DelayUncertainty:
    """Multiplicative input cover of an uncertain delay: ``e^{-sd} ∈ N(s)(1 + W(s) δ)``.

    For every ``d`` in ``[d_min, d_max]`` and every ω there is a ``|δ| ≤ 1`` with
    ``e^{-jωd} = N(jω)(1 + W(jω) δ)``.

    Attributes
    ----------
    N : control.StateSpace
        Nominal actuator model (first-order Padé of the mid delay, eq. 8, or 1).
    W : control.StateSpace
        Stable, minimum-phase weight covering the relative error.
    d_min, d_max : float
        Delay interval, s.
    nominal : str
        ``"pade"`` or ``"none"``.
    margin : float
        Relative safety margin of ``|W|`` over the envelope on the fitting grid.
    """

    N: control.StateSpace
    W: control.StateSpace
    d_min: float
    d_max: float
    nominal: str
    margin: float

    def envelope(self, omega) -> np.ndarray:
        """True envelope ``max_d |e^{-jωd} - N| / |N|`` at ``omega`` (rad/s)."""
        w = np.asarray(omega, dtype=float)
        return delay_envelope(w, self.d_min, self.d_max, self.N(1j * w))

    def bound(self, omega) -> np.ndarray:
        """``|W(jω)|`` at ``omega`` (rad/s)."""
        w = np.asarray(omega, dtype=float)
        return np.abs(np.atleast_1d(self.W(1j * w)).ravel())

    def delta_for(self, omega: float, d: float) -> complex:
        """The δ that reproduces ``e^{-jωd}`` exactly at ``omega``: ``(e^{-jωd} - N)/(W N)``."""
        s = 1j * float(omega)
        Nj, Wj = complex(self.N(s)), complex(self.W(s))
        return (np.exp(-s * float(d)) - Nj) / (Wj * Nj)


def _pade_nominal(d: float) -> control.StateSpace:
    if d == 0:
        return control.ss([], [], [], [[1.0]])
    num, den = control.pade(d, 1)  # (1 - s d/2)/(1 + s d/2), eq. (8)
    return control.ss(control.tf(num, den))


def delay_uncertainty(d_min: float = 0.0, d_max: float = 0.025, *, nominal: str = "pade",
                      order: int = 2, margin: float = 0.02,
                      omega_range: tuple[float, float] = (1e-2, 1e5),
                      n_grid: int = 300) -> DelayUncertainty:
    """Cover the delays ``d ∈ [d_min, d_max]`` by ``N(s)(1 + W(s) δ)``, ``|δ| ≤ 1``.

    ``W`` is ``k Π (s + z_i)/(s + p_i)`` with positive ``z_i``, ``p_i`` (stable and
    minimum phase), fitted to the exact envelope (:func:`delay_envelope`) by minimising
    the mean log over-bound on a log grid; ``k`` is set so that ``|W| ≥ (1 + margin) ×
    envelope`` on the grid, and is raised if a 10× finer check grid (extended two
    decades each way) finds a point below ``(1 + margin/2) ×`` envelope.

    Parameters
    ----------
    d_min, d_max : float
        Delay interval in s, ``0 ≤ d_min ≤ d_max``, ``d_max > 0``.
    nominal : {"pade", "none"}
        ``"pade"``: first-order Padé of ``(d_min + d_max)/2`` (eq. 8); ``"none"``: N = 1.
    order : int
        Order of ``W`` (1, 2 or 3).
    margin : float
        Relative safety margin (0 to 1).
    omega_range : (float, float)
        Fitting band, rad/s.
    n_grid : int
        Number of fitting frequencies.

    Returns
    -------
    DelayUncertainty

    Raises
    ------
    ParameterError
        On a negative or reversed delay interval, ``d_max == 0``, an unknown nominal,
        an order outside 1..3 or a bad margin.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat.uncertainty import delay_uncertainty
    >>> du = delay_uncertainty(0.0, 0.025)
    >>> w = np.logspace(-1, 4, 50)
    >>> bool(np.all(du.bound(w) >= du.envelope(w)))
    True
    """
    d_min, d_max = _real(d_min, "d_min"), _real(d_max, "d_max")
    margin = _real(margin, "margin")
    if d_min < 0:
        raise ParameterError(f"d_min must be >= 0 s, got {d_min}")
    if d_max < d_min:
        raise ParameterError(f"d_max ({d_max}) must not be below d_min ({d_min})")
    if d_max == 0:
        raise ParameterError("d_max must be positive: there is no delay to cover")
    if nominal not in ("pade", "none"):
        raise ParameterError(f"nominal must be 'pade' or 'none', got {nominal!r}")
    if isinstance(order, bool) or order not in (1, 2, 3):
        raise ParameterError(f"order must be 1, 2 or 3, got {order!r}")
    if not 0 < margin < 1:
        raise ParameterError(f"margin must lie in (0, 1), got {margin}")
    w_lo, w_hi = (_real(v, "omega_range") for v in omega_range)
    if not 0 < w_lo < w_hi:
        raise ParameterError(f"omega_range must satisfy 0 < lo < hi, got {omega_range}")

    N = _pade_nominal(0.5 * (d_min + d_max)) if nominal == "pade" else \
        control.ss([], [], [], [[1.0]])
    w = np.logspace(np.log10(w_lo), np.log10(w_hi), int(n_grid))
    env = delay_envelope(w, d_min, d_max, N(1j * w))
    keep = env > 1e-12 * env.max()
    w, env = w[keep], env[keep]
    s = 1j * w

    z_floor = 0.1 * w_lo  # keeps the zeros at finite, documented distance from s = 0

    def zp(theta):
        return np.maximum(np.exp(theta[:order]), z_floor), np.exp(theta[order:])

    def shape(theta):
        z, p = zp(theta)
        return np.abs(np.prod((s[:, None] + z) / (s[:, None] + p), axis=1))

    def gain(theta):
        return (1 + margin) * np.max(env / shape(theta))

    log_env = np.log(env)

    def cost(theta):
        # log of k|W|/env with k = (1 + margin) max(env/|W|), from one shape evaluation
        excess = np.log(shape(theta)) - log_env
        return float(np.mean(excess) - excess.min() + math.log1p(margin))

    # Starting guess: the classical 2.1 τ s/(τ s + 1) cover of a delay τ, with extra
    # pole/zero pairs spread around the corner 1/τ.
    tau = (d_max - d_min) if nominal == "pade" and d_max > d_min else d_max
    z0 = [w_lo * 0.1] + [1.0 / tau * 3.0 ** (i + 1) for i in range(order - 1)]
    p0 = [1.0 / tau * 3.0 ** i for i in range(order)]
    best = None
    for spread in (1.0, 0.5, 2.0):
        theta0 = np.log(np.concatenate([z0[:1], np.array(z0[1:]) * spread, np.array(p0) * spread]))
        res = optimize.minimize(cost, theta0, method="Nelder-Mead",
                                options=dict(maxiter=4000 * order, xatol=1e-6, fatol=1e-9))
        if best is None or res.fun < best.fun:
            best = res
    theta = best.x
    z, p = zp(theta)
    k = gain(theta)
    # Independent check on a finer, wider grid; raise k rather than trust the fit grid.
    wc = np.logspace(np.log10(w_lo) - 2, np.log10(w_hi) + 2, 10 * int(n_grid))
    envc = delay_envelope(wc, d_min, d_max, N(1j * wc))
    bc = k * np.abs(np.prod((1j * wc[:, None] + z) / (1j * wc[:, None] + p), axis=1))
    worst = float(np.max(envc / bc))
    if worst * (1 + margin / 2) > 1:
        logger.debug("raising delay weight gain by %.4g after the check grid", worst)
        k *= worst * (1 + margin / 2)
    num = k * np.real(np.poly(-z))
    den = np.real(np.poly(-p))
    W = control.ss(control.tf(num, den))
    return DelayUncertainty(N=N, W=W, d_min=d_min, d_max=d_max, nominal=nominal, margin=margin)


# --------------------------------------------------------------------------- paper
@dataclass(frozen=True)
class NormBounded:
    """The paper's norm-bounded perturbations (eqs. 9 and 16), δ's included::

        [ΔA ΔB] = L1 F [E_A E_B],   ΔC1 = L2 F E_C1,   ΔC3 = L3 F E_C3,   FᵀF ≤ I.

    Attributes
    ----------
    L1 : ndarray (6, 6)
    E_A : ndarray (6, 6)
    E_B : ndarray (6, 1)
    L2 : ndarray (1, 6)
    E_C1 : ndarray (6, 6)
    L3 : ndarray (2, 6)
    E_C3 : ndarray (6, 6)
    delta : float
        The common δ (0.02 in the paper).
    """

    L1: np.ndarray
    E_A: np.ndarray
    E_B: np.ndarray
    L2: np.ndarray
    E_C1: np.ndarray
    L3: np.ndarray
    E_C3: np.ndarray
    delta: float

    def perturbations(self, F_AB, F_C1=None, F_C3=None) -> tuple[np.ndarray, ...]:
        """``(ΔA, ΔB, ΔC1, ΔC3)`` for given 6×6 matrices F (``F_C1``, ``F_C3`` default to
        ``F_AB``, the paper's single F)."""
        F_AB = as_finite_array(F_AB, "F_AB", ndim=2)
        F_C1 = F_AB if F_C1 is None else as_finite_array(F_C1, "F_C1", ndim=2)
        F_C3 = F_AB if F_C3 is None else as_finite_array(F_C3, "F_C3", ndim=2)
        for name, F in (("F_AB", F_AB), ("F_C1", F_C1), ("F_C3", F_C3)):
            if F.shape != (6, 6):
                raise DimensionError(f"{name} must be 6x6, got {F.shape}")
        return (self.L1 @ F_AB @ self.E_A, self.L1 @ F_AB @ self.E_B,
                self.L2 @ F_C1 @ self.E_C1, self.L3 @ F_C3 @ self.E_C3)

    def blocks(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Compressed, balanced factors ``(left, right)`` of each perturbation.

        ``L F E`` with ``L = U_r S_r V_rᵀ`` (rank r) equals ``(U_r S_r) G E`` with
        ``G = V_rᵀ F``, and ``G`` ranges over all r×6 contractions as F ranges over
        6×6 ones: the sets are equal and the block shrinks to r×6.  Keys ``"nb_AB"``
        (right factor acts on ``[x; u]``), ``"nb_C1"`` and ``"nb_C3"`` (act on x).
        """
        out = {}
        for key, L, E in (("nb_AB", self.L1, np.hstack([self.E_A, self.E_B])),
                          ("nb_C1", self.L2, self.E_C1), ("nb_C3", self.L3, self.E_C3)):
            U, S, _ = np.linalg.svd(L)
            r = int(np.sum(S > 1e-12 * max(S.max(), 1e-300)))
            left = U[:, :r] * S[:r]
            a = _balance(left, E)
            out[key] = (left * a, E / a)
        return out


def _pattern_of_parameters(params: SeatParameters) -> np.ndarray:
    """1 where an entry of A depends on a mass, damper or spring, 0 where it is kinematic."""
    p = params
    A1 = seat_matrices(p).A
    # Perturb all physical parameters at once: kinematic entries (0, ±1) never move.
    p2 = replace(p, m1=p.m1 * 1.1, m21=p.m21 * 1.1, m22=p.m22 * 1.1, m3=p.m3 * 1.1,
                 c1=p.c1 * 1.3 + 1, c2=p.c2 * 1.3 + 1, c3=p.c3 * 1.3 + 1,
                 k1=p.k1 * 1.3, k2=p.k2 * 1.3, k3=p.k3 * 1.3)
    A2 = seat_matrices(p2).A
    return (A1 != A2).astype(float)


def paper_norm_bounded(params: SeatParameters | None = None, delta: float = 0.02) -> NormBounded:
    """The norm-bounded uncertainty of the paper (eqs. 9, 16) with all δ = ``delta``.

    Reconstruction (the printed L1 and E_B are garbled, see ``ERRATA.md``): the legible
    ``L2 = δ[0 0 0 1 1 1]`` is the sparsity pattern of C1 and ``L3 = δ[1 0 0 0 0 0;
    0 0 1 0 0 0]`` that of C3, so L1 is taken as the pattern of the *parameter-dependent*
    entries of A (rows 2, 4, 6).  Its columns are ``[0 1 0 0 0 0]``, ``[0 1 0 1 0 0]`` (×2),
    ``[0 1 0 1 0 1]``, ``[0 0 0 1 0 1]`` (×2); the printed fragments "0 0 1 0 0" (×2),
    "0 0 1 0 1" (×2) and "0 0 0 1 0 1" are these columns with the row-2 entry (or a
    zero) lost, the last one exact, and the first printed column is illegible.  By the
    same rule ``E_B = δ_B [0 1 0 0 0 0]ᵀ`` (pattern of B; printed empty).
    ``E_A = δ_A I``, ``E_C1 = δ_C1 I``, ``E_C3 = δ_C3 I`` as printed.

    The resulting ΔA entries are at most ``δ² ||F|| ~ 1e-3``, tiny next to A's
    entries (up to ~2e3): reproduced faithfully, not rescaled.

    Examples
    --------
    >>> from lmi_suspension.seat.uncertainty import paper_norm_bounded
    >>> nb = paper_norm_bounded()
    >>> nb.L1.shape, nb.E_B.ravel().tolist()
    ((6, 6), [0.0, 0.02, 0.0, 0.0, 0.0, 0.0])
    """
    params = SeatParameters() if params is None else params
    if not isinstance(params, SeatParameters):
        raise TypeError(f"params must be a SeatParameters, got {type(params).__name__}")
    delta = _real(delta, "delta")
    if delta < 0:
        raise ParameterError(f"delta must be >= 0, got {delta}")
    L1 = delta * _pattern_of_parameters(params)
    eB = np.zeros((6, 1))
    eB[1, 0] = 1.0
    L2 = delta * np.array([[0.0, 0, 0, 1, 1, 1]])
    L3 = delta * np.array([[1.0, 0, 0, 0, 0, 0], [0, 0, 1, 0, 0, 0]])
    I6 = np.eye(6)
    return NormBounded(L1=L1, E_A=delta * I6, E_B=delta * eB, L2=L2, E_C1=delta * I6,
                       L3=L3, E_C3=delta * I6, delta=delta)


# --------------------------------------------------------------------------- parametric
_ELEMENTS = ("k1", "k2", "k3", "c1", "c2", "c3")


@dataclass(frozen=True)
class ParametricUncertainty:
    """Real parametric uncertainty of the seat model as an upper LFT.

    Attributes
    ----------
    G : control.StateSpace
        Inputs ``[p_<name>..., 'w', 'u']``, outputs ``[q_<name>..., 'z3dd', 'x1', 'x3',
        'y1', 'y2']``; ``F_u(G, diag(δ))`` is the seat model at :meth:`params_at` (δ).
    names : tuple of str
        The uncertain parameters, in channel order (``'m3'`` first when present).
    relative : tuple of float
        ``r_i`` of each parameter: ``k = k_nom (1 + r δ)``, ``1/m3 = (1/m3_nom)(1 + r δ)``.
    nominal : SeatParameters
        Parameters at δ = 0 (``m3_nom`` is the centre of the range in ``1/m3``).
    """

    G: control.StateSpace
    names: tuple[str, ...]
    relative: tuple[float, ...]
    nominal: SeatParameters

    @property
    def blk(self) -> np.ndarray:
        """``mussv`` rows, one real scalar ``[-1, 0]`` per parameter."""
        return np.array([[-1, 0]] * len(self.names), dtype=int)

    def _deltas(self, delta) -> np.ndarray:
        if isinstance(delta, dict):
            unknown = set(delta) - set(self.names)
            if unknown:
                raise ParameterError(f"unknown uncertain parameters {sorted(unknown)}")
            delta = [delta.get(n, 0.0) for n in self.names]
        d = as_finite_array(delta, "delta").ravel()
        if d.size != len(self.names):
            raise DimensionError(f"need {len(self.names)} values of δ, got {d.size}")
        return d

    def params_at(self, delta) -> SeatParameters:
        """Physical parameters for δ (a sequence in :attr:`names` order or a dict)."""
        d = self._deltas(delta)
        changes = {}
        for name, r, di in zip(self.names, self.relative, d):
            nom = getattr(self.nominal, name)
            value = nom / (1 + r * di) if name == "m3" else nom * (1 + r * di)
            changes[name] = float(value)
        return replace(self.nominal, **changes)

    def model_at(self, delta) -> control.StateSpace:
        """``F_u(G, diag(δ))``: the seat model (seat_model's channels) at δ."""
        d = self._deltas(delta)
        return close_upper(self.G, np.diag(d))


def parametric_uncertainty(params: SeatParameters | None = None,
                           m3_range: tuple[float, float] | None = (30.0, 70.0),
                           stiffness_rel: float = 0.2, *,
                           stiffness: tuple[str, ...] = ("k1",),
                           damping: tuple[str, ...] = (),
                           damping_rel: float = 0.2,
                           k1_rel: float | None = None) -> ParametricUncertainty:
    """Occupant mass and spring/damper uncertainty as real scalars ``δ ∈ [-1, 1]`` (LFT).

    The model is written with element forces ``F1 = k1 x1 + c1 (x2 - w)``,
    ``F2 = k2 x3 + c2 (x4 - x2)``, ``F3 = k3 x5 + c3 (x6 - x4)`` and
    ``m1 ẋ2 = -F1 + F2 - u``, ``m2 ẋ4 = -F2 + F3``, ``m3 ẋ6 = -F3`` (eq. 1).  An uncertain
    element ``v = v_nom (1 + r δ)`` adds ``p = δ q`` to its force with
    ``q = r v_nom × (its deflection or relative velocity)``; ``1/m3 = (1/m3_nom)(1 + r δ)``
    adds ``p = δ q`` to ``ẋ6`` (and z̈3) with ``q = -r F3/m3_nom``.  Both are affine in δ,
    so the LFT is exact for every δ, including products such as ``k3/m3``.

    Parameters
    ----------
    params : SeatParameters, optional
        Nominal parameters (Table 1 by default); ``m3`` is replaced by the centre of
        ``m3_range`` in ``1/m3`` (42 kg for 30–70 kg).
    m3_range : (float, float) or None
        Occupant upper-body mass range, kg; ``None`` keeps m3 fixed.
    stiffness_rel : float
        Relative stiffness uncertainty (0.2 = ±20 %), in (0, 1).
    stiffness : tuple of {"k1", "k2", "k3"}
        The uncertain springs.
    damping, damping_rel
        The same for dampers ``"c1"``, ``"c2"``, ``"c3"``.
    k1_rel : float, optional
        The seat spring's own relative range, in (0, 1), in place of ``stiffness_rel``
        (a seat that estimates ``k1`` from its static deflection knows it better than
        the body's springs); ``None`` takes ``stiffness_rel``.

    Returns
    -------
    ParametricUncertainty

    Examples
    --------
    >>> from lmi_suspension.seat.uncertainty import parametric_uncertainty
    >>> pu = parametric_uncertainty()
    >>> pu.names, round(pu.nominal.m3, 6)
    (('m3', 'k1'), 42.0)
    >>> round(pu.params_at([1.0, -1.0]).m3, 9), round(pu.params_at([1.0, -1.0]).k1, 6)
    (30.0, 24800.0)
    """
    params = SeatParameters() if params is None else params
    if not isinstance(params, SeatParameters):
        raise TypeError(f"params must be a SeatParameters, got {type(params).__name__}")
    stiffness_rel = _real(stiffness_rel, "stiffness_rel")
    damping_rel = _real(damping_rel, "damping_rel")
    k1_rel = stiffness_rel if k1_rel is None else _real(k1_rel, "k1_rel")
    for label, rel, sel in (("stiffness_rel", stiffness_rel,
                             tuple(n for n in stiffness if n != "k1")),
                            ("k1_rel", k1_rel, tuple(n for n in stiffness if n == "k1")),
                            ("damping_rel", damping_rel, damping)):
        if sel and not 0 < rel < 1:
            raise ParameterError(f"{label} must lie in (0, 1), got {rel}")
    stiffness, damping = tuple(stiffness), tuple(damping)
    for name in stiffness:
        if name not in ("k1", "k2", "k3"):
            raise ParameterError(f"unknown spring {name!r}; use 'k1', 'k2' or 'k3'")
    for name in damping:
        if name not in ("c1", "c2", "c3"):
            raise ParameterError(f"unknown damper {name!r}; use 'c1', 'c2' or 'c3'")
    if len(set(stiffness)) != len(stiffness) or len(set(damping)) != len(damping):
        raise ParameterError("an uncertain element is listed twice")

    names: list[str] = []
    rel: list[float] = []
    nominal = params
    if m3_range is not None:
        lo, hi = (_real(v, "m3_range") for v in m3_range)
        if not 0 < lo < hi:
            raise ParameterError(f"m3_range must satisfy 0 < lo < hi, got {m3_range}")
        inv_lo, inv_hi = 1 / hi, 1 / lo
        nominal = replace(nominal, m3=2 / (inv_lo + inv_hi))
        names.append("m3")
        rel.append((inv_hi - inv_lo) / (inv_hi + inv_lo))
    for name in _ELEMENTS:
        if name in stiffness:
            names.append(name)
            rel.append(k1_rel if name == "k1" else stiffness_rel)
        elif name in damping:
            names.append(name)
            rel.append(damping_rel)
    if not names:
        raise ParameterError("no uncertain parameter selected")

    G = _parametric_lft(nominal, tuple(names), tuple(rel))
    return ParametricUncertainty(G=G, names=tuple(names), relative=tuple(rel), nominal=nominal)


def _parametric_lft(p: SeatParameters, names: tuple[str, ...], rel: tuple[float, ...]):
    nx, npar = 6, len(names)
    # Linear maps over v = [x (6); p (npar); w; u] -> row vectors.
    nv = nx + npar + 2
    iw, iu = nx + npar, nx + npar + 1

    def e(i):
        row = np.zeros(nv)
        row[i] = 1.0
        return row

    x = [e(i) for i in range(nx)]
    wv, uv = e(iw), e(iu)
    pv = {name: e(nx + j) for j, name in enumerate(names)}
    # deflection/relative velocity of each element
    defl = {"k1": x[0], "k2": x[2], "k3": x[4],
            "c1": x[1] - wv, "c2": x[3] - x[1], "c3": x[5] - x[3]}
    elem_force = {}
    for name in _ELEMENTS:
        f = getattr(p, name) * defl[name]
        if name in pv:
            f = f + pv[name]  # p = δ · (r v_nom · motion)
        elem_force[name] = f
    F1 = elem_force["k1"] + elem_force["c1"]
    F2 = elem_force["k2"] + elem_force["c2"]
    F3 = elem_force["k3"] + elem_force["c3"]
    xdot6 = -F3 / p.m3 + (pv["m3"] if "m3" in pv else 0.0)
    rows = [x[1] - wv, (-F1 + F2 - uv) / p.m1, x[3] - x[1], (-F2 + F3) / p.m2,
            x[5] - x[3], xdot6]
    q = []
    for name, r in zip(names, rel):
        if name == "m3":
            q.append(-r * F3 / p.m3)
        else:
            q.append(r * getattr(p, name) * defl[name])
    outs = q + [xdot6, x[0], x[2], x[0], x[2]]
    # Balance each channel: p -> α p, q -> q / α keeps p = δ q.
    Mx = np.array(rows)
    Mo = np.array(outs)
    for j in range(npar):
        col = nx + j
        a = _balance(np.concatenate([Mx[:, col], Mo[npar:, col]]), Mo[j, :])
        Mx[:, col] *= a
        Mo[:, col] *= a
        Mo[j, :] /= a
    A, B = Mx[:, :nx], Mx[:, nx:]
    C, D = Mo[:, :nx], Mo[:, nx:]
    inputs = [f"p_{n}" for n in names] + ["w", "u"]
    outputs = [f"q_{n}" for n in names] + list(OUTPUT_NAMES)
    return control.ss(A, B, C, D, inputs=inputs, outputs=outputs,
                      states=[f"x{i + 1}" for i in range(nx)], name="seat_param")
