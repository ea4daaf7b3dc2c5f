//! `specfx report`: the main job on built-in defaults.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;

use super::Outcome;
use specfx::analysis::check::CheckReport;
use specfx::analysis::methods::{max_errors, report_methods};
use specfx::analysis::paper::reproduce;
use specfx::output::write_atomic;
use specfx::pipeline::{Config, Datapath};
use specfx::provenance::{INPUTS_FILE, PROVENANCE_FILE};
use specfx::report::csv::{write_coefficients, write_method_errors};
use specfx::report::index::{
    index_html, write_summary, CostRow, FigureRow, FitSummary, Results, StabilitySummary,
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
    /// The error budgets of the trade-off's frontier charts (shape_total, in lsb8): at each,
    /// every algorithm's cheapest datapath found by the optimiser. A shorter ladder is a
    /// quicker report.
    #[arg(long, default_value = "8,4,2,1,0.75,0.5", value_parser = super::tradeoff::parse_ladder)]
    ladder: super::tradeoff::Ladder,
    /// The stability map samples the float paths at every c = j / 2^BITS (as `specfx
    /// stability --c-bits`; the datapaths at every input code whatever BITS is). A coarser map
    /// is a quicker report: at 12 the map takes about a quarter of its default time.
    #[arg(long, value_name = "BITS", default_value_t = 15, value_parser = clap::value_parser!(u32).range(1..=24))]
    stability_c_bits: u32,
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

/// Every run of the report takes these steps (place and route adds unnumbered ones).
const STEPS: u64 = 12;

/// Runs `specfx report`.
pub fn run(args: &ReportArgs) -> Result<Outcome> {
    if args.ladder.0.is_empty() {
        bail!("--ladder: the report charts the frontier; expected at least one budget in lsb8 (e.g. 1)");
    }
    let (out_dir, resumed) = specfx::output::OutDir::begin_resumable(
        &args.out,
        "report",
        args.force,
        &[],
        args.restart,
    )?;
    let mut r = Report::open(args, out_dir.path(), resumed)?;
    let paper = r.paper()?;
    let errs = r.methods()?;
    let (dp, checked) = r.check()?;
    let n_vectors = r.vectors(&dp)?;
    let sims = r.simulate(&dp)?;
    let costs = r.costs(&dp)?;
    let budget = r.budget(&dp)?;
    let figures = r.tradeoff(&args.ladder.0)?;
    let stability = r.stability(args.stability_c_bits)?;
    let scene = specfx::scene::Scene::default_scene();
    let render = r.render(&scene)?;
    let fit = r.fit(&scene)?;
    let furnace = r.furnace()?;
    r.steps.finish();
    r.resume.finish()?;
    // Everything the report computes is built in: its inputs are the command alone (and the
    // version, which fixes the built-in configurations, scene and settings).
    let provenance = specfx::provenance::Provenance::new(
        &specfx::provenance::Inputs::new("report")
            .option("ladder", args.ladder.0.clone())
            .option("stability_c_bits", i64::from(args.stability_c_bits)),
    );
    super::output::write_provenance(r.dir, &provenance)?;
    r.written.push(r.dir.join(INPUTS_FILE));
    r.written.push(r.dir.join(PROVENANCE_FILE));
    let results = Results {
        paper: &paper,
        checked: &checked,
        budget: &budget,
        figures: &figures,
        stability: &stability,
        render: &render,
        fit: &fit,
        furnace: &furnace,
        costs: &costs,
        sims: &sims,
        provenance: &provenance,
    };
    let files: Vec<String> = r.written.iter().map(|p| relative(r.dir, p)).collect();
    let index = index_html(&files, &results);
    write_atomic(&r.dir.join("index.html"), &index)?;
    r.written.push(r.dir.join("index.html"));

    let vectors = args.out.join("vectors_baseline").display().to_string();
    // Written into the staging directory, renamed to --out below.
    let shown: Vec<String> = files
        .iter()
        .chain(std::iter::once(&"index.html".to_string()))
        .map(|f| args.out.join(f).display().to_string())
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

/// `path` relative to `dir`, its components joined by `/`.
fn relative(dir: &Path, path: &Path) -> String {
    path.strip_prefix(dir)
        .unwrap_or(path)
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

/// A run of the report: where it writes, what it wrote so far, its steps and checkpoints.
struct Report<'a> {
    dir: &'a Path,
    written: Vec<PathBuf>,
    steps: super::progress::Steps,
    resume: super::resume::Resume,
    hdl: PathBuf,
    yosys: bool,
    nextpnr: bool,
}

impl<'a> Report<'a> {
    /// Opens the run in the staging directory `dir` (taken over from an interrupted run when
    /// `resumed`); its checkpoints are valid for this build, these tools and this hdl_ref/.
    fn open(args: &ReportArgs, dir: &'a Path, resumed: bool) -> Result<Report<'a>> {
        let yosys_version = specfx::tools::version("yosys", "-V");
        let nextpnr_version = specfx::tools::version("nextpnr-ice40", "--version");
        let hdl = super::hdl_ref::hdl_ref_dir(None);
        let key = super::resume::run_key(&format!(
            "yosys {yosys_version:?}\nnextpnr-ice40 {nextpnr_version:?}\nhdl_ref {}\nladder {:?}\nstability_c_bits {}",
            hdl.display(),
            args.ladder.0,
            args.stability_c_bits
        ));
        let resume = super::resume::Resume::open(dir, key, resumed)?;
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
        Ok(Report {
            dir,
            written: Vec::new(),
            steps: super::progress::Steps::new("specfx report", STEPS),
            resume,
            hdl,
            yosys: yosys_version.is_some(),
            nextpnr: nextpnr_version.is_some(),
        })
    }

    /// Renders `name` into memory and writes it into the report; notes it as written.
    fn emit(
        &mut self,
        name: &str,
        render: impl FnOnce(&mut Vec<u8>) -> std::io::Result<()>,
    ) -> Result<()> {
        self.written.push(emit(self.dir, name, render)?);
        Ok(())
    }

    /// Notes the files `names` of the directory `sub` as written.
    fn wrote_in(&mut self, sub: &str, names: impl IntoIterator<Item = impl AsRef<str>>) {
        let dir = self.dir.join(sub);
        self.written
            .extend(names.into_iter().map(|n| dir.join(n.as_ref())));
    }

    fn paper(&mut self) -> Result<specfx::analysis::paper::PaperReproduction> {
        self.steps.start("reproducing the paper's claims");
        let paper = reproduce();
        self.emit("paper.txt", |b| write_paper_table(b, &paper, None))?;
        self.emit("paper.json", |b| json(b, &paper))?;
        Ok(paper)
    }

    fn methods(&mut self) -> Result<Vec<specfx::analysis::methods::MethodErrors>> {
        self.steps
            .start("measuring every reference method against cos^n, n = 16..=1024");
        let ns: Vec<u32> = (16..=1024).collect();
        let errs = max_errors(&report_methods(), &ns);
        self.emit("methods.csv", |b| write_method_errors(b, &ns, &errs))?;
        let all_n: Vec<u32> = (1..=1024).collect();
        self.emit("coefficients.csv", |b| write_coefficients(b, &all_n, 4))?;
        Ok(errs)
    }

    fn check(&mut self) -> Result<(Datapath, CheckReport)> {
        self.steps
            .start("checking baseline exhaustively: every input code, n = 16..=1024");
        let dp = Datapath::new(Config::baseline())?;
        let checked = specfx::analysis::check::check(&dp)?;
        self.emit("check_baseline.txt", |b| {
            specfx::report::check::write_check_table(b, &checked, None)
        })?;
        self.emit("check_baseline.json", |b| json(b, &checked))?;
        Ok((dp, checked))
    }

    fn vectors(&mut self, dp: &Datapath) -> Result<u64> {
        self.steps
            .start("writing baseline's golden vectors (corner cases and 1000 random)");
        let vectors_dir = self.dir.join("vectors_baseline");
        let selection: specfx::golden::CaseSelection = "corner,random:1000".parse()?;
        let (cases, _) = super::vectors::write_dir(
            dp,
            &vectors_dir,
            &selection,
            specfx::golden::Order::Interleaved,
            1,
            true,
            &[],
        )?;
        self.written.push(vectors_dir);
        Ok(cases.len() as u64)
    }

    fn simulate(&mut self, dp: &Datapath) -> Result<Vec<specfx::cycle::sim::SimStats>> {
        use specfx::cycle::{sim, Arch};
        self.steps
            .start("simulating baseline's cycle-level model (both architectures, 20000 cycles)");
        let mut sims = Vec::new();
        for arch in Arch::ALL {
            let mut stim = sim::Stimulus::new(1, 0.1, 0.1);
            let trace = if arch == Arch::Pipelined { 300 } else { 0 };
            let inputs = sim::random_inputs(dp, 1);
            let r = sim::simulate(
                dp,
                arch,
                inputs,
                &mut stim,
                sim::Stop::Cycles(20_000),
                trace,
            );
            if arch == Arch::Pipelined {
                self.emit("sim_baseline_pipelined.vcd", |b| {
                    specfx::cycle::vcd::write_vcd(b, dp, arch, &r.trace)
                })?;
            }
            sims.push(r.stats);
        }
        self.emit("sim_baseline.json", |b| json(b, &sims))?;
        Ok(sims)
    }

    fn costs(&mut self, dp: &Datapath) -> Result<Vec<CostRow>> {
        use specfx::hdl::pnr::{device_check, Device};
        if !self.yosys {
            self.steps.start_at(
                log::Level::Warn,
                "yosys not found: skipping the synthesis cost (apt-get install yosys)",
            );
            return Ok(Vec::new());
        }
        self.steps
            .start("synthesising baseline with yosys (ice40, both architectures)");
        let (dir, hdl, nextpnr, steps) = (self.dir, &self.hdl, self.nextpnr, &self.steps);
        let costs = self.resume.step("costs", &["cost_baseline.txt"], || {
            let mut reports = Vec::new();
            for arch in specfx::cycle::Arch::ALL {
                let target = specfx::hdl::cost::Target::Ice40;
                let mut c = specfx::tools::yosys::cost_report(dp, arch, target, hdl, false)?;
                c.device = Some(Device::Up5k);
                let (dsps, luts, ffs) = (c.dsps, c.luts, c.ffs);
                c.over_limit = device_check(
                    dsps.unwrap_or(0),
                    luts.unwrap_or(0),
                    ffs.unwrap_or(0),
                    Device::Up5k,
                );
                if nextpnr {
                    steps.part(&format!(
                        "placing and routing baseline ({arch}) on an iCE40 UP5K with nextpnr"
                    ));
                    c.timing = Some(specfx::tools::nextpnr::place_and_route(
                        dp,
                        arch,
                        Device::Up5k,
                        hdl,
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
        self.written.push(self.dir.join("cost_baseline.txt"));
        Ok(costs)
    }

    fn budget(&mut self, dp: &Datapath) -> Result<specfx::analysis::budget::BudgetReport> {
        self.steps
            .start("error budget of baseline (attribution per stage, gappa bounds if installed)");
        let ns: Vec<u32> = dp.constants().iter().map(|c| c.n).collect();
        let spread = specfx::analysis::gappa::spread(&ns);
        let budget =
            super::budget::budget(dp, None, Some(&spread), &self.dir.join("budget_baseline"))?;
        self.wrote_in(
            "budget_baseline",
            ["budget.html", "budget.md", "budget.json"],
        );
        Ok(budget)
    }

    fn tradeoff(&mut self, ladder: &[f64]) -> Result<Vec<FigureRow>> {
        self.steps
            .start("speed against accuracy of every method (the trade-off charts)");
        let tradeoff_dir = self.dir.join("tradeoff");
        let yosys = self.yosys;
        let figures: Vec<FigureRow> = self.resume.step("tradeoff", &["tradeoff"], || {
            let figures = super::tradeoff::tradeoff(
                &tradeoff_dir,
                &specfx::nset::NSet::range(16, 1024)?,
                yosys.then_some(specfx::hdl::cost::Target::Ice40),
                ladder,
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
        let charts =
            specfx::report::tradeoff::CostAxis::CHARTS.map(|(_, stem)| format!("{stem}.png"));
        self.wrote_in(
            "tradeoff",
            [
                "tradeoff.csv",
                "frontier.csv",
                "measured_speed_accuracy.png",
                "error_vs_n.png",
            ]
            .map(String::from)
            .into_iter()
            .chain(charts),
        );
        Ok(figures)
    }

    fn stability(&mut self, c_bits: u32) -> Result<StabilitySummary> {
        self.steps.start(
            "mapping where every method and datapath fails (n = 1..=4096, theta 0..90 degrees)",
        );
        let stability_dir = self.dir.join("stability");
        let stability = self.resume.step("stability", &["stability"], || {
            let report = super::stability::stability(
                &stability_dir,
                &specfx::analysis::stability::default_paths(),
                &specfx::analysis::stability::Grid {
                    c_bits,
                    ..Default::default()
                },
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
        self.wrote_in(
            "stability",
            [
                "stability.html",
                "stability.md",
                "stability.json",
                "regions.csv",
                "special_inputs.csv",
                "overshoot.csv",
                "overview.png",
            ],
        );
        Ok(stability)
    }

    fn render(
        &mut self,
        scene: &specfx::scene::Scene,
    ) -> Result<Vec<specfx::report::scene::MaterialRow>> {
        self.steps
            .start("rendering the built-in scene through baseline (three specular paths, FLIP)");
        let mut scene_cfg = Config::baseline();
        scene_cfg.n = specfx::nset::NSet::from_values(&scene.exponents())?;
        let scene_dp = Datapath::new(scene_cfg)?;
        let rows = super::render::render_scene(
            scene,
            "the built-in scene",
            &scene_dp,
            &self.dir.join("render"),
        )?;
        self.wrote_in("render", specfx::report::scene::RENDER_FILES);
        Ok(rows)
    }

    fn fit(&mut self, scene: &specfx::scene::Scene) -> Result<FitSummary> {
        self.steps.start("fitting a datapath to the built-in scene (default budget: no worse than baseline per material)");
        let fit_dir = self.dir.join("fit");
        let analytic_only = !self.yosys;
        let fit = self.resume.step("fit", &["fit"], || {
            let fit = super::fit::fit_scene(
                scene,
                "the built-in scene",
                &super::fit::FitArgs::defaults(fit_dir.clone(), analytic_only),
            )?
            .context(
                "the default fit budget is met by the generic datapath itself: this is a bug",
            )?;
            Ok(FitSummary {
                target: fit.target,
                inputs: fit.inputs,
                generic_cost: fit.generic_cost,
                fitted_cost: fit.fitted_cost,
            })
        })?;
        self.wrote_in("fit", specfx::report::fit::FIT_FILES);
        Ok(fit)
    }

    fn furnace(&mut self) -> Result<specfx::analysis::furnace::FurnaceReport> {
        use specfx::analysis::furnace::{parse_angles, FurnaceSettings, DEFAULT_ANGLES};
        self.steps.start("white furnace of every normalised form");
        let dp = Datapath::new(Config::baseline())?;
        let settings = FurnaceSettings::new(&dp, None, parse_angles(DEFAULT_ANGLES)?)?;
        let furnace = super::furnace::write_furnace(&dp, &settings, &self.dir.join("furnace"))?;
        let mut files = vec![
            "furnace.md".to_string(),
            "furnace.csv".to_string(),
            "furnace.json".to_string(),
        ];
        for f in &furnace.forms {
            let stem = specfx::report::furnace::chart_stem(f.form);
            files.push(format!("{stem}.png"));
            files.push(format!("{stem}.svg"));
        }
        self.wrote_in("furnace", files);
        Ok(furnace)
    }
}

/// Pretty JSON and a newline.
fn json(b: &mut Vec<u8>, value: &impl serde::Serialize) -> std::io::Result<()> {
    serde_json::to_writer_pretty(&mut *b, value).map_err(std::io::Error::other)?;
    b.push(b'\n');
    Ok(())
}
