#!/usr/bin/env bash
# Builds this crate and packages every model it exports as fmus/<Model>.fmu (modelDescription.xml and
# documentation/index.html generated from the declarations, binaries/linux64 and, when the Windows cross
# toolchain of scripts/setup.sh is installed, binaries/win64). Uses the project's packaging tool
# fmu-package; SPACECRAFT_FMUS points at the project (default: two folders up, where this template lives).
#
#   ./build.sh                 build, package, write fmus/
#   ./build.sh --win64 no      linux64 only (also SCFMU_NO_WIN64=1)
#   ./build.sh --xml md        also write md/<Model>.xml (commit it, and check it with --check)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
project="${SPACECRAFT_FMUS:-$here/../..}"
cargo run --quiet --release --locked --manifest-path "$project/Cargo.toml" -p spacecraft_fmus_package --bin fmu-package -- \
    --crate "$here" --out "$here/fmus" "$@"
