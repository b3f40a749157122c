"""Paper 002 as printed: the four gain sets of its Table 4 run as they are, under a small set of named
readings of what the paper leaves open, on the nominal step (θ_ref = 30 deg, 20 s).

Readings (every combination is run):

* the unit of the error the gains act on: rad (our port) or deg. Degrees are run on the same SI controller
  with every gain × 180/π (u = K e_deg = (180/π) K e_rad; λ and μ are orders and stay);
* the wheel-torque limit of the plant: 1 N·m (our plant's project choice), 10 N·m, none;
* the derivative on the error (the paper's law) or on the measurement. For a step reference from rest the
  latter is the controller's ``history_before_start`` = 1: the Grünwald–Letnikov operator is linear and sees
  θ_ref − θ extended by its value at t = 0 into the past, whose derivative of any order μ > 0 vanishes, so
  D^μ e = −D^μ θ (no kick at t = 0); tested against a numpy implementation.

Gain sets: the damaged digits of Table 4 leave several candidates per entry; every candidate value is run
once, one entry at a time from the first-listed reading (``gain_sets``), the same sets in quick and full
builds. The default reading is the error in degrees (the paper's cost, Eq. 19, and its plots are in degrees,
so its tuned gains are per degree), the project plant's 1 N·m limit (the plant is not a reading of the gains
table), and the derivative on the error (the paper states it). It is chosen on those grounds, before
looking at which reading passes which claim.
"""

from __future__ import annotations

import itertools
import math

from . import model as p2

UNITS = {"rad": 1.0, "deg": 180.0 / math.pi}
LIMITS = {"1 N·m": 1.0, "10 N·m": 10.0, "none": 1e30}
DERIVATIVE = {"on error": 0, "on measurement": 1}      # the controller's history_before_start
DEFAULT = ("deg", "1 N·m", "on error")


def readings() -> list[tuple[str, str, str]]:
    return list(itertools.product(UNITS, LIMITS, DERIVATIVE))


def name(r: tuple[str, str, str]) -> str:
    return f"error in {r[0]}, limit {r[1]}, derivative {r[2]}"


def gain_sets(reported: dict) -> dict[str, list[dict]]:
    """{controller: [gains]}: the first-listed candidate of every entry, then each other candidate of one entry
    at a time (every printed candidate value runs at least once)."""
    by = {}
    for g in reported["gains"]:
        by.setdefault(g["controller"], {})[g["gain"]] = [float(x) for x in g["candidates"]]
    out = {}
    for c, entries in by.items():
        base = {k: v[0] for k, v in entries.items()}
        sets = [dict(base)]
        for k, vals in entries.items():
            for x in vals[1:]:
                sets.append({**base, k: x})
        out[c] = sets
    return out


def overrides(controller: str, gains: dict, r: tuple[str, str, str]) -> dict:
    """Campaign overrides of the ``paper002/<controller>`` scenario for one gain set under one reading."""
    f = UNITS[r[0]]
    g = p2.full_gains(controller, gains)
    ov = {"controller.kp": g["kp"] * f, "controller.kd": g["kd"] * f,
          "plant.torque_limit": LIMITS[r[1]], "controller.history_before_start": DERIVATIVE[r[2]]}
    if p2.CONTROLLERS[controller][0] == "FopidController" or g["ki"]:
        ov["controller.ki"] = g["ki"] * f
    if p2.CONTROLLERS[controller][0] == "FopidController":
        ov.update({"controller.lambda": g["lambda"], "controller.mu": g["mu"]})
    return ov


def label(gains: dict) -> str:
    return ", ".join(f"{k} = {v:g}" for k, v in gains.items())


def pair_share(fo: list[dict], integer: list[dict], rule) -> tuple[int, int]:
    """How many (fractional set, integer set) combinations satisfy ``rule(fo_row, integer_row)``."""
    ok = sum(bool(rule(a, b)) for a in fo for b in integer)
    return ok, len(fo) * len(integer)


def verdict_of(shares: dict) -> str:
    """A reading supports a claim on the printed gains when it holds for every candidate combination; "some"
    when for part of them; "no" otherwise."""
    out = {}
    for r, (k, n) in shares.items():
        out[r] = "every candidate" if k == n and n else "some candidates" if k else "no candidate"
    return out


def run(ctx, theta_ref: float, t_end: float, reported: dict) -> dict:
    """Runs every printed gain set under every reading (one campaign per controller, no time series: the
    metric set ``paper002`` gives MAE, settling and overshoot). Returns {controller: {reading: [metrics row
    per gain set]}} with a failed or diverged run as infinite metrics, plus the gain sets."""
    from ... import campaign
    from ...report import common
    from . import scenarios
    sets_by = gain_sets(reported)
    out = {}
    for c, sets in sets_by.items():
        rs_ = readings()
        ovs = [overrides(c, g, r) for r in rs_ for g in sets]
        sc = scenarios.paper002(c, theta_ref, stop_time=t_end)
        name = f"paper002_printed_{c}" + ("_quick" if ctx.quick else "")
        rows = common.rows(ctx.campaign(campaign.Campaign(sc, ovs), name))
        res = {}
        for k, r in enumerate(rs_):
            res[r] = [_clean(rows[k * len(sets) + j]) for j in range(len(sets))]
        out[c] = res
    return {"results": out, "sets": sets_by}


def _clean(row: dict) -> dict:
    """MAE, settling, overshoot of one run; a failed or non-finite run counts as infinitely bad."""
    keys = ("mae_deg", "settling_s", "overshoot_pct")
    if row.get("status") != "ok" or not all(isinstance(row.get(k), (int, float)) and math.isfinite(row[k])
                                            for k in ("mae_deg",)):
        return {k: math.inf for k in keys}
    return {k: (math.inf if row.get(k) is None or (isinstance(row[k], float) and math.isnan(row[k])) else float(row[k]))
            for k in keys}


def shares(results: dict, pair_rule, phase_rule, pairs) -> dict:
    """Per reading: (k, n) of candidate combinations under which C002-1 (both pairs) and C002-2 hold."""
    out = {}
    for r in readings():
        res = {c: results[c][r] for c in results}
        p1 = [pair_share(res[f], res[i], lambda a, b: pair_rule(a, b)["holds"]) for i, f in pairs]
        n1 = p1[0][1] * p1[1][1]
        k1 = p1[0][0] * p1[1][0]                       # both pairs hold for a combination of all four sets
        k2 = n2 = 0
        for combo in itertools.product(*(res[c] for c in ("PD", "PID", "FOPD", "FOPID"))):
            n2 += 1
            k2 += bool(phase_rule(dict(zip(("PD", "PID", "FOPD", "FOPID"), (x["mae_deg"] for x in combo))))["holds"])
        out[r] = {"C002-1": (k1, n1), "C002-2": (k2, n2), **{f"{f} vs {i}": p for (i, f), p in zip(pairs, p1)}}
    return out


def claim_verdict(share_by_reading: dict, cid: str) -> tuple[str, list[str], list[str]]:
    """(verdict, readings where the claim holds for every candidate, readings where it holds for some). Holds
    for every candidate under every reading → confirmed; under none, for no candidate → not confirmed;
    otherwise it depends on a reading (the readings and the damaged digits named)."""
    from ...report.types import CONFIRMED, DEPENDS, NOT_CONFIRMED
    every = [name(r) for r, s in share_by_reading.items() if s[cid][0] == s[cid][1] and s[cid][1]]
    some = [name(r) for r, s in share_by_reading.items() if 0 < s[cid][0] < s[cid][1]]
    if len(every) == len(share_by_reading):
        return CONFIRMED, every, some
    if not every and not some:
        return NOT_CONFIRMED, every, some
    return DEPENDS, every, some


def table(share_by_reading: dict, results: dict):
    """The readings × claims table (share of candidate combinations where each holds: per pair, both pairs,
    C002-2) with the nominal MAE range per controller."""
    from ...report.types import Table
    rows = []
    for r, s in share_by_reading.items():
        mae = {c: [x["mae_deg"] for x in results[c][r]] for c in results}
        pair_cols = [k for k in s if " vs " in k]
        rows.append([name(r) + (" (default)" if r == DEFAULT else ""),
                     *(f"{s[k][0]} / {s[k][1]}" for k in pair_cols),
                     f"{s['C002-1'][0]} / {s['C002-1'][1]}", f"{s['C002-2'][0]} / {s['C002-2'][1]}",
                     *(f"{min(v):.3g} … {max(v):.3g}" for v in mae.values())])
    return Table("Paper 002's Table 4 gains as printed (every damaged-digit candidate, one entry at a time) under "
                 "each reading: candidate combinations under which C002-1 (both pairs) and C002-2 hold, and the "
                 "range of the nominal MAE (deg, ∞ = diverged or failed) per controller",
                 ["reading", *(f"C002-1 rule, {k}" for k in next(iter(share_by_reading.values())) if " vs " in k),
                  "C002-1 holds (both pairs)", "C002-2 holds", *(f"MAE {c}" for c in results)], rows)
