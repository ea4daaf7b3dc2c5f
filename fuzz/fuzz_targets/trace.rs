//! Fuzz target `trace`: [`specfx_fuzz::trace`] on every input (no panic or stack overflow, one-line errors, a trace agrees with itself).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    specfx_fuzz::trace(data);
});
