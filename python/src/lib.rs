//! The native half of the `specfx` Python package (`specfx._specfx`): a face of
//! `specfx::input` (the model from a configuration) and `specfx::engine::pairs` (evaluations
//! checked against the model's domain), with the GIL released during batch work. The Python
//! half (`specfx/__init__.py`) turns numpy arrays of any integer type and shape into the
//! contiguous 1-D arrays these functions take, and their results back.

use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadwriteArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use std::sync::{Arc, Mutex};

use specfx::cycle::lockstep::Lockstep;
use specfx::engine::pairs::{self, Ns};

/// (n, c) arrays of cases.
type Cases<'py> = (Bound<'py, PyArray1<u32>>, Bound<'py, PyArray1<i64>>);

/// A specfx error as Python's `ValueError`, with the command line's message.
fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
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
    }

    /// The model of a configuration's TOML text.
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Model> {
        let dp = specfx::input::datapath_from_toml(text).map_err(value_error)?;
        Ok(Model { dp: Arc::new(dp) })
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
    }

    /// The output code of one input code and exponent.
    fn eval(&self, c: i64, n: u32) -> PyResult<i64> {
        let p = pairs::eval_one(&self.dp, c, n).map_err(value_error)?;
        Ok(p.values[self.dp.stage_out()])
    }

    /// The output codes of `c[i]` with `n[i]` (or `n_all` for every code when `n` is None), on
    /// every core with the GIL released.
    #[pyo3(signature = (c, n, n_all))]
    fn eval_array<'py>(
        &self,
        py: Python<'py>,
        c: PyReadonlyArray1<'py, i64>,
        n: Option<PyReadonlyArray1<'py, u32>>,
        n_all: u32,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let cs = c.as_slice()?;
        let ns = exponents(&n, n_all)?;
        let out = py
            .detach(|| pairs::eval_outputs_vec(&self.dp, cs, ns))
            .map_err(value_error)?;
        Ok(out.into_pyarray(py))
    }

    /// [`Model::eval_array`] into `out` (as long as `c`), in one pass: on an error (a pair
    /// outside the model's domain) `out` may hold some outputs, as numpy's `out=`.
    #[pyo3(signature = (c, n, n_all, out))]
    fn eval_into<'py>(
        &self,
        py: Python<'py>,
        c: PyReadonlyArray1<'py, i64>,
        n: Option<PyReadonlyArray1<'py, u32>>,
        n_all: u32,
        mut out: PyReadwriteArray1<'py, i64>,
    ) -> PyResult<()> {
        let cs = c.as_slice()?;
        let ns = exponents(&n, n_all)?;
        let out = out.as_slice_mut()?;
        py.detach(|| pairs::eval_outputs_streaming(&self.dp, cs, ns, out))
            .map_err(value_error)
    }

    /// Every stage's value (a stages x len array), overflow event (0 none, 1 wrapped,
    /// 2 saturated, 3 zeroed; stages x len), whether the cutoff forced the base to zero and
    /// whether the input was above 1.0, for every pair, with the GIL released.
    #[allow(clippy::type_complexity)]
    #[pyo3(signature = (c, n, n_all))]
    fn probes_array<'py>(
        &self,
        py: Python<'py>,
        c: PyReadonlyArray1<'py, i64>,
        n: Option<PyReadonlyArray1<'py, u32>>,
        n_all: u32,
    ) -> PyResult<(
        Bound<'py, PyArray2<i64>>,
        Bound<'py, PyArray2<u8>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
    )> {
        let cs = c.as_slice()?;
        let ns = exponents(&n, n_all)?;
        let stages = self.dp.stages().len();
        let len = cs.len();
        let (values, events, cut, clamped) = py
            .detach(|| {
                let probes = pairs::eval_probes(&self.dp, cs, ns)?;
                let mut values = vec![0i64; stages * len];
                let mut events = vec![0u8; stages * len];
                for (i, p) in probes.iter().enumerate() {
                    for s in 0..stages {
                        values[s * len + i] = p.values[s];
                        events[s * len + i] = pairs::event_code(p.events[s]);
                    }
                }
                let cut: Vec<bool> = probes.iter().map(|p| p.cut).collect();
                let clamped: Vec<bool> = probes.iter().map(|p| p.input_clamped).collect();
                Ok::<_, specfx::Error>((values, events, cut, clamped))
            })
            .map_err(value_error)?;
        let shape = |v: Vec<i64>| numpy::ndarray::Array2::from_shape_vec((stages, len), v);
        let values = shape(values).map_err(value_error)?.into_pyarray(py);
        let events = numpy::ndarray::Array2::from_shape_vec((stages, len), events)
            .map_err(value_error)?
            .into_pyarray(py);
        Ok((
            values,
            events,
            cut.into_pyarray(py),
            clamped.into_pyarray(py),
        ))
    }

    /// The directed cases `specfx vectors` always writes (every n's corners, codes with a
    /// non-zero output, the inputs on and next to every stage's rounding boundary),
    /// interleaved with `seed`: (n, c) arrays.
    fn directed<'py>(&self, py: Python<'py>, seed: u64) -> PyResult<Cases<'py>> {
        let sel = specfx::golden::CaseSelection {
            corner: true,
            exhaustive: false,
            random: 0,
        };
        let mut cases = py
            .detach(|| specfx::golden::cases::select(&self.dp, &sel, seed))
            .map_err(value_error)?
            .cases;
        specfx::golden::cases::order(&mut cases, specfx::golden::Order::Interleaved, seed);
        let (n, c): (Vec<u32>, Vec<i64>) = cases.into_iter().unzip();
        Ok((n.into_pyarray(py), c.into_pyarray(py)))
    }

    /// The exhaustive check's report as JSON text (what `specfx check --json` prints), with the
    /// GIL released.
    fn check_json(&self, py: Python<'_>) -> PyResult<String> {
        let report = py
            .detach(|| specfx::analysis::check::check(&self.dp))
            .map_err(|e| value_error(format!("config {}: {e}", self.dp.config().name)))?;
        serde_json::to_string(&report).map_err(value_error)
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
        let arch: specfx::cycle::Arch = arch.parse().map_err(value_error)?;
        Ok(Machine {
            dp: model.dp.clone(),
            lockstep: Mutex::new(Lockstep::new(&model.dp, arch)),
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
        let mut ls = self.lockstep.lock().map_err(value_error)?;
        let p = ls.cycle(&self.dp, input, out_ready).map_err(value_error)?;
        Ok((p.in_ready, p.out))
    }

    /// The RTL core's registers now, under the RTL's names below `u_core`: (name, width,
    /// value or None when the register holds no valid data).
    fn registers(&self) -> PyResult<Vec<(String, u32, Option<u128>)>> {
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
