//! The per-n constant ROM in front of the datapath: what it stores, its analytic cost, and its
//! Verilog (a `case` that yosys synthesises beside the datapath).
//!
//! The datapath reads a slope, an offset, a threshold and a coefficient per exponent
//! (`hdl_ref/specfx_dut.v`'s `in_*` ports). A design serving a contiguous range of n addresses
//! the ROM with n itself, so the plain variant's slope (n with k fraction bits) is a wire; a
//! design serving a list of exponents (a scene's materials) addresses it with an index and
//! stores the slope. Constants that are the same for every n (the plain offset 1) are wires.
//! A datapath with a per-n depth stores j(n) too (`depth`, [`crate::hdl::DEPTH_BITS`] bits)
//! and its plain slope n / 2^j(n).

use serde::Serialize;

use crate::fixed::Format;
use crate::hdl::cost::Target;
use crate::pipeline::ports::PerN;
use crate::pipeline::{Datapath, Variant};
use crate::reference::lobe::Cutoff;

/// One stored field of the ROM.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct RomField {
    /// The port it drives (`slope`, `offset`, `threshold`, `coef`).
    pub name: &'static str,
    /// Its width in bits.
    pub bits: u32,
}

/// The constant ROM of a datapath.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConstantRom {
    /// Entries: one per exponent served.
    pub entries: u64,
    /// Addressed by n itself (a contiguous range) rather than by an index into the set.
    pub addressed_by_n: bool,
    /// Address width.
    pub address_bits: u32,
    /// The stored fields.
    pub fields: Vec<RomField>,
    /// Stored bits: entries x the fields' widths.
    pub bits: u64,
    /// Estimated LUTs on the target: each output bit a function of the address, one LUT per
    /// 2^inputs entries plus a multiplexer tree (LUT4 for generic and iCE40, LUT6 for Xilinx).
    pub luts: u64,
}

/// Bits to address `count` entries (at least 1).
fn index_bits(count: u64) -> u32 {
    (64 - count.saturating_sub(1).leading_zeros()).max(1)
}

/// The ROM a datapath needs, costed on a target.
///
/// # Examples
/// ```
/// use specfx::hdl::cost::Target;
/// use specfx::hdl::rom::constant_rom;
/// use specfx::nset::NSet;
/// use specfx::pipeline::{Config, Datapath};
/// // baseline: n = 16..1024 addressed by n; only the u8.16 coefficient is stored.
/// let rom = constant_rom(&Datapath::new(Config::baseline()).unwrap(), Target::Ice40);
/// assert_eq!((rom.entries, rom.address_bits, rom.bits), (1009, 11, 1009 * 24));
/// // Four exponents: a 2-bit index, and the slope is stored too.
/// let mut cfg = Config::baseline();
/// cfg.n = NSet::from_values(&[16, 64, 256, 1024]).unwrap();
/// let rom = constant_rom(&Datapath::new(cfg).unwrap(), Target::Ice40);
/// // slope: n = 1024 with k = 4 fraction bits, 11 bits.
/// assert_eq!((rom.entries, rom.address_bits, rom.bits), (4, 2, 4 * (11 + 24)));
/// ```
pub fn constant_rom(dp: &Datapath, target: Target) -> ConstantRom {
    let cfg = dp.config();
    let values = cfg.n.values();
    let entries = values.len() as u64;
    let addressed_by_n = values.windows(2).all(|w| w[1] == w[0] + 1);
    let address_bits = if addressed_by_n {
        32 - cfg.n.max().leading_zeros()
    } else {
        index_bits(entries)
    };
    let minimax = cfg.variant == Variant::Minimax;
    // Per-n depth: the plain slope n / 2^j(n) is no longer n itself, and j(n) is a field.
    let bypass = dp.bypass_from() < cfg.k as usize;
    let fields: Vec<RomField> = PerN::ALL
        .into_iter()
        .filter(|p| match p {
            PerN::Slope => minimax || !addressed_by_n || bypass,
            PerN::Offset => minimax,
            PerN::Threshold => cfg.cutoff == Cutoff::Paper,
            PerN::Coef => true,
            PerN::Depth => bypass,
        })
        .map(|p| RomField {
            name: p.field(),
            bits: p.format(dp).width(),
        })
        .collect();
    let width: u64 = fields.iter().map(|f| u64::from(f.bits)).sum();
    let inputs = match target {
        Target::Xilinx => 6,
        _ => 4,
    };
    let leaves = entries.div_ceil(1 << inputs);
    let tree = if leaves > 1 {
        (leaves - 1).div_ceil(inputs - 1)
    } else {
        0
    };
    ConstantRom {
        entries,
        addressed_by_n,
        address_bits,
        bits: entries * width,
        luts: width * (leaves + tree),
        fields,
    }
}

/// A raw code as Verilog hex of `f`'s width (two's complement for signed formats).
fn hex(raw: i64, f: Format) -> String {
    let w = f.width();
    let mask = if w >= 64 { u64::MAX } else { (1u64 << w) - 1 };
    format!("{w}'h{:x}", (raw as u64) & mask)
}

/// The ROM as a Verilog-2005 module `specfx_rom`: input `addr` (n, or the index of n in the
/// ascending set), one output per port of `specfx_dut` (`slope`, `offset`, `threshold`,
/// `coef`), wires where a port needs no storage.
pub fn rom_verilog(dp: &Datapath) -> String {
    let cfg = dp.config();
    let rom = constant_rom(dp, Target::Generic);
    let stored = |p: PerN| rom.fields.iter().any(|f| f.name == p.field());
    // Every per-n port of specfx_dut, but the depth where no n bypasses a stage.
    let ports: Vec<(PerN, Format)> = PerN::ALL
        .into_iter()
        .filter(|&p| p != PerN::Depth || stored(p))
        .map(|p| (p, p.format(dp)))
        .collect();
    let mut v = String::new();
    v.push_str(&format!(
        "// specfx_rom: the per-n constants of datapath `{}` ({} entries, addressed by {}).\n// Written by specfx; do not edit.\n`timescale 1ns / 1ps\n`default_nettype none\n\nmodule specfx_rom (\n    input  wire [{}:0] addr",
        cfg.name,
        rom.entries,
        if rom.addressed_by_n { "n" } else { "the index of n in the ascending set" },
        rom.address_bits - 1
    ));
    for &(p, f) in &ports {
        let kind = if stored(p) { "reg " } else { "wire" };
        v.push_str(&format!(
            ",\n    output {kind} [{}:0] {}",
            f.width() - 1,
            p.field()
        ));
    }
    v.push_str("\n);\n");
    let first = dp.constants_for(cfg.n.min()).expect("n set is not empty");
    for &(p, f) in &ports {
        if stored(p) {
            continue;
        }
        let value = match p {
            // Plain, addressed by n: the slope's raw code (n with k fraction bits) is n.
            PerN::Slope => "addr".to_string(),
            PerN::Offset => hex(first.offset_raw, f),
            _ => hex(0, f),
        };
        v.push_str(&format!("    assign {} = {value};\n", p.field()));
    }
    v.push_str("    always @* begin\n        case (addr)\n");
    for (i, &n) in cfg.n.values().iter().enumerate() {
        let nc = dp.constants_for(n).expect("n in the set");
        let addr = if rom.addressed_by_n { n as usize } else { i };
        let mut body = Vec::new();
        for &(p, f) in &ports {
            if stored(p) {
                body.push(format!("{} = {};", p.field(), hex(p.raw(nc), f)));
            }
        }
        v.push_str(&format!(
            "            {}'d{addr}: begin {} end // n = {n}\n",
            rom.address_bits,
            body.join(" ")
        ));
    }
    let defaults: Vec<String> = ports
        .iter()
        .filter(|(p, _)| stored(*p))
        .map(|(p, f)| format!("{} = {};", p.field(), hex(0, *f)))
        .collect();
    v.push_str(&format!(
        "            default: begin {} end\n        endcase\n    end\nendmodule\n\n`default_nettype wire\n",
        defaults.join(" ")
    ));
    v
}
