//! The fit's renderings: its files (the fitted configuration and ROM, the document, JSON,
//! the datapath's inputs, the pictures), its terminal summary, and why nothing fits.

use std::io::Write;

use crate::error::Error;
use crate::hdl::rom::rom_verilog;
use crate::pipeline::{Config, Datapath};
use crate::provenance::Provenance;
use crate::report::scene::{heatmap_png, path_png, write_inputs_csv};
use crate::report::table::{Align, TextTable};
use crate::scene::fit::Floor;
use crate::scene::fitting::{FitReport, Fitted, NoFit};
use crate::scene::render::difference_of;

/// The files `fit` writes in its output directory.
pub const FIT_FILES: [&str; 11] = [
    "fitted.toml",
    "fitted_rom.v",
    "fit.md",
    "fit.json",
    "inputs.csv",
    "f64_cos_n.png",
    "generic.png",
    "fitted.png",
    "diff_fitted_vs_cos_n.png",
    "diff_generic_vs_cos_n.png",
    "diff_fitted_vs_generic.png",
];

/// Every file of a fit's directory but its provenance, in [`FIT_FILES`]' order, rendered in
/// memory: `(name, bytes)`. The document ends with the provenance's line.
pub fn fit_files(f: &Fitted, provenance: &Provenance) -> Result<Vec<(String, Vec<u8>)>, Error> {
    let r = &f.report;
    let (fitted_r, generic_r) = (&f.fitted_render, &f.generic_render);
    let header = format!(
        "# specfx fit: the cheapest datapath found that renders {} within '{}' (against f64 cos^n),\n# proved on all {} inputs the scene produces; see fit.md.\n",
        r.scene.escape_debug(),
        r.budget,
        r.inputs
    );
    let mut inputs = Vec::new();
    write_inputs_csv(
        &mut inputs,
        &fitted_r.inputs,
        f.datapath.config().c.format.lsb(),
    )
    .expect("writing into memory cannot fail");
    let json = serde_json::to_vec_pretty(r).map_err(|e| Error::Render {
        message: format!("fit.json: {e}"),
    })?;
    let mut files: Vec<(String, Vec<u8>)> = vec![
        (
            "fitted.toml".into(),
            format!("{header}{}", r.fitted_config).into_bytes(),
        ),
        ("fitted_rom.v".into(), rom_verilog(&f.datapath).into_bytes()),
        (
            "fit.md".into(),
            format!("{}\n{}\n", fit_markdown(r), provenance.line()).into_bytes(),
        ),
        ("fit.json".into(), json),
        ("inputs.csv".into(), inputs),
        ("f64_cos_n.png".into(), path_png(fitted_r, 0)?),
        ("generic.png".into(), path_png(generic_r, 2)?),
        ("fitted.png".into(), path_png(fitted_r, 2)?),
    ];
    let maps = [
        (
            "diff_fitted_vs_cos_n.png",
            &fitted_r.codes[2],
            &fitted_r.codes[0],
            "fitted vs cos^n",
        ),
        (
            "diff_generic_vs_cos_n.png",
            &generic_r.codes[2],
            &fitted_r.codes[0],
            "generic vs cos^n",
        ),
        (
            "diff_fitted_vs_generic.png",
            &fitted_r.codes[2],
            &generic_r.codes[2],
            "fitted vs generic",
        ),
    ];
    for (file, a, b, title) in maps {
        files.push((
            file.into(),
            heatmap_png(fitted_r, &difference_of(a, b), title)?,
        ));
    }
    Ok(files)
}

/// The terminal summary.
pub fn summary(r: &FitReport) -> String {
    let all = r.rows.last().expect("the all row");
    let (g, f) = (&r.generic_cost, &r.fitted_cost);
    let opt = |x: Option<u64>| x.map_or("-".to_string(), |v| v.to_string());
    let cfg: Config = Config::from_toml(&r.fitted_config).expect("written by to_toml");
    format!(
        "fit: budget '{}' against f64 cos^n, proved on all {} inputs ({} pixels)\n  fitted: k = {}, {}, n = {}, c {}, t {}, b {}, squares {}, coef {}, out {}\n  image: max {} LSB (generic {}), {:.2}% differing (generic {:.2}%), FLIP {:.5} (generic {:.5})\n  cost on {} (datapath + constant ROM): analytic {} + {} = {} LUTs (generic {} + {} = {}), yosys {} + {} = {} LUTs (generic {} + {} = {}); DSPs {} (generic {})\n  {} candidates judged\n",
        r.budget,
        r.inputs,
        r.pixels,
        cfg.k,
        variant_depth(&cfg),
        cfg.n,
        cfg.c.format,
        cfg.t.format,
        cfg.b.format,
        cfg.square
            .iter()
            .map(|s| s.format.to_string())
            .collect::<Vec<_>>()
            .join("/"),
        cfg.coef.format,
        cfg.out.format,
        all.fitted.max_lsb,
        all.generic.max_lsb,
        100.0 * all.fitted.differing,
        100.0 * all.generic.differing,
        all.fitted.flip_mean,
        all.generic.flip_mean,
        r.target,
        f.analytic_luts,
        f.rom_analytic_luts,
        f.analytic_total_luts,
        g.analytic_luts,
        g.rom_analytic_luts,
        g.analytic_total_luts,
        opt(f.yosys_luts),
        opt(f.rom_yosys_luts),
        opt(f.yosys_total_luts),
        opt(g.yosys_luts),
        opt(g.rom_yosys_luts),
        opt(g.yosys_total_luts),
        opt(f.yosys_dsps).replace('-', &f.analytic_dsps.to_string()),
        opt(g.yosys_dsps).replace('-', &g.analytic_dsps.to_string()),
        r.n_evaluations
    )
}

/// A configuration's variant, with its depths when some exponent bypasses a squaring stage:
/// `minimax`, or `minimax, per-n depth (m = 16 for n = 16, m = 64 for n = 64..=1024)`.
fn variant_depth(cfg: &Config) -> String {
    match Datapath::new(cfg.clone()) {
        Ok(dp) if cfg.has_bypass() => format!(
            "{}, per-n depth ({})",
            cfg.variant.name(),
            crate::report::optimize::depth_text(&dp)
        ),
        _ => cfg.variant.name().to_string(),
    }
}

/// A floor's variant cell: `minimax`, or `minimax, per-n depth`.
fn variant_cell(f: &Floor) -> String {
    format!(
        "{}{}",
        f.variant.name(),
        if f.per_n { ", per-n depth" } else { "" }
    )
}

/// The floors table (Markdown).
fn floors_markdown(floors: &[Floor]) -> String {
    let mut s = "| k | variant | f64 floor: max LSB | mean LSB | differing | FLIP | meets the budget |\n|---:|---|---:|---:|---:|---:|---|\n".to_string();
    for f in floors {
        match (f.figures.as_ref().map(|e| &e.all), &f.reason) {
            (Some(e), _) => s.push_str(&format!(
                "| {} | {} | {} | {:.4} | {:.2}% | {:.5} | {} |\n",
                f.k,
                variant_cell(f),
                e.max_lsb,
                e.mean_lsb,
                100.0 * e.differing,
                e.flip_mean,
                if f.meets { "yes" } else { "no" }
            )),
            (None, reason) => s.push_str(&format!(
                "| {} | {} | - | - | - | - | not valid: {} |\n",
                f.k,
                variant_cell(f),
                reason.as_deref().unwrap_or("").replace('|', "/")
            )),
        }
    }
    s
}

/// The floors as a terminal table (the same columns as the Markdown table of the fit report).
pub fn floors_table(floors: &[Floor]) -> TextTable {
    let mut t = TextTable::new(&[
        ("k", Align::Right),
        ("variant", Align::Left),
        ("f64 floor: max LSB", Align::Right),
        ("mean LSB", Align::Right),
        ("differing", Align::Right),
        ("FLIP", Align::Right),
        ("meets the budget", Align::Left),
    ]);
    for f in floors {
        let (k, variant) = (f.k.to_string(), variant_cell(f));
        match (f.figures.as_ref().map(|e| &e.all), &f.reason) {
            (Some(e), _) => t.row([
                k,
                variant,
                e.max_lsb.to_string(),
                format!("{:.4}", e.mean_lsb),
                format!("{:.2}%", 100.0 * e.differing),
                format!("{:.5}", e.flip_mean),
                if f.meets { "yes" } else { "no" }.to_string(),
            ]),
            (None, reason) => t.row([
                k,
                variant,
                "-".into(),
                "-".into(),
                "-".into(),
                "-".into(),
                format!("not valid: {}", reason.as_deref().unwrap_or("")),
            ]),
        }
    }
    t
}

/// Why nothing fits, as text: the floors (a table fitted into `width`), the closest
/// algorithm and the closest datapath searched.
pub fn write_no_fit(w: &mut impl Write, no: &NoFit, width: Option<u16>) -> std::io::Result<()> {
    writeln!(w, "fit: no datapath meets '{}' on this scene", no.budget)?;
    writeln!(
        w,
        "the f64 floor of each algorithm (its image without quantization, against cos^n):"
    )?;
    floors_table(&no.floors).write(w, width)?;
    match &no.closest_floor {
        Some((f, excess)) if *excess > 1.0 => writeln!(
            w,
            "the closest algorithm is k = {}, {}, whose f64 floor alone is {excess:.2}x the budget: no quantization can do better; loosen the budget to its floor's figures (see the table) or lower the scene's exponents",
            f.k,
            variant_cell(f),
        )?,
        Some((f, excess)) => writeln!(
            w,
            "the closest algorithm is k = {}, {}, whose f64 floor is {excess:.2}x the budget, but none of its datapaths searched (from --start-frac fraction bits down) met it: quantization adds to the floor; raise --start-frac or loosen the budget",
            f.k,
            variant_cell(f),
        )?,
        None => {}
    }
    if let Some((c, e)) = &no.closest {
        writeln!(
            w,
            "closest datapath searched: k = {}, {}: max {} LSB, {:.2}% differing, FLIP {:.5} ({:.2}x the budget)",
            c.config.k,
            variant_depth(&c.config),
            e.max_lsb,
            100.0 * e.differing,
            e.flip_mean,
            c.excess
        )?;
    }
    Ok(())
}

/// The fit's document.
pub fn fit_markdown(r: &FitReport) -> String {
    let (g, f) = (&r.generic_cost, &r.fitted_cost);
    let opt = |x: Option<u64>| x.map_or("-".to_string(), |v| v.to_string());
    let saving = |a: u64, b: u64| {
        if b == 0 {
            "-".to_string()
        } else {
            format!("{:.0}%", 100.0 * (1.0 - a as f64 / b as f64))
        }
    };
    let saving_opt = |a: Option<u64>, b: Option<u64>| match (a, b) {
        (Some(a), Some(b)) => saving(a, b),
        _ => "-".to_string(),
    };
    let mut s = format!(
        "# specfx fit: {}\n\nBudget against the f64 cos^n image: `{}`{}.\n\nProved on every input the scene produces: {} (pixel, light) inputs over {} covered pixels, each evaluated bit-accurately by the fitted datapath and the image re-rendered through the renderer.\n\n",
        crate::report::doc::md_escape(&r.scene),
        r.budget,
        if r.default_budget {
            " (the default: no worse than the generic datapath renders this scene)"
        } else {
            ""
        },
        r.inputs,
        r.pixels
    );
    s.push_str("## Fitted configuration\n\n```toml\n");
    s.push_str(&r.fitted_config);
    s.push_str("```\n\n## Cost\n\n");
    s.push_str(&format!(
        "Target {}; the pipelined datapath plus its per-n constant ROM (`fitted_rom.v`; the generic one is addressed by n).\n\n| | generic ({}) | fitted | saving |\n|---|---:|---:|---:|\n",
        r.target, r.generic_config
    ));
    let rows: [(&str, u64, u64); 5] = [
        ("exponents served", g.rom_entries, f.rom_entries),
        ("ROM bits", g.rom_bits, f.rom_bits),
        ("analytic LUTs, datapath", g.analytic_luts, f.analytic_luts),
        (
            "analytic LUTs, ROM",
            g.rom_analytic_luts,
            f.rom_analytic_luts,
        ),
        (
            "analytic LUTs, total",
            g.analytic_total_luts,
            f.analytic_total_luts,
        ),
    ];
    for (name, a, b) in rows {
        s.push_str(&format!("| {name} | {a} | {b} | {} |\n", saving(b, a)));
    }
    s.push_str(&format!(
        "| analytic DSPs | {} | {} | {} |\n| analytic flip-flops | {} | {} | {} |\n",
        g.analytic_dsps,
        f.analytic_dsps,
        saving(f.analytic_dsps, g.analytic_dsps),
        g.analytic_ffs,
        f.analytic_ffs,
        saving(f.analytic_ffs, g.analytic_ffs)
    ));
    let yrows: [(&str, Option<u64>, Option<u64>); 5] = [
        ("yosys LUTs, datapath", g.yosys_luts, f.yosys_luts),
        ("yosys LUTs, ROM", g.rom_yosys_luts, f.rom_yosys_luts),
        ("yosys LUTs, total", g.yosys_total_luts, f.yosys_total_luts),
        ("yosys DSPs", g.yosys_dsps, f.yosys_dsps),
        ("yosys flip-flops", g.yosys_ffs, f.yosys_ffs),
    ];
    for (name, a, b) in yrows {
        s.push_str(&format!(
            "| {name} | {} | {} | {} |\n",
            opt(a),
            opt(b),
            saving_opt(b, a)
        ));
    }
    s.push_str(&format!(
        "\nThe search minimised the analytic LUTs on the target, datapath plus ROM: {} for the generic datapath, {} fitted (DSPs are not in the objective).\n\n## The image\n\n`f64_cos_n.png`, `generic.png`, `fitted.png`; differences in display LSBs `diff_fitted_vs_cos_n.png`, `diff_generic_vs_cos_n.png`, `diff_fitted_vs_generic.png`.\n\n| material | n | pixels | max LSB generic | max LSB fitted | mean LSB generic | mean LSB fitted | differing generic | differing fitted | FLIP generic | FLIP fitted |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        g.objective, f.objective
    ));
    for row in &r.rows {
        let n = if row.n == 0 {
            "-".to_string()
        } else {
            row.n.to_string()
        };
        s.push_str(&format!(
            "| {} | {n} | {} | {} | {} | {:.4} | {:.4} | {:.2}% | {:.2}% | {:.5} | {:.5} |\n",
            row.material,
            row.fitted.pixels,
            row.generic.max_lsb,
            row.fitted.max_lsb,
            row.generic.mean_lsb,
            row.fitted.mean_lsb,
            100.0 * row.generic.differing,
            100.0 * row.fitted.differing,
            row.generic.flip_mean,
            row.fitted.flip_mean
        ));
    }
    s.push_str("\nErrors are in display LSBs against the f64 cos^n image (the largest channel difference of a pixel); they include the approximation of cos^n by the algorithm, which no number of bits removes.\n\n## The search\n\nThe f64 floor of each algorithm is its image with no quantization; only algorithms whose floor meets the budget are searched.\n\n");
    s.push_str(&floors_markdown(&r.floors));
    s.push_str(&format!(
        "\n{} candidates judged, each on every input of the scene. Why the answer is minimal within the search:\n\n",
        r.n_evaluations
    ));
    for m in &r.minimality {
        s.push_str(&format!("- {m}\n"));
    }
    s
}
