"""Figures of the paper (Figs. 7–15) and the delay study, drawn with matplotlib.

Every function takes already-computed results and returns a :class:`matplotlib.figure.Figure`;
nothing here runs a simulation or a solver, and nothing calls ``plt.show()``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import NullFormatter

__all__ = ["plot_bounded_response", "plot_commanded_force", "plot_constrained_tradeoff",
           "plot_force_tradeoff", "plot_mu_bounds", "plot_peak_vs_delay", "plot_responses",
           "plot_occupants", "plot_occupant_maps", "plot_occupant_tradeoff",
           "plot_ratio_over_mass", "plot_road"]

_LABELS = {
    "z3dd": ("upper-body acceleration $\\ddot z_3$", "m/s²"),
    "x1": ("suspension deflection $x_1$", "m"),
    "u_applied": ("actuator force $u$ (applied)", "N"),
}


def plot_road(road, *, title: str = "") -> Figure:
    """Road displacement z0 and its velocity w = ż0 (paper Figs. 7 and 8).

    Examples
    --------
    >>> from lmi_suspension.seat import bump
    >>> fig = plot_road(bump())
    >>> len(fig.axes)
    2
    """
    fig = Figure(figsize=(7, 4.5), layout="constrained")
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    ax1.plot(road.t, road.z0, color="k")
    ax1.set_ylabel("$z_0$ [m]")
    ax2.plot(road.t, road.w, color="k")
    ax2.set_ylabel("$w = \\dot z_0$ [m/s]")
    ax2.set_xlabel("time [s]")
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
    fig.suptitle(title or getattr(road, "description", ""))
    return fig


def plot_responses(runs: Mapping[str, object], signal: str, *, title: str = "",
                   limit: float | None = None, t_max: float | None = None) -> Figure:
    """One signal of several simulations on one axis (paper Figs. 9–14).

    Parameters
    ----------
    runs : mapping of label -> SimulationResult
        E.g. ``{"passive": ..., "µ, d = 0 ms": ..., "µ, d = 25 ms": ...}``.
    signal : {"z3dd", "x1", "u_applied"}
        Which signal to draw.
    limit : float, optional
        A symmetric limit drawn as dashed lines (``z_max`` or ``u_max``).
    t_max : float, optional
        Right end of the time axis.

    Examples
    --------
    >>> from lmi_suspension.seat import bump, simulate
    >>> r = bump(t_end=0.5)
    >>> fig = plot_responses({"passive": simulate(None, r, dt=1e-3)}, "x1", limit=0.08)
    >>> [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    ['passive', 'limit ±0.08 m']
    """
    name, unit = _LABELS[signal]
    fig = Figure(figsize=(7, 3.8), layout="constrained")
    ax = fig.subplots()
    for label, run in runs.items():
        style = ({"color": "0.45", "lw": 1.6, "ls": "--"} if label.startswith("passive")
                 else {"lw": 1.2})
        ax.plot(run.t, getattr(run, signal), label=label, **style)
    return _finish_time_axes(fig, ax, f"{name} [{unit}]", limit,
                             f"limit ±{limit:g} {unit}" if limit is not None else "",
                             t_max, title, fontsize=8)


def _finish_time_axes(fig, ax, ylabel, limit, limit_label, t_max, title, *, fontsize):
    """Symmetric limit lines, labels, grid and legend of a time-response axis."""
    if limit is not None:
        for sign in (1, -1):
            ax.axhline(sign * limit, color="r", ls=":", lw=1,
                       label=limit_label if sign > 0 else None)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(ylabel)
    if t_max is not None:
        ax.set_xlim(0, t_max)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=fontsize, ncol=2)
    ax.set_title(title)
    return fig


def plot_commanded_force(runs: Mapping[str, object], *, limit: float | None = None,
                         t_max: float | None = None, title: str = "") -> Figure:
    """Commanded (solid) against applied (dashed) force of several simulations: where
    they part, the actuator clips and the loop is no longer the one designed.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.seat import bump, simulate
    >>> r = simulate(np.array([[20000.0, 0.0]]), bump(t_end=0.5), dt=1e-3)
    >>> fig = plot_commanded_force({"K": r}, limit=1500.0)
    >>> len(fig.axes[0].get_lines())
    4
    """
    fig = Figure(figsize=(7, 3.8), layout="constrained")
    ax = fig.subplots()
    for k, (label, run) in enumerate(runs.items()):
        ax.plot(run.t, run.u_command, color=f"C{k}", lw=1.2, label=f"{label}, commanded")
        ax.plot(run.t, run.u_applied, color=f"C{k}", lw=1.0, ls="--",
                label=f"{label}, applied")
    return _finish_time_axes(fig, ax, "actuator force $u$ [N]", limit,
                             f"actuator limit ±{limit:g} N" if limit is not None else "",
                             t_max, title, fontsize=7)


def plot_mu_bounds(omega: np.ndarray, upper: np.ndarray, lower: np.ndarray, *,
                   title: str = "") -> Figure:
    """µ upper and lower bounds over frequency (paper Fig. 15), ω in rad/s."""
    fig = Figure(figsize=(7, 3.8), layout="constrained")
    ax = fig.subplots()
    ax.semilogx(omega, upper, label="µ upper bound", color="C0")
    ax.semilogx(omega, lower, label="µ lower bound", color="C1", ls="--")
    ax.axhline(1.0, color="r", ls=":", lw=1, label="robust performance limit")
    k = int(np.argmax(upper))
    ax.plot(omega[k], upper[k], "o", color="C0")
    ax.annotate(f"peak {upper[k]:.3f} at {omega[k]:.3g} rad/s", (omega[k], upper[k]),
                textcoords="offset points", xytext=(8, 6), fontsize=8)
    ax.set_xlabel("frequency ω [rad/s]")
    ax.set_ylabel("µ")
    # headroom so the peak's annotation stays inside the axes
    ax.set_ylim(0, 1.15 * max(float(np.max(upper)), 1.0))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title)
    return fig


def plot_peak_vs_delay(delays: Sequence[float], peaks: Mapping[str, Sequence[float]], *,
                       limit: float | None = None, passive: float | None = None,
                       stable: Mapping[str, Sequence[bool]] | None = None,
                       title: str = "") -> Figure:
    """Peak ``|z̈3|`` on the bump against the actuator delay, with the physical limit.

    Parameters
    ----------
    delays : sequence of float
        Delays in seconds.
    peaks : mapping of label -> sequence of float
        Peak ``|z̈3|`` of each controller at each delay (``nan`` where unstable).
    limit : float, optional
        The smallest peak any admissible force history reaches (the LP bound).
    passive : float, optional
        The passive seat's peak.
    stable : mapping of label -> sequence of bool, optional
        Whether each closed loop is stable at each delay; unstable points are crossed
        out (their peak is only that of a finite record of a growing response).
    """
    d_ms = 1e3 * np.asarray(delays, dtype=float)
    fig = Figure(figsize=(9, 3.8), layout="constrained")
    ax = fig.subplots()
    crossed = False
    for label, values in peaks.items():
        line, = ax.plot(d_ms, values, "o-", label=label)
        flags = None if stable is None else stable.get(label)
        if flags is not None:
            bad = ~np.asarray(flags, dtype=bool)
            if bad.any():
                ax.plot(d_ms[bad], np.asarray(values, dtype=float)[bad], "x", ms=12, mew=2.5,
                        color="crimson", label=None if crossed else "closed loop unstable")
                crossed = True
    if passive is not None:
        ax.axhline(passive, color="0.45", ls="--", label="passive")
        ax.axhline(passive / 2, color="0.45", ls=":", label="half passive")
    if limit is not None:
        ax.axhline(limit, color="k", lw=2, label="physical limit (LP, full road knowledge)")
        ax.axhline(1.5 * limit, color="k", lw=1, ls=":", label="1.5 × physical limit")
    ax.set_xlabel("actuator delay d [ms]")
    ax.set_ylabel("peak $|\\ddot z_3|$ on the bump [m/s²]")
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    # Outside the axes: seven entries inside would hide the curves of the worst controller.
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.set_title(title)
    return fig


def plot_force_tradeoff(u_bounds: Sequence[float], hinf: Sequence[float],
                        hinf_lmi: Sequence[float], bump_peak: Sequence[float],
                        bump_force: Sequence[float], *, hinf_free: float | None = None,
                        passive: float | None = None, limit: float | None = None,
                        title: str = "") -> Figure:
    """The price of a hard force bound (peak-bounded seat designs, issue 16).

    Parameters
    ----------
    u_bounds : sequence of float
        Force bounds, N (for every floor velocity of the bump's energy).
    hinf, hinf_lmi : sequence of float
        Certified H∞ level of each design and the level its LMIs guarantee.
    bump_peak, bump_force : sequence of float
        Peak ``|z̈3|`` and largest ``|u|`` of each linear closed loop on the bump.
    hinf_free : float, optional
        The H∞ optimum without bounds.
    passive, limit : float, optional
        The passive seat's bump peak and the physical limit (LP), m/s².

    Examples
    --------
    >>> fig = plot_force_tradeoff([700, 1500], [39.3, 28.6], [39.6, 28.9], [24.4, 21.8],
    ...                           [352.0, 732.0], hinf_free=23.2)
    >>> len(fig.axes)
    3
    """
    u = np.asarray(u_bounds, dtype=float)
    fig = Figure(figsize=(11, 3.6), layout="constrained")
    a1, a2, a3 = fig.subplots(1, 3, sharex=True)
    a1.plot(u, hinf, "o-", label="certified (hinfnorm)")
    a1.plot(u, hinf_lmi, "s--", mfc="none", label="LMI level")
    if hinf_free is not None:
        a1.axhline(hinf_free, color="0.45", ls=":", label="no bound")
    a1.set_ylabel("$\\|w \\to [\\ddot z_3, \\rho u]\\|_\\infty$")
    a2.plot(u, bump_peak, "o-", color="C2", label="bounded design")
    if passive is not None:
        a2.axhline(passive, color="0.45", ls="--", label="passive")
    if limit is not None:
        a2.axhline(limit, color="k", lw=2, label="physical limit (LP)")
    a2.set_ylabel("peak $|\\ddot z_3|$ on the bump [m/s²]")
    a2.set_ylim(bottom=0)
    a3.plot(u, bump_force, "o-", color="C3", label="largest $|u|$ on the bump")
    a3.plot(u, u, color="k", lw=1, label="bound")
    a3.set_ylabel("force [N]")
    for ax in (a1, a2, a3):
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xticks(u, [f"{x:g}" for x in u], rotation=60, fontsize=8)
        ax.set_xlabel("force bound $u_{max}$ [N]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title)
    return fig


def plot_constrained_tradeoff(points: Sequence, *, limit: float,
                              reference: Mapping[str, tuple] | None = None,
                              u_actuator: float = 1500.0, goal: float = 1.3,
                              title: str = "",
                              label: str = "constrained µ designs",
                              bound_label: str = "force bound in the K-step (bump's energy)"
                              ) -> Figure:
    """The trade-off of the constrained µ designs (issue 17): bump peak against commanded
    force, and µ against the force bound.

    Parameters
    ----------
    points : sequence of TradeoffPoint
        From :func:`~lmi_suspension.seat.constrained.constrained_tradeoff` (anything with
        ``u_bound``, ``mu_peak``, ``bump_peak`` and ``bump_u``).
    limit : float
        The physical limit of the bump (LP), m/s².
    reference : mapping, optional
        Label -> ``(bump_u, bump_peak)`` per delay of other controllers (the µ
        controller of the paper's weights, say), drawn as single points.
    u_actuator : float
        The actuator's force limit, N.
    goal : float
        The goal as a multiple of ``limit``.
    label : str
        What the points are (the legend's first entry).
    bound_label : str
        What ``u_bound`` bounds (the second axes' abscissa).

    Examples
    --------
    >>> from types import SimpleNamespace as P
    >>> pts = [P(u_bound=2500.0, mu_peak=2.1, bump_peak=(20.6, 21.9), bump_u=(689.0, 700.0)),
    ...        P(u_bound=9000.0, mu_peak=2.6, bump_peak=(17.2, 18.0), bump_u=(1038.0, 1096.0))]
    >>> fig = plot_constrained_tradeoff(pts, limit=6.164, reference={"µ": ((2827.0,), (9.06,))})
    >>> len(fig.axes)
    2
    """
    order = np.argsort([p.u_bound for p in points])
    pts = [points[i] for i in order]
    fig = Figure(figsize=(10, 4), layout="constrained")
    a1, a2 = fig.subplots(1, 2)
    u_cmd = np.array([max(p.bump_u) for p in pts])
    worst = np.array([max(p.bump_peak) for p in pts])
    best = np.array([min(p.bump_peak) for p in pts])
    a1.plot(u_cmd, worst, "o-", color="C0", label=f"{label}, worst delay")
    a1.plot(u_cmd, best, "o--", mfc="none", color="C0", label="best delay")
    for p, x, y in zip(pts, u_cmd, worst):
        a1.annotate(f"{p.u_bound:g} N", (x, y), textcoords="offset points", xytext=(4, 4),
                    fontsize=8)
    for k, (name, (u, peak)) in enumerate((reference or {}).items()):
        a1.plot([max(u)], [max(peak)], "*", ms=12, color=f"C{k + 3}", label=name)
    a1.axhline(limit, color="k", lw=2, label=f"physical limit (LP) {limit:.3g} m/s²")
    a1.axhline(goal * limit, color="k", ls="--", lw=1, label=f"goal {goal:g} × limit")
    a1.axvline(u_actuator, color="C3", ls=":", label=f"actuator {u_actuator:g} N")
    a1.set_xlabel("largest commanded $|u|$ on the bump, 0–25 ms [N]")
    a1.set_ylabel("peak $|\\ddot z_3|$ on the bump [m/s²]")
    # room above the highest point for its label; the legend where no design lies
    # (below the limit at small forces: no design reaches the limit without force)
    tops = [*worst, goal * limit] + [max(peak) for _u, peak in (reference or {}).values()]
    a1.set_ylim(0, 1.12 * max(tops))
    a1.set_xlim(left=0)
    a1.legend(fontsize=8, loc="lower left")
    a2.plot([p.u_bound for p in pts], [p.mu_peak for p in pts], "o-", color="C1",
            label="µ upper bound (delay cover 0–25 ms)")
    a2.axhline(1.0, color="k", lw=1, label="µ = 1")
    a2.set_xlabel(f"{bound_label} [N]")
    a2.set_ylabel("µ")
    a2.set_ylim(bottom=0)
    a2.legend(fontsize=8)
    for ax in (a1, a2):
        ax.grid(True, alpha=0.3)
    fig.suptitle(title)
    return fig


def plot_bounded_response(sim, *, u_max: float, z_max: float, title: str = "") -> Figure:
    """A closed loop on the bump with the force and stroke bounds drawn: ``z̈3``,
    commanded force and ``x1`` (nothing clipped unless the simulation clipped).

    Examples
    --------
    >>> from lmi_suspension.seat import bump, simulate
    >>> fig = plot_bounded_response(simulate(None, bump()), u_max=1500.0, z_max=0.08)
    >>> len(fig.axes)
    3
    """
    fig = Figure(figsize=(8, 6.5), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    for ax, (data, label, bound) in zip(axes, (
            (sim.z3dd, "$\\ddot z_3$ [m/s²]", None),
            (sim.u_command, "commanded $u$ [N]", u_max),
            (sim.x1, "$x_1$ [m]", z_max))):
        ax.plot(sim.t, data, color="k")
        if bound is not None:
            for sign in (1, -1):
                ax.axhline(sign * bound, color="crimson", ls="--",
                           label="bound" if sign > 0 else None)
            ax.legend(fontsize=8, loc="upper right")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time [s]")
    axes[-1].set_xlim(0, min(float(sim.t[-1]), 1.5))
    fig.suptitle(title)
    return fig


def plot_occupants(check, samples, *, x: str = "m3", y: str = "k1", title: str = "") -> Figure:
    """A controller over a set of seats (:func:`~lmi_suspension.seat.occupants.certify_occupants`):
    each performance sample in the ``x`` × ``y`` plane, coloured by its worst peak over its
    own limit across the delays; stability samples whose loop is unstable marked ×,
    performance samples unstable at a delay boxed, those without a limit (failed LP)
    drawn as grey diamonds; the worst sample ringed.

    Parameters
    ----------
    check : OccupantCheck
    samples : OccupantSamples
        The samples ``check`` was computed on.
    x, y : str
        The :class:`~lmi_suspension.seat.SeatParameters` fields of the axes.
    """
    from matplotlib.colors import Normalize

    fig = Figure(figsize=(7, 4.6), layout="constrained")
    ax = fig.subplots()
    ratio = np.asarray(check.ratio, dtype=float)
    unstable = np.any(np.isposinf(ratio), axis=1)
    # a sample whose limit LP failed has no ratio (nan): drawn apart, not as unstable
    no_limit = ~unstable & np.any(np.isnan(ratio), axis=1)
    stable = ~unstable & ~no_limit
    worst = np.where(stable, np.max(np.where(stable[:, None], ratio, 0.0), axis=1), np.nan)
    px = np.array([getattr(p, x) for p in samples.performance])
    py = np.array([getattr(p, y) for p in samples.performance])
    norm = Normalize(vmin=1.0, vmax=max(float(np.max(worst[stable], initial=1.0)), 1.5))
    sc = ax.scatter(px[stable], py[stable], c=worst[stable], cmap="viridis", norm=norm, s=22,
                    label="performance samples")
    fig.colorbar(sc, ax=ax, label="worst peak $|\\ddot z_3|$ / own limit, 0–25 ms")
    if np.any(unstable):
        ax.scatter(px[unstable], py[unstable], marker="s", facecolors="none",
                   edgecolors="k", s=30, label="loop unstable at a delay")
    if np.any(no_limit):
        ax.scatter(px[no_limit], py[no_limit], marker="D", facecolors="none",
                   edgecolors="0.5", s=26, label="own limit not computed (LP failed)")
    if check.unstable_samples:
        ux = [getattr(p, x) for p, _ in check.unstable_samples]
        uy = [getattr(p, y) for p, _ in check.unstable_samples]
        ax.scatter(ux, uy, marker="x", color="r", s=30,
                   label=f"unstable stability samples ({check.unstable} of "
                         f"{check.n_stability}; first {len(ux)} shown)")
    if np.isfinite(check.worst_ratio):
        wx, wy = getattr(check.worst_sample, x), getattr(check.worst_sample, y)
        ax.plot(wx, wy, "o", ms=14, mfc="none", mec="r")
        ax.annotate(f"worst {check.worst_ratio:.2f} × at {check.worst_delay * 1e3:.0f} ms",
                    (wx, wy), textcoords="offset points", xytext=(10, 8), fontsize=8)
    units = {"m3": "kg", "k1": "N/m", "k2": "N/m", "k3": "N/m", "c1": "N·s/m",
             "c2": "N·s/m", "c3": "N·s/m"}
    ax.set_xlabel(f"{x} [{units.get(x, '')}]")
    ax.set_ylabel(f"{y} [{units.get(y, '')}]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    ax.set_title(title)
    return fig


def plot_occupant_tradeoff(points: Sequence, *, worst_goal: float = 1.5,
                           nominal_goal: float = 1.3, u_actuator: float = 1500.0,
                           x1_bound: float = 0.08, title: str = "") -> Figure:
    """What the force bound costs a controller for every seat of a set (issue 38): left,
    the worst and the nominal seat's peak ``|z̈3|`` over their own limits against the
    largest commanded force found over the set, with the goals; then that force and the
    stroke found by search and on the samples, against the design's force bound.

    Parameters
    ----------
    points : sequence of OccupantTradeoffPoint
        From :func:`~lmi_suspension.seat.multimodel.load_occupant_tradeoff` (anything
        with ``u_bound``, ``worst_ratio``, ``nominal_ratio``, ``u_samples``,
        ``u_searched``, ``x1_samples`` and ``x1_searched``).
    worst_goal, nominal_goal : float
        The goals, as multiples of each seat's own limit.
    u_actuator, x1_bound : float
        The actuator's force limit (N) and the stroke's bound (m).
    title : str
        The figure's title.

    Returns
    -------
    matplotlib.figure.Figure
        Three panels, one point per design on each line.

    Examples
    --------
    >>> from types import SimpleNamespace as P
    >>> pts = [P(u_bound=1500.0, worst_ratio=2.9, nominal_ratio=2.3, u_samples=1463.0,
    ...          u_searched=1497.0, x1_samples=0.064, x1_searched=0.073),
    ...        P(u_bound=2000.0, worst_ratio=1.8, nominal_ratio=1.4, u_samples=2036.0,
    ...          u_searched=2200.0, x1_samples=0.078, x1_searched=0.079)]
    >>> fig = plot_occupant_tradeoff(pts)
    >>> [len(ax.lines) for ax in fig.axes]
    [5, 4, 3]
    """
    pts = sorted(points, key=lambda p: p.u_bound)
    bound = np.array([p.u_bound for p in pts])
    searched = np.array([p.u_searched for p in pts])
    fig = Figure(figsize=(13, 4), layout="constrained")
    a1, a2, a3 = fig.subplots(1, 3, width_ratios=(1.4, 1, 1))
    a1.plot(searched, [p.worst_ratio for p in pts], "o-", color="C0",
            label="worst seat of the samples, 0–25 ms")
    a1.plot(searched, [p.nominal_ratio for p in pts], "s-", color="C2",
            label="nominal seat, 0–25 ms")
    for p, x, y in zip(pts, searched, [p.worst_ratio for p in pts]):
        a1.annotate(f"bound {p.u_bound:g} N", (x, y), textcoords="offset points",
                    xytext=(4, 4), fontsize=8)
    a1.axhline(worst_goal, color="C0", ls="--", lw=1, label=f"goal at worst {worst_goal:g} ×")
    a1.axhline(nominal_goal, color="C2", ls="--", lw=1,
               label=f"goal at the nominal seat {nominal_goal:g} ×")
    a1.axvline(u_actuator, color="C3", ls=":", label=f"actuator {u_actuator:g} N")
    a1.set_xlabel("largest commanded $|u|$ found over the set (search) [N]")
    a1.set_ylabel("peak $|\\ddot z_3|$ / that seat's own limit")
    a1.set_ylim(1.0, 1.1 * max(max(p.worst_ratio for p in pts), worst_goal))
    a1.legend(fontsize=8)
    a2.plot(bound, searched, "o-", color="C3", label="largest $|u|$ found by search")
    a2.plot(bound, [p.u_samples for p in pts], "o--", mfc="none", color="C3",
            label="largest $|u|$ on the samples")
    a2.plot(bound, bound, color="k", lw=1, label="bound")
    a2.axhline(u_actuator, color="C3", ls=":", lw=1, label=f"actuator {u_actuator:g} N")
    a2.set_ylabel("force [N]")
    a3.plot(bound, [p.x1_searched for p in pts], "^-", color="C4",
            label="largest $|x_1|$ found by search")
    a3.plot(bound, [p.x1_samples for p in pts], "^--", mfc="none", color="C4",
            label="largest $|x_1|$ on the samples")
    a3.axhline(x1_bound, color="k", lw=1, label=f"stroke bound {x1_bound:g} m")
    a3.set_ylim(0, 1.15 * x1_bound)
    a3.set_ylabel("stroke $|x_1|$ [m]")
    for ax in (a2, a3):
        ax.set_xlabel("force bound of the design (at its seats) [N]")
        ax.legend(fontsize=8, loc="lower right")
    for ax in (a1, a2, a3):
        ax.grid(True, alpha=0.3)
    fig.suptitle(title)
    return fig


def plot_occupant_maps(panels: Sequence[Mapping], *, box=None, title: str = "") -> Figure:
    """Controllers side by side over occupant mass × seat spring, on one colour scale.

    Parameters
    ----------
    panels : sequence of mapping
        One per controller: ``title``; ``m3`` and ``k1``, the grid's values (kg, N/m);
        ``ratio``, a ``len(k1) × len(m3)`` array of each cell's worst peak ``|z̈3|`` over
        its own limit (nan where there is none); ``stable``, a boolean array of the same
        shape (unstable cells are hatched, the boundary drawn in red); ``worst``,
        ``(m3, k1)`` of the worst cell of the set, or None.
    box : ((float, float), (float, float)), optional
        The set's ``m3`` and ``k1`` ranges, drawn on every panel.
    title : str

    Returns
    -------
    matplotlib.figure.Figure
        One panel per controller and one colour bar: the colour scale is the same on
        every panel (from the smallest stable ratio of all panels to the 98th percentile
        of all), so a colour means one ratio wherever it is.

    Examples
    --------
    >>> grid = dict(m3=[30.0, 70.0], k1=[20000.0, 31000.0])
    >>> a = dict(grid, title="a", ratio=np.array([[2.0, 3.0], [1.5, 2.5]]),
    ...          stable=np.array([[False, True], [True, True]]), worst=(70.0, 31000.0))
    >>> b = dict(grid, title="b", ratio=np.array([[1.2, 1.4], [1.1, 1.3]]),
    ...          stable=np.ones((2, 2), bool), worst=None)
    >>> fig = plot_occupant_maps([a, b], box=((30.0, 70.0), (24800.0, 37200.0)))
    >>> [ax.get_title() for ax in fig.axes[:2]], fig.axes[0].collections[0].norm.vmin
    (['a', 'b'], 1.1)
    """
    from matplotlib.colors import Normalize
    from matplotlib.patches import Rectangle

    from ..sweep.plots import draw_unstable

    if not panels:
        raise ValueError("no panels to draw")
    shown = [np.where(np.asarray(p["stable"], bool), np.asarray(p["ratio"], float), np.nan)
             for p in panels]
    finite = np.concatenate([v[np.isfinite(v)] for v in shown])
    norm = Normalize(vmin=float(finite.min()) if finite.size else 0.0,
                     vmax=float(np.percentile(finite, 98)) if finite.size else 1.0)
    fig = Figure(figsize=(5.6 * len(panels) + 1.0, 5.3), layout="constrained")
    axes = fig.subplots(1, len(panels), sharey=True, squeeze=False)[0]
    mesh = None
    for ax, p, z in zip(axes, panels, shown):
        xs, ys = np.asarray(p["m3"], float), np.asarray(p["k1"], float)
        stable = np.asarray(p["stable"], bool)
        mesh = ax.pcolormesh(xs, ys, z, shading="nearest", cmap="viridis", norm=norm)
        draw_unstable(ax, xs, ys, stable)
        if box is not None:
            (m_lo, m_hi), (k_lo, k_hi) = box
            ax.add_patch(Rectangle((m_lo, k_lo), m_hi - m_lo, k_hi - k_lo, fill=False,
                                   ec="white", ls="--", lw=1.5,
                                   label=f"the set ({m_lo:g}-{m_hi:g} kg, "
                                         f"{k_lo:.0f}-{k_hi:.0f} N/m)"))
        if p.get("worst") is not None:
            ax.plot(*p["worst"], "o", ms=14, mfc="none", mec="r", label="worst in the set")
        finite_p = z[np.isfinite(z)]
        if finite_p.size:
            # each cell's number: the map is small, and the comparison is the point
            for i, k1 in enumerate(ys):
                for j, m3 in enumerate(xs):
                    if np.isfinite(z[i, j]):
                        ax.text(m3, k1, f"{z[i, j]:.2f}", ha="center", va="center",
                                fontsize=7, color="w" if norm(z[i, j]) < 0.6 else "k")
        ax.set_title(p["title"], fontsize=10)
        ax.set_xlabel("upper-body mass m3 [kg]")
        # below the panel: inside it would hide the numbers of its corner cells
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize=7, ncol=2,
                  frameon=False)
    axes[0].set_ylabel("seat spring k1 [N/m]")
    fig.colorbar(mesh, ax=list(axes), label="worst peak |z3''| / own limit (stable cells)")
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def plot_ratio_over_mass(curves: Sequence, *, per_mass: str | None = None,
                         within: float = 1.2, title: str = "") -> Figure:
    """Peak ``|z̈3|`` over each seat's own limit against the occupant's mass, one line per
    controller (:func:`~lmi_suspension.seat.schedule_use.ratio_over_mass`'s curves).

    Parameters
    ----------
    curves : sequence of MassRatioCurve
        Anything with ``label``, ``m3`` and ``ratio`` (inf: unstable, drawn as a cross at
        the top of the axes).
    per_mass : str, optional
        The label of the curve of controllers each tuned for exactly its mass: drawn as
        points, with ``within`` times it as a dashed band (issue 62's target: a scheduled
        controller within 1.2 × of it).
    within : float
    title : str

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> from types import SimpleNamespace as C
    >>> fig = plot_ratio_over_mass([C(label="a", m3=(30.0, 50.0, 70.0), ratio=(2.0, 2.4, 2.2)),
    ...                             C(label="b", m3=(30.0, 50.0, 70.0), ratio=(1.5, np.inf, 1.3)),
    ...                             C(label="tuned", m3=(43.3,), ratio=(1.4,))],
    ...                            per_mass="tuned")
    >>> len(fig.axes[0].lines)      # a, b, b's unstable mass, tuned, 1.2 × tuned, the limit
    6
    """
    fig = Figure(figsize=(7.2, 4.6), layout="constrained")
    ax = fig.subplots()
    finite = [r * (within if c.label == per_mass else 1.0) for c in curves for r in c.ratio
              if np.isfinite(r)]
    top = 1.1 * max(finite) if finite else 2.0
    for k, c in enumerate(curves):
        m, r = np.asarray(c.m3, float), np.asarray(c.ratio, float)
        color = f"C{k}"
        if c.label == per_mass:
            ax.plot(m, r, "*", ms=14, color=color, label=c.label)
            ax.plot(m, within * r, "_", ms=24, mew=2, color=color,
                    label=f"{within:g} × that (the target for a scheduled controller)")
            continue
        ok = np.isfinite(r)
        ax.plot(m, np.where(ok, r, np.nan), "o-", color=color, label=c.label)
        if not ok.all():
            ax.plot(m[~ok], np.full((~ok).sum(), top), "x", ms=10, color=color,
                    label=f"{c.label}: unstable")
    ax.axhline(1.0, color="k", lw=0.8, ls=":", label="the seat's own limit")
    ax.set_xlabel("upper-body mass m3 [kg] (every other parameter Table 1's)")
    ax.set_ylabel("worst peak $|\\ddot z_3|$ over delays / own limit")
    ax.set_ylim(0.9, top * 1.05)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title, fontsize=10)
    return fig
