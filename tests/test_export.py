"""The exporter for users' crates (docs/export.md): the template examples/custom_controller, copied outside
the repository with only its spacecraft_fmus dependency line edited, builds with the installed packaging tool
into a valid FMU that carries only its own model and swaps into the `default` scenario in place of
PdController with the same trajectory; bad declarations fail at compile time (feed-through lists included)
with messages that name the variable and, for feed-through names, the valid ones.

Cost: the tool is installed with `cargo install --root <tmp>` and every crate is built with
CARGO_TARGET_DIR = the repository's target/, so the compiled dependencies (and the tool itself) are reused:
on a warm target/ the install takes seconds and each small crate about a minute of compiling (the
template, the feed-through crates); on a cold one the first build costs what docs/export.md says."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import textwrap
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from scfmu.engines import simulate
from scfmu.fmu import fmu_path
from scfmu.scenario import get
from scfmu.scenario.check import check

ROOT = Path(__file__).resolve().parents[1]
TARGET = ROOT / "target"
TEMPLATE = ROOT / "examples/custom_controller"
DEPENDENCY_LINE = 'spacecraft_fmus = { path = "../.." }'


def _env(**extra) -> dict:
    env = dict(os.environ, CARGO_TARGET_DIR=str(TARGET), CARGO_TERM_COLOR="never")
    env.update(extra)
    return env


def _win64_toolchain() -> bool:
    """Whether build.sh adds Windows binaries (the cross toolchain is installed and not switched off)."""
    if os.environ.get("SCFMU_NO_WIN64") == "1":
        return False
    return subprocess.run([str(ROOT / "scripts/build_win64.sh"), "--check"], capture_output=True).returncode == 0


@pytest.fixture(scope="module")
def tools(tmp_path_factory) -> Path:
    """fmu-package installed as docs/export.md says (`cargo install --locked --path src/package`), into a
    temporary root: its bin/ folder."""
    root = tmp_path_factory.mktemp("tools")
    r = subprocess.run(["cargo", "install", "--quiet", "--locked", "--path", str(ROOT / "src/package"), "--root",
                        str(root)], capture_output=True, text=True, env=_env(), timeout=1800)
    assert r.returncode == 0, r.stderr[-3000:]
    assert (root / "bin/fmu-package").is_file()
    return root / "bin"


def _copy_template(dest: Path) -> Path:
    """The template's tracked files copied to `dest`, with the dependency line (and only it) pointing at this
    repository by absolute path."""
    files = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z", "."], cwd=TEMPLATE,
                           capture_output=True, check=True).stdout.decode().split("\0")
    for rel in filter(None, files):
        (dest / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(TEMPLATE / rel, dest / rel)
    toml = (dest / "Cargo.toml").read_text()
    assert toml.count(DEPENDENCY_LINE) == 1
    (dest / "Cargo.toml").write_text(toml.replace(DEPENDENCY_LINE, f'spacecraft_fmus = {{ path = "{ROOT}" }}'))
    return dest


@pytest.fixture(scope="module")
def template(tmp_path_factory) -> Path:
    crate = _copy_template(tmp_path_factory.mktemp("elsewhere") / "my_controller")
    assert ROOT not in crate.parents
    assert not (crate / "target").exists() and not (crate / "fmus").exists()
    return crate


def _path_with(bin_dir: Path | None) -> str:
    """PATH with cargo's folder and the system's, plus `bin_dir`: no other fmu-package."""
    dirs = [str(Path(shutil.which("cargo")).parent), "/usr/local/bin", "/usr/bin", "/bin"]
    return os.pathsep.join(([str(bin_dir)] if bin_dir else []) + dirs)


@pytest.fixture(scope="module")
def built(template, tools) -> Path:
    r = subprocess.run([str(template / "build.sh")], capture_output=True, text=True,
                       env=_env(PATH=_path_with(tools)), timeout=3000)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    fmu = template / "fmus/SaturationAwarePd.fmu"
    assert fmu.is_file(), r.stdout + r.stderr
    assert f"wrote {fmu}" in r.stdout
    assert (template / "fmus/fmi3/SaturationAwarePd.fmu").is_file()
    return fmu


def test_without_the_tool_on_path_build_sh_installs_it_from_the_dependency_and_says_so(template, tmp_path):
    """The same copy, with no fmu-package on PATH: build.sh installs the tool from the spacecraft_fmus source
    Cargo resolved for the crate (into CARGO_INSTALL_ROOT here), says so, and packages."""
    if any((Path(d) / "fmu-package").exists() for d in _path_with(None).split(os.pathsep)):
        pytest.skip("an fmu-package is installed next to cargo")
    root = tmp_path / "root"
    out = tmp_path / "fmus"
    r = subprocess.run([str(template / "build.sh"), "--out", str(out), "--win64", "no"], capture_output=True,
                       text=True, env=_env(PATH=_path_with(None), CARGO_INSTALL_ROOT=str(root)), timeout=3000)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert f"fmu-package is not on PATH; installing it once from {ROOT}/src/package" in r.stderr, r.stderr[-2000:]
    assert (root / "bin/fmu-package").is_file()
    assert validate_fmu(str(out / "SaturationAwarePd.fmu")) == []


def test_build_sh_on_a_copy_outside_the_repository_gives_a_valid_fmu_that_carries_only_its_own_model(built):
    assert validate_fmu(str(built)) == []
    names = zipfile.ZipFile(built).namelist()
    expected = ["modelDescription.xml", "binaries/linux64/SaturationAwarePd.so", "documentation/index.html"]
    if _win64_toolchain():
        expected.insert(2, "binaries/win64/SaturationAwarePd.dll")
    assert names == expected
    z = zipfile.ZipFile(built)
    so = z.read("binaries/linux64/SaturationAwarePd.so")
    ours = zipfile.ZipFile(fmu_path("PdController")).read("binaries/linux64/PdController.so")
    # none of the project's 24 models is in the user's binary, which is a fraction of ours
    assert b"AttitudePlant" not in so and b"SaturationAwarePd" in so
    assert len(so) < len(ours) / 2, (len(so), len(ours))
    if "binaries/win64/SaturationAwarePd.dll" in names:
        assert z.read("binaries/win64/SaturationAwarePd.dll")[:2] == b"MZ"
    md = read_model_description(str(built))
    assert md.modelName == "SaturationAwarePd" and md.coSimulation.modelIdentifier == "SaturationAwarePd"
    # the package's metadata, not ours
    assert md.author == "Your Name <you@example.org>" and md.license == "BSD-2-Clause"
    names = {v.name: v for v in md.modelVariables}
    assert names["torque_limit"].unit == "N.m" and names["torque_limit"].min == "0.0"
    assert names["error_kind"].min == "0" and names["error_kind"].max == "1"
    # ModelStructure: every output depends on every input (a static law), as declared
    inputs = {v for v in md.modelVariables if v.causality == "input"}
    for o in md.outputs:
        assert set(o.dependencies) == inputs, o.variable.name
    doc = z.read("documentation/index.html").decode()
    assert "2 sign(q_E,w) q_E,v" in doc and "torque_limit" in doc


def test_the_users_fmu_refuses_another_models_guid(built, tmp_path):
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave
    d = extract(str(built), unzipdir=str(tmp_path / "x"))
    theirs = read_model_description(str(fmu_path("PdController"))).guid
    slave = FMU2Slave(guid=theirs, unzipDirectory=d, modelIdentifier="SaturationAwarePd", instanceName="x")
    with pytest.raises(Exception):
        slave.instantiate()


def test_it_passes_the_preflight_check_and_swaps_into_default_with_the_pd_trajectory(built):
    s = get("default", stop_time=30.0)
    mine = s.with_models({"controller": str(built)})
    report = check(mine)
    assert not report.errors, report.errors
    for engine in ("reference", "lean", "native"):
        ref = simulate(s, engine)
        out = simulate(mine, engine)
        assert set(ref) <= set(out)
        for k in ref:
            assert np.array_equal(ref[k], out[k]), (engine, k, np.max(np.abs(ref[k] - out[k])))
    # and it is a different law when asked: the vector-part error moves the trajectory
    alt = simulate(mine.with_overrides({"controller.error_kind": 1}), "native")
    assert not np.array_equal(alt["q_w"], ref["q_w"])


def test_the_staleness_check_works_for_a_users_committed_descriptions(built, template, tools, tmp_path):
    crate = template
    xml = tmp_path / "md"
    common = [str(tools / "fmu-package"), "--crate", str(crate), "--out", str(tmp_path / "fmus"), "--xml", str(xml), "--win64", "no"]
    r = subprocess.run(common, capture_output=True, text=True, env=_env(), timeout=1200)
    assert r.returncode == 0, r.stderr[-2000:]
    assert (xml / "SaturationAwarePd.xml").read_bytes() == zipfile.ZipFile(built).read("modelDescription.xml")
    ok = subprocess.run(common + ["--check"], capture_output=True, text=True, env=_env(), timeout=1200)
    assert ok.returncode == 0 and "up to date (1 models)" in ok.stdout, ok.stderr
    (xml / "SaturationAwarePd.xml").write_text("edited")
    stale = subprocess.run(common + ["--check"], capture_output=True, text=True, env=_env(), timeout=1200)
    assert stale.returncode == 1 and "stale generated files: SaturationAwarePd" in stale.stderr


# ----- bad user models -----------------------------------------------------------------------------

GOOD_ROWS = """
        0 => u: Real = 0.0, Input, "N.m", "Torque demand";
        1 => y: Real = 0.0, Output, "N.m", "Torque command";
        100 => gain: Real = 1.0, Parameter, "", "Gain", Positive;
"""

BAD = {
    # feature: (extra or replacing rows, what the compiler must say)
    "dup_vr": ('1 => w: Real = 0.0, Output, "N.m", "Clashes with y";',
               "BadVars.w (vr 1): its value reference is used by another variable"),
    # the Rust fields differ (w, w_x), the FMI names do not (w's components are w_x, w_y, w_z)
    "dup_name": ('20 => w: Vec3 = [0.0; 3], Output, "rad/s", "Rate";\n30 => w_x: Real = 0.0, Output, "rad/s", "Another w_x";',
                 "BadVars.w_x (vr 30): its name is used by another variable"),
    "unknown_unit": ('8 => rate: Real = 0.0, Output, "rad/sec", "Rate";',
                     'BadVars.rate (vr 8): unit "rad/sec" is not in spacecraft_fmus::units'),
    "unit_on_integer": ('9 => mode: Integer = 0, Parameter, "s", "Mode";', "BadVars.mode (vr 9): only Real variables carry a unit"),
    "start_outside_bound": ('102 => k: Real = -2.0, Parameter, "", "Gain k", Positive;',
                            "BadVars.k (vr 102): the start value lies outside the declared bound"),
    "choice_start": ('103 => sel: Integer = 5, Parameter, "", "Selector", Choice(&[0, 1]);',
                     "BadVars.sel (vr 103): the start value lies outside the declared bound"),
    "bound_on_output": ('10 => out2: Real = 0.0, Output, "", "Bounded output", Positive;',
                        "BadVars.out2 (vr 10): only parameters have bounds"),
    "no_description": ('11 => quiet: Real = 0.0, Output, "", "";', "BadVars.quiet (vr 11): the description is empty"),
    "missing_unit": ('12 => torque: Real = 0.0, Output, "Torque without a unit";', "12 => torque: Real"),
}


def _bad_crate(root: Path) -> Path:
    crate = root / "bad_models"
    (crate / "src").mkdir(parents=True)
    features = "\n".join(f"{f} = []" for f in [*BAD, "no_serde"])
    (crate / "Cargo.toml").write_text(textwrap.dedent(f"""\
        [package]
        name = "bad_models"
        version = "0.1.0"
        edition = "2021"
        publish = false

        [dependencies]
        spacecraft_fmus = {{ path = "{ROOT}" }}
        serde = {{ version = "1", features = ["derive"] }}

        [features]
        {features}

        [workspace]
        """))
    mods = []
    for feature, (rows, _) in BAD.items():
        mods.append(textwrap.dedent(f"""\
            #[cfg(feature = "{feature}")]
            mod {feature} {{
                use spacecraft_fmus::export::*;
                declare_variables! {{
                    pub struct BadVars {{
                        {GOOD_ROWS}
                        {rows}
                    }}
                }}
            }}
            """))
    mods.append(textwrap.dedent("""\
        #[cfg(feature = "no_serde")]
        mod no_serde {
            use spacecraft_fmus::export::*;
            declare_variables! {
                pub struct Vars {
                    0 => y: Real = 0.0, Output, "", "Output";
                }
            }
            /// State that cannot be serialized (no Serialize / Deserialize).
            #[derive(Clone)]
            pub struct Unsaved { pub history: Vec<f64> }
            impl Model for Unsaved {
                type Vars = Vars;
                const INFO: ModelInfo = ModelInfo { name: "Unsaved", ..ModelInfo::DEFAULT };
                const EVOLVING: &'static [&'static str] = &["history"];
                fn initialize(_v: &mut Vars, _e: &Experiment) -> Result<Self, String> { Ok(Unsaved { history: vec![] }) }
                fn outputs(&self, _v: &mut Vars, _t: f64) -> ModelResult { Ok(()) }
            }
        }
        """))
    (crate / "src/lib.rs").write_text("\n".join(mods))
    shutil.copyfile(ROOT / "Cargo.lock", crate / "Cargo.lock")
    return crate


@pytest.fixture(scope="module")
def bad_crate(tmp_path_factory) -> Path:
    crate = _bad_crate(tmp_path_factory.mktemp("bad"))
    r = subprocess.run(["cargo", "check", "--quiet", "--manifest-path", str(crate / "Cargo.toml")], capture_output=True,
                       text=True, env=_env(CARGO_TARGET_DIR=str(TARGET / "compile-fail")), timeout=1800)
    assert r.returncode == 0, "the crate with no bad model enabled must compile: " + r.stderr[-3000:]
    return crate


@pytest.mark.parametrize("feature", [*BAD, "no_serde"])
def test_a_bad_declaration_is_a_compile_error_that_names_the_variable(bad_crate, feature):
    r = subprocess.run(["cargo", "check", "--quiet", "--features", feature, "--manifest-path", str(bad_crate / "Cargo.toml")],
                       capture_output=True, text=True, env=_env(CARGO_TARGET_DIR=str(TARGET / "compile-fail")), timeout=600)
    assert r.returncode != 0, f"{feature} compiled"
    if feature == "no_serde":
        # the compiler names the type and the missing trait
        assert re.search(r"Unsaved: serde::(De)?[sS]erialize|(De)?[sS]erialize.*is not implemented for `Unsaved`", r.stderr), \
            r.stderr[-3000:]
    else:
        assert BAD[feature][1] in r.stderr, r.stderr[-3000:]


LEAKY = """\
    use spacecraft_fmus::export::*;
    declare_variables! {
        pub struct Vars {
            0 => u: Vec3 = [0.0; 3], Input, "", "Input";
            3 => v: Real = 0.0, Input, "", "Input without feed-through";
            10 => y: Vec3 = [0.0; 3], Output, "", "Output";
        }
    }
    #[derive(Clone, Serialize, Deserialize)]
    pub struct Leaky;
    impl Model for Leaky {
        type Vars = Vars;
        const INFO: ModelInfo = ModelInfo { name: "Leaky", description: "A gain on a vector",
            feedthrough: Feedthrough::Some(&[("y", &["INPUT"])]), ..ModelInfo::DEFAULT };
        const EVOLVING: &'static [&'static str] = &[];
        fn initialize(_v: &mut Vars, _e: &Experiment) -> Result<Self, String> { Ok(Leaky) }
        fn outputs(&self, v: &mut Vars, _t: f64) -> ModelResult { v.y = v.u; Ok(()) }
    }
    export_fmus!(Leaky);
    """


@pytest.fixture(scope="module")
def leaky(tmp_path_factory) -> Path:
    crate = tmp_path_factory.mktemp("leaky") / "leaky"
    (crate / "src").mkdir(parents=True)
    (crate / "Cargo.toml").write_text(textwrap.dedent(f"""\
        [package]
        name = "leaky"
        version = "0.1.0"
        edition = "2021"
        publish = false

        [lib]
        crate-type = ["cdylib"]

        [dependencies]
        spacecraft_fmus = {{ path = "{ROOT}" }}
        serde = {{ version = "1", features = ["derive"] }}

        [workspace]

        [profile.release]
        panic = "unwind"
        lto = "thin"
        codegen-units = 4
        strip = true
        """))
    shutil.copyfile(ROOT / "Cargo.lock", crate / "Cargo.lock")
    return crate


def _package_leaky(crate: Path, tools: Path, feedthrough_input: str) -> subprocess.CompletedProcess:
    (crate / "src/lib.rs").write_text(textwrap.dedent(LEAKY).replace("INPUT", feedthrough_input))
    shutil.rmtree(crate / "fmus", ignore_errors=True)
    return subprocess.run([str(tools / "fmu-package"), "--crate", str(crate), "--win64", "no"], capture_output=True,
                          text=True, env=_env(), timeout=1800)


def test_a_feedthrough_naming_an_unknown_variable_is_a_compile_error_listing_the_valid_names(leaky, tools):
    """The feed-through list names variables by string; the declaration's const check refuses a name that is
    neither a declared input nor a vector's stem while the crate compiles (no FMU is written)."""
    r = _package_leaky(leaky, tools, "uu")
    assert r.returncode == 1
    assert "Leaky: feed-through input `uu` is not an input of the model (nor the stem of a vector input); " \
        "its inputs are: u_x, u_y, u_z, v" in r.stderr, r.stderr[-3000:]
    assert "cargo build of" in r.stderr and "failed" in r.stderr
    assert not (leaky / "fmus").exists()


def test_a_vector_stem_in_a_feedthrough_list_stands_for_its_components(leaky, tools):
    r = _package_leaky(leaky, tools, "u")
    assert r.returncode == 0, r.stderr[-3000:]
    for fmu in (leaky / "fmus/Leaky.fmu", leaky / "fmus/fmi3/Leaky.fmu"):
        assert validate_fmu(str(fmu)) == [], fmu
        md = read_model_description(str(fmu))
        u = [v for v in md.modelVariables if v.name in ("u_x", "u_y", "u_z")]
        assert [o.variable.name for o in md.outputs] == ["y_x", "y_y", "y_z"], fmu
        for o in md.outputs:
            assert o.dependencies == u, (fmu, o.variable.name, [d.name for d in o.dependencies])


def test_a_library_without_the_export_macro_is_refused_with_the_reason(tools, tmp_path):
    lib = next((TARGET / "release").glob("libscfmu_native_loop.so"))
    r = subprocess.run([str(tools / "fmu-package"), "--lib", str(lib), "--out", str(tmp_path)], capture_output=True, text=True, timeout=60)
    assert r.returncode == 1
    assert "has no spacecraft_fmus_catalogue" in r.stderr and "export_fmus!" in r.stderr


def test_the_runtime_library_does_not_depend_on_the_packaging_crates():
    """The FMUs' shared library (and a user's, which depends on the same runtime crate) links neither the
    XML writer nor zip: only the packaging tool does."""
    def deps(package: str) -> set[str]:
        r = subprocess.run(["cargo", "tree", "--locked", "-p", package, "-e", "normal", "--prefix", "none"], cwd=ROOT,
                           capture_output=True, text=True, timeout=300, check=True)
        return {line.split()[0] for line in r.stdout.splitlines() if line.strip()}
    runtime = deps("spacecraft_fmus_cdylib")
    assert "spacecraft_fmus" in runtime
    assert not runtime & {"zip", "quick-xml", "serde_json"}, runtime
    assert {"zip", "quick-xml"} <= deps("spacecraft_fmus_package")
