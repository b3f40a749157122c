//! The serde `Serializer` behind [`Leaves::of`](super::Leaves::of): every serde data model type becomes
//! leaves under the current path (struct fields extend it, sequence elements share it, lengths and enum
//! variants are leaves of their own).

use serde::ser::{self, Serialize};

use super::{Error, Leaf, Leaves};

fn hash(bytes: &[u8]) -> u64 {
    crc32fast::hash(bytes) as u64 | ((bytes.len() as u64) << 32)
}

type R = Result<(), Error>;

/// Bytes of an unsigned LEB128 varint (postcard's encoding of integers wider than a byte, lengths and
/// enum variant indices; signed integers are zigzag-encoded first).
fn varint_len(v: u128) -> usize {
    (128 - v.leading_zeros() as usize).div_ceil(7).max(1)
}

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
        self.push(Leaf::Bool(v), 1);
        Ok(())
    }
    fn serialize_i8(self, v: i8) -> R {
        self.push(Leaf::Int(v as i128), 1);
        Ok(())
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
        self.push(Leaf::Int(v), varint_len(((v << 1) ^ (v >> 127)) as u128));
        Ok(())
    }
    fn serialize_u8(self, v: u8) -> R {
        self.push(Leaf::Int(v as i128), 1);
        Ok(())
    }
    fn serialize_u16(self, v: u16) -> R {
        self.serialize_u64(v as u64)
    }
    fn serialize_u32(self, v: u32) -> R {
        self.serialize_u64(v as u64)
    }
    fn serialize_u64(self, v: u64) -> R {
        self.push(Leaf::Int(v as i128), varint_len(v as u128));
        Ok(())
    }
    fn serialize_f32(self, v: f32) -> R {
        self.push(Leaf::F32(v.to_bits()), 4);
        Ok(())
    }
    fn serialize_f64(self, v: f64) -> R {
        self.push(Leaf::F64(v.to_bits()), 8);
        Ok(())
    }
    fn serialize_char(self, v: char) -> R {
        let n = v.len_utf8();
        self.push(Leaf::Char(v), varint_len(n as u128) + n);
        Ok(())
    }
    fn serialize_str(self, v: &str) -> R {
        let n = v.len();
        self.push(Leaf::Str(hash(v.as_bytes())), varint_len(n as u128) + n);
        Ok(())
    }
    fn serialize_bytes(self, v: &[u8]) -> R {
        self.push(Leaf::Bytes(hash(v)), varint_len(v.len() as u128) + v.len());
        Ok(())
    }
    fn serialize_none(self) -> R {
        self.push(Leaf::None, 1);
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> R {
        self.push(Leaf::Some, 1);
        value.serialize(self)
    }
    fn serialize_unit(self) -> R {
        self.push(Leaf::Unit, 0);
        Ok(())
    }
    fn serialize_unit_struct(self, _name: &'static str) -> R {
        self.serialize_unit()
    }
    fn serialize_unit_variant(self, _name: &'static str, index: u32, _variant: &'static str) -> R {
        self.push(Leaf::Variant(index), varint_len(index as u128));
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
        self.push(Leaf::Variant(index), varint_len(index as u128));
        self.enter(variant);
        value.serialize(&mut *self)?;
        self.leave();
        Ok(())
    }
    fn serialize_seq(self, len: Option<usize>) -> Result<Self, Error> {
        let len = len.ok_or_else(|| Error("sequence without a length".into()))?;
        self.push(Leaf::Len(len), varint_len(len as u128));
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
        self.push(Leaf::Variant(index), varint_len(index as u128));
        self.enter(variant);
        Ok(self)
    }
    fn serialize_map(self, len: Option<usize>) -> Result<Self, Error> {
        let len = len.ok_or_else(|| Error("map without a length".into()))?;
        self.push(Leaf::Len(len), varint_len(len as u128));
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
        self.push(Leaf::Variant(index), varint_len(index as u128));
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
