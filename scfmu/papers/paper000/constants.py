"""Paper 000 report: the thresholds of the verdict rules and the run groups, shared by the section and its figures."""

from __future__ import annotations

from . import scenarios

TITLE = "Design of an adaptive-fuzzy controller based on the EULERINT criterion for a satellite"

# ----- thresholds of the rules (stated in the report) ------------------------------------------------------
TOL_SMALL = 0.10      # C000-2: "about the same" = (max − min)/min of EULERINT over the small-command runs ≤ 10 %
TOL_IDENTICAL = 1e-6  # C000-3: "identical" = relative EULERINT difference ≤ 1e-6
TOL_ORDER = 0.005     # rankings: a ranks below b only if a < (1 − 0.5 %) b (closer values are a tie, e.g. the
                      # DCM reading equal to the quaternion law differs from it by integration round-off only)
EFFORT_RATIO = 1.5    # C000-6: "without much more effort than PD" = effort / effort(quaternion PD) ≤ 1.5

EI, EFF = "eulerint_deg_s", "effort_abs"
PD_VARIANTS = {"000-6": "PD quaternion", "000-4": "PD DCM", "000-2": "PD Euler"}
L_METHODS = {"000-6": "PD quat", "000-9L": "MRAC", "000-10L": "fuzzy PD", "000-11L": "adaptive fuzzy"}
L_RUNS = ["000-2", "000-4", "000-6", "000-7L", "000-8L", "000-9L", "000-10L", "000-11L"]
S_RUNS = ["000-1", "000-3", "000-5", "000-7S", "000-8S", "000-9S"]
ROBUST_CASES = {"R1": "R1: 10 N·m constant disturbance", "R2-1.2": "R2: inertia ×1.2",
                "R2-0.8": "R2: inertia ×0.8"}
ROBUST_CTRL = {"PD": "PD quat", "MRAC": "MRAC", "FuzzyPD": "fuzzy PD", "AdaptFuzzy": "adaptive fuzzy"}
DCM_READINGS = {0: "0: (M32, M13, M21), M = A(q)A(q_ref)ᵀ (as printed; default)",
                1: "1: vex((M − Mᵀ)/2) = sin α·n (= quaternion law)",
                2: "2: vex(M − Mᵀ) = 2 sin α·n",
                3: "3: −(M23, M31, M12) (error matrix A(q_ref)A(q)ᵀ)",
                4: "4: −(N32, N13, N21), N = A(q)ᵀA(q_ref) (attitude matrix body → inertial)",
                5: "5: (N23, N31, N12) (error matrix A(q_ref)ᵀA(q))"}


def _label(run_id: str) -> str:
    for r in scenarios.paper000_runs():
        if r.run_id == run_id:
            return f"{run_id} {r.label}"
    return run_id
