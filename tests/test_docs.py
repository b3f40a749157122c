"""The shipped texts against the code: the README's FMU table and the catalogue of docs/index.md list
exactly the models the project builds (the registry's `fmus!` lists, as generated into
modelDescription/), each once; docs/index.md links every page of docs/; every relative link of README.md,
CONTRIBUTING.md and docs/ reaches an existing file (and, with an anchor, a heading of it); and no shipped
text says the FMUs are FMI 2.0 Co-Simulation only.

Fast (reads files only, no FMU is loaded). `python tests/test_docs.py` prints every finding at once."""

from __future__ import annotations

import ast
import re
import sys
import tomllib
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
INDEX = ROOT / "docs" / "index.md"
CATALOGUE_MARK = "<!-- catalogue:"


# --- the models ---------------------------------------------------------------------------------------

def described_models() -> list[str]:
    """Model names of the generated descriptions modelDescription/*.xml (FMI 2.0) and fmi3/*.xml."""
    names = []
    for folder in (ROOT / "modelDescription", ROOT / "modelDescription" / "fmi3"):
        names.append(sorted(ET.parse(p).getroot().get("modelName") for p in folder.glob("*.xml")))
    assert names[0] == names[1], "modelDescription/ and modelDescription/fmi3/ describe different models"
    return names[0]


def registry_models() -> list[str]:
    """The entries of every family's `crate::fmus! { module::Type, ... }` list under src/models/."""
    out = []
    for mod in sorted((ROOT / "src" / "models").rglob("mod.rs")):
        for block in re.findall(r"crate::fmus!\s*\{([^}]*)\}", mod.read_text(encoding="utf-8")):
            out += re.findall(r"::\s*(\w+)\s*,?", block)
    return out


def section(text: str, heading: str) -> str:
    """The text under a `## heading` line, up to the next heading of level 1 or 2."""
    m = re.search(rf"^## {re.escape(heading)}\s*$(.*?)(?=^#{{1,2}} |\Z)", text, flags=re.M | re.S)
    assert m, f"no section '## {heading}'"
    return m.group(1)


def table_names(text: str, column: int) -> list[str]:
    """Every `Name` in backticks in one column of the first Markdown table of `text` (header row skipped)."""
    rows = [line for line in text.splitlines() if line.startswith("|")]
    names = []
    for row in rows[2:]:
        cells = row.strip().strip("|").split("|")
        names += re.findall(r"`(\w+)`", cells[column])
    assert rows, "no table"
    return names


def readme_fmu_names(text: str) -> list[str]:
    return table_names(section(text, "FMUs"), column=1)


def index_catalogue_names(text: str) -> list[str]:
    i = text.find(CATALOGUE_MARK)
    assert i >= 0, f"docs/index.md has no {CATALOGUE_MARK} marker above its catalogue table"
    return table_names(text[i:], column=0)


def list_problems(listed: list[str], models: list[str]) -> list[str]:
    """What is wrong with a table's list of names against the models: missing, unknown, doubled."""
    counts = Counter(listed)
    out = [f"missing: {m}" for m in models if m not in counts]
    out += [f"not a model the project builds: {n}" for n in counts if n not in models]
    out += [f"listed {c} times: {n}" for n, c in counts.items() if c > 1]
    return out


def test_the_registry_and_the_generated_descriptions_name_the_same_models():
    registry = registry_models()
    assert len(registry) == len(set(registry)), "a model is in two fmus! lists"
    assert sorted(registry) == described_models(), "modelDescription/ is stale: run scripts/regenerate.sh"


def test_the_readme_fmu_table_lists_exactly_the_models_built():
    problems = list_problems(readme_fmu_names(README.read_text(encoding="utf-8")), described_models())
    assert not problems, "README.md, section FMUs:\n" + "\n".join(problems)


def test_the_index_catalogue_lists_exactly_the_models_built():
    problems = list_problems(index_catalogue_names(INDEX.read_text(encoding="utf-8")), described_models())
    assert not problems, "docs/index.md, catalogue:\n" + "\n".join(problems)


def test_model_counts_in_the_readme_are_the_registry_count():
    n = len(described_models())
    said = [int(k) for k in re.findall(r"\b(\d+) (?:models|FMUs)\b", README.read_text(encoding="utf-8"))]
    assert said and all(k == n for k in said), f"README.md says {said} models; the project builds {n}"


def test_the_table_check_fails_on_a_removed_or_doubled_name():
    text = README.read_text(encoding="utf-8")
    models = described_models()
    assert list_problems(readme_fmu_names(text.replace("`Mekf`, ", "", 1)), models) == ["missing: Mekf"]
    doubled = text.replace("`Mekf`, ", "`Mekf`, `Mekf`, ", 1)
    assert list_problems(readme_fmu_names(doubled), models) == ["listed 2 times: Mekf"]
    assert list_problems(readme_fmu_names(text.replace("`Mekf`", "`Mekf2`", 1)), models) == [
        "missing: Mekf", "not a model the project builds: Mekf2"]


# --- links and the index --------------------------------------------------------------------------------

LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")


def prose(text: str) -> str:
    """Markdown without fenced code blocks and inline code (links there are examples, not links)."""
    text = re.sub(r"^(```|~~~).*?^\1[^\n]*$", "", text, flags=re.M | re.S)
    return re.sub(r"`[^`\n]*`", "``", text)


def slugs(text: str) -> set[str]:
    """GitHub's anchors for the headings of a Markdown file (lowercase, punctuation dropped, spaces to
    hyphens, a repeated heading gets -1, -2, ...)."""
    seen: Counter = Counter()
    out = set()
    for line in re.sub(r"^(```|~~~).*?^\1[^\n]*$", "", text, flags=re.M | re.S).splitlines():
        m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        s = re.sub(r"[^\w\- ]", "", m.group(1).lower()).replace(" ", "-")
        out.add(s if not seen[s] else f"{s}-{seen[s]}")
        seen[s] += 1
    return out


def pages() -> list[Path]:
    return [README, ROOT / "CONTRIBUTING.md", *sorted((ROOT / "docs").rglob("*.md"))]


def links(page: Path) -> list[str]:
    return [t for t in LINK.findall(prose(page.read_text(encoding="utf-8")))
            if not re.match(r"^[a-z][a-z0-9+.-]*:", t)]  # http:, https:, mailto: are not checked here


def link_problems(page: Path, root: Path = ROOT) -> list[str]:
    out = []
    for target in links(page):
        path, _, anchor = target.partition("#")
        dest = (page.parent / path).resolve() if path else page
        where = f"{page.relative_to(root)}: ({target})"
        if not dest.exists():
            out.append(f"{where}: no such file")
        elif anchor and dest.suffix == ".md" and anchor not in slugs(dest.read_text(encoding="utf-8")):
            out.append(f"{where}: no heading with anchor #{anchor} in {dest.relative_to(root)}")
    return out


def test_every_relative_link_resolves():
    problems = [p for page in pages() for p in link_problems(page)]
    assert not problems, "\n".join(problems)


def test_the_index_links_every_page_of_docs():
    linked = {(INDEX.parent / t.partition("#")[0]).resolve() for t in links(INDEX) if t.partition("#")[0]}
    missing = [p.relative_to(ROOT).as_posix() for p in sorted((ROOT / "docs").rglob("*.md"))
               if p != INDEX and p.resolve() not in linked]
    assert not missing, f"docs/index.md does not link: {missing}"


def test_a_broken_link_and_a_missing_anchor_are_found(tmp_path):
    page = tmp_path / "p.md"
    (tmp_path / "q.md").write_text("# Title\n## Two words, here\n")
    page.write_text("[a](q.md#two-words-here) [b](nope.md) [c](q.md#three) `[d](nope2.md)` [e](https://x.org/y)\n")
    assert link_problems(page, root=tmp_path) == ["p.md: (nope.md): no such file",
                                                  "p.md: (q.md#three): no heading with anchor #three in q.md"]


# --- "FMI 2.0 Co-Simulation" only -------------------------------------------------------------------------

# A sentence that calls the FMUs FMI 2.0 Co-Simulation ones, or says "FMI 2.0 CS", without naming FMI 3.0 or
# Model Exchange in the same sentence, says the FMUs are that only: they are FMI 2.0 and 3.0, Co-Simulation
# and (where a model is continuous or static) Model Exchange. Sentences about one thing that really is FMI 2.0
# Co-Simulation (the container FMU, a loop FMU, the Model Exchange wrapper) do not say "FMUs" after it.
ONLY_FMI2_CS = re.compile(r"FMI 2\.0 Co-Simulation FMUs?\b|FMI 2\.0 CS\b")
EXCUSES = re.compile(r"FMI 3\.0|3\.0|Model Exchange")


def sentences(text: str) -> list[str]:
    """Sentences of prose or a docstring: emphasis and code marks removed, lines joined; a blank line, a
    list item and a table cell each end one."""
    text = re.sub(r"[*`]", "", text)
    out = []
    for block in re.split(r"\n\s*\n|\n\s*[-*] |\|", text):
        block = " ".join(block.split())
        out += re.split(r"(?<=[.!?])\s+(?=[A-Z(\[])", block)
    return out


def stale_claims(text: str) -> list[str]:
    return [s for s in sentences(text) if ONLY_FMI2_CS.search(s) and not EXCUSES.search(s)]


def shipped_texts() -> dict[str, str]:
    """README.md, CONTRIBUTING.md, docs/**/*.md, every string literal of scfmu/ (docstrings, help and
    messages), pyproject.toml's description and the doc comments of src/export.rs."""
    texts = {p.relative_to(ROOT).as_posix(): p.read_text(encoding="utf-8") for p in pages()}
    for p in sorted((ROOT / "scfmu").rglob("*.py")):
        tree = ast.parse(p.read_text(encoding="utf-8"))
        strings = [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)]
        texts[p.relative_to(ROOT).as_posix()] = "\n\n".join(strings)
    texts["pyproject.toml"] = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["description"]
    export = (ROOT / "src" / "export.rs").read_text(encoding="utf-8").splitlines()
    texts["src/export.rs"] = "\n".join(re.sub(r"^\s*//[!/]\s?", "", line) if re.match(r"^\s*//[!/]", line) else ""
                                       for line in export)
    return texts


def test_no_shipped_text_says_the_fmus_are_fmi2_co_simulation_only():
    problems = [f"{name}: {s}" for name, text in shipped_texts().items() for s in stale_claims(text)]
    assert not problems, "\n".join(problems)


def test_the_wording_check_flags_the_old_readme_and_passes_its_correction():
    old = ("Plants and controllers from five spacecraft-control papers, written in Rust and packaged as standard\n"
           "**FMI 2.0 Co-Simulation** FMUs (`fmus/<Model>.fmu`, Linux x86-64 and aarch64, Windows x86-64 and macOS\n"
           "x86-64 + arm64 binaries; see `docs/tools.md`). Load them in fmpy. Every model is also an **FMI 3.0\n"
           "Co-Simulation** FMU (`fmus/fmi3/<Model>.fmu`).")
    assert len(stale_claims(old)) == 1 and stale_claims(old)[0].startswith("Plants and controllers")
    assert stale_claims('help="use this FMU (a path to any FMI 2.0 CS FMU, or a model name)"')
    assert stale_claims("FMUs are FMI 2.0 Co-Simulation FMUs, and FMI 3.0 ones too.") == []
    assert stale_claims("The container's FMI 2.0 Co-Simulation model description.") == []


if __name__ == "__main__":
    models = described_models()
    found = list_problems(readme_fmu_names(README.read_text(encoding="utf-8")), models)
    found += list_problems(index_catalogue_names(INDEX.read_text(encoding="utf-8")), models)
    found += [p for page in pages() for p in link_problems(page)]
    found += [f"{n}: {s}" for n, t in shipped_texts().items() for s in stale_claims(t)]
    print("\n".join(found) or "no findings")
    sys.exit(1 if found else 0)
