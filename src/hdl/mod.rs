//! The bridge to the reference Verilog: parameter headers for `hdl_ref/specfx_dut.v`.
//!
//! `hdl_ref/` holds one Verilog module per stage kind; the wrapper `specfx_dut.v` includes a
//! header of `` `define `` macros that this module renders for a configuration and an
//! architecture, so one RTL source serves every configuration.

pub mod calibrate;
pub mod cost;
pub mod pnr;
pub mod rom;
pub mod testbench;

use std::fmt::Write as _;

use crate::cycle::Arch;
use crate::fixed::{Format, Overflow, Rounding};
use crate::pipeline::{Datapath, StageSpec};
use crate::reference::lobe::Cutoff;

/// The Verilog code of a rounding mode (0 TRN .. 7 RND_CONV_ODD).
pub fn rounding_code(r: Rounding) -> u32 {
    match r {
        Rounding::Trn => 0,
        Rounding::TrnZero => 1,
        Rounding::Rnd => 2,
        Rounding::RndZero => 3,
        Rounding::RndInf => 4,
        Rounding::RndMinInf => 5,
        Rounding::RndConv => 6,
        Rounding::RndConvOdd => 7,
    }
}

/// The Verilog code of an overflow mode (0 WRAP, 1 SAT, 2 SAT_ZERO, 3 SAT_SYM).
pub fn overflow_code(o: Overflow) -> u32 {
    match o {
        Overflow::Wrap => 0,
        Overflow::Sat => 1,
        Overflow::SatZero => 2,
        Overflow::SatSym => 3,
    }
}

/// The Verilog code of a cutoff mode (0 clamp, 1 paper, 2 none).
pub fn cutoff_code(c: Cutoff) -> u32 {
    match c {
        Cutoff::Clamp => 0,
        Cutoff::Paper => 1,
        Cutoff::None => 2,
    }
}

/// The most squaring stages (`SQ1_*` .. `SQ7_*` parameters of `specfx_top`).
pub const MAX_SQUARES: usize = 7;

pub use crate::pipeline::DEPTH_BITS;

/// The values of `hdl_ref/rtl/specfx_top.v`'s parameters for a configuration and an
/// architecture, in the module's order: `ARCH`, `K`, `CUTOFF`, the formats (`<X>_W`, `<X>_F`,
/// `<X>_S`), modes (`<X>_RND`, `<X>_OVF`), the seven squaring stages `SQ1_*` .. `SQ7_*` (stages
/// above k are 0), `LAT_SUB`, `LAT_MUL`, `LAT_ADD`, `RESET_DATA` (1 when `reset_data`) and
/// `DEPTH_MIN`, the smallest per-n depth j(n) (k for a fixed depth: no stage has a bypass).
///
/// # Examples
/// ```
/// use specfx::cycle::Arch;
/// use specfx::hdl::top_parameters;
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let p = top_parameters(&dp, Arch::Folded, false);
/// assert_eq!(p[0], ("ARCH".to_string(), 1));
/// assert!(p.contains(&("SQ4_W".to_string(), 17)) && p.contains(&("SQ5_W".to_string(), 0)));
/// ```
pub fn top_parameters(dp: &Datapath, arch: Arch, reset_data: bool) -> Vec<(String, i64)> {
    let cfg = dp.config();
    let (slope, offset) = cfg.constant_formats();
    let mut p: Vec<(String, i64)> = Vec::new();
    let mut def = |name: &str, value: i64| p.push((name.to_string(), value));
    let format = |def: &mut dyn FnMut(&str, i64), x: &str, f: Format| {
        def(&format!("{x}_W"), i64::from(f.width()));
        def(&format!("{x}_F"), i64::from(f.frac_bits()));
        def(&format!("{x}_S"), i64::from(f.is_signed()));
    };
    let modes = |def: &mut dyn FnMut(&str, i64), x: &str, s: Option<&StageSpec>| {
        def(
            &format!("{x}_RND"),
            s.map_or(0, |s| i64::from(rounding_code(s.rounding))),
        );
        def(
            &format!("{x}_OVF"),
            s.map_or(0, |s| i64::from(overflow_code(s.overflow))),
        );
    };
    def(
        "ARCH",
        match arch {
            Arch::Pipelined => 0,
            Arch::Folded => 1,
        },
    );
    def("K", i64::from(cfg.k));
    def("CUTOFF", i64::from(cutoff_code(cfg.cutoff)));
    format(&mut def, "C", cfg.c.format);
    def("D_W", i64::from(cfg.d.format.width()));
    def("D_F", i64::from(cfg.d.format.frac_bits()));
    format(&mut def, "SLOPE", slope);
    def("SLOPE_POW2", i64::from(slope_is_pow2(cfg)));
    format(&mut def, "OFFSET", offset);
    format(&mut def, "T", cfg.t.format);
    modes(&mut def, "T", Some(&cfg.t));
    format(&mut def, "B", cfg.b.format);
    modes(&mut def, "B", Some(&cfg.b));
    for i in 0..MAX_SQUARES {
        let x = format!("SQ{}", i + 1);
        match cfg.square.get(i) {
            Some(s) => format(&mut def, &x, s.format),
            None => {
                for f in ["W", "F", "S"] {
                    def(&format!("{x}_{f}"), 0);
                }
            }
        }
        modes(&mut def, &x, cfg.square.get(i));
    }
    format(&mut def, "COEF", cfg.coef.format);
    format(&mut def, "OUT", cfg.out.format);
    modes(&mut def, "OUT", Some(&cfg.out));
    def("LAT_SUB", i64::from(cfg.latency.sub));
    def("LAT_MUL", i64::from(cfg.latency.mul));
    def("LAT_ADD", i64::from(cfg.latency.add));
    def("RESET_DATA", i64::from(reset_data));
    def("DEPTH_MIN", dp.bypass_from() as i64);
    p
}

/// The `specfx_params.vh` header of a configuration for one architecture: one
/// `` `define SPECFX_<NAME> <value> `` per parameter of [`top_parameters`] (data registers
/// without reset), for `hdl_ref/specfx_dut.v`.
///
/// # Examples
/// ```
/// use specfx::cycle::Arch;
/// use specfx::hdl::params_header;
/// use specfx::pipeline::{Config, Datapath};
/// let h = params_header(&Datapath::new(Config::baseline()).unwrap(), Arch::Pipelined);
/// assert!(h.contains("`define SPECFX_T_W 18\n"));
/// assert!(h.contains("`define SPECFX_SQ4_W 17\n`define SPECFX_SQ4_F 16\n"));
/// ```
pub fn params_header(dp: &Datapath, arch: Arch) -> String {
    define_header(dp, arch, false)
}

fn define_header(dp: &Datapath, arch: Arch, reset_data: bool) -> String {
    let cfg = dp.config();
    let mut h = format!(
        "// specfx parameters: configuration '{}', architecture {}, latency {} cycles.\n// Generated by `specfx hdl params`; include before specfx_dut.v.\n",
        cfg.name,
        arch,
        arch.latency(cfg)
    );
    for (name, value) in top_parameters(dp, arch, reset_data) {
        writeln!(h, "`define SPECFX_{name} {value}").expect("write to String");
    }
    h
}

/// Whether every slope is a power of two: the plain variant (slope n with k fraction bits) with
/// every n a power of two. The pipelined RTL then shifts d by the slope's one set bit instead
/// of multiplying (`SPECFX_SLOPE_POW2`), and the cost model prices a shifter.
///
/// # Examples
/// ```
/// use specfx::hdl::slope_is_pow2;
/// use specfx::nset::NSet;
/// use specfx::pipeline::Config;
/// let mut cfg = Config::baseline();
/// assert!(!slope_is_pow2(&cfg)); // n = 16..1024
/// cfg.n = NSet::from_values(&[16, 64, 256, 1024]).unwrap();
/// assert!(slope_is_pow2(&cfg));
/// ```
pub fn slope_is_pow2(cfg: &crate::pipeline::Config) -> bool {
    cfg.variant == crate::pipeline::Variant::Plain
        && cfg.n.values().iter().all(|n| n.is_power_of_two())
}

/// How `specfx hdl params` renders a configuration's parameters (its `--format` values).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamsFormat {
    /// `specfx_params.vh`: `` `define SPECFX_<NAME> <value> `` lines for `specfx_dut.v`.
    Define,
    /// A JSON object `{"NAME": value, ...}` (cocotb, VUnit, FuseSoC scripts).
    Json,
    /// Icarus Verilog flags, one per line: `-P<top>.<NAME>=<value>`.
    Iverilog,
    /// Verilator flags, one per line: `-G<NAME>=<value>` (for the top module).
    Verilator,
    /// FuseSoC parameter flags, one per line: `--<NAME>=<value>` (`fusesoc run --target T
    /// specfx:specfx:specfx_top` takes them after the core's name; `hdl_ref/specfx.core`).
    Fusesoc,
    /// A Verilog instantiation of `specfx_top` with every parameter set.
    Instance,
}

impl ParamsFormat {
    /// Every format, in the order `--help` lists them.
    pub const ALL: [ParamsFormat; 6] = [
        ParamsFormat::Define,
        ParamsFormat::Json,
        ParamsFormat::Iverilog,
        ParamsFormat::Verilator,
        ParamsFormat::Fusesoc,
        ParamsFormat::Instance,
    ];

    /// Its name as `--format` takes it.
    pub fn name(self) -> &'static str {
        match self {
            ParamsFormat::Define => "define",
            ParamsFormat::Json => "json",
            ParamsFormat::Iverilog => "iverilog",
            ParamsFormat::Verilator => "verilator",
            ParamsFormat::Fusesoc => "fusesoc",
            ParamsFormat::Instance => "instance",
        }
    }

    /// What it writes, in one line (`--help`).
    pub fn help(self) -> &'static str {
        match self {
            ParamsFormat::Define => {
                "`specfx_params.vh`: `` `define SPECFX_<NAME> <value> `` lines for `specfx_dut.v`"
            }
            ParamsFormat::Json => "A JSON object `{\"NAME\": value, ...}` (cocotb, VUnit, FuseSoC scripts)",
            ParamsFormat::Iverilog => "Icarus Verilog flags, one per line: `-P<top>.<NAME>=<value>`",
            ParamsFormat::Verilator => {
                "Verilator flags, one per line: `-G<NAME>=<value>` (for the top module)"
            }
            ParamsFormat::Fusesoc => {
                "FuseSoC flags, one per line: `--<NAME>=<value>` (after the core's name in `fusesoc run`; hdl_ref/specfx.core)"
            }
            ParamsFormat::Instance => "A Verilog instantiation of `specfx_top` with every parameter set",
        }
    }
}

crate::names::named_enum!(
    ParamsFormat,
    "parameter format",
    "define, json, iverilog, verilator, fusesoc or instance"
);

/// The parameters of [`top_parameters`] rendered in `format`; `top` names the module whose
/// parameters Icarus's `-P` flags set (the testbench or `specfx_top`).
///
/// # Examples
/// ```
/// use specfx::cycle::Arch;
/// use specfx::hdl::{render_parameters, ParamsFormat};
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let flags = render_parameters(&dp, Arch::Pipelined, true, ParamsFormat::Iverilog, "tb");
/// assert!(flags.starts_with("-Ptb.ARCH=0\n-Ptb.K=4\n"));
/// assert!(flags.ends_with("-Ptb.RESET_DATA=1\n-Ptb.DEPTH_MIN=4\n"));
/// ```
pub fn render_parameters(
    dp: &Datapath,
    arch: Arch,
    reset_data: bool,
    format: ParamsFormat,
    top: &str,
) -> String {
    let params = top_parameters(dp, arch, reset_data);
    let mut s = String::new();
    match format {
        ParamsFormat::Define => s = define_header(dp, arch, reset_data),
        ParamsFormat::Json => {
            let map: serde_json::Map<String, serde_json::Value> = params
                .into_iter()
                .map(|(k, v)| (k, serde_json::Value::from(v)))
                .collect();
            s = serde_json::to_string_pretty(&map).expect("a map of integers") + "\n";
        }
        ParamsFormat::Iverilog => {
            for (name, value) in params {
                writeln!(s, "-P{top}.{name}={value}").expect("write to String");
            }
        }
        ParamsFormat::Verilator => {
            for (name, value) in params {
                writeln!(s, "-G{name}={value}").expect("write to String");
            }
        }
        ParamsFormat::Fusesoc => {
            for (name, value) in params {
                writeln!(s, "--{name}={value}").expect("write to String");
            }
        }
        ParamsFormat::Instance => {
            let cfg = dp.config();
            writeln!(
                s,
                "// specfx_top for configuration '{}', architecture {arch} (specfx hdl params --format instance).",
                cfg.name
            )
            .expect("write to String");
            s.push_str("specfx_top #(\n");
            let n = params.len();
            for (i, (name, value)) in params.into_iter().enumerate() {
                let sep = if i + 1 < n { "," } else { "" };
                writeln!(s, "    .{name}({value}){sep}").expect("write to String");
            }
            s.push_str(") u_specfx (\n");
            s.push_str(&instance_connections());
            s.push_str(");\n");
        }
    }
    s
}

/// The port connections of the instance text, each port to a wire of its own name (from the
/// one port table, `pipeline::ports`): a line for the clock and reset, one for the input
/// handshake, the data inputs three to a line, and one for the output side.
fn instance_connections() -> String {
    use crate::pipeline::ports::{Carries, TOP_PORTS};
    let group = |c: Carries| match c {
        Carries::Clock | Carries::Reset => 0,
        Carries::InValid | Carries::InReady => 1,
        Carries::C | Carries::PerN(_) => 2,
        Carries::OutValid | Carries::OutReady | Carries::OutData => 3,
    };
    let mut lines: Vec<Vec<String>> = Vec::new();
    let mut last = None;
    for p in &TOP_PORTS {
        let g = group(p.carries);
        let full = lines.last().is_some_and(|l| l.len() == 3);
        if last != Some(g) || full {
            lines.push(Vec::new());
        }
        last = Some(g);
        lines
            .last_mut()
            .expect("a line")
            .push(format!(".{0}({0})", p.name));
    }
    let n = lines.len();
    lines
        .iter()
        .enumerate()
        .map(|(i, l)| format!("    {}{}\n", l.join(", "), if i + 1 < n { "," } else { "" }))
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_instance_connects_every_port_of_the_table() {
        // As an instance of specfx_top is written by hand (docs/faces.md, hdl_ref/README.md).
        assert_eq!(
            super::instance_connections(),
            "    .clk(clk), .rst(rst),\n    .in_valid(in_valid), .in_ready(in_ready),\n    \
             .in_c(in_c), .in_slope(in_slope), .in_offset(in_offset),\n    \
             .in_threshold(in_threshold), .in_coef(in_coef), .in_depth(in_depth),\n    \
             .out_valid(out_valid), .out_ready(out_ready), .out_data(out_data)\n"
        );
    }
}
