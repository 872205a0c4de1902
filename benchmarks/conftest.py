"""The benchmarks' machine description: ``--benchmark-json`` files name the OpenBLAS
kernel and thread count and the versions of the solvers, so that a table generated from
one (``benchmarks/current.py``) can say what it was measured on."""

import os
from importlib import metadata

#: load average when the session started: other jobs on the machine inflate the times
_LOAD_AT_START: tuple = ()


def pytest_sessionstart(session):
    global _LOAD_AT_START
    _LOAD_AT_START = os.getloadavg()


def pytest_benchmark_update_machine_info(config, machine_info):
    import numpy  # noqa: F401  (loads OpenBLAS, so that threadpoolctl sees it)

    try:
        import threadpoolctl

        blas = [i for i in threadpoolctl.threadpool_info() if i.get("internal_api") == "openblas"]
    except ImportError:  # threadpoolctl is a test dependency; without it, say so
        blas = []
    machine_info["openblas"] = {
        "kernel": blas[0].get("architecture") if blas else None,
        "threads": blas[0].get("num_threads") if blas else None,
        "OPENBLAS_CORETYPE": os.environ.get("OPENBLAS_CORETYPE"),
        "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS"),
    }
    versions = {}
    for dist in ("lmi_suspension", "control", "slycot", "cvxpy", "clarabel", "dkpy", "numpy"):
        try:
            versions[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:  # a peer not installed is not measured
            versions[dist] = None
    machine_info["versions"] = versions
    machine_info["cpu_count"] = os.cpu_count()
    # 1-minute load averages at the start and the end of the run
    machine_info["load_average"] = [round(_LOAD_AT_START[0], 2) if _LOAD_AT_START else None,
                                    round(os.getloadavg()[0], 2)]
