"""Tuning requirements (MATLAB's ``TuningGoal``): one small class each, behind one
protocol, as :mod:`lmi_suspension.synthesis.constraints` does for LMI specifications.

A requirement has a *normalised value*, ``≤ 1`` when it is met (as MATLAB's normalised
``TuningGoal`` values), computed on one model's closed loop with its (sub)gradient with
respect to the blocks' parameters θ; and it certifies itself on the closed loop
``lft(P, K)`` built from the returned numbers, by a route the optimiser did not use
(``hinfnorm`` and a dense σ̄ sweep of ``lft(P, K)``, ``numpy.linalg.eigvals``, a
sensitivity built by ``control.feedback``).

The protocol (:class:`Requirement`)::

    class MyRequirement:
        name = "my requirement"
        def bind(self, plant: GeneralizedPlant) -> "MyRequirement":
            ...   # check (and resolve) the channels against the plant; typed errors here
        def value(self, loop: ClosedLoop) -> tuple[float, numpy.ndarray | None]:
            ...   # (value, ∇θ value); inf and None where it cannot be met (unstable)
        def certify(self, CL: control.StateSpace, plant, K) -> float:
            ...   # the same value from lft(plant, K) by another route

:func:`~lmi_suspension.tune.systune` calls ``bind`` once per model before it starts,
``value`` at every iterate (on stable loops only), and ``certify`` on the result.
Where the value is a maximum (over frequencies, poles, loops) the gradient is that of
the active term: the Clarke subgradient the nonsmooth BFGS needs.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, replace
from typing import Protocol, runtime_checkable

import control
import numpy as np

from ..errors import DimensionError, IllPosedLoopError, ParameterError
from ..lti.checks import as_statespace
from ..lti.norms import freqresp, hinfnorm, is_stable, sigma_max
from ..lti.plant import GeneralizedPlant
from .closedloop import ClosedLoop
from .hinfstruct import _feedthrough_check

__all__ = ["HinfBound", "Margins", "PoleRegion", "Requirement"]

#: points per decade of the certificates' σ̄ sweeps, over the poles' band widened by
#: three decades each side: a peak of damping 1e-3 is ~2e-3 wide in ln ω, so 1000 points
#: a decade (spacing 0.0023 in ln ω) put a point on it; such a sweep took 0.085 s on a
#: random 20-state 2 × 2 system, 0.018 s on 4 states (2-core EPYC, 2026-12-02)
_SWEEP_PER_DECADE = 1000


@runtime_checkable
class Requirement(Protocol):
    """What :func:`~lmi_suspension.tune.systune` needs of a requirement (see the module
    docstring)."""

    name: str

    def bind(self, plant: GeneralizedPlant) -> Requirement: ...

    def value(self, loop: ClosedLoop) -> tuple: ...

    def certify(self, CL: control.StateSpace, plant: GeneralizedPlant, K) -> float: ...


# ------------------------------------------------------------------------------ helpers
def _selection(sel, labels, what: str, name: str):
    """Indices (0-based) of ``sel`` (None: all; ints or signal names) among ``labels``."""
    n = len(labels)
    if sel is None:
        return tuple(range(n))
    items = [sel] if isinstance(sel, (str, numbers.Integral, np.integer)) else list(sel)
    if not items:
        raise DimensionError(f"{name}: an empty {what} selection")
    out = []
    for s in items:
        if isinstance(s, str):
            if s not in labels:
                raise DimensionError(f"{name}: the plant has no {what} named {s!r}; its "
                                     f"{what}s are {', '.join(labels)}")
            out.append(labels.index(s))
        elif isinstance(s, (numbers.Integral, np.integer)) and not isinstance(s, bool):
            if not 0 <= int(s) < n:
                raise DimensionError(f"{name}: {what} {int(s)} out of range: the plant has "
                                     f"{n} {what}s (0-based)")
            out.append(int(s))
        else:
            raise DimensionError(f"{name}: a {what} is an index or a name, got {s!r}")
    if len(set(out)) != len(out):
        raise DimensionError(f"{name}: a {what} selected twice in {sel!r}")
    return tuple(out)


def _weight(W, n: int, side: str, name: str):
    if W is None:
        return None
    try:
        sys = as_statespace(W, f"{name}: {side} weight")
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{name}: {side} weight is not a system or matrix: "
                             f"{exc}") from exc
    if (sys.noutputs, sys.ninputs) not in ((n, n), (1, 1)):
        raise DimensionError(f"{name}: the {side} weight is {sys.noutputs}x{sys.ninputs}; "
                             f"the channel has {n} {'outputs' if side == 'left' else 'inputs'}")
    if not is_stable(sys):
        raise ParameterError(f"{name}: the {side} weight is not stable")
    if (sys.noutputs, sys.ninputs) == (1, 1) and n > 1:
        sys = control.append(*([sys] * n))
    return sys


def _response(sys, omega) -> np.ndarray:
    if sys is None:
        return None
    if not np.isfinite(omega):
        return np.asarray(sys.D, dtype=complex)
    return freqresp(sys, [omega])[:, :, 0]


def _swept_norm(sys) -> float:
    """``max(hinfnorm, a dense σ̄ sweep)`` of a stable system (``inf`` if unstable): the
    sweep is a lower bound of the norm, a second route beside ``hinfnorm``."""
    gamma = float(hinfnorm(sys)[0])
    if not np.isfinite(gamma) or sys.nstates == 0:
        return gamma
    p = np.linalg.eigvals(np.asarray(sys.A, dtype=float))
    mags = np.abs(p[np.abs(p) > 0])
    lo, hi = ((np.log10(mags.min()) - 3.0, np.log10(mags.max()) + 3.0) if mags.size
              else (-3.0, 3.0))
    w = np.concatenate([[0.0, np.inf], np.abs(p.imag), mags,
                        np.logspace(lo, hi, int((hi - lo) * _SWEEP_PER_DECADE) + 1)])
    return max(gamma, float(np.max(sigma_max(sys, w))))


def _positive(value, label: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or \
            not (np.isfinite(value) and value > 0):
        raise ParameterError(f"{label} must be positive and finite, got {value!r}")
    return float(value)


# ------------------------------------------------------------------------------ H∞ bound
@dataclass(frozen=True)
class HinfBound:
    """``‖W_L T_zw W_R‖∞ ≤ bound`` on a channel of the closed loop (MATLAB's
    ``TuningGoal.WeightedGain``).

    Attributes
    ----------
    inputs, outputs : int, str, sequence of them, or None
        The channel's disturbances ``w`` and errors ``z``: 0-based indices among the
        plant's ``w`` and ``z`` or the plant's signal names; ``None`` for all.
    bound : float
        The bound γ; the value is ``‖W_L T W_R‖∞ / γ``.
    wl, wr : LTI system or matrix, optional
        Stable weights on the channel's outputs (left) and inputs (right); a SISO
        weight applies to each signal.
    name : str

    Raises
    ------
    ParameterError
        A bound that is not positive, an unstable weight.
    DimensionError
        (at :meth:`bind`) a channel the plant does not have, a weight of another size.

    Examples
    --------
    >>> import control
    >>> from lmi_suspension.lti import GeneralizedPlant
    >>> P = GeneralizedPlant.from_statespace(control.ss(
    ...     [[-1.0]], [[1.0, 1.0]], [[1.0], [1.0]], [[0.0, 0.0], [0.0, 0.0]]), 1, 1)
    >>> HinfBound(outputs=3).bind(P)
    Traceback (most recent call last):
    ...
    lmi_suspension.errors.DimensionError: H∞ bound: output 3 out of range: the plant has 1 outputs (0-based)
    """

    inputs: object = None
    outputs: object = None
    bound: float = 1.0
    wl: object = None
    wr: object = None
    name: str = "H∞ bound"

    def __post_init__(self):
        _positive(self.bound, f"{self.name}: bound")

    def bind(self, plant: GeneralizedPlant) -> HinfBound:
        labels_w = list(plant.sys.input_labels[:plant.nw])
        labels_z = list(plant.sys.output_labels[:plant.nz])
        cols = _selection(self.inputs, labels_w, "input", self.name)
        rows = _selection(self.outputs, labels_z, "output", self.name)
        bound = replace(self, inputs=cols, outputs=rows)
        object.__setattr__(bound, "_wl", _weight(self.wl, len(rows), "left", self.name))
        object.__setattr__(bound, "_wr", _weight(self.wr, len(cols), "right", self.name))
        return bound

    def _bound_or_raise(self):
        if not hasattr(self, "_wl"):
            raise ParameterError(f"{self.name}: bind the requirement to a plant first")

    def _channel(self, A, B, C, D) -> control.StateSpace:
        rows, cols = list(self.outputs), list(self.inputs)
        sys = control.ss(A, B[:, cols], C[rows], D[np.ix_(rows, cols)])
        if self._wl is not None:
            sys = self._wl * sys
        if self._wr is not None:
            sys = sys * self._wr
        return sys

    def value(self, loop: ClosedLoop) -> tuple:
        """``(‖W_L T W_R‖∞ / γ, its subgradient)`` from the peak frequency."""
        self._bound_or_raise()
        if not loop.stable:
            return np.inf, None
        sys = self._channel(loop.A, loop.B, loop.C, loop.D)
        gamma, omega = hinfnorm(sys)
        if not np.isfinite(gamma):
            return np.inf, None
        gamma, omega = _feedthrough_check(sys, float(gamma), float(omega))
        T = loop.response(omega)[np.ix_(self.outputs, self.inputs)]
        WL, WR = _response(self._wl, omega), _response(self._wr, omega)
        Tw = (WL @ T if WL is not None else T)
        Tw = Tw @ WR if WR is not None else Tw
        U, _, Vh = np.linalg.svd(Tw)
        u, v = U[:, 0], Vh[0].conj()
        a_sub = WL.conj().T @ u if WL is not None else u
        b_sub = WR @ v if WR is not None else v
        a, b = np.zeros(loop.nz, complex), np.zeros(loop.nw, complex)
        a[list(self.outputs)], b[list(self.inputs)] = a_sub, b_sub
        return gamma / self.bound, loop.gain_gradient(omega, a, b) / self.bound

    def certify(self, CL: control.StateSpace, plant=None, K=None) -> float:
        """``max(hinfnorm, dense σ̄ sweep) / γ`` of the channel of ``CL = lft(P, K)``."""
        self._bound_or_raise()
        A, B, C, D = (np.asarray(M, dtype=float) for M in (CL.A, CL.B, CL.C, CL.D))
        return _swept_norm(self._channel(A, B, C, D)) / self.bound


# ------------------------------------------------------------------------------ poles
@dataclass(frozen=True)
class PoleRegion:
    """Closed-loop poles with decay ``-Re p ≥ min_decay``, damping ``-Re p / |p| ≥
    min_damping`` and ``|p| ≤ max_frequency`` (MATLAB's ``TuningGoal.Poles``).

    The value is ``1 + max_p max_k g_k(p) / scale`` over the poles ``p`` and the region's
    conditions ``g_k(p) ≤ 0``: ``g₁ = Re p + min_decay``, ``g₂ = Re p + min_damping |p|``
    and ``g₃ = |p| - max_frequency``; so ``≤ 1`` exactly when every pole is in the
    region.  ``scale`` (rad/s) only sets how a violation trades against other
    requirements in a soft objective.  The certificate recomputes the value from
    ``numpy.linalg.eigvals`` of ``lft(P, K)``.

    Raises
    ------
    ParameterError
        A negative decay, a damping outside ``[0, 1)``, a non-positive maximum frequency
        or scale.

    Examples
    --------
    >>> import control
    >>> from lmi_suspension.tune import ClosedLoop, tunable_gain
    >>> P = control.ss([[-1.0]], [[1.0, 1.0]], [[1.0], [1.0]], [[0.0, 0.0], [0.0, 0.0]])
    >>> loop = ClosedLoop.from_blocks(P, tunable_gain("K", 1, 1), [-2.0])   # pole at -3
    >>> float(PoleRegion(max_frequency=2.0).value(loop)[0])                # 1 + (3 - 2)/1
    2.0
    >>> float(PoleRegion(min_decay=1.0).value(loop)[0])                    # 1 + (-3 + 1)/1
    -1.0
    """

    min_decay: float = 0.0
    min_damping: float = 0.0
    max_frequency: float = np.inf
    scale: float = 1.0
    name: str = "poles"

    def __post_init__(self):
        ok = (isinstance(self.min_decay, numbers.Real) and np.isfinite(self.min_decay)
              and self.min_decay >= 0)
        if not ok:
            raise ParameterError(f"{self.name}: min_decay must be >= 0, got "
                                 f"{self.min_decay!r}")
        if not (isinstance(self.min_damping, numbers.Real) and 0 <= self.min_damping < 1):
            raise ParameterError(f"{self.name}: min_damping must be in [0, 1), got "
                                 f"{self.min_damping!r}")
        if not (isinstance(self.max_frequency, numbers.Real) and self.max_frequency > 0):
            raise ParameterError(f"{self.name}: max_frequency must be positive, got "
                                 f"{self.max_frequency!r}")
        _positive(self.scale, f"{self.name}: scale")

    def bind(self, plant: GeneralizedPlant) -> PoleRegion:
        return self

    def _terms(self, p):
        """``g`` (poles × conditions) and which conditions apply."""
        r = np.abs(p)
        g = np.stack([p.real + self.min_decay, p.real + self.min_damping * r,
                      r - (self.max_frequency if np.isfinite(self.max_frequency) else 0.0)],
                     axis=-1)
        if not np.isfinite(self.max_frequency):
            g[:, 2] = -np.inf
        return g

    def value(self, loop: ClosedLoop) -> tuple:
        p = loop.poles
        if p.size == 0:
            return 0.0, np.zeros(loop.n_params)
        g = self._terms(p)
        k, c = np.unravel_index(int(np.argmax(g)), g.shape)
        dl = loop.pole_gradient(int(k))
        lam = p[k]
        dr = (np.conj(lam) * dl).real / abs(lam) if abs(lam) > 0 else np.zeros(dl.size)
        grad = (dl.real, dl.real + self.min_damping * dr, dr)[c]
        return 1.0 + float(g[k, c]) / self.scale, grad / self.scale

    def certify(self, CL: control.StateSpace, plant=None, K=None) -> float:
        p = np.linalg.eigvals(np.asarray(CL.A, dtype=float))
        return 1.0 + float(np.max(self._terms(p))) / self.scale if p.size else 0.0


# ------------------------------------------------------------------------------ margins
@dataclass(frozen=True)
class Margins:
    """Gain and phase margins at the plant's controls, loop at a time, by disk margins
    (MATLAB's ``TuningGoal.Margins``, there with D-scalings across loops).

    With ``S = (I - K P22)⁻¹`` the input sensitivity and ``L_i`` the loop broken at
    control ``i`` with the others closed, ``S_ii = 1/(1 + L_i)`` and the symmetric disk
    margin of loop ``i`` is ``α_i = 1 / ‖S_ii - 1/2‖∞`` (Seiler, Packard & Gahinet, "An
    introduction to disk margins", IEEE Control Systems Magazine 40(5), 2020, skew 0):
    every gain in ``[(1 - α/2)/(1 + α/2), (1 + α/2)/(1 - α/2)]`` and every phase within
    ``±2 atan(α/2)``, and each with the other, keeps the loop stable.  The requirement
    asks for ``α_i ≥ α = max(2 (g - 1)/(g + 1), 2 tan(φ/2))``, ``g`` the gain margin as
    a ratio and ``φ`` the phase margin; the value is ``α max_i ‖S_ii - 1/2‖∞``.  The
    classical margins are then at least the asked ones (the disk is inside the set of
    perturbations they allow).

    Attributes
    ----------
    gain_margin : float
        Gain margin in dB (> 0).
    phase_margin : float
        Phase margin in degrees (in (0, 90)).
    loops : int, str, sequence of them, or None
        The controls (0-based among the plant's ``u``, or their names); ``None`` for all.
    name : str

    Examples
    --------
    ``u = -y`` on ``1/(s + 1)``: ``S = (s + 1)/(s + 2)``, ``S - 1/2 = s/(2 (s + 2))``
    peaks at 1/2 (ω → ∞), a disk margin of 2; 6 dB and 45° ask for
    ``α = 2 tan(22.5°) = 0.8284``:

    >>> import control
    >>> from lmi_suspension.tune import ClosedLoop, tunable_gain
    >>> P = control.ss([[-1.0]], [[1.0, 1.0]], [[1.0], [1.0]], [[0.0, 0.0], [0.0, 0.0]])
    >>> loop = ClosedLoop.from_blocks(P, tunable_gain("K", 1, 1), [-1.0])
    >>> req = Margins(6.0, 45.0).bind(loop.plant)
    >>> round(req.alpha, 4), round(float(req.value(loop)[0]), 4)
    (0.8284, 0.4142)
    """

    gain_margin: float = 6.0
    phase_margin: float = 45.0
    loops: object = None
    name: str = "margins"

    def __post_init__(self):
        _positive(self.gain_margin, f"{self.name}: gain_margin (dB)")
        pm = _positive(self.phase_margin, f"{self.name}: phase_margin (degrees)")
        if pm >= 90:
            raise ParameterError(f"{self.name}: phase_margin must be below 90 degrees for a "
                                 f"disk margin, got {pm!r}")

    @property
    def alpha(self) -> float:
        """The disk size the margins ask for."""
        g = 10.0 ** (self.gain_margin / 20.0)
        return float(max(2.0 * (g - 1.0) / (g + 1.0),
                         2.0 * np.tan(np.radians(self.phase_margin) / 2)))

    def bind(self, plant: GeneralizedPlant) -> Margins:
        labels = list(plant.sys.input_labels[plant.nw:])
        return replace(self, loops=_selection(self.loops, labels, "control", self.name))

    def _loops(self, nu):
        return range(nu) if self.loops is None else self.loops

    def value(self, loop: ClosedLoop) -> tuple:
        if not loop.stable:
            return np.inf, None
        S = loop.input_sensitivity
        best = (-np.inf, None, None)
        for i in self._loops(loop.nu):
            Sii = control.ss(S.A, S.B[:, i:i + 1], S.C[i:i + 1], S.D[i:i + 1, i:i + 1] - 0.5)
            gamma, omega = hinfnorm(Sii)
            gamma, omega = _feedthrough_check(Sii, float(gamma), float(omega))
            if gamma > best[0]:
                best = (gamma, omega, i)
        gamma, omega, i = best
        if not np.isfinite(gamma):
            return np.inf, None
        h = complex(loop._at(omega, S.B[:, i:i + 1], S.C[i:i + 1],
                             np.asarray(S.D[i:i + 1, i:i + 1]) - 0.5)[0, 0])
        a, b = np.zeros(loop.nu, complex), np.zeros(loop.nu, complex)
        a[i], b[i] = h / abs(h) if abs(h) > 0 else 1.0, 1.0
        return self.alpha * gamma, self.alpha * loop.sensitivity_gradient(omega, a, b)

    def certify(self, CL: control.StateSpace, plant: GeneralizedPlant, K) -> float:
        """From ``S = (I - K P22)⁻¹`` built by ``control.feedback`` from the plant's
        ``P22`` and ``K`` (not from the closed loop the optimiser used), its diagonal
        entries' norms by ``hinfnorm`` and a dense sweep."""
        K = as_statespace(K, "K")
        P22 = control.ss(plant.A, plant.B2, plant.C2, plant.D22)
        try:
            S = control.feedback(control.ss([], [], [], np.eye(plant.nu)), K * P22, sign=1)
        except (ValueError, np.linalg.LinAlgError) as exc:
            raise IllPosedLoopError(f"{self.name}: the loop at the controls is ill-posed: "
                                    f"{exc}") from exc
        worst = 0.0
        for i in self._loops(plant.nu):
            Sii = control.ss(S.A, S.B[:, i:i + 1], S.C[i:i + 1], S.D[i:i + 1, i:i + 1] - 0.5)
            worst = max(worst, _swept_norm(Sii))
        return self.alpha * worst
