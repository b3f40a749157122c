# Sourced by scripts/build_win64.sh, build_aarch64.sh and build_macos.sh: where a cross build keeps its
# cargo target folder between runs, so that the standard library compiled for the target (-Z build-std)
# and the crates.io dependencies are compiled once per machine and toolchain, not once per clone or test
# run. The folder survives a clean clone of the repository:
#
#   ${SCFMU_CROSS_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/scfmu/cross}/<target>-<toolchain key>/
#
# keyed by the target and the compiler's version (and, for macOS, Zig's), so a new toolchain starts a new
# folder and never links against a std built by another. The project's own crates are rebuilt whenever
# their sources change (cargo's fingerprints); the products are copied out of the cache into the clone
# (target/<name>/...) right after each build. Delete the folder to start afresh; SCFMU_CROSS_CACHE=DIR
# moves it (CI or a user with a small home folder).

# cross_cache_dir TARGET KEY: prints the cache folder for TARGET built by the toolchain KEY, created.
cross_cache_dir() {
    local root="${SCFMU_CROSS_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/scfmu/cross}"
    local key
    key=$(printf '%s' "$2" | tr -c 'A-Za-z0-9._-' '_')
    mkdir -p "$root/$1-$key"
    echo "$root/$1-$key"
}

# cross_products JSON_FILE TO_DIR: copies every cdylib that a `cargo build --message-format=json` run
# (its output in JSON_FILE) produced into TO_DIR (atomically: a copy, then a rename) and prints their paths.
cross_products() {
    mkdir -p "$2"
    python3 - "$1" "$2" <<'PY'
import json, os, shutil, sys
out = sys.argv[2]
for line in open(sys.argv[1]):
    try:
        m = json.loads(line)
    except ValueError:
        continue
    if m.get("reason") == "compiler-artifact" and "cdylib" in m["target"]["kind"]:
        for f in m["filenames"]:
            if f.endswith((".so", ".dll", ".dylib")):
                dest = os.path.join(out, os.path.basename(f))
                shutil.copyfile(f, dest + ".tmp")
                os.replace(dest + ".tmp", dest)
                print(dest)
PY
}

# cross_optional NAME LIB OUT_DIR JSON_FILE COMMAND...: runs COMMAND (a cargo build of one more package, its
# JSON messages written to JSON_FILE by COMMAND itself) for a library that may fail to build without failing the
# caller: the Model Exchange wrapper scfmu_me_cs (scfmu/engines/me_cs), built in a cargo run of its own after
# the FMUs' one, so that a wrapper that does not compile for a target never costs the FMUs their binary.
# On success its cdylib is copied into OUT_DIR (cross_products); on failure OUT_DIR/LIB is removed (never a
# stale library from an earlier build) and one line names the first compiler error. Always returns 0.
cross_optional() {
    local name=$1 lib=$2 out=$3 json=$4 err
    shift 4
    err=$(mktemp)
    rm -f "$out/$lib"
    if "$@" 2>"$err"; then
        cross_products "$json" "$out" >/dev/null
    fi
    if [ ! -f "$out/$lib" ]; then
        echo "$name: $lib not built (Model Exchange faces get no binary for this platform): $(grep -m1 -E '^error' "$err" || tail -n 1 "$err")" >&2
    fi
    rm -f "$err"
}
