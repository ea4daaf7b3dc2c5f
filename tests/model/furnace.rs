//! The white furnace: every azimuth-integrated kernel against brute-force 2D quadrature over
//! the hemisphere, closed forms of rho at and off normal incidence, the datapath path against a
//! slow per-code sum, the flags, and `specfx furnace` through the binary.

use crate::common;

use std::f64::consts::{FRAC_PI_2, PI};

use specfx::analysis::furnace::{
    furnace, kernel, reflectance, reflectance_of_steps, Curve, FurnacePath, FurnaceReport,
    FurnaceSettings, Step,
};
use specfx::nset::NSet;
use specfx::pipeline::{Config, Datapath};
use specfx::reference::normalisation::Form;

/// Gauss–Legendre nodes and weights on [-1, 1], by Newton's iteration on P_m.
fn gauss_legendre(m: usize) -> Vec<(f64, f64)> {
    (1..=m)
        .map(|i| {
            let mut x = (PI * (i as f64 - 0.25) / (m as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=m {
                    let kf = k as f64;
                    let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
                    p0 = p1;
                    p1 = p2;
                }
                dp = m as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// Composite Gauss–Legendre nodes and weights on [a, b]: `panels` panels of `m` points.
fn composite(a: f64, b: f64, panels: usize, m: usize) -> Vec<(f64, f64)> {
    let rule = gauss_legendre(m);
    let h = (b - a) / panels as f64;
    let mut v = Vec::with_capacity(panels * m);
    for p in 0..panels {
        let mid = a + (p as f64 + 0.5) * h;
        for &(x, w) in &rule {
            v.push((mid + 0.5 * h * x, 0.5 * h * w));
        }
    }
    v
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// rho(theta_i) = ∫_H f_r cos(theta_o) dw_o by brute force over w_o in (theta_o, phi_o), every
/// cosine computed from vectors: R = 2 (N.w_i) N - w_i, H = (w_i + w_o)/|w_i + w_o|. The
/// integrand f_r cos(theta_o) of each form: Phong RDF L(R.w_o), modified Phong
/// L(R.w_o) cos(theta_o), Blinn-Phong RDF L(N.H), modified L(N.H) cos(theta_o), the microfacet
/// forms D cos(theta_o) / (4 cos(theta_i) cos(theta_o)) with D = L(N.H).
fn brute_rho(form: Form, theta_i: f64, lobe: impl Fn(f64) -> f64) -> f64 {
    let (s, c) = theta_i.sin_cos();
    let wi = [s, 0.0, c];
    let r = [-s, 0.0, c];
    let thetas = composite(0.0, FRAC_PI_2, 96, 8);
    // The integrand is even in phi_o: integrate over [0, pi] and double.
    let phis = composite(0.0, PI, 96, 8);
    let mut sum = 0.0;
    for &(t, wt) in &thetas {
        let (st, ct) = t.sin_cos();
        for &(p, wp) in &phis {
            let (sp, cp) = p.sin_cos();
            let wo = [st * cp, st * sp, ct];
            let h = [wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]];
            let nh = h[2] / dot(h, h).sqrt();
            let v = match form {
                Form::Phong => lobe(dot(r, wo)),
                Form::PhongModified => lobe(dot(r, wo)) * ct,
                Form::BlinnPhong => lobe(nh),
                Form::BlinnPhongModified => lobe(nh) * ct,
                Form::BlinnPhongNdf | Form::BlinnPhongHeightfield => lobe(nh) / (4.0 * c),
            };
            sum += v * wt * wp * st;
        }
    }
    2.0 * sum
}

fn cos8(x: f64) -> f64 {
    x.max(0.0).powi(8)
}

#[test]
fn every_kernel_matches_brute_force_quadrature_over_the_hemisphere() {
    for form in Form::ALL {
        for deg in [0.0, 20.0, 45.0, 70.0, 85.0] {
            let t = f64::to_radians(deg);
            let want = brute_rho(form, t, cos8);
            let got = reflectance(form, t, cos8, &[]);
            assert!(
                ((got - want) / want).abs() < 1e-11,
                "{form} at {deg} deg: kernel gives {got}, brute force {want}"
            );
        }
    }
}

#[test]
fn kernels_match_brute_force_for_a_clamped_lobe_too() {
    // cs16 with n = 64: max(0, 4 (x - 1) + 1)^16, cut at x = 3/4; the cut is a breakpoint.
    let lobe = |x: f64| (4.0 * (x - 1.0) + 1.0).max(0.0).powi(16);
    for form in Form::ALL {
        for deg in [10.0, 50.0, 80.0] {
            let t = f64::to_radians(deg);
            let want = brute_rho(form, t, lobe);
            let got = reflectance(form, t, lobe, &[0.75]);
            assert!(
                ((got - want) / want).abs() < 1e-11,
                "{form} at {deg} deg: kernel gives {got}, brute force {want}"
            );
        }
    }
}

#[test]
fn classic_coefficients_give_one_at_normal_incidence() {
    // rho(0) = 2 pi coef ∫_0^1 x^n w(x) dx with w = 1 (Phong RDF) or x (modified Phong):
    // (n + 1)/(2 pi) 2 pi/(n + 1) = 1 and (n + 2)/(2 pi) 2 pi/(n + 2) = 1.
    for n in [1.0, 16.0, 100.0, 1024.0] {
        let modified = reflectance(
            Form::PhongModified,
            0.0,
            |x| (n + 2.0) / (2.0 * PI) * x.powf(n),
            &[],
        );
        assert!((modified - 1.0).abs() < 1e-9, "n = {n}: {modified}");
        let rdf = reflectance(
            Form::Phong,
            0.0,
            |x| (n + 1.0) / (2.0 * PI) * x.powf(n),
            &[],
        );
        assert!((rdf - 1.0).abs() < 1e-9, "n = {n}: {rdf}");
        // The microfacet forms reflect above the horizon only for h within 45 degrees of N:
        // (n + 2) ∫_{1/sqrt 2}^1 x^(n+1) dx = 1 - 2^(-(n+2)/2) with the heightfield
        // coefficient, times (n + 1)/(n + 2) with the NDF one.
        let lost = 1.0 - (-(n + 2.0) / 2.0).exp2();
        let hf = reflectance(
            Form::BlinnPhongHeightfield,
            0.0,
            |x| (n + 2.0) / (2.0 * PI) * x.powf(n),
            &[],
        );
        assert!((hf - lost).abs() < 1e-9, "n = {n}: {hf} vs {lost}");
        let ndf = reflectance(
            Form::BlinnPhongNdf,
            0.0,
            |x| (n + 1.0) / (2.0 * PI) * x.powf(n),
            &[],
        );
        let want = (n + 1.0) / (n + 2.0) * lost;
        assert!((ndf - want).abs() < 1e-9, "n = {n}: {ndf} vs {want}");
    }
}

fn baseline_report(ns: &[u32], angles: &[f64]) -> FurnaceReport {
    let dp = Datapath::new(Config::baseline()).unwrap();
    let ns = NSet::from_values(ns).unwrap();
    let settings = FurnaceSettings::new(&dp, Some(&ns), angles.to_vec()).unwrap();
    furnace(&dp, &settings)
}

fn curve(r: &FurnaceReport, form: Form, n: u32, path: FurnacePath) -> &Curve {
    r.forms
        .iter()
        .find(|f| f.form == form)
        .unwrap()
        .curves
        .iter()
        .find(|c| c.n == n && c.path == path)
        .unwrap()
}

fn default_angles() -> Vec<f64> {
    (0..=17).map(|i| f64::from(i) * 5.0).collect()
}

#[test]
fn a_wholly_visible_cs_lobe_reflects_cos_theta_or_one() {
    // n = 256, m = 16: the lobe lives in x >= 1 - 16/256 = 15/16, a cap of half-angle
    // arccos(15/16) = 20.4 degrees around R. While the cap is above the horizon (theta_i <= 69
    // degrees), the Phong RDF reflects 2 pi coef ∫ L dx = rho(0) at every angle, and modified
    // Phong reflects coef ∫ L(R.w) N.w dw = (N.R) coef 2 pi ∫ L x dx = cos(theta_i) rho(0),
    // since ∫ L(R.w) w dw is parallel to R. With the exact coefficient rho(0) = 1; with the
    // paper's 1.063 n/(2 pi) and Int = 16/(17 n), rho(0) = 1.063 * 16/17.
    let r = baseline_report(&[256], &default_angles());
    for (i, &deg) in r.angles_deg.iter().enumerate().filter(|&(_, &d)| d <= 65.0) {
        let cos = deg.to_radians().cos();
        let exact = curve(&r, Form::Phong, 256, FurnacePath::F64CsMExact).rho[i];
        assert!((exact - 1.0).abs() < 1e-10, "{deg}: {exact}");
        let paper = curve(&r, Form::Phong, 256, FurnacePath::F64CsMPaper).rho[i];
        assert!(
            (paper - 1.063 * 16.0 / 17.0).abs() < 1e-10,
            "{deg}: {paper}"
        );
        let modified = curve(&r, Form::PhongModified, 256, FurnacePath::F64CsMExact).rho[i];
        assert!((modified - cos).abs() < 1e-10, "{deg}: {modified} vs {cos}");
    }
}

#[test]
fn modified_phong_loses_energy_as_the_light_tilts() {
    // f_r cos(theta_o) = coef L(R.w_o) cos(theta_o): as R tilts, cos(theta_o) shrinks over the
    // lobe and the horizon cuts it, so rho falls strictly (it stays near cos(theta_i)).
    let r = baseline_report(&[16, 64, 1024], &default_angles());
    for n in [16, 64, 1024] {
        let c = curve(&r, Form::PhongModified, n, FurnacePath::F64CosN);
        for w in c.rho.windows(2) {
            assert!(w[1] < w[0], "n = {n}: {:?}", c.rho);
        }
        assert_eq!(c.max_angle_deg, 0.0);
        assert!(c.flagged_angles_deg.is_empty());
    }
}

#[test]
fn the_datapath_path_equals_a_slow_sum_over_every_code() {
    // Each code j holds x in [(j - 1/2) lsb, (j + 1/2) lsb] ∩ [0, 1] (the renderer rounds to
    // the nearest code); out(j) from Datapath::eval, ∫ K over the interval by a 64-point
    // midpoint rule.
    for (form, n, deg) in [
        (Form::PhongModified, 64, 30.0),
        (Form::BlinnPhong, 256, 60.0),
        (Form::BlinnPhongHeightfield, 1024, 80.0),
        (Form::Phong, 16, 45.0),
    ] {
        let t = f64::to_radians(deg);
        let mut cfg = Config::baseline();
        cfg.coef.form = form;
        cfg.n = NSet::from_values(&[n]).unwrap();
        let dp = Datapath::new(cfg).unwrap();
        let nc = dp.constants_for(n).unwrap();
        let lsb = dp.config().c.format.lsb();
        let out_format = dp.config().out.format;
        let mut slow = 0.0;
        for code in 0..=dp.one_code() {
            let out = out_format.to_f64(dp.eval(code, nc).values[dp.stage_out()]);
            if out == 0.0 {
                continue;
            }
            let lo = ((code as f64 - 0.5) * lsb).max(0.0);
            let hi = ((code as f64 + 0.5) * lsb).min(1.0);
            let steps = 64;
            let h = (hi - lo) / f64::from(steps);
            let k: f64 = (0..steps)
                .map(|i| kernel(form, lo + (f64::from(i) + 0.5) * h, t) * h)
                .sum();
            slow += out * k;
        }
        let r = baseline_report(&[n], &[deg]);
        let got = curve(&r, form, n, FurnacePath::Datapath).rho[0];
        assert!(
            ((got - slow) / slow).abs() < 1e-8,
            "{form} n = {n} at {deg} deg: {got} vs slow {slow}"
        );
    }
}

#[test]
fn rounding_the_cosine_to_the_nearest_code_is_the_trapezoid_rule() {
    // Code j holds x in [(j - 1/2) lsb, (j + 1/2) lsb] and the top code only half of it, so
    // at normal incidence (Phong: K = 2 pi) the step function of the lobe's values at the
    // codes integrates as the trapezoid rule on the grid j lsb: by Euler-Maclaurin,
    // ∫ L + lsb^2/12 (L'(1) - L'(0)). For cs16 with n >= 16, L'(1) = n, L'(0) = 0 and
    // 2 pi coef = 1/∫L = 17 n/16, so rho(0) - 1 = (n lsb)^2 17/(12 16).
    let lsb = 2f64.powi(-15);
    for n in [64.0, 256.0, 1024.0] {
        let coef = 17.0 * n / (32.0 * PI);
        let steps: Vec<Step> = (0..=1i64 << 15)
            .map(|j| {
                let x = j as f64 * lsb;
                Step {
                    lo: ((j as f64 - 0.5) * lsb).max(0.0),
                    hi: ((j as f64 + 0.5) * lsb).min(1.0),
                    value: coef * (n / 16.0 * (x - 1.0) + 1.0).max(0.0).powi(16),
                }
            })
            .filter(|s| s.value != 0.0)
            .collect();
        let excess = reflectance_of_steps(Form::Phong, 0.0, &steps) - 1.0;
        let want = (n * lsb).powi(2) * 17.0 / (12.0 * 16.0);
        assert!(
            (excess - want).abs() < 1e-3 * want,
            "n = {n}: {excess} vs {want}"
        );
    }
}

#[test]
fn values_above_one_are_flagged_and_reported() {
    let r = baseline_report(&[16, 256], &default_angles());
    // The paper's Phong coefficient 1.063 n/(2 pi) against Int = 16/(17 n): rho(0) =
    // 1.063 * 16/17 = 1.00047 > 1, on a plateau up to where the horizon cuts the lobe.
    let paper = curve(&r, Form::Phong, 16, FurnacePath::F64CsMPaper);
    assert!((paper.rho_normal - 1.063 * 16.0 / 17.0).abs() < 1e-10);
    assert!(paper.flagged_angles_deg.contains(&0.0));
    assert_eq!(paper.max_angle_deg, 0.0);
    // The heightfield microfacet BRDF without a masking term, cos^16 with (n + 2)/(2 pi), at
    // 85 degrees: the brute-force quadrature of D/(4 cos theta_i) over the hemisphere is
    // far above 1.
    let n = 16.0;
    let brute = brute_rho(Form::BlinnPhongHeightfield, 85f64.to_radians(), |x| {
        (n + 2.0) / (2.0 * PI) * x.max(0.0).powf(n)
    });
    assert!(brute > 1.5, "{brute}");
    let hf = curve(&r, Form::BlinnPhongHeightfield, 16, FurnacePath::F64CosN);
    assert!((hf.rho[17] - brute).abs() < 1e-9 * brute);
    assert!(hf.flagged_angles_deg.contains(&85.0));
    let summary = r.summary();
    let phong = summary.iter().find(|s| s.form == Form::Phong).unwrap();
    assert!(phong.n_flagged_curves >= 2);
    let hfs = summary
        .iter()
        .find(|s| s.form == Form::BlinnPhongHeightfield)
        .unwrap();
    let worst = hfs.worst.unwrap();
    assert_eq!((worst.n, worst.theta_deg), (16, 85.0));
    let mut md = Vec::new();
    specfx::report::doc::write_markdown(&mut md, &specfx::report::furnace::document(&r)).unwrap();
    let md = String::from_utf8(md).unwrap();
    assert!(
        md.contains("| phong | 16 | f64_cs_m_paper | 0-45 | 1.000471 | 0 |"),
        "{md}"
    );
}

#[test]
fn a_coefficient_that_does_not_fit_makes_the_datapath_unavailable() {
    // u6.16 holds coefficients below 64: the Blinn-Phong RDF ones (about (n + 2)/(8 pi), 41
    // at n = 1024) fit, the Phong ones (about n/(2 pi), 163 at n = 1024) do not.
    let mut cfg = Config::baseline();
    cfg.coef.form = Form::BlinnPhong;
    cfg.coef.format = "u6.16".parse().unwrap();
    let dp = Datapath::new(cfg).unwrap();
    let ns = NSet::from_values(&[16, 1024]).unwrap();
    let r = furnace(
        &dp,
        &FurnaceSettings::new(&dp, Some(&ns), vec![0.0]).unwrap(),
    );
    for f in &r.forms {
        let fits = matches!(f.form, Form::BlinnPhong | Form::BlinnPhongModified);
        assert_eq!(f.datapath_unavailable.is_none(), fits, "{}", f.form);
        assert_eq!(f.curves.len(), if fits { 2 * 4 } else { 2 * 3 });
        if let Some(e) = &f.datapath_unavailable {
            assert!(e.starts_with("coef.format"), "{e}");
        }
    }
}

// --- the command ---

const FILES: [&str; 15] = [
    "furnace.md",
    "furnace.csv",
    "furnace.json",
    "furnace_phong.svg",
    "furnace_phong.png",
    "furnace_phong_modified.svg",
    "furnace_phong_modified.png",
    "furnace_blinn_phong.svg",
    "furnace_blinn_phong.png",
    "furnace_blinn_phong_modified.svg",
    "furnace_blinn_phong_modified.png",
    "furnace_blinn_phong_ndf.svg",
    "furnace_blinn_phong_ndf.png",
    "furnace_blinn_phong_heightfield.svg",
    "furnace_blinn_phong_heightfield.png",
];

#[test]
fn furnace_writes_every_file_and_reruns_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a");
    let o = common::specfx(&["furnace", "--out", a.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8(o.stdout).unwrap();
    // The summary table: a header and one row per form.
    assert_eq!(stdout.lines().count(), 1 + 6, "{stdout}");
    assert!(stdout.starts_with("form "), "{stdout}");
    assert!(
        stdout.lines().nth(1).unwrap().starts_with("phong "),
        "{stdout}"
    );
    for f in FILES {
        assert!(a.join(f).is_file(), "{f}");
    }
    let csv = std::fs::read_to_string(a.join("furnace.csv")).unwrap();
    assert!(csv.starts_with("form,n,path,theta_deg,rho\n"));
    // 6 forms x 7 exponents x 4 paths x 18 angles.
    assert_eq!(csv.lines().count(), 1 + 6 * 7 * 4 * 18);

    let b = dir.path().join("b");
    let o = common::specfx(&["furnace", "--out", b.to_str().unwrap(), "--json"]);
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v.as_array().unwrap().len(), 6);
    assert_eq!(v[0]["form"], "phong");
    for f in FILES {
        let (x, y) = (
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
        );
        assert!(x == y, "{f} differs between runs");
    }
}

#[test]
fn furnace_refuses_bad_input_with_one_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    for (args, needle) in [
        (vec!["--n", "8,16"], "n set 16..=1024, got 8"),
        (vec!["--n", "abc"], "--n"),
        (
            vec!["--angles", "0..95:5"],
            "angles must be degrees in [0, 90)",
        ),
        (vec!["--angles", "x"], "angles must be degrees in [0, 90)"),
        (vec!["--config", "no/such.toml"], "no/such.toml"),
    ] {
        let out = dir.path().join("out");
        let mut all = vec!["furnace", "--out", out.to_str().unwrap()];
        all.extend(&args);
        let o = common::specfx(&all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} wrote output");
    }
}
