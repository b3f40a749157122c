#!/usr/bin/env python3
"""Issue 43, item 5: the cost of a day of `leo/nadir` (86,400 s at 0.1 s) on the compiled engine against the
same loop in the plant's textbook environment (`leo/nadir-textbook`: no Orbit/Environment units, circular
orbit and dipole field inside the plant) and against the same scenario in Basilisk 2.12.1
(benches/basilisk_leo.py, run with the Basilisk venv when it exists). The three runs are interleaved round by
round in one invocation, so they see the same machine load; only the simulation loop is timed (not the
loading, instantiation or set-up). Prints a table of wall and CPU times and the ratios leo/nadir ÷ textbook
(issue target ≤ 2) and FMUs ÷ Basilisk.

    .venv/bin/python benches/leo_cost.py [--rounds 1] [--stop 86400] [--no-basilisk] [--log all|few]

Each FMU run happens in a child process of the project venv (one engine, one scenario per process, so a run
does not inherit the other's loaded libraries or memory); the Basilisk run in a child of .venv-bsk
(--bsk-python). Wall and CPU time (`time.process_time` of the process that runs the loop) are each the
minimum over the rounds; on a loaded machine the CPU time is the steadier of the two. `--log few` keeps only the quaternions (q_*: attitude, reference, measurement, estimate) and the wheel
momentum of each scenario's log (what the loop costs with little logging); the default logs what the scenario logs (56 signals in leo/nadir-textbook).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ("leo/nadir", "leo/nadir-textbook")

CHILD = """
import json, math, time
from scfmu import scenario as scenarios
from scfmu.engines.compiled import CompiledLoop
try:
    sc = scenarios.get({name!r})
except KeyError:  # a venv installed before the leo plug-in existed: register it by hand
    from scfmu.papers import leo
    from scfmu.registry import REGISTRY
    leo.register(REGISTRY)
    sc = scenarios.get({name!r})
sc.stop_time = sc.start_time + {stop!r}
if {log_few!r}:
    sc.log = {{k: v for k, v in sc.log.items() if k.startswith(("q_", "h_wheel"))}}
with CompiledLoop(sc) as m:
    w, c = time.perf_counter(), time.process_time()
    r = m.run()
    w, c = time.perf_counter() - w, time.process_time() - c
last = {{k: float(v[-1]) for k, v in r.items() if k != "time"}}
final = {{}}
if all(k in last for k in ("q_w", "q_ref_w")):  # pointing error: angle between the attitude and its reference
    dot = abs(sum(last[f"q_{{a}}"] * last[f"q_ref_{{a}}"] for a in "wxyz"))
    final["pointing error [deg]"] = math.degrees(2 * math.acos(min(1.0, dot)))
if "h_wheel_x" in last:
    final["wheel momentum [N·m·s]"] = math.sqrt(sum(last[f"h_wheel_{{a}}"] ** 2 for a in "xyz"))
print(json.dumps({{"wall_s": w, "cpu_s": c, "steps": sc.n_steps, "step": sc.step, "signals": len(sc.log),
                  "final": final}}))
"""


def fmu_run(name: str, stop: float, log_few: bool) -> dict:
    code = CHILD.format(name=name, stop=stop, log_few=log_few)
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    env.setdefault("SCFMU_FMU_DIR", str(ROOT / "fmus"))
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=ROOT)
    if p.returncode != 0:
        raise RuntimeError(f"{name}: {p.stderr.strip().splitlines()[-1] if p.stderr.strip() else p.returncode}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def basilisk_run(python: str, stop: float) -> dict:
    p = subprocess.run([python, str(ROOT / "benches" / "basilisk_leo.py"), "--stop", str(stop), "--json"],
                       capture_output=True, text=True, cwd=ROOT, check=True)
    return json.loads(p.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--stop", type=float, default=86_400.0, help="simulated seconds (default one day)")
    ap.add_argument("--log", choices=("all", "few"), default="all")
    ap.add_argument("--bsk-python", default=str(ROOT / ".venv-bsk" / "bin" / "python"))
    ap.add_argument("--no-basilisk", action="store_true")
    ap.add_argument("--scenarios", nargs=2, default=SCENARIOS, metavar=("WORLD", "TEXTBOOK"),
                    help="the two registered scenarios compared (default: leo/nadir leo/nadir-textbook)")
    a = ap.parse_args()
    with_bsk = not a.no_basilisk and Path(a.bsk_python).exists()
    runs = [*a.scenarios, *(["Basilisk 2.12.1"] if with_bsk else [])]
    best: dict[str, dict] = {}
    loads = [os.getloadavg()[0]]
    start = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    for i in range(a.rounds):
        for name in runs:
            r = basilisk_run(a.bsk_python, a.stop) if name.startswith("Basilisk") else fmu_run(name, a.stop,
                                                                                                a.log == "few")
            loads.append(os.getloadavg()[0])
            print(f"round {i + 1}: {name}: wall {r['wall_s']:.2f} s, cpu {r.get('cpu_s', float('nan')):.2f} s",
                  file=sys.stderr)
            if name not in best:
                best[name] = r
            else:  # the minimum wall and the minimum CPU time, each over the rounds; the rest from the first
                best[name]["wall_s"] = min(best[name]["wall_s"], r["wall_s"])
                best[name]["cpu_s"] = min(best[name]["cpu_s"], r["cpu_s"])
    print(f"{start}, load average {min(loads):.1f}–{max(loads):.1f} (1 min, sampled between runs); "
          f"{a.stop:g} s at 0.1 s, min over {a.rounds} interleaved round(s), log: {a.log}")
    print("| loop | wall [s] | CPU [s] | µs/step (CPU) | sanity (final values) |")
    print("|---|---:|---:|---:|---|")
    for name, r in best.items():
        steps = r.get("steps") or int(round(a.stop / 0.1))
        label = f"`{name}`, compiled engine" if not name.startswith("Basilisk") else name
        if name.startswith("Basilisk"):
            sanity = (f"pointing error {r['final_pointing_error_deg']:.3g}°, wheel momentum "
                      f"{r['final_wheel_momentum_Nms']:.3g} N·m·s ({r['field']})")
        else:
            sanity = ", ".join(f"{k} {v:.3g}" for k, v in r["final"].items()) or "—"
        print(f"| {label} | {r['wall_s']:.3f} | {r.get('cpu_s', float('nan')):.3f} | "
              f"{r['cpu_s'] / steps * 1e6:.2f} | {sanity} |")
    nadir, text = best[a.scenarios[0]], best[a.scenarios[1]]
    ratio = nadir["wall_s"] / text["wall_s"]
    print(f"\n{a.scenarios[0]} ÷ {a.scenarios[1]}: {ratio:.2f} wall, {nadir['cpu_s'] / text['cpu_s']:.2f} CPU "
          f"(target ≤ 2: {'met' if ratio <= 2.0 else 'NOT met'})")
    if with_bsk:
        b = best["Basilisk 2.12.1"]
        print(f"{a.scenarios[0]} (FMUs, compiled) ÷ Basilisk 2.12.1: {nadir['wall_s'] / b['wall_s']:.3f} wall, "
              f"{nadir['cpu_s'] / b['cpu_s']:.3f} CPU")
    return 0


if __name__ == "__main__":
    sys.exit(main())
