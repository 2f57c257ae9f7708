//! The encoding of a device's message set that extends another: an enum
//! `{ Base(B), Ext(E) }` written as `B` itself, or as one more variant of
//! `B` holding `E` (numbered after `B`'s last). So the scale device's
//! requests and replies give the learner's messages the bytes they have on
//! the learning coprocessor, whose own types have no scale variant.
//!
//! The number of `B`'s variants comes from `B`'s own `Deserialize` (the
//! variant names it hands the deserializer), never from a constant kept
//! beside it.

use core::fmt;
use core::marker::PhantomData;

use serde::de::{self, DeserializeSeed, EnumAccess, IntoDeserializer, VariantAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer, forward_to_deserialize_any};

/// The number of variants of the enum `B`.
pub(crate) fn variants<'de, B: Deserialize<'de>>() -> u32 {
    let mut count = 0;
    // It stops at the enum's variant list: the error is expected.
    let _ = B::deserialize(Count(&mut count));
    count
}

/// Writes `value` as variant `name` of `B`, numbered after `B`'s last.
pub(crate) fn serialize<B, E, S>(
    serializer: S,
    name: &'static str,
    value: &E,
) -> Result<S::Ok, S::Error>
where
    B: for<'de> Deserialize<'de>,
    E: Serialize,
    S: Serializer,
{
    serializer.serialize_newtype_variant("Extended", variants::<B>(), name, value)
}

/// Reads a `B` (made a `T` by `base`) or the extension's `E` (made a `T`
/// by `ext`).
pub(crate) fn deserialize<'de, B, E, T, D>(
    deserializer: D,
    base: fn(B) -> T,
    ext: fn(E) -> T,
) -> Result<T, D::Error>
where
    B: Deserialize<'de>,
    E: Deserialize<'de>,
    D: Deserializer<'de>,
{
    deserializer.deserialize_enum(
        "Extended",
        &["Base", "Extension"],
        Either {
            base,
            ext,
            _types: PhantomData,
        },
    )
}

/// Visits the variant index: `B`'s count is `E`, fewer is `B`'s own.
struct Either<B, E, T> {
    base: fn(B) -> T,
    ext: fn(E) -> T,
    _types: PhantomData<(B, E)>,
}

impl<'de, B, E, T> Visitor<'de> for Either<B, E, T>
where
    B: Deserialize<'de>,
    E: Deserialize<'de>,
{
    type Value = T;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a message of the base set or of its extension")
    }

    fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<T, A::Error> {
        let (index, variant): (u32, A::Variant) = data.variant()?;
        if index == variants::<B>() {
            return variant.newtype_variant::<E>().map(self.ext);
        }
        B::deserialize(Replay {
            index,
            variant,
            _error: PhantomData,
        })
        .map(self.base)
    }
}

/// Hands `B`'s `Deserialize` the variant index already read, then the
/// rest of the variant.
struct Replay<A, Err> {
    index: u32,
    variant: A,
    _error: PhantomData<Err>,
}

impl<'de, A, Err> Deserializer<'de> for Replay<A, Err>
where
    A: VariantAccess<'de, Error = Err>,
    Err: de::Error,
{
    type Error = Err;

    fn deserialize_any<Vis: Visitor<'de>>(self, visitor: Vis) -> Result<Vis::Value, Err> {
        visitor.visit_enum(self)
    }

    forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf option unit unit_struct newtype_struct seq tuple
        tuple_struct map struct enum identifier ignored_any
    }
}

impl<'de, A, Err> EnumAccess<'de> for Replay<A, Err>
where
    A: VariantAccess<'de, Error = Err>,
    Err: de::Error,
{
    type Error = Err;
    type Variant = A;

    fn variant_seed<S: DeserializeSeed<'de>>(self, seed: S) -> Result<(S::Value, A), Err> {
        let index: de::value::U32Deserializer<Err> = self.index.into_deserializer();
        Ok((seed.deserialize(index)?, self.variant))
    }
}

/// A deserializer that only counts an enum's variants.
struct Count<'a>(&'a mut u32);

/// Why [`Count`] stopped.
#[derive(Debug)]
struct Stop;

impl fmt::Display for Stop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("counted")
    }
}

impl de::Error for Stop {
    fn custom<M: fmt::Display>(_: M) -> Self {
        Stop
    }
}

impl core::error::Error for Stop {}

impl<'de> Deserializer<'de> for Count<'_> {
    type Error = Stop;

    fn deserialize_any<Vis: Visitor<'de>>(self, _: Vis) -> Result<Vis::Value, Stop> {
        Err(Stop)
    }

    fn deserialize_enum<Vis: Visitor<'de>>(
        self,
        _name: &'static str,
        variants: &'static [&'static str],
        _: Vis,
    ) -> Result<Vis::Value, Stop> {
        *self.0 = u32::try_from(variants.len()).unwrap_or(u32::MAX);
        Err(Stop)
    }

    forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf option unit unit_struct newtype_struct seq tuple
        tuple_struct map struct identifier ignored_any
    }
}
