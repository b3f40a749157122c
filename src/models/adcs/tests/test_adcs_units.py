"""The packaged ``ModeManager``, ``EstimateGate`` and ``CommandSwitch`` (src/models/adcs) through fmpy, FMI 2.0 and 3.0.

``ModeManager`` is driven through a scripted mission with a communication step of 0.25 s (its sample period
is 1 s): the body rate decays as 0.05 exp(-t/20) rad/s, the sun appears at t = 50 s and its angle from the
sun axis falls by 0.01 rad/s from 0.6 rad, the attitude sigma falls as 0.05 exp(-(t - 93)/8) rad once the
estimator runs, the NIS per dimension is 10 before that and 0.5 after, and the actuator fault flag rises
at t = 130.3 s. The transition times are computed here by hand from the thresholds (the first sample
instant k T at which each condition holds, after the dwell):

* DETUMBLE -> SUN_ACQUISITION: 0.05 exp(-k/20) < 0.00873 first at k = ceil(20 ln(0.05/0.00873)) = 35 (> 10 s dwell);
* SUN_ACQUISITION -> DETERMINATION: 0.6 - 0.01 (k - 50) < 0.1745 first at k = 93 (the rate is below too);
* DETERMINATION -> FINE_POINTING: 0.05 exp(-(k - 93)/8) < 0.00873 first at k = 93 + 14 = 107 (dwell 10 s met;
  the NIS average restarted at the entry, so it is 0.5 < 3: without the restart it would be
  0.5 + 9.5 exp(-14/30) = 6.5 here, and below 3 only 41 updates after the entry, at 134 s);
* FINE_POINTING -> SAFE: the flag is up from the sample 131 and confirmed after fault_confirm_time = 2 s: 133.

The switches are checked against their selection tables, and in the loop against the manager's outputs.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from fmu_state_replay import replay_three_ways
from scfmu.fmu import Fmu, fmu_path

AX = "xyz"
QN = "wxyz"
H = 0.25
T_END = 150.0
PARAMS = {"fault_confirm_time": 2.0}
SAFE, DETUMBLE, SUN_ACQ, DETERMINATION, FINE = range(5)


def fmu_file(model: str, fmi: int):
    p = fmu_path(model)
    return p if fmi == 2 else p.parent / "fmi3" / p.name


def script(t: float) -> dict:
    """The inputs of the scripted mission at time t."""
    rate = 0.05 * math.exp(-t / 20)
    w = np.array([2.0, -1.0, 2.0]) / 3 * rate
    ang = 0.6 - 0.01 * (t - 50) if t >= 50 else 0.6
    sigma = 0.05 * math.exp(-(t - 93) / 8) if t >= 93 else 0.05
    out = {f"w_meas_{a}": w[i] for i, a in enumerate(AX)}
    out |= {"sun_meas_x": 2 * math.cos(ang), "sun_meas_y": 2 * math.sin(ang), "sun_meas_z": 0.0}
    out |= {"sun_valid": 1.0 if t >= 50 else 0.0, "nis": 30.0 if t <= 93 else 1.5}
    out |= {"p_att_x": sigma**2 / 2, "p_att_y": sigma**2, "p_att_z": sigma**2 / 4}
    out |= {"actuator_fault": 1.0 if t >= 130.3 else 0.0}
    return out


def hand_times() -> dict:
    """The transition sample times from the thresholds (the module docstring)."""
    t_det = max(math.ceil(20 * math.log(0.05 / 0.00873)), 10)
    t_sun = 50 + math.floor((0.6 - 0.1745) / 0.01) + 1
    t_fine = t_sun + max(math.ceil(8 * math.log(0.05 / 0.00873)), 10)
    t_safe = math.ceil(130.3) + 2
    return {(DETUMBLE, SUN_ACQ): t_det, (SUN_ACQ, DETERMINATION): t_sun, (DETERMINATION, FINE): t_fine,
            (FINE, SAFE): t_safe}


OUTS = ["time_in_mode", "torque_select", "dipole_select", "estimator_init", "controller_enable", "rate",
        "sigma_att", "nis_avg", "sun_angle"]


def mission(f: Fmu, k0: int, k1: int, loop: tuple | None = None) -> list[tuple]:
    """Communication points k0..k1-1: set the script's inputs, read the outputs (mode first), step. With
    `loop` = (switch, gate) the manager's selections go to a CommandSwitch and an EstimateGate."""
    rows = []
    for k in range(k0, k1):
        t = k * H
        u = script(t)
        f.set_reals(list(u), list(u.values()))
        f.set("nis_dim", 3)
        row = (t, f.get("mode"), f.get("mode_changes"), f.get("last_reason"), *f.get_reals(OUTS))
        if loop:
            sw, gate = loop
            sw.set_reals(["torque_select", "dipole_select"], row[5:7])
            gate.set_reals(["enable"], [row[8]])
            row += (*sw.get_reals([f"torque_cmd_{a}" for a in AX] + [f"m_cmd_{a}" for a in AX]),
                    *gate.get_reals([f"q_{c}" for c in QN]))
            sw.do_step(t, H)
            gate.do_step(t, H)
        rows.append(row)
        f.do_step(t, H)
    return rows


def transitions(rows) -> list[tuple]:
    return [(r[0], p[1], r[1]) for p, r in zip(rows, rows[1:]) if r[1] != p[1]]


@pytest.mark.parametrize("fmi", [2, 3])
def test_mode_sequence_and_transition_times_match_the_hand_computed_samples(fmi):
    f = Fmu("ModeManager", PARAMS, path=fmu_file("ModeManager", fmi), logging_on=True)
    try:
        rows = mission(f, 0, int(T_END / H))
    finally:
        f.close()
    want = [(float(t), a, b) for (a, b), t in hand_times().items()]
    assert transitions(rows) == want == [(35.0, 1, 2), (93.0, 2, 3), (107.0, 3, 4), (133.0, 4, 0)]
    assert rows[0][1] == DETUMBLE and rows[-1][1:4] == (SAFE, 4, 1)  # 4 changes, the last for FAULT (1)
    at = {r[0]: r for r in rows}
    # the selection table in each phase: (torque_select, dipole_select, estimator_init, controller_enable)
    for t, sel in [(20.0, (0, 1, 0, 0)), (60.0, (1, 0, 0, 0)), (93.0, (1, 0, 1, 0)), (93.75, (1, 0, 1, 0)),
                   (94.0, (1, 0, 0, 0)), (120.0, (2, 0, 0, 1)), (140.0, (1, 0, 0, 0))]:
        assert at[t][5:9] == sel, (t, at[t][5:9])
    # diagnostics held from the last sample: time in mode, rate, sigma, NIS average, sun angle
    r = at[100.5]
    assert r[4] == 7.0 and r[3] == 9  # 7 s after the entry at 93; the last change was SUN_ACQUIRED (9)
    assert math.isclose(r[9], 0.05 * math.exp(-5), rel_tol=1e-12)
    assert math.isclose(r[10], 0.05 * math.exp(-7 / 8), rel_tol=1e-12)
    assert r[11] == 0.5 and math.isclose(r[12], 0.6 - 0.5, rel_tol=1e-9)
    events = [m[2] for m in f.messages if m[1] == "logEvents"]
    assert [re.search(r"t = \d+ s: \w+ -> \w+", e).group(0) for e in events] == [
        "t = 35 s: DETUMBLE -> SUN_ACQUISITION", "t = 93 s: SUN_ACQUISITION -> DETERMINATION",
        "t = 107 s: DETERMINATION -> FINE_POINTING", "t = 133 s: FINE_POINTING -> SAFE"], events
    assert "rate 0.008689 rad/s < rate_detumbled 0.00873; DETUMBLED" in events[0], events[0]
    assert "held 2 s >= fault_confirm_time 2 s; FAULT" in events[3], events[3]
    print(f"\nModeManager FMI {fmi}: transitions {transitions(rows)}; log:\n  " + "\n  ".join(events))


@pytest.mark.parametrize("fmi", [2, 3])
def test_the_switches_follow_the_manager_in_the_loop(fmi):
    f = Fmu("ModeManager", PARAMS, path=fmu_file("ModeManager", fmi))
    sw = Fmu("CommandSwitch", path=fmu_file("CommandSwitch", fmi))
    gate = Fmu("EstimateGate", path=fmu_file("EstimateGate", fmi))
    try:
        sw.set_reals([f"{n}_{a}" for n in ("torque_safe", "torque_fine", "m_bdot") for a in AX], range(1, 10))
        gate.set_reals([f"q_est_{c}" for c in QN] + [f"q_ref_{c}" for c in QN], [0, 0, 0, 2, 0, 3, 0, 0])
        rows = mission(f, 0, int(T_END / H), loop=(sw, gate))
    finally:
        for u in (f, sw, gate):
            u.close()
    want = {DETUMBLE: ((0, 0, 0), (7, 8, 9)), SUN_ACQ: ((1, 2, 3), (0, 0, 0)), DETERMINATION: ((1, 2, 3), (0, 0, 0)),
            FINE: ((4, 5, 6), (0, 0, 0)), SAFE: ((1, 2, 3), (0, 0, 0))}
    for r in rows:
        torque, m, q = r[13:16], r[16:19], r[19:23]
        assert (torque, m) == want[r[1]], r
        assert q == ((0, 0, 0, 1) if r[1] == FINE else (0, 1, 0, 0)), r  # q_est/|q_est| only in FINE_POINTING
    assert {r[1] for r in rows} == {0, 1, 2, 3, 4}


@pytest.mark.parametrize("fmi", [2, 3])
def test_fmu_state_restores_mid_mission_bit_for_bit(fmi):
    f = Fmu("ModeManager", PARAMS, path=fmu_file("ModeManager", fmi))
    try:
        mission(f, 0, 400)  # t = 100 s, in DETERMINATION with a NIS average running
        a, b, c, _ = replay_three_ways(f, fmi, lambda: mission(f, 400, 600))
    finally:
        f.close()
    assert a == b == c and transitions([(0, DETERMINATION)] + a) == [(107.0, 3, 4), (133.0, 4, 0)]


def test_the_value_references_are_the_agreed_ones():
    """Other units are written against these names and value references (issue 44)."""
    agreed = {
        "ModeManager": {"w_meas_x": 0, "sun_valid": 3, "sun_meas_x": 4, "p_att_x": 7, "nis": 10, "nis_dim": 11,
                        "actuator_fault": 12, "recover": 13, "safe_request": 14, "mode": 20, "time_in_mode": 21,
                        "mode_changes": 22, "torque_select": 23, "dipole_select": 24, "estimator_init": 25,
                        "controller_enable": 26, "rate": 30, "sigma_att": 31, "nis_avg": 32, "sun_angle": 33,
                        "last_reason": 34, "sample_period": 100, "rate_detumbled": 101, "rate_tumbling": 102,
                        "rate_safe": 103, "sun_angle_acquired": 104, "sun_angle_lost": 105, "sun_axis_x": 106,
                        "sigma_converged": 109, "sigma_diverged": 110, "nis_max": 111, "nis_diverged": 112,
                        "nis_time_constant": 113, "min_dwell": 114, "fault_confirm_time": 115,
                        "recover_time": 116, "init_duration": 117, "initial_mode": 120, "safe_on_divergence": 121},
        "EstimateGate": {"q_est_w": 0, "w_est_x": 4, "q_ref_w": 7, "w_ref_x": 11, "enable": 14, "q_w": 20, "w_x": 24},
        "CommandSwitch": {"torque_safe_x": 0, "torque_fine_x": 3, "m_bdot_x": 6, "torque_select": 9,
                          "dipole_select": 10, "torque_cmd_x": 20, "m_cmd_x": 23},
    }
    for model, vrs in agreed.items():
        for fmi in (2, 3):
            f = Fmu(model, path=fmu_file(model, fmi), initialize=False)
            try:
                assert {n: f.var(n).valueReference for n in vrs} == vrs, (model, fmi)
            finally:
                f.close()


@pytest.mark.parametrize("fmi", [2, 3])
def test_the_switches_select_by_code_and_refuse_other_values(fmi):
    sw = Fmu("CommandSwitch", path=fmu_file("CommandSwitch", fmi), logging_on=True)
    gate = Fmu("EstimateGate", path=fmu_file("EstimateGate", fmi), logging_on=True)
    try:
        sw.set_reals([f"{n}_{a}" for n in ("torque_safe", "torque_fine", "m_bdot") for a in AX],
                     [0.1, 0.2, 0.3, -1, -2, -3, 5, 6, 7])
        names = [f"torque_cmd_{a}" for a in AX] + [f"m_cmd_{a}" for a in AX]
        for ts, ds, want in [(0, 0, [0] * 6), (1, 0, [0.1, 0.2, 0.3, 0, 0, 0]), (2, 1, [-1, -2, -3, 5, 6, 7]),
                             (0.8, 1.2, [0.1, 0.2, 0.3, 5, 6, 7]), (2.25, -0.2, [-1, -2, -3, 0, 0, 0])]:
            sw.set_reals(["torque_select", "dipole_select"], [ts, ds])
            assert sw.get_reals(names) == want, (ts, ds)
        sw.set_reals(["torque_select"], [1.5])
        with pytest.raises(Exception) as e:
            sw.get_reals(names)
        assert "torque_select = 1.5" in str(e.value) or any("torque_select = 1.5" in m[2] for m in sw.messages)
        assert any("0 (zero), 1 (torque_safe), 2 (torque_fine)" in m[2] for m in sw.messages), sw.messages[-3:]
        # the gate: the reference (normalised) when disabled, the estimate (normalised) when enabled
        gate.set_reals([f"q_est_{c}" for c in QN] + [f"w_est_{a}" for a in AX] + [f"q_ref_{c}" for c in QN]
                       + [f"w_ref_{a}" for a in AX], [1, 1, 1, 1, 0.1, 0.2, 0.3, 0, 0, 0, -4, 0, -1e-3, 0])
        out = [f"q_{c}" for c in QN] + [f"w_{a}" for a in AX]
        for enable, want in [(0.0, [0, 0, 0, -1, 0, -1e-3, 0]), (0.5, [0.5, 0.5, 0.5, 0.5, 0.1, 0.2, 0.3])]:
            gate.set_reals(["enable"], [enable])
            assert gate.get_reals(out) == want, enable
        gate.set_reals([f"q_ref_{c}" for c in QN], [0, 0, 0, 0])
        with pytest.raises(Exception):
            gate.get_reals(out)
        assert any("q_ref" in m[2] and "norm 0" in m[2] for m in gate.messages), gate.messages[-3:]
    finally:
        sw.close()
        gate.close()


def test_bad_parameters_and_inputs_of_the_manager_are_refused_by_name():
    for bad, names in [({"rate_detumbled": 0.05}, ("rate_detumbled", "rate_tumbling")),
                       ({"nis_max": 20.0}, ("nis_max", "nis_diverged")), ({"initial_mode": 7}, ("initial_mode",)),
                       ({"sun_axis_x": 0.0}, ("sun_axis",))]:
        with pytest.raises(Exception) as e:
            Fmu("ModeManager", bad, logging_on=True)
        assert all(n in str(e.value) for n in names), (bad, str(e.value))
    f = Fmu("ModeManager", {}, logging_on=True)
    try:
        f.set_reals(["p_att_y"], [-1e-6])
        with pytest.raises(Exception) as e:
            f.do_step(0.0, H)
        assert "p_att" in str(e.value), str(e.value)
    finally:
        f.close()
