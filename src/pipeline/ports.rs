//! The ports of `specfx_top`, the reference RTL's top, written once: each port's name, its
//! direction, its width (the model's format, and the Verilog parameter that sizes it), and for
//! the per-n inputs the constant it carries ([`PerN`]).
//!
//! Everything that names a port loops over this table: the vector files and their columns,
//! the VCD traces, the register views of the per-n constants, the instance text, the
//! place-and-route harness, the co-simulation's file list, the ROM's fields and the C and
//! Python faces' constants. `tests/model/ports.rs` reads the port lists of `specfx_top`,
//! `specfx_pipelined` and `specfx_folded` and holds them to [`TOP_PORTS`].
//!
//! **Invariant:** a new per-n input is one [`PerN`] variant (its port, field, format and
//! value here), the walk's use of it, and the Verilog: no other file spells its name.

use crate::fixed::Format;
use crate::pipeline::{Datapath, NConstants, DEPTH_BITS};

/// Which way a port of the top points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Driven by the testbench or the surrounding design.
    Input,
    /// Driven by the datapath.
    Output,
}

/// A per-n constant: what the per-n ROM stores for each exponent and the datapath reads on an
/// input port of its own, beside the input code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PerN {
    /// The slope: n / 2^j(n) with k fraction bits (plain) or A(n) (minimax).
    Slope,
    /// The offset: 1 (plain) or A(n) + B(n) (minimax).
    Offset,
    /// The paper cutoff's threshold code (0 for the other cutoffs).
    Threshold,
    /// The coefficient coef(n).
    Coef,
    /// j(n): the squarings n uses (k for a fixed depth).
    Depth,
}

impl PerN {
    /// Every per-n constant, in the order of the ports, the vector files and the faces.
    pub const ALL: [PerN; 5] = [
        PerN::Slope,
        PerN::Offset,
        PerN::Threshold,
        PerN::Coef,
        PerN::Depth,
    ];

    /// Its name as a field: of the ROM, the C struct, the Python tuple (`slope`, `depth`).
    pub fn field(self) -> &'static str {
        match self {
            PerN::Slope => "slope",
            PerN::Offset => "offset",
            PerN::Threshold => "threshold",
            PerN::Coef => "coef",
            PerN::Depth => "depth",
        }
    }

    /// The input port of `specfx_top` that carries it (`in_slope`, `in_depth`).
    pub const fn port(self) -> &'static str {
        match self {
            PerN::Slope => "in_slope",
            PerN::Offset => "in_offset",
            PerN::Threshold => "in_threshold",
            PerN::Coef => "in_coef",
            PerN::Depth => "in_depth",
        }
    }

    /// What it is, in a vector manifest's or a page's words.
    pub fn description(self) -> &'static str {
        match self {
            PerN::Slope => "slope: n with k fraction bits (plain) or A(n) (minimax)",
            PerN::Offset => "offset: 1 (plain) or A(n) + B(n) (minimax)",
            PerN::Threshold => {
                "paper cutoff: inputs below this code give 0 (0 for the other cutoffs)"
            }
            PerN::Coef => "coef(n), the per-n coefficient constant",
            PerN::Depth => {
                "j(n): the squarings n uses (stages past it pass their input through; k for a fixed depth)"
            }
        }
    }

    /// Its format on the port, for datapath `dp`.
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::ports::PerN;
    /// let dp = specfx::load_datapath("baseline", None).unwrap();
    /// let widths: Vec<u32> = PerN::ALL.iter().map(|p| p.format(&dp).width()).collect();
    /// // slope u7.4 (n <= 1024 with k = 4 fraction bits), offset u1.0, threshold as c
    /// // (u1.15), coef u8.16, depth 3 bits.
    /// assert_eq!(widths, [11, 1, 16, 24, 3]);
    /// ```
    pub fn format(self, dp: &Datapath) -> Format {
        let cfg = dp.config();
        match self {
            PerN::Slope => cfg.constant_formats().0,
            PerN::Offset => cfg.constant_formats().1,
            PerN::Threshold => cfg.c.format,
            PerN::Coef => cfg.coef.format,
            PerN::Depth => Format::unsigned(DEPTH_BITS as i32, 0).expect("a few bits"),
        }
    }

    /// Its raw code for one exponent, as the port shows it (the threshold 0 without the paper
    /// cutoff).
    pub fn raw(self, nc: &NConstants) -> i64 {
        match self {
            PerN::Slope => nc.slope_raw,
            PerN::Offset => nc.offset_raw,
            PerN::Threshold => nc.threshold.unwrap_or(0),
            PerN::Coef => nc.coef_raw,
            PerN::Depth => i64::from(nc.depth),
        }
    }
}

/// What a port of `specfx_top` carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Carries {
    /// `clk`.
    Clock,
    /// `rst`, synchronous and active high.
    Reset,
    /// `in_valid`.
    InValid,
    /// `in_ready`.
    InReady,
    /// `in_c`, the input cosine's code.
    C,
    /// A per-n constant.
    PerN(PerN),
    /// `out_valid`.
    OutValid,
    /// `out_ready`.
    OutReady,
    /// `out_data`, the output's code.
    OutData,
}

/// One port of `specfx_top`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TopPort {
    /// Its name in the Verilog.
    pub name: &'static str,
    /// Its direction.
    pub direction: Direction,
    /// What it carries.
    pub carries: Carries,
    /// Its width in the Verilog: the parameter that sizes it (`C_W`), or a number of bits.
    pub verilog_width: &'static str,
}

const fn port(
    name: &'static str,
    direction: Direction,
    carries: Carries,
    verilog_width: &'static str,
) -> TopPort {
    TopPort {
        name,
        direction,
        carries,
        verilog_width,
    }
}

/// The ports of `specfx_top` (and of both cores), in the Verilog's order.
pub const TOP_PORTS: [TopPort; 13] = [
    port("clk", Direction::Input, Carries::Clock, "1"),
    port("rst", Direction::Input, Carries::Reset, "1"),
    port("in_valid", Direction::Input, Carries::InValid, "1"),
    port("in_ready", Direction::Output, Carries::InReady, "1"),
    port("in_c", Direction::Input, Carries::C, "C_W"),
    port(
        PerN::Slope.port(),
        Direction::Input,
        Carries::PerN(PerN::Slope),
        "SLOPE_W",
    ),
    port(
        PerN::Offset.port(),
        Direction::Input,
        Carries::PerN(PerN::Offset),
        "OFFSET_W",
    ),
    port(
        PerN::Threshold.port(),
        Direction::Input,
        Carries::PerN(PerN::Threshold),
        "C_W",
    ),
    port(
        PerN::Coef.port(),
        Direction::Input,
        Carries::PerN(PerN::Coef),
        "COEF_W",
    ),
    // DEPTH_BITS.
    port(
        PerN::Depth.port(),
        Direction::Input,
        Carries::PerN(PerN::Depth),
        "3",
    ),
    port("out_valid", Direction::Output, Carries::OutValid, "1"),
    port("out_ready", Direction::Input, Carries::OutReady, "1"),
    port("out_data", Direction::Output, Carries::OutData, "OUT_W"),
];

impl TopPort {
    /// Its width in bits for datapath `dp`.
    pub fn width(&self, dp: &Datapath) -> u32 {
        match self.carries {
            Carries::C => dp.config().c.format.width(),
            Carries::PerN(p) => p.format(dp).width(),
            Carries::OutData => dp.config().out.format.width(),
            _ => 1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_per_n_constant_has_its_port_in_the_table_once() {
        for p in PerN::ALL {
            let rows: Vec<&TopPort> = TOP_PORTS
                .iter()
                .filter(|t| t.carries == Carries::PerN(p))
                .collect();
            assert_eq!(rows.len(), 1, "{p:?}");
            assert_eq!(rows[0].name, p.port());
            assert_eq!(rows[0].name, format!("in_{}", p.field()));
        }
        // The depth's width in the Verilog is DEPTH_BITS.
        let depth = TOP_PORTS.iter().find(|t| t.name == "in_depth").unwrap();
        assert_eq!(depth.verilog_width, DEPTH_BITS.to_string());
    }

    #[test]
    fn the_widths_follow_the_configuration() {
        let dp = crate::input::load_datapath("baseline", None).unwrap();
        let widths: Vec<(&str, u32)> = TOP_PORTS.iter().map(|t| (t.name, t.width(&dp))).collect();
        // The baseline: c u1.15 (16 bits), slope u7.4, offset u1.0, coef and out u8.16.
        assert_eq!(
            widths,
            [
                ("clk", 1),
                ("rst", 1),
                ("in_valid", 1),
                ("in_ready", 1),
                ("in_c", 16),
                ("in_slope", 11),
                ("in_offset", 1),
                ("in_threshold", 16),
                ("in_coef", 24),
                ("in_depth", 3),
                ("out_valid", 1),
                ("out_ready", 1),
                ("out_data", 24),
            ]
        );
    }
}
