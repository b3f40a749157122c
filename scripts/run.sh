#!/usr/bin/env bash
# The first result: sets up what this machine needs and runs the default scenario (paper 000's large-angle
# slew, quaternion PD): prints EULERINT, settling times and control effort, writes out/default/default.{csv,png}.
# Builds for this machine only: the FMUs' library and the packager (cargo), the Python venv with what `scfmu run`
# needs (scripts/setup.sh --run-only: requirements-run.txt; in parallel with the build), then `scfmu run default`. Nothing else: no system package, no cross build, no reference results,
# SSP files or loop FMUs — those come with scripts/test.sh, scripts/build_fmus.sh --all (or --platform P,
# --reference-results, --scenario-files), scripts/build_wheel.sh --platform P and scfmu export ssp|loop.
# Arguments go to `scfmu run`: a scenario name and options, or options alone for the default scenario
# (scripts/run.sh --set controller.wn=2).
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
log=$(mktemp)
trap 'rm -f "$log"' EXIT
scripts/setup.sh --run-only >"$log" 2>&1 &
setup_pid=$!
scripts/build_fmus.sh --fmus-only
if ! wait "$setup_pid"; then
    cat "$log" >&2
    echo "run: scripts/setup.sh failed (messages above)" >&2
    exit 1
fi
cat "$log"
echo "run: set-up and build in $(( $(date +%s) - start )) s; skipped: cross builds, reference results, SSP files and loop FMUs (scripts/build_fmus.sh --all)" >&2
case "${1:-}" in
    "" | -*) set -- default "$@" ;;  # options alone: the default scenario with them
esac
.venv/bin/scfmu run "$@"
