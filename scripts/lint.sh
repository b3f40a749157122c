#!/usr/bin/env bash
# The lint and format gates that scripts/test.sh runs before the tests (each fails the run):
#   cargo fmt --check      the Rust tree is rustfmt-formatted (rustfmt.toml: 120 columns)
#   cargo clippy -D warnings  every target of the workspace; allowances and their reasons in Cargo.toml's
#                          [workspace.lints.clippy] and at the top of src/fmi/mod.rs
#   ruff check             the Python package, tests (also those beside the families in src/models), benches,
#                          scripts and examples (rules in pyproject.toml)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo fmt --all --check
(cd examples/custom_controller && cargo fmt --check)
cargo clippy --release --locked --all-targets --workspace -- -D warnings
.venv/bin/ruff check scfmu tests benches scripts examples src
echo "lint: cargo fmt, clippy and ruff clean"
