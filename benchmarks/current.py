"""The current figure of every benchmark: one table each, at the top of BENCHMARKS.md, and
the figures the documentation quotes (``benchmarks/current.json``), from one source.

The source is ``benchmarks/results/``:

- ``*.json`` files written by ``pytest benchmarks/bench_X.py --benchmark-json=FILE``
  (pytest-benchmark; ``benchmarks/conftest.py`` adds the OpenBLAS kernel, thread count
  and solver versions to their ``machine_info``), added with ``--add FILE``;
- ``transcribed.json``: figures transcribed by hand from dated entries of
  ``benchmarks/HISTORY.md`` for benchmarks whose runs left no JSON file, each with its
  date, machine, kernel, command and the entry it comes from.

For each benchmark the newest entry wins. Usage::

    python benchmarks/current.py --add out.json   # store a run (then regenerates)
    python benchmarks/current.py                  # regenerate BENCHMARKS.md and current.json
    python benchmarks/current.py --check          # exit 1 if either is out of date

``tests/test_benchmarks_current.py`` runs ``--check``, and ``docs/conf.py`` reads
``current.json`` for the figures ``docs/comparison.md`` quotes, so the two cannot part.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import shutil
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results"
BENCHMARKS_MD = ROOT / "BENCHMARKS.md"
CURRENT_JSON = HERE / "current.json"
HISTORY = "benchmarks/HISTORY.md"

#: the generated part of BENCHMARKS.md ends here; the text below it is kept as it is
MARKER = "<!-- end of the generated tables: benchmarks/current.py writes everything above -->"

#: table order; a benchmark not listed comes after these
ORDER = ("hinfsyn", "kernel_agreement", "mussv", "musyn", "musyn_kernels", "msyn", "sweep",
         "refine")


# --- pytest-benchmark JSON -> entries ---------------------------------------------------

def _module(bench: dict) -> str:
    """``bench_hinfsyn`` from ``benchmarks/bench_hinfsyn.py::test_hinfsyn[4-lmi]``."""
    return Path(bench["fullname"].split("::", 1)[0]).stem


def _machine(run: dict) -> tuple[str, str]:
    info = run.get("machine_info", {})
    cpu = info.get("cpu", {}).get("brand_raw") or info.get("processor") or "unknown CPU"
    cores = info.get("cpu_count") or info.get("cpu", {}).get("count")
    machine = f"{cores}-core {cpu}" if cores else cpu
    load = info.get("load_average")
    if load and None not in load:
        machine += f", load average {load[0]:g} at the start and {load[1]:g} at the end"
    blas = info.get("openblas") or {}
    kernel = blas.get("kernel") or "kernel not recorded"
    if blas.get("OPENBLAS_CORETYPE"):
        kernel += " (OPENBLAS_CORETYPE)"
    threads = blas.get("OPENBLAS_NUM_THREADS") or blas.get("threads")
    if threads:
        kernel += f", {threads} thread{'s' if str(threads) != '1' else ''}"
    return machine, kernel


def _loaded(run: dict) -> bool:
    """Other work ran beside the benchmark: a load average above the core count."""
    info = run.get("machine_info", {})
    load, cores = info.get("load_average") or [], info.get("cpu_count")
    return bool(cores) and any(x is not None and x > cores for x in load)


def _seconds(bench: dict) -> float:
    return float(bench["stats"]["median"])


def _hinfsyn_entry(benches: list[dict]) -> dict:
    by = {(b["extra_info"]["n"], b["extra_info"]["method"]): b for b in benches}
    orders = sorted({n for n, _ in by})
    methods = [m for m in ("lmi", "lmi_explicit", "lmi_sdp", "lmi_clarabel", "riccati", "dkpy")
               if any(k[1] == m for k in by)]
    label = {"lmi": "LMI", "lmi_explicit": "LMI explicit", "lmi_sdp": "LMI controller SDP",
             "lmi_clarabel": "LMI Clarabel", "riccati": "Riccati", "dkpy": "dkpy"}
    columns = ["n"] + [f"{label[m]} [s]" for m in methods] + ["LMI/Riccati"]
    columns += [f"certified γ {label[m]}" for m in methods]
    no_dkpy = [n for n in orders if (n, "dkpy") not in by]
    rows = []
    for n in orders:
        row: list = [n]
        for m in methods:
            b = by.get((n, m))
            row.append(round(_seconds(b), 3) if b else "")
        lmi, ric = by.get((n, "lmi")), by.get((n, "riccati"))
        row.append(round(_seconds(lmi) / _seconds(ric), 1) if lmi and ric else "")
        for m in methods:
            b = by.get((n, m))
            if b is None:
                row.append("")
            elif "error" in b["extra_info"]:
                row.append("no controller")
            else:
                g = b["extra_info"].get("gamma")
                own = b["extra_info"].get("gamma_solver")
                cell = "inf (unstable)" if g is None or not math.isfinite(g) else f"{g:.6g}"
                if m == "riccati" and own is not None and (g is None or not math.isfinite(g)):
                    cell += f", its own γ {own:.6g}"
                status = b["extra_info"].get("status")
                if m == "lmi_explicit" and status is not None and status != "explicit":
                    cell += f" (status {status}: the controller LMI's)"
                if m == "lmi" and status == "explicit" and "lmi_sdp" in methods:
                    cell += " (explicit)"
                row.append(cell)
        rows.append(row)
    return {"id": "hinfsyn",
            "title": "H∞ synthesis: LMI against python-control's Riccati" +
                     (" and dkpy" if "dkpy" in methods else ""),
            "note": "one round per case (median of 1); every γ certified by "
                    "hinfnorm(lft(P, K)), inf where the loop is unstable" +
                    ("" if "dkpy" in methods else "; dkpy not installed for this run") +
                    ("; dkpy not run at n = " + ", ".join(str(n) for n in no_dkpy) +
                     " (bench_hinfsyn.DKPY_MAX_ORDER)" if "dkpy" in methods and no_dkpy
                     else "") +
                    ("; LMI explicit: HinfsynOptions(controller=\"explicit\"), the "
                     "controller LMI's controller where the explicit formulas fail their "
                     "check (status shown)" if "lmi_explicit" in methods else "") +
                    ("; LMI: the defaults (structured γ minimisation, explicit controller "
                     "where it passes its checks: marked), LMI controller SDP: "
                     "controller=\"sdp\", LMI Clarabel: gamma_solver=\"clarabel\", "
                     "controller=\"sdp\" (the defaults until 2026-11-29)"
                     if "lmi_clarabel" in methods else ""),
            "columns": columns, "rows": rows}


def _generic_entry(module: str, benches: list[dict]) -> dict:
    rows = [[b["name"], round(_seconds(b), 4), b["stats"]["rounds"],
             ", ".join(f"{k}={_short(v)}" for k, v in sorted(b["extra_info"].items())
                       if not isinstance(v, (list, dict)))]
            for b in sorted(benches, key=lambda b: b["name"])]
    return {"id": module.removeprefix("bench_").removeprefix("test_bench_"),
            "title": f"{module}.py", "note": "median over the rounds",
            "columns": ["benchmark", "median [s]", "rounds", "extra_info"], "rows": rows}


def _short(v) -> str:
    return f"{v:.6g}" if isinstance(v, float) else str(v)


def entries_from_run(path: Path) -> list[dict]:
    """The table entries of one ``--benchmark-json`` file, one per benchmark module."""
    run = json.loads(path.read_text())
    machine, kernel = _machine(run)
    modules: dict[str, list[dict]] = {}
    for b in run["benchmarks"]:
        modules.setdefault(_module(b), []).append(b)
    commit = run.get("commit_info", {})
    out = []
    for module, benches in sorted(modules.items()):
        entry = _hinfsyn_entry(benches) if module == "bench_hinfsyn" else \
            _generic_entry(module, benches)
        versions = run.get("machine_info", {}).get("versions") or {}
        entry.update(
            date=run["datetime"][:10], machine=machine, kernel=kernel,
            command=f"python -m pytest benchmarks/{module}.py --benchmark-only "
                    f"-p no:cacheprovider --benchmark-json=FILE",
            source=f"benchmarks/results/{path.name}",
            commit=(commit.get("id") or "")[:10] + (" (dirty)" if commit.get("dirty") else ""),
            loaded=_loaded(run),
            versions={k: v for k, v in versions.items() if v})
        out.append(entry)
    return out


def load_entries(results: Path = RESULTS) -> list[dict]:
    """The newest entry of every benchmark: runs' JSON files and the transcribed ones."""
    candidates: list[dict] = []
    transcribed = results / "transcribed.json"
    if transcribed.exists():
        for e in json.loads(transcribed.read_text())["entries"]:
            candidates.append(dict(e, source=f"transcribed by hand from {HISTORY}, "
                                             f"“{e['history']}”"))
    for path in sorted(results.glob("*.json")):
        if path.name != "transcribed.json":
            candidates.extend(entries_from_run(path))
    newest: dict[str, dict] = {}
    for e in candidates:  # later files win a tie of dates
        if e["id"] not in newest or e["date"] >= newest[e["id"]]["date"]:
            newest[e["id"]] = e
    rank = {k: i for i, k in enumerate(ORDER)}
    return sorted(newest.values(), key=lambda e: (rank.get(e["id"], len(ORDER)), e["id"]))


# --- the figures the documentation quotes ---------------------------------------------

def _cell(entry: dict, key, column: str):
    """The cell of ``column`` in the row whose first cell is ``key``."""
    j = entry["columns"].index(column)
    for row in entry["rows"]:
        if row[0] == key:
            return row[j]
    raise KeyError(f"{entry['id']}: no row {key!r}")


def _num(x, spec: str) -> str:
    return format(x, spec) if isinstance(x, (int, float)) else str(x)


def _and(items: list[str]) -> str:
    """``"a, b and c"``; ``"no"`` for none."""
    return " and ".join([", ".join(items[:-1]), items[-1]]) if len(items) > 1 else \
        "".join(items) or "no"


def quoted_figures(entries: list[dict]) -> dict[str, str]:
    """Flat ``name -> text`` figures for ``docs/comparison.md`` (MyST substitutions)."""
    e = {x["id"]: x for x in entries}
    f: dict[str, str] = {}
    h = e["hinfsyn"]
    has = set(h["columns"])
    for n in (22, 40):
        f[f"hinfsyn_{n}_lmi"] = _num(_cell(h, n, "LMI [s]"), ".2f") + " s"
        f[f"hinfsyn_{n}_riccati"] = _num(_cell(h, n, "Riccati [s]"), ".2f") + " s"
        if "dkpy [s]" not in has:
            f[f"hinfsyn_{n}_dkpy"] = "not measured in this run"
            continue
        f[f"hinfsyn_{n}_dkpy"] = _num(_cell(h, n, "dkpy [s]"), ".2f") + " s"
        if "certified γ dkpy" in has and _cell(h, n, "certified γ dkpy") == "no controller":
            f[f"hinfsyn_{n}_dkpy"] += " to return no controller"
    # which peers failed where, when the table says (a run's JSON does)
    for method, column in (("riccati", "certified γ Riccati"), ("dkpy", "certified γ dkpy")):
        if column in has:
            j = h["columns"].index(column)
            unstable = [str(r[0]) for r in h["rows"] if str(r[j]).startswith("inf")]
            none = [str(r[0]) for r in h["rows"] if r[j] == "no controller"]
            f[f"hinfsyn_{method}_unstable_at"] = _and(unstable)
            f[f"hinfsyn_{method}_none_at"] = _and(none)
    ratios = [r[h["columns"].index("LMI/Riccati")] for r in h["rows"] if r[0] >= 22]
    ratios = [r for r in ratios if isinstance(r, (int, float))]
    f["hinfsyn_ratio_from_22"] = f"{min(ratios):.1f}–{max(ratios):.1f}"
    f["hinfsyn_source"] = f"{h['date']}, {h['machine']}, OpenBLAS {h['kernel']}"
    m = e["musyn"]
    f["musyn_lmi_mu"] = _num(_cell(m, "LMI K-steps (default)", "µ (dense grid)"), ".4f")
    f["musyn_lmi_s"] = _num(_cell(m, "LMI K-steps (default)", "seconds"), ".1f")
    f["musyn_best_mu"] = _num(_cell(m, 'method="best"', "µ (dense grid)"), ".4f")
    f["musyn_best_s"] = _num(_cell(m, 'method="best"', "seconds"), ".1f")
    f["musyn_dkpy_mu"] = _num(_cell(m, "dkpy 0.1.9, SLICOT K-step", "µ (dense grid)"), ".4f")
    f["musyn_dkpy_s"] = _num(_cell(m, "dkpy 0.1.9, SLICOT K-step", "seconds"), ".1f")
    f["musyn_source"] = f"{m['date']}, {m['kernel']}"
    k = e["musyn_kernels"]
    mus = [r[j] for r in k["rows"] for j in (1, 3)]
    secs = [r[j] for r in k["rows"] for j in (2, 4)]
    f["musyn_kernels_mu"] = f"{min(mus):.4f}–{max(mus):.4f}"
    f["musyn_kernels_spread"] = re.sub(r"e-0(\d)", r"e-\1", f"{max(mus) / min(mus) - 1:.1e}")
    f["musyn_kernels_s"] = f"{min(secs):.0f}–{max(secs):.0f}"
    f["musyn_kernels_count"] = str(len(mus))
    s = e["sweep"]
    f["sweep_1000_wall_2_workers"] = _num(_cell(s, 2, "wall [s]"), ".0f")
    f["sweep_1000_wall_1_worker"] = _num(_cell(s, 1, "wall [s]"), ".0f")
    f["sweep_1000_rate_2_workers"] = _num(_cell(s, 2, "cases/s"), ".1f")
    f["sweep_source"] = f"{s['date']}, {s['kernel']}"
    return f


# --- rendering ------------------------------------------------------------------------

def _fmt(v) -> str:
    # as stored: the transcribed figures keep their printed digits, a run's are rounded
    # where its entry is built
    return str(v).replace("|", "\\|")


def render(entries: list[dict]) -> str:
    """The generated top of BENCHMARKS.md (up to and including :data:`MARKER`)."""
    out = ["# Benchmarks: current figures", "",
           "One table per benchmark: its newest measurement, with the peers measured in the "
           "same run, the machine, the OpenBLAS kernel, the date and the command. Generated "
           "by `python benchmarks/current.py` from `benchmarks/results/` (the runs' "
           "`--benchmark-json` files, and figures transcribed from dated entries where a run "
           "left none); do not edit above the line at the end of this part. The dated "
           f"history of every benchmark, with what changed and why, is in [`{HISTORY}`]"
           f"({HISTORY}).", ""]
    for e in entries:
        out += [f"## {e['title']}", ""]
        meta = [f"**{e['date']}**, {e['machine']}, OpenBLAS {e['kernel']}",
                f"command: `{e['command']}`", f"source: {e['source']}"]
        if e.get("commit"):
            meta.append(f"commit {e['commit']}")
        if e.get("versions"):
            meta.append("versions: " + ", ".join(f"{k} {v}" for k, v in e["versions"].items()))
        out += ["; ".join(meta[:1]) + ".  ", *(m + ".  " for m in meta[1:-1]), meta[-1] + ".",
                ""]
        out += ["| " + " | ".join(e["columns"]) + " |",
                "|" + "---|" * len(e["columns"])]
        out += ["| " + " | ".join(_fmt(c) for c in row) + " |" for row in e["rows"]]
        if e.get("note"):
            # only a Latin first letter is capitalised: "µ".upper() is Greek capital Mu
            note = e["note"]
            out += ["", (note[0].upper() if note[0].isascii() else note[0]) + note[1:] + "."]
        if e.get("loaded"):
            out += ["", "The machine was shared during this run (load average above its "
                        "core count): its times are inflated against an idle run, the peers' "
                        "as much as ours; the certified figures do not depend on it. The "
                        "idle figures of earlier runs are in the history."]
        out.append("")
    out.append(MARKER)
    return "\n".join(out) + "\n"


def generated(results: Path = RESULTS) -> tuple[str, str]:
    """(BENCHMARKS.md's generated part, current.json's text)."""
    entries = load_entries(results)
    current = {"about": "Generated by benchmarks/current.py from benchmarks/results/; "
                        "docs/comparison.md quotes 'figures' (MyST substitutions, docs/conf.py).",
               "figures": quoted_figures(entries),
               "benchmarks": {e["id"]: {k: e[k] for k in ("date", "machine", "kernel", "source")}
                              for e in entries}}
    return render(entries), json.dumps(current, indent=1, ensure_ascii=False) + "\n"


def _kept_part(text: str) -> str:
    """What follows the generated part (its marker line's newline excluded)."""
    return text.split(MARKER, 1)[1].removeprefix("\n") if MARKER in text else text


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--add", type=Path, metavar="FILE",
                    help="copy a --benchmark-json file into benchmarks/results/ first")
    ap.add_argument("--check", action="store_true",
                    help="exit 1 if BENCHMARKS.md or current.json is not what the results give")
    args = ap.parse_args(argv)
    if args.add is not None:
        run = json.loads(args.add.read_text())
        modules = sorted({_module(b) for b in run["benchmarks"]})
        stamp = re.sub(r"[^0-9T]", "", run["datetime"][:16])
        dst = RESULTS / f"{'+'.join(m.removeprefix('bench_') for m in modules)}-{stamp}.json"
        shutil.copyfile(args.add, dst)
        print(f"stored {dst.relative_to(ROOT)}")
    top, current = generated()
    old_md = BENCHMARKS_MD.read_text() if BENCHMARKS_MD.exists() else ""
    new_md = top + _kept_part(old_md)
    if args.check:
        stale = [p.name for p, old, new in ((BENCHMARKS_MD, old_md, new_md),
                                             (CURRENT_JSON, CURRENT_JSON.read_text()
                                              if CURRENT_JSON.exists() else "", current))
                 if old != new]
        if stale:
            print(f"out of date: {', '.join(stale)} (run python benchmarks/current.py)")
            return 1
        return 0
    BENCHMARKS_MD.write_text(new_md)
    CURRENT_JSON.write_text(current)
    print(f"wrote {BENCHMARKS_MD.relative_to(ROOT)} and {CURRENT_JSON.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
