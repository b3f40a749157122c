#!/usr/bin/env bash
# Builds the FMUs (scripts/build_fmus.sh) and writes a wheel of the scfmu package into dist/ that carries
# them as package data (scfmu/fmus/<Model>.fmu), with the compiled engine's loop library
# (scfmu/engines/native_loop/bin/<platform>/): `pip install dist/scfmu-*.whl` then gives a machine
# without a Rust toolchain the FMUs, the scenarios and the `scfmu` command. The SSP files and loop FMUs
# are not shipped (they repeat the FMUs); `scfmu export ssp|loop` writes them from the installed package.
#
#   scripts/build_wheel.sh                  # set-up, build the FMUs, write dist/scfmu-<version>-py3-none-any.whl
#   scripts/build_wheel.sh --no-fmu-build   # package the FMUs already in fmus/ (the test suite uses this)
#   scripts/build_wheel.sh --out DIR        # write the wheel into DIR instead of dist/
set -euo pipefail
cd "$(dirname "$0")/.."
build_fmus=1
out=dist
while [ $# -gt 0 ]; do
    case "$1" in
        --no-fmu-build) build_fmus=0 ;;
        --out) out=$2; shift ;;
        *) echo "build_wheel: unknown option $1" >&2; exit 2 ;;
    esac
    shift
done
scripts/setup.sh
if [ "$build_fmus" = 1 ]; then
    scripts/build_fmus.sh
fi
shopt -s nullglob
fmus=(fmus/*.fmu)
if [ ${#fmus[@]} -eq 0 ]; then
    echo "build_wheel: no FMUs in fmus/ (run without --no-fmu-build)" >&2
    exit 1
fi
# Stage the package with the FMUs inside it, so that the source tree is never written to.
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
cp pyproject.toml README.md "$stage/"
tar --exclude='__pycache__' --exclude='*/tests' -cf - scfmu | tar -xf - -C "$stage"
mkdir -p "$stage/scfmu/fmus"
cp "${fmus[@]}" "$stage/scfmu/fmus/"
# The compiled engine's loop library (scfmu/engines/native_loop, built with the FMUs by cargo build --release
# at the root) as scfmu/engines/native_loop/bin/<platform>/; without it the wheel's campaigns use "native".
n_loop=0
for lib in linux64:target/release/libscfmu_native_loop.so \
           win64:target/win64/x86_64-win7-windows-gnu/release/scfmu_native_loop.dll; do
    if [ -f "${lib#*:}" ]; then
        mkdir -p "$stage/scfmu/engines/native_loop/bin/${lib%%:*}"
        cp "${lib#*:}" "$stage/scfmu/engines/native_loop/bin/${lib%%:*}/"
        n_loop=$((n_loop + 1))
    fi
done
[ "$n_loop" -gt 0 ] || echo "build_wheel: no compiled loop library in target/ (cargo build --release): not shipped" >&2
mkdir -p "$out"
.venv/bin/python -m build --wheel --no-isolation --outdir "$out" "$stage" >"$stage/build.log" 2>&1 ||
    { cat "$stage/build.log" >&2; exit 1; }
wheel=$(ls -t "$out"/scfmu-*.whl | head -n 1)
echo "build_wheel: wrote $wheel ($(du -h "$wheel" | cut -f1), ${#fmus[@]} FMUs, $n_loop compiled loop libraries)"
echo "$wheel"
