"""Paper 004's feedback-linearising controller on other papers' plants: the rule the benchmark states.

The law cancels the nominal rigid-body dynamics with the nominal inertia and imposes q̈ = −k_q q − k_q̇ q̇
per axis (paper 004's gains k_q = 0.5 1/s², k_q̇ = 2 1/s); on another plant it keeps those gains and takes
the nominal inertia from the place (its slot values; products of inertia are not used). Project choice,
stated on the benchmark page."""

from __future__ import annotations

HOME = ("paper004/*",)
UNUSED = ("inertia_xy", "inertia_xz", "inertia_yz")


def retune(slot: dict, scenario) -> tuple[dict, str]:
    if not all(f"inertia_{a}" in slot for a in ("xx", "yy", "zz")):
        raise ValueError("the place gives no nominal inertia (inertia_xx, _yy, _zz)")
    i = ", ".join(f"{float(slot[f'inertia_{a}']):g}" for a in ("xx", "yy", "zz"))
    return {}, f"paper 004's gains (k_q = 0.5, k_q̇ = 2 per axis) on this plant's nominal inertia diag({i}) kg·m² (the place's)"
