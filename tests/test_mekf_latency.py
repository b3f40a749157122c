"""The Mekf's star-tracker latency compensation (``st_latency``) in the loop: the sensing loop's star tracker
with its 0.1 s latency feeding the estimator of ``sensing+estimation/default`` (paper 000's large slew, 30 s,
gyro and filter at 0.01 s, star tracker every 0.2 s, sun sensor and magnetometer every 0.1 s).

Over the pointing phase (the last third), with the filter told the latency (``st_latency`` = 0.1 s):

* the time-averaged NIS per degree of freedom (every update of the phase: star tracker 3 dof, sun sensor and
  magnetometer 2 dof each) lies inside the 95 % band of chi2(dof)/dof (scipy.stats.chi2: independent);
* the RMS of the estimate's true attitude error (numpy quaternion algebra against the plant's q) is within
  2 σ, σ the RMS over the phase of the filter's own sqrt(tr P_att);
* the FMI 3.0 Mekf in the same loop gives bit-identical signals (one declaration, two FMI versions).

The same loop with ``st_latency`` = 0 (the quaternion taken as measured at its arrival) fails both bounds
(asserted: the checks can fail). The scenarios keep their latency-free star tracker (docs/sensing.md).
"""

from __future__ import annotations

import numpy as np
import pytest
from quat_oracle import estimate_error
from scipy.stats import chi2

from scfmu import scenario as scenarios
from scfmu.engines import simulate
from scfmu.fmu import fmu_path

LATENCY = 0.1


def _run(st_latency: float, fmi: int = 2) -> dict:
    sc = scenarios.get("sensing+estimation/default").with_overrides(
        {"star_tracker.latency": LATENCY, "estimator.st_latency": st_latency})
    if fmi == 3:  # the FMI 3.0 unit in the estimator's place, with the same parameters (a swap drops them)
        params = {f"estimator.{k}": v for k, v in sc.component("estimator").params.items()}
        sc = sc.with_models({"estimator": str(fmu_path("Mekf").parent / "fmi3" / "Mekf.fmu")}).with_overrides(params)
    return simulate(sc)


def _checks(r: dict) -> dict:
    t = r["time"]
    assert np.allclose(np.diff(t), 0.01)  # every filter sample is logged: its nis and nis_dim are all seen
    ph = t >= t[-1] * 2 / 3
    nis, dof = float(np.sum(r["nis"][ph])), int(np.sum(r["nis_dim"][ph]))
    lo, hi = chi2.ppf([0.025, 0.975], dof) / dof
    rms = float(np.sqrt(np.mean(estimate_error(r)[ph] ** 2)))
    sigma = float(np.sqrt(np.mean((r["p_att_x"] + r["p_att_y"] + r["p_att_z"])[ph])))
    return {"nis_dof": nis / dof, "dof": dof, "band": (float(lo), float(hi)), "rms_deg": np.degrees(rms),
            "sigma_deg": np.degrees(sigma), "nis_ok": lo <= nis / dof <= hi, "err_ok": rms <= 2 * sigma}


def _line(name: str, c: dict) -> str:
    return (f"{name}: NIS/dof {c['nis_dof']:.4f} over {c['dof']} dof (95 % band {c['band'][0]:.4f}..{c['band'][1]:.4f}), "
            f"RMS error {c['rms_deg']:.3e} deg, filter sigma {c['sigma_deg']:.3e} deg")


@pytest.fixture(scope="module")
def compensated() -> dict:
    return _run(LATENCY)


def test_compensated_latency_is_consistent(compensated):
    c = _checks(compensated)
    print("\n" + _line("st_latency 0.1 s", c))
    assert c["nis_ok"], c
    assert c["err_ok"], c
    assert np.all(compensated["nis_dim"][compensated["time"] > 0.5] >= 0)


def test_fmi3_unit_gives_the_same_run(compensated):
    r3 = _run(LATENCY, fmi=3)
    for k in ("q_est_w", "q_est_x", "q_est_y", "q_est_z", "p_att_x", "nis", "nis_dim", "q_w", "alpha_deg"):
        assert np.array_equal(r3[k], compensated[k]), k


def test_without_compensation_the_same_loop_fails_the_bounds():
    c = _checks(_run(0.0))
    print("\n" + _line("st_latency 0 (uncompensated)", c))
    assert not c["nis_ok"] and c["nis_dof"] > c["band"][1], c
    assert not c["err_ok"], c
