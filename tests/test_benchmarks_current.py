"""BENCHMARKS.md, the figures the documentation quotes and the gallery come from one source
each, and cannot drift from it."""

import importlib.util
import json
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _current():
    spec = importlib.util.spec_from_file_location("bench_current",
                                                  ROOT / "benchmarks" / "current.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_benchmarks_md_and_current_json_are_generated_from_the_results():
    """``python benchmarks/current.py --check``: regenerate after adding a result."""
    assert _current().main(["--check"]) == 0


def test_every_current_table_names_its_date_machine_kernel_and_command():
    text = (ROOT / "BENCHMARKS.md").read_text()
    top = text.split(_current().MARKER, 1)[0]
    sections = top.split("\n## ")[1:]
    assert len(sections) >= 5
    for section in sections:
        assert re.search(r"\*\*20\d\d-\d\d-\d\d\*\*, .+, OpenBLAS ", section), section[:80]
        assert "command: `" in section and "source: " in section


def test_comparison_page_quotes_only_current_figures():
    """The comparison page's figures are substitutions from current.json (docs/conf.py):
    each one exists, and no figure of an earlier measurement is typed in by hand."""
    figures = json.loads((ROOT / "benchmarks" / "current.json").read_text())["figures"]
    page = (ROOT / "docs" / "comparison.md").read_text()
    used = set(re.findall(r"\{\{\s*(\w+)\s*\}\}", page))
    assert used and used <= set(figures), used - set(figures)
    for other in (ROOT / "docs").glob("guide/*.md"):  # other pages quote some too
        names = set(re.findall(r"\{\{\s*(\w+)\s*\}\}", other.read_text()))
        assert names <= set(figures), (other.name, names - set(figures))
    # the stale figures this page once carried (issue 40)
    for stale in ("0.964–0.972", "0.9687", "0.9706", "10.8 s", "14.3 s", "7.4 s"):
        assert stale not in page, stale


def test_quoted_musyn_figures_are_those_of_the_benchmarks_table():
    figures = json.loads((ROOT / "benchmarks" / "current.json").read_text())["figures"]
    text = (ROOT / "BENCHMARKS.md").read_text()
    row = re.search(r"\| LMI K-steps \(default\) \| ([0-9.]+) \| ([0-9.]+) \|", text)
    assert row is not None
    assert figures["musyn_lmi_mu"] == f"{float(row.group(1)):.4f}"
    assert figures["musyn_lmi_s"] == f"{float(row.group(2)):.1f}"


def test_gallery_shows_every_figure_reproduce_writes():
    from test_reproduce import EXPECTED_PNGS

    page = (ROOT / "docs" / "gallery.md").read_text()
    shown = set(re.findall(r"\]\(gallery/([\w.]+\.png)\)", page))
    assert EXPECTED_PNGS <= shown, EXPECTED_PNGS - shown
    for name in shown:
        assert (ROOT / "docs" / "gallery" / name).stat().st_size > 0
    # small enough to keep in the repository
    assert sum(p.stat().st_size for p in (ROOT / "docs" / "gallery").glob("*.png")) < 1.5e6
