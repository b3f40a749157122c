"""A small satellite in its real environment (issue 43): a 6U CubeSat on a 500 km sun-synchronous orbit with
the environment family's ``Orbit`` (J2 + drag) and ``Environment`` (IGRF-14, sun, eclipse, atmosphere), the
plant's facet drag, solar-pressure, gravity-gradient and residual-dipole torques, reaction wheels with
magnetorquer momentum dumping, the sensors and the Mekf. Not a paper: a plug-in with the scenarios
``leo/detumble``, ``leo/sun-pointing``, ``leo/nadir`` (and ``leo/nadir-textbook``, the same loop in the
plant's textbook environment, the cost baseline) and the figure command."""

from __future__ import annotations


def register(reg) -> None:
    from . import scenarios
    reg.scenarios("leo", scenarios.build, scenarios.names, exported=scenarios.EXPORTED)
