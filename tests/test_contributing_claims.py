"""CONTRIBUTING.md's claims that the source can check: where ctypes lives in the Python package (the paragraph
"C calls from Python") and the two edits a new model needs (section "Adding a model")."""

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BINDING = "scfmu/binding.py"
# what only the binding may do: load a library, declare a signature or a callback, define a C struct
BINDING_ONLY = {"CDLL", "PyDLL", "cdll", "pydll", "LoadLibrary", "CFUNCTYPE", "PYFUNCTYPE", "Structure", "Union",
                "argtypes", "restype", "errcheck", "dlclose", "dlopen"}


def _paragraph(title: str) -> str:
    text = (ROOT / "CONTRIBUTING.md").read_text()
    start = text.index(f"**{title}**")
    return text[start:text.index("\n\n", start)]


def claimed_ctypes_modules() -> set[str]:
    """The modules the paragraph names as importing ctypes besides the binding."""
    par = _paragraph("C calls from Python.")
    tail = par[par.index("ctypes is imported only"):]
    return set(re.findall(r"`(scfmu/[\w/]+\.py)`", tail[:tail.index("fmpy stays")]))


def ctypes_use(source: str) -> tuple[bool, set[str]]:
    """(imports ctypes or _ctypes anywhere, the binding-only names it uses) of one module's source."""
    tree = ast.parse(source)
    imports, used = False, set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] in ("ctypes", "_ctypes"):
                    imports = True
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] in ("ctypes", "_ctypes"):
            imports = True
            used |= {a.name for a in node.names} & BINDING_ONLY
        elif isinstance(node, ast.Attribute) and node.attr in BINDING_ONLY:
            used.add(node.attr)
        elif isinstance(node, ast.Name) and node.id in BINDING_ONLY:
            used.add(node.id)
    return imports, used


def scan(root: Path) -> dict[str, tuple[bool, set[str]]]:
    return {p.relative_to(root).as_posix(): ctypes_use(p.read_text()) for p in sorted((root / "scfmu").rglob("*.py"))
            if "tests" not in p.relative_to(root).parts}


def violations(found: dict, claimed: set[str]) -> list[str]:
    out = []
    importers = {m for m, (imp, _u) in found.items() if imp}
    out += [f"{m} imports ctypes but CONTRIBUTING does not list it" for m in sorted(importers - claimed - {BINDING})]
    out += [f"CONTRIBUTING lists {m}, which does not import ctypes" for m in sorted(claimed - importers)]
    out += [f"{m} uses {', '.join(sorted(u))}: only {BINDING} may" for m, (_i, u) in found.items()
            if u and m != BINDING]
    if not found.get(BINDING, (False,))[0]:
        out.append(f"{BINDING} is missing or imports no ctypes")
    return out


def test_ctypes_lives_where_contributing_says():
    claimed = claimed_ctypes_modules()
    assert len(claimed) == 9, claimed  # the paragraph's list was read (a changed wording must not empty it)
    assert violations(scan(ROOT), claimed) == []


def test_the_ctypes_check_fails_on_a_planted_import(tmp_path):
    """A copy of the package with one extra ctypes import, one declared signature and one stale claim."""
    found = scan(ROOT)
    claimed = claimed_ctypes_modules()
    found["scfmu/metrics.py"] = ctypes_use("import numpy\nfrom ctypes import c_double\n")
    found["scfmu/engines/lean.py"] = ctypes_use("import ctypes\nf = ctypes.CDLL(None).free\nf.restype = None\n")
    v = violations(found, claimed | {"scfmu/results.py"})
    assert v == ["scfmu/metrics.py imports ctypes but CONTRIBUTING does not list it",
                 "CONTRIBUTING lists scfmu/results.py, which does not import ctypes",
                 f"scfmu/engines/lean.py uses CDLL, restype: only {BINDING} may"]


def test_binding_declares_every_fmi_function_the_package_names():
    """Every ``fmi2*``/``fmi3*`` function name in the package's Python source has its signature in the
    binding's table (the engines' tables of names bind through it)."""
    from scfmu.binding import SIGNATURES, STATUS2, STATUS3
    values = {*STATUS2, *STATUS3, "fmi2True", "fmi2False", "fmi2CoSimulation", "fmi2ModelExchange"}
    names = set()
    for p in (ROOT / "scfmu").rglob("*.py"):
        names |= set(re.findall(r"\"(fmi[23][A-Z]\w+)\"", p.read_text())) - values
    assert len(names) > 40 and sorted(names - set(SIGNATURES)) == []


def test_raw_signatures_are_the_typed_ones_with_plain_pointers():
    """The engines' raw form of a signature differs from the checker's only in its pointer arguments."""
    import ctypes
    from scfmu.binding import SIGNATURES, signature
    for name in SIGNATURES:
        res, typed = signature(name)
        _res, raw = signature(name, raw=True)
        assert _res is res and len(raw) == len(typed)
        for t, r in zip(typed, raw):
            assert r is (ctypes.c_void_p if issubclass(t, ctypes._Pointer) else t), (name, t, r)
    assert signature("fmi2GetReal", raw=True)[1] == [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t,
                                                    ctypes.c_void_p]


# ------------------------------------------------------------------------ the two edits a new model needs
ENTRY = re.compile(r"^\s*([a-z0-9_]+)::([A-Za-z0-9_]+),?\s*$")
# the parts of the crate that must not know any model by name (their tests excepted)
MODEL_BLIND = ["src/fmi", "src/cdylib", "src/catalogue", "src/package", "src/model", "src/export.rs",
               "src/registry.rs"]


def _code(text: str) -> str:
    """Rust source without comments and without its test module (from the first ``#[cfg(test)]`` on)."""
    text = text.split("#[cfg(test)]")[0]
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    return "\n".join(re.sub(r"//.*", "", line) for line in text.splitlines())


def fmus_lists(src: Path) -> dict[str, tuple[Path, str]]:
    """Model name -> (the family's mod.rs, the file stem of the model) for every ``fmus!`` entry."""
    models = {}
    for mod in sorted(src.glob("models/**/mod.rs")):
        m = re.search(r"crate::fmus!\s*\{(.*?)\}", _code(mod.read_text()), re.S)
        if m:
            for line in m.group(1).splitlines():
                e = ENTRY.match(line)
                if e:
                    models[e.group(2)] = (mod, e.group(1))
    return models


def model_edit_problems(src: Path) -> list[str]:
    out = []
    models = fmus_lists(src)
    if not models:
        return ["no fmus! lists found"]
    for name, (mod, stem) in models.items():
        own = [mod.parent / f"{stem}.rs", *sorted((mod.parent / stem).rglob("*.rs"))]
        if not any(re.search(rf"impl\s+Model\s+for\s+{name}\b", p.read_text()) for p in own if p.exists()):
            out.append(f"{name}: no `impl Model for {name}` in {stem}.rs or {stem}/ beside {mod}")
    families = [m for m in {mod for mod, _s in models.values()}]
    registry = _code((src / "registry.rs").read_text())
    for mod in families:
        path = "::".join(mod.parent.relative_to(src / "models").parts)
        if not re.search(rf"\b{path}::FMUS\b", registry):
            out.append(f"src/registry.rs does not list the family {path}")
    blind = []
    for entry in MODEL_BLIND:
        p = src.parent / entry
        # test code may use the project's models as data (a `tests/` folder, `*_tests.rs`, `tests.rs`)
        blind += [p] if p.is_file() else sorted(
            x for x in p.rglob("*.rs")
            if not (x.stem.endswith("_tests") or x.name == "tests.rs" or "tests" in x.relative_to(p).parts[:-1]))
    for p in blind:
        code = _code(p.read_text())
        named = sorted(n for n in models if re.search(rf"\b{n}\b", code))
        if named:
            out.append(f"{p.relative_to(src.parent)} names {', '.join(named)}")
    return out


def test_a_new_model_is_its_file_and_one_line_in_its_familys_list():
    """CONTRIBUTING: a new controller of an existing family needs exactly two edits (its file and one line
    in the family's ``fmus!`` list): every listed model is implemented in its own file (or folder) of the
    family, every family's list reaches the registry, and no part of the FMI layer, the shared library,
    the catalogue, the packaging tool, the model contract or the registry names a model."""
    assert len(fmus_lists(ROOT / "src")) >= 30
    assert model_edit_problems(ROOT / "src") == []


@pytest.mark.parametrize("plant", ["registry", "layer"])
def test_the_model_edit_check_fails_on_a_planted_model_name(tmp_path, plant):
    import shutil
    src = tmp_path / "src"
    shutil.copytree(ROOT / "src", src, ignore=shutil.ignore_patterns("target", "*.md"))
    if plant == "registry":  # a model named in the registry: a third edit
        p = src / "registry.rs"
        p.write_text(p.read_text() + "\npub const EXTRA: &str = stringify!(PdController);\n")
        want = "src/registry.rs names PdController"
    else:
        p = src / "fmi" / "boundary.rs"
        p.write_text("use crate::models::attitude::control::LqrController;\n" + p.read_text())
        want = "src/fmi/boundary.rs names LqrController"
    assert model_edit_problems(src) == [want]
