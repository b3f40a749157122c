"""The benchmark's "with estimator" column (``scfmu benchmark --estimator``): every pair that ran is run
again on its scenario's estimator-in-the-loop variant — the same controller, configuration, override sets
and seeds, with gyro, star tracker, sun sensor, magnetometer, the on-board ephemeris and the ``Mekf``
between the plant and the controller and a 10 Hz flight computer
(:func:`scfmu.scenario.templates.with_estimation`, the scenarios ``sensing+estimation/<name>``) — and the
case's primary metric (mean over the runs, all of which must succeed) is shown beside the truth-fed value
with its rank among the controllers. It doubles the benchmark's runs, hence a flag.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .. import campaign
from ..scenario.templates import with_estimation
from .common import EST_KEY, Entry, _slug


def prepare(e: Entry, case, sc, c, out: Path):
    """The job (entry, case, estimator scenario, campaign, folder) of a pair that ran, or None when its
    scenario takes no estimator (``e.est_status`` says why)."""
    try:
        est = with_estimation(sc)
    except KeyError as err:
        e.est_status = "no estimator variant: " + str(err.args[0] if err.args else err)
        e.means[EST_KEY] = math.nan
        return None
    ce = campaign.Campaign(est, c.overrides, c.seeds, engine=c.engine)
    return e, case, est, ce, Path(out) / "runs_estimator" / _slug(case.label) / _slug(e.controller)


def run_pair(client, log, e: Entry, case, sc, c, folder: Path) -> None:
    rows = campaign.run(c, folder, client=client, progress=False, overwrite=True).to_pylist()
    good = [r for r in rows if r["status"] == "ok"]
    v = np.array([r.get(case.primary, math.nan) for r in good], dtype=float)
    e.est_runs, e.est_ok = len(rows), len(good)
    e.means[EST_KEY] = float(np.mean(v)) if v.size and len(good) == len(rows) and np.all(np.isfinite(v)) else math.nan
    if len(good) < len(rows):
        e.est_status = f"{len(rows) - len(good)} of {len(rows)} runs with the estimator failed: " + \
            next(f"{r['status']}: {r['message'][:160]}" for r in rows if r["status"] != "ok")
    log(f"  {case.label} / {e.controller} with estimator: {e.est_ok}/{e.est_runs} ok, {case.primary} = "
        f"{e.means[EST_KEY]:.6g}")
