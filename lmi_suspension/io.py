"""Saving and loading controllers as JSON, exactly.

A saved controller is a continuous-time state-space system with keys ``A``, ``B``, ``C``,
``D`` (lists of rows), ``inputs``, ``outputs`` and free-form ``metadata``. Python's ``json``
writes floats with the shortest repr that round-trips, so loading gives back the same
IEEE-754 numbers bit for bit.
"""

from __future__ import annotations

import json
from pathlib import Path

import control
import numpy as np

from .errors import DimensionError, InputError
from .lti.checks import as_finite_array, as_statespace

__all__ = ["controller_to_dict", "controller_from_dict", "save_controller", "load_controller"]

FORMAT = "lmi_suspension.controller/1"


def _rows(M: np.ndarray) -> list[list[float]]:
    return [[float(v) for v in row] for row in np.asarray(M, dtype=float)]


def controller_to_dict(K, *, inputs=None, outputs=None, metadata=None) -> dict:
    """Describe a continuous-time controller as a JSON-ready dict.

    Examples
    --------
    >>> import control
    >>> from lmi_suspension.io import controller_to_dict, controller_from_dict
    >>> K = control.ss([[-1.0]], [[1.0, 0.5]], [[2.0]], [[0.0, 0.1]])
    >>> d = controller_to_dict(K, inputs=["x1", "x3"], outputs=["u"])
    >>> K2 = controller_from_dict(d)
    >>> bool((K2.A == K.A).all() and (K2.D == K.D).all())
    True
    """
    K = as_statespace(K, "K")
    inputs = list(inputs) if inputs is not None else list(K.input_labels)
    outputs = list(outputs) if outputs is not None else list(K.output_labels)
    if len(inputs) != K.ninputs or len(outputs) != K.noutputs:
        raise DimensionError(
            f"controller has {K.ninputs} inputs and {K.noutputs} outputs; names given for "
            f"{len(inputs)} and {len(outputs)}")
    n = K.nstates
    return {
        "format": FORMAT,
        "A": _rows(np.reshape(K.A, (n, n))),
        "B": _rows(np.reshape(K.B, (n, K.ninputs))),
        "C": _rows(np.reshape(K.C, (K.noutputs, n))),
        "D": _rows(np.reshape(K.D, (K.noutputs, K.ninputs))),
        "inputs": inputs,
        "outputs": outputs,
        "metadata": dict(metadata or {}),
    }


def controller_from_dict(data: dict) -> control.StateSpace:
    """Rebuild the controller saved by :func:`controller_to_dict` (exactly)."""
    try:
        inputs, outputs = list(data["inputs"]), list(data["outputs"])
        D = as_finite_array(data["D"], "D", ndim=2)
        A = np.array(data["A"], dtype=float).reshape(len(data["A"]), -1) if data["A"] else \
            np.zeros((0, 0))
    except KeyError as exc:
        raise InputError(f"controller description lacks key {exc}") from exc
    n = A.shape[0]
    if A.shape != (n, n):
        raise DimensionError(f"A must be square, got {A.shape}")
    nu, ny = len(outputs), len(inputs)
    if D.shape != (nu, ny):
        raise DimensionError(f"D must be {nu}x{ny} for inputs {inputs} and outputs {outputs}")
    A = as_finite_array(A, "A", ndim=2)
    B = as_finite_array(data["B"], "B", ndim=2).reshape(n, ny) if n else np.zeros((0, ny))
    C = as_finite_array(data["C"], "C", ndim=2).reshape(nu, n) if n else np.zeros((nu, 0))
    return control.ss(A, B, C, D, inputs=inputs, outputs=outputs, name="K")


def save_controller(path, K, *, inputs=None, outputs=None, metadata=None) -> Path:
    """Write ``K`` to ``path`` as JSON (see :func:`controller_to_dict`); returns the path."""
    path = Path(path)
    data = controller_to_dict(K, inputs=inputs, outputs=outputs, metadata=metadata)

    def default(obj):  # numpy scalars and arrays in metadata
        if isinstance(obj, np.generic):
            return obj.item()
        if isinstance(obj, np.ndarray):
            return obj.tolist()
        raise TypeError(f"cannot store {type(obj).__name__} in controller metadata")

    text = json.dumps(data, indent=1, default=default, allow_nan=True)
    path.write_text(text + "\n")
    return path


def load_controller(path) -> tuple[control.StateSpace, dict]:
    """Read a controller written by :func:`save_controller`.

    Returns
    -------
    K : control.StateSpace
        The controller, bit-for-bit equal to the saved one.
    metadata : dict
        The saved metadata.
    """
    path = Path(path)
    try:
        data = json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise InputError(f"{path} is not valid JSON: {exc}") from exc
    if not isinstance(data, dict):
        raise InputError(f"{path} does not hold a controller object")
    return controller_from_dict(data), dict(data.get("metadata", {}))
