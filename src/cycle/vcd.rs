//! VCD traces of a simulation under the reference RTL's hierarchy, names and widths, so that a
//! Verilog simulator's dump of the co-simulation testbench and the model's trace can be
//! compared signal by signal ([`crate::cycle::compare`]).
//!
//! The trace has three scopes, as Icarus Verilog and Verilator dump `tb_specfx`:
//!
//! - `tb_specfx`: `clk`, `rst`, `cycle` (the testbench's 32-bit `integer`), `in_n` and the
//!   DUT's ports;
//! - `tb_specfx.dut`: the ports of `specfx_dut` (the table of the top's ports,
//!   [`TOP_PORTS`]);
//! - `tb_specfx.dut.g_pipelined.u_core` or `tb_specfx.dut.g_folded.u_core`: the same ports,
//!   `advance` (pipelined), and every register of the core ([`crate::cycle::rtl`]).
//!
//! It follows the testbench's time line: a clock period of [`PERIOD`] time units (ns), rising
//! edges at `5 + 10 j`, reset high for the first four edges, cycle t from the edge at
//! [`cycle_start`]`(t)` to the next. The input ports carry, as the testbench drives them, the
//! source's next input whether it is offered or not (zeros when none is left). Values are two's
//! complement of the RTL width; a register without valid data is `x`.

use std::io::{self, Write};

use vcd::{IdCode, ReferenceIndex, ScopeType, TimescaleUnit, Value, VarType};

use crate::cycle::rtl::{core_scope, Widths};
use crate::cycle::sim::CycleTrace;
use crate::cycle::{Arch, Word};
use crate::pipeline::ports::{Carries, TOP_PORTS};
use crate::pipeline::Datapath;

/// Clock period in the trace, in time units (ns), as the testbench's `always #5 clk = ~clk`.
pub const PERIOD: u64 = 10;

/// Rising edges during which reset is high, as in the testbench.
pub const RESET_EDGES: u64 = 4;

/// The time of the rising edge that starts cycle `cycle` (the one that ends it is
/// `cycle_start(cycle + 1)`): the testbench's first edge is at half a period, and cycle 0
/// starts at the edge that releases reset.
///
/// # Examples
/// ```
/// assert_eq!(specfx::cycle::vcd::cycle_start(0), 35);
/// ```
pub fn cycle_start(cycle: u64) -> u64 {
    PERIOD / 2 + (RESET_EDGES - 1 + cycle) * PERIOD
}

/// Where a traced signal's value comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Source {
    /// A port of the top (the one port table, `pipeline::ports`).
    Port(Carries),
    Cycle,
    InN,
    /// `registers[i]` of the cycle.
    Register(usize),
}

/// One `$var`: its scope below the top, name, width and source.
struct Signal {
    scope: Vec<String>,
    name: String,
    width: u32,
    source: Source,
}

fn port_list(dp: &Datapath) -> Vec<(&'static str, u32, Source)> {
    TOP_PORTS
        .iter()
        .map(|p| (p.name, p.width(dp), Source::Port(p.carries)))
        .collect()
}

/// Every signal of the trace, in declaration order.
fn signals(dp: &Datapath, arch: Arch, first: Option<&CycleTrace>) -> Vec<Signal> {
    let w = Widths::of(dp);
    let scope_of = |s: &str| -> Vec<String> {
        if s.is_empty() {
            Vec::new()
        } else {
            s.split('.').map(str::to_string).collect()
        }
    };
    let mut v = Vec::new();
    let mut push = |scope: &str, name: &str, width: u32, source: Source| {
        v.push(Signal {
            scope: scope_of(scope),
            name: name.to_string(),
            width,
            source,
        })
    };
    let core = format!("dut.{}", core_scope(arch));
    for scope in ["", "dut", &core] {
        for (name, width, source) in port_list(dp) {
            push(scope, name, width, source);
        }
        if scope.is_empty() {
            push("", "cycle", 32, Source::Cycle);
            push("", "in_n", w.n, Source::InN);
        }
    }
    if arch == Arch::Pipelined {
        push(&core, "advance", 1, Source::Port(Carries::InReady));
    }
    for (i, r) in first.map_or(&[][..], |t| &t.registers).iter().enumerate() {
        let (scope, name) = match r.name.rsplit_once('.') {
            Some((s, n)) => (format!("{core}.{s}"), n),
            None => (core.clone(), r.name.as_str()),
        };
        push(&scope, name, r.width, Source::Register(i));
    }
    v
}

fn bits(word: &Word) -> Vec<Value> {
    (0..word.width())
        .rev()
        .map(|i| if word.bit(i) { Value::V1 } else { Value::V0 })
        .collect()
}

/// A signal's value in a cycle (`None`: unknown).
fn value(dp: &Datapath, t: &CycleTrace, source: Source, width: u32) -> Option<Word> {
    let nc = t.input.map(|(n_idx, _)| &dp.constants()[n_idx]);
    let raw = match source {
        Source::Port(Carries::Clock | Carries::Reset) => 0,
        Source::Cycle => t.cycle as i64,
        Source::InN => nc.map_or(0, |nc| i64::from(nc.n)),
        Source::Port(Carries::InValid) => i64::from(t.in_valid),
        Source::Port(Carries::InReady) => i64::from(t.in_ready),
        Source::Port(Carries::C) => t.input.map_or(0, |(_, c)| c),
        Source::Port(Carries::PerN(p)) => nc.map_or(0, |nc| p.raw(nc)),
        Source::Port(Carries::OutValid) => i64::from(t.out_valid),
        Source::Port(Carries::OutReady) => i64::from(t.out_ready),
        Source::Port(Carries::OutData) => t.out_data?,
        Source::Register(i) => return t.registers[i].value.clone(),
    };
    Some(Word::new(raw, width))
}

/// The longest trace specfx writes, in cycles (2^18, room for the default co-simulation of
/// the baseline in either architecture: the folded one is expected to need about 137,000
/// cycles): every register of every traced cycle is kept in memory, several kilobytes a
/// cycle, until the trace is written.
pub const MAX_TRACE_CYCLES: u64 = 1 << 18;

/// The first bytes of every trace [`write_vcd`] writes (a simulator's dump begins with
/// `$date` or a comment): how a command recognises its own earlier trace before replacing it.
pub const VCD_HEADER: &str = "$timescale 1 ns $end\n$scope module tb_specfx $end\n";

/// Writes a trace of `arch` as VCD (GTKWave opens it) under the RTL's names: see the module
/// documentation.
///
/// # Examples
/// ```
/// use specfx::cycle::sim::{simulate, Stimulus, Stop};
/// use specfx::cycle::Arch;
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let inputs = (0..10).map(|i| (0, 30_000 + i));
/// let r = simulate(&dp, Arch::Pipelined, inputs, &mut Stimulus::new(1, 0.0, 0.0),
///     Stop::Drained(100), u64::MAX);
/// let mut buf = Vec::new();
/// specfx::cycle::vcd::write_vcd(&mut buf, &dp, Arch::Pipelined, &r.trace).unwrap();
/// let text = String::from_utf8(buf).unwrap();
/// assert!(text.contains("$scope module u_core $end"));
/// assert!(text.contains("$var wire 17 ") && text.contains(" y_q [16:0] $end"));
/// ```
pub fn write_vcd(
    w: &mut impl Write,
    dp: &Datapath,
    arch: Arch,
    trace: &[CycleTrace],
) -> io::Result<()> {
    let signals = signals(dp, arch, trace.first());
    let mut vcd = vcd::Writer::new(w);
    vcd.timescale(1, TimescaleUnit::NS)?;
    // One identifier per source: a port shown in three scopes is one signal, as simulators
    // write connected nets.
    let mut ids: Vec<(Source, IdCode)> = Vec::new();
    let clk = IdCode::FIRST;
    let mut next_id = clk.next();
    let mut id_of = |source: Source| -> (IdCode, bool) {
        if source == Source::Port(Carries::Clock) {
            return (clk, false);
        }
        if let Some(&(_, id)) = ids.iter().find(|(s, _)| *s == source) {
            return (id, false);
        }
        let id = next_id;
        next_id = next_id.next();
        ids.push((source, id));
        (id, true)
    };
    let scope_type = |name: &str| {
        if name.starts_with("g_") {
            ScopeType::Begin
        } else {
            ScopeType::Module
        }
    };
    vcd.add_module("tb_specfx")?;
    let mut open: Vec<String> = Vec::new();
    // The identifier and width of each distinct source, in first-declaration order.
    let mut changes: Vec<(IdCode, u32, Source)> = Vec::new();
    for s in &signals {
        let common = open
            .iter()
            .zip(&s.scope)
            .take_while(|(a, b)| a == b)
            .count();
        while open.len() > common {
            vcd.upscope()?;
            open.pop();
        }
        for name in &s.scope[common..] {
            vcd.scope_def(scope_type(name), name)?;
            open.push(name.clone());
        }
        let (id, new) = id_of(s.source);
        let var_type = match s.source {
            Source::Cycle => VarType::Integer,
            Source::Port(Carries::Clock | Carries::Reset) if s.scope.is_empty() => VarType::Reg,
            _ => VarType::Wire,
        };
        let index = (s.width > 1).then(|| ReferenceIndex::Range(s.width as i32 - 1, 0));
        vcd.var_def(var_type, s.width, id, &s.name, index)?;
        if new {
            changes.push((id, s.width, s.source));
        }
    }
    for _ in &open {
        vcd.upscope()?;
    }
    vcd.upscope()?;
    vcd.enddefinitions()?;

    let write = |vcd: &mut vcd::Writer<_>, id: IdCode, value: Vec<Value>| {
        if value.len() == 1 {
            vcd.change_scalar(id, value[0])
        } else {
            vcd.change_vector(id, value)
        }
    };
    // Reset: everything unknown but the clock, reset and the cycle counter.
    vcd.timestamp(0)?;
    vcd.change_scalar(clk, Value::V0)?;
    let mut last: Vec<Vec<Value>> = Vec::with_capacity(changes.len());
    for &(id, width, source) in &changes {
        let v = match source {
            Source::Port(Carries::Reset) => vec![Value::V1],
            Source::Cycle => bits(&Word::new(0, 32)),
            _ => vec![Value::X; width as usize],
        };
        write(&mut vcd, id, v.clone())?;
        last.push(v);
    }
    for edge in 0..RESET_EDGES - 1 {
        vcd.timestamp(PERIOD / 2 + edge * PERIOD)?;
        vcd.change_scalar(clk, Value::V1)?;
        vcd.timestamp((edge + 1) * PERIOD)?;
        vcd.change_scalar(clk, Value::V0)?;
    }
    for t in trace {
        let start = cycle_start(t.cycle);
        vcd.timestamp(start)?;
        vcd.change_scalar(clk, Value::V1)?;
        for (&(id, width, source), last) in changes.iter().zip(last.iter_mut()) {
            let v = value(dp, t, source, width)
                .map_or_else(|| vec![Value::X; width as usize], |w| bits(&w));
            if v != *last {
                write(&mut vcd, id, v.clone())?;
                *last = v;
            }
        }
        vcd.timestamp(start + PERIOD / 2)?;
        vcd.change_scalar(clk, Value::V0)?;
    }
    // The edge that ends the last cycle, where a comparison samples it.
    let end = trace.last().map_or(0, |t| t.cycle + 1);
    vcd.timestamp(cycle_start(end))?;
    vcd.change_scalar(clk, Value::V1)?;
    Ok(())
}
