#!/usr/bin/env python3
"""Two builds of the FMUs side by side in one session: the compiled loop (scfmu/engines/native_loop) and the
native container with no Python call per step, µs per communication step, for the loops of
benches/cosim_loops.py (2 FMUs, and the 4 FMUs of run 000-6). Each measurement runs in its own process
(the FMU folder is chosen per process through SCFMU_FMU_DIR), the two folders alternate round by round,
and each figure is the minimum over the rounds (docs/benchmarks.md, issue 45: handles that are never reused).

Usage: .venv/bin/python benches/loop_ab.py OLD_FMU_DIR NEW_FMU_DIR [--rounds 7]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import json, sys
sys.path.insert(0, {benches!r})
from cosim_loops import two_fmu_scenario, t_compiled, t_native
from scfmu import scenario as scenarios
out = {{}}
for name, sc in (("2 FMUs", two_fmu_scenario()), ("run 000-6", scenarios.get("default"))):
    for how, f in (("compiled loop", t_compiled), ("native, no Python per step", lambda s: t_native(s, 0))):
        f(sc)  # warm: extraction, first load
        out[f"{{how}}, {{name}}"] = min(f(sc) for _ in range(5)) / sc.n_steps * 1e6
print(json.dumps(out))
"""


def measure(fmu_dir: str) -> dict[str, float]:
    env = {**os.environ, "SCFMU_FMU_DIR": fmu_dir}
    code = CHILD.format(benches=str(ROOT / "benches"))
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True, cwd=ROOT)
    return json.loads(p.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--rounds", type=int, default=7)
    a = ap.parse_args()
    best: dict[str, dict[str, float]] = {"old": {}, "new": {}}
    for _ in range(a.rounds):
        for which, d in (("old", a.old), ("new", a.new)):
            for k, v in measure(d).items():
                best[which][k] = min(best[which].get(k, float("inf")), v)
    print(f"\n| µs per communication step, min over {a.rounds} alternating rounds | old | new | new / old |")
    print("|---|---:|---:|---:|")
    for k in best["old"]:
        o, n = best["old"][k], best["new"][k]
        print(f"| {k} | {o:.3f} | {n:.3f} | {n / o:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
