#!/usr/bin/env bash
# Builds the FMUs: the workspace's libraries in release mode for this machine, then packaging with
# fmu-package exactly as a user's model crate is packaged: modelDescription/<Model>.xml, fmus/<Model>.fmu
# (FMI 2.0), fmus/fmi3/<Model>.fmu (FMI 3.0) and the generated pages docs/models/*.md and docs/references.md.
# Without options it builds for this machine only (what a run needs); the other platforms' binaries, the
# reference results inside the FMUs and the scenario files for other tools are asked for by name:
#
#   scripts/build_fmus.sh                     host build: the FMUs' library, the packager, the compiled
#                                             engine's loop (scfmu/engines/native_loop) and the Model Exchange
#                                             wrapper of Co-Simulation faces (scfmu/engines/me_cs); FMUs with
#                                             this machine's binary only
#   scripts/build_fmus.sh --fmus-only         only the FMUs' library and the packager (scripts/run.sh)
#   scripts/build_fmus.sh --platform P        also the cross build of platform P (repeatable): win-amd64,
#                                             linux-aarch64, macos (both macOS CPUs: one universal file),
#                                             or all (every platform whose cross toolchain is installed)
#   scripts/build_fmus.sh --all-platforms     the same as --platform all
#   scripts/build_fmus.sh --reference-results write each FMU's reference results into it
#                                             (extra/org.fmi-standard.fmi-ls-ref/, `scfmu verify --write`)
#   scripts/build_fmus.sh --scenario-files    also fmus/ssp/<scenario>.ssp (SSP 1.0) and fmus/loops/<scenario>.fmu
#                                             (one container FMU per standard closed loop), with every platform
#                                             the FMUs carry (implies --reference-results: the files copy them)
#   scripts/build_fmus.sh --all               all of the above (scripts/test.sh)
#
# A cross build needs its toolchain (`scripts/setup.sh --cross` installs them): asked for by name
# (--platform win-amd64) and missing, the build stops and says so; under --platform all a missing toolchain
# is skipped with a message. SCFMU_NO_WIN64=1, SCFMU_NO_AARCH64=1, SCFMU_NO_MACOS=1 skip a platform even when
# asked; a macOS build made on a Mac (SCFMU_DARWIN64_LIB=<universal dylib>) joins as darwin64 instead of the
# cross builds. The cross builds keep their compiled standard library and dependencies in
# ~/.cache/scfmu/cross (scripts/cross_cache.sh), so they are compiled once per machine.
set -euo pipefail
cd "$(dirname "$0")/.."
engines=1
refs=0
scenario_files=0
want=()
while [ $# -gt 0 ]; do
    case "$1" in
        --fmus-only) engines=0 ;;
        --platform)
            p=${2:-}
            case "$p" in
                win-amd64 | linux-aarch64 | macos | all) want+=("$p") ;;
                linux-x86_64) ;;  # the host build
                macos-x86_64 | macos-arm64) want+=(macos) ;;
                *) echo "build_fmus: --platform takes win-amd64, linux-aarch64, macos or all, not '$p'" >&2; exit 2 ;;
            esac
            shift ;;
        --all-platforms) want+=(all) ;;
        --reference-results) refs=1 ;;
        --scenario-files) refs=1; scenario_files=1 ;;
        --all) want+=(all); refs=1; scenario_files=1 ;;
        *) echo "build_fmus: unknown option '$1' (allowed: --fmus-only, --platform P, --all-platforms," \
                "--reference-results, --scenario-files, --all)" >&2; exit 2 ;;
    esac
    shift
done
wanted() {  # wanted PLATFORM: 0 = asked by name, 1 = asked through "all", 2 = not asked
    case " ${want[*]:-} " in *" $1 "*) return 0 ;; esac
    case " ${want[*]:-} " in *" all "*) return 1 ;; esac
    return 2
}
start=$(date +%s)
if [ "$engines" = 1 ]; then
    cargo build --release --locked
else
    cargo build --release --locked -p spacecraft_fmus_cdylib -p spacecraft_fmus_package
fi
# the library just built, given to fmu-package (--crate with --lib): a cargo run of its own on src/cdylib alone
# would unify the dependencies' features differently and compile the library a second time
host_lib=$(ls target/release/libspacecraft_fmus_cdylib.so target/release/libspacecraft_fmus_cdylib.dylib 2>/dev/null || true)
package_args=(--locked --crate src/cdylib --lib "$host_lib" --win64 no)
skipped=()
# cross_build NAME SKIP_VAR SCRIPT: 0 = built (its output in $cross_out), 1 = not built
cross_build() {
    local name=$1 skip=$2 script=$3 how
    wanted "$name" && how=named || { [ $? = 1 ] && how=all || return 1; }
    if [ "${!skip:-0}" = 1 ]; then
        echo "build_fmus: $skip=1: no $name binaries" >&2
        return 1
    fi
    if ! "$script" --check; then
        if [ "$how" = named ]; then
            echo "build_fmus: --platform $name asked for, but its cross toolchain is missing (scripts/setup.sh --cross installs it)" >&2
            exit 2
        fi
        skipped+=("$name (toolchain not installed: scripts/setup.sh --cross)")
        return 1
    fi
    cross_out=$("$script") || { echo "build_fmus: the $name cross build failed (messages above)" >&2; exit 1; }
}
if cross_build win-amd64 SCFMU_NO_WIN64 scripts/build_win64.sh; then
    package_args+=(--add-lib "win64=$(tail -n 1 <<<"$cross_out")")
fi
if cross_build linux-aarch64 SCFMU_NO_AARCH64 scripts/build_aarch64.sh; then
    package_args+=(--add-lib "aarch64-linux=$(tail -n 1 <<<"$cross_out")")
fi
if [ -n "${SCFMU_DARWIN64_LIB:-}" ]; then
    package_args+=(--add-lib "darwin64=$SCFMU_DARWIN64_LIB")
elif cross_build macos SCFMU_NO_MACOS scripts/build_macos.sh; then
    package_args+=(--add-lib "$(grep '^x86_64-darwin=' <<<"$cross_out")" --add-lib "$(grep '^aarch64-darwin=' <<<"$cross_out")")
fi
./target/release/fmu-package "${package_args[@]}" >/dev/null
echo "build_fmus: packaged $(ls fmus/*.fmu | wc -l) FMUs (FMI 2.0 in fmus/, FMI 3.0 in fmus/fmi3/) with binaries for" \
     "$(.venv/bin/python -c 'import zipfile; print(", ".join(sorted({n.split("/")[1] for n in zipfile.ZipFile("fmus/AttitudePlant.fmu").namelist() if n.startswith("binaries/")})))' 2>/dev/null ||
        echo "this machine")" >&2
[ ${#skipped[@]} -eq 0 ] || echo "build_fmus: not built: ${skipped[*]}" >&2
if [ "$refs" = 1 ]; then
    if [ ! -x .venv/bin/scfmu ]; then
        echo "build_fmus: --reference-results and --scenario-files need the venv (scripts/setup.sh)" >&2
        exit 2
    fi
    # reference results inside every FMU (fmi-ls-ref; scfmu/verify): before the SSP and loop files copy them
    .venv/bin/scfmu verify --write fmus/*.fmu fmus/fmi3/*.fmu
    if [ "$scenario_files" = 1 ]; then
        .venv/bin/scfmu export ssp --platform all --out fmus/ssp
        .venv/bin/scfmu export loop --platform all --out fmus/loops
        .venv/bin/scfmu verify --write --no-inputs fmus/loops/*.fmu
    fi
fi
if [ "${#want[@]}" -eq 0 ] && [ "$refs" = 0 ]; then
    echo "build_fmus: host only, in $(( $(date +%s) - start )) s. Not built (on request): other platforms' binaries" \
         "(--platform P | --all-platforms), reference results (--reference-results), SSP files and loop FMUs" \
         "(--scenario-files, or scfmu export ssp|loop); --all does everything (scripts/test.sh)" >&2
fi
