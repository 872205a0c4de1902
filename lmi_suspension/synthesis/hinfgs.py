"""Polytopic gain-scheduled H∞ synthesis (:func:`hinfgs`, Apkarian, Gahinet & Becker 1995;
MATLAB's ``hinfgs``).

The plant is affine in the parameter vector ``p``, which ranges over a box, and its
control and measurement data ``B2``, ``C2``, ``D12``, ``D21`` (and ``D22``) do not depend
on ``p``.  Then the closed loop's matrices are affine in the plant's vertex data and in
the controller's matrices jointly, and one pair ``(R, S)`` satisfying the projected
bounded-real LMIs at every vertex of the box gives a controller at each vertex whose
convex combination ``K(p) = Σ α_v(p) K_v`` (``α`` the multilinear coordinates of ``p`` in
the box) keeps the closed loop's bounded-real inequality, with **one** Lyapunov matrix,
everywhere in the box: the bound holds for parameters varying arbitrarily fast.  The
vertex controllers are formed from the common ``(R, S)`` in one balanced frame (so in
the same state coordinates) by :func:`~lmi_suspension.synthesis.lmi.decoupled_controller`
and certified, as :func:`~lmi_suspension.lpv.lpvsyn`'s, by ``hinfnorm`` on a grid four
times denser than the vertices' and by the closed loop's inequality with that matrix.

Where ``B2``, ``C2``, ``D12`` or ``D21`` depend on ``p`` the method does not apply
(:class:`~lmi_suspension.errors.AssumptionError`); the standard workaround filters the
control input (and/or the measurement) through a fixed low-pass filter whose states are
appended to the plant, which moves the parameter dependence into ``A`` — or use the
gridded :func:`~lmi_suspension.lpv.lpvsyn`, which has no such requirement.

Reference: P. Apkarian, P. Gahinet, G. Becker, "Self-scheduled H∞ control of linear
parameter-varying systems: a design example", Automatica 31(9) (1995) 1251-1261.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass

import control
import numpy as np

from ..errors import AssumptionError, DimensionError, InputError, ParameterError
from ..lti.checks import finite_scalar
from ..lti.norms import hinfnorm
from ..lti.plant import lft
from ..lti.scaling import PlantScaling, scale_plant
from . import lmi as _lmi
from .hinfsyn import _undo_loop_shift, _without_d22
from .lpv import _apply_scaling, _axes, _check_axes, _floats, _gamma_lmi, _plant_at
from .result import HinfsynOptions

__all__ = ["HinfgsResult", "PolytopicController", "hinfgs"]

#: relative tolerance of the affinity check (the plant at the box's centre and at each
#: vertex against the affine model fitted to the centre and one step per parameter) and
#: of the constancy of B2, C2, D12, D21, D22 across the vertices
_AFFINE_RTOL = 1e-9


@dataclass(frozen=True)
class PolytopicController:
    """``K(p) = Σ_v α_v(p) K_v``, the vertex controllers' matrices combined with the
    multilinear coordinates ``α(p)`` of ``p`` in the box.

    Attributes
    ----------
    names : tuple of str
    bounds : tuple of (float, float)
    vertices : tuple of tuple
        The box's corners, in the order of :func:`itertools.product` over the bounds.
    controllers : tuple of control.StateSpace
        ``K_v`` at each vertex, all in the same state coordinates.
    level : float
        The level (plant units) the vertex controllers were formed at.
    """

    names: tuple
    bounds: tuple
    vertices: tuple
    controllers: tuple
    level: float

    def weights(self, *args, **named) -> np.ndarray:
        """``α(p)``: nonnegative, summing to 1, ``p = Σ α_v v``."""
        if named:
            if args or set(named) != set(self.names):
                raise ParameterError(f"expected values of {self.names}, got {tuple(named)}")
            args = tuple(named[n] for n in self.names)
        if len(args) != len(self.names):
            raise ParameterError(f"expected {len(self.names)} values {self.names}")
        p = [finite_scalar(v, f"parameter {n}") for n, v in zip(self.names, args)]
        t = []
        for n, v, (lo, hi) in zip(self.names, p, self.bounds):
            tol = 1e-12 * max(1.0, abs(lo), abs(hi))
            if not lo - tol <= v <= hi + tol:
                raise ParameterError(f"{n} = {v:g} is outside [{lo:g}, {hi:g}]")
            t.append(min(max((v - lo) / (hi - lo), 0.0), 1.0))
        return np.array([np.prod([tk if c == hi else 1.0 - tk
                                  for tk, c, (_lo, hi) in zip(t, vert, self.bounds)])
                         for vert in self.vertices])

    def at(self, *args, **named) -> control.StateSpace:
        """The controller at one parameter value."""
        a = self.weights(*args, **named)
        mats = [sum(ai * np.asarray(getattr(K, M), dtype=float)
                    for ai, K in zip(a, self.controllers)) for M in "ABCD"]
        return control.ss(*mats)

    def to_dict(self) -> dict:
        """JSON-ready description: the box, the vertices and each vertex controller's
        matrices, every float a Python float (which :mod:`json` writes as its shortest
        round-tripping repr), so that :meth:`from_dict` gives back the same IEEE-754
        numbers and ``at(p)`` of the loaded controller equals the original's bit for bit
        at every ``p``, not only at the vertices (it is computed from those numbers
        alone)."""
        return {
            "names": list(self.names),
            "bounds": [[float(lo), float(hi)] for lo, hi in self.bounds],
            "vertices": [[float(v) for v in vert] for vert in self.vertices],
            "level": float(self.level),
            "controllers": [{"shape": [int(K.nstates), int(K.ninputs), int(K.noutputs)],
                             **{M: _floats(getattr(K, M)) for M in "ABCD"}}
                            for K in self.controllers],
        }

    @classmethod
    def from_dict(cls, data: dict) -> PolytopicController:
        """The controller described by :meth:`to_dict` (exactly)."""
        try:
            names = tuple(str(n) for n in data["names"])
            bounds = tuple((float(lo), float(hi)) for lo, hi in data["bounds"])
            vertices = tuple(tuple(float(v) for v in vert) for vert in data["vertices"])
            if len(bounds) != len(names) or any(len(v) != len(names) for v in vertices):
                raise DimensionError("the bounds and vertices do not match the "
                                     f"{len(names)} parameters {names}")
            if len(data["controllers"]) != len(vertices):
                raise DimensionError(f"{len(data['controllers'])} vertex controllers for "
                                     f"{len(vertices)} vertices")
            controllers = []
            for K in data["controllers"]:
                n, ny, nu = (int(v) for v in K["shape"])
                mats = [np.asarray(K[M], dtype=float).reshape(shape) for M, shape in
                        zip("ABCD", ((n, n), (n, ny), (nu, n), (nu, ny)))]
                controllers.append(control.ss(*mats))
            return cls(names, bounds, vertices, tuple(controllers), float(data["level"]))
        except KeyError as exc:
            raise InputError(f"polytopic controller description lacks key {exc}") from exc
        except (TypeError, ValueError) as exc:
            raise InputError(f"malformed polytopic controller description: {exc}") from exc


@dataclass(frozen=True)
class HinfgsResult:
    """Result of :func:`hinfgs`.

    Attributes
    ----------
    K : PolytopicController
    gamma : float
        The largest ``hinfnorm(lft(P(p), K(p)))`` over ``check_grid``.
    gamma_lmi : float
        The vertex LMIs' optimum (plant units).
    check_grid : dict
    gamma_check : numpy.ndarray
    lyapunov_check : numpy.ndarray
        At each check point, the largest eigenvalue (relative to the level) of the closed
        loop's bounded-real inequality with the one Lyapunov matrix of the design
        (negative: the bound holds there for any rate of variation).
    warnings : tuple of str
    seconds : float
    """

    K: PolytopicController
    gamma: float
    gamma_lmi: float
    check_grid: dict
    gamma_check: np.ndarray
    lyapunov_check: np.ndarray
    warnings: tuple
    seconds: float


def _check_polytopic(plant, names, bounds, nmeas, ncon):
    """The vertex plants, after checking affinity in ``p`` and constant B2, C2, D12,
    D21, D22 (typed errors naming the violation)."""
    vertices = list(itertools.product(*bounds))
    first = _plant_at(plant, vertices[0], nmeas, ncon)
    shape = (first.nstates, first.sys.ninputs, first.sys.noutputs)
    Gs = [first] + [_plant_at(plant, v, nmeas, ncon, shape) for v in vertices[1:]]
    ref = first.blocks()
    for key in ("B2", "C2", "D12", "D21", "D22"):
        for v, G in zip(vertices[1:], Gs[1:]):
            M = G.blocks()[key]
            scale = max(1.0, np.abs(ref[key]).max(initial=0.0))
            if M.size and np.abs(M - ref[key]).max() > _AFFINE_RTOL * scale:
                raise AssumptionError(
                    f"{key} depends on the parameters ({key} at {v} differs from {key} at "
                    f"{vertices[0]}): the polytopic method needs B2, C2, D12, D21 and D22 "
                    "constant. Filter the control input (or the measurement) through a "
                    "fixed low-pass filter appended to the plant, which moves the "
                    "dependence into A, or use lpvsyn on a grid")
    # affine: the model fitted to the centre and one step per parameter predicts every
    # vertex
    centre = tuple(0.5 * (lo + hi) for lo, hi in bounds)
    def mat(p):
        s = _plant_at(plant, p, nmeas, ncon, shape).sys
        return np.block([[s.A, s.B], [s.C, s.D]])
    M0 = mat(centre)
    slopes = []
    for k, (lo, hi) in enumerate(bounds):
        step = tuple(c + (0.25 * (hi - lo) if i == k else 0.0) for i, c in enumerate(centre))
        slopes.append((mat(step) - M0) / (0.25 * (hi - lo)))
    for v, G in zip(vertices, Gs):
        pred = M0 + sum((v[k] - centre[k]) * slopes[k] for k in range(len(bounds)))
        s = G.sys
        got = np.block([[s.A, s.B], [s.C, s.D]])
        if np.abs(got - pred).max() > _AFFINE_RTOL * max(1.0, np.abs(got).max()) * 1e3:
            raise AssumptionError(f"the plant is not affine in the parameters (at {v} it "
                                  "differs from the affine model through the centre): "
                                  "the polytopic method needs P(p) affine; use lpvsyn")
    return vertices, Gs, shape


def hinfgs(P, bounds: dict, nmeas: int, ncon: int, *, backoff: float = 2e-2,
           check_density: int = 4, options: HinfsynOptions | None = None) -> HinfgsResult:
    """Polytopic gain-scheduled H∞ synthesis (see the module docstring).

    Parameters
    ----------
    P : callable
        ``P(*p) -> control.StateSpace``, affine in ``p``, with ``B2``, ``C2``, ``D12``,
        ``D21``, ``D22`` constant.
    bounds : dict
        ``{name: (low, high)}``: the parameter box.
    nmeas, ncon : int
    backoff : float
        The vertex controllers are formed at ``(1 + backoff) γ_lmi``.
    check_density : int
        Pieces per parameter interval of the certificate's grid.
    options : HinfsynOptions, optional

    Returns
    -------
    HinfgsResult

    Raises
    ------
    AssumptionError
        ``B2``, ``C2``, ``D12``, ``D21`` or ``D22`` depends on ``p``, or ``P`` is not
        affine in ``p``.
    ParameterError, NonFiniteError, DimensionError
        A bad box (one value, non-finite, reversed), sizes changing with ``p``.

    Examples
    --------
    A mass-spring-damper whose stiffness ``k`` in [0.5, 2] is measured (``B2`` does not
    depend on it):

    >>> import control, numpy as np
    >>> def plant(k):
    ...     return control.ss([[0, 1], [-k, -0.2]], [[0, 0, 0], [1, 0, 1]],
    ...                       [[1, 0], [0, 0], [1, 0]], [[0, 0, 0], [0, 0, 0.1], [0, 0.1, 0]])
    >>> res = hinfgs(plant, {"k": (0.5, 2.0)}, 1, 1)
    >>> res.warnings, bool(np.all(res.lyapunov_check < 0))
    ((), True)
    >>> res.K.at(k=1.2).nstates
    2
    """
    t0 = time.perf_counter()
    opts = HinfsynOptions() if options is None else options
    if not isinstance(bounds, dict):
        raise ParameterError("bounds must be a dict {name: (low, high)}")
    box = {}
    for name, b in bounds.items():
        try:
            lo, hi = b
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"bounds[{name!r}] must be a pair (low, high)") from exc
        lo, hi = finite_scalar(lo, f"bounds[{name!r}][0]"), finite_scalar(hi, f"bounds[{name!r}][1]")
        if not lo < hi:
            raise ParameterError(f"bounds[{name!r}] = ({lo:g}, {hi:g}) is not an interval")
        box[name] = [lo, hi]
    names, axes = _axes(box)
    if any(a.size != 2 for a in axes):
        raise ParameterError("every parameter needs two distinct bounds")
    backoff = finite_scalar(backoff, "backoff")
    if backoff <= 0:
        raise ParameterError(f"backoff must be positive, got {backoff!r}")
    bnds = tuple((float(a[0]), float(a[1])) for a in axes)
    vertices, Gs, shape = _check_polytopic(P, names, bnds, nmeas, ncon)
    if not shape[0]:
        raise DimensionError("the plant has no states")
    mid = _without_d22(Gs[0])
    if opts.scale:
        _, sc = scale_plant(mid)
    else:
        sc = PlantScaling(np.ones(mid.nstates), np.ones(mid.nu), np.ones(mid.ny), 1.0, 1.0)
    plants = [_apply_scaling(_without_d22(G), sc) for G in Gs]
    warnings: list[str] = []
    F = np.ones((len(plants), 1))                   # one (R, S) for every vertex
    g_s, (R,), (S,), _status = _gamma_lmi(plants, F, opts, warnings)
    level_s = g_s * (1.0 + backoff)
    c = float(np.sqrt(1.0 + backoff))
    Ks = []
    for Ps, G in zip(plants, Gs):
        # one frame: the balancing of the common (R, S), the same at every vertex, so
        # the vertex controllers share their state coordinates
        K0, _cond = _lmi.decoupled_controller(Ps, c * R, c * S, level_s)
        Ks.append(_undo_loop_shift(sc.controller_to_original(K0), G.D22))
    K = PolytopicController(tuple(names), bnds, tuple(vertices), tuple(Ks),
                            level_s / sc.gamma_factor)
    # the closed loop's Lyapunov matrix: P Π1 = Π2 in the balanced frame, N = I
    T, sigma = _lmi.balancing_transform(c * R, c * S)
    n = R.shape[0]
    Xb = Yb = np.diag(sigma)
    I, Z = np.eye(n), np.zeros((n, n))
    Pi1 = np.block([[Yb, I], [I - Xb @ Yb, Z]])
    Pi2 = np.block([[I, Xb], [Z, I]])
    Pb = np.linalg.solve(Pi1.T, Pi2.T).T
    Ti = np.linalg.inv(T)
    J = np.block([[Ti, Z], [Z, I]])
    Pcl = _lmi._sym(J.T @ Pb @ J)                  # coordinates [x_s; x_K]
    check = _check_axes(axes, int(check_density))
    norms, lyap = [], []
    for p in itertools.product(*(a.tolist() for a in check)):
        Kp = K.at(*p)
        CL = lft(_plant_at(P, p, nmeas, ncon, shape), Kp)
        gam = float(hinfnorm(CL)[0])
        norms.append(gam)
        where = ", ".join(f"{nm}={v:.6g}" for nm, v in zip(names, p))
        if not np.isfinite(gam) or gam > K.level * (1.0 + 1e-6):
            warnings.append(f"at {where}: certified {gam:.6g} above the level {K.level:.6g}")
        Jp = np.diag(np.r_[sc.T, np.ones(CL.nstates - n)])
        A = np.linalg.solve(Jp, CL.A @ Jp)
        B = np.linalg.solve(Jp, CL.B) * sc.cw
        C, D = CL.C @ Jp / sc.cz, CL.D * sc.cw / sc.cz
        L = np.block([[A.T @ Pcl + Pcl @ A, Pcl @ B, C.T],
                      [B.T @ Pcl, -level_s * np.eye(B.shape[1]), D.T],
                      [C, D, -level_s * np.eye(C.shape[0])]])
        lyap.append(float(np.linalg.eigvalsh(_lmi._sym(L))[-1]) / level_s)
        if lyap[-1] >= 0.0:
            warnings.append(f"at {where}: the closed loop's bounded-real inequality with "
                            f"the common Lyapunov matrix fails ({lyap[-1]:.3g} γ)")
    return HinfgsResult(K=K, gamma=float(max(norms)), gamma_lmi=g_s / sc.gamma_factor,
                        check_grid=dict(zip(names, check)), gamma_check=np.asarray(norms),
                        lyapunov_check=np.asarray(lyap), warnings=tuple(warnings),
                        seconds=time.perf_counter() - t0)
