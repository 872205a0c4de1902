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

__all__ = ["GriddedController", "parameter_values"]

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
    """State-space controllers at the nodes of a grid, interpolated multilinearly.

    Attributes
    ----------
    names : tuple of str
        The scheduling parameters.
    axes : tuple of numpy.ndarray
        Each parameter's node values, strictly increasing (one value: the parameter is
        held there).
    controllers : tuple of control.StateSpace
        The controller at each node, in the order of :func:`itertools.product` over the
        axes; the same numbers of states, inputs and outputs at every node.
    inputs, outputs : tuple of str
        Signal names.
    """

    names: tuple
    axes: tuple
    controllers: tuple = field(repr=False)
    inputs: tuple = ()
    outputs: tuple = ()

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
        axes = []
        for n, a in zip(names, self.axes):
            a = np.array(a, dtype=float).ravel()
            if a.size < 1 or not np.all(np.isfinite(a)) or np.any(np.diff(a) <= 0):
                raise ParameterError(f"the nodes of {n} must be finite and strictly "
                                     f"increasing, got {a.tolist()}")
            a.setflags(write=False)
            axes.append(a)
        count = int(np.prod([a.size for a in axes]))
        Ks = tuple(as_statespace(K, f"controller {i}") for i, K in enumerate(self.controllers))
        if len(Ks) != count:
            raise DimensionError(f"{len(Ks)} controllers for the {count} nodes of the grid")
        size = (Ks[0].nstates, Ks[0].ninputs, Ks[0].noutputs)
        for i, K in enumerate(Ks):
            if (K.nstates, K.ninputs, K.noutputs) != size:
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
        # the nodes' matrices stacked on the grid's shape, for the interpolation
        shape = tuple(a.size for a in axes)
        object.__setattr__(self, "_stack", tuple(
            np.stack([np.asarray(getattr(K, M), dtype=float) for K in Ks]).reshape(
                shape + np.shape(getattr(Ks[0], M))) for M in "ABCD"))

    @classmethod
    def from_controllers(cls, grid: dict, controllers, *, inputs=(), outputs=()
                         ) -> GriddedController:
        """The table from ``{name: node values}`` and the controllers at the nodes (in
        the order of :func:`itertools.product` over ``grid``'s values)."""
        if not isinstance(grid, dict) or not grid:
            raise ParameterError("grid must be a non-empty dict {name: node values}")
        return cls(tuple(grid), tuple(grid.values()), tuple(controllers), tuple(inputs),
                   tuple(outputs))

    @property
    def bounds(self) -> tuple:
        """Each parameter's range ``(first node, last node)``."""
        return tuple((float(a[0]), float(a[-1])) for a in self.axes)

    @property
    def nodes(self) -> tuple:
        """The grid's nodes, in the order of ``controllers``."""
        return tuple(itertools.product(*(a.tolist() for a in self.axes)))

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
        along each axis in turn."""
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
        return {
            "names": list(self.names),
            "axes": [_floats(a) for a in self.axes],
            "inputs": list(self.inputs), "outputs": list(self.outputs),
            "interpolation": "multilinear",
            "controllers": [{"p": dict(zip(self.names, node)),
                             "A": _floats(K.A), "B": _floats(K.B), "C": _floats(K.C),
                             "D": _floats(K.D)}
                            for node, K in zip(self.nodes, self.controllers)],
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
            if data.get("interpolation", "multilinear") != "multilinear":
                raise InputError(f"unknown interpolation {data['interpolation']!r}")
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
        return cls(names, axes, tuple(Ks), inputs, outputs)
