//! Fuzz target `budget`: [`specfx_fuzz::budget`] on every input (no panic, one-line errors, round trips).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    specfx_fuzz::budget(data);
});
