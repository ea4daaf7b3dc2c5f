//! The index page of `specfx report` (`index.html`): the verdict, then a section per part of
//! the report with its figures and links, from the summaries each step keeps (also in its
//! checkpoint, so a resumed report renders the same page).

use std::io::Write;

use serde::{Deserialize, Serialize};

use crate::provenance::{INPUTS_FILE, PROVENANCE_FILE};

/// What the index page and the summary need of one architecture's synthesis (kept when a
/// report is interrupted, see `cli/resume.rs`).
#[derive(Serialize, Deserialize)]
pub struct CostRow {
    /// The architecture.
    pub arch: crate::cycle::Arch,
    /// yosys LUTs.
    pub luts: u64,
    /// yosys DSP blocks.
    pub dsps: u64,
    /// yosys flip-flops.
    pub ffs: u64,
    /// yosys carry cells.
    pub carries: u64,
    /// The analytic model's LUTs.
    pub analytic_luts: u64,
    /// Latency in cycles.
    pub latency: u64,
    /// Initiation interval in cycles.
    pub initiation_interval: u64,
    /// yosys LUTs of the constant ROM.
    pub rom_luts: u64,
    /// Place and route (nextpnr), when it ran.
    pub timing: Option<TimingRow>,
    /// Resources beyond the UP5K.
    pub over_limit: Vec<String>,
}

/// What the index page needs of a place and route.
#[derive(Serialize, Deserialize)]
pub struct TimingRow {
    /// Fmax in MHz, when the design was placed.
    pub fmax_mhz: Option<f64>,
    /// Whether Fmax is an upper bound (nextpnr does not time through the DSPs).
    pub fmax_is_upper_bound: bool,
    /// Latency in ns at Fmax.
    pub latency_ns: Option<f64>,
    /// Throughput at Fmax.
    pub throughput_samples_per_s: Option<f64>,
}

impl CostRow {
    /// The row of one architecture's cost report.
    pub fn new(c: &crate::hdl::cost::CostReport) -> CostRow {
        CostRow {
            arch: c.arch,
            luts: c.luts.unwrap_or(0),
            dsps: c.dsps.unwrap_or(0),
            ffs: c.ffs.unwrap_or(0),
            carries: c.yosys.as_ref().map_or(0, |y| y.carries),
            analytic_luts: c.analytic.luts,
            latency: c.analytic.latency,
            initiation_interval: c.analytic.initiation_interval,
            rom_luts: c.rom_yosys.as_ref().map_or(0, |r| r.luts),
            timing: c.timing.as_ref().map(|t| TimingRow {
                fmax_mhz: t.fmax_mhz,
                fmax_is_upper_bound: t.fmax_is_upper_bound,
                latency_ns: t.latency_ns,
                throughput_samples_per_s: t.throughput_samples_per_s,
            }),
            over_limit: c.over_limit.clone(),
        }
    }
}

/// What the index page needs of one method of the trade-off.
#[derive(Serialize, Deserialize)]
pub struct FigureRow {
    /// The method's name.
    pub method: String,
    /// Its largest error against cos^n.
    pub max_abs_err: f64,
    /// Its mean error against cos^n.
    pub mean_abs_err: f64,
}

/// What the index page and the summary need of the stability maps.
#[derive(Serialize, Deserialize)]
pub struct StabilitySummary {
    /// Every path, and whether it stays within the tolerance everywhere.
    pub paths: Vec<(String, bool)>,
    /// The exponents of the grid, as printed.
    pub n: String,
    /// The tolerance, as printed.
    pub tol: String,
}

/// What the index page and the summary need of the fit to the built-in scene.
#[derive(Serialize, Deserialize)]
pub struct FitSummary {
    /// The target of the costs.
    pub target: crate::hdl::cost::Target,
    /// Inputs the scene produces (every one proved).
    pub inputs: u64,
    /// The generic datapath's cost.
    pub generic_cost: crate::scene::fitting::SideCost,
    /// The fitted datapath's cost.
    pub fitted_cost: crate::scene::fitting::SideCost,
}

/// What the index page summarises.
pub struct Results<'a> {
    /// The paper's claims.
    pub paper: &'a crate::analysis::paper::PaperReproduction,
    /// The baseline's exhaustive check.
    pub checked: &'a crate::analysis::check::CheckReport,
    /// The baseline's error budget.
    pub budget: &'a crate::analysis::budget::BudgetReport,
    /// The trade-off's methods.
    pub figures: &'a [FigureRow],
    /// The stability maps.
    pub stability: &'a StabilitySummary,
    /// The built-in scene through baseline, per material.
    pub render: &'a [crate::report::scene::MaterialRow],
    /// The fit to the built-in scene.
    pub fit: &'a FitSummary,
    /// The white furnace.
    pub furnace: &'a crate::analysis::furnace::FurnaceReport,
    /// The synthesis of each architecture (none without yosys).
    pub costs: &'a [CostRow],
    /// The cycle model's runs.
    pub sims: &'a [crate::cycle::sim::SimStats],
    /// The report's provenance.
    pub provenance: &'a crate::provenance::Provenance,
}

/// The index page's bytes ([`write_index`]), with numbers in the page's text that never
/// break at their minus sign (U+2212 instead of -).
pub fn index_html(files: &[String], results: &Results<'_>) -> Vec<u8> {
    let page = crate::report::in_memory(|w| write_index(w, files, results));
    let page = String::from_utf8(page).expect("the page is UTF-8");
    let (head, body) = page.split_at(page.find("<body>").unwrap_or(0));
    format!("{head}{}", crate::report::doc::number_minus(body)).into_bytes()
}

/// A self-contained index page linking (and showing) everything the report wrote: `files`
/// are the report's files by their names relative to its directory (`a/b.png`).
pub fn write_index(
    w: &mut impl Write,
    files: &[String],
    results: &Results<'_>,
) -> std::io::Result<()> {
    let Results {
        paper,
        checked,
        budget,
        figures,
        stability,
        render,
        fit,
        furnace,
        costs,
        sims,
        provenance,
    } = *results;
    writeln!(
        w,
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>specfx report</title>"
    )?;
    writeln!(
        w,
        "<style>body{{font-family:sans-serif;max-width:1000px;margin:2em auto;padding:0 1em}}.table{{overflow-x:auto}}td,th{{padding:2px 8px;text-align:right;white-space:nowrap}}td:first-child,th:first-child{{text-align:left}}img{{max-width:100%;height:auto}}</style></head><body>"
    )?;
    writeln!(w, "<h1>specfx report</h1>")?;
    // The verdict first: the numbers a designer acts on.
    let lsb8 = crate::analysis::LSB8;
    let total = checked.shape_total_max_abs;
    let pipelined = costs
        .iter()
        .find(|c| c.arch == crate::cycle::Arch::Pipelined);
    writeln!(w, "<p style=\"border:1px solid #888;padding:0.6em\"><b>Verdict.</b> The baseline datapath (plain cs16, every input code, n = 16..1024) is {:.2} lsb8 from cos^n at worst (lsb8 = 2^-8 of the lobe's peak, one step of an 8-bit display): it {} a 1 lsb8 budget. Its own quantization adds only {:.3} lsb8; the rest ({:.2} lsb8) is the cs16 approximation, which no bits remove (<code>specfx optimize</code> with its default budget of 1 lsb8 finds a k = 5 minimax datapath instead). Output monotonic: {}. {}On the built-in scene, a datapath fitted to its four exponents renders every material no worse and costs {} analytic {} LUTs with its constant ROM against {}.</p>",
        total / lsb8,
        if total <= lsb8 { "meets" } else { "does not meet" },
        checked.shape_quant_max_abs / lsb8,
        checked.shape_approx_max_abs / lsb8,
        if checked.monotonic { "yes" } else { "NO" },
        pipelined.map_or(String::new(), |c| format!(
            "Synthesis (yosys, iCE40, pipelined): {} LUTs, {} DSPs, {} flip-flops, latency {} cycles, one result per cycle. ",
            c.luts, c.dsps, c.ffs, c.latency
        )),
        fit.fitted_cost.analytic_total_luts,
        fit.target,
        fit.generic_cost.analytic_total_luts
    )?;
    let n_ok = paper.forms.iter().filter(|f| f.reproduced).count()
        + usize::from(paper.delta.reproduced_max)
        + usize::from(paper.delta.reproduced_min);
    writeln!(
        w,
        "<h2>The paper</h2><p>{n_ok} of {} printed claims reproduce to 2 significant digits: <a href=\"paper.txt\">paper.txt</a>, <a href=\"paper.json\">paper.json</a>.</p>",
        paper.forms.len() + 2
    )?;
    writeln!(
        w,
        "<h2>The baseline datapath</h2><p>{} evaluations, every input code and n = 16..1024: lobe error against cos^n {:.3e} (quantization {:.3e}, approximation {:.3e}), output max {}, monotonic: {}. <a href=\"check_baseline.txt\">check_baseline.txt</a>, <a href=\"check_baseline.json\">check_baseline.json</a>.</p>",
        checked.n_evaluations,
        checked.shape_total_max_abs,
        checked.shape_quant_max_abs,
        checked.shape_approx_max_abs,
        out_ulp(checked),
        if checked.monotonic { "yes" } else { "no" }
    )?;
    let a = &budget.attribution;
    let top = a
        .incremental
        .iter()
        .max_by(|x, y| x.max_abs.total_cmp(&y.max_abs))
        .map_or(String::new(), |s| s.source.clone());
    let formal = budget
        .formal
        .iter()
        .map(|f| f.bound_ulp / f.exhaustive_ulp.max(1e-300))
        .fold(0.0, f64::max);
    writeln!(
        w,
        "<h2>Error budget of the baseline</h2><p>Output quantization error {:.3e} ({:.0} output LSBs); the largest part comes from stage <code>{top}</code>. {} <a href=\"budget_baseline/budget.html\">budget_baseline/budget.html</a> (also .md, .json).</p><img src=\"budget_baseline/error_vs_n.png\" alt=\"error per exponent\">",
        a.total.max_abs,
        a.total.max_ulp,
        if budget.formal.is_empty() {
            budget.formal_note.clone().unwrap_or_default()
        } else {
            format!(
                "gappa proves bounds for {} exponents, at most {formal:.2} times the exhaustive maximum.",
                budget.formal.len()
            )
        }
    )?;
    if !costs.is_empty() {
        writeln!(
            w,
            "<h2>Cost</h2><p>The baseline synthesised by yosys for iCE40, beside the calibrated analytic model (details: <a href=\"cost_baseline.txt\">cost_baseline.txt</a>; the per-n constant ROM is counted apart).</p><div class=\"table\"><table><tr><th>architecture</th><th>yosys LUTs</th><th>analytic LUTs</th><th>DSPs</th><th>flip-flops</th><th>ROM LUTs (yosys)</th></tr>"
        )?;
        for c in costs {
            writeln!(
                w,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                c.arch, c.luts, c.analytic_luts, c.dsps, c.ffs, c.rom_luts,
            )?;
        }
        writeln!(
            w,
            "</table></div><div class=\"table\"><table><tr><th>architecture</th><th>latency (cycles)</th><th>initiation interval</th><th>Fmax on UP5K (nextpnr)</th><th>latency (ns)</th><th>throughput (Msamples/s)</th></tr>"
        )?;
        for c in costs {
            let t = c.timing.as_ref();
            writeln!(
                w,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                c.arch,
                c.latency,
                c.initiation_interval,
                t.and_then(|t| t.fmax_mhz.map(|f| format!(
                    "{}{f:.1} MHz",
                    if t.fmax_is_upper_bound { "&le; " } else { "" }
                )))
                .unwrap_or_else(|| "-".into()),
                t.and_then(|t| t.latency_ns)
                    .map_or("-".into(), |l| format!("{l:.0}")),
                t.and_then(|t| t.throughput_samples_per_s)
                    .map_or("-".into(), |x| format!("{:.1}", x / 1e6)),
            )?;
        }
        writeln!(w, "</table></div>")?;
        if costs.iter().any(|c| c.timing.is_some()) {
            writeln!(
                w,
                "<p>Fmax is register to register inside a serial harness, placed and routed by nextpnr on an iCE40 UP5K; it is an upper bound because nextpnr does not time the delay through the SB_MAC16 DSP blocks (<code>specfx timing</code>, <code>hdl_ref/README.md</code>). The analytic figures are the calibrated model's (<code>docs/cost.md</code>).</p>"
            )?;
        }
        for flag in costs.iter().flat_map(|c| &c.over_limit) {
            writeln!(w, "<p><b>Exceeds the UP5K:</b> {flag}</p>")?;
        }
    }
    writeln!(
        w,
        "<h2>The cycle model</h2><p>20,000 cycles of each microarchitecture under seeded bubbles and stalls, every output checked against the functional model (<a href=\"sim_baseline.json\">sim_baseline.json</a>; a VCD of the first 300 cycles: <a href=\"sim_baseline_pipelined.vcd\">sim_baseline_pipelined.vcd</a>).</p><div class=\"table\"><table><tr><th>architecture</th><th>outputs</th><th>results per cycle</th><th>latency (nominal)</th><th>latency seen</th><th>mismatches</th></tr>"
    )?;
    for st in sims {
        writeln!(
            w,
            "<tr><td>{}</td><td>{}</td><td>{:.3}</td><td>{}</td><td>{}..{}</td><td>{}</td></tr>",
            st.arch,
            st.n_outputs,
            st.throughput,
            st.latency_nominal,
            st.latency_min,
            st.latency_max,
            st.mismatches
        )?;
    }
    writeln!(w, "</table></div>")?;
    writeln!(
        w,
        "<h2>Error against hardware cost: the reachable frontier</h2><p>For each algorithm (plain and minimax, k = 1..7, every n squaring k times or to its own best depth), the cheapest pipelined datapath the optimiser finds within each budget of the ladder (<code>shape_total</code> at most 8, 4, 2, 1, 0.75 and 0.5 lsb8 by default; an algorithm stops where its own f64 floor is above the budget), each proved by an exhaustive check, drawn by its error in lsb8 against its calibrated analytic cost on each target; the dashed line is the Pareto front across algorithms, and the iCE40 charts show the UP5K's limit (<a href=\"tradeoff/frontier.csv\">frontier.csv</a>, with each datapath's configuration in <code>frontier.json</code>; the model and its calibration error: <code>docs/cost.md</code>). A pipelined datapath past the UP5K's 8 DSPs is what <code>specfx optimize</code> folds onto one shared multiplier.</p><img src=\"tradeoff/error_vs_luts_ice40.png\" alt=\"error against iCE40 LUTs\"><img src=\"tradeoff/error_vs_dsps_ice40.png\" alt=\"error against iCE40 DSPs\"><img src=\"tradeoff/error_vs_luts_xilinx.png\" alt=\"error against Xilinx LUTs\"><img src=\"tradeoff/error_vs_latency.png\" alt=\"error against latency\">"
    )?;
    writeln!(
        w,
        "<h2>Speed against accuracy</h2><p>Software speed is measured in this run on this machine (one core), so the chart and <a href=\"tradeoff/measured_speed.csv\">measured_speed.csv</a> differ from run to run; every other file of the report is the same on every run.</p><img src=\"tradeoff/measured_speed_accuracy.png\" alt=\"speed against accuracy (measured)\"><img src=\"tradeoff/error_vs_n.png\" alt=\"error against n\">"
    )?;
    writeln!(
        w,
        "<div class=\"table\"><table><tr><th>method</th><th>max |err|</th><th>mean |err|</th></tr>"
    )?;
    for f in figures {
        writeln!(
            w,
            "<tr><td>{}</td><td>{:.3e}</td><td>{:.3e}</td></tr>",
            f.method, f.max_abs_err, f.mean_abs_err
        )?;
    }
    writeln!(w, "</table></div>")?;
    let passing: Vec<&str> = stability
        .paths
        .iter()
        .filter(|(_, passes)| *passes)
        .map(|(path, _)| path.as_str())
        .collect();
    writeln!(
        w,
        "<h2>Where the methods fail</h2><p>{} paths mapped over n = {} and theta in [0, 90] degrees against a tolerance of {}; {} stay within it everywhere ({}). Failure regions, special inputs (NaN, infinities, cosines just outside [0, 1]) and one heat map per path: <a href=\"stability/stability.html\">stability/stability.html</a> (also .md, .json, regions.csv).</p><img src=\"stability/overview.png\" alt=\"where each path passes or fails\">",
        stability.paths.len(),
        stability.n,
        stability.tol,
        passing.len(),
        passing.join(", ")
    )?;
    if let Some(all) = render.iter().find(|r| r.material == "all") {
        writeln!(
            w,
            "<h2>The datapath in an image</h2><p>The built-in scene (cells, a vessel, a bone-like ring; n = 16 to 1024) rendered with the baseline datapath's specular lobe: at most {} display LSBs from f64 cos^n ({:.2}% of covered pixels differ, FLIP mean {:.4}), at most {} from the f64 model of its own algorithm (the quantization alone). Per material: <a href=\"render/render.md\">render/render.md</a>.</p><img src=\"render/datapath.png\" alt=\"the scene through the datapath\"><img src=\"render/diff_vs_cos_n.png\" alt=\"difference from cos^n in display LSBs\">",
            all.total.max_lsb,
            100.0 * all.total.differing,
            all.total.flip_mean,
            all.quant.max_lsb
        )?;
    }
    let (g, f) = (&fit.generic_cost, &fit.fitted_cost);
    let yosys = match (g.yosys_total_luts, f.yosys_total_luts) {
        (Some(a), Some(b)) => format!(", yosys {b} LUTs against {a}"),
        _ => String::new(),
    };
    writeln!(
        w,
        "<h2>No more than the scene needs</h2><p><code>specfx fit</code> on the built-in scene, with the default budget (every material no worse than the generic baseline renders it, against f64 cos^n): the fitted datapath serves only the scene's exponents ({} entries in its constant ROM, against {}) and costs {} analytic {} LUTs with its ROM against {} for the generic n = 16..1024 datapath{}; proved on all {} inputs the scene produces. Configuration <a href=\"fit/fitted.toml\">fit/fitted.toml</a>, report <a href=\"fit/fit.md\">fit/fit.md</a>.</p><img src=\"fit/fitted.png\" alt=\"the scene through the fitted datapath\"><img src=\"fit/diff_fitted_vs_generic.png\" alt=\"fitted against generic, display LSBs\">",
        f.rom_entries,
        g.rom_entries,
        f.analytic_total_luts,
        fit.target,
        g.analytic_total_luts,
        yosys,
        fit.inputs
    )?;
    let flagged: usize = furnace.summary().iter().map(|s| s.n_flagged_values).sum();
    writeln!(
        w,
        "<h2>Energy conservation</h2><p>The white furnace: the reflectance of each of the six normalised forms against incident angle, for f64 cos^n, the f64 lobe with the paper's and with the exact coefficient, and the bit-accurate datapath; {flagged} values above 1 are flagged (see <a href=\"furnace/furnace.md\">furnace/furnace.md</a>: the paper's coefficients overshoot slightly, the microfacet forms gain energy near grazing without a masking term).</p><img src=\"furnace/furnace_phong.png\" alt=\"white furnace, Phong\">"
    )?;
    writeln!(w, "<h2>Every file</h2><ul>")?;
    for r in files {
        writeln!(w, "<li><a href=\"{r}\">{r}</a></li>")?;
    }
    writeln!(w, "</ul>")?;
    writeln!(
        w,
        "<p>specfx {} · <code>specfx {}</code> · inputs sha256 <code>{}</code> (<a href=\"{INPUTS_FILE}\">{INPUTS_FILE}</a>, <a href=\"{PROVENANCE_FILE}\">{PROVENANCE_FILE}</a>; each part's directory holds its own)</p>",
        provenance.specfx_version, provenance.command, provenance.inputs_sha256
    )?;
    writeln!(w, "</body></html>")
}

/// What the report's summary on stdout needs beside [`Results`]: where its files are (as the
/// command names them), the golden vectors written, the methods' errors, the baseline's
/// correctly rounded outputs.
pub struct SummaryParts<'a> {
    /// The output directory, as the command names it.
    pub out: &'a str,
    /// The vector directory, as the command names it.
    pub vectors: &'a str,
    /// Golden vectors written.
    pub n_vectors: u64,
    /// Every method's largest error against cos^n.
    pub errs: &'a [crate::analysis::methods::MethodErrors],
    /// The fraction of the baseline's outputs correctly rounded.
    pub out_correctly_rounded: f64,
    /// Every file written, as the command names it.
    pub files: &'a [String],
}

/// The report's summary on stdout: where its results are, the paper's claims, the baseline's
/// figures, the cost, the stability maps, the fit, the furnace, the methods' errors (a table
/// fitted into `width`), and every file.
pub fn write_summary(
    out: &mut impl Write,
    results: &Results<'_>,
    s: &SummaryParts<'_>,
    width: Option<u16>,
) -> std::io::Result<()> {
    let Results {
        paper,
        checked,
        budget,
        stability,
        fit,
        furnace,
        costs,
        sims,
        ..
    } = *results;
    let n_claims = paper.forms.len() + 2;
    let n_ok = paper.forms.iter().filter(|f| f.reproduced).count()
        + usize::from(paper.delta.reproduced_max)
        + usize::from(paper.delta.reproduced_min);
    writeln!(out, "specfx report: results in {}", s.out)?;
    writeln!(
        out,
        "  paper: {n_ok} of {n_claims} printed claims reproduce (details: paper.txt)"
    )?;
    for f in paper.forms.iter().filter(|f| !f.reproduced) {
        writeln!(
            out,
            "    {}: printed res {:.1e}, computed {:.2e}",
            f.form, f.claim_res_max, f.paper_res_max
        )?;
    }
    if !paper.delta.reproduced_min {
        writeln!(
            out,
            "    Delta min: printed {:.1e}, computed {:.1e} (cs16 <= cos^n for n >= 16)",
            paper.delta.claim_min, paper.delta.min
        )?;
    }
    let worst_exact = paper
        .forms
        .iter()
        .map(|f| f.exact_res_max)
        .fold(0.0, f64::max);
    writeln!(
        out,
        "  exact coefficients: max res {worst_exact:.1e} over every form, n = 16..=1024"
    )?;
    writeln!(
        out,
        "  baseline, {} evaluations: lobe error vs cos^n {:.3e} (quantization {:.3e}, approximation {:.3e}); output max {}, {:.2}% correctly rounded; monotonic: {}",
        checked.n_evaluations,
        checked.shape_total_max_abs,
        checked.shape_quant_max_abs,
        checked.shape_approx_max_abs,
        out_ulp(checked),
        100.0 * s.out_correctly_rounded,
        if checked.monotonic { "yes" } else { "NO" }
    )?;
    writeln!(out, "  golden vectors: {} in {}", s.n_vectors, s.vectors)?;
    writeln!(
        out,
        "  error budget: output quantization error {:.3e} ({:.0} LSB), {} gappa bounds (details: budget_baseline/budget.html)",
        budget.attribution.total.max_abs,
        budget.attribution.total.max_ulp,
        budget.formal.len()
    )?;
    for st in sims {
        writeln!(
            out,
            "  cycle model {}: latency {}..{} cycles (nominal {}), {:.3} results/cycle under 10% bubbles and stalls, {} mismatches",
            st.arch,
            st.latency_min,
            st.latency_max,
            st.latency_nominal,
            st.throughput,
            st.mismatches
        )?;
    }
    for c in costs {
        writeln!(
            out,
            "  yosys ice40 {}: {} LUT4, {} carry, {} DSP, {} FF",
            c.arch, c.luts, c.carries, c.dsps, c.ffs
        )?;
    }
    let passing = stability.paths.iter().filter(|(_, passes)| *passes).count();
    writeln!(
        out,
        "  stability: {passing} of {} paths stay within {} of cos^n over n = {} (details: stability/stability.html)",
        stability.paths.len(),
        stability.tol,
        stability.n
    )?;
    writeln!(
        out,
        "  fit (built-in scene, each material no worse than baseline): {} exponents, {} analytic {} LUTs with the constant ROM against {} generic (details: fit/fit.md)",
        fit.fitted_cost.rom_entries,
        fit.fitted_cost.analytic_total_luts,
        fit.target,
        fit.generic_cost.analytic_total_luts
    )?;
    let flagged: usize = furnace.summary().iter().map(|s| s.n_flagged_values).sum();
    writeln!(
        out,
        "  furnace: 6 forms, {flagged} reflectance values above 1 (details: furnace/furnace.md)"
    )?;
    writeln!(out, "  max |error| against cos^n over n = 16..=1024:")?;
    let mut table = crate::report::table::TextTable::new(&[
        ("method", crate::report::table::Align::Left),
        ("max |error|", crate::report::table::Align::Right),
        ("at n", crate::report::table::Align::Right),
        ("c", crate::report::table::Align::Right),
    ])
    .indent(4);
    for e in s.errs {
        table.row([
            e.method.to_string(),
            format!("{:.3e}", e.max_abs_err),
            e.argmax_n.to_string(),
            format!("{:.6}", e.argmax_c),
        ]);
    }
    table.write(out, width)?;
    writeln!(out, "  files:")?;
    for f in s.files {
        writeln!(out, "    {f}")?;
    }
    Ok(())
}

/// The output's largest error in LSBs with what it means ([`super::check::out_ulp_brief`]).
fn out_ulp(checked: &crate::analysis::check::CheckReport) -> String {
    match checked.stages.iter().find(|s| s.stage == "out") {
        Some(out) => super::check::out_ulp_brief(out, 2),
        None => format!("{:.2} ulp", checked.out_max_ulp),
    }
}
