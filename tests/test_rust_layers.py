"""The FMI layer's import rules (src/fmi/), read from the code's own paths: every `use` and every
`crate::fmi::…` / `super::…` path names a module file; the graph of those references has no circle,
FMI 3.0 files never reference FMI 2.0 files (nor the other way round). Brace imports (`use super::{a, b}`)
are expanded first. A child module may use its parent's items (`instance/me.rs` adds methods to the
`Instance` of `instance/mod.rs`) as long as no circle results; `mod.rs` may re-export its children."""

from __future__ import annotations

import re
from pathlib import Path


ROOT = Path(__file__).resolve().parents[1] / "src" / "fmi"
BRACES = re.compile(r"\b((?:crate::fmi|super|self)(?:::\w+)*)::\{([^{}]*)\}")  # `use super::{a, b::c}`
PATH = re.compile(r"\b(crate::fmi(?:::\w+)*|super(?:::\w+)+|self::\{[^}]*\}|self(?:::\w+)+)")


def module_of(path: Path, root: Path) -> tuple[str, ...]:
    rel = path.relative_to(root).with_suffix("")
    parts = rel.parts
    return parts[:-1] if parts[-1] == "mod" else parts


def modules(root: Path) -> dict[tuple[str, ...], Path]:
    return {module_of(p, root): p for p in root.rglob("*.rs")}


def resolve(segments: list[str], mods: dict) -> tuple[str, ...] | None:
    """The longest prefix of `segments` that is a module file."""
    for k in range(len(segments), -1, -1):
        if tuple(segments[:k]) in mods:
            return tuple(segments[:k])
    return None


def edges(root: Path) -> dict[tuple[str, ...], set[tuple[str, ...]]]:
    mods = modules(root)
    graph: dict[tuple[str, ...], set[tuple[str, ...]]] = {m: set() for m in mods}
    for mod, path in mods.items():
        if path.name == "tests.rs":
            continue  # a test-only module may reach anywhere
        text = re.sub(r"//[^\n]*", "", path.read_text())
        text = text.split("#[cfg(test)]\nmod tests {")[0]  # a file's own unit tests may reach anywhere
        text = BRACES.sub(lambda m: " ".join(f"{m.group(1)}::{item.strip()}" for item in m.group(2).split(",")
                                             if item.strip() and not item.strip().startswith("*")), text)
        for m in PATH.finditer(text):
            p = m.group(1)
            if p.startswith("crate::fmi"):
                segs = p.split("::")[2:]
            elif p.startswith("self"):
                base = list(mod)
                inner = p[len("self::"):].strip("{}")
                for part in inner.split(","):
                    name = part.strip().split("::")[0]
                    if name and name != "*":
                        target = resolve(base + [name], mods)
                        if target and target != mod:
                            graph[mod].add(target)
                continue
            else:
                segs, base = p.split("::"), list(mod)
                while segs and segs[0] == "super":
                    segs, base = segs[1:], base[:-1]
                segs = base + segs
            target = resolve(segs, mods)
            if target is not None and target != mod:
                graph[mod].add(target)
    return graph


def cycles(graph) -> list[list]:
    out, state, stack = [], {}, []

    def visit(n):
        state[n] = 1
        stack.append(n)
        for m in graph[n]:
            if state.get(m) == 1:
                out.append(stack[stack.index(m):] + [m])
            elif m not in state:
                visit(m)
        stack.pop()
        state[n] = 2

    for n in graph:
        if n not in state:
            visit(n)
    return out


def violations(root: Path) -> list[str]:
    graph = edges(root)
    bad = [" -> ".join("::".join(x) or "fmi" for x in c) for c in cycles(graph)]
    for a, targets in graph.items():
        for b in targets:
            if a[:1] in {("fmi3",), ("fmi2",)} and b[:1] in {("fmi3",), ("fmi2",)} and a[:1] != b[:1]:
                bad.append(f"{'::'.join(a)} references {'::'.join(b)} (one FMI version imports the other)")
    return sorted(set(bad))


def test_the_fmi_layer_has_no_circle_and_no_import_across_versions():
    assert violations(ROOT) == []


def test_the_rule_catches_a_circle_and_a_cross_version_import(tmp_path):
    """The check can fail: a tree with abi.rs <-> abi_me.rs (the old layout) and an FMI 3.0 file using FMI 2.0."""
    (tmp_path / "fmi2").mkdir()
    (tmp_path / "fmi3").mkdir()
    (tmp_path / "mod.rs").write_text("pub mod abi;\nmod abi_me;\npub mod fmi2;\npub mod fmi3;\n")
    (tmp_path / "abi.rs").write_text("pub use super::abi_me::*;\npub fn call() {}\n")
    (tmp_path / "abi_me.rs").write_text("use super::abi::call;\n")
    (tmp_path / "fmi2" / "mod.rs").write_text("pub mod common;\n")
    (tmp_path / "fmi2" / "common.rs").write_text("pub fn call() {}\n")
    (tmp_path / "fmi3" / "mod.rs").write_text("pub mod common;\n")
    (tmp_path / "fmi3" / "common.rs").write_text("use crate::fmi::fmi2::common::call;\nuse super::mask;\n")
    found = violations(tmp_path)
    assert any("abi -> abi_me -> abi" in v or "abi_me -> abi -> abi_me" in v for v in found), found
    assert any("fmi3::common references fmi2::common" in v for v in found), found
    # a circle through a brace import is found too
    (tmp_path / "x.rs").write_text("use super::{y::f, abi};\n")
    (tmp_path / "y.rs").write_text("use super::x::g;\n")
    (tmp_path / "mod.rs").write_text("pub mod abi;\nmod abi_me;\npub mod fmi2;\npub mod fmi3;\nmod x;\nmod y;\n")
    assert any(v in ("x -> y -> x", "y -> x -> y") for v in violations(tmp_path)), violations(tmp_path)
