"""The README's Quickstart is what CI runs."""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def quickstart_lines():
    text = (ROOT / "README.md").read_text()
    section = text.split("## Quickstart", 1)[1]
    block = re.search(r"```(?:bash|sh)?\n(.*?)```", section, re.S).group(1)
    return [line for line in block.splitlines() if line.strip()]


def test_quickstart_has_exactly_two_command_lines():
    lines = quickstart_lines()
    assert len(lines) == 2, lines
    assert lines[0].startswith("pip install") and "lmi-suspension" in lines[0]
    assert lines[1].startswith("pip install") and "pytest" in lines[1]


def test_ci_runs_quickstart_line_two():
    ci = (ROOT / ".ci" / "run").read_text().splitlines()
    commands = [c for c in ci if c.strip() and not c.startswith("#")
                and not c.startswith(("set ", "cd ", "export ", "echo ", "other="))]
    assert commands[0] == quickstart_lines()[1]
    # then the numerical tests once more under another OpenBLAS kernel
    assert len(commands) == 3 and commands[1].startswith("OPENBLAS_CORETYPE=$other ")
    assert "tests/test_hinfsyn.py" in commands[1] and "tests/test_musyn.py" in commands[1]
    # then the documentation, built by the README's command, warnings as errors
    assert commands[2] == docs_command() and " -W " in commands[2]


def docs_command() -> str:
    text = (ROOT / "README.md").read_text()
    section = text.split("## Documentation", 1)[1]
    block = section.split("```bash", 1)[1].split("```", 1)[0]
    lines = [ln for ln in block.splitlines() if ln.strip()]
    assert len(lines) == 1
    return lines[0]


@pytest.mark.slow  # the snippet runs a D-K iteration (≈ 40 s)
def test_using_it_snippet_runs():
    """The README's Python example runs as printed (its own assert included)."""
    text = (ROOT / "README.md").read_text()
    section = text.split("## Using it", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    namespace: dict = {}
    exec(compile(code, "README.md", "exec"), namespace)
    res = namespace["res"]
    assert res.mu_lower_peak <= res.mu_peak < 1.04  # below the open-source plateau
