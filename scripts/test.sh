#!/usr/bin/env bash
# Runs every test: the lint gates (scripts/lint.sh), Rust unit and integration tests, then the pytest suite that drives the built FMUs
# through fmpy, the papers' tests in their plug-in folders, the import-layer contract and the wheel test.
# Sets up everything first (system packages included) and builds every platform; fails on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh --all        # the venv, rustfmt/clippy, gcc, valgrind, the cross toolchains, Wine and qemu
scripts/build_fmus.sh --all   # every platform (cross builds cached in ~/.cache/scfmu/cross), reference results, SSP and loop files
scripts/lint.sh   # cargo fmt --check, cargo clippy -D warnings, ruff check
cargo test --release --locked
# free space where the tests write (a full disk shows up as odd failures: say it in the log first)
df -Ph "${TMPDIR:-/tmp}" . | awk 'NR > 1 {print "test.sh: " $4 " free on " $6 " (" $1 ")"}'
.venv/bin/python -m pytest -q -n 2 --dist loadfile   # two processes, a test file each (pytest-xdist); testpaths (pyproject.toml): tests/, the papers' own tests under scfmu/, the family tests under src/models/
