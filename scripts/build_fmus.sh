#!/usr/bin/env bash
# Builds the workspace's default members in release mode (the FMUs' shared library src/cdylib, the
# packaging tool fmu-package and the compiled engine's loop scfmu/engines/native_loop), then packages
# with fmu-package exactly as a user's model crate is packaged: modelDescription/<Model>.xml,
# fmus/<Model>.fmu and the generated pages docs/models/*.md and docs/references.md. Then the
# scenario files for other tools: fmus/ssp/<scenario>.ssp (SSP 1.0) and fmus/loops/<scenario>.fmu (one
# container FMU per standard closed loop), after writing each FMU's reference results into it
# (extra/org.fmi-standard.fmi-ls-ref/, `scfmu verify --write`). The last three need the Python venv (scripts/setup.sh); without
# it they are skipped with a message. When the Windows cross toolchain is installed (scripts/setup.sh
# installs it), every FMU also carries binaries/win64/<Model>.dll (scripts/build_win64.sh); without it
# the FMUs carry linux64 only and this script says so. SCFMU_NO_WIN64=1 skips the Windows build.
# SCFMU_NO_SCENARIO_FILES=1 skips fmus/ssp and fmus/loops (scripts/build_wheel.sh: the wheel ships neither).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --locked
package_args=(--locked)
if [ "${SCFMU_NO_WIN64:-0}" = 1 ]; then
    echo "build_fmus: SCFMU_NO_WIN64=1: packaging linux64 binaries only (no binaries/win64)" >&2
elif scripts/build_win64.sh --check; then
    dll=$(scripts/build_win64.sh | tail -n 1)
    package_args+=(--add-lib "win64=$dll")
else
    package_args+=(--win64 no)
    echo "build_fmus: Windows cross toolchain not installed: packaging linux64 binaries only (no binaries/win64)" >&2
fi
# Linux aarch64 and macOS (x86_64 + arm64) cross builds (scripts/build_aarch64.sh, scripts/build_macos.sh;
# folders: docs/tools.md), each when its toolchain is installed (scripts/setup.sh), built once here and
# reused by the tests and the wheels. Each cross script also builds the Model Exchange wrapper of
# Co-Simulation faces (scfmu_me_cs, scfmu/engines/cs_face.py) for its platform where it compiles.
# SCFMU_NO_AARCH64=1 / SCFMU_NO_MACOS=1 skip them. A macOS build
# made on a Mac (SCFMU_DARWIN64_LIB) joins as darwin64 instead of the cross builds.
if [ "${SCFMU_NO_AARCH64:-0}" != 1 ] && scripts/build_aarch64.sh --check; then
    package_args+=(--add-lib "aarch64-linux=$(scripts/build_aarch64.sh | tail -n 1)")
else
    echo "build_fmus: no aarch64-linux binaries (SCFMU_NO_AARCH64=1 or cross toolchain not installed)" >&2
fi
if [ -n "${SCFMU_DARWIN64_LIB:-}" ]; then
    package_args+=(--add-lib "darwin64=$SCFMU_DARWIN64_LIB")
elif [ "${SCFMU_NO_MACOS:-0}" != 1 ] && scripts/build_macos.sh --check; then
    mac=$(scripts/build_macos.sh)
    package_args+=(--add-lib "$(grep '^x86_64-darwin=' <<<"$mac")" --add-lib "$(grep '^aarch64-darwin=' <<<"$mac")")
else
    echo "build_fmus: no macOS binaries (SCFMU_NO_MACOS=1 or cross toolchain not installed)" >&2
fi
./target/release/fmu-package "${package_args[@]}"
if [ -x .venv/bin/python ]; then
    # reference results inside every FMU (fmi-ls-ref; scfmu/verify): before the SSP and loop files copy them
    .venv/bin/scfmu verify --write fmus/*.fmu fmus/fmi3/*.fmu
    if [ "${SCFMU_NO_SCENARIO_FILES:-0}" = 1 ]; then
        echo "build_fmus: SCFMU_NO_SCENARIO_FILES=1: fmus/ssp and fmus/loops not written" >&2
    else
        .venv/bin/scfmu export ssp --out fmus/ssp
        .venv/bin/scfmu export loop --out fmus/loops
        .venv/bin/scfmu verify --write --no-inputs fmus/loops/*.fmu
    fi
else
    echo "build_fmus: no .venv (run scripts/setup.sh): no reference results, fmus/ssp and fmus/loops not written" >&2
fi
