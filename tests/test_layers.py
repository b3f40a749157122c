"""The package's import structure: the layer and independence contracts of pyproject.toml (import-linter,
which sees function-local imports too), no import cycle between any two modules, and no path tricks."""

import re
import subprocess
import sys
from pathlib import Path

import grimp

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "scfmu"


def test_import_contracts_hold():
    r = subprocess.run([str(Path(sys.executable).parent / "lint-imports"), "--config", str(ROOT / "pyproject.toml")],
                       cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-2000:]
    assert "0 broken" in r.stdout


def _cycle(graph) -> list[str] | None:
    """One import cycle among the package's modules (depth-first search), or None."""
    mods = sorted(graph.modules)
    colour = dict.fromkeys(mods, 0)
    stack: list[str] = []

    def visit(m):
        colour[m] = 1
        stack.append(m)
        for n in sorted(graph.find_modules_directly_imported_by(m)):
            if n not in colour:
                continue
            if colour[n] == 1:
                return stack[stack.index(n):] + [n]
            if colour[n] == 0:
                c = visit(n)
                if c:
                    return c
        stack.pop()
        colour[m] = 2
        return None

    for m in mods:
        if colour[m] == 0:
            c = visit(m)
            if c:
                return c
    return None


def test_no_import_cycles_function_local_imports_included():
    graph = grimp.build_graph("scfmu", include_external_packages=False)
    # a package's __init__ importing its own submodules is not a cycle of two modules of its own layer,
    # but a submodule importing its parent package back would be: keep both kinds of edges
    assert _cycle(graph) is None, f"import cycle: {' -> '.join(_cycle(graph))}"


def test_cycle_finder_finds_a_cycle():
    class G:
        modules = {"a", "b", "c"}

        @staticmethod
        def find_modules_directly_imported_by(m):
            return {"a": {"b"}, "b": {"c"}, "c": {"a"}}[m]

    assert _cycle(G) == ["a", "b", "c", "a"]


def test_no_path_tricks_in_the_package():
    """Data files are package data (importlib.resources); no sys.path edits, no counting parent folders."""
    bad = []
    for p in PKG.rglob("*.py"):
        for i, line in enumerate(p.read_text().splitlines(), 1):
            if re.search(r"sys\.path\.(insert|append)|parents\[\d\]|PYTHONPATH", line):
                bad.append(f"{p.relative_to(ROOT)}:{i}: {line.strip()}")
    assert not bad, "\n".join(bad)
