//! The batch engine: its output fingerprint equals one computed from `eval` code by code, and
//! is the same with one and two threads.

use crate::common;

use specfx::engine::{items, output_sum, ITEM_CODES};
use specfx::pipeline::{Config, Datapath};

/// The fingerprint of `OutputSum`, from `eval` one code at a time.
fn slow_sum(dp: &Datapath, codes: std::ops::Range<i64>) -> u64 {
    let mut sum = 0u64;
    for nc in dp.constants() {
        for c in codes.clone() {
            let out = dp.eval(c, nc).values[dp.stage_out()];
            let w = (c as u64).wrapping_add(1).wrapping_mul(u64::from(nc.n));
            sum = sum.wrapping_add((out as u64).wrapping_mul(w));
        }
    }
    sum
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

#[test]
fn output_sum_equals_the_scalar_model_with_any_thread_count() {
    let configs = [
        Config::baseline(),
        Config::from_toml("cutoff = \"paper\"\nk = 5\n").unwrap(),
        // t wraps: the cut codes are no prefix and every code is evaluated.
        Config::from_toml("[t]\nformat = \"s2.12\"\noverflow = \"WRAP\"\n").unwrap(),
        Config::from_toml("variant = \"minimax\"\n[b]\nformat = \"u1.24\"\n").unwrap(),
        // A signed input: the cut prefix starts at negative codes.
        Config::from_toml("[c]\nformat = \"s2.10\"\n[d]\nformat = \"s3.11\"\n").unwrap(),
    ];
    for mut cfg in configs {
        cfg.n = "16,17,100,555,1024".parse().unwrap();
        let dp = Datapath::new(cfg).unwrap();
        let codes = (*dp.input_codes().start()).max(-3000)..dp.one_code() + 100;
        let want = slow_sum(&dp, codes.clone());
        for threads in [1, 2] {
            let got = in_pool(threads, || output_sum(&dp, codes.clone()));
            assert_eq!(got.checksum, want, "{} threads", threads);
            assert_eq!(got.evaluations, 5 * (codes.end - codes.start) as u64);
        }
    }
}

#[test]
fn items_cover_every_code_once_in_order() {
    let mut cfg = Config::baseline();
    cfg.n = "16,20".parse().unwrap();
    let dp = Datapath::new(cfg).unwrap();
    let all = items(&dp, -5..(2 * ITEM_CODES as i64 + 7));
    assert_eq!(all.len(), 6);
    for pair in all.windows(2) {
        let same_n = pair[0].n_idx == pair[1].n_idx;
        assert!(!same_n || pair[0].codes.end == pair[1].codes.start);
    }
    assert_eq!(all[0].codes.start, -5);
    assert_eq!(all[2].codes.end, 2 * ITEM_CODES as i64 + 7);
    assert_eq!(all[3].n_idx, 1);
}

#[test]
fn the_throughput_command_prints_the_checksum_of_the_outputs() {
    let mut cfg = Config::baseline();
    cfg.n = "16..=20".parse().unwrap();
    let dp = Datapath::new(cfg).unwrap();
    let want = slow_sum(&dp, 0..32_769);
    for threads in ["1", "2"] {
        let run = common::specfx(&[
            "throughput",
            "--n",
            "16..=20",
            "--threads",
            threads,
            "--repeat",
            "1",
            "--json",
        ]);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
        assert_eq!(v["checksum"], want.to_string());
        assert_eq!(v["evaluations"], 5 * 32_769);
        assert_eq!(v["threads"], threads.parse::<u64>().unwrap());
    }
    let bad = common::specfx(&["throughput", "--threads", "0"]);
    assert_eq!(bad.status.code(), Some(2));
    assert_eq!(String::from_utf8_lossy(&bad.stderr).lines().count(), 1);
}

#[test]
fn check_and_budget_are_the_same_with_one_and_two_threads() {
    let mut cfg = Config::from_toml("cutoff = \"paper\"\n").unwrap();
    cfg.n = "16,17,100,555,1024".parse().unwrap();
    let dp = Datapath::new(cfg).unwrap();
    let one = in_pool(1, || specfx::analysis::check::check(&dp).unwrap());
    let two = in_pool(2, || specfx::analysis::check::check(&dp).unwrap());
    assert_eq!(one, two);
    let one = in_pool(1, || specfx::analysis::budget::analyse(&dp, None).unwrap());
    let two = in_pool(2, || specfx::analysis::budget::analyse(&dp, None).unwrap());
    assert_eq!(one, two);
}

/// The stability map of a datapath (some exponents it cannot hold, a wrapping narrow one with
/// per-element events) and the trade-off's accuracy figures are folded from the engine's
/// stream in n order: the same with one and two threads.
#[test]
fn stability_and_tradeoff_accuracy_are_the_same_with_one_and_two_threads() {
    use specfx::analysis::stability::{map, narrow_datapath, Grid, MapPath};
    use specfx::fixed::Overflow;
    let grid = Grid {
        n: "1..=40,500,4000".parse().unwrap(),
        ..Grid::default()
    };
    let paths = [
        MapPath::Fixed(Box::new(Config::baseline())),
        MapPath::Fixed(Box::new(narrow_datapath(Overflow::Wrap))),
    ];
    let one = in_pool(1, || map(&paths, &grid, &|_, _| {}).unwrap());
    let two = in_pool(2, || map(&paths, &grid, &|_, _| {}).unwrap());
    assert_eq!(one, two);
    let dp = Datapath::new(specfx::analysis::tradeoff::fixed_config(10)).unwrap();
    // A clock that reads 1 s, so the speed figure is the same too.
    let figures = || {
        let mut clock = |f: &mut dyn FnMut()| {
            f();
            1.0
        };
        specfx::analysis::tradeoff::fixed_figures(&dp, &mut clock)
    };
    let (one, two) = (in_pool(1, figures), in_pool(2, figures));
    assert!(one.per_n_max_abs_err.iter().all(|&e| e > 0.0));
    assert_eq!(one, two);
}

/// A sweep point (the check's output figures the sweep and the optimiser compare) is the same
/// with one and two threads.
#[test]
fn a_sweep_point_is_the_same_with_one_and_two_threads() {
    use specfx::analysis::sweep::{evaluate, Space};
    let space = Space::from_toml("n = \"16..=300\"\n[vary]\nk = [3, 4]\n").unwrap();
    for index in 0..2 {
        let one = in_pool(1, || evaluate(&space, index));
        let two = in_pool(2, || evaluate(&space, index));
        assert!(one.shape_total_max_abs.is_some());
        assert_eq!(one, two);
    }
}

/// A sweep's points evaluated through one `Evaluator` (rows of cos^n and f64 floors shared
/// between points, the floors over the codes above the f64 model's own cut prefix) give the
/// figures of the plain, uncached `check_outputs` of each point: points that share the
/// floors (same k, other formats), that do not (other k and cutoffs), a cutoff that leaves no
/// f64 prefix (none), and the same evaluator for every point in turn.
#[test]
fn a_sweeps_shared_evaluator_gives_each_points_own_figures() {
    use specfx::analysis::check::check_outputs;
    use specfx::analysis::sweep::{Evaluator, Space};
    let space = Space::from_toml(
        "n = \"16,17,40,333,1024\"\n[vary]\nk = [3, 5]\ncutoff = [\"clamp\", \"paper\", \"none\"]\n\"square.frac\" = [6, 15]\n",
    )
    .unwrap();
    let shared = Evaluator::new(&space);
    for index in 0..space.n_points() {
        let got = shared.evaluate(index);
        let dp = Datapath::new(space.point(index).unwrap().0).unwrap();
        let want = check_outputs(&dp).unwrap();
        let label = &got.values;
        assert_eq!(
            got.shape_total_max_abs,
            Some(want.shape_total_max_abs),
            "{label}"
        );
        assert_eq!(
            got.shape_quant_max_abs,
            Some(want.shape_quant_max_abs),
            "{label}"
        );
        assert_eq!(got.out_max_ulp, Some(want.out_max_ulp), "{label}");
        assert_eq!(
            got.out_correctly_rounded,
            Some(want.out_correctly_rounded),
            "{label}"
        );
        assert_eq!(got.monotonic, Some(want.monotonic), "{label}");
    }
}

/// cos^n of a code follows one rule everywhere: 0 at and below c = 0 (the lobe is
/// max(0, c)^n), so a signed input's negative codes give 0, not NaN, to every analysis
/// streaming the engine's `ln c` (the budget's targets among them); above 0, `c^n` by `powi`.
#[test]
fn cos_n_of_a_signed_inputs_codes_is_zero_at_and_below_zero() {
    let toml = "name = \"signed_c\"\n[c]\nformat = \"s2.15\"\n[d]\nformat = \"s3.15\"\n";
    let dp = Datapath::new(Config::from_toml(toml).unwrap()).unwrap();
    let codes = specfx::engine::Codes::up_to_one(&dp);
    assert_eq!(codes.codes[0], -65536, "the stream starts at c = -2");
    let lsb = 2f64.powi(-15);
    for n in [1, 2, 16, 1024] {
        for (&k, &ln) in codes.codes.iter().zip(&codes.ln_c).step_by(97) {
            let got = (f64::from(n) * ln).exp();
            let c = k as f64 * lsb;
            let want = if c <= 0.0 { 0.0 } else { c.powi(n) };
            assert!(
                (got - want).abs() <= 1e-12 * want.max(1e-300),
                "n = {n}, c = {c}: {got} against {want}"
            );
        }
    }
}
