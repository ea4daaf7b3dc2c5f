//! Fuzz target `mesh_obj`: [`specfx_fuzz::mesh_obj`] on every input (no panic, one-line errors, round trips).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    specfx_fuzz::mesh_obj(data);
});
