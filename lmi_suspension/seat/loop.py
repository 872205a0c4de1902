"""The seat's loop with any linear controller ``u = K y``: its exact-delay bump response,
its poles and its µ over two full complex blocks, each in closed form and cheap to
repeat for many controllers (what a search over controllers and the certificates need).

* :class:`BumpResponse`: peaks of the response to a road at several actuator delays, the
  loop with the exact delay ``e^{-sτ}``, linear and unclipped, transformed back by FFT
  (it matches the time-stepping :func:`~.simulate.simulate` within 0.2 %, a test
  checks it);
* :class:`TwoBlockMu`: µ over the delay cover and the performance block, two full
  complex blocks, for which µ equals its D-scaled upper bound (Packard & Doyle,
  Automatica 29(1), 1993, Sec. 9.1: 2S + F ≤ 3), minimised per frequency over the one
  scale ratio (a test compares it with :func:`~lmi_suspension.mu.mussv`);
* :func:`loop_poles`, :func:`interconnection_poles`, :func:`loop_response`,
  :func:`frequency_response`: the loop's poles and responses.

This module holds no design code: the refinement (:mod:`.refine`), the occupants' set
(:mod:`.occupants`), the worst-case search (:mod:`.worstcase`) and the certificate
(:mod:`.record`) use it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DimensionError, InputError, ParameterError
from .augmented import SeatDesignOptions, seat_augmented_plant
from .model import seat_matrices
from .params import SeatParameters
from .roads import RoadInput, bump

__all__ = ["REFINE_DELAYS", "BumpResponse", "TwoBlockMu", "frequency_response",
           "interconnection_poles", "loop_poles", "loop_response"]

#: The delays the bump requirements are evaluated at, s (the issue's 0, 5, ..., 25 ms).
REFINE_DELAYS = (0.0, 0.005, 0.01, 0.015, 0.02, 0.025)

#: Record length of the FFT, s: every loop pole decays at least at _MIN_DECAY = 0.5
#: rad/s (a constraint of the search), by e^-12 at 24 s, so the circular convolution
#: does not wrap.  (With 16 s and 0.05 rad/s the search found a loop whose wrapped FFT
#: response met 2000 N while the time simulation commanded 2424 N, 2026-11-26.)
_FFT_HORIZON = 24.0
#: The peak refinement between grid points: the bracket (two grid spacings, 0.08
#: decades) sampled at this many points, then the bracket around the best, this many
#: times: 0.08 / 12² ≈ 6e-4 decades (0.13 % in frequency) at the end, where a peak of
#: damping 0.1 is within 1e-4 of its top.  One batched evaluation per zoom: a golden
#: section (20 steps) cost 32 ms per controller against 9 ms for the grid.
_PEAK_POINTS = 13
_PEAK_ZOOMS = 2
#: Golden-section steps of the per-frequency scale search (on log d in [-10, 10]: the
#: bracket shrinks to 20 · 0.618^30 ≈ 1e-5, and µ is flat to second order there: 25
#: steps and 40 gave the µ controller's peak equal to 3e-11, 2026-11-26).
_GOLDEN_STEPS = 30


@dataclass(frozen=True)
class BumpResponse:
    """Peaks of the seat's response to a road at several actuator delays, for any
    linear controller ``u = K y``, in closed form in the frequency domain.

    With ``u_a = e^{-sτ} u``: ``u = K (G_yw w + G_yu u_a)``, so
    ``u = K G_yw w / (1 - K G_yu e^{-sτ})``; ``z̈3`` and ``x1`` follow from ``w`` and
    ``u_a``. The road is zero-padded to :data:`_FFT_HORIZON` and transformed once; each
    controller costs one frequency response and one inverse FFT per delay. No clipping:
    this is the linear loop whose commanded force the requirements bound.

    Parameters
    ----------
    road : RoadInput, optional
        The paper's bump by default; its sample period is the FFT's.
    delays : sequence of float
        Actuator delays, s.
    params : SeatParameters, optional

    Examples
    --------
    >>> import control
    >>> z, u, x1 = BumpResponse(delays=(0.0,)).peaks(control.ss([], [], [], [[0.0, 0.0]]))
    >>> round(float(z[0]), 2)               # passive seat (FACTS.md: 26.47 m/s²)
    26.47
    """

    road: RoadInput | None = None
    delays: tuple = REFINE_DELAYS
    params: SeatParameters | None = None

    def __post_init__(self):
        road = bump() if self.road is None else self.road
        if not isinstance(road, RoadInput):
            raise ParameterError(f"road must be a RoadInput, got {type(road).__name__}")
        delays = np.asarray(self.delays, dtype=float).ravel()
        if delays.size == 0 or not np.all(np.isfinite(delays)) or np.any(delays < 0):
            raise ParameterError(f"delays must be finite and non-negative, got {self.delays!r}")
        dt = float(road.t[1] - road.t[0])
        n = int(round(max(_FFT_HORIZON, 4 * (road.t[-1] - road.t[0])) / dt))
        w = np.zeros(n)
        w[:road.w.size] = road.w
        s = 2j * np.pi * np.fft.rfftfreq(n, dt)
        M = seat_matrices(self.params)
        lam, V = np.linalg.eig(M.A)
        Vi = np.linalg.inv(V)
        resolvent = 1.0 / (s[None, :] - lam[:, None])

        def fr(C, B):  # C (sI - A)^-1 B on the grid, (p, m, F)
            return np.einsum("pn,nm,nf->pmf", C @ V, Vi @ B, resolvent)

        cache = dict(n=n, dt=dt, s=s, W=np.fft.rfft(w), keep=road.w.size,
                     Gy_w=fr(M.C3, M.Bw), Gy_u=fr(M.C3, M.B), Gz_w=fr(M.C1, M.Bw)[0, 0],
                     Gz_u=fr(M.C1, M.B)[0, 0], Gx_w=fr(M.C2, M.Bw)[0, 0],
                     Gx_u=fr(M.C2, M.B)[0, 0], E=np.exp(-np.outer(delays, s)))
        object.__setattr__(self, "_c", cache)

    def peaks(self, K) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(peak |z̈3|, peak |u| commanded, peak |x1|)``, one entry per delay, over
        the road's record.  The loop must be stable (see :func:`loop_poles`)."""
        c = self._c
        Kw = frequency_response(K, c["s"])
        KGu = np.einsum("yf,yf->f", Kw, c["Gy_u"][:, 0])
        KGw = np.einsum("yf,yf->f", Kw, c["Gy_w"][:, 0])
        U = KGw * c["W"] / (1.0 - KGu * c["E"])
        Ua = U * c["E"]
        Z = c["Gz_w"] * c["W"] + c["Gz_u"] * Ua
        X = c["Gx_w"] * c["W"] + c["Gx_u"] * Ua
        k = c["keep"]
        peak = (lambda F: np.max(np.abs(np.fft.irfft(F, c["n"])[:, :k]), axis=1))
        return peak(Z), peak(U), peak(X)


def frequency_response(K, s: np.ndarray) -> np.ndarray:
    """``K(s)`` of a one-output controller at the points ``s``, shape ``(ny, len(s))``,
    by its eigendecomposition (cheap for many points)."""
    A, B, C, D = (np.asarray(m, dtype=float) for m in (K.A, K.B, K.C, K.D))
    if C.shape[0] != 1:
        raise DimensionError(f"a seat controller has one output, got {C.shape[0]}")
    if A.size == 0:
        return np.repeat(D.T, len(s), axis=1)
    lam, V = np.linalg.eig(A)
    r = (C @ V)[0][:, None] * np.linalg.solve(V, B)          # (n, ny) residues
    return np.einsum("ny,nf->yf", r, 1.0 / (s[None, :] - lam[:, None])) + D.T


def loop_response(K, omega: np.ndarray, blocks) -> np.ndarray:
    """``F_l(P, K)(jω)`` of a plant with one control input, shape ``(F, nz, nw)``, from
    the plant's responses ``blocks = (P11, P12, P21, P22)`` on ``omega`` (``P12`` and
    ``P22`` with their one input column dropped)."""
    P11, P12, P21, P22 = blocks
    Kw = frequency_response(K, 1j * omega)                  # (ny, F)
    loop = 1.0 - np.einsum("yf,yf->f", Kw, P22)
    KP21 = np.einsum("yf,ywf->wf", Kw, P21) / loop
    return np.moveaxis(P11 + P12[:, None, :] * KP21[None, :, :], -1, 0)


def interconnection_poles(P, K, nw: int, nu: int, nz: int, ny: int) -> np.ndarray:
    """Poles of ``F_l(P, K)`` where ``P`` has ``nw + nu`` inputs and ``nz + ny``
    outputs and ``D22 = 0``, as every seat plant here has (a nonzero ``D22`` is an
    :class:`InputError`: the formula below would be wrong for it)."""
    A, B, C = (np.asarray(m, dtype=float) for m in (P.A, P.B, P.C))
    if np.any(np.asarray(P.D, dtype=float)[nz:nz + ny, nw:nw + nu] != 0):
        raise InputError("interconnection_poles needs D22 = 0")
    B2, C2 = B[:, nw:nw + nu], C[nz:nz + ny]
    Ak, Bk, Ck, Dk = (np.asarray(m, dtype=float) for m in (K.A, K.B, K.C, K.D))
    return np.linalg.eigvals(np.block([[A + B2 @ Dk @ C2, B2 @ Ck], [Bk @ C2, Ak]]))


def loop_poles(K, params: SeatParameters | None = None) -> np.ndarray:
    """Poles of the seat with ``u = K y`` and no delay."""
    M = seat_matrices(params)
    A, B, C, D = (np.asarray(m, dtype=float) for m in (K.A, K.B, K.C, K.D))
    Acl = np.block([[M.A + M.B @ D @ M.C3, M.B @ C], [B @ M.C3, A]])
    return np.linalg.eigvals(Acl)


@dataclass(frozen=True)
class TwoBlockMu:
    """µ of the seat's closed loop over a structure of two full complex blocks, on a
    frequency grid, for any controller ``u = K y``.

    For two full complex blocks µ equals its upper bound ``min_D σ̄(D M D⁻¹)``
    (Packard & Doyle 1993: 2S + F ≤ 3), and ``D = diag(d I, I)`` has one free ratio,
    found per frequency by a golden-section search on ``log d`` (vectorised over the
    grid).  The plant's responses are computed once; each controller costs one
    frequency response and a batch of small SVDs.

    Parameters
    ----------
    design : SeatDesignOptions
        The µ weights (the structure must be two full complex blocks, as the paper's
        delay cover with the performance block is).
    omega : array_like
        Grid, rad/s.
    params : SeatParameters, optional
    """

    design: SeatDesignOptions
    omega: np.ndarray
    params: SeatParameters | None = None

    def __post_init__(self):
        from ..lti import freqresp
        from ..umodel.blocks import BlockStructure

        aug = seat_augmented_plant(self.design, self.params)
        blk = np.asarray(aug.blk)
        if blk.shape != (2, 2) or np.any(blk <= 0):
            raise DimensionError(f"TwoBlockMu needs two full complex blocks, got blk "
                                 f"{blk.tolist()}")
        nz, nw = BlockStructure.coerce(aug.blk).shape_M
        omega = np.asarray(self.omega, dtype=float).ravel()
        if omega.size < 2 or np.any(omega <= 0) or not np.all(np.isfinite(omega)):
            raise ParameterError("omega must hold positive finite frequencies")
        ny, nu = aug.nmeas, aug.ncon
        object.__setattr__(self, "_c", dict(
            omega=omega, P=aug.P, blk=aug.blk, nz=nz, nw=nw, ny=ny, nu=nu,
            rows=int(blk[0, 1]), cols=int(blk[0, 0])))
        self._c["grid"] = self._blocks(freqresp(aug.P, omega))

    def _blocks(self, Pw):
        c = self._c
        nz, nw, ny, nu = c["nz"], c["nw"], c["ny"], c["nu"]
        return (Pw[:nz, :nw], Pw[:nz, nw:nw + nu][:, 0], Pw[nz:nz + ny, :nw],
                Pw[nz:nz + ny, nw:nw + nu][:, 0])

    def loop_poles(self, K) -> np.ndarray:
        """Poles of the µ loop ``F_l(P, K)`` (the weights' poles included)."""
        c = self._c
        return interconnection_poles(c["P"], K, c["nw"], c["nu"], c["nz"], c["ny"])

    def _loop(self, K, omega=None) -> np.ndarray:
        """The closed loop's response, shape ``(F, nz, nw)``, on the grid or at ``omega``."""
        from ..lti import freqresp

        c = self._c
        if omega is None:
            omega, (P11, P12, P21, P22) = c["omega"], c["grid"]
        else:
            omega = np.asarray(omega, dtype=float).ravel()
            P11, P12, P21, P22 = self._blocks(freqresp(c["P"], omega))
        return loop_response(K, omega, (P11, P12, P21, P22))

    def cover_gain(self, K, omega=None) -> np.ndarray:
        """σ̄ of the first block's channel on the grid, or at ``omega`` (rad/s): µ of
        robust stability against that block alone (one full complex block: µ is σ̄),
        the delay cover's."""
        M = self._loop(K, omega)[:, :self._c["rows"], :self._c["cols"]]
        return np.linalg.svd(M, compute_uv=False)[:, 0]

    def cover_peaks(self, K, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The delay cover's gain on the grid and its ``count`` largest local maxima
        refined between grid points, as :meth:`peaks` does for µ."""
        return _zoomed_peaks(lambda w=None: self.cover_gain(K, w), self._c["omega"], count)

    def curve(self, K, omega=None) -> np.ndarray:
        """µ at each grid frequency, or at ``omega`` (rad/s) where given."""
        c = self._c
        M = self._loop(K, omega)
        r, k = c["rows"], c["cols"]

        def scaled_norm(log_d):
            d = np.exp(log_d)[:, None, None]
            S = M.copy()
            S[:, :r, :] *= d
            S[:, :, :k] /= d
            # σ̄ by the largest eigenvalue of SᴴS: half the time of a batched SVD
            return np.sqrt(np.linalg.eigvalsh(np.conj(np.swapaxes(S, 1, 2)) @ S)[:, -1])

        lo = np.full(M.shape[0], -10.0)
        hi = np.full(M.shape[0], 10.0)
        g = (np.sqrt(5.0) - 1.0) / 2.0
        a, b = hi - g * (hi - lo), lo + g * (hi - lo)
        fa, fb = scaled_norm(a), scaled_norm(b)
        for _ in range(_GOLDEN_STEPS):
            left = fa < fb              # the minimum lies in [lo, b]
            hi = np.where(left, b, hi)
            lo = np.where(left, lo, a)
            a_new = np.where(left, hi - g * (hi - lo), b)
            b_new = np.where(left, a, lo + g * (hi - lo))
            a, b = a_new, b_new
            fa, fb = scaled_norm(a), scaled_norm(b)
        return np.minimum(fa, fb)

    def peaks(self, K, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """µ on the grid, and its ``count`` largest local maxima refined between grid
        points: ``(curve, peak values, peak frequencies)``.

        Each of the largest local maxima of the grid curve is maximised over the interval
        between its neighbours by sampling it and zooming in (:data:`_PEAK_POINTS`,
        :data:`_PEAK_ZOOMS`); where there are fewer maxima, the largest is repeated, so that the
        number of values is fixed (the search's constraints need that).  A sharp peak
        between grid points is found this way, which a grid alone can miss.
        """
        return _zoomed_peaks(lambda w=None: self.curve(K, w), self._c["omega"], count)


def _zoomed_peaks(f, omega: np.ndarray, count: int):
    """``(f on the grid, its count largest local maxima refined, their frequencies)``
    for a curve ``f(omega=None)`` given on the grid ``omega`` (see :meth:`TwoBlockMu.peaks`)."""
    mu = f()
    w = np.log(omega)
    inner = np.flatnonzero((mu[1:-1] >= mu[:-2]) & (mu[1:-1] >= mu[2:])) + 1
    if inner.size == 0:
        inner = np.array([int(np.clip(np.argmax(mu), 1, mu.size - 2))])
    top = inner[np.argsort(-mu[inner], kind="stable")][:count]
    top = np.concatenate([top, np.repeat(top[:1], count)])[:count]
    lo, hi = w[top - 1], w[top + 1]
    best_mu, best_w = mu[top], omega[top]
    cols = np.arange(count)
    for _ in range(_PEAK_ZOOMS):
        # every peak's bracket sampled at once (one batched evaluation per zoom)
        t = np.linspace(0.0, 1.0, _PEAK_POINTS)
        grid = lo[:, None] + (hi - lo)[:, None] * t[None, :]        # (count, n)
        vals = f(np.exp(grid.ravel())).reshape(grid.shape)
        j = np.argmax(vals, axis=1)
        better = vals[cols, j] > best_mu
        best_mu = np.where(better, vals[cols, j], best_mu)
        best_w = np.where(better, np.exp(grid[cols, j]), best_w)
        step = (hi - lo) / (_PEAK_POINTS - 1)
        lo, hi = grid[cols, j] - step, grid[cols, j] + step
    return mu, best_mu, best_w


#: step of the physical limit's LP for ``plants``, s (bump_limit's default; the sweep's;
#: the occupants' certificate uses it too)
_LIMIT_DT = 2e-3
