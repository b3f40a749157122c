"""The report section "Sensors and estimator in the loop": do paper 000's and paper 003's controller
rankings survive realistic sensing, and an estimator in the loop? (``scfmu report``; quick mode: 3 seeds and
paper 003's cases over 30 s, as ``scfmu paper sensing rankings --quick``.)

Every number is simulated here under a project-choice sensor suite (none of it is a paper's number): the
truth column is one run of the paper's scenario, the sensors and estimator columns are the mean ± standard
deviation over the seeded runs of its ``sensing/`` and ``sensing+estimation/`` variants. A ranking
"survives" when the order by those values is the order with the truth (ties within 1e-6 relative)."""

from __future__ import annotations

import time

from ...report.types import CONFIRMED, NOT_CONFIRMED, Claim, Figure, PaperSection, Table
from . import rankings

FULL_SEEDS, QUICK_SEEDS, QUICK_STOP_003 = 10, 3, 30.0


def _cell(r: dict, key: str) -> str:
    return f"{r[f'{key}_mean']:.4g} ± {r[f'{key}_std']:.2g}"


def _claim(cid: str, statement: str, rows: list[dict], groups: list[str], key: str, what: str) -> Claim:
    rs = [r for r in rows if r["group"] in groups]
    holds = all(r[key] for r in rs)
    broken = sorted({r["group"] for r in rs if not r[key]})
    evidence = (f"Ranked by the mean over the seeds {what}: the order is the truth's in "
                f"{len(groups) - len(broken)} of {len(groups)} group(s)"
                + (f"; it changes in {', '.join(broken)}" if broken else "") + ". Rule: confirmed when every "
                "group keeps the truth's order (ties within 1e-6 relative).")
    return Claim(cid, statement, CONFIRMED if holds else NOT_CONFIRMED, evidence)


def build(ctx) -> PaperSection:
    t0 = time.time()
    seeds = QUICK_SEEDS if ctx.quick else FULL_SEEDS
    out = ctx.out_dir / "runs" / "sensing"
    rows = rankings.run(out, seeds, ctx.workers, QUICK_STOP_003 if ctx.quick else None, log=print,
                        estimator=True, client=ctx.client)
    rankings.write(rows, out)
    n_runs = len(rows) * (1 + 2 * seeds)
    if hasattr(ctx, "add_runs"):
        ctx.add_runs(n_runs)  # the campaigns ran on the report's client outside ctx.campaign
    fig = ctx.figures_dir / "sensing_rankings.png"
    fig.write_bytes((out / "rankings.png").read_bytes())
    g000 = [g for g, *_ in rankings.GROUPS if g.startswith("paper 000")]
    g003 = [g for g, *_ in rankings.GROUPS if g.startswith("paper 003")]
    sens = "with gyro, star tracker and the 10 Hz flight computer"
    est = "with the Mekf estimator (fed by gyro, star tracker, sun sensor and magnetometer) in the loop"
    claims = [
        _claim("Csensing-1", "Paper 000's ranking of its controllers on the large slew (EULERINT) holds with "
               "realistic sensors.", rows, g000, "ranking_survives", sens),
        _claim("Csensing-2", "Paper 000's ranking on the large slew holds with an estimator in the loop.", rows, g000,
               "ranking_survives_estimator", est),
        _claim("Csensing-3", "Paper 003's T2F-SMC keeps its lead over GA-SMC (ISE) in cases N, C, S and W with "
               "realistic sensors.", rows, g003, "ranking_survives", sens),
        _claim("Csensing-4", "Paper 003's T2F-SMC keeps its lead over GA-SMC with an estimator in the loop.", rows,
               g003, "ranking_survives_estimator", est),
    ]
    table = Table(
        caption=(f"Primary metric per controller (paper 000: EULERINT [deg·s]; paper 003: ISE [rad²·s]); how each "
                 f"number was obtained: truth = one simulated run of the paper's scenario; sensors, estimator = "
                 f"mean ± sd over {seeds} seeded simulated runs of the sensing/ and sensing+estimation/ variants "
                 f"(sensor suite: project choice){'; quick mode: paper 003 over 30 s' if ctx.quick else ''}"),
        columns=["group", "controller", "truth", "sensors", "estimator", "rank truth / sensors / estimator"],
        rows=[[r["group"], r["controller"], f"{r['truth']:.4g}", _cell(r, "sensed"), _cell(r, "est"),
               f"{r['rank_truth']} / {r['rank_sensed']} / {r['rank_est']}"] for r in rows])
    setup = (f"Paper 000's large slew (one scenario per controller) and paper 003's cases N, C, S, W (GA-SMC, "
             f"T2F-SMC; the paper's 150 s{', quick mode: 30 s' if ctx.quick else ''}), each run once with the plant's truth and {seeds} times (seeds 1…{seeds}) with sensors and "
             f"with the estimator in the loop; {n_runs} runs on the native engine.")
    notes = ("Sensor suite (project choice): gyro 100 Hz, ARW 0.15 deg/sqrt(h), bias instability 1 deg/h (Gauss–Markov, τ_c 300 s); star "
             "tracker 5 Hz, 5/41 arcsec, 0.1 s latency; sun sensor 10 Hz, 0.1 deg, 60 deg field of view, none in "
             "eclipse; magnetometer 10 Hz, 100 nT; Mekf at 100 Hz with the sensors' own noise; flight computer "
             "10 Hz with a 0.05 s delay. docs/sensing.md discusses the results.")
    return PaperSection(paper="sensing", title="Sensors and estimator in the loop: do the papers' rankings survive?",
                        setup=setup, claims=claims, figures=[Figure("figures/sensing_rankings.png",
                                                                    "Primary metric with truth, sensors and estimator")],
                        tables=[table], notes=notes, runtime_s=time.time() - t0)
