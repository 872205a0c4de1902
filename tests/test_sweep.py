"""Sweeps on Dask: specs, determinism across workers and order, resume, dead workers, errors.

The clusters here are real: a LocalCluster of worker processes, and a ``dask scheduler`` and
``dask worker`` started as separate processes on localhost.
"""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import control
import numpy as np
import pyarrow.parquet as pq
import pytest

from lmi_suspension.errors import InputError, ParameterError
from lmi_suspension.io import save_controller
from lmi_suspension.seat import SeatParameters, bump, closed_loop_stable, simulate
from lmi_suspension.sweep import SweepSpec, parse_range, read_results, run_sweep
from lmi_suspension.sweep.spec import SIM_STEP

#: a simple stabilising controller of the seat (u = -k (x1 velocity-free PD on x1)); the
#: sweep's numbers are the simulator's, checked against it below, so any controller does
K_SIMPLE = control.ss([[-200.0]], [[200.0, 0.0]], [[-3000.0]], [[-1500.0, 0.0]])


@pytest.fixture(scope="module")
def controller_file(tmp_path_factory):
    return save_controller(tmp_path_factory.mktemp("k") / "k.json", K_SIMPLE,
                           inputs=["x1", "x3"], outputs=["u"])


def _spec(controller_file, **kw):
    base = dict(controllers=(str(controller_file), "passive"),
                grid=(("m3", (40.0, 60.0)), ("delay", (0.0, 0.01, 0.02))), duration=0.6,
                limit=False)
    base.update(kw)
    return SweepSpec(**base)


def _rows(out):
    """The table's rows without the wall-time column (the only one that may differ)."""
    table, _ = read_results(out)
    return [{k: v for k, v in r.items() if k != "seconds"} for r in table.to_pylist()]


@pytest.fixture(scope="module")
def reference(tmp_path_factory, controller_file):
    """The sweep evaluated in this process, one batch after another."""
    out = tmp_path_factory.mktemp("ref")
    res = run_sweep(_spec(controller_file), out, workers=0, figures=False)
    assert res.n_run == res.n_cases == 12 and res.n_failed == 0
    return _rows(out)


# ----------------------------------------------------------------- spec


def test_parse_range_forms():
    assert parse_range("30:70:9", "m3") == tuple(np.linspace(30, 70, 9))
    assert parse_range("0.01", "delay") == (0.01,)
    assert parse_range([1, 2.5], "k1") == (1.0, 2.5)


@pytest.mark.parametrize("text, match", [
    ("30:70:0", "m3: empty range"), ("30:70", "m3: expected start:stop:count"),
    ("30:x:3", "m3: 'x' is not a number"), ("30:70:2.5", "m3: count"),
    ([], "m3: empty list"), ("nan", "m3: 'nan' is not finite")])
def test_parse_range_errors_name_the_field(text, match):
    with pytest.raises(ParameterError, match=match):
        parse_range(text, "m3")


@pytest.mark.parametrize("kw, match", [
    (dict(grid=(("m4", (1.0,)),)), "m4: unknown parameter"),
    (dict(grid=(("m3", ()),)), "m3: empty list"),
    (dict(grid=(("m3", (-1.0,)),)), "m3: -1.0 must be positive"),
    (dict(grid=(("delay", (-0.01,)),)), "delay: -0.01 s is negative"),
    (dict(grid=(("m3", (1.0,)), ("m3", (2.0,)))), "m3: given twice"),
    (dict(road="gravel"), "road: unknown road"),
    (dict(road="noise", grid=(("height", (0.1,)),)), "height: unknown parameter"),
    (dict(road_options=(("psd", 1.0),)), "road_options: 'psd'"),
    (dict(samples=3), "samples: Monte-Carlo needs"),
    (dict(ranges=(("m3", 30.0, 70.0),)), "ranges: Monte-Carlo ranges given"),
    (dict(samples=2, ranges=(("m3", 70.0, 30.0),)), "m3: Monte-Carlo range"),
    (dict(controllers=()), "controllers")])
def test_bad_specs_are_typed_errors_naming_the_field(kw, match):
    with pytest.raises(ParameterError, match=match):
        SweepSpec(**kw)


def test_cases_are_numbered_controller_then_grid_outer_axis_first(controller_file):
    spec = _spec(controller_file)
    cases = spec.cases()
    assert spec.n_cases == len(cases) == 12
    assert [c.index for c in cases] == list(range(12))
    assert [(c.controller == "passive", c.values["m3"], c.values["delay"]) for c in cases[:4]] \
        == [(False, 40.0, 0.0), (False, 40.0, 0.01), (False, 40.0, 0.02), (False, 60.0, 0.0)]
    assert all(c.controller == "passive" for c in cases[6:])


def test_delays_are_rounded_to_the_simulation_step():
    spec = SweepSpec(grid=(("delay", parse_range("0:0.05:4", "delay")),))
    assert [c.values["delay"] for c in spec.cases()] == [
        round(d / SIM_STEP) * SIM_STEP for d in np.linspace(0, 0.05, 4)]


def test_monte_carlo_draws_come_from_each_cases_spawned_seed():
    spec = SweepSpec(samples=5, ranges=(("m3", 30.0, 70.0), ("k1", 2e4, 4e4)), seed=7)
    cases = spec.cases()
    # independent route: SeedSequence.spawn, as numpy documents it
    children = np.random.SeedSequence(7).spawn(5)
    for case, child in zip(cases, children):
        rng = np.random.default_rng(child)
        assert case.values == {"m3": rng.uniform(30.0, 70.0), "k1": rng.uniform(2e4, 4e4)}
    assert len({c.values["m3"] for c in cases}) == 5


def test_spec_round_trips_through_json_and_reads_toml(tmp_path, controller_file):
    spec = _spec(controller_file, road_options=(("height", 0.05),), seed=3)
    assert SweepSpec.from_json(spec.to_json()) == spec
    (tmp_path / "k.json").write_text(Path(controller_file).read_text())
    (tmp_path / "s.toml").write_text(
        'controllers = ["k.json", "passive"]\nroad = "bump"\nduration = 0.6\nlimit = false\n'
        "[road_options]\nheight = 0.05\n[grid]\nm3 = [40, 60]\ndelay = \"0:0.02:3\"\n"
        "[monte_carlo]\nsamples = 2\nk1 = [25000, 37000]\n")
    read = SweepSpec.from_toml(tmp_path / "s.toml")
    assert read.controllers == (str(tmp_path / "k.json"), "passive")
    assert read.grid == (("m3", (40.0, 60.0)), ("delay", (0.0, 0.01, 0.02)))
    assert read.samples == 2 and read.ranges == (("k1", 25000.0, 37000.0),)
    assert read.n_cases == 2 * 2 * 3 * 2
    (tmp_path / "bad.toml").write_text("[grid]\nm9 = [1]\n")
    with pytest.raises(ParameterError, match="m9: unknown parameter"):
        SweepSpec.from_toml(tmp_path / "bad.toml")
    (tmp_path / "bad2.toml").write_text("speed = 3\n")
    with pytest.raises(ParameterError, match="speed: unknown key"):
        SweepSpec.from_toml(tmp_path / "bad2.toml")
    with pytest.raises(InputError, match="spec file"):
        SweepSpec.from_toml(tmp_path / "missing.toml")


# ----------------------------------------------------------------- Latin hypercube

LHS_RANGES = (("m3", 30.0, 70.0), ("k1", 2e4, 4e4), ("c2", 50.0, 300.0))


def _strata(values, lo, hi, n):
    """The stratum (0 … n-1) of each value among n equal-width strata of [lo, hi]."""
    return sorted(min(int((v - lo) / (hi - lo) * n), n - 1) for v in values)


def _range_values(cases):
    return [tuple(c.values[name] for name, _, _ in LHS_RANGES) for c in cases]


def test_lhs_puts_one_sample_in_each_equal_width_stratum_of_every_axis(controller_file):
    n = 20
    spec = SweepSpec(controllers=(str(controller_file), "passive"),
                     grid=(("height", (0.05, 0.1)),), samples=n, ranges=LHS_RANGES,
                     sampling="lhs", seed=5)
    cases = spec.cases()
    assert len(cases) == 2 * 2 * n
    blocks = [cases[i:i + n] for i in range(0, len(cases), n)]
    for block in blocks:
        for name, lo, hi in LHS_RANGES:
            values = [c.values[name] for c in block]
            assert all(lo <= v <= hi for v in values)
            assert _strata(values, lo, hi, n) == list(range(n)), name
    # one hypercube shared by every controller and grid point: each meets the same seats
    assert all(_range_values(b) == _range_values(blocks[0]) for b in blocks)
    assert [c.values["height"] for c in cases[:n + 1]] == [0.05] * n + [0.1]
    # the check discriminates: uniform draws of the same spec are not stratified
    uniform = SweepSpec(samples=n, ranges=LHS_RANGES, seed=5).cases()
    assert any(_strata([c.values[name] for c in uniform], lo, hi, n) != list(range(n))
               for name, lo, hi in LHS_RANGES)


def test_lhs_case_takes_its_row_of_the_documented_hypercube_delay_rounded():
    from scipy.stats import qmc

    ranges = (("delay", 0.0, 0.05), ("m3", 30.0, 70.0), ("k2", 5e4, 5e4))
    spec = SweepSpec(controllers=("passive", "design"), samples=6, ranges=ranges,
                     sampling="lhs", seed=9)
    # independent route: the hypercube as the docstring gives it, scaled by hand
    unit = qmc.LatinHypercube(d=3, seed=np.random.default_rng(
        np.random.SeedSequence(9))).random(6)
    for case in spec.cases():
        row = unit[case.index % 6]
        assert case.values["delay"] == round(0.05 * row[0] / SIM_STEP) * SIM_STEP
        assert case.values["m3"] == pytest.approx(30.0 + 40.0 * row[1], rel=1e-15)
        assert case.values["k2"] == 5e4  # an empty range is its value
        assert list(case.values) == ["delay", "m3", "k2"]


def test_lhs_is_reproducible_from_the_seed():
    def values(seed):
        spec = SweepSpec(samples=8, ranges=LHS_RANGES, sampling="lhs", seed=seed)
        return _range_values(spec.cases())

    assert values(3) == values(3)
    other = values(4)
    assert all(a != b for row, row4 in zip(values(3), other) for a, b in zip(row, row4))
    assert sorted(values(3)) != sorted(other)


def test_lhs_values_do_not_depend_on_the_controllers_the_grid_or_the_split(
        tmp_path, controller_file):
    alone = _range_values(SweepSpec(samples=5, ranges=LHS_RANGES, sampling="lhs",
                                    seed=2).cases())
    crossed = SweepSpec(controllers=(str(controller_file), "passive", "design"),
                        grid=(("speed_kmh", (20.0, 30.0, 40.0)),), samples=5,
                        ranges=LHS_RANGES, sampling="lhs", seed=2).cases()
    assert _range_values(crossed) == alone * 9
    # a sweep run one case per batch in shuffled order, and resumed, gives the rows of one
    # batch run straight through; each row holds its case's values
    spec = SweepSpec(samples=4, ranges=(("m3", 40.0, 70.0), ("delay", 0.0, 0.02)),
                     sampling="lhs", seed=1, duration=0.3, limit=False)

    class Stop(Exception):
        pass

    def stop(k):
        if k == 2:
            raise Stop

    with pytest.raises(Stop):
        run_sweep(spec, tmp_path / "a", workers=0, batch_size=1, shuffle_seed=4,
                  on_batch=stop, figures=False)
    res = run_sweep(spec, tmp_path / "a", workers=0, batch_size=1, shuffle_seed=5,
                    figures=False)
    assert (res.n_skipped, res.n_run) == (2, 2)
    run_sweep(spec, tmp_path / "b", workers=0, batch_size=4, figures=False)
    rows = _rows(tmp_path / "a")
    assert rows == _rows(tmp_path / "b")
    assert [(r["m3"], r["delay"]) for r in rows] == [(c.values["m3"], c.values["delay"])
                                                      for c in spec.cases()]


def test_sampling_round_trips_through_json_and_toml(tmp_path):
    spec = SweepSpec(grid=(("m3", (40.0, 60.0)),), samples=3, ranges=LHS_RANGES[1:],
                     sampling="lhs", seed=4)
    text = spec.to_json()
    assert json.loads(text)["sampling"] == "lhs"
    assert SweepSpec.from_json(text) == spec
    assert SweepSpec.from_json(text).cases() == spec.cases()
    # a uniform spec writes the JSON of before the option (its output directories
    # resume), and JSON without the key reads as uniform
    uniform = SweepSpec(samples=3, ranges=LHS_RANGES, seed=4)
    assert "sampling" not in json.loads(uniform.to_json())
    old = json.loads(spec.to_json())
    del old["sampling"]
    assert SweepSpec.from_json(json.dumps(old)).sampling == "uniform"
    assert SweepSpec.from_json(uniform.to_json()) == uniform
    # TOML: the key sampling of the [monte_carlo] table
    (tmp_path / "s.toml").write_text(
        'seed = 4\n[grid]\nm3 = [40, 60]\n[monte_carlo]\nsamples = 3\nsampling = "lhs"\n'
        "k1 = [20000, 40000]\nc2 = [50, 300]\n")
    assert SweepSpec.from_toml(tmp_path / "s.toml") == spec
    (tmp_path / "u.toml").write_text("[monte_carlo]\nsamples = 3\nk1 = [20000, 40000]\n")
    assert SweepSpec.from_toml(tmp_path / "u.toml").sampling == "uniform"
    (tmp_path / "bad.toml").write_text(
        '[monte_carlo]\nsamples = 3\nsampling = "sobol"\nk1 = [20000, 40000]\n')
    with pytest.raises(ParameterError, match="sampling: unknown sampling 'sobol'; choose one "
                                             "of uniform, lhs"):
        SweepSpec.from_toml(tmp_path / "bad.toml")


@pytest.mark.parametrize("kw, match", [
    (dict(sampling="sobol"), "sampling: unknown sampling 'sobol'; choose one of uniform, lhs"),
    (dict(sampling="LHS"), "sampling: unknown sampling 'LHS'; choose one of uniform, lhs"),
    (dict(sampling=1), "sampling: unknown sampling 1; choose one of uniform, lhs"),
    (dict(sampling=None), "sampling: unknown sampling None"),
    (dict(sampling="lhs", samples=0, ranges=()), "sampling: 'lhs' draws Monte-Carlo samples, "
                                                 "but samples = 0")])
def test_bad_sampling_is_a_typed_error_naming_the_values(kw, match):
    base = dict(samples=3, ranges=LHS_RANGES)
    base.update(kw)
    with pytest.raises(ParameterError, match=match):
        SweepSpec(**base)


@pytest.mark.parametrize("explicit", [False, True])
def test_uniform_sampling_is_unchanged(controller_file, explicit):
    """Each case's draws recomputed the old way: its own spawned generator, one uniform
    draw per range in order (the delay then rounded to the step)."""
    ranges = (("m3", 30.0, 70.0), ("delay", 0.0, 0.05), ("k1", 2e4, 4e4))
    spec = SweepSpec(controllers=(str(controller_file), "passive"),
                     grid=(("height", (0.05, 0.1)),), samples=3, ranges=ranges, seed=13,
                     **(dict(sampling="uniform") if explicit else {}))
    assert spec.sampling == "uniform"
    cases = spec.cases()
    assert len(cases) == 12
    for k, case in enumerate(cases):
        rng = np.random.default_rng(np.random.SeedSequence(13, spawn_key=(k,)))
        drawn = {name: rng.uniform(lo, hi) for name, lo, hi in ranges}
        drawn["delay"] = round(drawn["delay"] / SIM_STEP) * SIM_STEP
        assert case.values == {"height": (0.05, 0.1)[(k // 3) % 2], **drawn}
        assert case.seed == (13, k)


@pytest.mark.parametrize("content, match", [
    (None, "not found"), ("{not json", "is not a saved controller"),
    ('{"A": [[1.0]]}', "is not a saved controller")])
def test_unreadable_controller_files_fail_before_any_case(tmp_path, content, match):
    path = tmp_path / "k.json"
    if content is not None:
        path.write_text(content)
    t0 = time.perf_counter()
    with pytest.raises(InputError, match=f"controllers: .*{match}"):
        run_sweep(SweepSpec(controllers=(str(path),), grid=(("m3", (40.0,)),)),
                  tmp_path / "out", workers=0)
    assert time.perf_counter() - t0 < 5.0  # no case ran (each takes a simulation)
    assert not (tmp_path / "out").exists()


# ----------------------------------------------------------------- rows


def test_rows_are_the_simulators_numbers(reference):
    """Each row against a direct call of the simulator and the Nyquist test."""
    for row in (reference[4], reference[9]):
        K = K_SIMPLE if row["controller"] != "passive" else None
        p = SeatParameters(m3=row["m3"])
        res = simulate(K, bump(t_end=0.6), delay=row["delay"], params=p, dt=SIM_STEP)
        m = res.metrics()
        assert row["peak_z3dd"] == m.peak_z3dd and row["peak_x1"] == m.peak_x1
        assert row["wrms_z3dd"] == m.weighted_rms_z3dd and row["peak_u"] == m.peak_u
        assert row["peak_u_command"] == m.peak_u_command
        assert row["stable"] == (True if K is None else closed_loop_stable(K, row["delay"], p))
        assert row["error"] is None and row["limit_ratio"] is None


def test_rows_record_the_commanded_force_apart_from_the_applied_one(tmp_path):
    """Ten times ``K_SIMPLE``'s gain commands about 2490 N on the bump (measured), which
    the actuator clips at its 1500 N: the row holds both, each the simulator's."""
    K = control.ss([[-200.0]], [[200.0, 0.0]], [[-30000.0]], [[-15000.0, 0.0]])
    f = save_controller(tmp_path / "strong.json", K, inputs=["x1", "x3"], outputs=["u"])
    spec = SweepSpec(controllers=(str(f),), grid=(("m3", (43.3,)),), duration=0.6,
                     limit=False)
    run_sweep(spec, tmp_path / "out", workers=0, figures=False)
    row = read_results(tmp_path / "out")[0].to_pylist()[0]
    m = simulate(K, bump(t_end=0.6), params=SeatParameters(m3=43.3), dt=SIM_STEP).metrics()
    assert row["peak_u_command"] == m.peak_u_command > 1500.0
    assert row["peak_u"] == m.peak_u == 1500.0


def test_limit_ratio_is_the_peak_over_that_cases_own_limit(tmp_path, controller_file):
    from lmi_suspension.seat import bump_limit

    spec = SweepSpec(controllers=(str(controller_file),), grid=(("m3", (40.0, 60.0)),),
                     duration=1.5)
    run_sweep(spec, tmp_path, workers=0, figures=False)
    rows = read_results(tmp_path)[0].to_pylist()
    limits = [bump_limit(bump(t_end=1.5), SeatParameters(m3=m)).certified_peak
              for m in (40.0, 60.0)]
    assert [r["limit_peak"] for r in rows] == pytest.approx(limits, rel=1e-9)
    assert rows[0]["limit_peak"] != rows[1]["limit_peak"]
    for r in rows:
        assert r["limit_ratio"] == pytest.approx(r["peak_z3dd"] / r["limit_peak"], rel=1e-12)


def test_a_failing_case_records_its_error_and_the_sweep_goes_on(tmp_path):
    wrong = save_controller(tmp_path / "k1.json", control.ss([], [], [], [[1.0]]))  # 1 input
    spec = SweepSpec(controllers=(str(wrong), "passive"), grid=(("m3", (40.0, 60.0)),),
                     duration=0.3, limit=False)
    res = run_sweep(spec, tmp_path / "out", workers=0, figures=False)
    rows = read_results(tmp_path / "out")[0].to_pylist()
    assert res.n_failed == 2 and len(rows) == 4
    assert all("DimensionError" in r["error"] for r in rows[:2])
    assert all(r["error"] is None and r["peak_z3dd"] > 0 for r in rows[2:])


def test_table_metadata_holds_the_spec_and_versions(tmp_path, controller_file):
    spec = _spec(controller_file, grid=(("m3", (50.0,)),))
    res = run_sweep(spec, tmp_path, workers=0)
    meta = pq.read_schema(res.table).metadata
    assert SweepSpec.from_json(meta[b"lmi_suspension.spec"].decode()) == spec
    versions = json.loads(meta[b"lmi_suspension.versions"])
    assert versions["pyarrow"] and versions["numpy"] == np.__version__
    assert [p.name for p in res.figures] == ["tradeoff.png"]  # one axis: no map


def test_another_specs_directory_is_refused(tmp_path, controller_file):
    run_sweep(_spec(controller_file, grid=(("m3", (50.0,)),)), tmp_path, workers=0,
              figures=False)
    with pytest.raises(ParameterError, match="another sweep"):
        run_sweep(_spec(controller_file, grid=(("m3", (55.0,)),)), tmp_path, workers=0)


# ----------------------------------------------------------------- resume


def test_a_part_written_before_a_column_was_added_is_refused_on_resume(
        tmp_path, controller_file):
    """A directory of the same spec whose part lacks ``peak_u_command`` (as parts written
    before that column existed do): resuming would leave the column empty for its cases;
    it is a typed error naming the column instead."""
    spec = _spec(controller_file, grid=(("m3", (50.0, 60.0)),))
    run_sweep(spec, tmp_path, workers=0, figures=False)
    part = sorted((tmp_path / "parts").glob("*.parquet"))[0]
    pq.write_table(pq.read_table(part).drop(["peak_u_command"]), part)
    (tmp_path / "results.parquet").unlink()
    with pytest.raises(InputError, match="peak_u_command"):
        run_sweep(spec, tmp_path, workers=0, figures=False)


def test_an_interrupted_sweep_resumes_where_it_stopped(tmp_path, controller_file, reference):
    class Stop(Exception):
        pass

    def stop_after_two(k):
        if k == 2:
            raise Stop

    spec = _spec(controller_file)
    with pytest.raises(Stop):
        run_sweep(spec, tmp_path, workers=0, batch_size=3, on_batch=stop_after_two)
    assert not (tmp_path / "results.parquet").exists()
    res = run_sweep(spec, tmp_path, workers=0, batch_size=3)
    assert (res.n_skipped, res.n_run) == (6, 6)
    assert _rows(tmp_path) == reference
    again = run_sweep(spec, tmp_path, workers=0)
    assert (again.n_skipped, again.n_run) == (12, 0)


# ----------------------------------------------------------------- dask


@pytest.mark.slow  # 20 s on Zen 1 (2026-12-02): the second tier
def test_local_cluster_of_two_processes_gives_the_same_rows_in_any_order(
        tmp_path, controller_file, reference):
    spec = _spec(controller_file)
    res = run_sweep(spec, tmp_path / "a", workers=2, batch_size=2, shuffle_seed=3,
                    figures=False)
    assert res.workers == 2 and res.n_run == 12
    assert _rows(tmp_path / "a") == reference
    res1 = run_sweep(spec, tmp_path / "b", workers=1, batch_size=5, figures=False)
    assert res1.workers == 1 and _rows(tmp_path / "b") == reference


def _start(cmd, **kw):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    return subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            env=env, **kw)


def _wait_for(predicate, seconds=60.0):
    t_end = time.monotonic() + seconds
    while time.monotonic() < t_end:
        if predicate():
            return
        time.sleep(0.2)
    raise TimeoutError("the dask processes did not come up")


def _scheduler_address(path):
    try:
        return json.loads(path.read_text())["address"]
    except (FileNotFoundError, json.JSONDecodeError, KeyError):
        return None


@pytest.fixture
def dask_processes(tmp_path):
    """A ``dask scheduler`` and two ``dask worker`` processes (no nanny: a killed worker
    stays dead), as separate processes on localhost."""
    dask = [sys.executable, "-m", "dask"]  # the dask CLI of this interpreter
    sched_file = tmp_path / "scheduler.json"
    procs = [_start(dask + ["scheduler", "--host", "127.0.0.1", "--port", "0",
                            "--no-dashboard", "--scheduler-file", str(sched_file)])]
    try:
        # dask writes the file in place, not atomically: it exists empty for a moment
        # (CI read '' once), so wait until it parses.
        _wait_for(lambda: _scheduler_address(sched_file) is not None)
        address = _scheduler_address(sched_file)
        for _ in range(2):
            procs.append(_start(dask + ["worker", address, "--nthreads", "1", "--no-nanny",
                                        "--no-dashboard", "--host", "127.0.0.1"]))
        from distributed import Client

        with Client(address, timeout="20s") as c:
            c.wait_for_workers(2, timeout=60)
        yield address, procs[1:]
    finally:
        for p in procs:  # test processes: no state worth a graceful close (which
            if p.poll() is None:  # took 20 s per process)
                p.kill()
        for p in procs:
            p.wait(timeout=20)


def test_a_running_scheduler_and_workers_started_apart(dask_processes, tmp_path,
                                                       controller_file, reference):
    address, _workers = dask_processes
    res = run_sweep(_spec(controller_file), tmp_path, scheduler=address, batch_size=1,
                    figures=False)
    assert res.workers == 2 and res.n_run == 12
    assert _rows(tmp_path) == reference


def test_a_worker_killed_mid_sweep_loses_and_duplicates_nothing(dask_processes, tmp_path,
                                                               controller_file, reference):
    address, workers = dask_processes
    killed = []

    def kill_one(k):
        if k == 1:  # the other worker is busy with its next batch now
            workers[0].send_signal(signal.SIGKILL)
            workers[0].wait(timeout=20)
            killed.append(k)

    res = run_sweep(_spec(controller_file), tmp_path, scheduler=address, batch_size=1,
                    on_batch=kill_one, figures=False)
    assert killed == [1] and res.n_run == 12 and res.n_failed == 0
    rows = _rows(tmp_path)
    assert [r["case"] for r in rows] == list(range(12))
    assert rows == reference
    parts = [pq.read_table(p, columns=["case"]).column("case").to_pylist()
             for p in sorted((tmp_path / "parts").glob("*.parquet"))]
    assert sorted(c for part in parts for c in part) == list(range(12))  # each case once


# ----------------------------------------------------------------- CLI


def test_cli_sweep_writes_table_and_figures(tmp_path, controller_file, capsys):
    from lmi_suspension.cli import main

    rc = main(["sweep", "--controller", str(controller_file), "--m3", "40:60:2",
               "--delay", "0:0.3:3", "--duration", "0.6", "--no-limit", "--workers", "0",
               "--out", str(tmp_path), "-q"])
    out = capsys.readouterr().out
    assert rc == 0 and "6 cases (6 run now" in out
    rows = read_results(tmp_path)[0].to_pylist()
    assert [r["delay"] for r in rows[:3]] == [0.0, 0.15, 0.3]
    assert (tmp_path / "map-k.png").is_file() and (tmp_path / "tradeoff.png").is_file()


@pytest.mark.parametrize("argv, match", [
    (["--m3", "30:70:0"], "m3: empty range"),
    (["--param", "k9=1:2:3"], "k9: unknown parameter"),
    (["--controller", "missing.json"], "controllers: file missing.json not found"),
    (["--samples", "3", "--m3", "30:50:4"], "m3: with --samples give a range lo:hi")])
def test_cli_sweep_bad_input_is_one_line_exit_2(tmp_path, argv, match, capsys):
    from lmi_suspension.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["sweep", "--out", str(tmp_path / "o"), "--workers", "0"] + argv)
    assert exc.value.code == 2
    assert match in capsys.readouterr().err


def test_cli_sweep_sampling_flag_reaches_the_spec(tmp_path, capsys):
    from lmi_suspension.cli import main

    argv = ["sweep", "--samples", "3", "--m3", "40:70", "--delay", "0:0.02", "--seed", "6",
            "--duration", "0.3", "--no-limit", "--workers", "0", "-q"]
    assert main(argv + ["--sampling", "lhs", "--out", str(tmp_path / "lhs")]) == 0
    table, spec = read_results(tmp_path / "lhs")
    expected = SweepSpec(samples=3, ranges=(("m3", 40.0, 70.0), ("delay", 0.0, 0.02)),
                         seed=6, duration=0.3, limit=False, sampling="lhs")
    assert spec == expected
    assert json.loads((tmp_path / "lhs" / "spec.json").read_text())["sampling"] == "lhs"
    assert [(r["m3"], r["delay"]) for r in table.to_pylist()] == [
        (c.values["m3"], c.values["delay"]) for c in expected.cases()]
    assert main(argv + ["--out", str(tmp_path / "u")]) == 0
    assert read_results(tmp_path / "u")[1].sampling == "uniform"
    capsys.readouterr()


@pytest.mark.parametrize("argv, match", [
    (["--samples", "3", "--m3", "40:70", "--sampling", "sobol"],
     "--sampling: invalid choice: 'sobol'"),  # (argparse quotes the choices by version)
    (["--m3", "40:70:3", "--sampling", "lhs"],
     "sampling: 'lhs' draws Monte-Carlo samples, but samples = 0"),
    (["--spec", "s.toml", "--sampling", "lhs"], "--spec: give the axes")])
def test_cli_sweep_bad_sampling_is_one_line_exit_2(tmp_path, argv, match, capsys):
    from lmi_suspension.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["sweep", "--out", str(tmp_path / "o"), "--workers", "0"] + argv)
    assert exc.value.code == 2
    assert match in capsys.readouterr().err


# ----------------------------------------------------------------- per-case designs


@pytest.mark.slow  # 20 s on Zen 1 (2026-12-02): the second tier
def test_design_entry_synthesises_one_controller_per_distinct_seat(tmp_path, monkeypatch):
    """Every case of one seat runs the µ controller designed for that seat, designed once."""
    from lmi_suspension.seat import design as design_module

    calls = []
    real = design_module.design_mu_controller

    def counting(*args, **kwargs):
        calls.append(kwargs["params"].m3)
        return real(*args, **kwargs)

    monkeypatch.setattr(design_module, "design_mu_controller", counting)
    spec = SweepSpec(controllers=("design",), grid=(("m3", (60.0,)), ("delay", (0.0, 0.02))),
                     duration=0.5, limit=False)
    res = run_sweep(spec, tmp_path, workers=0, figures=False)
    assert calls == [60.0] and res.n_failed == 0
    rows = read_results(tmp_path)[0].to_pylist()
    # independent route: the same design called directly, simulated directly
    K = real(params=SeatParameters(m3=60.0), rng=np.random.default_rng(spec.seed)).K
    for row in rows:
        m = simulate(K, bump(t_end=0.5), delay=row["delay"], params=SeatParameters(m3=60.0),
                     dt=SIM_STEP).metrics()
        assert row["peak_z3dd"] == pytest.approx(m.peak_z3dd, rel=1e-9)
        assert row["stable"] == closed_loop_stable(K, row["delay"], SeatParameters(m3=60.0))


@pytest.mark.slow  # 26 s on Zen 1 (2026-12-02): the second tier
def test_a_design_entry_can_name_any_route(tmp_path):
    """``design:<route>``: the peak-bounded route designed for each seat of the grid (once
    each), its rows equal to a direct design and simulation."""
    from lmi_suspension.seat.routes import design_seat

    spec = SweepSpec(controllers=("design:peak_bounded",), grid=(("m3", (35.0, 65.0)),),
                     duration=0.5, limit=False)
    res = run_sweep(spec, tmp_path, workers=0, figures=False)
    rows = read_results(tmp_path)[0].to_pylist()
    assert res.n_failed == 0 and [r["controller"] for r in rows] == [spec.controllers[0]] * 2
    for row in rows:
        p = SeatParameters(m3=row["m3"])
        K = design_seat("peak_bounded", params=p).K
        m = simulate(K, bump(t_end=0.5), params=p, dt=SIM_STEP).metrics()
        assert row["peak_z3dd"] == pytest.approx(m.peak_z3dd, rel=1e-9)
    with pytest.raises(ParameterError, match="unknown design route 'nope'"):
        SweepSpec(controllers=("design:nope",))


def test_step_sets_the_simulation_and_the_delay_rounding(tmp_path):
    spec = SweepSpec(grid=(("delay", (0.0123,)),), duration=0.4, limit=False, step=5e-4)
    assert spec.cases()[0].values["delay"] == round(0.0123 / 5e-4) * 5e-4
    run_sweep(spec, tmp_path, workers=0, figures=False)
    row = read_results(tmp_path)[0].to_pylist()[0]
    m = simulate(None, bump(t_end=0.4), delay=row["delay"], dt=5e-4).metrics()
    assert row["peak_z3dd"] == m.peak_z3dd and row["delay_used"] == row["delay"]
    with pytest.raises(ParameterError, match="step"):
        SweepSpec(step=0.0)


def test_a_failed_design_marks_its_cases_and_the_sweep_goes_on(tmp_path, monkeypatch):
    from lmi_suspension.errors import InfeasibleError
    from lmi_suspension.seat import design as design_module

    def failing(*args, **kwargs):  # the injected failure
        raise InfeasibleError("no stabilising controller")

    monkeypatch.setattr(design_module, "design_mu_controller", failing)
    spec = SweepSpec(controllers=("design", "passive"), grid=(("m3", (50.0, 60.0)),),
                     duration=0.3, limit=False)
    res = run_sweep(spec, tmp_path, workers=0, figures=False)
    rows = read_results(tmp_path)[0].to_pylist()
    assert res.n_failed == 2
    assert all("design failed: InfeasibleError" in r["error"] for r in rows[:2])
    assert all(r["error"] is None for r in rows[2:])


def test_progress_reports_cumulative_cases_of_this_run(tmp_path, controller_file):
    seen = []
    run_sweep(_spec(controller_file), tmp_path, workers=0, batch_size=5, figures=False,
              progress=lambda done, total: seen.append((done, total)))
    assert seen == [(5, 12), (10, 12), (12, 12)]
