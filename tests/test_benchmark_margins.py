"""Stability margins of a black-box loop (scfmu.benchmark.margins) against python-control's margins of the
closed-form loop: the quaternion PD on the linear small-angle plant, per axis
L(s) = (I_c/I) (wn² + 2 ζ wn s)/s² (k = wn² I_c, k_d = 2 ζ wn I_c with the controller's nominal inertia I_c),
sampled by the co-simulation at the communication step h (ZOH: python-control's c2d), alone, behind a
pure computation delay (SampleHold at period h with delay d: z^-d/h) and behind a 10 Hz flight computer
(SampleHold at 0.1 s: the loop is c2d(L, 0.1))."""

import copy
import math

import control
import numpy as np
import pytest

from scfmu.benchmark.margins import loop_margins
from scfmu.scenario import Component, get

WN, ZETA = 0.8, 0.7
INERTIA = {"x": 1000.0, "y": 500.0, "z": 700.0}  # the plant's (paper 000)
NOMINAL = {"x": 1200.0, "y": 500.0, "z": 560.0}  # the controller's: +20 %, exact, -20 %


def pd_loop():
    """The linear plant with the PD, at rest at the reference attitude 0 (the operating point)."""
    sc = get("paper000/000-5")
    sc = sc.with_overrides({"command.ref_euler321_roll": 0.0, "command.ref_euler321_pitch": 0.0,
                            "command.ref_euler321_yaw": 0.0, "controller.wn": WN, "controller.zeta": ZETA,
                            "plant.init_euler321_roll": 0.01, "plant.init_euler321_pitch": -0.01},
                           stop_time=20.0)
    c = sc.component("controller")
    c.slot = {f"inertia_{a}{a}": NOMINAL[a] for a in "xyz"}
    return sc


def with_hold(sc, period, delay):
    sc = copy.deepcopy(sc)
    names = [c.name for c in sc.components]
    sc.components.insert(names.index("plant"), Component("hold", "SampleHold", {"sample_period": period, "delay": delay}))
    sc.connections.update({**{f"hold.u_{i}": f"controller.torque_cmd_{a}" for i, a in enumerate("xyz", 1)},
                           **{f"plant.torque_cmd_{a}": f"hold.y_{i}" for i, a in enumerate("xyz", 1)}})
    sc.unconnected = [*sc.unconnected, "hold.u_*"]
    return sc


def reference(a, T, delay_steps=0):
    """python-control's margins of the closed form sampled at T (ZOH), times z^-delay_steps."""
    s = control.tf("s")
    L = (NOMINAL[a] / INERTIA[a]) * (WN**2 + 2 * ZETA * WN * s) / s**2
    Ld = control.c2d(L, T, "zoh") * control.tf([1], [1] + [0] * delay_steps, T)
    gm, pm, _, wpg, wpc, _ = control.stability_margins(Ld, returnall=True)
    (i,) = np.nonzero(np.asarray(wpc) > 0)[0][:1]
    # the phase crosses -180° at the Nyquist frequency (z = -1), where python-control's search stops: there
    # c2d(1/s²) = T²(z+1)/(2(z-1)²) vanishes and c2d(1/s) = T/(z-1) = -T/2, so without delay
    # L(-1) = -(I_c/I) 2 ζ wn T/2 (the delay z^-d multiplies it by (-1)^d); python-control evaluates Ld there
    at_nyquist = complex(Ld(-1.0))
    if delay_steps == 0:
        assert at_nyquist == pytest.approx(-(NOMINAL[a] / INERTIA[a]) * ZETA * WN * T, rel=1e-9)
    up = [g for g in gm if g > 1]
    if at_nyquist.real < 0:
        up.append(1 / abs(at_nyquist))
    return {"gm_db": 20 * math.log10(min(up)) if up else math.inf, "pm_deg": pm[i], "wc": wpc[i],
            "dm_s": math.radians(pm[i]) / wpc[i], "L": L}


@pytest.fixture(scope="module")
def plain():
    return loop_margins(pd_loop(), horizon=25.0)


def test_pd_linear_plant_against_python_control(plain):
    for m in plain:
        ref = reference(m.axis, 0.01)
        assert m.sample_time == pytest.approx(0.01)
        assert m.pm_deg == pytest.approx(ref["pm_deg"], rel=1e-5), m.axis
        assert m.wc == pytest.approx(ref["wc"], rel=1e-5), m.axis
        assert m.dm_s == pytest.approx(ref["dm_s"], rel=1e-5), m.axis
        assert m.gm_db == pytest.approx(ref["gm_db"], rel=1e-4), m.axis
        # and the continuous closed form: the same crossover, the phase less the ZOH's half-sample lag
        gm, pm, _, _, wc, _ = control.stability_margins(ref["L"])
        assert m.wc == pytest.approx(wc, rel=1e-3)
        assert m.pm_deg == pytest.approx(pm - math.degrees(wc * 0.01 / 2), abs=0.01)


def test_pure_delay_within_two_percent(plain):
    d = 0.05
    held = loop_margins(with_hold(pd_loop(), 0.01, d), horizon=25.0)
    for m, m0 in zip(held, plain):
        ref = reference(m.axis, 0.01, delay_steps=5)
        assert m.dm_s == pytest.approx(ref["dm_s"], rel=0.02), m.axis
        assert m0.dm_s - m.dm_s == pytest.approx(d, rel=0.02), m.axis  # a pure delay d takes d off the margin
        assert m.pm_deg == pytest.approx(ref["pm_deg"], rel=1e-4)


def test_sampled_flight_computer():
    held = loop_margins(with_hold(pd_loop(), 0.1, 0.0), horizon=25.0)
    for m in held:
        ref = reference(m.axis, 0.1)
        assert m.sample_time == pytest.approx(0.1)
        assert m.pm_deg == pytest.approx(ref["pm_deg"], rel=1e-4), m.axis
        assert m.wc == pytest.approx(ref["wc"], rel=1e-4), m.axis
        assert m.gm_db == pytest.approx(ref["gm_db"], rel=1e-3), m.axis


def test_benchmark_page_margins_effort_pointing(tmp_path):
    """End to end (--quick, the large slew, PD and LQR): the page's margins of the PD at the slew's final
    attitude equal python-control's on the closed form (body-frame quaternion error, rest: decoupled axes,
    L = (1 + 2s)/s² for wn = ζ = 1, sampled at 0.01 s); the Monte Carlo and pointing columns are filled."""
    import csv

    from scfmu import benchmark

    benchmark.run(None, "attitude", tmp_path, quick=True, controllers=["PdController", "LqrController"],
                  cases=["default"], log=lambda *a: None)
    s = control.tf("s")
    _, pm, _, _, wc, _ = control.stability_margins(control.c2d((1 + 2 * s) / s**2, 0.01, "zoh"))
    rows = list(csv.DictReader(open(tmp_path / "margins.csv")))
    pd_rows = [r for r in rows if r["controller"].startswith("PD")]
    assert len(pd_rows) == 3
    for r in pd_rows:
        assert float(r["pm_deg"]) == pytest.approx(pm, rel=1e-4)
        assert float(r["crossover_rad_s"]) == pytest.approx(wc, rel=1e-4)
        assert float(r["delay_margin_s"]) == pytest.approx(math.radians(pm) / wc, rel=1e-4)
    eng = list(csv.DictReader(open(tmp_path / "engineering.csv")))
    assert eng and all(math.isfinite(float(r["ape_deg"])) and float(r["ape_deg"]) < 0.01 for r in eng)
    rob = list(csv.DictReader(open(tmp_path / "robustness.csv")))
    assert {r["controller"] for r in rob} == {r["controller"] for r in eng}
    assert all(float(r["pass_fraction"]) == 1.0 and int(r["runs"]) == 8 for r in rob)
    page = (tmp_path / "benchmark.md").read_text()
    assert "### Stability margins" in page and "### Robustness Monte Carlo" in page
    assert (tmp_path / "figures").glob("bode_*.png") and list((tmp_path / "figures").glob("effort_*.png"))
