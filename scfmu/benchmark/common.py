"""The benchmark's shared vocabulary: metric titles and units, the comparison resolution, the extension
points (:func:`add_column`, :func:`add_section`, :func:`add_warning`), the :class:`Entry` of one (scenario,
controller) pair and the comparisons the page and the engineering section share (ranks, identical
responses, the main error of a run)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

UNIT = "unit under test"

# Units of measure of the metrics per family (the metric sets' definitions in scfmu.metrics)
_ATT = {"eulerint_deg_s": "deg·s", "ise": "rad²·s", "isf": "N²·m²·s", "settling_s": "s", "effort_abs": "N·m·s",
        "final_error": "deg", "mae_deg": "deg", "euler_end_max_deg": "deg"}
METRIC_UNITS = {"attitude": _ATT,
                "single_axis": dict(_ATT, ise="rad²·s", isf="N²·m²·s"),
                "formation": {"ise": "m²·s", "isf": "N²·s", "settling_s": "s", "effort_abs": "N·s", "final_error": "m"}}
TITLES = {"eulerint_deg_s": "EULERINT", "ise": "ISE", "isf": "ISF", "settling_s": "settling time",
          "effort_abs": "effort ∫Σ abs(u) dt", "final_error": "final error", "mae_deg": "MAE",
          "euler_end_max_deg": "largest final angle"}
COLUMNS = [("eulerint_deg_s", "EULERINT"), ("ise", "ISE"), ("isf", "ISF"), ("settling_s", "settling time"),
           ("effort_abs", "effort ∫Σ abs(u) dt"), ("final_error", "final error")]

# Resolution of the comparisons: two values a, b of a metric are equal when
#   |a − b| ≤ rel · max(|a|, |b|) + abs      (abs in the metric's unit)
# (project choice: 1e-6 relative is far above the round-off differences of equivalent laws, ~1e-14, and far
# below any difference an engineer would act on; abs keeps values that are zero to round-off equal).
RESOLUTION = {"default": (1e-6, 1e-9)}
# responses are identical when max |Δ signal| over the logged samples ≤ rel · max |signal| + abs
RESPONSE_RESOLUTION = (1e-6, 1e-9)


def resolution(metric: str) -> tuple[float, float]:
    return RESOLUTION.get(metric, RESOLUTION["default"])


def equal(a: float, b: float, metric: str = "default") -> bool:
    rel, ab = resolution(metric)
    return abs(a - b) <= rel * max(abs(a), abs(b)) + ab


def metric_title(key: str, family: str) -> str:
    unit = METRIC_UNITS.get(family, {}).get(key) or ("deg" if key.endswith("_deg") else "s" if key.endswith("_s") else "")
    name = TITLES.get(key) or next((t for k, t in COLUMNS if k == key), key)
    return f"{name} [{unit}]" if unit else f"{name} [–]"


EST_KEY = "with_estimator"  # Entry.means key of the primary metric with the estimator in the loop (--estimator)


# ----- extension points ------------------------------------------------------------------------------------
SECTIONS: list = []  # fn(out, case or None, entries, ctx) -> (markdown lines, html text); case None: page-level
WARNINGS: list = []  # fn(cases, entries, ctx) -> [warning text]


def add_column(key: str, title: str, unit: str = "", family: str | None = None) -> None:
    """A metric column (a key of the campaign rows, e.g. one a metric set computes): shown with its unit,
    averaged over the runs, in the CSV."""
    if key not in [k for k, _ in COLUMNS]:
        COLUMNS.append((key, title))
    TITLES[key] = title
    for fam in ([family] if family else list(METRIC_UNITS)):
        if unit:
            METRIC_UNITS.setdefault(fam, {})[key] = unit


def add_section(fn) -> None:
    """``fn(out, case, entries, ctx) -> (markdown lines, html)``: called once per scenario (below its table)
    and once with ``case=None`` (after the scenarios); ``ctx`` has ``family``, ``unit_label``, ``quick``."""
    SECTIONS.append(fn)


def add_warning(fn) -> None:
    """``fn(cases, entries, ctx) -> [text]``: lines of the warnings block at the top of the page."""
    WARNINGS.append(fn)


@dataclass
class Entry:
    case: str
    controller: str
    model: str
    runs: int = 0
    ok: int = 0
    settled: int = 0
    means: dict = field(default_factory=dict)
    status: str = ""  # "" (ran), "n/a: reason", or "not designed for this plant: reason"
    series: dict | None = None  # {"time": ..., signal: ...} of the first run
    failures: list = field(default_factory=list)
    config: str = ""  # how the controller is configured on this scenario (paper's tuning, rule, your unit)
    envelope: str = ""  # "home" (its paper's tuning), "retuned", "outside", "unit"
    unbound: list = field(default_factory=list)  # slot values the unit does not receive (texts)
    unbound_items: list = field(default_factory=list)  # the same as scfmu.scenario.resolve.Unbound
    flags: list = field(default_factory=list)  # e.g. "error grew: …"
    rows: list = field(default_factory=list)  # the campaign rows of the runs that succeeded
    error0: float = math.nan  # main error at the start and at the end of the first run [deg] (if logged)
    error_end: float = math.nan
    est_runs: int = 0  # runs with the estimator in the loop (--estimator; the value is means[EST_KEY])
    est_ok: int = 0
    est_status: str = ""  # why the estimator column is empty or partial

    @property
    def passed(self) -> bool:
        return not self.status and self.runs > 0 and self.ok == self.runs and self.settled == self.runs


def _slug(text: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in text)[:80]


def error_series(series: dict | None):
    """The main error [deg] over a logged run: α, else the largest 321-angle (or θ) error from its
    reference (0 where no reference is logged); None when neither is logged."""
    if not series:
        return None
    if "alpha_deg" in series:
        return np.abs(np.asarray(series["alpha_deg"], dtype=float))
    ang = [a for a in ("roll", "pitch", "yaw") if a in series] or (["theta"] if "theta" in series else [])
    if not ang:
        return None
    errs = []
    for a in ang:
        d = np.asarray(series[a], dtype=float) - np.asarray(series.get(f"{a}_ref", 0.0), dtype=float)
        errs.append(np.degrees(np.abs((d + np.pi) % (2 * np.pi) - np.pi)))
    return np.max(np.vstack(errs), axis=0)


def _check_error_growth(e: Entry) -> None:
    err = error_series(e.series)
    if err is None or err.size < 2:
        return
    e.error0, e.error_end = float(err[0]), float(err[-1])
    if e.error_end > e.error0 + 1e-9:
        e.flags.append(f"error grew: {e.error0:.3g} deg at the start, {e.error_end:.3g} deg at the end")


# ----- comparisons ------------------------------------------------------------------------------------------
def ranks(cases, entries: list[Entry]) -> dict:
    """{case label: {controller: rank}} by the case's primary metric (lower is better) among the passing;
    values equal within the metric's resolution share a rank (competition ranking: 1, 2, 2, 4)."""
    out = {}
    for case in cases:
        es = [e for e in entries if e.case == case.label and e.passed and math.isfinite(e.means.get(case.primary, math.nan))]
        vals = [e.means[case.primary] for e in es]
        out[case.label] = {e.controller: 1 + sum(1 for v in vals if v < e.means[case.primary]
                                                 and not equal(v, e.means[case.primary], case.primary))
                           for e in es}
    return out


def identical_groups(case, entries: list[Entry]) -> list[list[str]]:
    """Groups (2 or more) of controllers on ``case`` whose responses are identical: the case's plotted signal
    and the main error (α, or the largest angle error) of the first run differ by at most
    :data:`RESPONSE_RESOLUTION` at every logged sample, and the primary metric is equal within its resolution."""
    es = [e for e in entries if e.case == case.label and e.series and case.signal in e.series]
    rel, ab = RESPONSE_RESOLUTION

    def same(a, b) -> bool:
        if a is None or b is None:
            return a is None and b is None
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        return a.shape == b.shape and bool(np.all(np.isfinite(a)) and np.all(np.isfinite(b))) and \
            float(np.max(np.abs(a - b))) <= rel * float(max(np.max(np.abs(a)), np.max(np.abs(b)))) + ab

    groups: list[list[Entry]] = []
    for e in es:
        for g in groups:
            r = g[0]
            if same(r.series[case.signal], e.series[case.signal]) and same(error_series(r.series), error_series(e.series)) \
                    and equal(r.means.get(case.primary, math.nan), e.means.get(case.primary, math.nan), case.primary):
                g.append(e)
                break
        else:
            groups.append([e])
    return [[x.controller for x in g] for g in groups if len(g) > 1]


def estimator_ranks(cases, entries: list[Entry]) -> dict:
    """{case label: {controller: rank}} by the primary metric with the estimator in the loop (``EST_KEY``),
    among the pairs that pass with truth and have a value with the estimator; ties as in :func:`ranks`."""
    out = {}
    for case in cases:
        es = [e for e in entries if e.case == case.label and e.passed and math.isfinite(e.means.get(EST_KEY, math.nan))]
        vals = [e.means[EST_KEY] for e in es]
        out[case.label] = {e.controller: 1 + sum(1 for v in vals if v < e.means[EST_KEY]
                                                 and not equal(v, e.means[EST_KEY], case.primary)) for e in es}
    return out
