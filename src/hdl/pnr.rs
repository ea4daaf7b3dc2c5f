//! Place and route on iCE40 with nextpnr: devices and their resources, the harness around the
//! DUT, the yosys script and nextpnr command line, the reading of nextpnr's `--report` JSON,
//! and the timing figures built from it (the CLI runs the tools; nothing here starts a process).
//!
//! # The harness
//!
//! `specfx_dut` has far more ports than a package has pins (baseline: 71 input bits, 26 output
//! bits; an iCE40 UP5K in the SG48 package has 39 I/O), and nextpnr has no out-of-context mode.
//! So the DUT is placed and routed inside `specfx_pnr_top(clk, sin, sout)` ([`harness_verilog`]):
//!
//! 1. every DUT input (`rst`, `in_valid`, `out_ready` and every data bit) is a flip-flop of one
//!    serial shift register fed from the pin `sin`;
//! 2. every DUT output (`in_ready`, `out_valid`, `out_data`) is XORed into a flip-flop of a
//!    second shift register whose last bit drives the pin `sout`.
//!
//! Every output stays observable at `sout`, so synthesis removes nothing, and every path of the
//! datapath starts and ends at a register clocked by `clk`. The Fmax reported is the
//! register-to-register Fmax of the datapath inside the harness; the pin-to-register paths of
//! `sin` and `sout` are a different timing domain and are not part of it. The harness adds
//! [`HarnessBits::total`] flip-flops (one per DUT port bit) to the utilisation.
//!
//! # DSP blocks are not timed through
//!
//! nextpnr 0.4's iCE40 timing model treats every port of an `SB_MAC16` as a register clocked
//! by the block's `CLK` pin and has no delay through the block, so the multiplier's own delay
//! is never timed (`icetime` stops at the block's inputs too; no free tool models it):
//!
//! 1. where yosys left a block combinational (`CLK` tied to 0; the pipelined core quantizes
//!    each product before its register, so no register is absorbed), nextpnr reports the path
//!    *into* the block and the path *out of* it as cross-domain paths of that constant "clock",
//!    never the path through it. A path through the block takes at least the longer segment,
//!    so [`Timing::fmax_mhz`] is the smaller of nextpnr's Fmax and `1000 / longest segment`;
//! 2. where yosys absorbed an operand register into the block (`CLK` = `clk`, as in the folded
//!    core), its output is timed as if it were registered.
//!
//! Either way, a design with DSP blocks gets an Fmax that is an upper bound
//! ([`Timing::fmax_is_upper_bound`]); on a device without DSPs (HX8K) every path is timed.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::cycle::Arch;
use crate::error::Error;
use crate::pipeline::Datapath;

/// The name of the harness's top module.
pub const HARNESS_TOP: &str = "specfx_pnr_top";

/// nextpnr's placement seed: fixed, so the same design gives the same figures.
pub const NEXTPNR_SEED: u64 = 1;

/// The clock target given to nextpnr in MHz (48 MHz, the UP5K's internal oscillator). With
/// `--timing-allow-fail` it only steers timing-driven placement; the Fmax reported is what the
/// placed and routed design achieves, above or below it.
pub const NEXTPNR_FREQ_MHZ: u32 = 48;

/// An iCE40 device and package that nextpnr places and routes for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Device {
    /// iCE40 UltraPlus UP5K in the SG48 package: 5280 logic cells, 8 SB_MAC16 DSPs.
    Up5k,
    /// iCE40 HX8K in the CT256 package: 7680 logic cells, no DSPs (multipliers in LUTs).
    Hx8k,
}

/// The resources of a device (and package).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Limits {
    /// Logic cells: one LUT4, one flip-flop and one carry each (`ICESTORM_LC`).
    pub logic_cells: u64,
    /// LUT4s (one per logic cell).
    pub luts: u64,
    /// Flip-flops (one per logic cell).
    pub ffs: u64,
    /// SB_MAC16 DSP blocks (16 x 16 multipliers).
    pub dsps: u64,
    /// 4-kbit block RAMs (`SB_RAM40_4K`).
    pub bram_4k: u64,
    /// User I/O pins of the package.
    pub ios: u64,
}

impl Device {
    /// Every device.
    pub const ALL: [Device; 2] = [Device::Up5k, Device::Hx8k];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Device::Up5k => "up5k",
            Device::Hx8k => "hx8k",
        }
    }

    /// The name in reports: `iCE40 UP5K`.
    pub fn full_name(self) -> &'static str {
        match self {
            Device::Up5k => "iCE40 UP5K",
            Device::Hx8k => "iCE40 HX8K",
        }
    }

    /// nextpnr-ice40's device flag.
    pub fn nextpnr_flag(self) -> &'static str {
        match self {
            Device::Up5k => "--up5k",
            Device::Hx8k => "--hx8k",
        }
    }

    /// The package (nextpnr's `--package`).
    pub fn package(self) -> &'static str {
        match self {
            Device::Up5k => "sg48",
            Device::Hx8k => "ct256",
        }
    }

    /// The device's resources (from Lattice's data sheets; nextpnr's report agrees on the
    /// logic cells, DSPs and RAMs).
    ///
    /// # Examples
    /// ```
    /// use specfx::hdl::pnr::Device;
    /// assert_eq!(Device::Up5k.limits().dsps, 8);
    /// assert_eq!(Device::Hx8k.limits().luts, 7680);
    /// ```
    pub fn limits(self) -> Limits {
        match self {
            Device::Up5k => Limits {
                logic_cells: 5280,
                luts: 5280,
                ffs: 5280,
                dsps: 8,
                bram_4k: 30,
                ios: 39,
            },
            Device::Hx8k => Limits {
                logic_cells: 7680,
                luts: 7680,
                ffs: 7680,
                dsps: 0,
                bram_4k: 32,
                ios: 206,
            },
        }
    }

    /// Whether the device has DSP blocks (yosys maps multipliers to SB_MAC16 only then).
    pub fn has_dsps(self) -> bool {
        self.limits().dsps > 0
    }
}

crate::names::named_enum!(Device, "device", "up5k or hx8k");

/// The resource flags of a design on a device: one line per resource it needs more of than
/// the device has (`9 DSPs > 8 on iCE40 UP5K`); empty when it fits. Needs no place and route:
/// the counts may come from yosys or from the analytic model.
///
/// A LUT4 and a flip-flop share a logic cell, so a design within both limits can still fail
/// to pack; nextpnr is the judge of that.
///
/// # Examples
/// ```
/// use specfx::hdl::pnr::{device_check, Device};
/// assert!(device_check(7, 800, 400, Device::Up5k).is_empty());
/// assert_eq!(device_check(9, 800, 400, Device::Up5k), ["9 DSPs > 8 on iCE40 UP5K"]);
/// assert_eq!(device_check(1, 800, 400, Device::Hx8k), ["1 DSPs > 0 on iCE40 HX8K"]);
/// ```
pub fn device_check(dsps: u64, luts: u64, ffs: u64, device: Device) -> Vec<String> {
    let limits = device.limits();
    [
        ("DSPs", dsps, limits.dsps),
        ("LUTs", luts, limits.luts),
        ("flip-flops", ffs, limits.ffs),
    ]
    .into_iter()
    .filter(|&(_, used, available)| used > available)
    .map(|(what, used, available)| format!("{used} {what} > {available} on {}", device.full_name()))
    .collect()
}

/// The flip-flops the harness adds around the DUT: one per input bit and one per output bit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct HarnessBits {
    /// DUT input bits: every input port of the table of the top's ports
    /// ([`TOP_PORTS`](crate::pipeline::ports::TOP_PORTS)) but the clock, the depth only when
    /// some n bypasses a squaring stage.
    pub inputs: u64,
    /// DUT output bits: `in_ready`, `out_valid`, `out_data`.
    pub outputs: u64,
}

impl HarnessBits {
    /// The harness's flip-flops.
    pub fn total(self) -> u64 {
        self.inputs + self.outputs
    }
}

/// The harness's shift-register lengths for a datapath (the DUT's port widths).
///
/// # Examples
/// ```
/// use specfx::hdl::pnr::harness_bits;
/// use specfx::pipeline::{Config, Datapath};
/// let bits = harness_bits(&Datapath::new(Config::baseline()).unwrap());
/// // 3 control bits, c and threshold u1.15, slope 11 bits, offset 1 bit, coef 24 bits.
/// assert_eq!(bits.inputs, 3 + 2 * 16 + 11 + 1 + 24);
/// assert_eq!(bits.outputs, 2 + 24);
/// ```
pub fn harness_bits(dp: &Datapath) -> HarnessBits {
    use crate::pipeline::ports::{Carries, Direction, PerN, TOP_PORTS};
    // Every port but the clock; the depth only where some n bypasses a squaring stage.
    let bits = |direction: Direction| -> u64 {
        TOP_PORTS
            .iter()
            .filter(|p| p.direction == direction && p.carries != Carries::Clock)
            .filter(|p| p.carries != Carries::PerN(PerN::Depth) || dp.config().has_bypass())
            .map(|p| u64::from(p.width(dp)))
            .sum()
    };
    HarnessBits {
        inputs: bits(Direction::Input),
        outputs: bits(Direction::Output),
    }
}

/// The harness `specfx_pnr_top.v`: `specfx_dut` between two shift registers (see the module
/// docs). The text is the same for every configuration: it reads the port widths from
/// `specfx_params.vh`, like `specfx_dut.v`.
///
/// # Examples
/// ```
/// let v = specfx::hdl::pnr::harness_verilog();
/// assert!(v.contains("module specfx_pnr_top ("));
/// assert!(v.contains("specfx_dut u_dut ("));
/// ```
pub fn harness_verilog() -> String {
    HARNESS.to_string()
}

/// `hdl_ref/specfx_pnr_top.v`, the harness's text (`tests/model/ports.rs` holds its instance of
/// `specfx_dut` to the table of the top's ports).
const HARNESS: &str = include_str!("../../hdl_ref/specfx_pnr_top.v");

/// The yosys script that synthesises the harness for a device: `synth_ice40` (with `-dsp` when
/// the device has DSP blocks) writing `design.json` for nextpnr, and `stat.json` (the cell
/// counts `specfx cost` reads). `files` are the DUT's sources then the harness;
/// `include_dir` holds `specfx_params.vh`.
///
/// # Examples
/// ```
/// use specfx::hdl::pnr::{pnr_yosys_script, Device};
/// let s = pnr_yosys_script(Device::Up5k, &["a.v".into()], "/tmp/w");
/// assert!(s.contains("synth_ice40 -dsp -top specfx_pnr_top -json design.json\n"));
/// ```
pub fn pnr_yosys_script(device: Device, files: &[String], include_dir: &str) -> String {
    let dsp = if device.has_dsps() { " -dsp" } else { "" };
    format!(
        "read_verilog -I{include_dir} {}\nhierarchy -check -top {HARNESS_TOP}\nsynth_ice40{dsp} -top {HARNESS_TOP} -json design.json\ntee -q -o stat.json stat -json\n",
        files.join(" ")
    )
}

/// nextpnr-ice40's arguments (run in the directory holding `design.json`): the device and
/// package, pins placed freely (`--pcf-allow-unconstrained`: the harness has three), a fixed
/// seed, the target clock, `--timing-allow-fail` (report the Fmax achieved rather than fail),
/// and the report `report.json`; the log goes to `nextpnr.log`.
///
/// # Examples
/// ```
/// use specfx::hdl::pnr::{nextpnr_args, Device};
/// let a = nextpnr_args(Device::Up5k).join(" ");
/// assert!(a.starts_with("--up5k --package sg48 --json design.json --report report.json"));
/// ```
pub fn nextpnr_args(device: Device) -> Vec<String> {
    [
        device.nextpnr_flag(),
        "--package",
        device.package(),
        "--json",
        "design.json",
        "--report",
        "report.json",
        "--freq",
        &NEXTPNR_FREQ_MHZ.to_string(),
        "--seed",
        &NEXTPNR_SEED.to_string(),
        "--timing-allow-fail",
        "--pcf-allow-unconstrained",
        "-q",
        "-l",
        "nextpnr.log",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

/// One clock's Fmax in nextpnr's report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClockFmax {
    /// nextpnr's name of the clock net (`clk$SB_IO_IN_$glb_clk`).
    pub clock: String,
    /// The Fmax achieved, MHz.
    pub achieved_mhz: f64,
    /// The target, MHz.
    pub constraint_mhz: f64,
}

/// One resource's utilisation in nextpnr's report.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Utilisation {
    /// nextpnr's bel type (`ICESTORM_LC`, `ICESTORM_DSP`, `ICESTORM_RAM`, `SB_IO`, `SB_GB`..).
    pub resource: String,
    /// Used.
    pub used: u64,
    /// Available on the device (all of the die's, e.g. 96 `SB_IO` on a UP5K whatever the
    /// package).
    pub available: u64,
}

/// One end of a timing path: a cell's port.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct PathEnd {
    /// The cell (a packed logic cell, DSP or I/O; names come from the netlist).
    pub cell: String,
    /// Its port.
    pub port: String,
}

/// A critical path of nextpnr's report, summarised.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CriticalPath {
    /// The launching clock edge (`posedge clk$SB_IO_IN_$glb_clk`, or `<async>` for a pin).
    pub from_clock: String,
    /// The capturing clock edge.
    pub to_clock: String,
    /// Where the path starts (a register's output).
    pub start: PathEnd,
    /// Where it ends (a register's input).
    pub end: PathEnd,
    /// Total delay, ns: clock-to-output, logic, routing and setup.
    pub delay_ns: f64,
    /// The part of it in cells (logic, clock-to-output, setup), ns.
    pub logic_ns: f64,
    /// The part of it in routing, ns.
    pub routing_ns: f64,
    /// Cells traversed between the two registers (nextpnr's `logic` steps).
    pub logic_levels: u64,
    /// Steps of the path (cells and nets).
    pub segments: u64,
}

/// What nextpnr's `--report` JSON says.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NextpnrReport {
    /// Every clock's Fmax.
    pub clocks: Vec<ClockFmax>,
    /// Every resource of the device with its use, by name.
    pub utilisation: Vec<Utilisation>,
    /// The critical path of every pair of clock domains nextpnr reports.
    pub critical_paths: Vec<CriticalPath>,
}

fn tool_error(message: String) -> Error {
    Error::Tool {
        tool: "nextpnr",
        message,
    }
}

/// Reads nextpnr's `--report` JSON (`fmax`, `utilization`, `critical_paths`).
///
/// nextpnr 0.4 labels the first step of a path oddly (a clock-to-output step's `from` names
/// another cell's clock pin), so a path's start is its first step's `to` and its end its last
/// step's `to`.
///
/// # Examples
/// ```
/// let text = r#"{"fmax": {"clk": {"achieved": 50.0, "constraint": 12}},
///   "utilization": {"ICESTORM_DSP": {"available": 8, "used": 2}},
///   "critical_paths": [{"from": "posedge clk", "to": "posedge clk", "path": [
///     {"type": "clk-to-q", "delay": 1.4, "from": {"cell": "x", "port": "CLK"}, "to": {"cell": "a", "port": "O"}},
///     {"type": "routing", "delay": 3.0, "from": {"cell": "a", "port": "O"}, "to": {"cell": "b", "port": "I0"}},
///     {"type": "logic", "delay": 1.2, "from": {"cell": "b", "port": "I0"}, "to": {"cell": "b", "port": "O"}},
///     {"type": "setup", "delay": 0.1, "from": {"cell": "b", "port": "O"}, "to": {"cell": "b", "port": "O"}}]}]}"#;
/// let r = specfx::hdl::pnr::parse_report(text).unwrap();
/// assert_eq!(r.clocks[0].achieved_mhz, 50.0);
/// assert_eq!(r.critical_paths[0].start.cell, "a");
/// assert_eq!(r.critical_paths[0].logic_levels, 1);
/// ```
pub fn parse_report(text: &str) -> Result<NextpnrReport, Error> {
    let v: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| tool_error(format!("cannot read nextpnr's report: {e}")))?;
    let fmax = v
        .get("fmax")
        .and_then(|f| f.as_object())
        .ok_or_else(|| tool_error("nextpnr's report has no fmax".into()))?;
    let clocks = fmax
        .iter()
        .map(|(clock, f)| ClockFmax {
            clock: clock.clone(),
            achieved_mhz: f["achieved"].as_f64().unwrap_or(0.0),
            constraint_mhz: f["constraint"].as_f64().unwrap_or(0.0),
        })
        .collect();
    let utilisation = v
        .get("utilization")
        .and_then(|u| u.as_object())
        .ok_or_else(|| tool_error("nextpnr's report has no utilization".into()))?
        .iter()
        .map(|(resource, u)| Utilisation {
            resource: resource.clone(),
            used: u["used"].as_u64().unwrap_or(0),
            available: u["available"].as_u64().unwrap_or(0),
        })
        .collect();
    let mut critical_paths = Vec::new();
    for p in v
        .get("critical_paths")
        .and_then(|p| p.as_array())
        .map_or(&[][..], |p| p.as_slice())
    {
        let steps = p["path"].as_array().map_or(&[][..], |s| s.as_slice());
        let end_of = |step: Option<&serde_json::Value>| {
            let to = step.map(|s| &s["to"]);
            PathEnd {
                cell: to
                    .and_then(|t| t["cell"].as_str())
                    .unwrap_or("")
                    .to_string(),
                port: to
                    .and_then(|t| t["port"].as_str())
                    .unwrap_or("")
                    .to_string(),
            }
        };
        let delay = |kind: Option<&str>| -> f64 {
            steps
                .iter()
                .filter(|s| kind.is_none_or(|k| s["type"].as_str() == Some(k)))
                .map(|s| s["delay"].as_f64().unwrap_or(0.0))
                .sum()
        };
        let delay_ns = delay(None);
        let routing_ns = delay(Some("routing"));
        critical_paths.push(CriticalPath {
            from_clock: p["from"].as_str().unwrap_or("").to_string(),
            to_clock: p["to"].as_str().unwrap_or("").to_string(),
            start: end_of(steps.first()),
            end: end_of(steps.last()),
            delay_ns,
            logic_ns: delay_ns - routing_ns,
            routing_ns,
            logic_levels: steps
                .iter()
                .filter(|s| s["type"].as_str() == Some("logic"))
                .count() as u64,
            segments: steps.len() as u64,
        });
    }
    Ok(NextpnrReport {
        clocks,
        utilisation,
        critical_paths,
    })
}

/// Whether a clock name of nextpnr's is the harness's `clk` (`clk$SB_IO_IN_$glb_clk`).
fn is_harness_clock(name: &str) -> bool {
    let name = name.strip_prefix("posedge ").unwrap_or(name);
    name == "clk" || name.starts_with("clk$")
}

/// Whether a clock name of nextpnr's is a constant net (the tied `CLK` of a combinational DSP).
fn is_constant_clock(name: &str) -> bool {
    name.contains("$PACKER_GND_NET") || name.contains("$PACKER_VCC_NET")
}

/// The paths nextpnr times up to and from combinational DSP blocks, but not through them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UntimedDsp {
    /// The longest path from a register to a DSP's input, ns.
    pub into_ns: Option<f64>,
    /// The longest path from a DSP's output to a register, ns.
    pub out_of_ns: Option<f64>,
    /// The longest path from a DSP's output to another DSP's input, ns.
    pub between_ns: Option<f64>,
}

impl UntimedDsp {
    /// The longest segment: a lower bound on the register-to-register delay through a DSP.
    pub fn longest_ns(&self) -> f64 {
        [self.into_ns, self.out_of_ns, self.between_ns]
            .into_iter()
            .flatten()
            .fold(0.0, f64::max)
    }
}

/// The cells yosys mapped the harnessed design to (from its `stat`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct SynthCells {
    /// SB_LUT4 cells.
    pub luts: u64,
    /// Flip-flops (the harness's [`HarnessBits::total`] included).
    pub ffs: u64,
    /// SB_MAC16 blocks.
    pub dsps: u64,
}

/// Real timing of a datapath on a device: nextpnr's figures and what follows from them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Timing {
    /// Configuration name.
    pub config: String,
    /// Architecture.
    pub arch: Arch,
    /// The device (and package).
    pub device: Device,
    /// Its full name (`iCE40 UP5K`).
    pub device_name: &'static str,
    /// The package.
    pub package: &'static str,
    /// Whether nextpnr placed and routed the design.
    pub fits: bool,
    /// The register-to-register Fmax of the datapath inside the harness, MHz: nextpnr's Fmax
    /// of the clock, capped by the paths into and out of unregistered DSPs (see the module
    /// docs). None when the design does not fit.
    pub fmax_mhz: Option<f64>,
    /// nextpnr's own Fmax of the clock, MHz.
    pub nextpnr_fmax_mhz: Option<f64>,
    /// Whether `fmax_mhz` is only an upper bound: the design has DSP blocks, and nextpnr does
    /// not time the multiplier's delay (see the module docs).
    pub fmax_is_upper_bound: bool,
    /// The segments of paths through combinational DSPs, when there are any.
    pub untimed_dsp: Option<UntimedDsp>,
    /// The clock's critical path.
    pub critical_path: Option<CriticalPath>,
    /// Every resource the device has, with its use (empty when the design does not fit).
    pub utilisation: Vec<Utilisation>,
    /// What yosys mapped the harnessed design to.
    pub synthesis: SynthCells,
    /// Flip-flops of the harness (in `synthesis.ffs` and the logic cells, not in the DUT).
    pub harness_ffs: u64,
    /// Resources the design needs more of than the device has (`9 DSPs > 8 on iCE40 UP5K`),
    /// from yosys's counts without the harness's flip-flops.
    pub over_limit: Vec<String>,
    /// Input-to-output latency, cycles.
    pub latency_cycles: u64,
    /// Initiation interval, cycles.
    pub initiation_interval: u64,
    /// Latency at Fmax, ns: `latency_cycles * 1000 / fmax_mhz`.
    pub latency_ns: Option<f64>,
    /// Throughput at Fmax, samples per second: `fmax_mhz * 1e6 / initiation_interval`.
    pub throughput_samples_per_s: Option<f64>,
}

impl Timing {
    /// The timing of a datapath from nextpnr's report (None when nextpnr could not place the
    /// design) and yosys's cell counts of the harnessed design.
    ///
    /// # Examples
    /// ```
    /// use specfx::cycle::Arch;
    /// use specfx::hdl::pnr::{Device, SynthCells, Timing};
    /// use specfx::pipeline::{Config, Datapath};
    /// let dp = Datapath::new(Config::baseline()).unwrap();
    /// let cells = SynthCells { luts: 6000, ffs: 500, dsps: 9 };
    /// let t = Timing::new(&dp, Arch::Pipelined, Device::Up5k, None, cells);
    /// assert_eq!(t.fmax_mhz, None);
    /// assert_eq!(t.over_limit, ["9 DSPs > 8 on iCE40 UP5K", "6000 LUTs > 5280 on iCE40 UP5K"]);
    /// ```
    pub fn new(
        dp: &Datapath,
        arch: Arch,
        device: Device,
        report: Option<&NextpnrReport>,
        synthesis: SynthCells,
    ) -> Timing {
        let cfg = dp.config();
        let harness_ffs = harness_bits(dp).total();
        let latency_cycles = arch.latency(cfg);
        let initiation_interval = arch.initiation_interval(cfg);
        let over_limit = device_check(
            synthesis.dsps,
            synthesis.luts,
            synthesis.ffs.saturating_sub(harness_ffs),
            device,
        );
        let clock = report.and_then(|r| r.clocks.iter().find(|c| is_harness_clock(&c.clock)));
        let nextpnr_fmax_mhz = clock.map(|c| c.achieved_mhz);
        let paths = report.map_or(&[][..], |r| r.critical_paths.as_slice());
        let critical_path = paths
            .iter()
            .find(|p| is_harness_clock(&p.from_clock) && is_harness_clock(&p.to_clock))
            .cloned();
        let segment = |from: fn(&str) -> bool, to: fn(&str) -> bool| {
            paths
                .iter()
                .filter(|p| from(&p.from_clock) && to(&p.to_clock))
                .map(|p| p.delay_ns)
                .reduce(f64::max)
        };
        let untimed = UntimedDsp {
            into_ns: segment(is_harness_clock, is_constant_clock),
            out_of_ns: segment(is_constant_clock, is_harness_clock),
            between_ns: segment(is_constant_clock, is_constant_clock),
        };
        let untimed_dsp = (untimed.longest_ns() > 0.0).then_some(untimed);
        let fmax_mhz = nextpnr_fmax_mhz.map(|f| match &untimed_dsp {
            Some(u) => f.min(1000.0 / u.longest_ns()),
            None => f,
        });
        let utilisation = report.map_or_else(Vec::new, |r| r.utilisation.clone());
        Timing {
            config: cfg.name.clone(),
            arch,
            device,
            device_name: device.full_name(),
            package: device.package(),
            fits: report.is_some(),
            fmax_is_upper_bound: fmax_mhz.is_some()
                && (synthesis.dsps > 0 || untimed_dsp.is_some()),
            latency_ns: fmax_mhz.map(|f| latency_cycles as f64 * 1000.0 / f),
            throughput_samples_per_s: fmax_mhz.map(|f| f * 1e6 / initiation_interval as f64),
            fmax_mhz,
            nextpnr_fmax_mhz,
            untimed_dsp,
            critical_path,
            utilisation,
            synthesis,
            harness_ffs,
            over_limit,
            latency_cycles,
            initiation_interval,
        }
    }

    /// The utilisation of one resource by nextpnr's name.
    pub fn used(&self, resource: &str) -> Option<&Utilisation> {
        self.utilisation.iter().find(|u| u.resource == resource)
    }
}

/// The resources worth printing: every one the design uses, and the logic cells, DSPs and
/// RAMs always, in nextpnr's (alphabetical) order.
pub fn utilisation_rows(utilisation: &[Utilisation]) -> Vec<&Utilisation> {
    let always: BTreeMap<&str, ()> = ["ICESTORM_LC", "ICESTORM_DSP", "ICESTORM_RAM"]
        .into_iter()
        .map(|r| (r, ()))
        .collect();
    utilisation
        .iter()
        .filter(|u| u.available > 0 && (u.used > 0 || always.contains_key(u.resource.as_str())))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::Config;

    const SAMPLE: &str = include_str!("../../tests/data/nextpnr_report_up5k.json");

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    #[test]
    fn report_sample_is_read() {
        // A trimmed report of baseline pipelined on a UP5K (the first three and last two steps
        // of each path kept); every expected figure below is read off the file by hand.
        let r = parse_report(SAMPLE).unwrap();
        assert_eq!(r.clocks.len(), 1);
        assert_eq!(r.clocks[0].clock, "clk$SB_IO_IN_$glb_clk");
        assert!(close(r.clocks[0].achieved_mhz, 25.116));
        assert!(close(r.clocks[0].constraint_mhz, 50.0));
        let dsp = r
            .utilisation
            .iter()
            .find(|u| u.resource == "ICESTORM_DSP")
            .unwrap();
        assert_eq!((dsp.used, dsp.available), (7, 8));
        let lc = r
            .utilisation
            .iter()
            .find(|u| u.resource == "ICESTORM_LC")
            .unwrap();
        assert_eq!(lc.available, 5280);
        assert_eq!(r.critical_paths.len(), 5);
        let p = &r.critical_paths[0];
        assert_eq!(p.from_clock, "posedge clk$SB_IO_IN_$glb_clk");
        assert!(p.start.cell.contains("g_square[4].r_square"));
        assert_eq!(p.start.port, "O");
        assert!(p.end.cell.contains("r_mul_out"));
        assert_eq!(p.end.port, "SR");
        // clk-to-q 1.39, routing 2.952, logic 1.205, routing 0.635, setup 0.1.
        assert!(close(p.delay_ns, 1.39 + 2.952 + 1.205 + 0.635 + 0.1));
        assert!(close(p.routing_ns, 2.952 + 0.635));
        assert_eq!((p.logic_levels, p.segments), (1, 5));
        assert_eq!(r.critical_paths[2].from_clock, "<async>");
        assert_eq!(r.critical_paths[2].start.cell, "sin$sb_io");
    }

    #[test]
    fn timing_of_the_sample_caps_fmax_at_the_dsp_segments() {
        let r = parse_report(SAMPLE).unwrap();
        let dp = Datapath::new(Config::baseline()).unwrap();
        let cells = SynthCells {
            luts: 767,
            ffs: 413,
            dsps: 7,
        };
        let t = Timing::new(&dp, Arch::Pipelined, Device::Up5k, Some(&r), cells);
        let u = t.untimed_dsp.as_ref().unwrap();
        // Into a DSP: 1.39 + 5.439 + 0.1; out of one: the first three and last two steps.
        assert!(close(u.into_ns.unwrap(), 1.39 + 5.439 + 0.1));
        assert!(close(
            u.out_of_ns.unwrap(),
            0.1 + 5.229 + 0.609 + 0.635 + 0.1
        ));
        assert_eq!(u.between_ns, None);
        // The trimmed segments are short: nextpnr's 25.116 MHz is the smaller.
        assert!(close(t.fmax_mhz.unwrap(), 25.116));
        assert!(t.fmax_is_upper_bound);
        assert_eq!(t.latency_cycles, 8);
        assert!(close(t.latency_ns.unwrap(), 8.0 * 1000.0 / 25.116));
        assert!(close(t.throughput_samples_per_s.unwrap(), 25.116e6));
        assert!(t.over_limit.is_empty());
        assert!(t.critical_path.unwrap().end.cell.contains("r_mul_out"));
        let rows: Vec<&str> = utilisation_rows(&t.utilisation)
            .iter()
            .map(|u| u.resource.as_str())
            .collect();
        assert_eq!(
            rows,
            [
                "ICESTORM_DSP",
                "ICESTORM_LC",
                "ICESTORM_RAM",
                "SB_GB",
                "SB_IO"
            ]
        );
    }

    #[test]
    fn a_long_dsp_segment_caps_fmax() {
        let mut r = parse_report(SAMPLE).unwrap();
        r.critical_paths[1].delay_ns = 50.0; // out of a DSP: 50 ns, so at most 20 MHz
        let dp = Datapath::new(Config::baseline()).unwrap();
        let cells = SynthCells {
            luts: 767,
            ffs: 413,
            dsps: 7,
        };
        let t = Timing::new(&dp, Arch::Folded, Device::Up5k, Some(&r), cells);
        assert!(close(t.fmax_mhz.unwrap(), 20.0));
        assert!(close(t.nextpnr_fmax_mhz.unwrap(), 25.116));
        // Folded baseline: II = (k + 2) * lat_mul = 6.
        assert_eq!(t.initiation_interval, 6);
        assert!(close(t.throughput_samples_per_s.unwrap(), 20e6 / 6.0));
    }

    #[test]
    fn without_dsps_fmax_is_nextpnrs() {
        let mut r = parse_report(SAMPLE).unwrap();
        r.critical_paths
            .retain(|p| !p.from_clock.contains("PACKER") && !p.to_clock.contains("PACKER"));
        let dp = Datapath::new(Config::baseline()).unwrap();
        let cells = SynthCells {
            luts: 4381,
            ffs: 429,
            dsps: 0,
        };
        let t = Timing::new(&dp, Arch::Pipelined, Device::Hx8k, Some(&r), cells);
        assert_eq!(t.untimed_dsp, None);
        assert!(!t.fmax_is_upper_bound);
        assert!(close(t.fmax_mhz.unwrap(), 25.116));
    }

    #[test]
    fn device_check_flags_each_resource_over_its_limit() {
        let check = |dsps, luts, ffs, d| device_check(dsps, luts, ffs, d);
        assert!(check(8, 5280, 5280, Device::Up5k).is_empty());
        assert_eq!(
            check(9, 5281, 5281, Device::Up5k),
            [
                "9 DSPs > 8 on iCE40 UP5K",
                "5281 LUTs > 5280 on iCE40 UP5K",
                "5281 flip-flops > 5280 on iCE40 UP5K"
            ]
        );
        assert!(check(0, 7680, 7680, Device::Hx8k).is_empty());
        assert_eq!(
            check(0, 7681, 10, Device::Hx8k),
            ["7681 LUTs > 7680 on iCE40 HX8K"]
        );
    }

    #[test]
    fn devices_have_names() {
        for d in Device::ALL {
            assert_eq!(d.name().parse::<Device>().unwrap(), d);
        }
        assert!("UP5K".parse::<Device>().is_ok());
        assert!("ecp5".parse::<Device>().is_err());
        assert!(!Device::Hx8k.has_dsps());
        let s = pnr_yosys_script(Device::Hx8k, &["a.v".into(), "b.v".into()], "/w");
        assert_eq!(
            s,
            "read_verilog -I/w a.v b.v\nhierarchy -check -top specfx_pnr_top\nsynth_ice40 -top specfx_pnr_top -json design.json\ntee -q -o stat.json stat -json\n"
        );
        assert!(nextpnr_args(Device::Hx8k)
            .join(" ")
            .contains("--hx8k --package ct256"));
    }

    #[test]
    fn a_report_without_fmax_is_an_error() {
        assert!(parse_report("{}").is_err());
        assert!(parse_report("not json").is_err());
    }
}
