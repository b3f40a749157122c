"""``scfmu check``: the conformance and robustness gauntlet for any FMI 2.0 or 3.0 FMU.

Static checks (in this process): the modelDescription against the standard's schema and rules, and the
binaries for this platform. Dynamic checks (in child processes with a time limit each, so that a crash,
abort or hang of the FMU ends only the child), per interface the FMU offers (Co-Simulation, Model
Exchange): ``nominal_run``, ``state_machine``, ``bad_arguments``, ``random_sequences``, ``fmu_state``,
``memory``, ``threads`` (see scfmu.check.gauntlet), ``start_times``, ``stale_handles``, ``state_nan``
(scfmu.check.hostile). Deterministic for a seed. Every failed row has a ``class`` ("standard": a clause of
FMI 2.0/3.0 is violated; "robustness": a rule of this project the standard does not make) and the ``rule``
(scfmu.check.rules).

    from scfmu.check import check, check_quick
    report = check("MyController.fmu", quick=True, seed=1)
    report.ok, report.failures()       # rows: check, interface, status, kind, detail, reproducer, metrics
    report.write("out/")               # check.json + check.html
"""

from __future__ import annotations

import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path

STATIC_CHECKS = ("schema", "archive", "units", "start_values", "model_structure", "value_references", "variables", "binaries")
CLASSIC_CHECKS = ("nominal_run", "state_machine", "bad_arguments", "random_sequences", "fmu_state", "memory",
                  "threads")
HOSTILE_CHECKS = ("start_times", "stale_handles", "state_nan")  # what a hostile master does (scfmu.check.hostile)
DYNAMIC_CHECKS = CLASSIC_CHECKS + HOSTILE_CHECKS

QUICK = dict(steps=100, sequences=20, length=30, mutations=30, cycles=100, loads=4, threads=4, thread_steps=100,
             memory_limit=1 << 20, timeout=30.0, call_timeout=5.0, reuse_tries=64, nan_words=64)
FULL = dict(steps=1000, sequences=200, length=60, mutations=300, cycles=1000, loads=20, threads=8, thread_steps=500,
            memory_limit=1 << 20, timeout=120.0, call_timeout=5.0, reuse_tries=256, nan_words=512)
ADDRESS_SPACE = 8 << 30  # bytes of address space a check process may map
FILE_SIZE = 64 << 20      # bytes a check process may write to one file


@dataclass
class Report:
    fmu: str
    model: str = ""
    fmi_version: str = ""
    interfaces: list = field(default_factory=list)
    seed: int = 0
    quick: bool = False
    options: dict = field(default_factory=dict)
    rows: list = field(default_factory=list)
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        return not self.failures()

    def failures(self) -> list[dict]:
        return [r for r in self.rows if r["status"] == "fail"]

    def row(self, check: str, interface: str | None = None) -> dict:
        for r in self.rows:
            if r["check"] == check and (interface is None or r.get("interface") in (interface, None)):
                return r
        raise KeyError(f"no row for check {check!r}" + (f" on {interface}" if interface else ""))

    def failed_checks(self) -> set[str]:
        return {r["check"] for r in self.failures()}

    def findings(self, cls: str) -> list[dict]:
        """The failed rows of class "standard" or "robustness" (scfmu.check.rules)."""
        return [r for r in self.failures() if r.get("class") == cls]

    def to_dict(self) -> dict:
        return {"fmu": self.fmu, "model": self.model, "fmi_version": self.fmi_version, "interfaces": self.interfaces,
                "seed": self.seed, "quick": self.quick, "options": self.options, "ok": self.ok,
                "seconds": round(self.seconds, 2),
                "findings": {c: [f"{r['check']}" + (f" ({r['interface']})" if r.get("interface") else "")
                                 for r in self.findings(c)] for c in ("standard", "robustness")},
                "rows": self.rows}

    def write(self, folder) -> tuple[Path, Path]:
        from .report import write
        return write(self, Path(folder))

    def text(self, width: int = 110) -> str:
        from .report import text
        return text(self, width)


def _extract(path: Path):
    """(model description, folder, created) of the FMU under check: a whole extraction of its own (every
    platform, so that the binaries row can name the platforms present) into the process's scratch folder,
    never the shared unit cache (scfmu.fmu.units): the unit's library runs in child processes that may
    write into it. :func:`_release` removes it."""
    from .. import fmu as fmu_mod
    md = fmu_mod.described(path)
    d = fmu_mod.safe_extract(path)
    return md, Path(d), [d]


def _release(d: Path, created: list) -> None:
    if created:
        shutil.rmtree(d, ignore_errors=True)


def check(path, *, quick: bool = False, seed: int = 0, sequences: int | None = None, timeout: float | None = None,
          checks: list[str] | None = None, interfaces: list[str] | None = None, progress=None,
          call_timeout: float | None = None) -> Report:
    """Runs the gauntlet on the FMU at `path` and returns the :class:`Report` (never raises for a bad FMU:
    everything wrong with it is a failed row). `checks` restricts the dynamic checks, `interfaces` to
    "cs"/"me"; `progress(text)` is called before each step."""
    rep = _check(path, quick, seed, sequences, timeout, checks, interfaces, progress, call_timeout)
    from .rules import classify
    version = 3 if rep.fmi_version.startswith("3") else 2
    rep.rows = [classify(_order(r), version) for r in rep.rows]
    return rep


def _check(path, quick, seed, sequences, timeout, checks, interfaces, progress, call_timeout) -> Report:
    """The rows of :func:`check`, before classification."""
    from .runner import run_checks
    from .static import binaries_check, rule_checks, schema_check, unit_spec
    t_start = time.monotonic()
    path = Path(path)
    opts = dict(QUICK if quick else FULL)
    if sequences is not None:
        opts["sequences"] = int(sequences)
    if timeout is not None:
        opts["timeout"] = float(timeout)
    if call_timeout is not None:
        opts["call_timeout"] = float(call_timeout)
    opts.update(seed=int(seed), address_space=ADDRESS_SPACE, file_size=FILE_SIZE)
    rep = Report(fmu=str(path), seed=int(seed), quick=quick, options={k: v for k, v in opts.items()})
    say = progress or (lambda _t: None)
    say("static checks")
    row, version = schema_check(path)
    rep.rows.append(row)
    rep.fmi_version = version or ""
    if version is None:
        _skip_rest(rep, "the modelDescription cannot be read")
        rep.seconds = time.monotonic() - t_start
        return rep
    try:
        md, d, created = _extract(path)
    except Exception as e:  # an archive the extraction refuses, or a description fmpy cannot read
        msg = str(e).splitlines()[0] if str(e) else type(e).__name__
        if rep.rows[0]["status"] == "fail":  # fmpy refuses to read what fails the schema: already reported
            _skip_rest(rep, "the modelDescription fails the schema (see schema)")
        else:
            rep.rows.append({"check": "archive", "status": "fail", "kind": "archive",
                             "detail": f"the FMU cannot be extracted or read: {msg}"})
            _skip_rest(rep, "the FMU cannot be extracted or read (see archive)")
        rep.seconds = time.monotonic() - t_start
        return rep
    files = [p for p in d.rglob("*") if p.is_file()]
    rep.rows.append({"check": "archive", "status": "pass",
                     "detail": f"extracted: {len(files)} files, {sum(p.stat().st_size for p in files) / 1e6:.1f} MB"})
    try:
        rep.model = md.modelName
        rep.rows.extend(rule_checks(md))
        brow, libs = binaries_check(md, d)
        rep.rows.append(brow)
        offered = [i for i in ("cs", "me") if (md.coSimulation if i == "cs" else md.modelExchange) is not None]
        rep.interfaces = [i for i in offered if interfaces is None or i in interfaces]
        names = [c for c in DYNAMIC_CHECKS if checks is None or c in checks]
        if not offered:
            rep.rows += [{"check": c, "status": "n/a", "detail": "no Co-Simulation or Model Exchange interface"}
                         for c in names]
        seen = {"hung": False}
        for itf in rep.interfaces:
            if itf not in libs:
                for c in names:
                    rep.rows.append({"check": c, "interface": itf, "status": "n/a",
                                     "detail": "no binary for this platform (see binaries)"})
                continue
            spec = unit_spec(md, d, itf, libs[itf])
            say(f"{itf.upper()}: {', '.join(names)}")
            res = run_checks(spec, names, opts, opts["timeout"], seen)
            for c in names:
                r = dict(res[c])
                r.update(check=c, interface=itf)
                rep.rows.append(_order(r))
    finally:
        _release(d, created)
    rep.seconds = time.monotonic() - t_start
    return rep


def _order(r: dict) -> dict:
    keys = ("check", "interface", "status", "class", "rule", "kind", "detail", "metrics", "reproducer")
    return {k: r[k] for k in keys if k in r} | {k: v for k, v in r.items() if k not in keys}


def _skip_rest(rep: Report, why: str) -> None:
    have = {r["check"] for r in rep.rows}
    for c in STATIC_CHECKS:
        if c not in have:
            rep.rows.append({"check": c, "status": "n/a", "detail": why})
    for c in DYNAMIC_CHECKS:
        rep.rows.append({"check": c, "status": "n/a", "detail": why})


def check_quick(path, seed: int = 0) -> Report:
    """The pre-flight of a benchmark or campaign: :func:`check` with ``quick=True``, without the hostile-master
    checks (extreme start times, stale handles, NaN in a state: calls a benchmark or a campaign never makes)."""
    return check(path, quick=True, seed=seed, checks=list(CLASSIC_CHECKS))
