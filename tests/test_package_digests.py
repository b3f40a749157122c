"""The packaging tool's output is pinned byte for byte: the sha256 of every generated file — each FMU's
`modelDescription.xml`, `documentation/index.html` and (FMI 3.0) `terminalsAndIcons/terminalsAndIcons.xml`
(fmus/*.fmu and fmus/fmi3/*.fmu), the committed modelDescription/ files (fmi3/terminalsAndIcons/ too) and the generated pages docs/models/*.md and docs/references.md — equals the
list in tests/data/package_digests.json. A refactoring of the catalogue or the packager must leave them
all unchanged.

Regenerate the list only when a change of the output is deliberate (a model's declarations or texts, a
new model, the packager's rendering, a version number), after scripts/build_fmus.sh, and say so in the
commit:

    .venv/bin/python tests/test_package_digests.py --write
"""

from __future__ import annotations

import hashlib
import json
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DIGESTS = ROOT / "tests" / "data" / "package_digests.json"
MEMBERS = ("modelDescription.xml", "documentation/index.html", "terminalsAndIcons/terminalsAndIcons.xml")


def generated_files(root: Path = ROOT) -> dict[str, bytes]:
    """Every file the packager generates, by a stable name ("fmus/X.fmu:member" for archive members)."""
    files: dict[str, bytes] = {}
    for fmu in sorted([*root.glob("fmus/*.fmu"), *root.glob("fmus/fmi3/*.fmu")]):
        with zipfile.ZipFile(fmu) as z:
            for member in (m for m in MEMBERS if m in z.namelist()):
                files[f"{fmu.relative_to(root).as_posix()}:{member}"] = z.read(member)
    pages = [*root.glob("modelDescription/*.xml"), *root.glob("modelDescription/fmi3/*.xml"),
             *root.glob("modelDescription/fmi3/terminalsAndIcons/*.xml"),
             *root.glob("docs/models/*.md"), root / "docs" / "references.md"]
    for path in sorted(pages):
        files[path.relative_to(root).as_posix()] = path.read_bytes()
    return files


def digests(files: dict[str, bytes]) -> dict[str, str]:
    return {name: hashlib.sha256(data).hexdigest() for name, data in sorted(files.items())}


def differences(expected: dict[str, str], actual: dict[str, str]) -> list[str]:
    """One line per file that changed, appeared or disappeared."""
    out = [f"changed: {n}" for n in expected if n in actual and actual[n] != expected[n]]
    out += [f"missing: {n}" for n in expected if n not in actual]
    out += [f"new: {n}" for n in actual if n not in expected]
    return out


def test_the_packagers_output_is_byte_identical_to_the_pinned_digests():
    expected = json.loads(DIGESTS.read_text())
    actual = digests(generated_files())
    assert len(expected) > 100, "the digest list covers too little"
    problems = differences(expected, actual)
    assert not problems, (
        f"{len(problems)} generated files differ from tests/data/package_digests.json (if deliberate, run "
        f"`.venv/bin/python tests/test_package_digests.py --write` and say why in the commit):\n"
        + "\n".join(problems[:20])
    )


def test_one_changed_character_is_detected():
    files = generated_files()
    name = next(n for n in files if n.endswith(":modelDescription.xml"))
    tampered = dict(files)
    tampered[name] = files[name].replace(b'description="', b'description="x', 1)
    assert differences(digests(files), digests(tampered)) == [f"changed: {name}"]


if __name__ == "__main__":
    if sys.argv[1:] != ["--write"]:
        sys.exit("usage: tests/test_package_digests.py --write   (regenerates tests/data/package_digests.json)")
    DIGESTS.write_text(json.dumps(digests(generated_files()), indent=1, sort_keys=True) + "\n")
    print(f"wrote {DIGESTS.relative_to(ROOT)}")
