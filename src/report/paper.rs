//! Renders the paper reproduction as readable text tables (comfy-table, through
//! [`TextTable`]).

use std::io::{self, Write};

use crate::analysis::paper::PaperReproduction;
use crate::report::table::{Align, TextTable};

fn yes_no(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "NO"
    }
}

/// Writes the claim-by-claim tables of a [`PaperReproduction`], fitted into `width` characters
/// (`None`: as wide as their content; see [`TextTable::write`]).
pub fn write_paper_table(
    w: &mut impl Write,
    r: &PaperReproduction,
    width: Option<u16>,
) -> io::Result<()> {
    let d = &r.delta;
    writeln!(
        w,
        "Delta(theta, n) = cos^n(theta) - cs16(theta, n), n = {}..{}, theta in [0, 1.5], cutoff 6/sqrt(n)",
        r.n_min, r.n_max
    )?;
    let mut delta = TextTable::new(&[
        ("", Align::Left),
        ("computed", Align::Right),
        ("printed", Align::Right),
        ("reproduced", Align::Right),
        ("where", Align::Left),
    ])
    .indent(2)
    .gap_before(4, 1);
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
        delta.row([
            name.to_string(),
            format!("{value:.3e}"),
            format!("{claim:.1e}"),
            yes_no(ok).to_string(),
            format!(
                "n = {}, theta = {:.4} (exact cutoff: {clamp:.3e})",
                at.n, at.theta
            ),
        ]);
    }
    delta.write(w, width)?;
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
    let mut res = TextTable::new(&[
        ("form", Align::Left),
        ("printed", Align::Right),
        ("paper coef", Align::Right),
        ("reading", Align::Left),
        ("ok", Align::Right),
        ("refit (a n+b)", Align::Right),
        ("refit res", Align::Right),
        ("exact res", Align::Right),
        ("classic res", Align::Right),
    ])
    .indent(2);
    for f in &r.forms {
        res.row([
            f.form.to_string(),
            format!("{:.1e}", f.claim_res_max),
            format!("{:.3e}", f.paper_res_max),
            f.reading.to_string(),
            yes_no(f.reproduced).to_string(),
            format!("{:.4} n {:+.3}", f.refit.a, f.refit.b),
            format!("{:.3e}", f.refit_res_max),
            format!("{:.1e}", f.exact_res_max),
            format!("{:.3e}", f.classic_res_max),
        ]);
    }
    res.write(w, width)?;
    writeln!(w)?;
    writeln!(
        w,
        "  readings: theta_cr integrates theta up to 6/sqrt(n) as the text says; lobe_support up to where"
    )?;
    writeln!(
        w,
        "  the lobe ends (12/sqrt(n) for the half-angle forms). Both, for the half-angle forms:"
    )?;
    let mut readings = TextTable::new(&[
        ("form", Align::Left),
        ("reading", Align::Left),
        ("paper res", Align::Right),
        ("at n", Align::Right),
        ("reproduces", Align::Right),
        ("refit (a n+b)", Align::Right),
        ("refit res", Align::Right),
    ])
    .indent(4);
    for f in r
        .forms
        .iter()
        .filter(|f| f.readings[0].paper_res_max != f.readings[1].paper_res_max)
    {
        for rd in &f.readings {
            readings.row([
                f.form.to_string(),
                rd.reading.to_string(),
                format!("{:.3e}", rd.paper_res_max),
                rd.paper_res_argmax_n.to_string(),
                yes_no(rd.reproduced).to_string(),
                format!("{:.4} n {:+.3}", rd.refit.a, rd.refit.b),
                format!("{:.3e}", rd.refit_res_max),
            ]);
        }
    }
    readings.write(w, width)?;
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
