//! The reference RTL's names, widths and contents of the cycle model's registers
//! (`hdl_ref/rtl/specfx_pipelined.v`, `hdl_ref/rtl/specfx_folded.v`), so that a trace of the
//! model and a Verilog simulator's dump of the co-simulation can be compared signal by signal.
//!
//! Names are hierarchical below the core instance, as Icarus Verilog and Verilator write them
//! in their VCD files: a generate block `g_square` iteration `2` is the scope `g_square[2]`,
//! the registers of a `specfx_delay` instance `r_sub` are `r_sub.g_regs.g_stage[s].r`
//! (`s = 0` takes the input). Every register of both cores is here:
//!
//! - `pipelined`: the valid bits `u_valid.g_regs.g_stage[s].r`; then per operation the
//!   delay line's output wires and its registers, each register holding the concatenation the
//!   RTL gives its `specfx_delay`: `r_sub` `{depth_1, coef_1, threshold_1, offset_1, slope_1,
//!   c_cl_1, d_1}`, `r_mul_t` `{depth_2, coef_2, threshold_2, offset_2, c_cl_2, t_2}`,
//!   `r_add_b` `{depth_b, coef_b, b_q}`, `g_square[i].r_square` `{depth_q, coef_q, y_q}`
//!   (i = 1..k), `r_mul_out` `out_data`. The 3-bit depth j(n) rides along in every
//!   architecture and configuration (synthesis removes it where no stage reads it).
//! - `folded`: `busy`, `step`, `count`, `x`, `slope_r`, `offset_r`, `threshold_r`, `c_cl_r`,
//!   `coef_r`, `depth_r` (and the output register, the ports `out_valid` and `out_data`).
//!
//! A register that holds no valid data has no value (`x` in a trace): the RTL's contents of an
//! empty slot are unspecified. Values are derived from the items the model holds, the per-n
//! constants from [`Datapath::constants`].

use crate::cycle::{Arch, Op, RegisterView, Token, Word};
use crate::pipeline::ports::PerN;
use crate::pipeline::Datapath;

/// The width of the testbench's `in_n` (`tb_specfx.v`'s `N_W`).
pub const TESTBENCH_N_W: u32 = 32;

/// The scope of the core below the DUT (`specfx_dut`'s generate block and instance).
pub fn core_scope(arch: Arch) -> &'static str {
    match arch {
        Arch::Pipelined => "g_pipelined.u_core",
        Arch::Folded => "g_folded.u_core",
    }
}

/// The widths of the RTL's ports and values for a datapath: the parameters
/// `specfx hdl params` writes (`SPECFX_<X>_W`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Widths {
    /// `c`, `in_c` and the clamped input `c_cl` (the per-n ports' widths are
    /// [`PerN::format`]'s).
    pub c: u32,
    /// The testbench's `in_n` (32 bits, whatever the largest n: `in_n.hex` words are
    /// zero-extended).
    pub n: u32,
    /// `out_data`.
    pub out: u32,
    /// `d`.
    pub d: u32,
    /// `t`.
    pub t: u32,
    /// `b` (the squaring chain's stage 0).
    pub b: u32,
    /// `sq_1` .. `sq_k`.
    pub squares: Vec<u32>,
}

impl Widths {
    /// The widths of a datapath's RTL.
    ///
    /// # Examples
    /// ```
    /// use specfx::cycle::rtl::Widths;
    /// use specfx::pipeline::{Config, Datapath};
    /// let w = Widths::of(&Datapath::new(Config::baseline()).unwrap());
    /// assert_eq!((w.c, w.n, w.out), (16, 32, 24));
    /// assert_eq!(w.folded_x(), 18);
    /// ```
    pub fn of(dp: &Datapath) -> Widths {
        let cfg = dp.config();
        Widths {
            c: cfg.c.format.width(),
            n: TESTBENCH_N_W,
            out: cfg.out.format.width(),
            d: cfg.d.format.width(),
            t: cfg.t.format.width(),
            b: cfg.b.format.width(),
            squares: cfg.square.iter().map(|s| s.format.width()).collect(),
        }
    }

    /// `specfx_folded`'s `X_W = operand_w(K)`: a signed register holding d and every value of
    /// the squaring chain (b, sq_1 .. sq_k) with one bit to spare for the unsigned ones.
    pub fn folded_x(&self) -> u32 {
        std::iter::once(self.b)
            .chain(self.squares.iter().copied())
            .map(|w| w + 1)
            .fold(self.d, u32::max)
    }
}

/// Verilog's `$clog2`: the bits needed to count `v` values.
fn clog2(v: u32) -> u32 {
    if v <= 1 {
        0
    } else {
        32 - (v - 1).leading_zeros()
    }
}

/// The registers of `specfx_pipelined`: register `r` (input side first) belongs to operation
/// `owner[r]` and holds `tokens[r]`, whose `value` is the value of that operation's stage and
/// `c` the clamped input code.
pub fn pipelined_registers(
    dp: &Datapath,
    owner: &[Op],
    tokens: &[Option<Token>],
) -> Vec<RegisterView> {
    let w = Widths::of(dp);
    let mut regs = Vec::new();
    for (s, token) in tokens.iter().enumerate() {
        regs.push(RegisterView {
            name: format!("u_valid.g_regs.g_stage[{s}].r"),
            width: 1,
            value: Some(Word::new(i64::from(token.is_some()), 1)),
        });
    }
    let mut start = 0;
    while start < owner.len() {
        let op = owner[start];
        let end = start + owner[start..].iter().take_while(|&&o| o == op).count();
        // The delay line's word: the per-n constants the operations after it still read
        // (`{field}{suffix}`, in the reverse of the ports' order), the clamped input where the
        // paper cutoff still needs it (`c_cl{suffix}`), then the operation's value.
        let (prefix, delay, suffix, constants, clamped, value): (
            String,
            &str,
            &str,
            &[PerN],
            bool,
            (&str, u32),
        ) = match op {
            Op::Sub => (String::new(), "r_sub", "_1", &PerN::ALL, true, ("d_1", w.d)),
            Op::MulT => (
                String::new(),
                "r_mul_t",
                "_2",
                &[PerN::Offset, PerN::Threshold, PerN::Coef, PerN::Depth],
                true,
                ("t_2", w.t),
            ),
            Op::AddB => (
                String::new(),
                "r_add_b",
                "_b",
                &[PerN::Coef, PerN::Depth],
                false,
                ("b_q", w.b),
            ),
            Op::Square(i) => (
                format!("g_square[{}].", i + 1),
                "r_square",
                "_q",
                &[PerN::Coef, PerN::Depth],
                false,
                ("y_q", w.squares[i]),
            ),
            // The output is the core's port out_data, which traces show with the ports.
            Op::MulOut => (String::new(), "r_mul_out", "", &[], false, ("", w.out)),
        };
        // The fields of the word, most significant first: (output name, width, value of a
        // token).
        let mut fields: Vec<Field> = constants
            .iter()
            .rev()
            .map(|&p| Field::constant(dp, p, suffix))
            .collect();
        if clamped {
            fields.push(Field {
                name: format!("c_cl{suffix}"),
                width: w.c,
                holds: Holds::Clamped,
            });
        }
        fields.push(Field {
            name: value.0.to_string(),
            width: value.1,
            holds: Holds::Value,
        });
        let word = |token: &Option<Token>| {
            token.as_ref().map(|t| {
                let raw: Vec<(i64, u32)> = fields.iter().map(|f| (f.raw(dp, t), f.width)).collect();
                Word::concat(&raw)
            })
        };
        // The delay line's outputs (its last register's fields), in the RTL's order.
        for f in fields.iter().rev().filter(|f| !f.name.is_empty()) {
            regs.push(RegisterView {
                name: format!("{prefix}{}", f.name),
                width: f.width,
                value: tokens[end - 1]
                    .as_ref()
                    .map(|t| Word::new(f.raw(dp, t), f.width)),
            });
        }
        let width = fields.iter().map(|f| f.width).sum();
        for (s, token) in tokens[start..end].iter().enumerate() {
            regs.push(RegisterView {
                name: format!("{prefix}{delay}.g_regs.g_stage[{s}].r"),
                width,
                value: word(token),
            });
        }
        start = end;
    }
    regs
}

/// What [`folded_registers`] reads of the `folded` machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FoldedState {
    /// `busy`.
    pub busy: bool,
    /// `step` (0..k+1).
    pub step: usize,
    /// `count` (0..lat_mul-1).
    pub count: u32,
    /// The operand register `x` with its input's n and clamped code, while it holds one.
    pub x: Option<Token>,
}

/// The registers of `specfx_folded` but the output register: `busy`, `step`, `count` (reset,
/// so always known), the operand `x` and the current input's constants (known while the unit
/// holds an input).
pub fn folded_registers(dp: &Datapath, state: &FoldedState) -> Vec<RegisterView> {
    let w = Widths::of(dp);
    let k = dp.config().k;
    let step_w = clog2(k + 2);
    let lat_mul = dp.config().latency.mul;
    let count_w = if lat_mul > 1 { clog2(lat_mul) } else { 1 };
    let known = |name: &str, raw: i64, width: u32| RegisterView {
        name: name.to_string(),
        width,
        value: Some(Word::new(raw, width)),
    };
    let of_x = |name: &str, width: u32, f: &dyn Fn(&Token) -> i64| RegisterView {
        name: name.to_string(),
        width,
        value: state.x.as_ref().map(|t| Word::new(f(t), width)),
    };
    let constant = |p: PerN| {
        let f = Field::constant(dp, p, "_r");
        of_x(&f.name, f.width, &|t| f.raw(dp, t))
    };
    vec![
        known("busy", i64::from(state.busy), 1),
        known("step", state.step as i64, step_w),
        known("count", i64::from(state.count), count_w),
        of_x("x", w.folded_x(), &|t| t.value),
        constant(PerN::Slope),
        constant(PerN::Offset),
        constant(PerN::Threshold),
        of_x("c_cl_r", w.c, &|t| t.c),
        constant(PerN::Coef),
        constant(PerN::Depth),
    ]
}

/// A field of a register of the RTL: its name, width and what it holds of a token.
struct Field {
    name: String,
    width: u32,
    holds: Holds,
}

/// What a field of a register holds of a token.
#[derive(Clone, Copy)]
enum Holds {
    /// A per-n constant of the token's n.
    Constant(PerN),
    /// The clamped input code.
    Clamped,
    /// The value of the register's operation.
    Value,
}

impl Field {
    /// The field `{field}{suffix}` holding per-n constant `p`, as wide as its port.
    fn constant(dp: &Datapath, p: PerN, suffix: &str) -> Field {
        Field {
            name: format!("{}{suffix}", p.field()),
            width: p.format(dp).width(),
            holds: Holds::Constant(p),
        }
    }

    /// Its raw contents for token `t`.
    fn raw(&self, dp: &Datapath, t: &Token) -> i64 {
        match self.holds {
            Holds::Constant(p) => p.raw(&dp.constants()[t.n_idx]),
            Holds::Clamped => t.c,
            Holds::Value => t.value,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clog2_is_verilogs() {
        let got: Vec<u32> = (1..=9).map(clog2).collect();
        assert_eq!(got, [0, 1, 2, 2, 3, 3, 3, 3, 4]);
    }
}
