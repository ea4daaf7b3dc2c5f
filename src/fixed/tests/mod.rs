//! Cross-cutting tests of the fixed-point core: a slow oracle, the `fixed` crate, serde.
mod differential;
mod oracle;
mod serde_str;
