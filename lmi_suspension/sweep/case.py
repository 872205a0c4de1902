"""One sweep case, evaluated: a pure function of the :class:`~.spec.Case` and the controller,
run on whichever worker the scheduler picks.

A case that raises records its error in its row (``error``) instead of ending the sweep.
"""

from __future__ import annotations

import math
import time
import traceback

import numpy as np

from ..seat import (
    SeatParameters,
    bump,
    bump_limit,
    closed_loop_stable,
    iso8608_road,
    simulate,
    white_noise,
)
from ..seat.schedule_use import controller_for_seat
from .spec import PASSIVE, PLANT_AXES, ROADS, Case, design_route, schedule_errors

__all__ = ["METRIC_COLUMNS", "compute_design", "controller_from_saved", "compute_limit", "design_key", "error_row", "evaluate_batch",
           "evaluate_case", "limit_key"]

#: the result columns of every row, after the case's index, controller and axis values
METRIC_COLUMNS = ("delay_used", "stable", "stable_sim", "peak_z3dd", "rms_z3dd",
                  "wrms_z3dd", "vdv_z3dd", "peak_x1", "x1_within_limit", "peak_u",
                  "peak_u_command", "saturation_time", "limit_peak", "limit_ratio",
                  "seconds", "error")
#: the LP step of the physical limit, s (bump_limit's default: 1500 steps over 3 s)
_LIMIT_DT = 2e-3


def _params(values: dict) -> SeatParameters:
    return SeatParameters(**{k: float(v) for k, v in values.items() if k in PLANT_AXES})


def _road(road: str, settings: dict, values: dict, rng: np.random.Generator):
    s = dict(settings)
    s.update({k: v for k, v in values.items() if k in ROADS[road]})
    if road == "bump":
        return bump(s["height"], s["length"], s["speed_kmh"], t_end=s["duration"], dt=1e-3)
    if road == "iso8608":
        return iso8608_road(str(s["road_class"]), s["speed_kmh"], s["duration"], 1e-3, rng=rng)
    return white_noise(s["duration"], 1e-3, psd=s["psd"], bandwidth_hz=s["bandwidth_hz"],
                       rng=rng)


def limit_key(case: Case, road: str, settings: dict) -> tuple | None:
    """What the physical limit of ``case`` depends on (its seat and its bump), or None where
    there is no limit to compute (other roads)."""
    if road != "bump":
        return None
    seat = tuple(sorted((k, float(v)) for k, v in case.values.items() if k in PLANT_AXES))
    bump_values = tuple((k, float(case.values.get(k, settings[k]))) for k in ROADS["bump"])
    return seat + bump_values + (("duration", float(settings["duration"])),)


def compute_limit(key: tuple) -> float:
    """The clairvoyant LP's certified peak ``|z3''|`` for a key of :func:`limit_key`
    (nan where the LP fails: the row says so in ``limit_ratio``)."""
    d = dict(key)
    p = _params(d)
    road = bump(d["height"], d["length"], d["speed_kmh"], t_end=d["duration"], dt=1e-3)
    try:
        return float(bump_limit(road, p, dt=_LIMIT_DT).certified_peak)
    except Exception:  # an infeasible or failed LP: no limit for this seat, not no sweep
        return float("nan")


def design_key(case: Case) -> tuple | None:
    """What the per-case design of ``case`` depends on (its route and seat), or None where
    the case runs a saved controller or none."""
    route = design_route(case.controller)
    if route is None:
        return None
    return (("route", route),) + tuple(sorted((k, float(v)) for k, v in case.values.items()
                                              if k in PLANT_AXES))


def compute_design(key: tuple, seed: int) -> dict:
    """The controller designed along the route for the seat of a :func:`design_key`, as a
    saved dict (the route's figures in the metadata), or ``{"error": ...}`` where the
    design fails."""
    from ..io import controller_to_dict
    from ..seat.routes import design_seat

    values = dict(key)
    try:
        d = design_seat(values["route"], params=_params(values),
                        rng=np.random.default_rng(seed))
    except Exception as exc:  # the cases of this seat record it; the sweep goes on
        return {"error": f"design failed: {type(exc).__name__}: {exc}"}
    return controller_to_dict(d.K, inputs=["x1", "x3"], outputs=["u"],
                              metadata=d.metadata())


def controller_from_saved(data: dict):
    """The controller of a saved dict: a ``StateSpace``
    (:func:`~lmi_suspension.io.controller_from_dict`) or, when its ``format`` says so, a
    scheduled controller (:func:`~lmi_suspension.io.scheduled_from_dict`)."""
    from ..io import SCHEDULED_FORMATS, controller_from_dict, scheduled_from_dict

    if data.get("format") in SCHEDULED_FORMATS:
        return scheduled_from_dict(data)
    return controller_from_dict(data)


def _blank_row(case: Case) -> dict:
    """A case's key and values, every result column empty."""
    return {"case": case.index, "controller": case.controller, **case.values,
            **dict.fromkeys(METRIC_COLUMNS)}


def error_row(case: Case, message: str) -> dict:
    """The row of a case that could not be evaluated."""
    return {**_blank_row(case), "error": message, "seconds": 0.0}


def evaluate_case(case: Case, K, road: str, settings: dict, limit: float | None) -> dict:
    """The row of one case (``K`` the controller, None for the passive seat;
    ``settings`` the road's, with the simulation ``step``).  A scheduled ``K`` runs at
    the case's seat plus its estimate errors (the ``*_error`` axes,
    :func:`~lmi_suspension.seat.schedule_use.controller_for_seat`)."""
    t0 = time.perf_counter()
    row = _blank_row(case)
    try:
        p = _params(case.values)
        K = controller_for_seat(K, p, schedule_errors(case.values))
        delay = float(case.values.get("delay", 0.0))
        r = _road(road, settings, case.values, case.rng())
        res = simulate(K, r, delay=delay, params=p, dt=settings["step"])
        m = res.metrics()
        stable_lin = True if K is None else bool(closed_loop_stable(K, delay, p))
        peak = float(m.peak_z3dd)
        row.update(delay_used=res.delay, stable=stable_lin, stable_sim=bool(m.stable),
                   peak_z3dd=peak, rms_z3dd=float(m.rms_z3dd),
                   wrms_z3dd=float(m.weighted_rms_z3dd), vdv_z3dd=float(m.vdv_z3dd),
                   peak_x1=float(m.peak_x1), x1_within_limit=bool(m.x1_within_limit),
                   peak_u=float(m.peak_u), peak_u_command=float(m.peak_u_command),
                   saturation_time=float(m.saturation_time))
        if limit is not None:
            row["limit_peak"] = float(limit)
            row["limit_ratio"] = peak / limit if limit > 0 else math.nan
    except Exception as exc:  # recorded in the row; the sweep goes on
        last = traceback.extract_tb(exc.__traceback__)[-1]
        row["error"] = f"{type(exc).__name__}: {exc} ({last.filename.split('/')[-1]}:" \
                       f"{last.lineno})"
    row["seconds"] = time.perf_counter() - t0
    return row


def evaluate_batch(cases: list, controllers: dict, road: str, settings: dict,
                   limits: dict, designs: dict | None = None) -> list[dict]:
    """Rows of a batch of cases.  ``controllers`` maps each controller entry to its saved
    dict (rebuilt exactly here, on the worker); ``limits`` maps limit keys to peaks and
    ``designs`` design keys to saved dicts (:func:`compute_design`)."""
    built = {name: controller_from_saved(d) for name, d in controllers.items()
             if name != PASSIVE and design_route(name) is None}
    built[PASSIVE] = None
    for key, d in (designs or {}).items():
        built[key] = d if "error" in d else controller_from_saved(d)
    rows = []
    for case in cases:
        key = limit_key(case, road, settings)
        limit = None if key is None else limits.get(key)
        dkey = design_key(case)
        K = built[case.controller] if dkey is None else built[dkey]
        if isinstance(K, dict):  # a failed design
            rows.append(error_row(case, K["error"]))
            continue
        rows.append(evaluate_case(case, K, road, settings, limit))
    return rows

