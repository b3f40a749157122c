#!/usr/bin/env bash
# Cross-builds cdylibs for Linux aarch64 (ARM 64-bit) on an x86-64 Linux machine. Without arguments: the
# three shared libraries of the workspace, giving
# target/aarch64/aarch64-unknown-linux-gnu/release/libspacecraft_fmus_cdylib.so (the FMUs' binary),
# libscfmu_native_loop.so (the compiled engine's loop, shipped in the aarch64 wheel) and libscfmu_me_cs.so
# (the Model Exchange wrapper of Co-Simulation faces, scfmu/engines/cs_face.py; shipped in every wheel;
# built in a cargo run of its own that may fail without costing the FMUs their binary: it then says why).
#
# Uses Debian's Rust (rustc-web, cargo-web: /usr/bin/rustc, /usr/bin/cargo) with its prebuilt standard
# library for the target from Debian's arm64 architecture (libstd-rust-web-dev:arm64, the same 1.96
# version: nothing of std is compiled here), and Debian's cross linker gcc-aarch64-linux-gnu. Without the
# prebuilt std it falls back to building std from the sources (rust-web-src, -Z build-std, as
# scripts/build_win64.sh does). scripts/setup.sh installs these packages. The cargo target folder lives
# in the cross-build cache (scripts/cross_cache.sh), so dependencies are compiled once per machine.
# Run the results under user-mode emulation: qemu-aarch64 -L /usr/aarch64-linux-gnu (tests/test_aarch64.py).
#
#   scripts/build_aarch64.sh          build; prints the FMUs' .so path on the last line
#   scripts/build_aarch64.sh --check  exit 0 when the cross toolchain is installed, 1 (with the reason) if not
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/cross_cache.sh

TARGET=aarch64-unknown-linux-gnu
RUSTC_DEB=/usr/bin/rustc
CARGO_DEB=/usr/bin/cargo
LINKER=aarch64-linux-gnu-gcc

missing=()
[ -x "$RUSTC_DEB" ] || missing+=("$RUSTC_DEB (rustc-web)")
[ -x "$CARGO_DEB" ] || missing+=("$CARGO_DEB (cargo-web)")
build_std=()
if [ -x "$RUSTC_DEB" ]; then
    sysroot=$("$RUSTC_DEB" --print sysroot)
    if ! ls "$sysroot/lib/rustlib/$TARGET/lib"/libstd-*.rlib >/dev/null 2>&1; then
        if [ -d "$sysroot/lib/rustlib/src/rust/library/std" ]; then
            build_std=(-Z build-std=std,panic_unwind)
        else
            missing+=("the $TARGET standard library (libstd-rust-web-dev:arm64, or rust-web-src to build it)")
        fi
    fi
fi
command -v "$LINKER" >/dev/null 2>&1 || missing+=("$LINKER (gcc-aarch64-linux-gnu)")
if [ ${#missing[@]} -gt 0 ]; then
    echo "build_aarch64: cross toolchain not installed: ${missing[*]}" >&2
    exit 1
fi
if [ "${1:-}" = "--check" ]; then
    exit 0
fi

version=$("$RUSTC_DEB" --version)
cache=$(cross_cache_dir "$TARGET" "$version${build_std:+-build-std}")
json=$(mktemp)
trap 'rm -f "$json"' EXIT
build() {
    RUSTC_BOOTSTRAP=1 RUSTC="$RUSTC_DEB" RUSTDOC=/usr/bin/rustdoc \
    CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER="$LINKER" \
        "$CARGO_DEB" build --release --locked --lib "$@" \
        ${build_std[@]+"${build_std[@]}"} --target "$TARGET" --target-dir "$cache" --message-format=json-render-diagnostics >"$json"
}
start=$(date +%s)
build -p spacecraft_fmus_cdylib -p scfmu_native_loop
out=target/aarch64/$TARGET/release
cross_products "$json" "$out" >/dev/null
so=$out/libspacecraft_fmus_cdylib.so
[ -f "$so" ] || { echo "build_aarch64: $so was not produced" >&2; exit 1; }
# the Model Exchange wrapper (scfmu_me_cs: Co-Simulation faces, scfmu/engines/cs_face.py), a run of its own
cross_optional build_aarch64 libscfmu_me_cs.so "$out" "$json" build -p scfmu_me_cs
echo "build_aarch64: built in $(( $(date +%s) - start )) s (cargo target folder: $cache)" >&2
echo "$so"
