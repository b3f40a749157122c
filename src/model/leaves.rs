//! The serialized form of a model's internal state as a flat list of leaves, each named by the path
//! of struct fields that leads to it (`law.integral.history`). The FMI layer uses it to check a
//! restored state without per-model code: every leaf outside the paths a model declares as evolving
//! ([`Model::EVOLVING`](super::Model::EVOLVING)) must equal the leaf of a fresh `initialize`, and every
//! number inside them must be finite. Elements of a sequence share the sequence's path; the length of
//! every sequence is a leaf of its own.

use serde::ser::{self, Serialize};
use std::fmt;

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
#[derive(Default)]
pub struct Leaves {
    pub paths: Vec<String>,
    pub leaves: Vec<(u32, Leaf)>,
    stack: Vec<u32>,
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
            leaves: Vec::new(),
            stack: vec![0],
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

    fn push(&mut self, leaf: Leaf) {
        let p = self.cur();
        self.leaves.push((p, leaf));
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

fn hash(bytes: &[u8]) -> u64 {
    crc32fast::hash(bytes) as u64 | ((bytes.len() as u64) << 32)
}

type R = Result<(), Error>;

impl ser::Serializer for &mut Leaves {
    type Ok = ();
    type Error = Error;
    type SerializeSeq = Self;
    type SerializeTuple = Self;
    type SerializeTupleStruct = Self;
    type SerializeTupleVariant = Self;
    type SerializeMap = Self;
    type SerializeStruct = Self;
    type SerializeStructVariant = Self;

    fn serialize_bool(self, v: bool) -> R {
        self.push(Leaf::Bool(v));
        Ok(())
    }
    fn serialize_i8(self, v: i8) -> R {
        self.serialize_i128(v as i128)
    }
    fn serialize_i16(self, v: i16) -> R {
        self.serialize_i128(v as i128)
    }
    fn serialize_i32(self, v: i32) -> R {
        self.serialize_i128(v as i128)
    }
    fn serialize_i64(self, v: i64) -> R {
        self.serialize_i128(v as i128)
    }
    fn serialize_i128(self, v: i128) -> R {
        self.push(Leaf::Int(v));
        Ok(())
    }
    fn serialize_u8(self, v: u8) -> R {
        self.serialize_i128(v as i128)
    }
    fn serialize_u16(self, v: u16) -> R {
        self.serialize_i128(v as i128)
    }
    fn serialize_u32(self, v: u32) -> R {
        self.serialize_i128(v as i128)
    }
    fn serialize_u64(self, v: u64) -> R {
        self.serialize_i128(v as i128)
    }
    fn serialize_f32(self, v: f32) -> R {
        self.push(Leaf::F32(v.to_bits()));
        Ok(())
    }
    fn serialize_f64(self, v: f64) -> R {
        self.push(Leaf::F64(v.to_bits()));
        Ok(())
    }
    fn serialize_char(self, v: char) -> R {
        self.push(Leaf::Char(v));
        Ok(())
    }
    fn serialize_str(self, v: &str) -> R {
        self.push(Leaf::Str(hash(v.as_bytes())));
        Ok(())
    }
    fn serialize_bytes(self, v: &[u8]) -> R {
        self.push(Leaf::Bytes(hash(v)));
        Ok(())
    }
    fn serialize_none(self) -> R {
        self.push(Leaf::None);
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> R {
        self.push(Leaf::Some);
        value.serialize(self)
    }
    fn serialize_unit(self) -> R {
        self.push(Leaf::Unit);
        Ok(())
    }
    fn serialize_unit_struct(self, _name: &'static str) -> R {
        self.serialize_unit()
    }
    fn serialize_unit_variant(self, _name: &'static str, index: u32, _variant: &'static str) -> R {
        self.push(Leaf::Variant(index));
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(self, _name: &'static str, value: &T) -> R {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        index: u32,
        variant: &'static str,
        value: &T,
    ) -> R {
        self.push(Leaf::Variant(index));
        self.enter(variant);
        value.serialize(&mut *self)?;
        self.leave();
        Ok(())
    }
    fn serialize_seq(self, len: Option<usize>) -> Result<Self, Error> {
        let len = len.ok_or_else(|| Error("sequence without a length".into()))?;
        self.push(Leaf::Len(len));
        Ok(self)
    }
    fn serialize_tuple(self, _len: usize) -> Result<Self, Error> {
        Ok(self)
    }
    fn serialize_tuple_struct(self, _name: &'static str, _len: usize) -> Result<Self, Error> {
        Ok(self)
    }
    fn serialize_tuple_variant(
        self,
        _name: &'static str,
        index: u32,
        variant: &'static str,
        _len: usize,
    ) -> Result<Self, Error> {
        self.push(Leaf::Variant(index));
        self.enter(variant);
        Ok(self)
    }
    fn serialize_map(self, len: Option<usize>) -> Result<Self, Error> {
        let len = len.ok_or_else(|| Error("map without a length".into()))?;
        self.push(Leaf::Len(len));
        Ok(self)
    }
    fn serialize_struct(self, _name: &'static str, _len: usize) -> Result<Self, Error> {
        Ok(self)
    }
    fn serialize_struct_variant(
        self,
        _name: &'static str,
        index: u32,
        variant: &'static str,
        _len: usize,
    ) -> Result<Self, Error> {
        self.push(Leaf::Variant(index));
        self.enter(variant);
        Ok(self)
    }
}

impl ser::SerializeSeq for &mut Leaves {
    type Ok = ();
    type Error = Error;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> R {
        value.serialize(&mut **self)
    }
    fn end(self) -> R {
        Ok(())
    }
}
impl ser::SerializeTuple for &mut Leaves {
    type Ok = ();
    type Error = Error;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> R {
        value.serialize(&mut **self)
    }
    fn end(self) -> R {
        Ok(())
    }
}
impl ser::SerializeTupleStruct for &mut Leaves {
    type Ok = ();
    type Error = Error;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> R {
        value.serialize(&mut **self)
    }
    fn end(self) -> R {
        Ok(())
    }
}
impl ser::SerializeTupleVariant for &mut Leaves {
    type Ok = ();
    type Error = Error;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> R {
        value.serialize(&mut **self)
    }
    fn end(self) -> R {
        self.leave();
        Ok(())
    }
}
impl ser::SerializeMap for &mut Leaves {
    type Ok = ();
    type Error = Error;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> R {
        key.serialize(&mut **self)
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> R {
        value.serialize(&mut **self)
    }
    fn end(self) -> R {
        Ok(())
    }
}
impl ser::SerializeStruct for &mut Leaves {
    type Ok = ();
    type Error = Error;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, key: &'static str, value: &T) -> R {
        self.enter(key);
        value.serialize(&mut **self)?;
        self.leave();
        Ok(())
    }
    fn end(self) -> R {
        Ok(())
    }
}
impl ser::SerializeStructVariant for &mut Leaves {
    type Ok = ();
    type Error = Error;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, key: &'static str, value: &T) -> R {
        self.enter(key);
        value.serialize(&mut **self)?;
        self.leave();
        Ok(())
    }
    fn end(self) -> R {
        self.leave();
        Ok(())
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
