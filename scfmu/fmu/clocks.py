"""What an FMI 3.0 model description says about clocks beyond fmpy's reader: the ``priority``,
``intervalDecimal`` and ``shiftDecimal`` of each ``<Clock>`` (fmpy 0.3.32 has the fields but does not fill
them)."""

from __future__ import annotations

import zipfile
from pathlib import Path

from lxml import etree

from . import described, file_key

_ATTRIBUTES: dict = {}


def clock_attributes(path: str | Path) -> dict[int, dict]:
    """``{value reference: {"priority": int | None, "intervalDecimal": float | None, "shiftDecimal": float |
    None}}`` of the ``<Clock>`` variables of an FMI 3.0 FMU, read from the archive's ``modelDescription.xml``
    (inspected by :func:`described` first); cached like it."""
    key = file_key(path)
    hit = _ATTRIBUTES.get(key)
    if hit is None:
        described(path)
        with zipfile.ZipFile(key[0]) as z:
            root = etree.fromstring(z.read("modelDescription.xml"), etree.XMLParser(resolve_entities=False))
        hit = _ATTRIBUTES[key] = {int(c.get("valueReference")): {
            "priority": _num(c.get("priority"), int), "intervalDecimal": _num(c.get("intervalDecimal"), float),
            "shiftDecimal": _num(c.get("shiftDecimal"), float)} for c in root.iter("Clock")}
    return hit


def _num(text, kind):
    return None if text is None else kind(text)
