//! `specfx timing`: place and route on iCE40 with yosys and nextpnr, for Fmax, the critical
//! path, utilisation, and latency and throughput at that Fmax.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use super::hdl_ref::hdl_ref;
use super::output::{print_json, print_with};
use super::Outcome;
use specfx::cycle::Arch;
use specfx::hdl::pnr::Device;
use specfx::report::cost::write_timing;
use specfx::tools;

/// Arguments of `specfx timing`.
#[derive(Debug, Args)]
pub struct TimingArgs {
    /// A TOML configuration file, a vector directory, or a built-in name: baseline.
    #[arg(long, default_value = "baseline")]
    config: String,
    /// Microarchitecture: pipelined or folded [default: the configuration's `arch` key, else
    /// pipelined].
    #[arg(long, value_parser = super::named_values(&Arch::ALL, Arch::name, super::no_help))]
    arch: Option<Arch>,
    /// Device: up5k (iCE40 UltraPlus UP5K, SG48, 8 DSPs) or hx8k (iCE40 HX8K, CT256, no DSPs).
    #[arg(long, default_value = "up5k", value_parser = super::named_values(&Device::ALL, Device::name, super::no_help))]
    device: Device,
    /// The reference Verilog directory (default: $SPECFX_HDL_REF, else the hdl_ref/ of the
    /// source tree this binary was built from).
    #[arg(long)]
    hdl_ref: Option<PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// Runs `specfx timing`.
pub fn run(args: &TimingArgs) -> Result<Outcome> {
    let dp = specfx::input::load_datapath(&args.config, None)?;
    let arch = dp.config().resolve_arch(args.arch);
    let dir = hdl_ref(args.hdl_ref.as_deref())?;
    tools::yosys::check()?;
    // Synthesis, placement and routing take seconds to minutes: say so (a bar on a terminal).
    let mut steps = super::progress::Steps::new("specfx timing", 1);
    steps.start(&format!(
        "placing and routing {} ({arch}) on the {} with yosys and nextpnr",
        dp.config().name,
        args.device.full_name()
    ));
    let t = tools::nextpnr::place_and_route(&dp, arch, args.device, &dir)?;
    steps.finish();
    if args.json {
        print_json(&t)?;
    } else {
        print_with(|w| write_timing(w, &t, super::terminal::table_width()))?;
    }
    // A design that does not fit the device is a failed check (exit code 1), not an error.
    Ok(if t.fits && t.over_limit.is_empty() {
        Outcome::Ok
    } else {
        Outcome::CheckFailed
    })
}
