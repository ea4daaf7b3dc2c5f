//! The per-n squaring depth (`docs/arithmetic.md` section 3.1.0): the depths, constants and
//! bypassed stages checked against the minimax table's text, the document's formulas and a
//! hand computation, and the validation's messages.

use specfx::pipeline::{Config, Datapath, Depth, DepthStep, Variant};

/// The table `data/minimax.csv` read as text: (k, n) -> (a, b, max_abs_err, plain_max_abs_err).
fn table() -> std::collections::HashMap<(u32, u32), [f64; 4]> {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/data/minimax.csv"))
        .expect("the minimax table is in the repository");
    let mut rows = std::collections::HashMap::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let num = |i: usize| f[i].parse::<f64>().expect("a number");
        rows.insert(
            (f[0].parse().unwrap(), f[1].parse().unwrap()),
            [num(2), num(3), num(4), num(5)],
        );
    }
    rows
}

fn config(text: &str) -> Config {
    Config::from_toml(text).expect("valid configuration")
}

#[test]
fn best_depths_have_the_smallest_floor_of_the_table() {
    let t = table();
    for (variant, column) in [(Variant::Minimax, 2), (Variant::Plain, 3)] {
        let mut cfg = Config::baseline();
        cfg.k = 6;
        cfg.square = vec![cfg.square[0]; 6];
        cfg.variant = variant;
        cfg.depth = Depth::Best;
        let dp = Datapath::new(cfg).expect("valid");
        for nc in dp.constants() {
            // The first j of the smallest floor.
            let floors: Vec<f64> = (1..=6).map(|j| t[&(j, nc.n)][column]).collect();
            let min = floors.iter().copied().fold(f64::INFINITY, f64::min);
            let want = 1 + floors.iter().position(|&e| e == min).unwrap() as u32;
            assert_eq!(nc.depth, want, "{variant:?} n = {}", nc.n);
        }
    }
}

#[test]
fn per_n_constants_are_those_of_the_lobe_used() {
    let t = table();
    let steps = "depth = [{ from = 16, j = 3 }, { from = 40, j = 5 }, { from = 300, j = 2 }]\n";
    let plain = Datapath::new(config(&format!("k = 5\n{steps}"))).unwrap();
    let minimax = Datapath::new(config(&format!(
        "k = 5\nvariant = \"minimax\"\n{steps}[minimax]\na_format = \"u9.16\"\n"
    )))
    .unwrap();
    for n in [16, 39, 40, 299, 300, 1024] {
        let j = if n < 40 {
            3
        } else if n < 300 {
            5
        } else {
            2
        };
        let p = plain.constants_for(n).unwrap();
        assert_eq!(p.depth, j, "n = {n}");
        // n / 2^j with k = 5 fraction bits.
        assert_eq!((p.slope_raw, p.slope_frac), (i64::from(n) << (5 - j), 5));
        // The exact Phong coefficient of the lobe with m = 2^j (n >= m here), in the
        // document's operation order.
        let (m, nf, pi) = (f64::from(1u32 << j), f64::from(n), std::f64::consts::PI);
        assert_eq!(
            p.coef,
            1.0 / (2.0 * pi * ((1.0 / (m + 1.0)) / (nf / m))),
            "n = {n}"
        );
        let mm = minimax.constants_for(n).unwrap();
        assert_eq!(mm.depth, j);
        let [a, b, _, _] = t[&(j, n)];
        assert_eq!((mm.slope, mm.offset), (a, a + b), "n = {n}");
    }
}

#[test]
fn a_bypassed_stage_requantizes_its_input() {
    // k = 3, every n squares once: sq1 = Q(b^2), then sq2 and sq3 are sq1 brought into their
    // own formats. n = 2, m = 2: b = (2/2)(c - 1) + 1 = c, exact.
    let dp = Datapath::new(config(
        "k = 3\nn = \"2\"\ndepth = [{ from = 1, j = 1 }]\n\
         [[square]]\nformat = \"u1.16\"\n\
         [[square]]\nformat = \"u1.12\"\nrounding = \"TRN\"\n\
         [[square]]\nformat = \"u1.14\"\n",
    ))
    .unwrap();
    let nc = dp.constants_for(2).unwrap();
    // c = 0.7 + ... : code 22937 of u1.15. b = 22937 * 2 (u1.16).
    let p = dp.eval(22937, nc);
    let b = 22937i64 * 2;
    assert_eq!(p.values[2], b);
    // b^2 has 32 fraction bits; RND to 16: floor((b^2 + 2^15) / 2^16).
    let sq1 = (b * b + (1 << 15)) >> 16;
    assert_eq!(p.values[3], sq1);
    // sq2: TRN from 16 to 12 fraction bits; sq3: 12 to 14, exact (a left shift).
    assert_eq!(p.values[4], sq1 >> 4);
    assert_eq!(p.values[5], (sq1 >> 4) << 2);
}

#[test]
fn rules_that_leave_an_exponent_without_a_depth_are_refused() {
    let refused = |text: &str| {
        Datapath::new(config(text))
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        refused("k = 6\ndepth = [{ from = 16, j = 4 }, { from = 40, j = 7 }]\n"),
        "depth: step 2 (from = 40): expected j in 1..=k = 1..=6, got 7"
    );
    assert_eq!(
        refused("depth = [{ from = 20, j = 4 }]\n"),
        "depth: the first step starts at n = 20, after the set's first exponent 16: expected from <= 16"
    );
    assert_eq!(
        refused("depth = [{ from = 16, j = 4 }, { from = 16, j = 3 }]\n"),
        "depth: step 2 starts at n = 16, not after the step before (from = 16): expected increasing from"
    );
    assert_eq!(
        refused("depth = []\n"),
        "depth: expected at least one { from = N, j = J } step"
    );
    assert_eq!(
        refused("depth = \"best\"\nn = \"16..=5000\"\n"),
        "depth: \"best\" ranks the depths by the minimax table's floors, which end at n = 4096; the set reaches n = 5000"
    );
    // Parse errors say what depth and a step are, once each ("expected expected" and
    // "expected u32" before).
    let parse = |text: &str| Config::from_toml(text).unwrap_err().to_string();
    let step = "(a step is { from = N, j = J }: from exponent N on, J squarings)";
    for (text, message) in [
        (
            "depth = \"deep\"\n",
            "line 1: depth: expected \"fixed\", \"best\" or a list of steps { from = N, j = J }, got string \"deep\"".to_string(),
        ),
        (
            "depth = 4\n",
            "line 1: depth: expected \"fixed\", \"best\" or a list of steps { from = N, j = J }, got integer 4".to_string(),
        ),
        (
            "depth = [{ from = -5, j = 3 }]\n",
            format!("line 1: depth: step 1: from = -5: expected the step's first exponent, a whole number >= 0 {step}"),
        ),
        (
            "depth = [{ from = 1, j = 3 }, { from = 16, j = -1 }]\n",
            format!("line 1: depth: step 2: j = -1: expected a number of squarings, a whole number in 1..=k {step}"),
        ),
        (
            "depth = [{ from = 16 }]\n",
            format!("line 1: depth: step 1: missing `j` {step}"),
        ),
        (
            "depth = [3]\n",
            format!("line 1: depth: step 1: expected a table {{ from = N, j = J }}, got integer 3 {step}"),
        ),
        (
            "depth = [{ from = 16, depth = 4 }]\n",
            format!("line 1: depth: step 1: unknown key `depth`, expected `from` and `j` {step}"),
        ),
    ] {
        assert_eq!(parse(text), message, "{text}");
        assert!(!parse(text).contains("expected expected"), "{text}");
    }
}

#[test]
fn depth_rules_round_trip_and_fixed_is_left_out() {
    let mut c = Config::baseline();
    assert!(!c.to_toml().contains("depth"));
    for depth in [
        Depth::Best,
        Depth::Steps(vec![
            DepthStep { from: 1, j: 2 },
            DepthStep { from: 100, j: 4 },
        ]),
    ] {
        c.depth = depth;
        assert_eq!(Config::from_toml(&c.to_toml()).unwrap(), c);
    }
}

/// `docs/arithmetic.md` section 3.3 as written: its Python reference code, with the plain
/// variant's per-n constants computed by the very expression the section gives for
/// `slope_raw` (read from the document), equals `Datapath::eval` on every probe, at exponents
/// that square twice (two stages bypassed) and four times. The section once gave
/// `slope_raw = n`, the fixed depth's constant, which this finds.
#[test]
fn the_documented_reference_code_follows_the_per_n_depth() {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/arithmetic.md"))
        .expect("the document is in the repository");
    let section = &doc[doc.find("### 3.3 Reference code").expect("section 3.3")..];
    let section = &section[..section.find("\n## 4.").expect("section 4 follows")];
    let code_start = section.find("```python\n").expect("a Python block") + "```python\n".len();
    let code_len = section[code_start..].find("```").expect("the block ends");
    let code = &section[code_start..code_start + code_len];
    let after = &section[code_start + code_len..];
    let plain = &after[after.find("`plain` variant").expect("the plain constants")..];
    let rule_start = plain.find("`slope_raw = ").expect("slope_raw's rule") + "`slope_raw = ".len();
    let rule = &plain[rule_start..rule_start + plain[rule_start..].find('`').unwrap()];

    let dp = Datapath::new(config(
        "k = 4\nn = \"16,40,63,64,100\"\ndepth = [{ from = 16, j = 2 }, { from = 64, j = 4 }]\n",
    ))
    .unwrap();
    let codes = [0i64, 1000, 20000, 30000, 32000, 32767, 32768];
    let mut cases = String::new();
    let mut expected = String::new();
    for nc in dp.constants() {
        for &c in &codes {
            cases.push_str(&format!(
                "({}, {}, {}, {}),\n",
                nc.n, nc.depth, nc.coef_raw, c
            ));
            let p = dp.eval(c, nc);
            let values: Vec<String> = p.values[..9].iter().map(i64::to_string).collect();
            expected.push_str(&values.join(" "));
            expected.push('\n');
        }
    }
    let driver = format!(
        r#"{code}
from types import SimpleNamespace as NS
spec = lambda fmt: (fmt, "RND", "SAT")
cfg = NS(c=(False, 1, 15), d=(True, 1, 15), t=spec((True, 2, 16)), b=spec((False, 1, 16)),
         square=[spec((False, 1, 16))] * 4, out=spec((False, 8, 16)), coef_format=(False, 8, 16),
         cutoff="clamp")
k = 4
for n, j, coef_raw, c in [{cases}]:
    K = NS(depth=j, slope_raw=({rule}), slope_frac=k, offset_raw=1, offset_frac=0,
           threshold=None, coef_raw=coef_raw)
    values, events, cut, clamped = evaluate(cfg, K, c)
    print(" ".join(str(v) for v in values))
"#
    );
    let out = std::process::Command::new("python3")
        .arg("-c")
        .arg(&driver)
        .output()
        .expect("python3 runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let got = String::from_utf8(out.stdout).unwrap();
    assert_eq!(got, expected, "the document's slope_raw rule: {rule}");
}
