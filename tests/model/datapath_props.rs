//! Properties of the datapath on random configurations: the batch kernels equal the plain
//! model bit for bit, and TOML round trips. Two generators: everyday configurations, and
//! configurations at the edges of what validation accepts (fraction bits from -300 to 300,
//! shifts of 62 to 600 bits, 64-bit and one-bit formats), where the batch plan must fall back
//! to the exact kernel.

use crate::common::oracle;

use proptest::prelude::*;
use specfx::fixed::{Event, Format, Overflow, Rounding};
use specfx::nset::NSet;
use specfx::pipeline::{
    CoefSpec, Config, Datapath, Depth, DepthStep, FormatSpec, LatencySpec, MinimaxSpec,
    OutputScratch, ProbeColumns, StageSpec, Variant,
};
use specfx::reference::lobe::Cutoff;
use specfx::reference::normalisation::{CoefSource, Form};

fn fmt(signed: bool, int_bits: i32, frac_bits: i32) -> Format {
    Format::new(signed, int_bits, frac_bits).unwrap()
}

fn stage() -> impl Strategy<Value = StageSpec> {
    (
        any::<bool>(),
        1i32..=3,
        2i32..=22,
        prop::sample::select(Rounding::ALL.to_vec()),
        prop::sample::select(Overflow::ALL.to_vec()),
    )
        .prop_map(|(signed, i, f, rounding, overflow)| StageSpec {
            format: fmt(signed, i + i32::from(signed), f),
            rounding,
            overflow,
        })
}

/// What a depth rule is drawn from: its kind (fixed, best or steps), the later steps
/// (`from` -> a depth index) and the first step's depth index.
type DepthDraw = (u8, std::collections::BTreeMap<u32, u32>, u32);

fn depth_draw() -> impl Strategy<Value = DepthDraw> {
    (
        0u8..=2,
        prop::collection::btree_map(2u32..=300, 0u32..7, 0..=2),
        0u32..7,
    )
}

/// The depth rule of a draw for a datapath of `k` stages: fixed, best, or up to three steps
/// from n = 1 (so they cover every exponent the generators draw) with depths in 1..=k.
fn depth_rule((kind, later, first): &DepthDraw, k: u32) -> Depth {
    match kind {
        0 => Depth::Fixed,
        1 => Depth::Best,
        _ => Depth::Steps(
            std::iter::once((1, *first))
                .chain(later.iter().map(|(&f, &j)| (f, j)))
                .map(|(from, j)| DepthStep { from, j: 1 + j % k })
                .collect(),
        ),
    }
}

prop_compose! {
    fn config()(
        k in 1u32..=7,
        cutoff in prop::sample::select(Cutoff::ALL.to_vec()),
        minimax in any::<bool>(),
        signed_c in any::<bool>(),
        fc in 3i32..=12,
        extra_d in 0i32..=2,
        t_int in 1i32..=9,
        t_frac in 2i32..=20,
        t_modes in (prop::sample::select(Rounding::ALL.to_vec()), prop::sample::select(Overflow::ALL.to_vec())),
        b in stage(),
        squares in prop::collection::vec(stage(), 7),
        out in stage(),
        form in prop::sample::select(Form::ALL.to_vec()),
        source in prop::sample::select(CoefSource::ALL.to_vec()),
        coef_frac in 2i32..=14,
        coef_rounding in prop::sample::select(Rounding::ALL.to_vec()),
        ns in prop::collection::btree_set(1u32..=300, 1..=3),
        lat in (1u32..=4, 1u32..=4, 1u32..=4),
        depth in depth_draw(),
    ) -> Config {
        let n_text: Vec<String> = ns.iter().map(|n| n.to_string()).collect();
        let c = if signed_c { fmt(true, 2, fc) } else { fmt(false, 1, fc) };
        let d = fmt(true, if signed_c { 3 } else { 1 }, fc + extra_d);
        Config {
            name: "random".into(),
            variant: if minimax { Variant::Minimax } else { Variant::Plain },
            k,
            depth: depth_rule(&depth, k),
            cutoff,
            n: n_text.join(",").parse::<NSet>().unwrap(),
            c: FormatSpec { format: c },
            d: FormatSpec { format: d },
            t: StageSpec { format: fmt(true, t_int, t_frac), rounding: t_modes.0, overflow: t_modes.1 },
            b,
            square: squares[..k as usize].to_vec(),
            coef: CoefSpec { form, source, format: fmt(false, 9, coef_frac), rounding: coef_rounding },
            out,
            minimax: MinimaxSpec {
                a_format: fmt(false, 8, 12),
                offset_format: fmt(false, 2, 14),
                rounding: Rounding::Rnd,
            },
            latency: LatencySpec { sub: lat.0, mul: lat.1, add: lat.2 },
            arch: None,
        }
    }
}

/// Fraction bits weighted towards the edges: far negative, around zero, far positive.
fn edge_frac() -> impl Strategy<Value = i32> {
    prop_oneof![-300i32..=-40, -40i32..=40, 40i32..=300, Just(62), Just(-62)]
}

/// A format of any accepted width (1 to 64 bits, unsigned up to 63) with edge fraction bits.
fn edge_format() -> impl Strategy<Value = Format> {
    (
        any::<bool>(),
        prop_oneof![1u32..=4, 5u32..=40, 41u32..=64],
        edge_frac(),
    )
        .prop_map(|(signed, width, frac)| {
            let width = if signed { width } else { width.min(63) };
            fmt(signed, width as i32 - frac, frac)
        })
}

fn edge_stage() -> impl Strategy<Value = StageSpec> {
    (
        edge_format(),
        prop::sample::select(Rounding::ALL.to_vec()),
        prop::sample::select(Overflow::ALL.to_vec()),
    )
        .prop_map(|(format, rounding, overflow)| StageSpec {
            format,
            rounding,
            overflow,
        })
}

/// A stage that is either an everyday one or an edge one, so that configurations mix both
/// and enough of them pass validation.
fn mixed_stage() -> impl Strategy<Value = StageSpec> {
    prop_oneof![stage(), edge_stage()]
}

prop_compose! {
    fn edge_config()(
        base in config(),
        wide_d in 0i32..=40,
        t in mixed_stage(),
        b in mixed_stage(),
        squares in prop::collection::vec(mixed_stage(), 7),
        out in mixed_stage(),
        coef_frac in prop_oneof![-3i32..=2, 2i32..=20, 20i32..=54],
        a_frac in 4i32..=40,
    ) -> Config {
        let mut cfg = base;
        let c = cfg.c.format;
        cfg.d.format = fmt(true, c.int_bits() + 1, c.frac_bits() + wide_d);
        cfg.t = t;
        cfg.b = b;
        cfg.square = squares[..cfg.k as usize].to_vec();
        cfg.out = out;
        cfg.coef.format = fmt(false, 9, coef_frac);
        cfg.minimax.a_format = fmt(false, 8, a_frac);
        cfg
    }
}

/// Every code of a small input format, or a spread of codes and both ends of a wide one.
fn codes_of(dp: &Datapath) -> Vec<i64> {
    let codes = dp.input_codes();
    let (lo, hi) = (*codes.start(), *codes.end());
    if hi - lo <= 20_000 {
        return codes.collect();
    }
    let step = (hi - lo) / 10_000;
    let one = dp.one_code();
    let mut v: Vec<i64> = (0..=10_000).map(|i| lo + i * step).collect();
    v.extend([hi, one - 1, one, one + 1]);
    v.sort_unstable();
    v.dedup();
    v
}

/// `eval_batch` against `eval` on every code of `codes_of`, events included.
fn batch_equals_scalar(dp: &Datapath) -> Result<(), TestCaseError> {
    let codes = codes_of(dp);
    let mut cols = ProbeColumns::default();
    for nc in dp.constants() {
        dp.eval_batch(nc, &codes, &mut cols);
        let mut counts = vec![[0u64; 3]; dp.stages().len()];
        for (i, &code) in codes.iter().enumerate() {
            let p = dp.eval(code, nc);
            let row = cols.row(i);
            prop_assert_eq!(&row.values[..], &p.values[..], "n={} code={}", nc.n, code);
            prop_assert_eq!(row.cut, p.cut);
            prop_assert_eq!(row.input_clamped, p.input_clamped);
            for (stage_idx, e) in p.events.iter().take(dp.stages().len()).enumerate() {
                match e {
                    Event::None => {}
                    Event::Wrapped => counts[stage_idx][0] += 1,
                    Event::Saturated => counts[stage_idx][1] += 1,
                    Event::Zeroed => counts[stage_idx][2] += 1,
                }
            }
        }
        prop_assert_eq!(&counts, &cols.event_counts, "n={}", nc.n);
    }
    Ok(())
}

/// `eval_outputs_range` (dead prefix filled, squaring chain tabulated) and `eval_outputs` against
/// `eval`'s output on every code of a small input format, or a window around 1.0 and both ends
/// of a wide one.
fn outputs_equal_scalar(dp: &Datapath) -> Result<(), TestCaseError> {
    let all = dp.input_codes();
    let (lo, hi) = (*all.start(), *all.end());
    let ranges = if hi - lo <= 20_000 {
        std::iter::once(lo..hi + 1).collect::<Vec<_>>()
    } else {
        let one = dp.one_code();
        vec![lo..lo + 3000, one - 3000..one + 3000, hi - 3000..hi + 1]
    };
    let mut scratch = OutputScratch::default();
    for nc in dp.constants() {
        for range in &ranges {
            let len = (range.end - range.start) as usize;
            let mut got = vec![0; len];
            dp.eval_outputs_range(nc, range.clone(), &mut got, &mut scratch);
            let codes: Vec<i64> = range.clone().collect();
            let mut plain = vec![0; len];
            dp.eval_outputs(nc, &codes, &mut plain, &mut scratch);
            for (i, &code) in codes.iter().enumerate() {
                let want = dp.eval(code, nc).values[dp.stage_out()];
                prop_assert_eq!(got[i], want, "range: n={} code={}", nc.n, code);
                prop_assert_eq!(plain[i], want, "codes: n={} code={}", nc.n, code);
            }
        }
    }
    Ok(())
}

/// The corner codes of `golden::cases` (found by bisection where the cut is a proven prefix)
/// against a brute-force scan of `eval`'s cut flag over every code up to 1.0.
fn corners_equal_brute_force(dp: &Datapath) -> Result<(), TestCaseError> {
    let codes = dp.input_codes();
    let (lo, hi) = (*codes.start(), *codes.end());
    if hi - lo > 20_000 {
        return Ok(());
    }
    let one = dp.one_code();
    for nc in dp.constants() {
        let got = specfx::golden::cases::corner_codes(dp, nc.n).codes;
        let mut want = std::collections::BTreeSet::new();
        for c in [lo, lo + 1, 0, 1, one - 1, one, one + 1, hi - 1, hi] {
            want.insert(c);
        }
        for c in lo + 1..=hi.min(one) {
            if dp.eval(c, nc).cut != dp.eval(c - 1, nc).cut {
                want.extend([c - 2, c - 1, c, c + 1]);
            }
        }
        want.retain(|c| (lo..=hi).contains(c));
        prop_assert_eq!(got, want, "n={}", nc.n);
    }
    Ok(())
}

/// The output-only check (without and with the cache of cos^n and floors) and the events-only
/// pass against the full check's figures (they must be the same bits).
fn output_check_equals_full_check(dp: &Datapath) -> Result<(), TestCaseError> {
    use specfx::analysis::check::{check, check_outputs, check_outputs_cached, stage_events};
    let report = check(dp).unwrap();
    let full = report.output_figures();
    prop_assert_eq!(check_outputs(dp).unwrap(), full);
    let cache = specfx::analysis::check::CosCache::new(1 << 20);
    prop_assert_eq!(check_outputs_cached(dp, Some(&cache)).unwrap(), full);
    prop_assert_eq!(check_outputs_cached(dp, Some(&cache)).unwrap(), full);
    let events = stage_events(dp).unwrap();
    for (e, s) in events.iter().zip(&report.stages) {
        prop_assert_eq!(*e, [s.wrapped, s.saturated, s.zeroed], "{}", s.stage);
    }
    Ok(())
}

/// `eval` against the independent big-integer oracle (`tests/common/oracle.rs`, written from
/// `docs/arithmetic.md`) on about 100 codes per n, ends and 1.0 included.
fn scalar_equals_oracle(dp: &Datapath) -> Result<(), TestCaseError> {
    let all = codes_of(dp);
    let step = (all.len() / 100).max(1);
    let mut codes: Vec<i64> = all.iter().step_by(step).copied().collect();
    codes.extend([*all.last().unwrap(), dp.one_code()]);
    for nc in dp.constants() {
        for &code in &codes {
            let p = dp.eval(code, nc);
            let want = oracle::oracle_eval(dp.config(), nc, code);
            let n_stages = dp.stages().len();
            prop_assert_eq!(
                &p.values[..n_stages],
                &want.values[..],
                "n={} code={}",
                nc.n,
                code
            );
            prop_assert_eq!(
                &p.events[..n_stages],
                &want.events[..],
                "n={} code={}",
                nc.n,
                code
            );
            prop_assert_eq!(p.cut, want.cut);
            prop_assert_eq!(p.input_clamped, want.input_clamped);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn batch_kernels_equal_the_plain_model(cfg in config()) {
        // A configuration the validation refuses has nothing to compare.
        let dp = Datapath::new(cfg.clone());
        prop_assume!(dp.is_ok());
        let dp = dp.unwrap();
        batch_equals_scalar(&dp)?;
        outputs_equal_scalar(&dp)?;
        corners_equal_brute_force(&dp)?;
        output_check_equals_full_check(&dp)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, max_global_rejects: 100_000, ..ProptestConfig::default() })]

    #[test]
    fn batch_kernels_equal_the_plain_model_at_the_edges(cfg in edge_config()) {
        let dp = Datapath::new(cfg.clone());
        prop_assume!(dp.is_ok());
        let dp = dp.unwrap();
        batch_equals_scalar(&dp)?;
        outputs_equal_scalar(&dp)?;
        corners_equal_brute_force(&dp)?;
        output_check_equals_full_check(&dp)?;
        scalar_equals_oracle(&dp)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn any_configuration_round_trips_through_toml(cfg in config()) {
        let text = cfg.to_toml();
        prop_assert_eq!(Config::from_toml(&text).unwrap(), cfg);
    }
}
