"""Before collection, in the controlling pytest process only:

- the notebooks' ``.ipynb`` files, generated from their percent-format sources
  (``notebooks/*.py``, edited as text) so that ``pytest --nbmake`` runs what the sources say.
  The ``.ipynb`` files are build products (ignored by git), rewritten whenever their source
  is newer;
- under pytest-xdist (``-n N``), the BLAS threads of each worker, so that N workers share the
  cores instead of each starting one OpenBLAS thread per core.
"""

import os
from pathlib import Path

NOTEBOOKS = Path(__file__).parent / "notebooks"

#: items that carry no decorator of their own (notebooks, doctests) but belong to the second
#: tier (``-m slow``), with their time on a 2-core Zen 1 EPYC (2026-12-02, the whole suite
#: in one process): each is a full design run; notebook 01, 03 and every other doctest
#: stay in the first tier
_SLOW_ITEMS = {
    "notebooks/02_mu_synthesis.ipynb": 43,
    "notebooks/04_robustness_map.ipynb": 123,
    "notebooks/05_constraints.ipynb": 65,
    "notebooks/06_uncertain_models.ipynb": 66,
    "notebooks/07_structured_tuning.ipynb": 15,  # 26-33 s while the machine was shared
    "notebooks/08_gain_scheduling.ipynb": 41,
    "lmi_suspension/mu/dsearch.py::lmi_suspension.mu.dsearch.search_dscales": 14,
}

#: OpenBLAS's and the OpenMP runtime's thread settings, given to the workers (and to the
#: notebook kernels they start) through the environment they inherit; a value the user
#: set is kept (the second pass of ``.ci/run`` sets its own thread count).
_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")


def pytest_configure(config):
    if hasattr(config, "workerinput"):  # an xdist worker: the controller did the work
        return
    import jupytext

    for src in sorted(NOTEBOOKS.glob("[0-9][0-9]_*.py")):
        dst = src.with_suffix(".ipynb")
        if not dst.exists() or dst.stat().st_mtime < src.stat().st_mtime:
            jupytext.write(jupytext.read(src, fmt="py:percent"), dst, fmt="ipynb")

    workers = _xdist_workers(config)
    if workers > 1:
        threads = str(max(1, (os.cpu_count() or 1) // workers))
        for name in _THREAD_VARIABLES:
            os.environ.setdefault(name, threads)


def _xdist_workers(config) -> int:
    """The number of xdist workers this run starts (0 without xdist)."""
    n = getattr(config.option, "numprocesses", None)
    if n in (None, 0):
        return 0
    if isinstance(n, int):
        return n
    return os.cpu_count() or 1  # "auto" / "logical": xdist starts one worker per CPU


def pytest_collection_modifyitems(config, items):
    import pytest

    for item in items:
        path = item.nodeid.split("::", 1)[0]
        if path in _SLOW_ITEMS or item.nodeid in _SLOW_ITEMS:
            item.add_marker(pytest.mark.slow)
