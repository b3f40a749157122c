"""The container FMU of each standard closed loop (fmus/loops/, written by scripts/build_fmus.sh through
`scfmu export loop`): valid for fmpy, and simulated as one FMU with ``fmpy.simulate_fmu`` and no start value set,
it reproduces the reference run of the scenario declaration. The container steps its nested FMUs with the
reference master's fixed-step Gauss–Seidel scheme in the same order; see each test for the expected
difference."""

from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from scfmu import scenario as scenarios
from scfmu.registry import REGISTRY
from scfmu.scenario import ssp

from scfmu.engines import run_reference

STANDARD = REGISTRY.exported_scenarios()

LOOP_DIR = Path(__file__).resolve().parents[1] / "fmus" / "loops"


def loop_file(name):
    p = LOOP_DIR / f"{ssp.file_stem(name)}.fmu"
    if not p.exists():
        pytest.fail(f"{p} missing: run scripts/build_fmus.sh")
    return p


@pytest.mark.parametrize("name", STANDARD)
def test_loop_fmu_validates_and_carries_the_scenario(name):
    p = loop_file(name)
    assert validate_fmu(str(p)) == []
    sc = scenarios.get(name)
    md = read_model_description(str(p))
    assert float(md.defaultExperiment.stopTime) == sc.stop_time
    assert float(md.defaultExperiment.stepSize) == sc.step
    start = {v.name: v.start for v in md.modelVariables}
    for c in sc.components:
        for k, v in c.params.items():
            assert float(start[f"{c.name}.{k}"]) == float(v), f"{c.name}.{k}"
    for q, v in sc.inputs.items():
        assert float(start[q]) == float(v), q


@pytest.mark.parametrize("name,t", [("default", 3.0), ("paper000/000-9L", 2.0), ("paper000/000-11L", 2.0),
                                    ("paper001/c", 0.5), ("wheel_fault", 5.0),
                                    ("paper003/T2FSMC/N", 2.0), ("paper003/SMC/N", 2.0),
                                    ("leo/nadir", 3.0), ("leo/sun-pointing", 3.0), ("leo/detumble", 20.0)])
def test_loop_fmu_in_simulate_fmu_is_bit_identical_to_reference(name, t):
    """Same fixed step, same Gauss–Seidel order (command, controller, plant, metrics) as the reference
    master, so the expected difference is zero: compared bit for bit at every communication point."""
    sc = scenarios.get(name, stop_time=t)
    ref = run_reference(sc)
    qualified = {k: q for k, q in sc.log.items()}
    res = simulate_fmu(str(loop_file(name)), stop_time=t, output=sorted(set(qualified.values())))
    np.testing.assert_allclose(res["time"], ref["time"], rtol=0, atol=1e-12)
    for k, q in qualified.items():
        np.testing.assert_array_equal(res[q], ref[k], err_msg=f"{name}: {k}")
    assert any(np.ptp(ref[k]) > 0 for k in qualified)


def test_loop_fmu_start_values_can_be_changed_by_qualified_name():
    """A changed gain in the loop FMU gives the same result as the same change in the declaration."""
    t = 2.0
    sc = scenarios.get("default", stop_time=t).with_overrides({"controller.wn": 0.8})
    ref = run_reference(sc)
    res = simulate_fmu(str(loop_file("default")), stop_time=t, start_values={"controller.wn": 0.8},
                       output=["plant.w_x", "metrics.alpha_deg"])
    np.testing.assert_array_equal(res["plant.w_x"], ref["w_x"])
    np.testing.assert_array_equal(res["metrics.alpha_deg"], ref["alpha_deg"])
