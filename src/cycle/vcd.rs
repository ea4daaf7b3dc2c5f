//! VCD traces of a simulation: clock, cycle counter, both handshakes and every register.

use std::io::{self, Write};

use vcd::{IdCode, TimescaleUnit, Value};

use crate::cycle::sim::CycleTrace;

/// Clock period in the trace, in nanoseconds (the rising edge that ends cycle t is at
/// `(t + 1) * PERIOD`).
pub const PERIOD_NS: u64 = 10;

fn bits(value: i64, width: u32) -> Vec<Value> {
    (0..width)
        .rev()
        .map(|i| {
            // Bits above 63 repeat the sign.
            let bit = (value >> i.min(63)) & 1 == 1;
            if bit {
                Value::V1
            } else {
                Value::V0
            }
        })
        .collect()
}

fn unknown(width: u32) -> Vec<Value> {
    vec![Value::X; width as usize]
}

/// Writes a trace as VCD (GTKWave opens it). Register values are in two's complement of
/// their width; a register without valid data is `x`.
pub fn write_vcd(
    w: &mut impl Write,
    trace: &[CycleTrace],
    c_width: u32,
    out_width: u32,
) -> io::Result<()> {
    let mut vcd = vcd::Writer::new(w);
    vcd.timescale(1, TimescaleUnit::NS)?;
    vcd.add_module("specfx")?;
    let clk = vcd.add_wire(1, "clk")?;
    let cycle = vcd.add_wire(32, "cycle")?;
    let in_valid = vcd.add_wire(1, "in_valid")?;
    let in_ready = vcd.add_wire(1, "in_ready")?;
    let in_c = vcd.add_wire(c_width, "in_c")?;
    let out_valid = vcd.add_wire(1, "out_valid")?;
    let out_ready = vcd.add_wire(1, "out_ready")?;
    let out_data = vcd.add_wire(out_width, "out_data")?;
    let regs: Vec<(IdCode, u32)> = match trace.first() {
        Some(t) => {
            vcd.add_module("registers")?;
            let ids = t
                .registers
                .iter()
                .map(|r| Ok((vcd.add_wire(r.width, &r.name)?, r.width)))
                .collect::<io::Result<Vec<_>>>()?;
            vcd.upscope()?;
            ids
        }
        None => Vec::new(),
    };
    vcd.upscope()?;
    vcd.enddefinitions()?;
    let scalar = |b: bool| if b { Value::V1 } else { Value::V0 };
    for t in trace {
        // Values of cycle t settle just after the edge that starts it.
        vcd.timestamp(t.cycle * PERIOD_NS)?;
        vcd.change_scalar(clk, Value::V1)?;
        vcd.change_vector(cycle, bits(t.cycle as i64, 32))?;
        vcd.change_scalar(in_valid, scalar(t.in_valid))?;
        vcd.change_scalar(in_ready, scalar(t.in_ready))?;
        vcd.change_vector(
            in_c,
            t.in_c
                .map_or_else(|| unknown(c_width), |c| bits(c, c_width)),
        )?;
        vcd.change_scalar(out_valid, scalar(t.out_valid))?;
        vcd.change_scalar(out_ready, scalar(t.out_ready))?;
        vcd.change_vector(
            out_data,
            t.out_data
                .map_or_else(|| unknown(out_width), |o| bits(o, out_width)),
        )?;
        for (&(id, width), r) in regs.iter().zip(&t.registers) {
            vcd.change_vector(
                id,
                r.value.map_or_else(|| unknown(width), |v| bits(v, width)),
            )?;
        }
        vcd.timestamp(t.cycle * PERIOD_NS + PERIOD_NS / 2)?;
        vcd.change_scalar(clk, Value::V0)?;
    }
    if let Some(last) = trace.last() {
        vcd.timestamp((last.cycle + 1) * PERIOD_NS)?;
    }
    Ok(())
}
