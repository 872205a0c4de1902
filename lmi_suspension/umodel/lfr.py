"""Linear fractional representation (LFR) of uncertain matrices and systems.

Every uncertain object is an upper LFT ``F_u(M, Δ)`` of a *certain* system ``M``
(possibly without states) and a block-diagonal normalised uncertainty
``Δ = diag(Δ_1, ..., Δ_m)``::

    ẋ = A x  + Bw w  + Bu u
    z = Cz x + Dzw w + Dzu u        w = Δ z
    y = Cy x + Dyw w + Dyu u

One block per uncertain element (atom): ``δ I_r`` for a real or complex parameter
entering ``r`` times, ``Δ(s)`` (``ny × nu``, normalised by its bound) for an
``ultidyn``.

Arithmetic (``+ - * /``, unary minus, inverse, concatenation, feedback, named
interconnection) is one operation, :func:`interconnect_parts`: the parts are
appended and closed through a static interconnection of their certain inputs and
outputs, which is the textbook LFT sum/product/feedback formula written once.
Afterwards the blocks of each atom are merged and the representation is *reduced*
(:func:`reduce_lfr`) by an n-D (structured) Kalman decomposition: the smallest
block-structured subspace that contains the range of the input matrix and is
invariant under the loop matrix (iterated ``V_k <- span(V_k ∪ P_k A_nd V)``), then
the same for the transposed system, and a projection onto it.  States are a frozen
block (kept whole, so the dynamics, stable or not, are never removed), as are full
``ultidyn`` blocks; only repeated scalar blocks are reduced.  The projection is exact:
``F_u`` is unchanged for every ``Δ``.
"""

from __future__ import annotations

import logging
import numbers
from dataclasses import dataclass
from itertools import pairwise

import control
import numpy as np
import scipy.linalg

from ..errors import DimensionError, IllPosedLoopError, InputError, NonFiniteError, ParameterError
from ..lti.checks import as_statespace

__all__ = ["UBlock", "UMat", "USS", "as_uncertain", "interconnect_parts", "reduce_lfr", "umat"]

logger = logging.getLogger(__name__)

#: relative rank tolerance of the structured Kalman reduction (see _reach)
_REDUCE_RTOL = 1e-10


class _Atom:
    """Base of the uncertain elements of :mod:`.atoms`: their arithmetic is that of their
    LFR.  The LFR asks of an atom only its ``kind`` -- ``"real"`` (``nominal`` and
    ``lfr_coefficients``), ``"complex"`` (``nominal``, ``radius``) or ``"dynamic"``
    (``ny``, ``nu``, ``bound``) -- so this module does not know the atoms' classes."""

    kind = ""
    __array_ufunc__ = None  # numpy defers to our reflected operators

    def _lfr(self):
        return as_uncertain(self)

    def __add__(self, other):
        return self._lfr() + other

    def __radd__(self, other):
        return self._lfr().__radd__(other)

    def __sub__(self, other):
        return self._lfr() - other

    def __rsub__(self, other):
        return self._lfr().__rsub__(other)

    def __mul__(self, other):
        return self._lfr() * other

    def __rmul__(self, other):
        return self._lfr().__rmul__(other)

    def __truediv__(self, other):
        return self._lfr() / other

    def __rtruediv__(self, other):
        return self._lfr().__rtruediv__(other)

    def __neg__(self):
        return -self._lfr()

    def __pos__(self):
        return self._lfr()


def _scalar(atom) -> bool:
    """True for an atom whose block is ``δ I`` (real, complex, or a SISO ``ultidyn``)."""
    return atom.kind != "dynamic" or (atom.ny == 1 and atom.nu == 1)


@dataclass(frozen=True)
class UBlock:
    """One block of Δ: ``nw × nz`` (``w = Δ z``) for ``atom``.

    Scalar atoms have ``nw == nz == r`` (the repetition); an ``ultidyn`` ``ny × nu``
    has ``nw = ny``, ``nz = nu`` (or ``r × r`` for a repeated SISO one).
    """

    atom: object
    nw: int
    nz: int

    @property
    def reducible(self) -> bool:
        """True for repeated scalar blocks (``δ I_r`` commutes with any ``r × r`` basis)."""
        return _scalar(self.atom)

    @property
    def blk_row(self) -> list[int]:
        """MATLAB ``mussv`` row of this block."""
        a = self.atom
        if a.kind == "real":
            return [-self.nw, 0]
        if a.kind == "complex" or (self.nw > 1 and _scalar(a)):
            return [self.nw, 0]
        return [self.nw, self.nz]


def _slices(sizes):
    edges = [0, *np.cumsum(sizes).astype(int).tolist()]
    return [slice(a, b) for a, b in pairwise(edges)]


class _Uncertain:
    """Common base of :class:`UMat` (static) and :class:`USS` (dynamic)."""

    __array_ufunc__ = None  # numpy arrays defer to our reflected operators

    def __init__(self, A, B, C, D, blocks, *, inputs=None, outputs=None):
        self.A = np.asarray(A, dtype=float)
        self.B = np.asarray(B, dtype=float)
        self.C = np.asarray(C, dtype=float)
        self.D = np.asarray(D, dtype=float)
        self.blocks = tuple(blocks)
        self.nw = sum(b.nw for b in self.blocks)
        self.nz = sum(b.nz for b in self.blocks)
        n = self.A.shape[0]
        nu = self.B.shape[1] - self.nw
        ny = self.C.shape[0] - self.nz
        self._shape = (ny, nu)
        if self.A.shape != (n, n) or self.D.shape != (self.nz + ny, self.nw + nu) or self.C.shape[1] != n:
            raise DimensionError("inconsistent LFR matrices")
        self.input_labels = list(inputs) if inputs is not None else [f"u[{i}]" for i in range(nu)]
        self.output_labels = list(outputs) if outputs is not None else [f"y[{i}]" for i in range(ny)]
        if len(self.input_labels) != nu or len(self.output_labels) != ny:
            raise DimensionError(f"need {nu} input and {ny} output names")

    # ------------------------------------------------------------------ sizes / parts
    @property
    def shape(self) -> tuple[int, int]:
        """``(outputs, inputs)``."""
        return self._shape

    @property
    def nstates(self) -> int:
        """Number of states of the certain part."""
        return self.A.shape[0]

    @property
    def ninputs(self) -> int:
        return self._shape[1]

    @property
    def noutputs(self) -> int:
        return self._shape[0]

    @property
    def uncertainty(self) -> dict:
        """``{name: atom}`` of the uncertain elements, in block order."""
        return {b.atom.name: b.atom for b in self.blocks}

    def partition(self):
        """``(A, Bw, Bu, Cz, Cy, Dzw, Dzu, Dyw, Dyu)``."""
        nw, nz = self.nw, self.nz
        return (self.A, self.B[:, :nw], self.B[:, nw:], self.C[:nz], self.C[nz:],
                self.D[:nz, :nw], self.D[:nz, nw:], self.D[nz:, :nw], self.D[nz:, nw:])

    def __repr__(self):
        reps = ", ".join(f"{b.atom.name}:{max(b.nw, b.nz) if b.reducible else f'{b.nw}x{b.nz}'}"
                         for b in self.blocks)
        return (f"{type(self).__name__}({self.noutputs}x{self.ninputs}, states={self.nstates}, "
                f"blocks=[{reps}])")

    # ------------------------------------------------------------------ arithmetic
    def _kind(self, other):
        return USS if (isinstance(self, USS) or isinstance(other, USS)) else UMat

    def __add__(self, other):
        other = as_uncertain(other)
        a, b = _broadcast_add(self, other)
        p, m = a.shape
        return interconnect_parts([a, b], F=np.zeros((2 * m, 2 * p)),
                                  E=np.vstack([np.eye(m), np.eye(m)]),
                                  H=np.hstack([np.eye(p), np.eye(p)]), J=np.zeros((p, m)),
                                  cls=self._kind(other))

    def __radd__(self, other):
        return as_uncertain(other).__add__(self)

    def __neg__(self):
        out = _copy(self)
        out.C = out.C.copy()
        out.D = out.D.copy()
        out.C[self.nz:] *= -1
        out.D[self.nz:] *= -1
        return out

    def __pos__(self):
        return self

    def __sub__(self, other):
        return self + (-as_uncertain(other))

    def __rsub__(self, other):
        return as_uncertain(other) + (-self)

    def __mul__(self, other):
        """``self * other``: ``other`` first, then ``self`` (a matrix product)."""
        other = as_uncertain(other)
        a, b = self, other
        if a.shape[1] != b.shape[0]:
            if a.shape == (1, 1):
                a = _scalar_times_identity(a, b.shape[0])
            elif b.shape == (1, 1):
                b = _scalar_times_identity(b, a.shape[1])
            else:
                raise DimensionError(f"cannot multiply {a.shape} by {b.shape}")
        p, k = a.shape
        m = b.shape[1]
        F = np.zeros((k + m, p + k))
        F[:k, p:] = np.eye(k)  # a's input <- b's output
        E = np.vstack([np.zeros((k, m)), np.eye(m)])
        H = np.hstack([np.eye(p), np.zeros((p, k))])
        return interconnect_parts([a, b], F=F, E=E, H=H, J=np.zeros((p, m)), cls=self._kind(other))

    def __rmul__(self, other):
        return as_uncertain(other).__mul__(self)

    def __matmul__(self, other):
        return self.__mul__(other)

    def __rmatmul__(self, other):
        return self.__rmul__(other)

    def inv(self):
        """Inverse system/matrix (needs an invertible feedthrough ``Dyu``)."""
        A, Bw, Bu, Cz, Cy, Dzw, Dzu, Dyw, Dyu = self.partition()
        if Dyu.shape[0] != Dyu.shape[1]:
            raise DimensionError(f"only square uncertain objects can be inverted, got {self.shape}")
        if Dyu.size and np.linalg.cond(Dyu) > 1e12 or not np.all(np.isfinite(Dyu)):
            names = ", ".join(b.atom.name for b in self.blocks) or "a certain factor"
            raise ParameterError(f"cannot invert: the nominal value is singular (uncertain elements: {names})")
        Di = np.linalg.inv(Dyu)
        nA = A - Bu @ Di @ Cy
        nBw, nBu = Bw - Bu @ Di @ Dyw, Bu @ Di
        nCz, nDzw, nDzu = Cz - Dzu @ Di @ Cy, Dzw - Dzu @ Di @ Dyw, Dzu @ Di
        nCy, nDyw, nDyu = -Di @ Cy, -Di @ Dyw, Di
        return type(self)(nA, np.hstack([nBw, nBu]), np.vstack([nCz, nCy]),
                          np.block([[nDzw, nDzu], [nDyw, nDyu]]), self.blocks)

    def __truediv__(self, other):
        """``self / other`` for a scalar ``other``: ``self`` first, then ``other⁻¹``.

        Putting the divisor on the output side lets the rows of a matrix with a common
        denominator (``[-k/m, -c/m, 1/m]``) share one channel of ``m`` after reduction.
        """
        other = as_uncertain(other)
        if other.shape != (1, 1):
            raise DimensionError("division is only defined by a scalar (1x1) uncertain object")
        inv = other.inv()
        if self.shape[0] <= self.shape[1]:
            return inv * self
        return self * inv

    def __rtruediv__(self, other):
        if self.shape != (1, 1):
            raise DimensionError("division is only defined by a scalar (1x1) uncertain object")
        return as_uncertain(other).__truediv__(self)

    def __pow__(self, k):
        if not isinstance(k, numbers.Integral):
            raise InputError("only integer powers of uncertain objects are defined")
        if k < 0:
            return self.inv() ** (-k)
        out = as_uncertain(np.eye(self.shape[0])) if k == 0 else self
        for _ in range(int(k) - 1):
            out = out * self
        return out


class UMat(_Uncertain):
    """Uncertain matrix (static LFR), e.g. the result of ``k / m`` for ureal ``k, m``.

    Examples
    --------
    >>> from lmi_suspension.uncertain import ureal
    >>> k, m = ureal("k", 2.0, plusminus=0.5), ureal("m", 1.0, percent=20)
    >>> e = k / m + 1
    >>> e
    UMat(1x1, states=0, blocks=[k:1, m:1])
    """


class USS(_Uncertain):
    """Uncertain continuous-time state-space system (build it with :func:`uss`).

    Supports ``+``, ``-``, ``*`` (series: ``G2 * G1`` is ``G1`` then ``G2``), ``/`` by
    scalars, unary minus, and mixing with ``control.StateSpace``, ``TransferFunction``,
    numbers, arrays and uncertain matrices.  Input and output names (``input_labels``,
    ``output_labels``) are used by :func:`~lmi_suspension.uncertain.connect`.
    """


def _copy(x: _Uncertain) -> _Uncertain:
    return type(x)(x.A, x.B, x.C, x.D, x.blocks, inputs=x.input_labels, outputs=x.output_labels)


# ---------------------------------------------------------------------------- conversion
def _atom_lfr(atom) -> _Uncertain:
    if atom.kind == "real":
        a, c = atom.lfr_coefficients
        return UMat(np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((2, 0)),
                    np.array([[a, 1.0], [c, atom.nominal]]), [UBlock(atom, 1, 1)])
    if atom.kind == "complex":
        return UMat(np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((2, 0)),
                    np.array([[0.0, 1.0], [atom.radius, atom.nominal]]), [UBlock(atom, 1, 1)])
    ny, nu = atom.ny, atom.nu
    D = np.block([[np.zeros((nu, ny)), np.eye(nu)], [atom.bound * np.eye(ny), np.zeros((ny, nu))]])
    return USS(np.zeros((0, 0)), np.zeros((0, ny + nu)), np.zeros((nu + ny, 0)), D, [UBlock(atom, ny, nu)])


def _certain(A, B, C, D, cls, inputs=None, outputs=None):
    return cls(A, B, C, D, [], inputs=inputs, outputs=outputs)


def as_uncertain(x) -> _Uncertain:
    """Convert a number, array, nested list, atom or python-control system.

    Nested lists may hold uncertain entries (see :func:`umat`).
    """
    if isinstance(x, _Uncertain):
        return x
    if isinstance(x, _Atom):
        return _atom_lfr(x)
    if isinstance(x, (control.StateSpace, control.TransferFunction)):
        ss = as_statespace(x, "system")
        n = ss.nstates
        A = np.asarray(ss.A, dtype=float).reshape(n, n)
        B = np.asarray(ss.B, dtype=float).reshape(n, ss.ninputs)
        C = np.asarray(ss.C, dtype=float).reshape(ss.noutputs, n)
        D = np.asarray(ss.D, dtype=float).reshape(ss.noutputs, ss.ninputs)
        return _certain(A, B, C, D, USS, list(ss.input_labels), list(ss.output_labels))
    if isinstance(x, (list, tuple)) or (isinstance(x, np.ndarray) and x.dtype == object):
        return umat(x)
    if isinstance(x, bool):
        raise InputError("a boolean is not a matrix")
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"cannot use {type(x).__name__} as an uncertain matrix or system") from exc
    if arr.ndim > 2:
        raise DimensionError(f"a matrix must be at most 2-D, got shape {arr.shape}")
    arr = np.atleast_2d(arr)
    if not np.all(np.isfinite(arr)):
        raise NonFiniteError("matrix contains NaN or infinite entries")
    p, m = arr.shape
    return _certain(np.zeros((0, 0)), np.zeros((0, m)), np.zeros((p, 0)), arr, UMat)


def umat(rows) -> _Uncertain:
    """Uncertain (block) matrix from nested lists, like ``np.block``.

    Entries are numbers, arrays, atoms or uncertain objects; a row of entries must
    have equal heights, a column equal widths.

    Examples
    --------
    >>> from lmi_suspension.uncertain import ureal, umat
    >>> k = ureal("k", 1.0, plusminus=0.2)
    >>> umat([[0, 1], [-k, -k]])
    UMat(2x2, states=0, blocks=[k:1])
    """
    if isinstance(rows, np.ndarray):
        rows = rows.tolist()
    rows = list(rows)
    if not rows:
        raise DimensionError("empty matrix")
    if not isinstance(rows[0], (list, tuple, np.ndarray)):
        rows = [rows]  # a single row
    rows = [list(r) for r in rows]
    ncol = len(rows[0])
    if any(len(r) != ncol for r in rows) or ncol == 0:
        raise DimensionError("all rows of an uncertain matrix need the same number of entries")
    ents = [[as_uncertain(e) for e in r] for r in rows]
    heights = [ents[i][0].shape[0] for i in range(len(ents))]
    widths = [ents[0][j].shape[1] for j in range(ncol)]
    for i, r in enumerate(ents):
        for j, e in enumerate(r):
            if e.shape != (heights[i], widths[j]):
                raise DimensionError(f"entry ({i}, {j}) has shape {e.shape}, expected {(heights[i], widths[j])}")
    parts = [e for r in ents for e in r]
    p, m = sum(heights), sum(widths)
    rs, cs = _slices(heights), _slices(widths)
    nu_tot = sum(e.shape[1] for e in parts)
    ny_tot = sum(e.shape[0] for e in parts)
    E = np.zeros((nu_tot, m))
    H = np.zeros((p, ny_tot))
    iu = iy = 0
    for i, r in enumerate(ents):
        for j, e in enumerate(r):
            E[iu:iu + e.shape[1], cs[j]] = np.eye(e.shape[1])
            H[rs[i], iy:iy + e.shape[0]] = np.eye(e.shape[0])
            iu += e.shape[1]
            iy += e.shape[0]
    cls = USS if any(isinstance(e, USS) for e in parts) else UMat
    return interconnect_parts(parts, F=np.zeros((nu_tot, ny_tot)), E=E, H=H, J=np.zeros((p, m)), cls=cls)


def _broadcast_add(a, b):
    if a.shape == b.shape:
        return a, b
    if a.shape == (1, 1):
        return _scalar_broadcast(a, b.shape), b
    if b.shape == (1, 1):
        return a, _scalar_broadcast(b, a.shape)
    raise DimensionError(f"cannot add uncertain objects of shapes {a.shape} and {b.shape}")


def _scalar_broadcast(s, shape):
    """``s * ones(shape)``: one copy of ``s``'s channels."""
    p, m = shape
    return as_uncertain(np.ones((p, 1))) * s * as_uncertain(np.ones((1, m)))


def _scalar_times_identity(s, k):
    """``s I_k`` (``k`` copies of the scalar)."""
    if k == 1:
        return s
    return interconnect_parts([s] * k, F=np.zeros((k, k)), E=np.eye(k), H=np.eye(k),
                              J=np.zeros((k, k)), cls=type(s))


# ---------------------------------------------------------------------------- interconnection
def interconnect_parts(parts, *, F, E, H, J, cls, inputs=None, outputs=None, reduce=True):
    """Append ``parts`` and close the static interconnection of their certain signals.

    With ``v`` the stacked certain inputs of the parts and ``η`` their stacked certain
    outputs: ``v = F η + E u`` and ``y = H η + J u``.  The Δ channels of all parts are
    kept (merged per atom and reduced).

    Raises
    ------
    IllPosedLoopError
        If ``I - Dyu F`` is singular (an algebraic loop without a solution).
    """
    As, Bws, Bus, Czs, Cys, Dzws, Dzus, Dyws, Dyus = zip(*(p.partition() for p in parts))
    bd = scipy.linalg.block_diag
    A, Bw, Bu = bd(*As), bd(*Bws), bd(*Bus)
    Cz, Cy = bd(*Czs), bd(*Cys)
    Dzw, Dzu, Dyw, Dyu = bd(*Dzws), bd(*Dzus), bd(*Dyws), bd(*Dyus)
    n = A.shape[0]
    # scipy's block_diag drops empty shapes inconsistently: fix the sizes explicitly
    nw = sum(p.nw for p in parts)
    nz = sum(p.nz for p in parts)
    nv = sum(p.ninputs for p in parts)
    ne = sum(p.noutputs for p in parts)
    A = A.reshape(n, n)
    Bw, Bu, Cz, Cy = (_fix(Bw, n, nw), _fix(Bu, n, nv), _fix(Cz, nz, n), _fix(Cy, ne, n))
    Dzw, Dzu, Dyw, Dyu = _fix(Dzw, nz, nw), _fix(Dzu, nz, nv), _fix(Dyw, ne, nw), _fix(Dyu, ne, nv)
    F, E, H, J = (np.asarray(X, dtype=float) for X in (F, E, H, J))
    Mloop = np.eye(ne) - Dyu @ F
    if ne and (np.linalg.cond(Mloop) > 1e13):
        raise IllPosedLoopError("the interconnection is not well posed (I - D F is singular)")
    L = np.linalg.inv(Mloop) if ne else np.zeros((0, 0))
    FL = F @ L
    G = FL @ Dyu @ E + E
    nA = A + Bu @ FL @ Cy
    nBw = Bw + Bu @ FL @ Dyw
    nBu = Bu @ G
    nCz = Cz + Dzu @ FL @ Cy
    nDzw = Dzw + Dzu @ FL @ Dyw
    nDzu = Dzu @ G
    HL = H @ L
    nCy, nDyw, nDyu = HL @ Cy, HL @ Dyw, HL @ Dyu @ E + J
    blocks = [b for p in parts for b in p.blocks]
    out = _build(nA, nBw, nBu, nCz, nCy, nDzw, nDzu, nDyw, nDyu, blocks, cls, inputs, outputs)
    return reduce_lfr(out) if reduce else out


def _fix(X, r, c):
    return np.asarray(X, dtype=float).reshape(r, c) if X.size == r * c else np.zeros((r, c))


def _build(A, Bw, Bu, Cz, Cy, Dzw, Dzu, Dyw, Dyu, blocks, cls, inputs=None, outputs=None):
    return cls(A, np.hstack([Bw, Bu]), np.vstack([Cz, Cy]),
               np.block([[Dzw, Dzu], [Dyw, Dyu]]), blocks, inputs=inputs, outputs=outputs)


def _merge(x: _Uncertain) -> _Uncertain:
    """Group the channels of each atom into one block (blocks sorted by name)."""
    order: dict[str, list[int]] = {}
    atoms: dict[str, object] = {}
    for i, b in enumerate(x.blocks):
        name = b.atom.name
        if name in atoms and atoms[name] != b.atom:
            raise ParameterError(
                f"two different uncertain elements are named {name!r}: {atoms[name]!r} and {b.atom!r}")
        atoms.setdefault(name, b.atom)
        order.setdefault(name, []).append(i)
    order = dict(sorted(order.items()))  # blocks in alphabetical order of names
    if all(len(v) == 1 for v in order.values()) and [v[0] for v in order.values()] == list(range(len(x.blocks))):
        return x
    wsl = _slices([b.nw for b in x.blocks])
    zsl = _slices([b.nz for b in x.blocks])
    pw, pz, blocks = [], [], []
    for name, idx in order.items():
        atom = atoms[name]
        if len(idx) > 1 and not _scalar(atom):
            raise ParameterError(
                f"the ultidyn {name!r} ({atom.ny}x{atom.nu}) enters the model {len(idx)} times; "
                "a repeated multivariable dynamic uncertainty is not supported")
        for i in idx:
            pw.extend(range(x.nw)[wsl[i]])
            pz.extend(range(x.nz)[zsl[i]])
        blocks.append(UBlock(atom, sum(x.blocks[i].nw for i in idx), sum(x.blocks[i].nz for i in idx)))
    A, Bw, Bu, Cz, Cy, Dzw, Dzu, Dyw, Dyu = x.partition()
    return _build(A, Bw[:, pw], Bu, Cz[pz], Cy, Dzw[np.ix_(pz, pw)], Dzu[pz], Dyw[:, pw], Dyu,
                  blocks, type(x), x.input_labels, x.output_labels)


def _orth(X, tol):
    if X.shape[1] == 0:
        return np.zeros((X.shape[0], 0))
    U, s, _ = np.linalg.svd(X, full_matrices=False)
    return U[:, : int(np.sum(s > tol))]


def _reach(And, Bnd, zsizes, wsizes, reducible, rtol):
    """Bases of the smallest structured subspace ⊇ range(Bnd), invariant under And·Δ.

    The rank decision of each block is relative to the size of that block's own rows of
    ``[Bnd, And]`` (what its reachable vectors are made of), not to the whole
    realization's: a closed loop with a 22-state D-G-K controller (entries up to ~1e8)
    had its only real parameter, whose rows are O(1), removed as unreachable with a
    tolerance relative to the whole (2026-11-27, notebooks/06)."""
    zsl, wsl = _slices(zsizes), _slices(wsizes)
    tols = [rtol * max(1.0, np.linalg.norm(np.hstack([Bnd[zsl[k]], And[zsl[k]]])))
            for k in range(len(zsizes))]
    bases = [np.zeros((zsizes[k], 0)) if reducible[k] else None for k in range(len(zsizes))]
    for _ in range(sum(zsizes) + 2):
        Tw = scipy.linalg.block_diag(*[np.eye(wsizes[k]) if bases[k] is None else bases[k]
                                       for k in range(len(zsizes))])
        Tw = Tw.reshape(sum(wsizes), -1) if Tw.size else np.zeros((sum(wsizes), 0))
        vecs = np.hstack([Bnd, And @ Tw])
        changed = False
        for k in range(len(zsizes)):
            if not reducible[k]:
                continue
            Q = _orth(vecs[zsl[k]], tols[k])
            if Q.shape[1] > bases[k].shape[1]:
                bases[k] = Q
                changed = True
        if not changed:
            break
    return bases


def _project(And, Bnd, Cnd, zsizes, wsizes, bases):
    Tz = [np.eye(zsizes[k]) if b is None else b for k, b in enumerate(bases)]
    Tw = [np.eye(wsizes[k]) if b is None else b for k, b in enumerate(bases)]
    Tz = _bd(Tz, sum(zsizes))
    Tw = _bd(Tw, sum(wsizes))
    return Tz.T @ And @ Tw, Tz.T @ Bnd, Cnd @ Tw


def _bd(mats, nrows):
    ncols = sum(m.shape[1] for m in mats)
    out = np.zeros((nrows, ncols))
    i = j = 0
    for m in mats:
        out[i:i + m.shape[0], j:j + m.shape[1]] = m
        i += m.shape[0]
        j += m.shape[1]
    return out


def reduce_lfr(x: _Uncertain) -> _Uncertain:
    """Merge the blocks of each atom and remove redundant repetitions (exact).

    The n-D Kalman decomposition of the module docstring: structured reachability,
    then structured observability; states and full (multivariable ``ultidyn``) blocks
    are kept whole.  A scalar block whose channels are all redundant disappears.
    """
    x = _merge(x)
    if not x.blocks:
        return x
    A, Bw, Bu, Cz, Cy, Dzw, Dzu, Dyw, Dyu = x.partition()
    n = x.nstates
    And = np.block([[A, Bw], [Cz, Dzw]])
    Bnd = np.vstack([Bu, Dzu])
    Cnd = np.hstack([Cy, Dyw])
    zsizes = [n] + [b.nz for b in x.blocks]
    wsizes = [n] + [b.nw for b in x.blocks]
    red = [False] + [b.reducible for b in x.blocks]
    tol = _REDUCE_RTOL
    # keep full bases as identities: no needless rotation
    def tidy(bases, sizes):
        return [None if (b is not None and b.shape[1] == sizes[k]) else b for k, b in enumerate(bases)]
    bases = tidy(_reach(And, Bnd, zsizes, wsizes, red, tol), zsizes)
    if any(b is not None for b in bases):
        And, Bnd, Cnd = _project(And, Bnd, Cnd, zsizes, wsizes, bases)
        zsizes = [zsizes[k] if b is None else b.shape[1] for k, b in enumerate(bases)]
        wsizes = [wsizes[k] if b is None else b.shape[1] for k, b in enumerate(bases)]
    obases = tidy(_reach(And.T, Cnd.T, wsizes, zsizes, red, tol), wsizes)
    if any(b is not None for b in obases):
        AT, CT, BT = _project(And.T, Cnd.T, Bnd.T, wsizes, zsizes, obases)
        And, Bnd, Cnd = AT.T, BT.T, CT.T
        zsizes = [zsizes[k] if b is None else b.shape[1] for k, b in enumerate(obases)]
        wsizes = [wsizes[k] if b is None else b.shape[1] for k, b in enumerate(obases)]
    blocks, keep_w, keep_z = [], [], []
    wsl, zsl = _slices(wsizes[1:]), _slices(zsizes[1:])
    for k, b in enumerate(x.blocks):
        if wsizes[k + 1] == 0 and zsizes[k + 1] == 0:
            continue
        blocks.append(UBlock(b.atom, wsizes[k + 1], zsizes[k + 1]))
        keep_w.extend(range(sum(wsizes[1:]))[wsl[k]])
        keep_z.extend(range(sum(zsizes[1:]))[zsl[k]])
    nwt, nzt = sum(wsizes[1:]), sum(zsizes[1:])
    A, Bw, Cz, Dzw = And[:n, :n], And[:n, n:], And[n:, :n], And[n:, n:]
    Bu, Dzu = Bnd[:n], Bnd[n:]
    Cy, Dyw = Cnd[:, :n], Cnd[:, n:]
    Bw, Cz = Bw.reshape(n, nwt)[:, keep_w], Cz.reshape(nzt, n)[keep_z]
    Dzw = Dzw.reshape(nzt, nwt)[np.ix_(keep_z, keep_w)]
    Dzu, Dyw = Dzu.reshape(nzt, Bnd.shape[1])[keep_z], Dyw.reshape(Cy.shape[0], nwt)[:, keep_w]
    return _build(A, Bw, Bu, Cz, Cy, Dzw, Dzu, Dyw, Dyu, blocks, type(x), x.input_labels, x.output_labels)
