//! The f64 interpreter of the datapath's walk ([`F64Walk`]): every step in `f64`, the error
//! sources in a mask quantized as the datapath quantizes them and every other step exact. With
//! no source it is the same algorithm without rounding (the reference of `check`, the stability
//! map's and the renderer's f64 model); with one source it is the budget's mixed model; with
//! every source it is the datapath itself wherever the f64 products are exact.

use crate::fixed::quantize_f64;
use crate::pipeline::walk::{walk, Arithmetic, Stage};
use crate::pipeline::{Datapath, NConstants, StageSpec, Variant, MAX_STAGES};

/// An error source: a quantization the datapath performs that the f64 model does not.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// The minimax constants A(n) and A(n) + B(n) rounded into their formats.
    Constants,
    /// The t stage (`t = slope * d`).
    T,
    /// The b stage (`b = t + offset`, after the cutoff).
    B,
    /// Squaring stage `i` (0-based).
    Square(usize),
    /// The coefficient rounded into its format.
    Coef,
    /// The output stage (`out = sq_k * coef`).
    Out,
}

impl Source {
    /// The bit of this source in a quantization mask of [`mixed_eval`].
    pub fn mask(self) -> u32 {
        match self {
            Source::Constants => 1,
            Source::T => 1 << 1,
            Source::B => 1 << 2,
            Source::Square(i) => 1 << (3 + i),
            Source::Coef => 1 << 11,
            Source::Out => 1 << 12,
        }
    }

    /// The stage this source quantizes (`None` for the minimax constants, which feed t and
    /// b but are no stage of their own).
    pub fn stage(self) -> Option<Stage> {
        match self {
            Source::Constants => None,
            Source::T => Some(Stage::T),
            Source::B => Some(Stage::B),
            Source::Square(i) => Some(Stage::Square(i)),
            Source::Coef => Some(Stage::Coef),
            Source::Out => Some(Stage::Out),
        }
    }

    /// The name reports use: `constants`, or the stage's name (`t`, `b`, `sq1`.., `coef`,
    /// `out`).
    pub fn name(self) -> String {
        self.stage()
            .map_or_else(|| "constants".to_string(), |s| s.to_string())
    }
}

/// The error sources of a datapath, in pipeline order. The plain variant's constants (n/m and
/// 1) are exact, so they are a source of the minimax variant only.
///
/// # Examples
/// ```
/// use specfx::pipeline::f64_walk::sources;
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let names: Vec<String> = sources(&dp).iter().map(|s| s.name()).collect();
/// assert_eq!(names, ["t", "b", "sq1", "sq2", "sq3", "sq4", "coef", "out"]);
/// ```
pub fn sources(dp: &Datapath) -> Vec<Source> {
    let cfg = dp.config();
    let mut v = Vec::new();
    if cfg.variant == Variant::Minimax {
        v.push(Source::Constants);
    }
    v.extend([Source::T, Source::B]);
    v.extend((0..cfg.k as usize).map(Source::Square));
    v.extend([Source::Coef, Source::Out]);
    v
}

/// A quantization mask with every source set: the mixed model then is the datapath itself
/// (whenever the f64 products are exact, that is for products of at most 53 bits).
pub const ALL_SOURCES: u32 = u32::MAX;

fn quantize_spec(x: f64, spec: &StageSpec) -> f64 {
    quantize_f64(x, spec.format, spec.rounding, spec.overflow)
        .map_or(x, |q| spec.format.to_f64(q.raw))
}

/// The `f64` interpreter of the datapath's walk ([`walk`]): every step in `f64`, the sources in
/// `mask` quantized as the datapath quantizes them and every other step exact. With `mask = 0`
/// it is the same algorithm without rounding, the reference of `check`.
pub struct F64Walk<'a> {
    dp: &'a Datapath,
    nc: &'a NConstants,
    /// The input, clamped to 1.0.
    c: f64,
    below: bool,
    mask: u32,
    slope: f64,
    offset: f64,
    /// The value of every stage, indexed like the datapath's probes.
    pub values: [f64; MAX_STAGES],
}

impl<'a> F64Walk<'a> {
    /// The interpreter for an input value `c` (clamped to 1.0 here); `below_threshold` says
    /// whether the paper cutoff cuts it.
    pub fn new(
        dp: &'a Datapath,
        nc: &'a NConstants,
        c: f64,
        below_threshold: bool,
        mask: u32,
    ) -> F64Walk<'a> {
        let on = mask & Source::Constants.mask() != 0;
        let (slope, offset) = if on {
            (
                nc.slope_raw as f64 * (-f64::from(nc.slope_frac)).exp2(),
                nc.offset_raw as f64 * (-f64::from(nc.offset_frac)).exp2(),
            )
        } else {
            (nc.slope, nc.offset)
        };
        F64Walk {
            dp,
            nc,
            c: c.min(1.0),
            below: below_threshold,
            mask,
            slope,
            offset,
            values: [0.0; MAX_STAGES],
        }
    }

    /// The interpreter for a raw input code (clamped to 1.0, exact in `f64`).
    pub fn at_code(dp: &'a Datapath, nc: &'a NConstants, c_raw: i64, mask: u32) -> F64Walk<'a> {
        let code = c_raw.min(dp.one_code());
        let c = code as f64 * dp.config().c.format.lsb();
        F64Walk::new(dp, nc, c, nc.below_threshold(code), mask)
    }

    /// Walks the datapath: returns (lobe, output); every stage's value is in `values`.
    pub fn run(&mut self) -> (f64, f64) {
        let cfg = self.dp.config();
        let w = walk(self, cfg.cutoff, cfg.k as usize, self.nc.depth as usize);
        (w.lobe, w.out)
    }

    fn on(&self, s: Source) -> bool {
        self.mask & s.mask() != 0
    }

    fn record(&mut self, stage: Stage, x: f64) -> f64 {
        self.values[stage.index(self.dp.config().k as usize)] = x;
        x
    }
}

impl Arithmetic for F64Walk<'_> {
    type Value = f64;

    fn sub(&mut self) -> f64 {
        self.record(Stage::D, self.c - 1.0)
    }

    fn below_threshold(&self) -> bool {
        self.below
    }

    fn mul_t(&mut self, d: f64) -> f64 {
        let mut t = self.slope * d;
        if self.on(Source::T) {
            t = quantize_spec(t, &self.dp.config().t);
        }
        self.record(Stage::T, t)
    }

    fn add_offset(&mut self, t: f64) -> f64 {
        t + self.offset
    }

    fn is_negative(&self, sum: f64) -> bool {
        sum < 0.0
    }

    fn zero(&self) -> f64 {
        0.0
    }

    fn quant_b(&mut self, mut base: f64) -> f64 {
        if self.on(Source::B) {
            base = quantize_spec(base, &self.dp.config().b);
        }
        self.record(Stage::B, base)
    }

    fn square(&mut self, i: usize, x: f64) -> f64 {
        let mut s = x * x;
        if self.on(Source::Square(i)) {
            s = quantize_spec(s, &self.dp.config().square[i]);
        }
        self.record(Stage::Square(i), s)
    }

    fn pass(&mut self, i: usize, mut x: f64) -> f64 {
        if self.on(Source::Square(i)) {
            x = quantize_spec(x, &self.dp.config().square[i]);
        }
        self.record(Stage::Square(i), x)
    }

    fn mul_out(&mut self, s: f64) -> f64 {
        let cfg = self.dp.config();
        let coef = if self.on(Source::Coef) {
            cfg.coef.format.to_f64(self.nc.coef_raw)
        } else {
            self.nc.coef
        };
        self.record(Stage::Coef, coef);
        let mut out = s * coef;
        if self.on(Source::Out) {
            out = quantize_spec(out, &cfg.out);
        }
        self.record(Stage::Out, out)
    }
}

/// The f64 model of the datapath with the sources in `mask` quantized as the datapath
/// quantizes them and everything else exact: returns (lobe, output). It is [`F64Walk`] at a
/// raw input code.
///
/// With `mask = 0` this is the reference of `check` (`analysis::check::reference_probes`);
/// with [`ALL_SOURCES`] it is the datapath itself whenever every f64 product is exact.
///
/// # Examples
/// ```
/// use specfx::pipeline::f64_walk::{mixed_eval, ALL_SOURCES};
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let nc = dp.constants_for(100).unwrap();
/// let (_, out) = mixed_eval(&dp, nc, 32_000, ALL_SOURCES);
/// let fixed = dp.eval(32_000, nc).values[dp.stage_out()];
/// assert_eq!(out, dp.stages()[dp.stage_out()].format.to_f64(fixed));
/// ```
pub fn mixed_eval(dp: &Datapath, nc: &NConstants, c_raw: i64, mask: u32) -> (f64, f64) {
    F64Walk::at_code(dp, nc, c_raw, mask).run()
}
