//! Renders an exhaustive accuracy check as a readable table (comfy-table, through
//! [`TextTable`]).

use std::io::{self, Write};

use crate::analysis::check::CheckReport;
use crate::report::table::{Align, TextTable};

/// Writes the table of a [`CheckReport`]: the per-stage table fitted into `width` characters
/// (`None`: as wide as its content; see [`TextTable::write`]), the rest as lines of text.
pub fn write_check_table(
    w: &mut impl Write,
    r: &CheckReport,
    width: Option<u16>,
) -> io::Result<()> {
    writeln!(
        w,
        "check {}: n = {} ({} exponents) x {} input codes up to 1.0 = {} evaluations",
        r.config, r.n_set, r.n_exponents, r.n_input_codes, r.n_evaluations
    )?;
    if r.n_codes_above_one > 0 {
        writeln!(
            w,
            "  ({} codes above 1.0 per exponent clamp to 1.0 and give its result)",
            r.n_codes_above_one
        )?;
    }
    writeln!(w, "errors against the f64 value of the same algorithm:")?;
    let mut table = TextTable::new(&[
        ("stage", Align::Left),
        ("format", Align::Left),
        ("max |err|", Align::Right),
        ("mean err", Align::Right),
        ("rms err", Align::Right),
        ("max ulp", Align::Right),
        ("correct", Align::Right),
        ("faithful", Align::Right),
        ("worst input", Align::Left),
        ("sat", Align::Right),
        ("wrap", Align::Right),
        ("zero", Align::Right),
    ])
    .indent(2)
    .gap_before(8, 1)
    .note_indent(8);
    for s in &r.stages {
        table.row([
            s.stage.clone(),
            s.format.clone(),
            format!("{:.3e}", s.max_abs_err),
            format!("{:.2e}", s.mean_err),
            format!("{:.3e}", s.rms_err),
            format!("{:.4}", s.max_ulp),
            format!("{:.3}%", 100.0 * s.correctly_rounded),
            format!("{:.3}%", 100.0 * s.faithfully_rounded),
            format!("n={} c_raw={}", s.worst.n, s.worst.c_raw),
            s.saturated.to_string(),
            s.wrapped.to_string(),
            s.zeroed.to_string(),
        ]);
        // The explanation of a figure sits beside it.
        for note in r
            .notes
            .iter()
            .filter(|n| n.starts_with(&format!("{} ", s.stage)))
        {
            table.note(format!("^ {note}"));
        }
        if s.stage == "out" {
            if let Some(line) = effective_bits(s) {
                table.note(format!("^ {line}"));
            }
        }
    }
    table.write(w, width)?;
    writeln!(
        w,
        "normalised lobe (before the coefficient), max |error| (lsb8 = 2^-8 = 3.906e-3, one step of an 8-bit display at the lobe's peak):"
    )?;
    for (name, v, at) in [
        (
            "quantization  (fixed vs f64 lobe)",
            r.shape_quant_max_abs,
            r.shape_quant_worst,
        ),
        (
            "approximation (f64 lobe vs cos^n)",
            r.shape_approx_max_abs,
            r.shape_approx_worst,
        ),
        (
            "total         (fixed vs cos^n)  ",
            r.shape_total_max_abs,
            r.shape_total_worst,
        ),
    ] {
        writeln!(
            w,
            "  {name} {v:.3e} = {:.3} lsb8 at n={} c={:.6}",
            v / crate::analysis::LSB8,
            at.n,
            at.c
        )?;
    }
    let out_lsb = r
        .stages
        .last()
        .and_then(|s| s.format.parse::<crate::fixed::Format>().ok())
        .map_or(1.0, |f| f.lsb());
    writeln!(
        w,
        "normalised output against exact normalised cos^n (the output against coef(n) cos^n, coef the form's exact cos^n coefficient): max |error| {:.4e} = {:.1} output LSBs at n={} c={:.6}",
        r.norm_total_max_abs,
        r.norm_total_max_abs / out_lsb,
        r.norm_total_worst.n,
        r.norm_total_worst.c
    )?;
    writeln!(
        w,
        "  relative to the peak coef(n): {:.3e} ({:.1} effective bits, the budget's effective_bits); the algorithm's own floor in f64 is {:.3e} ({:.1} bits): an energy-conserving lobe of another shape peaks away from cos^n's peak, which no width removes",
        r.norm_total_rel,
        crate::analysis::check::effective_bits(r.norm_total_rel),
        r.norm_approx_rel,
        crate::analysis::check::effective_bits(r.norm_approx_rel)
    )?;
    if r.monotonic {
        writeln!(
            w,
            "monotonic: yes, the output never decreases as c increases"
        )?;
    } else {
        writeln!(
            w,
            "monotonic: NO, {} places where the output decreases as c increases; first:",
            r.n_monotonicity_violations
        )?;
        for v in r.monotonicity_violations.iter().take(10) {
            writeln!(
                w,
                "  n={} c_raw={}: out {} after {}",
                v.n, v.c_raw, v.out_here, v.out_before
            )?;
        }
    }
    writeln!(
        w,
        "cutoff: {} evaluations had their base cut to zero",
        r.n_cut
    )?;
    for note in r.notes.iter().filter(|n| {
        !r.stages
            .iter()
            .any(|s| n.starts_with(&format!("{} ", s.stage)))
    }) {
        writeln!(w, "note: {note}")?;
    }
    Ok(())
}

/// The output's largest error in LSBs (with `decimals` digits) for a summary line, with what it
/// means when it is more than one LSB: `1953.53 ulp (the lobe's error times the coefficient:
/// 1.72e-4 of the largest output, 12.5 bits agree with f64)`; `s` the output stage's
/// statistics.
pub(crate) fn out_ulp_brief(s: &crate::analysis::check::StageStats, decimals: usize) -> String {
    let ulp = format!("{:.*} ulp", decimals, s.max_ulp);
    match many_lsbs(s) {
        Some((_, _, relative)) => format!(
            "{ulp} (the lobe's error times the coefficient: {relative:.2e} of the largest \
             output, {:.1} bits agree with f64)",
            -relative.log2()
        ),
        None => ulp,
    }
}

/// For an output whose largest error is more than one LSB (and whose largest value is
/// positive): its format, its largest value, and its largest error relative to that value.
fn many_lsbs(s: &crate::analysis::check::StageStats) -> Option<(crate::fixed::Format, f64, f64)> {
    let format: crate::fixed::Format = s.format.parse().ok()?;
    let largest = format.to_f64(s.raw_max);
    (s.max_ulp > 1.0 && largest > 0.0).then(|| (format, largest, s.max_abs_err / largest))
}

/// What the output's error in LSBs means: the lobe's error times the coefficient, so many of
/// the output's fraction bits are noise; its effective fraction bits and relative accuracy.
fn effective_bits(s: &crate::analysis::check::StageStats) -> Option<String> {
    let (format, largest, relative) = many_lsbs(s)?;
    let noise_bits = s.max_ulp.log2();
    Some(format!(
        "{:.1} output LSBs: the lobe's error times the coefficient; about {:.1} of its {} fraction bits are noise ({:.1} effective), a relative error of {:.2e} of the largest output {:.4} ({:.1} bits agree with the same algorithm in f64; against cos^n see the normalised output below)",
        s.max_ulp,
        noise_bits,
        format.frac_bits(),
        f64::from(format.frac_bits()) - noise_bits,
        relative,
        largest,
        -relative.log2()
    ))
}

#[cfg(test)]
mod tests {
    use super::out_ulp_brief;
    use crate::analysis::check::{Input, StageStats};

    /// The baseline's output stage as `specfx check` reports it (u8.16, its largest output
    /// 173.1606, its largest error 2.981e-2 = 1953.53 LSBs).
    fn out(max_abs_err: f64, max_ulp: f64) -> StageStats {
        StageStats {
            stage: "out".into(),
            format: "u8.16".into(),
            max_abs_err,
            mean_err: 0.0,
            mean_abs_err: 0.0,
            rms_err: 0.0,
            max_ulp,
            correctly_rounded: 0.9623,
            faithfully_rounded: 0.9658,
            worst: Input {
                n: 959,
                c_raw: 32764,
                c: 32764.0 / 32768.0,
            },
            raw_min: 0,
            raw_max: (173.1606f64 * 65536.0).round() as i64,
            wrapped: 0,
            saturated: 0,
            zeroed: 0,
        }
    }

    #[test]
    fn an_output_error_of_many_lsbs_says_what_it_is() {
        // By hand: 2.981e-2 / 173.1606 = 1.7215e-4, and -log2 of that is 12.504.
        assert_eq!(
            out_ulp_brief(&out(2.981e-2, 1953.5349), 2),
            "1953.53 ulp (the lobe's error times the coefficient: 1.72e-4 of the largest \
             output, 12.5 bits agree with f64)"
        );
        // Within one LSB there is nothing to explain.
        assert_eq!(out_ulp_brief(&out(1.0e-5, 0.6554), 3), "0.655 ulp");
    }
}
