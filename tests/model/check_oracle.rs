//! `specfx check`'s figures against a slow, plain computation of their definitions
//! (`docs/arithmetic.md` section 6): every code and n evaluated with `eval`, the f64 reference of
//! the same algorithm written out here, no shortcut. The check's fast paths (the dead prefix
//! found by bisection, d's exact figures, the live compaction) must give the same figures.

use specfx::analysis::check::{check, check_outputs, check_outputs_cached, CosCache};
use specfx::fixed::Event;
use specfx::pipeline::{Config, Datapath};
use specfx::reference::lobe::Cutoff;

struct Slow {
    max_abs: Vec<f64>,
    worst: Vec<(u32, i64)>,
    sum: Vec<f64>,
    n_correct: Vec<u64>,
    n_faithful: Vec<u64>,
    raw_min: Vec<i64>,
    raw_max: Vec<i64>,
    events: Vec<[u64; 3]>,
    quant: f64,
    approx: f64,
    total: f64,
    norm_abs: f64,
    norm_rel: f64,
    norm_approx_rel: f64,
    n_cut: u64,
    n_violations: u64,
    count: u64,
}

fn slow_check(dp: &Datapath) -> Slow {
    let cfg = dp.config();
    let n_stages = dp.stages().len();
    let lsb: Vec<f64> = dp.stages().iter().map(|s| s.format.lsb()).collect();
    let one = dp.one_code();
    let c_lsb = cfg.c.format.lsb();
    let codes = dp.input_codes();
    let (lo, last) = (*codes.start(), (*codes.end()).min(one));
    let mut s = Slow {
        max_abs: vec![-1.0; n_stages],
        worst: vec![(0, 0); n_stages],
        sum: vec![0.0; n_stages],
        n_correct: vec![0; n_stages],
        n_faithful: vec![0; n_stages],
        raw_min: vec![i64::MAX; n_stages],
        raw_max: vec![i64::MIN; n_stages],
        events: vec![[0; 3]; n_stages],
        quant: -1.0,
        approx: -1.0,
        total: -1.0,
        norm_abs: -1.0,
        norm_rel: -1.0,
        norm_approx_rel: -1.0,
        n_cut: 0,
        n_violations: 0,
        count: 0,
    };
    let last_sq = dp.stage_last_square();
    for nc in dp.constants() {
        let mut prev_out: Option<i64> = None;
        for k in lo..=last {
            let p = dp.eval(k, nc);
            // The f64 value of every stage, by the same algorithm without rounding.
            let mut r = vec![0.0; n_stages];
            r[0] = (k.min(one) as f64 * c_lsb) - 1.0;
            r[1] = nc.slope * r[0];
            let sum = r[1] + nc.offset;
            r[2] = match cfg.cutoff {
                Cutoff::Clamp => sum.max(0.0),
                Cutoff::Paper if nc.threshold.is_some_and(|t| k.min(one) < t) => 0.0,
                _ => sum,
            };
            for i in 3..=last_sq {
                r[i] = r[i - 1] * r[i - 1];
            }
            r[dp.stage_coef()] = nc.coef;
            r[dp.stage_out()] = r[last_sq] * nc.coef;
            for i in 0..n_stages {
                let err = p.values[i] as f64 * lsb[i] - r[i];
                if err.abs() > s.max_abs[i] {
                    s.max_abs[i] = err.abs();
                    s.worst[i] = (nc.n, k);
                }
                s.sum[i] += err;
                s.n_correct[i] += u64::from(err.abs() <= 0.5 * lsb[i] * (1.0 + 1e-9));
                s.n_faithful[i] += u64::from(err.abs() < lsb[i] * (1.0 - 1e-12));
                s.raw_min[i] = s.raw_min[i].min(p.values[i]);
                s.raw_max[i] = s.raw_max[i].max(p.values[i]);
                match p.events[i] {
                    Event::None => {}
                    Event::Wrapped => s.events[i][0] += 1,
                    Event::Saturated => s.events[i][1] += 1,
                    Event::Zeroed => s.events[i][2] += 1,
                }
            }
            let c = k as f64 * c_lsb;
            let cos_n = if c <= 0.0 {
                0.0
            } else {
                (f64::from(nc.n) * c.ln()).exp()
            };
            let fixed_lobe = p.values[last_sq] as f64 * lsb[last_sq];
            s.quant = s.quant.max((fixed_lobe - r[last_sq]).abs());
            s.approx = s.approx.max((r[last_sq] - cos_n).abs());
            s.total = s.total.max((fixed_lobe - cos_n).abs());
            // The normalised output against exact normalised cos^n: Phong's cos^n
            // coefficient (n + 1) / (2 pi), by hand.
            let peak = (f64::from(nc.n) + 1.0) / (2.0 * std::f64::consts::PI);
            let out_value = p.values[dp.stage_out()] as f64 * lsb[dp.stage_out()];
            let e = (out_value - peak * cos_n).abs();
            s.norm_abs = s.norm_abs.max(e);
            s.norm_rel = s.norm_rel.max(e / peak);
            s.norm_approx_rel = s
                .norm_approx_rel
                .max((r[dp.stage_out()] - peak * cos_n).abs() / peak);
            s.n_cut += u64::from(p.cut);
            let out = p.values[dp.stage_out()];
            if prev_out.is_some_and(|prev| out < prev) {
                s.n_violations += 1;
            }
            prev_out = Some(out);
            s.count += 1;
        }
    }
    s
}

fn compare(toml: &str) {
    let mut cfg = Config::from_toml(toml).unwrap();
    assert_eq!(cfg.coef.form, specfx::reference::normalisation::Form::Phong);
    cfg.n = "16,17,40,100,333,1000,1024".parse().unwrap();
    let dp = Datapath::new(cfg).unwrap();
    let fast = check(&dp).unwrap();
    // The output-only check gives the full check's output figures, bit for bit.
    assert_eq!(check_outputs(&dp).unwrap(), fast.output_figures(), "{toml}");
    let slow = slow_check(&dp);
    assert_eq!(fast.n_evaluations, slow.count, "{toml}");
    for (i, st) in fast.stages.iter().enumerate() {
        let what = format!("{toml}: stage {}", st.stage);
        assert_eq!(st.max_abs_err, slow.max_abs[i], "{what} max");
        if slow.max_abs[i] > 0.0 {
            assert_eq!((st.worst.n, st.worst.c_raw), slow.worst[i], "{what} worst");
        }
        let mean = slow.sum[i] / slow.count as f64;
        assert!(
            (st.mean_err - mean).abs() <= 1e-9 * mean.abs().max(st.max_abs_err) + 1e-300,
            "{what} mean {} vs {mean}",
            st.mean_err
        );
        let count = slow.count as f64;
        assert_eq!(
            st.correctly_rounded,
            slow.n_correct[i] as f64 / count,
            "{what}"
        );
        assert_eq!(
            st.faithfully_rounded,
            slow.n_faithful[i] as f64 / count,
            "{what}"
        );
        assert_eq!(
            (st.raw_min, st.raw_max),
            (slow.raw_min[i], slow.raw_max[i]),
            "{what}"
        );
        assert_eq!(
            [st.wrapped, st.saturated, st.zeroed],
            slow.events[i],
            "{what} events"
        );
    }
    assert_eq!(fast.shape_quant_max_abs, slow.quant, "{toml} quant");
    assert!(
        (fast.shape_approx_max_abs - slow.approx).abs() <= 1e-15,
        "{toml} approx"
    );
    assert!(
        (fast.shape_total_max_abs - slow.total).abs() <= 1e-15,
        "{toml} total"
    );
    assert_eq!(fast.norm_total_max_abs, slow.norm_abs, "{toml} norm");
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1e-300);
    assert!(close(fast.norm_total_rel, slow.norm_rel), "{toml} norm rel");
    assert!(
        close(fast.norm_approx_rel, slow.norm_approx_rel),
        "{toml} norm approx {} vs {}",
        fast.norm_approx_rel,
        slow.norm_approx_rel
    );
    assert_eq!(fast.n_cut, slow.n_cut, "{toml} cut");
    assert_eq!(
        fast.n_monotonicity_violations, slow.n_violations,
        "{toml} monotonic"
    );
}

#[test]
fn baseline_and_its_cutoffs() {
    compare("");
    compare("cutoff = \"paper\"\nk = 5\n");
    compare("cutoff = \"none\"\nk = 3\n");
}

#[test]
fn wrapping_zeroing_and_symmetric_t() {
    compare("[t]\nformat = \"s2.12\"\noverflow = \"WRAP\"\n");
    compare("[t]\nformat = \"s2.10\"\noverflow = \"SAT_ZERO\"\n");
    compare("[t]\noverflow = \"SAT_SYM\"\nrounding = \"TRN\"\n");
}

#[test]
fn minimax_signed_inputs_and_narrow_formats() {
    compare("variant = \"minimax\"\n");
    compare("[c]\nformat = \"s2.10\"\n[d]\nformat = \"s3.11\"\n");
    // A d of more than 53 bits: its f64 reference is rounded, so d's figures and the
    // overflowed prefix (which reads d as exact) take their general path. With 1025 input
    // codes and 7 exponents against b's 2^17 codes, the output-only check runs the squaring
    // chain on the live codes; on the baseline's codes it looks the chain up from b.
    compare("[c]\nformat = \"u1.10\"\n[d]\nformat = \"s1.56\"\n");
    compare(
        "k = 2\n[c]\nformat = \"u1.8\"\n[d]\nformat = \"s1.8\"\n[b]\nformat = \"u1.6\"\n\
         [square]\nformat = \"u1.5\"\nrounding = \"TRN\"\n[out]\nformat = \"u6.2\"\n",
    );
}

/// The optimiser's cache of `cos^n` (`check_outputs_cached`): datapaths with the first one's
/// input format read its rows, their live codes starting elsewhere (other cutoffs, wider
/// stages with more live codes, other variants and overflow modes), one of another input
/// format bypasses it, and a cache too small to keep anything computes every row itself. Every
/// figure is the uncached check's, bit for bit.
#[test]
fn cached_cos_gives_the_same_figures() {
    let shared = CosCache::new(1 << 22);
    let tiny = CosCache::new(0);
    for toml in [
        "",
        "[square]\nformat = \"u1.24\"\n[out]\nformat = \"u8.24\"\n",
        "cutoff = \"paper\"\nk = 5\n",
        "cutoff = \"none\"\nk = 3\n",
        "variant = \"minimax\"\n",
        "[t]\nformat = \"s2.12\"\noverflow = \"WRAP\"\n",
        "[b]\nformat = \"u1.9\"\n",
        "[c]\nformat = \"s2.10\"\n[d]\nformat = \"s3.11\"\n",
    ] {
        let mut cfg = Config::from_toml(toml).unwrap();
        cfg.n = "16,17,40,100,333,1000,1024".parse().unwrap();
        let dp = Datapath::new(cfg).unwrap();
        let want = check_outputs(&dp).unwrap();
        assert_eq!(
            check_outputs_cached(&dp, Some(&shared)).unwrap(),
            want,
            "{toml}"
        );
        assert_eq!(
            check_outputs_cached(&dp, Some(&tiny)).unwrap(),
            want,
            "{toml}"
        );
    }
    assert!(shared.entries() > 0);
    assert_eq!(tiny.entries(), 0);
}
