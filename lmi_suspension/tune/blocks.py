"""Tunable blocks of structured H∞ tuning: a static gain, a PID, a fixed-order state space.

A tunable block is a continuous-time LTI system whose state-space matrices are smooth
functions of a few named real parameters.  Every block here offers the same small
protocol (:class:`TunableBlock`):

* ``name``, ``ninputs`` (the measurements it reads), ``noutputs`` (the controls it
  drives), ``nstates``;
* ``param_names``, the names of its *free* parameters (``"C.kp"``, ``"C.A[0,1]"``), and
  ``n_params``; ``start``, their default starting values (a copy, as a vector);
* ``matrices(theta) -> (A, B, C, D)`` and ``ss(theta) -> control.StateSpace``;
* ``jacobian(theta)``: the derivatives of the stacked matrix
  ``Kbar = [[D, C], [B, A]]`` (which maps ``[y; x_K] -> [u; x_K']``) with respect to each
  free parameter, an array of shape ``(n_params, noutputs + nstates, ninputs + nstates)``;
* ``freqresp_derivative(theta, s)``: ``dK/dθ_i(s)`` at complex points ``s``, from the
  Jacobian: ``dK_i(s) = [I, C (sI - A)⁻¹] dKbar_i [I; (sI - A)⁻¹ B]``;
* ``values(theta) -> dict``: the free parameters by name.

The sizes follow MATLAB's ``tunableGain(name, ny, nu)``: ``ny`` outputs (controls),
``nu`` inputs (measurements).  Parameters can be held at a value (``fixed=``, MATLAB's
``Free = false``) or started elsewhere (``start=``), by short (``"kp"``) or full
(``"C.kp"``) name; a block left with no free parameter is a
:class:`~lmi_suspension.errors.ParameterError`.  Indices in names are 0-based.

A user block is any object with these attributes and methods; :func:`hinfstruct
<lmi_suspension.tune.hinfstruct>` asks for nothing else.
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping
from typing import Protocol, runtime_checkable

import control
import numpy as np

from ..errors import DimensionError, InputError, NonFiniteError, ParameterError
from ..lti.checks import finite_scalar

__all__ = ["TunableBlock", "tunable_gain", "tunable_pid", "tunable_ss", "tunable_modal",
           "block_diagonal"]


@runtime_checkable
class TunableBlock(Protocol):
    """What :func:`~lmi_suspension.tune.hinfstruct` needs of a tunable block (see the
    module docstring)."""

    name: str
    ninputs: int
    noutputs: int
    nstates: int
    param_names: tuple

    @property
    def n_params(self) -> int: ...

    @property
    def start(self) -> np.ndarray: ...

    def matrices(self, theta) -> tuple: ...

    def jacobian(self, theta) -> np.ndarray: ...

    def ss(self, theta) -> control.StateSpace: ...

    def freqresp_derivative(self, theta, s) -> np.ndarray: ...

    def values(self, theta) -> dict: ...


def _size(value, label: str, *, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (numbers.Integral, np.integer)):
        raise DimensionError(f"{label} must be an integer, got {value!r}")
    if int(value) < minimum:
        raise DimensionError(f"{label} must be >= {minimum}, got {value!r}")
    return int(value)




class _Block:
    """A block whose matrices are functions of a full parameter vector, some of whose
    entries are free.  Subclasses give ``_labels`` (short names), a default full vector,
    ``_full_matrices(p)`` and ``_full_jacobian(p)`` (one slice per full parameter)."""

    #: kind of block, for ``repr``
    kind = "block"

    def __init__(self, name, noutputs, ninputs, nstates, labels, default, *,
                 start=None, fixed=None, positive=()):
        if not isinstance(name, str) or not name:
            raise ParameterError(f"a block's name must be a non-empty string, got {name!r}")
        self.name = name
        self.noutputs, self.ninputs, self.nstates = noutputs, ninputs, nstates
        self._labels = tuple(labels)
        full = np.array(default, dtype=float)
        free = np.ones(full.size, dtype=bool)
        for value, label, make_fixed in ((start, "start", False), (fixed, "fixed", True)):
            if value is None:
                continue
            if not isinstance(value, Mapping):
                raise ParameterError(f"{label} must be a mapping of parameter names to "
                                     f"values, got {type(value).__name__}")
            for key, v in value.items():
                k = self._index(key)
                full[k] = finite_scalar(v, f"{label}[{key!r}]")
                if make_fixed:
                    free[k] = False
        for k in positive:
            if not full[k] > 0:
                raise ParameterError(f"{self._full_name(k)} must be positive, got {full[k]!r}")
        if not free.any():
            raise ParameterError(f"block {name!r} has no free parameter")
        self._default = full
        self._free = np.flatnonzero(free)
        self._positive = np.array([k in positive for k in range(full.size)])
        self.param_names = tuple(self._full_name(k) for k in self._free)

    # ----------------------------------------------------------------- names
    def _full_name(self, k: int) -> str:
        return f"{self.name}.{self._labels[k]}"

    def _index(self, key) -> int:
        if isinstance(key, str):
            short = key[len(self.name) + 1:] if key.startswith(self.name + ".") else key
            if short in self._labels:
                return self._labels.index(short)
        raise ParameterError(f"block {self.name!r} has no parameter {key!r}; "
                             f"its parameters are {', '.join(self._labels)}")

    @property
    def n_params(self) -> int:
        """Number of free parameters."""
        return int(self._free.size)

    @property
    def start(self) -> np.ndarray:
        """Default starting values of the free parameters (a copy)."""
        return self._default[self._free].copy()

    @property
    def positive(self) -> np.ndarray:
        """Which free parameters must stay positive (a time constant): random starts
        perturb those multiplicatively."""
        return self._positive[self._free].copy()

    def __repr__(self) -> str:
        return (f"<{self.kind} {self.name!r}: {self.noutputs}x{self.ninputs}, "
                f"{self.nstates} states, parameters {', '.join(self.param_names)}>")

    # ----------------------------------------------------------------- values
    def _theta(self, theta) -> np.ndarray:
        try:
            theta = np.asarray(theta, dtype=float)
        except (TypeError, ValueError) as exc:
            raise InputError(f"theta of block {self.name!r} must be numeric: {exc}") from exc
        if theta.shape != (self.n_params,):
            raise DimensionError(f"block {self.name!r} has {self.n_params} free parameters; "
                                 f"theta has shape {theta.shape}")
        return theta

    def _full(self, theta) -> np.ndarray:
        p = self._default.copy()
        p[self._free] = theta
        return p

    def matrices(self, theta) -> tuple:
        """``(A, B, C, D)`` at the free parameters ``theta``."""
        return self._full_matrices(self._full(self._theta(theta)))

    def jacobian(self, theta) -> np.ndarray:
        """``d[[D, C], [B, A]]/dθ_i`` for each free parameter, shape
        ``(n_params, noutputs + nstates, ninputs + nstates)``."""
        return self._full_jacobian(self._full(self._theta(theta)))[self._free]

    def ss(self, theta) -> control.StateSpace:
        """The block at ``theta`` as a :class:`control.StateSpace`."""
        theta = self._theta(theta)
        if not np.all(np.isfinite(theta)):
            raise NonFiniteError(f"theta of block {self.name!r} holds NaN or infinity")
        A, B, C, D = self.matrices(theta)
        return control.ss(A, B, C, D)

    def values(self, theta) -> dict:
        """The free parameters by name, as floats."""
        return {n: float(v) for n, v in zip(self.param_names, self._theta(theta))}

    def freqresp_derivative(self, theta, s) -> np.ndarray:
        """``dK/dθ_i(s)`` at the complex point(s) ``s`` (``s = inf`` gives ``dD/dθ_i``).

        Returns an array of shape ``(n_params, noutputs, ninputs)`` for a scalar ``s``,
        with a trailing axis over the points for an array.
        """
        theta = self._theta(theta)
        return _freqresp_derivative(self, theta, s)


def _freqresp_derivative(block, theta, s) -> np.ndarray:
    """``dK/dθ_i`` of ``block`` at the point(s) ``s``, from its matrices and Jacobian."""
    A, B, C, _ = block.matrices(theta)
    J = block.jacobian(theta)
    points = np.atleast_1d(np.asarray(s, dtype=complex))
    out = np.empty((block.n_params, block.noutputs, block.ninputs, points.size), dtype=complex)
    for k, sk in enumerate(points):
        out[..., k] = _derivative_at(A, B, C, J, block.noutputs, block.ninputs, sk)
    return out[..., 0] if np.ndim(s) == 0 else out


def _derivative_at(A, B, C, J, no, ni, s) -> np.ndarray:
    n = A.shape[0]
    if n == 0 or not np.isfinite(s):
        return J[:, :no, :ni].astype(complex)
    X = np.linalg.solve(s * np.eye(n) - A, np.hstack([B, np.eye(n)]))
    left = np.hstack([np.eye(no), C @ X[:, ni:]])            # [I, C (sI - A)^-1]
    right = np.vstack([np.eye(ni), X[:, :ni]])               # [I; (sI - A)^-1 B]
    return left @ J @ right


# --------------------------------------------------------------------------- gain
class _Gain(_Block):
    kind = "tunable gain"

    def __init__(self, name, ny, nu, *, start=None, fixed=None):
        ny, nu = _size(ny, "ny", minimum=1), _size(nu, "nu", minimum=1)
        labels = ["k"] if ny == nu == 1 else [f"k[{i},{j}]" for i in range(ny) for j in range(nu)]
        super().__init__(name, ny, nu, 0, labels, np.zeros(ny * nu), start=start, fixed=fixed)

    def _full_matrices(self, p):
        return (np.zeros((0, 0)), np.zeros((0, self.ninputs)), np.zeros((self.noutputs, 0)),
                p.reshape(self.noutputs, self.ninputs))

    def _full_jacobian(self, p):
        return np.eye(p.size).reshape(p.size, self.noutputs, self.ninputs)


def tunable_gain(name: str, ny: int, nu: int, *, start=None, fixed=None):
    """A tunable static gain ``u = K y`` (``ny`` outputs, ``nu`` inputs, MATLAB's order).

    Parameters
    ----------
    name : str
        Block name; the parameters are ``name.k`` for a 1 × 1 gain and ``name.k[i,j]``
        (0-based, row-major) otherwise.
    ny, nu : int
        Numbers of outputs (controls) and inputs (measurements), at least 1.
    start, fixed : mapping of str to float, optional
        Starting values (default 0) and parameters held at a value, by short or full name.

    Returns
    -------
    TunableBlock

    Raises
    ------
    DimensionError
        A size below 1.
    ParameterError, NonFiniteError
        An unknown parameter name, a non-finite value, or every parameter fixed.

    Examples
    --------
    >>> K = tunable_gain("K", 1, 2)
    >>> K.param_names
    ('K.k[0,0]', 'K.k[0,1]')
    >>> K.ss([1.0, -2.0]).D.tolist()
    [[1.0, -2.0]]
    """
    return _Gain(name, ny, nu, start=start, fixed=fixed)


# --------------------------------------------------------------------------- PID
#: the PID's default starting values: unit proportional and integral gains, no derivative
#: action (its filter state then starts hidden and stable), a 0.01 s filter
_PID_START = {"kp": 1.0, "ki": 1.0, "kd": 0.0, "tf": 0.01}


class _Pid(_Block):
    kind = "tunable PID"

    def __init__(self, name, kind, tf, *, start=None, fixed=None):
        if kind not in ("P", "PI", "PD", "PID"):
            raise ParameterError(f"kind must be 'P', 'PI', 'PD' or 'PID', got {kind!r}")
        self.pid_kind = kind
        labels = ["kp"] + (["ki"] if "I" in kind else []) + (["kd", "tf"] if "D" in kind else [])
        fixed = dict(fixed or {})
        if "D" in kind:
            if tf is not None:
                fixed["tf"] = finite_scalar(tf, "tf")
        elif tf is not None:
            raise ParameterError(f"tf applies to kinds 'PD' and 'PID', not {kind!r}")
        default = [_PID_START[k] for k in labels]
        nstates = ("I" in kind) + ("D" in kind)
        positive = (labels.index("tf"),) if "D" in kind else ()
        super().__init__(name, 1, 1, nstates, labels, default, start=start, fixed=fixed,
                         positive=positive)
        self._has_i, self._has_d = "I" in kind, "D" in kind

    def _parts(self, p):
        it = iter(p)
        kp = next(it)
        ki = next(it) if self._has_i else 0.0
        kd, tf = (next(it), next(it)) if self._has_d else (0.0, 1.0)
        return kp, ki, kd, tf

    def _full_matrices(self, p):
        # states [integrator, derivative filter]: K = kp + ki/s + kd s/(tf s + 1), with
        # kd s/(tf s + 1) = kd/tf - (kd/tf)(1/tf)/(s + 1/tf); the filter's input and
        # output gains split as 1/tf and -kd/tf (not 1 and -kd/tf²) to stay balanced
        kp, ki, kd, tf = self._parts(p)
        if tf == 0.0:
            tf = np.nan                     # no filter: a non-finite block, rejected by lft
        a, b, c = [], [], []
        if self._has_i:
            a.append(0.0), b.append(1.0), c.append(ki)
        if self._has_d:
            a.append(-1.0 / tf), b.append(1.0 / tf), c.append(-kd / tf)
        n = len(a)
        D = kp + (kd / tf if self._has_d else 0.0)
        return np.diag(a).reshape(n, n), np.array(b).reshape(n, 1), np.array(c).reshape(1, n), \
            np.array([[D]])

    def _full_jacobian(self, p):
        kp, ki, kd, tf = self._parts(p)
        n = self.nstates
        J = np.zeros((len(p), 1 + n, 1 + n))
        J[0, 0, 0] = 1.0                                   # kp: D
        k = 1
        if self._has_i:
            J[k, 0, 1] = 1.0                               # ki: C of the integrator
            k += 1
        if self._has_d:
            f = n                                          # the filter's row/column in Kbar
            J[k, 0, 0] = 1.0 / tf                          # kd: D and C of the filter
            J[k, 0, f] = -1.0 / tf
            J[k + 1, 0, 0] = -kd / tf**2                   # tf: D, C, B and A of the filter
            J[k + 1, 0, f] = kd / tf**2
            J[k + 1, f, 0] = -1.0 / tf**2
            J[k + 1, f, f] = 1.0 / tf**2
        return J


def tunable_pid(name: str, kind: str = "PID", *, tf: float | None = None, start=None,
                fixed=None):
    """A tunable continuous-time PID ``K(s) = kp + ki/s + kd s/(tf s + 1)``.

    Parameters
    ----------
    name : str
        Block name; the parameters are ``name.kp``, ``name.ki``, ``name.kd``, ``name.tf``
        (those of ``kind``).
    kind : {"P", "PI", "PD", "PID"}
        Which terms the controller has.
    tf : float, optional
        ``"PD"`` and ``"PID"`` only: a value fixes the derivative filter's time constant
        (s); ``None`` (default) makes ``name.tf`` a tunable parameter, started at 0.01 s
        and kept positive by the search (a negative ``tf`` is an unstable filter, which
        the closed loop's stability test rejects).
    start, fixed : mapping of str to float, optional
        Starting values and parameters held at a value, by short (``"kp"``) or full
        (``"C.kp"``) name.  The default start is ``kp = ki = 1``, ``kd = 0``,
        ``tf = 0.01``.

    Returns
    -------
    TunableBlock
        One input (the measurement), one output (the control); a state for the
        integrator (first) and one for the derivative filter.

    Raises
    ------
    ParameterError, NonFiniteError
        An unknown kind or parameter, ``tf`` for a kind without derivative, a
        non-positive ``tf``, a non-finite value, or every parameter fixed.

    Examples
    --------
    >>> C = tunable_pid("C", kind="PI")
    >>> C.param_names, C.start.tolist()
    (('C.kp', 'C.ki'), [1.0, 1.0])
    >>> import control
    >>> K = tunable_pid("C", "PID", tf=0.1).ss([2.0, 3.0, 0.5])   # kp, ki, kd
    >>> complex(control.evalfr(K, 1j)).real                      # 2 + 0.5 * 0.1/(0.01 + 1)
    2.0495049504950495
    """
    return _Pid(name, kind, tf, start=start, fixed=fixed)


# --------------------------------------------------------------------------- state space
def _ss_labels(order, ny, nu):
    labels, kinds = [], []
    i = 0
    while i < order:
        if i + 1 < order:                                  # a 2 x 2 block
            labels += [f"A[{i},{i}]", f"A[{i},{i + 1}]", f"A[{i + 1},{i + 1}]"]
            kinds.append(2)
            i += 2
        else:
            labels.append(f"A[{i},{i}]")
            kinds.append(1)
            i += 1
    labels += [f"B[{i},{j}]" for i in range(order) for j in range(nu)]
    labels += [f"C[{i},{j}]" for i in range(ny) for j in range(order)]
    labels += [f"D[{i},{j}]" for i in range(ny) for j in range(nu)]
    return labels, kinds


#: two eigenvalues closer than this (relative to the largest magnitude, floor 1) are
#: taken as a repeated one, whose modal realization is ill-conditioned or does not exist
_MODAL_SEPARATION = 1e-8


def _modal_parameters(K, order, ny, nu, kinds):
    """The full parameter vector of a ``tunable_ss`` block realizing the continuous-time
    controller ``K``: a modal realization (``scipy.linalg.cdf2rdf`` form), complex pairs
    first, then the real poles paired into ``[[λ1, 0], [0, λ2]]`` blocks, an odd one
    last -- the pattern of ``kinds`` (the parity of the real poles is that of the order,
    so the pattern always fits)."""
    if not isinstance(K, control.StateSpace) or not K.isctime():
        raise ParameterError("a start controller must be a continuous-time StateSpace")
    A, B, C, D = (np.atleast_2d(np.asarray(M, dtype=float)) for M in (K.A, K.B, K.C, K.D))
    if (K.noutputs, K.ninputs) != (ny, nu) or K.nstates != order:
        raise DimensionError(f"the start controller has {K.noutputs} outputs, {K.ninputs} "
                             f"inputs and {K.nstates} states; the block {ny}, {nu} and {order}")
    if not all(np.all(np.isfinite(M)) for M in (A, B, C, D)):
        raise NonFiniteError("the start controller holds NaN or infinity")
    if order == 0:
        return D.ravel()
    lam, V = np.linalg.eig(A)
    scale = max(1.0, float(np.max(np.abs(lam))))
    gaps = np.abs(lam[:, None] - lam[None, :])
    np.fill_diagonal(gaps, np.inf)
    if np.min(gaps) < _MODAL_SEPARATION * scale or np.linalg.cond(V) > 1e12:
        raise ParameterError("the start controller has a repeated pole: a tunable_ss block "
                             "(2 x 2 modal blocks) realizes distinct poles only")
    cplx = [k for k in range(order) if lam[k].imag > 0]
    real = [k for k in range(order) if lam[k].imag == 0 or
            abs(lam[k].imag) <= _MODAL_SEPARATION * scale]
    cols, a_part = [], []
    for k in cplx:                           # A [Re v, Im v] = [Re v, Im v] [[σ, ω], [-ω, σ]]
        v = V[:, k] / np.linalg.norm(V[:, k])        # one scale for the pair keeps that form
        cols += [v.real, v.imag]
        a_part += [lam[k].real, lam[k].imag, lam[k].real]
    real = sorted(real, key=lambda k: lam[k].real)
    for j in range(0, len(real) - 1, 2):
        cols += [V[:, real[j]].real, V[:, real[j + 1]].real]
        a_part += [lam[real[j]].real, 0.0, lam[real[j + 1]].real]
    if len(real) % 2:
        cols.append(V[:, real[-1]].real)
        a_part.append(lam[real[-1]].real)
    T = np.column_stack(cols)
    Bm, Cm = np.linalg.solve(T, B), C @ T
    return np.concatenate([a_part, Bm.ravel(), Cm.ravel(), D.ravel()])


class _StateSpace(_Block):
    kind = "tunable state space"

    def __init__(self, name, order, ny, nu, *, start=None, fixed=None):
        order = _size(order, "order", minimum=0)
        ny, nu = _size(ny, "ny", minimum=1), _size(nu, "nu", minimum=1)
        labels, self._kinds = _ss_labels(order, ny, nu)
        # A = -diag(1, 2, ..., order) (distinct real modes: with equal ones, equal B and
        # C = 0 the gradient keeps the states identical and the block acts as one state),
        # B = 1, C = 0, D = 0: K = 0 at the start
        diag = -np.arange(1.0, order + 1.0)
        a_part, i = [], 0
        for k in self._kinds:
            a_part += [diag[i], 0.0, diag[i + 1]] if k == 2 else [diag[i]]
            i += k
        default = np.concatenate([np.array(a_part), np.ones(order * nu),
                                  np.zeros(ny * order + ny * nu)])
        if isinstance(start, control.StateSpace):
            start = dict(zip(labels, _modal_parameters(start, order, ny, nu, self._kinds)))
        super().__init__(name, ny, nu, order, labels, default, start=start, fixed=fixed)

    def _full_matrices(self, p):
        n, ny, nu = self.nstates, self.noutputs, self.ninputs
        A = np.zeros((n, n))
        i = k = 0
        for kind in self._kinds:
            if kind == 2:
                A[i, i], A[i, i + 1], A[i + 1, i + 1] = p[k], p[k + 1], p[k + 2]
                A[i + 1, i] = -p[k + 1]
                k += 3
            else:
                A[i, i] = p[k]
                k += 1
            i += kind
        B = p[k:k + n * nu].reshape(n, nu)
        k += n * nu
        C = p[k:k + ny * n].reshape(ny, n)
        k += ny * n
        return A, B, C, p[k:].reshape(ny, nu)

    def _full_jacobian(self, p):
        n, ny, nu = self.nstates, self.noutputs, self.ninputs
        J = np.zeros((p.size, ny + n, nu + n))
        i = k = 0
        for kind in self._kinds:            # A sits at rows ny + i, columns nu + j
            if kind == 2:
                J[k, ny + i, nu + i] = 1.0
                J[k + 1, ny + i, nu + i + 1] = 1.0
                J[k + 1, ny + i + 1, nu + i] = -1.0
                J[k + 2, ny + i + 1, nu + i + 1] = 1.0
                k += 3
            else:
                J[k, ny + i, nu + i] = 1.0
                k += 1
            i += kind
        for r in range(n):                  # B
            for c in range(nu):
                J[k, ny + r, c] = 1.0
                k += 1
        for r in range(ny):                 # C
            for c in range(n):
                J[k, r, nu + c] = 1.0
                k += 1
        for r in range(ny):                 # D
            for c in range(nu):
                J[k, r, c] = 1.0
                k += 1
        return J


def tunable_ss(name: str, order: int, ny: int, nu: int, *, start=None, fixed=None):
    """A tunable fixed-order state-space block with a block-diagonal ``A``.

    ``A`` is block diagonal with 2 × 2 blocks ``[[a, b], [-b, d]]`` (and one 1 × 1 block
    ``[a]`` when ``order`` is odd); ``B``, ``C`` and ``D`` are free.  Why this form:

    * it is generic: a 2 × 2 block holds any pair of poles, real (``|a - d| > 2|b|``,
      e.g. ``b = 0`` with the two poles on the diagonal) or complex
      (``a = d = σ``, ``b = ω`` for ``σ ± jω``), so every controller with distinct
      poles has a realization of this form;
    * it stays well conditioned: both canonical cases are normal matrices (eigenvector
      condition number 1), and the blocks decouple, so a parameter moves one pair of
      poles; a full ``A`` (MATLAB's default) carries ``order²`` entries for ``order``
      poles and can drift, along its similarity directions, into realizations whose
      poles move by large amounts under round-off, and a companion form has entries of
      the size of products of the poles;
    * it has ``3 order / 2`` parameters in ``A`` instead of ``order²``.

    What is not covered: a (nearly) defective double real pole, and coupling between
    blocks (which a similarity removes anyway).  ``B`` and ``C`` keep the usual
    redundancy of a realization (a state scaled up and its output gain down): a flat
    direction of the objective.  Fixing one entry of ``B`` per block removes it
    (``fixed={"B[0,0]": 1.0, "B[2,0]": 1.0, ...}``); on three plants of 3-4 states
    (tests/test_tune.py, full order, 2 starts) that ended 1.7, 3.9 and 10 % above the
    optimum against 2.2, 4.7 and 7.0 % with ``B`` free (measured 2026-12-02): no
    consistent gain, so ``B`` stays free by default.

    Parameters
    ----------
    name : str
        Block name; the parameters are ``name.A[i,j]`` (the free entries: the diagonal
        and, per 2 × 2 block, ``A[i,i+1]``, with ``A[i+1,i] = -A[i,i+1]``),
        ``name.B[i,j]``, ``name.C[i,j]`` and ``name.D[i,j]``, 0-based.
    order : int
        Number of states (0 gives a static gain ``D``).
    ny, nu : int
        Numbers of outputs (controls) and inputs (measurements), MATLAB's order.
    start : mapping of str to float, or control.StateSpace, optional
        Starting values by short (``"D[0,0]"``) or full name; or a controller of this
        order (as MATLAB's ``hinfstruct`` starts from a block's current value), realized
        in the block's modal form (its poles must be distinct).  The default start is
        ``A = -diag(1, 2, ..., order)``, ``B = 1``, ``C = 0``, ``D = 0`` (the block starts
        at ``K = 0``, its modes distinct).
    fixed : mapping of str to float, optional
        Parameters held at a value, by short or full name.

    Returns
    -------
    TunableBlock

    Raises
    ------
    DimensionError
        A negative order or a size below 1; a start controller of another size.
    ParameterError, NonFiniteError
        An unknown parameter name, a non-finite value, every parameter fixed, or a start
        controller with a repeated pole.

    Examples
    --------
    >>> K = tunable_ss("K", 3, 1, 1)
    >>> K.n_params, K.param_names[:4]
    (11, ('K.A[0,0]', 'K.A[0,1]', 'K.A[1,1]', 'K.A[2,2]'))
    >>> theta = K.start
    >>> theta[:3] = [-1.0, 2.0, -1.0]                     # the pair -1 ± 2j
    >>> sorted(K.ss(theta).poles().round(6).tolist(), key=lambda p: p.imag)
    [(-1-2j), (-3+0j), (-1+2j)]

    Started from a given controller (the same transfer function, another realization):

    >>> import control
    >>> K0 = control.ss(control.tf([1.0, 3.0], [1.0, 2.0, 5.0]))
    >>> K = tunable_ss("K", 2, 1, 1, start=K0)
    >>> bool(np.allclose(control.evalfr(K.ss(K.start), 2j), control.evalfr(K0, 2j)))
    True
    """
    return _StateSpace(name, order, ny, nu, start=start, fixed=fixed)


# --------------------------------------------------------------------------- stable modal
def _modal_kinds(A) -> list:
    """The block pattern (1: ``[a]``, 2: ``[[σ, ω], [-ω, σ]]``) of a real modal ``A``."""
    n, kinds, i = A.shape[0], [], 0
    while i < n:
        k = 2 if i + 1 < n and A[i, i + 1] != 0.0 else 1
        kinds.append(k)
        i += k
    return kinds


class _StableModal(_Block):
    kind = "tunable stable modal state space"

    def __init__(self, name, start, *, pole_bounds=None):
        if not isinstance(start, control.StateSpace) or not start.isctime():
            raise ParameterError("tunable_modal needs a continuous-time StateSpace start")
        A, B, C, D = (np.atleast_2d(np.asarray(M, dtype=float))
                      for M in (start.A, start.B, start.C, start.D))
        n, no, ni = A.shape[0], D.shape[0], D.shape[1]
        if not all(np.all(np.isfinite(M)) for M in (A, B, C, D)):
            raise NonFiniteError("the start controller holds NaN or infinity")
        kinds = _modal_kinds(A)
        expect, labels, poles, i = np.zeros_like(A), [], [], 0
        for k in kinds:
            if k == 1:
                expect[i, i] = A[i, i]
                labels.append(f"ln(-a[{i}])")
                poles.append(-A[i, i])
            else:
                sigma, omega = A[i, i], A[i, i + 1]
                expect[i:i + 2, i:i + 2] = [[sigma, omega], [-omega, sigma]]
                labels += [f"ln(-sigma[{i}])", f"ln(omega[{i}])"]
                poles += [-sigma, omega]
            i += k
        if not np.array_equal(A, expect) or not np.all(np.asarray(poles) > 0):
            raise ParameterError("tunable_modal needs a stable real modal start: 1 x 1 "
                                 "blocks [a], a < 0, and 2 x 2 blocks [[s, w], [-w, s]], s < "
                                 "0 < w (seat.refine.modal_form gives one)")
        self._kinds, self.n_poles = kinds, len(poles)
        labels += [f"B[{r},{c}]" for r in range(n) for c in range(ni)]
        labels += [f"C[{r},{c}]" for r in range(no) for c in range(n)]
        labels += [f"D[{r},{c}]" for r in range(no) for c in range(ni)]
        gains = np.concatenate([B.ravel(), C.ravel(), D.ravel()])
        # each gain in units of its own magnitude; an entry that is zero (a rotated pair's
        # second output gain) in a tenth of its mode's
        mode = np.sqrt(np.sum(B ** 2, axis=1) + np.sum(C ** 2, axis=0))
        floor = np.concatenate([np.repeat(mode, ni), np.tile(mode, no),
                                np.full(D.size, np.linalg.norm(D))]) * 0.1
        floor = np.maximum(floor, 1e-12)
        self._scale = np.concatenate([np.ones(self.n_poles), np.maximum(np.abs(gains), floor)])
        # one logarithm at a time, as a scalar: the seat's shipped refinement was started so
        x0 = np.concatenate([[np.log(v) for v in poles], gains])
        super().__init__(name, no, ni, n, labels, x0 / self._scale)
        self.lower = np.full(self.n_params, -np.inf)
        self.upper = np.full(self.n_params, np.inf)
        if pole_bounds is not None:
            lo, hi = pole_bounds
            if not (0 < float(lo) < float(hi) < np.inf):
                raise ParameterError(f"pole_bounds must be 0 < low < high < inf, got "
                                     f"{pole_bounds!r}")
            self.lower[:self.n_poles] = np.log(float(lo))
            self.upper[:self.n_poles] = np.log(float(hi))

    def _full_matrices(self, p):
        x = p * self._scale
        n, ny, nu = self.nstates, self.noutputs, self.ninputs
        A = np.zeros((n, n))
        i = j = 0
        for k in self._kinds:
            if k == 1:
                A[i, i] = -np.exp(x[j])
            else:
                sigma, omega = -np.exp(x[j]), np.exp(x[j + 1])
                A[i:i + 2, i:i + 2] = [[sigma, omega], [-omega, sigma]]
            i, j = i + k, j + k
        B = x[j:j + n * nu].reshape(n, nu)
        C = x[j + n * nu:j + n * nu + ny * n].reshape(ny, n)
        D = x[j + n * nu + ny * n:].reshape(ny, nu)
        return A, B, C, D

    def _full_jacobian(self, p):
        x = p * self._scale
        n, ny, nu = self.nstates, self.noutputs, self.ninputs
        J = np.zeros((p.size, ny + n, nu + n))
        i = j = 0
        for k in self._kinds:            # A sits at rows ny + i, columns nu + i
            if k == 1:
                J[j, ny + i, nu + i] = -np.exp(x[j])
            else:
                J[j, ny + i, nu + i] = J[j, ny + i + 1, nu + i + 1] = -np.exp(x[j])
                J[j + 1, ny + i, nu + i + 1] = np.exp(x[j + 1])
                J[j + 1, ny + i + 1, nu + i] = -np.exp(x[j + 1])
            i, j = i + k, j + k
        for r in range(n):               # B
            for c in range(nu):
                J[j, ny + r, c] = self._scale[j]
                j += 1
        for r in range(ny):              # C
            for c in range(n):
                J[j, r, nu + c] = self._scale[j]
                j += 1
        for r in range(ny):              # D
            for c in range(nu):
                J[j, r, c] = self._scale[j]
                j += 1
        return J


def tunable_modal(name: str, start: control.StateSpace, *, pole_bounds=None):
    """A tunable state-space block in stable real modal form, in normalised parameters.

    ``A`` is block diagonal with blocks ``[a]`` and ``[[σ, ω], [-ω, σ]]``, parametrised by
    ``ln(-a)``, ``ln(-σ)`` and ``ln ω``, so every parameter value gives a stable block
    with the start's pattern of real poles and pairs; ``B``, ``C`` and ``D`` are free,
    each entry in units of its start's magnitude (an entry that starts at zero in a tenth
    of its mode's gain), so that a step of 0.1 in any parameter moves any gain by about
    10 % and any pole by a factor ``e^0.1``: one trust region suits all parameters (the
    seat's refinement, :func:`~lmi_suspension.seat.refine.refine_seat_controller`,
    tunes its controller so).  Use it to refine a given controller; :func:`tunable_ss`
    to search from scratch.

    Parameters
    ----------
    name : str
    start : control.StateSpace
        A continuous-time controller in stable real modal form (its ``A`` exactly of the
        block pattern above, e.g. from :func:`~lmi_suspension.seat.refine.modal_form`);
        one without states gives a static gain in the same units.
    pole_bounds : (float, float), optional
        Every pole parameter (``-a``, ``-σ``, ``ω``) within ``[low, high]``, rad/s:
        the block's ``lower`` and ``upper`` bounds, which the SLSQP route of
        :func:`~lmi_suspension.tune.systune` respects.

    Returns
    -------
    TunableBlock
        Also with ``n_poles`` (the pole parameters come first), ``lower`` and ``upper``.

    Raises
    ------
    ParameterError, NonFiniteError
        A start not in stable real modal form, or with non-finite entries.

    Examples
    --------
    >>> import control
    >>> K0 = control.ss([[-1.0, 2.0], [-2.0, -1.0]], [[1.0], [0.5]], [[3.0, 0.0]], [[0.0]])
    >>> K = tunable_modal("K", K0)
    >>> K.param_names[:2], K.n_poles
    (('K.ln(-sigma[0])', 'K.ln(omega[0])'), 2)
    >>> bool(np.allclose(K.ss(K.start).A, K0.A))
    True
    """
    return _StableModal(name, start, pole_bounds=pole_bounds)


# --------------------------------------------------------------------------- block diagonal
class _BlockDiagonal:
    """Several blocks as one: ``K = diag(K_1, ..., K_m)``, inputs, outputs, states and
    parameters stacked in the blocks' order.  It satisfies :class:`TunableBlock`."""

    kind = "block diagonal"

    def __init__(self, blocks):
        self.blocks = tuple(blocks)
        names = [n for b in self.blocks for n in b.param_names]
        seen = set()
        for n in names:
            if n in seen:
                raise ParameterError(f"parameter {n!r} appears in two blocks: give the "
                                     f"blocks different names")
            seen.add(n)
        self.name = "+".join(b.name for b in self.blocks)
        self.param_names = tuple(names)
        self.ninputs = sum(b.ninputs for b in self.blocks)
        self.noutputs = sum(b.noutputs for b in self.blocks)
        self.nstates = sum(b.nstates for b in self.blocks)
        self._offsets = np.cumsum([0] + [b.n_params for b in self.blocks])

    @property
    def n_params(self) -> int:
        return int(self._offsets[-1])

    @property
    def start(self) -> np.ndarray:
        return np.concatenate([np.asarray(b.start, dtype=float) for b in self.blocks])

    @property
    def positive(self) -> np.ndarray:
        return np.concatenate([np.asarray(getattr(b, "positive", np.zeros(b.n_params, bool)),
                                          dtype=bool) for b in self.blocks])

    def _split(self, theta):
        theta = np.asarray(theta, dtype=float)
        if theta.shape != (self.n_params,):
            raise DimensionError(f"the blocks have {self.n_params} free parameters; theta "
                                 f"has shape {theta.shape}")
        return [theta[a:b] for a, b in zip(self._offsets[:-1], self._offsets[1:])]

    def matrices(self, theta) -> tuple:
        parts = [b.matrices(t) for b, t in zip(self.blocks, self._split(theta))]
        n, ni, no = self.nstates, self.ninputs, self.noutputs
        A, B, C, D = np.zeros((n, n)), np.zeros((n, ni)), np.zeros((no, n)), np.zeros((no, ni))
        r = c = s = 0
        for blk, (a, b, cc, d) in zip(self.blocks, parts):
            ks = slice(s, s + blk.nstates)
            ro, ci = slice(r, r + blk.noutputs), slice(c, c + blk.ninputs)
            A[ks, ks], B[ks, ci], C[ro, ks], D[ro, ci] = a, b, cc, d
            r, c, s = r + blk.noutputs, c + blk.ninputs, s + blk.nstates
        return A, B, C, D

    def jacobian(self, theta) -> np.ndarray:
        no, ni = self.noutputs, self.ninputs
        J = np.zeros((self.n_params, no + self.nstates, ni + self.nstates))
        r = c = s = 0
        for blk, t, off in zip(self.blocks, self._split(theta), self._offsets):
            Jb = np.asarray(blk.jacobian(t), dtype=float)
            bo, bi = blk.noutputs, blk.ninputs
            rows = np.r_[r:r + bo, no + s:no + s + blk.nstates]
            cols = np.r_[c:c + bi, ni + s:ni + s + blk.nstates]
            J[off:off + blk.n_params][:, rows[:, None], cols[None, :]] = Jb
            r, c, s = r + bo, c + bi, s + blk.nstates
        return J

    def ss(self, theta) -> control.StateSpace:
        theta = np.asarray(theta, dtype=float)
        if not np.all(np.isfinite(theta)):
            raise NonFiniteError("theta holds NaN or infinity")
        return control.ss(*self.matrices(theta))

    def values(self, theta) -> dict:
        out = {}
        for b, t in zip(self.blocks, self._split(theta)):
            out.update(b.values(t))
        return out

    def freqresp_derivative(self, theta, s) -> np.ndarray:
        theta = np.asarray(theta, dtype=float)
        return _freqresp_derivative(self, theta, s)


_BLOCK_ATTRIBUTES = ("name", "ninputs", "noutputs", "nstates", "param_names", "n_params",
                     "start", "matrices", "jacobian", "ss", "values")


def block_diagonal(blocks):
    """One tunable block from one block or a sequence of them (``K = diag(K_1, ...)``).

    Raises
    ------
    ParameterError
        An empty sequence, an object that is not a tunable block (a gain surface without
        its scheduling point included), or two blocks whose parameters share a name.

    Examples
    --------
    >>> K = block_diagonal([tunable_gain("K1", 1, 1), tunable_pid("K2", "PI")])
    >>> K.param_names, (K.noutputs, K.ninputs, K.nstates)
    (('K1.k', 'K2.kp', 'K2.ki'), (2, 2, 1))
    """
    items = [blocks] if not isinstance(blocks, (list, tuple)) else list(blocks)
    if not items:
        raise ParameterError("no tunable block given")
    for b in items:
        if hasattr(b, "scheduling") and hasattr(b, "at"):
            raise ParameterError(
                f"block {getattr(b, 'name', b)!r} depends on a scheduling point: give it "
                f"one with .at(...), or tune it over models with systune")
        missing = [a for a in _BLOCK_ATTRIBUTES if not hasattr(b, a)]
        if missing:
            raise ParameterError(f"{b!r} is not a tunable block: it lacks {', '.join(missing)}")
        if int(b.n_params) < 1:
            raise ParameterError(f"block {b.name!r} has no free parameter")
    return items[0] if len(items) == 1 else _BlockDiagonal(items)
