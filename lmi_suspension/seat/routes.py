"""One entry for every seat design: routes, one result type, one certificate.

The seat is designed along several routes -- µ-synthesis as in the paper
(:class:`~.design.MuRoute`), µ-synthesis with hard force, stroke and pole bounds in every
K-step (:class:`~.constrained.ConstrainedRoute`), the µ controller refined to the exact
bump requirements (:class:`~.refine.RefineRoute`), that refinement over a set of
occupants and springs (:class:`~.multimodel.OccupantRoute`) and H∞ with peak bounds by
multi-objective LMIs (:class:`~.bounded.PeakBoundedRoute`).  Each is a small frozen
dataclass of what a user chooses, living beside its algorithm, with a ``name`` and a
``design`` method (the :class:`SeatRoute` protocol); :func:`design_seat` runs any of
them and returns a :class:`~.record.SeatDesign`.  A new route is one such class in one module:
pass an instance to :func:`design_seat`, no registration needed.

Whatever the route, :func:`~.record.certify_seat` checks the controller by computations the
routes do not use to produce it (time simulation of the exact-delay loop, the 1 kHz
sampled-data loop, µ bounds of :func:`~lmi_suspension.mu.mussv` on a dense grid,
worst-case peaks from the closed loop's Gramian, and, given samples of a set of seats,
stability and road figures over them and their mixed µ) and judges the figures against
:class:`~.record.SeatRequirements` (issue 38's targets by default).  :func:`save_seat_design`
and :func:`load_seat_design` write and read any design as a controller file
(``controller.json``'s format), so that ``reproduce``, the CLI, the sweep and a user's
script treat every route alike.  This module is the top of the seat package: it alone
imports the routes, and no module of the package imports it.

Examples
--------
>>> from lmi_suspension.seat.routes import design_seat, route_named
>>> d = design_seat(route_named("peak_bounded"))
>>> d.route, d.K.ninputs, d.K.noutputs, d.Kd.dt
('peak_bounded', 2, 1, 0.001)
>>> bool(d.figures["u_peak"] <= 1500.0 * 1.005)
True
"""

from __future__ import annotations

import logging
import math
from pathlib import Path
from types import MappingProxyType
from typing import Callable, ClassVar, Protocol, runtime_checkable

import control
import numpy as np

from ..errors import InputError, ParameterError
from .augmented import CONSTRAINED_DESIGN, DEFAULT_DESIGN, SeatDesignOptions
from .bounded import PeakBoundedRoute
from .constrained import SHIPPED_CONTROLLER, ConstrainedRoute
from .design import MuRoute
from .discrete_design import SHIPPED_DISCRETE, DiscreteMuRoute
from .multimodel import SHIPPED_OCCUPANTS, OccupantRoute
from .params import SeatParameters
from .record import SeatDesign
from .refine import SHIPPED_REFINED, RefineRoute

__all__ = ["SeatRoute", "ROUTE_NAMES", "SHIPPED_DESIGNS", "route_named", "design_seat",
           "save_seat_design", "load_seat_design"]

logger = logging.getLogger(__name__)

_ROUTES = MappingProxyType({route.name: route for route in (
    MuRoute, ConstrainedRoute, RefineRoute, OccupantRoute, PeakBoundedRoute,
    DiscreteMuRoute)})
#: the routes shipped with the package, by name (:func:`route_named`)
ROUTE_NAMES = tuple(_ROUTES)

#: the designs shipped with the package, by route name (their searches take minutes to
#: hours; ``reproduce`` loads and re-certifies them).  The µ design is not among them:
#: it takes seconds and ``reproduce`` runs it.
SHIPPED_DESIGNS = MappingProxyType({"constrained": SHIPPED_CONTROLLER,
                                    "refined": SHIPPED_REFINED,
                                    "occupants": SHIPPED_OCCUPANTS,
                                    "discrete": SHIPPED_DISCRETE})


@runtime_checkable
class SeatRoute(Protocol):
    """What :func:`design_seat` runs: a frozen dataclass of the route's choices with a
    ``name`` and a ``design`` method.

    ``design(params, rng=..., progress=...)`` returns a :class:`~.record.SeatDesign` for the seat
    ``params``; ``rng`` seeds whatever the route draws at random; ``progress``, if given,
    is called with a line of text per iteration (a D-K iteration, a refinement stage).
    """

    name: ClassVar[str]

    def design(self, params: SeatParameters, *, rng: np.random.Generator,
               progress: Callable[[str], None] | None = None) -> "SeatDesign":
        ...


def route_named(name: str) -> SeatRoute:
    """The route ``name`` of :data:`ROUTE_NAMES` with its default choices.

    Raises
    ------
    ParameterError
        An unknown name.
    """
    if name not in _ROUTES:
        raise ParameterError(f"unknown seat design route {name!r}; the routes are "
                             f"{', '.join(ROUTE_NAMES)}")
    return _ROUTES[name]()


def design_seat(route: SeatRoute | str = "mu", *, params: SeatParameters | None = None,
                rng: np.random.Generator | None = None,
                progress: Callable[[str], None] | None = None) -> SeatDesign:
    """Design a seat controller along ``route``.

    Parameters
    ----------
    route : SeatRoute or str
        A route (any object of the :class:`SeatRoute` protocol) or the name of a shipped
        one with its default choices (:data:`ROUTE_NAMES`).
    params : SeatParameters, optional
        The seat (Table 1 by default).
    rng : numpy.random.Generator, optional
        Seeds the route's random draws (``default_rng(0)`` by default).
    progress : callable, optional
        Called with a line of text per iteration of the route.

    Returns
    -------
    SeatDesign

    Raises
    ------
    ParameterError
        ``route`` is neither a route nor a known name, ``params`` not
        :class:`SeatParameters`, ``rng`` not a Generator.
    InfeasibleError
        The route's requirements cannot be met (for the routes with hard bounds).
    """
    route = route_named(route) if isinstance(route, str) else route
    if not isinstance(route, SeatRoute):
        raise ParameterError(f"route must be a SeatRoute or one of {ROUTE_NAMES}, got "
                             f"{type(route).__name__}")
    params = SeatParameters() if params is None else params
    if not isinstance(params, SeatParameters):
        raise ParameterError(f"params must be SeatParameters, got {type(params).__name__}")
    rng = np.random.default_rng(0) if rng is None else rng
    if not isinstance(rng, np.random.Generator):
        raise ParameterError("rng must be a numpy.random.Generator")
    logger.info("seat design along route %r", route.name)
    d = route.design(params, rng=rng, progress=progress)
    if not isinstance(d, SeatDesign) or d.route != route.name:
        raise ParameterError(f"route {route.name!r} returned {type(d).__name__} "
                             f"{getattr(d, 'route', '')!r}, not its own SeatDesign")
    return d


# ------------------------------------------------------------------------------ files

def save_seat_design(path, d: SeatDesign) -> Path:
    """Write a design as a controller file (``controller.json``'s format): both
    realizations, the route, the seat, the figures and the description in its metadata.
    :func:`load_seat_design` reads every field back equal (the matrices bit for bit),
    ``detail`` aside."""
    from ..io import save_controller

    if not isinstance(d, SeatDesign):
        raise ParameterError(f"d must be a SeatDesign, got {type(d).__name__}")
    return save_controller(path, d.K, inputs=["x1", "x3"], outputs=["u"],
                           metadata=d.metadata(), discrete=d.Kd)


_META_KEYS = ("route", "description", "params", "weights", "design_seconds",
              "discretisation", "primary")


def _default_weights(route: str) -> SeatDesignOptions:
    """The µ weights of a route's default choices (for files that do not say)."""
    return CONSTRAINED_DESIGN if route == "constrained" else DEFAULT_DESIGN


def load_seat_design(path_or_route, *, route: str | None = None) -> SeatDesign:
    """Read a design: a file written by :func:`save_seat_design`, or the shipped design
    of a route name (:data:`SHIPPED_DESIGNS`).

    Files written before designs had routes (the shipped ones, ``save_refined``'s and
    ``save_constrained``'s) carry no route: give it as ``route``, or load them by name.

    Raises
    ------
    InputError
        The file holds no route and none is given, or no discrete realization.
    """
    from ..io import load_controller, load_discrete_controller

    if isinstance(path_or_route, str) and path_or_route in SHIPPED_DESIGNS:
        route, path = path_or_route, SHIPPED_DESIGNS[path_or_route]
    elif isinstance(path_or_route, str) and path_or_route in ROUTE_NAMES:
        raise InputError(f"no shipped design of route {path_or_route!r} (the shipped ones: "
                         f"{', '.join(SHIPPED_DESIGNS)}); design it: "
                         f"design_seat({path_or_route!r})")
    else:
        path = Path(path_or_route)
    K, meta = load_controller(path)
    try:
        Kd, _ = load_discrete_controller(path)
    except (KeyError, InputError) as exc:
        raise InputError(f"{path} holds no discrete realization: {exc}") from exc
    name = meta.get("route", route)
    if name is None:
        raise InputError(f"{path} names no route: pass route=")
    if route is not None and name != route:
        raise InputError(f"{path} holds a design of route {name!r}, not {route!r}")
    K = control.ss(K.A, K.B, K.C, K.D, inputs=["x1", "x3"], outputs=["u"], name=f"K_{name}")
    params = SeatParameters(**meta["params"]) if "params" in meta else SeatParameters()
    weights = (SeatDesignOptions(**{k: tuple(v) if isinstance(v, list) else v
                                    for k, v in meta["weights"].items()})
               if "weights" in meta else _default_weights(str(name)))
    return SeatDesign(route=str(name), K=K, Kd=Kd, params=params, weights=weights,
                      figures={k: v for k, v in meta.items() if k not in _META_KEYS},
                      description=str(meta.get("description", "")),
                      seconds=float(meta.get("design_seconds", math.nan)),
                      primary=str(meta.get("primary", "continuous")))
