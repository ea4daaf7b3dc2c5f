//! Fuzz target `format`: [`specfx_fuzz::format`] on every input (no panic, one-line errors, round trips).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    specfx_fuzz::format(data);
});
