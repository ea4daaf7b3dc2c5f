//! Renders the paper reproduction as a readable text table.

use std::io::{self, Write};

use crate::analysis::paper::PaperReproduction;

fn yes_no(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "NO"
    }
}

/// Writes the claim-by-claim table of a [`PaperReproduction`].
pub fn write_paper_table(w: &mut impl Write, r: &PaperReproduction) -> io::Result<()> {
    let d = &r.delta;
    writeln!(
        w,
        "Delta(theta, n) = cos^n(theta) - cs16(theta, n), n = {}..{}, theta in [0, 1.5], cutoff 6/sqrt(n)",
        r.n_min, r.n_max
    )?;
    writeln!(
        w,
        "  {:<5} {:>11} {:>9} {:>11}  where",
        "", "computed", "printed", "reproduced"
    )?;
    for (name, value, claim, ok, at, clamp) in [
        (
            "max",
            d.max,
            d.claim_max,
            d.reproduced_max,
            d.argmax,
            d.clamp_max,
        ),
        (
            "min",
            d.min,
            d.claim_min,
            d.reproduced_min,
            d.argmin,
            d.clamp_min,
        ),
    ] {
        writeln!(
            w,
            "  {name:<5} {value:>11.3e} {claim:>9.1e} {:>11}  n = {}, theta = {:.4} (exact cutoff: {clamp:.3e})",
            yes_no(ok),
            at.n,
            at.theta
        )?;
    }
    if !d.reproduced_min {
        writeln!(
            w,
            "  note: for n >= 16, cs16 <= cos^n wherever the base is >= 0 (16 ln(1 - n x/16) <= n ln(1 - x)),\n        and the paper cutoff's negative bases give < 1e-14, so Delta >= 0 up to rounding."
        )?;
    }
    writeln!(w)?;
    writeln!(
        w,
        "res(n) = |2 pi coef(n) Int(n) - 1|, max over n = {}..{} (m = 16)",
        r.n_min, r.n_max
    )?;
    writeln!(
        w,
        "  {:<24} {:>8} {:>10} {:>13} {:>5} {:>16} {:>10} {:>10} {:>11}",
        "form",
        "printed",
        "paper coef",
        "reading",
        "ok",
        "refit (a n+b)",
        "refit res",
        "exact res",
        "classic res"
    )?;
    for f in &r.forms {
        writeln!(
            w,
            "  {:<24} {:>8.1e} {:>10.3e} {:>13} {:>5} {:>7.4} n{:>+7.3} {:>10.3e} {:>10.1e} {:>11.3e}",
            f.form,
            f.claim_res_max,
            f.paper_res_max,
            f.reading,
            yes_no(f.reproduced),
            f.refit.a,
            f.refit.b,
            f.refit_res_max,
            f.exact_res_max,
            f.classic_res_max
        )?;
    }
    writeln!(w)?;
    writeln!(
        w,
        "  readings: theta_cr integrates theta up to 6/sqrt(n) as the text says; lobe_support up to where"
    )?;
    writeln!(
        w,
        "  the lobe ends (12/sqrt(n) for the half-angle forms). Both, for the half-angle forms:"
    )?;
    for f in r
        .forms
        .iter()
        .filter(|f| f.readings[0].paper_res_max != f.readings[1].paper_res_max)
    {
        for rd in &f.readings {
            writeln!(
                w,
                "    {:<22} {:<13} paper res {:.3e} (n = {}, {}), refit ({:.4} n {:+.3}) res {:.3e}",
                f.form,
                rd.reading,
                rd.paper_res_max,
                rd.paper_res_argmax_n,
                if rd.reproduced { "reproduces" } else { "does not reproduce" },
                rd.refit.a,
                rd.refit.b,
                rd.refit_res_max
            )?;
        }
    }
    let n_ok = r.forms.iter().filter(|f| f.reproduced).count()
        + usize::from(d.reproduced_max)
        + usize::from(d.reproduced_min);
    writeln!(w)?;
    writeln!(
        w,
        "{} of {} printed claims reproduce to 2 significant digits",
        n_ok,
        r.forms.len() + 2
    )
}
