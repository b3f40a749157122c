"""The Rust import rules, read from the code's own paths: in every crate of the repository (the runtime crate
`src/` with the models, `src/cdylib`, `src/package/src`, and scfmu's engine crates under `scfmu/engines/`) every `crate::…`, `super::…` and `self::…` path
and every path through a child module (`declare::concat` in `model/mod.rs`) names a module file; the graph
of those references between files has no circle anywhere (no file circle), and in the FMI layer
(src/fmi/) FMI 3.0 files never reference FMI 2.0 files (nor the other way round). Brace imports
(`use super::{a, b}`) are expanded first. A child module may use its parent's items as long as no circle
results, so a `mod.rs` that re-exports its children keeps what the children need in a leaf of their own
(`model/contract.rs`, `model/entry.rs`). Not counted: comments, `$crate::…` paths of macro bodies (they
resolve where the macro is expanded), and test-only code (`tests.rs`, files under a `tests/` folder, a
file's own `#[cfg(test)] mod tests { … }`), which may reach anywhere."""

from __future__ import annotations

import re
from pathlib import Path


SRC = Path(__file__).resolve().parents[1] / "src"
ENGINES = SRC.parent / "scfmu" / "engines"  # scfmu's own Rust crates: the compiled loop, the ME wrapper, the stepper
# (crate root, folders below it that are other crates)
CRATES = [(SRC, ("cdylib", "package", "dopri")), (SRC / "cdylib", ()), (SRC / "package" / "src", ()),
          (SRC / "dopri" / "src", ())] + [
    (c.parent / "src", ()) for c in sorted(ENGINES.glob("*/Cargo.toml"))]
BRACES = re.compile(r"(?<!\$)\b((?:crate|super|self)(?:::\w+)*)::\{([^{}]*)\}")  # `use super::{a, b::c}`
PATH = re.compile(r"(?<!\$)\b(crate(?:::\w+)+|super(?:::\w+)+|self::\{[^}]*\}|self(?:::\w+)+)")
CHILD = re.compile(r"(?<![\w:$])(\w+)::")  # `declare::concat`: a path through a child module


def module_of(path: Path, root: Path) -> tuple[str, ...]:
    parts = path.relative_to(root).with_suffix("").parts
    if parts in (("lib",), ("main",)):
        return ()
    return parts[:-1] if parts[-1] == "mod" else parts


def modules(root: Path, other_crates=()) -> dict[tuple[str, ...], Path]:
    out = {}
    for p in sorted(root.rglob("*.rs")):
        rel = p.relative_to(root).parts
        if rel[0] in other_crates or rel == ("main.rs",):  # a binary's main.rs is a crate of its own
            continue
        out[module_of(p, root)] = p
    return out


def resolve(segments: list[str], mods: dict) -> tuple[str, ...] | None:
    """The longest prefix of `segments` that is a module file."""
    for k in range(len(segments), -1, -1):
        if tuple(segments[:k]) in mods:
            return tuple(segments[:k])
    return None


def code_of(path: Path) -> str | None:
    """The non-test code of a file without comments; None for a test-only file."""
    if path.name == "tests.rs" or "tests" in path.parent.parts[-1:]:
        return None
    text = re.sub(r"//[^\n]*", "", path.read_text())
    text = text.split("#[cfg(test)]\nmod tests {")[0]
    return BRACES.sub(lambda m: " ".join(f"{m.group(1)}::{item.strip()}" for item in m.group(2).split(",")
                                         if item.strip() and not item.strip().startswith("*")), text)


def edges(root: Path, other_crates=()) -> dict[tuple[str, ...], set[tuple[str, ...]]]:
    mods = modules(root, other_crates)
    graph: dict[tuple[str, ...], set[tuple[str, ...]]] = {m: set() for m in mods}
    for mod, path in mods.items():
        text = code_of(path)
        if text is None:
            continue
        for m in PATH.finditer(text):
            p = m.group(1)
            if p.startswith("crate"):
                segs = p.split("::")[1:]
            elif p.startswith("self"):
                inner = p[len("self::"):].strip("{}")
                segs = None
                for part in inner.split(","):
                    name = part.strip().split("::")[0]
                    if name and name != "*":
                        target = resolve(list(mod) + [name], mods)
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
        for m in CHILD.finditer(text):
            if mod + (m.group(1),) in mods:
                graph[mod].add(mod + (m.group(1),))
    return graph


def cycles(graph) -> list[list]:
    out, state, stack = [], {}, []

    def visit(n):
        state[n] = 1
        stack.append(n)
        for m in sorted(graph[n]):
            if state.get(m) == 1:
                out.append(stack[stack.index(m):] + [m])
            elif m not in state:
                visit(m)
        stack.pop()
        state[n] = 2

    for n in sorted(graph):
        if n not in state:
            visit(n)
    return out


def name(m: tuple[str, ...]) -> str:
    return "::".join(m) or "crate"


def violations(root: Path, other_crates=()) -> list[str]:
    graph = edges(root, other_crates)
    bad = [" -> ".join(name(x) for x in c) for c in cycles(graph)]
    versions = {("fmi", "fmi2"), ("fmi", "fmi3")}
    for a, targets in graph.items():
        for b in targets:
            if a[:2] in versions and b[:2] in versions and a[:2] != b[:2]:
                bad.append(f"{name(a)} references {name(b)} (one FMI version imports the other)")
    return sorted(set(bad))


def test_no_file_circle_in_any_crate_and_no_import_across_fmi_versions():
    found = {str(root.relative_to(SRC.parent)): violations(root, other) for root, other in CRATES}
    assert all(v == [] for v in found.values()), found
    assert len(CRATES) == 7, [str(r) for r, _ in CRATES]  # src, cdylib, package, dopri + native_loop, me_cs, fmi_stepper


def test_the_whole_crate_is_read():
    """Every file under src/ and of the engine crates belongs to one crate's graph, models and the FMI layer included."""
    read = set()
    for root, other in CRATES:
        read |= set(modules(root, other).values())
    # not read: the packager's main.rs and its integration tests (each a crate of its own, test-only)
    every = {p for p in SRC.rglob("*.rs") if p.parent != SRC / "package" / "tests"} - {SRC / "package" / "src" / "main.rs"}
    every |= set(ENGINES.glob("*/src/**/*.rs"))
    assert every == read
    graph = edges(SRC, ("cdylib", "package", "dopri"))
    assert ("models", "attitude", "plant", "environment") in graph[("models", "attitude", "plant")]
    assert ("fmi", "boundary") in graph[("fmi", "fmi3", "common")]


def test_the_rule_catches_a_circle_and_a_cross_version_import(tmp_path):
    """The check can fail: a tree with abi.rs <-> abi_me.rs (the old layout), an FMI 3.0 file using FMI 2.0,
    a circle through a brace import and one through a parent that re-exports its child."""
    fmi = tmp_path / "fmi"
    (fmi / "fmi2").mkdir(parents=True)
    (fmi / "fmi3").mkdir()
    (tmp_path / "lib.rs").write_text("pub mod fmi;\npub mod model;\n")
    (fmi / "mod.rs").write_text("pub mod abi;\nmod abi_me;\npub mod fmi2;\npub mod fmi3;\n")
    (fmi / "abi.rs").write_text("pub use super::abi_me::*;\npub fn call() {}\n")
    (fmi / "abi_me.rs").write_text("use super::abi::call;\n")
    (fmi / "fmi2" / "mod.rs").write_text("pub mod common;\n")
    (fmi / "fmi2" / "common.rs").write_text("pub fn call() {}\n")
    (fmi / "fmi3" / "mod.rs").write_text("pub mod common;\n")
    (fmi / "fmi3" / "common.rs").write_text("use crate::fmi::fmi2::common::call;\nuse super::mask;\n")
    found = violations(tmp_path)
    assert any("fmi::abi -> fmi::abi_me -> fmi::abi" in v or "fmi::abi_me -> fmi::abi -> fmi::abi_me" in v
               for v in found), found
    assert any("fmi::fmi3::common references fmi::fmi2::common" in v for v in found), found
    # a circle through a brace import is found too
    (fmi / "x.rs").write_text("use super::{y::f, abi};\n")
    (fmi / "y.rs").write_text("use super::x::g;\n")
    assert any(v in ("fmi::x -> fmi::y -> fmi::x", "fmi::y -> fmi::x -> fmi::y") for v in violations(tmp_path))
    # and one between a mod.rs that uses its child by a bare path and the child that uses the parent
    (tmp_path / "model").mkdir()
    (tmp_path / "model" / "mod.rs").write_text("mod declare;\npub use declare::same_str;\npub trait Model {}\n")
    (tmp_path / "model" / "declare.rs").write_text("use super::Model;\npub fn same_str() {}\n")
    assert "model -> model::declare -> model" in violations(tmp_path), violations(tmp_path)
    # while `$crate::` paths of a macro body, comments and a file's own unit tests do not count
    (tmp_path / "model" / "declare.rs").write_text(
        "// super::Model\nmacro_rules! m { () => { $crate::model::Model } }\n"
        "#[cfg(test)]\nmod tests {\n    use super::super::Model;\n}\n")
    assert "model -> model::declare -> model" not in violations(tmp_path), violations(tmp_path)


# ----- the version-neutral core ------------------------------------------------------------------------

FMI = SRC / "fmi"
ROOMS = ("fmi2", "fmi3")
# a version's name: the C prefixes and names of one version (fmi2DoStep, Fmi3, fmi3::…), or the
# standard's name with its version in a string ("FMI 2.0")
VERSION_NAME = re.compile(r"fmi[23]|fmi ?[23]\.\d", re.IGNORECASE)
# the only code lines of the core that may spell one: the layer's root declares its two rooms
CORE_ALLOWED = {("mod.rs", "pub mod fmi2;"), ("mod.rs", "pub mod fmi3;")}


def version_names_in_core(fmi: Path) -> list[str]:
    """The code lines (comments left out, unit tests included) of the core, every file of the FMI layer
    outside the rooms fmi2/ and fmi3/, that name an FMI version, as `file:line: text`."""
    found = []
    for p in sorted(fmi.rglob("*.rs")):
        rel = p.relative_to(fmi)
        if rel.parts[0] in ROOMS:
            continue
        for n, line in enumerate(p.read_text().splitlines(), 1):
            code = re.sub(r"//.*", "", line).strip()
            if VERSION_NAME.search(code) and (rel.as_posix(), code) not in CORE_ALLOWED:
                found.append(f"{rel.as_posix()}:{n}: {code}")
    return found


def test_the_fmi_core_names_no_fmi_version():
    """Issue 47, item 3: the states, failures and messages of the core are version-neutral; which
    interface an instance serves it knows only through the Dialect its room gives it, and the rooms word
    its failures. No identifier or string of the core names fmi2/fmi3 or "FMI 2.0"/"FMI 3.0"."""
    assert (FMI / "types.rs").exists() and (FMI / "instance" / "mod.rs").exists()
    assert version_names_in_core(FMI) == []


def test_the_core_rule_catches_a_version_name(tmp_path):
    """The check can fail: a function name in a string, a room's path, a version in a message and a
    variant named after a version are found; the same in a comment, the rooms' own files and the root's
    `pub mod fmi2;` are not."""
    import shutil
    fmi = tmp_path / "fmi"
    shutil.copytree(FMI, fmi)
    assert version_names_in_core(fmi) == []
    planted = {
        "instance/me.rs": 'const F: &str = "fmi2SetContinuousStates";',
        "boundary.rs": "use crate::fmi::fmi3::common::FMI3;",
        "state.rs": 'const V: &str = "FMI 3.0";',
        "types.rs": "pub enum L { Fmi2(u8) }",
    }
    for rel, line in planted.items():
        (fmi / rel).write_text((fmi / rel).read_text() + "\n// fmi2DoStep in a comment\n" + line + "\n")
    (fmi / "fmi2" / "common.rs").write_text((fmi / "fmi2" / "common.rs").read_text() + '\nconst G: &str = "fmi2X";\n')
    found = version_names_in_core(fmi)
    assert sorted(f.split(":")[0] for f in found) == sorted(planted), found
    assert all(f.endswith(planted[f.split(":")[0]]) for f in found), found
