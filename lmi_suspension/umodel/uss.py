"""Uncertain state-space systems: building, interconnecting, substituting, sampling.

:func:`uss` builds a :class:`~lmi_suspension.umodel.lfr.USS` from (uncertain)
matrices; :func:`feedback` and :func:`connect` interconnect; :func:`lftdata` returns
the certain part ``M`` and the normalised block structure; :func:`usubs`,
:func:`usample` and :func:`nominal` return python-control ``StateSpace`` objects.
"""

from __future__ import annotations

import logging
import numbers
from dataclasses import dataclass

import control
import numpy as np

from ..errors import DimensionError, InputError, NonFiniteError, ParameterError
from .atoms import UComplex, UReal
from .blocks import BlockStructure
from .lfr import USS, UBlock, UMat, _build, _Uncertain, as_uncertain, interconnect_parts

__all__ = ["LFTData", "uss", "feedback", "connect", "lftdata", "usubs", "usample", "nominal"]

logger = logging.getLogger(__name__)


def uss(A, B=None, C=None, D=None, *, inputs=None, outputs=None) -> USS:
    """Uncertain continuous-time state-space system ``ẋ = A x + B u, y = C x + D u``.

    Parameters
    ----------
    A, B, C, D : array_like, nested lists or uncertain matrices
        Entries may be numbers or uncertain expressions of :func:`ureal` /
        :func:`ucomplex` atoms (``A = [[0, 1], [-k / m, -c / m]]``).  With ``B`` omitted,
        ``A`` is a system (``control.StateSpace``, ``TransferFunction``, an ``ultidyn``
        or an uncertain matrix) converted to a :class:`USS`.
    inputs, outputs : list of str, optional
        Signal names (used by :func:`connect`); default ``u[i]``, ``y[i]``.

    Returns
    -------
    USS
        With the minimal repetition of each parameter this reduction finds (see
        :func:`~lmi_suspension.umodel.lfr.reduce_lfr`).

    Raises
    ------
    DimensionError
        If the matrices do not fit.

    Examples
    --------
    >>> from lmi_suspension.uncertain import ureal, uss, lftdata
    >>> k = ureal("k", 1.0, plusminus=0.4)
    >>> m = ureal("m", 1.0, plusminus=0.3)
    >>> G = uss([[0, 1], [-k / m, -0.1 / m]], [[0], [1 / m]], [[1, 0]], [[0]])
    >>> G
    USS(1x1, states=2, blocks=[k:1, m:1])
    >>> lftdata(G).blk.to_blk().tolist()
    [[-1, 0], [-1, 0]]
    """
    if B is None:
        x = as_uncertain(A)
        out = USS(x.A, x.B, x.C, x.D, x.blocks, inputs=inputs or x.input_labels,
                  outputs=outputs or x.output_labels)
        return out
    mats = [as_uncertain(M) for M in (A, B, C, D)]
    if any(isinstance(M, USS) for M in mats):
        raise InputError("uss(A, B, C, D) needs static (possibly uncertain) matrices, not systems")
    (n, n2), (nb, m), (p, nc), (pd, md) = (M.shape for M in mats)
    if n != n2 or nb != n or nc != n or pd != p or md != m:
        raise DimensionError(
            f"uss: A {mats[0].shape}, B {mats[1].shape}, C {mats[2].shape}, D {mats[3].shape} do not fit")
    big = as_uncertain([[mats[0], mats[1]], [mats[2], mats[3]]])
    _, Bw, Bu, Cz, Cy, Dzw, Dzu, Dyw, Dyu = big.partition()
    # static rows: [z; xdot; y], columns [w; x; u]
    sys = _build(Dyu[:n, :n], Dyw[:n], Dyu[:n, n:], Dzu[:, :n], Dyu[n:, :n], Dzw, Dzu[:, n:],
                 Dyw[n:], Dyu[n:, n:], big.blocks, USS, inputs, outputs)
    return sys


def feedback(G, K=1, sign: int = -1):
    """Feedback interconnection ``y = G (u + sign K y)`` (python-control's convention).

    Examples
    --------
    >>> from lmi_suspension.uncertain import ureal, uss, feedback, nominal
    >>> g = ureal("g", 2.0, plusminus=0.5)
    >>> T = feedback(uss([[-1]], [[g]], [[1]], [[0]]), 1)
    >>> nominal(T).poles().real.round(6).tolist()
    [-3.0]
    """
    if sign not in (-1, 1):
        raise InputError(f"sign must be -1 or +1, got {sign!r}")
    G, K = as_uncertain(G), as_uncertain(K)
    (p, m), (pk, mk) = G.shape, K.shape
    if (pk, mk) != (m, p):
        if (pk, mk) == (1, 1):
            K = K * as_uncertain(np.eye(p)) if p == m else K
        if K.shape != (m, p):
            raise DimensionError(f"feedback: G is {G.shape}, K must be {(m, p)}, got {K.shape}")
    F = np.zeros((m + p, p + m))
    F[:m, p:] = sign * np.eye(m)
    F[m:, :p] = np.eye(p)
    E = np.vstack([np.eye(m), np.zeros((p, m))])
    H = np.hstack([np.eye(p), np.zeros((p, m))])
    cls = USS if (isinstance(G, USS) or isinstance(K, USS)) else UMat
    return interconnect_parts([G, K], F=F, E=E, H=H, J=np.zeros((p, m)), cls=cls)


def connect(systems, inputs, outputs) -> USS:
    """Interconnect systems by signal names (a minimal ``control.interconnect``).

    Every input signal of every system must be either an output name of a system
    (it is then connected to it) or one of the external ``inputs`` (or both, then they
    add).  There are no sum blocks: build differences with a gain system
    (``uss(..., inputs=["r", "y"], outputs=["e"])``) or python-control's
    ``summing_junction``.  Output names must be unique; ``outputs`` are output names.

    Examples
    --------
    >>> import control
    >>> from lmi_suspension.uncertain import ureal, uss, connect, nominal
    >>> k = ureal("k", 1.0, percent=10)
    >>> P = uss([[-1]], [[k]], [[1]], [[0]], inputs=["u"], outputs=["y"])
    >>> S = control.summing_junction(inputs=["r", "-y"], output="e")
    >>> C = control.ss([], [], [], [[2.0]], inputs="e", outputs="u")
    >>> T = connect([P, S, C], inputs=["r"], outputs=["y"])
    >>> float(nominal(T).dcgain())     # 2/(s+3) at s = 0
    0.6666666666666666
    """
    parts = [as_uncertain(s) for s in systems]
    if isinstance(inputs, str):
        inputs = [inputs]
    if isinstance(outputs, str):
        outputs = [outputs]
    inputs, outputs = list(inputs), list(outputs)
    out_index: dict[str, int] = {}
    i = 0
    for k, p in enumerate(parts):
        for name in p.output_labels:
            if name in out_index:
                raise InputError(f"connect: the output name {name!r} is used by two systems")
            out_index[name] = i
            i += 1
    ne = i
    nv = sum(p.ninputs for p in parts)
    F = np.zeros((nv, ne))
    E = np.zeros((nv, len(inputs)))
    j = 0
    for k, p in enumerate(parts):
        for name in p.input_labels:
            used = False
            if name in out_index:
                F[j, out_index[name]] = 1.0
                used = True
            if name in inputs:
                E[j, inputs.index(name)] = 1.0
                used = True
            if not used:
                raise InputError(f"connect: input {name!r} of system {k} is neither an external "
                                 "input nor the output of a system")
            j += 1
    H = np.zeros((len(outputs), ne))
    for r, name in enumerate(outputs):
        if name not in out_index:
            raise InputError(f"connect: output {name!r} is not an output of any system")
        H[r, out_index[name]] = 1.0
    return interconnect_parts(parts, F=F, E=E, H=H, J=np.zeros((len(outputs), len(inputs))),
                              cls=USS, inputs=inputs, outputs=outputs)


@dataclass(frozen=True)
class LFTData:
    """The certain part and the normalised uncertainty of an uncertain system.

    ``usys = F_u(M, Δ)`` with ``[z; y] = M [w; u]``, ``w = Δ z``, ``Δ`` normalised
    (``|δ| <= 1``, ``‖Δ_i‖∞ <= 1``).

    Attributes
    ----------
    M : control.StateSpace
        Inputs ``[w; u]`` (uncertainty channels first), outputs ``[z; y]``.
    blk : BlockStructure
        MATLAB rows in block order: ``[-r, 0]`` for a real parameter entering ``r``
        times, ``[r, 0]`` for a complex one (or a repeated SISO ``ultidyn``),
        ``[ny, nu]`` for an ``ultidyn``.
    names : tuple of str
        The atom of each block.
    atoms : tuple
        The atoms themselves (for ``value``/``normalise``).
    nw, nz : int
        Number of uncertainty inputs ``w`` and outputs ``z`` of ``M``.
    """

    M: control.StateSpace
    blk: BlockStructure
    names: tuple[str, ...]
    atoms: tuple
    nw: int
    nz: int


def lftdata(usys) -> LFTData:
    """Decompose an uncertain system or matrix into ``(M, blk, names)``.

    Examples
    --------
    >>> from lmi_suspension.uncertain import ureal, uss, lftdata
    >>> a = ureal("a", -2.0, plusminus=0.5)
    >>> d = lftdata(uss([[a]], [[1]], [[1]], [[0]]))
    >>> d.names, d.blk.to_blk().tolist(), d.M.ninputs
    (('a',), [[-1, 0]], 2)
    """
    x = as_uncertain(usys)
    if not x.blocks:
        struct = None
    else:
        struct = BlockStructure.from_blk([b.blk_row for b in x.blocks])
    w_names = [f"w_{b.atom.name}[{i}]" for b in x.blocks for i in range(b.nw)]
    z_names = [f"z_{b.atom.name}[{i}]" for b in x.blocks for i in range(b.nz)]
    M = control.ss(x.A, x.B, x.C, x.D, inputs=w_names + list(x.input_labels),
                   outputs=z_names + list(x.output_labels))
    return LFTData(M=M, blk=struct, names=tuple(b.atom.name for b in x.blocks),
                   atoms=tuple(b.atom for b in x.blocks), nw=x.nw, nz=x.nz)


def _to_statespace(x: _Uncertain) -> control.StateSpace:
    n = x.nstates
    return control.ss(x.A.reshape(n, n), x.B.reshape(n, x.ninputs), x.C.reshape(x.noutputs, n),
                      x.D, inputs=list(x.input_labels), outputs=list(x.output_labels))


def nominal(usys):
    """Nominal system (every ``δ = 0``) as a ``control.StateSpace`` (or array for a matrix).

    Examples
    --------
    >>> from lmi_suspension.uncertain import ureal, nominal
    >>> k = ureal("k", 3.0, plusminus=1.0)
    >>> nominal(2 * k).tolist()
    [[6.0]]
    """
    x = as_uncertain(usys)
    A, Bw, Bu, Cz, Cy, Dzw, Dzu, Dyw, Dyu = x.partition()
    cert = type(x)(A, Bu, Cy, Dyu, [], inputs=x.input_labels, outputs=x.output_labels)
    return _to_statespace(cert) if isinstance(x, USS) else cert.D.copy()


def _delta_part(block: UBlock, value):
    """Normalised Δ of one block for a physical value, as a certain uncertain object."""
    atom = block.atom
    name = atom.name
    if isinstance(atom, (UReal, UComplex)):
        if isinstance(value, bool) or not isinstance(value, numbers.Number):
            raise ParameterError(f"value of {name!r} must be a number, got {value!r}")
        if not np.isfinite(value):
            raise NonFiniteError(f"value of {name!r} is not finite ({value!r})")
        if isinstance(value, complex) and value.imag != 0:
            raise ParameterError(
                f"value {value!r} of {name!r} is not real: python-control systems have real "
                "coefficients")
        delta = atom.normalise(float(np.real(value)))
        return as_uncertain(delta * np.eye(block.nw))
    # ultidyn: a system or a constant matrix
    try:
        d = as_uncertain(value)
    except InputError as exc:
        raise ParameterError(f"value of ultidyn {name!r}: {exc}") from exc
    if d.blocks:
        raise ParameterError(f"value of ultidyn {name!r} must be certain")
    if d.shape != (atom.ny, atom.nu):
        raise DimensionError(f"value of ultidyn {name!r} must be {atom.ny}x{atom.nu}, got {d.shape}")
    d = d * (1.0 / atom.bound)
    if block.nw > 1 and (atom.ny, atom.nu) == (1, 1):
        from .lfr import _scalar_times_identity
        d = _scalar_times_identity(d, block.nw)
    return d


def _substitute(x: _Uncertain, values: dict):
    """Close the blocks named in ``values`` (physical values); keep the others."""
    if not isinstance(values, dict):
        raise InputError("values must be a dict {name: value}")
    names = {b.atom.name for b in x.blocks}
    unknown = [k for k in values if k not in names]
    if unknown:
        raise ParameterError(
            f"unknown uncertain element(s) {unknown}: the model has {sorted(names)}")
    sel = [i for i, b in enumerate(x.blocks) if b.atom.name in values]
    if not sel:
        return x
    deltas = [_delta_part(x.blocks[i], values[x.blocks[i].atom.name]) for i in sel]
    keep = [i for i in range(len(x.blocks)) if i not in sel]
    wsl = _slices_of([b.nw for b in x.blocks])
    zsl = _slices_of([b.nz for b in x.blocks])
    ws = [j for i in sel for j in wsl[i]]
    zs = [j for i in sel for j in zsl[i]]
    wk = [j for i in keep for j in wsl[i]]
    zk = [j for i in keep for j in zsl[i]]
    A, Bw, Bu, Cz, Cy, Dzw, Dzu, Dyw, Dyu = x.partition()
    # pulled-out system: certain inputs [w_sel; u], outputs [z_sel; y], blocks = kept
    pulled = _build(A, Bw[:, wk], np.hstack([Bw[:, ws], Bu]), Cz[zk], np.vstack([Cz[zs], Cy]),
                    Dzw[np.ix_(zk, wk)], np.hstack([Dzw[np.ix_(zk, ws)], Dzu[zk]]),
                    np.vstack([Dzw[np.ix_(zs, wk)], Dyw[:, wk]]),
                    np.block([[Dzw[np.ix_(zs, ws)], Dzu[zs]], [Dyw[:, ws], Dyu]]),
                    [x.blocks[i] for i in keep], type(x))
    nws, nzs = len(ws), len(zs)
    ny, nu = x.shape
    nd_in = sum(d.ninputs for d in deltas)
    nd_out = sum(d.noutputs for d in deltas)
    Dall = interconnect_parts(deltas, F=np.zeros((nd_in, nd_out)), E=np.eye(nd_in), H=np.eye(nd_out),
                              J=np.zeros((nd_out, nd_in)),
                              cls=USS if any(isinstance(d, USS) for d in deltas) else UMat)
    F = np.zeros((nws + nu + nzs, nzs + ny + nws))
    F[:nws, nzs + ny:] = np.eye(nws)
    F[nws + nu:, :nzs] = np.eye(nzs)
    E = np.zeros((nws + nu + nzs, nu))
    E[nws:nws + nu] = np.eye(nu)
    H = np.zeros((ny, nzs + ny + nws))
    H[:, nzs:nzs + ny] = np.eye(ny)
    cls = USS if (isinstance(x, USS) or isinstance(Dall, USS)) else UMat
    return interconnect_parts([pulled, Dall], F=F, E=E, H=H, J=np.zeros((ny, nu)), cls=cls,
                              inputs=x.input_labels, outputs=x.output_labels)


def _slices_of(sizes):
    edges = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
    return [list(range(a, b)) for a, b in zip(edges[:-1], edges[1:])]


def usubs(usys, values: dict):
    """Substitute physical values for uncertain elements.

    Parameters
    ----------
    usys : USS or UMat
    values : dict
        ``{name: value}``: actual (not normalised) parameter values, which may lie
        outside the ranges; for an ``ultidyn`` a ``control`` system or a constant
        matrix of its size.

    Returns
    -------
    control.StateSpace, ndarray or USS
        A ``StateSpace`` (an array for an uncertain matrix) when every element is
        substituted, else the remaining uncertain object.

    Raises
    ------
    ParameterError
        An unknown name (the message lists the model's names), a non-numeric value.
    NonFiniteError
        A NaN or infinite value.

    Examples
    --------
    >>> from lmi_suspension.uncertain import ureal, uss, usubs
    >>> k = ureal("k", 1.0, plusminus=0.4)
    >>> m = ureal("m", 1.0, plusminus=0.3)
    >>> G = uss([[0, 1], [-k / m, -0.1 / m]], [[0], [1 / m]], [[1, 0]], [[0]])
    >>> P = usubs(G, {"k": 1.2, "m": 0.9})
    >>> round(float(P.dcgain()), 12)      # 1/k
    0.833333333333
    """
    x = as_uncertain(usys)
    for name, v in values.items() if isinstance(values, dict) else ():
        if isinstance(v, numbers.Number) and not isinstance(v, bool) and not np.isfinite(v):
            raise NonFiniteError(f"value of {name!r} is not finite ({v!r})")
    out = _substitute(x, values)
    if out.blocks:
        return out
    return _to_statespace(out) if isinstance(out, USS) else out.D.copy()


def _random_value(atom, rng):
    if isinstance(atom, UReal):
        return atom.value(rng.uniform(-1.0, 1.0))
    if isinstance(atom, UComplex):
        return atom.value(rng.uniform(-1.0, 1.0))  # real values only (real systems)
    G = rng.standard_normal((atom.ny, atom.nu))
    G *= atom.bound * rng.uniform(0.0, 1.0) / max(np.linalg.norm(G, 2), 1e-300)
    a = 10.0 ** rng.uniform(-1.0, 1.0)
    allpass = control.tf([1.0, -a], [1.0, a])
    return control.ss(allpass) * G if G.size > 1 else control.ss(allpass * float(G[0, 0]))


def usample(usys, n: int = 1, rng: np.random.Generator | None = None):
    """Random instances of an uncertain system.

    Real parameters are drawn uniformly in the normalised ``δ ∈ [-1, 1]`` (uniform in
    the physical range for symmetric ranges), ``ucomplex`` elements take real values
    ``nominal + radius δ`` (python-control systems are real), and an ``ultidyn`` is a
    random gain of norm ``<= bound`` times a first-order all-pass ``(s - a)/(s + a)``.

    Parameters
    ----------
    usys : USS or UMat
    n : int
        Number of samples.
    rng : numpy.random.Generator, optional
        Source of randomness (default ``np.random.default_rng(0)``).

    Returns
    -------
    systems : list of control.StateSpace (arrays for an uncertain matrix)
    values : list of dict
        The substituted ``{name: value}`` of each sample.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.uncertain import ureal, uss, usample
    >>> k = ureal("k", 1.0, plusminus=0.4)
    >>> systems, values = usample(uss([[-k]], [[1]], [[1]], [[0]]), 3, np.random.default_rng(1))
    >>> all(0.6 <= v["k"] <= 1.4 for v in values)
    True
    """
    if rng is None:
        rng = np.random.default_rng(0)
    if not isinstance(rng, np.random.Generator):
        raise InputError("rng must be a numpy.random.Generator")
    if isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 1:
        raise InputError(f"n must be a positive integer, got {n!r}")
    x = as_uncertain(usys)
    systems, values = [], []
    for _ in range(int(n)):
        vals = {b.atom.name: _random_value(b.atom, rng) for b in x.blocks}
        systems.append(usubs(x, vals))
        values.append(vals)
    return systems, values
