"""FMI 3.0 terminals of an FMU: ``terminalsAndIcons/terminalsAndIcons.xml`` (FMI 3.0 section 2.4.9), read
from the archive (after :func:`~scfmu.fmu.archive.inspect_archive`), each member with the unit and
causality of its variable in the model description. A unit without the file (any FMI 2.0 FMU, or an FMI 3.0
FMU without terminals) has none. Cached per process by file (:func:`scfmu.fmu.file_key`)."""

from __future__ import annotations

import zipfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

PATH = "terminalsAndIcons/terminalsAndIcons.xml"


@dataclass(frozen=True)
class Member:
    member: str  # memberName ("" when the terminal does not give one: sequence matching)
    variable: str  # variableName: the variable connected
    unit: str  # the variable's unit ("" = none declared)
    causality: str  # the variable's causality ("" when the model description has no such variable)


@dataclass(frozen=True)
class Terminal:
    name: str
    matching_rule: str  # plug, bus, sequence, none, or a layered standard's rule
    kind: str  # terminalKind ("" when absent)
    members: tuple[Member, ...]


_CACHE: dict = {}


def terminals_of(path: str | Path) -> dict[str, Terminal]:
    """``{terminal name: Terminal}`` of an FMU file (top-level terminals, in file order)."""
    from . import described, file_key
    from .archive import inspect_archive
    key = file_key(path)
    hit = _CACHE.get(key)
    if hit is not None:
        return hit
    inspect_archive(key[0])
    with zipfile.ZipFile(key[0]) as z:
        text = z.read(PATH) if PATH in z.namelist() else None
    out: dict[str, Terminal] = {}
    if text is not None:
        md = described(key[0])
        vars_ = {v.name: v for v in md.modelVariables}
        root = ET.fromstring(text)
        for t in root.findall("./Terminals/Terminal"):
            members = []
            for m in t.findall("TerminalMemberVariable"):
                v = vars_.get(m.get("variableName", ""))
                unit = ((v.unit or (v.declaredType.unit if v.declaredType is not None else None))
                        if v is not None else None)
                members.append(Member(m.get("memberName", ""), m.get("variableName", ""), unit or "",
                                      v.causality if v is not None else ""))
            out[t.get("name", "")] = Terminal(t.get("name", ""), t.get("matchingRule", ""), t.get("terminalKind", ""),
                                              tuple(members))
    _CACHE[key] = out
    return out
