#!/usr/bin/env bash
# Runs every test: Rust unit and integration tests, then the pytest suite that drives the built FMUs
# through fmpy. Sets up the toolchain check and the Python venv first; fails on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build_fmus.sh
cargo test --release --locked
.venv/bin/python -m pytest -q tests
