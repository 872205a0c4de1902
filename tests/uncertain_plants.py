"""Test plants of tests/test_uncertain*.py: each is built twice, once from ``ureal``
atoms (the code under test) and once directly with numbers in numpy (the reference),
and brute-force margins / worst-case gains computed on grids of the parameter box."""

import control
import numpy as np

from lmi_suspension.uncertain import feedback, ureal, uss

# ---------------------------------------------------------------- plant 1: two-mass spring-damper
# m1 x1'' = -k1 x1 - c1 x1' - k (x1 - x2) - c (x1' - x2') + u ;  m2 x2'' = -k (x2 - x1) - c (x2' - x1')
M1, K1, C1, C = 1.0, 1.0, 0.1, 0.05
TWO_MASS = {"k": dict(nominal=2.0, plusminus=0.6), "m2": dict(nominal=0.5, percent=20)}


def two_mass_direct(k, m2):
    A = np.array([[0, 0, 1, 0], [0, 0, 0, 1],
                  [-(K1 + k) / M1, k / M1, -(C1 + C) / M1, C / M1],
                  [k / m2, -k / m2, C / m2, -C / m2]])
    B = np.array([[0], [0], [1 / M1], [0]])
    Cm = np.array([[0, 1.0, 0, 0]])
    return A, B, Cm, np.zeros((1, 1))


def two_mass_uncertain():
    k = ureal("k", **TWO_MASS["k"])
    m2 = ureal("m2", **TWO_MASS["m2"])
    A = [[0, 0, 1, 0], [0, 0, 0, 1],
         [-(K1 + k) / M1, k / M1, -(C1 + C) / M1, C / M1],
         [k / m2, -k / m2, C / m2, -C / m2]]
    return uss(A, [[0], [0], [1 / M1], [0]], [[0, 1, 0, 0]], [[0]])


# ---------------------------------------------------------------- plant 2: mass-spring, actuator lag, PD
# m x'' + c x' + k x = f,  tau f' = -f + u,  u = r - (KP x + KD x')
K, CD, KP, KD = 1.0, 0.2, 4.0, 2.0
LAG = {"m": dict(nominal=1.0, plusminus=0.3), "tau": dict(nominal=0.1, range=(0.05, 0.3))}


def lag_loop_direct(m, tau):
    A = np.array([[0, 1, 0], [-K / m, -CD / m, 1 / m], [-KP / tau, -KD / tau, -1 / tau]])
    return A, np.array([[0], [0], [1 / tau]]), np.array([[1.0, 0, 0]]), np.zeros((1, 1))


def lag_loop_uncertain():
    m = ureal("m", **LAG["m"])
    tau = ureal("tau", **LAG["tau"])
    plant = uss([[0, 1, 0], [-K / m, -CD / m, 1 / m], [0, 0, -1 / tau]], [[0], [0], [1 / tau]],
                [[1, 0, 0], [0, 1, 0]], [[0], [0]])
    ctrl = control.ss([], [], [], [[KP, KD]])
    loop = feedback(plant, ctrl)  # u = r - K y
    return uss(np.array([[1.0, 0.0]]) * loop)


# ---------------------------------------------------------------- plant 3: third-order, 3 parameters
# x''' + a x'' + b x' + c x = u; Routh-Hurwitz: stable iff a > 0, c > 0, a b > c
THIRD = {"a": dict(nominal=2.0, plusminus=0.5), "b": dict(nominal=2.0, plusminus=0.5),
         "c": dict(nominal=1.0, plusminus=0.5)}
#: closed form of the margin: (2 - α/2)^2 = 1 + α/2  ->  α^2 - 10 α + 12 = 0
THIRD_MARGIN = 5.0 - np.sqrt(13.0)


def third_direct(a, b, c):
    A = np.array([[0, 1, 0], [0, 0, 1], [-c, -b, -a]])
    return A, np.array([[0], [0], [1.0]]), np.array([[1.0, 0, 0]]), np.zeros((1, 1))


def third_uncertain():
    a, b, c = (ureal(n, **THIRD[n]) for n in "abc")
    return uss([[0, 1, 0], [0, 0, 1], [-c, -b, -a]], [[0], [0], [1]], [[1, 0, 0]], [[0]])


PLANTS = {
    "two-mass spring-damper (k, m2)": (two_mass_uncertain, two_mass_direct, TWO_MASS),
    "mass-spring + lag + PD loop (m, tau)": (lag_loop_uncertain, lag_loop_direct, LAG),
    "third-order (a, b, c)": (third_uncertain, third_direct, THIRD),
}


def physical(spec, name, delta):
    """Value of parameter ``name`` at normalised ``delta`` (same maps as documented)."""
    return ureal(name, **spec[name]).value(delta)


def brute_margin(direct, spec, points=41, iters=30, hi=20.0):
    """Smallest box scaling with an unstable grid point: bisection on the scale, full box grid."""
    names = list(spec)
    g = np.linspace(-1.0, 1.0, points)
    grid = np.array(np.meshgrid(*[g] * len(names), indexing="ij")).reshape(len(names), -1).T

    atoms = [ureal(n, **spec[n]) for n in names]

    def unstable(alpha):
        vals = np.array([a.value(alpha * grid[:, i]) for i, a in enumerate(atoms)]).T
        if not np.all(np.isfinite(vals)):
            return True
        As = np.array([direct(*v)[0] for v in vals])
        return bool(np.max(np.linalg.eigvals(As).real) >= 0)

    lo, hi_ = 0.0, hi
    if not unstable(hi_):
        return np.inf
    for _ in range(iters):
        mid = 0.5 * (lo + hi_)
        if unstable(mid):
            hi_ = mid
        else:
            lo = mid
    return hi_


def brute_wcgain(direct, spec, points=21):
    """Largest H∞ norm over a grid of the unit box (python-control's own norm routine)."""
    names = list(spec)
    g = np.linspace(-1.0, 1.0, points)
    best = 0.0
    for row in np.array(np.meshgrid(*[g] * len(names), indexing="ij")).reshape(len(names), -1).T:
        vals = [physical(spec, n, d) for n, d in zip(names, row)]
        sys = control.ss(*direct(*vals))
        w = np.logspace(-3, 3, 3000)
        best = max(best, float(np.max(np.abs(sys(1j * w)))))
    return best
