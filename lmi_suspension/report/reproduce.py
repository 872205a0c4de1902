"""The paper's whole study in one call: µ design, comparison controllers, simulations, figures.

:func:`reproduce` runs every stage of the seat-suspension study and writes figures (Figs.
7–15 of the paper plus the peak-versus-delay study), ``summary.json`` and ``controller.json``
into one directory. :func:`comparison_table` formats the headline figures as text.

``controller.json`` is the shipped seat controller scheduled on what the seat measures
(issue 62, :data:`~lmi_suspension.seat.schedule_use.SHIPPED_SCHEDULED`), with its
schedule; where that cannot be loaded, the shipped controller for every occupant (30–70
kg, springs and dampers ±20 %, delay 0–25 ms;
:data:`~lmi_suspension.seat.multimodel.SHIPPED_OCCUPANTS`); never this run's µ design: the
µ design goes unstable once the seat spring is about 17 % soft (issue 38), and a user who
takes the run's controller takes it to a seat that is not the nominal one.  The µ design
is ``controllers/mu.json``.

Deviation from the paper, on purpose: the white-noise floor velocity has a two-sided PSD of
``1e-4`` (m/s)²/Hz in a 50 Hz band (about the level of an ISO 8608 class-C road at 30 km/h),
not the paper's unit PSD, which would be a floor velocity of about 10 m/s RMS and keep the
1500 N actuator saturated all the time.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import shutil
import textwrap
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import LmiSuspensionError, ParameterError

__all__ = [
    "CONTROLLER_NAMES",
    "ControllerSummary",
    "ReproduceSummary",
    "comparison_table",
    "reproduce",
]

logger = logging.getLogger(__name__)

#: Names of the compared controllers, in table order.
CONTROLLER_NAMES = ("passive", "hinf_lmi_nominal", "hinf_riccati", "mu", "mu_constrained",
                    "mu_refined", "mu_occupants", "mu_1khz", "mu_scheduled")
#: the controller written to ``controller.json`` (the one ``simulate``, ``sweep`` and a
#: user take): the shipped seat controller scheduled on what the seat measures (issue 62,
#: :data:`~lmi_suspension.seat.schedule_use.SHIPPED_SCHEDULED`), with its schedule; where
#: it cannot be loaded the design for every occupant, spring and delay of the set
#: (:data:`~lmi_suspension.seat.multimodel.SHIPPED_OCCUPANTS`), else the µ design (the
#: summary's facts then say so)
EXPORTED = "mu_scheduled"
#: the robust controller the exported one is compared with on the map and over the mass
ROBUST = "mu_occupants"
#: the estimate errors a scheduled controller is evaluated with in the Monte-Carlo where
#: its file's metadata gives none (``estimate_errors``): issue 62's ±5 kg on the mass
_ESTIMATE_ERRORS = {"m3": 5.0}
#: the stages of :func:`reproduce`, in order: each announces itself with one progress
#: message that does not start with a space (details follow indented), and its wall time
#: is ``summary.json``'s ``timings[name]``
STAGES = ("mu_design", "mu_analysis", "mu_constrained", "mu_refined", "mu_occupants",
          "mu_1khz", "mu_scheduled", "hinf_lmi_nominal", "hinf_riccati",
          "limit",
          *(f"simulate_{n}" for n in CONTROLLER_NAMES), "iso_C", "monte_carlo",
          "occupant_map", "worst_seats", "ratio_over_mass", "figures")
_LONG_NAMES = {"passive": "passive", "hinf_lmi_nominal": "H∞ LMI (no delay)",
               "hinf_riccati": "H∞ Riccati", "mu": "µ (D-K)",
               "mu_constrained": "µ, hard bounds", "mu_refined": "µ, refined",
               "mu_occupants": "µ, every occupant", "mu_1khz": "µ at 1 kHz",
               "mu_scheduled": "µ, scheduled"}
#: the curve of controllers each tuned for exactly its mass (ratio_over_mass.png)
_PER_MASS = "tuned for exactly that mass"
#: sample time of every controller's discrete realization in controllers/<name>.json
_SAMPLE_TIME = 1e-3

_NOISE_PSD = 1e-4        # (m/s)²/Hz, two-sided; see the module docstring
_NOISE_BAND_HZ = 50.0


@dataclass(frozen=True)
class _Settings:
    """Run lengths and steps of a full or a quick run."""

    bump_t_end: float
    noise_t_end: float
    iso_t_end: float
    road_dt: float
    sim_dt: float
    limit_dt: float
    mc_n: int
    #: Dask workers of the Monte-Carlo sweep and of the occupant map (0: in this process)
    mc_workers: int
    #: the occupant map's grid: m3 (kg), k1 relative to Table 1, delays (s); its
    #: simulation step (s) and record length (s)
    map_m3: tuple
    map_k1_rel: tuple
    map_delays: tuple
    map_step: float
    map_t_end: float
    #: the search for the set's worst force and stroke (``worst_bump_seats``): samples
    #: besides the 128 corners, and climbs per figure
    search_n: int = 200
    search_starts: int = 3
    #: the masses of the ratio-over-mass figure (kg; the per-mass controllers' own
    #: masses are added)
    ratio_m3: tuple = (30.0, 35.0, 40.0, 45.0, 50.0, 55.0, 60.0, 65.0, 70.0)


# The map reaches past the set (m3 30-70 kg, k1 ±20 %) far enough to show where the
# exported controller loses stability: a seat spring 40-50 % soft (measured 2026-11-28 at
# delays 0, 12.5 and 25 ms, every m3 of the grid).  Its size keeps reproduce within 2
# minutes: 63 seats × 3 delays of 3 s records took 46 s of a 118 s run on this 2-core
# machine (0.15 s a case, 0.6 s a seat for its limit LP), so the grid is 49 seats × the
# two end delays, on 1.5 s records: the bump is over in 0.24 s, and each limit was the
# same to 1e-9 on 1.5 s as on 3 s (seats 30/70/43.3 kg on k1 -20/+20/0 %) in half the time.
_FULL = _Settings(bump_t_end=3.0, noise_t_end=3.0, iso_t_end=3.0, road_dt=1e-3, sim_dt=2e-4,
                  limit_dt=2e-3, mc_n=64, mc_workers=2,
                  map_m3=(20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0),
                  map_k1_rel=(-0.5, -0.4, -0.3, -0.2, 0.0, 0.2, 0.3),
                  map_delays=(0.0, 0.025), map_step=5e-4, map_t_end=1.5)
_QUICK = _Settings(bump_t_end=1.5, noise_t_end=1.0, iso_t_end=1.0, road_dt=1e-3, sim_dt=5e-4,
                   limit_dt=5e-3, mc_n=4, mc_workers=0, map_m3=(30.0, 70.0),
                   map_k1_rel=(-0.5, 0.0, 0.2), map_delays=(0.025,), map_step=5e-4, map_t_end=1.5,
                   search_n=0, search_starts=0, ratio_m3=(30.0, 50.0, 70.0))


def _monte_carlo(controller: Path, cfg: _Settings, delay_range, params, seed: int,
                 nominal_limit: float, road, estimate_errors: Mapping | None = None) -> dict:
    """The Monte-Carlo over the uncertainty set as a sweep (:mod:`lmi_suspension.sweep`):
    ``cfg.mc_n`` cases on ``cfg.mc_workers`` Dask workers, each also tested for linear
    stability with its exact delay; the table and its trade-off figure go to
    ``monte_carlo/`` beside the other results.  The samples are drawn over the set the
    exported controller is designed for (:class:`~lmi_suspension.seat.occupants.OccupantSet`:
    m3, every spring and damper), as the occupant map's box is; a scheduled controller
    runs at each sample's values plus an estimate error drawn in ``±estimate_errors[name]``
    (the sweep's ``<name>_error`` axes).  Returns the summary's ``monte_carlo`` entry."""
    from ..seat.occupants import OccupantSet
    from ..sweep import SweepSpec, read_results, run_sweep
    from ..sweep.spec import PLANT_AXES

    ranges = [(n, float(lo), float(hi)) for n, lo, hi in OccupantSet(nominal=params).ranges()]
    if delay_range[1] > delay_range[0]:
        ranges.append(("delay", float(delay_range[0]), float(delay_range[1])))
    errors = {n: float(e) for n, e in (estimate_errors or {}).items() if e > 0}
    ranges += [(f"{n}_error", -e, e) for n, e in errors.items()]
    # the nominal seat's limit only (one LP per sample cost 0.34 s, twice the simulation)
    spec = SweepSpec(controllers=(str(controller),), samples=cfg.mc_n, ranges=tuple(ranges),
                     road="bump", duration=float(road.t[-1]), seed=seed, limit=False,
                     step=cfg.sim_dt)
    out = controller.parent / "monte_carlo"
    if out.exists():
        shutil.rmtree(out)  # a new controller: the previous run's cases are not this one's
    res = run_sweep(spec, out, workers=cfg.mc_workers)
    rows = read_results(out)[0].to_pylist()
    # an unstable sample is the worst; one that raised has no figures and never is
    score = [-math.inf if r["error"] is not None else
             r["peak_z3dd"] if r["stable"] and r["stable_sim"] else math.inf for r in rows]
    k_worst = int(np.argmax(score))
    worst = rows[k_worst]
    peak = math.nan if worst["peak_z3dd"] is None else worst["peak_z3dd"]
    own = math.nan
    if math.isfinite(score[k_worst]):
        # the sample with the largest peak against its own limit too (one LP: its seat is
        # not the nominal one the samples are divided by); the certified peak, as the
        # occupant map and certify_occupants take it
        from ..seat import bump_limit

        seat = dataclasses.replace(params, **{n: worst[n] for n, _, _ in ranges
                                              if n in PLANT_AXES})
        try:
            own = bump_limit(road, seat, dt=cfg.limit_dt).certified_peak
        except LmiSuspensionError as exc:
            logger.info("Monte-Carlo: no limit for its worst sample (%s)", exc)
    return {
        "n": cfg.mc_n, "ranges": {n: [lo, hi] for n, lo, hi in ranges if n != "delay"},
        "estimate_errors": errors,
        "delay_range": [float(d) for d in delay_range], "seed": seed,
        "peak_z3dd": [r["peak_z3dd"] for r in rows],
        "delays": [r.get("delay", float(delay_range[0])) for r in rows],
        "worst": {k: v for k, v in worst.items() if k not in ("controller", "seconds")},
        "worst_ratio_to_limit": peak / nominal_limit,
        # of the sample with the largest peak (not the largest ratio over the samples)
        "worst_own_limit": own, "worst_ratio_to_own_limit": peak / own,
        # (its wall time is the stage's, in "timings")
        "sweep": {"workers": res.workers, "failed": res.n_failed,
                  "table": "monte_carlo/results.parquet"},
    }


def _occupant_map(controller: Path, cfg: _Settings, params, seed: int,
                  compare: Mapping | None = None) -> tuple:
    """The exported controller over occupant mass × seat spring: a grid sweep
    (:mod:`lmi_suspension.sweep`, ``cfg.mc_workers`` Dask workers) of ``m3`` × ``k1`` ×
    delay on the bump, each cell's peak ``|z̈3|`` over *its own* physical limit (the LP of
    :func:`~lmi_suspension.seat.bump_limit` for that seat) and its exact-delay stability;
    a scheduled controller runs at each cell's own values (no estimate error).  The
    controllers of ``compare`` (``{name: file}``) run on the same grid in the same sweep
    (the limits are computed once per seat).  The table goes to ``occupant_map/``.
    Returns ``(entry, table, spec, worst)``: the summary's ``occupant_map`` entry (the
    compared controllers' under ``entry["compared"][name]``), the sweep's table and
    spec, and the exported controller's worst row inside the set: the first unstable
    one in case order if any, else the one of the largest ratio (cases that raised, and
    cells whose limit LP failed, are counted apart, never the worst)."""
    from ..seat.occupants import OccupantSet
    from ..sweep import SweepSpec, read_results, run_sweep

    compare = dict(compare or {})
    ranges = dict((n, (lo, hi)) for n, lo, hi in OccupantSet(nominal=params).ranges())
    k1_values = tuple(params.k1 * (1 + r) for r in cfg.map_k1_rel)
    spec = SweepSpec(controllers=(str(controller), *(str(c) for c in compare.values())),
                     grid=(("m3", cfg.map_m3), ("k1", k1_values), ("delay", cfg.map_delays)),
                     road="bump", duration=cfg.map_t_end, seed=seed, limit=True,
                     step=cfg.map_step)
    out = controller.parent / "occupant_map"
    if out.exists():
        shutil.rmtree(out)
    # its figure is drawn by the caller, with the set's box
    res = run_sweep(spec, out, workers=cfg.mc_workers, figures=False)
    table = read_results(out)[0]
    all_rows = table.to_pylist()

    def inside(r):  # a relative tolerance: the grid's k1 are products of floats
        return all(lo * (1 - 1e-9) <= r[n] <= hi * (1 + 1e-9)
                   for n, (lo, hi) in ranges.items() if n in ("m3", "k1"))

    def failed(r):  # the case raised: no figures, neither stable nor unstable
        return r["error"] is not None

    def unstable(r):  # by the Nyquist count, or diverged in the (saturating) simulation
        return not failed(r) and not (r["stable"] and r["stable_sim"])

    def has_ratio(r):  # its limit LP may have failed (nan)
        return r["limit_ratio"] is not None and math.isfinite(r["limit_ratio"])

    keep = ("m3", "k1", "delay", "stable", "stable_sim", "peak_z3dd", "limit_peak",
            "limit_ratio", "peak_u", "peak_u_command", "peak_x1", "error")

    def summarise(path) -> tuple:
        rows = [r for r in all_rows if r["controller"] == str(path)]
        in_set = [r for r in rows if inside(r)]
        unstable_in = [r for r in in_set if unstable(r)]
        scored = [r for r in in_set if not failed(r) and not unstable(r) and has_ratio(r)]
        # an unstable seat of the set is its worst (the first in case order); else the ratio
        worst = unstable_in[0] if unstable_in else (
            max(scored, key=lambda r: r["limit_ratio"]) if scored else None)
        return {
            "controller": str(path), "cells": len(rows),
            "unstable_cells": sum(unstable(r) for r in rows),
            "unstable_cells_in_set": len(unstable_in),
            "failed_cells": sum(failed(r) for r in rows),
            "cells_in_set_without_limit": sum(not failed(r) and not unstable(r)
                                              and not has_ratio(r) for r in in_set),
            "worst_in_set": None if worst is None else {k: worst[k] for k in keep},
        }, worst

    entry, worst = summarise(controller)
    entry.update({
        "grid": {"m3": list(cfg.map_m3), "k1": list(k1_values), "delay": list(cfg.map_delays)},
        "set": {"m3": list(ranges["m3"]), "k1": list(ranges["k1"])},
        "step": cfg.map_step,
        "sweep": {"workers": res.workers, "failed": res.n_failed,
                  "table": "occupant_map/results.parquet"},
        "compared": {name: summarise(path)[0] for name, path in compare.items()},
    })
    return entry, table, spec, worst


def _map_panel(table, entry: Mapping, path, title: str) -> dict:
    """One controller's cells of the occupant map as a panel of
    :func:`~lmi_suspension.report.figures.plot_occupant_maps`: per (k1, m3) the worst ratio
    over the delays, stable where every delay is (by the Nyquist count and the
    simulation)."""
    m3, k1 = entry["grid"]["m3"], entry["grid"]["k1"]
    ratio = np.full((len(k1), len(m3)), np.nan)
    stable = np.ones((len(k1), len(m3)), dtype=bool)
    for r in table.to_pylist():
        if r["controller"] != str(path) or r["error"] is not None:
            continue
        i = int(np.argmin(np.abs(np.asarray(k1) - r["k1"])))
        j = int(np.argmin(np.abs(np.asarray(m3) - r["m3"])))
        if not (r["stable"] and r["stable_sim"]):
            stable[i, j] = False
        elif r["limit_ratio"] is not None and math.isfinite(r["limit_ratio"]):
            ratio[i, j] = np.fmax(ratio[i, j], r["limit_ratio"])
    worst = entry.get("worst_in_set")
    return {"title": title, "m3": m3, "k1": k1, "ratio": ratio, "stable": stable,
            "worst": None if worst is None else (worst["m3"], worst["k1"])}


def _save_scheduled_mat(path: Path, Ks, metadata: Mapping) -> Path:
    """A scheduled controller for MATLAB: its node controllers as an array of models
    (``A`` n × n × N, ``B``, ``C``, ``D``; ``P`` N × k the nodes, ``ParameterName``),
    the layout of :func:`~lmi_suspension.io.save_scheduled_mat`; doubles, so the numbers
    are the file's.  Where the node controllers differ in order (a bin's controller
    designed smaller), ``A``, ``B``, ``C``, ``D`` are N × 1 cell arrays of each node's
    matrices instead, and ``Nx`` gives the orders (in MATLAB: ``K = cellfun(@ss, s.A,
    s.B, s.C, s.D, 'UniformOutput', false)``); padding them to one order would add modes
    that are not the controller's."""
    import scipy.io

    from ..seat.schedule_use import schedule_nodes

    nodes = schedule_nodes(Ks)
    mats = [Ks.at(**p) for p in nodes]
    orders = [int(K.nstates) for K in mats]
    if len(set(orders)) == 1:
        data = {M: np.stack([np.asarray(getattr(K, M), dtype=float) for K in mats], axis=-1)
                for M in "ABCD"}
    else:
        data = {}
        for M in "ABCD":
            cells = np.empty((len(mats), 1), dtype=object)
            for i, K in enumerate(mats):
                cells[i, 0] = np.asarray(getattr(K, M), dtype=float)
            data[M] = cells
    data.update(Nx=np.asarray(orders, dtype=float),
                P=np.array([[p[n] for n in Ks.names] for p in nodes], dtype=float),
                ParameterName=np.array(list(Ks.names), dtype=object).reshape(-1, 1),
                InputName=np.array(["x1", "x3"], dtype=object).reshape(-1, 1),
                OutputName=np.array(["u"], dtype=object).reshape(-1, 1),
                Description=str(metadata.get("description", "")))
    scipy.io.savemat(path, data, do_compression=False, oned_as="column")
    return path


@dataclass(frozen=True)
class ControllerSummary:
    """Headline figures of one controller.

    Attributes
    ----------
    name : str
        Key in ``summary.json`` (one of :data:`CONTROLLER_NAMES`).
    delays : tuple of float
        Delays simulated, s.
    peak_z3dd : tuple of float
        Peak ``|z̈3|`` on the bump at each delay, m/s² (``nan`` if the run diverged).
    peak_x1, peak_u : tuple of float
        Peak deflection (m) and applied force (N) on the bump at each delay.
    stable : tuple of bool
        Linear closed loop stable with the exact delay (Nyquist), at each delay.
    delay_margin : float
        Smallest delay at which stability is lost, s (``inf``: none below 1 s; the passive
        seat has no loop and gets ``inf``).
    limit_ratio : tuple of float
        ``peak_z3dd / physical limit`` at each delay.
    error : str
        Why the controller is missing (empty if it was designed).
    peak_u_command : tuple of float
        Peak commanded force on the bump at each delay, N (above 1500 N the actuator
        clips and the loop is not the linear one designed).
    sampled_peak_z3dd : tuple of float
        Peak ``|z̈3|`` of the 1 kHz sampled-data loop on the bump at each delay (the
        controllers shipped with a discrete realization; empty otherwise).
    fastest_pole : float
        Largest pole magnitude of the controller, rad/s (0 for the passive seat). Above
        the Nyquist rate ``π/dt`` of the 1 kHz realization written beside it
        (3142 rad/s), that realization does not resolve the pole.
    """

    name: str
    delays: tuple
    peak_z3dd: tuple
    peak_x1: tuple
    peak_u: tuple
    stable: tuple
    delay_margin: float
    limit_ratio: tuple
    error: str = ""
    peak_u_command: tuple = ()
    sampled_peak_z3dd: tuple = ()
    fastest_pole: float = 0.0

    @property
    def stable_on_interval(self) -> bool:
        """Stable at every simulated delay and margin beyond the largest one."""
        return bool(not self.error and all(self.stable)
                    and self.delay_margin > max(self.delays))


@dataclass(frozen=True)
class ReproduceSummary:
    """What :func:`reproduce` computed and wrote.

    Attributes
    ----------
    out_dir : pathlib.Path
        The output directory.
    files : tuple of pathlib.Path
        Every file written.
    controllers : tuple of ControllerSummary
        In the order of :data:`CONTROLLER_NAMES`.
    limit_peak : float
        Physical limit of the bump (LP optimum), m/s².
    mu_peak, mu_lower_peak : float
        Peaks of the µ upper and lower bounds of the µ design.
    seconds : float
        Wall time of the whole run.
    timings : mapping of str -> float
        Wall time of each stage, s.
    data : mapping
        Everything written to ``summary.json``.
    facts : tuple of str
        Facts about the designs that a reader of the table needs (controller poles that
        the 1 kHz realizations do not resolve, actuator saturation on the bump), one
        sentence each; also ``summary.json``'s ``facts``. They are properties of the
        compared designs, not failures of the run, so they are not logged as warnings.
    """

    out_dir: Path
    files: tuple
    controllers: tuple
    limit_peak: float
    mu_peak: float
    mu_lower_peak: float
    seconds: float
    timings: Mapping[str, float] = field(repr=False)
    data: Mapping = field(repr=False)
    facts: tuple = ()

    def controller(self, name: str) -> ControllerSummary:
        """The summary of the controller called ``name``."""
        for c in self.controllers:
            if c.name == name:
                return c
        raise KeyError(name)


def _design_api():
    """The seat designs (imported late: they are heavy, and tests replace them)."""
    from types import SimpleNamespace

    from ..io import load_controller
    from ..seat import augmented, design, record, refine, routes, schedule_use
    return SimpleNamespace(
        design_seat=routes.design_seat, load_seat_design=routes.load_seat_design,
        load_scheduled=lambda: load_controller(schedule_use.SHIPPED_SCHEDULED),
        load_at_mass=lambda: load_controller(schedule_use.SHIPPED_AT_MASS),
        certify_seat=record.certify_seat,
        load_refined_tradeoff=refine.load_refined_tradeoff,
        analyse_uncertainty=design.analyse_uncertainty,
        design_nominal_hinf=design.design_nominal_hinf,
        DEFAULT_DESIGN=augmented.DEFAULT_DESIGN, DEFAULT_MUSYN=design.DEFAULT_MUSYN)


def _jsonable(obj):
    """Plain JSON data: numpy to Python, dataclasses to dicts, non-finite floats to None."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: _jsonable(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, Mapping):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        value = float(obj)
        return value if math.isfinite(value) else None
    if isinstance(obj, (str, type(None))):
        return obj
    if isinstance(obj, Path):
        return str(obj)
    return repr(obj)


def _check_delays(delays) -> tuple:
    try:
        values = tuple(float(d) for d in delays)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"delays must be a sequence of numbers, got {delays!r}") from exc
    if not values:
        raise ParameterError("delays must not be empty")
    if any(not math.isfinite(d) or d < 0 for d in values):
        raise ParameterError(f"delays must be finite and >= 0 s, got {delays!r}")
    return tuple(sorted(set(values)))


def _sim_dt(delays: Sequence[float], dt: float) -> float | None:
    """``dt`` if every delay is a whole number of steps, else ``None`` (simulate's choice)."""
    for d in delays:
        r = d / dt
        if abs(r - round(r)) > 1e-6 * max(1.0, r):
            return None
    return dt


def _pick(delays: Sequence[float], k: int = 3) -> list:
    """Up to ``k`` delays spread over the list (first, middle, last)."""
    if len(delays) <= k:
        return list(delays)
    idx = np.unique(np.round(np.linspace(0, len(delays) - 1, k)).astype(int))
    return [delays[i] for i in idx]


def reproduce(out_dir, *, progress: Callable[[str], None] | None = None,
              rng: np.random.Generator | None = None,
              delays: Sequence[float] = (0, .005, .01, .015, .02, .025),
              quick: bool = False) -> ReproduceSummary:
    """Run the seat-suspension study and write its figures and data into ``out_dir``.

    Stages: the µ design (D-K iteration, progress reported per iteration); the comparison
    controllers (passive seat; nominal H∞ by LMIs ignoring the delay; the Riccati H∞
    baseline); the physical limit of the bump (LP, :func:`~lmi_suspension.seat.bump_limit`);
    bump and white-noise simulations of every controller at every delay with the exact
    delay and saturation; linear stability (Nyquist, exact delay) at each delay and the
    delay margin of each controller; an ISO 8608 class-C road at 30 km/h at the smallest and
    largest delay; for the exported controller (``controller.json``), a seeded Monte-Carlo
    over the occupant set (mass, springs and dampers) with delays drawn from
    ``[0, max(delays)]`` (the sample of the largest peak reported, also against its
    own limit) and the occupant map: a grid sweep of ``m3`` × ``k1`` reaching past the
    set, at the map's own delays
    (0 and 25 ms whatever ``delays``; 25 ms with ``quick``), each cell's peak over its
    own physical limit and its exact-delay stability, with the worst seat in the set
    replayed for its figure; and, in the set's seven parameters, the seats where its
    commanded force and stroke on the bump are largest, found by
    :func:`~lmi_suspension.seat.worstcase.worst_bump_seats` at the run's delays (the
    summary's ``occupant_map["searched"]``; a requirement missed there is a fact).

    Files written: ``fig07_bump.png`` … ``fig15_mu_bounds.png`` (the paper's figures),
    ``peak_vs_delay.png``, ``iso_C_z3dd.png``, ``summary.json`` (non-finite numbers are
    written as ``null``; a ``null`` delay margin means no loss of stability below 1 s) and
    ``controller.json`` (the controller scheduled on the occupant's measured values, with
    its schedule, ``y = [x1, x3]`` in m to ``u`` in N; its µ with the paper's weights at
    the nominal seat and its 1 kHz loop at every scheduling value
    (:func:`~lmi_suspension.seat.schedule_use.sampled_schedule_check`) recomputed here;
    the controller for every occupant, then the µ design, where the shipped files cannot
    be loaded, which the summary's facts then say) and ``controller.mat`` (a scheduled
    one's node controllers as an array of models); ``occupant_map.png`` (its map beside
    the robust controller's on one colour scale, the set's box and the stability
    boundary drawn), ``ratio_over_mass.png`` (peak over each seat's own limit along the
    mass: the schedule, the robust controller and the controllers tuned for exactly one
    mass, :data:`~lmi_suspension.seat.schedule_use.SHIPPED_AT_MASS`, at their masses),
    ``occupant_map/`` (the map's sweep table), ``worst_case.png`` (the worst seat of the
    map in the set, on the bump: ``z̈3`` against that seat's own limit, force, stroke);
    ``controllers/<name>.json`` for every designed controller, each with its 1 kHz
    discrete realization (``Ad``, ``Bd``, ``Cd``, ``Dd``, ``dt``);
    ``force_commanded_vs_applied.png``, ``mu_bounds_constrained.png``,
    ``mu_bounds_refined.png`` and ``tradeoff_refined.png`` (the shipped trade-off of the
    refinement over the force bound, :func:`~lmi_suspension.seat.refine.load_refined_tradeoff`,
    with this run's µ and refined controllers).

    The µ design with hard force and stroke bounds (``mu_constrained``,
    :func:`~lmi_suspension.seat.constrained.design_constrained_mu`) takes minutes, so the
    shipped one is loaded and re-certified here (µ bounds, worst-case force and stroke,
    poles), and simulated like the others, also as its 1 kHz sampled-data loop; so are the
    refined controller (``mu_refined``), the controller for every occupant
    (``mu_occupants``, four refinement rounds of 8 to 14 minutes each) and the µ design
    made on the plant sampled at 1 kHz (``mu_1khz``,
    :class:`~lmi_suspension.seat.discrete_design.DiscreteMuRoute`: its file's discrete
    realization is the controller, ``A``–``D`` its bilinear image; its sampled-data loop is
    what runs).

    Parameters
    ----------
    out_dir : str or path
        Output directory (created if missing; existing files of the same name are replaced).
    progress : callable, optional
        Called with one line of text per stage and per D-K iteration.
    rng : numpy.random.Generator, optional
        Source of every random number: it seeds one independent stream each for the
        design, the µ analysis, the noise road, the ISO road and the Monte-Carlo samples;
        ``numpy.random.default_rng(0)`` if omitted, so the run is reproducible.
    delays : sequence of float
        Actuator delays to simulate, s.
    quick : bool
        Short records, coarser steps, at most two delays, a four-sample Monte-Carlo and a
        six-cell occupant map (for tests; the figures are then rough).

    Returns
    -------
    ReproduceSummary

    Raises
    ------
    ParameterError
        Bad ``delays`` or ``rng``.
    LmiSuspensionError
        The µ design or the limit LP failed (comparison controllers that fail to design
        are recorded in ``summary.json`` instead).
    """
    from .. import __version__
    from ..errors import InputError
    from ..io import save_controller, save_controller_mat, save_scheduled_controller
    from ..seat.sampled import discretise_controller, fastest_pole, simulate_sampled
    from ..seat.schedule_use import (controller_for_seat, is_scheduled,
                                     sampled_schedule_check, schedule_nodes)
    from ..seat import (
        SeatParameters,
        bump,
        bump_limit,
        closed_loop_stable,
        iso8608_road,
        simulate,
        stability_delay_margin,
        white_noise,
    )
    from . import figures

    t_start = time.perf_counter()
    say = progress if progress is not None else (lambda message: None)
    if rng is None:
        rng = np.random.default_rng(0)
    if not isinstance(rng, np.random.Generator):
        raise ParameterError("rng must be a numpy.random.Generator")
    # one independent stream per stage, so that the roads and the Monte-Carlo samples do
    # not change when an algorithm upstream draws a different number of random numbers
    # (the µ lower bound's restarts did, and moved the Monte-Carlo worst case)
    rng_design, rng_analysis, rng_noise, rng_iso, rng_mc = (
        np.random.default_rng(int(seed)) for seed in rng.integers(2**63, size=5))
    delays = _check_delays(delays)
    cfg = _QUICK if quick else _FULL
    if quick and len(delays) > 2:
        delays = (delays[0], delays[-1])
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    params = SeatParameters()
    api = _design_api()
    timings: dict[str, float] = {}
    files: list[Path] = []

    def stage(name: str, message: str):
        say(message)
        logger.info(message)
        return name, time.perf_counter()

    def done(token):
        name, t0 = token
        timings[name] = time.perf_counter() - t0

    # --- µ design --------------------------------------------------------------------
    tok = stage("mu_design", "µ design (D-K iteration) ...")

    # the µ route's own result (its D-K history, dense-grid bounds) is the design's detail
    mu_design = api.design_seat("mu", params=params, rng=rng_design,
                                progress=lambda line: say("  " + line)).detail
    done(tok)
    say(f"  µ peak upper {mu_design.mu_peak:.4f}, lower {mu_design.mu_lower_peak:.4f}, "
        f"controller order {mu_design.K.nstates}")
    tok = stage("mu_analysis", "µ analysis with the paper's norm-bounded uncertainty ...")
    mu_checks = api.analyse_uncertainty(mu_design.K, rng=rng_analysis)
    for check in mu_checks:
        say(f"  {check.structure}: µ upper {check.mu_peak:.4f}, lower "
            f"{check.mu_lower_peak:.4f}")
    done(tok)

    # --- the shipped designs (their searches take minutes): loaded and re-certified ----
    # every route alike: its file read by load_seat_design, its µ bounds, worst cases and
    # poles recomputed by certify_seat with the design's own µ weights (the bump is
    # simulated below with every other controller)
    errors: dict[str, str] = {}

    def shipped(name, route, message, describe):
        tok = stage(name, message)
        result = None
        try:
            d = api.load_seat_design(route)
            cert = api.certify_seat(d.K, Kd=d.Kd, params=d.params, design=d.weights,
                                    delays=(), rng=np.random.default_rng(
                                        int(rng_analysis.integers(2**63))))
            result = (d, cert)
            c = cert.mu
            say(f"  µ upper {c.mu_peak:.4f}, lower {c.mu_lower_peak:.4f}; "
                + describe(c) + f"fastest pole {c.fastest_pole:.0f} rad/s "
                f"(controller {c.controller_fastest_pole:.0f})")
        except (LmiSuspensionError, OSError) as exc:
            errors[name] = f"{type(exc).__name__}: {exc}"
            say(f"  {name} failed: {errors[name]}")
        done(tok)
        return result

    constrained = shipped(
        "mu_constrained", "constrained",
        "µ design with hard force/stroke bounds (shipped, re-certified) ...",
        lambda c: (f"worst case over floor velocities of the bump's energy: |u| "
                   f"{c.u_peak:.0f} N, |x1| {c.x1_peak:.4f} m; "))
    refined = shipped(
        "mu_refined", "refined", "µ controller refined to the force/stroke/pole bounds "
        "(shipped, re-certified) ...", lambda c: "")
    occupants = shipped(
        "mu_occupants", "occupants", "seat controller for every occupant, spring and "
        "delay of the set (shipped, re-certified) ...", lambda c: "")
    # designed at 1 kHz: its discrete realization is the controller, K its bilinear image
    at_1khz = shipped(
        "mu_1khz", "discrete", "µ design on the plant sampled at 1 kHz (shipped, "
        "re-certified) ...", lambda c: "")
    # scheduled on what the seat measures: its schedule is the exported controller; at
    # the nominal seat it is re-certified with the paper's weights like the others, and
    # its 1 kHz loop is checked against the continuous one at every scheduling value
    tok = stage("mu_scheduled", "seat controller scheduled on what the seat measures "
                "(shipped, re-certified at the nominal seat, 1 kHz loop at every "
                "scheduling value) ...")
    scheduled = None
    try:
        Ks, meta_s = api.load_scheduled()
        if not is_scheduled(Ks):
            raise InputError("mu_scheduled.json does not hold a scheduled controller")
        K_nom = controller_for_seat(Ks, params)
        cert_s = api.certify_seat(K_nom, params=params, delays=(), rng=np.random.default_rng(
            int(rng_analysis.integers(2**63))))
        check_1k = sampled_schedule_check(
            Ks, dt=_SAMPLE_TIME, delays=(delays[0], delays[-1]),
            road=bump(t_end=cfg.bump_t_end, dt=cfg.road_dt), params=params)
        scheduled = (Ks, dict(meta_s), cert_s, check_1k)
        say(f"  scheduled on {', '.join(Ks.names)}; at the nominal seat µ upper "
            f"{cert_s.mu.mu_peak:.4f}, lower {cert_s.mu.mu_lower_peak:.4f}; 1 kHz loop "
            f"within {check_1k.gap:.2%} of the continuous one at {len(check_1k.nodes)} "
            f"scheduling values ({'within' if check_1k.passed else 'NOT within'} "
            f"{check_1k.tolerance:.1%})")
    except (LmiSuspensionError, OSError, ValueError) as exc:
        errors["mu_scheduled"] = f"{type(exc).__name__}: {exc}"
        say(f"  mu_scheduled failed: {errors['mu_scheduled']}")
    done(tok)

    # --- comparison controllers ------------------------------------------------------
    controllers: dict[str, object] = {"passive": None}
    for name, method in (("hinf_lmi_nominal", "lmi"), ("hinf_riccati", "riccati")):
        tok = stage(name, f"nominal H∞ design ({method}, delay ignored) ...")
        try:
            controllers[name] = api.design_nominal_hinf(method=method)
        except LmiSuspensionError as exc:
            errors[name] = f"{type(exc).__name__}: {exc}"
            say(f"  {name} failed: {errors[name]}")
        done(tok)
    controllers["mu"] = mu_design.K
    discrete = {}
    for name, loaded in (("mu_constrained", constrained), ("mu_refined", refined),
                         ("mu_occupants", occupants), ("mu_1khz", at_1khz)):
        if loaded is not None:
            controllers[name], discrete[name] = loaded[0].K, loaded[0].Kd
    if scheduled is not None:
        # in the comparison: the schedule at the nominal seat's values (and its 1 kHz loop)
        controllers["mu_scheduled"] = controller_for_seat(scheduled[0], params)
        discrete["mu_scheduled"] = discretise_controller(controllers["mu_scheduled"],
                                                         _SAMPLE_TIME, warn_unresolved=False)

    # --- roads and the physical limit ------------------------------------------------
    road_bump = bump(t_end=cfg.bump_t_end, dt=cfg.road_dt)
    road_noise = white_noise(cfg.noise_t_end, cfg.road_dt, psd=_NOISE_PSD,
                             bandwidth_hz=_NOISE_BAND_HZ, rng=rng_noise)
    tok = stage("limit", "physical limit of the bump (LP) ...")
    limit = bump_limit(road_bump, params, dt=cfg.limit_dt)
    done(tok)
    say(f"  limit: peak |z3''| >= {limit.peak:.3f} m/s² "
        f"(re-simulated {limit.certified_peak:.3f})")

    # --- simulations and stability ---------------------------------------------------
    dt = _sim_dt(delays, cfg.sim_dt)
    runs: dict[str, dict[str, dict[float, object]]] = {"bump": {}, "noise": {}}
    per_ctrl: dict[str, dict] = {}
    summaries = []
    # passive runs are shared between delays; each entry holds its result, so that no id
    # is reused by a later result while its entry lives (the sampled runs are not kept
    # elsewhere: a freed one's id, reused, once gave a loop another loop's figures)
    metrics_of: dict[int, tuple] = {}

    def metrics(res):
        if id(res) not in metrics_of:
            metrics_of[id(res)] = (res, dataclasses.asdict(res.metrics()))
        return dict(metrics_of[id(res)][1])

    def bump_value(row, key):
        return row["bump"][key] if row["bump"]["stable"] else math.nan

    for name in CONTROLLER_NAMES:
        if name in errors:
            per_ctrl[name] = {"error": errors[name]}
            nan = (math.nan,) * len(delays)
            summaries.append(ControllerSummary(name, delays, nan, nan, nan,
                                               (False,) * len(delays), math.nan, nan,
                                               error=errors[name]))
            continue
        K = controllers[name]
        tok = stage(f"simulate_{name}", f"simulating {_LONG_NAMES[name]} at "
                    f"{len(delays)} delays (bump, noise) ...")
        pole = 0.0 if K is None else fastest_pole(K)
        entry: dict = {"order": 0 if K is None else int(K.nstates), "fastest_pole": pole,
                       "resolved_at_sample_time": pole < math.pi / _SAMPLE_TIME}
        for road_name, road in (("bump", road_bump), ("noise", road_noise)):
            runs[road_name][name] = {}
            if K is None:  # passive: the delay changes nothing
                res = simulate(None, road, params=params, dt=dt)
                runs[road_name][name] = {d: res for d in delays}
            else:
                for d in delays:
                    runs[road_name][name][d] = simulate(K, road, delay=d, params=params, dt=dt)
        rows = []
        for d in delays:
            row = {"delay": d,
                   "stable_linear": True if K is None else closed_loop_stable(K, d, params)}
            for road_name in ("bump", "noise"):
                row[road_name] = metrics(runs[road_name][name][d])
            row["bump"]["ratio_to_limit"] = row["bump"]["peak_z3dd"] / limit.peak
            if name in discrete:
                sampled = simulate_sampled(discrete[name], road_bump, delay=d, params=params)
                row["bump_sampled"] = dict(metrics(sampled),
                                           sample_time=float(discrete[name].dt))
            rows.append(row)
        entry["per_delay"] = rows
        margin = math.inf if K is None else stability_delay_margin(K, params)
        entry["delay_margin"] = margin
        done(tok)
        say(f"  delay margin {margin * 1e3:.1f} ms" if math.isfinite(margin)
            else "  no loss of stability below 1 s")

        s = ControllerSummary(
            name=name, delays=delays,
            peak_z3dd=tuple(bump_value(r, "peak_z3dd") for r in rows),
            peak_x1=tuple(bump_value(r, "peak_x1") for r in rows),
            peak_u=tuple(bump_value(r, "peak_u") for r in rows),
            stable=tuple(bool(r["stable_linear"]) for r in rows),
            delay_margin=margin,
            limit_ratio=tuple(bump_value(r, "peak_z3dd") / limit.peak for r in rows),
            peak_u_command=tuple(bump_value(r, "peak_u_command") for r in rows),
            sampled_peak_z3dd=tuple(r["bump_sampled"]["peak_z3dd"] for r in rows
                                    if "bump_sampled" in r),
            fastest_pole=pole)
        entry["stable_on_interval"] = s.stable_on_interval
        entry["saturates_on_bump"] = [bool(r["bump"]["peak_u_command"] > params.u_max)
                                      for r in rows]
        per_ctrl[name] = entry
        summaries.append(s)

    # --- extras: ISO 8608 class C, Monte-Carlo ---------------------------------------
    tok = stage("iso_C", "ISO 8608 class-C road at 30 km/h ...")
    road_iso = iso8608_road("C", 30.0, cfg.iso_t_end, cfg.road_dt, rng=rng_iso)
    iso_runs = {}
    iso_data: dict = {"description": road_iso.description, "results": {}}
    for name in CONTROLLER_NAMES:
        if name in errors:
            continue
        K = controllers[name]
        for d in ((delays[0],) if K is None else (delays[0], delays[-1])):
            res = simulate(K, road_iso, delay=d, params=params, dt=dt)
            label = name if K is None else f"{name}@{d * 1e3:g}ms"
            iso_runs[label] = res
            iso_data["results"][label] = dict(delay=d, **dataclasses.asdict(res.metrics()))
    done(tok)

    # --- controller.json (the Monte-Carlo sweep reads it) -------------------------------
    design_opts = getattr(getattr(mu_design, "aug", None), "options", None)
    if design_opts is None:
        design_opts = getattr(api, "DEFAULT_DESIGN", None)
    musyn_opts = getattr(api, "DEFAULT_MUSYN", None)
    metadata = {
        "description": "µ-synthesis seat controller: y = [x1, x3] (m) -> u (N), sign of eq. (1)",
        "mu_peak_upper": float(mu_design.mu_peak),
        "mu_peak_lower": float(mu_design.mu_lower_peak),
        "design_options": _jsonable(design_opts),
        "musyn_options": _jsonable(musyn_opts),
        "version": __version__,
    }
    # controller.json is the controller for every occupant; the µ design only where that
    # one could not be loaded (a fact of the summary then says so)
    exported = (EXPORTED if scheduled is not None else
                "mu_occupants" if occupants is not None else "mu")
    if exported == "mu":
        K_export, meta_export = mu_design.K, dict(metadata)
    elif exported == EXPORTED:
        K_export, meta_export = scheduled[0], dict(scheduled[1])
        cert_s, check_1k = scheduled[2], scheduled[3]
        meta_export["paper_mu_nominal_seat"] = {"upper": cert_s.mu.mu_peak,
                                                "lower": cert_s.mu.mu_lower_peak}
        meta_export["sampled_1khz"] = {
            "dt": check_1k.dt, "tolerance": check_1k.tolerance, "gap": check_1k.gap,
            "passed": check_1k.passed,
            "nodes": [{"point": n.point, "gap": n.gap} for n in check_1k.nodes]}
    else:
        K_export, meta_export = occupants[0].K, occupants[0].metadata()
        # controllers/mu_occupants.json holds the 1 kHz realization; this file does not
        meta_export.pop("discretisation", None)
        # what this run recomputed: µ with the paper's weights at the nominal seat (the
        # set's mixed µ is the design's own certificate, not recomputed here)
        meta_export["paper_mu_nominal_seat"] = {"upper": occupants[1].mu.mu_peak,
                                                "lower": occupants[1].mu.mu_lower_peak}
    meta_export.update(exported_as=exported, version=__version__)
    if is_scheduled(K_export):
        # the schedule itself, exactly (io.load_controller gives it back, at() bit for bit)
        files.append(save_scheduled_controller(out / "controller.json", K_export,
                                               metadata=_jsonable(meta_export)))
        # for MATLAB / Simulink: the node controllers as an array of models
        files.append(_save_scheduled_mat(out / "controller.mat", K_export, meta_export))
    else:
        files.append(save_controller(out / "controller.json", K_export, inputs=["x1", "x3"],
                                     outputs=["u"], metadata=_jsonable(meta_export)))
        # the same controller for MATLAB / Simulink (lmi-suspension export does it for any
        # file)
        files.append(save_controller_mat(out / "controller.mat", K_export,
                                         inputs=["x1", "x3"], outputs=["u"],
                                         metadata=_jsonable(meta_export)))
    # every designed controller, with its 1 kHz Tustin realization (the constrained one's
    # own; a controller with poles above the Nyquist rate is discretised all the same:
    # that is a fact about the design, which the summary's facts and the table report,
    # not a failure of this run, so the discretisation does not warn)
    (out / "controllers").mkdir(exist_ok=True)
    for name, K in controllers.items():
        if K is None:
            continue
        if name == "mu_scheduled":   # the schedule, as controller.json holds it
            files.append(save_scheduled_controller(
                out / "controllers" / f"{name}.json", scheduled[0],
                metadata=_jsonable(dict(scheduled[1], fastest_pole=max(
                    fastest_pole(scheduled[0].at(**p)) for p in schedule_nodes(scheduled[0]))))))
            continue
        Kd = discrete.get(name) or discretise_controller(K, _SAMPLE_TIME,
                                                         warn_unresolved=False)
        loaded = {"mu_constrained": constrained, "mu_refined": refined,
                  "mu_occupants": occupants, "mu_1khz": at_1khz}.get(name)
        meta = dict(metadata) if name == "mu" else (
            loaded[0].metadata() if loaded is not None else
            {"description": f"{_LONG_NAMES[name]}: y = [x1, x3] (m) -> u (N)"})
        meta["fastest_pole"] = fastest_pole(K)
        files.append(save_controller(out / "controllers" / f"{name}.json", K,
                                     inputs=["x1", "x3"], outputs=["u"], metadata=meta,
                                     discrete=Kd))
    tok = stage("monte_carlo", f"Monte-Carlo over the uncertainty set ({cfg.mc_n} samples, "
                f"{_LONG_NAMES[exported]}, {cfg.mc_workers or 'no'} Dask workers) ...")
    estimate_errors = None
    if is_scheduled(K_export):
        given = meta_export.get("estimate_errors") or _ESTIMATE_ERRORS
        estimate_errors = {n: float(e) for n, e in given.items() if n in K_export.names}
    mc_data = _monte_carlo(out / "controller.json", cfg, (delays[0], delays[-1]), params,
                           int(rng_mc.integers(2**63)), limit.peak, road_bump,
                           estimate_errors)
    files.append(out / "monte_carlo")  # results.parquet, tradeoff.png, spec.json, parts/
    done(tok)
    worst = mc_data["worst"]
    say(f"  worst sample: peak |z3''| {_fmt(worst['peak_z3dd'], '.3f')} m/s² "
        f"(stable {worst['stable']}; {_fmt(mc_data['worst_ratio_to_own_limit'], '.2f')} × "
        "its own limit)")
    n_map = len(cfg.map_m3) * len(cfg.map_k1_rel) * len(cfg.map_delays)
    tok = stage("occupant_map", f"occupant mass × seat spring map ({n_map} cells, "
                f"{_LONG_NAMES[exported]}, each seat's own limit) ...")
    compare = ({ROBUST: out / "controllers" / f"{ROBUST}.json"}
               if exported != ROBUST and ROBUST in controllers else {})
    map_data, map_table, map_spec, map_worst = _occupant_map(
        out / "controller.json", cfg, params, int(rng_mc.integers(2**63)), compare)
    files.append(out / "occupant_map")
    worst_run = None
    if map_worst is not None:
        worst_seat = dataclasses.replace(params, m3=map_worst["m3"], k1=map_worst["k1"])
        # the map's road and step: the figure's run is the map's case, replayed (a
        # scheduled controller at that seat's values, as the map ran it)
        worst_run = simulate(controller_for_seat(K_export, worst_seat), bump(t_end=cfg.map_t_end, dt=1e-3),
                             delay=map_worst["delay"], params=worst_seat, dt=cfg.map_step)
        map_data["worst_in_set"]["replayed_peak_z3dd"] = float(
            np.max(np.abs(worst_run.z3dd)))
    search_seed = int(rng_mc.integers(2**63))
    done(tok)
    say(f"  {map_data['unstable_cells_in_set']} unstable cells in the set, "
        f"{map_data['unstable_cells']} in the map; worst in the set: "
        + _map_worst_text(map_data["worst_in_set"]))
    # the set's corners, where the force peaks and which the map's plane does not reach
    tok = stage("worst_seats", "the set's largest force and stroke, by search ...")
    searched = _searched_worst(K_export, params, delays, cfg, search_seed,
                               (estimate_errors or {}).get("m3", 0.0))
    map_data["searched"] = {w.figure: dict(w.as_dict(), scheduled_on=on)
                            for w, on in searched}
    searched = [w for w, _on in searched]
    done(tok)
    say("  " + _searched_text(map_data["searched"]))
    # the price of robustness along the mass: the exported schedule, the robust controller
    # and controllers each tuned for exactly one mass (the best a schedule could do)
    ratio_data, ratio_curves = None, ()
    if is_scheduled(K_export):
        tok = stage("ratio_over_mass", "peak ratio over the occupant's mass (scheduled, "
                    "robust, tuned for exactly that mass) ...")
        ratio_data, ratio_curves = _ratio_over_mass(
            K_export, controllers.get(ROBUST), api, cfg, params, errors)
        done(tok)
        say("  " + _ratio_text(ratio_data))

    # --- figures ---------------------------------------------------------------------
    tok = stage("figures", "writing figures ...")
    shown = _pick(delays)
    z_max, u_max = params.z_max, params.u_max

    def save(fig, filename):
        path = out / filename
        fig.savefig(path, dpi=110)
        files.append(path)

    save(figures.plot_road(road_bump, title="Fig. 7: bump (eq. 32) and floor velocity"),
         "fig07_bump.png")
    save(figures.plot_road(road_noise, title="Fig. 8: white-noise floor velocity "
                           f"(two-sided PSD {_NOISE_PSD:g} (m/s)²/Hz, {_NOISE_BAND_HZ:g} Hz)"),
         "fig08_white_noise.png")
    numbered = [(9, "bump", "z3dd", None), (10, "bump", "x1", z_max),
                (11, "bump", "u_applied", u_max), (12, "noise", "z3dd", None),
                (13, "noise", "x1", z_max), (14, "noise", "u_applied", u_max)]
    for number, road_name, signal, lim in numbered:
        sel = {}
        if signal != "u_applied":
            sel["passive"] = runs[road_name]["passive"][delays[0]]
        for d in shown:
            sel[f"µ, d = {d * 1e3:g} ms"] = runs[road_name]["mu"][d]
        what = {"z3dd": "upper-body acceleration", "x1": "suspension deflection",
                "u_applied": "actuator force"}[signal]
        title = f"Fig. {number}: {what}, {road_name}"
        save(figures.plot_responses(sel, signal, title=title, limit=lim,
                                    t_max=1.5 if road_name == "bump" else None),
             f"fig{number:02d}_{road_name}_{signal}.png")
    save(figures.plot_mu_bounds(np.asarray(mu_design.omega), np.asarray(mu_design.mu_upper),
                                np.asarray(mu_design.mu_lower),
                                title="Fig. 15: µ bounds of the closed loop (µ controller)"),
         "fig15_mu_bounds.png")
    def shown_name(name):  # the exported design, named as the file a user takes
        return _LONG_NAMES[name] + (" = controller.json" if name == exported else "")

    peaks = {shown_name(s.name): list(s.peak_z3dd) for s in summaries
             if s.name != "passive" and not s.error}
    stable = {shown_name(s.name): list(s.stable) for s in summaries
              if s.name != "passive" and not s.error}
    passive_peak = summaries[0].peak_z3dd[0]
    save(figures.plot_peak_vs_delay(delays, peaks, limit=limit.peak, passive=passive_peak,
                                    stable=stable,
                                    title="Bump: peak upper-body acceleration vs delay "
                                          "(exact delay, saturation)"),
         "peak_vs_delay.png")
    save(figures.plot_responses(iso_runs, "z3dd", title=road_iso.description), "iso_C_z3dd.png")
    forced = {f"{_LONG_NAMES[n]}, d = {d * 1e3:g} ms": runs["bump"][n][d]
              for n in ("mu", "mu_constrained", "mu_refined") if n in controllers
              for d in (delays[0], delays[-1])}
    save(figures.plot_commanded_force(forced, limit=u_max, t_max=1.5,
                                      title="Bump: commanded (solid) and applied (dashed) "
                                            "force"),
         "force_commanded_vs_applied.png")
    if constrained is not None:
        check_c = constrained[1].mu
        save(figures.plot_mu_bounds(check_c.omega, check_c.mu_upper, check_c.mu_lower,
                                    title="µ bounds, µ design with hard force/stroke bounds"),
             "mu_bounds_constrained.png")
    if refined is not None:
        check_r = refined[1].mu
        save(figures.plot_mu_bounds(check_r.omega, check_r.mu_upper, check_r.mu_lower,
                                    title="µ bounds, µ controller refined to the bounds"),
             "mu_bounds_refined.png")
        # the price of the force bound (shipped: a refinement per bound takes 5-25 min),
        # against this run's µ and refined controllers on the same bump
        points, _table = api.load_refined_tradeoff()
        reference = {}
        for name in ("mu", "mu_refined"):
            m = [runs["bump"][name][d].metrics() for d in delays]
            reference[f"{_LONG_NAMES[name]} (this run)"] = (
                tuple(r.peak_u_command for r in m), tuple(r.peak_z3dd for r in m))
        save(figures.plot_constrained_tradeoff(
            points, limit=limit.peak, u_actuator=u_max, reference=reference,
            label="refined designs (shipped)", bound_label="force bound of the refinement",
            title="Bump peak against the force bound (refined µ designs)"),
            "tradeoff_refined.png")
    if map_data["compared"]:
        panels = [_map_panel(map_table, map_data, out / "controller.json",
                             f"controller.json ({_LONG_NAMES[exported]}"
                             + (", run at each seat's own values" if is_scheduled(K_export)
                                else "") + ")")]
        for name, entry in map_data["compared"].items():
            panels.append(_map_panel(map_table, dict(entry, grid=map_data["grid"]),
                                     compare[name], f"{_LONG_NAMES[name]} ({name}.json)"))
        delays_map = ", ".join(format(d * 1e3, "g") for d in cfg.map_delays)
        map_fig = figures.plot_occupant_maps(
            panels, box=(tuple(map_data["set"]["m3"]), tuple(map_data["set"]["k1"])),
            title=f"worst peak |z3''| / own limit over delays {delays_map} ms "
                  f"(one colour scale)")
    else:
        map_fig = _plot_occupant_map(map_table, map_spec, out / "controller.json", map_data,
                                     _LONG_NAMES[exported])
    if map_fig is not None:
        import matplotlib.pyplot as plt

        try:
            save(map_fig, "occupant_map.png")
        finally:
            plt.close(map_fig)  # the sweep's plot is a pyplot figure
    if worst_run is not None:
        fig = figures.plot_bounded_response(
            worst_run, u_max=u_max, z_max=z_max,
            title=f"{_LONG_NAMES[exported]}, the map's worst seat in the set:\n"
                  + _map_worst_text(map_data["worst_in_set"]))
        own = map_data["worst_in_set"]["limit_peak"]
        if own is not None and math.isfinite(own):
            for sign in (1, -1):  # the seat's own limit: what the ratio is measured against
                fig.axes[0].axhline(sign * own, color="tab:blue", ls=":",
                                    label="this seat's limit (LP)" if sign > 0 else None)
            fig.axes[0].legend(fontsize=8, loc="upper right")
        save(fig, "worst_case.png")
    if ratio_curves:
        save(figures.plot_ratio_over_mass(
            ratio_curves, per_mass=_PER_MASS,
            title=f"Bump at {', '.join(format(d * 1e3, 'g') for d in cfg.map_delays)} ms: "
                  f"each seat against its own limit"), "ratio_over_mass.png")
    done(tok)

    # --- summary.json ---------------------------------------------------------------
    # per-iteration diagnostics without the controllers (the returned one is controller.json)
    history = [dataclasses.replace(h, K=None)
               for h in getattr(getattr(mu_design, "musyn", None), "history", ())]
    total = time.perf_counter() - t_start
    timings["total"] = total
    facts = _design_facts(summaries, params.u_max)
    if exported != EXPORTED:
        # the designs before it in the order of export, each with why it is not there
        skipped = [n for n in (EXPORTED, ROBUST) if n != exported][
            :(EXPORTED, ROBUST, "mu").index(exported)]
        facts += (f"controller.json holds the {_LONG_NAMES[exported]} design: "
                  + "; ".join(f"{_LONG_NAMES[n]} failed ({errors.get(n, 'not loaded')})"
                              for n in skipped),)
    if meta_export.get("stand_in"):
        facts += (f"controller.json is a stand-in: {meta_export.get('description', '')}",)
    if scheduled is not None and not scheduled[3].passed:
        facts += (f"the scheduled controller's 1 kHz loop is {scheduled[3].gap:.2%} from the "
                  f"continuous one at a scheduling value (tolerance "
                  f"{scheduled[3].tolerance:.1%})",)
    over = [w for w in searched
            if not w.value <= {"u": params.u_max, "x1": params.z_max}[w.figure]]
    if over:
        facts += ("controller.json misses a requirement at a seat of the set around the "
                  "nominal seat (found by search): "
                  + "; ".join(f"{w.label} {w.describe()}" if w.value != math.inf
                              else f"{w.label} (the loop is {w.describe()})" for w in over),)
    if map_data["failed_cells"] or map_data["cells_in_set_without_limit"]:
        facts += (f"occupant map: {map_data['failed_cells']} cells raised (occupant_map/"
                  f"results.parquet has the errors) and {map_data['cells_in_set_without_limit']}"
                  f" stable cells of the set have no limit (LP failed): its worst case is "
                  f"over the others",)
    data = {
        "version": __version__, "quick": bool(quick), "delays": list(delays),
        "simulation_dt": dt, "units": {"z3dd": "m/s^2", "x1": "m", "u": "N", "delay": "s",
                                       "omega": "rad/s", "vdv": "m/s^1.75"},
        "roads": {"bump": road_bump.description, "noise": road_noise.description,
                  "iso_C": road_iso.description},
        "limit": {"peak": limit.peak, "certified_peak": limit.certified_peak,
                  "certified_peak_x1": limit.certified_peak_x1,
                  "certified_peak_u": limit.certified_peak_u, "dt": limit.dt,
                  "status": limit.status, "solve_time": limit.solve_time},
        "passive_peak": passive_peak, "half_passive_peak": passive_peak / 2,
        "controllers": per_ctrl,
        "iso_C": iso_data,
        "monte_carlo": mc_data,
        "mu": {"peak_upper": mu_design.mu_peak, "peak_lower": mu_design.mu_lower_peak,
               "omega": mu_design.omega, "upper": mu_design.mu_upper,
               "lower": mu_design.mu_lower, "history": history,
               "analysis": list(mu_checks),
               "design_seconds": getattr(mu_design, "seconds", None)},
        "design_options": metadata["design_options"],
        "musyn_options": metadata["musyn_options"],
        **{name: None if loaded is None else {
            "check": loaded[1], "design": loaded[0].metadata(),
            # judged without the bump (simulated above with every controller)
            "requirements_not_met": list(loaded[1].failures())}
           for name, loaded in (("mu_constrained", constrained), ("mu_refined", refined),
                                ("mu_occupants", occupants), ("mu_1khz", at_1khz))},
        "exported": exported,
        "mu_scheduled": None if scheduled is None else {
            "names": list(scheduled[0].names), "bounds": scheduled[0].bounds,
            "nodes": list(schedule_nodes(scheduled[0])), "metadata": scheduled[1],
            "check": scheduled[2], "sampled_1khz": dict(
                dt=scheduled[3].dt, tolerance=scheduled[3].tolerance,
                gap=scheduled[3].gap, passed=scheduled[3].passed,
                nodes=[dataclasses.asdict(n) for n in scheduled[3].nodes])},
        "occupant_map": map_data,
        "ratio_over_mass": ratio_data,
        "timings": timings,
        "facts": list(facts),
    }
    data = _jsonable(data)
    summary_path = out / "summary.json"
    summary_path.write_text(json.dumps(data, indent=1, allow_nan=False) + "\n")
    files.append(summary_path)
    say(f"done in {total:.1f} s; files in {out}")
    return ReproduceSummary(out_dir=out, files=tuple(files), controllers=tuple(summaries),
                            limit_peak=float(limit.peak), mu_peak=float(mu_design.mu_peak),
                            mu_lower_peak=float(mu_design.mu_lower_peak), seconds=total,
                            timings=dict(timings), data=data, facts=facts)


def _searched_worst(K, params, delays, cfg: _Settings, seed: int, error: float = 0.0
                    ) -> list:
    """The exported controller's largest commanded force and stroke over the set around
    the nominal seat (:class:`~lmi_suspension.seat.occupants.OccupantSet`), by search
    (:func:`~lmi_suspension.seat.worstcase.worst_bump_seats`), as ``[(WorstSeat,
    scheduled_on)]``.

    A scheduled controller is searched at each of its nodes (``scheduled_on``; a table
    of bins at each bin's centre): the controller there over the seats it may meet, the
    true mass within ``error`` of the node's (of the bin's ends) (:func:`~lmi_suspension.seat.scheduled.scheduling_subset`; every other
    parameter over the whole set, also one it is scheduled on, which is conservative),
    with the search's samples shared out between the nodes; the largest of each figure
    over the nodes is kept.  One controller: ``scheduled_on`` is None."""
    from ..seat.occupants import OccupantSet
    from ..seat.schedule_use import is_scheduled, schedule_nodes
    from ..seat.scheduled import scheduling_subset
    from ..seat.worstcase import worst_bump_seats

    occupants = OccupantSet(nominal=params)
    rng = np.random.default_rng(seed)
    if not is_scheduled(K):
        return [(w, None) for w in worst_bump_seats(
            K, occupants, rng=rng, n=cfg.search_n, starts=cfg.search_starts, delays=delays)]
    nodes = schedule_nodes(K)
    lo, hi = occupants.m3
    # a table of bins runs one controller over its whole bin of estimates: search the
    # seats of the bin widened by the error, not of its centre alone
    bins = K.bins if getattr(K, "interpolation", None) == "bins" else None
    best: dict = {}
    for i, p in enumerate(nodes):
        if "m3" not in p:
            sub = occupants
        elif bins is not None:
            sub = scheduling_subset(occupants, bins[i][K.names.index("m3")], error)
        else:
            sub = scheduling_subset(occupants, min(max(p["m3"], lo), hi), error)
        for w in worst_bump_seats(K.at(**p), sub, rng=rng, n=cfg.search_n // len(nodes),
                                  starts=cfg.search_starts, delays=delays):
            if w.figure not in best or w.value > best[w.figure][0].value:
                best[w.figure] = (w, dict(p))
    return list(best.values())


def _searched_text(searched: Mapping) -> str:
    """The search's worst force and stroke (the summary's entries), in one phrase."""
    scheduled = any(w.get("scheduled_on") for w in searched.values())
    return ("largest over the set by search"
            + (" (the schedule at each node, over the seats whose mass it may be "
               "estimated as)" if scheduled else "") + ": "
            + "; ".join(f"{w['label']} {w['text']}"
                        + (" (scheduled on " + ", ".join(
                            f"{n} {v:g}" for n, v in w["scheduled_on"].items()) + ")"
                           if w.get("scheduled_on") else "")
                        for w in searched.values()))


def _ratio_over_mass(Ks, K_robust, api, cfg: _Settings, params, errors: dict) -> tuple:
    """The ratio-over-mass study: the schedule, the robust controller and the controllers
    tuned for exactly one mass (``api.load_at_mass``, at their own masses), each seat
    against its own limit (:func:`~lmi_suspension.seat.schedule_use.ratio_over_mass`,
    the occupant map's delays, road and step).  Returns the summary's entry and the
    curves."""
    from ..seat import bump
    from ..seat.schedule_use import ratio_over_mass, schedule_nodes

    exported = f"{_LONG_NAMES[EXPORTED]} (controller.json)"
    controllers = {exported: Ks}
    if K_robust is not None:
        controllers[f"{_LONG_NAMES[ROBUST]} (robust)"] = K_robust
    at_mass = None
    try:
        at_mass, _meta = api.load_at_mass()
        controllers[_PER_MASS] = at_mass
    except (LmiSuspensionError, OSError, ValueError) as exc:
        errors["mu_at_mass"] = f"{type(exc).__name__}: {exc}"
    # the per-mass controllers' own masses too: the scheduled one is compared there
    node_m3 = [] if at_mass is None else [p["m3"] for p in schedule_nodes(at_mass)]
    masses = sorted(set(cfg.ratio_m3) | set(node_m3))
    curves = ratio_over_mass(controllers, masses, delays=cfg.map_delays, params=params,
                             road=bump(t_end=cfg.map_t_end, dt=1e-3), dt=cfg.map_step,
                             limit_dt=cfg.limit_dt,
                             at_nodes=(_PER_MASS,) if at_mass is not None else ())
    by_label = {c.label: c for c in curves}
    vs = []
    if at_mass is not None:
        sched = dict(zip(by_label[exported].m3, by_label[exported].ratio))
        for m, r in zip(by_label[_PER_MASS].m3, by_label[_PER_MASS].ratio):
            vs.append({"m3": m, "per_mass": r, "scheduled": sched[m],
                       "scheduled_over_per_mass": sched[m] / r})
    entry = {"m3": masses, "delays": list(cfg.map_delays), "step": cfg.map_step,
             "curves": [dataclasses.asdict(c) for c in curves],
             "scheduled_vs_per_mass": vs,
             "within_1_2": bool(vs) and all(v["scheduled_over_per_mass"] <= 1.2 for v in vs),
             "per_mass_error": errors.get("mu_at_mass")}
    return entry, curves


def _ratio_text(entry: Mapping | None) -> str:
    """The ratio-over-mass study in one phrase."""
    if not entry:
        return "no ratio over the mass (the exported controller is not scheduled)"
    parts = []
    for c in entry["curves"]:
        r = [x for x in c["ratio"] if x is not None]
        parts.append(f"{c['label']} {_fmt(max(r), '.2f') if r else 'n/a'}")
    text = ("peak / own limit along m3 (Table 1 otherwise), largest: " + "; ".join(parts))
    for v in entry["scheduled_vs_per_mass"]:
        text += (f"; at {v['m3']:g} kg the schedule is {_fmt(v['scheduled_over_per_mass'], '.2f')}"
                 f" × the controller tuned for that mass")
    if entry.get("per_mass_error"):
        text += f" (no per-mass controllers: {entry['per_mass_error']})"
    return text


def _map_worst_text(worst: Mapping | None) -> str:
    """The occupant map's worst cell in the set, in one phrase."""
    if worst is None:
        return "none: no stable cell of the set has its limit"
    where = (f"m3 {worst['m3']:.0f} kg, k1 {worst['k1']:.0f} N/m, "
             f"{worst['delay'] * 1e3:g} ms")
    if not (worst["stable"] and worst["stable_sim"]):
        return f"unstable at {where}"
    # the commanded force: the seat's force requirement (|u| <= 1500 N) is on it, unclipped
    return (f"{worst['limit_ratio']:.2f} × its own limit at {where} "
            f"(commanded |u| {worst['peak_u_command']:.0f} N, |x1| {worst['peak_x1']:.3f} m)")


def _plot_occupant_map(table, spec, controller: Path, entry: Mapping, name: str):
    """The sweep's map of the occupant grid (:func:`~lmi_suspension.sweep.plots.plot_map`)
    with the set's box and its worst cell drawn."""
    from matplotlib.patches import Rectangle

    from ..sweep.plots import plot_map

    varied = [n for n, v in spec.grid if len(v) > 1][:2]
    if varied != ["m3", "k1"]:  # plot_map's axes; the box is drawn in m3 × k1
        return None
    fig = plot_map(table, spec, str(controller), value="limit_ratio")
    ax = fig.axes[0]
    (m_lo, m_hi), (k_lo, k_hi) = entry["set"]["m3"], entry["set"]["k1"]
    ax.add_patch(Rectangle((m_lo, k_lo), m_hi - m_lo, k_hi - k_lo, fill=False, ec="white",
                           ls="--", lw=1.5,
                           label=f"the set ({m_lo:g}-{m_hi:g} kg, {k_lo:.0f}-{k_hi:.0f} N/m)"))
    worst = entry["worst_in_set"]
    if worst is not None:
        ax.plot(worst["m3"], worst["k1"], "o", ms=14, mfc="none", mec="r",
                label="worst in the set")
    ax.legend(loc="upper left", fontsize=8)
    delays = dict(spec.grid).get("delay", (0.0,))
    ax.set_title(f"{name}: worst peak |z3''| / own limit over delays "
                 f"{', '.join(format(d * 1e3, 'g') for d in delays)} ms", fontsize=10)
    return fig


def _design_facts(summaries, u_max: float) -> tuple:
    """What the table's reader should know about the compared designs, one sentence each.

    Controller poles above the Nyquist rate of the 1 kHz realizations written to
    ``controllers/`` (those realizations do not resolve them), and the designs whose
    commanded force exceeds the actuator's ``u_max`` on the bump (the loop simulated is
    then not the linear one designed).
    """
    nyquist = math.pi / _SAMPLE_TIME
    fast = [f"{_LONG_NAMES[c.name]} {_pole_text(c.fastest_pole)}" for c in summaries
            if not c.error and c.fastest_pole > nyquist]
    facts = []
    if fast:
        facts.append(f"controller poles above the {1e-3 / _SAMPLE_TIME:g} kHz Nyquist rate "
                     f"{nyquist:.0f} rad/s: {', '.join(fast)} rad/s (their 1 kHz "
                     f"realizations in controllers/ do not resolve them)")
    saturated = [f"{_LONG_NAMES[c.name]} {max(c.peak_u_command):.0f} N" for c in summaries
                 if not c.error and c.peak_u_command
                 and all(map(math.isfinite, c.peak_u_command))
                 and max(c.peak_u_command) > u_max]
    if saturated:
        facts.append(f"actuator saturated on the bump (largest commanded force above "
                     f"{u_max:.0f} N): {', '.join(saturated)}")
    return tuple(facts)


def _pole_text(pole: float) -> str:
    """A pole magnitude in rad/s as the table prints it (whole numbers below 1e5)."""
    return format(pole, ".0f" if pole < 1e5 else ".1e")


def _fmt(value: float, spec: str) -> str:
    return "n/a" if value is None or not math.isfinite(value) else format(value, spec)


def comparison_table(summary: ReproduceSummary) -> str:
    """The headline comparison as a text table: one row per controller.

    Columns: peak ``|z̈3|`` on the bump at the smallest and largest delay, its ratio to the
    physical limit at the largest delay, the worst peak ``|x1|`` and ``|u|`` over the delays,
    the largest commanded force, the controller's fastest pole (``*``: above the Nyquist
    rate of its 1 kHz realization), the delay margin and whether the loop is stable over
    the whole delay range. Below the table: the physical limit, the µ peak and the facts
    about the designs (:attr:`ReproduceSummary.facts`).

    Examples
    --------
    >>> s = ControllerSummary("mu", (0.0, 0.025), (3.0, 4.0), (0.01, 0.02), (800.0, 900.0),
    ...                       (True, True), 0.05, (0.5, 0.65), fastest_pole=5000.0)
    >>> summ = ReproduceSummary(Path("."), (), (s,), 6.17, 0.9, 0.8, 1.0, {}, {},
    ...                         facts=("a fact",))
    >>> lines = comparison_table(summ).splitlines()
    >>> print(lines[2])  # doctest: +NORMALIZE_WHITESPACE
    µ (D-K)  3.000  4.000  0.65  0.0200  900  n/a  5000*  50.0  yes
    >>> print(lines[-1])
    - a fact
    """
    d0, d1 = summary.controllers[0].delays[0], summary.controllers[0].delays[-1]
    head = (f"{'controller':<18} {'z3dd@' + format(d0 * 1e3, 'g') + 'ms':>10} "
            f"{'z3dd@' + format(d1 * 1e3, 'g') + 'ms':>10} {'/limit':>7} {'x1 [m]':>8} "
            f"{'u [N]':>7} {'u cmd':>7} {'pole':>8} {'margin[ms]':>10} {'stable':>7}")
    lines = [head, "-" * len(head)]
    for c in summary.controllers:
        name = _LONG_NAMES.get(c.name, c.name)
        if c.error:
            lines.append(f"{name:<18} design failed: {c.error}")
            continue
        worst_x1 = max(c.peak_x1) if all(map(math.isfinite, c.peak_x1)) else math.nan
        worst_u = max(c.peak_u) if all(map(math.isfinite, c.peak_u)) else math.nan
        worst_cmd = max(c.peak_u_command) if c.peak_u_command and all(
            map(math.isfinite, c.peak_u_command)) else math.nan
        # * marks a pole the 1 kHz realization in controllers/ does not resolve
        star = "*" if c.fastest_pole > math.pi / _SAMPLE_TIME else ""
        pole = _pole_text(c.fastest_pole) + star
        if c.name == "passive":
            margin, stable, pole = "no loop", "yes", "-"
        else:
            margin = _fmt(c.delay_margin * 1e3, ".1f") if math.isfinite(c.delay_margin) \
                else ">1000"
            stable = "yes" if c.stable_on_interval else "NO"
        lines.append(f"{name:<18} {_fmt(c.peak_z3dd[0], '.3f'):>10} "
                     f"{_fmt(c.peak_z3dd[-1], '.3f'):>10} {_fmt(c.limit_ratio[-1], '.2f'):>7} "
                     f"{_fmt(worst_x1, '.4f'):>8} {_fmt(worst_u, '.0f'):>7} "
                     f"{_fmt(worst_cmd, '.0f'):>7} {pole:>8} {margin:>10} "
                     f"{stable:>7}")
    lines.append(f"physical limit (LP, full road knowledge): {summary.limit_peak:.3f} m/s²; "
                 f"µ peak upper {summary.mu_peak:.4f}, lower {summary.mu_lower_peak:.4f}")
    grid = summary.data.get("occupant_map")
    if grid:
        exported = _LONG_NAMES.get(summary.data.get("exported"), "?")
        runs = (", the schedule run at each seat's own values, no estimate error"
                if summary.data.get("exported") == EXPORTED else "")
        lines.append(textwrap.fill(
            f"controller.json ({exported}) over occupant mass × seat spring "
            f"({grid['cells']} cells, each seat's own limit{runs}): "
            f"{grid['unstable_cells_in_set']} unstable in the set, {grid['unstable_cells']} "
            f"in the map; worst in the set {_map_worst_text(grid['worst_in_set'])}",
            width=len(head)))
        for name, other in grid.get("compared", {}).items():
            lines.append(textwrap.fill(
                f"{_LONG_NAMES.get(name, name)} ({name}.json) on the same map: "
                f"{other['unstable_cells_in_set']} unstable in the set; worst in the set "
                f"{_map_worst_text(other['worst_in_set'])}", width=len(head)))
        if grid.get("searched"):
            lines.append(textwrap.fill(_searched_text(grid["searched"]), width=len(head)))
    if summary.data.get("ratio_over_mass"):
        lines.append(textwrap.fill(_ratio_text(summary.data["ratio_over_mass"]),
                                   width=len(head)))
    sched = summary.data.get("mu_scheduled")
    if sched:
        s1k = sched["sampled_1khz"]
        lines.append(textwrap.fill(
            f"{_LONG_NAMES[EXPORTED]}: its row is the schedule at the nominal seat's "
            f"values; its 1 kHz loop (Tustin) on the bump is within "
            f"{_fmt(s1k['gap'] * 100 if s1k['gap'] is not None else None, '.2f')} % of "
            f"the continuous one at each of its {len(s1k['nodes'])} scheduling values "
            f"(tolerance {s1k['tolerance'] * 100:g} %: "
            f"{'met' if s1k['passed'] else 'NOT met'})", width=len(head)))
    # one screen: the facts wrapped to the table's width
    lines += [textwrap.fill(fact, width=len(head), initial_indent="- ",
                            subsequent_indent="  ") for fact in summary.facts]
    return "\n".join(lines)
