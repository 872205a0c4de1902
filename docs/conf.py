"""Sphinx configuration: user guide (MyST markdown), API reference (autosummary +
numpydoc, from the docstrings), and the notebooks executed during the build (myst-nb,
reading their percent-format sources through jupytext).

Build: ``sphinx-build -W -b html docs docs/_build/html`` (warnings are errors).

While iterating on the prose, ``LMI_DOCS_NB_EXECUTION=off`` (or ``cache``) skips (or
caches) the notebooks' execution; the default, and CI, run them all.
"""

import json
import os
import shutil
from pathlib import Path

import lmi_suspension

HERE = Path(__file__).parent
ROOT = HERE.parent

project = "lmi_suspension"
author = "lmi_suspension developers"
release = version = lmi_suspension.__version__
copyright = "2026, lmi_suspension developers"

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    # MathJax 3 shipped inside a PyPI package and copied into _static/: the pages render
    # their maths with no network at read time (sphinx.ext.mathjax alone loads a CDN)
    "sphinx-mathjax-offline",
    "numpydoc",
]

# --- the notebooks: copied from notebooks/ (their only source) before every build -------
_NB_DIR = HERE / "notebooks"


def _copy_notebooks():
    _NB_DIR.mkdir(exist_ok=True)
    for src in sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.py")):
        shutil.copy2(src, _NB_DIR / src.name)
    shutil.copy2(ROOT / "notebooks" / "controller.json", _NB_DIR / "controller.json")


_copy_notebooks()
nb_custom_formats = {".py": ["jupytext.reads", {"fmt": "py:percent"}]}
# every build runs them: the pages show today's numbers
nb_execution_mode = os.environ.get("LMI_DOCS_NB_EXECUTION", "force")
nb_execution_timeout = 600
nb_execution_raise_on_error = True  # a failing notebook fails the build
nb_merge_streams = True
# the notebooks' tables are display(Markdown(...)) pipe tables: CommonMark (the default)
# has no tables and shows the pipes as a paragraph; MyST renders them as HTML tables
nb_render_markdown_format = "myst"
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "substitution"]
# the benchmark figures the pages quote ({{ name }}), from the file that also writes
# BENCHMARKS.md's tables (benchmarks/current.py): the two cannot disagree
myst_substitutions = json.loads((ROOT / "benchmarks" / "current.json").read_text())["figures"]
myst_heading_anchors = 3

# .rst first: autosummary writes its generated pages with the first suffix
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".py": "myst-nb"}
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]
# only the notebooks are .py sources; conf.py itself is not a page
exclude_patterns += ["conf.py"]

# --- API reference -----------------------------------------------------------------------
autosummary_generate = True
autosummary_ignore_module_all = False  # a module's public names are its __all__
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types
autodoc_default_options = {"members": True, "inherited-members": False}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks = set()  # the docstrings follow numpydoc; the build checks markup

html_theme = "furo"
html_title = f"lmi_suspension {release}"
html_static_path = []
