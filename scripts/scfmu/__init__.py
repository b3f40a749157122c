"""Python side of spacecraft_fmus: a fixed-step FMI 2.0 co-simulation master (fmpy) that wires FMUs
by port name, plus metrics shared by the experiment scripts and the tests."""

from .master import Fmu, CoSimulation, FMU_DIR, fmu_path  # noqa: F401
