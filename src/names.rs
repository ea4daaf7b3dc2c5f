//! Named enums: one macro gives every policy enum its `Display` and case-insensitive `FromStr`
//! from its `name()` and `ALL`, with the library's usual error.

/// Implements `Display` (the name) and `FromStr` (any case, else
/// [`crate::Error::UnknownName`]) for an enum with `const ALL: [Self; N]` and
/// `fn name(self) -> &'static str`.
macro_rules! named_enum {
    ($ty:ty, $what:expr, $expected:expr) => {
        impl std::fmt::Display for $ty {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl std::str::FromStr for $ty {
            type Err = $crate::error::Error;
            fn from_str(s: &str) -> Result<Self, $crate::error::Error> {
                <$ty>::ALL
                    .into_iter()
                    .find(|x| x.name().eq_ignore_ascii_case(s))
                    .ok_or_else(|| $crate::error::Error::UnknownName {
                        what: $what,
                        expected: $expected,
                        got: s.to_string(),
                    })
            }
        }
    };
}

pub(crate) use named_enum;
