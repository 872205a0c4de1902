"""Figures of a sweep: a map over two grid axes with its stability boundary, and the
comfort-against-stroke trade-off of every case."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .spec import SweepSpec

__all__ = ["draw_unstable", "plot_map", "plot_tradeoff", "write_figures"]

_LABELS = {"m3": "upper-body mass m3 [kg]", "delay": "actuator delay [ms]",
           "k1": "seat spring k1 [N/m]", "speed_kmh": "speed [km/h]",
           "height": "bump height [m]", "length": "bump length [m]",
           "limit_ratio": "peak |z3''| / physical limit", "peak_z3dd": "peak |z3''| [m/s²]",
           "wrms_z3dd": "Wk-weighted RMS z3'' [m/s²]", "peak_x1": "peak |x1| [m]"}
#: axes shown in milliseconds
_MS = {"delay"}


def _label(name: str) -> str:
    return _LABELS.get(name, name)


def _columns(table) -> dict:
    return {name: table.column(name).to_numpy(zero_copy_only=False)
            for name in table.column_names}


def draw_unstable(ax, xs, ys, stable) -> bool:
    """Hatch a map's unstable cells and draw the stability boundary in red (with its
    legend entry); returns whether any cell is unstable.

    ``stable`` is a ``len(ys) × len(xs)`` boolean array over the cells centred at
    ``xs``, ``ys``.
    """
    stable = np.asarray(stable, bool)
    if stable.all():
        return False
    ax.pcolor(xs, ys, np.where(stable, np.nan, 1.0), shading="nearest", hatch="//",
              cmap="Greys", vmin=0, vmax=3, alpha=0.6)
    if stable.any():
        ax.contour(xs, ys, stable.astype(float), levels=[0.5], colors="red", linewidths=2.0)
    ax.plot([], [], color="red", lw=2, label="stability boundary (hatched: unstable)")
    return True


def plot_map(table, spec: SweepSpec, controller: str, value: str | None = None):
    """Heat map of ``value`` (default ``limit_ratio`` where computed, else ``peak_z3dd``)
    over the first two grid axes with more than one value, for one controller; unstable
    cells (exact-delay Nyquist test, or a simulation that diverged) are hatched and the
    stability boundary drawn.  Other
    axes are reduced to their worst case (largest value, unstable if any is).  Returns the
    figure, or None where the grid has fewer than two such axes."""
    import matplotlib.pyplot as plt

    axes = [(n, v) for n, v in spec.grid if len(v) > 1][:2]
    if len(axes) < 2:
        return None
    cols = _columns(table)
    if value is None:
        value = "limit_ratio" if np.any(np.isfinite(
            cols["limit_ratio"].astype(float))) else "peak_z3dd"
    (xn, xv), (yn, yv) = axes
    Z = np.full((len(yv), len(xv)), np.nan)
    stable = np.ones((len(yv), len(xv)), dtype=bool)
    pick = cols["controller"] == controller
    vals = cols[value].astype(float)
    st, st_sim = cols["stable"], cols["stable_sim"]
    # nearest grid value: a delay is rounded to the simulation step in its case
    xi = np.abs(cols[xn].astype(float)[:, None] - np.asarray(xv)[None, :]).argmin(axis=1)
    yi = np.abs(cols[yn].astype(float)[:, None] - np.asarray(yv)[None, :]).argmin(axis=1)
    for k in np.flatnonzero(pick):
        i, j = yi[k], xi[k]
        if st[k] is None or not st[k] or st_sim[k] is False:
            stable[i, j] = False
        if np.isfinite(vals[k]):
            Z[i, j] = vals[k] if np.isnan(Z[i, j]) else max(Z[i, j], vals[k])
    xs = np.asarray(xv) * (1e3 if xn in _MS else 1.0)
    ys = np.asarray(yv) * (1e3 if yn in _MS else 1.0)
    fig, ax = plt.subplots(figsize=(7.0, 4.8), constrained_layout=True)
    shown = np.where(stable, Z, np.nan)
    finite = shown[np.isfinite(shown)]
    vmax = np.percentile(finite, 98) if finite.size else 1.0
    mesh = ax.pcolormesh(xs, ys, shown, shading="nearest", cmap="viridis",
                         vmin=np.nanmin(finite) if finite.size else 0.0, vmax=vmax)
    fig.colorbar(mesh, ax=ax, label=_label(value) + " (stable cases)")
    if draw_unstable(ax, xs, ys, stable):
        ax.legend(loc="upper left", fontsize=8)
    ax.set_xlabel(_label(xn))
    ax.set_ylabel(_label(yn))
    name = Path(controller).stem if controller != "passive" else "passive"
    ax.set_title(f"{name}: {_label(value)} ({spec.road})", fontsize=10)
    return fig


def plot_tradeoff(table, spec: SweepSpec):
    """Peak upper-body acceleration against peak suspension stroke, one point per stable
    case, coloured by the first varied axis; one marker per controller."""
    import matplotlib.pyplot as plt

    cols = _columns(table)
    fig, ax = plt.subplots(figsize=(6.4, 4.6), constrained_layout=True)
    color_axis = next((n for n in spec.axis_names if len(set(cols[n].tolist())) > 1), None)
    markers = "o^sDv<>"
    ok = np.array([bool(s) for s in cols["stable"]]) & np.array(
        [e is None for e in cols["error"]])
    sc = None
    for k, ctrl in enumerate(dict.fromkeys(cols["controller"].tolist())):
        sel = ok & (cols["controller"] == ctrl)
        c = None if color_axis is None else cols[color_axis][sel].astype(float) * (
            1e3 if color_axis in _MS else 1.0)
        name = Path(ctrl).stem if ctrl != "passive" else "passive"
        sc = ax.scatter(cols["peak_x1"][sel].astype(float) * 1e3,
                        cols["peak_z3dd"][sel].astype(float), c=c, s=14,
                        marker=markers[k % len(markers)], label=name,
                        **({} if c is None else {"cmap": "plasma"}))
    ax.axvline(_z_max(spec) * 1e3, color="grey", ls="--", lw=1, label="stroke limit z_max")
    if color_axis is not None and sc is not None and ok.any():
        fig.colorbar(sc, ax=ax, label=_label(color_axis))
    ax.set_xlabel("peak |x1| [mm]")
    ax.set_ylabel(_label("peak_z3dd"))
    ax.set_title(f"comfort against stroke, {int(ok.sum())} stable cases ({spec.road})",
                 fontsize=10)
    ax.legend(fontsize=8)
    return fig


def _z_max(spec: SweepSpec) -> float:
    """The stroke limit of the sweep (the largest, where it is an axis)."""
    from ..seat import SeatParameters

    for n, v in spec.grid:
        if n == "z_max":
            return float(max(v))
    return SeatParameters().z_max


def write_figures(path, spec: SweepSpec, out) -> list[Path]:
    """Write ``map-<controller>.png`` for every controller (where the grid has two varied
    axes) and ``tradeoff.png`` into ``out``; return the paths."""
    import matplotlib.pyplot as plt
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    out = Path(out)
    written = []
    for ctrl in spec.controllers:
        fig = plot_map(table, spec, ctrl)
        if fig is None:
            break
        name = Path(ctrl).stem if ctrl != "passive" else "passive"
        p = out / f"map-{name}.png"
        fig.savefig(p, dpi=110)
        plt.close(fig)
        written.append(p)
    fig = plot_tradeoff(table, spec)
    p = out / "tradeoff.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    written.append(p)
    return written
