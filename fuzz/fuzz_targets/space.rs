//! Fuzz target `space`: [`specfx_fuzz::space`] on every input (no panic, one-line errors, round trips).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    specfx_fuzz::space(data);
});
