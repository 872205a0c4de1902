"""Gain surfaces: a static gain scheduled on measured parameters (MATLAB's
``tunableSurface``).

A gain surface is ``K(p; θ) = K0 + Σᵢ Fᵢ(p) Kᵢ`` over named scheduling parameters ``p``
(an operating point: a speed, a load), with basis functions ``F₁ … F_m`` the user
chooses and coefficient matrices ``K0 … K_m`` that are tuned.  The surface itself has no
matrices (they depend on ``p``); :meth:`GainSurface.at` fixes a scheduling point and
returns a :class:`~lmi_suspension.tune.TunableBlock` (a static gain) whose free
parameters are the surface's coefficients, the same at every point.  That is the whole
extension of the block protocol (:class:`ScheduledBlock`): a block that depends on a
scheduling point offers ``scheduling`` (the names of its parameters) and ``at(**p)``;
:func:`~lmi_suspension.tune.systune` calls ``at`` with each model's point, so that one
vector θ tunes the surface over every model at once.

The gain is linear in θ, so its derivative is the basis itself:
``∂K(p)/∂(K_j)_{rc} = F_j(p) E_{rc}`` (``F_0 = 1``).

The basis is checked on a design grid (the Cartesian product of the parameters' values):
the constant and the basis functions must be linearly independent there, else some
combination of coefficients would not change the gain anywhere on the grid (a flat
direction of every objective, and coefficients the grid cannot determine).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from typing import Protocol, runtime_checkable

import numpy as np

from ..errors import DimensionError, InputError, NonFiniteError, ParameterError
from ..lti.checks import finite_scalar
from .blocks import _Block, _freqresp_derivative, _size

__all__ = ["GainSurface", "ScheduledBlock", "tunable_surface"]

#: relative singular-value threshold of the grid's basis matrix ``[1, F(p)]``: below it
#: the basis counts as linearly dependent on the grid (a dependence exact in exact
#: arithmetic, e.g. ``F = [p, 2 p]``, gives ~1e-16; a genuine basis of order one on a
#: grid of a few points gives 1e-3 and up)
_RANK_RTOL = 1e-9


@runtime_checkable
class ScheduledBlock(Protocol):
    """A tunable block that depends on a scheduling point: its free parameters
    (``name``, ``param_names``, ``n_params``, ``start``) as for a
    :class:`~lmi_suspension.tune.TunableBlock`, the names of its scheduling parameters,
    and ``at(**p)``, the block at one point (a ``TunableBlock`` with the same free
    parameters)."""

    name: str
    param_names: tuple
    scheduling: tuple

    @property
    def n_params(self) -> int: ...

    @property
    def start(self) -> np.ndarray: ...

    def at(self, **point): ...


class GainSurface(_Block):
    """A gain surface ``K(p) = K0 + Σᵢ Fᵢ(p) Kᵢ``; build one with :func:`tunable_surface`.

    Its free parameters are the coefficients' entries, ``name.K0``, ``name.K1``, … for
    a 1 × 1 gain and ``name.Kj[r,c]`` otherwise (0-based entries, ``j`` the basis
    function's number, ``K0`` the constant)."""

    kind = "gain surface"

    def __init__(self, name, domain, basis, shape, *, start=None, fixed=None):
        ny, nu = _shape(shape)
        self.scheduling, self.grid = _domain(domain)
        if not callable(basis):
            raise ParameterError(f"basis must be a function of the scheduling parameters "
                                 f"({', '.join(self.scheduling)}), got {basis!r}")
        self._basis = basis
        values = np.array([self._call(point) for point in self.grid])
        self.n_basis = values.shape[1]
        _check_independent(values, self.scheduling)
        self._shape = (ny, nu)
        entries = ([""] if ny == nu == 1 else
                   [f"[{r},{c}]" for r in range(ny) for c in range(nu)])
        labels = [f"K{j}{e}" for j in range(self.n_basis + 1) for e in entries]
        super().__init__(name, ny, nu, 0, labels, np.zeros(len(labels)), start=start,
                         fixed=fixed)

    # ----------------------------------------------------------------- the basis
    def _call(self, point) -> np.ndarray:
        try:
            f = np.asarray(self._basis(*point), dtype=float).ravel()
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"gain surface basis failed at "
                                 f"{dict(zip(self.scheduling, point))}: {exc}") from exc
        if f.size == 0:
            raise ParameterError("the basis returned no function: a gain surface needs at "
                                 "least one basis function (else use tunable_gain)")
        if hasattr(self, "n_basis") and f.size != self.n_basis:
            raise DimensionError(f"the basis returned {f.size} values at "
                                 f"{dict(zip(self.scheduling, point))}, {self.n_basis} "
                                 "on the grid")
        if not np.all(np.isfinite(f)):
            raise NonFiniteError(f"the basis is not finite at "
                                 f"{dict(zip(self.scheduling, point))}: {f.tolist()}")
        return f

    def _point(self, point: Mapping) -> tuple:
        unknown = [k for k in point if k not in self.scheduling]
        if unknown:
            raise ParameterError(f"gain surface {self.name!r} has no scheduling parameter "
                                 f"{', '.join(map(repr, unknown))}; its parameters are "
                                 f"{', '.join(self.scheduling)}")
        missing = [k for k in self.scheduling if k not in point]
        if missing:
            raise ParameterError(f"gain surface {self.name!r} needs a value of "
                                 f"{', '.join(missing)}")
        return tuple(finite_scalar(point[k], f"{self.name}: {k}") for k in self.scheduling)

    def basis(self, **point) -> np.ndarray:
        """``[1, F₁(p), …, F_m(p)]`` at the scheduling point ``p``."""
        return np.concatenate([[1.0], self._call(self._point(point))])

    # ----------------------------------------------------------------- evaluation
    def at(self, **point) -> _SurfaceAt:
        """The surface at one scheduling point: a static-gain
        :class:`~lmi_suspension.tune.TunableBlock` with the surface's free parameters.

        Raises
        ------
        ParameterError, NonFiniteError
            An unknown or missing scheduling parameter, or a non-finite value."""
        return _SurfaceAt(self, point, self.basis(**point))

    def gain(self, point: Mapping, theta=None) -> np.ndarray:
        """``K(p)`` at the scheduling point ``point`` (a mapping) for the free parameters
        ``theta`` (a vector, or a mapping by full name such as a
        :class:`~lmi_suspension.tune.SystuneResult`'s ``values``, whose other blocks'
        names are ignored; default: the start)."""
        if not isinstance(point, Mapping):
            raise ParameterError(f"point must be a mapping of scheduling parameters to "
                                 f"values, got {type(point).__name__}")
        return self.at(**point).matrices(self._theta_of(theta))[3]

    def _theta_of(self, theta) -> np.ndarray:
        if theta is None:
            return self.start
        if isinstance(theta, Mapping):
            missing = [n for n in self.param_names if n not in theta]
            if missing:
                raise ParameterError(f"no value for {', '.join(missing)}")
            return np.array([finite_scalar(theta[n], n) for n in self.param_names])
        return self._theta(theta)

    def matrices(self, theta):
        raise ParameterError(f"gain surface {self.name!r} has a gain only at a scheduling "
                             f"point: use .at({', '.join(k + '=...' for k in self.scheduling)})")

    jacobian = ss = freqresp_derivative = matrices

    def _coefficients(self, theta) -> np.ndarray:
        """``[K0, K1, …]`` as an array ``(n_basis + 1, ny, nu)``."""
        return self._full(self._theta(theta)).reshape(self.n_basis + 1, *self._shape)

    def __repr__(self) -> str:
        return (f"<gain surface {self.name!r}: {self.noutputs}x{self.ninputs} over "
                f"{', '.join(self.scheduling)}, {self.n_basis} basis functions, "
                f"{self.n_params} free parameters>")


class _SurfaceAt:
    """A gain surface at one scheduling point: a static gain whose free parameters are
    the surface's (a :class:`~lmi_suspension.tune.TunableBlock`)."""

    kind = "gain surface at a point"
    nstates = 0

    def __init__(self, surface: GainSurface, point, weights):
        self.surface, self.point, self._w = surface, dict(point), weights
        self.name, self.param_names = surface.name, surface.param_names
        self.noutputs, self.ninputs = surface.noutputs, surface.ninputs

    @property
    def n_params(self) -> int:
        return self.surface.n_params

    @property
    def start(self) -> np.ndarray:
        return self.surface.start

    @property
    def positive(self) -> np.ndarray:
        return np.zeros(self.n_params, dtype=bool)

    def matrices(self, theta) -> tuple:
        D = np.tensordot(self._w, self.surface._coefficients(theta), axes=1)
        return (np.zeros((0, 0)), np.zeros((0, self.ninputs)), np.zeros((self.noutputs, 0)),
                D)

    def jacobian(self, theta) -> np.ndarray:
        self.surface._theta(theta)
        ny, nu = self.noutputs, self.ninputs
        J = np.einsum("j,rc->jrc", self._w, np.ones((ny, nu)))
        full = np.zeros((self._w.size, ny * nu, ny, nu))
        for e, (r, c) in enumerate(itertools.product(range(ny), range(nu))):
            full[:, e, r, c] = J[:, r, c]
        return full.reshape(-1, ny, nu)[self.surface._free]

    def ss(self, theta):
        import control
        theta = self.surface._theta(theta)
        if not np.all(np.isfinite(theta)):
            raise NonFiniteError(f"theta of block {self.name!r} holds NaN or infinity")
        return control.ss(*self.matrices(theta))

    def values(self, theta) -> dict:
        return self.surface.values(theta)

    def freqresp_derivative(self, theta, s) -> np.ndarray:
        return _freqresp_derivative(self, self.surface._theta(theta), s)

    def __repr__(self) -> str:
        return f"<gain surface {self.name!r} at {self.point}>"


def _shape(shape):
    if not (isinstance(shape, (tuple, list)) and len(shape) == 2):
        raise DimensionError(f"shape must be (ny, nu), got {shape!r}")
    return _size(shape[0], "ny", minimum=1), _size(shape[1], "nu", minimum=1)


def _domain(domain):
    if not isinstance(domain, Mapping) or not domain:
        raise ParameterError("params must be a non-empty mapping of scheduling-parameter "
                             "names to their design grid values, e.g. {'V': [10, 20, 30]}")
    names, axes = [], []
    for name, values in domain.items():
        if not isinstance(name, str) or not name.isidentifier():
            raise ParameterError(f"a scheduling parameter's name must be an identifier, "
                                 f"got {name!r}")
        try:
            v = np.atleast_1d(np.asarray(values, dtype=float))
        except (TypeError, ValueError) as exc:
            raise InputError(f"grid of {name!r} must be numeric: {exc}") from exc
        if v.ndim != 1 or v.size == 0:
            raise DimensionError(f"grid of {name!r} must be a non-empty 1-D sequence")
        if not np.all(np.isfinite(v)):
            raise NonFiniteError(f"grid of {name!r} holds NaN or infinity")
        names.append(name)
        axes.append(v)
    return tuple(names), tuple(itertools.product(*axes))


def _check_independent(values: np.ndarray, names) -> None:
    """``[1, F(p)]`` over the grid must have full column rank."""
    zero = [j + 1 for j in range(values.shape[1]) if not np.any(values[:, j])]
    if zero:
        raise ParameterError(f"basis function(s) {zero} (1-based) are zero at every grid "
                             f"point of {', '.join(names)}: their coefficients would not "
                             "change the gain")
    M = np.hstack([np.ones((values.shape[0], 1)), values])
    if M.shape[0] < M.shape[1]:
        raise ParameterError(f"the grid has {M.shape[0]} points for {M.shape[1]} "
                             f"coefficients (K0 and {values.shape[1]} basis functions): "
                             "the basis is linearly dependent on it; use more grid points")
    # columns scaled to unit norm, so that a basis of large values (a speed in m/s
    # squared) is judged by its shape, not its units
    M = M / np.linalg.norm(M, axis=0)
    sv = np.linalg.svd(M, compute_uv=False)
    if sv[-1] <= _RANK_RTOL * sv[0]:
        raise ParameterError(f"the basis functions and the constant are linearly "
                             f"dependent on the grid (smallest singular value "
                             f"{sv[-1]:.2e} of {sv[0]:.2e}): some coefficients would not "
                             "change the gain anywhere on it")


def tunable_surface(name: str, params, basis, shape=(1, 1), *, start=None, fixed=None):
    """A tunable gain surface ``K(p) = K0 + Σᵢ Fᵢ(p) Kᵢ`` (MATLAB's ``tunableSurface``).

    Parameters
    ----------
    name : str
        Block name; the free parameters are ``name.K0``, ``name.K1``, … (1 × 1) or
        ``name.Kj[r,c]`` (0-based entries).
    params : mapping of str to array_like
        The scheduling parameters and their design grid, e.g.
        ``{"V": [10, 20, 30], "m": [60, 90]}``: the grid is the Cartesian product, on
        which the basis is checked; the surface can be evaluated anywhere.
    basis : callable
        ``basis(p1, p2, ...) -> [F1, ..., Fm]``, called with the scheduling parameters
        positionally in the order of ``params``.  Keep the ``Fi`` of order one on the
        grid (write them in normalised variables, as MATLAB does): the coefficients are
        then of the size of the gain, which the optimiser's first steps assume.
    shape : (int, int)
        ``(ny, nu)``: outputs (controls) and inputs (measurements), MATLAB's order.
    start, fixed : mapping of str to float, optional
        Starting values (default 0) and coefficients held at a value, by short
        (``"K1"``) or full name.

    Returns
    -------
    GainSurface
        A :class:`ScheduledBlock`: ``.at(**p)`` is the static gain at ``p`` (a
        :class:`~lmi_suspension.tune.TunableBlock`), ``.gain(p, theta)`` its value.

    Raises
    ------
    ParameterError
        A basis that is not a function, that returns nothing, has a function zero at
        every grid point, or is linearly dependent with the constant on the grid; an
        empty or badly named ``params``; an unknown coefficient in ``start``/``fixed``.
    DimensionError, NonFiniteError
        A bad ``shape``, a basis returning different sizes, non-finite values.

    Examples
    --------
    A gain scheduled on a speed ``V`` in 10 … 30 m/s, affine in ``(V - 20)/10``:

    >>> S = tunable_surface("K", {"V": [10, 20, 30]}, lambda V: [(V - 20) / 10])
    >>> S.param_names
    ('K.K0', 'K.K1')
    >>> S.gain({"V": 25}, [2.0, -1.0]).tolist()          # 2 - 0.5
    [[1.5]]
    >>> S.at(V=25).jacobian([2.0, -1.0]).ravel().tolist()  # dK/dK0, dK/dK1
    [1.0, 0.5]
    >>> tunable_surface("K", {"V": [10, 20]}, lambda V: [V, 2 * V + 1])
    Traceback (most recent call last):
    ...
    lmi_suspension.errors.ParameterError: the grid has 2 points for 3 coefficients (K0 and 2 basis functions): the basis is linearly dependent on it; use more grid points
    """
    return GainSurface(name, params, basis, shape, start=start, fixed=fixed)
