//! Cycle-level model: the `pipelined` and `folded` microarchitectures with valid/ready
//! handshakes, as `docs/cycle.md` specifies them.
//!
//! A clocked step is a pure function: [`Machine::next`] takes the registers and the inputs of
//! one cycle and returns the registers after the clock edge; the simulator ([`sim`]) commits
//! them. Each operation computes with the bit-accurate stage operations of
//! [`crate::pipeline::Datapath`] (`op_sub`, `op_mul_t`, `op_add_b`, `op_square`,
//! `op_mul_out`), so values are computed stage by stage as they move, as in the RTL.
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

pub mod sim;
pub mod vcd;

use serde::Serialize;

use crate::pipeline::walk::Stage;
use crate::pipeline::Datapath;

/// The two microarchitectures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Arch {
    /// One new input per cycle; every operation its own stage with its register latency.
    Pipelined,
    /// One shared multiplier for all k + 2 products, driven by an FSM.
    Folded,
}

impl Arch {
    /// Both architectures.
    pub const ALL: [Arch; 2] = [Arch::Pipelined, Arch::Folded];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Arch::Pipelined => "pipelined",
            Arch::Folded => "folded",
        }
    }

    /// Cycles from an input's transfer to its output's transfer when nothing stalls.
    ///
    /// # Examples
    /// ```
    /// use specfx::cycle::Arch;
    /// use specfx::pipeline::Config;
    /// let cfg = Config::baseline();
    /// assert_eq!(Arch::Pipelined.latency(&cfg), 8);
    /// assert_eq!(Arch::Folded.latency(&cfg), 7);
    /// ```
    pub fn latency(self, cfg: &crate::pipeline::Config) -> u64 {
        let l = &cfg.latency;
        let k = u64::from(cfg.k);
        match self {
            Arch::Pipelined => u64::from(l.sub + l.add) + (k + 2) * u64::from(l.mul),
            Arch::Folded => (k + 2) * u64::from(l.mul) + 1,
        }
    }

    /// Cycles between the starts of two inputs when nothing stalls.
    pub fn initiation_interval(self, cfg: &crate::pipeline::Config) -> u64 {
        match self {
            Arch::Pipelined => 1,
            Arch::Folded => (u64::from(cfg.k) + 2) * u64::from(cfg.latency.mul),
        }
    }
}

crate::names::named_enum!(Arch, "architecture", "pipelined or folded");

/// One input of a stream: its sequence number, the index of its n in the datapath's n set,
/// and its raw input code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Item {
    /// Sequence number (0, 1, 2, ... in stream order).
    pub tag: u64,
    /// Index into [`Datapath::constants`].
    pub n_idx: usize,
    /// Raw input code.
    pub c_raw: i64,
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
            Op::Square(i) => (token.c, dp.op_square(i, token.value).raw),
            Op::MulOut => (token.c, dp.op_mul_out(token.value, nc).raw),
        };
        Token { c, value, ..token }
    }
}

/// A named register for traces: its value if it holds one.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RegisterView {
    /// Register name, e.g. `mul_t_0` or `x`.
    pub name: String,
    /// Bit width in the trace.
    pub width: u32,
    /// The value, when the register holds valid data.
    pub value: Option<i64>,
}

/// One microarchitecture's registers and its clocked step.
pub trait Machine: Clone {
    /// `in_ready` during this cycle, given `out_ready` (rule 3).
    fn in_ready(&self, out_ready: bool) -> bool;
    /// The output register: `Some((tag, raw))` when `out_valid` is high.
    fn output(&self) -> Option<(u64, i64)>;
    /// The registers after the clock edge, given this cycle's transferred input (if any) and
    /// `out_ready`.
    fn next(&self, dp: &Datapath, input: Option<Item>, out_ready: bool) -> Self;
    /// [`Machine::next`] written into `next` (whose old registers are overwritten), so that a
    /// simulator can keep two register sets and swap them without allocating.
    fn next_into(&self, dp: &Datapath, input: Option<Item>, out_ready: bool, next: &mut Self) {
        *next = self.next(dp, input, out_ready);
    }
    /// Adds 1 to `counts[unit]` for every unit that holds valid data now (the units of
    /// [`Machine::unit_names`], in order).
    fn count_occupancy(&self, counts: &mut [u64]) {
        for (count, busy) in counts.iter_mut().zip(self.occupancy()) {
            *count += u64::from(busy);
        }
    }
    /// Names of the units whose occupancy is measured.
    fn unit_names(&self) -> Vec<String>;
    /// Whether each unit holds valid data now.
    fn occupancy(&self) -> Vec<bool>;
    /// Every register, for traces.
    fn registers(&self, dp: &Datapath) -> Vec<RegisterView>;
}

/// The `pipelined` architecture: one delay line of `latency` registers per operation.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pipelined {
    /// The operation computed on entry to each register (`None`: a plain delay register).
    ops: Vec<Option<Op>>,
    /// The operation each register belongs to (for occupancy and names).
    owner: Vec<Op>,
    /// The registers, input side first.
    regs: Vec<Option<Token>>,
    /// The registers of each unit (of `op_units(owner)`), a contiguous range each.
    unit_regs: Vec<std::ops::Range<usize>>,
}

impl Pipelined {
    /// An empty pipeline for a datapath.
    pub fn new(dp: &Datapath) -> Pipelined {
        let cfg = dp.config();
        let lat = &cfg.latency;
        let mut plan = vec![(Op::Sub, lat.sub), (Op::MulT, lat.mul), (Op::AddB, lat.add)];
        plan.extend((0..cfg.k as usize).map(|i| (Op::Square(i), lat.mul)));
        plan.push((Op::MulOut, lat.mul));
        let mut ops = Vec::new();
        let mut owner = Vec::new();
        for (op, l) in plan {
            for r in 0..l {
                ops.push((r == 0).then_some(op));
                owner.push(op);
            }
        }
        let regs = vec![None; ops.len()];
        let mut unit_regs: Vec<std::ops::Range<usize>> = Vec::new();
        for (r, &op) in owner.iter().enumerate() {
            match unit_regs.last_mut() {
                Some(range) if owner[range.start] == op => range.end = r + 1,
                _ => unit_regs.push(r..r + 1),
            }
        }
        Pipelined {
            ops,
            owner,
            regs,
            unit_regs,
        }
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
    fn in_ready(&self, out_ready: bool) -> bool {
        self.output().is_none() || out_ready
    }

    fn output(&self) -> Option<(u64, i64)> {
        self.regs
            .last()
            .copied()
            .flatten()
            .map(|t| (t.tag, t.value))
    }

    fn next(&self, dp: &Datapath, input: Option<Item>, out_ready: bool) -> Pipelined {
        let mut next = self.clone();
        self.next_into(dp, input, out_ready, &mut next);
        next
    }

    fn next_into(&self, dp: &Datapath, input: Option<Item>, out_ready: bool, next: &mut Self) {
        if !self.in_ready(out_ready) {
            // Rule 5: a stalled pipeline holds everything (and accepts nothing).
            next.regs.copy_from_slice(&self.regs);
            return;
        }
        for r in 0..self.regs.len() {
            let incoming = if r == 0 {
                input.map(|it| Token {
                    tag: it.tag,
                    n_idx: it.n_idx,
                    c: it.c_raw,
                    value: it.c_raw,
                })
            } else {
                self.regs[r - 1]
            };
            next.regs[r] = match self.ops[r] {
                Some(op) => incoming.map(|t| op.apply(dp, t)),
                None => incoming,
            };
        }
    }

    fn count_occupancy(&self, counts: &mut [u64]) {
        for (count, range) in counts.iter_mut().zip(&self.unit_regs) {
            *count += u64::from(self.regs[range.clone()].iter().any(Option::is_some));
        }
    }

    fn unit_names(&self) -> Vec<String> {
        op_units(&self.owner).iter().map(|o| o.name()).collect()
    }

    fn occupancy(&self) -> Vec<bool> {
        op_units(&self.owner)
            .iter()
            .map(|&op| {
                self.owner
                    .iter()
                    .zip(&self.regs)
                    .any(|(&o, r)| o == op && r.is_some())
            })
            .collect()
    }

    fn registers(&self, dp: &Datapath) -> Vec<RegisterView> {
        let stages = dp.stages();
        let k = dp.config().k as usize;
        let width_of = |op: Op| -> u32 { stages[op.stage().index(k)].format.width() };
        let mut index_in_op = 0;
        self.owner
            .iter()
            .zip(&self.regs)
            .enumerate()
            .map(|(r, (&op, reg))| {
                if r > 0 && self.owner[r - 1] == op {
                    index_in_op += 1;
                } else {
                    index_in_op = 0;
                }
                RegisterView {
                    name: format!("{}_q{}", op.name(), index_in_op),
                    width: width_of(op),
                    value: reg.map(|t| t.value),
                }
            })
            .collect()
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

    fn next(&self, dp: &Datapath, input: Option<Item>, out_ready: bool) -> Folded {
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

    fn unit_names(&self) -> Vec<String> {
        vec!["multiplier".into(), "out_reg".into()]
    }

    fn occupancy(&self) -> Vec<bool> {
        vec![self.busy, self.out.is_some()]
    }

    fn registers(&self, dp: &Datapath) -> Vec<RegisterView> {
        let widest = dp
            .stages()
            .iter()
            .map(|s| s.format.width())
            .max()
            .unwrap_or(1);
        vec![
            RegisterView {
                name: "x".into(),
                width: widest,
                value: self.x.map(|t| t.value),
            },
            RegisterView {
                name: "step".into(),
                width: 8,
                value: self.busy.then_some(self.step as i64),
            },
            RegisterView {
                name: "count".into(),
                width: 8,
                value: self.busy.then_some(i64::from(self.count)),
            },
            RegisterView {
                name: "out_q".into(),
                width: dp.stages()[dp.stage_out()].format.width(),
                value: self.out.map(|o| o.1),
            },
        ]
    }
}
