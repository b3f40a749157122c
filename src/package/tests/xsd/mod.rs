//! XML Schema validation of an FMI 3.0 model description against the official FMI 3.0 XSD files that
//! fmi-rs ships (`fmi-rs-<version>/src/schema/fmi3/`), with the system's libxml2, the validator fmi-rs's
//! own `schema::validate_fmi3_model_description` wraps. That function sits behind fmi-rs's `schema`
//! feature, whose build script downloads and compiles its own libxml2, which the project's machines
//! cannot do; the schema files and the validating library are the same.
//!
//! The schema folder is found through `cargo metadata` (the fmi-rs the lock file pins, wherever Cargo
//! keeps its sources); the main schema is parsed from its file, so its `xs:include`s resolve beside it.

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::PathBuf;
use std::process::Command;

#[repr(C)]
struct XmlErrorHead {
    domain: c_int,
    code: c_int,
    message: *const c_char,
    level: c_int,
    file: *const c_char,
    line: c_int,
}

type Opaque = *mut c_void;
type StructuredErrorFunc = unsafe extern "C" fn(user: *mut c_void, error: *const XmlErrorHead);

#[link(name = "xml2")]
unsafe extern "C" {
    fn xmlInitParser();
    fn xmlSchemaNewParserCtxt(url: *const c_char) -> Opaque;
    fn xmlSchemaSetParserStructuredErrors(ctxt: Opaque, f: StructuredErrorFunc, user: *mut c_void);
    fn xmlSchemaParse(ctxt: Opaque) -> Opaque;
    fn xmlSchemaFreeParserCtxt(ctxt: Opaque);
    fn xmlSchemaNewValidCtxt(schema: Opaque) -> Opaque;
    fn xmlSchemaSetValidStructuredErrors(ctxt: Opaque, f: StructuredErrorFunc, user: *mut c_void);
    fn xmlSchemaValidateDoc(ctxt: Opaque, doc: Opaque) -> c_int;
    fn xmlSchemaFreeValidCtxt(ctxt: Opaque);
    fn xmlSchemaFree(schema: Opaque);
    fn xmlReadMemory(
        buffer: *const c_char,
        size: c_int,
        url: *const c_char,
        encoding: *const c_char,
        options: c_int,
    ) -> Opaque;
    fn xmlFreeDoc(doc: Opaque);
}

/// XML_PARSE_NONET: never fetch anything while parsing.
const XML_PARSE_NONET: c_int = 1 << 11;

unsafe extern "C" fn collect(user: *mut c_void, error: *const XmlErrorHead) {
    if user.is_null() || error.is_null() {
        return;
    }
    // SAFETY: `user` is the Vec<String> handed to libxml2 below, alive for the whole call; `error`
    // points to a libxml2 error whose leading fields are the ones declared in XmlErrorHead.
    let (out, e) = unsafe { (&mut *(user as *mut Vec<String>), &*error) };
    let message = if e.message.is_null() {
        format!("libxml2 error {}", e.code)
    } else {
        // SAFETY: a NUL-terminated message owned by libxml2 for the duration of the callback
        unsafe { CStr::from_ptr(e.message) }
            .to_string_lossy()
            .trim_end()
            .to_string()
    };
    out.push(format!("line {}: {message}", e.line));
}

/// The platform this runs on, as rustc names it (`x86_64-unknown-linux-gnu`).
fn host_triple() -> String {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let out = Command::new(rustc).arg("-vV").output().expect("rustc -vV runs");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let host = text.lines().find_map(|l| l.strip_prefix("host: "));
    host.expect("rustc -vV names the host").trim().to_string()
}

/// The folder of the FMI 3.0 XSD files inside the fmi-rs the lock file pins (this platform's packages
/// only: the others' need not be downloaded).
pub fn fmi3_schema_dir() -> PathBuf {
    let out = Command::new(env!("CARGO"))
        .args(["metadata", "--format-version", "1", "--offline", "--filter-platform"])
        .arg(host_triple())
        .arg("--manifest-path")
        .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.toml"))
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "cargo metadata: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).expect("cargo metadata prints JSON");
    let manifest = meta["packages"]
        .as_array()
        .expect("packages")
        .iter()
        .find(|p| p["name"] == "fmi-rs")
        .and_then(|p| p["manifest_path"].as_str())
        .expect("fmi-rs among the packages (a dev-dependency of the packager)");
    let dir = PathBuf::from(manifest).parent().unwrap().join("src/schema/fmi3");
    assert!(
        dir.join("fmi3ModelDescription.xsd").is_file(),
        "no FMI 3.0 schema in {}",
        dir.display()
    );
    dir
}

/// A parsed XML schema and its validation context.
pub struct Schema {
    schema: Opaque,
    valid: Opaque,
}

impl Schema {
    /// `fmi3ModelDescription.xsd` of the folder [`fmi3_schema_dir`].
    pub fn fmi3_model_description() -> Schema {
        static INIT: std::sync::Once = std::sync::Once::new();
        // SAFETY: libxml2's global initialisation, once, before any use from the test threads
        INIT.call_once(|| unsafe { xmlInitParser() });
        let path = fmi3_schema_dir().join("fmi3ModelDescription.xsd");
        let c_path = CString::new(path.to_str().unwrap()).unwrap();
        let mut errors: Vec<String> = vec![];
        // SAFETY: plain libxml2 calls; `errors` outlives the parser context, freed before it returns
        unsafe {
            let pctx = xmlSchemaNewParserCtxt(c_path.as_ptr());
            assert!(!pctx.is_null(), "libxml2 cannot open {}", path.display());
            xmlSchemaSetParserStructuredErrors(pctx, collect, &mut errors as *mut Vec<String> as *mut c_void);
            let schema = xmlSchemaParse(pctx);
            xmlSchemaFreeParserCtxt(pctx);
            assert!(!schema.is_null(), "{}: {errors:?}", path.display());
            let valid = xmlSchemaNewValidCtxt(schema);
            assert!(!valid.is_null());
            Schema { schema, valid }
        }
    }

    /// What the schema finds wrong with `xml` (empty: valid).
    pub fn problems(&self, xml: &str) -> Vec<String> {
        let mut errors: Vec<String> = vec![];
        let url = c"modelDescription.xml";
        // SAFETY: the document is parsed from `xml`'s bytes (copied by libxml2) and freed here; the
        // error sink `errors` outlives the validation
        unsafe {
            let doc = xmlReadMemory(
                xml.as_ptr() as *const c_char,
                xml.len() as c_int,
                url.as_ptr(),
                std::ptr::null(),
                XML_PARSE_NONET,
            );
            if doc.is_null() {
                return vec!["not well-formed XML".into()];
            }
            xmlSchemaSetValidStructuredErrors(self.valid, collect, &mut errors as *mut Vec<String> as *mut c_void);
            let rc = xmlSchemaValidateDoc(self.valid, doc);
            xmlFreeDoc(doc);
            if rc != 0 && errors.is_empty() {
                errors.push(format!("libxml2 validation failed with code {rc}"));
            }
        }
        errors
    }
}

impl Drop for Schema {
    fn drop(&mut self) {
        // SAFETY: both were created in fmi3_model_description and are freed once
        unsafe {
            xmlSchemaFreeValidCtxt(self.valid);
            xmlSchemaFree(self.schema);
        }
    }
}
