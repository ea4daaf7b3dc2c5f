//! Signal-by-signal comparison of two VCD traces of the co-simulation testbench: the model's
//! ([`crate::cycle::vcd`]) and a Verilog simulator's dump of `tb_specfx`.
//!
//! 1. Signals are matched by their full hierarchical name (`tb_specfx.dut.in_c`), a leading
//!    `TOP` scope (Verilator's) dropped; a bit-select variable keeps its index (`a[3]`).
//! 2. Each file is sampled just before every rising edge of `tb_specfx.clk` at which
//!    `tb_specfx.rst` (when the file has it) is 0: the values of the last time step before the
//!    edge's. A sample is keyed by the value of `tb_specfx.cycle` (the testbench's cycle
//!    counter: during cycle t it holds t), so the two files need not share a time line.
//! 3. For every signal in both files the widths must be equal (a signal whose widths differ is
//!    reported and not compared); at every cycle sampled in both files, a bit that is `x` or
//!    `z` in the **first** file is don't-care (the model writes `x` where a register holds no
//!    valid data), and every other bit must be equal in the second.
//! 4. A signal in one file only was never compared: by default ([`Missing::Differ`]) the files
//!    then differ when it is the first file's, or a register of the second file in a scope
//!    the first file has signals in (below [`TESTBENCH`]); [`Options`] accepts them or leaves
//!    named signals out.
//!
//! A file must be well-formed VCD: scopes nested at most [`MAX_SCOPE_DEPTH`] deep, a header of
//! at most [`MAX_HEADER_BYTES`], every variable at least 1 bit wide, every value change for a
//! declared identifier and no wider than its variable, time never going back. Anything else is
//! an error naming the line.
//!
//! Reads from any `io::BufRead`; the files are the caller's business.

use std::collections::HashMap;
use std::io::{BufRead, Read};

use vcd::{Command, IdCode, ReferenceIndex, ScopeItem, ScopeType, Value, VarType};

use crate::error::Error;

/// The clock, reset and cycle counter every trace is sampled by.
pub const CLOCK: &str = "tb_specfx.clk";
/// Samples are taken only while this is 0 (when the file has it).
pub const RESET: &str = "tb_specfx.rst";
/// The cycle counter samples are keyed by.
pub const CYCLE: &str = "tb_specfx.cycle";
/// The deepest `$scope` nesting a trace may have (the parser recurses per scope).
pub const MAX_SCOPE_DEPTH: usize = 256;
/// The longest header (everything up to `$enddefinitions`) a trace may have: 64 MiB.
pub const MAX_HEADER_BYTES: u64 = 64 << 20;
/// The testbench's scope: its own variables (bookkeeping) are not the RTL's registers.
pub const TESTBENCH: &str = "tb_specfx";
/// Variables the reference RTL declares `reg` that hold no state, so that the model has no
/// register of that name: the folded core's `always @*` step multiplexer.
pub const COMBINATIONAL_REGS: &[&str] = &["tb_specfx.dut.g_folded.u_core.step_result"];

/// What a comparison makes of a signal that only one file has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Missing {
    /// The files differ when a signal of the first file is not in the second, or a register
    /// of the second file (`$var reg`, outside functions and tasks, but
    /// [`COMBINATIONAL_REGS`]) sits in a scope below [`TESTBENCH`] in which the first file
    /// declares signals, and the first file lacks it.
    #[default]
    Differ,
    /// Such signals are listed, and are no difference.
    Ignore,
}

/// How [`compare_with`] compares two traces.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Options {
    /// What a signal in one file only makes of the comparison.
    pub missing: Missing,
    /// Signals left out altogether (neither compared nor missing): each a full name
    /// (`tb_specfx.dut.g_folded.u_core.x`), or a prefix followed by `*` (`tb_specfx.extra.*`),
    /// that must match a signal of one of the files.
    pub ignore: Vec<String>,
}

impl Options {
    /// Whether `name` is one of [`Options::ignore`]'s.
    fn ignores(&self, name: &str) -> bool {
        self.ignore.iter().any(|p| matches(p, name))
    }
}

/// Whether an ignored name (a full name, or a prefix followed by `*`) matches `name`.
fn matches(pattern: &str, name: &str) -> bool {
    match pattern.strip_suffix('*') {
        Some(prefix) => name.starts_with(prefix),
        None => name == pattern,
    }
}

/// The trace with its header checked for depth and length (read whole, so that the parser,
/// which recurses per scope, cannot overflow the stack), followed by the rest of it.
fn guarded<R: BufRead>(which: usize, mut r: R) -> Result<impl BufRead, Error> {
    let mut header = Vec::new();
    let (mut depth, mut line, mut skipping) = (0usize, 0u64, false);
    // Inside a `$var`: the field the next token is (1 type, 2 width, 3 id, 4 reference), 0
    // outside; the line of a width of 0, refused once the variable's name is known.
    let (mut var_field, mut zero_width) = (0usize, None::<u64>);
    let zero_width_error = |at: u64, name: &str| {
        trace_error(
            which,
            format!("line {at}: $var {name}has width 0 (a variable has at least 1 bit)"),
        )
    };
    loop {
        let start = header.len();
        let room = MAX_HEADER_BYTES + 1 - start as u64;
        let got = (&mut r)
            .take(room)
            .read_until(b'\n', &mut header)
            .map_err(|e| trace_error(which, format!("cannot read it: {e}")))?;
        if got == 0 {
            break;
        }
        if header.len() as u64 > MAX_HEADER_BYTES {
            return Err(trace_error(
                which,
                format!(
                    "the header (up to $enddefinitions) is longer than {MAX_HEADER_BYTES} bytes"
                ),
            ));
        }
        line += 1;
        let mut done = false;
        for token in header[start..]
            .split(|b| b.is_ascii_whitespace())
            .filter(|t| !t.is_empty())
        {
            match token {
                b"$end" => {
                    if let Some(at) = zero_width.take() {
                        return Err(zero_width_error(at, ""));
                    }
                    skipping = false;
                    var_field = 0;
                }
                _ if skipping => {}
                _ if var_field > 0 => {
                    if var_field == 2 && token.iter().all(|&b| b == b'0') {
                        zero_width = Some(line);
                    }
                    if var_field == 4 {
                        if let Some(at) = zero_width.take() {
                            let name = String::from_utf8_lossy(token);
                            return Err(zero_width_error(
                                at,
                                &format!("'{}' ", name.escape_debug()),
                            ));
                        }
                    }
                    var_field += 1;
                }
                b"$var" => var_field = 1,
                b"$comment" | b"$date" | b"$version" => skipping = true,
                b"$scope" => {
                    depth += 1;
                    if depth > MAX_SCOPE_DEPTH {
                        return Err(trace_error(
                            which,
                            format!("line {line}: $scope nested deeper than {MAX_SCOPE_DEPTH}"),
                        ));
                    }
                }
                b"$upscope" => depth = depth.saturating_sub(1),
                b"$enddefinitions" => done = true,
                _ => {}
            }
        }
        if done {
            break;
        }
    }
    Ok(std::io::Cursor::new(header).chain(r))
}

/// A parser's error as `line N: what` (the parser's own errors carry their line; a read
/// error takes the parser's current line).
fn parse_failure(e: &std::io::Error, line: u64) -> String {
    match e
        .get_ref()
        .and_then(|i| i.downcast_ref::<vcd::ParseError>())
    {
        // A time, a width or a real value: say what was expected, not only Rust's reason.
        Some(p) if matches!(p.kind(), vcd::ParseErrorKind::ParseIntError(_)) => format!(
            "line {}: expected an unsigned decimal number below 2^64 ({})",
            p.line(),
            p.kind()
        ),
        Some(p) => format!("line {}: {}", p.line(), p.kind()),
        None => format!("line {line}: {e}"),
    }
}

/// A signal whose widths differ between the files.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WidthMismatch {
    /// Full name.
    pub signal: String,
    /// Width in the first file.
    pub first: u32,
    /// Width in the second file.
    pub second: u32,
}

/// The first cycle at which the files differ.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Difference {
    /// The cycle (`tb_specfx.cycle`).
    pub cycle: u64,
    /// The first differing signal in the first file's declaration order.
    pub signal: String,
    /// Its value in the first file, hexadecimal (`x` for a digit with an unknown bit).
    pub first: String,
    /// Its value in the second file.
    pub second: String,
    /// The other signals that differ at that cycle, in the same order.
    pub also: Vec<String>,
}

/// What [`compare`] found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Comparison {
    /// Signals in both files with equal widths, compared at every common cycle.
    pub signals_compared: usize,
    /// Signals only in the first file: a difference unless [`Missing::Ignore`].
    pub only_first: Vec<String>,
    /// Signals only in the second file.
    pub only_second: Vec<String>,
    /// The registers among [`Comparison::only_second`] in scopes the first file covers (see
    /// [`Missing::Differ`]): a difference unless [`Missing::Ignore`].
    pub registers_only_second: Vec<String>,
    /// What signals in one file only make of the comparison.
    pub missing: Missing,
    /// Signals of either file left out by [`Options::ignore`].
    pub ignored: Vec<String>,
    /// Signals in both files with different widths.
    pub width_mismatches: Vec<WidthMismatch>,
    /// Cycles sampled in both files.
    pub cycles_compared: u64,
    /// Cycles sampled only in the first file.
    pub cycles_only_first: u64,
    /// Cycles sampled only in the second file.
    pub cycles_only_second: u64,
    /// Compared signals that are unknown (`x` or `z` in every bit) in the first file at every
    /// cycle compared: nothing of them was checked.
    pub never_known: Vec<String>,
    /// Signals that differ at some cycle.
    pub signals_differing: usize,
    /// The first cycle with a difference.
    pub first_difference: Option<Difference>,
}

impl Comparison {
    /// Whether the files agree: something was compared, no width differs, no value differs,
    /// and no signal is missing from one file (unless [`Missing::Ignore`]).
    pub fn agrees(&self) -> bool {
        self.signals_compared > 0
            && self.cycles_compared > 0
            && self.width_mismatches.is_empty()
            && self.first_difference.is_none()
            && (self.missing == Missing::Ignore || self.missing_signals() == 0)
    }

    /// The signals missing from one file that make a difference under [`Missing::Differ`]:
    /// [`Comparison::only_first`] and [`Comparison::registers_only_second`].
    pub fn missing_signals(&self) -> usize {
        self.only_first.len() + self.registers_only_second.len()
    }
}

/// A variable of a file: full name, width, identifier, scope, whether it is a register.
struct Var {
    name: String,
    width: u32,
    code: IdCode,
    /// The full name of its scope.
    scope: String,
    /// Declared `reg`, outside a function or task.
    register: bool,
}

fn trace_error(which: usize, problem: String) -> Error {
    Error::Trace { which, problem }
}

/// Every identifier code the file declares, with its variable's width. One code declared
/// twice (a signal seen in two scopes) must have one width.
fn declared(items: &[ScopeItem], out: &mut HashMap<IdCode, u32>) -> Result<(), String> {
    for item in items {
        match item {
            ScopeItem::Scope(s) => declared(&s.items, out)?,
            ScopeItem::Var(v) => {
                let w = *out.entry(v.code).or_insert(v.size);
                if w != v.size {
                    return Err(format!(
                        "identifier '{}' is declared with widths {w} and {} ({})",
                        v.code, v.size, v.reference
                    ));
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// The file's variables in declaration order, full names unique (the first kept).
fn variables(items: &[ScopeItem]) -> Vec<Var> {
    fn walk(items: &[ScopeItem], path: &mut Vec<String>, in_function: bool, out: &mut Vec<Var>) {
        for item in items {
            match item {
                ScopeItem::Scope(s) => {
                    // Verilator puts the design under a scope of its own.
                    let top = path.is_empty() && s.identifier == "TOP";
                    if !top {
                        path.push(s.identifier.clone());
                    }
                    let function = in_function
                        || matches!(s.scope_type, ScopeType::Function | ScopeType::Task);
                    walk(&s.items, path, function, out);
                    if !top {
                        path.pop();
                    }
                }
                ScopeItem::Var(v) => {
                    if matches!(v.var_type, VarType::Real | VarType::String | VarType::Event) {
                        continue;
                    }
                    let mut name = path.clone();
                    let leaf = match v.index {
                        Some(ReferenceIndex::BitSelect(i)) => format!("{}[{i}]", v.reference),
                        _ => v.reference.clone(),
                    };
                    name.push(leaf);
                    out.push(Var {
                        name: name.join("."),
                        width: v.size,
                        code: v.code,
                        scope: path.join("."),
                        register: v.var_type == VarType::Reg && !in_function,
                    });
                }
                _ => {}
            }
        }
    }
    let mut out = Vec::new();
    walk(items, &mut Vec::new(), false, &mut out);
    let mut seen = std::collections::HashSet::new();
    out.retain(|v| seen.insert(v.name.clone()));
    out
}

/// The bits of some signals, packed: values and unknown (`x`/`z`) masks, bit `offset + i` of
/// a signal at `offset` being its bit i.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Packed {
    value: Vec<u64>,
    unknown: Vec<u64>,
}

impl Packed {
    fn get(&self, bit: usize) -> Option<bool> {
        let (w, b) = (bit / 64, bit % 64);
        if self.unknown[w] >> b & 1 == 1 {
            None
        } else {
            Some(self.value[w] >> b & 1 == 1)
        }
    }
}

/// Where each compared signal sits in a [`Packed`] sample.
struct Layout {
    /// Per compared signal: bit offset, width.
    fields: Vec<(usize, u32)>,
    words: usize,
}

impl Layout {
    fn new(widths: impl Iterator<Item = u32>) -> Layout {
        let mut offset = 0;
        let fields = widths
            .map(|w| {
                let f = (offset, w);
                offset += w as usize;
                f
            })
            .collect();
        Layout {
            fields,
            words: offset.div_ceil(64).max(1),
        }
    }
}

/// A value change extended to `width` bits, most significant first (VCD's rule: a shorter
/// value is padded on the left with 0, or with `x`/`z` when its first bit is one).
fn extend(v: &[Value], width: usize) -> Vec<Value> {
    if v.len() >= width {
        return v[v.len() - width..].to_vec();
    }
    let pad = match v.first() {
        Some(Value::X) => Value::X,
        Some(Value::Z) => Value::Z,
        None => Value::X,
        _ => Value::V0,
    };
    let mut out = vec![pad; width - v.len()];
    out.extend_from_slice(v);
    out
}

/// One file being read: the parser, the current value of each variable of interest.
struct Reader<R> {
    which: usize,
    parser: vcd::Parser<R>,
    /// Identifier of each slot's variable(s) to the slot.
    slots: HashMap<IdCode, usize>,
    /// The current value of each slot, most significant bit first.
    current: Vec<Vec<Value>>,
    clk: usize,
    rst: Option<usize>,
    cycle: usize,
    /// Per compared signal, its slot.
    signal_slots: Vec<usize>,
    /// Every declared identifier code and its width.
    declared: HashMap<IdCode, u32>,
    /// The last time step seen.
    time: Option<u64>,
}

impl<R: BufRead> Reader<R> {
    /// Prepares to sample `compared` (full names) of a file whose variables are `vars`.
    fn new(which: usize, parser: vcd::Parser<R>, header: &Header, compared: &[&str]) -> Reader<R> {
        let vars = &header.vars;
        let mut slots = HashMap::new();
        let mut current = Vec::new();
        let mut slot_of = |v: &Var| -> usize {
            *slots.entry(v.code).or_insert_with(|| {
                current.push(vec![Value::X; v.width as usize]);
                current.len() - 1
            })
        };
        let find = |name: &str| vars.iter().find(|v| v.name == name);
        let clk = slot_of(find(CLOCK).expect("checked"));
        let rst = find(RESET).map(&mut slot_of);
        let cycle = slot_of(find(CYCLE).expect("checked"));
        let signal_slots = compared
            .iter()
            .map(|name| slot_of(find(name).expect("in both files")))
            .collect();
        Reader {
            which,
            parser,
            slots,
            current,
            clk,
            rst,
            cycle,
            signal_slots,
            declared: header.declared.clone(),
            time: None,
        }
    }

    /// Reads the whole file, calling `sample(cycle, values)` before each rising clock edge at
    /// which reset is low and the cycle counter known.
    fn run(
        mut self,
        layout: &Layout,
        mut sample: impl FnMut(u64, Packed) -> Result<(), Error>,
    ) -> Result<(), Error> {
        let mut batch: Vec<(usize, Vec<Value>)> = Vec::new();
        loop {
            let command = self
                .parser
                .next()
                .transpose()
                .map_err(|e| trace_error(self.which, parse_failure(&e, self.parser.line())))?;
            self.check(&command)?;
            let end_of_step = matches!(command, None | Some(Command::Timestamp(_)));
            if end_of_step {
                let clk_before = self.current[self.clk].last().copied();
                let clk_after = batch
                    .iter()
                    .rev()
                    .find(|(slot, _)| *slot == self.clk)
                    .and_then(|(_, v)| v.last().copied());
                if clk_before != Some(Value::V1) && clk_after == Some(Value::V1) {
                    if let Some((cycle, packed)) = self.sample(layout) {
                        sample(cycle, packed)?;
                    }
                }
                for (slot, v) in batch.drain(..) {
                    self.current[slot] = v;
                }
            }
            match command {
                None => return Ok(()),
                Some(Command::ChangeScalar(id, v)) => self.change(&mut batch, id, &[v]),
                Some(Command::ChangeVector(id, v)) => {
                    let v: Vec<Value> = v.iter().collect();
                    self.change(&mut batch, id, &v)
                }
                Some(_) => {}
            }
        }
    }

    /// Refuses a change of an undeclared identifier, a value wider than its variable and a
    /// time step before the last.
    fn check(&mut self, command: &Option<Command>) -> Result<(), Error> {
        let line = self.parser.line();
        let fail = |what: String| Err(trace_error(self.which, format!("line {line}: {what}")));
        let (id, bits) = match command {
            Some(Command::Timestamp(t)) => {
                if let Some(last) = self.time.filter(|&last| *t < last) {
                    return fail(format!("time #{t} goes back (the last was #{last})"));
                }
                self.time = Some(*t);
                return Ok(());
            }
            Some(Command::ChangeScalar(id, _)) => (id, 1),
            Some(Command::ChangeVector(id, v)) => (id, v.len()),
            Some(Command::ChangeReal(id, _)) | Some(Command::ChangeString(id, _)) => (id, 0),
            // Declarations belong to the header: one among the values would go unread.
            Some(
                Command::ScopeDef(..)
                | Command::Upscope
                | Command::VarDef(..)
                | Command::Enddefinitions
                | Command::Timescale(..),
            ) => return fail("a declaration after $enddefinitions".to_string()),
            _ => return Ok(()),
        };
        match self.declared.get(id) {
            None => fail(format!(
                "a value for identifier '{id}', which no $var declares"
            )),
            Some(&w) if bits > w as usize => fail(format!(
                "a value of {bits} bits for identifier '{id}', a variable of {w} bits"
            )),
            Some(_) => Ok(()),
        }
    }

    fn change(&self, batch: &mut Vec<(usize, Vec<Value>)>, id: IdCode, v: &[Value]) {
        if let Some(&slot) = self.slots.get(&id) {
            batch.push((slot, extend(v, self.current[slot].len())));
        }
    }

    /// The values now, if this is a sample: reset low, the cycle counter known.
    fn sample(&self, layout: &Layout) -> Option<(u64, Packed)> {
        if let Some(rst) = self.rst {
            if self.current[rst].iter().any(|&b| b != Value::V0) {
                return None;
            }
        }
        let mut cycle = 0u64;
        for &b in &self.current[self.cycle] {
            cycle = cycle.wrapping_shl(1)
                | match b {
                    Value::V0 => 0,
                    Value::V1 => 1,
                    _ => return None,
                };
        }
        let mut packed = Packed {
            value: vec![0; layout.words],
            unknown: vec![0; layout.words],
        };
        for (&slot, &(offset, width)) in self.signal_slots.iter().zip(&layout.fields) {
            let v = &self.current[slot];
            for i in 0..width as usize {
                let bit = offset + i;
                let (w, b) = (bit / 64, bit % 64);
                match v[v.len() - 1 - i] {
                    Value::V0 => {}
                    Value::V1 => packed.value[w] |= 1 << b,
                    _ => packed.unknown[w] |= 1 << b,
                }
            }
        }
        Some((cycle, packed))
    }
}

/// A signal's value in a sample, hexadecimal: one digit per 4 bits, `x` for a digit with an
/// unknown bit.
fn hex(packed: &Packed, offset: usize, width: u32) -> String {
    let digits = (width as usize).div_ceil(4).max(1);
    (0..digits)
        .rev()
        .map(|d| {
            let mut nibble = 0;
            for i in (0..4).rev() {
                let bit = d * 4 + i;
                if bit >= width as usize {
                    continue;
                }
                match packed.get(offset + bit) {
                    None => return 'x',
                    Some(b) => nibble = nibble << 1 | u32::from(b),
                }
            }
            char::from_digit(nibble, 16).expect("a nibble")
        })
        .collect()
}

/// Whether signal `(offset, width)` differs: a known bit of `first` that `second` does not
/// have (unknown in `second`, or the other value).
fn differs(first: &Packed, second: &Packed, offset: usize, width: u32) -> bool {
    (offset..offset + width as usize).any(|bit| match first.get(bit) {
        None => false,
        Some(b) => second.get(bit) != Some(b),
    })
}

/// What a file's header declares.
struct Header {
    /// The variables, full names unique.
    vars: Vec<Var>,
    /// Every identifier code and its width.
    declared: HashMap<IdCode, u32>,
}

/// The variables of a file's header, which must hold the clock and the cycle counter.
fn header<R: BufRead>(which: usize, p: &mut vcd::Parser<R>) -> Result<Header, Error> {
    let h = p.parse_header().map_err(|e| {
        trace_error(
            which,
            format!("not a VCD file: {}", parse_failure(&e, p.line())),
        )
    })?;
    let vars = variables(&h.items);
    for needed in [CLOCK, CYCLE] {
        if !vars.iter().any(|v| v.name == needed) {
            return Err(trace_error(which, format!("no signal {needed}")));
        }
    }
    let mut ids = HashMap::new();
    declared(&h.items, &mut ids).map_err(|e| trace_error(which, e))?;
    Ok(Header {
        vars,
        declared: ids,
    })
}

/// Compares two VCD traces of the testbench (see the module documentation) with the default
/// [`Options`]: `first`'s `x` and `z` bits are don't-care, a signal missing from one file is a
/// difference ([`Missing::Differ`]).
///
/// # Errors
/// [`Error::Trace`] (naming the file, 0 or 1) when a file is not VCD or lacks `tb_specfx.clk`
/// or `tb_specfx.cycle`.
///
/// # Examples
/// ```
/// use specfx::cycle::compare::compare;
/// let model = "$scope module tb_specfx $end $var reg 1 ! clk $end
/// $var integer 32 \" cycle $end $var wire 4 # v $end $upscope $end $enddefinitions $end
/// #0 0! b0 \" bx #
/// #5 1! #6 b1 \" b101 # #10 0! #15 1!\n";
/// let rtl = model.replace("b101", "b100");
/// let c = compare(model.as_bytes(), rtl.as_bytes()).unwrap();
/// let d = c.first_difference.unwrap();
/// assert_eq!((d.cycle, d.signal.as_str(), d.first.as_str(), d.second.as_str()),
///     (1, "tb_specfx.v", "5", "4"));
/// assert_eq!(c.cycles_compared, 2); // cycle 0: v is x in the model, don't-care
/// ```
pub fn compare(first: impl BufRead, second: impl BufRead) -> Result<Comparison, Error> {
    compare_with(first, second, &Options::default())
}

/// Compares two VCD traces of the testbench (see the module documentation) as `options` say:
/// signals [`Options::ignore`] names are left out, and [`Options::missing`] decides whether a
/// signal in one file only makes a difference.
///
/// # Errors
/// [`Error::Trace`] (naming the file, 0 or 1) when a file is not VCD or lacks `tb_specfx.clk`
/// or `tb_specfx.cycle`; [`Error::UnknownName`] when an ignored name matches no signal.
///
/// # Examples
/// ```
/// use specfx::cycle::compare::{compare_with, Missing, Options};
/// let model = "$scope module tb_specfx $end $var reg 1 ! clk $end
/// $var integer 32 \" cycle $end $var wire 4 # v $end $upscope $end
/// $scope module extra $end $var reg 1 ~~ ghost $end $upscope $end $enddefinitions $end
/// #0 0! b0 \" b101 # 1~~ #5 1! #6 b1 \" #10 0! #15 1!\n";
/// let rtl = model.replace("$scope module extra $end $var reg 1 ~~ ghost $end $upscope $end", "")
///     .replace(" 1~~", "");
/// let strict = compare_with(model.as_bytes(), rtl.as_bytes(), &Options::default()).unwrap();
/// assert_eq!(strict.only_first, ["extra.ghost"]);
/// assert!(!strict.agrees()); // every value is equal, but ghost was never compared
/// let waived = Options { missing: Missing::Ignore, ..Options::default() };
/// assert!(compare_with(model.as_bytes(), rtl.as_bytes(), &waived).unwrap().agrees());
/// let ignored = Options { ignore: vec!["extra.*".into()], ..Options::default() };
/// assert!(compare_with(model.as_bytes(), rtl.as_bytes(), &ignored).unwrap().agrees());
/// ```
pub fn compare_with(
    first: impl BufRead,
    second: impl BufRead,
    options: &Options,
) -> Result<Comparison, Error> {
    let mut pa = vcd::Parser::new(guarded(0, first)?);
    let mut pb = vcd::Parser::new(guarded(1, second)?);
    let ha = header(0, &mut pa)?;
    let hb = header(1, &mut pb)?;
    let (va, vb) = (&ha.vars, &hb.vars);
    if let Some(p) = options
        .ignore
        .iter()
        .find(|p| !va.iter().chain(vb).any(|v| matches(p, &v.name)))
    {
        return Err(Error::UnknownName {
            what: "signal to ignore",
            expected: "the full name of a signal of either trace, or a prefix followed by *",
            got: p.clone(),
        });
    }
    let mut ignored: Vec<String> = Vec::new();
    for v in va.iter().chain(vb) {
        if options.ignores(&v.name) && !ignored.contains(&v.name) {
            ignored.push(v.name.clone());
        }
    }
    let (va, vb): (Vec<&Var>, Vec<&Var>) = (
        va.iter().filter(|v| !options.ignores(&v.name)).collect(),
        vb.iter().filter(|v| !options.ignores(&v.name)).collect(),
    );
    let by_name_b: HashMap<&str, &Var> = vb.iter().map(|v| (v.name.as_str(), *v)).collect();
    let by_name_a: HashMap<&str, &Var> = va.iter().map(|v| (v.name.as_str(), *v)).collect();
    // The scopes the first file covers: those below the testbench's it declares signals in.
    let below_testbench = format!("{TESTBENCH}.");
    let covered: std::collections::HashSet<&str> = va
        .iter()
        .map(|v| v.scope.as_str())
        .filter(|s| s.starts_with(&below_testbench))
        .collect();
    let mut compared: Vec<(&str, u32)> = Vec::new();
    let mut width_mismatches = Vec::new();
    let mut only_first = Vec::new();
    for a in &va {
        match by_name_b.get(a.name.as_str()) {
            None => only_first.push(a.name.clone()),
            Some(b) if b.width != a.width => width_mismatches.push(WidthMismatch {
                signal: a.name.clone(),
                first: a.width,
                second: b.width,
            }),
            Some(_) => compared.push((&a.name, a.width)),
        }
    }
    let only_second: Vec<&Var> = vb
        .iter()
        .filter(|b| !by_name_a.contains_key(b.name.as_str()))
        .copied()
        .collect();
    let registers_only_second = only_second
        .iter()
        .filter(|b| {
            b.register
                && covered.contains(b.scope.as_str())
                && !COMBINATIONAL_REGS.contains(&b.name.as_str())
        })
        .map(|b| b.name.clone())
        .collect();
    let only_second = only_second.iter().map(|b| b.name.clone()).collect();
    let names: Vec<&str> = compared.iter().map(|c| c.0).collect();
    let layout = Layout::new(compared.iter().map(|c| c.1));

    // The first file's samples, then the second's compared with them as they come.
    let mut samples_a: Vec<Packed> = Vec::new();
    let mut index_a: HashMap<u64, usize> = HashMap::new();
    Reader::new(0, pa, &ha, &names).run(&layout, |cycle, packed| {
        index_a.entry(cycle).or_insert_with(|| {
            samples_a.push(packed);
            samples_a.len() - 1
        });
        Ok(())
    })?;
    let mut matched = vec![false; samples_a.len()];
    let mut seen_b = std::collections::HashSet::new();
    let (mut cycles_compared, mut cycles_only_second) = (0u64, 0u64);
    let mut first_cycle_of = vec![None::<u64>; compared.len()];
    let mut known = vec![false; compared.len()];
    let mut first_difference: Option<Difference> = None;
    Reader::new(1, pb, &hb, &names).run(&layout, |cycle, b| {
        if !seen_b.insert(cycle) {
            return Ok(());
        }
        let Some(&ia) = index_a.get(&cycle) else {
            cycles_only_second += 1;
            return Ok(());
        };
        matched[ia] = true;
        cycles_compared += 1;
        let a = &samples_a[ia];
        for (s, k) in known.iter_mut().enumerate() {
            let (offset, width) = layout.fields[s];
            *k = *k || (offset..offset + width as usize).any(|bit| a.get(bit).is_some());
        }
        let differing: Vec<usize> = (0..compared.len())
            .filter(|&s| differs(a, &b, layout.fields[s].0, layout.fields[s].1))
            .collect();
        for &s in &differing {
            let first = first_cycle_of[s].get_or_insert(cycle);
            *first = (*first).min(cycle);
        }
        if let Some(&s) = differing.first() {
            if first_difference.as_ref().is_none_or(|d| cycle < d.cycle) {
                let (offset, width) = layout.fields[s];
                first_difference = Some(Difference {
                    cycle,
                    signal: names[s].to_string(),
                    first: hex(a, offset, width),
                    second: hex(&b, offset, width),
                    also: differing[1..]
                        .iter()
                        .map(|&o| names[o].to_string())
                        .collect(),
                });
            }
        }
        Ok(())
    })?;
    Ok(Comparison {
        signals_compared: compared.len(),
        only_first,
        only_second,
        registers_only_second,
        missing: options.missing,
        ignored,
        width_mismatches,
        cycles_compared,
        cycles_only_first: matched.iter().filter(|&&m| !m).count() as u64,
        cycles_only_second,
        never_known: (0..compared.len())
            .filter(|&s| !known[s])
            .map(|s| names[s].to_string())
            .collect(),
        signals_differing: first_cycle_of.iter().filter(|c| c.is_some()).count(),
        first_difference,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_vector_values_are_padded_as_vcd_says() {
        use Value::*;
        assert_eq!(extend(&[V1, V0], 4), [V0, V0, V1, V0]);
        assert_eq!(extend(&[X, V1], 3), [X, X, V1]);
        assert_eq!(extend(&[Z], 2), [Z, Z]);
        assert_eq!(extend(&[V1, V1, V0], 2), [V1, V0]);
    }

    const GOOD: &str = "$scope module tb_specfx $end $var reg 1 ! clk $end
$var integer 32 \" cycle $end $var wire 4 # v $end $upscope $end $enddefinitions $end
#0 0! b0 \" bx #
#5 1! #6 b1 \" b101 # #10 0! #15 1!
";

    /// `second`'s error against the good trace.
    fn second_error(second: &str) -> String {
        match compare(GOOD.as_bytes(), second.as_bytes()) {
            Err(Error::Trace { which: 1, problem }) => problem,
            other => panic!("{second}: {other:?}"),
        }
    }

    #[test]
    fn malformed_traces_are_refused_with_their_line() {
        assert!(compare(GOOD.as_bytes(), GOOD.as_bytes()).unwrap().agrees());
        for (from, to, expect) in [
            (
                "b101 #",
                "b101 %",
                "line 4: a value for identifier '%', which no $var declares",
            ),
            (
                "b101 #",
                "b10101 #",
                "line 4: a value of 5 bits for identifier '#', a variable of 4 bits",
            ),
            (
                "#10 0!",
                "#4 0!",
                "line 4: time #4 goes back (the last was #6)",
            ),
            ("#15", "#1x", "line 4: "),
        ] {
            assert_eq!(
                second_error(&GOOD.replacen(from, to, 1)).split_once(" at line"),
                None
            );
            let e = second_error(&GOOD.replacen(from, to, 1));
            assert!(e.starts_with(expect), "{to}: {e}");
        }
        // A variable of no bit, its width on the line named, wherever its name is.
        let e = second_error(&GOOD.replacen("4 # v", "0 # v", 1));
        assert_eq!(
            e,
            "line 2: $var 'v' has width 0 (a variable has at least 1 bit)"
        );
        let e = second_error(&GOOD.replacen("4 # v $end", "000\n#\nv\n$end", 1));
        assert_eq!(
            e,
            "line 2: $var 'v' has width 0 (a variable has at least 1 bit)"
        );
        let e = second_error(&GOOD.replacen("4 # v $end", "0 $end", 1));
        assert_eq!(
            e,
            "line 2: $var has width 0 (a variable has at least 1 bit)"
        );
        // A 0 elsewhere in a declaration is no width, nor one in a comment.
        let named = GOOD.replacen("# v $end", "# 0 $end $comment $var wire 0 % w $end", 1);
        let r = compare(GOOD.as_bytes(), named.as_bytes());
        assert!(r.is_ok(), "{r:?}");
        let e = second_error(&GOOD.replacen("#10", "$var wire 1 % w $end #10", 1));
        assert_eq!(e, "line 4: a declaration after $enddefinitions");
        let e = second_error(&GOOD.replacen("4 # v", "4 # v $end $var wire 1 # w", 1));
        assert_eq!(e, "identifier '#' is declared with widths 4 and 1 (w)");
        let e = second_error(&GOOD.replacen("#10", "#1x0", 1));
        assert_eq!(
            e,
            "line 4: expected an unsigned decimal number below 2^64 (invalid digit found in string)"
        );
        // The line is said once: the parser's own errors carry it as "at line N".
        let e = second_error(&GOOD.replacen("#6", "#6 q", 1));
        assert_eq!(e, "line 4: unexpected character at start of command");
    }

    #[test]
    fn deep_scopes_and_long_headers_are_refused_before_parsing() {
        let at = |depth: usize| {
            let scopes = "$scope module a $end\n".repeat(depth - 1);
            let ups = "$upscope $end ".repeat(depth - 1);
            GOOD.replacen("$var reg", &format!("{scopes}$var reg"), 1)
                .replacen("$upscope", &format!("{ups}$upscope"), 1)
        };
        // 256 deep is read (and compared: the clock is then not tb_specfx.clk); 257 is not.
        let e = second_error(&at(MAX_SCOPE_DEPTH));
        assert_eq!(e, "no signal tb_specfx.clk");
        let e = second_error(&at(MAX_SCOPE_DEPTH + 1));
        assert_eq!(e, "line 256: $scope nested deeper than 256");
        // Far deeper than the stack would allow the parser's recursion.
        let e = second_error(&at(100_000));
        assert_eq!(e, "line 256: $scope nested deeper than 256");
        // `$scope` in a comment is not a scope.
        let commented = GOOD.replacen(
            "$scope",
            &format!("$comment {} $end $scope", "$scope ".repeat(300)),
            1,
        );
        assert!(compare(GOOD.as_bytes(), commented.as_bytes())
            .unwrap()
            .agrees());
        let long = format!(
            "$comment {} $end\n{GOOD}",
            "x".repeat(MAX_HEADER_BYTES as usize)
        );
        let e = second_error(&long);
        assert!(
            e.starts_with("the header (up to $enddefinitions) is longer than"),
            "{e}"
        );
    }

    /// GOOD with `extra` declared inside its scope.
    fn with(extra: &str) -> String {
        GOOD.replacen(" $upscope", &format!(" {extra} $upscope"), 1)
    }

    #[test]
    fn a_signal_in_one_file_only_differs_unless_ignored() {
        let model = with("$scope module dut $end $var wire 1 % a $end $upscope $end");
        let rtl = |q: &str| {
            with(&format!(
                "$scope module dut $end $var wire 1 % a $end {q} $upscope $end"
            ))
        };
        let run = |first: &str, second: &str, options: &Options| {
            compare_with(first.as_bytes(), second.as_bytes(), options).unwrap()
        };
        let strict = Options::default();
        assert!(run(&model, &rtl(""), &strict).agrees());
        // The model's signal the RTL lacks.
        let c = run(&model, GOOD, &strict);
        assert_eq!(c.only_first, ["tb_specfx.dut.a"]);
        assert!(!c.agrees() && c.first_difference.is_none());
        // The RTL's register in a scope the model has signals in; not a wire, not in a
        // function, not the testbench's own, not in a scope the model does not have.
        let c = run(&model, &rtl("$var reg 1 & q $end"), &strict);
        assert_eq!(c.registers_only_second, ["tb_specfx.dut.q"]);
        assert!(!c.agrees());
        for agreeing in [
            rtl("$var wire 1 & q $end"),
            rtl("$scope function f $end $var reg 1 & q $end $upscope $end"),
            rtl("$scope module u $end $var reg 1 & q $end $upscope $end"),
            with("$scope module dut $end $var wire 1 % a $end $upscope $end $var reg 1 & q $end"),
        ] {
            let c = run(&model, &agreeing, &strict);
            assert!(c.agrees(), "{agreeing}: {c:?}");
            assert_eq!(c.only_second.len(), 1);
        }
        // Accepted as a policy, or left out by name or prefix.
        let waived = Options {
            missing: Missing::Ignore,
            ..Options::default()
        };
        assert!(run(&model, &rtl("$var reg 1 & q $end"), &waived).agrees());
        assert!(run(&model, GOOD, &waived).agrees());
        for pattern in ["tb_specfx.dut.a", "tb_specfx.dut.*", "tb_specfx.d*"] {
            let o = Options {
                ignore: vec![pattern.into()],
                ..Options::default()
            };
            let c = run(&model, GOOD, &o);
            assert!(c.agrees(), "{pattern}: {c:?}");
            assert_eq!(c.ignored, ["tb_specfx.dut.a"]);
        }
        // An ignored name must be a signal's; ignoring everything compares nothing.
        let o = Options {
            ignore: vec!["tb_specfx.dut.b".into()],
            ..Options::default()
        };
        let e = compare_with(model.as_bytes(), GOOD.as_bytes(), &o).unwrap_err();
        assert!(e
            .to_string()
            .starts_with("unknown signal to ignore 'tb_specfx.dut.b'"));
        let o = Options {
            ignore: vec!["*".into()],
            ..Options::default()
        };
        let c = run(&model, GOOD, &o);
        assert_eq!((c.signals_compared, c.agrees()), (0, false));
    }

    #[test]
    fn hex_digits_show_unknown_nibbles() {
        let p = Packed {
            value: vec![0b1_0110_1010],
            unknown: vec![1 << 9],
        };
        assert_eq!(hex(&p, 0, 9), "16a");
        assert_eq!(hex(&p, 0, 10), "x6a");
        assert_eq!(hex(&p, 4, 4), "6");
    }
}
