#!/usr/bin/env bash
# One-time (idempotent) set-up on a fresh machine: checks the Rust toolchain and creates the Python
# virtual environment .venv with the pinned packages of requirements.txt and this package (scfmu, editable,
# with its `scfmu` command). Re-running is cheap: the venv is rebuilt only when requirements.txt or
# pyproject.toml changes. Without options it installs no system package (scripts/run.sh needs none: the
# host build needs only cargo and the C linker the Rust toolchain already uses).
#
#   scripts/setup.sh                 the venv with every pinned package of requirements.txt, no system package
#   scripts/setup.sh --run-only      the venv with what `scfmu run` needs only (requirements-run.txt; scripts/run.sh)
#   scripts/setup.sh --test-tools    also rustfmt/clippy and the system tools the tests use: gcc, valgrind (apt)
#   scripts/setup.sh --cross         also the cross toolchains of the other platforms' binaries and their
#                                    emulators: MinGW-w64 + Debian's Rust + Wine (Windows), the aarch64 cross
#                                    linker + qemu-user (Linux aarch64) (apt, as root on Debian 12)
#   scripts/setup.sh --basilisk      also Basilisk (requirements-bsk.txt) in its own venv .venv-bsk: the
#                                    independent simulator the drag/solar-pressure test compares against
#   scripts/setup.sh --all           all of them (scripts/test.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
test_tools=0
cross=0
run_only=0
basilisk=0
for arg in "$@"; do
    case "$arg" in
        --test-tools) test_tools=1 ;;
        --cross) cross=1 ;;
        --basilisk) basilisk=1 ;;
        --all) test_tools=1; cross=1; basilisk=1 ;;
        --run-only) run_only=1 ;;
        *) echo "setup: unknown option '$arg' (allowed: --run-only, --test-tools, --cross, --basilisk, --all)" >&2; exit 2 ;;
    esac
done

if ! command -v cargo >/dev/null 2>&1; then
    echo "setup: cargo not found. Install the Rust toolchain (https://rustup.rs), then re-run." >&2
    exit 1
fi
# The lint gates of scripts/lint.sh need rustfmt and clippy; a rustup toolchain adds them as components.
for c in fmt:rustfmt clippy:clippy; do
    [ "$test_tools" = 1 ] || break
    if ! cargo "${c%%:*}" --version >/dev/null 2>&1; then
        if command -v rustup >/dev/null 2>&1; then
            echo "setup: adding the ${c#*:} component"
            rustup component add "${c#*:}" >/dev/null
        else
            echo "setup: cargo ${c%%:*} is missing (install the ${c#*:} component of your Rust toolchain)" >&2
        fi
    fi
done
# System tools the tests use: gcc (the hostile C master of tests/test_hardening.py) and valgrind
# (memcheck). Installed with apt-get where missing and we are root (CI, fresh machines).
can_apt() { [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; }
apt_updated=0
apt_install() {
    [ "$apt_updated" = 1 ] || { apt-get update -qq && apt_updated=1; }
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >/dev/null
}
missing=()
if [ "$test_tools" = 1 ]; then
    command -v gcc >/dev/null 2>&1 || missing+=(gcc libc6-dev)
    command -v valgrind >/dev/null 2>&1 || missing+=(valgrind)
fi
if [ ${#missing[@]} -gt 0 ]; then
    if can_apt; then
        echo "setup: installing ${missing[*]}"
        apt_install "${missing[@]}"
    else
        echo "setup: please install ${missing[*]} (needed by tests/test_hardening.py)" >&2
    fi
fi
# Windows x86-64 binaries (scripts/build_win64.sh) and their smoke test (tests/test_win64.py): Debian's
# Rust 1.96 with its std sources (rustc-web, cargo-web, rust-web-src), the MinGW-w64 linker and Wine.
# Checked with dpkg, so a machine that has them costs no apt call. Best effort: where they cannot be
# installed (not Debian 12, not root) the FMUs carry linux64 binaries only and scripts/build_fmus.sh
# says so.
win_missing=()
if [ "$cross" = 1 ] && command -v dpkg-query >/dev/null 2>&1; then
    for p in rustc-web cargo-web rust-web-src gcc-mingw-w64-x86-64 wine wine64; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || win_missing+=("$p")
    done
fi
if [ ${#win_missing[@]} -gt 0 ]; then
    if can_apt; then
        echo "setup: installing the Windows cross toolchain and Wine: ${win_missing[*]}"
        apt_install "${win_missing[@]}" ||
            echo "setup: could not install ${win_missing[*]}: FMUs will carry linux64 binaries only" >&2
    else
        echo "setup: for Windows binaries in the FMUs install ${win_missing[*]} (Debian 12)" >&2
    fi
fi
# Linux aarch64 binaries (scripts/build_aarch64.sh) and their emulated run (tests/test_aarch64.py): the
# cross linker and C library, qemu's user-mode emulator, and Debian's prebuilt aarch64 std for the same
# Rust 1.96 (libstd-rust-web-dev:arm64, from Debian's arm64 architecture, added to dpkg for it). Best
# effort like the Windows tools; without them the FMUs carry no aarch64-linux binaries and
# scripts/build_fmus.sh says so. macOS binaries need no system package (Zig and cargo-zigbuild come from
# requirements.txt).
arm_missing=()
if [ "$cross" = 1 ] && command -v dpkg-query >/dev/null 2>&1; then
    for p in gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user libstd-rust-web-dev:arm64; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || arm_missing+=("$p")
    done
fi
if [ ${#arm_missing[@]} -gt 0 ]; then
    if can_apt; then
        echo "setup: installing the aarch64 cross toolchain and qemu-user: ${arm_missing[*]}"
        if ! dpkg --print-foreign-architectures | grep -qx arm64; then
            dpkg --add-architecture arm64
            apt_updated=0
        fi
        apt_install --no-install-recommends "${arm_missing[@]}" ||
            echo "setup: could not install ${arm_missing[*]}: FMUs will carry no aarch64-linux binaries" >&2
    else
        echo "setup: for aarch64 Linux binaries install ${arm_missing[*]} (Debian 12, arm64 architecture added)" >&2
    fi
fi
PY=${PYTHON:-python3}
if ! command -v "$PY" >/dev/null 2>&1; then
    echo "setup: $PY not found (Python >= 3.11 needed)." >&2
    exit 1
fi
# The stamp records what the venv holds: "full <sha256 of requirements.txt + requirements-run.txt>" (every
# pinned package) or "run <sha256 of requirements-run.txt>" (--run-only: what `scfmu run` needs). A full venv
# serves --run-only; a run-only venv is completed in place when the full set is asked for; a change of pins
# rebuilds the venv.
stamp=.venv/.requirements.sha256
run_want="run $(cat requirements-run.txt | sha256sum | cut -d' ' -f1)"
full_want="full $(cat requirements.txt requirements-run.txt | sha256sum | cut -d' ' -f1)"
have=$(cat "$stamp" 2>/dev/null || true)
if [ "$run_only" = 1 ]; then
    want_set=requirements-run.txt want=$run_want
else
    want_set=requirements.txt want=$full_want
fi
if [ ! -x .venv/bin/python ] || { [ "$have" != "$want" ] && [ "$have" != "$full_want" ] && [ "$have" != "$run_want" ]; }; then
    echo "setup: creating .venv with the pinned packages of $want_set"
    rm -rf .venv
    "$PY" -m venv .venv
    .venv/bin/python -m pip install --quiet --upgrade pip
    .venv/bin/python -m pip install --quiet -r "$want_set"
    echo "$want" > "$stamp"
elif [ "$have" = "$run_want" ] && [ "$want" = "$full_want" ]; then
    echo "setup: adding the test, extra and build packages of requirements.txt to .venv"
    .venv/bin/python -m pip install --quiet -r requirements.txt
    echo "$want" > "$stamp"
fi
# The package itself, editable: `scfmu` on .venv/bin, the plug-ins' entry points registered, FMUs taken from
# this checkout's fmus/. Re-installed when pyproject.toml changes (e.g. a new paper plug-in).
pstamp=.venv/.pyproject.sha256
pwant=$(sha256sum pyproject.toml | cut -d' ' -f1)
if [ "$(cat "$pstamp" 2>/dev/null)" != "$pwant" ] || [ ! -x .venv/bin/scfmu ]; then
    echo "setup: installing the scfmu package (editable) into .venv"
    .venv/bin/python -m pip install --quiet --no-deps --no-build-isolation -e .
    echo "$pwant" > "$pstamp"
fi
# Basilisk in its own venv (its pins conflict with ours), rebuilt when requirements-bsk.txt changes.
if [ "$basilisk" = 1 ]; then
    bstamp=.venv-bsk/.requirements.sha256
    bwant=$(sha256sum requirements-bsk.txt | cut -d' ' -f1)
    if [ "$(cat "$bstamp" 2>/dev/null)" != "$bwant" ] || [ ! -x .venv-bsk/bin/python ]; then
        echo "setup: creating .venv-bsk with Basilisk (requirements-bsk.txt)"
        rm -rf .venv-bsk
        "$PY" -m venv .venv-bsk
        .venv-bsk/bin/python -m pip install --quiet -r requirements-bsk.txt
        echo "$bwant" > "$bstamp"
    fi
fi
