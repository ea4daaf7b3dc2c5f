//! The cached minimax table: reproducible, better than the plain constants, and optimal as far
//! as independent oracles can tell.

use specfx::reference::lobe::{affine_lobe, m_of_k};
use specfx::reference::minimax::{constants, fit, max_abs_error, table, TABLE_N_MAX};

const SAMPLE: [(u32, u32); 12] = [
    (1, 1),
    (1, 7),
    (3, 2),
    (16, 4),
    (17, 4),
    (100, 7),
    (128, 4),
    (555, 3),
    (1024, 4),
    (2000, 5),
    (4096, 1),
    (4096, 7),
];

#[test]
fn table_is_what_the_solver_computes() {
    for (n, k) in SAMPLE {
        assert_eq!(constants(n, k).unwrap(), fit(n, k), "n={n} k={k}");
    }
}

#[test]
fn table_covers_every_entry_and_beats_the_plain_constants() {
    let t = table();
    assert_eq!(t.len(), 7 * TABLE_N_MAX as usize);
    for f in t {
        assert!(
            f.max_abs_err <= f.plain_max_abs_err + 1e-12,
            "n={} k={}: {} > {}",
            f.n,
            f.k,
            f.max_abs_err,
            f.plain_max_abs_err
        );
        // Away from n = m (where the plain constants are exact) the minimax error is well
        // under half the plain one: Beaudoin and Guardado's "roughly halving".
        if f.plain_max_abs_err > 1e-6 {
            assert!(
                f.max_abs_err < 0.45 * f.plain_max_abs_err,
                "n={} k={}",
                f.n,
                f.k
            );
        }
    }
}

/// Brute force: a uniform grid of one million points on [0, 1].
fn brute_force_error(n: u32, k: u32, a: f64, b: f64) -> f64 {
    (0..=1_000_000)
        .map(|i| {
            let c = f64::from(i) / 1e6;
            (affine_lobe(c, a, b, k) - c.powi(n as i32)).abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn recorded_errors_agree_with_a_brute_force_grid() {
    for (n, k) in SAMPLE {
        let f = constants(n, k).unwrap();
        let brute = brute_force_error(n, k, f.a, f.b);
        // The grid can only miss the peak, never exceed it.
        assert!(
            brute <= f.max_abs_err * (1.0 + 1e-12) + 1e-15,
            "n={n} k={k}"
        );
        assert!(
            brute >= f.max_abs_err * (1.0 - 1e-3),
            "n={n} k={k}: {brute} vs {}",
            f.max_abs_err
        );
        let plain = brute_force_error(
            n,
            k,
            f64::from(n) / f64::from(m_of_k(k)),
            1.0 - f64::from(n) / f64::from(m_of_k(k)),
        );
        assert!(
            plain >= f.plain_max_abs_err * (1.0 - 1e-3) - 1e-15,
            "n={n} k={k}"
        );
    }
}

#[test]
fn no_small_step_of_the_constants_lowers_the_error() {
    // Local optimality: move the zero c0 = -b/a and the value s at c = 1 by a small relative
    // step in eight directions; the continuous max error never drops by more than 1e-4.
    for (n, k) in SAMPLE {
        let f = constants(n, k).unwrap();
        if f.plain_max_abs_err == 0.0 {
            continue;
        }
        let m = f64::from(m_of_k(k));
        let c0 = -f.b / f.a;
        let s = (f.a + f.b).powf(m);
        let u0 = 1.0 - c0;
        for (dc, ds) in [
            (1, 0),
            (-1, 0),
            (0, 1),
            (0, -1),
            (1, 1),
            (1, -1),
            (-1, 1),
            (-1, -1),
        ] {
            let step = 1e-3;
            let c0p = c0 - f64::from(dc) * step * u0;
            let sp = s * (1.0 + f64::from(ds) * step);
            let ap = sp.powf(1.0 / m) / (1.0 - c0p);
            let bp = -ap * c0p;
            let (e, _) = max_abs_error(n, k, ap, bp);
            assert!(
                e >= f.max_abs_err * (1.0 - 1e-4),
                "n={n} k={k} step ({dc},{ds}): {e} < {}",
                f.max_abs_err
            );
        }
    }
}
