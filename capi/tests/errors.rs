//! Bad input over the C boundary gets an error value and one line in `specfx_last_error`,
//! never a crash: a configuration refused with the command line's own message, null pointers,
//! an n outside the set, a code outside the input format, a stage or index out of range,
//! invalid UTF-8; and the error is per thread.

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
