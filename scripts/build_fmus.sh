#!/usr/bin/env bash
# Builds the release cdylib and writes modelDescription/<Model>.xml and fmus/<Model>.fmu, then the
# scenario files for other tools: fmus/ssp/<scenario>.ssp (SSP 1.0) and fmus/loops/<scenario>.fmu (one
# container FMU per standard closed loop). The last two need the Python venv (scripts/setup.sh); without
# it they are skipped with a message.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --locked
./target/release/package
if [ -x .venv/bin/python ]; then
    PYTHONPATH=scripts .venv/bin/python -m scfmu.ssp --out fmus/ssp
    PYTHONPATH=scripts .venv/bin/python -m scfmu.loops --out fmus/loops
else
    echo "build_fmus: no .venv (run scripts/setup.sh): fmus/ssp and fmus/loops not written" >&2
fi
