//! The cost and timing reports as text: `specfx cost`'s tables (the analytic model beside
//! yosys, the constant ROM, the device check) and `specfx timing`'s place-and-route figures.

use crate::hdl::cost::CostReport;
use crate::hdl::pnr::{utilisation_rows, Timing};
use crate::report::table::{Align, TextTable};

/// Renders the report as text, its tables fitted into `width` characters (`None`: as wide as
/// their content).
pub fn write_cost(
    w: &mut impl std::io::Write,
    r: &CostReport,
    width: Option<u16>,
) -> std::io::Result<()> {
    let a = &r.analytic;
    writeln!(
        w,
        "cost {}, {}, target {}: latency {} cycles, initiation interval {}",
        r.config, r.arch, r.target, a.latency, a.initiation_interval
    )?;
    let opt = |x: Option<u64>| x.map_or("-".to_string(), |v| v.to_string());
    let rat = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.2}"));
    let mut table = TextTable::new(&[
        ("", Align::Left),
        ("analytic", Align::Right),
        ("yosys", Align::Right),
        ("ratio", Align::Right),
    ])
    .indent(2);
    table.row([
        a.logic_unit.to_string(),
        a.luts.to_string(),
        opt(r.luts),
        rat(r.lut_ratio),
    ]);
    table.row([
        "flip-flops".to_string(),
        a.ffs.to_string(),
        opt(r.ffs),
        rat(r.ff_ratio),
    ]);
    table.row([
        "DSP blocks".to_string(),
        a.dsps.to_string(),
        opt(r.dsps),
        String::new(),
    ]);
    if let Some(y) = &r.yosys {
        table.row([
            "carry cells".to_string(),
            "-".into(),
            y.carries.to_string(),
            String::new(),
        ]);
        table.row([
            "cells".to_string(),
            "-".into(),
            y.cells.to_string(),
            String::new(),
        ]);
        if let Some(t) = y.transistors {
            table.row([
                "transistors (CMOS)".to_string(),
                "-".into(),
                t.to_string(),
                String::new(),
            ]);
        }
    }
    table.write(w, width)?;
    let cal = crate::hdl::calibrate::calibration(r.target);
    writeln!(
        w,
        "  analytic model: calibrated against yosys on {} configurations; {} within {:.0}% (median), {:.0}% (90th percentile)",
        cal.error.records,
        a.logic_unit,
        100.0 * cal.error.median_rel,
        100.0 * cal.error.p90_rel
    )?;
    write!(
        w,
        "  multipliers ({} partial-product bits, {} left to logic):",
        a.features.multiplier_bits, a.features.soft_multiplier_bits
    )?;
    for m in &a.features.multipliers {
        write!(w, " {} {}x{}", m.name, m.a_bits, m.b_bits)?;
    }
    writeln!(w)?;
    let rom = &r.rom;
    writeln!(
        w,
        "  constant ROM (beside the datapath): {} entries x {} bits ({}), addressed by {}: analytic {} LUTs, yosys {}",
        rom.entries,
        rom.fields.iter().map(|f| f.bits).sum::<u32>(),
        rom.fields
            .iter()
            .map(|f| format!("{} {}", f.name, f.bits))
            .collect::<Vec<_>>()
            .join(", "),
        if rom.addressed_by_n { "n" } else { "index" },
        rom.luts,
        r.rom_yosys.as_ref().map_or("-".to_string(), |y| format!(
            "{} LUTs, {} cells",
            y.luts, y.cells
        ))
    )?;
    if let Some(d) = r.device {
        if r.over_limit.is_empty() {
            writeln!(
                w,
                "  fits the {d} ({})",
                if r.luts.is_some() {
                    "yosys figures"
                } else {
                    "analytic figures"
                }
            )?;
        }
        for flag in &r.over_limit {
            writeln!(w, "  EXCEEDS THE DEVICE: {flag}")?;
        }
    }
    if let Some(t) = &r.timing {
        writeln!(w, "timing (nextpnr place and route on the {}):", t.device)?;
        write_timing(w, t, width)?;
    }
    if let Some(v) = &r.yosys_version {
        writeln!(w, "  {v}")?;
    }
    Ok(())
}

/// Renders the timing as text, its table fitted into `width` characters (`None`: as wide as its
/// content).
pub fn write_timing(
    w: &mut impl std::io::Write,
    t: &Timing,
    width: Option<u16>,
) -> std::io::Result<()> {
    writeln!(
        w,
        "timing {}, {}, {} ({}): latency {} cycles, initiation interval {}",
        t.config, t.arch, t.device_name, t.package, t.latency_cycles, t.initiation_interval
    )?;
    match t.fmax_mhz {
        Some(f) => {
            let bound = if t.fmax_is_upper_bound { "<= " } else { "" };
            writeln!(
                w,
                "  Fmax {bound}{f:.2} MHz (register to register inside the harness; nextpnr {:.2} MHz)",
                t.nextpnr_fmax_mhz.unwrap_or(f)
            )?;
        }
        None => writeln!(
            w,
            "  Fmax -: the design does not fit the device (nextpnr could not place it)"
        )?,
    }
    if let Some(u) = &t.untimed_dsp {
        let ns = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.2} ns"));
        writeln!(
            w,
            "  combinational DSPs: nextpnr times paths into them ({}) and out of them ({}), not through them",
            ns(u.into_ns),
            ns(u.out_of_ns)
        )?;
    }
    if t.fmax_is_upper_bound {
        writeln!(
            w,
            "  Fmax is an upper bound: nextpnr does not time the delay through the {} DSP blocks",
            t.synthesis.dsps
        )?;
    }
    if let Some(p) = &t.critical_path {
        writeln!(
            w,
            "  critical path {:.2} ns ({:.2} logic, {:.2} routing), {} logic levels, {} segments",
            p.delay_ns, p.logic_ns, p.routing_ns, p.logic_levels, p.segments
        )?;
        writeln!(w, "    from {}.{}", p.start.cell, p.start.port)?;
        writeln!(w, "    to   {}.{}", p.end.cell, p.end.port)?;
    }
    if let (Some(ns), Some(sps)) = (t.latency_ns, t.throughput_samples_per_s) {
        writeln!(
            w,
            "  latency {} cycles = {ns:.1} ns, throughput {:.3} Msamples/s (Fmax / {})",
            t.latency_cycles,
            sps / 1e6,
            t.initiation_interval
        )?;
    }
    writeln!(
        w,
        "  yosys: {} LUT4s, {} flip-flops ({} of them the harness's), {} DSPs",
        t.synthesis.luts, t.synthesis.ffs, t.harness_ffs, t.synthesis.dsps
    )?;
    let rows = utilisation_rows(&t.utilisation);
    if !rows.is_empty() {
        let mut table = TextTable::new(&[
            ("resource", Align::Left),
            ("used", Align::Right),
            ("available", Align::Right),
            ("%", Align::Right),
        ])
        .indent(2);
        for u in rows {
            table.row([
                u.resource.to_string(),
                u.used.to_string(),
                u.available.to_string(),
                format!("{:.1}%", 100.0 * u.used as f64 / u.available as f64),
            ]);
        }
        table.write(w, width)?;
    }
    for flag in &t.over_limit {
        writeln!(w, "  OVER LIMIT: {flag}")?;
    }
    Ok(())
}
