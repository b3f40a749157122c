#!/usr/bin/env bash
# Cross-builds the FMUs' shared library for macOS on Linux, for both Mac CPUs: Intel (x86_64-apple-darwin,
# macOS 10.12 or later) and Apple silicon (aarch64-apple-darwin, macOS 11 or later):
#   target/macos/<triple>/release/libspacecraft_fmus_cdylib.dylib
# and, beside it, libscfmu_me_cs.dylib: the Model Exchange wrapper of Co-Simulation faces
# (scfmu/engines/cs_face.py joins the two into the universal darwin64 file of an FMI 2.0 face), built in a
# `cargo rustc` of its own that may fail without costing the FMUs their library (it then says why). Cargo
# compiles std once more for that run (its own hash of std), once per machine and toolchain like the first:
# ~2.5 min per CPU on a cold cache, seconds afterwards (docs/benchmarks.md, cross builds).
# The compiled engine's loop library (scfmu/engines/native_loop) is not built for macOS: a second cargo run
# with its own install name compiles std again (cargo hashes std differently per run), which doubles an
# already long build; the macOS wheels therefore carry no compiled loop and campaigns there use the
# "native" engine.
# Prints one line per CPU, `x86_64-darwin=PATH` and `aarch64-darwin=PATH` (fmu-package --add-lib specs).
#
# No macOS SDK and no Apple tool: Debian's Rust (rustc-web, cargo-web) compiles the standard library for
# each target from its sources (rust-web-src, -Z build-std, as scripts/build_win64.sh does: no prebuilt
# darwin std exists here), and Zig (PyPI's ziglang) links, through cargo-zigbuild (PyPI), against the
# stub of libSystem that Zig carries (the only library a Rust cdylib with libc needs). Zig's linker signs
# the arm64 library ad hoc, as Apple's linker does (macOS refuses unsigned arm64 code). Symbols are not
# stripped: the strip that rustc runs for Apple targets is Apple's, absent here. Both tools are pinned in
# requirements.txt and installed into .venv by scripts/setup.sh. The cargo target folders live in the
# cross-build cache (scripts/cross_cache.sh): std is compiled once per machine and toolchain.
#
# The libraries are built, not run: no macOS machine is available to this project's CI.
# tests/test_macos_binaries.py checks them structurally (Mach-O headers, CPU, exported FMI functions,
# dynamic dependencies, code signature).
#
#   scripts/build_macos.sh            build both; prints the two --add-lib specs
#   scripts/build_macos.sh --check    exit 0 when the tools are installed, 1 (with the reason) if not
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/cross_cache.sh

RUSTC_DEB=/usr/bin/rustc
CARGO_DEB=/usr/bin/cargo
PY=.venv/bin/python
ZIGBUILD=.venv/bin/cargo-zigbuild

missing=()
[ -x "$RUSTC_DEB" ] || missing+=("$RUSTC_DEB (rustc-web)")
[ -x "$CARGO_DEB" ] || missing+=("$CARGO_DEB (cargo-web)")
if [ -x "$RUSTC_DEB" ] && [ ! -d "$("$RUSTC_DEB" --print sysroot)/lib/rustlib/src/rust/library/std" ]; then
    missing+=("std sources (rust-web-src)")
fi
[ -x "$ZIGBUILD" ] || missing+=("$ZIGBUILD (cargo-zigbuild, requirements.txt: scripts/setup.sh)")
if [ -x "$PY" ] && ! "$PY" -c "import ziglang" 2>/dev/null; then
    missing+=("Zig (ziglang in .venv, requirements.txt: scripts/setup.sh)")
fi
if [ ${#missing[@]} -gt 0 ]; then
    echo "build_macos: cross toolchain not installed: ${missing[*]}" >&2
    exit 1
fi
if [ "${1:-}" = "--check" ]; then
    exit 0
fi

zig_version=$("$PY" -m ziglang version)
rust_version=$("$RUSTC_DEB" --version)
# cargo-zigbuild runs `cargo` and `zig` from PATH: Debian's cargo (with the compiler whose std sources we
# build from) and the pinned ziglang of .venv. They sit in a fixed folder of the cache, with a copy of
# cargo-zigbuild itself: the linker wrapper it writes names these paths, and cargo rebuilds everything
# when the linker's path changes, so the paths must not depend on the clone or on a temporary folder.
tools=$(cross_cache_dir macos-tools "$rust_version-zig-$zig_version")
ln -sfn "$CARGO_DEB" "$tools/cargo"
printf '#!/bin/sh\nexec "%s" -m ziglang "$@"\n' "$PWD/$PY" >"$tools/zig.tmp.$$" && chmod +x "$tools/zig.tmp.$$" && mv -f "$tools/zig.tmp.$$" "$tools/zig"
cmp -s "$ZIGBUILD" "$tools/cargo-zigbuild" || { cp "$ZIGBUILD" "$tools/cargo-zigbuild.tmp.$$" && mv -f "$tools/cargo-zigbuild.tmp.$$" "$tools/cargo-zigbuild"; }
json=$(mktemp)
trap 'rm -f "$json"' EXIT

start_all=$(date +%s)
for pair in x86_64-darwin:x86_64-apple-darwin aarch64-darwin:aarch64-apple-darwin; do
    key=${pair%%:*} triple=${pair#*:}
    cache=$(cross_cache_dir "$triple" "$rust_version-zig-$zig_version")
    start=$(date +%s)
    # the oldest macOS of each CPU that Rust supports (its targets' defaults), passed to Zig's linker
    # (else it stamps its newest macOS into the library and older ones refuse to load it); `cargo rustc`
    # to give the library the install name @rpath/<file> (not the build folder)
    case "$triple" in x86_64-*) min=10.12 ;; *) min=11.0 ;; esac
    build() {  # build PACKAGE: one `cargo rustc` (its JSON messages into $json)
        PATH="$tools:$PATH" CARGO="$CARGO_DEB" RUSTC="$RUSTC_DEB" RUSTDOC=/usr/bin/rustdoc RUSTC_BOOTSTRAP=1 \
        MACOSX_DEPLOYMENT_TARGET=$min CARGO_ZIGBUILD_CACHE_DIR="$cache/zigbuild" CARGO_PROFILE_RELEASE_STRIP=false \
            "$tools/cargo-zigbuild" rustc --release --locked --lib -p "$1" \
            -Z build-std=std,panic_unwind --target "$triple" --target-dir "$cache" \
            --message-format=json-render-diagnostics -- -C "link-arg=-Wl,-install_name,@rpath/lib$1.dylib" >"$json"
    }
    build spacecraft_fmus_cdylib
    out=target/macos/$triple/release
    cross_products "$json" "$out" >/dev/null
    lib=$out/libspacecraft_fmus_cdylib.dylib
    [ -f "$lib" ] || { echo "build_macos: $lib was not produced" >&2; exit 1; }
    # the Model Exchange wrapper (scfmu_me_cs: Co-Simulation faces, scfmu/engines/cs_face.py), a run of its own
    cross_optional build_macos libscfmu_me_cs.dylib "$out" "$json" build scfmu_me_cs
    echo "build_macos: $triple built in $(( $(date +%s) - start )) s (cargo target folder: $cache)" >&2
    echo "$key=$lib"
done
echo "build_macos: both built in $(( $(date +%s) - start_all )) s" >&2
