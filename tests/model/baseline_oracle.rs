//! An independent, slow model of the `baseline` datapath, written from its specification with
//! plain integer division, compared with the library on every input code for several n.

use std::f64::consts::PI;

use specfx::pipeline::{Config, Datapath, ProbeColumns};

/// Round-half-up (RND) of `x / 2^s`: floor((x + 2^(s-1)) / 2^s), with Euclidean division so
/// negative values floor correctly.
fn rnd(x: i128, s: u32) -> i128 {
    (x + (1i128 << (s - 1))).div_euclid(1i128 << s)
}

fn sat(x: i128, lo: i128, hi: i128) -> i128 {
    x.max(lo).min(hi)
}

/// Every probe of baseline for one (c_raw, n): [d, t, b, sq1, sq2, sq3, sq4, coef, out].
fn baseline_slow(c_raw: i64, n: u32) -> [i64; 9] {
    // c: u1.15, clamped to 1.0 = 32768.
    let c = i128::from(c_raw.min(32768));
    // d = c - 1 in s1.15: exact.
    let d = c - 32768;
    // t = d * n / 16: exact with 15 + 4 = 19 fraction bits, RND to 16, SAT to s2.16.
    let t = sat(rnd(d * i128::from(n), 3), -(1 << 17), (1 << 17) - 1);
    // b = t + 1 (16 fraction bits), negative -> 0, u1.16 SAT.
    let b = sat((t + (1 << 16)).max(0), 0, (1 << 17) - 1);
    // Four squarings: 32 fraction bits, RND to 16, u1.16 SAT.
    let mut sq = [0i128; 4];
    let mut s = b;
    for v in &mut sq {
        s = sat(rnd(s * s, 16), 0, (1 << 17) - 1);
        *v = s;
    }
    // coef = 17 n / (32 pi) (exact Phong coefficient for n >= 16), u8.16 with RND: the f64
    // value times 2^16, rounded half up.
    let coef_f = 17.0 * f64::from(n) / (32.0 * PI);
    let coef = (coef_f * 65536.0 + 0.5).floor() as i128;
    // out = sq4 * coef: 32 fraction bits, RND to 16, u8.16 SAT.
    let out = sat(rnd(s * coef, 16), 0, (1 << 24) - 1);
    [d, t, b, sq[0], sq[1], sq[2], sq[3], coef, out].map(|x| x as i64)
}

#[test]
fn baseline_matches_the_slow_model_on_every_code() {
    let dp = Datapath::new(Config::baseline()).unwrap();
    let codes: Vec<i64> = (0..=65535).collect();
    let mut cols = ProbeColumns::default();
    for n in [16, 17, 31, 100, 255, 256, 257, 500, 777, 1000, 1023, 1024] {
        let nc = dp.constants_for(n).unwrap();
        dp.eval_batch(nc, &codes, &mut cols);
        for &code in &codes {
            let want = baseline_slow(code, n);
            let scalar = dp.eval(code, nc);
            assert_eq!(&scalar.values[..9], &want, "eval, n = {n}, c_raw = {code}");
            let batch = cols.row(code as usize);
            assert_eq!(
                &batch.values[..9],
                &want,
                "eval_batch, n = {n}, c_raw = {code}"
            );
        }
    }
}

#[test]
fn baseline_hand_computed_points() {
    // c = 1.0 (and above): d = 0, t = 0, b = 1.0, every square 1.0, out = coef.
    let dp = Datapath::new(Config::baseline()).unwrap();
    let nc = dp.constants_for(64).unwrap();
    for code in [32768, 40000, 65535] {
        let p = dp.eval(code, nc);
        assert_eq!(&p.values[..7], &[0, 0, 65536, 65536, 65536, 65536, 65536]);
        assert_eq!(p.values[8], p.values[7]);
        assert_eq!(p.input_clamped, code > 32768);
    }
    // n = 16, c = 0.5 (16384): d = -0.5 = -16384; t = -16384*16/16 = -0.5 = -32768 in s2.16;
    // b = 0.5 = 32768; squares: 0.25, 0.0625, 2^-8, 2^-16 = 16384, 4096, 256, 1.
    let nc = dp.constants_for(16).unwrap();
    let p = dp.eval(16384, nc);
    assert_eq!(
        &p.values[..7],
        &[-16384, -32768, 32768, 16384, 4096, 256, 1]
    );
    // coef(16) = 17*16/(32 pi) = 2.70563...; * 2^16 = 177316.43 -> 177316; out = 1 * 177316 / 2^16
    // = 2.7056 -> RND -> 3.
    assert_eq!(p.values[7], 177_316);
    assert_eq!(p.values[8], 3);
}
