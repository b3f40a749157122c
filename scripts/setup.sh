#!/usr/bin/env bash
# One-time (idempotent) set-up on a fresh machine: checks the Rust toolchain and creates the Python
# virtual environment .venv with the pinned packages of requirements.txt. Re-running is cheap: the
# venv is rebuilt only when requirements.txt changes.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v cargo >/dev/null 2>&1; then
    echo "setup: cargo not found. Install the Rust toolchain (https://rustup.rs), then re-run." >&2
    exit 1
fi
# System tools the tests and the build use: gcc (the hostile C master of tests/test_hardening.py),
# valgrind (memcheck) and the Windows cross toolchain below. Installed with apt-get where missing and
# we are root (CI, fresh machines).
missing=()
command -v gcc >/dev/null 2>&1 || missing+=(gcc libc6-dev)
command -v valgrind >/dev/null 2>&1 || missing+=(valgrind)
# Windows x86-64 cross build and its smoke test (scripts/build_win64.sh, tests/test_win64.py): Debian's
# Rust with its std sources, the MinGW-w64 linker and Wine. Checked by the files they install, so a
# machine that has them costs no apt call.
[ -x /usr/bin/rustc ] || missing+=(rustc-web)
[ -x /usr/bin/cargo ] || missing+=(cargo-web)
[ -d /usr/lib/rustlib/src/rust/library/std ] || missing+=(rust-web-src)
command -v x86_64-w64-mingw32-gcc >/dev/null 2>&1 || missing+=(gcc-mingw-w64-x86-64)
command -v wine >/dev/null 2>&1 || missing+=(wine64)
if [ ${#missing[@]} -gt 0 ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "setup: installing ${missing[*]}"
        apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
    else
        echo "setup: please install ${missing[*]} (gcc, valgrind: tests/test_hardening.py; the rest: the win64 build and tests/test_win64.py)" >&2
    fi
fi
PY=${PYTHON:-python3}
if ! command -v "$PY" >/dev/null 2>&1; then
    echo "setup: $PY not found (Python >= 3.11 needed)." >&2
    exit 1
fi
stamp=.venv/.requirements.sha256
want=$(sha256sum requirements.txt | cut -d' ' -f1)
if [ ! -x .venv/bin/python ] || [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
    echo "setup: creating .venv with the pinned packages of requirements.txt"
    rm -rf .venv
    "$PY" -m venv .venv
    .venv/bin/python -m pip install --quiet --upgrade pip
    .venv/bin/python -m pip install --quiet -r requirements.txt
    echo "$want" > "$stamp"
fi
