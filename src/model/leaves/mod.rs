//! The serialized form of a model's internal state as a flat list of leaves, each named by the path
//! of struct fields that leads to it (`law.integral.history`). The FMI layer uses it to check a
//! restored state without per-model code: every leaf outside the paths a model declares as evolving
//! ([`Model::EVOLVING`](super::Model::EVOLVING)) must equal the leaf of a fresh `initialize`, and every
//! number inside them must be finite. Elements of a sequence share the sequence's path; the length of
//! every sequence is a leaf of its own. `serializer.rs` is the serde `Serializer` that walks a value
//! into leaves.

use serde::ser::{self, Serialize};
use std::fmt;

mod serializer;

/// One scalar of a serialized state (floats by their bits, so that 0.0 and -0.0 differ and the
/// comparison is exact).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Leaf {
    F64(u64),
    F32(u32),
    Int(i128),
    Bool(bool),
    Char(char),
    Str(u64),
    Bytes(u64),
    Unit,
    None,
    Some,
    /// Length of a sequence or map.
    Len(usize),
    /// Index of an enum variant.
    Variant(u32),
}

impl Leaf {
    /// The value as a float, for the finite check.
    pub fn float(self) -> Option<f64> {
        match self {
            Leaf::F64(b) => Some(f64::from_bits(b)),
            Leaf::F32(b) => Some(f32::from_bits(b) as f64),
            _ => None,
        }
    }
}

impl fmt::Display for Leaf {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Leaf::F64(_) | Leaf::F32(_) => write!(f, "{}", self.float().unwrap_or(f64::NAN)),
            Leaf::Int(i) => write!(f, "{i}"),
            Leaf::Bool(b) => write!(f, "{b}"),
            Leaf::Len(n) => write!(f, "length {n}"),
            Leaf::Variant(v) => write!(f, "variant {v}"),
            Leaf::None => write!(f, "None"),
            Leaf::Some => write!(f, "Some"),
            other => write!(f, "{other:?}"),
        }
    }
}

/// Flattens a serializable value into (path, leaf) pairs, paths as indices into `paths`.
/// `offsets[i]` is where leaf i starts in the value's postcard encoding (the byte format of FMU
/// states), so that a test can write into a serialized state at a named field.
#[derive(Default)]
pub struct Leaves {
    pub paths: Vec<String>,
    pub leaves: Vec<(u32, Leaf)>,
    pub offsets: Vec<usize>,
    stack: Vec<u32>,
    pos: usize,
}

#[derive(Debug)]
pub struct Error(String);

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for Error {}
impl ser::Error for Error {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Error(msg.to_string())
    }
}

impl Leaves {
    pub fn of<T: Serialize + ?Sized>(value: &T) -> Result<Leaves, String> {
        let mut l = Leaves {
            paths: vec![String::new()],
            stack: vec![0],
            ..Leaves::default()
        };
        value.serialize(&mut l).map_err(|e| e.0)?;
        Ok(l)
    }

    pub fn path(&self, i: u32) -> &str {
        &self.paths[i as usize]
    }

    fn cur(&self) -> u32 {
        *self.stack.last().expect("root path")
    }

    /// A leaf of `size` bytes in the postcard encoding.
    fn push(&mut self, leaf: Leaf, size: usize) {
        let p = self.cur();
        self.leaves.push((p, leaf));
        self.offsets.push(self.pos);
        self.pos += size;
    }

    fn enter(&mut self, field: &str) {
        let parent = &self.paths[self.cur() as usize];
        let path = if parent.is_empty() {
            field.to_string()
        } else {
            format!("{parent}.{field}")
        };
        // paths repeat (every element of a sequence of structs): reuse the index of the last use
        let idx = match self.paths.iter().rposition(|p| *p == path) {
            Some(i) => i as u32,
            None => {
                self.paths.push(path);
                (self.paths.len() - 1) as u32
            }
        };
        self.stack.push(idx);
    }

    fn leave(&mut self) {
        self.stack.pop();
    }
}

/// Whether `path` lies under one of the `prefixes` (equal, or followed by a '.').
pub fn under(path: &str, prefixes: &[&str]) -> bool {
    prefixes
        .iter()
        .any(|p| path == *p || (path.starts_with(p) && path.as_bytes().get(p.len()) == Some(&b'.')))
}

/// The check of a restored state against a fresh one: every leaf outside `evolving` equal (same
/// paths, same values, same sequence lengths), every float inside `evolving` finite. The message names
/// the first field that differs.
pub fn check_restored<T: Serialize>(restored: &T, fresh: &T, evolving: &[&str]) -> Result<(), String> {
    let r = Leaves::of(restored)?;
    let f = Leaves::of(fresh)?;
    let mut fi = f.leaves.iter().filter(|(p, _)| !under(f.path(*p), evolving));
    for (p, leaf) in &r.leaves {
        let path = r.path(*p);
        if under(path, evolving) {
            if let Some(x) = leaf.float() {
                if !x.is_finite() {
                    return Err(format!("restored state: {path} = {x} is not finite"));
                }
            }
            continue;
        }
        match fi.next() {
            Some((fp, fl)) if f.path(*fp) == path && fl == leaf => {}
            Some((fp, fl)) if f.path(*fp) == path => {
                return Err(format!(
                    "restored state: {path} = {leaf} does not match the parameters (they give {fl})"
                ));
            }
            _ => {
                return Err(format!(
                    "restored state: {path} does not match the parameters (different structure)"
                ))
            }
        }
    }
    if let Some((fp, _)) = fi.next() {
        return Err(format!(
            "restored state: {} is missing (different structure)",
            f.path(*fp)
        ));
    }
    Ok(())
}

/// Every float of a restored value must be finite, evolving or not: a NaN or infinity anywhere in a
/// state (even in a field nothing reads yet) is refused with the field's path (`what` prefixes it).
pub fn check_all_finite<T: Serialize + ?Sized>(value: &T, what: &str) -> Result<(), String> {
    let l = Leaves::of(value)?;
    for (p, leaf) in &l.leaves {
        if let Some(x) = leaf.float() {
            if !x.is_finite() {
                return Err(format!("restored state: {what}{} = {x} is not finite", l.path(*p)));
            }
        }
    }
    Ok(())
}

/// Test support: every leaf path outside `evolving`, for registry-wide checks of restored states.
pub fn derived_paths<T: Serialize>(value: &T, evolving: &[&str]) -> Result<Vec<String>, String> {
    let l = Leaves::of(value)?;
    let mut out: Vec<String> = l
        .leaves
        .iter()
        .map(|(p, _)| l.path(*p))
        .filter(|p| !under(p, evolving))
        .map(str::to_string)
        .collect();
    out.dedup();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Serialize;

    #[derive(Serialize)]
    struct Inner {
        a: f64,
        hist: Vec<f64>,
        flag: bool,
    }
    #[derive(Serialize)]
    struct Outer {
        law: Inner,
        e0: Option<f64>,
        mode: Mode,
    }
    #[derive(Serialize)]
    enum Mode {
        #[allow(dead_code)]
        A,
        B {
            k: f64,
        },
    }

    fn sample() -> Outer {
        Outer {
            law: Inner {
                a: 1.0,
                hist: vec![1.0, 2.0],
                flag: false,
            },
            e0: Some(0.5),
            mode: Mode::B { k: 3.0 },
        }
    }

    #[test]
    fn paths_and_comparison() {
        let s = sample();
        let l = Leaves::of(&s).unwrap();
        let names: Vec<&str> = l.leaves.iter().map(|(p, _)| l.path(*p)).collect();
        assert_eq!(
            names,
            ["law.a", "law.hist", "law.hist", "law.hist", "law.flag", "e0", "e0", "mode", "mode.B.k"]
        );
        let ev = ["law.hist", "e0"];
        assert!(check_restored(&s, &sample(), &ev).is_ok());
        // evolving parts may differ, even in length
        let mut r = sample();
        r.law.hist.push(7.0);
        r.e0 = None;
        assert!(check_restored(&r, &sample(), &ev).is_ok());
        // but must be finite
        r.law.hist[0] = f64::NAN;
        assert!(check_restored(&r, &sample(), &ev)
            .unwrap_err()
            .contains("law.hist = NaN is not finite"));
        // a derived flag that differs is named
        let mut r = sample();
        r.law.flag = true;
        assert!(check_restored(&r, &sample(), &ev)
            .unwrap_err()
            .contains("law.flag = true does not match"));
        let mut r = sample();
        r.mode = Mode::A;
        assert!(check_restored(&r, &sample(), &ev).unwrap_err().contains("mode"));
        assert!(under("law.hist", &["law"]) && !under("lawyer", &["law"]));
    }
}
