#!/usr/bin/env bash
# Runs every test: the lint gates (scripts/lint.sh), Rust unit and integration tests, then the pytest suite that drives the built FMUs
# through fmpy, the papers' tests in their plug-in folders, the import-layer contract and the wheel test.
# Sets up the toolchain check and the Python venv first; fails on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build_fmus.sh
scripts/lint.sh   # cargo fmt --check, cargo clippy -D warnings, ruff check
cargo test --release --locked
# free space where the tests write (a full disk shows up as odd failures: say it in the log first)
df -Ph "${TMPDIR:-/tmp}" . | awk 'NR > 1 {print "test.sh: " $4 " free on " $6 " (" $1 ")"}'
.venv/bin/python -m pytest -q   # testpaths (pyproject.toml): tests/, the papers' own tests under scfmu/, the family tests under src/models/
