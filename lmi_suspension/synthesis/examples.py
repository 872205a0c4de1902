"""Seeded random generalized plants for tests and benchmarks."""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..lti.plant import GeneralizedPlant

__all__ = ["random_plant"]


def random_plant(n: int, nw: int, nu: int, nz: int, ny: int, *, rng: np.random.Generator,
                 regular: bool = True, d11: bool = True, d22: bool = False,
                 unstable: int = 1) -> GeneralizedPlant:
    """A random generalized plant, stabilisable and detectable with probability one.

    Parameters
    ----------
    n, nw, nu, nz, ny : int
        Numbers of states, disturbances, controls, errors, measurements.
    rng : numpy.random.Generator
        Source of randomness (seed it for reproducibility).
    regular : bool
        If True, ``D12`` has full column rank and ``D21`` full row rank (needs
        ``nz >= nu`` and ``nw >= ny``), so the Riccati method applies; otherwise
        ``D21 = 0`` (a singular problem).
    d11, d22 : bool
        Whether ``D11`` / ``D22`` are non-zero.
    unstable : int
        Number of open-loop eigenvalues moved into the right half-plane.

    Examples
    --------
    >>> import numpy as np
    >>> P = random_plant(4, 2, 1, 2, 1, rng=np.random.default_rng(0))
    >>> P.nstates, P.nw, P.nu, P.nz, P.ny
    (4, 2, 1, 2, 1)
    """
    if not isinstance(rng, np.random.Generator):
        raise ParameterError("rng must be a numpy.random.Generator")
    if regular and (nz < nu or nw < ny):
        raise ParameterError("a regular plant needs nz >= nu and nw >= ny")
    # stable modal part with a few lightly damped modes, then a similarity
    k = n // 2
    re = -rng.uniform(0.1, 2.0, size=n)
    A = np.diag(re)
    for i in range(k):
        w = rng.uniform(0.5, 5.0)
        A[2 * i:2 * i + 2, 2 * i:2 * i + 2] = [[re[2 * i], w], [-w, re[2 * i]]]
    # move the first `unstable` eigenvalues (whole complex pairs) to the right half-plane
    for i in range(min(unstable, n)):
        A[i, i] = abs(A[i, i])
        if i < 2 * k and i % 2 == 0:
            A[i + 1, i + 1] = abs(A[i + 1, i + 1])
    T = rng.standard_normal((n, n)) + 2.0 * np.eye(n)
    A = T @ A @ np.linalg.inv(T)
    B1 = rng.standard_normal((n, nw))
    B2 = rng.standard_normal((n, nu))
    C1 = rng.standard_normal((nz, n))
    C2 = rng.standard_normal((ny, n))
    D11 = 0.1 * rng.standard_normal((nz, nw)) if d11 else np.zeros((nz, nw))
    D22 = 0.1 * rng.standard_normal((ny, nu)) if d22 else np.zeros((ny, nu))
    if regular:
        D12 = np.vstack([np.zeros((nz - nu, nu)), np.eye(nu)]) + 0.1 * rng.standard_normal((nz, nu))
        D21 = np.hstack([np.zeros((ny, nw - ny)), np.eye(ny)]) + 0.1 * rng.standard_normal((ny, nw))
    else:
        D12 = np.vstack([np.zeros((nz - nu, nu)), np.eye(nu)]) if nz >= nu else \
            rng.standard_normal((nz, nu))
        D21 = np.zeros((ny, nw))
    return GeneralizedPlant.from_matrices(A, B1, B2, C1, C2, D11, D12, D21, D22)
