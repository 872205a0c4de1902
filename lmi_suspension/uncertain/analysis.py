"""Robustness analysis of uncertain systems: ``robstab`` and ``wcgain``.

Both work on the LFT ``F_u(M, Δ)`` of :func:`~lmi_suspension.uncertain.lftdata` with
the normalised uncertainty (``|δ_i| <= 1``), on a frequency grid that includes
``ω = 0`` (a real pole crossing the origin) and the natural frequencies of the
nominal poles, with local refinement around the peak.

Upper bounds of µ (lower bounds of the stability margin, upper bounds of the gain)
come from :func:`~lmi_suspension.mu.mussv`: first with every block relaxed to a full
complex block (its fast D-scaling bound, valid because the relaxed set contains the
true one), then, only at the frequencies where that is not already good enough, with
the true structure (the D-G LMI bound for real parameters).  They are certified at the
grid frequencies, as MATLAB's are.  Where the grid bound exceeds the checked destabilising
perturbation (the grid stepped over a crossing of real µ), it is re-evaluated around the
crossing with the real parameters regularised by a small complex disc; if still
contradicted, ``lower`` is reported as 0 with a ``warnings`` entry, never above ``upper``.

One real parameter (possibly repeated, up to ``_EXACT_MAX_STATES`` states): µ is zero
between crossing frequencies, so instead ``robstab`` solves the crossing conditions
exactly (:func:`_exact_single_real`) and both bounds are the margin.

Lower bounds of µ (upper bounds of the margin, lower bounds of the gain) are explicit
perturbations that are checked, never estimates:

* ``robstab``, real parameters only: the smallest destabilising scaling ``α`` of the
  box is ``min_d α(d)`` over directions ``d`` with ``max |d_i| = 1``, where ``α(d)`` is
  the first instability along the ray ``δ = α d`` (a closed-loop pole reaching the
  imaginary axis, or a loss of well-posedness).  ``α(d)`` is found by a geometric scan
  and bisection of the closed loop's spectral abscissa; ``d`` runs over the vertices,
  a grid on the faces of the box (up to 3 parameters) or seeded random directions, and
  a Nelder–Mead refinement.  This replaces the power iteration, which often fails for
  purely real µ (µ is discontinuous there); ``mussv``'s own lower bound is used for
  complex and dynamic blocks and as an extra candidate.  The reported perturbation
  has a closed-loop pole on or right of the imaginary axis (checked).
* ``wcgain``: the gain of the system at a perturbation in the unit box (vertices, face
  grid and local search over the real parameters), recomputed by the H∞ norm of
  :func:`~lmi_suspension.uncertain.usubs` at the reported values.
"""

from __future__ import annotations

import itertools
import logging
import time
from dataclasses import dataclass, field
from types import MappingProxyType

import control
import numpy as np
import scipy.linalg
import scipy.optimize

from ..errors import AssumptionError, InputError
from ..lti.norms import hinfnorm
from ..mu import MussvOptions, mussv
from ..umodel.atoms import UComplex, ULTIDyn, UReal
from ..umodel.blocks import BlockStructure
from ..umodel.lfr import USS, as_uncertain
from ..umodel.uss import usubs

__all__ = ["RobstabResult", "WcgainResult", "robstab", "wcgain"]

logger = logging.getLogger(__name__)

_STAB_TOL = 1e-9
#: options of the true-structure (LMI) bound: a certified bound at 1e-4 relative accuracy
_LMI = dict(rtol=1e-4, max_lmi_iter=12)


# ---------------------------------------------------------------------------- helpers
def _as_uss(usys) -> USS:
    x = as_uncertain(usys)
    if not isinstance(x, USS):
        raise InputError("robustness analysis needs an uncertain system (USS), not a matrix")
    return x


def _check_nominal(x: USS):
    A = x.A
    if A.size == 0:
        return np.zeros(0, dtype=complex)
    p = np.linalg.eigvals(A)
    bad = p[p.real >= -_STAB_TOL * np.maximum(1.0, np.abs(p))]
    if bad.size:
        raise AssumptionError(
            f"the nominal system is not stable (pole(s) {np.round(bad, 6).tolist()}): robustness "
            "analysis needs a nominally stable model")
    return p


def default_grid(poles, n: int = 160) -> np.ndarray:
    """Frequency grid: 0, a log grid two decades around the poles, and the poles' |p|."""
    mags = np.abs(poles)
    mags = mags[mags > 0]
    lo = max(mags.min() / 100.0, 1e-6) if mags.size else 1e-2
    hi = mags.max() * 100.0 if mags.size else 1e2
    extra = np.concatenate([mags, np.abs(poles.imag[np.abs(poles.imag) > 0])]) if mags.size else []
    return np.unique(np.concatenate([[0.0], np.logspace(np.log10(lo), np.log10(hi), n), extra]))


def _freq_stack(A, B, C, D, omega):
    """``D + C (jωI - A)⁻¹ B`` for every ω, shape (p, m, nf)."""
    n = A.shape[0]
    out = np.empty((C.shape[0], B.shape[1], len(omega)), dtype=complex)
    if n == 0:
        out[:] = D[:, :, None]
        return out
    S = 1j * np.asarray(omega)[:, None, None] * np.eye(n) - A
    X = np.linalg.solve(S, np.broadcast_to(B, (len(omega), *B.shape)))
    out[:] = np.moveaxis(C @ X + D, 0, -1)
    return out


def _relaxed(blk: BlockStructure) -> BlockStructure:
    """Every block as a full complex block of the same size (a superset of Δ)."""
    return BlockStructure.from_blk([[b.rows, b.cols] for b in blk.blocks])


def _channel_delta(blocks, dvals):
    """Diagonal of Δ (length nw) from one normalised scalar per (scalar) block."""
    return np.concatenate([np.full(b.nw, v) for b, v in zip(blocks, dvals)])


class _Closure:
    """Closed loop ``A + Bw Δ (I - Dzw Δ)⁻¹ Cz`` for diagonal (scalar-block) Δ."""

    def __init__(self, x: USS):
        (self.A, self.Bw, self.Bu, self.Cz, self.Cy, self.Dzw, self.Dzu, self.Dyw,
         self.Dyu) = x.partition()
        self.blocks = x.blocks
        self.n = x.nstates

    def systems(self, dvals):
        """Batched closed loops for rows of ``dvals`` (N × n_blocks): (A, B, C, D, ok)."""
        dv = np.atleast_2d(np.asarray(dvals, dtype=float))
        N = dv.shape[0]
        reps = [b.nw for b in self.blocks]
        dd = np.repeat(dv, reps, axis=1)  # N × nw
        n = self.n
        nw = dd.shape[1]
        if nw == 0:
            rep = lambda M: np.broadcast_to(M, (N, *M.shape))  # noqa: E731
            return rep(self.A), rep(self.Bu), rep(self.Cy), rep(self.Dyu), np.ones(N, bool)
        L = np.eye(nw)[None] - self.Dzw[None] * dd[:, None, :]
        det = np.linalg.det(L)
        ok = det > 1e-10  # det = 1 at Δ = 0; a sign change is a loss of well-posedness
        L[~ok] = np.eye(nw)
        X = np.linalg.solve(L, np.broadcast_to(np.hstack([self.Cz, self.Dzu]), (N, nw, n + self.Bu.shape[1])))
        BwD = self.Bw[None] * dd[:, None, :]
        DywD = self.Dyw[None] * dd[:, None, :]
        A = self.A[None] + BwD @ X[:, :, :n]
        B = self.Bu[None] + BwD @ X[:, :, n:]
        C = self.Cy[None] + DywD @ X[:, :, :n]
        D = self.Dyu[None] + DywD @ X[:, :, n:]
        return A, B, C, D, ok

    def system(self, dvals):
        """(A, B, C, D) of the closed loop at one Δ, or None if ill posed."""
        A, B, C, D, ok = self.systems([list(dvals)])
        return (A[0], B[0], C[0], D[0]) if ok[0] else None

    def abscissa(self, dvals_list):
        """Spectral abscissa (``inf`` when ill posed) for each Δ, and the ω of its pole."""
        A, _, _, _, ok = self.systems(dvals_list)
        N = A.shape[0]
        out = np.full(N, np.inf)
        wout = np.zeros(N)
        if self.n == 0:
            out[ok] = -np.inf
            return out, wout
        ev = np.linalg.eigvals(A[ok])
        k = np.argmax(ev.real, axis=1)
        r = np.arange(ev.shape[0])
        out[ok] = ev.real[r, k]
        wout[ok] = np.abs(ev.imag[r, k])
        return out, wout


def _unstable(a, n):
    return a >= 0.0


def _first_crossing(clo: _Closure, d, a_lo, a_hi, npts=24, rtol=1e-11):
    """First α in (a_lo, a_hi] where the ray α d is unstable: (α_unstable, ω) or None.

    A geometric scan, then a batched multi-section (8 points per step) of the first
    bracket; the returned α is on the unstable side.
    """
    d = np.asarray(d, dtype=float)
    alphas = np.geomspace(a_lo, a_hi, npts)
    ab, _ = clo.abscissa(alphas[:, None] * d[None, :])
    bad = np.flatnonzero(_unstable(ab, clo.n))
    if bad.size == 0:
        return None
    i = bad[0]
    lo = alphas[i - 1] if i > 0 else 0.0
    hi = alphas[i]
    if i == 0:  # unstable already at a_lo: look below it
        lo = 0.0
    for _ in range(40):
        if hi - lo <= rtol * hi:
            break
        pts = np.linspace(lo, hi, 10)[1:-1]
        ab, _ = clo.abscissa(pts[:, None] * d[None, :])
        u = np.flatnonzero(_unstable(ab, clo.n))
        if u.size:
            hi = pts[u[0]]
            lo = pts[u[0] - 1] if u[0] > 0 else lo
        else:
            lo = pts[-1]
    _, w = clo.abscissa([hi * d])
    return hi, float(w[0])


def _directions(nb, rng, face_pts=9, n_random=200):
    """Vertices, a grid on the faces of the box (nb <= 3) or random directions."""
    dirs = []
    if nb <= 8:
        dirs.extend(np.array(v, dtype=float) for v in itertools.product([-1.0, 1.0], repeat=nb))
    if nb <= 3:
        g = np.linspace(-1.0, 1.0, face_pts)
        for i in range(nb):
            for s in (-1.0, 1.0):
                for rest in itertools.product(g, repeat=nb - 1):
                    d = np.insert(np.array(rest, dtype=float), i, s)
                    dirs.append(d)
    else:
        for _ in range(n_random):
            v = rng.standard_normal(nb)
            dirs.append(v / np.abs(v).max())
    return dirs


def _ray_search(clo: _Closure, nb, a_min, rng):
    """min over directions of the first destabilising α; (α, d, ω) or None."""
    best = None
    a_cap = max(1e3 * a_min, 1e2)
    alpha_of = {}
    for d in _directions(nb, rng):
        top = best[0] if best is not None else a_cap
        res = _first_crossing(clo, d, a_min, top, npts=24 if best is None else 12)
        if res is not None and (best is None or res[0] < best[0]):
            best = (res[0], d, res[1])
        alpha_of[tuple(d)] = res[0] if res is not None else np.inf
    if best is None:
        return None
    # local refinement of the direction from the best few
    starts = sorted(alpha_of, key=alpha_of.get)[:3]

    def obj(v):
        nv = np.abs(v).max()
        if nv == 0:
            return np.inf
        r = _first_crossing(clo, v / nv, a_min, best[0] * 1.5, npts=8, rtol=1e-7)
        return r[0] if r is not None else best[0] * 2.0

    for s in starts[:2]:
        sol = scipy.optimize.minimize(obj, np.array(s), method="Nelder-Mead",
                                      options={"maxfev": 40, "xatol": 1e-4, "fatol": 1e-6 * best[0]})
        v = sol.x / np.abs(sol.x).max()
        r = _first_crossing(clo, v, a_min, best[0], npts=10)
        if r is not None and r[0] < best[0]:
            best = (r[0], v, r[1])
    return best


def _values(blocks, dvals, omega=None):
    """{name: physical value} of normalised block values."""
    out = {}
    for b, v in zip(blocks, dvals):
        a = b.atom
        if isinstance(a, UReal):
            out[a.name] = float(a.value(float(np.real(v))))
        elif isinstance(a, UComplex):
            out[a.name] = complex(a.value(v)) if np.iscomplexobj(v) and np.imag(v) != 0 else float(a.value(np.real(v)))
        else:
            out[a.name] = np.asarray(v) * a.bound  # value of Δ(jω) at the critical frequency
    return out


def _block_values_from_delta(x: USS, Delta):
    """Per-block normalised value of a structured Δ (nw × nz) from mussv."""
    vals, i, j = [], 0, 0
    for b in x.blocks:
        blk = Delta[i:i + b.nw, j:j + b.nz]
        if isinstance(b.atom, UReal):
            vals.append(float(np.real(blk[0, 0])))
        elif isinstance(b.atom, UComplex) or (b.nw == b.nz and b.nw > 1):
            vals.append(complex(blk[0, 0]))
        else:
            vals.append(blk.copy())
        i += b.nw
        j += b.nz
    return vals


# ---------------------------------------------------------------------------- exact route
#: state-dimension cap of the exact single-parameter route.  Its cost is one dense solve
#: with the n² × n² Kronecker sum and the eigenvalues of a 2rn × 2rn matrix; measured on
#: this machine (2 cores, shared, random stable A, r = 1, 2026-11-27): n = 14 (notebook
#: 06's complex-design loop) 0.003 s, n = 27 (its mixed-design loop) 0.03 s, n = 40 0.18 s,
#: n = 60 1.1 s (and n⁴ memory); the cap keeps it well under the grid's cost.
_EXACT_MAX_STATES = 40
#: a computed root ``μ = 1/δ`` counts as real when ``|Im μ| <= _REAL_RTOL |μ|``.  Loose on
#: purpose: a crossing frequency gives a double root (``jω + (−jω)`` appears twice in
#: ``A ⊕ A``), computed with an imaginary part of order sqrt(eps) |μ|; a spurious
#: candidate let through costs one eigenvalue check and is rejected there.
_REAL_RTOL = 1e-5
#: a pole touching the axis without crossing it is reported at its root, ``lower`` this
#: much (relative) below it; a crossing is bisected to ``_BISECT_RTOL`` between a stable
#: and an unstable point.
_BRACKET = 1e-6
_BISECT_RTOL = 1e-12
#: relative tolerance of a pole touching the axis without crossing it (a tangency):
#: ``|Re λ| <= _AXIS_RTOL max(1, |λ|max)`` at the candidate itself.
_AXIS_RTOL = 1e-8
#: points per side of the independent sweep of the closed loop's spectral abscissa over
#: ``[-α, α]`` that confirms the interval the roots say is stable (0.01 s at n = 14).
_SWEEP_POINTS = 200
#: roots of larger ``|δ|`` are not examined: they include rounding-error roots (1e7-1e15
#: on one-sided problems), and where ``δ`` enters quadratically the loop evaluated there
#: looks unstable from rounding alone (``c = (2δ - 1)² + 1e-3`` at ``δ = -1e6``: a pole
#: of -2.5e-13 computed beside one of -4e12); a margin beyond it is reported as at least
#: this, not as infinite
_EXACT_MAX_DELTA = 1e3
#: the independent sweep covers ``[-min(lower, _SWEEP_MAX), min(lower, _SWEEP_MAX)]``: the
#: normalised range and ten times beyond it, where a user reads a margin
_SWEEP_MAX = 10.0
#: roots closer than this (relative) are one root: a double root at a crossing is
#: computed as two a few 1e-9 apart, and the midpoint between them says nothing
_ROOT_MERGE_RTOL = 1e-6


class _ExactFailed(Exception):
    """The exact single-parameter route could not certify its answer (fall back)."""


def _single_real_roots(A, Bw, Cz, Dzw):
    """Real ``δ`` at which ``A(δ) = A + Bw δ (I − δ Dzw)⁻¹ Cz`` can touch the imaginary axis.

    With ``G(s) = Dzw + Cz (sI − A)⁻¹ Bw``, ``det(sI − A(δ)) = det(sI − A) det(I − δ G(s))
    / det(I − δ Dzw)``, so a pole of the loop at ``s = 0`` is a root of ``det(I − δ G(0))``
    and a pair ``±jω`` is a zero eigenvalue of the Kronecker sum ``A(δ) ⊕ A(δ)`` (it has
    the eigenvalues ``λ_i + λ_j``), itself an LFT in ``δ`` with ``A ⊕ A``,
    ``[Bw ⊗ I, I ⊗ Bw]``, ``[Cz ⊗ I; I ⊗ Cz]``, ``diag(Dzw ⊗ I, I ⊗ Dzw)`` (repetition
    2rn).  ``A`` and ``A ⊕ A`` are nonsingular (stable nominal), so the finite eigenvalues
    of the pencil ``[[A, Bw], [Cz, Dzw]] − μ [[0, 0], [0, I]]`` are those of the Schur
    complement ``Dzw − Cz A⁻¹ Bw`` (no infinite eigenvalues to tell apart from huge
    finite ones): ``δ = 1/μ``.  Losses of well-posedness, ``det(I − δ Dzw) = 0``, are
    added.  Returns candidates (a superset: pairs ``λ_i = −λ_j`` off the axis are roots
    too), sorted by ``|δ|``.
    """
    # balance first: a closed loop with a D-G-K controller is far from normal, and the
    # Kronecker sum inherits it (notebook 06's mixed loop: cond(A ⊕ A) 1.8e24 unbalanced,
    # 3.4e11 balanced; its crossings came out 2e-5 off and complex unbalanced, to 1e-9
    # balanced).  A diagonal similarity with permutation leaves the loop's poles alone.
    A, T = scipy.linalg.matrix_balance(A)
    Bw, Cz = np.linalg.solve(T, Bw), Cz @ T
    n = A.shape[0]
    I = np.eye(n)
    A2 = np.kron(A, I) + np.kron(I, A)
    B2 = np.hstack([np.kron(Bw, I), np.kron(I, Bw)])
    C2 = np.vstack([np.kron(Cz, I), np.kron(I, Cz)])
    Dk = np.kron(Dzw, I)
    D2 = np.block([[Dk, np.zeros_like(Dk)], [np.zeros_like(Dk), np.kron(I, Dzw)]])
    mus = [np.linalg.eigvals(Dzw - Cz @ np.linalg.solve(A, Bw)),
           np.linalg.eigvals(D2 - C2 @ np.linalg.solve(A2, B2)),
           np.linalg.eigvals(Dzw)]
    mu = np.concatenate(mus)
    real = (np.abs(mu.imag) <= _REAL_RTOL * np.abs(mu)) & (mu.real != 0)
    d = 1.0 / mu.real[real]
    return d[np.argsort(np.abs(d))]


def _abscissa_1(clo: _Closure, d: float) -> tuple[float, float, float]:
    """(spectral abscissa or inf if ill posed, |Im| of that pole, spectral radius) at ``δ = d``."""
    sysm = clo.system([d])
    if sysm is None:
        return np.inf, np.inf, np.inf
    ev = np.linalg.eigvals(sysm[0])
    k = int(np.argmax(ev.real))
    return float(ev.real[k]), float(abs(ev.imag[k])), float(np.abs(ev).max())


def _exact_single_real(x: USS, clo: _Closure):
    """Exact stability margin of one real (repeated) parameter.

    Returns ``(lower, upper, δ_worst, ω_c)``: the closed loop is stable for every
    ``|δ| <= lower`` and has a pole on or right of the imaginary axis (or is ill posed) at
    ``δ_worst``, ``|δ_worst| = upper``.  A crossing is bisected to
    ``upper − lower <= 1e-12 upper``; a pole that touches the axis without crossing it
    (``|Re λ| <= _AXIS_RTOL``, relative) is reported at its root, ``lower`` then
    ``_BRACKET`` (relative) below it.  ``(inf, inf, None, nan)`` if no real ``δ``
    destabilises the loop; ``(_EXACT_MAX_DELTA, inf, None, nan)`` if none does up to that
    size and roots beyond it were not examined.

    Exact because every ``δ`` at which a pole reaches the axis is a root found by
    :func:`_single_real_roots`, the poles are continuous in ``δ`` while the loop is well
    posed, and the nominal is stable: on each side the roots are examined in order, each
    between the midpoints to its neighbours (a computed root off by more than the bracket
    is still caught: the loop is stable at the lower midpoint and unstable at the upper
    one, and the crossing is bisected between them).  Raises :class:`_ExactFailed` when
    the verification contradicts this (a root missed numerically).
    """
    A, Bw, _, Cz, _, Dzw, *_ = x.partition()
    cands = _single_real_roots(A, Bw, Cz, Dzw)
    beyond = bool(np.any(np.abs(cands) > _EXACT_MAX_DELTA))
    cands = cands[np.abs(cands) <= _EXACT_MAX_DELTA]
    found = {}
    limit = _EXACT_MAX_DELTA  # nothing beyond a crossing already found needs examining

    def stable(d):
        return _abscissa_1(clo, d)[0] < 0

    for s in (1.0, -1.0):
        mags = np.unique(np.abs(cands[np.sign(cands) == s]))
        mags = mags[mags <= limit]
        if mags.size:
            keep = np.concatenate([[True], np.diff(mags) > _ROOT_MERGE_RTOL * mags[1:]])
            mags = mags[keep]
        lo = 0.5 * mags[0] if mags.size else 0.0
        if mags.size and not stable(s * lo):
            raise _ExactFailed(f"unstable at δ = {s * lo:.6g}, below the first root")
        for k, m in enumerate(mags):
            hi = 0.5 * (m + mags[k + 1]) if k + 1 < mags.size else min(2.0 * m, _EXACT_MAX_DELTA)
            if not stable(s * hi):  # a crossing in (lo, hi): bisect it
                while hi - lo > _BISECT_RTOL * hi:
                    mid = 0.5 * (lo + hi)
                    if stable(s * mid):
                        lo = mid
                    else:
                        hi = mid
                found[s] = (lo, hi)
                break
            a_c, _, rho = _abscissa_1(clo, s * m)
            if a_c >= -_AXIS_RTOL * max(1.0, rho):  # touches the axis without crossing
                found[s] = (m * (1 - _BRACKET), m)
                break
            lo = hi  # a spurious root (λ_i = −λ_j off the axis): not a crossing
        if s in found:
            limit = min(limit, found[s][1])
    if not found:
        lower, upper, dworst, wc = (_EXACT_MAX_DELTA if beyond else np.inf), np.inf, None, np.nan
    else:
        s = min(found, key=lambda t: found[t][1])
        lower, upper = (float(v) for v in found[s])
        dworst = s * upper
        a, wc, rho = _abscissa_1(clo, dworst)
        if not a >= -_AXIS_RTOL * max(1.0, rho):
            raise _ExactFailed(f"no pole on the axis at the reported δ = {dworst:.6g}")
        if not np.isfinite(wc):
            wc = np.inf  # loss of well-posedness: a pole at infinity
    # independent check of the interval the roots call stable: a sweep of the abscissa
    span = min(lower, _SWEEP_MAX)
    t = np.linspace(-span, span, 2 * _SWEEP_POINTS + 1)
    ab, _ = clo.abscissa(t[:, None])
    if np.any(ab >= 0):
        raise _ExactFailed(f"the sweep finds an instability at δ = {t[np.argmax(ab >= 0)]:.6g}")
    return lower, upper, dworst, wc


# ---------------------------------------------------------------------------- results
@dataclass(frozen=True)
class RobstabResult:
    """Robust stability margin bounds (MATLAB ``robstab`` sense).

    The margin ``α`` is the largest scaling of the normalised uncertainty box for which
    the system stays stable: ``α = 1`` is exactly the specified ranges, ``α > 1`` stable
    for every allowed value, ``α < 1`` unstable for some allowed value.

    Attributes
    ----------
    lower, upper : float
        ``lower <= α <= upper``, never ``lower > upper``.  With ``method == "exact"``
        (one real parameter, see :func:`robstab`) both are the exact margin, bracketed by
        bisection to ``upper - lower <= 1e-12 upper`` (to ``1e-6 upper`` where a pole
        touches the axis without crossing it); ``lower = 1000, upper = inf`` says that
        no value up to 1000 times the range destabilises the loop.  Otherwise ``lower = 1 / max_ω
        µ_upper`` (grid-certified) and ``upper`` the size of the checked destabilising
        perturbation (``inf`` if none was found); if the grid bound contradicts the
        checked perturbation even after refinement, ``lower`` is 0 (see ``warnings``).
    critical_frequency : float
        Frequency (rad/s) of the destabilising pole (0 for a real pole at the origin).
    worst : Mapping
        ``{name: value}`` at which the system has a pole on or right of the imaginary
        axis (physical values; for an ``ultidyn`` the complex matrix ``Δ(jω_c)``).
    worst_normalised : Mapping
        The same perturbation, normalised (``max |δ| = upper``).
    checked : bool
        True if the worst perturbation was verified (closed-loop pole with
        ``Re >= -1e-9`` for real parameters; ``det(I - M11 Δ) ≈ 0`` otherwise).
    omega, mu_upper : ndarray
        Frequencies evaluated and the µ upper bound there.
    mussv : MussvResult or None
        ``mussv`` with the true structure where it was needed.
    seconds : float
        Wall-clock time.
    method : str
        ``"exact"`` (single real parameter, roots of the crossing conditions) or
        ``"grid"`` (µ bounds on a frequency grid).
    warnings : tuple of str
        What was not certified: the exact route falling back to the grid, or a grid
        bound that contradicted the checked perturbation (its value is given there).
    """

    lower: float
    upper: float
    critical_frequency: float
    worst: MappingProxyType
    worst_normalised: MappingProxyType
    checked: bool
    omega: np.ndarray = field(repr=False)
    mu_upper: np.ndarray = field(repr=False)
    mussv: object = field(repr=False)
    seconds: float = 0.0
    method: str = "grid"
    warnings: tuple = ()


@dataclass(frozen=True)
class WcgainResult:
    """Worst-case H∞ gain bounds over the unit box of the normalised uncertainty.

    Attributes
    ----------
    lower, upper : float
        ``lower`` is the H∞ norm of ``usubs(usys, worst)`` (recomputed); ``upper`` is
        the skewed-µ bound (grid-certified).  Both ``inf`` if the system is unstable for
        some value in the box; ``upper = inf`` if robust stability is not proven.
    critical_frequency : float
        Frequency of the worst gain.
    worst : Mapping
        ``{name: value}`` (physical) attaining ``lower``.
    robstab : RobstabResult
    seconds : float
    """

    lower: float
    upper: float
    critical_frequency: float
    worst: MappingProxyType
    robstab: RobstabResult = field(repr=False)
    seconds: float = 0.0


# ---------------------------------------------------------------------------- robstab
def robstab(usys, omega=None, *, rng: np.random.Generator | None = None) -> RobstabResult:
    """Robust stability margin of an uncertain system (bounds and a destabilising value).

    Parameters
    ----------
    usys : USS
        Nominally stable uncertain system (e.g. a closed loop).
    omega : array_like, optional
        Frequency grid (rad/s); default :func:`default_grid` of the nominal poles (it
        always includes 0).
    rng : numpy.random.Generator, optional
        Seeded source for random search directions (more than 3 real parameters) and
        ``mussv``'s restarts (default ``np.random.default_rng(0)``).

    Returns
    -------
    RobstabResult
        With one real parameter (closure available, at most 40 states) ``method ==
        "exact"`` and ``lower`` and ``upper`` bracket the exact margin to 1e-12
        (relative); otherwise grid bounds, see :class:`RobstabResult`.

    Raises
    ------
    AssumptionError
        If the nominal system is not stable.

    Examples
    --------
    >>> from lmi_suspension.uncertain import ureal, uss, robstab
    >>> c = ureal("c", 1.0, plusminus=2.0)       # x'' + c x' + x: unstable for c <= 0
    >>> r = robstab(uss([[0, 1], [-1, -c]], [[0], [1]], [[1, 0]], [[0]]))
    >>> round(r.lower, 9), round(r.upper, 9), r.method   # exact margin 1/2 (c = 0)
    (0.5, 0.5, 'exact')
    >>> abs(r.worst["c"]) < 1e-6
    True
    """
    t0 = time.perf_counter()
    rng = np.random.default_rng(0) if rng is None else rng
    if not isinstance(rng, np.random.Generator):
        raise InputError("rng must be a numpy.random.Generator")
    x = _as_uss(usys)
    poles = _check_nominal(x)
    if not x.blocks:
        return RobstabResult(np.inf, np.inf, np.nan, MappingProxyType({}), MappingProxyType({}), True,
                             np.zeros(0), np.zeros(0), None, time.perf_counter() - t0)
    blk = BlockStructure.from_blk([b.blk_row for b in x.blocks])
    w = default_grid(poles) if omega is None else np.unique(np.concatenate([[0.0], np.abs(np.asarray(omega, float))]))
    A, Bw, Bu, Cz, Cy, Dzw, Dzu, Dyw, Dyu = x.partition()

    def m11(ws):
        return _freq_stack(A, Bw, Cz, Dzw, ws)

    fast = MussvOptions(compute_lower=False)
    rel = mussv(m11(w), _relaxed(blk), options=fast)
    mu_up = np.array(rel.upper, dtype=float)
    all_real = all(isinstance(b.atom, UReal) for b in x.blocks)
    clo = _Closure(x) if all(b.reducible and not isinstance(b.atom, ULTIDyn) for b in x.blocks) else None

    best = None  # (alpha, normalised block values, omega_c)
    peak_rel = float(mu_up.max())
    if all_real and peak_rel > 0:
        a_min = 0.5 / peak_rel
        ray = _ray_search(clo, len(x.blocks), a_min, rng)
        if ray is not None:
            best = (ray[0], list(ray[0] * ray[1]), ray[2])

    # the true structure where the relaxed bound is not good enough
    target = 1.0 / best[0] if best is not None else 0.0
    need = mu_up > target * (1 + 1e-3)
    w_all = w
    if best is not None:
        wc = best[2]
        w_all = np.unique(np.concatenate([w, [wc]]))
        rel_all = mussv(m11(w_all), _relaxed(blk), options=fast)
        mu_up = np.array(rel_all.upper, dtype=float)
        need = mu_up > target * (1 + 1e-3)
        need |= np.isclose(w_all, wc)
    need_all = need.copy()
    need = _thin(need, mu_up, target)
    if best is not None:
        need |= np.isclose(w_all, best[2])
    res = None
    if np.any(need) and not blk.is_complex_full_only:
        opts = MussvOptions(compute_lower=not all_real, **_LMI)
        res = mussv(m11(w_all[need]), blk, omega=w_all[need], rng=rng, options=opts)
        mu_up[need] = np.minimum(mu_up[need], np.atleast_1d(res.upper))
        if not all_real:
            lows = np.atleast_1d(res.lower)
            deltas = res.delta if np.ndim(res.upper) else res.delta[:, :, None]
            for k, lo in enumerate(lows):
                if lo > 0 and (best is None or 1.0 / lo < best[0]):
                    vals = _block_values_from_delta(x, deltas[:, :, k])
                    best = (1.0 / lo, vals, float(w_all[need][k]))
    elif np.any(need) and blk.is_complex_full_only:
        res = mussv(m11(w_all[need]), blk, omega=w_all[need], rng=rng)
        lows = np.atleast_1d(res.lower)
        deltas = res.delta if np.ndim(res.upper) else res.delta[:, :, None]
        for k, lo in enumerate(lows):
            if lo > 0 and (best is None or 1.0 / lo < best[0]):
                best = (1.0 / lo, _block_values_from_delta(x, deltas[:, :, k]), float(w_all[need][k]))

    drop = need_all & ~need  # thinned out of the grid (see _thin)
    w_all, mu_up = w_all[~drop], mu_up[~drop]
    # local refinement of the upper bound around its peak
    k = int(np.argmax(mu_up))
    lo_w = w_all[max(k - 1, 0)]
    hi_w = w_all[min(k + 1, len(w_all) - 1)]
    extra_w, extra_mu = [], []
    if hi_w > lo_w:
        def neg_mu(om):
            r = mussv(m11(np.array([om]))[:, :, 0], blk, options=fast)
            extra_w.append(om)
            extra_mu.append(r.upper)
            return -r.upper
        scipy.optimize.minimize_scalar(neg_mu, bounds=(lo_w, hi_w), method="bounded",
                                       options={"maxiter": 8, "xatol": 1e-4 * max(hi_w, 1e-9)})
    if extra_w:
        w_all = np.concatenate([w_all, extra_w])
        mu_up = np.concatenate([mu_up, extra_mu])
        order = np.argsort(w_all)
        w_all, mu_up = w_all[order], mu_up[order]
    peak = float(mu_up.max())
    lower = 1.0 / peak if peak > 0 else np.inf

    notes = []
    if (clo is not None and len(x.blocks) == 1 and isinstance(x.blocks[0].atom, UReal)
            and 0 < x.nstates <= _EXACT_MAX_STATES):
        # one real parameter: µ is zero between crossing frequencies and the grid can step
        # over a crossing (lower above the true margin), so solve the crossing conditions
        try:
            lo_e, up_e, dw, wce = _exact_single_real(x, clo)
            if best is not None and best[0] < lo_e * (1 - 1e-9):
                # the ray search's checked instability inside the interval called stable
                raise _ExactFailed(f"the ray search is unstable at α = {best[0]:.6g} < {lo_e:.6g}")
            if dw is None:
                return RobstabResult(lo_e, np.inf, np.nan, MappingProxyType({}), MappingProxyType({}),
                                     False, w_all, mu_up, res, time.perf_counter() - t0, "exact")
            name = x.blocks[0].atom.name
            return RobstabResult(lo_e, up_e, float(wce), MappingProxyType(_values(x.blocks, [dw])),
                                 MappingProxyType({name: dw}), _check_worst(x, clo, [dw], wce), w_all,
                                 mu_up, res, time.perf_counter() - t0, "exact")
        except (_ExactFailed, ValueError, np.linalg.LinAlgError) as e:
            # a fallback to the grid route, whose bounds hold as ever: told in ``warnings``
            notes.append(f"exact single-parameter route not certified ({e}); grid bounds reported")
            logger.info("robstab: %s", notes[-1])

    if best is None:
        return RobstabResult(lower, np.inf, float(w_all[np.argmax(mu_up)]), MappingProxyType({}),
                             MappingProxyType({}), False, w_all, mu_up, res, time.perf_counter() - t0,
                             "grid", tuple(notes))
    alpha, dvals, wc = best
    checked = _check_worst(x, clo, dvals, wc)
    worst = _values(x.blocks, dvals)
    norm = {b.atom.name: v for b, v in zip(x.blocks, dvals)}
    upper = float(alpha)
    if upper < lower <= upper * (1 + _AGREE_RTOL):
        lower = upper  # the two agree to roundoff (a pole at the origin: both exact)
    if lower > upper and checked:
        # the grid stepped over the crossing: re-evaluate around it with the real blocks
        # regularised (continuous in ω), and report no grid value the perturbation refutes
        ws, mus = _regularised_peak(A, Bw, Cz, Dzw, x.blocks, blk, float(wc), rng)
        grid_lower = lower
        peak = max(peak, float(mus.max()))
        lower = 1.0 / peak
        w_all = np.concatenate([w_all, ws])
        mu_up = np.concatenate([mu_up, mus])
        order = np.argsort(w_all, kind="stable")
        w_all, mu_up = w_all[order], mu_up[order]
        if lower > upper:
            notes.append(f"the grid bound {grid_lower:.6g} (regularised around ω = {wc:.6g}: "
                         f"{lower:.6g}) exceeds the checked destabilising perturbation {upper:.6g}; "
                         "no certified lower bound, reported as 0")
            logger.warning("robstab: %s", notes[-1])
            lower = 0.0
        else:
            # the regularised bound replaces the grid's: a fallback that keeps the guarantee
            notes.append(f"the grid bound {grid_lower:.6g} exceeded the checked perturbation "
                         f"{upper:.6g}; replaced by the bound regularised around ω = {wc:.6g}")
            logger.info("robstab: %s", notes[-1])
    elif lower > upper:
        # a perturbation that did not check is no bound: the grid's is kept, and said
        notes.append(f"the perturbation of size {upper:.6g} did not check (no pole on the "
                     f"axis) and the grid bound {lower:.6g} is above it: no upper bound reported")
        logger.warning("robstab: %s", notes[-1])
        upper = np.inf
    return RobstabResult(lower, upper, float(wc), MappingProxyType(worst), MappingProxyType(norm),
                         checked, w_all, mu_up, res, time.perf_counter() - t0, "grid", tuple(notes))


#: grid and checked perturbation closer than this (relative) agree: both are computed
#: to about 1e-10 (a loss of well-posedness of a static loop gave 0.5 against
#: 0.49999999995, 2026-11-27)
_AGREE_RTOL = 1e-8
#: size of the complex disc added to each real parameter by :func:`_regularised_peak`: the
#: bound over-estimates real µ by at most the factor ``1 + ε`` at a crossing and its spike
#: there widens in proportion to ``ε`` (Packard & Pandey 1993).
_REG_EPS = 0.05
#: relative half-width and points of the local grid around the crossing frequency.
_REG_SPAN, _REG_POINTS = 0.05, 41


def _regularised_peak(A, Bw, Cz, Dzw, blocks, blk, wc, rng):
    """µ upper bounds around ``wc`` with every real ``δ_i`` replaced by ``δ_i + ε δc_i``.

    Packard & Pandey ("Continuity properties of the real/complex structured singular
    value", IEEE TAC 38(3), 1993): with ``δc_i`` complex, ``|δc_i| <= 1``, µ of the
    enlarged structure is continuous in ω and bounds real µ (``δc = 0`` is allowed).  It
    is µ of ``N = [I; Pzᵀ] M [I, ε Pw]`` for ``diag(Δ, δc_1 I, ...)`` (``Pw``, ``Pz``
    select the real channels): ``det(I − N diag(Δ, Δc)) = det(I − M (Δ + ε Pw Δc Pzᵀ))``.
    Returns (frequencies, bounds).
    """
    if wc > 0 and np.isfinite(wc):
        ws = wc * (1 + np.linspace(-_REG_SPAN, _REG_SPAN, _REG_POINTS))
    else:
        ws = np.concatenate([[0.0], np.geomspace(1e-6, 1e-2, _REG_POINTS - 1)])
    M = _freq_stack(A, Bw, Cz, Dzw, ws)
    nz, nw = M.shape[:2]
    cols_w, cols_z, rows = [], [], []
    iw = iz = 0
    for b in blocks:
        if isinstance(b.atom, UReal):
            cols_w.extend(range(iw, iw + b.nw))
            cols_z.extend(range(iz, iz + b.nz))
            rows.append([b.nw, 0])
        iw += b.nw
        iz += b.nz
    Pw = np.eye(nw)[:, cols_w]
    Pz = np.eye(nz)[:, cols_z]
    MP = np.einsum("ijk,jl->ilk", M, Pw)
    N = np.concatenate([np.concatenate([M, _REG_EPS * MP], axis=1),
                        np.concatenate([np.einsum("ji,jlk->ilk", Pz, M),
                                        _REG_EPS * np.einsum("ji,jlk->ilk", Pz, MP)], axis=1)], axis=0)
    big = BlockStructure.from_blk(blk.to_blk().tolist() + rows)
    r = mussv(N, big, omega=ws, rng=rng, options=MussvOptions(compute_lower=False, **_LMI))
    return ws, np.atleast_1d(np.asarray(r.upper, dtype=float))


def _thin(need, mu, target, stride=3, near=0.8):
    """Frequencies that get the true-structure bound: every ``stride``-th one of each run
    of ``need``, and all of those whose relaxed bound is within a factor ``1/near`` of the
    target's neighbourhood (the rest of the run is dropped from the grid)."""
    idx = np.flatnonzero(need)
    keep = np.zeros_like(need)
    keep[idx[::stride]] = True
    keep[idx[mu[idx] <= target / near]] = True
    # both neighbours of the largest relaxed values
    if idx.size:
        top = idx[np.argsort(-mu[idx])[:5]]
        for t in top:
            keep[max(t - 1, 0):t + 2] = need[max(t - 1, 0):t + 2]
    return keep


def _check_worst(x, clo, dvals, wc):
    if clo is not None and all(np.isrealobj(v) or np.imag(v) == 0 for v in dvals):
        sysm = clo.system([float(np.real(v)) for v in dvals])
        if sysm is None:
            return True  # loss of well-posedness: a pole at infinity
        if x.nstates == 0:
            return False
        return bool(np.max(np.linalg.eigvals(sysm[0]).real) >= -1e-7 * max(1.0, np.linalg.norm(sysm[0])))
    # generic: det(I - M11(jωc) Δ) ≈ 0
    A, Bw, Bu, Cz, Cy, Dzw, Dzu, Dyw, Dyu = x.partition()
    M = _freq_stack(A, Bw, Cz, Dzw, [wc])[:, :, 0]
    Delta = np.zeros((x.nw, x.nz), dtype=complex)
    i = j = 0
    for b, v in zip(x.blocks, dvals):
        Delta[i:i + b.nw, j:j + b.nz] = v * np.eye(b.nw) if np.ndim(v) == 0 else v
        i += b.nw
        j += b.nz
    smin = np.linalg.svd(np.eye(M.shape[0]) - M @ Delta, compute_uv=False)[-1]
    return bool(smin <= 1e-6 * (1 + np.linalg.norm(M @ Delta, 2)))


# ---------------------------------------------------------------------------- wcgain
def _peak_gain(clo: _Closure, dvals, w=None):
    """H∞ norm of the closed loop at ``dvals`` (``inf`` if unstable or ill posed)."""
    sysm = clo.system(dvals)
    if sysm is None:
        return np.inf
    A, B, C, D = sysm
    if A.size and np.max(np.linalg.eigvals(A).real) >= -_STAB_TOL:
        return np.inf
    return float(hinfnorm(control.ss(A, B, C, D))[0])


def wcgain(usys, omega=None, *, rng: np.random.Generator | None = None) -> WcgainResult:
    """Worst-case H∞ gain of an uncertain system over the unit box of its uncertainty.

    Upper bound: the smallest ``γ`` with ``µ([M11 M12; M21/γ M22/γ]) <= 1`` over the
    grid for the structure ``diag(Δ, Δ_perf)`` (skewed µ, ``Δ_perf`` a full
    ``nu × ny`` block), from ``mussv``'s upper bound.  Lower bound: the H∞ norm of
    ``usubs(usys, worst)`` at the best perturbation found (real parameters: vertices,
    face grid, Nelder–Mead in the box).

    Parameters
    ----------
    usys : USS
    omega : array_like, optional
        Frequency grid (default as in :func:`robstab`).
    rng : numpy.random.Generator, optional

    Returns
    -------
    WcgainResult

    Examples
    --------
    >>> from lmi_suspension.uncertain import ureal, uss, wcgain
    >>> a = ureal("a", 2.0, plusminus=1.0)        # 1/(s + a): worst gain 1/1 at a = 1
    >>> g = wcgain(uss([[-a]], [[1]], [[1]], [[0]]))
    >>> round(g.lower, 6), g.upper <= 1.01, g.worst["a"]
    (1.0, True, 1.0)
    """
    t0 = time.perf_counter()
    rng = np.random.default_rng(0) if rng is None else rng
    x = _as_uss(usys)
    rs = robstab(x, omega, rng=rng)
    if rs.upper <= 1.0:
        return WcgainResult(np.inf, np.inf, rs.critical_frequency, rs.worst, rs, time.perf_counter() - t0)
    poles = np.linalg.eigvals(x.A) if x.nstates else np.zeros(0)
    w = default_grid(poles) if omega is None else np.unique(np.concatenate([[0.0], np.abs(np.asarray(omega, float))]))
    A, Bw, Bu, Cz, Cy, Dzw, Dzu, Dyw, Dyu = x.partition()
    ny, nu = x.shape

    # ---------------- lower bound: a perturbation in the box, gain recomputed by hinfnorm
    nb = len(x.blocks)
    scal = [b for b in x.blocks if isinstance(b.atom, (UReal, UComplex))]
    clo = _Closure(x) if len(scal) == nb else None
    best_d = [0.0] * nb
    if clo is not None:
        cands = [np.zeros(nb)] + _directions(nb, rng, face_pts=5, n_random=100)
        scores = [(_peak_gain(clo, list(d), w), tuple(d)) for d in cands]
        scores.sort(key=lambda s: -s[0])
        unstable = [np.array(scores[0][1])] if np.isinf(scores[0][0]) else []

        def obj(v):
            v = np.clip(v, -1, 1)
            g = _peak_gain(clo, list(v), w)
            if np.isinf(g):  # unstable (or ill posed) inside the box: the answer is inf
                unstable.append(v)
                return -1e300  # (Nelder-Mead cannot order -inf values)
            return -g

        best_val, best_v = scores[0][0], np.array(scores[0][1])
        for val, d in scores[:3]:
            if unstable:
                break
            sol = scipy.optimize.minimize(obj, np.array(d), method="Nelder-Mead",
                                          options={"maxfev": 80, "xatol": 1e-5, "fatol": 1e-9})
            if -sol.fun > best_val:
                best_val, best_v = -sol.fun, np.clip(sol.x, -1, 1)
        if unstable:
            # robstab's grid did not see it (its margin is certified on the grid only)
            # the answer is an infinite gain, with its perturbation: no loss to warn of
            logger.info("wcgain: unstable inside the box (robstab's margin %.4g was "
                        "certified on its grid only)", rs.lower)
            worst = _values(x.blocks, list(unstable[0]))
            return WcgainResult(np.inf, np.inf, rs.critical_frequency, MappingProxyType(worst),
                                rs, time.perf_counter() - t0)
        best_d = list(best_v)
    worst = _values(x.blocks, best_d) if clo is not None else {}
    if clo is not None:
        lower, wcrit = hinfnorm(usubs(x, worst))
    else:
        lower, wcrit = hinfnorm(usubs(x, {}) if not x.blocks else _nominal_ss(x))
    lower, wcrit = float(lower), float(wcrit)
    if rs.lower <= 1.0:
        return WcgainResult(lower, np.inf, wcrit, MappingProxyType(worst), rs, time.perf_counter() - t0)

    # ---------------- upper bound: skewed µ
    blk = BlockStructure.from_blk([b.blk_row for b in x.blocks] + [[nu, ny]])
    rel = _relaxed(blk)
    if np.isfinite(wcrit):
        w = np.unique(np.concatenate([w, [wcrit], wcrit * np.linspace(0.95, 1.05, 11)]))
    Mfull = _freq_stack(A, x.B, x.C, x.D, w)
    nz = x.nz

    def skew(M, g):
        M = M.copy()
        M[nz:] /= g[None, None, :] if np.ndim(g) else g
        return M

    fast = MussvOptions(compute_lower=False)
    lmi = MussvOptions(compute_lower=False, **_LMI)
    gt = max(lower, 1e-300) * (1 + 2e-3)
    ok = np.atleast_1d(mussv(skew(Mfull, np.full(len(w), gt)), rel, options=fast).upper) <= 1.0
    gam = np.full(len(w), gt)
    if not np.all(ok) and not blk.is_complex_full_only:
        idx = np.flatnonzero(~ok)
        r = mussv(skew(Mfull[:, :, idx], np.full(len(idx), gt)), blk, options=lmi)
        ok[idx] = np.atleast_1d(r.upper) <= 1.0
    bad = np.flatnonzero(~ok)
    if bad.size:
        # bracket with the relaxed bound, then bisect with the true structure
        hi = np.full(bad.size, gt * 2)
        for _ in range(60):
            u = np.atleast_1d(mussv(skew(Mfull[:, :, bad], hi), rel, options=fast).upper)
            if np.all(u <= 1.0):
                break
            hi = np.where(u > 1.0, hi * 2, hi)
        lo = np.full(bad.size, gt)
        for _ in range(10):
            mid = np.sqrt(lo * hi)
            u = np.atleast_1d(mussv(skew(Mfull[:, :, bad], mid), blk, options=lmi).upper)
            hi = np.where(u <= 1.0, mid, hi)
            lo = np.where(u <= 1.0, lo, mid)
            if np.all(hi <= lo * (1 + 1e-3)):
                break
        gam[bad] = hi
    upper = float(gam.max())
    return WcgainResult(lower, upper, wcrit, MappingProxyType(worst), rs, time.perf_counter() - t0)


def _nominal_ss(x):
    from ..umodel.uss import nominal
    return nominal(x)
