"""The certificate of a seat controller scheduled on the occupant's measured mass.

A seat knows its occupant's mass once they sit down (a load cell, the static deflection
of the suspension), up to an error; a controller scheduled on that estimate must be
robust to what the seat does not measure (the body's springs and dampers, an aged seat
spring, the delay) and to the error of the estimate.  :func:`certify_scheduled` measures
a scheduled controller ``Ks`` (anything with ``names``, ``bounds`` and ``at(m3=...)``
returning a ``StateSpace``: a :class:`~lmi_suspension.lti.gridded.GriddedController`,
:func:`~lmi_suspension.lpv.lpvsyn`'s :class:`~lmi_suspension.lpv.ScheduledController`)
over an :class:`~.occupants.OccupantSet` as :func:`~.occupants.certify_occupants`
measures one controller, and more:

* **stability** of every stability sample's exact-delay loop
  (:func:`~.simulate.closed_loop_stable`, a Nyquist count) with the controller scheduled
  on the sample's *estimated* mass: the true mass plus an error drawn uniformly in
  ``±error`` (or given), the estimate held inside the schedule's range (a seat saturates
  its estimate to the masses its schedule covers);
* **the road requirements** at every performance sample and delay, the controller
  scheduled on the sample's estimate: peak ``|z̈3|`` over the sample's own limit,
  commanded ``|u|`` and ``|x1|`` in closed form (:class:`~.refine.BumpResponse`), the
  worst few re-simulated with the exact delay (:func:`~.simulate.simulate`);
* **at every scheduling value** ``m̂`` of a grid, over the seats the controller
  scheduled there may meet (true mass in ``[m̂ - error, m̂ + error]`` within the set's
  range, every other parameter and delay of the set: :func:`scheduling_subset`): mixed µ
  of robust stability (:func:`~.occupants.occupant_mu`; below 1 over every frequency
  certifies stability of every such seat) and the worst-seat search for force and stroke
  (:func:`~.worstcase.worst_bump_seats`).

A table of bins (``GriddedController(interpolation="bins")``: one controller per bin of
the estimated mass, picked once per ride) is certified per *bin*: the controller of a
bin of estimates ``[a, b]`` meets the true masses ``[a - error, b + error]``
(``scheduling_subset(occupants, (a, b), error)``), and that is the set its µ and its
search cover.

With one controller at every mass (``GriddedController`` of equal nodes) the sampled
figures are :func:`~.occupants.certify_occupants`' on the same samples, bit for bit (the
test suite checks it).

Examples
--------
>>> import numpy as np
>>> from lmi_suspension.seat.scheduled import scheduling_subset
>>> from lmi_suspension.seat.occupants import OccupantSet
>>> s = scheduling_subset(OccupantSet(), 32.0, 5.0)
>>> s.m3, s.nominal.m3
((30.0, 37.0), 32.0)
>>> scheduling_subset(OccupantSet(), 50.0, 0.0).fixed
('m3',)
>>> b = scheduling_subset(OccupantSet(), (40.0, 50.0), 5.0)
>>> b.m3, b.nominal.m3
((35.0, 55.0), 45.0)
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Callable

import control
import numpy as np

from ..errors import DimensionError, ParameterError
from .occupant_subset import OccupantSubset
from .occupants import MixedMuCheck, OccupantSamples, OccupantSet, road_figures

__all__ = ["ScheduledCheck", "ScheduleValueCheck", "certify_scheduled", "scheduling_subset",
           "schedule_estimates"]

#: the scheduling parameter of a seat controller
_MASS = "m3"


def _estimate_interval(m3_hat) -> tuple[float, float]:
    """``(a, b)`` of an estimate (a number: ``a == b``) or a bin of estimates (a pair)."""
    try:
        a, b = ((float(m3_hat),) * 2 if np.ndim(m3_hat) == 0
                else tuple(float(v) for v in m3_hat))
    except (TypeError, ValueError):
        raise ParameterError(f"m3_hat must be a mass or a pair (lo, hi) of masses, got "
                             f"{m3_hat!r}") from None
    if not (math.isfinite(a) and math.isfinite(b) and a <= b):
        raise ParameterError(f"m3_hat must be finite (a pair with lo <= hi), got {m3_hat!r}")
    return a, b


def scheduling_subset(occupants: OccupantSet, m3_hat, error: float) -> OccupantSubset:
    """The seats a controller scheduled on the estimate ``m3_hat`` may meet: true mass
    within ``m3_hat ± error`` inside the set's range (fixed at ``m3_hat`` for ``error =
    0``), every other parameter and the delay as in ``occupants``.  With a bin of
    estimates ``m3_hat = (a, b)`` (the controller of a piecewise-constant table serves
    every estimate in it), the true masses ``[a - error, b + error]``, the seat of the
    set at the bin's centre.

    Raises
    ------
    ParameterError
        ``m3_hat`` (or a bin end) outside the set's mass range, a bin with ``a > b``,
        ``error`` negative or not finite.
    """
    if not isinstance(occupants, OccupantSet):
        raise ParameterError(f"occupants must be an OccupantSet, got "
                             f"{type(occupants).__name__}")
    lo, hi = occupants.m3
    a, b = _estimate_interval(m3_hat)
    e = float(error)
    if not (lo <= a and b <= hi):
        raise ParameterError(f"m3_hat = {m3_hat!r} is outside the set's masses [{lo:g}, {hi:g}]")
    if not (math.isfinite(e) and e >= 0):
        raise ParameterError(f"error must be finite and >= 0 kg, got {error!r}")
    m = a if a == b else (a + b) / 2
    fixed = tuple(n for n in getattr(occupants, "fixed", ()) if n != _MASS)
    return OccupantSubset(nominal=replace(occupants.nominal, m3=m),
                          m3=(max(lo, a - e), min(hi, b + e)),
                          stiffness_rel=occupants.stiffness_rel,
                          damping_rel=occupants.damping_rel, delay=occupants.delay,
                          k1_rel=occupants.k1_rel, fixed=fixed)


def _mass_range(Ks) -> tuple[float, float]:
    """The schedule's range of ``m3`` (a controller scheduled on the mass alone)."""
    names = tuple(getattr(Ks, "names", ()))
    if names != (_MASS,) or not callable(getattr(Ks, "at", None)):
        raise ParameterError(f"Ks must be a controller scheduled on {_MASS!r} alone (names "
                             f"({_MASS!r},) and at({_MASS}=...)), got names {names!r}")
    lo, hi = (float(v) for v in Ks.bounds[0])
    return lo, hi


def schedule_estimates(true_m3, Ks, error, rng: np.random.Generator | None = None
                       ) -> np.ndarray:
    """The masses a seat schedules ``Ks`` on: ``true_m3`` plus an error, held inside the
    schedule's range.

    Parameters
    ----------
    true_m3 : array_like
        The occupants' masses, kg.
    Ks : scheduled controller
    error : float or array_like
        A half-width, kg: the errors are drawn uniformly in ``[-error, error]`` from
        ``rng``; or the errors themselves, one per mass.
    rng : numpy.random.Generator, optional
        Needed for a half-width.
    """
    m = np.asarray(true_m3, dtype=float).ravel()
    lo, hi = _mass_range(Ks)
    if np.ndim(error) == 0:
        e = float(error)
        if not (math.isfinite(e) and e >= 0):
            raise ParameterError(f"error must be finite and >= 0 kg, got {error!r}")
        if not isinstance(rng, np.random.Generator):
            raise ParameterError("rng must be a numpy.random.Generator (seeded by the caller)")
        drawn = rng.uniform(-e, e, m.size)
    else:
        drawn = np.asarray(error, dtype=float).ravel()
        if drawn.shape != m.shape or not np.all(np.isfinite(drawn)):
            raise DimensionError(f"give {m.size} finite errors, got {np.shape(error)}")
    return np.clip(m + drawn, lo, hi)


@dataclass(frozen=True)
class ScheduleValueCheck:
    """The certificate at one scheduling value (:func:`certify_scheduled`).

    Attributes
    ----------
    m3_hat : float
        The estimate the controller is scheduled on, kg (a bin's centre).
    occupants : OccupantSubset
        The seats it may meet (:func:`scheduling_subset`).
    mu : MixedMuCheck or None
        Mixed µ over them (None where the nominal µ loop is unstable: no bound).
    rs_mu : float
        ``mu.rs_sup``, the robust-stability bound over every frequency (inf where the
        nominal µ loop is unstable; nan when not computed).
    worst_seats : tuple of WorstSeat
        The largest force and stroke found over them (empty when not searched).
    controller_radius : float
        Largest pole magnitude of the controller there, rad/s.
    estimates : (float, float)
        The estimates the value stands for: ``(m3_hat, m3_hat)``, or a bin's ends.
    """

    m3_hat: float
    occupants: OccupantSubset
    mu: MixedMuCheck | None
    rs_mu: float
    worst_seats: tuple
    controller_radius: float
    estimates: tuple = ()


@dataclass(frozen=True)
class ScheduledCheck:
    """A scheduled controller's certificate (:func:`certify_scheduled`).

    Attributes
    ----------
    n_stability, unstable : int
        Stability samples, and how many of their loops (controller at the estimate,
        exact delay) are unstable.
    unstable_samples : tuple of (SeatParameters, float, float)
        The first (at most 20): seat, delay, estimated mass.
    stability_estimates, performance_estimates : ndarray
        The masses the controller was scheduled on, kg.
    delays : tuple of float
    ratio, u_peak, x1_peak : ndarray
        Per performance sample and delay, as :class:`~.occupants.OccupantCheck`.
    worst_ratio, worst_sample, worst_delay, u_max, x1_max : as OccupantCheck
    nominal_ratio : float
        The nominal seat's worst ratio over the delays, scheduled on its true mass.
    confirmed : tuple
        The time-domain re-simulations, as :class:`~.occupants.OccupantCheck`.
    values : tuple of ScheduleValueCheck
        The certificate at each scheduling value of the grid.
    rs_mu_max : float
        The largest mixed µ of robust stability over the grid (nan when not computed).
    u_searched, x1_searched : float
        The largest force (N) and stroke (m) the searches found over the grid (nan when
        not searched).
    controller_radius : float
        Largest controller pole magnitude over the grid, rad/s.
    loop_radius : float
        Largest loop pole magnitude (no delay) over the performance samples, each with
        its controller, rad/s.
    error : float or None
        The half-width the errors were drawn in (None where given).
    seconds : float
    """

    n_stability: int
    unstable: int
    unstable_samples: tuple
    stability_estimates: np.ndarray
    performance_estimates: np.ndarray
    delays: tuple
    ratio: np.ndarray
    u_peak: np.ndarray
    x1_peak: np.ndarray
    worst_ratio: float
    worst_sample: object
    worst_delay: float
    u_max: float
    x1_max: float
    nominal_ratio: float
    confirmed: tuple
    values: tuple
    rs_mu_max: float
    u_searched: float
    x1_searched: float
    controller_radius: float
    loop_radius: float
    error: float | None
    seconds: float


def _controller(Ks, m3: float) -> control.StateSpace:
    K = Ks.at(**{_MASS: float(m3)})
    if not isinstance(K, control.StateSpace) or K.isdtime(strict=True) \
            or K.ninputs != 2 or K.noutputs != 1:
        raise ParameterError(f"Ks.at({_MASS}={m3:g}) must be a continuous-time StateSpace "
                             "from y = [x1, x3] to u")
    return K


def _road_figures(Ks, samples: OccupantSamples, estimates, delays, confirm):
    """``ratio, u, x1, confirmed, loop_radius``: :func:`~.occupants.certify_occupants`'
    road figures with each performance sample's controller at its estimate."""
    return road_figures([_controller(Ks, e) for e in estimates], samples, delays, confirm)


def _check_value(Ks, occupants, m3_hat, error) -> tuple[float, float]:
    """``(a, b)`` of a scheduling value (a mass, or a bin of estimates of a table of
    bins), checked against the schedule and the set."""
    a, b = _estimate_interval(m3_hat)
    Ks.values(**{_MASS: a})
    Ks.values(**{_MASS: b})
    if a < b and getattr(Ks, "interpolation", None) == "bins":
        # one controller serves the whole bin: it must be the one at each end too
        # (the top edge belongs to the next bin, so the check is just below it)
        if not all(Ks.bin_index(**{_MASS: v}) == Ks.bin_index(**{_MASS: (a + b) / 2})
                   for v in (a, b - 1e-9 * max(1.0, abs(b)))):
            raise ParameterError(f"the estimates [{a:g}, {b:g}] are not one bin of Ks")
    scheduling_subset(occupants, (a, b), float(error))
    return a, b


def _at_value(Ks, occupants, m3_hat, error, delays, *, mu, search, omega, design, rng,
              search_n, road) -> ScheduleValueCheck:
    """The certificate at one scheduling value."""
    from .occupants import occupant_mu
    from .worstcase import worst_bump_seats

    a, b = _check_value(Ks, occupants, m3_hat, error)
    K = _controller(Ks, (a + b) / 2)
    subset = scheduling_subset(occupants, (a, b), error)
    check, rs = None, math.nan
    if mu:
        try:
            check = occupant_mu(K, subset, design=design, omega=omega, rng=rng)
            rs = check.rs_sup
        except ParameterError:          # the nominal µ loop is unstable: no bound
            rs = math.inf
    worst = (worst_bump_seats(K, subset, rng=rng, n=search_n, delays=delays,
                              road=road) if search else ())
    radius = float(np.max(np.abs(np.linalg.eigvals(K.A)), initial=0.0))
    return ScheduleValueCheck(m3_hat=(a + b) / 2, occupants=subset, mu=check, rs_mu=rs,
                              worst_seats=tuple(worst), controller_radius=radius,
                              estimates=(a, b))


def certify_scheduled(Ks, samples: OccupantSamples, *, rng: np.random.Generator,
                      error=5.0, errors=None, grid=None, delays=None, confirm: int = 3,
                      mu: bool = True, search: bool = True, search_n: int = 50,
                      omega=None, design=None,
                      progress: Callable[[str], None] | None = None) -> ScheduledCheck:
    """Certify a seat controller scheduled on the occupant's estimated mass (see the
    module docstring).

    Parameters
    ----------
    Ks : scheduled controller
        ``names == ("m3",)``, ``bounds``, ``at(m3=...)`` a continuous-time
        ``StateSpace`` from ``y = [x1, x3]`` (m) to ``u`` (N).
    samples : OccupantSamples
        Drawn by :func:`~.occupants.occupant_samples` from a seeded generator (10 000
        stability samples for a certificate).
    rng : numpy.random.Generator
        Draws the estimate errors (stability samples first, then performance samples),
        then seeds the µ lower bounds and the searches, one scheduling value after the
        other.
    error : float
        Half-width of the estimate's error, kg (5 by default); also the width of the set
        each scheduling value is certified over.
    errors : (array_like, array_like), optional
        The errors themselves for the stability and the performance samples (instead of
        draws); ``error`` still sets the sets of the grid.
    grid : array_like, optional
        The scheduling values of µ and the search (by default 9 over the schedule's
        range; for a table of bins, ``Ks.bins``); a value may be a bin of estimates
        ``(lo, hi)`` of a table of bins, certified over
        ``scheduling_subset(occupants, (lo, hi), error)``.
    delays : sequence of float, optional
        Delays of the road requirements (0, 5, …, 25 ms by default).
    confirm : int
        Re-simulations of the worst of each figure, as in ``certify_occupants``.
    mu, search : bool
        Compute mixed µ / run the worst-seat search at each scheduling value.
    search_n : int
        Latin-hypercube samples of each search besides the corners.
    omega : array_like, optional
        µ's frequency grid (:func:`~.occupants.occupant_mu`'s default).
    design : SeatDesignOptions, optional
        µ's delay cover (:data:`~.design.DEFAULT_DESIGN` by default).
    progress : callable, optional
        Called with a line of text every 1000 stability samples and per scheduling value.

    Returns
    -------
    ScheduledCheck

    Raises
    ------
    ParameterError
        ``Ks`` not scheduled on ``m3`` alone, its ``at`` not a seat controller, samples
        not from ``occupant_samples``, a grid value outside the set's masses.
    """
    from .loop import REFINE_DELAYS, BumpResponse
    from .simulate import closed_loop_stable

    t0 = time.perf_counter()
    if not isinstance(samples, OccupantSamples):
        raise ParameterError("samples must come from occupant_samples")
    if not isinstance(rng, np.random.Generator):
        raise ParameterError("rng must be a numpy.random.Generator (seeded by the caller)")
    lo, hi = _mass_range(Ks)
    if isinstance(confirm, bool) or not isinstance(confirm, int) or confirm < 0:
        raise ParameterError(f"confirm must be a non-negative int, got {confirm!r}")
    delays = tuple(float(d) for d in (REFINE_DELAYS if delays is None else delays))
    if not delays or any(not math.isfinite(d) or d < 0 for d in delays):
        raise ParameterError(f"delays must be finite and non-negative, got {delays!r}")
    occupants = samples.occupants
    if grid is None and getattr(Ks, "interpolation", None) == "bins":
        # a bin's ends clipped to the set's masses (the table may reach beyond them)
        grid = [(max(b[0][0], occupants.m3[0]), min(b[0][1], occupants.m3[1]))
                for b in Ks.bins if b[0][1] > occupants.m3[0] and b[0][0] < occupants.m3[1]]
    elif grid is None:
        grid = np.linspace(max(lo, occupants.m3[0]), min(hi, occupants.m3[1]), 9).tolist()
    else:
        grid = [g if np.ndim(g) else float(g) for g in
                (grid if isinstance(grid, (list, tuple)) else np.asarray(grid, dtype=float)
                 .tolist())]
    for m in grid:                      # before the long part: a bad grid fails at once
        _check_value(Ks, occupants, m, error)
    true_s = [p.m3 for p in samples.stability]
    true_p = [p.m3 for p in samples.performance]
    if errors is None:
        est_s = schedule_estimates(true_s, Ks, error, rng)
        est_p = schedule_estimates(true_p, Ks, error, rng)
    else:
        if len(errors) != 2:
            raise ParameterError("errors must be a pair (stability, performance)")
        est_s = schedule_estimates(true_s, Ks, errors[0])
        est_p = schedule_estimates(true_p, Ks, errors[1])

    unstable = []
    for k, (p, d, m) in enumerate(zip(samples.stability, samples.stability_delays, est_s)):
        if not closed_loop_stable(_controller(Ks, m), float(d), p):
            unstable.append((p, float(d), float(m)))
        if progress is not None and (k + 1) % 1000 == 0:
            progress(f"stability: {k + 1} of {len(samples.stability)}, "
                     f"{len(unstable)} unstable")
    ratio, u, x1, confirmed, loop_radius = _road_figures(Ks, samples, est_p, delays, confirm)
    nom = occupants.nominal
    Knom = _controller(Ks, float(np.clip(nom.m3, lo, hi)))
    nominal_ratio = (float(np.max(BumpResponse(road=samples.road, delays=delays, params=nom)
                                  .peaks(Knom)[0])) / samples.nominal_limit
                     if all(closed_loop_stable(Knom, d, nom) for d in delays) else math.inf)
    n = len(samples.performance)
    if n:
        i, j = np.unravel_index(int(np.argmax(np.where(np.isnan(ratio), -np.inf, ratio))),
                                ratio.shape)
        worst = (float(ratio[i, j]), samples.performance[i], delays[j])
    else:
        worst = (math.nan, None, math.nan)

    values = []
    for m in grid:
        values.append(_at_value(Ks, occupants, m, float(error), delays, mu=mu,
                                search=search, omega=omega, design=design, rng=rng,
                                search_n=search_n, road=samples.road))
        if progress is not None:
            v = values[-1]
            progress(f"m3_hat {v.estimates[0]:g}-{v.estimates[1]:g} kg: mixed µ {v.rs_mu:.4g}, "
                     + ", ".join(w.describe() for w in v.worst_seats))
    rs = [v.rs_mu for v in values]
    found = {f: [w.value for v in values for w in v.worst_seats if w.figure == f]
             for f in ("u", "x1")}
    return ScheduledCheck(
        n_stability=len(samples.stability), unstable=len(unstable),
        unstable_samples=tuple(unstable[:20]), stability_estimates=est_s,
        performance_estimates=est_p, delays=delays, ratio=ratio, u_peak=u, x1_peak=x1,
        worst_ratio=worst[0], worst_sample=worst[1], worst_delay=worst[2],
        u_max=float(np.max(u, initial=-np.inf)), x1_max=float(np.max(x1, initial=-np.inf)),
        nominal_ratio=nominal_ratio, confirmed=confirmed, values=tuple(values),
        rs_mu_max=float(max(rs)) if mu and rs else math.nan,
        u_searched=float(max(found["u"])) if found["u"] else math.nan,
        x1_searched=float(max(found["x1"])) if found["x1"] else math.nan,
        controller_radius=max(v.controller_radius for v in values) if values else math.nan,
        loop_radius=loop_radius,
        error=None if errors is not None else float(error),
        seconds=time.perf_counter() - t0)
