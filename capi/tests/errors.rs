//! Bad input over the C boundary gets an error value and one line in `specfx_last_error`,
//! never a crash: a configuration refused with the command line's own message, null pointers,
//! an n outside the set, a code outside the input format, a stage or index out of range,
//! invalid UTF-8; and the error is per thread. A failed call writes through none of its out
//! pointers, and a failed cycle leaves a cycle model exactly as it was; a batch whose output
//! overlaps its input is computed in place.

use std::ffi::{c_char, CStr, CString};
use std::ptr::{null, null_mut};

use specfx_c::*;

fn last_error() -> String {
    // SAFETY: specfx_last_error returns a valid NUL-terminated string.
    unsafe { CStr::from_ptr(specfx_last_error()) }
        .to_string_lossy()
        .into_owned()
}

fn open(config: &str) -> *mut specfx_model {
    let c = CString::new(config).unwrap();
    specfx_open(c.as_ptr())
}

#[test]
fn a_refused_configuration_gets_the_command_lines_message() {
    assert!(open("no/such.toml").is_null());
    // The line `specfx check --config no/such.toml` prints after "specfx: error: ".
    assert_eq!(
        last_error(),
        "config no/such.toml: no such file (and it is not a built-in name: baseline)"
    );
    let toml = CString::new("k = 9").unwrap();
    assert!(specfx_from_toml(toml.as_ptr()).is_null());
    assert!(last_error().starts_with("config: "), "{}", last_error());
    assert!(specfx_open(null()).is_null());
    assert_eq!(last_error(), "config: a null pointer, expected a string");
    let bad = [0xffu8, 0];
    assert!(specfx_open(bad.as_ptr() as *const c_char).is_null());
    assert_eq!(
        last_error(),
        "config: expected UTF-8 text, got an invalid byte at offset 0"
    );
}

#[test]
fn evaluations_outside_the_domain_are_error_values() {
    let m = open("baseline");
    assert!(!m.is_null());
    let mut out = -7i64;
    assert_eq!(specfx_eval(m, 0, 7, &mut out), SPECFX_ERROR);
    assert_eq!(
        last_error(),
        "n = 7 is not in the configuration's exponent set 16..=1024"
    );
    assert_eq!(specfx_eval(m, 65536, 16, &mut out), SPECFX_ERROR);
    assert_eq!(
        last_error(),
        "c = 65536 is not a code of the input format u1.15 (expected 0..=65535)"
    );
    assert_eq!(out, -7, "nothing written on failure");
    assert_eq!(specfx_eval(m, 0, 16, null_mut()), SPECFX_ERROR);
    assert_eq!(
        last_error(),
        "out: a null pointer, expected a place for the result"
    );
    assert_eq!(specfx_eval(null(), 0, 16, &mut out), SPECFX_ERROR);
    assert_eq!(last_error(), "model: a null pointer, expected a model");
    assert_eq!(specfx_n_at(m, 1009), -1);
    assert_eq!(
        last_error(),
        "i = 1009 is not an index of the n set (expected 0..1009)"
    );
    assert!(specfx_stage_name(m, 9).is_null());
    assert_eq!(
        last_error(),
        "stage = 9 is not a stage index (expected 0..9)"
    );
    let mut v = 0i64;
    let mut e = 0i32;
    assert_eq!(
        specfx_dpi_probe(m.cast(), 0, -1, 0, &mut v, &mut e),
        SPECFX_ERROR
    );
    assert_eq!(last_error(), "n = -1 is not an exponent (expected n >= 0)");
    assert_eq!(specfx_dpi_constant(m.cast(), 16, 5, &mut v), SPECFX_ERROR);
    assert!(last_error().starts_with("which = 5: expected 0 (slope)"));
    // A batch with one pair outside the domain writes nothing.
    let cs = [0i64, 1, 70_000];
    let mut outs = [-1i64; 3];
    assert_eq!(
        specfx_eval_batch(m, cs.as_ptr(), null(), 16, 3, outs.as_mut_ptr()),
        SPECFX_ERROR
    );
    assert_eq!(
        last_error(),
        "c[2] = 70000 is not a code of the input format u1.15 (expected 0..=65535)"
    );
    assert_eq!(outs, [-1; 3]);
    assert_eq!(
        specfx_eval_batch(m, null(), null(), 16, 3, outs.as_mut_ptr()),
        SPECFX_ERROR
    );
    // Errors are per thread: another thread's error is not this one's.
    std::thread::spawn(|| {
        assert!(open("no/such.toml").is_null());
    })
    .join()
    .unwrap();
    assert!(
        last_error().starts_with("c, out: a null pointer"),
        "{}",
        last_error()
    );
    specfx_free(m);
    specfx_free(null_mut());
}

#[test]
fn a_model_answers_what_a_testbench_asks() {
    let m = open("baseline");
    assert_eq!(specfx_n_count(m), 1009);
    assert_eq!((specfx_n_at(m, 0), specfx_n_at(m, 1008)), (16, 1024));
    let (mut lo, mut hi, mut one) = (0i64, 0i64, 0i64);
    assert_eq!(specfx_input_codes(m, &mut lo, &mut hi, &mut one), SPECFX_OK);
    // u1.15: codes 0..=65535, 1.0 is 2^15.
    assert_eq!((lo, hi, one), (0, 65535, 32768));
    assert_eq!(specfx_stage_count(m), 9);
    // SAFETY: a valid stage name.
    let name = unsafe { CStr::from_ptr(specfx_stage_name(m, 3)) };
    assert_eq!(name.to_str().unwrap(), "sq1");
    let (mut s, mut i, mut f) = (0, 0, 0);
    assert_eq!(
        specfx_stage_format(m, -1, &mut s, &mut i, &mut f),
        SPECFX_OK
    );
    assert_eq!((s, i, f), (0, 1, 15));
    // n = 64 with k = 4: the plain slope n with k = 4 fraction bits, the offset 1.
    let mut k = std::mem::MaybeUninit::<specfx_constants>::uninit();
    assert_eq!(specfx_constants_of(m, 64, k.as_mut_ptr()), SPECFX_OK);
    // SAFETY: written on success.
    let k = unsafe { k.assume_init() };
    assert_eq!((k.slope, k.slope_frac, k.has_threshold), (64, 4, 0));
    // At c = 1.0 the lobe is 1: the output is the coefficient.
    let mut out = 0;
    assert_eq!(specfx_eval(m, one, 64, &mut out), SPECFX_OK);
    let mut coef = 0;
    assert_eq!(
        specfx_dpi_constant(m.cast(), 64, SPECFX_COEF, &mut coef),
        SPECFX_OK
    );
    assert_eq!(out, coef);
    assert_eq!(coef, k.coef);
    // A fixed depth: every n squares k = 4 times.
    let mut depth = 0;
    assert_eq!(
        specfx_dpi_constant(m.cast(), 64, SPECFX_DEPTH, &mut depth),
        SPECFX_OK
    );
    assert_eq!((depth, k.depth), (4, 4));
    specfx_free(m);
}

/// One cycle of `machine` with every out pointer given: `(in_ready, out_valid, out_data,
/// out_tag)`, or None when the call failed.
fn cycle(
    machine: *mut std::ffi::c_void,
    input: Option<(i64, i32)>,
    out_ready: bool,
) -> Option<(i32, i32, i64, i64)> {
    let (mut in_ready, mut out_valid, mut data, mut tag) = (-5, -5, -5i64, -5i64);
    let (c, n) = input.unwrap_or((0, 0));
    let rc = specfx_dpi_machine_cycle(
        machine,
        i32::from(input.is_some()),
        c,
        n,
        i32::from(out_ready),
        &mut in_ready,
        &mut out_valid,
        &mut data,
        &mut tag,
    );
    (rc == SPECFX_OK).then_some((in_ready, out_valid, data, tag))
}

#[test]
fn a_failed_machine_cycle_leaves_the_machine_as_it_was() {
    let m = open("baseline");
    assert!(!m.is_null());
    let one = 32768; // u1.15's 1.0
    for arch in [0, 1] {
        let failing = specfx_dpi_machine_new(m.cast(), arch);
        let twin = specfx_dpi_machine_new(m.cast(), arch);
        assert!(!failing.is_null() && !twin.is_null());
        // The same stimulus to both: a few inputs with out_ready low and high.
        let stimulus: Vec<(Option<(i64, i32)>, bool)> = (0..40)
            .map(|i| {
                let input = (i % 3 != 2).then_some((one - i64::from(i) * 17, 16 + i));
                (input, i % 5 != 4)
            })
            .collect();
        for (i, &(input, out_ready)) in stimulus.iter().enumerate() {
            if i % 4 == 1 {
                // Failing calls before this cycle's real one: each out pointer null in turn
                // (with a valid input offered, which would transfer), then inputs outside the
                // domain; each writes nothing and takes no clock edge.
                let (mut a, mut b, mut d, mut t) = (-5, -5, -5i64, -5i64);
                let places = [
                    (
                        null_mut(),
                        &mut b as *mut i32,
                        &mut d as *mut i64,
                        &mut t as *mut i64,
                    ),
                    (
                        &mut a as *mut i32,
                        null_mut(),
                        &mut d as *mut i64,
                        &mut t as *mut i64,
                    ),
                    (
                        &mut a as *mut i32,
                        &mut b as *mut i32,
                        null_mut(),
                        &mut t as *mut i64,
                    ),
                    (
                        &mut a as *mut i32,
                        &mut b as *mut i32,
                        &mut d as *mut i64,
                        null_mut(),
                    ),
                ];
                for (name, (ir, ov, od, ot)) in ["in_ready", "out_valid", "out_data", "out_tag"]
                    .iter()
                    .zip(places)
                {
                    let rc = specfx_dpi_machine_cycle(failing, 1, one, 64, 1, ir, ov, od, ot);
                    assert_eq!(rc, SPECFX_ERROR);
                    assert_eq!(
                        last_error(),
                        format!("{name}: a null pointer, expected a place for the result")
                    );
                }
                assert_eq!((a, b, d, t), (-5, -5, -5, -5), "nothing written on failure");
                assert_eq!(cycle(failing, Some((one, 7)), true), None);
                assert_eq!(
                    last_error(),
                    "n = 7 is not in the configuration's exponent set 16..=1024"
                );
                assert_eq!(cycle(failing, Some((one, -16)), true), None);
                assert_eq!(last_error(), "n = -16 is not an exponent (expected n >= 0)");
                assert_eq!(cycle(failing, Some((65536, 64)), false), None);
            }
            let got = cycle(failing, input, out_ready);
            let want = cycle(twin, input, out_ready);
            assert!(want.is_some(), "cycle {i}: {}", last_error());
            assert_eq!(got, want, "arch {arch}, cycle {i}");
        }
        specfx_dpi_machine_free(failing);
        specfx_dpi_machine_free(twin);
    }
    specfx_free(m);
}

#[test]
fn a_failed_call_writes_through_none_of_its_pointers() {
    let m = open("baseline");
    let (mut lo, mut hi) = (-5i64, -5i64);
    assert_eq!(
        specfx_input_codes(m, &mut lo, &mut hi, null_mut()),
        SPECFX_ERROR
    );
    assert_eq!(
        last_error(),
        "one: a null pointer, expected a place for the result"
    );
    assert_eq!((lo, hi), (-5, -5));
    let (mut s, mut i) = (-5, -5);
    assert_eq!(
        specfx_stage_format(m, 0, &mut s, &mut i, null_mut()),
        SPECFX_ERROR
    );
    assert_eq!((s, i), (-5, -5));
    let mut v = -5i64;
    assert_eq!(
        specfx_dpi_probe(m.cast(), 32768, 64, 0, &mut v, null_mut()),
        SPECFX_ERROR
    );
    assert_eq!(
        last_error(),
        "event: a null pointer, expected a place for the result"
    );
    assert_eq!(v, -5);
    let mut n = -5;
    assert_eq!(
        specfx_dpi_directed_at(m.cast(), 0, &mut n, null_mut()),
        SPECFX_ERROR
    );
    assert_eq!(n, -5);
    specfx_free(m);
}

/// Two batches of outputs are equal, or the first place they differ.
fn assert_same(got: &[i64], want: &[i64], what: &str) {
    assert_eq!(got.len(), want.len(), "{what}");
    if let Some(i) = got.iter().zip(want).position(|(g, w)| g != w) {
        panic!("{what}: out[{i}] = {}, expected {}", got[i], want[i]);
    }
}

#[test]
fn a_batch_into_its_own_input_is_computed_in_place() {
    let m = open("baseline");
    let mut coef = 0i64;
    assert_eq!(
        specfx_dpi_constant(m.cast(), 64, SPECFX_COEF, &mut coef),
        SPECFX_OK
    );
    // Consecutive runs (the kernels' range path) and scattered codes (one by one and the
    // batch path), every code at most 1.0 (32768).
    let consecutive: Vec<i64> = (0..=32768).collect();
    let scattered: Vec<i64> = (0..5000i64).map(|i| i * 7919 % 32769).collect();
    for codes in [consecutive, scattered] {
        let len = codes.len();
        let mut fresh = vec![-1i64; len];
        let rc = specfx_eval_batch(m, codes.as_ptr(), null(), 64, len, fresh.as_mut_ptr());
        assert_eq!(rc, SPECFX_OK);
        // With n = 64 and k = 4 the base (64/16)(c - 1) + 1 is at most 0 up to c = 0.75
        // (code 24576): the output is 0; at c = 1.0 the lobe is 1: the output is coef.
        for (&c, &o) in codes.iter().zip(&fresh) {
            if c <= 24576 {
                assert_eq!(o, 0, "c = {c}");
            }
            if c == 32768 {
                assert_eq!(o, coef);
            }
        }
        // out = c.
        let mut inout = codes.clone();
        let p = inout.as_mut_ptr();
        assert_eq!(specfx_eval_batch(m, p, null(), 64, len, p), SPECFX_OK);
        assert_same(&inout, &fresh, "out = c");
        // out one place past c (overlapping all but one).
        let mut shifted = vec![0i64; len + 1];
        shifted[..len].copy_from_slice(&codes);
        let p = shifted.as_mut_ptr();
        // SAFETY: within the vector of len + 1.
        let out = unsafe { p.add(1) };
        assert_eq!(specfx_eval_batch(m, p, null(), 64, len, out), SPECFX_OK);
        assert_same(&shifted[1..], &fresh, "out = c + 1");
        // n stored in out's own bytes (its first half as u32).
        let ns: Vec<u32> = (0..len).map(|i| [16, 64, 1024][i % 3]).collect();
        let mut want = vec![0i64; len];
        let rc = specfx_eval_batch(m, codes.as_ptr(), ns.as_ptr(), 0, len, want.as_mut_ptr());
        assert_eq!(rc, SPECFX_OK);
        let mut out = vec![0i64; len];
        let n_in_out = out.as_mut_ptr().cast::<u32>();
        // SAFETY: len u32 fit in the first half of len i64.
        unsafe { std::slice::from_raw_parts_mut(n_in_out, len) }.copy_from_slice(&ns);
        let rc = specfx_eval_batch(m, codes.as_ptr(), n_in_out, 0, len, out.as_mut_ptr());
        assert_eq!(rc, SPECFX_OK);
        assert_same(&out, &want, "n in out's bytes");
    }
    specfx_free(m);
}
