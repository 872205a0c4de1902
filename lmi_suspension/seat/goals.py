"""The seat's tuning requirements, as classes of :mod:`lmi_suspension.tune`'s protocol.

The refinement (:func:`~.refine.refine_seat_controller`) tunes a seat controller with
:func:`~lmi_suspension.tune.systune`'s SLSQP route against these requirements, each a
small class with ``name``, ``bind``, ``value``, ``certify`` (the protocol of
:class:`~lmi_suspension.tune.Requirement`) and the vector of every term of its maximum
(``terms`` for the soft one, ``margins`` for the hard ones):

* :class:`BumpPeak` (soft): peak ``|z̈3|`` on the road at each delay and seat, over the
  seat's own limit where there are several seats;
* :class:`BumpForce`, :class:`BumpStroke`: commanded ``|u|`` and ``|x1|`` on the road;
* :class:`MuBound`: µ over the delay cover and the performance block (or the cover's gain
  alone), at the further seats the cover's gain, and over a set of seats their mixed µ
  with scalings refreshed at each stage's start;
* :class:`PoleDisk`: every controller and loop pole inside a disk a 1 kHz controller
  resolves;
* :class:`PoleShape`: the slowest poles' decay and the least damped poles' damping.

Their figures are exact and in closed form (the loop with the exact delay by FFT,
:class:`~.loop.BumpResponse`; µ of two full blocks, :class:`~.loop.TwoBlockMu`), computed
once per controller by one :class:`SeatLoops` that they share.  The tuned model is the
design seat's µ plant (``lft(P, K)`` is the µ loop, whose stability the engine checks);
the other figures come from the controller itself (:attr:`ClosedLoop.controller
<lmi_suspension.tune.ClosedLoop.controller>`).  Each certifies itself by another route:
the time-stepping simulation of the exact-delay loop (:func:`~.simulate.simulate`), µ by
:func:`~lmi_suspension.mu.mussv` and the delay cover's gain by ``freqresp`` of
``lft(P, K)``, the set's mixed µ by scalings optimised for the controller itself, the
poles by ``numpy.linalg.eigvals`` of ``lft(P, K)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import control
import numpy as np

from ..errors import DimensionError
from .loop import TwoBlockMu, loop_poles

__all__ = ["MIN_DAMPING", "MIN_DECAY", "BumpForce", "BumpPeak", "BumpStroke", "DesignSeat",
           "MuBound", "PoleDisk", "PoleShape", "SeatLoops"]

#: every loop pole's real part below minus this (rad/s), so that the FFT record decays
#: (see :data:`~.loop._FFT_HORIZON`); the µ controller's slowest is 0.66
MIN_DECAY = 0.5
#: and its damping ratio above this: µ's peak at a pole of damping ζ is about 2ζ wide,
#: so a grid cannot hide it (the search hid a peak µ 1.72 at 1.9 rad/s from a 150-point
#: grid, 2026-11-26); the µ controller's least damped loop pole has ζ = 0.52
MIN_DAMPING = 0.05
#: how many of the slowest and the least damped poles carry those constraints
_SHAPE_POLES = 4
#: µ's largest local maxima on the grid, refined between grid points
#: (:meth:`~.loop.TwoBlockMu.peaks`), are terms too, this many: on the 150-point grid
#: alone the search hid a resonance at 76 rad/s between two points, µ 0.978 on the grid
#: and 1.035 at the peak (2026-11-26).
_PEAKS = 6
#: µ is also taken at this many least damped loop pole pairs (|p| and |Im p| of each)
_RESONANCES = 6
#: forward-difference step of ``value``'s gradient, in the block's parameters (normalised
#: by the seat's modal block: 1e-6 of a gain's magnitude, of a pole's logarithm)
_FD_STEP = 1e-6


def _shape_margins(poles: np.ndarray) -> np.ndarray:
    """Normalised margins (>= 0 where met) of the :data:`_SHAPE_POLES` slowest poles'
    decay (:data:`MIN_DECAY`) and least damped poles' damping (:data:`MIN_DAMPING`)."""
    decay = np.sort(-poles.real)[:_SHAPE_POLES] / MIN_DECAY - 1
    zeta = np.sort(-poles.real / np.maximum(np.abs(poles), 1e-300))[:_SHAPE_POLES]
    return np.concatenate([decay, zeta / MIN_DAMPING - 1])


def _resonance_points(poles: np.ndarray) -> np.ndarray:
    """``|p|`` and ``|Im p|`` of the :data:`_RESONANCES` least damped pole pairs (the
    least damped repeated where there are fewer pairs): a fixed number of frequencies."""
    p = poles[poles.imag > 0]
    if p.size == 0:
        return np.ones(2 * _RESONANCES)
    p = p[np.argsort(-p.real / np.abs(p), kind="stable")]
    p = np.concatenate([p, np.repeat(p[:1], _RESONANCES)])[:_RESONANCES]
    return np.concatenate([np.abs(p), p.imag])


def _cover_points(mu: TwoBlockMu, K, poles: np.ndarray) -> list:
    """The delay cover's gain where it is bounded: on the grid, at its :data:`_PEAKS`
    largest maxima refined between grid points, and at the loop's resonances, as µ is
    for robust performance.  On the grid alone the multi-seat design's cover reached µ
    0.999 (mixed, dense grid) at 86.6 rad/s between two points of its 200 (2026-11-27)."""
    curve, top, _ = mu.cover_peaks(K, _PEAKS)
    return [curve, top, mu.cover_gain(K, _resonance_points(poles))]


@dataclass(frozen=True)
class DesignSeat:
    """One seat the requirements are evaluated at: its bump response, the unit of its
    peak ``|z̈3|`` (1: m/s²; or its own limit), its parameters and its delay cover's
    :class:`~.loop.TwoBlockMu` (None at the design seat, whose µ is :class:`SeatLoops`')."""

    bumpr: object
    unit: float
    params: object
    cover: TwoBlockMu | None


@dataclass(frozen=True)
class _Figures:
    z: np.ndarray           # peak |z3''| per seat and delay (over the seat's unit)
    u: np.ndarray
    x1: np.ndarray
    mu_curve: np.ndarray    # µ on the search grid, at its refined peaks and resonances
    magnitudes: np.ndarray  # controller and loop pole magnitudes, sorted
    shape: np.ndarray       # decay and damping margins of the slowest / least damped


class SeatLoops:
    """Every figure the seat's requirements read, for one controller at a time, computed
    once and cached per parameter vector (the requirements share one instance).

    Parameters
    ----------
    seats : sequence of DesignSeat
        The design seat first.
    mu : TwoBlockMu
        The design seat's µ over the delay cover and the performance block.
    mu_performance : bool
        µ of both blocks at the design seat (True) or the cover's gain alone.
    rs : MixedRsBound, optional
        The set of seats' robust stability, its scalings held through a stage.
    """

    def __init__(self, seats, mu: TwoBlockMu, mu_performance: bool = True, rs=None):
        self.seats, self.mu, self.mu_performance, self.rs = tuple(seats), mu, mu_performance, rs
        self.rs_scal = None
        self._cache: dict = {}
        self._certified: dict = {}

    # ------------------------------------------------------------------ the search's
    def figures(self, loop) -> _Figures | None:
        """The figures of the loop's controller, None where a loop is unstable."""
        theta = np.asarray(loop.theta, dtype=float)
        key = theta.tobytes()
        if key not in self._cache:
            self._cache[key] = self._figures(loop, theta)
        return self._cache[key]

    def figures_at(self, theta) -> _Figures | None:
        """The cached figures at ``theta`` (None if not evaluated, or unstable)."""
        return self._cache.get(np.asarray(theta, dtype=float).tobytes())

    def refresh(self, K) -> None:
        """The set's scalings for ``K`` (its robust stability's D-step); every cached
        figure is forgotten (its µ was another bound)."""
        self.rs_scal = self.rs.scalings(K)
        self._cache.clear()

    def stable(self, K) -> bool:
        """Every loop the figures need stable (the seats', the µ loops', the set's)."""
        with np.errstate(all="ignore"):
            try:
                poles = np.concatenate(
                    [loop_poles(K, s.params) for s in self.seats] + [self.mu.loop_poles(K)]
                    + [s.cover.loop_poles(K) for s in self.seats if s.cover is not None]
                    + ([self.rs.loop_poles(K)] if self.rs is not None else []))
            except np.linalg.LinAlgError:
                return False
        return bool(np.all(np.isfinite(poles)) and np.max(poles.real) < 0)

    def _figures(self, loop, theta):
        n_poles = int(getattr(loop.block, "n_poles", 0))
        if not np.all(np.isfinite(theta)) or np.any(theta[:n_poles] > 50):
            return None
        K = loop.controller
        with np.errstate(all="ignore"):
            try:
                pa = self.mu.loop_poles(K)
                covers = [(s.cover, s.cover.loop_poles(K)) for s in self.seats
                          if s.cover is not None]
                poles = np.concatenate([loop_poles(K, s.params) for s in self.seats] + [pa]
                                       + [pc for _, pc in covers])
                # the set's µ loop: its stability only (its weights' poles are not the
                # loop's shape)
                if self.rs is not None and np.max(self.rs.loop_poles(K).real) >= 0:
                    return None
            except np.linalg.LinAlgError:
                return None
            if not np.all(np.isfinite(poles)) or np.max(poles.real) >= 0:
                return None             # unstable: neither the FFT nor µ applies
            peaks = [s.bumpr.peaks(K) for s in self.seats]
            z = np.concatenate([zs / s.unit for (zs, _, _), s in zip(peaks, self.seats)])
            u = np.concatenate([p[1] for p in peaks])
            x1 = np.concatenate([p[2] for p in peaks])
            if self.mu_performance:
                curve, top, _ = self.mu.peaks(K, _PEAKS)
                rp = [curve, top, self.mu.curve(K, _resonance_points(pa))]
            else:
                rp = _cover_points(self.mu, K, pa)
            if self.rs is not None:
                rp.append(self.rs.levels(K, self.rs_scal))
            mu = np.concatenate(rp + [g for cover, pc in covers
                                      for g in _cover_points(cover, K, pc)])
        mags = np.sort(np.abs(np.concatenate([poles, np.linalg.eigvals(K.A)])))
        return _Figures(z, u, x1, mu, mags, _shape_margins(poles))

    # ------------------------------------------------------------------ certificates
    def certified(self, K) -> dict:
        """The same figures by other routes, cached per controller: the bump by the
        time-stepping exact-delay simulation, µ by :func:`~lmi_suspension.mu.mussv`,
        the covers' gains by ``freqresp`` of ``lft(P, K)``, the set's mixed µ by scalings
        optimised for ``K`` over every frequency, the poles by ``eigvals`` of the
        interconnections built by ``lft``."""
        from ..lti import freqresp, lft
        from ..mu import mussv
        from ..mu.steps import mu_part
        from ..umodel.blocks import BlockStructure
        from .roads import bump
        from .simulate import simulate

        key = b"".join(np.asarray(m, dtype=float).tobytes() for m in (K.A, K.B, K.C, K.D))
        if key in self._certified:
            return self._certified[key]
        K = control.ss(K.A, K.B, K.C, K.D)
        z, u, x1 = [], [], []
        for s in self.seats:
            c = s.bumpr
            road = bump() if c.road is None else c.road
            for d in np.atleast_1d(c.delays):
                # the peaks alone (SimulationResult.metrics's, without its comfort filter)
                r = simulate(K, road, delay=float(d), params=s.params, u_max=np.inf)
                z.append(float(np.max(np.abs(r.z3dd))) / s.unit)
                u.append(float(np.max(np.abs(r.u_command))))
                x1.append(float(np.max(np.abs(r.x1))))
        mu_c = self.mu._c
        CL = lft(mu_c["P"], K, int(mu_c["ny"]), int(mu_c["nu"]))
        omega = np.unique(np.concatenate([mu_c["omega"], self.mu.peaks(K, _PEAKS)[2]]))
        if self.mu_performance:
            blk = mu_c["blk"]
            struct = BlockStructure.coerce(blk)
            mu = [float(np.max(mussv(freqresp(mu_part(CL, struct), omega), blk,
                                     rng=np.random.default_rng(0)).upper))]
        else:
            mu = [_cover_gain(CL, mu_c, omega)]
        poles = [np.linalg.eigvals(np.asarray(CL.A))]
        for s in self.seats:
            poles.append(loop_poles(K, s.params))
            if s.cover is not None:
                cc = s.cover._c
                CLc = lft(cc["P"], K, int(cc["ny"]), int(cc["nu"]))
                mu.append(_cover_gain(CLc, cc, omega))
                poles.append(np.linalg.eigvals(np.asarray(CLc.A)))
        rs_sup = float("nan")
        if self.rs is not None:
            rs_sup = float(self.rs.scalings(K).sup)
            mu.append(rs_sup)
        poles = np.concatenate(poles)
        out = {"z": float(np.max(z)), "u": float(np.max(u)), "x1": float(np.max(x1)),
               "mu": float(np.max(mu)), "rs_sup": rs_sup,
               "radius": float(np.max(np.abs(np.concatenate(
                   [poles, np.linalg.eigvals(np.asarray(K.A))])))),
               "shape": float(np.min(_shape_margins(poles)))}
        self._certified[key] = out
        return out


def _cover_gain(CL, c, omega) -> float:
    """σ̄ of the delay cover's channel of ``CL`` on ``omega`` (one full block: µ)."""
    from ..lti import freqresp

    M = np.moveaxis(freqresp(CL, omega)[:c["rows"], :c["cols"]], -1, 0)
    return float(np.max(np.linalg.svd(M, compute_uv=False)[:, 0]))


def _fd_gradient(f, loop) -> np.ndarray:
    """Forward differences of ``f`` (a function of a loop) in the block's parameters."""
    theta = np.asarray(loop.theta, dtype=float)
    f0 = f(loop)
    g = np.zeros(theta.size)
    for i in range(theta.size):
        t = theta.copy()
        t[i] += _FD_STEP
        probe = SimpleNamespace(theta=t, block=loop.block, controller=loop.block.ss(t))
        g[i] = (f(probe) - f0) / _FD_STEP
    return g


class _SeatRequirement:
    """What the seat's requirements share: one :class:`SeatLoops`, the protocol's
    ``bind`` (the seat's µ plant: two measurements, one control) and ``value`` as the
    largest term with a forward-difference gradient."""

    name = "seat requirement"

    def __init__(self, loops: SeatLoops):
        if not isinstance(loops, SeatLoops):
            raise DimensionError(f"{self.name}: loops must be SeatLoops, got "
                                 f"{type(loops).__name__}")
        self.loops = loops

    def bind(self, plant):
        if (plant.ny, plant.nu) != (2, 1):
            raise DimensionError(f"{self.name}: a seat controller reads two measurements "
                                 f"and drives one control; the plant has {plant.ny} and "
                                 f"{plant.nu}")
        return self

    def _value(self, loop) -> float:
        t = self.terms(loop) if hasattr(self, "terms") else 1.0 - self.margins(loop, 1.0)
        return np.inf if t is None else float(np.max(t))

    def value(self, loop) -> tuple:
        v = self._value(loop)
        if not np.isfinite(v):
            return np.inf, None
        return v, _fd_gradient(self._value, loop)


class BumpPeak(_SeatRequirement):
    """Soft: peak ``|z̈3|`` on the road, each seat and delay (m/s², or over each seat's
    own limit with several seats)."""

    name = "bump peak"

    def terms(self, loop):
        f = self.loops.figures(loop)
        return None if f is None else f.z

    def certify(self, CL, plant, K) -> float:
        return self.loops.certified(K)["z"]


class _Bound(_SeatRequirement):
    """A hard bound on a figure: margins ``1 - figure / (bound · tighten)``."""

    figure = ""

    def __init__(self, loops: SeatLoops, bound: float):
        super().__init__(loops)
        self.bound = float(bound)

    def margins(self, loop, tighten):
        f = self.loops.figures(loop)
        return None if f is None else 1 - getattr(f, self.figure) / (self.bound * tighten)

    def certify(self, CL, plant, K) -> float:
        return self.loops.certified(K)[self.figure.split("_")[0]] / self.bound


class BumpForce(_Bound):
    """Hard: commanded ``|u| <= bound`` (N) on the road, each seat and delay."""

    name = "bump force"
    figure = "u"


class BumpStroke(_Bound):
    """Hard: ``|x1| <= bound`` (m) on the road, each seat and delay."""

    name = "bump stroke"
    figure = "x1"


class MuBound(_Bound):
    """Hard: µ (or the delay cover's gain) ``<= bound`` at the seats, and the set's mixed
    µ with its scalings refreshed at each stage's start (:meth:`refresh`)."""

    name = "µ bound"
    figure = "mu_curve"

    def refresh(self, loop) -> None:
        if self.loops.rs is not None:
            self.loops.refresh(loop.controller)

    def certify(self, CL, plant, K) -> float:
        return self.loops.certified(K)["mu"] / self.bound


class PoleDisk(_Bound):
    """Hard: every controller and loop pole inside ``|s| < bound`` (rad/s)."""

    name = "pole disk"
    figure = "magnitudes"

    def certify(self, CL, plant, K) -> float:
        return self.loops.certified(K)["radius"] / self.bound


class PoleShape(_SeatRequirement):
    """Hard: the slowest loop poles decay faster than :data:`MIN_DECAY`, the least damped
    have damping above :data:`MIN_DAMPING` (margins not tightened)."""

    name = "pole shape"

    def margins(self, loop, tighten):
        f = self.loops.figures(loop)
        return None if f is None else f.shape

    def certify(self, CL, plant, K) -> float:
        return 1.0 - self.loops.certified(K)["shape"]
