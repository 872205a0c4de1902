"""Uncertain models (ureal/ultidyn, LFT arithmetic, reduction, usubs) and robstab/wcgain.

Reference values and their sources:
- usubs: the same plants built directly with numbers (tests/uncertain_plants.py), compared
  by transfer-function values at several s.
- robstab, x'' + c x' + k x: stable iff c > 0 and k > 0 (second-order Routh-Hurwitz);
  third order s^3 + a s^2 + b s + c: stable iff a, c > 0 and a b > c, which gives the
  margin 5 - sqrt(13) in closed form (tests/uncertain_plants.py).
- robstab, one real parameter (coupled_modes below): a dense sweep of the closed-loop
  eigenvalues of the matrix built with numbers, then bisection, in the test itself;
  x'' + c x' + x with c = 1 + 2δ: exact margin 1/2 (c = 0), the robstab docstring.
- ultidyn: small-gain theorem, margin = 1 / (bound ‖G‖∞) for one SISO full block.
- wcgain: 1/(s^2 + 2 ζ s + 1) peaks at 1/(2 ζ sqrt(1 - ζ^2)) (ζ < 1/sqrt 2), largest at
  the smallest ζ.
Brute-force comparisons (grids of the box) are in the slow tests at the end.
"""

import time

import control
import numpy as np
import pytest

from lmi_suspension.errors import AssumptionError, NonFiniteError, ParameterError
from lmi_suspension.lti import hinfnorm
from lmi_suspension.lti.norms import freqresp
from lmi_suspension.uncertain import (connect, feedback, lftdata, nominal, robstab, ucomplex,
                                      ultidyn, ureal, usample, uss, usubs, wcgain)
from uncertain_plants import (PLANTS, THIRD_MARGIN, brute_margin, brute_wcgain,
                              lag_loop_uncertain, physical, third_uncertain)

S_POINTS = [0.0, 0.3j, 1j, 2.5j, 1 + 2j, 10j]
W60 = np.logspace(-2, 2, 60)


def snippet():
    k = ureal("k", 1.0, plusminus=0.4)
    m = ureal("m", 1.0, plusminus=0.3)
    A = [[0, 1], [-k / m, -0.1 / m]]
    return uss(A, [[0], [1 / m]], [[1, 0]], [[0]])


def tf_close(P, D, rtol=1e-10):
    for s in S_POINTS:
        a, b = np.asarray(P(s)), np.asarray(D(s))
        assert np.allclose(a, b, rtol=rtol, atol=1e-12), (s, a, b)


# ---------------------------------------------------------------- models
def test_snippet_minimal_repetitions_and_usubs():
    G = snippet()
    d = lftdata(G)
    assert d.names == ("k", "m")
    assert d.blk.to_blk().tolist() == [[-1, 0], [-1, 0]]  # k:1, m:1
    P = usubs(G, {"k": 1.2, "m": 0.9})
    assert isinstance(P, control.StateSpace)
    tf_close(P, control.ss([[0, 1], [-1.2 / 0.9, -0.1 / 0.9]], [[0], [1 / 0.9]], [[1, 0]], [[0]]))


def test_reduction_keeps_needed_repetitions():
    k = ureal("k", 1.0, plusminus=0.2)
    # diag(k, k) needs k twice (rank 2); a rank-one use needs it once
    two = uss([[-k, 0], [0, -k]], np.eye(2), np.eye(2), np.zeros((2, 2)))
    one = uss([[-k, -k], [0, -1]], np.eye(2), np.eye(2), np.zeros((2, 2)))
    assert lftdata(two).blk.to_blk().tolist() == [[-2, 0]]
    assert lftdata(one).blk.to_blk().tolist() == [[-1, 0]]
    tf_close(usubs(one, {"k": 1.1}), control.ss([[-1.1, -1.1], [0, -1]], np.eye(2), np.eye(2), 0))
    # k - k has no uncertainty left
    assert lftdata(uss([[-1 + k - k]], [[1]], [[1]], [[0]])).blk is None


@pytest.mark.parametrize("name", ["two-mass spring-damper (k, m2)", "mass-spring + lag + PD loop (m, tau)"])
def test_usubs_equals_direct_model(name):
    unc, direct, spec = PLANTS[name]
    G = unc()
    rng = np.random.default_rng(7)
    for _ in range(4):
        vals = {n: physical(spec, n, rng.uniform(-1.5, 1.5)) for n in spec}
        tf_close(usubs(G, vals), control.ss(*direct(*vals.values())))


def test_lftdata_closes_to_usubs():
    """F_u(M, Δ) at normalised δ, evaluated by hand, equals usubs at the physical value."""
    G = lag_loop_uncertain()
    d = lftdata(G)
    dv = {"m": 0.7, "tau": -0.4}
    Delta = np.diag(np.concatenate([np.full(b[0] * -1, dv[n]) for b, n in zip(d.blk.to_blk(), d.names)]))
    vals = {n: d.atoms[i].value(dv[n]) for i, n in enumerate(d.names)}
    P = usubs(G, vals)
    for s in S_POINTS[1:]:
        M = np.asarray(d.M(s)).reshape(d.M.noutputs, d.M.ninputs)
        M11, M12, M21, M22 = M[:d.nz, :d.nw], M[:d.nz, d.nw:], M[d.nz:, :d.nw], M[d.nz:, d.nw:]
        Fu = M22 + M21 @ Delta @ np.linalg.solve(np.eye(d.nz) - M11 @ Delta, M12)
        assert np.allclose(Fu, np.asarray(P(s)).reshape(Fu.shape), rtol=1e-10)


def test_connect_equals_feedback():
    m = ureal("m", 1.0, plusminus=0.3)
    P = uss([[0, 1], [-1 / m, -0.2 / m]], [[0], [1 / m]], [[1, 0]], [[0]], inputs=["u"], outputs=["y"])
    S = control.summing_junction(inputs=["r", "-y"], output="e")
    C = control.ss([], [], [], [[3.0]], inputs="e", outputs="u")
    T1 = connect([P, S, C], inputs=["r"], outputs=["y"])
    T2 = feedback(P * 3.0, 1)
    for v in (0.75, 1.2):
        tf_close(usubs(T1, {"m": v}), usubs(T2, {"m": v}))
    direct = control.feedback(control.ss([[0, 1], [-1 / 1.2, -0.2 / 1.2]], [[0], [1 / 1.2]], [[1, 0]], 0) * 3.0, 1)
    tf_close(usubs(T1, {"m": 1.2}), direct)


def test_asymmetric_range_map_and_usubs():
    m = ureal("m", 1.0, range=(0.5, 3.0))
    assert [m.value(d) for d in (-1.0, 0.0, 1.0)] == pytest.approx([0.5, 1.0, 3.0], rel=1e-14)
    d = np.linspace(-1, 1, 11)
    assert np.all(np.diff(m.value(d)) > 0)  # monotone on the box
    G = uss([[-1 / m]], [[1]], [[1]], [[0]])
    tf_close(usubs(G, {"m": 2.2}), control.ss([[-1 / 2.2]], [[1]], [[1]], [[0]]))
    assert ureal("p", 2.0, percent=(10, 30)).hi == pytest.approx(2.6)


def test_ultidyn_and_nominal_and_usample():
    D = ultidyn("D", (1, 1), bound=0.5)
    P = control.tf([1], [1, 1])
    G = uss(P * (1 + D))
    assert lftdata(G).blk.to_blk().tolist() == [[1, 1]]
    dval = control.tf([0.4], [1, 2])
    tf_close(usubs(G, {"D": dval}), P * (1 + dval))
    tf_close(nominal(G), control.ss(P))
    s1, v1 = usample(snippet(), 5, np.random.default_rng(3))
    s2, v2 = usample(snippet(), 5, np.random.default_rng(3))
    assert v1 == v2 and all(0.6 <= v["k"] <= 1.4 and 0.7 <= v["m"] <= 1.3 for v in v1)
    tf_close(s1[2], usubs(snippet(), v1[2]))


# ---------------------------------------------------------------- errors
@pytest.mark.parametrize("build, err, text", [
    (lambda: ureal("kappa", 1.0, range=(1.5, 2.0)), ParameterError, "kappa"),
    (lambda: ureal("kappa", 1.0, range=(1.0, 1.0)), ParameterError, "zero width"),
    (lambda: ureal("kappa", 0.0, percent=10), ParameterError, "kappa"),
    (lambda: ureal("kappa", float("nan"), plusminus=1), NonFiniteError, "kappa"),
    (lambda: ureal("kappa", 1.0, plusminus=float("inf")), NonFiniteError, "kappa"),
    (lambda: ureal("kappa", 1.0), ParameterError, "exactly one"),
    (lambda: ureal("kappa", 1.0, plusminus=0.1) + ureal("kappa", 1.0, plusminus=0.2), ParameterError, "kappa"),
    (lambda: usubs(snippet(), {"q": 1.0}), ParameterError, "'q'"),
    (lambda: usubs(snippet(), {"k": float("nan")}), NonFiniteError, "'k'"),
    (lambda: ucomplex("zeta", 1.0, -0.1), ParameterError, "zeta"),
])
def test_bad_input_is_a_typed_error_naming_the_parameter(build, err, text):
    t0 = time.perf_counter()
    with pytest.raises(err, match=text) as raised:
        build()
    assert time.perf_counter() - t0 < 1.0
    assert isinstance(raised.value, ValueError)  # what was raised, not the table's entry


def test_robstab_refuses_unstable_nominal():
    k = ureal("k", -1.0, plusminus=0.1)
    with pytest.raises(AssumptionError, match="not stable"):
        robstab(uss([[0, 1], [-k, -1]], [[0], [1]], [[1, 0]], [[0]]))


# ---------------------------------------------------------------- robstab / wcgain (closed forms)
def test_robstab_snippet_real_pole_at_zero():
    """k = 1 - 0.4 α reaches 0 at α = 2.5 (a pole at s = 0), before m = 0 at α = 10/3."""
    r = robstab(snippet(), W60)
    assert r.lower <= r.upper
    assert r.lower <= 2.5 * (1 + 1e-9) and r.upper >= 2.5 * (1 - 1e-9)
    assert r.upper / r.lower - 1 < 0.05
    assert r.critical_frequency == pytest.approx(0.0, abs=1e-6)
    assert r.worst["k"] == pytest.approx(0.0, abs=1e-8) and r.checked
    assert np.max(usubs(snippet(), dict(r.worst)).poles().real) >= -1e-7


def test_robstab_third_order_closed_form():
    G = third_uncertain()
    r = robstab(G, W60)
    assert r.lower <= r.upper
    assert r.lower <= THIRD_MARGIN * (1 + 1e-6) and r.upper >= THIRD_MARGIN * (1 - 1e-6)
    assert r.upper / r.lower - 1 < 0.05
    p = usubs(G, dict(r.worst)).poles()
    k = np.argmax(p.real)
    assert p[k].real >= -1e-7 and abs(p[k].imag) == pytest.approx(r.critical_frequency, rel=1e-5)
    # the Routh boundary a b = c at the worst values
    a, b, c = (r.worst[n] for n in "abc")
    assert a * b == pytest.approx(c, rel=1e-6)


def test_robstab_ultidyn_small_gain():
    """One full dynamic block: by the small-gain theorem (exact for an unstructured
    block) the margin is 1 / (bound ‖P‖∞), with ‖P‖∞ in closed form: |P(jω)|² =
    4 / ((4 - ω²)² + ω²/4) peaks at ω² = 4 - 1/8, so ‖P‖∞ = 2 / sqrt(1/64 + 3.875/4).
    The bounds must bracket it: a lower bound above it, or an upper bound below it, is
    wrong (measured 2026-12-01, Haswell and Sandybridge: lower 4.4e-15 above it, its
    peak search's roundoff, and upper 2.0 % above it; 1e-9 allowed for roundoff)."""
    P = control.tf([2.0], [1, 0.5, 4])
    D = ultidyn("D", (1, 1), bound=0.25)
    T = feedback(uss(P), D)
    gP = 2.0 / np.sqrt(1 / 64 + 3.875 / 4)  # the closed form above
    assert hinfnorm(P)[0] == pytest.approx(gP, rel=1e-9)
    margin = 1 / (0.25 * gP)
    r = robstab(T, W60)
    assert r.lower <= r.upper
    assert r.lower <= margin * (1 + 1e-9) and r.upper >= margin * (1 - 1e-9)
    assert r.upper / r.lower - 1 < 0.05 and r.checked


def test_wcgain_damping_closed_form():
    z = ureal("zeta", 0.3, plusminus=0.1)
    G = uss([[0, 1], [-1, -2 * z]], [[0], [1]], [[1, 0]], [[0]])
    g = wcgain(G, W60)
    exact = 1 / (2 * 0.2 * np.sqrt(1 - 0.2**2))
    assert g.lower <= exact * (1 + 1e-6) <= g.upper * (1 + 1e-6) + 1e-12
    assert g.lower == pytest.approx(exact, rel=1e-6)
    assert g.upper / g.lower - 1 < 0.05
    assert hinfnorm(usubs(G, dict(g.worst)))[0] == pytest.approx(g.lower, rel=1e-9)
    assert g.worst["zeta"] == pytest.approx(0.2)


def test_wcgain_unstable_in_box_is_infinite():
    c = ureal("c", 1.0, plusminus=1.5)
    g = wcgain(uss([[0, 1], [-1, -c]], [[0], [1]], [[1, 0]], [[0]]), W60)
    assert g.lower == np.inf and g.upper == np.inf


# ---------------------------------------------------------------- robstab, one real parameter
#: two lightly damped modes (1 and 3.5 rad/s) coupled by one real parameter through the
#: rank-one term δ b cᵀ.  Its crossing (0.80 rad/s) falls between the default grid's
#: frequencies, where the grid's µ bound alone read 1/0.2621 (margin 0.2621 above the
#: true 0.2386, 2026-11-27): the defect the exact route fixes.
Z1, Z2, W2 = 0.08, 0.05, 3.5
B_COUPLE = np.array([-0.78, 0.75, 1.63, 0.27])
C_COUPLE = np.array([0.42, 1.14, 0.11, -0.55])
A_MODES = np.array([[0, 1, 0, 0], [-1, -2 * Z1, 0, 0], [0, 0, 0, 1], [0, 0, -W2**2, -2 * Z2 * W2]])


def coupled_modes(output_gain=None):
    """The uncertain model (δ = d, nominal 0, ±1); ``output_gain`` an optional second
    parameter on the output, which cannot change stability."""
    d = ureal("d", 0.0, plusminus=1.0)
    A = [[A_MODES[i, j] + B_COUPLE[i] * C_COUPLE[j] * d for j in range(4)] for i in range(4)]
    g = 1.0 if output_gain is None else output_gain
    return uss(A, [[0], [1], [0], [0]], [[g, 0, 0, 0]], [[0]])


def coupled_modes_brute_margin(points=4001):
    """Independent reference: dense sweep of |δ| on both sides of the matrix built with
    numbers, then bisection of the first unstable interval (abscissa >= 0)."""
    def unstable(dv):
        return np.max(np.linalg.eigvals(A_MODES + dv * np.outer(B_COUPLE, C_COUPLE)).real) >= 0

    best = np.inf
    for s in (1.0, -1.0):
        ts = np.linspace(0.0, 2.0, points)
        bad = [t for t in ts if unstable(s * t)]
        if not bad:
            continue
        hi = bad[0]
        lo = hi - ts[1]
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if unstable(s * mid) else (mid, hi)
        best = min(best, hi)
    return best


def test_robstab_single_real_exact_where_the_grid_steps_over_the_crossing():
    G = coupled_modes()
    r = robstab(G)
    bm = coupled_modes_brute_margin()
    assert r.method == "exact" and not r.warnings
    assert r.lower <= bm * (1 + 1e-9) and bm <= r.upper * (1 + 1e-9)
    assert r.upper - r.lower <= 1e-9 * r.upper
    # the grid alone was wrong here: its µ peak gives a "margin" above the true one
    assert 1.0 / np.max(r.mu_upper) > bm * 1.05
    # the worst value is checked with the matrix built with numbers
    p = np.linalg.eigvals(A_MODES + r.worst["d"] * np.outer(B_COUPLE, C_COUPLE))
    k = np.argmax(p.real)
    assert abs(p[k].real) <= 1e-7 and abs(p[k].imag) == pytest.approx(r.critical_frequency, rel=1e-6)


def test_robstab_docstring_example_is_exact():
    """x'' + c x' + x, c = 1 + 2δ: a pole pair at ±j exactly when c = 0, δ = -1/2."""
    c = ureal("c", 1.0, plusminus=2.0)
    r = robstab(uss([[0, 1], [-1, -c]], [[0], [1]], [[1, 0]], [[0]]))
    assert r.method == "exact" and r.checked
    assert r.lower <= 0.5 <= r.upper * (1 + 1e-12)
    assert r.upper - r.lower <= 1e-9
    assert r.worst["c"] == pytest.approx(0.0, abs=1e-8)
    assert r.critical_frequency == pytest.approx(1.0, rel=1e-6)


def test_robstab_no_crossing_is_an_infinite_exact_margin():
    """x' = -(a² + 1) x: the pole is below -1 for every real a (a repeated twice)."""
    a = ureal("a", 2.0, plusminus=1.0)
    r = robstab(uss([[-a * a - 1]], [[1]], [[1]], [[0]]))  # -(a² + 1) < 0 for every real a
    # (rounding-error roots far out are not examined: "at least 1000 times the range")
    assert r.method == "exact" and r.lower >= 1000.0 and r.upper == np.inf


def _second_order(k, c):
    """x'' + c x' + k x = u, y = x (Routh-Hurwitz: stable iff c > 0 and k > 0)."""
    return uss([[0, 1], [-k, -c]], [[0], [1]], [[1, 0]], [[0]])


@pytest.mark.parametrize("build, margin, bracket, rtol", [
    # k = 1 + 3δ reaches 0 at δ = -1/3 (a real pole crosses at s = 0); c stays positive:
    # one side crosses, the other only has rounding-error roots
    (lambda d: _second_order(1 + 3 * d, 1 + d * d), 1 / 3, 1e-12, 1e-8),
    (lambda d: _second_order(1 + 3 * d, (2 * d - 1) * (2 * d - 1) + 0.1), 1 / 3, 1e-12, 1e-8),
    # c = (2δ - 1)² touches 0 at δ = 1/2 without changing sign: a pole pair touches ±j.
    # A double root is computed to about sqrt(eps): 5.8e-9 (Haswell) and 1.2e-8
    # (Nehalem) below 1/2, measured 2026-11-27, hence rtol 1e-7 there
    (lambda d: _second_order(1, (2 * d - 1) * (2 * d - 1)), 0.5, 1e-6, 1e-7),
])
def test_robstab_exact_on_one_sided_and_touching_crossings(build, margin, bracket, rtol):
    """Routh-Hurwitz gives each margin; the exact route must take them (it examined
    rounding-error roots far out on the side without a crossing and gave up, found in
    review 2026-11-27)."""
    r = robstab(build(ureal("d", 0.0, plusminus=1.0)))
    assert r.method == "exact" and not r.warnings
    assert r.lower <= margin * (1 + rtol) and margin * (1 - rtol) <= r.upper
    assert r.upper - r.lower <= bracket * r.upper * 1.01


def test_robstab_no_crossing_within_the_examined_range():
    """c = (2δ - 1)² + 1e-3 > 0 for every real δ: no crossing; roots beyond 1000 times
    the range are not examined (rounding alone makes the loop look unstable there), so
    the margin is reported as at least 1000."""
    d = ureal("d", 0.0, plusminus=1.0)
    r = robstab(_second_order(1, (2 * d - 1) * (2 * d - 1) + 1e-3))
    assert r.method == "exact" and r.lower == 1000.0 and r.upper == np.inf


def test_robstab_static_loop_loses_well_posedness():
    """y = 2 u / (1 - 2 δ)-type static loop: ill posed at |δ| = 1/2 (no states, so the
    grid route; it read 0.5 against a checked 0.49999999995, which must not be returned
    as lower > upper)."""
    r = robstab(feedback(uss(control.ss([], [], [], [[2.0]])), ureal("d", 0.0, plusminus=1.0)))
    assert r.lower <= r.upper
    assert r.lower == pytest.approx(0.5, rel=1e-8) and r.upper == pytest.approx(0.5, rel=1e-8)


@pytest.mark.parametrize("route", ["auto", "lmi"])
def test_robstab_grid_contradiction_is_never_returned(monkeypatch, route):
    """Two parameters (the exact route does not apply); the output gain g cannot change
    stability, so the margin is the single-parameter one.  With the LMI upper bound the
    grid, as above, reads a µ peak below the checked perturbation: it must be refined or
    withdrawn, and said.  ``mussv``'s "auto" takes AB13MD on this structure, which does
    not read it so; the LMI route is forced to inject the contradiction."""
    from lmi_suspension.mu import BlockStructure
    from lmi_suspension.uncertain import analysis

    if route == "lmi":
        real = analysis.mussv

        def lmi_mussv(M, blk, **kw):
            if BlockStructure.coerce(blk).has_real:
                kw.setdefault("method", "lmi")
            return real(M, blk, **kw)

        monkeypatch.setattr(analysis, "mussv", lmi_mussv)
    G = coupled_modes(ureal("g", 1.0, plusminus=0.1))
    r = robstab(G)
    bm = coupled_modes_brute_margin()
    assert r.method == "grid" and r.checked
    assert r.lower <= r.upper and r.lower <= bm * (1 + 1e-9)
    assert r.upper == pytest.approx(bm, rel=1e-6)
    if route == "lmi":
        assert r.warnings and "exceeded the checked perturbation" in r.warnings[0]


# ---------------------------------------------------------------- brute force (slow)
@pytest.mark.slow
@pytest.mark.parametrize("name", list(PLANTS))
def test_robstab_against_brute_force(name):
    unc, direct, spec = PLANTS[name]
    G = unc()
    r = robstab(G)
    assert r.lower <= r.upper
    bm = brute_margin(direct, spec, points=41 if len(spec) < 3 else 21)
    # the grid's margin is an upper bound of the true one, within the grid's resolution
    assert r.lower <= bm * (1 + 1e-6)
    assert r.upper <= bm * (1 + 1e-6) and r.upper >= bm * (1 - 0.02)
    assert r.upper / r.lower - 1 < 0.05
    assert np.max(usubs(G, dict(r.worst)).poles().real) >= -1e-7


@pytest.mark.slow
@pytest.mark.parametrize("name", list(PLANTS))
def test_wcgain_against_brute_force(name):
    unc, direct, spec = PLANTS[name]
    G = unc()
    g = wcgain(G)
    bg = brute_wcgain(direct, spec, points=21 if len(spec) < 3 else 9)
    assert g.upper >= bg * (1 - 1e-6)         # the grid's worst is attained: below the bound
    assert g.lower >= bg * (1 - 1e-3)          # our search does at least as well as the grid
    assert g.upper / g.lower - 1 < 0.05
    assert hinfnorm(usubs(G, dict(g.worst)))[0] == pytest.approx(g.lower, rel=1e-9)


def test_reduction_keeps_a_parameter_beside_large_certain_dynamics():
    """The structured reduction decides each block's rank relative to that block's own
    rows: a parameter entering with O(1) coefficients beside a certain part with entries
    of 1e12 (as a D-G-K controller's states) stays in the model, and usubs still equals
    the model built with numbers (with a tolerance relative to the whole realization,
    the parameter was dropped from such a closed loop, 2026-11-27)."""
    a = ureal("a", -2.0, plusminus=0.5)
    fast = control.ss([[-1e12]], [[1e12]], [[1e12]], [[0.0]])
    G = uss([[a]], [[1.0]], [[1.0]], [[0.0]]) + fast
    assert lftdata(G).names == ("a",)
    w = np.logspace(-1, 1, 7)
    for value in (-2.5, -1.7):
        direct = control.ss([[value]], [[1.0]], [[1.0]], [[0.0]]) + fast
        np.testing.assert_allclose(freqresp(usubs(G, {"a": value}), w), freqresp(direct, w),
                                   rtol=1e-9)


# ---------------------------------------------------------------- mutation pass (issue 59)
def test_a_repeated_multivariable_ultidyn_is_refused_and_a_scalar_one_repeats():
    """A 1x2 ultidyn entering twice (``D + D``) has no LFT with one full block: refused,
    naming it; a SISO one entering twice is the repeated block ``[2, 0]`` (lfr's
    ``UBlock.blk_row``)."""
    D = ultidyn("D", (1, 2))
    with pytest.raises(ParameterError, match="ultidyn 'D' .1x2. enters the model 2 times"):
        D + D
    E = ultidyn("E", (1, 1))
    assert lftdata(uss([[E, 0], [0, E]])).blk.to_blk().tolist() == [[2, 0]]


@pytest.mark.parametrize("shape, bound", [((1, 1), 0.25), ((2, 2), 0.5)])
def test_usample_draws_ultidyn_values_within_the_bound(shape, bound):
    """``usample``'s docstring: an ultidyn is a gain of norm <= bound times an all-pass,
    so every sample's H∞ norm (hinfnorm, here) is at most the bound; the draws fill the
    ball (largest of 20 above half the bound: 0.974 and 0.992 of it, measured
    2026-12-01)."""
    D = ultidyn("D", shape, bound=bound)
    systems, values = usample(uss(D), 20, np.random.default_rng(5))
    norms = [hinfnorm(s)[0] for s in systems]
    assert max(norms) <= bound * (1 + 1e-9) and max(norms) > 0.5 * bound
    assert all(v["D"] is not None for v in values)


@pytest.mark.parametrize("A", [lambda k: [[0, 1], [0, -k]], lambda k: [[0, 1], [-k, 0]]],
                         ids=["pole at 0", "poles at ±j"])
def test_robstab_refuses_a_nominal_pole_on_the_imaginary_axis(A):
    """x'' = -k x' has poles 0 and -k, x'' = -k x the pair ±j sqrt(k) (k = 1 nominal):
    not stable, so no margin exists; both are refused, not analysed."""
    k = ureal("k", 1.0, plusminus=0.1)
    with pytest.raises(AssumptionError, match="not stable"):
        robstab(uss(A(k), [[0], [1]], [[1, 0]], [[0]]))


def test_wcgain_upper_bounds_the_gain_at_a_complex_perturbation():
    """1/(s² + 0.2 s + a), ``a = 1 + 0.1 δ`` complex: at ω = 1 (a grid frequency, the
    nominal poles' magnitude) the gain is 1/|0.2 j + 0.1 δ|, which δ = -j makes
    1/(0.2 - 0.1) = 10; the upper bound must be at least that (a closed form the µ
    bounds do not use).  Real values of δ reach only about 5.3 there (the lower bound's
    search): the two are apart, so the upper bound is the skewed-µ bisection's, not
    the lower bound's level (measured 10.08 and 5.30, 2026-12-01)."""
    a = ucomplex("a", 1.0, 0.1)
    g = wcgain(uss([[0, 1], [-a, -0.2]], [[0], [1]], [[1, 0]], [[0]]))
    assert g.lower <= g.upper and np.isfinite(g.upper)
    assert g.upper >= 10.0 * (1 - 1e-9)


def test_robstab_reports_an_ultidyn_worst_case_in_physical_units():
    """feedback(P, Δ) = P/(1 + P Δ) loses stability where 1 + P(jω) Δ(jω) = 0.  The
    reported ``worst["D"]`` is Δ(jω_c) itself (physical: normalised size ``upper`` times
    the bound 0.5), and 1 + P(jω_c) worst vanishes, with P's response evaluated here
    (measured 6e-16, 2026-12-01; 1e-9 allowed)."""
    P = control.tf([1.0], [1, 0.4, 2])
    D = ultidyn("D", (1, 1), bound=0.5)
    r = robstab(feedback(uss(P), D))
    delta = complex(np.asarray(r.worst["D"]).ravel()[0])
    assert abs(delta) == pytest.approx(r.upper * 0.5, rel=1e-9)
    assert abs(1 + complex(P(1j * r.critical_frequency)) * delta) <= 1e-9


def test_robstab_exact_takes_the_nearer_of_crossings_on_both_sides():
    """x'' + c x' + x with c = (1 + 2δ)(1 - δ): stable iff c > 0 (Routh-Hurwitz), so the
    loop crosses at δ = 1 and at δ = -1/2, and the margin is the nearer, 1/2, at
    c = 0 (the pole pair at ±j)."""
    d = ureal("d", 0.0, plusminus=1.0)
    r = robstab(_second_order(1, (1 + 2 * d) * (1 - d)))
    assert r.method == "exact" and not r.warnings
    assert r.lower <= 0.5 * (1 + 1e-9) and 0.5 * (1 - 1e-9) <= r.upper
    assert r.worst["d"] == pytest.approx(-0.5, abs=1e-9)
    assert r.critical_frequency == pytest.approx(1.0, rel=1e-6)
