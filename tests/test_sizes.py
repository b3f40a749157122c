"""Size rule of the code base: no source file over 450 lines and no function over 80 lines in `src/` (Rust) and
`scfmu/` (Python), unless the file's opening comment states why.

The reason is a line starting with `Size:` in the file's opening comment (Rust: the leading `//!`/`//` lines;
Python: the module docstring or the leading `#` lines). For a long file it may be any text; for a long function
the line must name the function in backticks, e.g. "Size: `export_fmi3!` lists every C symbol of FMI 3.0 in
one place, as the standard's header does." Generated and vendored trees (target/, .venv/) are not read.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path


ROOT = Path(__file__).resolve().parents[1]
MAX_FILE = 450
MAX_FUNCTION = 80


def _sources():
    for p in sorted((ROOT / "src").rglob("*.rs")):
        if "target" not in p.parts:
            yield p
    for p in sorted((ROOT / "scfmu").rglob("*.rs")):
        if "target" not in p.parts:
            yield p
    for p in sorted((ROOT / "scfmu").rglob("*.py")):
        yield p


def opening_comment(path: Path, text: str) -> str:
    """The file's opening comment: leading comment lines (and, for Python, the module docstring)."""
    lines = []
    if path.suffix == ".py":
        try:
            doc = ast.get_docstring(ast.parse(text)) or ""
        except SyntaxError:
            doc = ""
        lines.append(doc)
        prefix = "#"
    else:
        prefix = "//"
    for line in text.splitlines():
        s = line.strip()
        if s.startswith(prefix) or s.startswith("#!") or not s:
            lines.append(s)
            continue
        if path.suffix == ".py" and (s.startswith('"""') or s.startswith("from __future__")):
            continue  # the docstring was read above
        break
    return "\n".join(lines)


def size_reasons(comment: str) -> list[str]:
    return [m.group(1) for m in re.finditer(r"Size:\s*(.+)", comment)]


_RUST_FN = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?(?:const\s+)?(?:unsafe\s+)?(?:extern\s+\"C\"\s+)?fn\s+(\w+)")
_RUST_MACRO = re.compile(r"^\s*macro_rules!\s*(\w+)")


def rust_functions(text: str):
    """(name, first line, line count) of every fn and macro_rules! body, by brace matching (strings, chars
    and comments skipped)."""
    lines = text.splitlines()
    out = []
    for i, line in enumerate(lines):
        m = _RUST_FN.match(line) or _RUST_MACRO.match(line)
        if not m:
            continue
        name = m.group(1) + ("!" if _RUST_MACRO.match(line) else "")
        depth, opened, j = 0, False, i
        while j < len(lines):
            code = _strip_rust(lines[j])
            if not opened and ";" in code and "{" not in code:
                break  # a declaration without a body (trait method, extern)
            for ch in code:
                if ch == "{":
                    depth += 1
                    opened = True
                elif ch == "}":
                    depth -= 1
            if opened and depth <= 0:
                out.append((name, i + 1, j - i + 1))
                break
            j += 1
    return out


def _strip_rust(line: str) -> str:
    line = re.sub(r"//.*", "", line)
    line = re.sub(r'"(?:\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(?:\\.|[^'\\])'", "''", line)
    return line


def python_functions(text: str):
    tree = ast.parse(text)
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            yield node.name, node.lineno, node.end_lineno - node.lineno + 1


def violations():
    found = []
    for path in _sources():
        text = path.read_text(encoding="utf-8")
        rel = path.relative_to(ROOT)
        reasons = size_reasons(opening_comment(path, text))
        n = len(text.splitlines())
        if n > MAX_FILE and not reasons:
            found.append(f"{rel}: {n} lines (over {MAX_FILE}, no `Size:` reason in its opening comment)")
        funcs = python_functions(text) if path.suffix == ".py" else rust_functions(text)
        for name, line, length in funcs:
            if length > MAX_FUNCTION and not any(f"`{name}`" in r for r in reasons):
                found.append(f"{rel}:{line}: {name} is {length} lines (over {MAX_FUNCTION}, no `Size:` reason naming it)")
    return found


def test_no_oversized_file_or_function_without_a_reason():
    found = violations()
    assert not found, "size rule (tests/test_sizes.py):\n" + "\n".join(found)


def test_the_rule_can_fail(tmp_path):
    long_fn = "def f():\n" + "    x = 1\n" * 90
    assert max(n for _, _, n in python_functions(long_fn)) > MAX_FUNCTION
    rust = "pub fn g() {\n" + "    let a = \"}\";\n" * 85 + "}\n"
    assert rust_functions(rust) == [("g", 1, 87)]
    assert size_reasons(opening_comment(Path("x.rs"), "//! Size: `g` is one table.\nfn g() {}\n")) == ["`g` is one table."]


if __name__ == "__main__":  # list the violations: python tests/test_sizes.py
    print("\n".join(violations()) or "size rule: clean")
    raise SystemExit(0)
