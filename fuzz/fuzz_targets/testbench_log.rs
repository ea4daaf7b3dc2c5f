//! Fuzz target `testbench_log`: [`specfx_fuzz::testbench_log`] on every input (no panic, one-line errors, the summary and problem lines read).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    specfx_fuzz::testbench_log(data);
});
