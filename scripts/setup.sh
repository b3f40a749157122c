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
# System tools the tests use: gcc (the hostile C master of tests/test_hardening.py) and valgrind
# (memcheck). Installed with apt-get where missing and we are root (CI, fresh machines).
missing=()
command -v gcc >/dev/null 2>&1 || missing+=(gcc libc6-dev)
command -v valgrind >/dev/null 2>&1 || missing+=(valgrind)
if [ ${#missing[@]} -gt 0 ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "setup: installing ${missing[*]}"
        apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
    else
        echo "setup: please install ${missing[*]} (needed by tests/test_hardening.py)" >&2
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
