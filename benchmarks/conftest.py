"""The benchmarks' machine description: ``--benchmark-json`` files name the OpenBLAS
kernel and thread count and the versions of the solvers, so that a table generated from
one (``benchmarks/current.py``) can say what it was measured on."""

import os
from importlib import metadata


def pytest_benchmark_update_machine_info(config, machine_info):
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
