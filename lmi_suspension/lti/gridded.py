"""A controller scheduled on measured parameters by a table: state-space controllers at
the nodes of a grid, interpolated between them.

:class:`GriddedController` holds one controller per node of a Cartesian grid over named
scheduling parameters (an occupant's mass, a speed), all of the same size and in state
coordinates that vary smoothly from node to node (the frozen controllers of a gain
surface, a structured controller tuned at each node, or one controller repeated);
``K.at(m3=42.0)`` is the controller at one value: its matrices interpolated
multilinearly between the surrounding nodes (MATLAB's gridded LPV models and
``ssInterpolant`` do the same), exactly the node's matrices at a node.  Between nodes the
interpolated controller is a different controller from any node's: a certificate holds
at the values it was computed at (see :func:`~lmi_suspension.seat.scheduled.certify_scheduled`).

With ``interpolation="bins"`` the table is piecewise constant instead: each axis holds a
parameter's bin *edges*, there is one controller per bin (a cell of the edges' grid), and
``at`` returns the controller of the bin the value falls in, unchanged (bins are closed
below and open above, the last one closed at both ends).  A seat that measures its
occupant's mass once, at rest, picks one controller per ride and never switches during
it; the controllers of different bins need not share a state dimension (they are never
blended).

:mod:`lmi_suspension.io` saves it exactly (format ``lmi_suspension.gridded_controller/1``)
and ``load_controller`` returns it.

Examples
--------
>>> import control
>>> from lmi_suspension.lti.gridded import GriddedController
>>> K30 = control.ss([[-10.0]], [[1.0, 0.0]], [[100.0]], [[0.0, 1.0]])
>>> K70 = control.ss([[-20.0]], [[1.0, 0.0]], [[300.0]], [[0.0, 3.0]])
>>> K = GriddedController.from_controllers({"m3": [30.0, 70.0]}, [K30, K70])
>>> K.at(m3=50.0).A, K.at(m3=30.0).D
(array([[-15.]]), array([[0., 1.]]))
>>> B = GriddedController.from_controllers({"m3": [30.0, 50.0, 70.0]}, [K30, K70],
...                                         interpolation="bins")
>>> B.at(m3=49.9).D, B.at(m3=50.0).D, B.bins
(array([[0., 1.]]), array([[0., 3.]]), (((30.0, 50.0),), ((50.0, 70.0),)))
>>> K.at(m3=80.0)
Traceback (most recent call last):
...
lmi_suspension.errors.ParameterError: m3 = 80 is outside the schedule's range [30, 70]
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import control
import numpy as np

from ..errors import DimensionError, InputError, ParameterError
from .checks import as_statespace, finite_scalar

__all__ = ["GriddedController", "parameter_values", "INTERPOLATIONS"]

#: how :meth:`GriddedController.at` reads its table: between nodes (``"multilinear"``) or
#: the bin a value falls in (``"bins"``, piecewise constant over explicit edges)
INTERPOLATIONS = ("multilinear", "bins")

#: a value this close (relative) beyond a range's end counts as the end: a mass computed
#: as ``30 + 40 * 1.0`` may land an ulp outside the node it means
_RANGE_RTOL = 1e-12


def parameter_values(names, bounds, args, named, what: str = "the range") -> tuple:
    """Values of the parameters ``names`` given by position (``args``) or by name
    (``named``), as floats in the order of ``names``: every one given once, finite and
    inside its ``(lo, hi)`` of ``bounds`` (within ``_RANGE_RTOL``).  The one check of a
    scheduled controller's point (:class:`GriddedController` here, lpvsyn's
    ``ScheduledController``); ``what`` names the range in the error.

    Raises
    ------
    ParameterError
        Both ways at once, a missing or unknown name, a wrong count, a value outside.
    NonFiniteError
        NaN or infinity.
    """
    if args and named:
        raise ParameterError("give the parameter values by position or by name, not both")
    if named:
        unknown = [k for k in named if k not in names]
        missing = [k for k in names if k not in named]
        if unknown or missing:
            raise ParameterError(f"the schedule's parameters are {tuple(names)}; "
                                 + (f"unknown {unknown}" if unknown else "")
                                 + ("; " if unknown and missing else "")
                                 + (f"missing {missing}" if missing else ""))
        args = tuple(named[n] for n in names)
    if len(args) != len(names):
        raise ParameterError(f"expected {len(names)} values {tuple(names)}, got {len(args)}")
    p = tuple(finite_scalar(v, f"parameter {n}") for n, v in zip(names, args))
    for n, v, (lo, hi) in zip(names, p, bounds):
        tol = _RANGE_RTOL * max(1.0, abs(lo), abs(hi))
        if not lo - tol <= v <= hi + tol:
            raise ParameterError(f"{n} = {v:g} is outside {what} [{lo:g}, {hi:g}]")
    return p


def _floats(M) -> list:
    return np.asarray(M, dtype=float).tolist()


@dataclass(frozen=True, eq=False)
class GriddedController:
    """State-space controllers at the nodes of a grid, interpolated multilinearly, or
    one per bin of a grid of edges (``interpolation="bins"``).

    Attributes
    ----------
    names : tuple of str
        The scheduling parameters.
    axes : tuple of numpy.ndarray
        Each parameter's node values, strictly increasing (one value: the parameter is
        held there); with bins, each parameter's bin edges (at least two).
    controllers : tuple of control.StateSpace
        The controller at each node (each bin), in the order of
        :func:`itertools.product` over the axes (over each axis's bins); the same
        numbers of inputs and outputs everywhere, and of states at every node of a
        multilinear table.
    inputs, outputs : tuple of str
        Signal names.
    interpolation : str
        ``"multilinear"`` (default) or ``"bins"`` (:data:`INTERPOLATIONS`).
    """

    names: tuple
    axes: tuple
    controllers: tuple = field(repr=False)
    inputs: tuple = ()
    outputs: tuple = ()
    interpolation: str = "multilinear"

    def __post_init__(self):
        if isinstance(self.names, str) or not self.names:
            raise ParameterError(f"names must be a non-empty tuple of parameter names, got "
                                 f"{self.names!r}")
        names = tuple(str(n) for n in self.names)
        if len(set(names)) != len(names):
            raise ParameterError(f"a scheduling parameter is named twice: {names!r}")
        if len(self.axes) != len(names):
            raise DimensionError(f"{len(self.axes)} axes for the {len(names)} parameters "
                                 f"{names}")
        if self.interpolation not in INTERPOLATIONS:
            raise ParameterError(f"interpolation must be one of {INTERPOLATIONS}, got "
                                 f"{self.interpolation!r}")
        bins = self.interpolation == "bins"
        axes = []
        for n, a in zip(names, self.axes):
            a = np.array(a, dtype=float).ravel()
            if a.size < (2 if bins else 1) or not np.all(np.isfinite(a)) \
                    or np.any(np.diff(a) <= 0):
                raise ParameterError(f"the {'bin edges' if bins else 'nodes'} of {n} must "
                                     f"be finite and strictly increasing"
                                     f"{' (at least two)' if bins else ''}, got {a.tolist()}")
            a.setflags(write=False)
            axes.append(a)
        shape = tuple(a.size - 1 if bins else a.size for a in axes)
        count = int(np.prod(shape))
        Ks = tuple(as_statespace(K, f"controller {i}") for i, K in enumerate(self.controllers))
        if len(Ks) != count:
            raise DimensionError(f"{len(Ks)} controllers for the {count} "
                                 f"{'bins' if bins else 'nodes'} of the grid")
        size = (Ks[0].nstates, Ks[0].ninputs, Ks[0].noutputs)
        for i, K in enumerate(Ks):
            # bins are never blended: only the signals must agree
            if (K.ninputs, K.noutputs) != size[1:] or (not bins and K.nstates != size[0]):
                raise DimensionError(f"controller {i} has (states, inputs, outputs) "
                                     f"{(K.nstates, K.ninputs, K.noutputs)}, the first {size}")
            if K.isdtime(strict=True):
                raise InputError("the controllers must be continuous-time")
        inputs = tuple(self.inputs) or tuple(Ks[0].input_labels)
        outputs = tuple(self.outputs) or tuple(Ks[0].output_labels)
        if (len(inputs), len(outputs)) != size[1:]:
            raise DimensionError(f"names for {len(inputs)} inputs and {len(outputs)} "
                                 f"outputs; the controllers have {size[1]} and {size[2]}")
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "axes", tuple(axes))
        object.__setattr__(self, "controllers", Ks)
        object.__setattr__(self, "inputs", tuple(str(s) for s in inputs))
        object.__setattr__(self, "outputs", tuple(str(s) for s in outputs))
        # the nodes' matrices stacked on the grid's shape, for the interpolation (bins
        # pick a controller whole and may differ in order: no stack)
        object.__setattr__(self, "_stack", None if bins else tuple(
            np.stack([np.asarray(getattr(K, M), dtype=float) for K in Ks]).reshape(
                shape + np.shape(getattr(Ks[0], M))) for M in "ABCD"))

    @classmethod
    def from_controllers(cls, grid: dict, controllers, *, inputs=(), outputs=(),
                         interpolation: str = "multilinear") -> GriddedController:
        """The table from ``{name: node values}`` (with bins, ``{name: bin edges}``) and
        the controllers at the nodes (in the bins), in the order of
        :func:`itertools.product` over ``grid``'s values (bins)."""
        if not isinstance(grid, dict) or not grid:
            raise ParameterError("grid must be a non-empty dict {name: node values}")
        return cls(tuple(grid), tuple(grid.values()), tuple(controllers), tuple(inputs),
                   tuple(outputs), interpolation)

    @property
    def bounds(self) -> tuple:
        """Each parameter's range ``(first node, last node)``."""
        return tuple((float(a[0]), float(a[-1])) for a in self.axes)

    @property
    def nodes(self) -> tuple:
        """The grid's nodes, in the order of ``controllers``; with bins, each bin's
        centre (the point per bin in that order)."""
        if self.interpolation == "bins":
            return tuple(tuple((lo + hi) / 2 for lo, hi in b) for b in self.bins)
        return tuple(itertools.product(*(a.tolist() for a in self.axes)))

    @property
    def bins(self) -> tuple:
        """With bins, each bin as a tuple of ``(lo, hi)`` per parameter, in the order of
        ``controllers``.

        Raises
        ------
        ParameterError
            A multilinear table (it has nodes, not bins).
        """
        if self.interpolation != "bins":
            raise ParameterError("a multilinear table has nodes, not bins")
        edges = [list(zip(a[:-1].tolist(), a[1:].tolist())) for a in self.axes]
        return tuple(itertools.product(*edges))

    def bin_index(self, *args, **named) -> int:
        """With bins, the index in ``controllers`` of the bin holding the value (checked
        as :meth:`values`): closed below, open above, the last bin closed at its top.

        Raises
        ------
        ParameterError
            A multilinear table, or a value :meth:`values` refuses.
        """
        if self.interpolation != "bins":
            raise ParameterError("a multilinear table has nodes, not bins")
        p = self.values(*args, **named)
        index = 0
        for v, a in zip(p, self.axes):
            # side="right" puts an edge into the bin above it; the top edge (and a value
            # an ulp beyond, which values() admits) into the last bin
            i = int(np.clip(np.searchsorted(a, v, side="right") - 1, 0, a.size - 2))
            index = index * (a.size - 1) + i
        return index

    def values(self, *args, **named) -> tuple:
        """The parameter values as a tuple in the order of ``names``, checked: a value
        by position or by name for every parameter, finite, inside its range.

        Raises
        ------
        ParameterError
            A missing or unknown name, a value outside the range.
        NonFiniteError
            NaN or infinity.
        """
        return parameter_values(self.names, self.bounds, args, named, "the schedule's range")

    def _cell(self, p) -> list:
        """Per axis ``(index, weight)``: ``p`` lies ``weight`` of the way from node
        ``index`` to the next (weight 0 at a node, and at the last node)."""
        out = []
        for v, a in zip(p, self.axes):
            i = int(np.clip(np.searchsorted(a, v, side="right") - 1, 0, a.size - 1))
            w = 0.0 if i == a.size - 1 else float((v - a[i]) / (a[i + 1] - a[i]))
            out.append((i, min(max(w, 0.0), 1.0)))
        return out

    def at(self, *args, **named) -> control.StateSpace:
        """The controller at one value of the scheduling parameters (``K.at(m3=42.0)``):
        at a node, that node's matrices bit for bit; between nodes, ``a + w (b - a)``
        along each axis in turn.  With bins, the controller of the value's bin
        (:meth:`bin_index`), its matrices bit for bit."""
        if self.interpolation == "bins":
            K = self.controllers[self.bin_index(*args, **named)]
            return control.ss(*(np.array(getattr(K, M), dtype=float) for M in "ABCD"),
                              inputs=list(self.inputs), outputs=list(self.outputs), name="K")
        cell = self._cell(self.values(*args, **named))
        mats = []
        for M in self._stack:
            for i, w in cell:               # each step removes the leading axis
                a = M[i]
                M = a if w == 0.0 else a + w * (M[i + 1] - a)
            mats.append(np.array(M))
        return control.ss(*mats, inputs=list(self.inputs), outputs=list(self.outputs),
                          name="K")

    def to_dict(self) -> dict:
        """JSON-ready description (every float a Python float, which :mod:`json` writes
        as its shortest round-tripping repr: :meth:`from_dict` is exact)."""
        bins = self.interpolation == "bins"
        where = ([dict(zip(self.names, ([lo, hi] for lo, hi in b))) for b in self.bins]
                 if bins else [dict(zip(self.names, node)) for node in self.nodes])
        return {
            "names": list(self.names),
            "axes": [_floats(a) for a in self.axes],
            "inputs": list(self.inputs), "outputs": list(self.outputs),
            "interpolation": self.interpolation,
            "controllers": [{"bin" if bins else "p": w,
                             "A": _floats(K.A), "B": _floats(K.B), "C": _floats(K.C),
                             "D": _floats(K.D)}
                            for w, K in zip(where, self.controllers)],
        }

    @classmethod
    def from_dict(cls, data: dict) -> GriddedController:
        """The controller described by :meth:`to_dict` (exactly).

        Raises
        ------
        InputError
            A missing key, an unknown interpolation, or matrices that do not fit.
        """
        try:
            interpolation = data.get("interpolation", "multilinear")
            if interpolation not in INTERPOLATIONS:
                raise InputError(f"unknown interpolation {interpolation!r}")
            names = tuple(str(n) for n in data["names"])
            axes = tuple(np.asarray(a, dtype=float) for a in data["axes"])
            inputs, outputs = tuple(data["inputs"]), tuple(data["outputs"])
            ny, nu = len(inputs), len(outputs)
            Ks = []
            for i, e in enumerate(data["controllers"]):
                n = len(e["A"])
                shapes = ((n, n), (n, ny), (nu, n), (nu, ny))
                mats = [np.asarray(e[M], dtype=float).reshape(s) if n or M == "D"
                        else np.zeros(s) for M, s in zip("ABCD", shapes)]
                Ks.append(control.ss(*mats))
        except KeyError as exc:
            raise InputError(f"gridded controller description lacks key {exc}") from exc
        except (TypeError, ValueError) as exc:
            if isinstance(exc, InputError):
                raise
            raise InputError(f"malformed gridded controller description: {exc}") from exc
        return cls(names, axes, tuple(Ks), inputs, outputs, interpolation)
