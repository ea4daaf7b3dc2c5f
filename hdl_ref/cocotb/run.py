#!/usr/bin/env python3
"""Runs a cocotb testbench of specfx_top under Icarus Verilog or Verilator: the vector replay
test_specfx.py, or the live scoreboard test_live.py.

Usage:
  run.py --vectors DIR [--sim icarus|verilator] [--arch pipelined|folded] [--seed S]
         [--bubble P] [--stall P] [--reset-data] [--specfx PATH] [--hdl-ref DIR]
         [--build-dir DIR] [--keep]
  run.py --live CONFIG [--n SET] [--nvec N] [the same options]

With --live CONFIG (a built-in name, a TOML file or a vector directory, as specfx --config
takes it), no vectors are read: test_live.py draws the directed cases and N random inputs,
computes each expected output with the specfx Python package (`import specfx`, installed in
target/cocotb-venv by ./scripts/test; for Verilator, in target/cocotb18-venv from its wheel in
target/wheels) as the input is accepted, checks every output and its cycle against the cycle
model, and on a failure names the first register of the core that differs from the model.

Two cocotb releases, one per simulator: cocotb 2.0.1 (pinned in requirements.txt, in
target/cocotb-venv) runs Icarus Verilog, but needs Verilator 5.036 or later and Debian has
5.006; cocotb 1.8.1 (pinned in requirements-verilator.txt, in target/cocotb18-venv) runs
Verilator 5.006 and later. The tests use only what both releases have (cocotb_compat.py), and
this script uses the runner of the cocotb it runs with (cocotb 1.x: `cocotb.runner`, 2.x:
`cocotb_tools.runner`): run it with target/cocotb18-venv/bin/python for `--sim verilator`.
Verilator is given `--public-flat-rw` (by cocotb's runner; test_live.py reads the core's
registers) and `--timescale 1ns/1ps`, and no `--timing`: the clock is driven from cocotb and
the RTL has no delays.

For a vector directory written by `specfx vectors --out DIR`, it asks specfx for the Verilog
parameters of specfx_top (`specfx hdl params --vectors DIR --arch A --format json
[--reset-data]`) and for the seeded valid/ready stimulus (`specfx hdl stimulus`), builds
`<hdl-ref>/rtl/*.v` with the simulator (cocotb's Python runner) with those parameters on the
toplevel, runs the test in a build directory (a temporary one, removed afterwards, unless
--build-dir or --keep) and prints one verdict line, e.g.
`cocotb: 1029 vectors passed (icarus, pipelined)`.

Exit code: 0 when every vector passed; 1 when the test ran and found a problem (or checked
nothing); 2 on bad usage or a failing tool (specfx, iverilog, verilator, a missing cocotb, a
cocotb too new for the Verilator installed).

The specfx binary is --specfx, else $SPECFX, else this repository's target/release/specfx,
else `specfx` on PATH. Needs cocotb (requirements.txt beside this file, which ./scripts/test
installs in target/cocotb-venv; for Verilator 5.006, requirements-verilator.txt in
target/cocotb18-venv, with the specfx wheel for --live) and the simulator: Icarus Verilog, or
Verilator with make and a C++ compiler.
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
TOPLEVEL = "specfx_top"
TEST_MODULE = "test_specfx"
LIVE_TEST_MODULE = "test_live"

EXIT_OK, EXIT_FAILED, EXIT_ERROR = 0, 1, 2

SIMULATORS = ("icarus", "verilator")
# The oldest Verilator each cocotb release supports (cocotb's documentation), newest release
# first: cocotb 2.0 needs 5.036, 1.9 5.022, 1.8 5.006.
VERILATOR_MINIMUM = (((2, 0), (5, 36)), ((1, 9), (5, 22)), ((1, 8), (5, 6)))
# The virtual environment with a cocotb for Debian's Verilator 5.006, and its requirements.
VERILATOR_VENV = "target/cocotb18-venv"
VERILATOR_REQUIREMENTS = "hdl_ref/cocotb/requirements-verilator.txt"


class UsageError(Exception):
    """Bad usage or a failing tool: exit code 2."""


def probability(text):
    try:
        p = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text}") from None
    if not 0.0 <= p < 1.0:
        raise argparse.ArgumentTypeError(f"a probability must be in [0, 1), got {text}")
    return text  # passed to specfx as written


def parse_args(argv):
    ap = argparse.ArgumentParser(
        prog="run.py",
        description="Run a cocotb testbench of specfx_top (Icarus Verilog or Verilator): the "
        "vector replay of a vector directory, or the live scoreboard.",
    )
    source = ap.add_mutually_exclusive_group(required=True)
    source.add_argument(
        "--vectors", type=Path, help="vector directory (specfx vectors --out DIR): replay it"
    )
    source.add_argument(
        "--live",
        metavar="CONFIG",
        help="no vectors: the live scoreboard test_live.py, expected values from `import "
        "specfx` as inputs are accepted, for this configuration (as specfx --config takes it)",
    )
    ap.add_argument("--n", help="with --live: exponents, replacing the configuration's set")
    ap.add_argument(
        "--nvec", type=int, default=2000,
        help="with --live: random vectors after the directed ones (default 2000)",
    )
    ap.add_argument(
        "--sim",
        choices=SIMULATORS,
        default="icarus",
        help="the simulator (default icarus); verilator needs a cocotb that supports the "
        f"Verilator installed: 5.006 needs cocotb 1.8 ({VERILATOR_VENV})",
    )
    ap.add_argument(
        "--arch", choices=["pipelined", "folded"], default="pipelined", help="microarchitecture"
    )
    ap.add_argument("--seed", type=int, default=1, help="seed of the bubble/stall patterns")
    ap.add_argument(
        "--bubble", type=probability, default="0.2", help="probability of no input in a cycle"
    )
    ap.add_argument(
        "--stall", type=probability, default="0.2", help="probability of out_ready low in a cycle"
    )
    ap.add_argument(
        "--reset-data",
        action="store_true",
        help="build with RESET_DATA = 1 (the test then checks out_data == 0 after reset)",
    )
    ap.add_argument("--specfx", type=Path, help="the specfx binary")
    ap.add_argument(
        "--hdl-ref",
        type=Path,
        default=REPO / "hdl_ref",
        help="reference Verilog directory whose rtl/*.v is built (default: this repository's)",
    )
    ap.add_argument(
        "--build-dir", type=Path, help="build and run here (kept), not in a temporary directory"
    )
    ap.add_argument(
        "--keep", action="store_true", help="keep the temporary build directory (path printed)"
    )
    return ap.parse_args(argv)


def find_specfx(given):
    candidates = []
    if given is not None:
        candidates.append(given)
    elif os.environ.get("SPECFX"):
        candidates.append(Path(os.environ["SPECFX"]))
    else:
        candidates.append(REPO / "target" / "release" / "specfx")
        on_path = shutil.which("specfx")
        if on_path:
            candidates.append(Path(on_path))
    for c in candidates:
        if c.is_file() and os.access(c, os.X_OK):
            return c
    raise UsageError(
        f"no specfx binary ({', '.join(str(c) for c in candidates)}): build it with "
        "`cargo build --release` or pass --specfx PATH"
    )


def run_specfx(specfx, args):
    proc = subprocess.run([str(specfx), *args], capture_output=True, text=True)
    if proc.returncode != 0:
        err = proc.stderr.strip() or proc.stdout.strip()
        raise UsageError(f"specfx {' '.join(args[:2])} failed: {err}")
    return proc.stdout


def rtl_sources(hdl_ref):
    sources = sorted((hdl_ref / "rtl").glob("*.v"))
    if not any(s.name == f"{TOPLEVEL}.v" for s in sources):
        raise UsageError(f"{hdl_ref}: no rtl/{TOPLEVEL}.v")
    return sources


def version_tuple(text):
    """The leading numbers of a version, e.g. (1, 8, 1) of `1.8.1` or (5, 6) of `5.006`."""
    numbers = re.match(r"\d+(?:\.\d+)*", text)
    return tuple(int(n) for n in numbers.group(0).split(".")) if numbers else ()


def cocotb_version():
    """The version of the cocotb installed for this Python, read without importing it."""
    from importlib import metadata

    try:
        return metadata.version("cocotb")
    except metadata.PackageNotFoundError:
        return None


def no_cocotb(sim):
    """The error when this Python has no cocotb (or no runner) for the simulator."""
    if sim == "verilator":
        return UsageError(
            f"cocotb is not installed for {sys.executable}: for Verilator 5.006, `python3 -m "
            f"venv {VERILATOR_VENV} && {VERILATOR_VENV}/bin/pip install -r "
            f"{VERILATOR_REQUIREMENTS}` (and for --live the specfx wheel: {VERILATOR_VENV}"
            "/bin/pip install --no-deps target/wheels/specfx-*.whl), and run this script with "
            f"{VERILATOR_VENV}/bin/python"
        )
    return UsageError(
        f"cocotb is not installed for {sys.executable}: run ./scripts/test (it makes "
        "target/cocotb-venv), or `python3 -m venv target/cocotb-venv && "
        "target/cocotb-venv/bin/pip install -r hdl_ref/cocotb/requirements.txt` and run "
        "this script with target/cocotb-venv/bin/python"
    )


def import_runner(sim):
    """cocotb's Python runner: (get_runner, get_results, the cocotb version as a tuple).
    cocotb 1.x has it in `cocotb.runner`, 2.x in `cocotb_tools.runner`."""
    version = cocotb_version()
    if version is None:
        raise no_cocotb(sim)
    try:
        if version_tuple(version) < (2,):
            # cocotb 1.x warns on import that its runner is experimental; it is pinned here.
            warnings.filterwarnings("ignore", "Python runners", UserWarning)
            from cocotb.runner import get_results, get_runner
        else:
            from cocotb_tools.runner import get_results, get_runner
    except ImportError:
        raise no_cocotb(sim) from None
    return get_runner, get_results, version_tuple(version)


def check_simulator(sim, release):
    """The simulator's tools are on PATH, and a Verilator is one the cocotb release (a version
    tuple) supports."""
    if sim == "icarus":
        if shutil.which("iverilog") is None or shutil.which("vvp") is None:
            raise UsageError(
                "iverilog and vvp not found on PATH (Debian/Ubuntu: apt-get install -y iverilog)"
            )
        return
    if shutil.which("verilator") is None:
        raise UsageError(
            "verilator not found on PATH (Debian/Ubuntu: apt-get install -y verilator)"
        )
    for tool in ("make", "g++"):
        if shutil.which(tool) is None:
            raise UsageError(
                f"{tool} not found on PATH: Verilator builds its model with make and g++ "
                "(Debian/Ubuntu: apt-get install -y make g++)"
            )
    proc = subprocess.run(["verilator", "--version"], capture_output=True, text=True)
    found = re.search(r"Verilator (\d+\.\d+)", proc.stdout)
    if proc.returncode != 0 or found is None:
        raise UsageError(f"verilator --version failed: {(proc.stderr or proc.stdout).strip()}")
    have = version_tuple(found.group(1))
    need = next((v for c, v in VERILATOR_MINIMUM if release >= c), VERILATOR_MINIMUM[-1][1])
    if have < need:
        raise UsageError(
            f"cocotb {'.'.join(map(str, release))} (for {sys.executable}) needs Verilator "
            f"{need[0]}.{need[1]:03d} or later, and this is Verilator {found.group(1)}: run "
            f"this script with {VERILATOR_VENV}/bin/python (cocotb 1.8.1, "
            f"{VERILATOR_REQUIREMENTS})"
        )


def dut_parameters(specfx_bin, source, args):
    """specfx_top's parameters for a configuration (`source`: --config or --vectors and its
    argument), the architecture and RESET_DATA of the arguments."""
    params_args = ["hdl", "params", *source, "--arch", args.arch, "--format", "json"]
    if args.reset_data:
        params_args.append("--reset-data")
    try:
        return json.loads(run_specfx(specfx_bin, params_args))
    except ValueError as e:
        raise UsageError(f"specfx hdl params printed no JSON: {e}") from None


def live_setup(args, build_dir, specfx_bin):
    """The DUT's parameters and the test's environment of a --live run."""
    try:
        import specfx
    except ImportError:
        raise UsageError(
            f"the specfx Python package is not installed for {sys.executable}: ./scripts/test "
            "installs it in target/cocotb-venv (or: maturin develop -m python/Cargo.toml)"
        ) from None
    try:
        dp = specfx.Datapath(args.live, args.n)
    except ValueError as e:
        raise UsageError(str(e)) from None
    config = build_dir / "config.toml"
    config.write_text(dp.toml)
    parameters = dut_parameters(specfx_bin, ["--config", str(config)], args)
    environment = {
        "SPECFX_CONFIG": str(config),
        "SPECFX_ARCH": args.arch,
        "SPECFX_SEED": str(args.seed),
        "SPECFX_NVEC": str(args.nvec),
        "SPECFX_BUBBLE": args.bubble,
        "SPECFX_STALL": args.stall,
        "SPECFX_RESET_DATA": str(parameters.get("RESET_DATA", 0)),
    }
    return parameters, environment


def vector_setup(args, build_dir, specfx_bin):
    """The DUT's parameters and the test's environment of a vector replay."""
    vectors = args.vectors.resolve()
    if not (vectors / "manifest.json").is_file():
        raise UsageError(
            f"{vectors}: no manifest.json (write one with specfx vectors --out {vectors})"
        )
    parameters = dut_parameters(specfx_bin, ["--vectors", str(vectors)], args)
    stim = build_dir / "stimulus"
    stim_args = ["hdl", "stimulus", "--vectors", str(vectors), "--arch", args.arch]
    stim_args += ["--seed", str(args.seed), "--bubble", args.bubble, "--stall", args.stall]
    run_specfx(specfx_bin, stim_args + ["--out", str(stim)])
    environment = {
        "SPECFX_VECTORS": str(vectors),
        "SPECFX_STIMULUS": str(stim),
        "SPECFX_RESET_DATA": str(parameters.get("RESET_DATA", 0)),
    }
    return parameters, environment


def build_options(sim, release, sources):
    """The keyword arguments of the runner's build() for the simulator and the cocotb release
    (a version tuple)."""
    # cocotb 1.x calls the sources verilog_sources and takes no timescale: Verilator is given
    # it as an option (some rtl files have `timescale, some not, which Verilator refuses
    # without one); Icarus is left with its default for the files without one.
    options = {"sources": sources} if release >= (2,) else {"verilog_sources": sources}
    if release >= (2,):
        options["timescale"] = ("1ns", "1ps")
    if sim == "icarus":
        options["build_args"] = ["-g2005"]
    elif release < (2,):
        # cocotb's runner already gives --vpi and --public-flat-rw (every register of the core
        # visible to the test); the clock comes from cocotb and the RTL has no delay: no
        # --timing.
        options["build_args"] = ["--timescale", "1ns/1ps"]
    return options


def simulate(args, build_dir):
    """Builds and runs the test in build_dir; returns the test's summary (a dict)."""
    get_runner, get_results, release = import_runner(args.sim)
    check_simulator(args.sim, release)
    specfx_bin = find_specfx(args.specfx)
    sources = rtl_sources(args.hdl_ref.resolve())
    if args.live is not None:
        parameters, environment = live_setup(args, build_dir, specfx_bin)
        test_module = LIVE_TEST_MODULE
    else:
        parameters, environment = vector_setup(args, build_dir, specfx_bin)
        test_module = TEST_MODULE

    summary_path = build_dir / "summary.json"
    extra_env = {
        **environment,
        "SPECFX_SUMMARY": str(summary_path),
        # No __pycache__ beside the tests in the repository.
        "PYTHONDONTWRITEBYTECODE": "1",
    }
    # cocotb 1.x lets this process's environment override extra_env, and runs Verilator's
    # make without -j: both set here, in the environment its build and test inherit.
    os.environ.update(extra_env)
    if args.sim == "verilator" and release < (2,):
        os.environ.setdefault("MAKEFLAGS", f"-j{os.cpu_count() or 1}")
    runner = get_runner(args.sim)
    tool = "iverilog" if args.sim == "icarus" else "verilator"
    try:
        runner.build(
            hdl_toplevel=TOPLEVEL,
            parameters=parameters,
            build_dir=build_dir,
            always=True,
            **build_options(args.sim, release, sources),
        )
    except (subprocess.CalledProcessError, SystemExit) as e:
        raise UsageError(f"{tool} failed to build {TOPLEVEL} ({e})") from None
    try:
        runner.test(
            test_module=test_module,
            hdl_toplevel=TOPLEVEL,
            build_dir=build_dir,
            test_dir=build_dir,
            extra_env=extra_env,
        )
    except SystemExit as e:
        # The simulator exited non-zero; the summary, if written, still tells what happened.
        if not summary_path.is_file():
            raise UsageError(
                f"the simulation failed (exit code {e.code}) before the test ended"
            ) from None
    if not summary_path.is_file():
        raise UsageError(f"the test wrote no summary (did cocotb load {test_module}?)")
    summary = json.loads(summary_path.read_text())
    try:
        summary["cocotb_tests"], summary["cocotb_failed"] = get_results(build_dir / "results.xml")
    except (RuntimeError, SystemExit) as e:
        # No results file: cocotb 2.x raises RuntimeError, 1.x SystemExit.
        raise UsageError(str(e.code if isinstance(e, SystemExit) else e)) from None
    return summary


def main(argv):
    args = parse_args(argv)
    temporary = args.build_dir is None
    if temporary:
        build_dir = Path(tempfile.mkdtemp(prefix="specfx-cocotb."))
    else:
        build_dir = args.build_dir.resolve()
        build_dir.mkdir(parents=True, exist_ok=True)
    where = f"{args.sim}, {args.arch}" + (", RESET_DATA = 1" if args.reset_data else "")
    if args.live is not None:
        where += ", live scoreboard"
    try:
        summary = simulate(args, build_dir)
    except UsageError as e:
        print(f"cocotb: error: {e}", file=sys.stderr)
        return EXIT_ERROR
    finally:
        if temporary and not args.keep:
            shutil.rmtree(build_dir, ignore_errors=True)
        elif temporary:
            print(f"cocotb: build directory {build_dir}", file=sys.stderr)

    passed, failed = summary.get("passed", 0), summary.get("failed", 0)
    n = summary.get("n_vectors")
    if (
        n
        and passed == n
        and failed == 0
        and summary["cocotb_tests"] == 1
        and summary["cocotb_failed"] == 0
    ):
        print(f"cocotb: {passed} vectors passed ({where})")
        return EXIT_OK
    for line in summary.get("problems", []):
        print(line)
    if n is None:
        print(f"cocotb: FAIL: the test could not start ({where})")
    elif n == 0:
        print(f"cocotb: FAIL: the vector directory holds no vector, nothing was checked ({where})")
    else:
        print(f"cocotb: FAIL: {passed} of {n} vectors passed, {failed} failed ({where})")
    return EXIT_FAILED


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
