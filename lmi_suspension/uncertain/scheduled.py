"""Robust stability of a scheduled controller's frozen loops against the plant's remaining
uncertainty (:func:`lpv_robstab`, certificate 4(c) of issue 61).

A controller scheduled on a measured parameter ``p`` (:func:`~lmi_suspension.lpv.lpvsyn`,
:func:`~lmi_suspension.lpv.hinfgs`) is designed on a plant known at each ``p``; the
plant may still carry uncertainty that is *not* measured (a damping, a stiffness: a
:class:`USS` at each ``p``).  Here every frozen loop ``lft(P(p), K(p))`` of the uncertain
plant is formed on a grid (by default the design's certificate grid, four times denser
than the design grid) and :func:`~lmi_suspension.uncertain.robstab` computes its
robust stability margin against that uncertainty.  As for the frozen-parameter H∞
certificate, the result holds for each *constant* ``p`` on the grid, not for a ``p``
that moves during operation, and nothing is claimed between grid points.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable
from dataclasses import dataclass

import control
import numpy as np

from ..errors import AssumptionError, DimensionError, InputError, ParameterError
from . import connect, robstab, uss

__all__ = ["LpvRobstabResult", "lpv_robstab"]


@dataclass(frozen=True)
class LpvRobstabResult:
    """Result of :func:`lpv_robstab`.

    Attributes
    ----------
    names : tuple of str
        The scheduling parameters.
    points : tuple of tuple of float
        The grid points, in the order of :func:`itertools.product` over ``grid``.
    grid : dict
        ``{name: values}`` the points are the product of.
    lower, upper : numpy.ndarray
        :func:`robstab`'s margin bounds at each point (``lower <= α <= upper``; 0 and 0
        where the nominal frozen loop is not stable).
    margin_lower : float
        ``min(lower)``: at every grid point the frozen loop is stable for the uncertainty
        scaled by this factor (robustly stable over the stated ranges where it is > 1).
    margin_upper : float
        ``min(upper)``: at some grid point a perturbation of this size destabilises it.
    worst : dict
        The grid point of ``margin_lower``, ``{name: value}``.
    worst_uncertainty : Mapping
        :func:`robstab`'s destabilising perturbation at the point of ``margin_upper``
        (physical values; empty when none was found).
    results : tuple of RobstabResult or None
        :func:`robstab`'s result at each point (``None`` where the nominal loop is not
        stable).
    warnings : tuple of str
        Nominal loops that are not stable and :func:`robstab`'s own warnings, each with
        its grid point.
    seconds : float
        Wall time.
    """

    names: tuple
    points: tuple
    grid: dict
    lower: np.ndarray
    upper: np.ndarray
    margin_lower: float
    margin_upper: float
    worst: dict
    worst_uncertainty: object
    results: tuple
    warnings: tuple
    seconds: float

    @property
    def robust(self) -> bool:
        """Robustly stable over the stated uncertainty at every grid point (margin > 1)."""
        return bool(self.margin_lower > 1.0)


def _controller(obj):
    """The scheduled controller of a result (``res.K``) or the controller itself."""
    K = getattr(obj, "K", obj)
    if not (hasattr(K, "at") and hasattr(K, "names")):
        raise InputError("expected a scheduled controller (lpvsyn's or hinfgs's result, or "
                         f"its .K), got {type(obj).__name__}")
    return K


def _closed_loop(P, K: control.StateSpace):
    """``lft(P, K)`` of an uncertain plant ``P`` (controls its last inputs, measurements
    its last outputs, as for hinfsyn) and a certain controller, by signal names."""
    ny, nu = K.ninputs, K.noutputs
    nw, nz = P.shape[1] - nu, P.shape[0] - ny
    if nw < 0 or nz < 0:
        raise DimensionError(f"the uncertain plant has {P.shape[1]} inputs and "
                             f"{P.shape[0]} outputs; the controller needs {nu} and {ny}")
    w = [f"w[{i}]" for i in range(nw)]
    z = [f"z[{i}]" for i in range(nz)]
    y = [f"y[{i}]" for i in range(ny)]
    u = [f"u[{i}]" for i in range(nu)]
    Pn = uss(P, inputs=w + u, outputs=z + y)
    Kn = control.ss(K.A, K.B, K.C, K.D, inputs=y, outputs=u)
    return connect([Pn, Kn], inputs=w, outputs=z)


def lpv_robstab(res, usys_at: Callable, grid: dict | None = None, *, omega=None,
                rng: np.random.Generator | None = None) -> LpvRobstabResult:
    """Robust stability margins of a scheduled controller's frozen loops against the
    uncertainty the plant still carries at each parameter value.

    Parameters
    ----------
    res : LpvsynResult, HinfgsResult, ScheduledController or PolytopicController
        The scheduled design (or its controller ``res.K``).
    usys_at : callable
        ``usys_at(*p) -> USS`` (or a ``StateSpace``, with no uncertainty): the uncertain
        plant at the parameter value ``p`` (positionally, in the order of the controller's
        ``names``), with its controls as the last inputs and its measurements as the
        last outputs — the design plant's partition, though not necessarily its
        performance channels.
    grid : dict, optional
        ``{name: values}``; by default the design's certificate grid ``res.check_grid``
        (each design interval cut in four, the ends included).
    omega : array_like, optional
        Passed to :func:`robstab` at every point.
    rng : numpy.random.Generator, optional
        Passed to :func:`robstab` at every point (its default ``default_rng(0)``).

    Returns
    -------
    LpvRobstabResult

    Raises
    ------
    InputError
        ``res`` is not a scheduled design, ``usys_at`` is not callable, no grid was given
        for a bare controller.
    ParameterError
        A grid over other parameters than the controller's, or outside its interval.
    DimensionError
        An uncertain plant whose inputs or outputs cannot take the controller.

    Notes
    -----
    Each point costs one :func:`robstab`: 0.6-0.9 s for one real parameter on a 4-state
    loop (its exact crossing route; measured 2026-12-02), so the 33-point default grid
    takes 20-30 s; pass a coarser ``grid`` for a quick look.

    Examples
    --------
    A mass-spring-damper whose measured mass ``m`` schedules the controller and whose
    damping ``c = 0.2 ± 0.5`` is not measured:

    >>> import control, numpy as np
    >>> from lmi_suspension.lpv import lpvsyn
    >>> from lmi_suspension.uncertain import ureal, uss
    >>> def msd(m, c=0.2):
    ...     return ([[0, 1], [-1 / m, -c / m]], [[0, 0, 0], [1 / m, 0, 1 / m]],
    ...             [[1, 0], [0, 0], [1, 0]], [[0, 0, 0], [0, 0, 0.1], [0, 0.1, 0]])
    >>> res = lpvsyn(lambda m: control.ss(*msd(m)), {"m": [1.0, 4.0]}, 1, 1)
    >>> c = ureal("c", 0.2, plusminus=0.5)
    >>> rs = lpv_robstab(res, lambda m: uss(*msd(m, c)), {"m": [1.0, 4.0]})
    >>> rs.robust, rs.worst
    (True, {'m': 1.0})
    """
    t0 = time.perf_counter()
    K = _controller(res)
    if not callable(usys_at):
        raise InputError("usys_at must be a callable p -> USS")
    if grid is None:
        grid = getattr(res, "check_grid", None)
        if grid is None:
            raise InputError("give the grid {name: values}: a bare controller has no "
                             "certificate grid")
    if not isinstance(grid, dict) or set(grid) != set(K.names):
        raise ParameterError(f"grid must be a dict over the parameters {K.names}, got "
                             f"{grid if not isinstance(grid, dict) else tuple(grid)!r}")
    axes = [np.unique(np.asarray(grid[n], dtype=float).ravel()) for n in K.names]
    points = list(itertools.product(*(a.tolist() for a in axes)))
    check = getattr(K, "values", None) or K.weights    # both raise outside the interval
    for p in points:                                    # every point checked first
        check(*p)
    lower, upper, results, warnings = [], [], [], []
    for p in points:
        where = ", ".join(f"{n}={v:.6g}" for n, v in zip(K.names, p))
        CL = _closed_loop(uss(usys_at(*p)), K.at(*p))
        try:
            r = robstab(CL, omega, rng=rng)
        except AssumptionError:
            warnings.append(f"at {where}: the nominal frozen loop is NOT stable")
            lower.append(0.0)
            upper.append(0.0)
            results.append(None)
            continue
        warnings += [f"at {where}: {w}" for w in r.warnings]
        lower.append(float(r.lower))
        upper.append(float(r.upper))
        results.append(r)
    lower, upper = np.asarray(lower), np.asarray(upper)
    i_lo, i_up = int(np.argmin(lower)), int(np.argmin(upper))
    worst_unc = results[i_up].worst if results[i_up] is not None else {}
    return LpvRobstabResult(tuple(K.names), tuple(points), dict(zip(K.names, axes)), lower,
                            upper, float(lower[i_lo]), float(upper[i_up]),
                            dict(zip(K.names, points[i_lo])), worst_unc, tuple(results),
                            tuple(warnings), time.perf_counter() - t0)
