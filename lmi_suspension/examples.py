"""Textbook generalized plants used in tests, benchmarks and notebooks.

Each function returns a :class:`ExamplePlant` with the plant, its partition and, for
µ problems, the block structure.
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

__all__ = ["COMPLEIB_PROBLEMS", "ExamplePlant", "compleib", "skogestad_distillation",
           "stiffness_oscillator", "uncertain_stiffness_oscillator", "uncertain_two_mass"]


@dataclass(frozen=True)
class ExamplePlant:
    """A generalized plant with its partition and (optionally) its µ block structure."""

    P: control.StateSpace
    nmeas: int
    ncon: int
    blk: np.ndarray | None = None
    source: str = ""


def skogestad_distillation() -> ExamplePlant:
    """Robust-performance problem of the ill-conditioned distillation column.

    Skogestad & Postlethwaite, *Multivariable Feedback Control*, 2nd ed. (2005),
    Section 8.12.4 and Table 8.1: ``G(s) = 1/(75 s + 1) [[87.8, -86.4], [108.2, -109.6]]``,
    input uncertainty ``W_I(s) = (s + 0.2)/(0.5 s + 1) I`` (diagonal, two 1×1 complex
    blocks) and performance weight ``w_P(s) = (s/2 + 0.05)/s`` approximated by
    ``0.5 (10 s + 1)/(10 s + 1e-5)``. The µ structure is ``[[1, 1], [1, 1], [2, 2]]``.

    Inputs ``[u_del(2); w(2); u(2)]``, outputs ``[y_del(2); z(2); v(2)]`` with
    ``y_del = W_I u``, ``z = W_P (G (u + u_del) + w)``, ``v = -(G (u + u_del) + w)``.

    Examples
    --------
    >>> ex = skogestad_distillation()
    >>> ex.P.nstates, ex.P.ninputs, ex.P.noutputs
    (6, 6, 6)
    """
    G = control.ss([[-1 / 75, 0], [0, -1 / 75]], np.eye(2) / 75,
                   [[87.8, -86.4], [108.2, -109.6]], np.zeros((2, 2)),
                   inputs=["ug[0]", "ug[1]"], outputs=["g[0]", "g[1]"], name="G")
    wp = control.ss(0.5 * control.tf([10, 1], [10, 1e-5]))
    wi = control.ss(control.tf([1, 0.2], [0.5, 1]))
    Wp = control.append(wp, wp)
    Wi = control.append(wi, wi)
    Wp = control.ss(Wp.A, Wp.B, Wp.C, Wp.D, inputs=["e[0]", "e[1]"], outputs=["z[0]", "z[1]"],
                    name="Wp")
    Wi = control.ss(Wi.A, Wi.B, Wi.C, Wi.D, inputs=["u[0]", "u[1]"],
                    outputs=["ydel[0]", "ydel[1]"], name="Wi")
    in_sum = control.summing_junction(inputs=["u", "udel"], output="ug", dimension=2,
                                      name="in_sum")
    out_sum = control.summing_junction(inputs=["g", "w"], output="e", dimension=2,
                                       name="out_sum")
    meas = control.ss([], [], [], -np.eye(2), inputs=["e[0]", "e[1]"], outputs=["v[0]", "v[1]"],
                      name="meas")
    P = control.interconnect(
        [G, Wp, Wi, in_sum, out_sum, meas],
        inplist=["udel[0]", "udel[1]", "w[0]", "w[1]", "u[0]", "u[1]"],
        outlist=["ydel[0]", "ydel[1]", "z[0]", "z[1]", "v[0]", "v[1]"],
        name="distillation")
    P = control.minreal(P, verbose=False)
    P = control.ss(P.A, P.B, P.C, P.D, name="distillation",
                   inputs=["udel[0]", "udel[1]", "w[0]", "w[1]", "u[0]", "u[1]"],
                   outputs=["ydel[0]", "ydel[1]", "z[0]", "z[1]", "v[0]", "v[1]"])
    return ExamplePlant(P=P, nmeas=2, ncon=2, blk=np.array([[1, 1], [1, 1], [2, 2]]),
                        source="Skogestad & Postlethwaite (2005), Sec. 8.12.4, Table 8.1")


def stiffness_oscillator(zeta: float = 0.02, rk: float = 0.5, wp: float = 2.0,
                         wu: float = 1.0, ap: float = 0.05) -> ExamplePlant:
    """A lightly damped oscillator with a real uncertain stiffness: a mixed-µ problem.

    ``x'' + 2ζ x' + k x = d + u`` with ``k = 1 + rk δ``, ``δ ∈ [-1, 1]`` real; the
    performance output is the position through the low-pass ``wp a/(s + a)`` and the
    control through ``wu``; the measurement is the position with 5 % noise.  A problem
    of this project (tests/test_dgk.py): its central H∞ controller has mixed µ 1.157
    and complex µ 2.32 (``mussv``, 2026-11-27), so the disc cover of ``k`` is far from
    the real interval.

    Inputs ``[w_k, d, n, u]``, outputs ``[z_k, e, z_u, y]``; structure
    ``[[-1, 0], [2, 2]]``.  :func:`uncertain_stiffness_oscillator` writes the same
    plant with a ``ureal``.

    Examples
    --------
    >>> ex = stiffness_oscillator()
    >>> ex.P.nstates, ex.blk.tolist()
    (3, [[-1, 0], [2, 2]])
    """
    A = np.array([[0, 1, 0], [-1.0, -2 * zeta, 0], [ap, 0, -ap]])
    B = np.array([[0, 0, 0, 0], [-rk, 1, 0, 1], [0, 0, 0, 0]])
    C = np.array([[1, 0, 0], [0, 0, wp], [0, 0, 0], [1, 0, 0]])
    D = np.array([[0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, wu], [0, 0, 0.05, 0]])
    return ExamplePlant(P=control.ss(A, B, C, D), nmeas=1, ncon=1,
                        blk=np.array([[-1, 0], [2, 2]]), source="this project (tests/test_dgk.py)")


def uncertain_stiffness_oscillator(zeta: float = 0.02, rk: float = 0.5, wp: float = 2.0,
                                   wu: float = 1.0, ap: float = 0.05):
    """:func:`stiffness_oscillator` written with ``k = ureal("k", 1, plusminus=rk)``: an
    uncertain plant with inputs ``[d, n, u]`` and outputs ``[e, z_u, y]``.

    Examples
    --------
    >>> from lmi_suspension.uncertain import lftdata
    >>> lftdata(uncertain_stiffness_oscillator()).blk.to_blk().tolist()
    [[-1, 0]]
    """
    from .uncertain import ureal, uss

    k = ureal("k", 1.0, plusminus=rk)
    A = [[0, 1, 0], [-k, -2 * zeta, 0], [ap, 0, -ap]]
    B = [[0, 0, 0], [1, 0, 1], [0, 0, 0]]
    C = [[0, 0, wp], [0, 0, 0], [1, 0, 0]]
    D = [[0, 0, 0], [0, 0, wu], [0, 0.05, 0]]
    return uss(A, B, C, D)


def uncertain_two_mass(wp: float = 0.5, wu: float = 0.5, c: float = 0.05,
                       noise: float = 0.01):
    """Two masses on an uncertain spring, a mixed-µ problem with two real parameters.

    ``m1 x1'' = u - f``, ``m2 x2'' = f + d``, ``f = k (x1 - x2) + c (x1' - x2')`` with
    ``m1 = 1``, ``k = ureal("k", 1, plusminus=0.4)`` and ``m2 = ureal("m2", 1,
    plusminus=0.3)`` (each appears once: :func:`~lmi_suspension.uncertain.lftdata`
    finds ``[[-1, 0], [-1, 0]]``); the control force acts on m1, the disturbance force on
    m2, the position of m2 is measured with ``noise`` (1 %) and weighted ``wp``, the
    control ``wu``.  Both masses are free (the rigid-body mode is a double pole at 0),
    as in the ACC robust-control benchmark.  A problem of this project (issue 64,
    ``tests/test_dgk.py``): inputs ``[d, n, u]``, outputs ``[e_x2, e_u, y]``, 4 states.

    Examples
    --------
    >>> from lmi_suspension.uncertain import lftdata
    >>> data = lftdata(uncertain_two_mass())
    >>> data.blk.to_blk().tolist(), data.M.nstates
    ([[-1, 0], [-1, 0]], 4)
    """
    from .uncertain import connect, ureal, uss

    k = ureal("k", 1.0, plusminus=0.4)
    m2 = ureal("m2", 1.0, plusminus=0.3)
    mass1 = uss([[0, 1], [0, 0]], [[0, 0], [1, -1]], [[1, 0], [0, 1]], [[0, 0], [0, 0]],
                inputs=["u", "fs"], outputs=["x1", "v1"])
    mass2 = uss([[0, 1], [0, 0]], [[0], [1 / m2]], [[1, 0], [0, 1]], [[0], [0]],
                inputs=["f2"], outputs=["x2", "v2"])
    spring = uss(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[k]],
                 inputs=["dx"], outputs=["fk"])
    dx = control.summing_junction(inputs=["x1", "-x2"], output="dx")
    fs = control.ss([], [], [], [[1.0, c, -c]], inputs=["fk", "v1", "v2"], outputs=["fs"])
    f2 = control.summing_junction(inputs=["fs", "d"], output="f2")
    out = control.ss([], [], [], [[wp, 0, 0], [0, wu, 0], [1, 0, noise]],
                     inputs=["x2", "u", "n"], outputs=["e1", "e2", "y"])
    return connect([mass1, mass2, spring, dx, fs, f2, out], inputs=["d", "n", "u"],
                   outputs=["e1", "e2", "y"])


#: the COMPleib problems shipped in ``lmi_suspension/data/compleib_subset.json``
COMPLEIB_PROBLEMS = ("AC1", "AC2", "AC3", "AC4", "AC6", "HE1", "HE2", "REA1", "REA2", "DIS1",
                     "NN1", "NN2")


def compleib(name: str):
    """A COMPleib plant shipped with the package, as a generalized plant.

    Leibfritz, *COMPleib: COnstraint Matrix-optimization Problem library*, Universität
    Trier (2004), problems transcribed from ``COMPleib.m`` (source and licence:
    ``lmi_suspension/data/COMPLEIB.md``).  Partition ``x' = A x + B1 w + B u``,
    ``z = C1 x + D11 w + D12 u``, ``y = C x + D21 w`` (``D22 = 0``).

    Parameters
    ----------
    name : str
        One of :data:`COMPLEIB_PROBLEMS`.

    Returns
    -------
    GeneralizedPlant

    Raises
    ------
    ParameterError
        ``name`` is not one of the shipped problems.

    Examples
    --------
    >>> P = compleib("AC4")
    >>> P.nstates, P.nu, P.ny
    (4, 1, 2)
    """
    import json
    from importlib import resources

    from .errors import ParameterError
    from .lti import GeneralizedPlant

    if name not in COMPLEIB_PROBLEMS:
        raise ParameterError(f"no COMPleib problem {name!r} here; shipped: "
                             f"{', '.join(COMPLEIB_PROBLEMS)}")
    text = resources.files("lmi_suspension").joinpath("data/compleib_subset.json").read_text()
    v = json.loads(text)["problems"][name]
    return GeneralizedPlant.from_matrices(v["A"], v["B1"], v["B"], v["C1"], v["C"],
                                          v["D11"], v["D12"], v["D21"])
