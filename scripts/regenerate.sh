#!/usr/bin/env bash
# One command for every committed file that a tool writes (CONTRIBUTING.md, "Generated files"), in order:
#
#   1. scripts/build_fmus.sh: fmu-package writes, from the model declarations in src/models/,
#        modelDescription/<Model>.xml and modelDescription/fmi3/<Model>.xml,
#        docs/models/<family>.md and docs/references.md,
#        and the FMUs in fmus/ (not committed, but their modelDescription.xml and documentation/index.html
#        are pinned by step 2).
#   2. tests/test_package_digests.py --write: tests/data/package_digests.json, the one pin: the sha256 of
#        every file of step 1 (the committed ones and the two members of each FMU, FMI 2.0 and 3.0).
#   3. with --report: `scfmu report --docs docs` (the full build; its measured time is in docs/report.md) rewrites the
#        generated blocks of docs/paperNNN.md, and its out/report/verdicts.json becomes
#        tests/data/report_full_verdicts.json (the verdicts every quick build must reach), its printed numbers
#        tests/data/report_full_values.json, its timings.json the recorded full build (scfmu/report/timings.json)
#        and the timings blocks of README.md and docs/report.md.
#   4. with --figures: scripts/adcs_figures.py (docs/adcs_*.png) and scripts/mekf_consistency.py
#        (docs/mekf_consistency.png, 100 Monte Carlo runs per plant).
#
# The README's FMU table is written by hand; tests/test_docs.py checks it against modelDescription/ (the
# models the registry builds), so a new model fails that test until the README and docs/index.md list it.
#
#   scripts/regenerate.sh                 steps 1 and 2 (what a change of a model's declarations needs)
#   scripts/regenerate.sh --report        also step 3
#   scripts/regenerate.sh --figures       also step 4
#   scripts/regenerate.sh --check         write nothing: exit 1 when a file of steps 1-2 is stale
#                                         (fmu-package --check, the digest test, tests/test_docs.py)
# Other arguments go to scripts/build_fmus.sh. Needs the set-up of scripts/setup.sh (.venv).
# Review `git diff` afterwards and say in the commit why the generated files changed.
set -euo pipefail
cd "$(dirname "$0")/.."
report=0
figures=0
check=0
build_args=()
for a in "$@"; do
    case "$a" in
        --report) report=1 ;;
        --figures) figures=1 ;;
        --check) check=1 ;;
        -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
        *) build_args+=("$a") ;;
    esac
done
if [ ! -x .venv/bin/python ]; then
    echo "regenerate: no .venv (run scripts/setup.sh first)" >&2
    exit 1
fi

if [ "$check" = 1 ]; then
    cargo build --release --locked -p spacecraft_fmus_package
    ./target/release/fmu-package --locked --check
    .venv/bin/python -m pytest -q -p no:cacheprovider tests/test_package_digests.py tests/test_docs.py
    exit 0
fi

echo "regenerate: 1/2 model descriptions, model pages, references, FMUs (scripts/build_fmus.sh)"
scripts/build_fmus.sh "${build_args[@]}"
echo "regenerate: 2/2 the digest pin (tests/data/package_digests.json)"
.venv/bin/python tests/test_package_digests.py --write

if [ "$report" = 1 ]; then
    echo "regenerate: report: docs/paperNNN.md blocks and tests/data/report_full_verdicts.json (full build)"
    .venv/bin/scfmu report --docs docs --out out/report
    cp out/report/verdicts.json tests/data/report_full_verdicts.json
    .venv/bin/python -m scfmu.report.prose out/report --values > tests/data/report_full_values.json
    .venv/bin/python -m scfmu.report.timings --record full out/report/timings.json --write README.md docs/report.md
fi
if [ "$figures" = 1 ]; then
    echo "regenerate: figures of docs/adcs.md and docs/estimation.md"
    .venv/bin/python scripts/adcs_figures.py --out docs
    .venv/bin/python scripts/mekf_consistency.py --out out/mekf
    cp out/mekf/mekf_consistency.png docs/mekf_consistency.png
fi
git status --short -- modelDescription docs tests/data
