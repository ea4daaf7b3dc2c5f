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
    /// `c`, `in_c` and `in_threshold`.
    pub c: u32,
    /// The testbench's `in_n` (32 bits, whatever the largest n: `in_n.hex` words are
    /// zero-extended).
    pub n: u32,
    /// `in_slope`.
    pub slope: u32,
    /// `in_offset`.
    pub offset: u32,
    /// `in_coef`.
    pub coef: u32,
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
    /// assert_eq!((w.c, w.n, w.slope, w.offset, w.coef, w.out), (16, 32, 11, 1, 24, 24));
    /// assert_eq!(w.folded_x(), 18);
    /// ```
    pub fn of(dp: &Datapath) -> Widths {
        let cfg = dp.config();
        let (slope, offset) = cfg.constant_formats();
        Widths {
            c: cfg.c.format.width(),
            n: TESTBENCH_N_W,
            slope: slope.width(),
            offset: offset.width(),
            coef: cfg.coef.format.width(),
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
        // The fields of this delay line's word, most significant first: (output name, width,
        // value of a token).
        type Field = (&'static str, u32, fn(&Datapath, &Token) -> i64);
        let coef: fn(&Datapath, &Token) -> i64 = |dp, t| dp.constants()[t.n_idx].coef_raw;
        let threshold: fn(&Datapath, &Token) -> i64 =
            |dp, t| dp.constants()[t.n_idx].threshold.unwrap_or(0);
        let offset: fn(&Datapath, &Token) -> i64 = |dp, t| dp.constants()[t.n_idx].offset_raw;
        let slope: fn(&Datapath, &Token) -> i64 = |dp, t| dp.constants()[t.n_idx].slope_raw;
        let c_cl: fn(&Datapath, &Token) -> i64 = |_, t| t.c;
        let value: fn(&Datapath, &Token) -> i64 = |_, t| t.value;
        let depth: fn(&Datapath, &Token) -> i64 = |dp, t| i64::from(dp.constants()[t.n_idx].depth);
        let d_w = crate::pipeline::DEPTH_BITS;
        let (prefix, delay, fields): (String, &str, Vec<Field>) = match op {
            Op::Sub => (
                String::new(),
                "r_sub",
                vec![
                    ("depth_1", d_w, depth),
                    ("coef_1", w.coef, coef),
                    ("threshold_1", w.c, threshold),
                    ("offset_1", w.offset, offset),
                    ("slope_1", w.slope, slope),
                    ("c_cl_1", w.c, c_cl),
                    ("d_1", w.d, value),
                ],
            ),
            Op::MulT => (
                String::new(),
                "r_mul_t",
                vec![
                    ("depth_2", d_w, depth),
                    ("coef_2", w.coef, coef),
                    ("threshold_2", w.c, threshold),
                    ("offset_2", w.offset, offset),
                    ("c_cl_2", w.c, c_cl),
                    ("t_2", w.t, value),
                ],
            ),
            Op::AddB => (
                String::new(),
                "r_add_b",
                vec![
                    ("depth_b", d_w, depth),
                    ("coef_b", w.coef, coef),
                    ("b_q", w.b, value),
                ],
            ),
            Op::Square(i) => (
                format!("g_square[{}].", i + 1),
                "r_square",
                vec![
                    ("depth_q", d_w, depth),
                    ("coef_q", w.coef, coef),
                    ("y_q", w.squares[i], value),
                ],
            ),
            // The output is the core's port out_data, which traces show with the ports.
            Op::MulOut => (String::new(), "r_mul_out", vec![("", w.out, value)]),
        };
        let word = |token: &Option<Token>| {
            token.as_ref().map(|t| {
                let raw: Vec<(i64, u32)> = fields.iter().map(|f| (f.2(dp, t), f.1)).collect();
                Word::concat(&raw)
            })
        };
        // The delay line's outputs (its last register's fields), in the RTL's order.
        for f in fields.iter().rev().filter(|f| !f.0.is_empty()) {
            regs.push(RegisterView {
                name: format!("{prefix}{}", f.0),
                width: f.1,
                value: tokens[end - 1].as_ref().map(|t| Word::new(f.2(dp, t), f.1)),
            });
        }
        let width = fields.iter().map(|f| f.1).sum();
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
    let nc = |t: &Token| &dp.constants()[t.n_idx];
    vec![
        known("busy", i64::from(state.busy), 1),
        known("step", state.step as i64, step_w),
        known("count", i64::from(state.count), count_w),
        of_x("x", w.folded_x(), &|t| t.value),
        of_x("slope_r", w.slope, &|t| nc(t).slope_raw),
        of_x("offset_r", w.offset, &|t| nc(t).offset_raw),
        of_x("threshold_r", w.c, &|t| nc(t).threshold.unwrap_or(0)),
        of_x("c_cl_r", w.c, &|t| t.c),
        of_x("coef_r", w.coef, &|t| nc(t).coef_raw),
        of_x("depth_r", crate::pipeline::DEPTH_BITS, &|t| {
            i64::from(nc(t).depth)
        }),
    ]
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
