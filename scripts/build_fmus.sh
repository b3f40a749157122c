#!/usr/bin/env bash
# Builds the release cdylib and writes modelDescription/<Model>.xml and fmus/<Model>.fmu.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --locked
./target/release/package
