"""pytest configuration: the FMU tests drive the built FMUs in fmus/ through fmpy and the installed
scfmu package (scripts/setup.sh installs it, editable, into .venv)."""
