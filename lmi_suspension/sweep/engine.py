"""Running a sweep on Dask (``dask.distributed``), streaming rows to Parquet, resumable.

The client expands the spec into cases, skips those already in the output directory,
computes each distinct physical limit once (as tasks of their own), and submits the rest in
batches; each finished batch is written at once as a part file (``parts/*.parquet``, by
rename, so a part is whole or absent).  At the end the parts become one table,
``results.parquet``, one row per case sorted by case, with the spec and the package
versions in its metadata, and the figures beside it.

Nothing in a row depends on the worker or on the order: every random number comes from the
case's own seed (``SeedSequence.spawn``), and a batch is a list of independent cases.  A
worker that dies takes its running batch with it; the scheduler runs that batch again on
another worker, and the part is written once, by the client, when its result arrives.
"""

from __future__ import annotations

import json
import logging
import math
import os
import random
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError, LmiSuspensionError, ParameterError
from .case import (
    compute_design,
    compute_limit,
    design_key,
    error_row,
    evaluate_batch,
    limit_key,
)
from .spec import PASSIVE, SweepSpec, design_route

__all__ = ["SweepResult", "run_sweep", "read_results"]

logger = logging.getLogger(__name__)

#: batches per worker the cases are split into (at least): enough that a dead worker's
#: batch is a small loss and that the last batch, run while the other workers may idle,
#: is short.  With 8 (63 cases, 18 s a batch) the 1000-case map on 2 workers spent 7 % of
#: the workers' time outside cases, mostly in that tail; a task costs the scheduler a
#: few milliseconds, nothing against a batch of seconds (measured 2026-11-25)
_BATCHES_PER_WORKER = 32
#: largest batch (cases): a batch is written as one Parquet part
_MAX_BATCH = 32
_PARTS = "parts"
_SPEC = "spec.json"
_TABLE = "results.parquet"


@dataclass(frozen=True)
class SweepResult:
    """What :func:`run_sweep` did.

    Attributes
    ----------
    table : pathlib.Path
        ``results.parquet``: one row per case.
    n_cases, n_run, n_skipped, n_failed : int
        Cases in the spec; run now; found finished in the directory (resume); with an
        ``error`` (of all rows).
    wall_seconds : float
        Wall time of this run (cluster start included).
    compute_seconds : float
        Sum of the cases' own times run now.
    workers : int
        Worker processes (0: evaluated in this process).
    figures : tuple of pathlib.Path
        The plots written beside the table.
    """

    table: Path
    n_cases: int
    n_run: int
    n_skipped: int
    n_failed: int
    wall_seconds: float
    compute_seconds: float
    workers: int
    figures: tuple = ()

    @property
    def throughput(self) -> float:
        """Cases run per second of wall time."""
        return self.n_run / self.wall_seconds if self.wall_seconds > 0 else math.nan


def _versions() -> dict:
    from importlib.metadata import PackageNotFoundError, version

    out = {}
    for pkg in ("lmi_suspension", "numpy", "scipy", "control", "slycot", "cvxpy", "clarabel",
                "dask", "distributed", "pyarrow"):
        try:
            out[pkg] = version(pkg)
        except PackageNotFoundError:
            out[pkg] = None
    return out


def _load_controllers(spec: SweepSpec) -> dict:
    """Every controller of the spec as its saved dict (read and checked now, in the client,
    so a bad file is an error before any case runs)."""
    from .case import controller_from_saved

    out = {}
    for name in spec.controllers:
        if name == PASSIVE or design_route(name) is not None:
            out[name] = None
            continue
        path = Path(name)
        if not path.is_file():
            raise InputError(f"controllers: file {path} not found")
        try:
            text = json.loads(path.read_text())
            controller_from_saved(text)
        except (OSError, UnicodeDecodeError) as exc:
            raise InputError(f"controllers: cannot read {path}: {exc}") from exc
        except (LmiSuspensionError, ValueError, KeyError, TypeError, IndexError) as exc:
            raise InputError(f"controllers: {path} is not a saved controller "
                             f"({type(exc).__name__}: {exc})") from exc
        out[name] = text
    return out


def _finished(out: Path) -> set:
    """The cases already in the directory's parts.  A part without every metric column
    (written before a column was added) is refused: resumed, its cases would keep an
    empty column without a word."""
    import pyarrow.parquet as pq

    from .case import METRIC_COLUMNS

    done = set()
    for part in sorted((out / _PARTS).glob("*.parquet")):
        missing = [c for c in METRIC_COLUMNS if c not in pq.read_schema(part).names]
        if missing:
            raise InputError(f"{part} has no column {', '.join(missing)}: it was written by "
                             "an earlier version of lmi_suspension; run the sweep into a "
                             "new directory")
        done.update(pq.read_table(part, columns=["case"]).column("case").to_pylist())
    return done


def _write_part(out: Path, rows: list[dict], name: str) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    tmp = out / _PARTS / f".{name}.tmp"
    pq.write_table(pa.Table.from_pylist(rows), tmp)
    os.replace(tmp, out / _PARTS / f"{name}.parquet")


def _prepare(out: Path, spec: SweepSpec) -> None:
    out.mkdir(parents=True, exist_ok=True)
    (out / _PARTS).mkdir(exist_ok=True)
    stored = out / _SPEC
    text = spec.to_json()
    if stored.exists():
        if stored.read_text() != text:
            raise ParameterError(f"out: {out} holds the results of another sweep (its "
                                 f"{_SPEC} differs); choose another directory")
    else:
        stored.write_text(text)


def _batches(cases: list, workers: int, batch_size: int | None) -> list[list]:
    if batch_size is None:
        batch_size = min(_MAX_BATCH, max(1, math.ceil(
            len(cases) / (_BATCHES_PER_WORKER * max(workers, 1)))))
    return [cases[i:i + batch_size] for i in range(0, len(cases), batch_size)]


def run_sweep(spec: SweepSpec, out, *, scheduler: str | None = None, workers: int | None = None,
              batch_size: int | None = None, shuffle_seed: int | None = None,
              progress: Callable[[int, int], None] | None = None,
              on_batch: Callable[[int], None] | None = None,
              figures: bool = True) -> SweepResult:
    """Run (or resume) a sweep; write ``out/results.parquet`` and its figures.

    Parameters
    ----------
    spec : SweepSpec
        The cases.
    out : path-like
        Output directory: ``results.parquet``, ``spec.json``, ``parts/``, figures.  Cases
        already in its parts are skipped (resume); a directory of another spec is an error.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``).  Default: a
        ``LocalCluster`` of ``workers`` processes, one thread each, started and closed here.
    workers : int, optional
        Worker processes of the local cluster (default 2); ``0`` evaluates every batch in
        this process, without Dask.
    batch_size : int, optional
        Cases per task (default: about 32 batches per worker, at most 32 cases).
    shuffle_seed : int, optional
        Submit the batches in an order shuffled by this seed (the rows do not change).
    progress : callable, optional
        ``progress(done, total)`` after each batch (cases of this run).
    on_batch : callable, optional
        ``on_batch(k)`` after the k-th batch of this run is written (tests use it to kill
        a worker or to interrupt a sweep).
    figures : bool
        Write the figures of :mod:`.plots` beside the table.

    Returns
    -------
    SweepResult

    Raises
    ------
    ParameterError, InputError
        Bad spec or out directory, unreadable controller file (before any case runs).
    """
    t0 = time.perf_counter()
    if not isinstance(spec, SweepSpec):
        raise ParameterError("spec must be a SweepSpec")
    if workers is not None and (isinstance(workers, bool) or int(workers) != workers
                                or workers < 0):
        raise ParameterError(f"workers must be a non-negative integer, got {workers!r}")
    if batch_size is not None and (int(batch_size) != batch_size or batch_size < 1):
        raise ParameterError(f"batch_size must be a positive integer, got {batch_size!r}")
    out = Path(out)
    controllers = _load_controllers(spec)
    _prepare(out, spec)
    cases = spec.cases()
    done = _finished(out)
    pending = [c for c in cases if c.index not in done]
    settings = spec.road_settings()
    n_workers = 2 if workers is None else int(workers)
    if scheduler is not None and workers == 0:
        raise ParameterError("workers=0 runs in this process; do not give a scheduler too")
    compute = 0.0
    if pending:
        batches = _batches(pending, n_workers, batch_size)
        if shuffle_seed is not None:
            random.Random(shuffle_seed).shuffle(batches)
        keys = sorted({k for c in pending
                       if spec.limit and (k := limit_key(c, spec.road, settings)) is not None})
        designs = sorted({k for c in pending if (k := design_key(c)) is not None})
        logger.info("sweep: %d cases (%d done before), %d batches, %d limits, %d designs",
                    len(pending), len(done), len(batches), len(keys), len(designs))
        if scheduler is None and n_workers == 0:
            compute, n_workers = _run_here(out, batches, controllers, spec, settings, keys,
                                           designs, progress, on_batch), 0
        else:
            compute, n_workers = _run_dask(out, batches, controllers, spec, settings, keys,
                                           designs, scheduler, n_workers, progress, on_batch)
    table, n_failed = _consolidate(out, spec)
    figs = ()
    if figures:
        from .plots import write_figures

        figs = tuple(write_figures(table, spec, out))
    return SweepResult(table=table, n_cases=len(cases), n_run=len(pending),
                       n_skipped=len(cases) - len(pending), n_failed=n_failed,
                       wall_seconds=time.perf_counter() - t0, compute_seconds=compute,
                       workers=n_workers, figures=figs)


def _part_name(batch: list) -> str:
    return f"cases-{batch[0].index:08d}-{batch[-1].index:08d}"


def _run_here(out, batches, controllers, spec, settings, keys, designs, progress,
              on_batch) -> float:
    limits = {k: compute_limit(k) for k in keys}
    made = {k: compute_design(k, spec.seed) for k in designs}
    finished = ((batch, evaluate_batch(batch, _used(controllers, batch), spec.road, settings,
                                       _needed(limits, batch, spec, settings),
                                       _designs(made, batch)))
                for batch in batches)
    return _collect(out, finished, sum(len(b) for b in batches), progress, on_batch)


def _collect(out, finished, total: int, progress, on_batch) -> float:
    """Write each ``(batch, rows)`` as it arrives as its part; report progress; return the
    sum of the cases' own times."""
    n, compute = 0, 0.0
    for k, (batch, rows) in enumerate(finished, start=1):
        _write_part(out, rows, _part_name(batch))
        compute += sum(r["seconds"] or 0.0 for r in rows)
        n += len(batch)
        if progress is not None:
            progress(n, total)
        if on_batch is not None:
            on_batch(k)
    return compute


def _used(controllers: dict, batch: list) -> dict:
    return {c.controller: controllers[c.controller] for c in batch
            if c.controller != PASSIVE and design_route(c.controller) is None}


def _designs(designs: dict, batch: list) -> dict:
    keys = {design_key(c) for c in batch}
    return {k: designs[k] for k in keys if k is not None}


def _needed(limits: dict, batch: list, spec: SweepSpec, settings: dict) -> dict:
    if not spec.limit:
        return {}
    keys = {limit_key(c, spec.road, settings) for c in batch}
    return {k: limits[k] for k in keys if k is not None}


def _run_dask(out, batches, controllers, spec, settings, keys, designs, scheduler, n_workers,
              progress, on_batch) -> tuple[float, int]:
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError as exc:  # a dependency of the package: a broken install
        raise InputError("sweeps need dask.distributed (pip install 'dask[distributed]')") \
            from exc
    cluster = None
    if scheduler is None:
        # one BLAS thread per worker process: two workers of two threads each on two
        # cores oversubscribe them (FACTS.md, "Sweeps")
        cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                               dashboard_address=":0", silence_logs=logging.ERROR,
                               env={"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1",
                                    "MKL_NUM_THREADS": "1"})
        client = Client(cluster)
    else:
        client = Client(scheduler, timeout="10s")
    try:
        n_workers = len(client.scheduler_info()["workers"]) or n_workers
        # each distinct limit LP and design once, as tasks of their own; the batches that
        # need them wait for them (Dask passes the results in place of the futures)
        limit_futs = {k: client.submit(compute_limit, k, pure=False) for k in keys}
        design_futs = {k: client.submit(compute_design, k, spec.seed, pure=False)
                       for k in designs}
        futures = {}
        for batch in batches:
            fut = client.submit(evaluate_batch, batch, _used(controllers, batch), spec.road,
                                settings, _needed(limit_futs, batch, spec, settings),
                                _designs(design_futs, batch), pure=False, retries=2)
            futures[fut] = batch

        def finished():
            for fut in as_completed(list(futures)):
                batch = futures[fut]
                try:
                    rows = fut.result()
                except Exception as exc:  # the batch itself failed (killed workers, ...)
                    logger.warning("sweep: batch %s failed: %s", _part_name(batch), exc)
                    rows = [error_row(c, f"{type(exc).__name__}: {exc}") for c in batch]
                yield batch, rows

        compute = _collect(out, finished(), sum(len(b) for b in batches), progress, on_batch)
        return compute, n_workers
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _consolidate(out: Path, spec: SweepSpec) -> tuple[Path, int]:
    """All parts as one table, one row per case (the first written wins), sorted by case."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from .case import METRIC_COLUMNS

    rows = {}
    for part in sorted((out / _PARTS).glob("*.parquet")):
        for row in pq.read_table(part).to_pylist():
            rows.setdefault(row["case"], row)
    columns = ["case", "controller", *spec.axis_names, *METRIC_COLUMNS]
    ordered = [rows[k] for k in sorted(rows)]
    table = pa.Table.from_pylist([{c: r.get(c) for c in columns} for r in ordered],
                                 schema=_schema(spec))
    meta = {b"lmi_suspension.spec": spec.to_json().encode(),
            b"lmi_suspension.versions": json.dumps(_versions(), sort_keys=True).encode()}
    table = table.replace_schema_metadata(meta)
    path = out / _TABLE
    tmp = out / f".{_TABLE}.tmp"
    pq.write_table(table, tmp)
    os.replace(tmp, path)
    return path, sum(1 for r in ordered if r.get("error"))


def _schema(spec: SweepSpec):
    import pyarrow as pa

    from .case import METRIC_COLUMNS

    f64, boolean = pa.float64(), pa.bool_()
    fields = [("case", pa.int64()), ("controller", pa.string())]
    fields += [(n, f64) for n in spec.axis_names]
    # the metric columns in METRIC_COLUMNS' order: one list to extend, not two
    other = {"stable": boolean, "stable_sim": boolean, "x1_within_limit": boolean,
             "error": pa.string()}
    fields += [(c, other.get(c, f64)) for c in METRIC_COLUMNS]
    return pa.schema(fields)


def read_results(out) -> tuple:
    """``(table, spec)`` of a sweep's output directory (a ``pyarrow.Table``)."""
    import pyarrow.parquet as pq

    path = Path(out) / _TABLE
    if not path.is_file():
        raise InputError(f"{path} not found: run the sweep first")
    table = pq.read_table(path)
    spec = SweepSpec.from_json(table.schema.metadata[b"lmi_suspension.spec"].decode())
    return table, spec
