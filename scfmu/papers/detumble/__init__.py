"""Detumbling (issue 37): a small satellite released with a tip-off rate of 5 deg/s per axis, slowed down by
its magnetorquers under the B-dot law — AttitudePlant → Magnetometer → BDot → AttitudePlant (dipole command
``m_cmd``). Not a paper: a plug-in with the scenarios and the figure command."""

from __future__ import annotations


def register(reg) -> None:
    from . import scenarios
    reg.scenarios("detumble", scenarios.build, scenarios.names)
