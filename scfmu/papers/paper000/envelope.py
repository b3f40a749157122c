"""Paper 000's controllers on other papers' plants: the rule the benchmark states and applies.

Paper 000 designs every law per axis from the nominal inertia (PD, LQR, pole placement: ω_n = 1 rad/s,
ζ = 1 on I s²; the fuzzy laws scale that PD; MRAC and adaptive fuzzy adapt the inertia estimate). On
another plant the rule keeps that closed-loop design and takes the nominal inertia from the place (its slot
values inertia_xx/_yy/_zz); the laws use the diagonal only, so products of inertia are not used. Torque
limits of the plant are not part of the design (project choice; stated on the benchmark page)."""

from __future__ import annotations

HOME = ("paper000/*", "default", "sensing/default")
UNUSED = ("inertia_xy", "inertia_xz", "inertia_yz")


def retune(slot: dict, scenario) -> tuple[dict, str]:
    if not all(f"inertia_{a}" in slot for a in ("xx", "yy", "zz")):
        raise ValueError("the place gives no nominal inertia (inertia_xx, _yy, _zz)")
    i = ", ".join(f"{float(slot[f'inertia_{a}']):g}" for a in ("xx", "yy", "zz"))
    return {}, (f"paper 000's closed-loop design (ω_n = 1 rad/s, ζ = 1 per axis) on this plant's nominal inertia "
                f"diag({i}) kg·m² (the place's); torque limits not designed for")
