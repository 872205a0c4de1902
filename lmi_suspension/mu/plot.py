"""Plots of µ bounds and D scalings against frequency (rad/s)."""

from __future__ import annotations

import numpy as np

from ..errors import InputError

__all__ = ["plot_dscales", "plot_mu"]


def _axes(ax):
    if ax is None:
        # pyplot only to create a figure when the caller gave no axes; no show().
        import matplotlib.pyplot as plt

        _, ax = plt.subplots()
    return ax


def _omega(result):
    if result.omega is None or np.ndim(result.upper) == 0:
        raise InputError("plotting needs a frequency sweep: call mussv with a stack and omega")
    return np.asarray(result.omega)


def plot_mu(result, ax=None):
    """Plot µ upper and lower bounds against ω (log axis, rad/s), like the paper's Fig. 15.

    Parameters
    ----------
    result : MussvResult
        Result of :func:`~lmi_suspension.mu.mussv` over a frequency grid.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure is made if omitted).

    Returns
    -------
    matplotlib.axes.Axes

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> from lmi_suspension.mu import mussv, plot_mu
    >>> w = np.logspace(-1, 1, 5)
    >>> M = np.stack([np.diag([1 / (1j * x + 1), 0.5]) for x in w], axis=-1)
    >>> ax = plot_mu(mussv(M, [[1, 1], [1, 1]], omega=w))
    >>> ax.get_xscale()
    'log'
    """
    w = _omega(result)
    ax = _axes(ax)
    ax.semilogx(w, result.upper, "-", label="µ upper bound")
    ax.semilogx(w, result.lower, "--", label="µ lower bound")
    ax.set_xlabel("ω (rad/s)")
    ax.set_ylabel("µ")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return ax


def plot_dscales(result, ax=None):
    """Plot the per-block D-scale magnitudes ``d_blocks`` against ω (log-log, rad/s).

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> from lmi_suspension.mu import mussv, plot_dscales
    >>> w = np.logspace(-1, 1, 5)
    >>> M = np.stack([np.array([[0.5, 1 / (1j * x + 1)], [0.2, 0.5]]) for x in w], axis=-1)
    >>> ax = plot_dscales(mussv(M, [[1, 1], [1, 1]], omega=w))
    >>> len(ax.get_lines())
    2
    """
    w = _omega(result)
    ax = _axes(ax)
    for i, row in enumerate(np.atleast_2d(result.d_blocks)):
        ax.loglog(w, row, label=f"block {i + 1}")
    ax.set_xlabel("ω (rad/s)")
    ax.set_ylabel("|d|")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return ax
