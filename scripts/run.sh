#!/usr/bin/env bash
# Builds every FMU and runs the default scenario (paper 000 large-angle command, quaternion PD):
# prints EULERINT, settling time and control effort, writes out/default/default.{csv,png}.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build_fmus.sh
.venv/bin/scfmu run default "$@"
