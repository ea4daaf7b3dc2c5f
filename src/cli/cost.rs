//! `specfx cost`: synthesis cost from yosys on the reference Verilog, beside the analytic model.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use super::hdl_ref::{hdl_ref, hdl_ref_dir};
use super::output::{print_json, print_with};
use super::Outcome;
use specfx::cycle::Arch;
use specfx::hdl::cost::Target;
use specfx::report::cost::write_cost;
use specfx::tools;

/// Arguments of `specfx cost`.
#[derive(Debug, Args)]
pub struct CostArgs {
    /// A TOML configuration file, a vector directory, or a built-in name: baseline.
    #[arg(long, default_value = "baseline")]
    config: String,
    /// Microarchitecture: pipelined or folded [default: the configuration's `arch` key, else
    /// pipelined].
    #[arg(long, value_parser = super::named_values(&Arch::ALL, Arch::name, super::no_help))]
    arch: Option<Arch>,
    /// Synthesis target: generic (gates and a CMOS transistor estimate), ice40 or xilinx.
    #[arg(long, default_value = "ice40", value_parser = super::named_values(&Target::ALL, Target::name, super::no_help))]
    target: Target,
    /// The reference Verilog directory (default: $SPECFX_HDL_REF, else the hdl_ref/ of the
    /// source tree this binary was built from).
    #[arg(long)]
    hdl_ref: Option<PathBuf>,
    /// Only the analytic model: do not run yosys.
    #[arg(long)]
    analytic_only: bool,
    /// Also place and route on an iCE40 device with nextpnr (target ice40): Fmax, critical
    /// path, latency and throughput at Fmax (`specfx timing` for the details).
    #[arg(long, conflicts_with = "analytic_only")]
    timing: bool,
    /// The iCE40 device whose resources the figures are checked against (target ice40): up5k
    /// or hx8k [default: up5k].
    #[arg(long)]
    device: Option<specfx::hdl::pnr::Device>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// Runs `specfx cost`.
pub fn run(args: &CostArgs) -> Result<Outcome> {
    // Everything that can be refused is refused before yosys spends seconds on synthesis:
    // the options that go together, the configuration, the reference Verilog and the tools.
    if args.target != Target::Ice40 {
        if args.timing {
            bail!(
                "--timing: place and route is available for --target ice40 only (nextpnr-ice40), got --target {}",
                args.target.name()
            );
        }
        if let Some(d) = args.device {
            bail!(
                "--device {d}: the device check is for --target ice40 only, got --target {}",
                args.target.name()
            );
        }
    }
    let device = args.device.unwrap_or(specfx::hdl::pnr::Device::Up5k);
    let dp = specfx::input::load_datapath(&args.config, None)?;
    let arch = dp.config().resolve_arch(args.arch);
    let dir = if args.analytic_only {
        hdl_ref_dir(args.hdl_ref.as_deref())
    } else {
        let dir = hdl_ref(args.hdl_ref.as_deref())?;
        tools::yosys::check()?;
        if args.timing {
            tools::nextpnr::check()?;
        }
        dir
    };
    // yosys takes seconds to minutes per run: a line per step (and a bar on a terminal).
    let n_steps = if args.analytic_only {
        0
    } else {
        tools::yosys::COST_REPORT_STEPS + u64::from(args.timing)
    };
    let mut steps = (n_steps > 0).then(|| super::progress::Steps::new("specfx cost", n_steps));
    let mut r = tools::yosys::cost_report_steps(
        &dp,
        arch,
        args.target,
        &dir,
        args.analytic_only,
        &mut |msg| {
            if let Some(s) = steps.as_mut() {
                s.start(msg);
            }
        },
    )?;
    if args.target == Target::Ice40 {
        let (dsps, luts, ffs) = match &r.yosys {
            Some(y) => (y.dsps, y.luts, y.ffs),
            None => (r.analytic.dsps, r.analytic.luts, r.analytic.ffs),
        };
        r.device = Some(device);
        r.over_limit = specfx::hdl::pnr::device_check(dsps, luts, ffs, device);
    }
    if args.timing {
        if let Some(s) = steps.as_mut() {
            s.start(&format!(
                "placing and routing {} ({arch}) on the {} with yosys and nextpnr",
                dp.config().name,
                device.full_name()
            ));
        }
        r.timing = Some(tools::nextpnr::place_and_route(&dp, arch, device, &dir)?);
    }
    if let Some(s) = steps {
        s.finish();
    }
    if args.json {
        print_json(&r)?;
    } else {
        print_with(|w| write_cost(w, &r, super::terminal::table_width()))?;
    }
    Ok(Outcome::Ok)
}
