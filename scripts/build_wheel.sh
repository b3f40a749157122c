#!/usr/bin/env bash
# Builds the FMUs (scripts/build_fmus.sh with the reference results and the cross build of each platform
# asked for, and nothing else: the wheel ships no SSP files or loop FMUs) and writes platform wheels of the scfmu package into dist/: each carries the FMUs (scfmu/fmus/<Model>.fmu,
# FMI 2.0, and scfmu/fmus/fmi3/<Model>.fmu, FMI 3.0) with only its platform's binary, and the compiled
# engine's loop library for that platform (scfmu/engines/native_loop/bin/<platform>/) and the Model Exchange
# wrapper of Co-Simulation faces for that platform (scfmu/engines/me_cs/bin/<tuple>/). `pip install` of
# the wheel gives a machine without a Rust toolchain the FMUs, the scenarios and the `scfmu` command;
# pip picks the wheel of its platform by the tag. `scfmu export ssp|loop` writes the scenario files from
# the installed package.
#
#   scripts/build_wheel.sh                       set-up, build the FMUs for this machine only (no cross build,
#                                                no system package), write the wheel of this machine
#                                                (linux-x86_64: dist/scfmu-<version>-py3-none-manylinux_2_N_x86_64.whl)
#   scripts/build_wheel.sh --platform P          the wheel of platform P: linux-x86_64, linux-aarch64,
#                                                win-amd64, macos-x86_64, macos-arm64, or all (every platform
#                                                whose cross toolchain is installed); repeatable. A platform
#                                                other than this machine's is cross-built: its toolchain comes
#                                                from `scripts/setup.sh --cross` (root, Debian 12), which this
#                                                script never runs by itself
#   scripts/build_wheel.sh --no-fmu-build        package the FMUs already in fmus/ (the test suite uses this)
#   scripts/build_wheel.sh --out DIR             write the wheels into DIR instead of dist/
# Prints one line per wheel written, the path last.
#
# Platforms and folders (docs/tools.md): FMI 3.0 binaries under their platform tuple; FMI 2.0 under linux64
# (x86-64 and aarch64 alike: the folder fmpy loads on either CPU), win64 or darwin64 (the CPU's slice of the
# universal file). Tags: manylinux_2_N_<arch> (N: the newest glibc symbol version the binaries need),
# win_amd64, macosx_<oldest macOS declared by the binaries>_<arch>.
set -euo pipefail
cd "$(dirname "$0")/.."
build_fmus=1
out=dist
platforms=()
while [ $# -gt 0 ]; do
    case "$1" in
        --no-fmu-build) build_fmus=0 ;;
        --out) out=${2:?--out needs a folder}; shift ;;
        --platform) platforms+=("${2:?--platform needs a platform}"); shift ;;
        *) echo "build_wheel: unknown option $1" >&2; exit 2 ;;
    esac
    shift
done
ALL=(linux-x86_64 linux-aarch64 win-amd64 macos-x86_64 macos-arm64)
case "$(uname -s)-$(uname -m)" in
    Linux-x86_64) host=linux-x86_64 ;;
    *) host="" ;;  # the wheels are built on x86-64 Linux; elsewhere name the platform
esac
if [ ${#platforms[@]} -eq 0 ]; then
    [ -n "$host" ] || { echo "build_wheel: this machine builds no wheel of its own: give --platform" >&2; exit 2; }
    platforms=("$host")
fi
for p in "${platforms[@]}"; do
    case " all ${ALL[*]} " in
        *" $p "*) ;;
        *) echo "build_wheel: --platform takes one of ${ALL[*]} or all, not '$p'" >&2; exit 2 ;;
    esac
done
scripts/setup.sh >&2
if [ "$build_fmus" = 1 ]; then
    # the cross builds of the platforms asked for (build_fmus.sh names the one whose toolchain is missing)
    cross=()
    for p in "${platforms[@]}"; do
        case "$p" in
            all) cross+=(--all-platforms) ;;
            "$host") ;;
            macos-*) cross+=(--platform macos) ;;
            *) cross+=(--platform "$p") ;;
        esac
    done
    scripts/build_fmus.sh --reference-results "${cross[@]}" >&2
fi
shopt -s nullglob
fmus=(fmus/*.fmu)
if [ ${#fmus[@]} -eq 0 ]; then
    echo "build_wheel: no FMUs in fmus/ (run without --no-fmu-build)" >&2
    exit 1
fi
# "all": the platforms whose binaries every FMU carries (AttitudePlant tells: one build serves all models)
if [ " ${platforms[*]} " = " all " ]; then
    have=$(.venv/bin/python -c 'import zipfile; print(" ".join(sorted({n.split("/")[1] for n in zipfile.ZipFile("fmus/AttitudePlant.fmu").namelist() if n.startswith("binaries/")})))')
    platforms=()
    for pair in linux-x86_64:linux64 linux-aarch64:aarch64-linux win-amd64:win64 macos-x86_64:darwin64 macos-arm64:darwin64; do
        case " $have " in *" ${pair#*:} "*) platforms+=("${pair%%:*}") ;; esac
    done
fi
# The compiled engine's loop library of each platform (built with the FMUs: cargo build --release and the
# cross-build scripts), as scfmu/engines/native_loop/bin/<FMI 2.0 folder>/ (scfmu/engines/compiled.py).
loop_lib() {
    case "$1" in
        linux-x86_64) echo "linux64 target/release/libscfmu_native_loop.so" ;;
        linux-aarch64) echo "linux64 target/aarch64/aarch64-unknown-linux-gnu/release/libscfmu_native_loop.so" ;;
        win-amd64) echo "win64 target/win64/x86_64-win7-windows-gnu/release/scfmu_native_loop.dll" ;;
        # not built for macOS (scripts/build_macos.sh says why): the macOS wheels use the "native" engine
        macos-*) echo "darwin64 -" ;;
    esac
}
# The Model Exchange wrapper of each platform (scfmu/engines/me_cs: cargo build --release and the cross-build
# scripts), as scfmu/engines/me_cs/bin/<FMI 3.0 platform tuple>/ (scfmu/engines/cs_face.py, wrapper_libraries)
me_cs_lib() {
    local tuple
    case "$1" in
        linux-x86_64) tuple=x86_64-linux ;;
        linux-aarch64) tuple=aarch64-linux ;;
        win-amd64) tuple=x86_64-windows ;;
        macos-x86_64) tuple=x86_64-darwin ;;
        macos-arm64) tuple=aarch64-darwin ;;
    esac
    echo "$tuple $(.venv/bin/python -c 'import sys; from scfmu.engines.cs_face import checkout_build as b; print(b(sys.argv[1]))' "$tuple")"
}
mkdir -p "$out"
for plat in "${platforms[@]}"; do
    # Stage the package with the FMUs inside it, so that the source tree is never written to.
    stage=$(mktemp -d)
    trap 'rm -rf "$stage"' EXIT
    cp pyproject.toml README.md "$stage/"
    tar --exclude='__pycache__' --exclude='*/tests' -cf - scfmu | tar -xf - -C "$stage"
    read -r folder lib <<<"$(loop_lib "$plat")"
    if [ "$lib" != - ] && [ -f "$lib" ]; then
        mkdir -p "$stage/scfmu/engines/native_loop/bin/$folder"
        cp "$lib" "$stage/scfmu/engines/native_loop/bin/$folder/"
    else
        echo "build_wheel: $plat: no compiled loop library ($lib): not shipped, campaigns use the \"native\" engine" >&2
        lib=-
    fi
    # the Model Exchange wrapper of Co-Simulation faces for that platform (scfmu/engines/cs_face.py)
    read -r tuple3 me_cs <<<"$(me_cs_lib "$plat")"
    if [ -f "$me_cs" ]; then
        mkdir -p "$stage/scfmu/engines/me_cs/bin/$tuple3"
        cp "$me_cs" "$stage/scfmu/engines/me_cs/bin/$tuple3/"
    else
        echo "build_wheel: $plat: no Model Exchange wrapper ($me_cs): not shipped, the native engine refuses Model Exchange units there" >&2
    fi
    tag=$(.venv/bin/python scripts/wheel_platform.py "$plat" "$stage/scfmu/fmus" "$lib")
    .venv/bin/python -m build --wheel --no-isolation --outdir "$stage/dist" "$stage" >"$stage/build.log" 2>&1 ||
        { cat "$stage/build.log" >&2; exit 1; }
    .venv/bin/python -m wheel tags --remove --platform-tag "$tag" "$stage"/dist/scfmu-*-py3-none-any.whl >"$stage/tags.log"
    whl=$(ls "$stage"/dist/scfmu-*-"$tag".whl)
    mv -f "$whl" "$out/"
    wheel="$out/$(basename "$whl")"
    echo "build_wheel: wrote $wheel ($(du -h "$wheel" | cut -f1), ${#fmus[@]} FMUs in FMI 2.0 and 3.0 for $plat)"
    rm -rf "$stage"
done
echo "$wheel"
