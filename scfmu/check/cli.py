"""``scfmu check FMU [--quick] [--report DIR] [--seed N] [--sequences N] [--check NAME] [--call-timeout S]``:
exit 0 when every check passes, 1 when a check fails, 2 for a usage mistake."""

from __future__ import annotations

import argparse
import sys
import zipfile
from pathlib import Path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="scfmu check", description="Check any FMI 2.0 or 3.0 FMU (Co-Simulation and/or "
                                 "Model Exchange): its modelDescription against the standard's schema and rules, "
                                 "then its binary in isolated child processes (state machine, bad arguments, "
                                 "random call sequences, FMU states, memory, threads, extreme start times, stale "
                                 "handles, NaN in a state). Each failure is marked STD (violates the FMI "
                                 "standard) or ROB (fails a robustness rule of this project). Exit 0 = every "
                                 "check passed, 1 = a check failed, 2 = a usage mistake.")
    ap.add_argument("fmu", help="the .fmu file, or the name of a model of the package (e.g. PidController)")
    ap.add_argument("--quick", action="store_true", help="fewer sequences, cycles and steps (about 5-20 s per interface)")
    ap.add_argument("--report", metavar="DIR", help="also write DIR/check.json and DIR/check.html")
    ap.add_argument("--seed", type=int, default=0, help="seed of the random sequences and inputs (default 0)")
    ap.add_argument("--sequences", type=int, default=None, metavar="N",
                    help="number of random call sequences (default 200, 20 with --quick)")
    ap.add_argument("--timeout", type=float, default=None, metavar="S",
                    help="time limit of each dynamic check in seconds (default 120, 30 with --quick)")
    ap.add_argument("--call-timeout", type=float, default=None, metavar="S",
                    help="time limit of one FMI call in seconds: a call still running is a hang (default 5; 2 once "
                         "the unit has hung)")
    ap.add_argument("--check", action="append", default=None, metavar="NAME", dest="checks",
                    help="run only this dynamic check (repeatable; default: every one)")
    ap.add_argument("--interface", choices=("cs", "me"), action="append", default=None,
                    help="check only this interface (repeatable; default: every interface the FMU offers)")
    ap.add_argument("--json", action="store_true", help="print the JSON result instead of the table")
    try:
        a = ap.parse_args(argv)
    except SystemExit as e:
        return int(e.code or 0) and 2
    p = Path(a.fmu).expanduser()
    if not p.exists() and not a.fmu.lower().endswith(".fmu") and "/" not in a.fmu and "\\" not in a.fmu:
        from ..fmu import UnknownModel, fmu_path
        try:  # a model name, as `scfmu verify NAME` takes it
            p = fmu_path(a.fmu)
        except UnknownModel as e:
            print(f"scfmu check: {e}", file=sys.stderr)
            return 2
    if not p.exists():
        print(f"scfmu check: FMU {a.fmu!r} not found (give an .fmu file or a model name)", file=sys.stderr)
        return 2
    if not p.is_file():
        print(f"scfmu check: FMU {a.fmu!r} is not a file (give the .fmu archive)", file=sys.stderr)
        return 2
    if not zipfile.is_zipfile(p):
        print(f"scfmu check: FMU {a.fmu!r} is not an FMU archive (not a zip file: truncated, or another kind of "
              f"file); allowed: an .fmu file (a zip archive) or a model name", file=sys.stderr)
        return 2
    if a.sequences is not None and not 0 <= a.sequences <= 1_000_000:
        print(f"scfmu check: --sequences {a.sequences} is outside 0..1000000", file=sys.stderr)
        return 2
    if a.timeout is not None and not 0 < a.timeout <= 86400:
        print(f"scfmu check: --timeout {a.timeout} must be > 0 and at most 86400 s", file=sys.stderr)
        return 2
    if a.call_timeout is not None and not 0 < a.call_timeout <= 86400:
        print(f"scfmu check: --call-timeout {a.call_timeout} must be > 0 and at most 86400 s", file=sys.stderr)
        return 2
    from . import DYNAMIC_CHECKS
    for c in a.checks or []:
        if c not in DYNAMIC_CHECKS:
            print(f"scfmu check: --check {c!r} is not a check; allowed: {', '.join(DYNAMIC_CHECKS)}", file=sys.stderr)
            return 2
    if not -(2 ** 63) <= a.seed < 2 ** 63:
        print(f"scfmu check: --seed {a.seed} is outside the 64-bit range", file=sys.stderr)
        return 2
    from . import check
    rep = check(p, quick=a.quick, seed=a.seed, sequences=a.sequences, timeout=a.timeout, interfaces=a.interface,
                checks=a.checks, call_timeout=a.call_timeout,
                progress=lambda t: print(f"scfmu check: {t} ...", file=sys.stderr))
    if a.json:
        import json
        print(json.dumps(rep.to_dict(), indent=1, default=str))
    else:
        print(rep.text())
    if a.report:
        j, h = rep.write(a.report)
        print(f"scfmu check: wrote {j} and {h}", file=sys.stderr)
    return 0 if rep.ok else 1


if __name__ == "__main__":
    sys.exit(main())
