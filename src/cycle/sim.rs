//! The stream simulator: drives a [`Machine`] with an input stream, seeded bubbles and output
//! stalls, and gathers what happened on every cycle.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use crate::cycle::{Arch, Folded, Item, Machine, Pipelined, RegisterView};
use crate::pipeline::Datapath;

/// Per-cycle `valid` offers and `out_ready` bits, drawn from ChaCha8 with a seed: for each
/// cycle, first the bubble draw, then the stall draw; or the co-simulation's handshake
/// pattern (`docs/cycle.md`, [`Stimulus::with_handshake`]).
#[derive(Debug, Clone)]
pub struct Stimulus {
    rng: ChaCha8Rng,
    bubble: f64,
    stall: f64,
    /// The co-simulation's pattern (stall bursts and directed episodes) instead of
    /// independent draws, when given.
    handshake: Option<super::stimulus::Handshake>,
}

impl Stimulus {
    /// A pattern source: `bubble` and `stall` are probabilities in [0, 1).
    pub fn new(seed: u64, bubble: f64, stall: f64) -> Stimulus {
        Stimulus {
            rng: ChaCha8Rng::seed_from_u64(seed),
            bubble,
            stall,
            handshake: None,
        }
    }

    /// A pattern source drawing the co-simulation's handshake pattern from ChaCha8 with a
    /// seed (`super::stimulus::Handshake`: directed episodes, stall bursts).
    pub fn with_handshake(seed: u64, handshake: super::stimulus::Handshake) -> Stimulus {
        Stimulus {
            handshake: Some(handshake),
            ..Stimulus::new(seed, 0.0, 0.0)
        }
    }

    /// Whether every cycle offers an input and is ready for an output (no bubbles, no
    /// stalls): [`Stimulus::next_cycle`] then draws nothing.
    pub fn always_ready(&self) -> bool {
        self.handshake.is_none() && self.bubble == 0.0 && self.stall == 0.0
    }

    /// The next cycle's (valid offer, out_ready).
    #[inline]
    pub fn next_cycle(&mut self) -> (bool, bool) {
        if let Some(h) = &mut self.handshake {
            return h.next(&mut self.rng);
        }
        if self.bubble == 0.0 && self.stall == 0.0 {
            // Both draws would be >= 0: skipping them changes no cycle, since nothing else
            // reads this generator.
            return (true, true);
        }
        let valid = self.rng.r#gen::<f64>() >= self.bubble;
        let ready = self.rng.r#gen::<f64>() >= self.stall;
        (valid, ready)
    }
}

/// What one cycle looked like at the ports, for traces.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CycleTrace {
    /// Cycle number.
    pub cycle: u64,
    /// `in_valid`.
    pub in_valid: bool,
    /// `in_ready`.
    pub in_ready: bool,
    /// The input on the data ports, `(n_idx, c_raw)`: the source's next input whether it
    /// offers it or not, as the co-simulation testbench drives them (`None` when the source has
    /// no input left: the testbench drives zeros).
    pub input: Option<(usize, i64)>,
    /// `out_valid`.
    pub out_valid: bool,
    /// `out_ready`.
    pub out_ready: bool,
    /// `out_data` (when valid).
    pub out_data: Option<i64>,
    /// Every register.
    pub registers: Vec<RegisterView>,
}

/// One output transfer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct OutputEvent {
    /// The input's sequence number.
    pub tag: u64,
    /// The raw output.
    pub value: i64,
    /// The cycle at the end of which it transferred.
    pub cycle: u64,
    /// Cycles since its input transferred.
    pub latency: u64,
}

/// Statistics of a simulation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimStats {
    /// The architecture.
    pub arch: Arch,
    /// Cycles simulated.
    pub n_cycles: u64,
    /// Inputs accepted.
    pub n_inputs: u64,
    /// Outputs delivered.
    pub n_outputs: u64,
    /// Smallest input-to-output latency seen, in cycles.
    pub latency_min: u64,
    /// Largest latency seen.
    pub latency_max: u64,
    /// The configured latency without stalls.
    pub latency_nominal: u64,
    /// The initiation interval without stalls.
    pub initiation_interval: u64,
    /// Outputs per cycle.
    pub throughput: f64,
    /// Cycles where the source had data but no offer (bubbles).
    pub bubble_cycles: u64,
    /// Cycles where `out_valid` was high and `out_ready` low.
    pub stall_cycles: u64,
    /// Cycles where the source offered data and the datapath refused it.
    pub backpressure_cycles: u64,
    /// Outputs that differ from the functional model (must be 0).
    pub mismatches: u64,
    /// Outputs out of order (must be 0).
    pub order_errors: u64,
    /// Per unit: name and share of cycles it held valid data.
    pub occupancy: Vec<(String, f64)>,
}

/// The result of a simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct SimResult {
    /// Statistics.
    pub stats: SimStats,
    /// Every output transfer, in order (empty unless [`Record::transfers`]).
    pub outputs: Vec<OutputEvent>,
    /// The `valid` offer bit of every simulated cycle (empty unless [`Record::transfers`]).
    pub valid_bits: Vec<bool>,
    /// The `out_ready` bit of every simulated cycle (empty unless [`Record::transfers`]).
    pub ready_bits: Vec<bool>,
    /// Port and register traces of the first `trace_cycles` cycles.
    pub trace: Vec<CycleTrace>,
}

/// When to stop a simulation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// After exactly this many cycles.
    Cycles(u64),
    /// When every input's output has transferred (or after this many cycles at most).
    Drained(u64),
}

/// Simulates `arch` on a stream of inputs (`items[i]` gets tag `i`).
///
/// `items` may be an endless iterator when stopping after a number of cycles.
pub fn simulate(
    dp: &Datapath,
    arch: Arch,
    items: impl Iterator<Item = (usize, i64)>,
    stimulus: &mut Stimulus,
    stop: Stop,
    trace_cycles: u64,
) -> SimResult {
    let record = Record {
        transfers: true,
        trace_cycles,
    };
    simulate_with(dp, arch, items, stimulus, stop, record)
}

/// [`simulate`], keeping only what `record` asks for besides the statistics.
pub fn simulate_with(
    dp: &Datapath,
    arch: Arch,
    items: impl Iterator<Item = (usize, i64)>,
    stimulus: &mut Stimulus,
    stop: Stop,
    record: Record,
) -> SimResult {
    match arch {
        Arch::Pipelined => run(dp, arch, Pipelined::new(dp), items, stimulus, stop, record),
        Arch::Folded => run(dp, arch, Folded::new(dp), items, stimulus, stop, record),
    }
}

/// [`simulate_with`] on a named stream of inputs (`seed` seeds the random one), the stream's
/// own iterator type given to the simulation (no call through a trait object per input).
pub fn simulate_stream(
    dp: &Datapath,
    arch: Arch,
    stream: Stream,
    seed: u64,
    stimulus: &mut Stimulus,
    stop: Stop,
    record: Record,
) -> SimResult {
    match (stream, arch) {
        (Stream::Random, _) => {
            simulate_with(dp, arch, random_inputs(dp, seed), stimulus, stop, record)
        }
        // The sweep's columns written run by run, not input by input.
        (Stream::Sweep, Arch::Pipelined) => {
            let source = Source::of_ranges(dp, fill_sweep(dp));
            run_source(dp, arch, Pipelined::new(dp), source, stimulus, stop, record)
        }
        (Stream::Sweep, Arch::Folded) => {
            let source = Source::of_ranges(dp, fill_sweep(dp));
            run_source(dp, arch, Folded::new(dp), source, stimulus, stop, record)
        }
    }
}

/// The input stream with each input's functional output, computed ahead in blocks: a block's
/// inputs are grouped by n and evaluated with [`Datapath::eval_outputs`]. Blocks grow from
/// [`Source::FIRST_BLOCK`] to [`Source::MAX_BLOCK`] inputs, so a short simulation reads little
/// ahead of what it accepts.
struct Source<'a, F> {
    dp: &'a Datapath,
    /// Appends up to the given number of the stream's next inputs to the two columns (fewer
    /// only when the stream ends).
    fill: F,
    /// The filler writes runs of one n whose codes are consecutive (each run a range).
    ranges: bool,
    /// Inputs read and evaluated (column by column: each one's n index, raw code and
    /// output); those before `next` are accepted.
    n_idx: Vec<usize>,
    codes: Vec<i64>,
    outs: Vec<i64>,
    next: usize,
    block: usize,
    exhausted: bool,
    scratch: crate::pipeline::OutputScratch,
    /// Reused buffers of [`Source::refill`] for a block not grouped by n.
    order: Vec<usize>,
    starts: Vec<usize>,
    group: Vec<i64>,
    values: Vec<i64>,
}

/// The filler of [`Source`] that reads an iterator.
fn fill_from<I: Iterator<Item = (usize, i64)>>(
    mut items: I,
) -> impl FnMut(&mut Vec<usize>, &mut Vec<i64>, usize) {
    move |n_idx, codes, block| {
        items.by_ref().take(block).for_each(|(n, c)| {
            n_idx.push(n);
            codes.push(c);
        })
    }
}

/// The filler of [`Source`] that writes [`sweep_inputs`]' stream run by run (each n's codes
/// are one range), without an iterator's step per input.
fn fill_sweep(dp: &Datapath) -> impl FnMut(&mut Vec<usize>, &mut Vec<i64>, usize) {
    let (first, last) = (*dp.input_codes().start(), dp.one_code());
    let n_count = dp.constants().len();
    let (mut n, mut c) = (0, first);
    move |n_idx, codes, block| {
        let mut left = block;
        while left > 0 {
            let run = left.min((last - c + 1) as usize);
            n_idx.resize(n_idx.len() + run, n);
            codes.extend(c..c + run as i64);
            left -= run;
            c += run as i64;
            if c > last {
                c = first;
                n = (n + 1) % n_count;
            }
        }
    }
}

impl<'a, F: FnMut(&mut Vec<usize>, &mut Vec<i64>, usize)> Source<'a, F> {
    const FIRST_BLOCK: usize = 256;
    const MAX_BLOCK: usize = 1 << 16;

    fn new(dp: &'a Datapath, fill: F) -> Self {
        Self::with(dp, fill, false)
    }

    /// A source whose filler writes runs of one n, each a range of codes.
    fn of_ranges(dp: &'a Datapath, fill: F) -> Self {
        Self::with(dp, fill, true)
    }

    fn with(dp: &'a Datapath, fill: F, ranges: bool) -> Self {
        Source {
            dp,
            fill,
            ranges,
            n_idx: Vec::new(),
            codes: Vec::new(),
            outs: Vec::new(),
            next: 0,
            block: Self::FIRST_BLOCK,
            exhausted: false,
            scratch: crate::pipeline::OutputScratch::default(),
            order: Vec::new(),
            starts: Vec::new(),
            group: Vec::new(),
            values: Vec::new(),
        }
    }

    /// The next input, if the stream has one.
    #[inline(always)]
    fn peek(&mut self) -> Option<(usize, i64, i64)> {
        if self.next == self.n_idx.len() {
            if self.exhausted {
                return None;
            }
            self.refill();
            if self.next == self.n_idx.len() {
                return None;
            }
        }
        let i = self.next;
        Some((self.n_idx[i], self.codes[i], self.outs[i]))
    }

    /// Accepts the input [`Source::peek`] returned.
    #[inline(always)]
    fn advance(&mut self) {
        self.next += 1;
    }

    /// Reads and evaluates the next block (once per block: kept out of the per-cycle loop).
    #[cold]
    #[inline(never)]
    fn refill(&mut self) {
        self.n_idx.clear();
        self.codes.clear();
        self.next = 0;
        self.n_idx.reserve(self.block);
        self.codes.reserve(self.block);
        (self.fill)(&mut self.n_idx, &mut self.codes, self.block);
        let len = self.n_idx.len();
        self.exhausted = len < self.block;
        self.block = (self.block * 2).min(Self::MAX_BLOCK);
        // Every output is written below: the columns' old values need no clearing.
        self.outs.resize(len, 0);
        if self.ranges || self.n_idx.windows(2).all(|w| w[0] <= w[1]) {
            // Already grouped by n (the sweep stream): each run of one n is evaluated in
            // place.
            let mut start = 0;
            while start < len {
                let n_idx = self.n_idx[start];
                let end = start + self.n_idx[start..].partition_point(|&n| n == n_idx);
                evaluate(
                    self.dp,
                    n_idx,
                    &self.codes[start..end],
                    &mut self.outs[start..end],
                    &mut self.scratch,
                    self.ranges,
                );
                start = end;
            }
            return;
        }
        // Group by n (a counting sort, so each group keeps stream order), evaluate, scatter
        // back.
        let constants = self.dp.constants();
        let (starts, order) = (&mut self.starts, &mut self.order);
        starts.clear();
        starts.resize(constants.len() + 1, 0);
        for &n_idx in &self.n_idx {
            starts[n_idx + 1] += 1;
        }
        for i in 1..starts.len() {
            starts[i] += starts[i - 1];
        }
        order.clear();
        order.resize(len, 0);
        for (i, &n_idx) in self.n_idx.iter().enumerate() {
            // starts[n_idx] is the next free place of group n_idx; it ends at the group's end.
            order[starts[n_idx]] = i;
            starts[n_idx] += 1;
        }
        let mut group_start = 0;
        for n_idx in 0..constants.len() {
            let group = &order[group_start..starts[n_idx]];
            group_start = starts[n_idx];
            if group.is_empty() {
                continue;
            }
            self.group.clear();
            self.group.extend(group.iter().map(|&i| self.codes[i]));
            self.values.clear();
            self.values.resize(group.len(), 0);
            evaluate(
                self.dp,
                n_idx,
                &self.group,
                &mut self.values,
                &mut self.scratch,
                false,
            );
            for (&i, &v) in group.iter().zip(&self.values) {
                self.outs[i] = v;
            }
        }
    }
}

/// The outputs of `codes` (non-empty) for exponent `n_idx`, into `values`: a run of
/// consecutive codes by range (its cut prefix found by bisection and filled, not evaluated),
/// any other codes one by one in a batch. `range`: the codes are known to be consecutive.
fn evaluate(
    dp: &Datapath,
    n_idx: usize,
    codes: &[i64],
    values: &mut [i64],
    scratch: &mut crate::pipeline::OutputScratch,
    range: bool,
) {
    let nc = &dp.constants()[n_idx];
    let (first, last) = (codes[0], codes[codes.len() - 1]);
    if range || last - first + 1 == codes.len() as i64 && codes.windows(2).all(|w| w[1] == w[0] + 1)
    {
        dp.eval_outputs_range(nc, first..last + 1, values, scratch);
    } else {
        dp.eval_outputs(nc, codes, values, scratch);
    }
}

/// What a simulation keeps besides its statistics.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Record {
    /// Keep every output transfer and the valid/ready bits of every cycle (the co-simulation's
    /// stimulus files need them; statistics do not).
    pub transfers: bool,
    /// Keep the ports and registers of the first this many cycles, for traces.
    pub trace_cycles: u64,
}

/// Runs `machine` on a stream of inputs (`items[i]` gets tag `i`) under `stimulus`'s bubbles
/// and stalls, keeping what `record` asks for; `arch` names the architecture in the
/// statistics. [`simulate`] is this with the machine of an architecture; tests run other
/// machines (a literal register-by-register pipeline) through it.
///
/// A run with neither bubbles nor stalls that records nothing (the statistics of a stream at
/// full rate) takes the same loop compiled without what it does not need: no draw per cycle
/// (a probability of 0 never draws, [`Stimulus::next_cycle`]), no record and no trace.
pub fn run<M: Machine>(
    dp: &Datapath,
    arch: Arch,
    machine: M,
    items: impl Iterator<Item = (usize, i64)>,
    stimulus: &mut Stimulus,
    stop: Stop,
    record: Record,
) -> SimResult {
    let source = Source::new(dp, fill_from(items));
    run_source(dp, arch, machine, source, stimulus, stop, record)
}

/// [`run`] on a [`Source`].
fn run_source<M: Machine, F: FnMut(&mut Vec<usize>, &mut Vec<i64>, usize)>(
    dp: &Datapath,
    arch: Arch,
    machine: M,
    source: Source<'_, F>,
    stimulus: &mut Stimulus,
    stop: Stop,
    record: Record,
) -> SimResult {
    if stimulus.always_ready() && !record.transfers && record.trace_cycles == 0 {
        run_loop::<M, F, true>(dp, arch, machine, source, stimulus, stop, record)
    } else {
        run_loop::<M, F, false>(dp, arch, machine, source, stimulus, stop, record)
    }
}

/// [`run`]'s loop; `STEADY`: the stimulus is always ready and nothing is recorded.
fn run_loop<M: Machine, F: FnMut(&mut Vec<usize>, &mut Vec<i64>, usize), const STEADY: bool>(
    dp: &Datapath,
    arch: Arch,
    mut machine: M,
    mut items: Source<'_, F>,
    stimulus: &mut Stimulus,
    stop: Stop,
    record: Record,
) -> SimResult {
    let transfers = !STEADY && record.transfers;
    let trace_cycles = if STEADY { 0 } else { record.trace_cycles };
    // Room for a run that stops after a number of cycles (up to 2^22 of them; longer runs
    // grow), so that the per-cycle records do not move as they grow.
    let room = match stop {
        Stop::Cycles(c) if transfers => c.min(1 << 22) as usize,
        _ => 0,
    };
    let mut outputs: Vec<OutputEvent> = Vec::with_capacity(room);
    let mut valid_bits = Vec::with_capacity(room);
    let mut ready_bits = Vec::with_capacity(room);
    let mut trace = Vec::new();
    // The inputs in flight, tags `first_in_flight..n_inputs`: the cycle each transferred and
    // the functional model's output for it, tag `t` at `in_flight[t % len]` (a ring of a
    // power-of-two length that doubles when full). Outputs leave in order, so the oldest
    // leaves first.
    let mut in_flight: Vec<(u64, i64)> = vec![(0, 0); 64];
    // The slot of a tag (masked by the ring's own length: no mask kept beside it to spill).
    let slot = |tag: u64, len: usize| tag as usize & (len - 1);
    let mut first_in_flight = 0u64;
    let (mut n_inputs, mut n_outputs) = (0u64, 0u64);
    let (mut latency_min, mut latency_max) = (u64::MAX, 0);
    let mut mismatches = 0;
    let units = machine.unit_names();
    let mut occupied = vec![0u64; units.len()];
    // Cycles in which every unit was busy (added to each unit's count at the end).
    let mut full_cycles = 0u64;
    let (mut bubbles, mut stalls, mut backpressure) = (0, 0, 0);
    let mut order_errors = 0;
    let (max_cycles, drained) = match stop {
        Stop::Cycles(c) => (c, false),
        Stop::Drained(c) => (c, true),
    };
    let mut cycle = 0u64;
    while cycle < max_cycles {
        let next_item = items.peek();
        if drained && next_item.is_none() && n_outputs == n_inputs {
            break;
        }
        let (offer, out_ready) = if STEADY {
            (true, true)
        } else {
            stimulus.next_cycle()
        };
        if transfers {
            valid_bits.push(offer);
            ready_bits.push(out_ready);
        }
        let in_valid = offer && next_item.is_some();
        let in_ready = machine.in_ready(out_ready);
        let output = machine.output();
        if cycle < trace_cycles {
            trace.push(CycleTrace {
                cycle,
                in_valid,
                in_ready,
                input: next_item.map(|(n_idx, c, _)| (n_idx, c)),
                out_valid: output.is_some(),
                out_ready,
                out_data: output.map(|o| o.1),
                registers: machine.registers(dp),
            });
        }
        if machine.full() {
            full_cycles += 1;
        } else {
            machine.count_occupancy(&mut occupied);
        }
        if !STEADY && next_item.is_some() && !offer {
            bubbles += 1;
        }
        if in_valid && !in_ready {
            backpressure += 1;
        }
        let item = match next_item {
            Some((n_idx, c_raw, out)) if in_valid && in_ready => {
                items.advance();
                let tag = n_inputs;
                n_inputs += 1;
                if tag - first_in_flight >= in_flight.len() as u64 {
                    in_flight = grow_ring(&in_flight, first_in_flight, tag);
                }
                let at = slot(tag, in_flight.len());
                in_flight[at] = (cycle, out);
                Some(Item {
                    tag,
                    n_idx,
                    c_raw,
                    out,
                })
            }
            _ => None,
        };
        if let Some((tag, value)) = output {
            if out_ready {
                if tag != n_outputs {
                    order_errors += 1;
                }
                n_outputs += 1;
                // An output whose tag names no input in flight is an order error only. (Its
                // slot is read all the same, and ignored: one comparison for the tag's range,
                // no branch.)
                let known = tag.wrapping_sub(first_in_flight) < n_inputs - first_in_flight;
                let (accepted, want) = in_flight[slot(tag, in_flight.len())];
                let latency = if known { cycle - accepted } else { 0 };
                mismatches += u64::from(known && want != value);
                first_in_flight += u64::from(known && tag == first_in_flight);
                latency_min = latency_min.min(latency);
                latency_max = latency_max.max(latency);
                if transfers {
                    outputs.push(OutputEvent {
                        tag,
                        value,
                        cycle,
                        latency,
                    });
                }
            } else {
                stalls += 1;
            }
        }
        machine.step(dp, item, out_ready);
        cycle += 1;
    }
    if n_outputs == 0 {
        latency_min = 0;
    }
    occupied.iter_mut().for_each(|o| *o += full_cycles);
    let cfg = dp.config();
    let stats = SimStats {
        arch,
        n_cycles: cycle,
        n_inputs,
        n_outputs,
        latency_min,
        latency_max,
        latency_nominal: arch.latency(cfg),
        initiation_interval: arch.initiation_interval(cfg),
        throughput: if cycle == 0 {
            0.0
        } else {
            n_outputs as f64 / cycle as f64
        },
        bubble_cycles: bubbles,
        stall_cycles: stalls,
        backpressure_cycles: backpressure,
        mismatches,
        order_errors,
        occupancy: units
            .into_iter()
            .zip(occupied)
            .map(|(u, o)| {
                (
                    u,
                    if cycle == 0 {
                        0.0
                    } else {
                        o as f64 / cycle as f64
                    },
                )
            })
            .collect(),
    };
    SimResult {
        stats,
        outputs,
        valid_bits,
        ready_bits,
        trace,
    }
}

/// The in-flight ring holding tags `first..tag` (full: `tag - first` is its length), moved
/// into one twice its size, each tag at its index modulo the new length.
#[cold]
#[inline(never)]
fn grow_ring(ring: &[(u64, i64)], first: u64, tag: u64) -> Vec<(u64, i64)> {
    let (old, new) = (ring.len() as u64, ring.len() * 2);
    let mut grown = vec![(0, 0); new];
    for t in first..tag {
        grown[(t % (new as u64)) as usize] = ring[(t % old) as usize];
    }
    grown
}

/// An input stream a simulation can be driven with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// [`random_inputs`]: n and c uniform, seeded.
    Random,
    /// [`sweep_inputs`]: every code up to 1.0 for every n in turn, as the co-simulation's
    /// sorted order and `scripts/bench-peers`' Verilator harness stream them.
    Sweep,
}

impl Stream {
    /// Both streams.
    pub const ALL: [Stream; 2] = [Stream::Random, Stream::Sweep];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Stream::Random => "random",
            Stream::Sweep => "sweep",
        }
    }

    /// The endless stream of inputs for a datapath (`seed` seeds the random one).
    pub fn inputs(self, dp: &Datapath, seed: u64) -> Box<dyn Iterator<Item = (usize, i64)> + '_> {
        match self {
            Stream::Random => Box::new(random_inputs(dp, seed)),
            Stream::Sweep => Box::new(sweep_inputs(dp)),
        }
    }
}

crate::names::named_enum!(Stream, "input stream", "random or sweep");

/// The endless stream of every input code from the format's first up to 1.0, for the first n
/// of the set, then the second, and so on, starting again after the last.
///
/// # Examples
/// ```
/// use specfx::cycle::sim::sweep_inputs;
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let first: Vec<(usize, i64)> = sweep_inputs(&dp).skip(32768).take(2).collect();
/// assert_eq!(first, [(0, 32768), (1, 0)]);
/// ```
pub fn sweep_inputs(dp: &Datapath) -> impl Iterator<Item = (usize, i64)> + '_ {
    let (first, last) = (*dp.input_codes().start(), dp.one_code());
    let n_count = dp.constants().len();
    let (mut n_idx, mut c) = (0, first);
    std::iter::from_fn(move || {
        let item = (n_idx, c);
        if c == last {
            c = first;
            n_idx = (n_idx + 1) % n_count;
        } else {
            c += 1;
        }
        Some(item)
    })
}

/// An endless seeded stream of random inputs: n uniform over the set, c uniform over the
/// input codes (a separate ChaCha8 stream from the stall pattern's).
pub fn random_inputs(dp: &Datapath, seed: u64) -> impl Iterator<Item = (usize, i64)> + '_ {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(1);
    let codes = dp.input_codes();
    let n_count = dp.constants().len();
    std::iter::repeat_with(move || (rng.gen_range(0..n_count), rng.gen_range(codes.clone())))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::Config;

    /// The sweep's run-by-run filler writes [`sweep_inputs`]' stream, whatever the blocks
    /// (within one n, across several, past the last n back to the first).
    #[test]
    fn the_sweep_filler_writes_the_sweep_stream() {
        let mut cfg = Config::from_toml("name = \"narrow\"\n[c]\nformat = \"u1.3\"\n").unwrap();
        cfg.n = "16,17,300".parse().unwrap();
        for dp in [
            Datapath::new(cfg).unwrap(),
            Datapath::new(Config::baseline()).unwrap(),
        ] {
            let mut fill = fill_sweep(&dp);
            let mut want = sweep_inputs(&dp);
            for block in [1, 2, 5, 9, 31, 70_000, 3, 200_000] {
                let (mut n_idx, mut codes) = (vec![7], vec![-1]);
                fill(&mut n_idx, &mut codes, block);
                assert_eq!((n_idx.len(), codes.len()), (block + 1, block + 1));
                let got: Vec<(usize, i64)> = n_idx.into_iter().zip(codes).skip(1).collect();
                let expected: Vec<(usize, i64)> = want.by_ref().take(block).collect();
                assert_eq!(got, expected, "a block of {block}");
            }
        }
    }
}
