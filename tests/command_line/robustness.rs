//! Bad input through the real binary, table-driven: every case must end with exit code 2 and
//! one clear line on stderr naming the culprit, without a panic, without hanging and without
//! leaving a file behind in its working directory.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// What a case puts in its working directory before running.
enum Input {
    /// A text file.
    File(&'static str, &'static str),
    /// A named pipe (reading it would block forever).
    Fifo(&'static str),
    /// A symbolic link to a target (which may not exist).
    Symlink(&'static str, &'static str),
    /// A text file: a head, then a body repeated a number of times.
    Repeated(&'static str, &'static str, &'static str, usize),
}

/// A one-sphere scene: `[image]` keys, then more tables (lights, a mesh object); its
/// material is `m` or the name given (as written in TOML).
macro_rules! scene {
    ($image:literal, $more:literal) => {
        scene!($image, $more, "m")
    };
    ($image:literal, $more:literal, $name:literal) => {
        concat!(
            "[image]\n",
            $image,
            "\n[camera]\nposition = [0.0, 0.0, 5.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_deg = 30.0\n",
            "[[light]]\nkind = \"directional\"\ndirection = [0.0, 0.0, 1.0]\n",
            "[[material]]\nname = \"",
            $name,
            "\"\nn = 16\nk_s = 0.1\nk_d = 0.5\ncolour = [0.8, 0.6, 0.4]\n",
            "[[object]]\nkind = \"sphere\"\nmaterial = \"",
            $name,
            "\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\n",
            $more
        )
    };
}

/// A trace of the testbench's clock and cycle counter, and a 4-bit signal `v` (id `#`).
macro_rules! trace {
    ($changes:literal) => {
        concat!(
            "$scope module tb_specfx $end $var reg 1 ! clk $end\n",
            "$var integer 32 \" cycle $end $var wire 4 # v $end $upscope $end $enddefinitions $end\n",
            "#0 0! b0 \" bx #\n",
            $changes
        )
    };
}

/// How long a step may take before it counts as hung.
const TIMEOUT: Duration = Duration::from_secs(60);

/// One bad invocation: arguments (`{dir}` is the case's working directory), the inputs it
/// needs, and a piece of the one error line it must print.
struct Case {
    args: &'static [&'static str],
    inputs: &'static [Input],
    expect: &'static str,
}

const CASES: &[Case] = &[
    // Names end up in generated files and file names.
    Case {
        args: &["hdl", "params", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "name = \"a\\n`define SPECFX_K 9\"\n")],
        expect: "name: expected 1..=64 ASCII letters",
    },
    Case {
        args: &[
            "stability",
            "--config",
            "{dir}/c.toml",
            "--out",
            "{dir}/out",
        ],
        inputs: &[Input::File("c.toml", "name = \"x/y\"\n")],
        expect: "'/' is not allowed",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "name = \"../../escaped\"\n")],
        expect: "name: expected",
    },
    Case {
        args: &["vectors", "--config", "{dir}/c.toml", "--out", "{dir}/v"],
        inputs: &[Input::File("c.toml", "name = \"a */ b\"\n")],
        expect: "' ' is not allowed",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "name = \"\"\n")],
        expect: "it is empty",
    },
    // Budgets that cannot mean anything.
    Case {
        args: &[
            "optimize",
            "--budget",
            "shape_total <= NaN",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "the limit must be a finite number >= 0",
    },
    Case {
        args: &[
            "optimize",
            "--budget",
            "shape_total <= -1 lsb8",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "the limit must be a finite number >= 0",
    },
    Case {
        args: &[
            "optimize",
            "--budget",
            "correct >= 150%",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "at most 100%",
    },
    Case {
        args: &["budget", "--budget", "luts <= inf", "--out", "{dir}/b"],
        inputs: &[],
        expect: "the limit must be a finite number >= 0",
    },
    // A bare number where the metric has a unit: refused with the units, never read as 1.0.
    Case {
        args: &[
            "optimize",
            "--budget",
            "shape_total <= 1",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "'shape_total <= 1' is a bare number: shape_total takes lsbN",
    },
    Case {
        args: &["budget", "--budget", "out <= 1", "--out", "{dir}/b"],
        inputs: &[],
        expect: "'out <= 1' is a bare number: out takes ulp",
    },
    Case {
        args: &[
            "optimize",
            "--budget",
            "effective_bits >= 65",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "effective bits are at most 64",
    },
    Case {
        args: &[
            "optimize",
            "--budget",
            "shape_total <= 1 lsb999",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "lsbN needs a number N in 1..=64",
    },
    // Design spaces: ranges at the i64 limits, and more points than a sweep may hold.
    Case {
        args: &["sweep", "--space", "{dir}/s.toml", "--out", "{dir}/sw"],
        inputs: &[Input::File(
            "s.toml",
            "[vary]\n\"square.frac\" = \"-9223372036854775808..=9223372036854775807\"\n",
        )],
        expect: "at most 257 values",
    },
    Case {
        args: &["sweep", "--space", "{dir}/s.toml", "--out", "{dir}/sw"],
        inputs: &[Input::File(
            "s.toml",
            "[vary]\n\"square.frac\" = \"9223372036854775800..=-9223372036854775800\"\n",
        )],
        expect: "at most 257 values",
    },
    Case {
        args: &["sweep", "--space", "{dir}/s.toml", "--out", "{dir}/sw"],
        inputs: &[Input::File(
            "s.toml",
            "[vary]\n\"square.frac\" = \"1..=200\"\n\"t.frac\" = \"1..=200\"\n\"b.frac\" = \"1..=200\"\nk = [1, 2, 3, 4, 5, 6, 7]\n",
        )],
        expect: "expected at most 1048576 points",
    },
    // Counts that cannot be written, or that wrap.
    Case {
        args: &[
            "vectors",
            "--cases",
            "random:18446744073709551615,random:1",
            "--out",
            "{dir}/v",
        ],
        inputs: &[],
        expect: "at most 67108864 in all",
    },
    Case {
        args: &[
            "vectors",
            "--cases",
            "random:1000000000000",
            "--out",
            "{dir}/v",
        ],
        inputs: &[],
        expect: "at most 67108864 in all",
    },
    Case {
        args: &[
            "cosim", "--bubble", "0.9999", "--sim", "icarus", "--cases", "corner",
        ],
        inputs: &[],
        expect: "the stimulus is limited to 67108864 cycles",
    },
    // Options whose help makes the value bad input, and their messages.
    Case {
        args: &["optimize", "--start-frac", "0", "--out", "{dir}/o.toml"],
        inputs: &[],
        expect: "0 is not in 1..=48",
    },
    Case {
        args: &["minimax", "--k", "0"],
        inputs: &[],
        expect: "expected numbers of squarings k in 1..=7",
    },
    Case {
        args: &["optimize", "--k", "8", "--out", "{dir}/o.toml"],
        inputs: &[],
        expect: "expected numbers of squarings k in 1..=7",
    },
    Case {
        args: &[
            "hdl",
            "stimulus",
            "--vectors",
            "{dir}",
            "--bubble",
            "1",
            "--out",
            "{dir}/s",
        ],
        inputs: &[],
        expect: "expected a probability in [0, 1)",
    },
    // Files that are not regular files would block or never end.
    Case {
        args: &["check", "--config", "{dir}/fifo.toml"],
        inputs: &[Input::Fifo("fifo.toml")],
        expect: "expected a regular file, got a FIFO",
    },
    Case {
        args: &["sweep", "--space", "{dir}/fifo.toml", "--out", "{dir}/sw"],
        inputs: &[Input::Fifo("fifo.toml")],
        expect: "expected a regular file, got a FIFO",
    },
    Case {
        args: &["trace", "compare", "{dir}/a.vcd", "{dir}/fifo.vcd"],
        inputs: &[
            Input::File("a.vcd", "$enddefinitions $end\n"),
            Input::Fifo("fifo.vcd"),
        ],
        expect: "expected a regular file, got a FIFO",
    },
    Case {
        args: &["render", "--scene", "{dir}/fifo.toml", "--out", "{dir}/r"],
        inputs: &[Input::Fifo("fifo.toml")],
        expect: "expected a regular file, got a FIFO",
    },
    Case {
        args: &["check", "--config", "{dir}"],
        inputs: &[],
        expect: "manifest.json",
    },
    Case {
        args: &["check", "--config", "{dir}/missing.toml"],
        inputs: &[],
        expect: "no such file (and it is not a built-in name: baseline)",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "k = 9\n")],
        expect: "k",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "k = 0\n")],
        expect: "k",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "k = \"four\"\n")],
        expect: "line 1: invalid type: string",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "nonsense = 1\n")],
        expect: "nonsense",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[t]\nformat = \"q1.15\"\n")],
        expect: "t",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[t]\nformat = \"s1.200\"\n")],
        expect: "t",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[t]\nrounding = \"ROUND\"\n")],
        expect: "ROUND",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[t]\noverflow = \"CLIP\"\n")],
        expect: "CLIP",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "cutoff = \"maybe\"\n")],
        expect: "maybe",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "variant = \"spline\"\n")],
        expect: "spline",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "n = \"0..=4\"\n")],
        expect: "n",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "n = \"100..=10\"\n")],
        expect: "n",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "n = \"1..=70000\"\n")],
        expect: "n",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[latency]\nmul = 0\n")],
        expect: "latency.mul",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[latency]\nmul = 9\n")],
        expect: "latency.mul",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[[square]]\nformat = \"u1.15\"\n")],
        expect: "square",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[c]\nformat = \"u1.70\"\n")],
        expect: "c",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[coef]\nform = \"lambert\"\n")],
        expect: "lambert",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[coef]\nsource = \"guess\"\n")],
        expect: "guess",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "k = 4\nk = 5\n")],
        expect: "line",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[t\n")],
        expect: "line",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "name = 5\n")],
        expect: "line 1: invalid type: integer",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File(
            "c.toml",
            "name = \"xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx\"\n",
        )],
        expect: "65 characters",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[out]\nformat = \"u0.0\"\n")],
        expect: "u0.0",
    },
    Case {
        args: &["check", "--n", "0"],
        inputs: &[],
        expect: "n",
    },
    Case {
        args: &["check", "--n", "a..b"],
        inputs: &[],
        expect: "n",
    },
    Case {
        args: &["check", "--n", "5..=3"],
        inputs: &[],
        expect: "n",
    },
    Case {
        args: &["check", "--n", "1..=99999"],
        inputs: &[],
        expect: "n",
    },
    Case {
        args: &["check", "--n", ","],
        inputs: &[],
        expect: "n",
    },
    Case {
        args: &["check", "--n", "16,,32"],
        inputs: &[],
        expect: "n",
    },
    Case {
        args: &["vectors", "--cases", "random:0", "--out", "{dir}/v"],
        inputs: &[],
        expect: "case",
    },
    Case {
        args: &["vectors", "--cases", "random:x", "--out", "{dir}/v"],
        inputs: &[],
        expect: "case",
    },
    Case {
        args: &["vectors", "--cases", "corner,bogus", "--out", "{dir}/v"],
        inputs: &[],
        expect: "case",
    },
    Case {
        args: &["vectors", "--cases", "random:-1", "--out", "{dir}/v"],
        inputs: &[],
        expect: "case",
    },
    Case {
        args: &["vectors", "--cases", "", "--out", "{dir}/v"],
        inputs: &[],
        expect: "case",
    },
    Case {
        args: &["sim", "--bubble", "1"],
        inputs: &[],
        expect: "probability",
    },
    Case {
        args: &["sim", "--bubble=-0.1"],
        inputs: &[],
        expect: "probability",
    },
    Case {
        args: &["sim", "--bubble", "nan"],
        inputs: &[],
        expect: "probability",
    },
    Case {
        args: &["sim", "--bubble", "x"],
        inputs: &[],
        expect: "probability",
    },
    Case {
        args: &["sim", "--arch", "systolic"],
        inputs: &[],
        expect: "systolic",
    },
    Case {
        args: &["sim", "--cycles", "0"],
        inputs: &[],
        expect: "--cycles",
    },
    Case {
        args: &["cost", "--target", "asic7nm", "--analytic-only"],
        inputs: &[],
        expect: "asic7nm",
    },
    Case {
        args: &["optimize", "--target", "gowin", "--out", "{dir}/o.toml"],
        inputs: &[],
        expect: "gowin",
    },
    Case {
        args: &["sweep", "--shard", "4/4", "--out", "{dir}/sw"],
        inputs: &[],
        expect: "shard",
    },
    Case {
        args: &["sweep", "--shard", "5/4", "--out", "{dir}/sw"],
        inputs: &[],
        expect: "shard",
    },
    Case {
        args: &["sweep", "--shard", "1/0", "--out", "{dir}/sw"],
        inputs: &[],
        expect: "shard",
    },
    Case {
        args: &["sweep", "--shard", "a/b", "--out", "{dir}/sw"],
        inputs: &[],
        expect: "shard",
    },
    Case {
        args: &["sweep", "--shard", "1", "--out", "{dir}/sw"],
        inputs: &[],
        expect: "shard",
    },
    Case {
        args: &["hdl", "params", "--format", "vhdl"],
        inputs: &[],
        expect: "vhdl",
    },
    Case {
        args: &["cosim", "--sim", "modelsim"],
        inputs: &[],
        expect: "modelsim",
    },
    Case {
        args: &["cosim", "--vectors", "{dir}/nothing"],
        inputs: &[],
        expect: "manifest.json",
    },
    Case {
        args: &["hdl", "stimulus", "--vectors", "{dir}", "--out", "{dir}/s"],
        inputs: &[],
        expect: "/s: is inside the input --vectors directory",
    },
    Case {
        args: &[
            "hdl",
            "stimulus",
            "--vectors",
            "{dir}/v",
            "--out",
            "{dir}/s",
        ],
        inputs: &[Input::File("v/readme.txt", "not vectors")],
        expect: "/v: no manifest.json",
    },
    Case {
        args: &["trace", "compare", "{dir}/a.vcd", "{dir}/b.vcd"],
        inputs: &[],
        expect: "a.vcd",
    },
    Case {
        args: &[
            "coef",
            "--form",
            "cook_torrance",
            "--source",
            "exact",
            "--n",
            "16",
        ],
        inputs: &[],
        expect: "cook_torrance",
    },
    Case {
        args: &["coef", "--form", "phong", "--source", "oracle", "--n", "16"],
        inputs: &[],
        expect: "oracle",
    },
    Case {
        args: &[
            "optimize",
            "--budget",
            "shape_total < 1 lsb8",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "budget",
    },
    Case {
        args: &[
            "optimize",
            "--budget",
            "correct <= 99%",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "budget",
    },
    Case {
        args: &[
            "optimize",
            "--budget",
            "shape_total <= 1 parsecs",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "budget",
    },
    Case {
        args: &[
            "optimize",
            "--budget",
            "luts <= 8 on fpga",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "budget",
    },
    Case {
        args: &[
            "optimize",
            "--budget",
            "out <= 1 lsb8",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "budget",
    },
    Case {
        args: &[
            "optimize",
            "--budget",
            "shape_total <= lsb8",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "budget",
    },
    Case {
        args: &[
            "optimize",
            "--budget",
            "shape_total <= 1 lsb8,",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "budget",
    },
    Case {
        args: &["sweep", "--space", "{dir}/s.toml", "--out", "{dir}/sw"],
        inputs: &[Input::File("s.toml", "[vary]\nwarp = [1, 2]\n")],
        expect: "warp",
    },
    Case {
        args: &["sweep", "--space", "{dir}/s.toml", "--out", "{dir}/sw"],
        inputs: &[Input::File("s.toml", "[vary]\nk = []\n")],
        expect: "vary.k",
    },
    Case {
        args: &["sweep", "--space", "{dir}/s.toml", "--out", "{dir}/sw"],
        inputs: &[Input::File("s.toml", "[vary]\nk = [9]\n")],
        expect: "vary.k",
    },
    Case {
        args: &["sweep", "--space", "{dir}/s.toml", "--out", "{dir}/sw"],
        inputs: &[Input::File(
            "s.toml",
            "target = \"asic\"\n[vary]\nk = [4]\n",
        )],
        expect: "target",
    },
    Case {
        args: &["sweep", "--space", "{dir}/s.toml", "--out", "{dir}/sw"],
        inputs: &[Input::File(
            "s.toml",
            "[vary]\n\"square.frac\" = \"a..=b\"\n",
        )],
        expect: "vary.square.frac",
    },
    Case {
        args: &["sweep", "--space", "{dir}/s.toml", "--out", "{dir}/sw"],
        inputs: &[Input::File("s.toml", "bogus = 1\n")],
        expect: "bogus",
    },
    Case {
        args: &["render", "--scene", "{dir}/sc.toml", "--out", "{dir}/r"],
        inputs: &[Input::File(
            "sc.toml",
            "[image]\nwidth = 0\nheight = 48\n\n[camera]\nposition = [0.0, 0.3, 6.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_deg = 36.0\n\n[[light]]\nkind = \"directional\"\ndirection = [-0.5, 0.6, 0.7]\nintensity = 1.5\n\n[[material]]\nname = \"a\"\nn = 64\nk_s = 0.05\nk_d = 0.8\ncolour = [0.85, 0.5, 0.6]\n",
        )],
        expect: "width",
    },
    Case {
        args: &["render", "--scene", "{dir}/sc.toml", "--out", "{dir}/r"],
        inputs: &[Input::File(
            "sc.toml",
            "[image]\nwidth = 100000\nheight = 100000\n\n[camera]\nposition = [0.0, 0.3, 6.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_deg = 36.0\n\n[[light]]\nkind = \"directional\"\ndirection = [-0.5, 0.6, 0.7]\nintensity = 1.5\n\n[[material]]\nname = \"a\"\nn = 64\nk_s = 0.05\nk_d = 0.8\ncolour = [0.85, 0.5, 0.6]\n",
        )],
        expect: "image",
    },
    Case {
        args: &["render", "--scene", "{dir}/sc.toml", "--out", "{dir}/r"],
        inputs: &[Input::File(
            "sc.toml",
            "[image]\nwidth = 64\nheight = 48\n\n[camera]\nposition = [0.0, 0.3, 6.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_deg = 36.0\n\n[[light]]\nkind = \"directional\"\ndirection = [-0.5, 0.6, 0.7]\nintensity = 1.5\n\n[[material]]\nname = \"a\"\nn = 0\nk_s = 0.05\nk_d = 0.8\ncolour = [0.85, 0.5, 0.6]\n",
        )],
        expect: "n",
    },
    Case {
        args: &["render", "--scene", "{dir}/sc.toml", "--out", "{dir}/r"],
        inputs: &[Input::File(
            "sc.toml",
            "[image]\nwidth = 64\nheight = 48\n\n[camera]\nposition = [0.0, 0.3, 6.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_deg = 36.0\n\n[[light]]\nkind = \"directional\"\ndirection = [-0.5, 0.6, 0.7]\nintensity = 1.5\n\n[[material]]\nname = \"a\"\nn = 64\nk_s = 0.05\nk_d = 0.8\ncolour = [0.85, 0.5, 0.6]\n\n[[object]]\nkind = \"mesh\"\nmaterial = \"a\"\nfile = \"missing.obj\"\n",
        )],
        expect: "missing.obj",
    },
    Case {
        args: &["render", "--scene", "{dir}/sc.toml", "--out", "{dir}/r"],
        inputs: &[Input::File("sc.toml", "not toml at all")],
        expect: "line",
    },
    // Found from outside (issue 14, third pass): limits stated before the work, and device
    // nodes never replaced by a file.
    Case {
        args: &["minimax", "--write", "{dir}/m.csv", "--n-max", "4294967295"],
        inputs: &[],
        expect: "--n-max: expected 1..=65535, got 4294967295",
    },
    Case {
        args: &["sim", "--cycles", "18446744073709551615"],
        inputs: &[],
        expect: "--cycles: expected 1..=1000000000",
    },
    Case {
        args: &["hdl", "rom", "--out", "/dev/null", "--force"],
        inputs: &[],
        expect: "--out /dev/null: is not a regular file",
    },
    Case {
        args: &[
            "vectors",
            "--n",
            "16",
            "--cases",
            "corner",
            "--out",
            "{dir}/vz/..",
            "--force",
        ],
        inputs: &[],
        expect: "expected a directory name",
    },
    // Found from outside (issue 14, fourth pass): work limits stated before any work.
    Case {
        args: &["render", "--scene", "{dir}/s.toml", "--out", "{dir}/r"],
        inputs: &[Input::File(
            "s.toml",
            scene!(
                "width = 8192\nheight = 8192",
                "[[light]]\nkind = \"directional\"\ndirection = [0.0, 1.0, 1.0]\n"
            ),
        )],
        expect: "light: 8192 x 8192 pixels x 2 lights is 134217728, above the limit of 67108864",
    },
    Case {
        args: &[
            "stability",
            "--n",
            "1..=65535",
            "--c-bits",
            "24",
            "--out",
            "{dir}/st",
        ],
        inputs: &[],
        expect: "samples, above the limit of 2^34 = 17179869184",
    },
    // Names that would reach generated files.
    Case {
        args: &["fit", "--scene", "{dir}/s.toml", "--out", "{dir}/f"],
        inputs: &[Input::File(
            "s.toml",
            scene!("width = 4\nheight = 4", "", "m\\nx = 1"),
        )],
        expect: "material[0].name: expected 1..=64 ASCII letters",
    },
    // Meshes: the line and what was expected.
    Case {
        args: &["render", "--scene", "{dir}/s.toml", "--out", "{dir}/r"],
        inputs: &[
            Input::File(
                "s.toml",
                scene!(
                    "width = 4\nheight = 4",
                    "[[object]]\nkind = \"mesh\"\nmaterial = \"m\"\nfile = \"m.obj\"\n"
                ),
            ),
            Input::File("m.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n"),
        ],
        expect: "(m.obj): line 3: vertex index 3 is out of range: 2 vertices come before this line",
    },
    Case {
        args: &["render", "--scene", "{dir}/s.toml", "--out", "{dir}/r"],
        inputs: &[
            Input::File(
                "s.toml",
                scene!(
                    "width = 4\nheight = 4",
                    "[[object]]\nkind = \"mesh\"\nmaterial = \"m\"\nfile = \"m.stl\"\n"
                ),
            ),
            Input::File(
                "m.stl",
                "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n",
            ),
        ],
        expect: "(m.stl): line 4: the ASCII STL ends before `endsolid` (expected vertex x y z)",
    },
    // Traces: nesting the parser would recurse through, and changes no header declares.
    Case {
        args: &["trace", "compare", "{dir}/a.vcd", "{dir}/deep.vcd"],
        inputs: &[
            Input::File("a.vcd", trace!("#5 1!\n")),
            Input::Repeated(
                "deep.vcd",
                "$scope module tb_specfx $end\n",
                "$scope module a $end\n",
                30_000,
            ),
        ],
        expect: "deep.vcd: line 257: $scope nested deeper than 256",
    },
    Case {
        args: &["trace", "compare", "{dir}/a.vcd", "{dir}/b.vcd"],
        inputs: &[
            Input::File("a.vcd", trace!("#5 1!\n")),
            Input::File("b.vcd", trace!("#5 1! b1 %\n")),
        ],
        expect: "b.vcd: line 4: a value for identifier '%', which no $var declares",
    },
    Case {
        args: &["trace", "compare", "{dir}/a.vcd", "{dir}/b.vcd"],
        inputs: &[
            Input::File("a.vcd", trace!("#5 1!\n")),
            Input::File("b.vcd", trace!("#5 1! b10101 #\n")),
        ],
        expect: "b.vcd: line 4: a value of 5 bits for identifier '#', a variable of 4 bits",
    },
    Case {
        args: &["trace", "compare", "{dir}/a.vcd", "{dir}/b.vcd"],
        inputs: &[
            Input::File("a.vcd", trace!("#5 1!\n")),
            Input::File("b.vcd", trace!("#5 1! #3 0!\n")),
        ],
        expect: "b.vcd: line 4: time #3 goes back (the last was #5)",
    },
    Case {
        args: &["trace", "compare", "{dir}/a.vcd", "{dir}/b.vcd"],
        inputs: &[
            Input::File("a.vcd", trace!("#5 1!\n")),
            Input::File("b.vcd", trace!("#5 1! q\n")),
        ],
        expect: "b.vcd: line 4: unexpected character at start of command",
    },
    // Messages that named the wrong thing.
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::Symlink("c.toml", "gone.toml")],
        expect: "config {dir}/c.toml: a symbolic link to gone.toml, which cannot be read",
    },
    Case {
        args: &[
            "budget",
            "--budget",
            "shape_total <= 1 lsb8 and",
            "--out",
            "{dir}/b",
        ],
        inputs: &[],
        expect: "an empty bound (',' or 'and' with nothing before or after it)",
    },
    Case {
        args: &["calibrate", "--count", "0", "--data", "{dir}/cal"],
        inputs: &[],
        expect: "'0' for '--count <COUNT>': expected a whole number of configurations in 1..=100000",
    },
    Case {
        args: &["calibrate", "--count", "-1", "--data", "{dir}/cal"],
        inputs: &[],
        expect: "'-1' for '--count <COUNT>': expected a whole number of configurations in 1..=100000",
    },
    Case {
        args: &["sweep", "--space", "{dir}/sp.toml", "--out", "{dir}/sw"],
        inputs: &[Input::File("sp.toml", "[base]\nk = 99\n[vary]\n")],
        expect: "space {dir}/sp.toml: base.k: expected a number of squarings in 1..=7, got 99",
    },
    Case {
        args: &["fit", "--budget", "differing <= 101%", "--out", "{dir}/f"],
        inputs: &[],
        expect: "a share of pixels is at most 100% (or 1) in 'differing <= 101%'",
    },
    // Outputs that cannot be written are found before the work (/proc takes no new file).
    Case {
        args: &["optimize", "--out", "/proc/o.toml"],
        inputs: &[],
        expect: "--out /proc/o.toml: cannot write into /proc",
    },
    Case {
        args: &["optimize", "--out", "{dir}/no/o.toml"],
        inputs: &[],
        expect: "--out {dir}/no/o.toml: its directory {dir}/no does not exist",
    },
    Case {
        args: &["hdl", "rom", "--out", "/proc/rom.v"],
        inputs: &[],
        expect: "--out /proc/rom.v: cannot write into /proc",
    },
    Case {
        args: &["sim", "--cycles", "10", "--vcd", "/proc/s.vcd"],
        inputs: &[],
        expect: "--vcd /proc/s.vcd: cannot write into /proc",
    },
    Case {
        args: &["man", "--out", "/proc/man"],
        inputs: &[],
        expect: "--out /proc/man: cannot write into /proc",
    },
    // Issue 25: messages that named the wrong thing or took the wrong rule.
    Case {
        args: &["check", "--config", "{dir}/x.json"],
        inputs: &[Input::File("x.json", "not json")],
        expect: "config {dir}/x.json: a JSON file, expected a TOML configuration",
    },
    Case {
        args: &[
            "hdl",
            "stimulus",
            "--vectors",
            "{dir}/nosuch",
            "--out",
            "{dir}/st",
        ],
        inputs: &[],
        expect: "{dir}/nosuch: no such file or directory, expected a vector directory",
    },
    Case {
        args: &[
            "hdl",
            "stimulus",
            "--vectors",
            "{dir}/loop",
            "--out",
            "{dir}/st",
        ],
        inputs: &[Input::Symlink("loop", "loop")],
        expect: "{dir}/loop: Too many levels of symbolic links",
    },
    Case {
        args: &["hdl", "params", "--vectors", "{dir}/vectors.csv"],
        inputs: &[Input::File("vectors.csv", "n,in_c\n16,0\n")],
        expect: "{dir}/vectors.csv: not a directory, expected a vector directory",
    },
    Case {
        args: &[],
        inputs: &[],
        expect: "'specfx' needs a subcommand, expected one of: report, paper, check,",
    },
    Case {
        args: &["hdl"],
        inputs: &[],
        expect: "'specfx hdl' needs a subcommand, expected one of: params, rom, stimulus",
    },
    Case {
        args: &["--quiet", "trace"],
        inputs: &[],
        expect: "'specfx trace' needs a subcommand, expected one of: compare",
    },
    Case {
        args: &["hdl", "params", "--format", "iverilog", "--top", "a b;"],
        inputs: &[],
        expect: "expected a Verilog module name (a letter or '_', then letters, digits, '_' or '$'), got 'a b;'",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[c]\nformat = \"u40.40\"\n")],
        expect: "width (int bits + frac bits) of u40.40 must be in 1..=63, got 80",
    },
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File("c.toml", "[c]\nformat = \"u0.0\"\n")],
        expect: "width (int bits + frac bits) of u0.0 must be in 1..=63, got 0",
    },
    // c - 1 of s64.0 reaches -2^63 - 1, which no 64-bit format holds; printed exactly.
    Case {
        args: &["check", "--config", "{dir}/c.toml"],
        inputs: &[Input::File(
            "c.toml",
            "[c]\nformat = \"s64.0\"\n[d]\nformat = \"s64.0\"\n",
        )],
        expect: "range down to -9223372036854775809), got s64.0",
    },
    Case {
        args: &["check", "--n", "+5"],
        inputs: &[],
        expect: "an exponent n must be a whole number in 1..=65535, digits only (in n set '+5'), got '+5'",
    },
    Case {
        args: &["check", "--n", "16.. =20"],
        inputs: &[],
        expect: "digits only (in n set '16.. =20'), got ' =20'",
    },
    Case {
        args: &["hdl", "stimulus", "--vectors", "{dir}", "--out", "/proc/st"],
        inputs: &[],
        expect: "--out /proc/st: cannot write into /proc",
    },
    Case {
        args: &["cosim", "--sim", "icarus", "--vcd", "/proc/traces"],
        inputs: &[],
        expect: "--vcd /proc/traces: cannot write into /proc",
    },
    // Found from outside (issue 14, fifth pass).
    Case {
        args: &["sim", "--vcd", "{dir}/s.vcd", "--vcd-cycles", "1000000000"],
        inputs: &[],
        expect: "1000000000 is not in 1..=262144",
    },
    Case {
        args: &[
            "cosim", "--sim", "icarus", "--cases", "corner", "--bubble", "0.99", "--vcd", "{dir}/t",
        ],
        inputs: &[],
        expect: "with --vcd, the trace is limited to 262144 cycles",
    },
    Case {
        args: &[
            "render",
            "--scene",
            "{dir}/s.toml",
            "--out",
            "{dir}/m",
            "--force",
        ],
        inputs: &[
            Input::File(
                "s.toml",
                scene!(
                    "width = 4\nheight = 4",
                    "[[object]]\nkind = \"mesh\"\nmaterial = \"m\"\nfile = \"m/ok.obj\"\n"
                ),
            ),
            Input::File("m/ok.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
        ],
        expect: "would replace the directory that holds the input a mesh of --scene",
    },
    Case {
        args: &[
            "optimize",
            "--budget",
            "shape_total <= 1 lsb8 shape_quant <= 1",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "two bounds need ',' or 'and' between them",
    },
    Case {
        args: &[
            "optimize",
            "--budget",
            "dsps <= 1.5 on ice40",
            "--out",
            "{dir}/o.toml",
        ],
        inputs: &[],
        expect: "a count of cells is a whole number",
    },
    Case {
        args: &["stability", "--float", "powf,powf", "--out", "{dir}/st"],
        inputs: &[],
        expect: "--float: 'powf' is listed twice",
    },
    Case {
        args: &["sweep", "--space", "{dir}/sp.toml", "--out", "{dir}/sw"],
        inputs: &[Input::File("sp.toml", "[vary]\nk = [3, 3]\n")],
        expect: "vary.k: expected distinct values, got 3 again (value 2)",
    },
    Case {
        args: &["sweep", "--space", "{dir}/sp.toml", "--out", "{dir}/sw"],
        inputs: &[Input::File(
            "sp.toml",
            "[base]\nname = \"a b\"\n[vary]\nk = [3]\n",
        )],
        expect: "base.name: expected 1..=64 ASCII letters",
    },
    // A negative number reaches the option's own check (clap took it for an option).
    Case {
        args: &["stability", "--tol", "-1", "--out", "{dir}/st"],
        inputs: &[],
        expect: "'-1' for '--tol <TOL>': the tolerance must be a positive number",
    },
];

fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = walk(dir);
    v.sort();
    v
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    if let Ok(rd) = std::fs::read_dir(dir) {
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                out.extend(walk(&p));
            }
            out.push(p);
        }
    }
    out
}

/// A full stderr does not turn an error (or progress and log lines) into a panic: the exit code
/// still says what happened (2 for bad input, 0 for a success).
#[test]
fn a_full_stderr_keeps_the_exit_code() {
    for (args, code) in [
        (&["check", "--config", "no-such.toml"][..], 2),
        (&["check", "--bogus"][..], 2),
        (&["-v", "check", "--n", "16..=20"][..], 0),
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_specfx"))
            .args(args)
            .stderr(std::fs::File::create("/dev/full").unwrap())
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(code), "{args:?}");
    }
}

/// A full disk behind stdout is an error that names stdout, not a panic.
#[test]
fn a_full_stdout_is_named() {
    for args in [
        &["paper"][..],
        &["check", "--n", "16..=20"][..],
        &["hdl", "params"][..],
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_specfx"))
            .args(args)
            .stdout(std::fs::File::create("/dev/full").unwrap())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("cannot write to stdout"), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn bad_input_gets_one_line_and_exit_code_2_and_leaves_nothing() {
    let mut failures = Vec::new();
    for (i, case) in CASES.iter().enumerate() {
        let dir = std::env::temp_dir().join(format!("specfx-bad-{}-{i}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for input in case.inputs {
            match input {
                Input::File(name, text) => {
                    let path = dir.join(name);
                    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
                    std::fs::write(path, text).unwrap()
                }
                Input::Fifo(name) => {
                    let ok = Command::new("mkfifo")
                        .arg(dir.join(name))
                        .status()
                        .unwrap()
                        .success();
                    assert!(ok, "mkfifo");
                }
                Input::Symlink(name, target) => {
                    std::os::unix::fs::symlink(target, dir.join(name)).unwrap()
                }
                Input::Repeated(name, head, body, count) => {
                    std::fs::write(dir.join(name), format!("{head}{}", body.repeat(*count)))
                        .unwrap()
                }
            }
        }
        let before = files_in(&dir);
        let args: Vec<String> = case
            .args
            .iter()
            .map(|a| a.replace("{dir}", dir.to_str().unwrap()))
            .collect();
        let (out, finished) = common::run_guarded(
            Command::new(env!("CARGO_BIN_EXE_specfx"))
                .args(&args)
                .current_dir(&dir)
                .stdin(Stdio::null()),
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        let label = format!("case {i} `specfx {}`", args.join(" "));
        if !finished {
            failures.push(format!("{label}: hung"));
        } else if out.status.code() != Some(2) {
            failures.push(format!(
                "{label}: exit {:?}, stderr {stderr}",
                out.status.code()
            ));
        }
        if stderr.contains("panicked") {
            failures.push(format!("{label}: panicked: {stderr}"));
        }
        let expect = case.expect.replace("{dir}", dir.to_str().unwrap());
        if stderr.lines().count() != 1 || !stderr.contains(&expect) {
            failures.push(format!(
                "{label}: expected one line containing {:?}, got {stderr:?}",
                expect
            ));
        }
        let after = files_in(&dir);
        if after != before {
            failures.push(format!("{label}: left {:?}", after));
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn specfx_in(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_specfx"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn fresh_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("specfx-out-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The staging directories (`.<name>.partial-<pid>`) in `dir`.
fn staging(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".partial-") || n.contains(".old-"))
        .collect()
}

/// A result directory is replaced by the same command, refused for anything else unless
/// --force, and a file in its place is refused.
#[test]
fn results_replace_their_own_kind_only() {
    let dir = fresh_dir("replace");
    let budget = |out: &str, force: bool| {
        let mut args = vec!["budget", "--no-gappa", "--n", "16..=64", "--out", out];
        if force {
            args.push("--force");
        }
        specfx_in(&dir, &args)
    };
    std::fs::create_dir(dir.join("b")).unwrap();
    assert!(
        budget("b", false).status.success(),
        "an empty directory is taken"
    );
    let first = std::fs::read(dir.join("b/budget.json")).unwrap();
    assert!(
        budget("b", false).status.success(),
        "an earlier budget is replaced"
    );
    assert_eq!(std::fs::read(dir.join("b/budget.json")).unwrap(), first);
    std::fs::create_dir(dir.join("mine")).unwrap();
    std::fs::write(dir.join("mine/data.txt"), "mine").unwrap();
    let o = budget("mine", false);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("pass --force to replace it"));
    assert_eq!(
        std::fs::read_to_string(dir.join("mine/data.txt")).unwrap(),
        "mine"
    );
    // Another command's result is not this command's either.
    let o = specfx_in(
        &dir,
        &["stability", "--n", "1..=8", "--c-bits", "6", "--out", "b"],
    );
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(budget("mine", true).status.success());
    assert!(!dir.join("mine/data.txt").exists());
    std::fs::write(dir.join("afile"), "x").unwrap();
    let o = budget("afile", true);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("is not a directory"));
    assert!(staging(&dir).is_empty(), "{:?}", staging(&dir));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Killed (SIGKILL) mid-run, a command leaves the earlier result as it was, its hidden
/// staging directory is removed by the next run; interrupted (SIGINT, SIGTERM), it removes its
/// staging directory itself and exits with 130.
#[test]
fn interrupted_runs_leave_the_earlier_result_intact() {
    let dir = fresh_dir("kill");
    let small = ["stability", "--n", "1..=8", "--c-bits", "6", "--out", "st"];
    assert!(specfx_in(&dir, &small).status.success());
    let before = std::fs::read(dir.join("st/stability.json")).unwrap();
    for signal in ["KILL", "INT", "TERM"] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_specfx"))
            .args(["stability", "--out", "st"])
            .current_dir(&dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let start = Instant::now();
        while staging(&dir).is_empty() {
            assert!(start.elapsed() < TIMEOUT, "no staging directory appeared");
            std::thread::sleep(Duration::from_millis(10));
        }
        std::thread::sleep(Duration::from_millis(300));
        let ok = Command::new("kill")
            .args([format!("-{signal}"), child.id().to_string()])
            .status()
            .unwrap()
            .success();
        assert!(ok);
        let status = child.wait().unwrap();
        assert_eq!(
            std::fs::read(dir.join("st/stability.json")).unwrap(),
            before,
            "SIGTERM/INT/KILL changed the earlier result"
        );
        if signal == "KILL" {
            assert_eq!(
                staging(&dir).len(),
                1,
                "the killed run's staging is left hidden"
            );
            // The next run removes what the killed one left.
            assert!(specfx_in(&dir, &small).status.success());
        } else {
            assert_eq!(status.code(), Some(130), "SIG{signal}");
        }
        assert!(staging(&dir).is_empty(), "SIG{signal}: {:?}", staging(&dir));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A full disk (a file size limit) met while writing several files leaves none of them, and
/// no directory made for them: `man --out` and `hdl stimulus` write all or nothing.
#[test]
fn a_full_disk_leaves_no_partial_pages_or_stimulus() {
    let dir = fresh_dir("full");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let man = dir.join("man");
    let (o, finished) = common::limited(2, &["man", "--out", &s(&man)]);
    assert!(finished, "man hung on a full disk");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("File too large"), "{err}");
    assert!(!man.exists(), "man left {:?}", files_in(&man));
    // Into an existing directory: its own files stay, nothing is added.
    std::fs::create_dir_all(&man).unwrap();
    std::fs::write(man.join("mine.txt"), "kept").unwrap();
    let (o, _) = common::limited(2, &["man", "--out", &s(&man)]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(files_in(&man), [man.join("mine.txt")]);
    // With room, every page.
    let o = common::specfx(&["man", "--out", &s(&man)]);
    assert!(o.status.success());
    assert!(files_in(&man).len() > 20);

    let vectors = dir.join("v");
    let o = common::specfx(&[
        "vectors",
        "--n",
        "16",
        "--cases",
        "random:2000",
        "--out",
        &s(&vectors),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stim = dir.join("a/stim");
    let args = [
        "hdl",
        "stimulus",
        "--vectors",
        &s(&vectors),
        "--out",
        &s(&stim),
    ];
    let (o, finished) = common::limited(2, &args);
    assert!(finished, "hdl stimulus hung on a full disk");
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        !dir.join("a").exists(),
        "left {:?}",
        files_in(&dir.join("a"))
    );
    let o = common::specfx(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(files_in(&stim).len(), 4);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// No command writes into the vector directory it reads, even with --force: `hdl stimulus`'s
/// --out (the directory itself, a path through `..`, a symbolic link to it) and its --vcd,
/// and `cosim`'s --vcd directory.
#[test]
fn the_input_vector_directory_is_never_written_into() {
    let dir = fresh_dir("into");
    let o = specfx_in(
        &dir,
        &["vectors", "--n", "16", "--cases", "random:10", "--out", "v"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::os::unix::fs::symlink("v", dir.join("link")).unwrap();
    let before = common::snapshot(&dir.join("v"));
    for (flag, out) in [
        ("--out", "v"),
        ("--out", "v/x/.."),
        ("--out", "link"),
        ("--out", "v/sub"),
        ("--vcd", "v/model.vcd"),
        ("--vcd", "link/model.vcd"),
    ] {
        let mut args = vec!["hdl", "stimulus", "--vectors", "v", "--force"];
        if flag == "--vcd" {
            args.extend(["--out", "st", "--vcd", out]);
        } else {
            args.extend(["--out", out]);
        }
        let o = specfx_in(&dir, &args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.contains(&format!(
                "{flag} {out}: is inside the input --vectors directory v"
            )),
            "{err}"
        );
        assert_eq!(common::snapshot(&dir.join("v")), before, "{args:?}");
        assert!(!dir.join("st").exists());
    }
    // cosim's trace directory, refused before any simulation.
    for vcd in ["v", "link", "v/traces"] {
        let args = ["cosim", "--vectors", "v", "--vcd", vcd, "--force"];
        let o = specfx_in(&dir, &args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.contains(&format!(
                "--vcd {vcd}: is inside the input --vectors directory v"
            )),
            "{err}"
        );
        assert_eq!(common::snapshot(&dir.join("v")), before, "{args:?}");
    }
    // Beside it, as before.
    let o = specfx_in(&dir, &["hdl", "stimulus", "--vectors", "v", "--out", "st"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A symbolic link named like a staging directory (`.o.partial-<dead pid>`, `.o.old-<dead
/// pid>`) pointing to a user's directory, even one holding a marker, is neither taken over,
/// put back in place of the result, nor emptied.
#[test]
fn links_named_like_staging_directories_are_left_alone() {
    let dir = fresh_dir("links");
    let users = dir.join("users");
    std::fs::create_dir(&users).unwrap();
    std::fs::write(users.join(".specfx-result"), "budget\n").unwrap();
    std::fs::write(users.join("notes.txt"), "mine").unwrap();
    for tag in ["partial", "old"] {
        std::os::unix::fs::symlink("users", dir.join(format!(".o.{tag}-999999999"))).unwrap();
    }
    let o = specfx_in(
        &dir,
        &["budget", "--no-gappa", "--n", "16..=20", "--out", "o"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let meta = std::fs::symlink_metadata(dir.join("o")).unwrap();
    assert!(meta.is_dir() && !meta.is_symlink());
    assert!(dir.join("o/budget.json").is_file());
    let mut kept: Vec<String> = std::fs::read_dir(&users)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    kept.sort();
    assert_eq!(kept, [".specfx-result", "notes.txt"]);
    for tag in ["partial", "old"] {
        let link = dir.join(format!(".o.{tag}-999999999"));
        assert!(std::fs::symlink_metadata(link).unwrap().is_symlink());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An existing result that cannot be moved aside (immutable) is refused before the work, with
/// one line, the earlier result unchanged. Needs root for chattr, as CI runs.
#[test]
fn an_immutable_result_is_refused_before_the_work() {
    let dir = fresh_dir("immutable");
    let args = ["budget", "--no-gappa", "--n", "16..=20", "--out", "o"];
    assert!(specfx_in(&dir, &args).status.success());
    let before = common::snapshot(&dir.join("o"));
    let chattr = |flag: &str| {
        Command::new("chattr")
            .args([flag, dir.join("o").to_str().unwrap()])
            .status()
            .is_ok_and(|s| s.success())
    };
    if !chattr("+i") {
        assert!(
            !euid_is_root(),
            "chattr +i failed as root: this test needs a filesystem with attributes"
        );
        eprintln!("skipped: chattr +i needs root");
        std::fs::remove_dir_all(&dir).unwrap();
        return;
    }
    let o = specfx_in(&dir, &args);
    assert!(chattr("-i"));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("--out o: cannot be replaced (moving it aside failed)"),
        "{err}"
    );
    assert!(staging(&dir).is_empty(), "{:?}", staging(&dir));
    assert_eq!(common::snapshot(&dir.join("o")), before);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Whether this process runs as root (`id -u` is 0).
fn euid_is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

/// A summary that cannot reach a full stdout after the result directory was committed: one
/// error line that says the result is complete, and it is.
#[test]
fn a_full_stdout_after_the_result_says_the_result_is_complete() {
    let dir = fresh_dir("fullout");
    let o = Command::new(env!("CARGO_BIN_EXE_specfx"))
        .args([
            "--quiet",
            "budget",
            "--no-gappa",
            "--n",
            "16..=20",
            "--json",
            "--out",
            "o",
        ])
        .current_dir(&dir)
        .stdout(std::fs::File::create("/dev/full").unwrap())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("cannot write to stdout") && err.contains("(the result in o is complete)"),
        "{err}"
    );
    assert!(dir.join("o/budget.json").is_file());
    std::fs::remove_dir_all(&dir).unwrap();
}
