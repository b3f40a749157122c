#!/usr/bin/env bash
# Builds the FMUs' cdylib instrumented with ThreadSanitizer: target/tsan/x86_64-unknown-linux-gnu/release/
# libspacecraft_fmus_cdylib.so. TSan needs a standard library built with the same instrumentation; Debian's
# Rust (rustc-web, cargo-web, rust-web-src: /usr/bin/rustc, /usr/bin/cargo and the std sources, which
# scripts/setup.sh installs for the Windows build) builds it with -Z build-std, allowed on this stable
# compiler by RUSTC_BOOTSTRAP=1: no nightly toolchain is needed. Separate target dir, so the normal
# build is untouched. About 1.5 minutes the first time, then a rebuild of the crate only.
#
#   scripts/build_tsan.sh            build; prints the library path on the last line
#   scripts/build_tsan.sh --check    exit 0 when the toolchain is installed, 1 (with the reason) if not
set -euo pipefail
cd "$(dirname "$0")/.."

TARGET=x86_64-unknown-linux-gnu
RUSTC_DEB=/usr/bin/rustc
CARGO_DEB=/usr/bin/cargo

missing=()
[ "$(uname -m)" = x86_64 ] || missing+=("an x86-64 Linux host (found $(uname -m))")
[ -x "$RUSTC_DEB" ] || missing+=("$RUSTC_DEB (rustc-web)")
[ -x "$CARGO_DEB" ] || missing+=("$CARGO_DEB (cargo-web)")
if [ -x "$RUSTC_DEB" ] && [ ! -d "$("$RUSTC_DEB" --print sysroot)/lib/rustlib/src/rust/library/std" ]; then
    missing+=("std sources (rust-web-src)")
fi
if [ ${#missing[@]} -gt 0 ]; then
    echo "build_tsan: ThreadSanitizer toolchain not installed: ${missing[*]}" >&2
    exit 1
fi
if [ "${1:-}" = "--check" ]; then
    exit 0
fi

RUSTC_BOOTSTRAP=1 RUSTC="$RUSTC_DEB" RUSTDOC=/usr/bin/rustdoc RUSTFLAGS="-Zsanitizer=thread" \
    "$CARGO_DEB" build --release --locked --lib -p spacecraft_fmus_cdylib -Z build-std=std,panic_unwind \
    --target "$TARGET" --target-dir target/tsan >&2
lib=target/tsan/$TARGET/release/libspacecraft_fmus_cdylib.so
[ -f "$lib" ] || { echo "build_tsan: $lib was not produced" >&2; exit 1; }
echo "$lib"
