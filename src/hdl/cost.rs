//! Hardware cost: a fast analytic model from the formats, and the yosys script and statistics
//! parser behind `specfx cost` (which runs yosys; nothing here starts a process).

use crate::error::Error;
use std::collections::BTreeMap;

use serde::Serialize;

use crate::cycle::Arch;
use crate::fixed::{Overflow, Rounding};
use crate::golden::constant_formats;
use crate::pipeline::Datapath;
use crate::reference::lobe::Cutoff;

/// A synthesis target of yosys.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// Generic gates (`synth`, then `abc -g cmos2`), with a CMOS transistor estimate.
    Generic,
    /// Generic gates mapped by `abc -fast -g cmos2`: minutes become seconds on wide or folded
    /// datapaths, for about 15% more cells.
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

/// One multiplier of a datapath: its name and operand widths.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Multiplier {
    /// Which product (`mul_t`, `sq1`.., `mul_out`, or `shared` for the folded unit).
    pub name: String,
    /// Width of the first operand.
    pub a_bits: u32,
    /// Width of the second operand.
    pub b_bits: u32,
}

/// The analytic cost of a datapath: counted from its formats, no synthesis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AnalyticCost {
    /// The architecture.
    pub arch: Arch,
    /// Every multiplier.
    pub multipliers: Vec<Multiplier>,
    /// Sum of a_bits * b_bits over the multipliers (partial-product bits).
    pub multiplier_bits: u64,
    /// Sum of the widths of the adders (subtraction, base sum, rounding increments).
    pub adder_bits: u64,
    /// Register bits (data, valid bits and the per-n constants carried along).
    pub register_bits: u64,
    /// DSP blocks on the target (0 for generic).
    pub dsps: u64,
    /// Estimated LUTs: adders and rounding plus, without DSP blocks, the partial products.
    pub luts: u64,
    /// Input-to-output latency in cycles.
    pub latency: u64,
    /// Initiation interval in cycles.
    pub initiation_interval: u64,
}

/// The analytic cost of a datapath on a target.
///
/// The LUT estimate is deliberately simple (one LUT per adder bit, one per quantizer output
/// bit for rounding unless it is TRN and one for overflow unless it is WRAP, one per
/// partial-product bit when no DSP takes the product); `specfx cost` prints it
/// beside yosys's count with their ratio, so sweeps can use it and calibrate it.
///
/// # Examples
/// ```
/// use specfx::cycle::Arch;
/// use specfx::hdl::cost::{analytic_cost, Target};
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let c = analytic_cost(&dp, Arch::Pipelined, Target::Ice40);
/// // d (16 bits) x n (11 bits), four 17 x 17 squares, 17 x 24 for the output.
/// assert_eq!(c.multiplier_bits, 16 * 11 + 4 * 17 * 17 + 17 * 24);
/// assert_eq!(c.multipliers.len(), 6);
/// ```
pub fn analytic_cost(dp: &Datapath, arch: Arch, target: Target) -> AnalyticCost {
    let cfg = dp.config();
    let (slope, offset) = constant_formats(cfg);
    let w = |f: crate::fixed::Format| f.width();
    // Every slope a power of two (pipelined): t's product is a shift of d by one of the
    // slope's bit positions, a multiplexer per product bit and select bit, not a multiplier.
    let shift_t = arch == Arch::Pipelined && crate::hdl::slope_is_pow2(cfg);
    let shifter_luts = if shift_t {
        let shifts = u64::from(w(slope));
        let select_bits = u64::from(64 - (shifts.max(2) - 1).leading_zeros());
        u64::from(w(cfg.d.format) + w(slope)) * select_bits
    } else {
        0
    };
    let mut products = if shift_t {
        Vec::new()
    } else {
        vec![Multiplier {
            name: "mul_t".into(),
            a_bits: w(cfg.d.format),
            b_bits: w(slope),
        }]
    };
    let mut prev = cfg.b.format;
    for (i, sq) in cfg.square.iter().enumerate() {
        products.push(Multiplier {
            name: crate::pipeline::walk::Stage::Square(i).to_string(),
            a_bits: w(prev),
            b_bits: w(prev),
        });
        prev = sq.format;
    }
    products.push(Multiplier {
        name: "mul_out".into(),
        a_bits: w(prev),
        b_bits: w(cfg.coef.format),
    });
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
    let adder_bits = u64::from(w(cfg.c.format)) + 1 + sum_bits + rounding_bits;
    let carried = u64::from(w(offset) + w(cfg.coef.format))
        + if cfg.cutoff == Cutoff::Paper {
            2 * u64::from(w(cfg.c.format))
        } else {
            0
        };
    let lat = &cfg.latency;
    let (multipliers, register_bits) = match arch {
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
            (products, bits)
        }
        Arch::Folded => {
            let a = products.iter().map(|m| m.a_bits).max().unwrap_or(1);
            let b = products.iter().map(|m| m.b_bits).max().unwrap_or(1);
            let widest = dp.widest_stage_bits();
            let bits = u64::from(widest)
                + carried
                + u64::from(w(slope))
                + u64::from(w(cfg.out.format))
                + 1
                + 16
                + u64::from(lat.mul - 1) * u64::from(a + b);
            (
                vec![Multiplier {
                    name: "shared".into(),
                    a_bits: a,
                    b_bits: b,
                }],
                bits,
            )
        }
    };
    let multiplier_bits: u64 = multipliers
        .iter()
        .map(|m| u64::from(m.a_bits) * u64::from(m.b_bits))
        .sum();
    let dsps: u64 = match target.dsp_operands() {
        // yosys maps the largest block that fits to DSPs and the leftover bits to logic.
        Some((da, db)) => multipliers
            .iter()
            .map(|m| {
                let (a, b) = (m.a_bits.min(m.b_bits), m.a_bits.max(m.b_bits));
                u64::from(((a / da) * (b / db)).max(1))
            })
            .sum(),
        None => 0,
    };
    let luts =
        adder_bits + overflow_bits + shifter_luts + if dsps == 0 { multiplier_bits } else { 0 };
    AnalyticCost {
        arch,
        multipliers,
        multiplier_bits,
        adder_bits,
        register_bits,
        dsps,
        luts,
        latency: arch.latency(cfg),
        initiation_interval: arch.initiation_interval(cfg),
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
