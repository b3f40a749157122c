//! The shared library inside every project FMU. It is built exactly as a user's model crate is
//! (docs/export.md): a `cdylib` that depends on `spacecraft_fmus` and exports its models with one
//! `export_fmus!` line — here the whole registry. Every `.fmu` in `fmus/` carries this library under its
//! own name, and `fmi2Instantiate` picks the model by that name and checks the GUID.

spacecraft_fmus::export_fmus!(
    list: spacecraft_fmus::registry::ALL,
    families: spacecraft_fmus::registry::FAMILIES,
    references: spacecraft_fmus::models::references::ALL,
);
