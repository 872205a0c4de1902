"""The import graph of the package, read from the source (``ast``, nothing is imported).

The floors of the numerical core, lowest first (the project's architecture notes): typed
errors, LTI plants, synthesis on one plant, the uncertain models (``umodel``), µ, and
the robustness analysis above µ (``uncertain``).  A module imports only its own floor
and those below; no modules import each other, directly or through others.  Imports
inside functions count: they run as soon as the function does.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "lmi_suspension"

#: floor of each folder (or module) of the core, lowest first
FLOORS = ("lmi_suspension.errors", "lmi_suspension.lti", "lmi_suspension.synthesis",
          "lmi_suspension.umodel", "lmi_suspension.mu", "lmi_suspension.uncertain")


def _modules() -> dict[str, Path]:
    out = {}
    for path in PACKAGE.rglob("*.py"):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def _is_package(path: Path) -> bool:
    return path.name == "__init__.py"


def _imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """The modules of the package that ``name`` imports (a ``from P import x`` of a
    submodule ``x`` names ``P.x``; the packages on the way to an imported module are
    imported too, except those that hold ``name`` itself)."""
    here = name if _is_package(path) else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here.split(".")
                base = base[:len(base) - (node.level - 1)]
                base = ".".join(base + ([node.module] if node.module else []))
            else:
                base = node.module or ""
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base
                       for a in node.names]
        else:
            continue
        for t in targets:
            while t and t not in modules:  # `import a.b.func`-like: the module holding it
                t = t.rpartition(".")[0]
            if not t:
                continue
            found.add(t)
            parent = t.rpartition(".")[0]
            while parent and not (name == parent or name.startswith(parent + ".")):
                found.add(parent)
                parent = parent.rpartition(".")[0]
    found.discard(name)
    return found


@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    modules = _modules()
    return {m: _imports(m, p, modules) for m, p in modules.items()}


def _floor(module: str) -> int | None:
    for i, f in enumerate(FLOORS):
        if module == f or module.startswith(f + "."):
            return i
    return None


def _cycles(graph: dict[str, set[str]], nodes: set[str]) -> list[list[str]]:
    """Strongly connected components of more than one module among ``nodes``
    (Tarjan's algorithm), each sorted."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v] & nodes:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return out


def test_the_reader_sees_imports_of_every_kind(graph):
    """The parser is checked on imports the package is known to hold: a relative import
    inside a function (``mu.dk`` takes ``lftdata`` from the models when it is given an
    uncertain plant), a ``from . import`` of a package's own names, and a submodule
    named through its package."""
    assert "lmi_suspension.umodel.uss" in graph["lmi_suspension.mu.dk"]
    assert "lmi_suspension.mu.steps" in graph["lmi_suspension.mu.steps.kstep"]
    assert "lmi_suspension.mu" in graph["lmi_suspension.uncertain.analysis"]
    assert "lmi_suspension.umodel.lfr" in graph["lmi_suspension.umodel.atoms"]
    # a cycle is found where there is one
    toy = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert _cycles(toy, set(toy)) == [["a", "b", "c"]]


def test_no_cycle_in_the_core(graph):
    core = {m for m in graph if _floor(m) is not None}
    assert _cycles(graph, core) == []


def test_no_import_runs_up_a_floor(graph):
    """Each module of the core imports only modules of its floor or below (a module of
    the package outside these floors -- the seat, tuning, reports -- stands above them
    all)."""
    upward = sorted((m, t) for m, targets in graph.items() if _floor(m) is not None
                    for t in targets
                    if _floor(t) is None or _floor(t) > _floor(m))
    assert upward == []


#: the seat package's floors, lowest first (the architecture notes): the seat itself (no
#: design code); the loop's closed forms, the µ check and the set of seats with its worst
#: case; the result module (SeatDesign, certify_seat); one module per route; the table of
#: routes on top.  A module of the seat not named here fails the test below: place it.
SEAT_FLOORS = (
    ("params", "model", "roads", "comfort", "weights", "simulate", "limit", "uncertainty",
     "augmented", "sampled"),
    ("loop", "goals", "mucheck", "occupants", "worstcase", "scheduled_lpv", "occupant_subset",
     "scheduled", "schedule_use"),
    ("record",),
    ("design", "constrained", "bounded", "discrete_design", "refine", "multimodel"),
    ("routes",),
)


def _seat_floor(module: str) -> int | None:
    short = module.removeprefix("lmi_suspension.seat.")
    return next((i for i, f in enumerate(SEAT_FLOORS) if short in f), None)


def test_no_cycle_in_the_seat(graph):
    """The seat's modules import no circle (``routes`` imported every route and every
    route took ``seat_design_from`` from ``routes``: nine modules in one circle until
    the result type and the loop's closed forms moved below the routes)."""
    seat = {m for m in graph if m.startswith("lmi_suspension.seat.")}
    assert len(seat) > 15
    assert _cycles(graph, seat) == []


def test_the_seat_floors(graph):
    """Every seat module has a floor and imports only its floor and those below; no seat
    module imports ``routes`` (only the package's face and the layers above the seat
    do)."""
    seat = sorted(m for m in graph if m.startswith("lmi_suspension.seat."))
    assert [m for m in seat if _seat_floor(m) is None] == []
    upward = sorted((m, t) for m in seat for t in graph[m]
                    if t.startswith("lmi_suspension.seat.") and _seat_floor(t) > _seat_floor(m))
    assert upward == []
    assert [m for m in seat if "lmi_suspension.seat.routes" in graph[m]] == []
