"""LMI H∞ synthesis on COMPleib plants (Leibfritz 2005), most of them singular (D21 = 0).

The plants ship with the package (``lmi_suspension/data/compleib_subset.json``, source and
licence in ``lmi_suspension/data/COMPLEIB.md``): no test here skips for want of data.

Reference values: no published full-order optimum could be verified for this subset, so
each problem is checked by independent computations inside the test:
* the certificate: hinfnorm(lft(P, K)) recomputed here, closed-loop poles stable;
* the LMI optimum is a lower bound for every controller, so it must not exceed the
  certified norm of an independently designed controller: python-control's Riccati
  hinfsyn on the ε-regularised plant (extra noise ε·v on y, extra error ε·u; these
  channels only add to the closed-loop gain, so that controller is admissible and its
  norm on the *original* plant is an upper bound on the optimum).
"""

import dataclasses

import control
import numpy as np
import pytest

from lmi_suspension.examples import compleib
from lmi_suspension.lti import GeneralizedPlant, hinfnorm, lft
from lmi_suspension.synthesis import HinfsynOptions, hinfsyn

RELAX = HinfsynOptions().gamma_relax
PROBLEMS = ["AC1", "AC2", "AC3", "AC4", "AC6", "HE1", "HE2", "REA1", "REA2", "DIS1",
            "NN1", "NN2"]
# Certified γ within 0.1 % of the LMI optimum (the target for this library), with
# the default tightening probe. Measured by `python benchmarks/compleib_table.py`
# (2026-11-24, sparse null-space bases in the γ minimisation): at most 0.07 % (AC3 0.06,
# AC6 0.07, HE1 0.07, NN2 0.06 %). HE1 needed a 0.5 % budget before (0.30 %: the dense
# γ minimisation stopped at 0.073814, the sparse one at 0.073622, and the controller
# LMI then certifies 0.073671 instead of 0.073916).
BUDGET: dict[str, float] = {}
DEFAULT_BUDGET = 0.001


def load(name):
    """The COMPleib plant shipped with the package (lmi_suspension/data/COMPLEIB.md)."""
    return compleib(name)


def test_shipped_data_is_the_documented_transcription():
    # the SHA-256 that COMPLEIB.md records for the copy of the former out-of-tree file:
    # an edit of the data must update its provenance note too
    import hashlib
    from importlib import resources

    from lmi_suspension.errors import ParameterError
    from lmi_suspension.examples import COMPLEIB_PROBLEMS

    data = resources.files("lmi_suspension").joinpath("data")
    raw = data.joinpath("compleib_subset.json").read_bytes()
    note = data.joinpath("COMPLEIB.md").read_text()
    assert hashlib.sha256(raw).hexdigest() in note
    assert len(raw) < 2_000_000 and tuple(PROBLEMS) == COMPLEIB_PROBLEMS
    # AC4's dimensions as COMPleib lists them (n = 4, nw = 2, nu = 1, nz = 2, ny = 2)
    P = load("AC4")
    assert (P.nstates, P.nw, P.nu, P.nz, P.ny) == (4, 2, 1, 2, 2)
    with pytest.raises(ParameterError, match="no COMPleib problem"):
        load("AC5")


@pytest.mark.parametrize("name", [p for p in PROBLEMS if p != "AC1"])
def test_compleib_certified_gamma(name):
    P = load(name)
    res = hinfsyn(P, P.ny, P.nu)
    gamma_cl = hinfnorm(lft(P, res.K))[0]
    assert np.isfinite(gamma_cl) and np.all(np.real(res.poles) < 0)
    assert res.gamma == pytest.approx(gamma_cl, rel=1e-6)
    # AC4 included: the issue-41 report of its γ minimisation stopping above the certified
    # γ of both routes (0.5579) does not reproduce on d4a1a73 under the Nehalem,
    # Sandybridge and Haswell kernels (0.5572908 against 0.5572951 certified, 2026-11-27);
    # its independent reference is test_compleib_ac4_against_riccati
    # a lower bound up to the γ minimisation's relative gap (CVXOPT's reltol,
    # HinfsynOptions.tol_gap_rel = 1e-6): measured at most 2.8e-8 above the certified γ
    # (REA1, REA2; 2026-12-01, Haswell and Sandybridge kernels)
    assert res.gamma >= res.gamma_lower * (1 - HinfsynOptions().tol_gap_rel)
    assert res.gamma <= res.gamma_lower * (1 + BUDGET.get(name, DEFAULT_BUDGET))


def test_compleib_ac4_against_riccati():
    """AC4 is regular (D12, D21 full rank), so python-control's Riccati hinfsyn applies;
    its controller, certified here by hinfnorm(lft(P, K)), bounds the optimum from
    above: the LMI lower bound must not exceed it by more than the solver's accuracy
    and the cost of the bound ``trace(X) + trace(Y) <= xy_bound n`` (measured
    2026-11-29: 0.5572915 against 0.5572907, 1.5e-6 above; 0.5572908 with a bound a
    thousand times wider; hence 1e-5) and the LMI controller must certify within the
    0.1 % budget of it (0.5572951)."""
    P = load("AC4")
    K, _CL, _gam, _ = control.hinfsyn(P.sys, P.ny, P.nu)
    best = hinfnorm(lft(P, K))[0]
    assert np.isfinite(best)
    res = hinfsyn(P, P.ny, P.nu)
    assert np.all(np.real(res.poles) < 0)
    assert res.gamma_lower <= best * (1 + 1e-5)
    assert best * (1 - 1e-6) <= res.gamma <= best * (1 + DEFAULT_BUDGET)
    assert not any("below the LMI optimum" in w for w in res.warnings)


def test_a_minimisation_stopped_above_a_certified_controller_is_a_warning(monkeypatch):
    """Injected: the γ minimisation claims an optimum 1 % above AC4's true one (the
    defect issue 41 reported on AC4: 0.5579 against 0.5573 certified).  A controller that
    certifies below the claimed optimum proves it is no lower bound; the result must say
    so in its warnings (and the certified γ stays the controller's)."""
    import importlib

    mod = importlib.import_module("lmi_suspension.synthesis.hinfsyn")
    refined = mod._refined_gamma_lmi

    def stopped_high(Ps, opts, *args, **kwargs):
        sol, earlier = refined(Ps, opts, *args, **kwargs)
        return dataclasses.replace(sol, gamma=sol.gamma * 1.01), earlier

    monkeypatch.setattr(mod, "_refined_gamma_lmi", stopped_high)
    P = load("AC4")
    res = hinfsyn(P, P.ny, P.nu)
    assert res.gamma == pytest.approx(hinfnorm(lft(P, res.K))[0], rel=1e-9)
    assert res.gamma < res.gamma_lower
    assert any("below the LMI optimum" in w and "inaccurate" in w for w in res.warnings)


def test_compleib_ac1_infimum_is_zero():
    # AC1: the LMI optimum is ~0 (no positive lower bound); the design falls back to
    # gamma_atol and still returns a certified, stabilising controller
    P = load("AC1")
    res = hinfsyn(P, P.ny, P.nu)
    assert res.gamma_lower < 1e-6
    assert np.all(np.real(res.poles) < 0) and res.gamma < 1e-4


def _regularised(P, eps):
    b = P.blocks()
    n, nw, nu, nz, ny = P.nstates, P.nw, P.nu, P.nz, P.ny
    return GeneralizedPlant.from_matrices(
        A=b["A"], B1=np.hstack([b["B1"], np.zeros((n, ny))]), B2=b["B2"],
        C1=np.vstack([b["C1"], np.zeros((nu, n))]), C2=b["C2"],
        D11=np.block([[b["D11"], np.zeros((nz, ny))], [np.zeros((nu, nw + ny))]]),
        D12=np.vstack([b["D12"], eps * np.eye(nu)]),
        D21=np.hstack([b["D21"], eps * np.eye(ny)]), D22=b["D22"])


@pytest.mark.slow
# AC2 is left out: its regularised plant has an invariant zero on the imaginary axis
@pytest.mark.parametrize("name", ["REA1", "NN2", "HE2"])
def test_compleib_lower_bound_below_regularised_riccati(name):
    P = load(name)
    res = hinfsyn(P, P.ny, P.nu)
    K, _CL, _gam, _ = control.hinfsyn(_regularised(P, 1e-3).sys, P.ny, P.nu)
    upper = hinfnorm(lft(P, K))[0]
    assert res.gamma_lower <= upper * (1 + 1e-4)
