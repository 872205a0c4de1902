"""The seat's µ design with hard force and stroke bounds (issue 17).

The shipped controller (``lmi-suspension design-constrained``) is checked by computations
that did not produce it: µ bounds by ``mussv`` on a grid of its own, the worst-case force
and stroke by the closed loop's Gramian, its poles, the Tustin map recomputed by
python-control, and exact-delay simulations of the continuous and the 1 kHz sampled-data
loop on the paper's bump.
"""

from dataclasses import replace

import control
import numpy as np
import pytest

from lmi_suspension.errors import InfeasibleError, ParameterError
from lmi_suspension.seat.constrained import (CONSTRAINED_MUSYN, SHIPPED_CONTROLLER,
                                             design_constrained_mu, load_constrained)
from lmi_suspension.seat.mucheck import certify_constrained
from lmi_suspension.seat.roads import bump
from lmi_suspension.seat.sampled import simulate_sampled
from lmi_suspension.seat.simulate import closed_loop_stable, simulate

DELAYS = (0.0, 0.005, 0.01, 0.015, 0.02, 0.025)


@pytest.fixture(scope="module")
def shipped():
    K, Kd, meta = load_constrained()
    return K, Kd, meta, certify_constrained(K)


def test_shipped_file_is_the_package_data():
    assert SHIPPED_CONTROLLER.is_file()


def test_shipped_bounds_hold_on_the_loop_recomputed_here(shipped):
    K, Kd, meta, check = shipped
    # the worst case over every floor velocity of the bump's energy, from the Gramian
    assert check.u_peak <= meta["u_bound"] * (1 + 5e-3)
    assert check.x1_peak <= meta["z_bound"] * (1 + 5e-3)
    assert check.fastest_pole < meta["disk_radius"]
    # µ on this grid (300 points) against the design's dense grid: the same peak within
    # the grids' difference, lower <= upper
    assert check.mu_lower_peak <= check.mu_peak * (1 + 1e-6)
    assert check.mu_peak == pytest.approx(meta["mu_peak_upper"], rel=0.03)


def test_shipped_discrete_realization_is_the_tustin_map(shipped):
    K, Kd, _, _ = shipped
    assert Kd.dt == 1e-3
    ref = control.sample_system(K, 1e-3, method="bilinear")
    for w in (1.0, 30.0, 300.0):
        z = np.exp(1j * w * 1e-3)
        assert np.allclose(np.asarray(Kd(z)), np.asarray(ref(z)), rtol=1e-8)


@pytest.mark.parametrize("delay", DELAYS)
def test_shipped_controller_on_the_bump(shipped, delay):
    """Issue 17's acceptance per delay: the linear loop (no clipping) stays within the
    1500 N actuator and the 0.08 m stroke, and the 1 kHz sampled-data loop reproduces
    the continuous loop's peak within 5 %."""
    K, Kd, _, _ = shipped
    assert closed_loop_stable(K, delay)
    cont = simulate(K, bump(), delay=delay, u_max=np.inf)
    assert np.max(np.abs(cont.u_command)) <= 1500.0
    assert np.max(np.abs(cont.x1)) <= 0.08
    sampled = simulate_sampled(Kd, bump(), delay=delay)  # clipping at 1500 N on
    peak_c, peak_s = np.max(np.abs(cont.z3dd)), np.max(np.abs(sampled.z3dd))
    assert abs(peak_s - peak_c) <= 0.05 * peak_c
    assert sampled.saturated_fraction == 0.0


@pytest.mark.slow  # 95 s on Zen 1 (2026-12-02): the second tier
def test_design_without_the_disk_meets_its_bounds():
    """One K-step without the pole disk (about 10 s): every figure recomputed by
    certify_constrained, which shares no code with the synthesis's own certificates."""
    d = design_constrained_mu(4000.0, 0.16, disk_radius=None,
                              musyn_options=replace(CONSTRAINED_MUSYN, max_iter=1))
    assert all(c.met for c in d.musyn.certificates)
    check = certify_constrained(d.K)
    assert check.u_peak <= 4000.0 * (1 + 5e-3) and check.x1_peak <= 0.16 * (1 + 5e-3)
    assert check.u_peak == pytest.approx(d.u_peak, rel=1e-6)
    assert np.isinf(d.disk_radius)


@pytest.mark.parametrize("kwargs", [dict(u_bound=0.0), dict(z_bound=-1.0),
                                    dict(disk_radius=np.nan), dict(energy=0.0)])
def test_bad_bounds_are_typed_errors(kwargs):
    with pytest.raises(ParameterError):
        design_constrained_mu(**kwargs)


@pytest.mark.slow  # 26 s on Zen 1 (2026-12-02): the second tier
def test_bounds_no_controller_meets_are_infeasible():
    # 1 N of force cannot hold the stroke below 1 cm (the passive seat's worst case for
    # the bump's energy is 6.4 cm)
    with pytest.raises(InfeasibleError):
        design_constrained_mu(1.0, 0.01, disk_radius=None)


# --- the trade-off (issue 17, item 6) -------------------------------------------------

@pytest.fixture
def stand_in_designs(monkeypatch, shipped):
    """design_constrained_mu replaced by the shipped design at every bound (the real one
    takes minutes): the trade-off's own work -- the bump simulations -- is what is tested."""
    import lmi_suspension.seat.constrained as mod

    K, Kd, meta, check = shipped
    asked = []

    def fake(u_bound, z_bound, **kw):
        from types import SimpleNamespace

        asked.append((u_bound, z_bound, kw.get("disk_radius")))
        return mod.ConstrainedMuDesign(
            K=K, Kd=Kd, musyn=SimpleNamespace(history=(), stop_reason="stand-in"),
            mu_peak=check.mu_peak, mu_lower_peak=check.mu_lower_peak, u_bound=u_bound,
            z_bound=z_bound, energy=check.energy, disk_radius=np.inf, u_peak=check.u_peak,
            x1_peak=check.x1_peak, fastest_pole=check.fastest_pole,
            controller_fastest_pole=check.controller_fastest_pole, seconds=1.0)

    monkeypatch.setattr(mod, "design_constrained_mu", fake)
    return K, check, asked


def test_tradeoff_simulates_each_design_at_every_delay(stand_in_designs):
    from lmi_suspension.seat.constrained import constrained_tradeoff

    K, check, asked = stand_in_designs
    seen = []
    points = constrained_tradeoff([9000, 3000], z_bound=0.1, disk_radius=None,
                                  delays=(0.0, 0.025), progress=seen.append)
    assert asked == [(9000.0, 0.1, None), (3000.0, 0.1, None)]
    assert [p.u_bound for p in points] == [9000.0, 3000.0] and list(points) == seen
    # recomputed here by the exact-delay simulator, clipping at the actuator's 1500 N
    for k, d in enumerate((0.0, 0.025)):
        run = simulate(K, bump(), delay=d)
        assert points[0].bump_peak[k] == pytest.approx(run.metrics().peak_z3dd, rel=1e-12)
        assert points[0].bump_u[k] == pytest.approx(np.max(np.abs(run.u_command)), rel=1e-12)
        assert points[0].bump_x1[k] == pytest.approx(run.metrics().peak_x1, rel=1e-12)
    assert points[0].mu_peak == check.mu_peak
    assert set(points[0].as_dict()) >= {"u_bound", "mu_peak", "bump_peak", "bump_u"}


@pytest.mark.parametrize("bounds", [[], [0.0], [np.inf], ["x"], None])
def test_tradeoff_bad_bounds_are_typed_errors(bounds):
    from lmi_suspension.seat.constrained import constrained_tradeoff

    with pytest.raises(ParameterError):
        constrained_tradeoff(bounds)


@pytest.mark.slow  # 25 s on Zen 1 (2026-12-02): the second tier
def test_tradeoff_cli_writes_table_figure_and_controllers(stand_in_designs, tmp_path,
                                                          monkeypatch, capsys):
    import json

    from matplotlib.image import imread

    import lmi_suspension.seat.design as design_mod
    from lmi_suspension.cli import main
    from lmi_suspension.io import load_controller

    K, check, asked = stand_in_designs

    class Mu:  # the µ controller's design (3 s) replaced by a known gain
        K = control.ss([], [], [], [[-20000.0, 0.0]])
        mu_peak = 0.9

    monkeypatch.setattr(design_mod, "design_mu_controller", lambda: Mu)
    assert main(["tradeoff", "--u-bounds", "3000,9000", "--disk-radius", "0", "--out",
                 str(tmp_path), "--quiet"]) == 0
    table = json.loads((tmp_path / "tradeoff.json").read_text())
    assert [p["u_bound"] for p in table["points"]] == [3000.0, 9000.0]
    assert asked[0][2] is None  # --disk-radius 0: no disk
    # the limit recomputed by the LP (FACTS.md: 6.164 m/s²)
    assert table["limit"] == pytest.approx(6.164, abs=1e-3)
    ref = simulate(Mu.K, bump(), delay=0.0)
    assert table["reference"]["bump_peak"][0] == pytest.approx(ref.metrics().peak_z3dd)
    assert imread(tmp_path / "tradeoff.png").shape[0] > 100
    K_back, meta = load_controller(tmp_path / "controllers" / "mu_constrained_3000N.json")
    assert np.array_equal(np.asarray(K_back.A), np.asarray(K.A))
    assert "3000 N" in capsys.readouterr().out



def test_shipped_tradeoff_holds_the_shipped_controller(shipped):
    """The shipped trade-off file (``lmi-suspension tradeoff``, 2026-11-25) against the
    shipped controller, simulated again here: its 9000 N design is that controller."""
    from lmi_suspension.seat.constrained import bump_figures, load_tradeoff

    K, Kd, meta, check = shipped
    points, table = load_tradeoff()
    assert table["command"].startswith("lmi-suspension tradeoff")
    same = next(p for p in points if p.u_bound == meta["u_bound"])
    peak, u_cmd, x1 = bump_figures(K, same.delays)
    assert same.bump_peak == pytest.approx(peak, rel=1e-6)
    assert same.bump_u == pytest.approx(u_cmd, rel=1e-6)
    assert same.mu_peak == pytest.approx(meta["mu_peak_upper"], rel=1e-9)
    # every point is a design whose bump force stays within the actuator, unclipped
    assert all(max(p.bump_u) <= 1500.0 for p in points)
