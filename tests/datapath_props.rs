//! Properties of the datapath on random configurations: the batch kernels equal the plain
//! model bit for bit, and TOML round trips.

use proptest::prelude::*;
use specfx::fixed::{Event, Format, Overflow, Rounding};
use specfx::nset::NSet;
use specfx::pipeline::{
    CoefSpec, Config, Datapath, FormatSpec, LatencySpec, MinimaxSpec, ProbeColumns, StageSpec,
    Variant,
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
    ) -> Config {
        let n_text: Vec<String> = ns.iter().map(|n| n.to_string()).collect();
        let c = if signed_c { fmt(true, 2, fc) } else { fmt(false, 1, fc) };
        let d = fmt(true, if signed_c { 3 } else { 1 }, fc + extra_d);
        Config {
            name: "random".into(),
            variant: if minimax { Variant::Minimax } else { Variant::Plain },
            k,
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
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn batch_kernels_equal_the_plain_model(cfg in config()) {
        // A configuration the validation refuses has nothing to compare.
        let dp = Datapath::new(cfg.clone());
        prop_assume!(dp.is_ok());
        let dp = dp.unwrap();
        let codes: Vec<i64> = dp.input_codes().collect();
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
            prop_assert_eq!(&counts, &cols.event_counts);
        }
    }

    #[test]
    fn any_configuration_round_trips_through_toml(cfg in config()) {
        let text = cfg.to_toml();
        prop_assert_eq!(Config::from_toml(&text).unwrap(), cfg);
    }
}
