#!/usr/bin/env bash
# Builds this crate and packages every model it exports as fmus/<Model>.fmu (modelDescription.xml and
# documentation/index.html generated from the declarations, binaries/linux64 and, when the Windows cross
# toolchain of the project's scripts/setup.sh is installed, binaries/win64), and fmus/fmi3/<Model>.fmu.
#
# It runs the packaging tool fmu-package: $FMU_PACKAGE if set, else the one on PATH, else
# ~/.cargo/bin/fmu-package (or $CARGO_INSTALL_ROOT/bin/fmu-package) from an earlier install; when there is
# none, it installs it there once (cargo install) from the very spacecraft_fmus source this crate depends
# on (the path or git dependency in Cargo.toml, as Cargo resolved it), so that the tool and the library
# are the same version. Copy this folder anywhere and edit only the spacecraft_fmus line of Cargo.toml;
# nothing else points at the project.
#
#   ./build.sh                 build, package, write fmus/
#   ./build.sh --win64 no      linux64 only (also SCFMU_NO_WIN64=1)
#   ./build.sh --xml md        also write md/<Model>.xml (commit it, and check it with --check)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"

# The folder of the spacecraft_fmus package this crate depends on, as Cargo resolved it (a path
# dependency's folder, or the git checkout under ~/.cargo/git).
library_source() {
    cargo metadata --format-version 1 --manifest-path "$here/Cargo.toml" \
        | grep -o '"manifest_path":"[^"]*"' | sed 's/^"manifest_path":"//; s/"$//' \
        | while read -r manifest; do
            dir="$(dirname "$manifest")"
            if [ -f "$dir/src/package/Cargo.toml" ] && grep -q '^name = "spacecraft_fmus"' "$manifest"; then
                echo "$dir"
                break
            fi
        done
}

tool="${FMU_PACKAGE:-}"
root="${CARGO_INSTALL_ROOT:-${CARGO_HOME:-$HOME/.cargo}}"
if [ -z "$tool" ]; then
    if command -v fmu-package >/dev/null 2>&1; then
        tool="fmu-package"
    elif [ -x "$root/bin/fmu-package" ]; then
        tool="$root/bin/fmu-package"  # installed by an earlier run, folder not on PATH
    else
        src="$(library_source)"
        if [ -z "$src" ]; then
            echo "build.sh: fmu-package is not on PATH and the spacecraft_fmus dependency of $here/Cargo.toml" \
                "could not be resolved; install the tool once with" \
                "'cargo install --locked --path <spacecraft_fmus folder>/src/package'" \
                "(or '--git <repository URL> spacecraft_fmus_package')" >&2
            exit 1
        fi
        echo "build.sh: fmu-package is not on PATH; installing it once from $src/src/package" \
            "(cargo install --locked --path …; a few minutes, see docs/export.md)" >&2
        cargo install --quiet --locked --path "$src/src/package"
        tool="$root/bin/fmu-package"
        if ! command -v fmu-package >/dev/null 2>&1; then
            echo "build.sh: installed $tool; add $root/bin to PATH to run fmu-package yourself" >&2
        fi
    fi
fi
exec "$tool" --crate "$here" --out "$here/fmus" "$@"
