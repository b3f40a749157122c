//! Text helpers usable in constants (a leaf: it uses nothing of the crate), shared by the declaration
//! checks (`model`) and the unit table (`units`).

/// Whether two strings are equal, in a `const fn` (`==` on `str` is not const).
pub const fn same_str(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}
