"""Before collection: the notebooks' ``.ipynb`` files, generated from their percent-format
sources (``notebooks/*.py``, edited as text) so that ``pytest --nbmake`` runs what the
sources say.  The ``.ipynb`` files are build products (ignored by git), rewritten whenever
their source is newer."""

from pathlib import Path

NOTEBOOKS = Path(__file__).parent / "notebooks"


def pytest_configure(config):
    import jupytext

    for src in sorted(NOTEBOOKS.glob("[0-9][0-9]_*.py")):
        dst = src.with_suffix(".ipynb")
        if not dst.exists() or dst.stat().st_mtime < src.stat().st_mtime:
            jupytext.write(jupytext.read(src, fmt="py:percent"), dst, fmt="ipynb")
