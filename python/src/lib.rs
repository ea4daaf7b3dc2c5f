//! The native half of the `specfx` Python package (`specfx._specfx`): a face of
//! `specfx::input` (the model from a configuration) and `specfx::engine::pairs` (evaluations
//! checked against the model's domain), with the GIL released during batch work. The Python
//! half (`specfx/__init__.py`) turns numpy arrays of any integer type and shape into the
//! contiguous 1-D arrays these functions take, and their results back.
//!
//! Nothing panics across the boundary: arrays are borrowed with numpy's checked borrows (a
//! read-only `out` is a `ValueError`, an `out` overlapping an input is computed in place from a
//! copy of the inputs), large outputs are allocated fallibly (`MemoryError`), and every body
//! runs under [`guarded`], which turns a panic (a bug) into `RuntimeError`.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{Arc, Mutex};

use numpy::{
    BorrowError, IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1,
    PyReadwriteArray1,
};
use pyo3::exceptions::{PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use specfx::cycle::lockstep::Lockstep;
use specfx::engine::pairs::{self, Ns};

/// (n, c) arrays of cases.
type Cases<'py> = (Bound<'py, PyArray1<u32>>, Bound<'py, PyArray1<i64>>);

/// Pairs per call of `pairs::eval_probes` in `probes_array`: the library's vector of probes
/// (about 120 bytes a pair) stays small, whatever the batch.
const PROBE_PIECE: usize = 1 << 16;

/// A specfx error as Python's `ValueError`, with the command line's message.
fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// Runs a native function's body, turning a panic into Python's `RuntimeError` (with the
/// panic's message) instead of PyO3's `PanicException`, which `except Exception` does not
/// catch. Every input is checked, so a panic here is a bug; this is only the last guard.
fn guarded<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|panic| {
        let what = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown".to_string());
        Err(PyRuntimeError::new_err(format!(
            "specfx: internal error: {}",
            what.replace('\n', " ")
        )))
    })
}

/// Why an array could not be borrowed, as a `ValueError` naming the argument.
fn borrow_error(e: BorrowError, what: &str) -> PyErr {
    match e {
        BorrowError::NotWriteable => value_error(format!("{what}: output array is read-only")),
        _ => value_error(format!(
            "{what}: the array is in use by another specfx call running now (as its out=)"
        )),
    }
}

/// An array borrowed to be read (refused while another call writes it, never a panic).
fn read<'py, T: numpy::Element>(
    a: &Bound<'py, PyArray1<T>>,
    what: &str,
) -> PyResult<PyReadonlyArray1<'py, T>> {
    a.try_readonly().map_err(|e| borrow_error(e, what))
}

/// A vector of `len` zeros, or `MemoryError` when it cannot be allocated (instead of the
/// process aborting).
fn zeroed<T: Clone + Default>(len: usize, what: &str) -> PyResult<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| {
        PyMemoryError::new_err(format!(
            "{what}: cannot allocate {} bytes for {len} elements",
            len.saturating_mul(std::mem::size_of::<T>())
        ))
    })?;
    v.resize(len, T::default());
    Ok(v)
}

/// A copy of `xs`, or `MemoryError`.
fn copied<T: Clone + Default>(xs: &[T], what: &str) -> PyResult<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(xs.len()).map_err(|_| {
        PyMemoryError::new_err(format!(
            "{what}: cannot allocate {} bytes for a copy of {} elements",
            xs.len().saturating_mul(std::mem::size_of::<T>()),
            xs.len()
        ))
    })?;
    v.extend_from_slice(xs);
    Ok(v)
}

/// The exponents of a batch: `n[i]` for each code, or `n_all` for all when `n` is None.
fn exponents<'a>(n: &'a Option<PyReadonlyArray1<'_, u32>>, n_all: u32) -> PyResult<Ns<'a>> {
    Ok(match n {
        Some(n) => Ns::Each(n.as_slice()?),
        None => Ns::One(n_all),
    })
}

/// A validated datapath (the native half of `specfx.Datapath`).
#[pyclass(frozen, module = "specfx._specfx")]
struct Model {
    dp: Arc<specfx::pipeline::Datapath>,
}

#[pymethods]
impl Model {
    /// The model a `--config` argument names (a built-in name, a TOML file, a vector
    /// directory), with `n` (e.g. "16..=64") replacing its exponent set.
    #[staticmethod]
    #[pyo3(signature = (config, n=None))]
    fn open(py: Python<'_>, config: &str, n: Option<&str>) -> PyResult<Model> {
        guarded(|| {
            let n = n
                .map(|t| {
                    t.parse::<specfx::nset::NSet>()
                        .map_err(|e| value_error(format!("n: {e}")))
                })
                .transpose()?;
            let dp = py
                .detach(|| specfx::input::load_datapath(config, n.as_ref()))
                .map_err(value_error)?;
            Ok(Model { dp: Arc::new(dp) })
        })
    }

    /// The model of a configuration's TOML text.
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Model> {
        guarded(|| {
            let dp = specfx::input::datapath_from_toml(text).map_err(value_error)?;
            Ok(Model { dp: Arc::new(dp) })
        })
    }

    /// The configuration's name.
    fn name(&self) -> String {
        self.dp.config().name.clone()
    }

    /// The configuration as TOML (every key).
    fn toml(&self) -> String {
        self.dp.config().to_toml()
    }

    /// The number of squarings k.
    fn k(&self) -> u32 {
        self.dp.config().k
    }

    /// The exponents, ascending.
    fn n(&self) -> Vec<u32> {
        self.dp.config().n.values().to_vec()
    }

    /// The stages: (name, format) in evaluation order, the input `c` first.
    fn formats(&self) -> Vec<(String, String)> {
        std::iter::once(("c".to_string(), self.dp.config().c.format.to_string()))
            .chain(
                self.dp
                    .stages()
                    .iter()
                    .map(|s| (s.name.clone(), s.format.to_string())),
            )
            .collect()
    }

    /// The input format's smallest and largest raw codes and the code of 1.0.
    fn input_codes(&self) -> (i64, i64, i64) {
        let codes = self.dp.input_codes();
        (*codes.start(), *codes.end(), self.dp.one_code())
    }

    /// The constants of `n`: (slope, slope_frac, offset, offset_frac, threshold or None,
    /// coef, slope_value, offset_value, coef_value, depth).
    #[allow(clippy::type_complexity)]
    fn constants(
        &self,
        n: u32,
    ) -> PyResult<(i64, i32, i64, i32, Option<i64>, i64, f64, f64, f64, u32)> {
        guarded(|| {
            let nc = self.dp.constants_checked(n, "n").map_err(value_error)?;
            Ok((
                nc.slope_raw,
                nc.slope_frac,
                nc.offset_raw,
                nc.offset_frac,
                nc.threshold,
                nc.coef_raw,
                nc.slope,
                nc.offset,
                nc.coef,
                nc.depth,
            ))
        })
    }

    /// The output code of one input code and exponent.
    fn eval(&self, c: i64, n: u32) -> PyResult<i64> {
        guarded(|| self.dp.eval_out(c, n).map_err(value_error))
    }

    /// The output codes of `c[i]` with `n[i]` (or `n_all` for every code when `n` is None), on
    /// every core with the GIL released; `MemoryError` when the output cannot be allocated.
    #[pyo3(signature = (c, n, n_all))]
    fn eval_array<'py>(
        &self,
        py: Python<'py>,
        c: Bound<'py, PyArray1<i64>>,
        n: Option<Bound<'py, PyArray1<u32>>>,
        n_all: u32,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        guarded(|| {
            let c = read(&c, "c")?;
            let n = n.as_ref().map(|n| read(n, "n")).transpose()?;
            let cs = c.as_slice()?;
            let ns = exponents(&n, n_all)?;
            let mut out = zeroed::<i64>(cs.len(), "out")?;
            py.detach(|| pairs::eval_outputs_streaming(&self.dp, cs, ns, &mut out))
                .map_err(value_error)?;
            Ok(out.into_pyarray(py))
        })
    }

    /// [`Model::eval_array`] into `out` (as long as `c`), in one pass: on an error (a pair
    /// outside the model's domain) `out` may hold some outputs, as numpy's `out=`. A read-only
    /// `out` is a `ValueError`; an `out` that is (or overlaps) `c` or `n` is computed in place
    /// (the inputs are copied first).
    #[pyo3(signature = (c, n, n_all, out))]
    fn eval_into<'py>(
        &self,
        py: Python<'py>,
        c: Bound<'py, PyArray1<i64>>,
        n: Option<Bound<'py, PyArray1<u32>>>,
        n_all: u32,
        out: Bound<'py, PyArray1<i64>>,
    ) -> PyResult<()> {
        guarded(|| {
            let c_read = read(&c, "c")?;
            let n_read = n.as_ref().map(|n| read(n, "n")).transpose()?;
            let into = |out: &mut PyReadwriteArray1<'py, i64>, cs: &[i64], ns: Ns| {
                let out = out.as_slice_mut()?;
                py.detach(|| pairs::eval_outputs_streaming(&self.dp, cs, ns, out))
                    .map_err(value_error)
            };
            match out.try_readwrite() {
                Ok(mut o) => into(&mut o, c_read.as_slice()?, exponents(&n_read, n_all)?),
                Err(BorrowError::AlreadyBorrowed) => {
                    // `out` overlaps an input (eval(c, 64, out=c)), or another call writes it:
                    // the inputs copied and their borrows released, `out` is borrowed again.
                    let cs = copied(c_read.as_slice()?, "c")?;
                    let ns = match &n_read {
                        Some(n) => Some(copied(n.as_slice()?, "n")?),
                        None => None,
                    };
                    drop((c_read, n_read));
                    let mut o = out.try_readwrite().map_err(|e| borrow_error(e, "out"))?;
                    let ns = match &ns {
                        Some(ns) => Ns::Each(ns),
                        None => Ns::One(n_all),
                    };
                    into(&mut o, &cs, ns)
                }
                Err(e) => Err(borrow_error(e, "out")),
            }
        })
    }

    /// Every stage's value (a stages x len array), overflow event (0 none, 1 wrapped,
    /// 2 saturated, 3 zeroed; stages x len), whether the cutoff forced the base to zero and
    /// whether the input was above 1.0, for every pair, with the GIL released; the pairs are
    /// checked whole first, then evaluated piece by piece; `MemoryError` when the arrays cannot
    /// be allocated.
    #[allow(clippy::type_complexity)]
    #[pyo3(signature = (c, n, n_all))]
    fn probes_array<'py>(
        &self,
        py: Python<'py>,
        c: Bound<'py, PyArray1<i64>>,
        n: Option<Bound<'py, PyArray1<u32>>>,
        n_all: u32,
    ) -> PyResult<(
        Bound<'py, PyArray2<i64>>,
        Bound<'py, PyArray2<u8>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
    )> {
        guarded(|| {
            let c = read(&c, "c")?;
            let n = n.as_ref().map(|n| read(n, "n")).transpose()?;
            let cs = c.as_slice()?;
            let ns = exponents(&n, n_all)?;
            let stages = self.dp.stages().len();
            let len = cs.len();
            let size = stages.checked_mul(len).ok_or_else(|| {
                PyMemoryError::new_err(format!("probes: {stages} x {len} values do not fit"))
            })?;
            let mut values = zeroed::<i64>(size, "probes")?;
            let mut events = zeroed::<u8>(size, "probes")?;
            let mut cut = zeroed::<bool>(len, "probes")?;
            let mut clamped = zeroed::<bool>(len, "probes")?;
            py.detach(|| {
                pairs::check_domain(&self.dp, cs, ns)?;
                for start in (0..len).step_by(PROBE_PIECE) {
                    let end = (start + PROBE_PIECE).min(len);
                    let piece_ns = match ns {
                        Ns::One(n) => Ns::One(n),
                        Ns::Each(ns) => Ns::Each(&ns[start..end]),
                    };
                    let probes = pairs::eval_probes(&self.dp, &cs[start..end], piece_ns)?;
                    for (i, p) in (start..end).zip(&probes) {
                        for s in 0..stages {
                            values[s * len + i] = p.values[s];
                            events[s * len + i] = pairs::event_code(p.events[s]);
                        }
                        cut[i] = p.cut;
                        clamped[i] = p.input_clamped;
                    }
                }
                Ok::<_, specfx::Error>(())
            })
            .map_err(value_error)?;
            let values = numpy::ndarray::Array2::from_shape_vec((stages, len), values)
                .map_err(value_error)?
                .into_pyarray(py);
            let events = numpy::ndarray::Array2::from_shape_vec((stages, len), events)
                .map_err(value_error)?
                .into_pyarray(py);
            Ok((
                values,
                events,
                cut.into_pyarray(py),
                clamped.into_pyarray(py),
            ))
        })
    }

    /// The directed cases `specfx vectors` always writes (every n's corners, codes with a
    /// non-zero output, the inputs on and next to every stage's rounding boundary),
    /// interleaved with `seed`: (n, c) arrays.
    fn directed<'py>(&self, py: Python<'py>, seed: u64) -> PyResult<Cases<'py>> {
        guarded(|| {
            let cases = py
                .detach(|| specfx::golden::cases::directed(&self.dp, seed))
                .map_err(value_error)?;
            let (n, c): (Vec<u32>, Vec<i64>) = cases.into_iter().unzip();
            Ok((n.into_pyarray(py), c.into_pyarray(py)))
        })
    }

    /// The exhaustive check's report as JSON text (what `specfx check --json` prints), with the
    /// GIL released.
    fn check_json(&self, py: Python<'_>) -> PyResult<String> {
        guarded(|| {
            let report = py
                .detach(|| specfx::analysis::check::check(&self.dp))
                .map_err(|e| value_error(format!("config {}: {e}", self.dp.config().name)))?;
            serde_json::to_string(&report).map_err(value_error)
        })
    }
}

/// The cycle model of one architecture, stepped in lockstep with a simulation of
/// `specfx_top` (docs/cycle.md).
#[pyclass(module = "specfx._specfx")]
struct Machine {
    dp: Arc<specfx::pipeline::Datapath>,
    lockstep: Mutex<Lockstep>,
}

#[pymethods]
impl Machine {
    /// An empty machine of `arch` (`pipelined` or `folded`) for the model, as after reset.
    #[new]
    fn new(model: &Model, arch: &str) -> PyResult<Machine> {
        guarded(|| {
            let arch: specfx::cycle::Arch = arch.parse().map_err(value_error)?;
            Ok(Machine {
                dp: model.dp.clone(),
                lockstep: Mutex::new(Lockstep::new(&model.dp, arch)),
            })
        })
    }

    /// One clock cycle: what the ports show during it (in_ready, and the output's
    /// (input number, raw code) or None when out_valid is low), given this cycle's offered
    /// input (None when in_valid is low) and out_ready; then the clock edge.
    #[pyo3(signature = (input, out_ready))]
    fn cycle(
        &self,
        input: Option<(i64, u32)>,
        out_ready: bool,
    ) -> PyResult<(bool, Option<(u64, i64)>)> {
        guarded(|| {
            let mut ls = self.lockstep.lock().map_err(value_error)?;
            // An input outside the domain is refused before the machine moves.
            let p = ls.cycle(&self.dp, input, out_ready).map_err(value_error)?;
            Ok((p.in_ready, p.out))
        })
    }

    /// The RTL core's registers now, under the RTL's names below `u_core`: (name, width,
    /// value or None when the register holds no valid data).
    fn registers(&self) -> PyResult<Vec<(String, u32, Option<u128>)>> {
        guarded(|| {
            let ls = self.lockstep.lock().map_err(value_error)?;
            Ok(ls
                .registers(&self.dp)
                .into_iter()
                .map(|r| {
                    let value = r.value.map(|w| {
                        (0..w.width().min(128)).fold(0u128, |v, i| v | (u128::from(w.bit(i)) << i))
                    });
                    (r.name, r.width, value)
                })
                .collect())
        })
    }
}

/// specfx's bit-accurate datapath model (native half).
#[pymodule]
fn _specfx(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Model>()?;
    m.add_class::<Machine>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
