"""Specifications of multi-objective synthesis: one small class each, and the protocol a
researcher implements to add one.

A specification receives the synthesis variables as affine CVXPY expressions
(:class:`LmiVariables`: the change of variables of Scherer, Gahinet and Chilali, IEEE TAC
42(7), 1997, with one Lyapunov matrix shared by every specification) and returns its LMIs;
and it certifies itself on the closed loop ``lft(P, K)`` alone, without the LMI variables.

The protocol (:class:`Specification`)::

    class MySpec:
        name = "my spec"
        def lmis(self, v: LmiVariables, level, slack) -> list:    # CVXPY constraints
            ...
        def certify(self, CL: control.StateSpace) -> float:       # achieved value
            ...
        bound: float | None                                       # the bound it asks for

``level`` is the CVXPY expression of the bound (a constant for a constraint, the objective
variable for the objective); ``slack`` is the margin every strict inequality keeps
(``L <= -slack I``), which the synthesis maximises when it reconstructs the controller.

**Discrete time.**  For a plant with sample time ``v.dt > 0`` the same congruence turns the
discrete-time inequalities (``Aclᵀ P Acl - P ...``, with ``calA`` standing for
``Πᵀ P Acl Π`` exactly as in continuous time) into LMIs in the same expressions; a
specification writes its discrete form when ``v.dt`` is set.  :class:`HinfBound`,
:class:`H2Bound` and :class:`Disk` have one; :class:`HalfPlane` becomes the disk
``|z| < exp(-alpha dt)`` (the image of ``Re s < -alpha`` under ``z = exp(s dt)``, exact);
:class:`Sector` and :class:`PeakBound` raise :class:`~lmi_suspension.errors.NotBuiltError`
(the image of a damping sector is not an LMI region).

A specification with a ``channel`` (:class:`Channel`) may set ``lyapunov_scalable = True``
when its bound is a norm of the channel (it scales with the channel's outputs) and its
LMIs certify it for the Lyapunov matrix ``alpha P`` as well as for ``P`` -- true of the
bounded-real and energy-to-peak forms, where ``alpha P`` amounts to the channel's inputs
times ``sqrt(alpha)`` and its outputs divided by it.  :func:`msyn` then treats it as the
norm bounds it ships: its channel's outputs in units of their own size, and ``alpha``
searched.  With one Lyapunov matrix for every specification, that scale decides how much
a constraint costs (on the seat at 1500 N / 0.08 m, the LMI's H∞ level was 96 at
``alpha = 10``, 30.4 at 100, 121 at 1000, and 28.9 at the scale found).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Protocol, runtime_checkable

import control
import cvxpy as cp
import numpy as np
import scipy.linalg

from ..errors import DimensionError, NotBuiltError, ParameterError
from ..lti.norms import h2norm, hinfnorm

__all__ = ["Specification", "LmiVariables", "StateFeedbackVariables", "Channel", "HinfBound", "H2Bound", "PeakBound",
           "HalfPlane", "Disk", "Sector"]


def _sym(E):
    return (E + E.T) / 2


@dataclass(frozen=True)
class Channel:
    """Rows of ``z`` and columns of ``w`` (0-based, in the plant's order); ``None`` means
    all of them."""

    outputs: tuple | None = None
    inputs: tuple | None = None

    def rows(self, nz: int) -> np.ndarray:
        return _indices(self.outputs, nz, "outputs")

    def cols(self, nw: int) -> np.ndarray:
        return _indices(self.inputs, nw, "inputs")


def _indices(sel, n: int, what: str) -> np.ndarray:
    if sel is None:
        return np.arange(n)
    idx = np.atleast_1d(np.asarray(sel, dtype=int))
    if idx.size == 0 or idx.min() < 0 or idx.max() >= n:
        raise DimensionError(f"channel {what} {list(idx)} out of range 0..{n - 1}")
    return idx


@dataclass
class LmiVariables:
    """The synthesis variables and the closed-loop data they make affine.

    With the change of variables of Scherer et al. (1997, Sec. III), a closed-loop
    inequality ``Aclᵀ P + P Acl ...`` in the common Lyapunov matrix ``P`` becomes the same
    inequality in ``calA = [[A Y + B2 Ĉ, A + B2 D̂ C2], [Â, X A + B̂ C2]]``,
    ``calX = [[Y, I], [I, X]]`` and, per channel, :meth:`B`, :meth:`C`, :meth:`D`.

    Here every one of them is returned after a further congruence by ``diag(E, E)``,
    ``E = diag(1 / scale)``, with the variables written relative to ``scale``
    (``Y = S Ŷ S``, ``X = S X̂ S``, ``Â = S Â_r S``, ``B̂ = S B̂_r``, ``Ĉ = Ĉ_r S``,
    ``S = diag(scale)``): in the frame of an earlier solution the variables are of order
    one whatever the decades between the plant's modes (see
    :class:`~lmi_suspension.synthesis.lmi.Frame`).  A congruence preserves definiteness,
    so a specification writes its LMIs in these expressions exactly as in the textbook.
    ``scale`` is all ones unless the synthesis sets a frame.
    """

    Xh: cp.Variable
    Yh: cp.Variable
    Ah: cp.Variable
    Bh: cp.Variable
    Ch: cp.Variable
    Dh: cp.Variable
    data: dict = field(repr=False)
    scale: np.ndarray = None
    #: sample time of the plant (0: continuous time), for the specifications' LMIs
    dt: float = 0.0

    def __post_init__(self):
        if self.scale is None:
            self.scale = np.ones(self.Xh.shape[0])

    @property
    def n(self) -> int:
        return self.Xh.shape[0]

    @property
    def calA(self):
        d, s = self.data, self.scale
        e = 1.0 / s
        A, B2, C2 = d["A"], d["B2"], d["C2"]
        return cp.bmat([[(e[:, None] * A * s[None, :]) @ self.Yh + (e[:, None] * B2) @ self.Ch,
                         e[:, None] * A * e[None, :]
                         + (e[:, None] * B2) @ self.Dh @ (C2 * e[None, :])],
                        [self.Ah, self.Xh @ (s[:, None] * A * e[None, :])
                         + self.Bh @ (C2 * e[None, :])]])

    @property
    def calX(self):
        e2 = np.diag(1.0 / self.scale**2)
        return _sym(cp.bmat([[self.Yh, e2], [e2, self.Xh]]))

    def B(self, ch: Channel):
        d, s = self.data, self.scale
        cols = ch.cols(d["B1"].shape[1])
        B1, D21 = d["B1"][:, cols], d["D21"][:, cols]
        e = 1.0 / s
        return cp.vstack([e[:, None] * B1 + (e[:, None] * d["B2"]) @ self.Dh @ D21,
                          self.Xh @ (s[:, None] * B1) + self.Bh @ D21])

    def C(self, ch: Channel):
        d, s = self.data, self.scale
        rows = ch.rows(d["C1"].shape[0])
        C1, D12 = d["C1"][rows], d["D12"][rows]
        e = 1.0 / s
        return cp.hstack([(C1 * s[None, :]) @ self.Yh + D12 @ self.Ch,
                          C1 * e[None, :] + D12 @ self.Dh @ (d["C2"] * e[None, :])])

    def D(self, ch: Channel):
        d = self.data
        rows, cols = ch.rows(d["C1"].shape[0]), ch.cols(d["B1"].shape[1])
        return d["D11"][np.ix_(rows, cols)] + d["D12"][rows] @ self.Dh @ d["D21"][:, cols]

    @property
    def lyapunov_trace(self):
        """``trace(X̂) + trace(Ŷ)``, which the synthesis bounds."""
        return cp.trace(self.Xh) + cp.trace(self.Yh)

    def with_channel_scaled(self, rows: np.ndarray, row_factor: float, cols: np.ndarray,
                            col_factor: float) -> "LmiVariables":
        """The same variables for the plant whose performance outputs ``rows`` are
        multiplied by ``row_factor`` and disturbance inputs ``cols`` by ``col_factor``
        (a specification's channel in units of its own, see :func:`msyn`)."""
        return replace(self, data=_channel_scaled(self.data, rows, row_factor, cols,
                                                  col_factor))

    def values(self) -> tuple:
        """``(X, Y, Â, B̂, Ĉ, D̂)`` of the solution, in the plant's own scaling."""
        s = self.scale
        X = s[:, None] * self.Xh.value * s[None, :]
        Y = s[:, None] * self.Yh.value * s[None, :]
        return (_sym(X), _sym(Y), s[:, None] * self.Ah.value * s[None, :],
                s[:, None] * self.Bh.value, self.Ch.value * s[None, :], self.Dh.value)


def _channel_scaled(data: dict, rows, row_factor: float, cols, col_factor: float) -> dict:
    d = {k: np.array(m, dtype=float) for k, m in data.items()}
    for key in ("C1", "D11", "D12"):
        d[key][rows] *= row_factor
    for key in ("B1", "D11", "D21"):
        d[key][:, cols] *= col_factor
    return d


@dataclass
class StateFeedbackVariables:
    """The variables of static state feedback ``u = K x`` (:func:`~.statefeedback.msfsyn`),
    with the interface of :class:`LmiVariables`, so that every specification serves both.

    With ``Y = P⁻¹`` and ``L = K Y`` (the congruence by ``Y`` of the closed-loop
    inequality in ``P``), the closed-loop data are affine: ``calA = A Y + B2 L``,
    ``calX = Y``, and per channel ``B = B1``, ``C = C1 Y + D12 L``, ``D = D11``.  The
    plant's measurements are its states in some coordinates, ``y = C2 x`` with ``C2``
    invertible, so that ``K_y = L Y⁻¹ C2⁻¹``.  As in :class:`LmiVariables` the variables
    are relative to ``scale`` (``Y = S Ŷ S``, ``L = L̂ S``) and the expressions are
    returned after the congruence by ``S⁻¹``.
    """

    Yh: cp.Variable
    Lh: cp.Variable
    data: dict = field(repr=False)
    scale: np.ndarray = None
    #: state feedback is built for continuous time only
    dt: float = 0.0

    def __post_init__(self):
        if self.scale is None:
            self.scale = np.ones(self.Yh.shape[0])

    @property
    def n(self) -> int:
        return self.Yh.shape[0]

    @property
    def calA(self):
        d, s = self.data, self.scale
        e = 1.0 / s
        return (e[:, None] * d["A"] * s[None, :]) @ self.Yh + (e[:, None] * d["B2"]) @ self.Lh

    @property
    def calX(self):
        return _sym(self.Yh)

    @property
    def lyapunov_trace(self):
        return cp.trace(self.Yh)

    def B(self, ch: Channel):
        d = self.data
        return (1.0 / self.scale)[:, None] * d["B1"][:, ch.cols(d["B1"].shape[1])]

    def C(self, ch: Channel):
        d = self.data
        rows = ch.rows(d["C1"].shape[0])
        return (d["C1"][rows] * self.scale[None, :]) @ self.Yh + d["D12"][rows] @ self.Lh

    def D(self, ch: Channel):
        d = self.data
        rows, cols = ch.rows(d["C1"].shape[0]), ch.cols(d["B1"].shape[1])
        return d["D11"][np.ix_(rows, cols)]

    def with_channel_scaled(self, rows, row_factor: float, cols,
                            col_factor: float) -> "StateFeedbackVariables":
        """See :meth:`LmiVariables.with_channel_scaled`."""
        return replace(self, data=_channel_scaled(self.data, rows, row_factor, cols,
                                                  col_factor))

    def values(self) -> tuple:
        """``(Y⁻¹, Y, L)`` of the solution in the plant's own scaling (the first two in
        the places of :meth:`LmiVariables.values`' ``X, Y``)."""
        s = self.scale
        Y = _sym(s[:, None] * self.Yh.value * s[None, :])
        return _sym(np.linalg.inv(Y)), Y, self.Lh.value * s[None, :]

    def gain(self) -> np.ndarray:
        """``K_y = L Y⁻¹ C2⁻¹``: the static gain from the measurements ``y = C2 x``."""
        _, Y, L = self.values()
        return np.linalg.solve(self.data["C2"].T, np.linalg.solve(Y, L.T)).T


@runtime_checkable
class Specification(Protocol):
    """What a specification provides (see the module docstring)."""

    name: str

    def lmis(self, v: LmiVariables, level, slack) -> list: ...

    def certify(self, CL: control.StateSpace) -> float: ...


def _sub(CL: control.StateSpace, ch: Channel):
    nz, nw = CL.noutputs, CL.ninputs
    rows, cols = ch.rows(nz), ch.cols(nw)
    return (np.asarray(CL.A), np.asarray(CL.B)[:, cols], np.asarray(CL.C)[rows],
            np.asarray(CL.D)[np.ix_(rows, cols)])


def _sub_system(CL: control.StateSpace, ch: Channel) -> control.StateSpace:
    """The channel of ``CL`` as a system in ``CL``'s time base."""
    return control.ss(*_sub(CL, ch), CL.dt or 0)


def _discrete(v) -> bool:
    return bool(getattr(v, "dt", 0.0))


def _not_in_discrete_time(what: str, instead: str) -> NotBuiltError:
    return NotBuiltError(f"{what} is built for continuous-time plants only; {instead}")


def _gramian(A, B) -> np.ndarray:
    if not np.all(np.linalg.eigvals(A).real < 0):
        return np.full((A.shape[0], A.shape[0]), np.inf)
    return scipy.linalg.solve_continuous_lyapunov(A, -B @ B.T)


@dataclass(frozen=True)
class HinfBound:
    """``‖T_zw‖∞ < bound`` on a channel (bounded-real lemma); ``bound=None`` when it is
    the objective."""

    channel: Channel = Channel()
    bound: float | None = None
    name: str = "H∞"

    def lmis(self, v: LmiVariables, level, slack) -> list:
        B, C, D = v.B(self.channel), v.C(self.channel), v.D(self.channel)
        nw, nz = B.shape[1], C.shape[0]
        if _discrete(v):
            # discrete bounded-real lemma (Gahinet & Apkarian 1994, Sec. 5), congruent to
            # [[P, P Acl, P Bcl, 0], [., P, 0, Cclᵀ], [., ., γI, Dclᵀ], [., ., ., γI]] > 0
            n2 = v.calX.shape[0]
            M = _sym(cp.bmat([[v.calX, v.calA, B, np.zeros((n2, nz))],
                              [v.calA.T, v.calX, np.zeros((n2, nw)), C.T],
                              [B.T, np.zeros((nw, n2)), level * np.eye(nw), D.T],
                              [np.zeros((nz, n2)), C, D, level * np.eye(nz)]]))
            return [M >> slack * np.eye(M.shape[0])]
        M = _sym(cp.bmat([[v.calA + v.calA.T, B, C.T],
                          [B.T, -level * np.eye(nw), D.T],
                          [C, D, -level * np.eye(nz)]]))
        return [M << -slack * np.eye(M.shape[0])]

    def certify(self, CL) -> float:
        return float(hinfnorm(_sub_system(CL, self.channel))[0])


def _no_feedthrough(v: LmiVariables, ch: Channel, what: str) -> list:
    d = v.data
    rows, cols = ch.rows(d["C1"].shape[0]), ch.cols(d["B1"].shape[1])
    if np.any(d["D11"][np.ix_(rows, cols)]):
        raise ParameterError(f"{what}: the channel has a direct feedthrough D11 != 0; its "
                             "H2 / peak norm is infinite")
    Dcl = v.D(ch)
    return [Dcl == 0] if np.any(d["D12"][rows]) and np.any(d["D21"][:, cols]) else []


@dataclass(frozen=True)
class H2Bound:
    """``‖T_zw‖₂ < bound`` on a channel (needs a strictly proper closed loop there)."""

    channel: Channel = Channel()
    bound: float | None = None
    name: str = "H2"

    def lmis(self, v: LmiVariables, level, slack) -> list:
        B, C = v.B(self.channel), v.C(self.channel)
        nw, nz = B.shape[1], C.shape[0]
        Q = cp.Variable((nz, nz), symmetric=True)
        if _discrete(v):
            # ‖T‖₂² = trace(C W Cᵀ + D Dᵀ) for any W > A W Aᵀ + B Bᵀ (the controllability
            # Gramian's inequality), by Schur complements with P = W⁻¹: M1 is that
            # inequality after the congruence diag(P, P, I), M2 says Q > C W Cᵀ + D Dᵀ
            D = v.D(self.channel)
            n2 = v.calX.shape[0]
            M1 = _sym(cp.bmat([[v.calX, v.calA, B],
                               [v.calA.T, v.calX, np.zeros((n2, nw))],
                               [B.T, np.zeros((nw, n2)), np.eye(nw)]]))
            M2 = _sym(cp.bmat([[Q, C, D], [C.T, v.calX, np.zeros((n2, nw))],
                               [D.T, np.zeros((nw, n2)), np.eye(nw)]]))
            return [M1 >> slack * np.eye(M1.shape[0]), M2 >> slack * np.eye(M2.shape[0]),
                    cp.trace(Q) <= level]
        M1 = _sym(cp.bmat([[v.calA + v.calA.T, B], [B.T, -np.eye(nw)]]))
        M2 = _sym(cp.bmat([[v.calX, C.T], [C, Q]]))
        # ‖T‖₂² < ν: level is ν = bound² (squared so that the LMI stays affine)
        return [M1 << -slack * np.eye(M1.shape[0]), M2 >> slack * np.eye(M2.shape[0]),
                cp.trace(Q) <= level] + _no_feedthrough(v, self.channel, self.name)

    def certify(self, CL) -> float:
        if CL.dt:
            return float(h2norm(_sub_system(CL, self.channel)))
        A, B, C, D = _sub(CL, self.channel)
        if np.any(D):
            return float("inf")
        return float(np.sqrt(max(np.trace(C @ _gramian(A, B) @ C.T), 0.0)))

    squared = True  # the LMI level is the bound squared


@dataclass(frozen=True)
class PeakBound:
    """Generalized H2 (energy-to-peak) bound per output row: ``|z_i(t)| <= bounds[i]`` for
    every ``w`` with ``‖w‖₂ <= 1`` (Wilson, IEEE TAC 34(1), 1989): the peak of row ``i``
    is ``sqrt((C Wc Cᵀ)_ii)``, ``Wc`` the closed loop's controllability Gramian.  Scale
    ``w`` (or the bounds) for another disturbance energy."""

    channel: Channel = Channel()
    bounds: tuple = ()
    name: str = "peak"

    @property
    def bound(self):
        return max(self.bounds) if self.bounds else None

    def lmis(self, v: LmiVariables, level, slack) -> list:
        if _discrete(v):
            raise _not_in_discrete_time("PeakBound", "bound the channel's H2 norm instead "
                                        "(H2Bound), which bounds every output's peak")
        B, C = v.B(self.channel), v.C(self.channel)
        nw, nz = B.shape[1], C.shape[0]
        if len(self.bounds) != nz:
            raise DimensionError(f"{self.name}: {len(self.bounds)} bounds for {nz} outputs")
        if not all(b > 0 and np.isfinite(b) for b in self.bounds):
            raise ParameterError(f"{self.name}: bounds must be positive, got {self.bounds}")
        M1 = _sym(cp.bmat([[v.calA + v.calA.T, B], [B.T, -np.eye(nw)]]))
        cons = [M1 << -slack * np.eye(M1.shape[0])]
        for i, b in enumerate(self.bounds):
            # C_i P⁻¹ C_iᵀ < b², written for the row C_i / b (a congruence): the entries
            # stay of order one however small the bound is in the plant's units
            Ci = C[i:i + 1] / b
            Mi = _sym(cp.bmat([[v.calX, Ci.T], [Ci, np.ones((1, 1))]]))
            cons.append(Mi >> slack * np.eye(Mi.shape[0]))
        return cons + _no_feedthrough(v, self.channel, self.name)

    def certify(self, CL) -> float:
        """The largest ratio ``peak_i / bounds[i]`` (≤ 1 when met); see :meth:`peaks`."""
        return float(np.max(self.peaks(CL) / np.asarray(self.bounds, dtype=float)))

    def peaks(self, CL) -> np.ndarray:
        A, B, C, D = _sub(CL, self.channel)
        W = _gramian(A, B)
        if np.any(D) or not np.all(np.isfinite(W)):   # a feedthrough, an unstable loop
            return np.full(C.shape[0], np.inf)
        return np.sqrt(np.maximum(np.diag(C @ W @ C.T), 0.0))


@dataclass(frozen=True)
class HalfPlane:
    """Closed-loop poles with ``Re s < -alpha`` (a decay rate)."""

    alpha: float = 0.0
    name: str = "half-plane"
    bound = None

    def lmis(self, v, level, slack) -> list:
        if _discrete(v):
            # Re s < -alpha  <=>  |z| < exp(-alpha dt) for z = exp(s dt)
            return Disk(radius=float(np.exp(-self.alpha * v.dt))).lmis(v, level, slack)
        M = _sym(v.calA + v.calA.T + 2 * self.alpha * v.calX)
        return [M << -slack * np.eye(M.shape[0])]

    def contains(self, p: np.ndarray) -> np.ndarray:
        return p.real < -self.alpha

    def certify(self, CL) -> float:
        """Largest ``Re p + alpha`` over the closed-loop poles (< 0 when met); in discrete
        time over ``log(p) / dt``, the poles' continuous-time images."""
        p = np.linalg.eigvals(np.asarray(CL.A))
        if not p.size:
            return -np.inf
        re = np.log(np.maximum(np.abs(p), 1e-300)) / CL.dt if CL.dt else p.real
        return float(np.max(re + self.alpha))


@dataclass(frozen=True)
class Disk:
    """Closed-loop poles in the disk ``|s + center| < radius`` (``center >= radius``
    keeps it in the left half-plane: bounds the natural frequencies); for a
    discrete-time plant the disk ``|z + center| < radius`` of the z-plane (``radius < 1``
    and ``center = 0``: a decay of ``log(radius)/dt`` per second)."""

    radius: float
    center: float = 0.0
    name: str = "disk"
    bound = None

    def lmis(self, v, level, slack) -> list:
        A, Xc = v.calA, v.calX
        # divided by the radius (a positive factor: the same LMI), so that its entries
        # are of the size of calX whatever the radius (1000 rad/s on the seat put them
        # 1e7 above the H∞ level's, and every Clarabel solve needed a recovery)
        c = self.center / self.radius
        M = _sym(cp.bmat([[-Xc, c * Xc + A / self.radius],
                          [c * Xc + A.T / self.radius, -Xc]]))
        return [M << -slack * np.eye(M.shape[0])]

    def certify(self, CL) -> float:
        """Largest ``|p + center| - radius`` (< 0 when met)."""
        p = np.linalg.eigvals(np.asarray(CL.A))
        return float(np.max(np.abs(p + self.center) - self.radius)) if p.size else -np.inf


@dataclass(frozen=True)
class Sector:
    """Closed-loop poles in the sector ``|Im s| < tan(theta) (-Re s)`` (damping ratio at
    least ``cos(theta)``)."""

    theta: float
    name: str = "sector"
    bound = None

    def lmis(self, v, level, slack) -> list:
        if _discrete(v):
            raise _not_in_discrete_time("Sector", "the image of a damping sector under "
                                        "z = exp(s dt) is not an LMI region; a Disk of the "
                                        "z-plane inside it bounds the damping from below")
        A = v.calA
        s, c = np.sin(self.theta), np.cos(self.theta)
        M = _sym(cp.bmat([[s * (A + A.T), c * (A - A.T)], [c * (A.T - A), s * (A + A.T)]]))
        return [M << -slack * np.eye(M.shape[0])]

    def certify(self, CL) -> float:
        """Largest ``sin θ Re p + cos θ |Im p|`` (< 0 when met)."""
        p = np.linalg.eigvals(np.asarray(CL.A))
        if not p.size:
            return -np.inf
        return float(np.max(np.sin(self.theta) * p.real + np.cos(self.theta) * np.abs(p.imag)))
