"""The result of ``scfmu check`` as a terminal table, JSON and a standalone HTML page."""

from __future__ import annotations

import html
import json
from pathlib import Path

MARK = {"pass": "pass", "fail": "FAIL", "n/a": "n/a"}
CLASSES = (("standard", "Violations of the FMI standard"),
           ("robustness", "Failures of this project's robustness rules (the standard does not require these)"))
TAG = {"standard": "STD", "robustness": "ROB"}


def _tag(r: dict) -> str:
    return TAG.get(r.get("class", ""), "FAIL") if r["status"] == "fail" else MARK[r["status"]]


def findings_text(rep) -> list[str]:
    """The failed rows grouped by class, each with its rule: the part of the table a reader acts on."""
    out = []
    for cls, title in CLASSES:
        rows = [r for r in rep.failures() if r.get("class") == cls]
        out += ["", f"  {title}: {len(rows)}"]
        for r in rows:
            itf = (r.get("interface") or "").upper()
            out.append(f"    - {r['check']}{' ' + itf if itf else ''}: {' '.join(str(r.get('detail', '')).split())}")
            out.append(f"      rule: {r.get('rule', '')}")
    return out


def _cell(s: str, w: int) -> str:
    s = " ".join(str(s).split())
    return s if len(s) <= w else s[: w - 1] + "…"


def text(rep, width: int = 110) -> str:
    out = [f"scfmu check {rep.fmu}",
           f"  model {rep.model or '?'}, FMI {rep.fmi_version or '?'}, interfaces "
           f"{', '.join(i.upper() for i in rep.interfaces) or 'none'}, seed {rep.seed}"
           f"{', quick' if rep.quick else ''}, {rep.seconds:.1f} s", ""]
    w_check, w_itf, w_st = 17, 3, 5
    w_det = max(30, width - w_check - w_itf - w_st - 8)
    out.append(f"  {'check':{w_check}s} {'itf':{w_itf}s} {'result':{w_st}s}  detail")
    out.append("  " + "-" * (w_check + w_itf + w_st + 4 + w_det))
    for r in rep.rows:
        itf = (r.get("interface") or "").upper() or "-"
        det = r.get("detail", "")
        if r["status"] == "fail" and r.get("kind"):
            det = f"[{r['kind']}] {det}"
        out.append(f"  {r['check']:{w_check}s} {itf:{w_itf}s} {_tag(r):{w_st}s}  {_cell(det, w_det)}")
    out.append("  (result: STD = violates the standard, ROB = fails a robustness rule of this project)")
    out += findings_text(rep)
    fails = rep.failures()
    for r in fails:
        if r.get("reproducer"):
            out.append("")
            out.append(f"  reproducer of {r['check']} ({(r.get('interface') or '').upper()}):")
            calls = r["reproducer"]
            shown = calls if len(calls) <= 40 else calls[:5] + [f"... {len(calls) - 35} calls ..."] + calls[-30:]
            out += [f"    {c}" + (";" if not c.startswith("//") and not c.startswith("...") else "") for c in shown]
    out.append("")
    n = {k: sum(1 for r in rep.rows if r["status"] == k) for k in MARK}
    n_std, n_rob = len(rep.findings("standard")), len(rep.findings("robustness"))
    out.append(f"  {n['pass']} passed, {n['fail']} failed ({n_std} standard, {n_rob} robustness), "
               f"{n['n/a']} not applicable: "
               + ("the FMU passes" if not fails else "the FMU FAILS: " + ", ".join(sorted(rep.failed_checks()))))
    return "\n".join(out)


def to_html(rep) -> str:
    e = html.escape
    css = ("body{font-family:sans-serif;margin:2em;max-width:75em}table{border-collapse:collapse;width:100%}"
           "td,th{border:1px solid #ccc;padding:4px 8px;vertical-align:top;text-align:left}"
           ".pass{background:#e6f4e6}.fail{background:#f9dddd;font-weight:bold}.na{color:#777}"
           ".rob{background:#fdf0d5;font-weight:bold}"
           "pre{background:#f6f6f6;padding:8px;overflow-x:auto;font-size:90%}")
    rows = []
    for r in rep.rows:
        cls = {"pass": "pass", "fail": "fail" if r.get("class") == "standard" else "rob", "n/a": "na"}[r["status"]]
        det = e(r.get("detail", ""))
        if r.get("kind") and r["status"] == "fail":
            det = f"<b>{e(r['kind'])}</b>: {det}"
        rows.append(f"<tr><td>{e(r['check'])}</td><td>{e((r.get('interface') or '-').upper())}</td>"
                    f"<td class='{cls}'>{e(_tag(r))}</td><td>{det}</td></tr>")
    groups = []
    for key, title in CLASSES:
        items = "".join(f"<li><b>{e(r['check'])}</b> {e((r.get('interface') or '').upper())}: "
                        f"{e(str(r.get('detail', '')))}<br><i>rule: {e(r.get('rule', ''))}</i></li>"
                        for r in rep.failures() if r.get("class") == key)
        groups.append(f"<h2>{e(title)}</h2>" + (f"<ul>{items}</ul>" if items else "<p>none</p>"))
    repro = []
    for r in rep.failures():
        if r.get("reproducer"):
            calls = "\n".join(c + (";" if not c.startswith("//") else "") for c in r["reproducer"])
            repro.append(f"<h3>{e(r['check'])} ({e((r.get('interface') or '').upper())})</h3><pre>{e(calls)}</pre>")
    verdict = "passes every check" if rep.ok else "FAILS: " + ", ".join(sorted(rep.failed_checks()))
    return f"""<!DOCTYPE html><html><head><meta charset="utf-8"><title>scfmu check: {e(rep.model)}</title>
<style>{css}</style></head><body>
<h1>scfmu check: {e(rep.model or rep.fmu)}</h1>
<p>{e(rep.fmu)}<br>FMI {e(rep.fmi_version)}, interfaces {e(', '.join(i.upper() for i in rep.interfaces) or 'none')},
seed {rep.seed}{', quick' if rep.quick else ''}, {rep.seconds:.1f} s. The FMU <b>{e(verdict)}</b>.</p>
<table><tr><th>check</th><th>interface</th><th>result</th><th>detail</th></tr>
{''.join(rows)}</table>
<p>STD = violates the FMI standard (the clause is named), ROB = fails a robustness rule of this project.</p>
{''.join(groups)}
{'<h2>Reproducers (the first failing call sequence of each failed check)</h2>' + ''.join(repro) if repro else ''}
<p style="color:#777">The static checks read the modelDescription; the dynamic checks call the binary in child
processes with a time limit each. See docs/check.md of scfmu for what each check does.</p>
</body></html>
"""


def write(rep, folder: Path) -> tuple[Path, Path]:
    folder.mkdir(parents=True, exist_ok=True)
    j = folder / "check.json"
    h = folder / "check.html"
    j.write_text(json.dumps(rep.to_dict(), indent=1, default=str) + "\n")
    h.write_text(to_html(rep))
    return j, h
