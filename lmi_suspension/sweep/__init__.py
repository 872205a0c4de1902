"""Sweeps: robustness maps and design studies over many cases, on Dask.

spec (grid or Monte-Carlo over seat, delay, road, controllers) -> cases -> batches on a
Dask cluster -> Parquet parts -> ``results.parquet`` and its figures.  Resumable: a re-run
into the same directory skips the finished cases.
"""

from .engine import SweepResult, read_results, run_sweep
from .plots import plot_map, plot_tradeoff
from .spec import Case, SweepSpec, parse_range

__all__ = ["SweepSpec", "Case", "parse_range", "run_sweep", "SweepResult", "read_results",
           "plot_map", "plot_tradeoff"]
