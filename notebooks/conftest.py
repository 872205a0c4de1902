"""The notebooks' sources are the percent-format ``*.py`` files here (jupytext); pytest
does not import them as modules (they are notebooks, run by nbmake from the ``.ipynb``
that the root ``conftest.py`` writes from them)."""

collect_ignore_glob = ["*.py"]
