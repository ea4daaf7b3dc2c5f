//! The optimiser's text: why nothing meets a budget (every algorithm's floor, the closest
//! algorithm and configuration searched).

use std::io::Write;

use crate::analysis::optimize::{Closest, OptimizeAll};
use crate::report::table::{Align, TextTable};

/// Why nothing meets the budget: every algorithm's f64 floor (a table fitted into `width`),
/// the closest algorithm and what would meet the budget, and the closest configuration
/// searched with its figures and cost ceilings.
pub fn write_no_answer(
    w: &mut impl Write,
    r: &OptimizeAll,
    closest: Option<&Closest>,
    width: Option<u16>,
) -> std::io::Result<()> {
    writeln!(w, "no configuration in the space meets the budget")?;
    writeln!(
        w,
        "the f64 floor of each algorithm (its own error against cos^n before any quantization):"
    )?;
    let normalised = r.budget.bounds.iter().any(|b| b.metric.is_normalised());
    let mut columns = vec![
        ("k", Align::Right),
        ("variant", Align::Left),
        ("shape_total floor", Align::Right),
        ("lsb8", Align::Right),
    ];
    if normalised {
        columns.extend([
            ("out_rel floor", Align::Right),
            ("effective bits", Align::Right),
        ]);
    }
    columns.push(("", Align::Left));
    let mut table = TextTable::new(&columns).indent(2);
    for f in &r.floors {
        let a = f.algorithm;
        let mut row = vec![a.k.to_string(), a.variant.name().to_string()];
        match (f.shape_total, &f.reason) {
            (Some(x), _) => {
                row.push(format!("{x:.3e}"));
                row.push(format!("{:.2}", x / crate::analysis::LSB8));
                if normalised {
                    match f.norm_rel {
                        Some(r) => {
                            row.push(format!("{r:.3e}"));
                            row.push(format!("{:.1}", crate::analysis::check::effective_bits(r)));
                        }
                        None => row.extend(["-".to_string(), "-".to_string()]),
                    }
                }
                row.push(if f.reachable { "" } else { "beyond the budget" }.to_string());
            }
            (None, reason) => {
                row.extend(["-".to_string(), "-".to_string()]);
                if normalised {
                    row.extend(["-".to_string(), "-".to_string()]);
                }
                row.push(format!("not valid: {}", reason.as_deref().unwrap_or("")));
            }
        }
        table.row(row);
    }
    table.write(w, width)?;
    if let Some(f) = r
        .floors
        .iter()
        .filter(|f| f.shape_total.is_some())
        .min_by(|a, b| a.shape_total.unwrap().total_cmp(&b.shape_total.unwrap()))
    {
        writeln!(
            w,
            "closest algorithm: k = {} {}, whose f64 floor is {:.3e} ({:.2} lsb8); what would meet the budget: a shape_total limit above that floor (quantization adds to it), or fewer exponents (--n: the floors fall when every n is at least m = 2^k)",
            f.algorithm.k,
            f.algorithm.variant.name(),
            f.shape_total.unwrap(),
            f.shape_total.unwrap() * 256.0
        )?;
    }
    if let Some(c) = closest {
        writeln!(
            w,
            "closest: k = {}, {}: shape_total {:.3e}, shape_quant {:.3e}, out {:.2} ulp, {:.2}% correct ({:.2}x the budget)",
            c.candidate.config.k,
            c.candidate.config.variant.name(),
            c.shape_total,
            c.shape_quant,
            c.out_ulp,
            100.0 * c.correctly_rounded,
            c.candidate.excess
        )?;
        for (b, value) in &c.costs {
            let kind = if b.metric.is_yosys() { "" } else { "analytic " };
            writeln!(w, "  its {kind}{}: {value} (limit {})", b.metric, b.limit)?;
        }
    }
    Ok(())
}
