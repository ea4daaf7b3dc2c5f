//! specfx's bit-accurate datapath model as a C library: a face of `specfx::input` (the model
//! from a configuration) and `specfx::engine::pairs` (evaluations checked against the model's
//! domain), plus the `specfx_dpi_*` functions a SystemVerilog testbench imports through DPI-C
//! (`hdl_ref/dpi/specfx_dpi.sv`).
//!
//! Every function catches panics and checks its pointers: a failure returns
//! `SPECFX_ERROR` (or a null pointer) and leaves its one-line message in
//! `specfx_last_error`, per thread. Every argument is checked before anything is written or
//! moves: a failed call writes through none of its out pointers and leaves a cycle model
//! (`specfx_dpi_machine_cycle`) exactly as it was. A model is immutable once made: any number of threads
//! may evaluate it at once. Raw codes cross as 64-bit two's complement integers: every format
//! (up to 64 bits signed, 63 unsigned) crosses exactly.

#![allow(non_camel_case_types)]
// These are C entry points: their pointer contracts are documented for C callers (and checked
// for null), not expressed as Rust `unsafe fn`s; the only Rust callers are this crate's tests.
#![allow(clippy::not_unsafe_ptr_arg_deref)]

use std::cell::RefCell;
use std::ffi::{c_char, c_int, c_longlong, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Arc;

use specfx::cycle::lockstep::Lockstep;
use specfx::cycle::Arch;
use specfx::engine::pairs::{self, Ns};
use specfx::pipeline::ports::PerN;
use specfx::pipeline::{Datapath, MAX_STAGES};

/// What a function returns when it succeeded.
pub const SPECFX_OK: c_int = 0;
/// What a function returns when it failed; `specfx_last_error` says why.
pub const SPECFX_ERROR: c_int = -1;
/// The most stages a datapath has (d, t, b, up to seven squarings, coef, out): the length of
/// the arrays `specfx_eval_probes` fills.
pub const SPECFX_MAX_STAGES: usize = 12;
const _: () = assert!(SPECFX_MAX_STAGES == MAX_STAGES);

/// Which per-n constant `specfx_constant` returns: the slope's raw code.
pub const SPECFX_SLOPE: c_int = 0;
/// The offset's raw code.
pub const SPECFX_OFFSET: c_int = 1;
/// The paper cutoff's threshold code (0 for the other cutoffs, as on `specfx_top`'s port).
pub const SPECFX_THRESHOLD: c_int = 2;
/// The coefficient's raw code.
pub const SPECFX_COEF: c_int = 3;
/// The per-n depth j(n), the squarings n uses (`specfx_top`'s `in_depth`; k for a fixed
/// depth).
pub const SPECFX_DEPTH: c_int = 4;
// The numbers are the library's order of the per-n constants (`PerN::ALL`), which
// `specfx_dpi_constant` indexes.
const _: () = {
    assert!(SPECFX_SLOPE as usize == PerN::Slope as usize);
    assert!(SPECFX_OFFSET as usize == PerN::Offset as usize);
    assert!(SPECFX_THRESHOLD as usize == PerN::Threshold as usize);
    assert!(SPECFX_COEF as usize == PerN::Coef as usize);
    assert!(SPECFX_DEPTH as usize == PerN::Depth as usize);
};

/// A validated datapath: made by `specfx_open` or `specfx_from_toml`, freed by
/// `specfx_free`.
pub struct specfx_model {
    dp: Arc<Datapath>,
    /// The stages' names, for `specfx_stage_name`.
    names: Vec<CString>,
    /// The directed cases, computed on first use.
    directed: std::sync::OnceLock<Result<Vec<(u32, i64)>, String>>,
}

/// The constants of one exponent as the datapath stores them.
#[repr(C)]
pub struct specfx_constants {
    /// The exponent.
    pub n: u32,
    /// Raw slope: n (plain) or A(n) quantized (minimax).
    pub slope: i64,
    /// Fraction bits of the slope.
    pub slope_frac: i32,
    /// Raw offset: 1 (plain) or A(n) + B(n) quantized (minimax).
    pub offset: i64,
    /// Fraction bits of the offset.
    pub offset_frac: i32,
    /// 1 when the paper cutoff applies a threshold, else 0.
    pub has_threshold: i32,
    /// The threshold code (inputs below it give 0); 0 without a threshold.
    pub threshold: i64,
    /// Raw coefficient in the coefficient's format.
    pub coef: i64,
    /// The depth j(n): the squarings n uses (k for a fixed depth).
    pub depth: u32,
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_error(message: &str) {
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = text);
}

/// Runs `f`, turning an error or a panic into `fail` and the thread's last error.
fn guard<T>(fail: T, f: impl FnOnce() -> Result<T, String>) -> T {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(v)) => v,
        Ok(Err(message)) => {
            set_error(&message);
            fail
        }
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown".to_string());
            set_error(&format!("specfx: internal error: {what}"));
            fail
        }
    }
}

/// The model behind a pointer, or the error naming it.
fn deref<'a>(m: *const specfx_model) -> Result<&'a specfx_model, String> {
    // SAFETY: a non-null pointer comes from specfx_open or specfx_from_toml and is not freed
    // (the documented contract of every function taking a model).
    unsafe { m.as_ref() }.ok_or_else(|| "model: a null pointer, expected a model".to_string())
}

/// A C string argument as UTF-8.
fn text<'a>(p: *const c_char, what: &str) -> Result<&'a str, String> {
    if p.is_null() {
        return Err(format!("{what}: a null pointer, expected a string"));
    }
    // SAFETY: the caller passes a NUL-terminated string (checked non-null above).
    unsafe { CStr::from_ptr(p) }.to_str().map_err(|e| {
        format!(
            "{what}: expected UTF-8 text, got an invalid byte at offset {}",
            e.valid_up_to()
        )
    })
}

/// An out pointer checked for null: every place a function writes is checked before it writes
/// any (and before a stateful one changes state), so a failure writes nothing.
struct Place<T>(*mut T);

impl<T> Place<T> {
    /// Writes the result.
    fn set(self, value: T) {
        // SAFETY: non-null (checked by `place`), and the caller gives a valid, aligned place
        // of type T (the documented contract).
        unsafe { self.0.write(value) }
    }
}

/// An out pointer that must not be null, or the error naming it.
fn place<T>(p: *mut T, what: &str) -> Result<Place<T>, String> {
    if p.is_null() {
        return Err(format!(
            "{what}: a null pointer, expected a place for the result"
        ));
    }
    Ok(Place(p))
}

/// An out pointer that may be null (the result is then not wanted).
fn optional_place<T>(p: *mut T) -> Option<Place<T>> {
    (!p.is_null()).then_some(Place(p))
}

fn boxed(dp: Datapath) -> *mut specfx_model {
    let names = dp
        .stages()
        .iter()
        .map(|s| CString::new(s.name.as_str()).unwrap_or_default())
        .collect();
    Box::into_raw(Box::new(specfx_model {
        dp: Arc::new(dp),
        names,
        directed: std::sync::OnceLock::new(),
    }))
}

fn n_of(n: c_int) -> Result<u32, String> {
    u32::try_from(n).map_err(|_| format!("n = {n} is not an exponent (expected n >= 0)"))
}

/// The message of the last failure on this thread ("" when none failed yet). The pointer is
/// valid until the next failing call on the same thread.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// The model a `--config` argument names, as the command line reads it: a built-in name
/// (`baseline`), a TOML file, or a vector directory written by `specfx vectors` (or its
/// `manifest.json`, the whole directory verified). Null on failure, with the command line's
/// message in `specfx_last_error`.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_open(config: *const c_char) -> *mut specfx_model {
    guard(std::ptr::null_mut(), || {
        let arg = text(config, "config")?;
        let dp = specfx::input::load_datapath(arg, None).map_err(|e| e.to_string())?;
        Ok(boxed(dp))
    })
}

/// The model of a configuration's TOML text (merged onto `baseline`). Null on failure.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_from_toml(toml: *const c_char) -> *mut specfx_model {
    guard(std::ptr::null_mut(), || {
        let t = text(toml, "toml")?;
        let dp = specfx::input::datapath_from_toml(t).map_err(|e| e.to_string())?;
        Ok(boxed(dp))
    })
}

/// Frees a model (null is ignored). The model must not be used afterwards.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_free(model: *mut specfx_model) {
    if !model.is_null() {
        // SAFETY: made by Box::into_raw in `boxed`, freed once (the caller's contract).
        drop(unsafe { Box::from_raw(model) });
    }
}

/// How many exponents the model's n set holds; -1 on failure.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_n_count(model: *const specfx_model) -> c_int {
    guard(SPECFX_ERROR, || {
        Ok(c_int::try_from(deref(model)?.dp.constants().len()).unwrap_or(c_int::MAX))
    })
}

/// The exponent at index `i` (ascending) of the model's n set; -1 on failure.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_n_at(model: *const specfx_model, i: c_int) -> c_int {
    guard(SPECFX_ERROR, || {
        let m = deref(model)?;
        let all = m.dp.constants();
        usize::try_from(i)
            .ok()
            .and_then(|i| all.get(i))
            .map(|nc| nc.n as c_int)
            .ok_or_else(|| {
                format!(
                    "i = {i} is not an index of the n set (expected 0..{})",
                    all.len()
                )
            })
    })
}

/// The input format's smallest and largest raw codes and the code of 1.0.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_input_codes(
    model: *const specfx_model,
    min: *mut i64,
    max: *mut i64,
    one: *mut i64,
) -> c_int {
    guard(SPECFX_ERROR, || {
        let dp = &deref(model)?.dp;
        let (min, max, one) = (place(min, "min")?, place(max, "max")?, place(one, "one")?);
        min.set(*dp.input_codes().start());
        max.set(*dp.input_codes().end());
        one.set(dp.one_code());
        Ok(SPECFX_OK)
    })
}

/// How many stages the model has (k + 5: d, t, b, the k squarings, coef, out); -1 on failure.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_stage_count(model: *const specfx_model) -> c_int {
    guard(
        SPECFX_ERROR,
        || Ok(deref(model)?.dp.stages().len() as c_int),
    )
}

fn stage_index(m: &specfx_model, stage: c_int) -> Result<usize, String> {
    let count = m.dp.stages().len();
    usize::try_from(stage)
        .ok()
        .filter(|&s| s < count)
        .ok_or_else(|| format!("stage = {stage} is not a stage index (expected 0..{count})"))
}

/// The name of stage `stage` (`d`, `t`, `b`, `sq1`.., `coef`, `out`), valid as long as the
/// model; null on failure.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_stage_name(model: *const specfx_model, stage: c_int) -> *const c_char {
    guard(std::ptr::null(), || {
        let m = deref(model)?;
        Ok(m.names[stage_index(m, stage)?].as_ptr())
    })
}

/// The format of stage `stage`: its signedness (1 signed), integer bits (the sign included)
/// and fraction bits. Stage -1 is the input c.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_stage_format(
    model: *const specfx_model,
    stage: c_int,
    is_signed: *mut c_int,
    int_bits: *mut c_int,
    frac_bits: *mut c_int,
) -> c_int {
    guard(SPECFX_ERROR, || {
        let m = deref(model)?;
        let (is_signed, int_bits, frac_bits) = (
            place(is_signed, "is_signed")?,
            place(int_bits, "int_bits")?,
            place(frac_bits, "frac_bits")?,
        );
        let f = if stage == -1 {
            m.dp.config().c.format
        } else {
            m.dp.stages()[stage_index(m, stage)?].format
        };
        is_signed.set(c_int::from(f.is_signed()));
        int_bits.set(f.int_bits());
        frac_bits.set(f.frac_bits());
        Ok(SPECFX_OK)
    })
}

/// The constants of exponent `n` into `*out`.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_constants_of(
    model: *const specfx_model,
    n: u32,
    out: *mut specfx_constants,
) -> c_int {
    guard(SPECFX_ERROR, || {
        let out = place(out, "out")?;
        let nc = deref(model)?
            .dp
            .constants_checked(n, "n")
            .map_err(|e| e.to_string())?;
        let c = specfx_constants {
            n: nc.n,
            slope: nc.slope_raw,
            slope_frac: nc.slope_frac,
            offset: nc.offset_raw,
            offset_frac: nc.offset_frac,
            has_threshold: i32::from(nc.threshold.is_some()),
            threshold: nc.threshold.unwrap_or(0),
            coef: nc.coef_raw,
            depth: nc.depth,
        };
        out.set(c);
        Ok(SPECFX_OK)
    })
}

/// The output code of one input code `c` and exponent `n` into `*out`. An `n` outside the
/// model's set or a `c` outside its input format is an error.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_eval(model: *const specfx_model, c: i64, n: u32, out: *mut i64) -> c_int {
    guard(SPECFX_ERROR, || {
        let dp = &deref(model)?.dp;
        let out = place(out, "out")?;
        out.set(dp.eval_out(c, n).map_err(|e| e.to_string())?);
        Ok(SPECFX_OK)
    })
}

/// Every stage's value (`values[SPECFX_MAX_STAGES]`, indexed like `specfx_stage_name`) and
/// overflow event (`events[SPECFX_MAX_STAGES]`: 0 none, 1 wrapped, 2 saturated, 3 zeroed) of
/// one evaluation, whether the cutoff forced the base to zero (`*cut`) and whether the input
/// was above 1.0 (`*clamped`). `events`, `cut` and `clamped` may be null.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_eval_probes(
    model: *const specfx_model,
    c: i64,
    n: u32,
    values: *mut i64,
    events: *mut u8,
    cut: *mut c_int,
    clamped: *mut c_int,
) -> c_int {
    guard(SPECFX_ERROR, || {
        let dp = &deref(model)?.dp;
        if values.is_null() {
            return Err("values: a null pointer, expected SPECFX_MAX_STAGES places".into());
        }
        let p = pairs::eval_one(dp, c, n).map_err(|e| e.to_string())?;
        // SAFETY: the caller gives SPECFX_MAX_STAGES places (documented); non-null checked.
        unsafe { std::slice::from_raw_parts_mut(values, MAX_STAGES) }.copy_from_slice(&p.values);
        if !events.is_null() {
            // SAFETY: as values.
            let ev = unsafe { std::slice::from_raw_parts_mut(events, MAX_STAGES) };
            for (e, &p) in ev.iter_mut().zip(&p.events) {
                *e = pairs::event_code(p);
            }
        }
        if let Some(cut) = optional_place(cut) {
            cut.set(c_int::from(p.cut));
        }
        if let Some(clamped) = optional_place(clamped) {
            clamped.set(c_int::from(p.input_clamped));
        }
        Ok(SPECFX_OK)
    })
}

/// Whether `a_len` places of `A` at `a` and `b_len` places of `B` at `b` share a byte.
fn overlaps<A, B>(a: *const A, a_len: usize, b: *const B, b_len: usize) -> bool {
    let (a0, b0) = (a as usize, b as usize);
    let a1 = a0.saturating_add(a_len.saturating_mul(std::mem::size_of::<A>()));
    let b1 = b0.saturating_add(b_len.saturating_mul(std::mem::size_of::<B>()));
    a0 < b1 && b0 < a1
}

/// A copy of `len` places at `p` (non-null), or the error when it cannot be allocated.
fn copy_of<T: Copy>(p: *const T, len: usize, what: &str) -> Result<Vec<T>, String> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| {
        format!("{what}: cannot allocate a copy of {len} elements (it overlaps out)")
    })?;
    // SAFETY: non-null, len places (the caller's contract); no mutable reference to them
    // exists yet.
    v.extend_from_slice(unsafe { std::slice::from_raw_parts(p, len) });
    Ok(v)
}

/// The output codes of `len` input codes `c[i]` into `out[i]`, with exponent `n[i]`, or
/// `n_all` for every code when `n` is null; in parallel on every core. Nothing is written
/// unless every pair is in the model's domain. `out` may be `c` (or overlap `c` or `n`): the
/// outputs are then computed in place, from a copy of the inputs.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_eval_batch(
    model: *const specfx_model,
    c: *const i64,
    n: *const u32,
    n_all: u32,
    len: usize,
    out: *mut i64,
) -> c_int {
    guard(SPECFX_ERROR, || {
        let dp = &deref(model)?.dp;
        if len > 0 && (c.is_null() || out.is_null()) {
            return Err("c, out: a null pointer, expected len places".into());
        }
        let most = isize::MAX as usize / std::mem::size_of::<i64>();
        if len > most {
            return Err(format!("len = {len}: expected at most {most}"));
        }
        if len == 0 {
            let ns = if n.is_null() {
                Ns::One(n_all)
            } else {
                Ns::Each(&[])
            };
            pairs::eval_outputs(dp, &[], ns, &mut []).map_err(|e| e.to_string())?;
            return Ok(SPECFX_OK);
        }
        // Inputs that share memory with out are copied before out is borrowed: the result is
        // the one a separate out gets (a slice and a mutable one over the same memory would
        // be undefined behaviour).
        let c_copy = if overlaps(c, len, out, len) {
            Some(copy_of(c, len, "c")?)
        } else {
            None
        };
        let n_copy = if !n.is_null() && overlaps(n, len, out, len) {
            Some(copy_of(n, len, "n")?)
        } else {
            None
        };
        // SAFETY: non-null, and the caller gives len places in each (documented); out overlaps
        // no slice read below (overlapping inputs were copied).
        let (cs, out) = unsafe {
            (
                c_copy
                    .as_deref()
                    .unwrap_or_else(|| std::slice::from_raw_parts(c, len)),
                std::slice::from_raw_parts_mut(out, len),
            )
        };
        let ns = match (&n_copy, n.is_null()) {
            (Some(ns), _) => Ns::Each(ns),
            (None, true) => Ns::One(n_all),
            // SAFETY: as c.
            (None, false) => Ns::Each(unsafe { std::slice::from_raw_parts(n, len) }),
        };
        pairs::eval_outputs(dp, cs, ns, out).map_err(|e| e.to_string())?;
        Ok(SPECFX_OK)
    })
}

// The DPI-C face: the types SystemVerilog's two-state `chandle`, `string`, `int` and
// `longint` map to (void*, const char*, int, long long), one scalar per argument, as
// hdl_ref/dpi/specfx_dpi.sv imports them.

fn dpi_model<'a>(m: *mut c_void) -> Result<&'a specfx_model, String> {
    deref(m as *const specfx_model)
}

/// DPI: `specfx_open` (`chandle specfx_dpi_open(string config)`); null on failure.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_open(config: *const c_char) -> *mut c_void {
    specfx_open(config) as *mut c_void
}

/// DPI: `specfx_free`.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_free(model: *mut c_void) {
    specfx_free(model as *mut specfx_model)
}

/// DPI: `specfx_last_error`.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_last_error() -> *const c_char {
    specfx_last_error()
}

/// DPI: `specfx_n_count`.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_n_count(model: *mut c_void) -> c_int {
    specfx_n_count(model as *const specfx_model)
}

/// DPI: `specfx_n_at`.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_n_at(model: *mut c_void, i: c_int) -> c_int {
    specfx_n_at(model as *const specfx_model, i)
}

/// DPI: the input format's smallest and largest codes and the code of 1.0.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_input_codes(
    model: *mut c_void,
    min: *mut c_longlong,
    max: *mut c_longlong,
    one: *mut c_longlong,
) -> c_int {
    specfx_input_codes(model as *const specfx_model, min, max, one)
}

/// DPI: one per-n constant as `specfx_top`'s port takes it (`which`: `SPECFX_SLOPE`,
/// `SPECFX_OFFSET`, `SPECFX_THRESHOLD`, `SPECFX_COEF`, `SPECFX_DEPTH`).
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_constant(
    model: *mut c_void,
    n: c_int,
    which: c_int,
    value: *mut c_longlong,
) -> c_int {
    guard(SPECFX_ERROR, || {
        let value = place(value, "value")?;
        let nc = dpi_model(model)?
            .dp
            .constants_checked(n_of(n)?, "n")
            .map_err(|e| e.to_string())?;
        let per_n = usize::try_from(which)
            .ok()
            .and_then(|i| PerN::ALL.get(i))
            .ok_or_else(|| {
                format!(
                    "which = {which}: expected 0 (slope), 1 (offset), 2 (threshold), 3 (coef) or 4 (depth)"
                )
            })?;
        let v = per_n.raw(nc);
        value.set(v);
        Ok(SPECFX_OK)
    })
}

/// DPI: `specfx_eval` (`int specfx_dpi_eval(chandle, longint c, int n, output longint out)`).
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_eval(
    model: *mut c_void,
    c: c_longlong,
    n: c_int,
    out: *mut c_longlong,
) -> c_int {
    guard(SPECFX_ERROR, || {
        let n = n_of(n)?;
        Ok(specfx_eval(model as *const specfx_model, c, n, out))
    })
}

/// DPI: one stage's value and overflow event (0 none, 1 wrapped, 2 saturated, 3 zeroed) of
/// one evaluation, the stage indexed like `specfx_stage_name`.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_probe(
    model: *mut c_void,
    c: c_longlong,
    n: c_int,
    stage: c_int,
    value: *mut c_longlong,
    event: *mut c_int,
) -> c_int {
    guard(SPECFX_ERROR, || {
        let m = dpi_model(model)?;
        let s = stage_index(m, stage)?;
        let (value, event) = (place(value, "value")?, place(event, "event")?);
        let p = pairs::eval_one(&m.dp, c, n_of(n)?).map_err(|e| e.to_string())?;
        value.set(p.values[s]);
        event.set(c_int::from(pairs::event_code(p.events[s])));
        Ok(SPECFX_OK)
    })
}

/// DPI: the first input code of `n` the cutoff does not force to zero, where the
/// configuration proves the cut codes are a prefix (else the smallest code): a boundary a
/// constrained-random testbench aims at.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_first_live(
    model: *mut c_void,
    n: c_int,
    code: *mut c_longlong,
) -> c_int {
    guard(SPECFX_ERROR, || {
        let dp = &dpi_model(model)?.dp;
        let code = place(code, "code")?;
        let nc = dp
            .constants_checked(n_of(n)?, "n")
            .map_err(|e| e.to_string())?;
        let codes = dp.input_codes();
        code.set(dp.first_live_code(nc, *codes.start()..*codes.end() + 1));
        Ok(SPECFX_OK)
    })
}

/// The cycle model of one architecture, stepped in lockstep with a simulation of
/// `specfx_top` (made by `specfx_dpi_machine_new`, freed by `specfx_dpi_machine_free`).
pub struct specfx_machine {
    dp: Arc<Datapath>,
    lockstep: Lockstep,
}

/// DPI: a cycle model of `arch` (0 pipelined, 1 folded, as `specfx_top`'s `ARCH`) for the
/// model, empty as after reset; null on failure. It keeps the model's datapath alive.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_machine_new(model: *mut c_void, arch: c_int) -> *mut c_void {
    guard(std::ptr::null_mut(), || {
        let dp = dpi_model(model)?.dp.clone();
        let arch = match arch {
            0 => Arch::Pipelined,
            1 => Arch::Folded,
            _ => {
                return Err(format!(
                    "arch = {arch}: expected 0 (pipelined) or 1 (folded)"
                ))
            }
        };
        let lockstep = Lockstep::new(&dp, arch);
        Ok(Box::into_raw(Box::new(specfx_machine { dp, lockstep })) as *mut c_void)
    })
}

/// DPI: frees a cycle model (null is ignored).
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_machine_free(machine: *mut c_void) {
    if !machine.is_null() {
        // SAFETY: made by Box::into_raw in specfx_dpi_machine_new, freed once.
        drop(unsafe { Box::from_raw(machine as *mut specfx_machine) });
    }
}

/// DPI: one clock cycle of the cycle model. Given this cycle's `in_valid` (with the input
/// `c`, `n` it offers) and `out_ready`, writes what `specfx_top`'s ports must show during the
/// cycle (`in_ready`, `out_valid`, `out_data`, and `out_tag`, the 0-based number of the input
/// the output belongs to), then takes the clock edge. A failure (a null pointer, an input
/// outside the model's domain while `in_valid` is high) writes nothing and takes no edge: the
/// machine is as before the call.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub extern "C" fn specfx_dpi_machine_cycle(
    machine: *mut c_void,
    in_valid: c_int,
    c: c_longlong,
    n: c_int,
    out_ready: c_int,
    in_ready: *mut c_int,
    out_valid: *mut c_int,
    out_data: *mut c_longlong,
    out_tag: *mut c_longlong,
) -> c_int {
    guard(SPECFX_ERROR, || {
        // SAFETY: a non-null pointer from specfx_dpi_machine_new, not freed, used by one
        // thread at a time (the caller's contract).
        let m = unsafe { (machine as *mut specfx_machine).as_mut() }
            .ok_or("machine: a null pointer, expected a cycle model")?;
        // Every argument is checked before the clock edge: a failed call leaves the machine
        // as it was (Lockstep::cycle refuses an input outside the domain before it moves).
        let (in_ready, out_valid, out_data, out_tag) = (
            place(in_ready, "in_ready")?,
            place(out_valid, "out_valid")?,
            place(out_data, "out_data")?,
            place(out_tag, "out_tag")?,
        );
        let input = if in_valid != 0 {
            Some((c, n_of(n)?))
        } else {
            None
        };
        let ports = m
            .lockstep
            .cycle(&m.dp, input, out_ready != 0)
            .map_err(|e| e.to_string())?;
        in_ready.set(c_int::from(ports.in_ready));
        out_valid.set(c_int::from(ports.out.is_some()));
        let (tag, data) = ports.out.unwrap_or((0, 0));
        out_data.set(data);
        out_tag.set(tag as c_longlong);
        Ok(SPECFX_OK)
    })
}

/// The directed cases of `specfx vectors` for the model (every n's corner cases: the ends of
/// the code range, 1.0 and above, every cutoff switch +-1 code; codes with a non-zero output;
/// the inputs on and next to every stage's rounding boundary), interleaved (seed 1).
fn directed(m: &specfx_model) -> Result<&[(u32, i64)], String> {
    m.directed
        .get_or_init(|| specfx::golden::cases::directed(&m.dp, 1).map_err(|e| e.to_string()))
        .as_ref()
        .map(Vec::as_slice)
        .map_err(Clone::clone)
}

/// DPI: how many directed cases the model has (see `specfx_dpi_directed_at`); -1 on failure.
/// The first call computes them (a search of every stage's rounding boundaries).
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_directed_count(model: *mut c_void) -> c_int {
    guard(SPECFX_ERROR, || {
        Ok(c_int::try_from(directed(dpi_model(model)?)?.len()).unwrap_or(c_int::MAX))
    })
}

/// DPI: directed case `i`: the cases `specfx vectors` always writes (corners, codes with a
/// non-zero output, every stage's rounding boundaries), interleaved.
#[unsafe(no_mangle)]
pub extern "C" fn specfx_dpi_directed_at(
    model: *mut c_void,
    i: c_int,
    n: *mut c_int,
    c: *mut c_longlong,
) -> c_int {
    guard(SPECFX_ERROR, || {
        let (n, c) = (place(n, "n")?, place(c, "c")?);
        let all = directed(dpi_model(model)?)?;
        let &(nv, cv) = usize::try_from(i)
            .ok()
            .and_then(|i| all.get(i))
            .ok_or_else(|| format!("i = {i} is not a directed case (expected 0..{})", all.len()))?;
        n.set(nv as c_int);
        c.set(cv);
        Ok(SPECFX_OK)
    })
}
