//! `specfx report`: the main job on built-in defaults.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;

use super::Outcome;
use specfx::analysis::methods::{max_errors, report_methods};
use specfx::analysis::paper::reproduce;
use specfx::output::write_atomic;
use specfx::provenance::{INPUTS_FILE, PROVENANCE_FILE};
use specfx::report::csv::{write_coefficients, write_method_errors};
use specfx::report::index::{
    write_index, write_summary, CostRow, FigureRow, FitSummary, Results, StabilitySummary,
    SummaryParts,
};
use specfx::report::paper::write_paper_table;

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
    let (out_dir, resumed) = specfx::output::OutDir::begin_resumable(
        &args.out,
        "report",
        args.force,
        &[],
        args.restart,
    )?;
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
            if resume.n_reusable() == 1 {
                "step"
            } else {
                "steps"
            }
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
    let checked = specfx::analysis::check::check(&dp)?;
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
    let budget = super::budget::budget(
        &dp,
        None,
        Some(&specfx::analysis::gappa::spread(&ns)),
        &budget_dir,
    )?;
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
    let render_rows =
        super::render::render_scene(&scene, "the built-in scene", &scene_dp, &render_dir)?;
    for f in specfx::report::scene::RENDER_FILES {
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
    for f in specfx::report::fit::FIT_FILES {
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
    written.push(emit(dir, "index.html", |b| {
        let files: Vec<String> = written
            .iter()
            .map(|p| {
                p.strip_prefix(dir)
                    .unwrap_or(p)
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect::<Vec<_>>()
                    .join("/")
            })
            .collect();
        write_index(b, &files, &results)?;
        // Numbers in the page's text never break at their minus sign (U+2212 instead of -).
        let page = String::from_utf8(std::mem::take(b)).map_err(std::io::Error::other)?;
        let (head, body) = page.split_at(page.find("<body>").unwrap_or(0));
        b.extend_from_slice(head.as_bytes());
        b.extend_from_slice(specfx::report::doc::number_minus(body).as_bytes());
        Ok(())
    })?);

    let vectors = args.out.join("vectors_baseline").display().to_string();
    let staged = out_dir.path().to_path_buf();
    // Written into the staging directory, renamed to --out below.
    let shown: Vec<String> = written
        .iter()
        .map(|p| {
            args.out
                .join(p.strip_prefix(&staged).unwrap_or(p))
                .display()
                .to_string()
        })
        .collect();
    let out = args.out.display().to_string();
    let parts = SummaryParts {
        out: &out,
        vectors: &vectors,
        n_vectors,
        errs: &errs,
        out_correctly_rounded: checked.stages[dp.stage_out()].correctly_rounded,
        files: &shown,
    };
    out_dir.commit()?;
    super::output::print_with(|w| {
        write_summary(w, &results, &parts, super::terminal::table_width())
    })?;
    Ok(Outcome::Ok)
}
