"""Figures of the paper (Figs. 7–15) and the delay study, drawn with matplotlib.

Every function takes already-computed results and returns a :class:`matplotlib.figure.Figure`;
nothing here runs a simulation or a solver, and nothing calls ``plt.show()``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure

__all__ = ["plot_mu_bounds", "plot_peak_vs_delay", "plot_responses", "plot_road"]

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
    if limit is not None:
        for sign in (1, -1):
            ax.axhline(sign * limit, color="r", ls=":", lw=1,
                       label=f"limit ±{limit:g} {unit}" if sign > 0 else None)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"{name} [{unit}]")
    if t_max is not None:
        ax.set_xlim(0, t_max)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    ax.set_title(title)
    return fig


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
