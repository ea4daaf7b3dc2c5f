//! Hardware cost: a fast analytic model from the formats, the yosys script and statistics
//! parser behind `specfx cost` (`tools::yosys` runs yosys; nothing here starts a process),
//! and the cost report that puts them side by side.

use crate::error::Error;
use std::collections::BTreeMap;

use serde::Serialize;

use crate::cycle::Arch;
use crate::fixed::{Overflow, Rounding};
use crate::pipeline::Datapath;
use crate::reference::lobe::Cutoff;

/// A synthesis target of yosys.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// Generic gates (`synth`, then `abc -g cmos2`), with a CMOS transistor estimate.
    Generic,
    /// Generic gates mapped by `abc -fast -g cmos2`: minutes become seconds on wide or folded
    /// datapaths, for about 15% more cells.
    #[serde(rename = "generic-fast")]
    GenericFast,
    /// Lattice iCE40 (`synth_ice40 -dsp`): LUT4, carry cells, SB_MAC16 DSPs.
    Ice40,
    /// Xilinx 7-series (`synth_xilinx -family xc7`): LUT1..6, CARRY4, DSP48E1.
    Xilinx,
}

impl Target {
    /// Every target.
    pub const ALL: [Target; 4] = [
        Target::Generic,
        Target::GenericFast,
        Target::Ice40,
        Target::Xilinx,
    ];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Target::Generic => "generic",
            Target::GenericFast => "generic-fast",
            Target::Ice40 => "ice40",
            Target::Xilinx => "xilinx",
        }
    }

    /// Width of one DSP block's operands (a x b), if the target has DSP blocks.
    pub fn dsp_operands(self) -> Option<(u32, u32)> {
        match self {
            Target::Generic | Target::GenericFast => None,
            Target::Ice40 => Some((16, 16)),
            Target::Xilinx => Some((18, 25)),
        }
    }
}

crate::names::named_enum!(
    Target,
    "synthesis target",
    "generic, generic-fast, ice40 or xilinx"
);

/// One multiplier of a datapath: its name and operands.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Multiplier {
    /// Which product (`mul_t`, `sq1`.., `mul_out`, or `shared` for the folded unit).
    pub name: String,
    /// Width of the first operand.
    pub a_bits: u32,
    /// Whether the first operand is signed.
    pub a_signed: bool,
    /// Width of the second operand.
    pub b_bits: u32,
    /// Whether the second operand is signed.
    pub b_signed: bool,
    /// Both operands are the same signal (a squaring).
    pub square: bool,
}

/// How a target's synthesis maps multipliers onto DSP blocks: yosys's `mul2dsp` parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct DspParams {
    a_max: u32,
    b_max: u32,
    a_max_partial: u32,
    a_min: u32,
    b_min: u32,
    y_min: u32,
    signed_only: bool,
}

impl Target {
    fn dsp_params(self) -> Option<DspParams> {
        match self {
            Target::Generic | Target::GenericFast => None,
            // synth_ice40 -dsp: SB_MAC16, 16 x 16, unsigned or signed.
            Target::Ice40 => Some(DspParams {
                a_max: 16,
                b_max: 16,
                a_max_partial: 16,
                a_min: 2,
                b_min: 2,
                y_min: 11,
                signed_only: false,
            }),
            // synth_xilinx -family xc7: DSP48E1, 25 x 18 signed, partial products 18 wide.
            Target::Xilinx => Some(DspParams {
                a_max: 25,
                b_max: 18,
                a_max_partial: 18,
                a_min: 2,
                b_min: 2,
                y_min: 0,
                signed_only: true,
            }),
        }
    }

    /// The unit of the target's logic figure: `LUTs` on the FPGAs, `gates` for generic.
    pub fn logic_unit(self) -> &'static str {
        match self {
            Target::Generic | Target::GenericFast => "gates",
            Target::Ice40 | Target::Xilinx => "LUTs",
        }
    }
}

/// How one multiplier maps onto a target: DSP blocks, partial-product bits left to logic,
/// and the widths of the adders that sum the DSP blocks' partial products.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct MulMap {
    dsps: u64,
    soft_bits: u64,
    glue_bits: u64,
}

/// Follows yosys's `mul2dsp` technology mapping (techlibs/common/mul2dsp.v): a product too
/// small for a DSP stays in logic; an unsigned one is widened to signed where the DSP is
/// signed-only; the wider operand goes first; an operand wider than the DSP is cut into
/// partial slices whose products are summed.
fn map_multiplier(
    p: &DspParams,
    (a, a_s): (u32, bool),
    (b, b_s): (u32, bool),
    y: u32,
    top: bool,
    out: &mut MulMap,
) {
    if a < p.a_min || b < p.b_min || y < p.y_min {
        out.soft_bits += u64::from(a) * u64::from(b);
        return;
    }
    if top && p.signed_only && !a_s && !b_s {
        return map_multiplier(p, (a + 1, true), (b + 1, true), y, true, out);
    }
    if top && a < b {
        return map_multiplier(p, (b, b_s), (a, a_s), y, true, out);
    }
    let h = u32::from(p.signed_only);
    let slices = |w: u32, max: u32, partial: u32, other: u32| {
        let n = (w - max + partial - h - 1) / (partial - h);
        let last = w - n * (partial - h);
        (n, last, y.min(other + partial), other + last)
    };
    if a > p.a_max {
        let (n, last, py, ly) = slices(a, p.a_max, p.a_max_partial, b);
        for _ in 0..n {
            map_multiplier(p, (p.a_max_partial, h == 1), (b, b_s), py, false, out);
        }
        map_multiplier(p, (last, a_s), (b, b_s), ly, false, out);
        out.glue_bits += u64::from(n) * u64::from(y);
    } else if b > p.b_max {
        let (n, last, py, ly) = slices(b, p.b_max, p.b_max, a);
        for _ in 0..n {
            map_multiplier(p, (a, a_s), (p.b_max, h == 1), py, false, out);
        }
        map_multiplier(p, (a, a_s), (last, b_s), ly, false, out);
        out.glue_bits += u64::from(n) * u64::from(y);
    } else {
        out.dsps += 1;
    }
}

/// The counted quantities of a datapath on a target, from its formats: what the analytic
/// model weighs with its calibrated coefficients.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Features {
    /// Every multiplier.
    pub multipliers: Vec<Multiplier>,
    /// Sum of a_bits * b_bits over the multipliers (partial-product bits).
    pub multiplier_bits: u64,
    /// Widths of the subtraction, the base sum and the paper cutoff's comparison.
    pub adder_bits: u64,
    /// Output widths of the quantizers that round (not TRN): an increment each.
    pub rounding_bits: u64,
    /// Output widths of the quantizers that saturate (not WRAP): a compare-and-select each.
    pub overflow_bits: u64,
    /// Partial-product bits built in logic (every one without DSP blocks).
    pub soft_multiplier_bits: u64,
    /// Widths of the adders summing a wide product's DSP slices.
    pub dsp_glue_bits: u64,
    /// Multiplexer inputs of the power-of-two slope shifter (pipelined, slopes all 2^j).
    pub shifter_bits: u64,
    /// Operand-select inputs of the folded architecture's shared multiplier.
    pub mux_bits: u64,
    /// Per-n depth, pipelined: inputs of the bypass multiplexers of the squaring stages some
    /// exponent bypasses (two per bit of the square they select against).
    pub bypass_bits: u64,
    /// Per-n depth, folded: the same inputs, on the steps of the shared multiplier (weighed
    /// apart: there the bypass also splits the step's requantizer from the square's).
    pub folded_bypass_bits: u64,
    /// Register bits (data, valid bits and the per-n constants carried along).
    pub register_bits: u64,
    /// DSP blocks.
    pub dsps: u64,
}

impl Features {
    /// Number of logic features weighed by the model.
    pub const LOGIC: usize = 10;
    /// Names of the logic features, in the order of [`Features::logic`].
    pub const LOGIC_NAMES: [&'static str; Features::LOGIC] = [
        "adder_bits",
        "rounding_bits",
        "overflow_bits",
        "soft_multiplier_bits",
        "dsp_glue_bits",
        "shifter_bits",
        "mux_bits",
        "bypass_bits",
        "folded_bypass_bits",
        "constant",
    ];

    /// The logic features, as the model weighs them.
    pub fn logic(&self) -> [f64; Features::LOGIC] {
        [
            self.adder_bits as f64,
            self.rounding_bits as f64,
            self.overflow_bits as f64,
            self.soft_multiplier_bits as f64,
            self.dsp_glue_bits as f64,
            self.shifter_bits as f64,
            self.mux_bits as f64,
            self.bypass_bits as f64,
            self.folded_bypass_bits as f64,
            1.0,
        ]
    }

    /// Logic cells under coefficients `c`.
    pub fn logic_cells(&self, c: &[f64; Features::LOGIC]) -> f64 {
        self.logic().iter().zip(c).map(|(x, w)| x * w).sum()
    }
}

/// Counts a datapath's features on a target (see [`analytic_cost`]).
pub fn features(dp: &Datapath, arch: Arch, target: Target) -> Features {
    let cfg = dp.config();
    let (slope, offset) = cfg.constant_formats();
    let w = |f: crate::fixed::Format| f.width();
    // Every slope a power of two (pipelined): t's product is a shift of d by one of the
    // slope's bit positions, a multiplexer per product bit and select bit, not a multiplier.
    let shift_t = arch == Arch::Pipelined && crate::hdl::slope_is_pow2(cfg);
    let shifter_bits = if shift_t {
        let shifts = u64::from(w(slope));
        let select_bits = u64::from(64 - (shifts.max(2) - 1).leading_zeros());
        u64::from(w(cfg.d.format) + w(slope)) * select_bits
    } else {
        0
    };
    let operand = |name: String, a: crate::fixed::Format, b: crate::fixed::Format| Multiplier {
        name,
        a_bits: w(a),
        a_signed: a.is_signed(),
        b_bits: w(b),
        b_signed: b.is_signed(),
        square: false,
    };
    let mut products = if shift_t {
        Vec::new()
    } else {
        vec![operand("mul_t".into(), cfg.d.format, slope)]
    };
    let mut prev = cfg.b.format;
    for (i, sq) in cfg.square.iter().enumerate() {
        let name = crate::pipeline::walk::Stage::Square(i).to_string();
        products.push(Multiplier {
            square: true,
            ..operand(name, prev, prev)
        });
        prev = sq.format;
    }
    products.push(operand("mul_out".into(), prev, cfg.coef.format));
    // A quantizer's rounding is an increment across its output (none for TRN, which only
    // drops bits); its overflow handling a compare-and-select per output bit (none for WRAP,
    // which only drops bits).
    let specs: Vec<&crate::pipeline::StageSpec> = [&cfg.t, &cfg.b, &cfg.out]
        .into_iter()
        .chain(cfg.square.iter())
        .collect();
    let rounding_bits: u64 = specs
        .iter()
        .filter(|s| s.rounding != Rounding::Trn)
        .map(|s| u64::from(s.format.width()))
        .sum();
    let overflow_bits: u64 = specs
        .iter()
        .filter(|s| s.overflow != Overflow::Wrap)
        .map(|s| u64::from(s.format.width()))
        .sum();
    let sum_bits = u64::from(
        cfg.t.format.int_bits().max(offset.int_bits()) as u32
            + cfg.t.format.frac_bits().max(offset.frac_bits()) as u32
            + 1,
    );
    let compare_bits = if cfg.cutoff == Cutoff::Paper {
        u64::from(w(cfg.c.format))
    } else {
        0
    };
    let adder_bits = u64::from(w(cfg.c.format)) + 1 + sum_bits + compare_bits;
    let carried = u64::from(w(offset) + w(cfg.coef.format))
        + if cfg.cutoff == Cutoff::Paper {
            2 * u64::from(w(cfg.c.format))
        } else {
            0
        };
    let lat = &cfg.latency;
    // Per-n depth: each stage some n bypasses selects between the square and its input (two
    // inputs per bit of the square), and the depth field (DEPTH_BITS) travels with the data
    // up to the last such stage.
    let k = cfg.k as usize;
    let bypass_from = dp.bypass_from();
    let mut bypass_mux = 0u64;
    let mut prev_w = w(cfg.b.format);
    for (i, sq) in cfg.square.iter().enumerate() {
        if i >= bypass_from {
            bypass_mux += 2 * 2 * u64::from(prev_w);
        }
        prev_w = w(sq.format);
    }
    let depth_bits = if bypass_from < k {
        u64::from(crate::hdl::DEPTH_BITS)
    } else {
        0
    };
    let (multipliers, register_bits, mux_bits) = match arch {
        Arch::Pipelined => {
            let mut bits = u64::from(lat.sub)
                * (u64::from(w(cfg.d.format)) + 1 + carried + u64::from(w(slope)));
            bits += u64::from(lat.mul) * (u64::from(w(cfg.t.format)) + 1 + carried);
            bits += u64::from(lat.add)
                * (u64::from(w(cfg.b.format)) + 1 + u64::from(w(cfg.coef.format)));
            for sq in &cfg.square {
                bits += u64::from(lat.mul)
                    * (u64::from(w(sq.format)) + 1 + u64::from(w(cfg.coef.format)));
            }
            bits += u64::from(lat.mul) * (u64::from(w(cfg.out.format)) + 1);
            // The depth rides in the registers of sub, mul_t, add_b and the squarings before
            // the last bypassed one.
            let stages_carried =
                u64::from(lat.sub + lat.mul + lat.add) + u64::from(lat.mul) * (k as u64 - 1);
            bits += depth_bits * stages_carried;
            (products, bits, 0)
        }
        Arch::Folded => {
            let a = products.iter().map(|m| m.a_bits).max().unwrap_or(1);
            let b = products.iter().map(|m| m.b_bits).max().unwrap_or(1);
            let mux: u64 = products
                .iter()
                .map(|m| u64::from(m.a_bits + m.b_bits))
                .sum();
            let widest = dp.widest_stage_bits();
            let bits = u64::from(widest)
                + carried
                + u64::from(w(slope))
                + u64::from(w(cfg.out.format))
                + 1
                + 16
                + u64::from(lat.mul - 1) * u64::from(a + b)
                + depth_bits;
            let shared = Multiplier {
                name: "shared".into(),
                a_bits: a,
                a_signed: products.iter().any(|m| m.a_signed),
                b_bits: b,
                b_signed: products.iter().any(|m| m.b_signed),
                square: false,
            };
            (vec![shared], bits, mux)
        }
    };
    let multiplier_bits: u64 = multipliers
        .iter()
        .map(|m| u64::from(m.a_bits) * u64::from(m.b_bits))
        .sum();
    let mut map = MulMap::default();
    match target.dsp_params() {
        Some(p) => {
            for m in &multipliers {
                // The RTL multiplies signed codes; an unsigned operand beside a signed one
                // keeps its zero sign bit, two unsigned operands lose both (yosys wreduce).
                let signed = m.a_signed || m.b_signed;
                let a = (m.a_bits + u32::from(signed && !m.a_signed), signed);
                let b = (m.b_bits + u32::from(signed && !m.b_signed), signed);
                let mut one = MulMap::default();
                // (A square's slices i x j and j x i are not merged by yosys 0.23.)
                map_multiplier(&p, a, b, a.0 + b.0, true, &mut one);
                map.dsps += one.dsps;
                map.soft_bits += one.soft_bits;
                map.glue_bits += one.glue_bits;
            }
        }
        None => map.soft_bits = multiplier_bits,
    }
    Features {
        multipliers,
        multiplier_bits,
        adder_bits,
        rounding_bits,
        overflow_bits,
        soft_multiplier_bits: map.soft_bits,
        dsp_glue_bits: map.glue_bits,
        shifter_bits,
        mux_bits,
        bypass_bits: if arch == Arch::Pipelined {
            bypass_mux
        } else {
            0
        },
        folded_bypass_bits: if arch == Arch::Folded { bypass_mux } else { 0 },
        register_bits,
        dsps: map.dsps,
    }
}

/// The three figures of a datapath on one target, named with the target: logic cells
/// (`LUTs` on the FPGAs, `gates` for generic), DSP blocks and flip-flops.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct CostFigures {
    /// The target.
    pub target: Target,
    /// Logic cells in the target's unit ([`Target::logic_unit`]).
    pub luts: u64,
    /// DSP blocks.
    pub dsps: u64,
    /// Flip-flops.
    pub ffs: u64,
}

impl CostFigures {
    /// The figures as text: `813 LUTs + 7 DSPs + 332 FFs on ice40`.
    pub fn describe(&self) -> String {
        let dsps = if self.target.dsp_operands().is_some() {
            format!(" + {} DSPs", self.dsps)
        } else {
            String::new()
        };
        format!(
            "{} {}{dsps} + {} FFs on {}",
            self.luts,
            self.target.logic_unit(),
            self.ffs,
            self.target.name()
        )
    }
}

/// The targets every report prices a datapath on: iCE40, Xilinx 7-series, generic gates.
pub const REPORTED_TARGETS: [Target; 3] = [Target::Ice40, Target::Xilinx, Target::Generic];

/// The analytic cost of a datapath: counted from its formats, no synthesis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AnalyticCost {
    /// The architecture.
    pub arch: Arch,
    /// The target the figures are for.
    pub target: Target,
    /// The unit of `luts`: `LUTs`, or `gates` for the generic targets.
    pub logic_unit: &'static str,
    /// Estimated logic cells (LUTs; gates for generic): the calibrated weighted sum of the
    /// features.
    pub luts: u64,
    /// DSP blocks (0 for generic), from the target's DSP mapping rules.
    pub dsps: u64,
    /// Estimated flip-flops: the calibrated multiple of the register bits.
    pub ffs: u64,
    /// Input-to-output latency in cycles.
    pub latency: u64,
    /// Initiation interval in cycles.
    pub initiation_interval: u64,
    /// The counted quantities the estimates weigh.
    pub features: Features,
}

impl AnalyticCost {
    /// The three figures, named with the target.
    pub fn figures(&self) -> CostFigures {
        CostFigures {
            target: self.target,
            luts: self.luts,
            dsps: self.dsps,
            ffs: self.ffs,
        }
    }
}

/// What one DSP block weighs in the optimiser's objective, in the target's logic unit: the
/// logic cells its product (the block's full operands, 16 x 16 on iCE40, 25 x 18 on Xilinx)
/// would take as soft partial-product bits under the calibrated model; 0 on targets without
/// DSP blocks.
///
/// # Examples
/// ```
/// use specfx::hdl::cost::{dsp_weight, Target};
/// assert!(dsp_weight(Target::Ice40) > 256.0); // above one LUT per partial-product bit
/// assert_eq!(dsp_weight(Target::Generic), 0.0);
/// ```
pub fn dsp_weight(target: Target) -> f64 {
    let soft = crate::hdl::calibrate::coefficients(target).logic[3];
    target
        .dsp_operands()
        .map_or(0.0, |(a, b)| soft * f64::from(a * b))
}

/// The optimiser's objective for figures: logic cells plus each DSP block at its
/// [`dsp_weight`], so that a block is worth the logic it saves and no more.
pub fn objective_value(f: &CostFigures) -> f64 {
    f.luts as f64 + f.dsps as f64 * dsp_weight(f.target)
}

/// The analytic cost figures of a datapath on every [`REPORTED_TARGETS`] target.
pub fn figures_on_targets(dp: &Datapath, arch: Arch) -> Vec<CostFigures> {
    REPORTED_TARGETS
        .iter()
        .map(|&t| analytic_cost(dp, arch, t).figures())
        .collect()
}

/// The analytic cost of a datapath on a target: one model per target, the same figure in
/// `cost`, `sweep`, `optimize`, `tradeoff`, `fit` and the reports.
///
/// The features (adder, rounding and overflow bits, partial-product bits left in logic after
/// yosys's DSP mapping rules, DSP glue adders, shifter and operand multiplexers, register
/// bits) are counted from the formats; the LUT and flip-flop estimates weigh them with
/// coefficients fitted against yosys over the calibration sample in `data/calibration/`
/// (`specfx calibrate`), whose error `specfx cost` prints.
///
/// # Examples
/// ```
/// use specfx::cycle::Arch;
/// use specfx::hdl::cost::{analytic_cost, Target};
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let c = analytic_cost(&dp, Arch::Pipelined, Target::Ice40);
/// // d (16 bits) x n (11 bits), four 17 x 17 squares, 17 x 24 for the output.
/// assert_eq!(c.features.multiplier_bits, 16 * 11 + 4 * 17 * 17 + 17 * 24);
/// assert_eq!(c.features.multipliers.len(), 6);
/// ```
pub fn analytic_cost(dp: &Datapath, arch: Arch, target: Target) -> AnalyticCost {
    let features = features(dp, arch, target);
    let c = crate::hdl::calibrate::coefficients(target);
    AnalyticCost {
        arch,
        target,
        logic_unit: target.logic_unit(),
        luts: features.logic_cells(&c.logic).round().max(0.0) as u64,
        dsps: features.dsps,
        ffs: (features.register_bits as f64 * c.ff_per_register_bit).round() as u64,
        latency: arch.latency(dp.config()),
        initiation_interval: arch.initiation_interval(dp.config()),
        features,
    }
}

/// The yosys script for a target, reading `files` with `include_dir` on the include path and
/// writing `stat.json` (and, for generic, `stat_cmos.txt` with the transistor estimate).
pub fn yosys_script(target: Target, files: &[String], include_dir: &str, top: &str) -> String {
    let mut s = format!("read_verilog -I{include_dir} {}\n", files.join(" "));
    s.push_str(&format!("hierarchy -check -top {top}\n"));
    match target {
        Target::Generic => {
            s.push_str(&format!("synth -top {top} -flatten\nabc -g cmos2\n"));
            s.push_str("tee -q -o stat_cmos.txt stat -tech cmos\n");
        }
        Target::GenericFast => {
            s.push_str(&format!("synth -top {top} -flatten\nabc -fast -g cmos2\n"));
            s.push_str("tee -q -o stat_cmos.txt stat -tech cmos\n");
        }
        Target::Ice40 => s.push_str(&format!("synth_ice40 -top {top} -dsp\n")),
        Target::Xilinx => s.push_str(&format!("synth_xilinx -top {top} -family xc7 -flatten\n")),
    }
    s.push_str("tee -q -o stat.json stat -json\n");
    s
}

/// What yosys counted, classified.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct YosysCost {
    /// All cells.
    pub cells: u64,
    /// Lookup tables (SB_LUT4, LUT1..LUT6; for generic, the logic gates).
    pub luts: u64,
    /// Carry-chain cells (SB_CARRY, CARRY4, CARRY8).
    pub carries: u64,
    /// DSP blocks (SB_MAC16, DSP48E1).
    pub dsps: u64,
    /// Flip-flops (any cell type with DFF or FD in its name).
    pub ffs: u64,
    /// The CMOS transistor estimate (generic target only).
    pub transistors: Option<u64>,
    /// Every cell type and its count.
    pub cells_by_type: BTreeMap<String, u64>,
}

/// Classifies yosys's `stat -json` output (the `design` totals).
pub fn parse_stat_json(text: &str, cmos_stat: Option<&str>) -> Result<YosysCost, Error> {
    let unreadable = |message: String| Error::Tool {
        tool: "yosys",
        message,
    };
    let v: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| unreadable(format!("stat -json output is not JSON: {e}")))?;
    let design = &v["design"];
    let by_type = design["num_cells_by_type"].as_object().ok_or_else(|| {
        unreadable("stat -json output has no design.num_cells_by_type".to_string())
    })?;
    let mut cells_by_type = BTreeMap::new();
    let (mut luts, mut carries, mut dsps, mut ffs) = (0, 0, 0, 0);
    for (name, count) in by_type {
        let count = count.as_u64().unwrap_or(0);
        cells_by_type.insert(name.clone(), count);
        let upper = name.to_uppercase();
        if upper.contains("DFF") || upper.starts_with("FD") || upper.contains("SDFF") {
            ffs += count;
        } else if upper.contains("CARRY") {
            carries += count;
        } else if upper.contains("MAC16") || upper.contains("DSP48") {
            dsps += count;
        } else if upper.contains("LUT") || upper.starts_with("$_") {
            luts += count;
        }
    }
    let transistors = cmos_stat.and_then(|t| {
        t.lines()
            .find(|l| l.contains("Estimated number of transistors"))
            .and_then(|l| l.split(':').nth(1))
            .and_then(|n| n.trim().trim_end_matches('+').parse().ok())
    });
    Ok(YosysCost {
        cells: design["num_cells"].as_u64().unwrap_or(0),
        luts,
        carries,
        dsps,
        ffs,
        transistors,
        cells_by_type,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stat_json_is_classified() {
        let text = r#"{"design": {"num_cells": 10, "num_cells_by_type": {
            "SB_LUT4": 4, "SB_CARRY": 2, "SB_DFFE": 1, "SB_DFFESR": 1, "SB_MAC16": 2 }}}"#;
        let c = parse_stat_json(text, None).unwrap();
        assert_eq!(
            (c.cells, c.luts, c.carries, c.ffs, c.dsps),
            (10, 4, 2, 2, 2)
        );
        let cmos = "   Estimated number of transistors:      78370+\n";
        let c = parse_stat_json(text, Some(cmos)).unwrap();
        assert_eq!(c.transistors, Some(78370));
        assert!(parse_stat_json("{}", None).is_err());
    }
}

impl YosysCost {
    /// Its logic cells, DSP blocks and flip-flops on `target`, the one it was synthesised for.
    pub fn figures(&self, target: Target) -> CostFigures {
        CostFigures {
            target,
            luts: self.luts,
            dsps: self.dsps,
            ffs: self.ffs,
        }
    }
}

/// What one yosys synthesis gives: its figures, its version and the exact script it ran.
#[derive(Debug, Clone)]
pub struct Synthesis {
    /// yosys's figures.
    pub cost: YosysCost,
    /// `yosys -V`.
    pub version: String,
    /// The script yosys ran.
    pub script: String,
}

/// Everything `specfx cost` reports.
#[derive(Debug, Serialize)]
pub struct CostReport {
    /// Configuration name.
    pub config: String,
    /// Architecture.
    pub arch: Arch,
    /// Synthesis target.
    pub target: Target,
    /// The analytic model's figures.
    pub analytic: AnalyticCost,
    /// yosys's figures, when it ran.
    pub yosys: Option<YosysCost>,
    /// yosys LUTs (or gates, for generic).
    pub luts: Option<u64>,
    /// yosys DSP blocks.
    pub dsps: Option<u64>,
    /// yosys flip-flops.
    pub ffs: Option<u64>,
    /// The per-n constant ROM in front of the datapath (not in the figures above).
    pub rom: crate::hdl::rom::ConstantRom,
    /// yosys's figures for the ROM alone (`specfx_rom`), when it ran.
    pub rom_yosys: Option<YosysCost>,
    /// `yosys -V`.
    pub yosys_version: Option<String>,
    /// The exact script yosys ran.
    pub yosys_script: Option<String>,
    /// yosys LUTs / analytic LUTs.
    pub lut_ratio: Option<f64>,
    /// yosys flip-flops / analytic flip-flops.
    pub ff_ratio: Option<f64>,
    /// The device the figures are checked against (iCE40 targets only).
    pub device: Option<crate::hdl::pnr::Device>,
    /// Resources beyond the device, from yosys's figures when it ran, else the analytic ones.
    pub over_limit: Vec<String>,
    /// Place-and-route timing (`--timing`).
    pub timing: Option<crate::hdl::pnr::Timing>,
}

impl CostReport {
    /// The report of `dp` on `target`: the analytic model's figures, beside yosys's synthesis
    /// of the datapath and the figures of its constant ROM when given; no device, no timing.
    pub fn new(
        dp: &Datapath,
        arch: Arch,
        target: Target,
        synthesis: Option<(Synthesis, YosysCost)>,
    ) -> CostReport {
        let analytic = analytic_cost(dp, arch, target);
        let (yosys, version, script, rom_yosys) = match synthesis {
            None => (None, None, None, None),
            Some((s, rom)) => (Some(s.cost), Some(s.version), Some(s.script), Some(rom)),
        };
        let ratio = |a: u64, b: u64| (b > 0).then(|| a as f64 / b as f64);
        CostReport {
            config: dp.config().name.clone(),
            arch,
            target,
            luts: yosys.as_ref().map(|y| y.luts),
            dsps: yosys.as_ref().map(|y| y.dsps),
            ffs: yosys.as_ref().map(|y| y.ffs),
            lut_ratio: yosys.as_ref().and_then(|y| ratio(y.luts, analytic.luts)),
            ff_ratio: yosys.as_ref().and_then(|y| ratio(y.ffs, analytic.ffs)),
            analytic,
            yosys,
            rom: crate::hdl::rom::constant_rom(dp, target),
            rom_yosys,
            yosys_version: version,
            yosys_script: script,
            device: None,
            over_limit: Vec::new(),
            timing: None,
        }
    }
}
