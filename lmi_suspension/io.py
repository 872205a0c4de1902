"""Saving and loading controllers as JSON, exactly, and exporting them as MATLAB files.

A saved controller is a continuous-time state-space system with keys ``A``, ``B``, ``C``,
``D`` (lists of rows), ``inputs``, ``outputs`` and free-form ``metadata``; a controller
meant for a computer also carries its discrete realization, ``Ad``, ``Bd``, ``Cd``, ``Dd``
and the sample time ``dt`` (s). Python's ``json``
writes floats with the shortest repr that round-trips, so loading gives back the same
IEEE-754 numbers bit for bit.

A file may hold a *scheduled* controller instead, told by its ``format``:

- ``lmi_suspension.gridded_controller/1``
  (:class:`~lmi_suspension.lti.gridded.GriddedController`): ``names`` (the scheduling
  parameters), ``axes`` (each one's node values, increasing), ``inputs``, ``outputs``,
  ``interpolation`` (``"multilinear"``), ``controllers`` (one per node, in the order of
  :func:`itertools.product` over the axes: ``p``, the node as ``{name: value}``, and
  ``A``, ``B``, ``C``, ``D`` as above) and ``metadata``.  ``K.at(m3=42.0)`` interpolates
  the matrices between the nodes; a reader without this package has every node's
  controller in the file.  With ``interpolation`` ``"bins"`` the table is piecewise
  constant: ``axes`` are each parameter's bin *edges* (at least two, increasing), there
  is one controller per bin, in the order of :func:`itertools.product` over each axis's
  bins, each with ``bin``, its ``{name: [lo, hi]}``, instead of ``p`` (the controllers
  of different bins may differ in state dimension); ``K.at(m3=42.0)`` is the controller
  of the bin holding 42 (closed below, open above, the last bin closed at its top),
  bit for bit.
- ``lmi_suspension.scheduled_controller/1`` (:func:`~lmi_suspension.lpv.lpvsyn`'s
  :class:`~lmi_suspension.lpv.ScheduledController`) and
  ``lmi_suspension.polytopic_controller/1`` (:func:`~lmi_suspension.lpv.hinfgs`'s):
  see :func:`scheduled_to_dict`.

:func:`load_controller` returns whichever the file holds, first in its tuple; every
scheduled controller offers ``names``, ``bounds`` and ``at(**p)``, a python-control
``StateSpace``, and loads exactly (its ``at`` bit for bit at every node).
"""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import control
import numpy as np

from .errors import DimensionError, InputError
from .lti.checks import as_finite_array, as_statespace

__all__ = ["controller_to_dict", "controller_from_dict", "save_controller", "load_controller",
           "discrete_from_dict", "load_discrete_controller", "save_controller_mat",
           "load_controller_mat", "scheduled_to_dict", "scheduled_from_dict",
           "save_scheduled_controller", "load_scheduled_controller", "save_scheduled_mat"]

FORMAT = "lmi_suspension.controller/1"


def _rows(M: np.ndarray) -> list[list[float]]:
    return [[float(v) for v in row] for row in np.asarray(M, dtype=float)]


def controller_to_dict(K, *, inputs=None, outputs=None, metadata=None, discrete=None) -> dict:
    """Describe a continuous-time controller as a JSON-ready dict (with ``discrete``, a
    discrete-time realization of it, also ``Ad``, ``Bd``, ``Cd``, ``Dd`` and ``dt``).

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
    data = {
        "format": FORMAT,
        "A": _rows(np.reshape(K.A, (n, n))),
        "B": _rows(np.reshape(K.B, (n, K.ninputs))),
        "C": _rows(np.reshape(K.C, (K.noutputs, n))),
        "D": _rows(np.reshape(K.D, (K.noutputs, K.ninputs))),
        "inputs": inputs,
        "outputs": outputs,
        "metadata": dict(metadata or {}),
    }
    if discrete is not None:
        Kd = discrete
        if not isinstance(Kd, control.StateSpace):
            raise InputError(f"discrete must be a control.StateSpace, got {type(Kd).__name__}")
        dt = _sample_time(Kd.dt, "discrete's sample time")
        if (Kd.ninputs, Kd.noutputs) != (K.ninputs, K.noutputs):
            raise DimensionError("the discrete realization must have the controller's "
                                 "inputs and outputs")
        nd = Kd.nstates
        data.update(Ad=_rows(np.reshape(Kd.A, (nd, nd))),
                    Bd=_rows(np.reshape(Kd.B, (nd, Kd.ninputs))),
                    Cd=_rows(np.reshape(Kd.C, (Kd.noutputs, nd))),
                    Dd=_rows(np.reshape(Kd.D, (Kd.noutputs, Kd.ninputs))), dt=dt)
    return data


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


def discrete_from_dict(data: dict) -> control.StateSpace:
    """The discrete realization stored by :func:`controller_to_dict` (exactly).

    Raises
    ------
    InputError
        The description holds no discrete realization.

    Examples
    --------
    >>> import control
    >>> K = control.ss([[-1.0]], [[1.0, 0.5]], [[2.0]], [[0.0, 0.1]])
    >>> d = controller_to_dict(K, discrete=control.c2d(K, 1e-3, "tustin"))
    >>> discrete_from_dict(d).dt
    0.001
    """
    if "dt" not in data:
        raise InputError("the controller description holds no discrete realization "
                         "(keys Ad, Bd, Cd, Dd, dt)")
    cont = controller_from_dict(data)
    view = {"A": data.get("Ad"), "B": data.get("Bd"), "C": data.get("Cd"),
            "D": data.get("Dd"), "inputs": data["inputs"], "outputs": data["outputs"]}
    if any(v is None for v in view.values()):
        raise InputError("the discrete realization needs Ad, Bd, Cd, Dd and dt")
    Kd = controller_from_dict(view)
    dt = _sample_time(data["dt"], "dt")
    return control.ss(Kd.A, Kd.B, Kd.C, Kd.D, dt, inputs=cont.input_labels,
                      outputs=cont.output_labels, name="Kd")


def load_discrete_controller(path) -> tuple[control.StateSpace, dict]:
    """Read the discrete realization of a controller file (see :func:`discrete_from_dict`)."""
    data = _read(path)
    return discrete_from_dict(data), dict(data.get("metadata", {}))


def _sample_time(dt, what: str) -> float:
    """``dt`` as a positive float of seconds (``True`` and ``None``, python-control's
    unspecified sample times, are refused)."""
    if isinstance(dt, bool) or not (isinstance(dt, (int, float)) and dt > 0):
        raise InputError(f"{what} must be a positive number of seconds, got {dt!r}")
    return float(dt)


def _read(path) -> dict:
    path = Path(path)
    try:
        data = json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise InputError(f"{path} is not valid JSON: {exc}") from exc
    if not isinstance(data, dict):
        raise InputError(f"{path} does not hold a controller object")
    return data


def save_controller(path, K, *, inputs=None, outputs=None, metadata=None,
                    discrete=None) -> Path:
    """Write ``K`` to ``path`` as JSON (see :func:`controller_to_dict`); returns the path."""
    path = Path(path)
    data = controller_to_dict(K, inputs=inputs, outputs=outputs, metadata=metadata,
                              discrete=discrete)

    text = json.dumps(data, indent=1, default=_json_default, allow_nan=True)
    path.write_text(text + "\n")
    return path


def load_controller(path) -> tuple:
    """Read a controller written by :func:`save_controller` or, when the file holds a
    scheduled controller (its ``format`` is one of :data:`SCHEDULED_FORMATS`), by
    :func:`save_scheduled_controller`.

    Returns
    -------
    K : control.StateSpace or scheduled controller
        The controller, bit-for-bit equal to the saved one; a scheduled controller
        (:class:`~lmi_suspension.lti.gridded.GriddedController`,
        :class:`~lmi_suspension.lpv.ScheduledController` or
        :class:`~lmi_suspension.lpv.PolytopicController`) gives the controller at the
        parameters' values with ``K.at(m3=...)``.
    metadata : dict
        The saved metadata.

    Examples
    --------
    >>> import control, tempfile, pathlib
    >>> from lmi_suspension.lti.gridded import GriddedController
    >>> K = GriddedController.from_controllers(
    ...     {"m3": [30.0, 70.0]}, [control.ss([], [], [], [[0.0, -1e4]]),
    ...                            control.ss([], [], [], [[0.0, -3e4]])],
    ...     inputs=["x1", "x3"], outputs=["u"])
    >>> path = save_scheduled_controller(pathlib.Path(tempfile.mkdtemp()) / "K.json", K)
    >>> K2, meta = load_controller(path)
    >>> K2.names, K2.at(m3=40.0).D
    (('m3',), array([[     0., -15000.]]))
    """
    data = _read(path)
    if data.get("format") in SCHEDULED_FORMATS:
        return scheduled_from_dict(data), dict(data.get("metadata", {}))
    return controller_from_dict(data), dict(data.get("metadata", {}))


def save_controller_mat(path, K, *, inputs=None, outputs=None, ts: float | None = None,
                        metadata=None) -> Path:
    """Write ``K`` as a MATLAB ``.mat`` file (``scipy.io.savemat``) for Simulink, dSPACE or
    a test rig.

    Variables: ``A``, ``B``, ``C``, ``D`` (doubles, so the file holds the same IEEE-754
    numbers as the controller), ``InputName`` and ``OutputName`` (cell arrays of
    strings), and, for a discrete realization, ``Ts``; a ``description`` string holds the
    metadata as JSON.  In MATLAB: ``s = load(path); K = ss(s.A, s.B, s.C, s.D)`` (add
    ``s.Ts`` for the discrete one) and ``K.InputName = s.InputName``.

    Parameters
    ----------
    path : path-like
        The ``.mat`` file.
    K : control.StateSpace
        Continuous-time controller.
    inputs, outputs : list of str, optional
        Names (default: the controller's labels).
    ts : float, optional
        Write the zero-order-hold discretisation at this sample time, s, instead
        (``control.c2d``, method ``"zoh"``).
    metadata : dict, optional
        Stored as JSON text in ``description``.

    Examples
    --------
    >>> import control, tempfile, pathlib
    >>> from lmi_suspension.io import save_controller_mat, load_controller_mat
    >>> K = control.ss([[-1.0]], [[1.0, 0.5]], [[2.0]], [[0.0, 0.1]])
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "K.mat"
    >>> _ = save_controller_mat(path, K, inputs=["x1", "x3"], outputs=["u"])
    >>> K2, names = load_controller_mat(path)
    >>> bool((K2.A == K.A).all() and (K2.D == K.D).all()), names
    (True, (['x1', 'x3'], ['u']))
    """
    import scipy.io

    d = controller_to_dict(K, inputs=inputs, outputs=outputs, metadata=metadata)
    n, ny, nu = len(d["A"]), len(d["inputs"]), len(d["outputs"])
    A = np.array(d["A"], dtype=float).reshape(n, n)
    B = np.array(d["B"], dtype=float).reshape(n, ny)
    C = np.array(d["C"], dtype=float).reshape(nu, n)
    D = np.array(d["D"], dtype=float).reshape(nu, ny)
    data = {"A": A, "B": B, "C": C, "D": D,
            "InputName": np.array(d["inputs"], dtype=object).reshape(-1, 1),
            "OutputName": np.array(d["outputs"], dtype=object).reshape(-1, 1),
            "description": json.dumps(d["metadata"], default=_json_default)}
    if ts is not None:
        ts = float(ts)
        if not (np.isfinite(ts) and ts > 0):
            raise InputError(f"ts must be a positive sample time in seconds, got {ts!r}")
        Kd = control.c2d(control.ss(A, B, C, D), ts, method="zoh")
        data.update(A=np.asarray(Kd.A, dtype=float).reshape(n, n),
                    B=np.asarray(Kd.B, dtype=float).reshape(n, ny),
                    C=np.asarray(Kd.C, dtype=float).reshape(nu, n),
                    D=np.asarray(Kd.D, dtype=float).reshape(nu, ny), Ts=ts)
    path = Path(path)
    scipy.io.savemat(path, data, do_compression=False, oned_as="column")
    return path


def load_controller_mat(path) -> tuple[control.StateSpace, tuple[list, list]]:
    """Read a file written by :func:`save_controller_mat`: the controller (discrete when
    the file has ``Ts``) and its ``(input names, output names)``."""
    import scipy.io

    path = Path(path)
    try:
        m = scipy.io.loadmat(path)
    except (OSError, ValueError, scipy.io.matlab.MatReadError) as exc:
        raise InputError(f"{path} is not a readable .mat file: {exc}") from exc
    try:
        A, B, C, D = (np.atleast_2d(np.asarray(m[k], dtype=float)) for k in "ABCD")
        names = tuple([str(np.ravel(x)[0]) for x in np.ravel(m[k])]
                      for k in ("InputName", "OutputName"))
    except KeyError as exc:
        raise InputError(f"{path} lacks the controller variable {exc}") from exc
    n = A.shape[0] if A.size else 0
    A = A.reshape(n, n)
    B, C = B.reshape(n, D.shape[1]), C.reshape(D.shape[0], n)
    ts = float(np.ravel(m["Ts"])[0]) if "Ts" in m else 0
    K = control.ss(A, B, C, D, ts, inputs=names[0], outputs=names[1], name="K")
    return K, names


def _json_default(obj):
    """numpy scalars and arrays in metadata, as JSON numbers and lists."""
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"cannot store {type(obj).__name__} in controller metadata")


# ----------------------------------------------------------------- scheduled controllers
SCHEDULED_FORMAT = "lmi_suspension.scheduled_controller/1"
#: :func:`~lmi_suspension.lpv.hinfgs`'s controller: the box and the vertex controllers
POLYTOPIC_FORMAT = "lmi_suspension.polytopic_controller/1"
#: :class:`~lmi_suspension.lti.gridded.GriddedController`: controllers at grid nodes
GRIDDED_FORMAT = "lmi_suspension.gridded_controller/1"
#: the formats :func:`load_controller` reads as a scheduled controller
SCHEDULED_FORMATS = (SCHEDULED_FORMAT, POLYTOPIC_FORMAT, GRIDDED_FORMAT)


def scheduled_to_dict(K, *, table=None, frozen: bool = True, metadata=None) -> dict:
    """Describe a :class:`~lmi_suspension.lpv.ScheduledController` (or the
    :class:`~lmi_suspension.lpv.LpvsynResult` holding it: its ``gamma`` and
    ``gamma_lmi`` then go into the metadata) as a JSON-ready dict; or a
    :class:`~lmi_suspension.lpv.PolytopicController` of ``hinfgs`` (or its
    ``HinfgsResult``), format ``lmi_suspension.polytopic_controller/1``: the box, the
    vertices, the level and each vertex controller's ``A``, ``B``, ``C``, ``D``
    (``table`` and ``frozen`` do not apply: the vertex controllers are the data); or a
    :class:`~lmi_suspension.lti.gridded.GriddedController`, format
    ``lmi_suspension.gridded_controller/1`` (see the module docstring; the node
    controllers are the data).

    The description holds everything :meth:`ScheduledController.at` needs (the
    Lyapunov coefficients ``X_i``, ``Y_i``, the scalings, the plant and basis as tables:
    see :meth:`~lmi_suspension.lpv.ScheduledController.to_dict`) and, with ``frozen``,
    the frozen controller at every node of the design grid in this module's controller
    format (``A``, ``B``, ``C``, ``D``, ``inputs``, ``outputs``, ``metadata`` with the
    parameter values and the level), for a reader without this package.

    Examples
    --------
    >>> import control, numpy as np
    >>> from lmi_suspension.lpv import lpvsyn, ScheduledController
    >>> def msd(m):
    ...     return control.ss([[0, 1], [-1 / m, -0.2 / m]], [[0, 0, 0], [1 / m, 0, 1 / m]],
    ...                       [[1, 0], [0, 0], [1, 0]], [[0, 0, 0], [0, 0, 0.1], [0, 0.1, 0]])
    >>> K = lpvsyn(msd, {"m": [1.0, 2.0, 4.0]}, 1, 1).K
    >>> K2 = scheduled_from_dict(scheduled_to_dict(K))
    >>> bool(np.array_equal(K2.at(m=2.5).A, K.at(m=2.5).A))       # a table node
    True
    """
    from .lti.gridded import GriddedController
    from .synthesis.hinfgs import PolytopicController

    metadata = dict(metadata or {})
    if isinstance(K, GriddedController):
        if table is not None:
            raise InputError("a gridded controller has no tables: it is saved exactly by "
                             "its node controllers")
        return {"format": GRIDDED_FORMAT, **K.to_dict(), "metadata": metadata}
    if hasattr(K, "K") and hasattr(K, "gamma_check"):        # an LpvsynResult, HinfgsResult
        metadata = {"gamma": float(K.gamma), "gamma_lmi": float(K.gamma_lmi), **metadata}
        K = K.K
    if isinstance(K, PolytopicController):
        if table is not None:
            raise InputError("a polytopic controller has no tables: it is saved exactly "
                             "by its vertex controllers")
        # the vertex controllers are the saved data: no separate frozen entries
        return {"format": POLYTOPIC_FORMAT, **K.to_dict(), "metadata": metadata}
    data = {"format": SCHEDULED_FORMAT, **K.to_dict(table)}
    if frozen:
        entries = []
        grid = K.grid if K.grid is not None else dict(zip(K.names, data["plant"]["axes"]))
        for p in itertools.product(*(np.asarray(grid[n], dtype=float).tolist()
                                     for n in K.names)):
            Kp, level, _ = K.build(*p)
            entries.append(controller_to_dict(
                Kp, metadata={"p": dict(zip(K.names, p)), "level": float(level)}))
        data["frozen"] = entries
    data["metadata"] = metadata
    return data


def scheduled_from_dict(data: dict):
    """The :class:`~lmi_suspension.lpv.ScheduledController` (or
    :class:`~lmi_suspension.lpv.PolytopicController`, or
    :class:`~lmi_suspension.lti.gridded.GriddedController`) of :func:`scheduled_to_dict`
    (exactly)."""
    from .lti.gridded import GriddedController
    from .synthesis.hinfgs import PolytopicController
    from .synthesis.lpv import ScheduledController

    fmt = data.get("format") if isinstance(data, dict) else None
    if fmt == GRIDDED_FORMAT:
        return GriddedController.from_dict(data)
    if fmt == POLYTOPIC_FORMAT:
        return PolytopicController.from_dict(data)
    if fmt != SCHEDULED_FORMAT:
        raise InputError(f"not a scheduled controller description (format one of "
                         f"{SCHEDULED_FORMATS})")
    return ScheduledController.from_dict(data)


def save_scheduled_controller(path, K, *, table=None, frozen: bool = True,
                              metadata=None) -> Path:
    """Write a scheduled controller to ``path`` as JSON (:func:`scheduled_to_dict`)."""
    path = Path(path)
    data = scheduled_to_dict(K, table=table, frozen=frozen, metadata=metadata)
    path.write_text(json.dumps(data, indent=1, default=_json_default, allow_nan=False) + "\n")
    return path


def load_scheduled_controller(path):
    """Read a file of :func:`save_scheduled_controller`: ``(K, metadata)``, ``K`` a
    :class:`~lmi_suspension.lpv.ScheduledController` equal to the saved one (its
    ``at`` bit for bit at every table node), or a
    :class:`~lmi_suspension.lpv.PolytopicController` (its ``at`` bit for bit
    everywhere)."""
    data = _read(path)
    return scheduled_from_dict(data), dict(data.get("metadata", {}))


def save_scheduled_mat(path, K, grid=None, *, dt: float | None = None) -> Path:
    """Write the frozen controllers of a scheduled controller on a grid as a MATLAB
    ``.mat`` file (``scipy.io.savemat``), MATLAB's layout of an array of models.

    Variables: ``A`` (n x n x N), ``B`` (n x ny x N), ``C`` (nu x n x N), ``D``
    (nu x ny x N) of the ``N`` grid points (doubles: the same IEEE-754 numbers as
    ``K.at(p)``), ``P`` (N x k, the parameter values of each, in the order of
    :func:`itertools.product`), ``ParameterName`` (cell array), one vector per
    parameter with its grid values, ``Level`` (N, the level each controller was formed
    at) and, with ``dt``, the Tustin realizations (:meth:`ScheduledController.at_discrete`)
    instead, with ``Ts``.  In MATLAB: ``s = load(path); K = ss(s.A, s.B, s.C, s.D)``
    is an ``N``-model array.

    Parameters
    ----------
    grid : dict, optional
        ``{name: values}``; default the design grid.
    dt : float, optional
        Sample time of discrete realizations (s).
    """
    import scipy.io

    grid = K.grid if grid is None else grid
    if not isinstance(grid, dict) or set(grid) != set(K.names):
        raise InputError(f"grid must be a dict over the parameters {K.names}")
    axes = [np.unique(as_finite_array(grid[n], f"grid[{n!r}]").ravel()) for n in K.names]
    points = list(itertools.product(*(a.tolist() for a in axes)))
    mats, levels = [], []
    for p in points:
        Kp, level, _ = K.build(*p)
        if dt is not None:
            Kp = K.at_discrete(*p, dt=dt)
        mats.append(tuple(np.asarray(M, dtype=float) for M in (Kp.A, Kp.B, Kp.C, Kp.D)))
        levels.append(level)
    data = {k: np.stack([m[i] for m in mats], axis=-1) for i, k in enumerate("ABCD")}
    data.update(P=np.asarray(points, dtype=float).reshape(len(points), len(K.names)),
                ParameterName=np.array(list(K.names), dtype=object).reshape(-1, 1),
                Level=np.asarray(levels, dtype=float))
    data.update({n: a for n, a in zip(K.names, axes) if n not in data})
    if dt is not None:
        data["Ts"] = float(dt)
    path = Path(path)
    scipy.io.savemat(path, data, do_compression=False, oned_as="column")
    return path
