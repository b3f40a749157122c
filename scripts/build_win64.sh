#!/usr/bin/env bash
# Cross-builds cdylibs for Windows x86-64 on Linux. Without arguments: the shared libraries of the
# workspace, giving target/win64/x86_64-win7-windows-gnu/release/spacecraft_fmus_cdylib.dll (the FMUs' binary),
# scfmu_native_loop.dll (the compiled engine's loop, shipped in the wheel by scripts/build_wheel.sh) and
# scfmu_me_cs.dll (the Model Exchange wrapper of Co-Simulation faces, scfmu/engines/cs_face.py; built in a
# cargo run of its own that may fail without costing the FMUs their DLL: it then says why).
# With --manifest-path PATH: that package (a user's model crate; fmu-package calls this), into
# <its target folder>/win64.
# Uses Debian's Rust (rustc-web, cargo-web, rust-web-src: /usr/bin/rustc, /usr/bin/cargo and the std
# sources in /usr/lib/rustlib/src) to build std for the target itself
# (-Z build-std, allowed on a stable compiler by RUSTC_BOOTSTRAP=1) and the MinGW-w64 linker
# (gcc-mingw-w64-x86-64). scripts/setup.sh installs these packages. Why the win7 target: docs/tools.md.
# The cargo target folder (std compiled for the target included) lives in the cross-build cache
# (scripts/cross_cache.sh, under ~/.cache by default), shared by every clone and by users' crates: std
# is compiled once per machine and compiler version, not at every clean build; the DLLs are copied out
# into target/win64 (or the crate's target folder).
#
#   scripts/build_win64.sh                         build; prints the FMUs' DLL path on the last line
#   scripts/build_win64.sh --manifest-path PATH    build that package; prints its release folder on the last line
#   scripts/build_win64.sh --check                 exit 0 when the cross toolchain is installed, 1 (with the reason) if not
set -euo pipefail
manifest=""
if [ "${1:-}" = "--manifest-path" ]; then
    manifest=$(realpath "${2:?--manifest-path needs a path}")
fi
cd "$(dirname "$0")/.."
. scripts/cross_cache.sh

TARGET=x86_64-win7-windows-gnu
RUSTC_DEB=/usr/bin/rustc
CARGO_DEB=/usr/bin/cargo
LINKER=x86_64-w64-mingw32-gcc

missing=()
[ -x "$RUSTC_DEB" ] || missing+=("$RUSTC_DEB (rustc-web)")
[ -x "$CARGO_DEB" ] || missing+=("$CARGO_DEB (cargo-web)")
if [ -x "$RUSTC_DEB" ] && [ ! -d "$("$RUSTC_DEB" --print sysroot)/lib/rustlib/src/rust/library/std" ]; then
    missing+=("std sources (rust-web-src)")
fi
if [ -x "$RUSTC_DEB" ] && ! "$RUSTC_DEB" --print target-list | grep -qx "$TARGET"; then
    missing+=("a $RUSTC_DEB that knows $TARGET (rustc-web 1.96; found $("$RUSTC_DEB" --version))")
fi
command -v "$LINKER" >/dev/null 2>&1 || missing+=("$LINKER (gcc-mingw-w64-x86-64)")
if [ ${#missing[@]} -gt 0 ]; then
    echo "build_win64: cross toolchain not installed: ${missing[*]}" >&2
    exit 1
fi
if [ "${1:-}" = "--check" ]; then
    exit 0
fi

# The Debian compiler is used for everything of this build (RUSTC), never the rustup one: std is
# compiled from the sources that match it exactly. Its own target dir (in the cache): the Linux build
# is untouched.
cache=$(cross_cache_dir "$TARGET" "$("$RUSTC_DEB" --version)")
json=$(mktemp)
trap 'rm -f "$json"' EXIT
build() {
    RUSTC_BOOTSTRAP=1 RUSTC="$RUSTC_DEB" RUSTDOC=/usr/bin/rustdoc \
    CARGO_TARGET_X86_64_WIN7_WINDOWS_GNU_LINKER="$LINKER" \
        "$CARGO_DEB" build --release --lib -Z build-std=std,panic_unwind --target "$TARGET" --target-dir "$cache" \
        --message-format=json-render-diagnostics "$@" >"$json"
}
start=$(date +%s)
if [ -n "$manifest" ]; then
    # the package's own target folder (its workspace's), win64 below it
    target_dir=$("$CARGO_DEB" metadata --no-deps --format-version 1 --manifest-path "$manifest" |
        python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')/win64
    build --manifest-path "$manifest"
    cross_products "$json" "$target_dir/$TARGET/release" >/dev/null
    echo "build_win64: built in $(( $(date +%s) - start )) s (cargo target folder: $cache)" >&2
    echo "$target_dir/$TARGET/release"
    exit 0
fi
build --locked -p spacecraft_fmus_cdylib -p scfmu_native_loop
cross_products "$json" "target/win64/$TARGET/release" >/dev/null
dll=target/win64/$TARGET/release/spacecraft_fmus_cdylib.dll
[ -f "$dll" ] || { echo "build_win64: $dll was not produced" >&2; exit 1; }
# the Model Exchange wrapper (scfmu_me_cs: Co-Simulation faces, scfmu/engines/cs_face.py), a run of its own
cross_optional build_win64 scfmu_me_cs.dll "target/win64/$TARGET/release" "$json" build --locked -p scfmu_me_cs
echo "build_win64: built in $(( $(date +%s) - start )) s (cargo target folder: $cache)" >&2
echo "$dll"
