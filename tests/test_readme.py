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


def ci_commands() -> list[str]:
    """The commands of ``.ci/run``: continuation lines joined; comments, shell settings,
    messages and variable assignments left out."""
    text = (ROOT / ".ci" / "run").read_text().replace("\\\n", " ")
    return [" ".join(c.split()) for c in text.splitlines()
            if c.strip() and not c.startswith("#")
            and not c.startswith(("set ", "cd ", "export ", "echo "))
            and not re.match(r"^\w+=\$\(", c)]


def test_ci_runs_quickstart_line_two():
    commands = ci_commands()
    assert commands[0] == quickstart_lines()[1]
    # line 2 runs the first tier on every core; the second tier is CI's named next step
    assert " -n auto " in commands[0] and commands[0].endswith('-m "not slow"')
    assert len(commands) == 4
    assert commands[1].startswith("OPENBLAS_CORETYPE=$other ") and " -m slow " in commands[1]
    assert "--nbmake" in commands[1] and " -n auto " in commands[1]
    # then the first tier's numerical tests once more under another kernel and thread count
    assert commands[2].startswith("OPENBLAS_CORETYPE=$other OPENBLAS_NUM_THREADS=2 ")
    assert '-m "not slow"' in commands[2] and " -n " not in commands[2]
    assert "tests/test_hinfsyn.py" in commands[2] and "tests/test_musyn.py" in commands[2]
    # then the documentation, built by the README's command, warnings as errors
    assert commands[3] == docs_command() and " -W " in commands[3]


def test_every_test_runs_in_one_of_the_two_tiers():
    """The first tier (``-m "not slow"``) and the second (``-m slow``) together are the
    whole suite: neither step of ``.ci/run`` narrows the selection by path."""
    first, second = ci_commands()[:2]
    assert not re.search(r"\b(tests|notebooks|lmi_suspension)/", first + second)
    assert "-k " not in first + second


#: test modules that run iterative numerics but stay out of the second pass: they run
#: the seat's end-to-end pipelines (design, reproduce, CLI, limit LP) on top of the
#: routines whose own modules are in it, and would double CI's time
_SECOND_PASS_EXEMPT = {"test_cli.py", "test_design.py", "test_reproduce.py", "test_limit.py",
                       "test_readme.py"}
#: entry points of the iterative numerical routines (synthesis, µ, D-K, intervals, ...)
_ITERATIVE = re.compile(r"\b(hinfsyn|hinfnorm|mussv|musyn|msyn|h2hinfsyn|interval_bound|"
                        r"refine_\w+|fit_dscales|search_dscales|robstab|wcgain|worst_bump_seats)\b")


def test_second_pass_names_every_iterative_numerical_module():
    """Issue 36: every test module of an iterative numerical algorithm runs twice in CI,
    the second time under another kernel and thread count (so roundoff-fragile
    assertions fail in CI before they fail on a user's CPU)."""
    second = set(re.findall(r"tests/(test_\w+\.py)", ci_commands()[2]))
    assert all((ROOT / "tests" / name).exists() for name in second), second
    iterative = {p.name for p in (ROOT / "tests").glob("test_*.py")
                 if _ITERATIVE.search(p.read_text())}
    assert iterative - _SECOND_PASS_EXEMPT <= second, iterative - _SECOND_PASS_EXEMPT - second


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
