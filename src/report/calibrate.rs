//! `specfx calibrate`'s text: per target, the refit's error against yosys and its
//! coefficients beside the committed ones.

use std::io::Write;

use crate::hdl::calibrate::TargetFit;
use crate::hdl::cost::Features;
use crate::report::table::{Align, TextTable};

/// The fits as text: per target the fit error and the coefficient table, fitted into `width`
/// characters (`None`: as wide as its content).
pub fn write_fits(
    w: &mut impl Write,
    fits: &[TargetFit],
    width: Option<u16>,
) -> std::io::Result<()> {
    for f in fits {
        let (a, b) = (&f.fitted, &f.committed);
        writeln!(
            w,
            "{} ({} records{}): logic {} within {:.1}% of yosys (median), {:.1}% (90th percentile), {:.1}% (worst); flip-flops {:.1}% (median); DSP count exact on {:.0}%",
            a.target.name(),
            a.error.records,
            if f.failed > 0 {
                format!(
                    "; yosys failed on {} more, tried again by the next run",
                    f.failed
                )
            } else {
                String::new()
            },
            a.target.logic_unit(),
            100.0 * a.error.median_rel,
            100.0 * a.error.p90_rel,
            100.0 * a.error.max_rel,
            100.0 * a.error.ff_median_rel,
            100.0 * a.error.dsp_exact,
        )?;
        let mut table = TextTable::new(&[
            ("coefficient", Align::Left),
            ("fitted", Align::Right),
            ("committed", Align::Right),
        ])
        .indent(2);
        for (i, name) in Features::LOGIC_NAMES.iter().enumerate() {
            table.row([
                name.to_string(),
                format!("{:.6}", a.coefficients.logic[i]),
                format!("{:.6}", b.coefficients.logic[i]),
            ]);
        }
        table.row([
            "ffs_per_register_bit".to_string(),
            format!("{:.6}", a.coefficients.ff_per_register_bit),
            format!("{:.6}", b.coefficients.ff_per_register_bit),
        ]);
        table.write(w, width)?;
    }
    Ok(())
}
