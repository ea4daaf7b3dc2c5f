//! Traces: the model's VCD (`specfx hdl stimulus --vcd`) against the testbench's dump of the
//! same run in Icarus Verilog and Verilator (`specfx cosim --vcd`), compared with
//! `specfx trace compare` signal by signal; a mutated RTL found at its first differing cycle
//! and signal (by `cosim --vcd` too, beside the failing vectors); the comparison's rules on
//! hand-written traces, signals in one file only among them.

use crate::common::{config_path, specfx};

use std::path::{Path, PathBuf};
use std::process::Output;

use specfx::cycle::compare::{compare, Comparison};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn temp_dir(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("specfx-trace-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    std::fs::create_dir_all(&p).unwrap();
    p
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn ok(o: &Output) {
    assert!(
        o.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Vectors of `config` in `dir/vectors` (its first, a middle and its last exponent, so that
/// the corner cases stay few); returns the directory and the number of vectors.
fn write_vectors(config: &str, cases: &str, dir: &Path) -> (PathBuf, u64) {
    let dp = specfx::pipeline::Datapath::new(match config {
        "baseline" => specfx::pipeline::Config::baseline(),
        path => {
            specfx::pipeline::Config::from_toml(&std::fs::read_to_string(path).unwrap()).unwrap()
        }
    })
    .unwrap();
    let ns = dp.config().n.values();
    let n = format!("{},{},{}", ns[0], ns[ns.len() / 2], ns[ns.len() - 1]);
    let out = dir.join("vectors");
    ok(&specfx(&[
        "vectors",
        "--config",
        config,
        "--n",
        &n,
        "--cases",
        cases,
        "--seed",
        "3",
        "--out",
        out.to_str().unwrap(),
    ]));
    let n_vectors = json(&out.join("manifest.json"))["n_vectors"]
        .as_u64()
        .unwrap();
    (out, n_vectors)
}

/// One co-simulation with both traces: `specfx cosim --vcd dir/traces`.
struct Cosim<'a> {
    vectors: &'a Path,
    sim: &'a str,
    arch: &'a str,
    bubble: &'a str,
    stall: &'a str,
    hdl_ref: Option<&'a Path>,
    reset_data: bool,
}

impl Cosim<'_> {
    fn run(&self, traces: &Path) -> Output {
        let mut args = vec![
            "cosim",
            "--vectors",
            self.vectors.to_str().unwrap(),
            "--sim",
            self.sim,
            "--arch",
            self.arch,
            "--seed",
            "7",
            "--bubble",
            self.bubble,
            "--stall",
            self.stall,
            "--vcd",
            traces.to_str().unwrap(),
        ];
        if let Some(h) = self.hdl_ref {
            args.extend(["--hdl-ref", h.to_str().unwrap()]);
        }
        if self.reset_data {
            args.push("--reset-data");
        }
        specfx(&args)
    }

    /// The number of cycles of the run, from `specfx hdl stimulus` with the same arguments
    /// (whose model trace must be the one `cosim` wrote, byte for byte).
    fn stimulus_cycles(&self, dir: &Path, model_vcd: &Path) -> u64 {
        let out = dir.join("stimulus");
        let vcd = dir.join("stimulus.vcd");
        ok(&specfx(&[
            "hdl",
            "stimulus",
            "--vectors",
            self.vectors.to_str().unwrap(),
            "--arch",
            self.arch,
            "--seed",
            "7",
            "--bubble",
            self.bubble,
            "--stall",
            self.stall,
            "--out",
            out.to_str().unwrap(),
            "--vcd",
            vcd.to_str().unwrap(),
        ]));
        assert!(std::fs::read(&vcd).unwrap() == std::fs::read(model_vcd).unwrap());
        json(&out.join("stim.json"))["n_cycles"].as_u64().unwrap()
    }
}

fn compare_files(a: &Path, b: &Path) -> Comparison {
    let open = |p: &Path| std::io::BufReader::new(std::fs::File::open(p).unwrap());
    compare(open(a), open(b)).unwrap()
}

fn trace_compare(a: &Path, b: &Path) -> Output {
    specfx(&["trace", "compare", a.to_str().unwrap(), b.to_str().unwrap()])
}

/// Every variable of a VCD file by full name, with its type and whether it sits in a function
/// scope (read with the vcd crate directly, not through the comparison).
fn variables(path: &Path) -> Vec<(String, vcd::VarType, bool)> {
    fn walk(
        items: &[vcd::ScopeItem],
        path: &mut Vec<String>,
        in_function: bool,
        out: &mut Vec<(String, vcd::VarType, bool)>,
    ) {
        for item in items {
            match item {
                vcd::ScopeItem::Scope(s) => {
                    path.push(s.identifier.clone());
                    let f = in_function || s.scope_type == vcd::ScopeType::Function;
                    walk(&s.items, path, f, out);
                    path.pop();
                }
                vcd::ScopeItem::Var(v) => {
                    out.push((
                        format!("{}.{}", path.join("."), v.reference),
                        v.var_type,
                        in_function,
                    ));
                }
                _ => {}
            }
        }
    }
    let text = std::fs::read(path).unwrap();
    let header = vcd::Parser::new(&text[..]).parse_header().unwrap();
    let mut out = Vec::new();
    walk(&header.items, &mut Vec::new(), false, &mut out);
    for v in &mut out {
        if let Some(rest) = v.0.strip_prefix("TOP.") {
            v.0 = rest.to_string();
        }
    }
    out
}

/// The registers of a core, written from the RTL source (specfx_pipelined.v, specfx_folded.v):
/// what the model's trace must hold.
fn expected_registers(arch: &str, k: u32, lat: (u32, u32, u32)) -> Vec<String> {
    let (sub, mul, add) = lat;
    let mut v: Vec<String> = vec!["out_valid".into(), "out_data".into()];
    let delay = |v: &mut Vec<String>, prefix: &str, name: &str, lat: u32| {
        for s in 0..lat {
            v.push(format!("{prefix}{name}.g_regs.g_stage[{s}].r"));
        }
    };
    if arch == "folded" {
        for r in [
            "busy",
            "step",
            "count",
            "x",
            "slope_r",
            "offset_r",
            "threshold_r",
            "c_cl_r",
            "coef_r",
            "depth_r",
        ] {
            v.push(r.into());
        }
        return v;
    }
    delay(&mut v, "", "u_valid", sub + add + (k + 2) * mul);
    delay(&mut v, "", "r_sub", sub);
    delay(&mut v, "", "r_mul_t", mul);
    delay(&mut v, "", "r_add_b", add);
    delay(&mut v, "", "r_mul_out", mul);
    for name in [
        "d_1",
        "c_cl_1",
        "slope_1",
        "offset_1",
        "threshold_1",
        "coef_1",
        "depth_1",
        "t_2",
        "c_cl_2",
        "offset_2",
        "threshold_2",
        "coef_2",
        "depth_2",
        "b_q",
        "coef_b",
        "depth_b",
    ] {
        v.push(name.into());
    }
    for i in 1..=k {
        let prefix = format!("g_square[{i}].");
        delay(&mut v, &prefix, "r_square", mul);
        v.push(format!("{prefix}y_q"));
        v.push(format!("{prefix}coef_q"));
        v.push(format!("{prefix}depth_q"));
    }
    v
}

/// The model's trace and Icarus's dump of one run agree, through `specfx cosim --vcd` and the
/// library; every cycle of the run is compared, every signal of the model's trace is in the
/// dump and known on some cycle, the model holds every register the RTL source declares and
/// every register Icarus dumps under the core.
fn check_agree(config: &str, name: &str, arch: &str, k: u32, lat: (u32, u32, u32)) {
    check_agree_with(config, name, arch, k, lat, false)
}

fn check_agree_with(
    config: &str,
    name: &str,
    arch: &str,
    k: u32,
    lat: (u32, u32, u32),
    reset_data: bool,
) {
    let dir = temp_dir(name);
    let (vectors, n_vectors) = write_vectors(config, "corner,random:150", &dir);
    let cosim = Cosim {
        vectors: &vectors,
        sim: "icarus",
        arch,
        bubble: "0.3",
        stall: "0.3",
        hdl_ref: None,
        reset_data,
    };
    let traces = dir.join("traces");
    let o = cosim.run(&traces);
    ok(&o);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.starts_with(&format!("{n_vectors} passed, 0 failed\ncompared ")),
        "{text}"
    );
    assert!(text.ends_with("traces agree\n"), "{text}");
    let (model, rtl) = (traces.join("model.vcd"), traces.join("rtl.vcd"));
    let n_cycles = cosim.stimulus_cycles(&dir, &model);

    let c = compare_files(&model, &rtl);
    assert!(c.agrees(), "{c:?}");
    assert_eq!(c.cycles_compared, n_cycles, "every cycle of the run");
    assert_eq!((c.cycles_only_first, c.cycles_only_second), (0, 0));
    assert!(c.only_first.is_empty(), "{:?}", c.only_first);
    assert!(c.never_known.is_empty(), "{:?}", c.never_known);
    let model_vars: Vec<String> = variables(&model).into_iter().map(|v| v.0).collect();
    assert_eq!(c.signals_compared, model_vars.len());

    let core = format!("tb_specfx.dut.g_{arch}.u_core.");
    for r in expected_registers(arch, k, lat) {
        let full = format!("{core}{r}");
        assert!(
            model_vars.contains(&full),
            "{name}: {full} not in the model"
        );
    }
    for tb in [
        "clk", "rst", "cycle", "in_n", "in_c", "in_coef", "in_depth", "out_data",
    ] {
        assert!(model_vars.contains(&format!("tb_specfx.{tb}")));
    }
    // Every register Icarus dumps in the core (but the combinational `always @*` result of
    // the folded step multiplexer and functions' variables) is in the model's trace ...
    let mut dumped: Vec<String> = variables(&rtl)
        .into_iter()
        .filter(|(n, t, in_function)| {
            n.starts_with(&core)
                && *t == vcd::VarType::Reg
                && !in_function
                && !n.ends_with(".step_result")
        })
        .map(|v| v.0)
        .collect();
    for r in &dumped {
        assert!(
            model_vars.contains(r),
            "{name}: RTL register {r} not in the model"
        );
    }
    // ... and they are the registers of the source: the delay lines' and the folded FSM's.
    let mut want: Vec<String> = expected_registers(arch, k, lat)
        .into_iter()
        .filter(|r| arch == "folded" || r.ends_with(".r"))
        .map(|r| format!("{core}{r}"))
        .collect();
    want.sort();
    dumped.sort();
    assert_eq!(dumped, want, "{name}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn baseline_pipelined_traces_agree() {
    check_agree("baseline", "base-p", "pipelined", 4, (1, 1, 1));
}

#[test]
fn baseline_folded_traces_agree() {
    check_agree("baseline", "base-f", "folded", 4, (1, 1, 1));
}

/// With RESET_DATA = 1 the RTL's empty registers hold 0 instead of x: still don't-care.
#[test]
fn reset_data_traces_agree() {
    check_agree_with("baseline", "reset-p", "pipelined", 4, (1, 1, 1), true);
    check_agree_with("baseline", "reset-f", "folded", 4, (1, 1, 1), true);
}

/// Latencies above 1 (every register inside the delay lines), signed stages, the paper
/// cutoff and five squarings.
#[test]
fn deep_latency_traces_agree_in_both_architectures() {
    let config = config_path("conv_sym_k5.toml");
    check_agree(&config, "k5-p", "pipelined", 5, (2, 2, 1));
    check_agree(&config, "k5-f", "folded", 5, (2, 2, 1));
}

/// A per-n depth (stages 2 to 4 bypassed for n < 9): the depth rides the delay lines beside
/// the coefficient, and the folded core holds it in `depth_r`.
#[test]
fn per_n_depth_traces_agree_in_both_architectures() {
    let config = config_path("depth_steps_signed.toml");
    check_agree(&config, "depth-p", "pipelined", 4, (2, 1, 2));
    check_agree(&config, "depth-f", "folded", 4, (2, 1, 2));
}

/// The minimax variant (its own slope and offset formats), a 3-cycle multiplier.
#[test]
fn minimax_traces_agree_in_both_architectures() {
    let config = config_path("minimax_folded.toml");
    check_agree(&config, "mm-p", "pipelined", 3, (1, 3, 1));
    check_agree(&config, "mm-f", "folded", 3, (1, 3, 1));
}

fn hex_words(path: &Path) -> Vec<u64> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| u64::from_str_radix(l.trim(), 16).unwrap())
        .collect()
}

/// The second squaring of a copy of the RTL truncates instead of rounding to nearest. The
/// comparison names the first cycle the mutated stage's register holds a value whose rounding
/// differs, found here from the golden vectors alone: baseline sq_1 and sq_2 are u1.16, so the
/// truncated square of vector j is `sq1[j]^2 >> 16`, and with neither bubbles nor stalls
/// vector j transfers at the end of cycle j and sits in `g_square[2]`'s register (the fifth:
/// sub, mul_t, add_b, square 1, square 2) during cycle j + 5.
#[test]
fn a_mutated_rounding_is_found_at_its_first_cycle_and_signal() {
    let dir = temp_dir("mutant");
    let (vectors, _) = write_vectors("baseline", "random:300", &dir);
    let hdl = dir.join("hdl_ref");
    for sub in ["rtl", "tb"] {
        std::fs::create_dir_all(hdl.join(sub)).unwrap();
        for entry in std::fs::read_dir(root().join("hdl_ref").join(sub)).unwrap() {
            let p = entry.unwrap().path();
            std::fs::copy(&p, hdl.join(sub).join(p.file_name().unwrap())).unwrap();
        }
    }
    let path = hdl.join("rtl/specfx_pipelined.v");
    let text = std::fs::read_to_string(&path).unwrap();
    let original = ".Y_RND(sq_field(SQ_RND, i, 0))";
    assert_eq!(text.matches(original).count(), 1);
    std::fs::write(
        &path,
        text.replace(original, ".Y_RND((i == 2) ? 0 : sq_field(SQ_RND, i, 0))"),
    )
    .unwrap();
    let traces = dir.join("traces");
    let o = Cosim {
        vectors: &vectors,
        sim: "icarus",
        arch: "pipelined",
        bubble: "0",
        stall: "0",
        hdl_ref: Some(&hdl),
        reset_data: false,
    }
    .run(&traces);
    assert_eq!(o.status.code(), Some(1));

    let sq1 = hex_words(&vectors.join("probe_sq1.hex"));
    let sq2 = hex_words(&vectors.join("probe_sq2.hex"));
    let truncated: Vec<u64> = sq1.iter().map(|&s| (s * s) >> 16).collect();
    // With no bubbles or stalls the stimulus is the handshake pattern's block of directed
    // episodes (docs/cycle.md; pipelined baseline: L = 8, ii = 1, s = 2), then one vector a
    // cycle. Each episode follows a drain of L + ii + 2 = 11 cycles and lasts 10, 11, 9 and 11
    // cycles; every offer is accepted (the pipeline is empty, or its stall has ended), so the
    // vectors enter at: episode 1 (from cycle 11) 11, 12, 13, 14; episode 2 (from 32) 32 and
    // 32 + L + s = 42; episode 3 (from 54) 54, 55; episode 4 (from 74) 74, 75, 76; then vector
    // j >= 11 at 85 + (j - 11). Each is in the second square's register 5 cycles after it
    // enters (every stall of the block comes later than that).
    let accepted = |j: usize| -> usize {
        const BLOCK: [usize; 11] = [11, 12, 13, 14, 32, 42, 54, 55, 74, 75, 76];
        BLOCK.get(j).copied().unwrap_or(85 + j - BLOCK.len())
    };
    let j = (0..sq1.len())
        .find(|&j| truncated[j] != sq2[j])
        .expect("some square rounds up");
    let cycle = accepted(j) + 5;
    let signal = "tb_specfx.dut.g_pipelined.u_core.g_square[2].y_q";
    let (model, rtl) = (traces.join("model.vcd"), traces.join("rtl.vcd"));
    let want = format!(
        "first difference: cycle {cycle}, {signal} = {:05x} in {}, {:05x} in {}\n",
        sq2[j],
        model.display(),
        truncated[j],
        rtl.display()
    );
    // cosim compared the traces although vectors failed (issue 25): the first differing
    // register follows the failing vectors and their summary, and the failure names it.
    let out = String::from_utf8_lossy(&o.stdout);
    let (vectors_part, traces_part) = out
        .split_once(" failed\n")
        .unwrap_or_else(|| panic!("no summary in {out}"));
    assert!(vectors_part.starts_with("mismatch i="), "{out}");
    assert!(!vectors_part.ends_with(" 0"), "{out}");
    assert!(traces_part.starts_with(&want), "want {want}got {out}");
    assert!(traces_part.ends_with("TRACES DIFFER\n"), "{out}");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&format!(
            "vectors failed; the model's and the RTL's traces first differ at cycle {cycle}, {signal}\n"
        )),
        "{err}"
    );

    let o = trace_compare(&model, &rtl);
    assert_eq!(o.status.code(), Some(1));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.starts_with(&want), "want {want}got {out}");
    assert!(out.contains("g_square[2].r_square.g_regs.g_stage[0].r"));
    assert!(out.ends_with("TRACES DIFFER\n"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Verilator's dump (`--trace`) agrees with the model's too. Verilator stops dumping before
/// the edge that ends the last cycle, so that one cycle is sampled only in the model's trace.
#[test]
fn verilator_traces_agree() {
    for (config, arch) in [
        ("baseline".to_string(), "folded"),
        (config_path("conv_sym_k5.toml"), "pipelined"),
    ] {
        let dir = temp_dir(&format!("verilator-{arch}"));
        let (vectors, n) = write_vectors(&config, "random:120", &dir);
        let traces = dir.join("traces");
        let o = Cosim {
            vectors: &vectors,
            sim: "verilator",
            arch,
            bubble: "0.3",
            stall: "0.3",
            hdl_ref: None,
            reset_data: false,
        }
        .run(&traces);
        ok(&o);
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(out.contains(&format!("{n} passed, 0 failed")), "{out}");
        assert!(out.contains("traces agree"), "{out}");
        let c = compare_files(&traces.join("model.vcd"), &traces.join("rtl.vcd"));
        assert!(c.agrees(), "{c:?}");
        assert!(c.only_first.is_empty() && c.never_known.is_empty(), "{c:?}");
        assert!(c.cycles_compared > n);
        assert_eq!((c.cycles_only_first, c.cycles_only_second), (1, 0));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// A tiny trace: `clk`, `rst`, `cycle` and a 4-bit `v` under `tb_specfx`, `v` taking
/// `values[t]` during cycle t (reset for the first edge); `decl` replaces v's declaration.
fn tiny(values: &[&str], decl: &str, top: bool) -> String {
    let mut s = String::from("$timescale 1ns $end\n");
    if top {
        s.push_str("$scope module TOP $end\n");
    }
    s.push_str("$scope module tb_specfx $end\n$var reg 1 ! clk $end\n$var reg 1 \" rst $end\n");
    s.push_str("$var integer 32 # cycle [31:0] $end\n");
    s.push_str(decl);
    s.push_str("\n$upscope $end\n");
    if top {
        s.push_str("$upscope $end\n");
    }
    // During reset v is 1111, which nobody compares. The edge at 5 releases reset; cycle t
    // runs from the edge at 5 + 10 t to the next, v taking its value in the middle.
    s.push_str("$enddefinitions $end\n#0\n0!\n1\"\nb0 #\nb1111 $\n#5\n1!\n0\"\n");
    for (t, v) in values.iter().enumerate() {
        let start = 5 + 10 * t;
        s.push_str(&format!("#{}\nb{v} $\n", start + 2));
        s.push_str(&format!("#{}\n0!\n", start + 5));
        s.push_str(&format!("#{}\n1!\nb{:b} #\n", start + 10, t + 1));
    }
    s
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn hand_written_traces_check_dont_care_widths_and_exit_codes() {
    let dir = temp_dir("tiny");
    let v4 = "$var wire 4 $ v [3:0] $end";
    let model = write(
        &dir,
        "model.vcd",
        &tiny(&["0001", "x", "1010", "xx11"], v4, false),
    );
    // The RTL's dump under Verilator's TOP scope, with values where the model has x.
    let rtl = write(
        &dir,
        "rtl.vcd",
        &tiny(&["1", "0110", "1010", "0111"], v4, true),
    );
    let o = trace_compare(&model, &rtl);
    ok(&o);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.starts_with("compared 4 signals over 4 cycles;"),
        "{out}"
    );
    assert!(out.ends_with("traces agree\n"));

    // A known bit that differs (cycle 3: xx11 against 0101), and an x in the second file
    // where the first knows the bit (cycle 2).
    let c = compare_files(
        &model,
        &write(
            &dir,
            "b.vcd",
            &tiny(&["0001", "1111", "1010", "0101"], v4, false),
        ),
    );
    assert!(!c.agrees() && c.first_difference.as_ref().unwrap().cycle == 3);
    let c = compare_files(
        &model,
        &write(
            &dir,
            "c.vcd",
            &tiny(&["0001", "0", "x010", "0011"], v4, false),
        ),
    );
    assert_eq!(c.first_difference.as_ref().unwrap().cycle, 2);
    let o = trace_compare(&model, &dir.join("c.vcd"));
    assert_eq!(o.status.code(), Some(1));
    let out = String::from_utf8_lossy(&o.stdout);
    let want = format!(
        "first difference: cycle 2, tb_specfx.v = a in {}, x in {}\n",
        model.display(),
        dir.join("c.vcd").display()
    );
    assert!(out.starts_with(&want), "{out}");
    // x in the first file is don't-care, but not the other way round.
    let c = compare_files(&dir.join("c.vcd"), &model);
    assert_eq!(c.first_difference.as_ref().unwrap().cycle, 1);

    // Widths must match: a 5-bit v is reported and not compared.
    let v5 = "$var wire 5 $ v [4:0] $end";
    let wide = write(
        &dir,
        "wide.vcd",
        &tiny(&["1", "0110", "1010", "0111"], v5, false),
    );
    let o = trace_compare(&model, &wide);
    assert_eq!(o.status.code(), Some(1));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.starts_with(&format!(
        "width differs: tb_specfx.v is 4 bits in {}, 5 bits in {}\n",
        model.display(),
        wide.display()
    )));
    assert!(out.contains("compared 3 signals over 4 cycles;"), "{out}");

    // Bad input: one clear line, exit code 2, nothing on stdout.
    let no_clk = write(
        &dir,
        "no_clk.vcd",
        &tiny(&["1"], v4, false).replace(" clk $end", " clock $end"),
    );
    let garbage = write(&dir, "garbage.vcd", "not a trace\n");
    let missing = dir.join("missing.vcd");
    for (a, b, why) in [
        (&model, &no_clk, "no signal tb_specfx.clk"),
        (&garbage, &model, "not a VCD file"),
        (&model, &missing, "cannot read"),
    ] {
        let o = trace_compare(a, b);
        assert_eq!(o.status.code(), Some(2), "{why}");
        assert!(o.stdout.is_empty());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with("specfx: error: ") && err.contains(why),
            "{err}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A signal in one file only (issue 25): the model's register the RTL's dump lacks is a
/// difference (it was never compared), unless --ignore-missing accepts it or --ignore leaves
/// it out; a register of the RTL in a scope the model has signals in, which the model lacks,
/// too; a variable of 0 bits is refused with its file and line.
#[test]
fn a_signal_in_one_file_only_is_a_difference_unless_ignored() {
    let dir = temp_dir("missing");
    let v4 = "$var wire 4 $ v [3:0] $end";
    let values = ["0001", "0010", "0011"];
    let rtl = write(&dir, "rtl.vcd", &tiny(&values, v4, false));
    // The issue's reproduction: a register `ghost` beside the testbench, 1 from the first
    // cycle on, equal everywhere else.
    let extra = "$scope module extra $end $var reg 1 ~~ ghost $end $upscope $end";
    let ghost_text = tiny(&values, v4, false)
        .replacen("$enddefinitions", &format!("{extra}\n$enddefinitions"), 1)
        .replacen("#5\n1!\n", "#5\n1!\n1~~\n", 1);
    let ghost = write(&dir, "ghost.vcd", &ghost_text);
    let run = |extra_args: &[&str], first: &Path| {
        let mut args = vec!["trace", "compare"];
        args.extend_from_slice(extra_args);
        args.extend([first.to_str().unwrap(), rtl.to_str().unwrap()]);
        specfx(&args)
    };
    let o = run(&[], &ghost);
    assert_eq!(o.status.code(), Some(1));
    let out = String::from_utf8_lossy(&o.stdout);
    // clk, rst, cycle and v compared over cycles 0, 1 and 2; ghost only in the model's.
    assert!(
        out.starts_with(&format!(
            "compared 4 signals over 3 cycles; 1 signals only in {}, 0 only in {}; 0 width mismatches; 0 signals differ\n  only in {}: extra.ghost\n",
            ghost.display(),
            rtl.display(),
            ghost.display()
        )),
        "{out}"
    );
    assert!(
        out.ends_with(
            "TRACES DIFFER: 1 signals missing from one file (--ignore-missing accepts them)\n"
        ),
        "{out}"
    );
    for waiver in [
        &["--ignore-missing"][..],
        &["--ignore", "extra.ghost"],
        &["--ignore", "extra.*"],
    ] {
        let o = run(waiver, &ghost);
        ok(&o);
        assert!(String::from_utf8_lossy(&o.stdout).ends_with("traces agree\n"));
    }
    // Where the RTL has a register of a scope the model covers and the model has not.
    let core = "$scope module dut $end $var wire 1 % a $end";
    let model = write(
        &dir,
        "model.vcd",
        &tiny(&values, &format!("{v4} {core} $upscope $end"), false),
    );
    let with_q = |decl: &str| format!("{v4} {core} {decl} $upscope $end");
    let q = write(
        &dir,
        "q.vcd",
        &tiny(&values, &with_q("$var reg 1 & q $end"), false),
    );
    let o = trace_compare(&model, &q);
    assert_eq!(o.status.code(), Some(1));
    let out = String::from_utf8_lossy(&o.stdout);
    let want = format!(
        "  1 registers only in {}, in scopes {} has signals in: tb_specfx.dut.q\n",
        q.display(),
        model.display()
    );
    assert!(out.contains(&want), "{out}");
    // A wire there is no register; the testbench's own registers are not the RTL's.
    for (name, decl) in [
        ("wire.vcd", with_q("$var wire 1 & q $end")),
        (
            "tb.vcd",
            format!("{v4} $var reg 1 & held $end {core} $upscope $end"),
        ),
    ] {
        let other = write(&dir, name, &tiny(&values, &decl, false));
        let o = trace_compare(&model, &other);
        ok(&o);
        // The figure says why it is no difference.
        let want = format!(
            "  the 1 only in {} are wires, or registers in scopes {} has no signal in: internal to the RTL, not a difference\n",
            other.display(),
            model.display()
        );
        assert!(String::from_utf8_lossy(&o.stdout).contains(&want));
    }

    // A variable of 0 bits: one line naming the file and the line of its declaration (the
    // eighth: $timescale, tb_specfx's scope, clk, rst, cycle, v, $upscope, then extra).
    let zero = write(
        &dir,
        "zero.vcd",
        &ghost_text.replace("reg 1 ~~", "reg 0 ~~"),
    );
    for (a, b) in [(&zero, &rtl), (&rtl, &zero)] {
        let o = trace_compare(a, b);
        assert_eq!(o.status.code(), Some(2));
        assert!(o.stdout.is_empty());
        assert_eq!(
            String::from_utf8_lossy(&o.stderr),
            format!(
                "specfx: error: {}: line 8: $var 'ghost' has width 0 (a variable has at least 1 bit)\n",
                zero.display()
            )
        );
    }
    // An ignored name no signal has is bad input, not a silent waiver.
    let o = run(&["--ignore", "extra.ghots"], &ghost);
    assert_eq!(o.status.code(), Some(2));
    assert!(o.stdout.is_empty());
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("specfx: error: unknown signal to ignore 'extra.ghots'"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The model's trace of the stimulus `specfx cosim --vcd` makes with its defaults (the
/// baseline's vectors, `corner,random:1000`, bubble and stall 0.2) fits the trace's limit in
/// both architectures: the folded one is expected to need about 137,000 cycles, past the
/// 131,072 the limit was.
#[test]
fn the_default_cosim_stimulus_fits_a_trace_in_both_architectures() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let vectors = dir.path().join("vec");
    ok(&specfx(&[
        "vectors",
        "--out",
        vectors.to_str().unwrap(),
        "--cases",
        "corner,random:1000",
        "--seed",
        "1",
    ]));
    for arch in ["pipelined", "folded"] {
        let out = dir.path().join(arch);
        let vcd = dir.path().join(format!("{arch}.vcd"));
        ok(&specfx(&[
            "hdl",
            "stimulus",
            "--vectors",
            vectors.to_str().unwrap(),
            "--arch",
            arch,
            "--out",
            out.to_str().unwrap(),
            "--vcd",
            vcd.to_str().unwrap(),
        ]));
        let cycles = json(&out.join("stim.json"))["n_cycles"].as_u64().unwrap();
        assert!(vcd.is_file() && cycles > 0, "{arch}");
    }
}
