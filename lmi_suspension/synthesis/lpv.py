"""Gridded gain-scheduled H∞ output-feedback synthesis (:func:`lpvsyn`), for parameters
frozen during operation (rate bound ν = 0) or varying at bounded rates ``|ṗ_k| <= ν_k``.

The plant ``P(p)`` is given on a grid of a measured parameter vector ``p`` (a callable
``p -> StateSpace``, or a list of ``(p, plant)`` pairs whose matrices are interpolated
linearly between grid points, as LPVTools does for gridded systems).  The Lyapunov
matrices of the projected (controller-eliminated) H∞ LMIs of Gahinet & Apkarian (1994)
are made parameter dependent, ``X(p) = Σ f_i(p) X_i`` and ``Y(p) = Σ f_i(p) Y_i`` with
user basis functions ``f`` (default ``[1, p_1, ..., p_k]``), and at every grid point ``p_g``::

    W_R(p_g)ᵀ BRL_R(A, B1, C1, D11 at p_g; X(p_g), γ) W_R(p_g) < 0
    W_S(p_g)ᵀ BRL_S(A, B1, C1, D11 at p_g; Y(p_g), γ) W_S(p_g) < 0
    [[X(p_g), I], [I, Y(p_g)]] >= 0,   trace X(p_g) + trace Y(p_g) <= xy_bound n

with ``W_R``, ``W_S`` the null-space bases of ``[B2ᵀ D12ᵀ]`` and ``[C2 D21]`` *at that
point* (so ``B2``, ``C2``, ``D12``, ``D21`` may depend on ``p``, unlike the polytopic
route); γ is minimised (one SDP, Clarabel through CVXPY, the building blocks and
settings of :mod:`.lmi`).  With ν = 0 the Lyapunov inequalities carry no ``∂X/∂p ṗ``
term (Wu et al. 1996, Apkarian & Adams 1998 with a zero rate bound): the controller is
guaranteed **for frozen parameters** — for each constant ``p`` the loop is stable with
``‖F_l(P(p), K(p))‖∞`` below the level — and nothing is claimed for a ``p`` that moves
during operation.

With a rate bound ν > 0 (Wu et al. 1996; Apkarian & Adams 1998) the ``X`` inequality
carries ``-Ẋ = -Σ_k ṗ_k ∂X/∂p_k`` (the ``Y`` one ``+Ẏ``) in its state block, imposed at
every vertex ``ṗ_k = ±ν_k`` of the rate box at every grid point.  With both matrices
parameter dependent the controller would need ``ṗ`` (LPVTools' ``lpvsyn`` returns such
a controller); here one of them is constant (``rate_form``: ``"X"`` makes ``X(p)``
dependent and ``Y`` constant, ``"Y"`` the converse, ``"auto"`` solves both and keeps
the lower γ), so that with controller coordinates fixed over the range the derivative
term in the controller's ``Â`` block vanishes and ``K(p)`` depends on ``p`` only
(Apkarian & Adams 1998, §3).  The price is measured in ``tests/test_lpv.py``: on its
mass-spring-damper the ``ṗ``-free forms reach γ_lmi 0.477, about what a constant pair
reaches (0.4775), against 0.312 for frozen parameters with the same basis.  The
closed loop then satisfies the bounded-real inequality with ``Ṗ`` at every vertex for
the Lyapunov matrix :meth:`ScheduledController.closed_loop_lyapunov`: its induced
L2 gain is below the level for every trajectory ``p(t)`` in the range with
``|ṗ_k| <= ν_k`` — where the inequalities hold, which is checked on the dense grid.

The scheduled controller is formed at any ``p`` (between grid points too) from
``X(p)``, ``Y(p)`` and ``P(p)`` by the project's explicit formulas
(:func:`~lmi_suspension.synthesis.lmi.decoupled_controller`, Gahinet 1996) at the level
``(1 + backoff) γ_lmi`` with ``(X, Y)`` scaled by ``sqrt(1 + backoff)``, as
:func:`~lmi_suspension.synthesis.hinfsyn` does on one plant; every frozen loop on a grid
at least 4 times denser than the design grid is certified by ``hinfnorm``.

References
----------
P. Gahinet, P. Apkarian, "A linear matrix inequality approach to H∞ control", Int. J.
Robust Nonlinear Control 4 (1994) 421-448.
F. Wu, X. H. Yang, A. Packard, G. Becker, "Induced L2-norm control for LPV systems with
bounded parameter variation rates", Int. J. Robust Nonlinear Control 6 (1996) 983-998.
P. Apkarian, R. J. Adams, "Advanced gain-scheduling techniques for uncertain systems",
IEEE Trans. Control Systems Technology 6(1) (1998) 21-32.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field
from typing import Callable

import logging

import control
import cvxpy as cp
import numpy as np

from ..errors import (DimensionError, InfeasibleError, InputError, NonFiniteError,
                      NyquistError, ParameterError, SolverError)
from ..lti.checks import as_statespace, finite_scalar
from ..lti.gridded import parameter_values
from ..lti.norms import hinfnorm
from ..lti.plant import GeneralizedPlant, lft
from ..lti.scaling import PlantScaling, scale_plant
from . import lmi as _lmi
from .hinfsyn import _undo_loop_shift, _without_d22
from .result import HinfsynOptions

__all__ = ["lpvsyn", "LpvsynResult", "ScheduledController"]

logger = logging.getLogger(__name__)

#: default back-off of the reconstruction level above the LMI optimum (relative).  The
#: explicit formulas at ``(1 + r) γ_lmi`` with ``(X, Y)`` scaled by ``sqrt(1 + r)`` have
#: poles that grow like ``1/r``: on the mass-spring-damper of tests/test_lpv.py (m in
#: [1, 4], 9 grid points, 33 check points; basis [1, m] | [1, m, 1/m]) the certified γ
#: over γ_lmi and the controllers' fastest pole were, for r = 5e-4: 0.979 | 0.999 and
#: 2.1e4 | 9.0e3 rad/s; 1e-2: 0.983 | 0.9995, 884 | 1.3e4; 2e-2: 0.988 | 1.005,
#: 399 | 897; 5e-2: 1.003 | 1.021, 138 | 122; 0.15: 1.049 | 1.068, 42 | 34 (plant modes
#: 0.5-1 rad/s; measured 2026-12-02).  2 % keeps every pole below 1e3 rad/s (a 1 kHz
#: realization's Nyquist frequency is 3.1e3) for at most 0.5 % of γ; LPVTools' default
#: accepts up to 15 % for the same purpose
BACKOFF = 2e-2
#: levels, relative to the reconstruction level, tried in turn where the projected
#: inequalities fail at a parameter value between grid points (they are only imposed on
#: the grid): a larger level only adds a negative term to them
_ESCALATION = (1.0, 1.005, 1.01, 1.02, 1.05, 1.1, 1.2, 1.5, 2.0, 4.0)
#: relative slack the coupling ``min eig(c² X(p) Y(p)) > 1`` must have before a
#: controller is formed (below it ``I - XY`` is numerically singular)
_COUPLING_RTOL = 1e-9
#: relative excess of a certified frozen norm over ``(1 + backoff) γ_lmi`` reported in
#: ``warnings`` (roundoff of hinfnorm, whose own tolerance is 1e-9)
_CERT_RTOL = 1e-6


# --------------------------------------------------------------------------- input


def _axes(grid) -> tuple[tuple[str, ...], tuple[np.ndarray, ...]]:
    """Names and sorted, distinct, finite values of each parameter of a grid dict."""
    if not isinstance(grid, dict) or not grid:
        raise ParameterError("grid must be a non-empty dict {name: values}")
    names, axes = [], []
    for name, values in grid.items():
        if not isinstance(name, str) or not name.isidentifier():
            raise ParameterError(f"parameter names must be identifiers, got {name!r}")
        try:
            v = np.asarray(values, dtype=float).ravel()
        except (TypeError, ValueError) as exc:
            raise InputError(f"grid[{name!r}] must be numeric: {exc}") from exc
        if v.size == 0:
            raise ParameterError(f"grid[{name!r}] is empty")
        if not np.all(np.isfinite(v)):
            raise NonFiniteError(f"grid[{name!r}] holds NaN or infinite values")
        v = np.unique(v)
        names.append(name)
        axes.append(v)
    return tuple(names), tuple(axes)


class _GridTable:
    """An array-valued function known on a rectangular grid: the stored values exactly
    at the nodes, their multilinear interpolation in between (axes with one value take
    no part in it; scipy needs two)."""

    def __init__(self, axes, nodes: dict):
        import scipy.interpolate

        self.axes = tuple(np.asarray(a, dtype=float) for a in axes)
        self.nodes = {tuple(float(v) for v in k): np.asarray(m, dtype=float)
                      for k, m in nodes.items()}
        first = next(iter(self.nodes.values()))
        self._live = [i for i, a in enumerate(self.axes) if a.size > 1]
        data = np.empty(tuple(a.size for a in self.axes) + first.shape)
        for idx in itertools.product(*(range(a.size) for a in self.axes)):
            data[idx] = self.nodes[tuple(float(a[i]) for a, i in zip(self.axes, idx))]
        data = data.reshape(tuple(self.axes[i].size for i in self._live) + first.shape)
        self._data = data
        self._interp = None if not self._live else scipy.interpolate.RegularGridInterpolator(
            tuple(self.axes[i] for i in self._live), data, method="linear")

    def __call__(self, p) -> np.ndarray:
        # at a node the stored value itself, so a table of a function reproduces it
        # there bit for bit (the interpolation's weights 1 and 0 need not)
        hit = self.nodes.get(tuple(float(v) for v in p))
        if hit is not None:
            return hit.copy()
        if self._interp is None:
            return self._data.copy()
        return self._interp(np.asarray([p[i] for i in self._live], dtype=float)[None, :])[0]


class _TablePlant:
    """A plant known on a rectangular grid, its state-space matrices interpolated
    (multi)linearly in between (LPVTools' convention for gridded systems)."""

    def __init__(self, axes, table: dict, shape):
        self.shape = tuple(shape)
        self.table = _GridTable(axes, {p: np.block([[sys.A, sys.B], [sys.C, sys.D]])
                                       for p, sys in table.items()})

    @classmethod
    def from_blocks(cls, axes, blocks: dict, shape) -> _TablePlant:
        """From ``{p: [[A, B], [C, D]]}`` (a saved table)."""
        self = cls.__new__(cls)
        self.shape = tuple(shape)
        self.table = _GridTable(axes, blocks)
        return self

    def __call__(self, *p):
        n = self.shape[0]
        M = self.table(p)
        return control.ss(M[:n, :n], M[:n, n:], M[n:, :n], M[n:, n:])


class _AffineBasis:
    """The default basis ``[1]`` and each parameter that takes more than one grid value
    (a class, not a closure, so a saved controller can name it)."""

    def __init__(self, live):
        self.live = tuple(int(i) for i in live)

    def __call__(self, *p):
        return [1.0] + [p[i] for i in self.live]

    def jacobian(self, *p) -> np.ndarray:
        """``∂f_i/∂p_k`` (exact)."""
        J = np.zeros((1 + len(self.live), len(p)))
        for r, i in enumerate(self.live):
            J[1 + r, i] = 1.0
        return J


class _TableBasis:
    """A basis known on a grid (a loaded controller's), interpolated in between, with
    its Jacobian where the saved controller is rate bounded."""

    def __init__(self, table: _GridTable, jac: _GridTable | None = None):
        self.table = table
        self.jac = jac

    def __call__(self, *p):
        return self.table(p)

    def jacobian(self, *p) -> np.ndarray:
        if self.jac is None:
            raise InputError("this saved basis has no Jacobian (saved without a rate bound)")
        return self.jac(p)


def _from_pairs(pairs, grid):
    """``(plant callable, names, axes)`` from a list of ``(p, plant)``."""
    pairs = list(pairs)
    if not pairs:
        raise ParameterError("the list of (p, plant) pairs is empty")
    if grid is None:
        names = None
    elif isinstance(grid, str):
        names = (grid,)
    elif isinstance(grid, dict):
        names = tuple(grid)
    else:
        names = tuple(grid)
    table, shape = {}, None
    for k, pair in enumerate(pairs):
        try:
            p, sys = pair
        except (TypeError, ValueError) as exc:
            raise InputError(f"entry {k} of the plant list is not a pair (p, plant)") from exc
        if isinstance(p, dict):
            if names is None:
                names = tuple(p)
            p = [p[nm] for nm in names]
        p = tuple(finite_scalar(v, f"parameter value of entry {k}")
                  for v in np.atleast_1d(np.asarray(p, dtype=object)))
        sys = as_statespace(sys, f"plant {k}")
        s = (sys.nstates, sys.ninputs, sys.noutputs)
        if shape is not None and s != shape:
            raise DimensionError(f"plant {k} has (states, inputs, outputs) = {s}, the first "
                                 f"one {shape}")
        shape = s
        if p in table:
            raise ParameterError(f"the parameter value {p} appears twice in the plant list")
        table[p] = sys
    if names is None:
        names = ("p",) if len(next(iter(table))) == 1 else \
            tuple(f"p{i + 1}" for i in range(len(next(iter(table)))))
    if any(len(p) != len(names) for p in table):
        raise DimensionError(f"every parameter value needs {len(names)} entries {names}")
    axes = tuple(np.unique([p[i] for p in table]) for i in range(len(names)))
    if len(table) != int(np.prod([a.size for a in axes])):
        raise ParameterError("the plants' parameter values do not form a rectangular grid "
                             f"({len(table)} values, axes of sizes {[a.size for a in axes]})")
    return _TablePlant(axes, table, shape), names, axes


def _default_basis(axes):
    """``[1]`` and each parameter that takes more than one value on the grid."""
    return _AffineBasis(i for i, a in enumerate(axes) if a.size > 1)


def _basis_values(basis, p, nb: int | None) -> np.ndarray:
    try:
        f = np.asarray(basis(*p), dtype=float).ravel()
    except (TypeError, ValueError) as exc:
        raise InputError(f"the basis at p = {p} did not return numbers: {exc}") from exc
    if nb is not None and f.size != nb:
        raise DimensionError(f"the basis returned {f.size} values at p = {p}, {nb} at the "
                             "first grid point")
    if f.size == 0:
        raise DimensionError("the basis returned no values")
    if not np.all(np.isfinite(f)):
        raise NonFiniteError(f"the basis is not finite at p = {p}: {f}")
    return f


#: complex step of the basis derivative (relative to max(1, |p_k|)): exact to roundoff
#: for any basis written with arithmetic and numpy functions (Squire & Trapp 1998)
_COMPLEX_STEP = 1e-30
#: central-difference step (relative) where the basis does not take complex values, and
#: the tolerance within which the complex step must agree with it
_FD_STEP = 1e-6
_FD_RTOL = 1e-5


def _basis_jacobian(basis, p, nb: int) -> np.ndarray:
    """``J[i, k] = ∂f_i/∂p_k`` at ``p``: the basis's own ``jacobian`` where it has one,
    else by complex step, checked against central differences (used alone where the
    callable refuses complex numbers)."""
    if hasattr(basis, "jacobian"):
        return np.asarray(basis.jacobian(*p), dtype=float).reshape(nb, len(p))
    J = np.empty((nb, len(p)))
    for k in range(len(p)):
        h = _FD_STEP * max(1.0, abs(p[k]))
        hi = tuple(v + (h if i == k else 0.0) for i, v in enumerate(p))
        lo = tuple(v - (h if i == k else 0.0) for i, v in enumerate(p))
        fd = (_basis_values(basis, hi, nb) - _basis_values(basis, lo, nb)) / (2 * h)
        try:
            hc = _COMPLEX_STEP * max(1.0, abs(p[k]))
            pc = tuple(complex(v, hc if i == k else 0.0) for i, v in enumerate(p))
            cs = np.asarray(basis(*pc), dtype=complex).ravel().imag / hc
        except (TypeError, ValueError):
            cs = None
        if cs is not None and cs.size == nb and np.all(np.isfinite(cs)) and np.allclose(
                cs, fd, rtol=_FD_RTOL, atol=_FD_RTOL * max(1.0, np.abs(fd).max())):
            J[:, k] = cs
        else:
            logger.info("basis derivative by central differences at p = %s", p)
            J[:, k] = fd
    if not np.all(np.isfinite(J)):
        raise NonFiniteError(f"the basis derivative is not finite at p = {p}")
    return J


def _vertices(nus) -> list[np.ndarray]:
    """The corners of the rate box ``|ṗ_k| <= ν_k`` (parameters with ν_k = 0 fixed at 0)."""
    live = [k for k, nu in enumerate(nus) if nu > 0]
    out = []
    for signs in itertools.product((-1.0, 1.0), repeat=len(live)):
        v = np.zeros(len(nus))
        for k, sg in zip(live, signs):
            v[k] = sg * nus[k]
        out.append(v)
    return out


def _plant_at(plant, p, nmeas, ncon, shape=None) -> GeneralizedPlant:
    sys = as_statespace(plant(*p), f"P{p}")
    s = (sys.nstates, sys.ninputs, sys.noutputs)
    if shape is not None and s != shape:
        raise DimensionError(f"P{p} has (states, inputs, outputs) = {s}, the plant at the "
                             f"first grid point {shape}")
    return GeneralizedPlant.from_statespace(sys, nmeas, ncon)


def _apply_scaling(G: GeneralizedPlant, sc: PlantScaling) -> GeneralizedPlant:
    """``G`` (``D22 = 0``) under the scalings ``sc`` that :func:`scale_plant` chose for
    another plant of the family: one set of coordinates for the whole grid, since
    ``X_i``, ``Y_i`` are shared by every grid point."""
    b = G.blocks()
    T, Ti = sc.T, 1.0 / sc.T
    Su, Sy, cw, cz = sc.Su, sc.Sy, sc.cw, sc.cz
    return GeneralizedPlant.from_matrices(
        Ti[:, None] * b["A"] * T[None, :], Ti[:, None] * b["B1"] * cw,
        Ti[:, None] * b["B2"] * Su[None, :], b["C1"] * T[None, :] / cz,
        Sy[:, None] * b["C2"] * T[None, :], b["D11"] * (cw / cz), b["D12"] * Su[None, :] / cz,
        Sy[:, None] * b["D21"] * cw, np.zeros_like(b["D22"]))


def _floats(M):
    """A numpy array as nested lists of Python floats (json writes them exactly)."""
    return np.asarray(M, dtype=float).tolist()


# --------------------------------------------------------------------------- controller
@dataclass(frozen=True)
class ScheduledController:
    """A controller scheduled on a measured parameter (frozen or rate-bounded design).

    ``K.at(m3=42.0)`` (or ``K.at(42.0)`` for one parameter) is the controller at that
    value: the explicit formulas of
    :func:`~lmi_suspension.synthesis.lmi.decoupled_controller` on ``P(p)`` with
    ``X(p) = Σ f_i(p) X_i`` and ``Y(p) = Σ f_i(p) Y_i``.

    Attributes
    ----------
    names : tuple of str
        The scheduling parameters, in the order the plant and basis callables take them.
    bounds : tuple of (float, float)
        Each parameter's design interval; ``at`` outside it is a :class:`ParameterError`.
    basis : callable
        ``f(*p) -> sequence of float``.
    X, Y : tuple of numpy.ndarray
        ``X_i``, ``Y_i``: the ``R`` and ``S`` of the projected LMIs of :mod:`.lmi`, in the
        coordinates of the scaled plant (``scaling``, shared by the whole grid).
    gamma_lmi_scaled : float
        The LMI optimum in scaled units.
    backoff : float
        The reconstruction level is ``(1 + backoff) γ_lmi``.
    scaling : PlantScaling
        Scalings of states, controls, measurements and errors common to the grid.
    plant : callable
        ``P(*p) -> StateSpace`` (the caller's, or the interpolated table).
    nmeas, ncon : int
    shape : tuple of int
        ``(states, inputs, outputs)`` of the plant.
    grid : dict
        The design grid ``{name: values}`` (the default table of :meth:`to_dict`).
    rate : tuple of float
        ``ν_k``, the bound on ``|dp_k/dt|`` the design holds for (0: frozen).
    rate_form : {"X", "Y"}
        With some ``ν_k > 0``: which Lyapunov matrix depends on ``p`` (and carries the
        rate terms); the other one is constant, held as a 1-tuple.
    frame : numpy.ndarray
        With a rate bound: the state coordinates, fixed over the range, in which the
        controller is formed (a frame that moved with ``p`` would put its derivative in
        the controller).
    """

    names: tuple
    bounds: tuple
    basis: Callable
    X: tuple
    Y: tuple
    gamma_lmi_scaled: float
    backoff: float
    scaling: PlantScaling
    plant: Callable
    nmeas: int
    ncon: int
    shape: tuple = field(repr=False, default=None)
    grid: dict = field(repr=False, default=None)
    rate: tuple = None
    frame: np.ndarray = field(repr=False, default=None)
    rate_form: str = None

    @property
    def rate_bounded(self) -> bool:
        """Designed for parameters that vary at bounded rates (some ν_k > 0)."""
        return self.rate is not None and any(nu > 0 for nu in self.rate)

    def values(self, *args, **named) -> tuple:
        """The parameter values as a tuple in the order of ``names`` (checked)."""
        return parameter_values(self.names, self.bounds, args, named, "the design interval")

    def lyapunov(self, *args, **named) -> tuple[np.ndarray, np.ndarray]:
        """``(X(p), Y(p))`` of the scaled plant."""
        p = self.values(*args, **named)
        rated = self.rate_bounded
        nb = len(self.Y) if rated and self.rate_form == "Y" else len(self.X)
        f = _basis_values(self.basis, p, nb)
        # with a rate bound one of them is constant (a 1-tuple, whatever the basis)
        X = self.X[0] if rated and self.rate_form == "Y" else sum(
            fi * Xi for fi, Xi in zip(f, self.X))
        Y = self.Y[0] if rated and self.rate_form == "X" else sum(
            fi * Yi for fi, Yi in zip(f, self.Y))
        return X, Y

    def lyapunov_rate(self, *args, **named) -> list[np.ndarray]:
        """``Σ_k ṗ_k ∂V/∂p_k`` of the parameter-dependent one ``V`` of ``X``, ``Y``
        (``rate_form``) at each vertex of the rate box (scaled plant); ``[0]`` for a
        frozen-parameter design."""
        p = self.values(*args, **named)
        if not self.rate_bounded:
            return [np.zeros_like(self.X[0])]
        Vs = self.X if self.rate_form == "X" else self.Y
        J = _basis_jacobian(self.basis, p, len(Vs))
        dX = [sum(J[i, k] * Vi for i, Vi in enumerate(Vs)) for k in range(len(p))]
        return [sum((v[k] * dX[k] for k in range(len(p)) if v[k]), np.zeros_like(self.X[0]))
                for v in _vertices(self.rate)]

    def inequalities(self, *args, level: float, **named) -> float:
        """The largest eigenvalue, relative to the level, of the projected inequalities
        and the coupling re-evaluated at ``p`` with ``X(p)``, ``Y(p)`` (and ``-Ẋ`` at
        every vertex of the rate box) as the controller at ``level`` (plant units) is
        formed from them: negative where they hold (certificate 4(b) of issue 61)."""
        p = self.values(*args, **named)
        X, Y = self.lyapunov(*p)
        g = float(level) * self.scaling.gamma_factor
        G = _plant_at(self.plant, p, self.nmeas, self.ncon, self.shape)
        Ps = _apply_scaling(_without_d22(G), self.scaling)
        return self._top(_lmi._projections(Ps, Ps, sparse=False), X, Y,
                         self.lyapunov_rate(*p), g)

    def _top(self, projections, X, Y, rates, g: float) -> float:
        """:meth:`inequalities` at the scaled level ``g`` for given matrices."""
        c = float(np.sqrt(g / self.gamma_lmi_scaled))
        worst = []
        # the X inequality carries -Ẋ, the Y one +Ẏ (one of them constant)
        zero = [np.zeros_like(Y)]
        x_rates = [-D for D in rates] if self.rate_form == "X" else zero
        y_rates = rates if self.rate_form == "Y" else zero
        for proj, V, dVs in zip(projections, (c * X, c * Y), (x_rates, y_rates)):
            if proj is None:
                continue
            E = proj.F @ V @ proj.Nx
            for dV in dVs:
                top = E + E.T - g * proj.Q + c * (proj.Nx.T @ dV @ proj.Nx)
                L = np.block([[top, proj.H], [proj.H.T, -g * np.eye(proj.H.shape[1])]])
                worst.append(float(np.linalg.eigvalsh(_lmi._sym(L))[-1]))
        n = X.shape[0]
        cpl = np.block([[c * X, np.eye(n)], [np.eye(n), c * Y]])
        worst.append(-float(np.linalg.eigvalsh(_lmi._sym(cpl))[0]))
        return max(worst) / g

    def closed_loop_lyapunov(self, *args, level: float, **named) -> np.ndarray:
        """The closed loop's Lyapunov matrix ``P(p)`` that the controller formed at
        ``level`` (plant units) is built on, in the coordinates ``[x_s; x_K]`` of the
        scaled plant (``x = diag(scaling.T) x_s``) and the controller's states, for the
        bounded-real inequality of the scaled loop at ``level * scaling.gamma_factor``
        in the form ``[[AᵀP + PA + Ṗ, PB, Cᵀ], [BᵀP, -γI, Dᵀ], [C, D, -γI]] < 0``:
        ``P Π₁ = Π₂`` with ``Π₁ = [[Y, I], [Mᵀ, 0]]``, ``Π₂ = [[I, X], [0, Nᵀ]]`` in the
        frame the controller was formed in (Scherer, Gahinet & Chilali 1997; here ``Y``
        is :meth:`lyapunov`'s ``X`` and vice versa).  For an independent check of the
        controller; the test suite differentiates it in ``p``."""
        p = self.values(*args, **named)
        R, S = self.lyapunov(*p)
        c = float(np.sqrt(float(level) * self.scaling.gamma_factor / self.gamma_lmi_scaled))
        R, S = c * R, c * S
        T = self.frame if self.rate_bounded else _lmi.balancing_transform(R, S)[0]
        Ti = np.linalg.inv(T)
        Yb, Xb = Ti @ R @ Ti.T, T.T @ S @ T
        n = R.shape[0]
        I, Z = np.eye(n), np.zeros((n, n))
        IXY = I - Xb @ Yb
        N, MT = (IXY, I) if self.rate_bounded and self.rate_form == "Y" else (I, IXY)
        Pi1 = np.block([[Yb, I], [MT, Z]])
        Pi2 = np.block([[I, Xb], [Z, N.T]])
        Pb = np.linalg.solve(Pi1.T, Pi2.T).T
        J = np.block([[Ti, Z], [Z, I]])
        return _lmi._sym(J.T @ Pb @ J)

    def build(self, *args, **named) -> tuple[control.StateSpace, float, float]:
        """``(K, level, cond_xy)``: the controller at ``p``, the level (plant units) it was
        formed at, and the condition number of ``I - X(p)Y(p)`` in the balanced frame.

        The level is ``(1 + backoff) γ_lmi`` wherever the projected inequalities hold
        there (on the grid, by construction); between grid points, where they fail, the
        first of ``_ESCALATION`` times it where they hold (:meth:`inequalities`; said
        by the returned level).  The explicit formulas alone do not detect a failed
        ``S`` inequality (the elimination checks one of its two projections)."""
        p = self.values(*args, **named)
        X, Y = self.lyapunov(*p)
        G = _plant_at(self.plant, p, self.nmeas, self.ncon, self.shape)
        Ps = _apply_scaling(_without_d22(G), self.scaling)
        g0 = self.gamma_lmi_scaled * (1.0 + self.backoff)
        # the smallest eigenvalue of X(p)Y(p): the coupling [[X, I], [I, Y]] > 0 holds
        # iff it exceeds 1 (imposed on the grid only; between grid points of a rich
        # basis it fell to 0.985 on the mass-spring-damper of tests/test_lpv.py)
        # (with X(p) > 0; an indefinite X(p) fails at every level)
        rates = self.lyapunov_rate(*p)
        projections = _lmi._projections(Ps, Ps, sparse=False)
        definite = np.linalg.eigvalsh(_lmi._sym(X))[0] > 0.0
        lam = float(np.min(np.linalg.eigvals(X @ Y).real)) if definite else -np.inf
        last = None
        for k in _ESCALATION:
            level = g0 * k
            # (c X, c Y) with c = sqrt(level / γ_lmi) keeps the projected inequalities
            # wherever (X, Y) satisfy them at γ_lmi (see hinfsyn's _explicit) and gives
            # the coupling c² - 1 of relative slack
            c2 = level / self.gamma_lmi_scaled
            if not c2 * lam > 1.0 + _COUPLING_RTOL:
                last = f"coupling: min eig(X(p) Y(p)) = {lam:.6g} against 1/{c2:.6g}"
                continue
            c = float(np.sqrt(c2))
            top = self._top(projections, X, Y, rates, level)
            if not top < 0.0:
                last = f"projected inequalities: largest eigenvalue {top:.3g} γ"
                continue
            try:
                if self.rate_bounded:
                    key = "dR" if self.rate_form == "X" else "dS"
                    Ks, cond_xy = _lmi.decoupled_controller(
                        Ps, c * X, c * Y, level, T=self.frame, **{key: [c * D for D in rates]})
                else:
                    Ks, cond_xy = _lmi.decoupled_controller(Ps, c * X, c * Y, level)
            except (SolverError, np.linalg.LinAlgError) as exc:
                last = exc
                continue
            K = _undo_loop_shift(self.scaling.controller_to_original(Ks), G.D22)
            return K, level / self.scaling.gamma_factor, float(cond_xy)
        raise SolverError(f"no controller at p = {p}: the projected inequalities fail up "
                          f"to {_ESCALATION[-1]:g} times the level ({last})")

    def at(self, *args, **named) -> control.StateSpace:
        """The controller at one parameter value (``K.at(m3=42.0)``)."""
        return self.build(*args, **named)[0]

    def at_discrete(self, *args, dt: float, allow_unresolved: bool = False,
                    **named) -> control.StateSpace:
        """The controller at one parameter value, discretised by Tustin's bilinear map at
        the sample time ``dt`` (s): ``K.at_discrete(dt=1e-3, m3=42.0)``.

        Tustin (python-control's ``sample_system``, method ``"bilinear"``) maps the left
        half-plane onto the unit disk, so the stable frozen controllers stay stable at
        any rate, and keeps the frequency response up to the warping
        ``ω -> (2/dt) tan(ω dt / 2)``.  A controller pole above the Nyquist rate ``π/dt``
        is compressed below it: the discrete controller is then a different one, and the
        certified γ says nothing about it.  That is a :class:`NyquistError`, not a
        warning: a realization for a computer is asked for exactly once per schedule
        point, nobody reads a log at that moment, and the error names the pole and the
        rate needed (``allow_unresolved=True`` returns the compressed realization
        anyway).  ``BACKOFF`` keeps the poles of :func:`lpvsyn`'s controllers below
        1e3 rad/s on the examples measured, a third of the 1 kHz Nyquist rate.

        Raises
        ------
        NyquistError
            A pole of ``K(p)`` faster than ``π/dt`` (without ``allow_unresolved``).
        ParameterError
            ``dt`` not positive, or a parameter value outside the design interval.
        """
        dt = finite_scalar(dt, "dt")
        if dt <= 0:
            raise ParameterError(f"dt must be a positive number of seconds, got {dt!r}")
        K = self.at(*args, **named)
        fast = float(np.max(np.abs(np.linalg.eigvals(K.A)))) if K.nstates else 0.0
        if fast > np.pi / dt and not allow_unresolved:
            p = self.values(*args, **named)
            where = ", ".join(f"{n}={v:.6g}" for n, v in zip(self.names, p))
            raise NyquistError(f"at {where} the controller has a pole at {fast:.6g} rad/s, "
                               f"above the Nyquist rate π/dt = {np.pi / dt:.6g} rad/s: "
                               f"sample faster than dt = {np.pi / fast:.3g} s (or pass "
                               "allow_unresolved=True)")
        Kd = control.sample_system(K, dt, method="bilinear")
        return control.ss(Kd.A, Kd.B, Kd.C, Kd.D, dt)

    def to_dict(self, table: dict | None = None) -> dict:
        """JSON-ready description (every float a Python float, which :mod:`json` writes
        as its shortest round-tripping repr: loading is exact).

        The plant and a caller's basis are callables; they are stored as tables on
        ``table`` (``{name: values}``), by default the plant's own table when it was
        given as a list of plants, else the design grid cut 4 times finer (the
        certificate's grid).  :meth:`from_dict` reproduces ``X_i``, ``Y_i``, the
        scalings and every table bit for bit, so ``at(p)`` of the loaded controller
        equals the original's bit for bit at every table node; between nodes the loaded
        controller uses the tables' linear interpolation (exact everywhere when the
        plant was a list of plants and the basis the default, ``"exact_between_nodes"``).
        """
        plant_is_table = isinstance(self.plant, _TablePlant) and table is None
        if table is not None:
            names, axes = _axes(table)
            if names != self.names:
                raise ParameterError(f"the table's parameters {names} are not {self.names}")
            # every node inside the design interval (the axes are sorted)
            self.values(*(float(a[0]) for a in axes))
            self.values(*(float(a[-1]) for a in axes))
        elif plant_is_table:
            axes = self.plant.table.axes
        elif self.grid is not None:
            axes = tuple(_check_axes(tuple(np.asarray(self.grid[n], dtype=float)
                                           for n in self.names), 4))
        else:
            raise ParameterError("give the table {name: values} the plant is stored on")
        nodes = list(itertools.product(*(a.tolist() for a in axes)))
        if plant_is_table:
            blocks = [self.plant.table.nodes[p] for p in nodes]
        else:
            blocks = []
            for p in nodes:
                G = as_statespace(self.plant(*p), f"P{p}")
                if (G.nstates, G.ninputs, G.noutputs) != tuple(self.shape):
                    raise DimensionError(f"P{p} does not have the sizes {self.shape}")
                blocks.append(np.block([[G.A, G.B], [G.C, G.D]]))
        nb = max(len(self.X), len(self.Y))
        if isinstance(self.basis, _AffineBasis):
            basis = {"kind": "affine", "live": list(self.basis.live)}
        elif isinstance(self.basis, _TableBasis) and table is None:
            b_axes = self.basis.table.axes
            b_nodes = list(itertools.product(*(a.tolist() for a in b_axes)))
            basis = {"kind": "table", "axes": [_floats(a) for a in b_axes],
                     "values": [_floats(self.basis.table.nodes[p]) for p in b_nodes]}
            if self.basis.jac is not None:
                basis["jacobian"] = [_floats(self.basis.jac.nodes[p]) for p in b_nodes]
        else:
            basis = {"kind": "table", "axes": [_floats(a) for a in axes],
                     "values": [_floats(_basis_values(self.basis, p, nb)) for p in nodes]}
            if self.rate_bounded:
                # the rate terms of the controller need ∂f/∂p as well
                basis["jacobian"] = [_floats(_basis_jacobian(self.basis, p, nb))
                                     for p in nodes]
        sc = self.scaling
        return {
            "names": list(self.names),
            "bounds": [[float(lo), float(hi)] for lo, hi in self.bounds],
            "nmeas": int(self.nmeas), "ncon": int(self.ncon),
            "shape": [int(v) for v in self.shape],
            "grid": None if self.grid is None else
            {n: _floats(self.grid[n]) for n in self.names},
            "X": [_floats(M) for M in self.X], "Y": [_floats(M) for M in self.Y],
            "gamma_lmi_scaled": float(self.gamma_lmi_scaled), "backoff": float(self.backoff),
            "scaling": {"T": _floats(sc.T), "Su": _floats(sc.Su), "Sy": _floats(sc.Sy),
                        "cw": float(sc.cw), "cz": float(sc.cz)},
            "plant": {"axes": [_floats(a) for a in axes],
                      "blocks": [_floats(M) for M in blocks]},
            "basis": basis,
            "exact_between_nodes": bool(plant_is_table and (
                basis["kind"] == "affine" or isinstance(self.basis, _TableBasis))),
            "rate": None if self.rate is None else [float(v) for v in self.rate],
            "rate_form": self.rate_form,
            "frame": None if self.frame is None else _floats(self.frame),
        }

    @classmethod
    def from_dict(cls, data: dict) -> ScheduledController:
        """The controller described by :meth:`to_dict` (exactly)."""
        try:
            names = tuple(str(n) for n in data["names"])
            shape = tuple(int(v) for v in data["shape"])
            plant_axes = [np.asarray(a, dtype=float) for a in data["plant"]["axes"]]
            nodes = list(itertools.product(*(a.tolist() for a in plant_axes)))
            blocks = data["plant"]["blocks"]
            if len(blocks) != len(nodes):
                raise DimensionError(f"the plant table has {len(blocks)} entries for "
                                     f"{len(nodes)} nodes")
            plant = _TablePlant.from_blocks(plant_axes, dict(zip(nodes, blocks)), shape)
            b = data["basis"]
            if b["kind"] == "affine":
                basis = _AffineBasis(b["live"])
            elif b["kind"] == "table":
                b_axes = [np.asarray(a, dtype=float) for a in b["axes"]]
                b_nodes = list(itertools.product(*(a.tolist() for a in b_axes)))
                if len(b["values"]) != len(b_nodes):
                    raise DimensionError("the basis table does not match its axes")
                jac = None if b.get("jacobian") is None else \
                    _GridTable(b_axes, dict(zip(b_nodes, b["jacobian"])))
                basis = _TableBasis(_GridTable(b_axes, dict(zip(b_nodes, b["values"]))), jac)
            else:
                raise InputError(f"unknown basis kind {b['kind']!r}")
            sc = data["scaling"]
            scaling = PlantScaling(np.asarray(sc["T"], dtype=float),
                                   np.asarray(sc["Su"], dtype=float),
                                   np.asarray(sc["Sy"], dtype=float),
                                   float(sc["cw"]), float(sc["cz"]))
            X = tuple(np.asarray(M, dtype=float) for M in data["X"])
            Y = tuple(np.asarray(M, dtype=float) for M in data["Y"])
            grid = None if data.get("grid") is None else \
                {n: np.asarray(data["grid"][n], dtype=float) for n in names}
            rate = None if data.get("rate") is None else \
                tuple(float(v) for v in data["rate"])
            frame = None if data.get("frame") is None else \
                np.asarray(data["frame"], dtype=float)
            return cls(names, tuple((float(lo), float(hi)) for lo, hi in data["bounds"]),
                       basis, X, Y, float(data["gamma_lmi_scaled"]), float(data["backoff"]),
                       scaling, plant, int(data["nmeas"]), int(data["ncon"]), shape, grid,
                       rate, frame, data.get("rate_form"))
        except KeyError as exc:
            raise InputError(f"scheduled controller description lacks key {exc}") from exc
        except (TypeError, ValueError) as exc:
            if isinstance(exc, InputError):
                raise
            raise InputError(f"malformed scheduled controller description: {exc}") from exc


# --------------------------------------------------------------------------- result
@dataclass(frozen=True)
class LpvsynResult:
    """Result of :func:`lpvsyn`.

    Attributes
    ----------
    K : ScheduledController
    gamma : float
        The certified value: the largest ``hinfnorm(lft(P(p), K(p)))`` over
        ``check_grid`` (``inf`` where a frozen loop is unstable).
    gamma_lmi : float
        The LMI optimum (plant units): the lowest level at which one pair ``X(p)``,
        ``Y(p)`` of this basis satisfies the LMIs at every grid point, i.e. a lower bound
        on what these Lyapunov certificates can prove, not on the frozen norms: those are
        exact per point and may be lower (0.979 γ_lmi with basis [1, m] on the example of
        tests/test_lpv.py, and 0.84 with basis [1]; measured 2026-12-02).  A frozen norm
        above ``(1 + backoff) γ_lmi`` (the level the controllers are formed at) is
        reported in ``warnings``.
    grid, check_grid : dict
        The design grid and the denser grid (each interval cut in ``check_density``
        pieces, the ends included) on which ``gamma`` is certified.
    gamma_check : numpy.ndarray
        The certified norm at each point of the check grid (in the order of
        :func:`itertools.product` over ``check_grid``'s values).
    levels : numpy.ndarray
        The level each of those controllers was formed at (``(1 + backoff) γ_lmi``, or
        above it between grid points where the grid's LMIs do not hold there).
    warnings : tuple of str
        What the certificate found wrong (a frozen loop unstable, a norm above
        ``(1 + backoff) γ_lmi``, a controller that could not be formed) and Clarabel's
        recoveries; empty when everything certified.
    notes : tuple of str
        Information that does not weaken the certificate: check points between grid
        points where the grid's LMIs do not hold at the level and the controller was
        formed at a higher one (its norm certified all the same).
    seconds, seconds_lmi, seconds_check : float
        Wall time in all, in the γ minimisation and in the check.
    status : str
        Clarabel's status of the γ minimisation.
    inequality_check : numpy.ndarray
        Certificate (b): at each check point, the largest eigenvalue (relative to the
        level) of the projected inequalities re-evaluated with the returned ``X(p)``,
        ``Y(p)`` — with ``-Ẋ(p)`` at every vertex of the rate box for ν > 0 — and of the
        coupling, as the controller there was formed (:meth:`ScheduledController.inequalities`);
        negative where they hold, a warning otherwise.
    """

    K: ScheduledController
    gamma: float
    gamma_lmi: float
    grid: dict
    check_grid: dict
    gamma_check: np.ndarray
    levels: np.ndarray
    warnings: tuple
    notes: tuple
    seconds: float
    seconds_lmi: float
    seconds_check: float
    status: str = ""
    inequality_check: np.ndarray = None

    def gamma_frozen(self, *args, **named) -> float:
        """``hinfnorm(lft(P(p), K(p)))`` at one parameter value (``inf`` if unstable)."""
        p = self.K.values(*args, **named)
        G = _plant_at(self.K.plant, p, self.K.nmeas, self.K.ncon, self.K.shape)
        return float(hinfnorm(lft(G, self.K.at(*p)))[0])


# --------------------------------------------------------------------------- synthesis
def _gamma_lmi(plants, F, opts: HinfsynOptions, warnings: list, J=None, nus=None,
               form: str = "X"):
    """The γ minimisation over the grid (scaled plants, ``D22 = 0``); with the basis
    Jacobians ``J`` (one ``nb x k`` matrix per grid point) and rate bounds ``nus``, the
    ``X`` inequality carries ``-Ẋ`` at every vertex of the rate box and ``Y`` is one
    constant matrix (``form="X"``), or the ``Y`` inequality ``+Ẏ`` and ``X`` is
    constant (``form="Y"``)."""
    n, nb = plants[0].nstates, F.shape[1]
    rated = nus is not None and any(nu > 0 for nu in nus)
    Xs = [cp.Variable((n, n), symmetric=True)
          for _ in range(1 if rated and form == "Y" else nb)]
    Ys = [cp.Variable((n, n), symmetric=True)
          for _ in range(1 if rated and form == "X" else nb)]
    g = cp.Variable(nonneg=True)
    eye = np.eye(n)
    cons = []
    corners = _vertices(nus) if rated else []
    for idx, (Pk, f) in enumerate(zip(plants, F)):
        X = Xs[0] if rated and form == "Y" else sum(float(fi) * Xi for fi, Xi in zip(f, Xs))
        Y = Ys[0] if rated and form == "X" else sum(float(fi) * Yi for fi, Yi in zip(f, Ys))
        pr, ps = _lmi._projections(Pk, Pk, sparse=False)
        for proj, V, Vs, sign, dependent in ((pr, X, Xs, -1.0, form == "X"),
                                             (ps, Y, Ys, 1.0, form == "Y")):
            if proj is None:
                continue
            if not (rated and dependent):
                cons.append(proj.lmi(V, g, opts.margin))
                continue
            pad = np.zeros((proj.Nx.shape[1], proj.H.shape[1]))
            for v in corners:
                w = J[idx] @ v                                  # ∂f/∂p · ṗ
                terms = [float(wi) * Vi for wi, Vi in zip(w, Vs) if wi]
                L = proj.matrix(V, g)
                if terms:
                    L = L + sign * cp.bmat([[proj.Nx.T @ sum(terms) @ proj.Nx, pad],
                                            [pad.T, np.zeros((pad.shape[1],) * 2)]])
                cons.append(_lmi._sym(L) << -opts.margin * np.eye(L.shape[0]))
        cons += [_lmi._sym(cp.bmat([[X, eye], [eye, Y]])) >> 0,
                 cp.trace(X) + cp.trace(Y) <= opts.xy_bound * n]
    prob = cp.Problem(cp.Minimize(g), cons)
    status, _ = _lmi._solve(prob, opts, "lpvsyn gamma minimisation", warnings)
    if status in _lmi._INFEASIBLE:
        raise InfeasibleError("the gridded H∞ LMIs are infeasible for every γ: no "
                              "scheduled controller with this basis stabilises every "
                              "frozen plant within the trace bound")
    return (float(g.value), tuple(_lmi._sym(V.value) for V in Xs),
            tuple(_lmi._sym(V.value) for V in Ys), str(status))


def _check_axes(axes, density: int):
    out = []
    for a in axes:
        if a.size == 1:
            out.append(a.copy())
            continue
        pts = [np.linspace(lo, hi, density + 1)[:-1] for lo, hi in zip(a[:-1], a[1:])]
        out.append(np.r_[np.concatenate(pts), a[-1]])
    return out


def lpvsyn(P, grid, nmeas: int, ncon: int, *, basis: Callable | None = None,
           rate: dict | None = None, rate_form: str = "auto", backoff: float = BACKOFF,
           check_density: int = 4,
           options: HinfsynOptions | None = None) -> LpvsynResult:
    """Gain-scheduled H∞ output-feedback synthesis on a parameter grid, for parameters
    frozen during operation (ν = 0) or varying at bounded rates ``|ṗ_k| <= ν_k``.

    Parameters
    ----------
    P : callable or list of (p, plant)
        ``P(*p) -> control.StateSpace`` (the parameters positionally, in the order of
        ``grid``), continuous time, the same sizes at every ``p``; or a list of pairs
        ``(p, plant)`` on a rectangular grid (``p`` a number, a tuple, or a dict by
        name), interpolated linearly between grid points.
    grid : dict or str or sequence of str
        ``{name: values}``: the design grid is the Cartesian product of the values.  With
        a list of plants, the parameter names (a dict's values are then not used).
    nmeas, ncon : int
        Numbers of measurements and controls (last outputs, last inputs).
    basis : callable, optional
        ``f(*p) -> sequence`` of the basis functions of ``X(p)`` and ``Y(p)``; the
        default is ``[1]`` and each parameter with more than one grid value.
    rate : dict, optional
        ``{name: ν}``, the bound on ``|dp/dt|`` (per second; absent names: 0, frozen).
    rate_form : {"auto", "X", "Y"}
        With a rate bound: which Lyapunov matrix depends on ``p`` (the other one is
        constant, so that the controller does not need ``ṗ``); ``"auto"`` solves both
        LMIs and keeps the lower γ (twice the time).
    backoff : float
        The controller is formed at ``(1 + backoff) γ_lmi`` (see ``BACKOFF``).
    check_density : int
        Each design interval is cut into this many pieces for the certificate (>= 1;
        the default 4 is what the certificate of issue 61 asks for).
    options : HinfsynOptions, optional
        Clarabel tolerances, ``margin``, ``xy_bound``, ``max_recoveries``, ``cert_rtol``.

    Returns
    -------
    LpvsynResult

    Raises
    ------
    NonFiniteError, DimensionError, DiscreteTimeError, ParameterError, InputError
        Bad grid, plant, basis or rate: NaN, an empty grid, discrete-time plants, sizes
        that change across the grid, a basis of the wrong length, non-finite, or
        linearly dependent on the grid, a rate bound on a parameter with one grid
        value, a negative or non-finite rate.
    InfeasibleError, SolverError
        No scheduled controller exists for this basis, or Clarabel failed.

    Notes
    -----
    With ν = 0 the controller is guaranteed for frozen parameters only: for each
    constant ``p`` the loop ``F_l(P(p), K(p))`` is stable with its norm below the level,
    certified on the check grid; a parameter that varies during operation, however
    slowly, is not covered.  With ν > 0 the parameter-dependent inequalities (with the
    ``∂X/∂p`` terms at every vertex of the rate box) are re-evaluated on the check grid
    (``inequality_check``), which bounds the induced L2 gain for varying parameters
    where they hold.  Between check points nothing is certified.

    Cost: one SDP whose size grows with the grid.  Measured 2026-12-02 (2-core Zen 1,
    shared, one OpenBLAS thread, basis ``[1, p, 1/p]``,
    ``benchmarks/lpv_grid_cost.py``): on a 2-state plant 0.04-0.08 s per grid point
    from 3 to 33 points, about one ``hinfsyn`` LMI (0.03-0.05 s), 90 % of it CVXPY's
    compilation; on the 10-state seat 0.2-0.4, 0.3-0.5 and 0.5-0.8 s per point at 3, 5
    and 9 points (one ``hinfsyn`` LMI: 0.16 s), Clarabel's iterations growing in cost
    with the grid.  The structured KKT solver of :mod:`.structured` (two unknowns, one
    coupling) is not used: see ``docs/guide/lpv.md``, "What one grid point costs".

    Examples
    --------
    A mass-spring-damper whose measured mass ``m`` is in [1, 4]; the control force acts
    through ``1/m``:

    >>> import control, numpy as np
    >>> def msd(m):      # w = [force, noise], u; z = [x, 0.1 u]; y = x + 0.1 noise
    ...     return control.ss([[0, 1], [-1 / m, -0.2 / m]], [[0, 0, 0], [1 / m, 0, 1 / m]],
    ...                       [[1, 0], [0, 0], [1, 0]], [[0, 0, 0], [0, 0, 0.1], [0, 0.1, 0]])
    >>> res = lpvsyn(msd, {"m": np.linspace(1.0, 4.0, 5)}, 1, 1)
    >>> res.K.at(m=2.2).nstates, len(res.check_grid["m"]), res.warnings
    (2, 17, ())
    >>> K, level, _ = res.K.build(m=2.2)          # between grid points
    >>> bool(res.gamma_frozen(m=2.2) <= level * (1 + 1e-6))
    True
    >>> bool(res.gamma <= res.gamma_lmi * (1 + res.K.backoff) * (1 + 1e-6))
    True
    """
    t0 = time.perf_counter()
    opts = HinfsynOptions() if options is None else options
    if not isinstance(opts, HinfsynOptions):
        raise ParameterError("options must be a HinfsynOptions instance")
    if isinstance(check_density, bool) or not isinstance(check_density, (int, np.integer)) \
            or check_density < 1:
        raise ParameterError(f"check_density must be a positive integer, got {check_density!r}")
    backoff = finite_scalar(backoff, "backoff")
    if backoff <= 0:
        raise ParameterError(f"backoff must be positive, got {backoff!r}")
    if callable(P) and not isinstance(P, (control.StateSpace, GeneralizedPlant)):
        names, axes = _axes(grid)
        plant = P
    elif isinstance(P, (list, tuple)):
        plant, names, axes = _from_pairs(P, grid)
    else:
        raise InputError("P must be a callable p -> StateSpace or a list of (p, plant)")
    rate = {} if rate is None else rate
    if not isinstance(rate, dict) or set(rate) - set(names):
        raise ParameterError(f"rate must be a dict over the parameters {names}, got {rate!r}")
    nus = []
    for name, a in zip(names, axes):
        nu = finite_scalar(rate.get(name, 0.0), f"rate[{name!r}]")
        if nu < 0:
            raise ParameterError(f"rate[{name!r}] must be >= 0, got {nu}")
        if nu > 0 and a.size < 2:
            raise ParameterError(f"rate[{name!r}] = {nu:g} but the grid gives {name!r} one "
                                 "value: a parameter that varies needs a range (at least "
                                 "two grid values)")
        nus.append(nu)
    nus = tuple(nus)
    rated = any(nu > 0 for nu in nus)
    if rate_form not in ("auto", "X", "Y"):
        raise ParameterError(f"rate_form must be 'auto', 'X' or 'Y', got {rate_form!r}")
    basis = _default_basis(axes) if basis is None else basis
    if not callable(basis):
        raise InputError("basis must be a callable f(*p) -> sequence of float")
    points = list(itertools.product(*(a.tolist() for a in axes)))
    nb = _basis_values(basis, points[0], None).size
    F = np.vstack([_basis_values(basis, p, nb) for p in points])
    if np.linalg.matrix_rank(F) < nb:
        raise ParameterError(f"the {nb} basis functions are linearly dependent on the grid "
                             f"(rank {np.linalg.matrix_rank(F)} over {len(points)} points): "
                             "X(p), Y(p) would not be unique; drop a function or refine "
                             "the grid")
    J = [_basis_jacobian(basis, p, nb) for p in points] if rated else None
    first = _plant_at(plant, points[0], nmeas, ncon)
    shape = (first.nstates, first.sys.ninputs, first.sys.noutputs)
    if not first.nstates:
        raise DimensionError("the plant has no states: a static problem; use hinfsyn at "
                             "each parameter value")
    Gs = [first] + [_plant_at(plant, p, nmeas, ncon, shape) for p in points[1:]]
    # one scaling for the whole grid (X_i, Y_i are shared): the one of the middle point
    mid = _without_d22(Gs[len(Gs) // 2])
    if opts.scale:
        _, sc = scale_plant(mid)
    else:
        sc = PlantScaling(np.ones(mid.nstates), np.ones(mid.nu), np.ones(mid.ny), 1.0, 1.0)
    plants = [_apply_scaling(_without_d22(G), sc) for G in Gs]
    warnings: list[str] = []
    t1 = time.perf_counter()
    notes = []
    if not rated:
        g_s, Xi, Yi, status = _gamma_lmi(plants, F, opts, warnings, J, nus)
        form = None
    else:
        forms = ("X", "Y") if rate_form == "auto" else (rate_form,)
        tried = {}
        for fm in forms:
            try:
                tried[fm] = _gamma_lmi(plants, F, opts, warnings, J, nus, fm)
            except InfeasibleError:
                if len(forms) == 1:
                    raise
        if not tried:
            raise InfeasibleError("the rate-bounded LMIs are infeasible with X(p) and with "
                                  "Y(p) parameter dependent")
        form = min(tried, key=lambda fm: tried[fm][0])
        g_s, Xi, Yi, status = tried[form]
        if len(tried) > 1:
            notes.append("rate bound: γ_lmi with X(p) (Y constant) "
                         f"{tried['X'][0] / sc.gamma_factor:.6g}, with Y(p) (X constant) "
                         f"{tried['Y'][0] / sc.gamma_factor:.6g}; kept {form}(p)")
    t_lmi = time.perf_counter() - t1
    frame = None
    if rated:
        # one frame for the whole range (a frame moving with p would put its derivative
        # in the controller): the balancing of the middle grid point's pair
        f_mid = F[len(points) // 2]
        Xm = Xi[0] if form == "Y" else sum(fi * X for fi, X in zip(f_mid, Xi))
        Ym = Yi[0] if form == "X" else sum(fi * Y for fi, Y in zip(f_mid, Yi))
        frame = _lmi.balancing_transform(Xm, Ym)[0]
    K = ScheduledController(tuple(names), tuple((float(a[0]), float(a[-1])) for a in axes),
                            basis, Xi, Yi, g_s, backoff, sc, plant, int(nmeas), int(ncon),
                            shape, dict(zip(names, axes)), nus, frame, form)
    gamma_lmi = g_s / sc.gamma_factor
    t2 = time.perf_counter()
    check = _check_axes(axes, int(check_density))
    level0 = gamma_lmi * (1.0 + backoff)
    norms, levels, escalated, ineq = [], [], [], []
    for p in itertools.product(*(a.tolist() for a in check)):
        where = ", ".join(f"{n}={v:.6g}" for n, v in zip(names, p))
        try:
            Kp, level, _cond = K.build(*p)
        except SolverError as exc:
            warnings.append(f"at {where}: {exc}")
            norms.append(np.inf)
            levels.append(np.inf)
            ineq.append(np.inf)
            continue
        ineq.append(K.inequalities(*p, level=level))
        if ineq[-1] >= 0.0:
            warnings.append(f"at {where}: the parameter-dependent inequalities fail with "
                            f"the returned X(p), Y(p) (largest eigenvalue {ineq[-1]:.3g} γ)")
        if level > level0 * (1.0 + 1e-12):
            escalated.append(where)
        G = _plant_at(plant, p, nmeas, ncon, shape)
        gam = float(hinfnorm(lft(G, Kp))[0])
        norms.append(gam)
        levels.append(level)
        if not np.isfinite(gam):
            warnings.append(f"at {where}: the frozen closed loop is NOT stable")
        elif gam > level0 * (1.0 + _CERT_RTOL):
            warnings.append(f"at {where}: certified {gam:.6g} exceeds the LMI's level "
                            f"(1 + backoff) γ_lmi = {level0:.6g} by "
                            f"{100 * (gam / level0 - 1):.3g} %")
    if escalated:
        notes.append(f"at {len(escalated)} of {len(norms)} check points ({escalated[0]}, "
                        f"...) the grid's LMIs do not hold at the level {level0:.6g}; the "
                        f"controllers there are formed at up to {max(levels):.6g} "
                        "(certified as everywhere)")
    norms = np.asarray(norms)
    t3 = time.perf_counter()
    return LpvsynResult(K=K, gamma=float(np.max(norms)), gamma_lmi=float(gamma_lmi),
                        grid=dict(zip(names, axes)), check_grid=dict(zip(names, check)),
                        gamma_check=norms, levels=np.asarray(levels),
                        inequality_check=np.asarray(ineq),
                        warnings=tuple(warnings), notes=tuple(notes), seconds=t3 - t0,
                        seconds_lmi=t_lmi, seconds_check=t3 - t2, status=status)
