"""The seat with its force and stroke limits imposed exactly: H∞ comfort with
generalized-H2 (energy-to-peak) bounds, by multi-objective LMI synthesis.

The paper states ``|u(t)| <= u_max = 1500 N`` (eq. 12) and ``|x1(t)| <= z_max = 0.08 m``
(eq. 13) and approximates them with output weights.  Here they are hard constraints for
every floor velocity of a given energy (Wilson, IEEE TAC 34(1), 1989): for
``‖w‖₂ <= E``, ``sup_t |z_i(t)| <= E · sqrt((C Wc Cᵀ)_ii)`` on the closed loop, ``Wc`` its
controllability Gramian.  With ``E`` the energy of the paper's bump velocity, the linear
closed loop meets both limits on the bump (and on every floor velocity of no more
energy), without clipping -- the approach of the suspension literature the paper cites
(Gao et al. 2006; Du and Zhang 2007).

Generalized plant (:func:`seat_peak_plant`), no delay, state feedback through the two
measured deflections::

    w = [z0' (m/s), n1, n2]          y = [x1 + eps n1, x3 + eps n2]
    z = [z3'', rho u, u, x1]

The H∞ objective is the channel ``w -> [z3'', rho u]``; the bounds act on the road
column alone (``u`` and ``x1`` rows).  ``rho`` and ``eps`` make the H∞ problem regular
(a small control penalty, measurement noise); they are not limits.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import control
import numpy as np

from ..errors import InfeasibleError, ParameterError
from ..lti.plant import GeneralizedPlant
from ..synthesis.constraints import Channel, HinfBound, PeakBound
from ..synthesis.multiobjective import MultiobjectiveResult, msyn
from .model import seat_matrices
from .params import SeatParameters
from .roads import RoadInput, bump, road_energy
from .simulate import SimulationResult, simulate

__all__ = ["PeakBoundedDesign", "seat_peak_plant", "design_peak_bounded",
           "force_tradeoff", "PeakBoundedRoute"]

#: control penalty (per N) and measurement noise (m per unit of w) that regularise the H∞
#: problem. Measured 2026-11-26 (certified H∞, fastest controller pole): at 1e-2 each,
#: 23.15 and 1.1e4 rad/s without bounds, 28.64 and 1.6e3 rad/s at 1500 N / 0.08 m; at
#: 1e-3 each, 5.81 (needing 48 kN for the worst road of the bump's energy) and 22.91 at
#: 1500 N / 0.08 m.  1e-2 keeps the unbounded design's force within 4x of the limit, so
#: that the trade-off starts from a controller a seat could carry.
_RHO = 1e-2
_EPS = 1e-2

#: the performance outputs of :func:`seat_peak_plant`
Z3DD, RHO_U, U, X1 = range(4)


def seat_peak_plant(params: SeatParameters | None = None) -> GeneralizedPlant:
    """The generalized plant of the peak-bounded design (see the module docstring).

    Examples
    --------
    >>> P = seat_peak_plant()
    >>> (P.nw, P.nu, P.nz, P.ny)
    (3, 1, 4, 2)
    """
    M = seat_matrices(params)
    n = M.A.shape[0]
    B1 = np.hstack([M.Bw.reshape(n, 1), np.zeros((n, 2))])
    C1 = np.vstack([M.C1, np.zeros((2, n)), M.C2])
    D12 = np.array([[0.0], [_RHO], [1.0], [0.0]])
    D21 = np.hstack([np.zeros((2, 1)), _EPS * np.eye(2)])
    return GeneralizedPlant.from_matrices(A=M.A, B1=B1, B2=M.B.reshape(n, 1), C1=C1,
                                          C2=M.C3, D12=D12, D21=D21)


@dataclass(frozen=True)
class PeakBoundedDesign:
    """A controller of :func:`design_peak_bounded` and its certificates.

    Attributes
    ----------
    K : control.StateSpace
        From ``y = [x1, x3]`` (m) to ``u`` (N), sign as in eq. (1).
    hinf : float
        Certified ``‖w -> [z3'', rho u]‖∞`` of the closed loop (``hinfnorm``).
    hinf_lmi : float
        The level the LMIs guarantee (≥ ``hinf``).
    u_max, z_max, energy : float
        The bounds asked for and the floor-velocity energy they hold for.
    u_peak, x1_peak : float
        The worst-case peaks over every floor velocity with ``‖w‖₂ <= energy``, from the
        closed loop's Gramian alone (``<= u_max``, ``<= z_max``).
    result : MultiobjectiveResult
        The synthesis (its ``certificates``, ``lyapunov_scales``, ``warnings``).
    """

    K: control.StateSpace
    hinf: float
    hinf_lmi: float
    u_max: float
    z_max: float
    energy: float
    u_peak: float
    x1_peak: float
    result: MultiobjectiveResult

    def simulate(self, road: RoadInput | None = None, **kwargs) -> SimulationResult:
        """The linear closed loop on ``road`` (the bump by default): no delay, no
        clipping unless ``u_max=`` is passed."""
        kwargs.setdefault("u_max", np.inf)
        return simulate(self.K, bump() if road is None else road, **kwargs)


def design_peak_bounded(u_max: float = 1500.0, z_max: float = 0.08, *,
                        energy: float | None = None, params: SeatParameters | None = None,
                        lyapunov_scales=None) -> PeakBoundedDesign:
    """H∞ comfort with hard force and stroke bounds for every floor velocity of energy
    ``energy`` (the paper's bump, 0.4534, by default).

    Parameters
    ----------
    u_max : float
        Force bound, N (``numpy.inf``: none).
    z_max : float
        Stroke bound on ``|x1|``, m (``numpy.inf``: none).
    energy : float, optional
        ``‖w‖₂`` the bounds hold for; :func:`road_energy` of :func:`bump` by default.
    params : SeatParameters, optional
    lyapunov_scales : sequence of float, optional
        Passed to :func:`~lmi_suspension.synthesis.msyn` (one per bound asked for).

    Returns
    -------
    PeakBoundedDesign

    Raises
    ------
    InfeasibleError
        No controller meets the bounds with a common Lyapunov matrix.

    Examples
    --------
    >>> d = design_peak_bounded(1500.0, 0.08)
    >>> bool(d.u_peak <= 1500.0 * 1.005 and d.x1_peak <= 0.08 * 1.005)
    True
    """
    E = road_energy(bump()) if energy is None else float(energy)
    if not (np.isfinite(E) and E > 0):
        raise ParameterError(f"energy must be positive and finite, got {energy!r}")
    for name, b in (("u_max", u_max), ("z_max", z_max)):
        if not b > 0:
            raise ParameterError(f"{name} must be positive, got {b!r}")
    P = seat_peak_plant(params)
    rows = [(U, float(u_max)), (X1, float(z_max))]
    rows = [(r, b) for r, b in rows if np.isfinite(b)]
    constraints = []
    if rows:
        # one specification for both rows: they are driven by the same floor velocity
        constraints.append(PeakBound(Channel(outputs=tuple(r for r, _ in rows), inputs=(0,)),
                                     tuple(b / E for _, b in rows), name="peak u, x1"))
    try:
        res = msyn(P, 2, 1, HinfBound(Channel(outputs=(Z3DD, RHO_U))), constraints,
                   lyapunov_scales=lyapunov_scales)
    except InfeasibleError as exc:
        raise InfeasibleError(f"no controller keeps |u| <= {u_max:g} N and |x1| <= "
                              f"{z_max:g} m for every floor velocity of energy {E:.4g} "
                              f"(with a common Lyapunov matrix): {exc}") from exc
    peaks = PeakBound(Channel(outputs=(U, X1), inputs=(0,)), (1.0, 1.0)).peaks(res.CL) * E
    K = control.ss(res.K.A, res.K.B, res.K.C, res.K.D, inputs=["x1", "x3"], outputs=["u"],
                   name="K_peak")
    return PeakBoundedDesign(K=K, hinf=res.objective, hinf_lmi=res.objective_lmi,
                             u_max=float(u_max), z_max=float(z_max), energy=E,
                             u_peak=float(peaks[0]), x1_peak=float(peaks[1]), result=res)


def force_tradeoff(u_bounds, z_max: float = 0.08, *, energy: float | None = None,
                   params: SeatParameters | None = None) -> list[PeakBoundedDesign]:
    """:func:`design_peak_bounded` for each force bound (the trade-off of issue 16);
    ``numpy.inf`` in ``u_bounds`` gives the design with the stroke bound alone."""
    return [design_peak_bounded(u, z_max, energy=energy, params=params) for u in u_bounds]


@dataclass(frozen=True)
class PeakBoundedRoute:
    """H∞ comfort with hard force and stroke bounds by multi-objective LMIs
    (:func:`design_peak_bounded`; no delay in the design) as a
    :class:`~.routes.SeatRoute`.

    Examples
    --------
    >>> PeakBoundedRoute().name
    'peak_bounded'
    """

    name: ClassVar[str] = "peak_bounded"
    u_max: float = 1500.0
    z_max: float = 0.08

    def design(self, params: SeatParameters, *, rng=None, progress=None):
        """:func:`design_peak_bounded` at ``params`` (nothing random, no iterations to
        report), as a :class:`~.record.SeatDesign`."""
        import time

        from .record import seat_design_from

        t0 = time.perf_counter()
        d = design_peak_bounded(self.u_max, self.z_max, params=params)
        return seat_design_from(
            self.name, d.K, params=params, weights=None, seconds=time.perf_counter() - t0,
            detail=d,
            description=(f"H∞ seat controller with |u| <= {d.u_max:g} N and |x1| <= "
                         f"{d.z_max:g} m for every floor velocity of the bump's energy "
                         f"(no delay): y = [x1, x3] (m) -> u (N)"),
            figures={"hinf": d.hinf, "hinf_lmi": d.hinf_lmi, "u_max": d.u_max,
                     "z_max": d.z_max, "energy": d.energy, "u_peak": d.u_peak,
                     "x1_peak": d.x1_peak})
