//! Serde round trips of formats and modes through their string notation.
use std::fmt;

use serde::de::value::{Error as DeError, StrDeserializer};
use serde::de::IntoDeserializer;
use serde::ser::{self, Impossible, Serialize};
use serde::Deserialize;

use crate::fixed::{Format, Overflow, Rounding};

/// The error of [`StringOnly`]: anything but a string was serialised.
#[derive(Debug)]
struct NotAString(String);

impl fmt::Display for NotAString {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for NotAString {}

impl ser::Error for NotAString {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        NotAString(msg.to_string())
    }
}

/// A serializer that accepts a single string and returns it; everything else is an error.
struct StringOnly;

macro_rules! reject {
    ($($method:ident($($arg:ty),*) -> $ret:ty;)*) => {
        $(fn $method(self, $(_: $arg),*) -> Result<$ret, NotAString> {
            Err(NotAString(format!("expected a string, got {}", stringify!($method))))
        })*
    };
}

impl ser::Serializer for StringOnly {
    type Ok = String;
    type Error = NotAString;
    type SerializeSeq = Impossible<String, NotAString>;
    type SerializeTuple = Impossible<String, NotAString>;
    type SerializeTupleStruct = Impossible<String, NotAString>;
    type SerializeTupleVariant = Impossible<String, NotAString>;
    type SerializeMap = Impossible<String, NotAString>;
    type SerializeStruct = Impossible<String, NotAString>;
    type SerializeStructVariant = Impossible<String, NotAString>;

    fn serialize_str(self, v: &str) -> Result<String, NotAString> {
        Ok(v.to_string())
    }

    fn serialize_some<T: ?Sized + Serialize>(self, _: &T) -> Result<String, NotAString> {
        Err(NotAString(
            "expected a string, got serialize_some".to_string(),
        ))
    }

    fn serialize_newtype_struct<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        _: &T,
    ) -> Result<String, NotAString> {
        Err(NotAString(
            "expected a string, got serialize_newtype_struct".to_string(),
        ))
    }

    fn serialize_newtype_variant<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> Result<String, NotAString> {
        Err(NotAString(
            "expected a string, got serialize_newtype_variant".to_string(),
        ))
    }

    reject! {
        serialize_bool(bool) -> String;
        serialize_i8(i8) -> String;
        serialize_i16(i16) -> String;
        serialize_i32(i32) -> String;
        serialize_i64(i64) -> String;
        serialize_u8(u8) -> String;
        serialize_u16(u16) -> String;
        serialize_u32(u32) -> String;
        serialize_u64(u64) -> String;
        serialize_f32(f32) -> String;
        serialize_f64(f64) -> String;
        serialize_char(char) -> String;
        serialize_bytes(&[u8]) -> String;
        serialize_none() -> String;
        serialize_unit() -> String;
        serialize_unit_struct(&'static str) -> String;
        serialize_unit_variant(&'static str, u32, &'static str) -> String;
        serialize_seq(Option<usize>) -> Impossible<String, NotAString>;
        serialize_tuple(usize) -> Impossible<String, NotAString>;
        serialize_tuple_struct(&'static str, usize) -> Impossible<String, NotAString>;
        serialize_tuple_variant(&'static str, u32, &'static str, usize) -> Impossible<String, NotAString>;
        serialize_map(Option<usize>) -> Impossible<String, NotAString>;
        serialize_struct(&'static str, usize) -> Impossible<String, NotAString>;
        serialize_struct_variant(&'static str, u32, &'static str, usize) -> Impossible<String, NotAString>;
    }
}

fn to_string<T: Serialize>(value: &T) -> String {
    value.serialize(StringOnly).unwrap()
}

fn from_str<'de, T: Deserialize<'de>>(text: &'de str) -> Result<T, DeError> {
    let deserializer: StrDeserializer<'de, DeError> = text.into_deserializer();
    T::deserialize(deserializer)
}

#[test]
fn formats_serialise_as_their_notation() {
    for text in ["u1.15", "s2.16", "u-2.10", "s10.-2", "s64.0"] {
        let f: Format = text.parse().unwrap();
        assert_eq!(to_string(&f), text);
        assert_eq!(from_str::<Format>(text).unwrap(), f);
    }
    let err = from_str::<Format>("x1.2").unwrap_err();
    assert_eq!(
        err.to_string(),
        "format must look like u1.15 or s2.16, got 'x1.2'"
    );
    let err = from_str::<Format>("u1.63").unwrap_err();
    assert!(err.to_string().contains("must be at most 63"), "{err}");
}

#[test]
fn modes_serialise_as_their_upper_case_names() {
    assert_eq!(to_string(&Rounding::RndConvOdd), "RND_CONV_ODD");
    assert_eq!(to_string(&Overflow::SatSym), "SAT_SYM");
    for mode in Rounding::ALL {
        assert_eq!(from_str::<Rounding>(&to_string(&mode)).unwrap(), mode);
    }
    for mode in Overflow::ALL {
        assert_eq!(from_str::<Overflow>(&to_string(&mode)).unwrap(), mode);
    }
    assert_eq!(from_str::<Rounding>("trn_zero").unwrap(), Rounding::TrnZero);
    assert_eq!(from_str::<Overflow>("sat_zero").unwrap(), Overflow::SatZero);
    let err = from_str::<Overflow>("SATURATE").unwrap_err();
    assert!(
        err.to_string().starts_with("overflow mode must be one of"),
        "{err}"
    );
}
