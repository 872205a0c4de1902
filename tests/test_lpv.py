"""Gridded gain-scheduled H∞ synthesis, frozen parameters (``lpvsyn``, issue 61).

The example: a mass-spring-damper whose mass ``m`` in [1, 4] is measured (k = 1, c = 0.2),
a force disturbance ``d`` and the control force ``u`` acting through ``1/m`` (so ``B2``
depends on the parameter: the gridded route, not the polytopic one), the position
measured with noise ``0.1 n``; errors ``[x, 0.1 u]``.  Two states.
"""

from __future__ import annotations

import time

import control
import numpy as np
import pytest

from lmi_suspension.errors import (DimensionError, DiscreteTimeError, LmiSuspensionError,
                                   NonFiniteError, ParameterError)
from lmi_suspension.lpv import LpvsynResult, ScheduledController, lpvsyn
from lmi_suspension.lti import hinfnorm, lft
from lmi_suspension.synthesis import hinfsyn

GRID = {"m": np.linspace(1.0, 4.0, 9)}


def msd(m, k=1.0, c=0.2):
    """w = [d, n], u; z = [x, 0.1 u], y = x + 0.1 n."""
    A = [[0.0, 1.0], [-k / m, -c / m]]
    B = [[0.0, 0.0, 0.0], [1.0 / m, 0.0, 1.0 / m]]
    C = [[1.0, 0.0], [0.0, 0.0], [1.0, 0.0]]
    D = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.1], [0.0, 0.1, 0.0]]
    return control.ss(A, B, C, D)


@pytest.fixture(scope="module")
def linear():
    return lpvsyn(msd, GRID, 1, 1, rate={"m": 0.0})          # basis [1, m]


@pytest.fixture(scope="module")
def constant():
    return lpvsyn(msd, GRID, 1, 1, basis=lambda m: [1.0])


def _sweep_peak(CL):
    """σ̄ of the closed loop on 4000 log-spaced frequencies by python-control's own
    frequency response (independent of hinfnorm's Hamiltonian iteration)."""
    w = np.logspace(-3, 4, 4000)
    H = CL.frequency_response(w).frdata                     # (outputs, inputs, freqs)
    return float(np.max(np.linalg.svd(np.moveaxis(H, 2, 0), compute_uv=False)))


# ------------------------------------------------------------------- (a) certificates
def test_dense_grid_certificate(linear):
    res = linear
    assert isinstance(res, LpvsynResult) and isinstance(res.K, ScheduledController)
    assert res.warnings == ()
    check = res.check_grid["m"]
    # 4 pieces per design interval, the ends included (issue 61, "Certificates")
    assert check.size == 4 * (GRID["m"].size - 1) + 1
    assert check[0] == 1.0 and check[-1] == 4.0
    level0 = res.gamma_lmi * (1.0 + res.K.backoff)
    for m, g in zip(check, res.gamma_check):
        CL = lft(msd(m), res.K.at(m=m))
        assert np.max(np.linalg.eigvals(CL.A).real) < 0.0     # every frozen loop stable
        peak = _sweep_peak(CL)
        # the sweep is a lower bound of the norm, and a close one on this 2+2-state loop
        assert g * (1.0 - 1e-3) <= peak <= g * (1.0 + 1e-9)
        assert g <= res.gamma * (1.0 + 1e-12)
    assert res.gamma == pytest.approx(np.max(res.gamma_check), rel=1e-12)
    # certified below the level the controllers are formed at (measured 2026-12-02:
    # 0.988 γ_lmi, every controller at the level 1.02 γ_lmi)
    assert np.all(res.levels <= level0 * (1.0 + 1e-12))
    assert res.gamma <= level0 * (1.0 + 1e-6)


def test_certificate_fails_for_controller_at_wrong_parameter(monkeypatch):
    """Injected: the controller formed at the mirrored parameter value 5 - m (issue 61,
    acceptance); the dense-grid certificate must say so."""
    build = ScheduledController.build

    def wrong(self, *p):
        K, level, cond = build(self, 5.0 - p[0])
        return K, level, cond

    monkeypatch.setattr(ScheduledController, "build", wrong)
    res = lpvsyn(msd, GRID, 1, 1)
    assert res.warnings and any("exceeds" in w or "NOT stable" in w for w in res.warnings)
    assert res.gamma > res.gamma_lmi * (1.0 + res.K.backoff) * (1.0 + 1e-3)


# ------------------------------------------------------------------- (b) lower bounds
@pytest.mark.parametrize("m", [1.0, 2.5, 4.0])
def test_no_scheduled_controller_beats_the_frozen_optimum(linear, m):
    # hinfsyn's LMI lower bound at the frozen plant (structured CVXOPT route, frames):
    # measured 2026-12-02 0.235435 (m=1), 0.238952 (2.5), 0.240246 (4); the scheduled
    # controller's frozen norm there is about 0.30
    frozen = hinfsyn(msd(m), 1, 1)
    assert frozen.gamma_lower is not None
    assert frozen.gamma_lower <= linear.gamma_frozen(m) * (1.0 + 1e-6)
    assert frozen.gamma_lower <= linear.gamma_frozen(m=m) * (1.0 + 1e-6)


def test_nested_bases(linear, constant):
    # span{1} ⊂ span{1, m} ⊂ span{1, m, 1/m}: the optima are ordered (up to Clarabel's
    # tolerances); measured 2026-12-02: 0.4775, 0.3119, 0.2453
    rich = lpvsyn(msd, GRID, 1, 1, basis=lambda m: [1.0, m, 1.0 / m])
    assert linear.gamma_lmi <= constant.gamma_lmi * (1.0 + 1e-6)
    assert rich.gamma_lmi <= linear.gamma_lmi * (1.0 + 1e-6)
    # and here each function buys much: the basis is used (measured, see above)
    assert rich.gamma_lmi < 0.9 * linear.gamma_lmi < 0.9 * 0.9 * constant.gamma_lmi
    # and every one is above the worst frozen optimum (hinfsyn at m = 4, 0.240246,
    # measured 2026-12-02)
    assert rich.gamma_lmi >= hinfsyn(msd(4.0), 1, 1).gamma_lower * (1.0 - 1e-4)
    for res in (constant, rich):
        assert np.all(np.isfinite(res.gamma_check))
        assert res.gamma <= res.gamma_lmi * (1.0 + res.K.backoff) * (1.0 + 1e-6)


def test_single_grid_point_is_hinfsyn():
    """Issue 61 acceptance: with one grid point lpvsyn's optimum is hinfsyn's to 1e-4."""
    res = lpvsyn(msd, {"m": [2.0]}, 1, 1)
    ref = hinfsyn(msd(2.0), 1, 1)        # the structured CVXOPT route: another solver
    assert res.gamma_lmi == pytest.approx(ref.gamma_lower, rel=1e-4)
    # one point: its frozen norm is the certified γ, at or above the frozen optimum
    assert res.gamma_frozen(2.0) == pytest.approx(res.gamma, rel=1e-9)
    assert ref.gamma_lower <= res.gamma * (1.0 + 1e-6)
    assert res.gamma <= res.gamma_lmi * (1.0 + res.K.backoff) * (1.0 + 1e-6)


# ------------------------------------------------------------------- (c) between points
@pytest.mark.parametrize("m", [1.3, 2.2, 3.7])
def test_between_grid_points(m):
    res = lpvsyn(msd, {"m": np.linspace(1.0, 4.0, 5)}, 1, 1)
    assert m not in set(res.check_grid["m"]) | set(res.grid["m"])
    K, level, _ = res.K.build(m=m)
    CL = lft(msd(m), K)
    assert np.max(np.linalg.eigvals(CL.A).real) < 0.0
    g = res.gamma_frozen(m)
    assert g == pytest.approx(_sweep_peak(CL), rel=1e-3)
    assert g <= level * (1.0 + 1e-6)
    # the grid's LMIs are not imposed here, yet the level stayed within 5 % (measured
    # 2026-12-02: at most 1.02 γ_lmi)
    assert level <= res.gamma_lmi * (1.0 + res.K.backoff) * 1.05


def test_api_as_written():
    """The call of issue 61, item 6, on the example rescaled to m3 in [30, 70]."""
    grid = {"m3": np.linspace(30.0, 70.0, 9)}
    res = lpvsyn(lambda m3: msd(m3 / 20.0), grid, nmeas=1, ncon=1,
                 basis=lambda m3: [1.0, m3, 1.0 / m3], rate={"m3": 0.0})
    K42 = res.K.at(m3=42.0)
    assert isinstance(K42, control.StateSpace) and K42.nstates == 2
    assert np.isfinite(res.gamma)
    assert not [w for w in res.warnings if "exceeds" in w or "NOT" in w]
    _, level, _ = res.K.build(m3=42.0)
    assert res.gamma_frozen(42.0) <= level * (1.0 + 1e-6)


def test_two_parameters_and_every_excess_is_reported():
    """Mass and stiffness scheduled on a coarse 3 x 2 grid: between grid points some
    frozen norms exceed the level (measured 2026-12-02: up to 1.15 % at m = 1.375,
    k = 0.5), and each of them must be in ``warnings``, none silently."""
    def plant(m, k):
        return msd(m, k=k)

    res = lpvsyn(plant, {"m": [1.0, 2.5, 4.0], "k": [0.5, 1.0]}, 1, 1)
    assert res.check_grid["m"].size == 9 and res.check_grid["k"].size == 5
    assert res.gamma_check.size == 45 and np.all(np.isfinite(res.gamma_check))
    assert res.K.at(m=3.0, k=0.7).nstates == 2
    level0 = res.gamma_lmi * (1.0 + res.K.backoff)
    excess = int(np.sum(res.gamma_check > level0 * (1.0 + 1e-6)))
    assert excess >= 1                                      # (measured, see above)
    assert excess == sum("exceeds" in w for w in res.warnings)
    # the design points themselves are certified at the level (the LMIs hold there)
    for m in (1.0, 2.5, 4.0):
        for k in (0.5, 1.0):
            assert res.gamma_frozen(m, k) <= level0 * (1.0 + 1e-6)


def test_list_of_plants_is_interpolated(linear):
    pairs = [(m, msd(m)) for m in GRID["m"]]
    res = lpvsyn(pairs, "m", 1, 1)
    # the same LMI on the same grid (Clarabel's tolerance 1e-6 relative)
    assert res.gamma_lmi == pytest.approx(linear.gamma_lmi, rel=1e-5)
    assert np.all(np.isfinite(res.gamma_check))
    # between grid points the plant is the linear interpolation of the matrices
    P = res.K.plant(1.2)
    t = (1.2 - 1.0) / 0.375                                  # grid step 3/8
    assert np.allclose(P.A, (1.0 - t) * msd(1.0).A + t * msd(1.375).A)


# ------------------------------------------------------------------- (d) typed errors
def _discrete(m):
    return control.c2d(msd(m), 0.01)


@pytest.mark.parametrize("kwargs, err", [
    ({"grid": {"m": [2.0]}, "rate": {"m": 0.1}}, ParameterError),   # rate on one value
    ({"rate": {"m": np.inf}}, NonFiniteError),
    ({"rate": {"m": -0.1}}, ParameterError),
    (dict(grid={"m": [1.0, np.nan, 4.0]}), NonFiniteError),
    (dict(grid={"m": []}), ParameterError),
    (dict(grid={}), ParameterError),
    (dict(P=_discrete), DiscreteTimeError),
    (dict(P=lambda m: msd(m) if m < 2 else control.append(msd(m), control.ss(-1, 0, 0, 0))),
     DimensionError),
    (dict(basis=lambda m: [1.0, m] if m < 2 else [1.0]), DimensionError),
    (dict(basis=lambda m: [1.0, np.nan if m > 3 else m]), NonFiniteError),
    (dict(basis=lambda m: [1.0, m, 2.0 * m]), ParameterError),   # singular on the grid
    (dict(grid={"m": [2.0]}, basis=lambda m: [1.0, m]), ParameterError),
    (dict(rate={"q": 0.0}), ParameterError),
])
def test_typed_errors(kwargs, err):
    args = dict(P=msd, grid=GRID, basis=None, rate=None)
    args.update(kwargs)
    t = time.perf_counter()
    with pytest.raises(err) as info:
        lpvsyn(args["P"], args["grid"], 1, 1, basis=args["basis"], rate=args["rate"])
    assert isinstance(info.value, LmiSuspensionError)
    assert time.perf_counter() - t < 1.0                    # issue 61: under a second


def test_at_outside_the_range_or_misnamed(linear):
    with pytest.raises(ParameterError):
        linear.K.at(m=4.5)
    with pytest.raises(ParameterError):
        linear.K.at(mass=2.0)
    with pytest.raises(NonFiniteError):
        linear.K.at(m=np.nan)


# ------------------------------------------------------------------- (e) save, export, sample
def _same_bits(a, b):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and a.tobytes() == b.tobytes()


def _same_ss(K1, K2):
    return all(_same_bits(getattr(K1, M), getattr(K2, M)) for M in "ABCD")


def test_json_round_trip_is_exact(linear, tmp_path):
    """Issue 61 item 3: the saved schedule loads back bit for bit (json writes each
    float's shortest round-tripping repr), and so does every frozen controller."""
    from lmi_suspension import io

    path = io.save_scheduled_controller(tmp_path / "K.json", linear, metadata={"note": "msd"})
    K2, meta = io.load_scheduled_controller(path)
    K = linear.K
    assert meta == {"gamma": linear.gamma, "gamma_lmi": linear.gamma_lmi, "note": "msd"}
    assert K2.names == K.names and K2.bounds == K.bounds and K2.shape == K.shape
    assert (K2.nmeas, K2.ncon, K2.backoff) == (K.nmeas, K.ncon, K.backoff)
    assert K2.gamma_lmi_scaled == K.gamma_lmi_scaled
    assert all(_same_bits(a, b) for a, b in zip(K2.X + K2.Y, K.X + K.Y))
    assert all(_same_bits(getattr(K2.scaling, f), getattr(K.scaling, f))
               for f in ("T", "Su", "Sy", "cw", "cz"))
    assert _same_bits(K2.grid["m"], K.grid["m"])
    # the callable plant is stored on the certificate's grid: at each of its nodes the
    # loaded controller is the original one, bit for bit
    nodes = linear.check_grid["m"]
    for m in nodes:
        assert _same_ss(K2.at(m=m), K.at(m=m))
    # the frozen controllers on the design grid, readable with the plain controller format
    import json
    data = json.loads(path.read_text())
    assert data["format"] == "lmi_suspension.scheduled_controller/1"
    assert data["exact_between_nodes"] is False
    assert len(data["frozen"]) == GRID["m"].size
    for entry, m in zip(data["frozen"], GRID["m"]):
        assert entry["metadata"]["p"] == {"m": m}
        assert _same_ss(io.controller_from_dict(entry), K.at(m=m))


def test_json_round_trip_of_a_table_plant_is_exact_between_nodes(tmp_path):
    """A plant given as a list and the default basis are stored as they are: the loaded
    controller equals the original everywhere, between nodes too."""
    from lmi_suspension.io import load_scheduled_controller, save_scheduled_controller

    res = lpvsyn([(m, msd(m)) for m in (1.0, 2.0, 4.0)], "m", 1, 1)
    K2, _ = load_scheduled_controller(save_scheduled_controller(tmp_path / "K.json", res.K))
    for m in (1.0, 1.37, 2.9, 4.0):
        assert _same_ss(K2.at(m), res.K.at(m))


def test_json_round_trip_of_a_callable_basis(tmp_path):
    """A caller's basis is tabulated: exact at the table's nodes (here a table given)."""
    from lmi_suspension import io
    from lmi_suspension.errors import InputError

    res = lpvsyn(msd, {"m": [1.0, 2.5, 4.0]}, 1, 1, basis=lambda m: [1.0, m, 1.0 / m])
    table = {"m": [1.0, 1.5, 2.5, 3.1, 4.0]}
    path = io.save_scheduled_controller(tmp_path / "K.json", res.K, table=table, frozen=False)
    K2, _ = io.load_scheduled_controller(path)
    for m in table["m"]:
        assert _same_ss(K2.at(m=m), res.K.at(m=m))
    with pytest.raises(ParameterError):                     # outside the design interval
        io.save_scheduled_controller(tmp_path / "bad.json", res.K, table={"m": [0.5, 2.0]})
    with pytest.raises(InputError):
        io.scheduled_from_dict({"format": "lmi_suspension.controller/1"})


def test_mat_export_of_frozen_controllers(linear, tmp_path):
    """The .mat file holds K(p) on the grid, MATLAB's n x n x N layout, bit for bit."""
    import scipy.io

    from lmi_suspension.io import save_scheduled_mat

    grid = {"m": linear.check_grid["m"]}
    m = scipy.io.loadmat(save_scheduled_mat(tmp_path / "K.mat", linear.K, grid))
    N = grid["m"].size
    assert m["A"].shape == (2, 2, N) and m["B"].shape == (2, 1, N)
    assert m["P"].shape == (N, 1) and _same_bits(m["P"][:, 0], grid["m"])
    assert _same_bits(np.ravel(m["m"]), grid["m"])
    assert [str(np.ravel(x)[0]) for x in np.ravel(m["ParameterName"])] == ["m"]
    for k, p in enumerate(grid["m"]):
        K, level, _ = linear.K.build(m=p)
        assert all(_same_bits(m[M][:, :, k], getattr(K, M)) for M in "ABCD")
        assert np.ravel(m["Level"])[k] == level
    md = scipy.io.loadmat(save_scheduled_mat(tmp_path / "Kd.mat", linear.K, dt=1e-3))
    assert float(np.ravel(md["Ts"])[0]) == 1e-3 and md["A"].shape[-1] == GRID["m"].size
    assert _same_bits(md["A"][:, :, 3], linear.K.at_discrete(GRID["m"][3], dt=1e-3).A)


def test_discrete_realization_and_nyquist(linear):
    """Tustin at 1 kHz: Kd(e^{jωT}) = K(j (2/T) tan(ωT/2)) (the bilinear map's warping,
    evaluated on both systems independently), and a pole above π/dt is a typed error."""
    from lmi_suspension.errors import NyquistError

    K = linear.K.at(m=2.2)
    Kd = linear.K.at_discrete(dt=1e-3, m=2.2)
    assert Kd.dt == 1e-3 and np.all(np.abs(Kd.poles()) < 1.0)
    T = 1e-3
    for w in (0.3, 3.0, 30.0, 300.0):
        zd = complex(Kd(np.exp(1j * w * T)))
        zc = complex(K(1j * (2.0 / T) * np.tan(w * T / 2.0)))
        assert zd == pytest.approx(zc, rel=1e-8)
    fast = float(np.max(np.abs(K.poles())))     # 6.73 rad/s here (measured 2026-12-02)
    dt = 2.0 * np.pi / fast                                 # Nyquist rate fast / 2
    with pytest.raises(NyquistError, match="Nyquist"):
        linear.K.at_discrete(dt=dt, m=2.2)
    assert isinstance(NyquistError("x"), ParameterError)
    Kc = linear.K.at_discrete(dt=dt, m=2.2, allow_unresolved=True)
    assert np.all(np.abs(Kc.poles()) < 1.0)                 # Tustin keeps stability
    with pytest.raises(ParameterError):
        linear.K.at_discrete(dt=0.0, m=2.2)


# ------------------------------------------------------------------- (f) rate bounds
NU = 0.5            # |dm/dt| <= 0.5 kg/s: the mass can sweep its range in 6 s


@pytest.fixture(scope="module")
def rated():
    return lpvsyn(msd, GRID, 1, 1, rate={"m": NU})            # both forms tried


def _scaled_loop(K, m):
    """The closed loop of msd(m) and K(m) (python-control's interconnection of the
    returned controller), in the scaled plant's coordinates and signals."""
    Kp, level, _ = K.build(m=m)
    CL = lft(msd(m), Kp)
    sc = K.scaling
    J = np.diag(np.r_[sc.T, np.ones(CL.nstates - sc.T.size)])
    A = np.linalg.solve(J, CL.A @ J)
    B = np.linalg.solve(J, CL.B) * sc.cw
    return A, B, CL.C @ J / sc.cz, CL.D * sc.cw / sc.cz, level


def _lpv_brl(K, m, pdot_values, h=1e-6):
    """Largest eigenvalue of the closed loop's bounded-real inequality with Ṗ = ṗ ∂P/∂m
    (central differences of the returned Lyapunov matrix) at each ṗ: a second route to
    the rate-bounded guarantee, from the closed loop rather than the projected LMIs."""
    A, B, C, D, level = _scaled_loop(K, m)
    g = level * K.scaling.gamma_factor
    P = K.closed_loop_lyapunov(m=m, level=level)
    lo, hi = max(1.0, m - h), min(4.0, m + h)
    dP = (K.closed_loop_lyapunov(m=hi, level=level)
          - K.closed_loop_lyapunov(m=lo, level=level)) / (hi - lo)
    assert np.linalg.eigvalsh(P)[0] > 0.0
    out = []
    for pd in pdot_values:
        L = np.block([[A.T @ P + P @ A + pd * dP, P @ B, C.T],
                      [B.T @ P, -g * np.eye(B.shape[1]), D.T],
                      [C, D, -g * np.eye(C.shape[0])]])
        out.append(float(np.linalg.eigvalsh((L + L.T) / 2)[-1]))
    return max(out)


def test_rate_bounded_certificates(rated, linear):
    """ν > 0 (issue 61 items 1 and 4(b)): the parameter-dependent inequalities with the
    ∂X/∂p terms hold at every vertex on the dense grid, every frozen loop is certified,
    and the closed loop's own LPV bounded-real inequality holds with Ṗ at ṗ = ±ν."""
    res = rated
    assert res.K.rate_bounded and res.K.rate == (NU,) and res.K.rate_form in ("X", "Y")
    assert res.warnings == ()
    assert res.notes and "kept" in res.notes[0]              # both forms were solved
    assert res.inequality_check.shape == res.gamma_check.shape
    assert np.all(res.inequality_check < 0.0)                # certificate (b)
    assert np.all(np.isfinite(res.gamma_check))
    assert res.gamma <= np.max(res.levels) * (1.0 + 1e-6)    # certificate (a)
    # the frozen design relaxes the rate-bounded one: its optimum is no higher
    # (measured 2026-12-02: 0.3119 against 0.4768, see the module docstring of lpv.py)
    assert linear.gamma_lmi <= res.gamma_lmi * (1.0 + 1e-6)
    # second route: at design points and between them (measured 2026-12-02: largest
    # eigenvalues -1e-4 to -4e-3 of γ ≈ 0.49 in scaled units)
    for m in (1.0, 1.2, 2.2, 3.3, 4.0):
        assert _lpv_brl(res.K, m, (-NU, 0.0, NU)) < 0.0


def test_rate_bound_certificate_fails_by_injection(rated):
    """Certificate (b) must be able to fail: the same controller re-evaluated for a
    rate bound 1e4 times larger."""
    import dataclasses

    fast = dataclasses.replace(rated.K, rate=(NU * 1e4,))
    worst = max(fast.inequalities(m=m, level=lv)
                for m, lv in zip(rated.check_grid["m"], rated.levels))
    assert worst > 0.0


@pytest.mark.parametrize("form", ["X", "Y"])
def test_rate_forms_and_monotone_in_the_rate(form):
    """Each form on its own; a larger rate bound cannot lower the optimum (the feasible
    set shrinks); the controller does not depend on ṗ (the same at every call)."""
    grid = {"m": [1.0, 2.5, 4.0]}
    slow = lpvsyn(msd, grid, 1, 1, rate={"m": 0.05}, rate_form=form)
    quick = lpvsyn(msd, grid, 1, 1, rate={"m": 50.0}, rate_form=form)
    assert slow.K.rate_form == quick.K.rate_form == form
    assert slow.gamma_lmi <= quick.gamma_lmi * (1.0 + 1e-5)   # Clarabel's tolerance
    for res, nu in ((slow, 0.05), (quick, 50.0)):
        assert res.warnings == () and np.all(res.inequality_check < 0.0)
        assert _lpv_brl(res.K, 1.7, (-nu, nu)) < 0.0
    assert _same_ss(slow.K.at(m=1.7), slow.K.at(m=1.7))


def test_rate_bounded_round_trip_with_a_callable_basis(tmp_path):
    """A rate-bounded schedule with a caller's basis: the basis and its Jacobian are
    tabulated; at the nodes the loaded controller is the original bit for bit."""
    from lmi_suspension.io import load_scheduled_controller, save_scheduled_controller

    res = lpvsyn(msd, {"m": [1.0, 2.5, 4.0]}, 1, 1, basis=lambda m: [1.0, 1.0 / m],
                 rate={"m": 0.2}, rate_form="Y")
    K2, _ = load_scheduled_controller(save_scheduled_controller(tmp_path / "K.json", res.K))
    assert K2.rate == res.K.rate and K2.rate_form == "Y"
    assert _same_bits(K2.frame, res.K.frame)
    for m in res.check_grid["m"]:
        assert _same_ss(K2.at(m=m), res.K.at(m=m))
    assert all(_same_bits(a, b) for a, b in zip(K2.lyapunov_rate(m=2.5),
                                                  res.K.lyapunov_rate(m=2.5)))
    # the basis derivative (complex step) against the formula d(1/m)/dm = -1/m²
    from lmi_suspension.synthesis.lpv import _basis_jacobian
    assert np.allclose(_basis_jacobian(lambda m: [1.0, 1.0 / m], (2.5,), 2)[:, 0],
                       [0.0, -1.0 / 2.5**2], rtol=1e-14, atol=0.0)
    # a basis that refuses complex numbers falls back to central differences
    J = _basis_jacobian(lambda m: [1.0, 1.0 / float(m)], (2.5,), 2)
    assert J[1, 0] == pytest.approx(-1.0 / 2.5**2, rel=1e-8)


# ------------------------------------------------------------------- (g) three plants
class _Repeated:
    """``diag(K, ..., K)`` with the parameters of ``K`` shared: one LTI controller tuned
    by ``hinfstruct`` on the stacked plants ``diag(P(p_1), ..., P(p_k))``, whose H∞ norm
    is the largest of the loops' (a multi-model design: the robust controller)."""

    def __init__(self, block, copies):
        self.b, self.k = block, copies
        self.name, self.param_names = block.name, block.param_names
        self.ninputs, self.noutputs = copies * block.ninputs, copies * block.noutputs
        self.nstates = copies * block.nstates

    n_params = property(lambda self: self.b.n_params)
    start = property(lambda self: self.b.start)

    def matrices(self, theta):
        import scipy.linalg

        return tuple(scipy.linalg.block_diag(*([M] * self.k)) for M in self.b.matrices(theta))

    def jacobian(self, theta):
        Jb = np.asarray(self.b.jacobian(theta))
        no, ni, n = self.b.noutputs, self.b.ninputs, self.b.nstates
        J = np.zeros((self.n_params, self.noutputs + self.nstates, self.ninputs + self.nstates))
        for c in range(self.k):
            rows = np.r_[c * no:(c + 1) * no, self.noutputs + c * n:self.noutputs + (c + 1) * n]
            cols = np.r_[c * ni:(c + 1) * ni, self.ninputs + c * n:self.ninputs + (c + 1) * n]
            J[:, rows[:, None], cols[None, :]] = Jb
        return J

    def ss(self, theta):
        return control.ss(*self.matrices(theta))

    def values(self, theta):
        return self.b.values(theta)

    def freqresp_derivative(self, theta, s):
        from lmi_suspension.tune.blocks import _freqresp_derivative

        return _freqresp_derivative(self, np.asarray(theta, dtype=float), s)


def _stacked(plants):
    """``diag(P_1, ..., P_k)`` with w, u, z, y regrouped (one measurement, one control)."""
    import scipy.linalg

    from lmi_suspension.lti import GeneralizedPlant

    bs = [GeneralizedPlant.from_statespace(P, 1, 1).blocks() for P in plants]
    return GeneralizedPlant.from_matrices(
        *(scipy.linalg.block_diag(*[b[k] for b in bs])
          for k in ("A", "B1", "B2", "C1", "C2", "D11", "D12", "D21", "D22"))).sys


def _gain_plant(b):
    """The mass-spring-damper at m = 1 with the control force scaled by b."""
    P = msd(1.0)
    return control.ss(P.A, np.c_[P.B[:, :2], b * P.B[:, 2:]], P.C, P.D)


THREE = {
    "mass": (msd, np.linspace(1.0, 4.0, 9), lambda m: [1.0, m, 1.0 / m]),
    "stiffness": (lambda k: msd(1.0, k=k), np.linspace(0.5, 4.0, 9), None),
    "gain": (_gain_plant, np.linspace(0.5, 2.0, 9), lambda b: [1.0, b, 1.0 / b]),
}


@pytest.mark.slow  # 32 s on Zen 1 (2026-12-02): the second tier
@pytest.mark.parametrize("name", list(THREE))
def test_scheduled_between_frozen_optimum_and_robust_controller(name):
    """Issue 61 acceptance: the certified scheduled γ lies between the worst frozen-point
    optimum (hinfsyn's LMI lower bound at each design point: no scheduled controller can
    beat it there) and the γ of one LTI controller over the range (a full-order block
    tuned by hinfstruct on the plants at both ends and the middle, certified by hinfnorm
    on the 33-point dense grid).  Measured 2026-12-02 (lower, scheduled, robust):
    mass 0.240246, 0.246567, 0.283978; stiffness 0.24314, 0.24597, 0.248061; gain
    0.33649, 0.340308, 0.368504."""
    from lmi_suspension.lti import hinfnorm
    from lmi_suspension.tune import hinfstruct, tunable_ss

    P, grid, basis = THREE[name]
    lower = max(hinfsyn(P(v), 1, 1).gamma_lower for v in grid)
    res = lpvsyn(P, {"p": grid}, 1, 1, basis=basis)
    assert res.warnings == ()
    ends = grid[[0, grid.size // 2, -1]]
    block = _Repeated(tunable_ss("K", 2, 1, 1), ends.size)
    tuned = hinfstruct(_stacked([P(v) for v in ends]), block, ends.size, ends.size,
                       starts=3, rng=np.random.default_rng(0))
    K = block.b.ss(tuned.theta)
    robust = max(float(hinfnorm(lft(P(v), K))[0]) for v in res.check_grid["p"])
    assert lower <= res.gamma * (1.0 + 1e-6)               # a theorem (up to 1e-6)
    # not a theorem (the scheduled γ carries the 2 % back-off and the tuning is local):
    # measured margins 15 %, 0.85 %, 8.3 % (see above); the damping of the same
    # plant, c in [0.05, 1], is a counter-example: there one LTI controller reaches the
    # worst frozen optimum 0.242727 and the scheduled γ is 0.245556 (docs/guide/lpv.md)
    assert res.gamma < robust


# ------------------------------------------------------------------- (h) polytopic hinfgs
def _stiff(k):
    return msd(1.0, k=k)


def test_hinfgs_certified_for_any_rate_and_equal_to_the_gridded_lmi():
    """Issue 61 item 2: the stiffness enters A only (affine, B2 constant).  The vertex
    LMIs with one (R, S) are the gridded LMIs with basis [1] (the plant being affine, the
    LMIs at the vertices hold on the whole box): two routes to one optimum, to Clarabel's
    tolerance (measured 2026-12-02: 0.256240 both).  The closed loop's bounded-real
    inequality with the one Lyapunov matrix holds at every check point: a bound for
    parameters varying arbitrarily fast."""
    from lmi_suspension.lpv import hinfgs

    res = hinfgs(_stiff, {"k": (0.5, 4.0)}, 1, 1)
    grid = lpvsyn(_stiff, {"k": np.linspace(0.5, 4.0, 5)}, 1, 1, basis=lambda k: [1.0])
    assert res.gamma_lmi == pytest.approx(grid.gamma_lmi, rel=1e-4)
    assert res.warnings == ()
    assert res.check_grid["k"].size == 5 and np.all(res.lyapunov_check < 0.0)
    assert res.gamma <= res.K.level * (1.0 + 1e-6)
    # the schedule interpolates the vertex controllers: exact at the vertices
    a = res.K.weights(k=1.2)
    assert np.all(a >= 0.0) and a.sum() == pytest.approx(1.0, rel=1e-15)
    assert _same_ss(res.K.at(k=4.0), res.K.controllers[1])
    # and is a controller of the plant at any k: stable frozen loops
    for k in (0.5, 1.7, 4.0):
        assert np.max(np.linalg.eigvals(lft(_stiff(k), res.K.at(k=k)).A).real) < 0.0


def test_hinfgs_json_round_trip_is_exact(tmp_path):
    """Issue 61 item 3 for the polytopic controller: saved and loaded, the vertex
    controllers are the same IEEE-754 numbers, so ``at(p)`` is equal bit for bit at any
    ``p`` (it is computed from them and ``p`` alone), and the certified γ travels in the
    metadata."""
    import json

    from lmi_suspension.errors import InputError
    from lmi_suspension.io import (
        load_scheduled_controller,
        save_scheduled_controller,
        scheduled_from_dict,
        scheduled_to_dict,
    )
    from lmi_suspension.lpv import PolytopicController, hinfgs

    res = hinfgs(_stiff, {"k": (0.5, 4.0)}, 1, 1)
    path = save_scheduled_controller(tmp_path / "K.json", res)
    K, meta = load_scheduled_controller(path)
    assert isinstance(K, PolytopicController)
    assert json.loads(path.read_text())["format"] == "lmi_suspension.polytopic_controller/1"
    assert (K.names, K.bounds, K.vertices, K.level) == \
        (res.K.names, res.K.bounds, res.K.vertices, res.K.level)
    assert all(_same_ss(a, b) for a, b in zip(K.controllers, res.K.controllers))
    for k in (0.5, 1.2345678901234567, np.pi, 4.0):       # vertices and between them
        assert _same_ss(K.at(k=k), res.K.at(k=k))
    assert meta == {"gamma": res.gamma, "gamma_lmi": res.gamma_lmi}
    # the loaded controller's certificate is the saved one (the same loops, recomputed)
    k0 = float(res.check_grid["k"][1])
    assert float(hinfnorm(lft(_stiff(k0), K.at(k=k0)))[0]) == res.gamma_check[1]
    data = scheduled_to_dict(res.K)
    with pytest.raises(InputError, match="tables"):
        scheduled_to_dict(res.K, table={"k": [1.0]})
    del data["controllers"]
    with pytest.raises(InputError, match="controllers"):
        scheduled_from_dict(data)
    with pytest.raises(InputError, match="format"):
        scheduled_from_dict({"format": "something else"})


@pytest.mark.parametrize("P, bounds, err, text", [
    (msd, {"m": (1.0, 4.0)}, "AssumptionError", "B2 depends"),       # u acts through 1/m
    (lambda k: msd(1.0, k=k * k), {"k": (0.5, 2.0)}, "AssumptionError", "not affine"),
    (_stiff, {"k": (1.0, 1.0)}, "ParameterError", "not an interval"),
    (_stiff, {"k": (0.5, np.nan)}, "NonFiniteError", "finite"),
])
def test_hinfgs_typed_errors(P, bounds, err, text):
    from lmi_suspension import errors
    from lmi_suspension.lpv import hinfgs

    t = time.perf_counter()
    with pytest.raises(getattr(errors, err), match=text):
        hinfgs(P, bounds, 1, 1)
    assert time.perf_counter() - t < 1.0


# ------------------------------------------------------------------- (i) certificate 4(c)
#: the damping is not measured: c = 0.2 ± 2.8 (negative damping down to -2.6, an active
#: element); chosen so that the design that ignores it loses robust stability at the
#: light end of the mass range while the design that models it keeps a margin above 1
#: (design grid m = 1, 2.5, 4; exact margins at m = 1 and 4, measured 2026-12-02: 0.8486
#: and 1.8435 ignoring it, 1.3257 and 2.3123 modelling it)
C_RHO = 2.8


def _msd_matrices(m, c):
    return ([[0.0, 1.0], [-1.0 / m, -c / m]], [[0.0, 0.0, 0.0], [1.0 / m, 0.0, 1.0 / m]],
            [[1.0, 0.0], [0.0, 0.0], [1.0, 0.0]],
            [[0.0, 0.0, 0.0], [0.0, 0.0, 0.1], [0.0, 0.1, 0.0]])


def _msd_uncertain(m):
    from lmi_suspension.uncertain import ureal, uss

    return uss(*_msd_matrices(m, ureal("c", 0.2, plusminus=C_RHO)))


def _msd_with_delta_channel(m):
    """The design plant that models the damping: ``w_δ`` a force (``-δ · z_δ`` closes the
    uncertainty), ``z_δ = ρ ẋ``; inputs [w_δ, d, n, u], outputs [z_δ, x, 0.1 u, y].  An
    H∞ design keeps that channel's gain small (small gain: a margin for complex δ, so
    also for the real damping)."""
    P = msd(m)
    B = np.c_[[0.0, -1.0 / m], P.B]
    C = np.r_[[[0.0, C_RHO]], P.C]
    D = np.zeros((4, 4))
    D[1:, 1:] = P.D
    return control.ss(P.A, B, C, D)


def _closed_loop_by_hand(m, K):
    """The uncertain closed loop formed from the matrices (u = K y, D22 = 0), the damping
    entering only its (2, 2) state entry: another realization and another route than
    lpv_robstab's interconnection by signal names."""
    from lmi_suspension.uncertain import ureal, uss

    A, B, C, D = (np.asarray(M, dtype=float) for M in _msd_matrices(m, 0.0))
    B1, B2, C1, C2 = B[:, :2], B[:, 2:], C[:2], C[2:]
    D11, D12, D21 = D[:2, :2], D[:2, 2:], D[2:, :2]
    Ak, Bk, Ck, Dk = K.A, K.B, K.C, K.D
    Acl = np.block([[A + B2 @ Dk @ C2, B2 @ Ck], [Bk @ C2, Ak]])
    c = ureal("c", 0.2, plusminus=C_RHO)
    rows = [[float(v) for v in row] for row in Acl]
    rows[1][1] = rows[1][1] - c / m                      # the damping's only entry
    return uss(rows, np.vstack([B1 + B2 @ Dk @ D21, Bk @ D21]),
               np.hstack([C1 + D12 @ Dk @ C2, D12 @ Ck]), D11 + D12 @ Dk @ D21)


def _poles_with_damping(m, K, c):
    A, B, C, D = (np.asarray(M, dtype=float) for M in _msd_matrices(m, c))
    return lft(control.ss(A, B, C, D), K).poles()


def test_lpv_robstab_agrees_with_robstab_and_certifies_the_robust_design():
    """Issue 61, certificate 4(c): lpv_robstab's bounds at two points equal robstab's on
    the loop formed by hand (exact single-parameter route both: 1e-9), the design that
    models the damping is robustly stable at every point (margin > 1), and a brute-force
    sweep of the damping over its whole range confirms it at those points."""
    from lmi_suspension.lpv import LpvRobstabResult, lpv_robstab
    from lmi_suspension.uncertain import robstab

    design = lpvsyn(_msd_with_delta_channel, {"m": [1.0, 2.5, 4.0]}, 1, 1)
    rs = lpv_robstab(design, _msd_uncertain, {"m": [1.0, 4.0]})
    assert isinstance(rs, LpvRobstabResult) and rs.warnings == ()
    assert rs.points == ((1.0,), (4.0,))
    for (m,), lo, up in zip(rs.points, rs.lower, rs.upper):
        ref = robstab(_closed_loop_by_hand(m, design.K.at(m=m)))
        assert ref.method == "exact"
        assert lo == pytest.approx(ref.lower, rel=1e-9)
        assert up == pytest.approx(ref.upper, rel=1e-9)
        # brute force: the loop built with numbers is stable over the damping's range
        for c in np.linspace(0.2 - C_RHO, 0.2 + C_RHO, 57):
            assert np.max(_poles_with_damping(m, design.K.at(m=m), c).real) < 0.0
    # measured 2026-12-02: 1.3257 (m = 1), 2.3123 (m = 4), see C_RHO
    assert rs.robust and rs.margin_lower == pytest.approx(np.min(rs.lower), rel=0)
    assert rs.margin_lower > 1.0 and rs.worst == {"m": 1.0}


def test_lpv_robstab_finds_the_design_that_ignores_the_uncertainty():
    """The nominal design (the damping at 0.2) is not robustly stable at m = 1: its
    margin is below 1, and the destabilising damping robstab returns puts a closed-loop
    pole on the imaginary axis (checked with the loop built with numbers)."""
    from lmi_suspension.lpv import lpv_robstab

    design = lpvsyn(msd, {"m": [1.0, 2.5, 4.0]}, 1, 1)
    rs = lpv_robstab(design, _msd_uncertain, {"m": [1.0, 4.0]})
    assert not rs.robust and rs.margin_lower < 1.0 and rs.worst == {"m": 1.0}
    assert rs.lower[1] > 1.0                           # robust at m = 4 (1.84, see C_RHO)
    c = float(rs.worst_uncertainty["c"])
    assert abs(c - 0.2) <= C_RHO * rs.margin_upper * (1.0 + 1e-9) < C_RHO
    assert np.max(_poles_with_damping(1.0, design.K.at(m=1.0), c).real) >= -1e-6


def test_lpv_robstab_typed_errors(linear):
    from lmi_suspension.errors import InputError
    from lmi_suspension.lpv import lpv_robstab

    t = time.perf_counter()
    with pytest.raises(ParameterError, match="outside"):
        lpv_robstab(linear, _msd_uncertain, {"m": [0.5, 2.0]})
    with pytest.raises(ParameterError, match="parameters"):
        lpv_robstab(linear, _msd_uncertain, {"k": [1.0]})
    with pytest.raises(InputError, match="callable"):
        lpv_robstab(linear, None)
    with pytest.raises(InputError, match="scheduled controller"):
        lpv_robstab(msd(1.0), _msd_uncertain, {"m": [1.0]})
    assert time.perf_counter() - t < 1.0

