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
