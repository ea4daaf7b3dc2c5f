//! `specfx report`: the main job on built-in defaults.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use serde::{Deserialize, Serialize};

use super::output::write_atomic;
use super::Outcome;
use specfx::analysis::methods::{max_errors, report_methods};
use specfx::analysis::paper::reproduce;
use specfx::provenance::{INPUTS_FILE, PROVENANCE_FILE};
use specfx::report::csv::{write_coefficients, write_method_errors};
use specfx::report::paper::write_paper_table;
use specfx::report::table::{Align, TextTable};

/// Arguments of `specfx report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Output directory. It is written completely or not at all (into a hidden staging
    /// directory beside it, renamed when done), replacing an earlier report there.
    #[arg(long, default_value = "specfx-out")]
    out: PathBuf,
    /// Replace an existing output directory that is not an earlier report.
    #[arg(long)]
    force: bool,
    /// Start afresh instead of resuming: by default a run interrupted (Ctrl-C, SIGTERM, an
    /// error, even SIGKILL) leaves its finished steps in the staging directory, and the next
    /// run with the same --out reuses those still true for this build and these tools.
    #[arg(long)]
    restart: bool,
}

/// Renders into a buffer and writes it atomically to `dir/name`; returns the path.
fn emit(
    dir: &Path,
    name: &str,
    render: impl FnOnce(&mut Vec<u8>) -> std::io::Result<()>,
) -> Result<PathBuf> {
    let mut buf = Vec::new();
    render(&mut buf).with_context(|| format!("cannot render {name}"))?;
    let path = dir.join(name);
    write_atomic(&path, &buf)?;
    Ok(path)
}

/// What the index page and the summary need of one architecture's synthesis (kept when a
/// report is interrupted, see [`super::resume`]).
#[derive(Serialize, Deserialize)]
struct CostRow {
    arch: specfx::cycle::Arch,
    /// yosys LUTs, DSPs, flip-flops and carry cells.
    luts: u64,
    dsps: u64,
    ffs: u64,
    carries: u64,
    /// The analytic model's LUTs, latency and initiation interval.
    analytic_luts: u64,
    latency: u64,
    initiation_interval: u64,
    /// yosys LUTs of the constant ROM.
    rom_luts: u64,
    /// Place and route (nextpnr), when it ran.
    timing: Option<TimingRow>,
    /// Resources beyond the UP5K.
    over_limit: Vec<String>,
}

/// What the index page needs of a place and route.
#[derive(Serialize, Deserialize)]
struct TimingRow {
    fmax_mhz: Option<f64>,
    fmax_is_upper_bound: bool,
    latency_ns: Option<f64>,
    throughput_samples_per_s: Option<f64>,
}

impl CostRow {
    fn new(c: &specfx::hdl::cost::CostReport) -> CostRow {
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
struct FigureRow {
    method: String,
    max_abs_err: f64,
    mean_abs_err: f64,
}

/// What the index page and the summary need of the stability maps.
#[derive(Serialize, Deserialize)]
struct StabilitySummary {
    /// Every path, and whether it stays within the tolerance everywhere.
    paths: Vec<(String, bool)>,
    /// The exponents of the grid, as printed.
    n: String,
    /// The tolerance, as printed.
    tol: String,
}

/// What the index page and the summary need of the fit to the built-in scene.
#[derive(Serialize, Deserialize)]
struct FitSummary {
    target: specfx::hdl::cost::Target,
    inputs: u64,
    generic_cost: super::fit::SideCost,
    fitted_cost: super::fit::SideCost,
}

/// What the index page summarises.
struct Results<'a> {
    paper: &'a specfx::analysis::paper::PaperReproduction,
    checked: &'a specfx::analysis::check::CheckReport,
    budget: &'a specfx::analysis::budget::BudgetReport,
    figures: &'a [FigureRow],
    stability: &'a StabilitySummary,
    render: &'a [specfx::report::scene::MaterialRow],
    fit: &'a FitSummary,
    furnace: &'a specfx::analysis::furnace::FurnaceReport,
    costs: &'a [CostRow],
    sims: &'a [specfx::cycle::sim::SimStats],
    provenance: &'a specfx::provenance::Provenance,
}

/// A self-contained index page linking (and showing) everything the report wrote.
fn write_index(
    w: &mut Vec<u8>,
    dir: &Path,
    files: &[PathBuf],
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
    let rel = |p: &PathBuf| {
        p.strip_prefix(dir)
            .unwrap_or(p)
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join("/")
    };
    writeln!(w, "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>specfx report</title>")?;
    writeln!(w, "<style>body{{font-family:sans-serif;max-width:1000px;margin:2em auto;padding:0 1em}}.table{{overflow-x:auto}}td,th{{padding:2px 8px;text-align:right;white-space:nowrap}}td:first-child,th:first-child{{text-align:left}}img{{max-width:100%;height:auto}}</style></head><body>")?;
    writeln!(w, "<h1>specfx report</h1>")?;
    // The verdict first: the numbers a designer acts on.
    let lsb8 = specfx::analysis::LSB8;
    let total = checked.shape_total_max_abs;
    let pipelined = costs
        .iter()
        .find(|c| c.arch == specfx::cycle::Arch::Pipelined);
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
    writeln!(w, "<h2>The paper</h2><p>{n_ok} of {} printed claims reproduce to 2 significant digits: <a href=\"paper.txt\">paper.txt</a>, <a href=\"paper.json\">paper.json</a>.</p>", paper.forms.len() + 2)?;
    writeln!(w, "<h2>The baseline datapath</h2><p>{} evaluations, every input code and n = 16..1024: lobe error against cos^n {:.3e} (quantization {:.3e}, approximation {:.3e}), output max {:.2} ulp, monotonic: {}. <a href=\"check_baseline.txt\">check_baseline.txt</a>, <a href=\"check_baseline.json\">check_baseline.json</a>.</p>",
        checked.n_evaluations, checked.shape_total_max_abs, checked.shape_quant_max_abs, checked.shape_approx_max_abs, checked.out_max_ulp, if checked.monotonic { "yes" } else { "no" })?;
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
    writeln!(w, "<h2>Error budget of the baseline</h2><p>Output quantization error {:.3e} ({:.0} output LSBs); the largest part comes from stage <code>{top}</code>. {} <a href=\"budget_baseline/budget.html\">budget_baseline/budget.html</a> (also .md, .json).</p><img src=\"budget_baseline/error_vs_n.png\" alt=\"error per exponent\">",
        a.total.max_abs, a.total.max_ulp,
        if budget.formal.is_empty() { budget.formal_note.clone().unwrap_or_default() } else { format!("gappa proves bounds for {} exponents, at most {formal:.2} times the exhaustive maximum.", budget.formal.len()) })?;
    if !costs.is_empty() {
        writeln!(w, "<h2>Cost</h2><p>The baseline synthesised by yosys for iCE40, beside the calibrated analytic model (details: <a href=\"cost_baseline.txt\">cost_baseline.txt</a>; the per-n constant ROM is counted apart).</p><div class=\"table\"><table><tr><th>architecture</th><th>yosys LUTs</th><th>analytic LUTs</th><th>DSPs</th><th>flip-flops</th><th>ROM LUTs (yosys)</th></tr>")?;
        for c in costs {
            writeln!(
                w,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                c.arch, c.luts, c.analytic_luts, c.dsps, c.ffs, c.rom_luts,
            )?;
        }
        writeln!(w, "</table></div><div class=\"table\"><table><tr><th>architecture</th><th>latency (cycles)</th><th>initiation interval</th><th>Fmax on UP5K (nextpnr)</th><th>latency (ns)</th><th>throughput (Msamples/s)</th></tr>")?;
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
            writeln!(w, "<p>Fmax is register to register inside a serial harness, placed and routed by nextpnr on an iCE40 UP5K; it is an upper bound because nextpnr does not time the delay through the SB_MAC16 DSP blocks (<code>specfx timing</code>, <code>hdl_ref/README.md</code>). The analytic figures are the calibrated model's (<code>docs/cost.md</code>).</p>")?;
        }
        for flag in costs.iter().flat_map(|c| &c.over_limit) {
            writeln!(w, "<p><b>Exceeds the UP5K:</b> {flag}</p>")?;
        }
    }
    writeln!(w, "<h2>The cycle model</h2><p>20,000 cycles of each microarchitecture under seeded bubbles and stalls, every output checked against the functional model (<a href=\"sim_baseline.json\">sim_baseline.json</a>; a VCD of the first 300 cycles: <a href=\"sim_baseline_pipelined.vcd\">sim_baseline_pipelined.vcd</a>).</p><div class=\"table\"><table><tr><th>architecture</th><th>outputs</th><th>results per cycle</th><th>latency (nominal)</th><th>latency seen</th><th>mismatches</th></tr>")?;
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
    writeln!(w, "<h2>Error against hardware cost</h2><p>Each fixed-point datapath of the trade-off (plain k = 4 at 8, 12 and 16 fraction bits; minimax k = 3..6) by its lobe error in lsb8 against the calibrated analytic cost on each target (<a href=\"tradeoff/tradeoff.csv\">tradeoff.csv</a>; the model and its calibration error: <code>docs/cost.md</code>).</p><img src=\"tradeoff/error_vs_luts_ice40.png\" alt=\"error against iCE40 LUTs\"><img src=\"tradeoff/error_vs_dsps_ice40.png\" alt=\"error against iCE40 DSPs\"><img src=\"tradeoff/error_vs_luts_xilinx.png\" alt=\"error against Xilinx LUTs\"><img src=\"tradeoff/error_vs_latency.png\" alt=\"error against latency\">")?;
    writeln!(w, "<h2>Speed against accuracy</h2><p>Software speed is measured in this run on this machine (one core), so the chart and <a href=\"tradeoff/measured_speed.csv\">measured_speed.csv</a> differ from run to run; every other file of the report is the same on every run.</p><img src=\"tradeoff/measured_speed_accuracy.png\" alt=\"speed against accuracy (measured)\"><img src=\"tradeoff/error_vs_n.png\" alt=\"error against n\">")?;
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
    writeln!(w, "<h2>Where the methods fail</h2><p>{} paths mapped over n = {} and theta in [0, 90] degrees against a tolerance of {}; {} stay within it everywhere ({}). Failure regions, special inputs (NaN, infinities, cosines just outside [0, 1]) and one heat map per path: <a href=\"stability/stability.html\">stability/stability.html</a> (also .md, .json, regions.csv).</p><img src=\"stability/overview.png\" alt=\"where each path passes or fails\">",
        stability.paths.len(), stability.n, stability.tol, passing.len(), passing.join(", "))?;
    if let Some(all) = render.iter().find(|r| r.material == "all") {
        writeln!(w, "<h2>The datapath in an image</h2><p>The built-in scene (cells, a vessel, a bone-like ring; n = 16 to 1024) rendered with the baseline datapath's specular lobe: at most {} display LSBs from f64 cos^n ({:.2}% of covered pixels differ, FLIP mean {:.4}), at most {} from the f64 model of its own algorithm (the quantization alone). Per material: <a href=\"render/render.md\">render/render.md</a>.</p><img src=\"render/datapath.png\" alt=\"the scene through the datapath\"><img src=\"render/diff_vs_cos_n.png\" alt=\"difference from cos^n in display LSBs\">",
            all.total.max_lsb, 100.0 * all.total.differing, all.total.flip_mean, all.quant.max_lsb)?;
    }
    let (g, f) = (&fit.generic_cost, &fit.fitted_cost);
    let yosys = match (g.yosys_total_luts, f.yosys_total_luts) {
        (Some(a), Some(b)) => format!(", yosys {b} LUTs against {a}"),
        _ => String::new(),
    };
    writeln!(w, "<h2>No more than the scene needs</h2><p><code>specfx fit</code> on the built-in scene, with the default budget (every material no worse than the generic baseline renders it, against f64 cos^n): the fitted datapath serves only the scene's exponents ({} entries in its constant ROM, against {}) and costs {} analytic {} LUTs with its ROM against {} for the generic n = 16..1024 datapath{}; proved on all {} inputs the scene produces. Configuration <a href=\"fit/fitted.toml\">fit/fitted.toml</a>, report <a href=\"fit/fit.md\">fit/fit.md</a>.</p><img src=\"fit/fitted.png\" alt=\"the scene through the fitted datapath\"><img src=\"fit/diff_fitted_vs_generic.png\" alt=\"fitted against generic, display LSBs\">",
        f.rom_entries, g.rom_entries, f.analytic_total_luts, fit.target, g.analytic_total_luts, yosys, fit.inputs)?;
    let flagged: usize = furnace.summary().iter().map(|s| s.n_flagged_values).sum();
    writeln!(w, "<h2>Energy conservation</h2><p>The white furnace: the reflectance of each of the six normalised forms against incident angle, for f64 cos^n, the f64 lobe with the paper's and with the exact coefficient, and the bit-accurate datapath; {flagged} values above 1 are flagged (see <a href=\"furnace/furnace.md\">furnace/furnace.md</a>: the paper's coefficients overshoot slightly, the microfacet forms gain energy near grazing without a masking term).</p><img src=\"furnace/furnace_phong.png\" alt=\"white furnace, Phong\">")?;
    writeln!(w, "<h2>Every file</h2><ul>")?;
    for f in files {
        let r = rel(f);
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

/// The report's steps: a line each on stderr, a bar over them on a terminal (a line every
/// tenth elsewhere), and with `-v` how long each took.
struct Steps {
    bar: super::progress::Progress,
    current: Option<(String, std::time::Instant)>,
}

impl Steps {
    /// Every run of the report takes these steps (place and route adds unnumbered ones).
    const COUNT: u64 = 12;

    fn new() -> Steps {
        Steps {
            bar: super::progress::Progress::new("report", "steps", Steps::COUNT),
            current: None,
        }
    }

    /// Ends the step under way and starts the next, logged at `level`.
    fn start_at(&mut self, level: log::Level, msg: &str) {
        self.end_current();
        log::log!(level, "specfx report: {msg}");
        self.bar.set_message(msg.to_string());
        self.current = Some((msg.to_string(), std::time::Instant::now()));
    }

    /// Ends the step under way and starts the next.
    fn start(&mut self, msg: &str) {
        self.start_at(log::Level::Info, msg);
    }

    /// A part of the step under way, logged and shown but not counted.
    fn part(&self, msg: &str) {
        log::info!("specfx report: {msg}");
        self.bar.set_message(msg.to_string());
    }

    fn end_current(&mut self) {
        if let Some((msg, start)) = self.current.take() {
            log::debug!(
                "specfx report: {:.3}s for: {msg}",
                start.elapsed().as_secs_f64()
            );
            self.bar.inc(1);
        }
    }

    fn finish(mut self) {
        self.end_current();
        self.bar.finish();
    }
}

/// Runs `specfx report`.
pub fn run(args: &ReportArgs) -> Result<Outcome> {
    let (out_dir, resumed) =
        super::output::OutDir::begin_resumable(&args.out, "report", args.force, &[], args.restart)?;
    let dir = out_dir.path();
    let yosys_version = specfx::tools::version("yosys", "-V");
    let nextpnr_version = specfx::tools::version("nextpnr-ice40", "--version");
    let hdl = super::hdl_ref::hdl_ref_dir(None);
    let key = super::resume::run_key(&format!(
        "yosys {yosys_version:?}\nnextpnr-ice40 {nextpnr_version:?}\nhdl_ref {}",
        hdl.display()
    ));
    let mut resume = super::resume::Resume::open(dir, key, resumed)?;
    if resumed {
        log::info!(
            "specfx report: resuming the interrupted run in {} ({} finished {} kept; --restart starts afresh)",
            args.out.display(),
            resume.n_reusable(),
            if resume.n_reusable() == 1 { "step" } else { "steps" }
        );
    }
    *super::output::RESUME_HINT.lock().expect("hint") = Some(format!(
        "run `specfx report --out {}` again to resume from the finished steps",
        args.out.display()
    ));
    let mut written = Vec::new();
    let mut steps = Steps::new();

    steps.start("reproducing the paper's claims");
    let paper = reproduce();
    written.push(emit(dir, "paper.txt", |b| {
        write_paper_table(b, &paper, None)
    })?);
    written.push(emit(dir, "paper.json", |b| {
        serde_json::to_writer_pretty(&mut *b, &paper).map_err(std::io::Error::other)?;
        b.push(b'\n');
        Ok(())
    })?);

    steps.start("measuring every reference method against cos^n, n = 16..=1024");
    let ns: Vec<u32> = (16..=1024).collect();
    let methods = report_methods();
    let errs = max_errors(&methods, &ns);
    written.push(emit(dir, "methods.csv", |b| {
        write_method_errors(b, &ns, &errs)
    })?);
    let all_n: Vec<u32> = (1..=1024).collect();
    written.push(emit(dir, "coefficients.csv", |b| {
        write_coefficients(b, &all_n, 4)
    })?);

    steps.start("checking baseline exhaustively: every input code, n = 16..=1024");
    let dp = specfx::pipeline::Datapath::new(specfx::pipeline::Config::baseline())?;
    let checked = specfx::analysis::check::check(&dp).map_err(anyhow::Error::msg)?;
    written.push(emit(dir, "check_baseline.txt", |b| {
        specfx::report::check::write_check_table(b, &checked, None)
    })?);
    written.push(emit(dir, "check_baseline.json", |b| {
        serde_json::to_writer_pretty(&mut *b, &checked).map_err(std::io::Error::other)?;
        b.push(b'\n');
        Ok(())
    })?);
    steps.start("writing baseline's golden vectors (corner cases and 1000 random)");
    let vectors_dir = dir.join("vectors_baseline");
    let selection: specfx::golden::CaseSelection = "corner,random:1000".parse()?;
    let (n_vectors, _) = super::vectors::write_dir(
        &dp,
        &vectors_dir,
        &selection,
        specfx::golden::Order::Interleaved,
        1,
        true,
        &[],
    )?;
    written.push(vectors_dir.clone());

    steps.start("simulating baseline's cycle-level model (both architectures, 20000 cycles)");
    let mut sims = Vec::new();
    for arch in specfx::cycle::Arch::ALL {
        let mut stim = specfx::cycle::sim::Stimulus::new(1, 0.1, 0.1);
        let r = specfx::cycle::sim::simulate(
            &dp,
            arch,
            specfx::cycle::sim::random_inputs(&dp, 1),
            &mut stim,
            specfx::cycle::sim::Stop::Cycles(20_000),
            if arch == specfx::cycle::Arch::Pipelined {
                300
            } else {
                0
            },
        );
        if arch == specfx::cycle::Arch::Pipelined {
            written.push(emit(dir, "sim_baseline_pipelined.vcd", |b| {
                specfx::cycle::vcd::write_vcd(b, &dp, arch, &r.trace)
            })?);
        }
        sims.push(r.stats);
    }
    written.push(emit(dir, "sim_baseline.json", |b| {
        serde_json::to_writer_pretty(&mut *b, &sims).map_err(std::io::Error::other)?;
        b.push(b'\n');
        Ok(())
    })?);
    let yosys_present = yosys_version.is_some();
    let mut costs = Vec::new();
    if yosys_present {
        steps.start("synthesising baseline with yosys (ice40, both architectures)");
        costs = resume.step("costs", &["cost_baseline.txt"], || {
            let mut reports = Vec::new();
            for arch in specfx::cycle::Arch::ALL {
                let mut c = specfx::tools::yosys::cost_report(
                    &dp,
                    arch,
                    specfx::hdl::cost::Target::Ice40,
                    &hdl,
                    false,
                )?;
                c.device = Some(specfx::hdl::pnr::Device::Up5k);
                c.over_limit = specfx::hdl::pnr::device_check(
                    c.dsps.unwrap_or(0),
                    c.luts.unwrap_or(0),
                    c.ffs.unwrap_or(0),
                    specfx::hdl::pnr::Device::Up5k,
                );
                if nextpnr_version.is_some() {
                    steps.part(&format!(
                        "placing and routing baseline ({arch}) on an iCE40 UP5K with nextpnr"
                    ));
                    c.timing = Some(specfx::tools::nextpnr::place_and_route(
                        &dp,
                        arch,
                        specfx::hdl::pnr::Device::Up5k,
                        &hdl,
                    )?);
                }
                reports.push(c);
            }
            emit(dir, "cost_baseline.txt", |b| {
                for c in &reports {
                    specfx::report::cost::write_cost(b, c, None)?;
                }
                Ok(())
            })?;
            Ok(reports.iter().map(CostRow::new).collect())
        })?;
        written.push(dir.join("cost_baseline.txt"));
    } else {
        steps.start_at(
            log::Level::Warn,
            "yosys not found: skipping the synthesis cost (apt-get install yosys)",
        );
    }

    steps.start("error budget of baseline (attribution per stage, gappa bounds if installed)");
    let budget_dir = dir.join("budget_baseline");
    let ns: Vec<u32> = dp.constants().iter().map(|c| c.n).collect();
    let budget = super::budget::budget(&dp, None, Some(&super::budget::spread(&ns)), &budget_dir)?;
    written.push(budget_dir.join("budget.html"));
    written.push(budget_dir.join("budget.md"));
    written.push(budget_dir.join("budget.json"));

    steps.start("speed against accuracy of every method (the trade-off charts)");
    let tradeoff_dir = dir.join("tradeoff");
    let figures: Vec<FigureRow> = resume.step("tradeoff", &["tradeoff"], || {
        let figures = super::tradeoff::tradeoff(
            &tradeoff_dir,
            &specfx::nset::NSet::range(16, 1024)?,
            yosys_present.then_some(specfx::hdl::cost::Target::Ice40),
        )?;
        Ok(figures
            .into_iter()
            .map(|f| FigureRow {
                method: f.method,
                max_abs_err: f.max_abs_err,
                mean_abs_err: f.mean_abs_err,
            })
            .collect())
    })?;
    written.push(tradeoff_dir.join("tradeoff.csv"));
    written.push(tradeoff_dir.join("measured_speed_accuracy.png"));
    written.push(tradeoff_dir.join("error_vs_n.png"));
    for (_, stem) in specfx::report::tradeoff::CostAxis::CHARTS {
        written.push(tradeoff_dir.join(format!("{stem}.png")));
    }

    steps
        .start("mapping where every method and datapath fails (n = 1..=4096, theta 0..90 degrees)");
    let stability_dir = dir.join("stability");
    let stability = resume.step("stability", &["stability"], || {
        let report = super::stability::stability(
            &stability_dir,
            &specfx::analysis::stability::default_paths(),
            &specfx::analysis::stability::Grid::default(),
        )?;
        Ok(StabilitySummary {
            paths: report
                .maps
                .iter()
                .map(|m| (m.path.clone(), m.passes()))
                .collect(),
            n: report.grid.n.to_string(),
            tol: report.grid.tol.to_string(),
        })
    })?;
    for f in [
        "stability.html",
        "stability.md",
        "stability.json",
        "regions.csv",
        "special_inputs.csv",
        "overshoot.csv",
        "overview.png",
    ] {
        written.push(stability_dir.join(f));
    }

    steps.start("rendering the built-in scene through baseline (three specular paths, FLIP)");
    let scene = specfx::scene::Scene::default_scene();
    let scene_ns = specfx::nset::NSet::from_values(&scene.exponents())?;
    let mut scene_cfg = specfx::pipeline::Config::baseline();
    scene_cfg.n = scene_ns;
    let scene_dp = specfx::pipeline::Datapath::new(scene_cfg)?;
    let render_dir = dir.join("render");
    let (render_rows, _) =
        super::render::render_scene(&scene, "the built-in scene", &scene_dp, &render_dir)?;
    for f in super::render::RENDER_FILES {
        written.push(render_dir.join(f));
    }

    steps.start("fitting a datapath to the built-in scene (default budget: no worse than baseline per material)");
    let fit_dir = dir.join("fit");
    let fit = resume.step("fit", &["fit"], || {
        let fit = super::fit::fit_scene(
            &scene,
            "the built-in scene",
            &super::fit::FitArgs::defaults(fit_dir.clone(), !yosys_present),
        )?
        .context("the default fit budget is met by the generic datapath itself: this is a bug")?;
        Ok(FitSummary {
            target: fit.target,
            inputs: fit.inputs,
            generic_cost: fit.generic_cost,
            fitted_cost: fit.fitted_cost,
        })
    })?;
    for f in super::fit::FIT_FILES {
        written.push(fit_dir.join(f));
    }

    steps.start("white furnace of every normalised form");
    let furnace_dir = dir.join("furnace");
    let furnace_dp = specfx::pipeline::Datapath::new(specfx::pipeline::Config::baseline())?;
    let settings = specfx::analysis::furnace::FurnaceSettings::new(
        &furnace_dp,
        None,
        specfx::analysis::furnace::parse_angles(specfx::analysis::furnace::DEFAULT_ANGLES)?,
    )?;
    let furnace = super::furnace::write_furnace(&furnace_dp, &settings, &furnace_dir)?;
    written.push(furnace_dir.join("furnace.md"));
    written.push(furnace_dir.join("furnace.csv"));
    written.push(furnace_dir.join("furnace.json"));
    for f in &furnace.forms {
        let stem = specfx::report::furnace::chart_stem(f.form);
        written.push(furnace_dir.join(format!("{stem}.png")));
        written.push(furnace_dir.join(format!("{stem}.svg")));
    }

    steps.finish();
    resume.finish()?;
    // Everything the report computes is built in: its inputs are the command alone (and the
    // version, which fixes the built-in configurations, scene and settings).
    let provenance =
        specfx::provenance::Provenance::new(&specfx::provenance::Inputs::new("report"));
    super::output::write_provenance(dir, &provenance)?;
    written.push(dir.join(INPUTS_FILE));
    written.push(dir.join(PROVENANCE_FILE));
    written.push(emit(dir, "index.html", |b| {
        let results = Results {
            paper: &paper,
            checked: &checked,
            budget: &budget,
            figures: &figures,
            stability: &stability,
            render: &render_rows,
            fit: &fit,
            furnace: &furnace,
            costs: &costs,
            sims: &sims,
            provenance: &provenance,
        };
        write_index(b, dir, &written, &results)?;
        // Numbers in the page's text never break at their minus sign (U+2212 instead of -).
        let page = String::from_utf8(std::mem::take(b)).map_err(std::io::Error::other)?;
        let (head, body) = page.split_at(page.find("<body>").unwrap_or(0));
        b.extend_from_slice(head.as_bytes());
        b.extend_from_slice(specfx::report::doc::number_minus(body).as_bytes());
        Ok(())
    })?);

    let n_claims = paper.forms.len() + 2;
    let n_ok = paper.forms.iter().filter(|f| f.reproduced).count()
        + usize::from(paper.delta.reproduced_max)
        + usize::from(paper.delta.reproduced_min);
    let mut out = super::output::stdout();
    let staged = out_dir.path().to_path_buf();
    out_dir.commit()?;
    writeln!(out, "specfx report: results in {}", args.out.display())?;
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
    let out_stage = &checked.stages[dp.stage_out()];
    writeln!(
        out,
        "  baseline, {} evaluations: lobe error vs cos^n {:.3e} (quantization {:.3e}, approximation {:.3e}); output max {:.2} ulp, {:.2}% correctly rounded; monotonic: {}",
        checked.n_evaluations,
        checked.shape_total_max_abs,
        checked.shape_quant_max_abs,
        checked.shape_approx_max_abs,
        checked.out_max_ulp,
        100.0 * out_stage.correctly_rounded,
        if checked.monotonic { "yes" } else { "NO" }
    )?;
    writeln!(
        out,
        "  golden vectors: {n_vectors} in {}",
        args.out.join("vectors_baseline").display()
    )?;
    writeln!(
        out,
        "  error budget: output quantization error {:.3e} ({:.0} LSB), {} gappa bounds (details: budget_baseline/budget.html)",
        budget.attribution.total.max_abs,
        budget.attribution.total.max_ulp,
        budget.formal.len()
    )?;
    for s in &sims {
        writeln!(
            out,
            "  cycle model {}: latency {}..{} cycles (nominal {}), {:.3} results/cycle under 10% bubbles and stalls, {} mismatches",
            s.arch, s.latency_min, s.latency_max, s.latency_nominal, s.throughput, s.mismatches
        )?;
    }
    for c in &costs {
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
    let mut table = TextTable::new(&[
        ("method", Align::Left),
        ("max |error|", Align::Right),
        ("at n", Align::Right),
        ("c", Align::Right),
    ])
    .indent(4);
    for e in &errs {
        table.row([
            e.method.to_string(),
            format!("{:.3e}", e.max_abs_err),
            e.argmax_n.to_string(),
            format!("{:.6}", e.argmax_c),
        ]);
    }
    table.write(&mut out, super::terminal::table_width())?;
    writeln!(out, "  files:")?;
    for p in &written {
        // Written into the staging directory, now renamed to --out.
        let rel = p.strip_prefix(&staged).unwrap_or(p);
        writeln!(out, "    {}", args.out.join(rel).display())?;
    }
    Ok(Outcome::Ok)
}
