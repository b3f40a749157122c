"""Connections by FMI 3.0 terminals: a scenario's ``terminals`` entry ``{"dst.terminal": "src.terminal"}``
expands into the scalar links of the two terminals, by the terminals' matching rule (FMI 3.0 section
2.4.9.2): ``plug`` pairs the members by member name and needs every member on both sides, ``bus`` pairs the
member names both sides have (at least one), ``sequence`` pairs the members by position and needs as many on
both sides; ``none`` (and any rule of another standard) is not connected. The two terminals must have the
same rule and kind (``terminalKind``); each pair must join an output of the source to an input of the
destination, with equal units. Each refusal is one line naming the connection and what does not match."""

from __future__ import annotations

RULES = ("plug", "bus", "sequence")


def _pairs(dst, src) -> tuple[list, str | None]:
    """The (dst member, src member) pairs of two terminals by their rule, or the reason there are none."""
    if dst.matching_rule != src.matching_rule:
        return [], f"matching rules differ: {src.matching_rule} -> {dst.matching_rule}"
    rule = dst.matching_rule
    if rule not in RULES:
        return [], f"matchingRule {rule!r} is not meant for connecting here (known: {', '.join(RULES)})"
    if dst.kind != src.kind:
        return [], f"kinds differ: {src.kind or '(none)'} -> {dst.kind or '(none)'}"
    if rule == "sequence":
        if len(dst.members) != len(src.members):
            return [], f"{len(src.members)} members -> {len(dst.members)} (sequence matching needs as many)"
        return list(zip(dst.members, src.members)), None
    by_name = {m.member: m for m in src.members}
    names = {m.member for m in dst.members}
    if rule == "plug" and names != set(by_name):
        lack_d = sorted(set(by_name) - names)
        lack_s = sorted(names - set(by_name))
        return [], ("members do not match: " + "; ".join(x for x in (
            f"source lacks {', '.join(lack_s)}" if lack_s else "", f"destination lacks {', '.join(lack_d)}" if lack_d else "")
            if x))
    pairs = [(m, by_name[m.member]) for m in dst.members if m.member in by_name]
    if not pairs:
        return [], "no member name in common (bus matching)"
    return pairs, None


def expand(sc, terminals: dict | None) -> tuple[dict, list[str]]:
    """The scalar connections ``{"dst.input": "src.output"}`` (scenario port names, after each unit's
    ``ports`` renames) of ``sc.terminals``, given each instance's terminals (``{instance: {name:
    Terminal}}``, :func:`scfmu.fmu.terminals.terminals_of`), and the one-line problems found."""
    out: dict[str, str] = {}
    problems: list[str] = []
    if not sc.terminals:
        return out, problems
    if terminals is None:
        return out, ["terminal connections need the units' terminals (FMI 3.0 terminalsAndIcons.xml)"]
    for dst, src in sc.terminals.items():
        what = f"terminal connection {dst} <- {src}"
        ends = []
        for q in (dst, src):
            inst, sep, name = q.partition(".")
            if not sep or not name:
                problems.append(f"{what}: {q!r} is not 'instance.terminal'")
                break
            if inst not in terminals:
                problems.append(f"{what}: unknown instance {inst!r}")
                break
            t = terminals[inst].get(name)
            if t is None:
                have = ", ".join(terminals[inst]) or "none: no terminalsAndIcons.xml"
                problems.append(f"{what}: {inst} has no terminal {name!r} (has {have})")
                break
            ends.append((inst, t))
        if len(ends) != 2:
            continue
        (di, td), (si, ts) = ends
        pairs, why = _pairs(td, ts)
        if why:
            problems.append(f"{what}: {why}")
            continue
        for md, ms in pairs:
            a, b = f"{di}.{md.variable}", f"{si}.{ms.variable}"
            if md.causality != "input" or ms.causality != "output":
                bad = a if md.causality != "input" else b
                problems.append(f"{what}: {bad} is not {'an input' if bad == a else 'an output'}")
            elif md.unit != ms.unit:
                problems.append(f"{what}: unit of {b} ({ms.unit or 'none'}) differs from {a} ({md.unit or 'none'})")
            else:
                key = f"{di}.{sc.alias(di, md.variable)}"
                val = f"{si}.{sc.alias(si, ms.variable)}"
                if key in out and out[key] != val:
                    problems.append(f"{what}: {a} is already fed by {out[key]}")
                out[key] = val
    for k, v in out.items():
        if k in sc.connections and sc.connections[k] != v:
            problems.append(f"input {k} is fed both by a terminal ({v}) and by connections ({sc.connections[k]})")
    return out, problems
