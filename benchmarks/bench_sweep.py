"""Sweep throughput: the same mass × delay map in this process, on 1 and on 2 Dask workers.

Run: ``python -m pytest benchmarks/bench_sweep.py -p no:cacheprovider``.  ``extra_info``
holds the throughput (cases per second of wall time, cluster start included) and the
efficiency ``Σ case time / (wall time × workers)``: the share of the workers' time spent
on cases rather than on scheduling, start-up and the physical-limit LPs.  The controller
is the seat µ design stored with the notebooks.
"""

from pathlib import Path

import pytest

from lmi_suspension.sweep import SweepSpec, parse_range, run_sweep

CONTROLLER = Path(__file__).resolve().parents[1] / "notebooks" / "controller.json"


@pytest.mark.parametrize("workers", [0, 1, 2])
def test_bench_sweep_map(benchmark, tmp_path, workers):
    spec = SweepSpec(controllers=(str(CONTROLLER),),
                     grid=(("m3", parse_range("30:70:10", "m3")),
                           ("delay", parse_range("0:0.3:20", "delay"))))
    counter = iter(range(100))
    res = benchmark.pedantic(
        lambda: run_sweep(spec, tmp_path / f"run{next(counter)}", workers=workers,
                          figures=False), rounds=1, iterations=1)
    benchmark.extra_info.update(
        cases=res.n_run, throughput=res.throughput, wall_seconds=res.wall_seconds,
        compute_seconds=res.compute_seconds,
        efficiency=res.compute_seconds / (res.wall_seconds * max(res.workers, 1)))
    assert res.n_failed == 0
