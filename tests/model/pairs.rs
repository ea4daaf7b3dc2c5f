//! `engine::pairs`, what the C ABI and the Python package call: arbitrary (c, n) pairs give the
//! big-integer oracle's bits (outputs by every path of the batch, probes and events), and every
//! input outside the domain is refused by name, before anything is written.

use crate::common;
use crate::common::oracle::oracle_eval;

use rand::{Rng, SeedableRng};
use specfx::engine::pairs::{eval_one, eval_outputs, eval_outputs_vec, eval_probes, Ns};
use specfx::pipeline::Datapath;

/// Configurations at the edges: signed inputs, a 64-bit output, one-bit stages, wrapping,
/// saturating to zero, symmetric rounding, the paper cutoff.
const CONFIGS: &[&str] = &[
    "baseline",
    "conv_sym_k5.toml",
    "wide_signed_out64.toml",
    "narrow_trn_wrap.toml",
    "lint_sq1.toml",
    "lint_narrowest.toml",
    "sat_out.toml",
    "lint_widest.toml",
    // A signed input format: negative codes (c < 0) and codes above 1.0.
    "n = \"16..=40\"\n[c]\nformat = \"s2.14\"\n[d]\nformat = \"s3.14\"\n",
];

fn datapath(name: &str) -> Datapath {
    if name.contains('\n') {
        return specfx::input::datapath_from_toml(name).expect("a valid configuration");
    }
    let arg = if name == "baseline" {
        name.to_string()
    } else {
        common::config_path(name)
    };
    specfx::input::load_datapath(&arg, None).expect("a valid configuration")
}

/// Pairs that take every path of `eval_outputs`: a long run of consecutive codes of one n, a
/// long run of shuffled codes of one n, and short runs of random n, with codes over the whole
/// input format (above 1.0 included).
fn pairs(dp: &Datapath, seed: u64) -> (Vec<i64>, Vec<u32>) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let ns = dp.config().n.values();
    let codes = dp.input_codes();
    let (lo, hi) = (*codes.start(), *codes.end());
    let mut cs = Vec::new();
    let mut n = Vec::new();
    let n0 = ns[rng.gen_range(0..ns.len())];
    let start = rng.gen_range(lo..=hi);
    for i in 0..3000 {
        cs.push((start + i).min(hi));
        n.push(n0);
    }
    // A run of consecutive codes ending at the largest code (i64::MAX for u1.62).
    for i in 0..100 {
        cs.push((hi - 99).max(lo) + i.min(hi - lo));
        n.push(n0);
    }
    let n1 = ns[rng.gen_range(0..ns.len())];
    for _ in 0..3000 {
        cs.push(rng.gen_range(lo..=hi));
        n.push(n1);
    }
    for _ in 0..3000 {
        cs.push(rng.gen_range(lo..=hi));
        n.push(ns[rng.gen_range(0..ns.len())]);
    }
    (cs, n)
}

#[test]
fn pairs_give_the_oracles_bits() {
    for (seed, name) in CONFIGS.iter().enumerate() {
        let dp = datapath(name);
        let (cs, ns) = pairs(&dp, seed as u64);
        let mut out = vec![0; cs.len()];
        eval_outputs(&dp, &cs, Ns::Each(&ns), &mut out).expect("pairs in the domain");
        let probes = eval_probes(&dp, &cs, Ns::Each(&ns)).expect("pairs in the domain");
        let fused = eval_outputs_vec(&dp, &cs, Ns::Each(&ns)).expect("pairs in the domain");
        assert_eq!(fused, out, "{name}: eval_outputs_vec");
        for (i, (&c, &n)) in cs.iter().zip(&ns).enumerate() {
            let nc = dp.constants_for(n).expect("n in the set");
            let want = oracle_eval(dp.config(), nc, c);
            let k = want.values.len();
            assert_eq!(
                out[i],
                want.values[k - 1],
                "{name}: out of c = {c}, n = {n}"
            );
            assert_eq!(
                &probes[i].values[..k],
                &want.values[..],
                "{name}: c = {c}, n = {n}"
            );
            assert_eq!(
                &probes[i].events[..k],
                &want.events[..],
                "{name}: c = {c}, n = {n}"
            );
            assert_eq!(probes[i].cut, want.cut, "{name}: c = {c}, n = {n}");
        }
        // One n for all: the same outputs as that n given for each.
        let n0 = ns[0];
        let mut one = vec![0; 3000];
        eval_outputs(&dp, &cs[..3000], Ns::One(n0), &mut one).expect("in the domain");
        assert_eq!(one, out[..3000], "{name}: Ns::One");
    }
}

#[test]
fn inputs_outside_the_domain_are_refused_by_name_and_nothing_is_written() {
    let dp = datapath("baseline");
    // u1.15: codes 0..=65535; n = 16..=1024.
    let mut out = vec![-1; 3];
    let err = eval_outputs(&dp, &[0, 65536, 5], Ns::One(16), &mut out).unwrap_err();
    assert_eq!(
        err.to_string(),
        "c[1] = 65536 is not a code of the input format u1.15 (expected 0..=65535)"
    );
    let err = eval_outputs(&dp, &[0, 1, 2], Ns::Each(&[16, 2000, 16]), &mut out).unwrap_err();
    assert_eq!(
        err.to_string(),
        "n[1] = 2000 is not in the configuration's exponent set 16..=1024"
    );
    let err = eval_outputs(&dp, &[0, 1, 2], Ns::Each(&[16, 16]), &mut out).unwrap_err();
    assert_eq!(
        err.to_string(),
        "c has 3 elements and n has 2: expected as many (or one n)"
    );
    let err = eval_outputs(&dp, &[0, 1], Ns::One(16), &mut out).unwrap_err();
    assert_eq!(
        err.to_string(),
        "the output has 3 elements and c has 2: expected as many"
    );
    assert_eq!(out, [-1, -1, -1], "nothing written");
    // The one-pass batch names the same input: the first code outside, else the first n.
    let many_c: Vec<i64> = (0..200_000).map(|i| i % 60_000).collect();
    let mut many_n = vec![16u32; 200_000];
    many_n[150_000] = 2000;
    let mut bad_c = many_c.clone();
    bad_c[190_000] = -5;
    let err = eval_outputs_vec(&dp, &bad_c, Ns::Each(&many_n)).unwrap_err();
    assert_eq!(
        err.to_string(),
        "c[190000] = -5 is not a code of the input format u1.15 (expected 0..=65535)"
    );
    let err = eval_outputs_vec(&dp, &many_c, Ns::Each(&many_n)).unwrap_err();
    assert_eq!(
        err.to_string(),
        "n[150000] = 2000 is not in the configuration's exponent set 16..=1024"
    );
    assert!(eval_outputs_vec(&dp, &many_c, Ns::One(7)).is_err());
    assert!(eval_outputs_vec(&dp, &many_c, Ns::Each(&many_n[1..])).is_err());
    assert!(eval_probes(&dp, &[-1], Ns::One(16)).is_err());
    assert_eq!(
        eval_one(&dp, -1, 16).unwrap_err().to_string(),
        "c = -1 is not a code of the input format u1.15 (expected 0..=65535)"
    );
    // A signed input format takes negative codes, down to its most negative one.
    let signed = datapath(CONFIGS[CONFIGS.len() - 1]);
    assert!(eval_one(&signed, -32768, 16).is_ok());
    assert_eq!(
        eval_one(&signed, -32769, 16).unwrap_err().to_string(),
        "c = -32769 is not a code of the input format s2.14 (expected -32768..=32767)"
    );
}
