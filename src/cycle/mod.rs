//! Cycle-level model: the `pipelined` and `folded` microarchitectures with valid/ready
//! handshakes, as `docs/cycle.md` specifies them.
//!
//! A clock edge is [`Machine::step`]: the registers and the inputs of one cycle give the
//! registers after the edge ([`Machine::next`] returns them without changing the machine); the
//! simulator ([`sim`]) drives it. The `folded` unit computes with the bit-accurate stage
//! operations of [`crate::pipeline::Datapath`] (`op_sub`, `op_mul_t`, `op_add_b`,
//! `op_square`, `op_mul_out`) as its FSM steps, as in the RTL. The `pipelined` one carries
//! tokens whose values are the functional model's (`docs/cycle.md`), checked register by
//! register against a literal pipeline in `tests/model/cycle_model.rs`.
//!
//! Valid/ready rules (both ports; see `docs/cycle.md`):
//!
//! 1. A transfer happens at the end of a cycle in which `valid` and `ready` are both high.
//! 2. A producer keeps its data stable while `valid` is high and no transfer has happened.
//! 3. `in_ready` may depend on `out_ready` in the same cycle; `valid` never depends on `ready`.
//! 4. Every accepted input produces exactly one output, in order: nothing is lost, duplicated
//!    or reordered, whatever the bubbles and stalls.
//! 5. While `out_valid` is high and `out_ready` low, the output does not change.
//!
//! **Invariant:** the outputs equal [`crate::pipeline::Datapath::eval`]'s, bit for bit, for
//! any input stream and any stall pattern (tested with proptest).
//!
//! **Invariant:** no I/O here; the VCD writer renders into any `io::Write`.

pub mod compare;
pub mod lockstep;
pub mod rtl;
pub mod sim;
pub mod stimulus;
pub mod vcd;

use crate::pipeline::walk::Stage;
use crate::pipeline::Datapath;

/// The two microarchitectures (defined beside [`crate::pipeline::Config`], whose `arch` key
/// records the one a configuration was costed with).
pub use crate::pipeline::Arch;

/// One input of a stream: its sequence number, the index of its n in the datapath's n set,
/// its raw input code, and its output under the functional model.
///
/// The output rides along because the `pipelined` machine needs no other value: each of its
/// registers applies its operation once to the token it takes in and holds the result, so the
/// value in any register is the functional model's value of its input at that register's
/// stage, and the simulator computes those in batches ([`Datapath::eval_outputs`]) ahead of
/// the stream. The `folded` machine computes its values itself, operation by operation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Item {
    /// Sequence number (0, 1, 2, ... in stream order).
    pub tag: u64,
    /// Index into [`Datapath::constants`].
    pub n_idx: usize,
    /// Raw input code.
    pub c_raw: i64,
    /// The raw output [`Datapath::eval`] gives for this input.
    pub out: i64,
}

impl Item {
    /// The item of input `(n_idx, c_raw)` with sequence number `tag`, its output computed
    /// alone (the simulator computes many at once).
    pub fn new(dp: &Datapath, tag: u64, n_idx: usize, c_raw: i64) -> Item {
        let out = dp.eval(c_raw, &dp.constants()[n_idx]).values[dp.stage_out()];
        Item {
            tag,
            n_idx,
            c_raw,
            out,
        }
    }

    /// The value this input has at `stage` (d, t, b, a square or out).
    pub fn value_at(&self, dp: &Datapath, stage: Stage) -> i64 {
        let probes = dp.eval(self.c_raw, &dp.constants()[self.n_idx]);
        probes.values[stage.index(dp.config().k as usize)]
    }
}

/// A value in a register, with the input it belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Token {
    /// The input's sequence number.
    pub tag: u64,
    /// Index of its n.
    pub n_idx: usize,
    /// The clamped input code (the paper cutoff needs it after the subtraction).
    pub c: i64,
    /// The raw value held (d, t, b, a square or the output, depending on the register).
    pub value: i64,
}

/// The operations of the datapath, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    /// Clamp and d = c - 1.
    Sub,
    /// t = d * slope.
    MulT,
    /// b = cutoff(t + offset).
    AddB,
    /// Squaring stage `i` (0-based).
    Square(usize),
    /// out = sq_k * coef.
    MulOut,
}

impl Op {
    /// The name used in traces (`sub`, `mul_t`, `add_b`, `sq1`.., `mul_out`).
    pub fn name(self) -> String {
        match self {
            Op::Sub => "sub".into(),
            Op::MulT => "mul_t".into(),
            Op::AddB => "add_b".into(),
            Op::Square(i) => Stage::Square(i).to_string(),
            Op::MulOut => "mul_out".into(),
        }
    }

    /// The stage whose value this operation computes.
    pub fn stage(self) -> Stage {
        match self {
            Op::Sub => Stage::D,
            Op::MulT => Stage::T,
            Op::AddB => Stage::B,
            Op::Square(i) => Stage::Square(i),
            Op::MulOut => Stage::Out,
        }
    }

    /// Applies the operation to a token (for `Sub`, `token.value` is the raw input code).
    pub fn apply(self, dp: &Datapath, token: Token) -> Token {
        let nc = &dp.constants()[token.n_idx];
        let (c, value) = match self {
            Op::Sub => dp.op_sub(token.value),
            Op::MulT => (token.c, dp.op_mul_t(token.value, nc).raw),
            Op::AddB => (token.c, dp.op_add_b(token.value, token.c, nc).0.raw),
            Op::Square(i) => (token.c, dp.op_stage(i, nc.depth, token.value).raw),
            Op::MulOut => (token.c, dp.op_mul_out(token.value, nc).raw),
        };
        Token { c, value, ..token }
    }
}

/// A register's bits as the RTL holds them: raw codes concatenated as Verilog's `{a, b, c}`
/// (the first field in the high bits), each in two's complement of its width.
///
/// # Examples
/// ```
/// use specfx::cycle::Word;
/// let w = Word::concat(&[(1, 1), (-2, 3)]); // {1'b1, 3'b110}
/// assert_eq!(w.width(), 4);
/// assert_eq!((0..4).map(|i| w.bit(i)).collect::<Vec<_>>(), [false, true, true, true]);
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Word {
    /// `(raw, width)`, most significant field first.
    fields: Vec<(i64, u32)>,
}

impl Word {
    /// One raw code of `width` bits (bits above 63 repeat the sign).
    pub fn new(raw: i64, width: u32) -> Word {
        Word {
            fields: vec![(raw, width)],
        }
    }

    /// Raw codes `(raw, width)` concatenated, the first in the high bits.
    pub fn concat(fields: &[(i64, u32)]) -> Word {
        Word {
            fields: fields.to_vec(),
        }
    }

    /// The width in bits.
    pub fn width(&self) -> u32 {
        self.fields.iter().map(|f| f.1).sum()
    }

    /// Bit `i` (0 is the least significant).
    pub fn bit(&self, i: u32) -> bool {
        let mut low = 0;
        for &(raw, width) in self.fields.iter().rev() {
            if i < low + width {
                return (raw >> (i - low).min(63)) & 1 == 1;
            }
            low += width;
        }
        panic!("bit {i} of a {low}-bit word")
    }
}

/// A register of the RTL for traces: its hierarchical name below the core instance
/// (`u_core`), its width and its contents.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RegisterView {
    /// The RTL's name below the core, scopes separated by dots, e.g. `d_1`,
    /// `g_square[2].y_q` or `r_mul_t.g_regs.g_stage[0].r` (see [`rtl`]).
    pub name: String,
    /// Bit width, the RTL's.
    pub width: u32,
    /// The contents, when the register holds valid data (else the RTL's contents are
    /// unspecified: `x` in a trace).
    pub value: Option<Word>,
}

/// One microarchitecture's registers and its clocked step.
pub trait Machine: Clone {
    /// `in_ready` during this cycle, given `out_ready` (rule 3).
    fn in_ready(&self, out_ready: bool) -> bool;
    /// The output register: `Some((tag, raw))` when `out_valid` is high.
    fn output(&self) -> Option<(u64, i64)>;
    /// The clock edge: the registers become those after the edge, given this cycle's
    /// transferred input (if any) and `out_ready`.
    fn step(&mut self, dp: &Datapath, input: Option<Item>, out_ready: bool);
    /// The registers after the clock edge, leaving these as they are.
    fn next(&self, dp: &Datapath, input: Option<Item>, out_ready: bool) -> Self {
        let mut next = self.clone();
        next.step(dp, input, out_ready);
        next
    }
    /// Adds 1 to `counts[unit]` for every unit that holds valid data now (the units of
    /// [`Machine::unit_names`], in order).
    fn count_occupancy(&self, counts: &mut [u64]) {
        for (count, busy) in counts.iter_mut().zip(self.occupancy()) {
            *count += u64::from(busy);
        }
    }
    /// Whether every unit holds valid data now: [`Machine::count_occupancy`] would add 1 to
    /// every count (a simulation counts such cycles once). `false` when unsure.
    #[inline]
    fn full(&self) -> bool {
        false
    }
    /// Names of the units whose occupancy is measured.
    fn unit_names(&self) -> Vec<String>;
    /// Whether each unit holds valid data now.
    fn occupancy(&self) -> Vec<bool>;
    /// Every register of the RTL core but its ports (`out_valid`, `out_data`), under the RTL's
    /// names and widths, for traces; only traces call it.
    fn registers(&self, dp: &Datapath) -> Vec<RegisterView>;
}

/// What a pipeline register holds where no token entered (its valid bit is clear).
const EMPTY: Item = Item {
    tag: 0,
    n_idx: 0,
    c_raw: 0,
    out: 0,
};

/// The slots of [`Pipelined`]'s ring: its most registers.
const RING: usize = 128;

/// The `pipelined` architecture: one delay line of `latency` registers per operation, the
/// first computing the operation on the token it takes in.
///
/// Nothing in the pipeline depends on the values it carries (a stall holds every register,
/// otherwise every register takes its predecessor's token), so the registers hold their
/// input's [`Item`] and show the value of its stage on demand; they sit in a ring, so a clock
/// edge costs the same whatever the latency.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pipelined {
    /// The operation each register belongs to (for names and stage values), input side first.
    owner: Vec<Op>,
    /// The registers, as a ring of [`RING`] slots (at least as many as registers, a power of
    /// two: an index masked by `RING - 1` needs no check): register `r` (input side first) is
    /// `ring[(head + r) % RING]`, its token when `valid`'s bit for `r` is set, [`EMPTY`] where
    /// no token entered (the slots past the last register hold nothing).
    ring: Box<[Item; RING]>,
    /// Where register 0 sits in the ring.
    head: usize,
    /// Bit `128 - len + r` (the bits of the registers at the top, the last register's bit
    /// 127): register `r` holds a token. A clock edge shifts it left by one, the leaving
    /// token's bit out of the word.
    valid: u128,
    /// `valid`'s bit of register 0.
    entry: u128,
    /// `valid` of a full pipeline: a bit for every register.
    all: u128,
    /// The registers of each unit (of `op_units(owner)`) as a mask of `valid`'s bits.
    unit_masks: Vec<u128>,
}

impl Pipelined {
    /// An empty pipeline for a datapath.
    pub fn new(dp: &Datapath) -> Pipelined {
        let cfg = dp.config();
        let lat = &cfg.latency;
        let mut plan = vec![(Op::Sub, lat.sub), (Op::MulT, lat.mul), (Op::AddB, lat.add)];
        plan.extend((0..cfg.k as usize).map(|i| (Op::Square(i), lat.mul)));
        plan.push((Op::MulOut, lat.mul));
        let owner: Vec<Op> = plan
            .iter()
            .flat_map(|&(op, l)| std::iter::repeat_n(op, l as usize))
            .collect();
        // At most 8 registers per operation and k + 4 <= 11 operations.
        assert!(owner.len() <= RING, "a pipeline of at most 128 registers");
        let low = 128 - owner.len();
        let unit_masks = op_units(&owner)
            .iter()
            .map(|&op| {
                (0..owner.len())
                    .filter(|&r| owner[r] == op)
                    .fold(0u128, |m, r| m | 1 << (low + r))
            })
            .collect();
        Pipelined {
            entry: 1 << low,
            all: u128::MAX << low,
            ring: Box::new([EMPTY; RING]),
            head: 0,
            valid: 0,
            unit_masks,
            owner,
        }
    }

    /// Register `r`, input side first.
    #[inline]
    fn reg(&self, r: usize) -> Option<Item> {
        let bit = 128 - self.owner.len() + r;
        (self.valid >> bit & 1 == 1).then(|| self.ring[(self.head + r) % RING])
    }
}

fn op_units(owner: &[Op]) -> Vec<Op> {
    let mut v: Vec<Op> = Vec::new();
    for &o in owner {
        if v.last() != Some(&o) {
            v.push(o);
        }
    }
    v
}

impl Machine for Pipelined {
    #[inline]
    fn in_ready(&self, out_ready: bool) -> bool {
        self.output().is_none() || out_ready
    }

    #[inline]
    fn output(&self) -> Option<(u64, i64)> {
        if self.valid >> 127 == 0 {
            return None;
        }
        let it = self.ring[(self.head + self.owner.len() - 1) % RING];
        Some((it.tag, it.out))
    }

    #[inline]
    fn step(&mut self, _dp: &Datapath, input: Option<Item>, out_ready: bool) {
        if !self.in_ready(out_ready) {
            // Rule 5: a stalled pipeline holds everything (and accepts nothing).
            return;
        }
        self.valid = self.valid << 1 | if input.is_some() { self.entry } else { 0 };
        // Register r takes register r - 1's token: the ring turns by one, and the slot before
        // register 0 becomes register 0.
        self.head = self.head.wrapping_sub(1) % RING;
        self.ring[self.head] = input.unwrap_or(EMPTY);
    }

    #[inline]
    fn count_occupancy(&self, counts: &mut [u64]) {
        // An empty pipeline occupies no unit (a full one, the simulator counts through
        // `full`).
        if self.valid != 0 {
            for (count, &mask) in counts.iter_mut().zip(&self.unit_masks) {
                *count += u64::from(self.valid & mask != 0);
            }
        }
    }

    #[inline]
    fn full(&self) -> bool {
        self.valid == self.all
    }

    fn unit_names(&self) -> Vec<String> {
        op_units(&self.owner).iter().map(|o| o.name()).collect()
    }

    fn occupancy(&self) -> Vec<bool> {
        self.unit_masks
            .iter()
            .map(|&m| self.valid & m != 0)
            .collect()
    }

    fn registers(&self, dp: &Datapath) -> Vec<RegisterView> {
        let tokens: Vec<Option<Token>> = (0..self.owner.len())
            .map(|r| {
                self.reg(r).map(|it| Token {
                    tag: it.tag,
                    n_idx: it.n_idx,
                    c: dp.op_sub(it.c_raw).0,
                    value: it.value_at(dp, self.owner[r].stage()),
                })
            })
            .collect();
        rtl::pipelined_registers(dp, &self.owner, &tokens)
    }
}

/// The `folded` architecture: one multiplier used k + 2 times per input, and an FSM.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Folded {
    k: usize,
    lat_mul: u32,
    busy: bool,
    step: usize,
    count: u32,
    /// The operand register with the current input's tag, n and clamped code.
    x: Option<Token>,
    /// The output register.
    out: Option<(u64, i64)>,
}

impl Folded {
    /// An idle unit for a datapath.
    pub fn new(dp: &Datapath) -> Folded {
        Folded {
            k: dp.config().k as usize,
            lat_mul: dp.config().latency.mul,
            busy: false,
            step: 0,
            count: 0,
            x: None,
            out: None,
        }
    }

    fn last(&self) -> bool {
        self.busy && self.step == self.k + 1 && self.count == self.lat_mul - 1
    }
}

impl Machine for Folded {
    fn in_ready(&self, out_ready: bool) -> bool {
        let out_free = self.out.is_none() || out_ready;
        (!self.busy || self.last()) && out_free
    }

    fn output(&self) -> Option<(u64, i64)> {
        self.out
    }

    fn step(&mut self, dp: &Datapath, input: Option<Item>, out_ready: bool) {
        *self = self.after(dp, input, out_ready);
    }

    fn unit_names(&self) -> Vec<String> {
        vec!["multiplier".into(), "out_reg".into()]
    }

    fn occupancy(&self) -> Vec<bool> {
        vec![self.busy, self.out.is_some()]
    }

    fn registers(&self, dp: &Datapath) -> Vec<RegisterView> {
        rtl::folded_registers(
            dp,
            &rtl::FoldedState {
                busy: self.busy,
                step: self.step,
                count: self.count,
                x: self.x,
            },
        )
    }
}

impl Folded {
    /// The registers after the clock edge.
    fn after(&self, dp: &Datapath, input: Option<Item>, out_ready: bool) -> Folded {
        let out_free = self.out.is_none() || out_ready;
        let mut next = self.clone();
        if self.out.is_some() && out_ready {
            next.out = None;
        }
        if self.last() {
            if out_free {
                let x = self.x.expect("a busy unit holds an operand");
                let result = Op::MulOut.apply(dp, x);
                next.out = Some((x.tag, result.value));
                next.busy = false;
                next.x = None;
            }
        } else if self.busy {
            if self.count + 1 < self.lat_mul {
                next.count = self.count + 1;
            } else {
                let x = self.x.expect("a busy unit holds an operand");
                next.x = Some(if self.step == 0 {
                    Op::AddB.apply(dp, Op::MulT.apply(dp, x))
                } else {
                    Op::Square(self.step - 1).apply(dp, x)
                });
                next.count = 0;
                next.step = self.step + 1;
            }
        }
        if let Some(it) = input {
            let token = Token {
                tag: it.tag,
                n_idx: it.n_idx,
                c: it.c_raw,
                value: it.c_raw,
            };
            next.x = Some(Op::Sub.apply(dp, token));
            next.busy = true;
            next.step = 0;
            next.count = 0;
        }
        next
    }
}
