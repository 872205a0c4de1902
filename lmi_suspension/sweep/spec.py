"""What a sweep computes: a declarative grid or Monte-Carlo over the seat, the delay, the road
and the controllers, expanded into numbered cases.

A :class:`SweepSpec` is plain data (it round-trips through JSON, and reads from TOML or from
the CLI's flags); :meth:`SweepSpec.cases` turns it into :class:`Case` records, each with
every value it needs and its own seed, so that a case gives the same row whichever worker
runs it, in whatever order.

Axes (names of a grid axis or of a Monte-Carlo range):

* the fields of :class:`~lmi_suspension.seat.SeatParameters` (``m1``, ``m21``, ``m22``,
  ``m3``, ``c1`` … ``k3``, ``z_max``, ``u_max``);
* ``delay``: the actuator delay, s (rounded to the simulation step, 0.1 ms by default);
* the road's parameters: ``height`` (m), ``length`` (m) and ``speed_kmh`` of the bump;
  ``speed_kmh`` of the ISO 8608 road; ``psd`` ((m/s)²/Hz) of the white floor velocity;
* ``<parameter>_error`` (``m3_error``, ``k1_error``, ...): the error of the seat's
  estimate of a parameter a *scheduled* controller (``seat/data/mu_scheduled.json``) is
  scheduled on, in that parameter's unit.  A scheduled controller runs at the case's
  values plus these errors
  (:func:`~lmi_suspension.seat.schedule_use.controller_for_seat`: held inside its
  schedule's range); an unscheduled controller, and a schedule not on that parameter,
  measure nothing and ignore them.

Monte-Carlo values are drawn uniformly, each case from its own generator (``sampling =
"uniform"``), or as one Latin hypercube shared by every controller and grid point
(``sampling = "lhs"``); see :class:`SweepSpec`.
"""

from __future__ import annotations

import itertools
import json
import math
import tomllib
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np

from ..errors import InputError, ParameterError
from ..seat.params import SeatParameters

__all__ = ["DESIGN", "design_route", "ERROR_AXES", "PASSIVE", "PLANT_AXES", "ROADS",
           "SAMPLINGS", "Case", "SweepSpec", "parse_range", "schedule_errors"]

#: the seat's parameters a sweep may vary (the delay bounds of SeatParameters are the
#: design's, not a case's: a case has one delay)
PLANT_AXES = tuple(f.name for f in fields(SeatParameters) if not f.name.startswith("delay_"))
#: the errors of a scheduled controller's estimates: ``m3_error`` is the seat's estimate
#: of ``m3`` minus the true ``m3`` (kg), likewise for every seat parameter
ERROR_AXES = tuple(f"{n}_error" for n in PLANT_AXES)


def schedule_errors(values: dict) -> dict:
    """The estimate errors of a case's values, by parameter (``{"m3": -5.0}`` for
    ``m3_error = -5``).

    Examples
    --------
    >>> schedule_errors({"m3": 50.0, "m3_error": -5.0, "delay": 0.0})
    {'m3': -5.0}
    """
    return {n[:-len("_error")]: float(v) for n, v in values.items() if n in ERROR_AXES}


#: each road and the parameters it takes (all numeric; ``road_class`` is a fixed option)
ROADS = {
    "bump": ("height", "length", "speed_kmh"),
    "iso8608": ("speed_kmh",),
    "noise": ("psd",),
}
#: the controller entry that means "no controller" (the passive seat)
PASSIVE = "passive"
#: the controller entry that means "a controller designed for this case's seat", once per
#: distinct seat of the sweep: ``"design"`` along the µ route (the paper's weights and
#: uncertainty), ``"design:<route>"`` along any route of
#: :data:`~lmi_suspension.seat.routes.ROUTE_NAMES` with its default choices
DESIGN = "design"


def design_route(entry: str) -> str | None:
    """The route a controller entry designs along (``"design"``: ``"mu"``), or None for a
    controller file or ``"passive"``.

    Examples
    --------
    >>> design_route("design"), design_route("design:peak_bounded"), design_route("k.json")
    ('mu', 'peak_bounded', None)
    """
    if entry == DESIGN:
        return "mu"
    if entry.startswith(DESIGN + ":"):
        return entry[len(DESIGN) + 1:]
    return None
#: how the Monte-Carlo values are drawn: uniformly, each case from its own generator, or
#: as one Latin hypercube (see SweepSpec)
SAMPLINGS = ("uniform", "lhs")
#: the default simulation step, s (the simulator's own default)
SIM_STEP = 1e-4
#: the default record lengths, s (the bump's tail lets the seat settle)
_DEFAULT_DURATION = {"bump": 3.0, "iso8608": 5.0, "noise": 5.0}
#: the reproduce study's white-noise floor velocity (see lmi_suspension.report.reproduce)
_DEFAULT_ROAD = {"bump": {"height": 0.1, "length": 2.0, "speed_kmh": 30.0},
                 "iso8608": {"speed_kmh": 30.0, "road_class": "C"},
                 "noise": {"psd": 1e-4, "bandwidth_hz": 50.0}}
#: a bound that keeps a typo (1e9 cases) from filling a disk
_MAX_CASES = 10_000_000


def parse_range(text, name: str) -> tuple[float, ...]:
    """Values of an axis from ``"start:stop:count"`` (inclusive, evenly spaced), one number,
    or a list of numbers.

    Examples
    --------
    >>> parse_range("30:70:5", "m3")
    (30.0, 40.0, 50.0, 60.0, 70.0)
    >>> parse_range([0.0, 0.01], "delay")
    (0.0, 0.01)
    """
    if isinstance(text, (list, tuple)):
        values = [_number(v, name) for v in text]
    elif isinstance(text, (int, float)) and not isinstance(text, bool):
        values = [_number(text, name)]
    elif isinstance(text, str):
        parts = text.split(":")
        if len(parts) == 1:
            values = [_number(parts[0], name)]
        elif len(parts) == 3:
            start, stop = _number(parts[0], name), _number(parts[1], name)
            try:
                count = int(parts[2])
            except ValueError:
                raise ParameterError(f"{name}: count of {text!r} must be an integer") from None
            if count < 1:
                raise ParameterError(f"{name}: empty range {text!r} (count {count})")
            if count == 1 and start != stop:
                raise ParameterError(f"{name}: one value cannot span {start}..{stop}")
            values = list(np.linspace(start, stop, count))
        else:
            raise ParameterError(f"{name}: expected start:stop:count, got {text!r}")
    else:
        raise ParameterError(f"{name}: expected a range string or numbers, got {text!r}")
    if not values:
        raise ParameterError(f"{name}: empty list of values")
    return tuple(float(v) for v in values)


def _number(value, name: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: {value!r} is not a number") from None
    if not math.isfinite(x):
        raise ParameterError(f"{name}: {value!r} is not finite")
    return x


@dataclass(frozen=True)
class Case:
    """One case of a sweep: everything a worker needs, and nothing it must look up.

    Attributes
    ----------
    index : int
        Position in :meth:`SweepSpec.cases` (the row's key).
    controller : str
        The controller file, or ``"passive"``.
    values : dict
        The case's value of every axis (grid or Monte-Carlo draw).
    seed : tuple of int
        ``(entropy, index)``: the case's generator is
        ``default_rng(SeedSequence(entropy, spawn_key=(index,)))``, i.e.
        ``SeedSequence(entropy).spawn(n)[index]``.
    """

    index: int
    controller: str
    values: dict
    seed: tuple

    def rng(self) -> np.random.Generator:
        """This case's own generator (draws after the Monte-Carlo values)."""
        entropy, index = self.seed
        return np.random.default_rng(np.random.SeedSequence(entropy, spawn_key=(index,)))


@dataclass(frozen=True)
class SweepSpec:
    """A sweep: controllers × (grid or Monte-Carlo) over the seat, the delay and the road.

    Attributes
    ----------
    controllers : tuple of str
        Saved controller files (:func:`~lmi_suspension.io.save_controller`, or a
        scheduled controller's, :func:`~lmi_suspension.io.save_scheduled_controller`:
        run at each case's values, see the ``*_error`` axes),
        ``"passive"`` (no controller), ``"design"``: a µ controller synthesised for the
        case's own seat (the µ route of :func:`~lmi_suspension.seat.routes.design_seat`,
        the paper's weights and uncertainty; about 2 s each, once per distinct seat), or
        ``"design:<route>"``: likewise along another route (``"design:peak_bounded"``,
        a few seconds each); each case runs one of them.
    grid : tuple of (str, tuple of float)
        Axes of a full grid, outermost first.  Axes not named keep their default
        (Table 1, no delay, the road's defaults).
    samples : int
        Monte-Carlo: this many cases per controller and grid point, drawn as ``sampling``
        says (0: no Monte-Carlo).  The grid, if any, is then crossed with the samples.
    ranges : tuple of (str, float, float)
        Monte-Carlo axes and their bounds.
    sampling : {"uniform", "lhs"}
        How the Monte-Carlo values are drawn.

        * ``"uniform"`` (default): each case draws every axis of ``ranges``, in order,
          uniformly from its own generator (:meth:`Case.rng`); every controller and grid
          point meets other seats.
        * ``"lhs"``: the ``samples`` points over the ``ranges`` axes form one Latin
          hypercube, ``scipy.stats.qmc.LatinHypercube(d=len(ranges),
          seed=default_rng(SeedSequence(seed)))``, scaled to the ranges
          (``qmc.scale``; an axis with ``lo == hi`` is that value); the s-th sample of
          every (controller, grid point) block takes row s.  So along each axis the
          samples fall one in each of ``samples`` equal-width strata of the range.  The
          hypercube is *shared* by every controller and grid point, rather than drawn per
          block, so that each controller meets the same seats: the controllers'
          differences are then not blurred by different draws (common random numbers),
          and each block is itself a Latin hypercube.  It depends only on ``seed``,
          ``samples`` and ``ranges``, never on how the cases are split, ordered or run,
          and not on the controllers or the grid.  The values follow SciPy's algorithm,
          so they may differ between SciPy versions (the table's metadata records them).
          A ``delay`` is then rounded to the step as with ``"uniform"``, which moves it
          by at most half a step (across a stratum's edge only when a stratum is
          comparable to the step).  Needs ``samples`` > 0.
    road : {"bump", "iso8608", "noise"}
        The paper's bump (eq. 32), an ISO 8608 road, or white floor velocity.
    road_options : tuple of (str, object)
        Fixed road values (e.g. ``("height", 0.05)``, ``("road_class", "D")``).
    duration : float or None
        Length of the record, s (bump 3, others 5).
    seed : int
        Entropy of every case's generator (and, with ``sampling="lhs"``, of the
        hypercube).
    limit : bool
        Compute each case's physical limit (bump only: the clairvoyant LP of
        :func:`~lmi_suspension.seat.bump_limit`, once per distinct seat and bump) and the
        ``limit_ratio`` column.
    step : float
        Simulation step, s (0.1 ms); every delay is rounded to a multiple of it.  The
        cost of a case is proportional to ``duration / step``.
    """

    controllers: tuple = (PASSIVE,)
    grid: tuple = ()
    samples: int = 0
    ranges: tuple = ()
    road: str = "bump"
    road_options: tuple = ()
    duration: float | None = None
    seed: int = 0
    limit: bool = True
    step: float = SIM_STEP
    sampling: str = "uniform"

    def __post_init__(self):
        if self.road not in ROADS:
            raise ParameterError(f"road: unknown road {self.road!r}; choose one of "
                                 f"{', '.join(ROADS)}")
        if not self.controllers:
            raise ParameterError("controllers: at least one controller file (or 'passive')")
        routes = {design_route(c) for c in self.controllers} - {None}
        if routes:
            from ..seat.routes import ROUTE_NAMES

            unknown = sorted(routes - set(ROUTE_NAMES))
            if unknown:
                raise ParameterError(f"controllers: unknown design route {unknown[0]!r} "
                                     f"(design:<route>, the routes are "
                                     f"{', '.join(ROUTE_NAMES)})")
        known = self.axes_known()
        seen = set()
        for name, values in self.grid:
            self._check_axis(name, known, seen)
            if not values:
                raise ParameterError(f"{name}: empty list of values")
        for name, lo, hi in self.ranges:
            self._check_axis(name, known, seen)
            if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
                raise ParameterError(f"{name}: Monte-Carlo range must be finite and lo <= hi, "
                                     f"got {lo}..{hi}")
        if isinstance(self.samples, bool) or int(self.samples) != self.samples \
                or self.samples < 0:
            raise ParameterError(f"samples must be a non-negative integer, got {self.samples!r}")
        if self.ranges and not self.samples:
            raise ParameterError("ranges: Monte-Carlo ranges given but samples = 0")
        if self.samples and not self.ranges:
            raise ParameterError("samples: Monte-Carlo needs at least one range")
        if not isinstance(self.sampling, str) or self.sampling not in SAMPLINGS:
            raise ParameterError(f"sampling: unknown sampling {self.sampling!r}; choose one "
                                 f"of {', '.join(SAMPLINGS)}")
        if self.sampling != "uniform" and not self.samples:
            raise ParameterError(f"sampling: {self.sampling!r} draws Monte-Carlo samples, "
                                 f"but samples = 0")
        allowed = set(ROADS[self.road]) | set(_DEFAULT_ROAD[self.road])
        for name, _value in self.road_options:
            if name not in allowed:
                raise ParameterError(f"road_options: {name!r} is not a parameter of the "
                                     f"{self.road} road ({', '.join(sorted(allowed))})")
        if self.duration is not None and not (math.isfinite(self.duration)
                                              and self.duration > 0):
            raise ParameterError(f"duration must be a positive number of seconds, "
                                 f"got {self.duration!r}")
        if not (isinstance(self.step, (int, float)) and math.isfinite(self.step)
                and 1e-6 <= self.step <= 1e-2):
            raise ParameterError(f"step must be a simulation step in [1e-6, 1e-2] s, "
                                 f"got {self.step!r}")
        if self.n_cases > _MAX_CASES:
            raise ParameterError(f"{self.n_cases} cases exceed the bound of {_MAX_CASES}")
        for name, value in self.grid:
            for v in value:
                self._check_value(name, v)
        for name, lo, hi in self.ranges:
            self._check_value(name, lo)
            self._check_value(name, hi)

    def axes_known(self) -> tuple:
        return PLANT_AXES + ("delay",) + ROADS[self.road] + ERROR_AXES

    def _check_axis(self, name, known, seen):
        if name not in known:
            raise ParameterError(f"{name}: unknown parameter; a {self.road} sweep varies "
                                 f"{', '.join(known)}")
        if name in seen:
            raise ParameterError(f"{name}: given twice")
        seen.add(name)

    @staticmethod
    def _check_value(name, v):
        if name in ERROR_AXES:
            return                      # an estimate's error has either sign
        if name == "delay":
            if v < 0:
                raise ParameterError(f"delay: {v} s is negative")
        elif name in ("c1", "c2", "c3"):
            if v < 0:
                raise ParameterError(f"{name}: damping {v} is negative")
        elif v <= 0:
            raise ParameterError(f"{name}: {v} must be positive")

    # ------------------------------------------------------------------ cases
    @property
    def n_cases(self) -> int:
        n = len(self.controllers) * max(int(self.samples), 1)
        for _name, values in self.grid:
            n *= len(values)
        return n

    @property
    def axis_names(self) -> tuple:
        """The columns of the varied values, in the order of the table."""
        return tuple(n for n, _ in self.grid) + tuple(n for n, _, _ in self.ranges)

    def cases(self) -> list[Case]:
        """Every case, numbered: controller outermost, then the grid (outer axis first),
        then the Monte-Carlo sample.  Monte-Carlo values are drawn from the case's own
        generator (``"uniform"``) or are the sample's row of the spec's one Latin
        hypercube (``"lhs"``), so they do not depend on how the cases are split or
        ordered."""
        out = []
        names = [n for n, _ in self.grid]
        points = list(itertools.product(*[v for _, v in self.grid])) if self.grid else [()]
        hypercube = self._latin_hypercube() if self.sampling == "lhs" else None
        range_names = [n for n, _, _ in self.ranges]
        k = 0
        for ctrl in self.controllers:
            for point in points:
                for s in range(max(int(self.samples), 1)):
                    values = dict(zip(names, point))
                    case = Case(k, str(ctrl), values, (int(self.seed), k))
                    if hypercube is not None:
                        values.update(zip(range_names, (float(x) for x in hypercube[s])))
                    elif self.ranges:
                        rng = case.rng()
                        for name, lo, hi in self.ranges:
                            values[name] = float(rng.uniform(lo, hi))
                    if "delay" in values:
                        values["delay"] = round(values["delay"] / self.step) * self.step
                    out.append(case)
                    k += 1
        return out

    def _latin_hypercube(self) -> np.ndarray:
        """The ``samples`` × ``len(ranges)`` Latin hypercube of ``sampling="lhs"``, scaled to
        the ranges (before the delay's rounding)."""
        from scipy.stats import qmc

        n = int(self.samples)
        unit = qmc.LatinHypercube(
            d=len(self.ranges),
            seed=np.random.default_rng(np.random.SeedSequence(int(self.seed)))).random(n)
        lo = np.array([r[1] for r in self.ranges], dtype=float)
        hi = np.array([r[2] for r in self.ranges], dtype=float)
        points = np.tile(lo, (n, 1))  # an axis with lo == hi is that value
        wide = lo < hi  # (qmc.scale refuses empty ranges)
        if wide.any():
            points[:, wide] = qmc.scale(unit[:, wide], lo[wide], hi[wide])
        return points

    def road_settings(self) -> dict:
        """The road's parameters with the fixed options applied (before the case's own),
        the record's ``duration`` and the simulation ``step``."""
        settings = dict(_DEFAULT_ROAD[self.road])
        settings.update(dict(self.road_options))
        settings["duration"] = (_DEFAULT_DURATION[self.road] if self.duration is None
                                else float(self.duration))
        settings["step"] = float(self.step)
        return settings

    # ------------------------------------------------------------------ I/O
    def to_json(self) -> str:
        """A canonical JSON text (a resumed sweep must have the same one).

        ``sampling`` is written only when it is not ``"uniform"``, so a uniform spec has the
        text it had before the option existed, and its earlier output directories resume.
        """
        d = asdict(self)
        if d["sampling"] == "uniform":
            del d["sampling"]
        return json.dumps(d, sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> SweepSpec:
        d = json.loads(text)
        return cls(controllers=tuple(d["controllers"]),
                   grid=tuple((n, tuple(v)) for n, v in d["grid"]),
                   samples=int(d["samples"]),
                   ranges=tuple((n, float(lo), float(hi)) for n, lo, hi in d["ranges"]),
                   road=d["road"], road_options=tuple((n, v) for n, v in d["road_options"]),
                   duration=d["duration"], seed=int(d["seed"]), limit=bool(d["limit"]),
                   step=float(d.get("step", SIM_STEP)), sampling=d.get("sampling", "uniform"))

    @classmethod
    def from_toml(cls, path) -> SweepSpec:
        """Read a spec file.

        Example::

            controllers = ["reproduce_out/controller.json", "passive"]
            road = "bump"             # "bump", "iso8608" or "noise"
            duration = 3.0            # s (optional)
            seed = 0
            limit = true              # bump only: the physical limit of each case

            [road_options]            # fixed road values (optional)
            height = 0.1

            [grid]                    # "start:stop:count", a number, or a list
            m3 = "30:70:9"
            delay = "0:0.05:11"

            [monte_carlo]             # optional; crossed with the grid
            samples = 100
            sampling = "lhs"          # "uniform" (default) or "lhs": one Latin hypercube
            k1 = [24800, 37200]       # ranges [lo, hi]
        """
        path = Path(path)
        try:
            data = tomllib.loads(path.read_text())
        except OSError as exc:
            raise InputError(f"spec file {path}: {exc.strerror or exc}") from exc
        except tomllib.TOMLDecodeError as exc:
            raise InputError(f"spec file {path} is not valid TOML: {exc}") from exc
        return cls.from_mapping(data, base=path.parent)

    @classmethod
    def from_mapping(cls, data: dict, base: Path | None = None) -> SweepSpec:
        """A spec from a TOML-like mapping (unknown keys are errors naming the key)."""
        allowed = {"controllers", "road", "duration", "seed", "limit", "step", "road_options",
                   "grid", "monte_carlo"}
        for key in data:
            if key not in allowed:
                raise ParameterError(f"{key}: unknown key of a sweep spec "
                                     f"({', '.join(sorted(allowed))})")
        ctrls = data.get("controllers", [PASSIVE])
        if isinstance(ctrls, str):
            ctrls = [ctrls]
        ctrls = [c if c == PASSIVE or design_route(c) is not None or base is None
                 or Path(c).is_absolute()
                 else str(base / c) for c in ctrls]
        grid = tuple((str(n), parse_range(v, str(n)))
                     for n, v in dict(data.get("grid", {})).items())
        mc = dict(data.get("monte_carlo", {}))
        samples = mc.pop("samples", 0)
        sampling = mc.pop("sampling", "uniform")
        ranges = []
        for n, v in mc.items():
            if not (isinstance(v, (list, tuple)) and len(v) == 2):
                raise ParameterError(f"{n}: a Monte-Carlo range is [lo, hi], got {v!r}")
            ranges.append((str(n), _number(v[0], n), _number(v[1], n)))
        return cls(controllers=tuple(ctrls), grid=grid, samples=samples, ranges=tuple(ranges),
                   road=str(data.get("road", "bump")),
                   road_options=tuple(dict(data.get("road_options", {})).items()),
                   duration=data.get("duration"), seed=int(data.get("seed", 0)),
                   limit=bool(data.get("limit", True)), step=data.get("step", SIM_STEP),
                   sampling=sampling)

