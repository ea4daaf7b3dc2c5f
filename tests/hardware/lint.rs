//! Lint of the reference Verilog (`hdl_ref/`) on any configuration the tool accepts: a seeded
//! generator reaches the edges of validation, and `verilator --lint-only -Wall` and
//! `iverilog -g2005 -Wall` must both be silent for both architectures.
//!
//! The generator plans plain data first ([`Candidate`], one per shape class), renders each to
//! a complete TOML file, and keeps the ones `specfx hdl params --config` accepts. Each shape
//! class must keep a minimum count, and the kept set must cover every k, rounding, overflow,
//! cutoff, variant, n-set kind and multiplier latency, so the generator cannot silently
//! degrade. The explicit edge shapes (16-, 32- and 64-bit packed chain buses, one-bit d,
//! one-bit last square, one-bit coefficient, every format one bit, the widest formats) run
//! every time, beside the committed configurations of `tests/configs/`. Both simulators must
//! be installed (`./scripts/test` installs them).

use crate::common::specfx;

use std::fmt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The generator's seed: fixed, so every run lints the same configurations.
const SEED: u64 = 20_240_611;

const ROUNDINGS: [&str; 8] = [
    "TRN",
    "TRN_ZERO",
    "RND",
    "RND_ZERO",
    "RND_INF",
    "RND_MIN_INF",
    "RND_CONV",
    "RND_CONV_ODD",
];
const OVERFLOWS: [&str; 4] = ["WRAP", "SAT", "SAT_ZERO", "SAT_SYM"];
const CUTOFFS: [&str; 3] = ["clamp", "paper", "none"];
const FORMS: [&str; 6] = [
    "phong",
    "phong_modified",
    "blinn_phong",
    "blinn_phong_modified",
    "blinn_phong_ndf",
    "blinn_phong_heightfield",
];
const SOURCES: [&str; 3] = ["classic", "paper", "exact"];
/// The widest format (`Format`): 64 bits signed, 63 unsigned.
const MAX_W: i32 = 64;
/// The largest exact intermediate the model validates (`MAX_EXACT_BITS`): a product of two
/// raws of widths a and b needs a + b bits.
const MAX_EXACT: i32 = 126;
/// The largest exponent a minimax configuration may serve (the cached table's).
const MINIMAX_N_MAX: u32 = 4096;

/// A fixed-point format, `s<int>.<frac>` or `u<int>.<frac>`; width = int + frac.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Fmt {
    signed: bool,
    int: i32,
    frac: i32,
}

impl Fmt {
    fn of_width(signed: bool, width: i32, frac: i32) -> Fmt {
        Fmt {
            signed,
            int: width - frac,
            frac,
        }
    }

    fn width(self) -> i32 {
        self.int + self.frac
    }
}

impl fmt::Display for Fmt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = if self.signed { 's' } else { 'u' };
        write!(f, "{s}{}.{}", self.int, self.frac)
    }
}

/// A quantizing stage: format, rounding and overflow.
#[derive(Debug, Clone, Copy)]
struct Stage {
    format: Fmt,
    rounding: &'static str,
    overflow: &'static str,
}

/// What a candidate is built to reach.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Shape {
    /// Everything random within (and just past) what validation accepts.
    General,
    /// b's width plus the squares' widths is exactly this many bits (and so are the k + 1
    /// coefficients beside them when k + 1 divides it).
    ChainBus(i32),
    /// d is one bit (c is `uI.0`, d `s1.0`).
    OneBitD,
    /// The last square is one bit.
    OneBitLastSquare,
    /// The coefficient is one bit.
    OneBitCoef,
    /// Every format one bit wide (n = 1, so the plain slope is one bit too).
    Narrowest,
    /// Plain variant, every n a power of two (`SPECFX_SLOPE_POW2 = 1`).
    PowerOfTwoSlopes,
    /// The minimax variant (per-n slope and offset formats).
    Minimax,
    /// The widest formats validation accepts, and extreme fraction bits.
    Widest,
}

/// How the n set is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum NKind {
    Range,
    List,
    Single,
    PowersOfTwo,
}

/// The exponents: their TOML text, their largest value, how they are written.
#[derive(Debug, Clone)]
struct NSpec {
    text: String,
    max: u32,
    kind: NKind,
}

/// One generated configuration, as plain data.
#[derive(Debug, Clone)]
struct Candidate {
    shape: Shape,
    name: String,
    minimax: Option<(Fmt, Fmt, &'static str)>,
    k: usize,
    cutoff: &'static str,
    n: NSpec,
    c: Fmt,
    d: Fmt,
    t: Stage,
    b: Stage,
    square: Vec<Stage>,
    coef: Fmt,
    coef_form: &'static str,
    coef_source: &'static str,
    coef_rounding: &'static str,
    out: Stage,
    latency: [u32; 3],
    /// The `depth` key's TOML value, when not the fixed default.
    depth: Option<String>,
}

impl Candidate {
    /// The configuration as a complete TOML file (no key left to the baseline).
    fn to_toml(&self) -> String {
        let stage = |name: &str, s: &Stage| {
            format!(
                "[{name}]\nformat = \"{}\"\nrounding = \"{}\"\noverflow = \"{}\"\n",
                s.format, s.rounding, s.overflow
            )
        };
        let mut t = format!(
            "# {:?}\nname = \"{}\"\nvariant = \"{}\"\nk = {}\ncutoff = \"{}\"\nn = \"{}\"\n",
            self.shape,
            self.name,
            if self.minimax.is_some() {
                "minimax"
            } else {
                "plain"
            },
            self.k,
            self.cutoff,
            self.n.text
        );
        if let Some(depth) = &self.depth {
            t += &format!("depth = {depth}\n");
        }
        t += &format!(
            "[c]\nformat = \"{}\"\n[d]\nformat = \"{}\"\n",
            self.c, self.d
        );
        t += &stage("t", &self.t);
        t += &stage("b", &self.b);
        for s in &self.square {
            t += &stage("[square]", s);
        }
        t += &format!(
            "[coef]\nform = \"{}\"\nsource = \"{}\"\nformat = \"{}\"\nrounding = \"{}\"\n",
            self.coef_form, self.coef_source, self.coef, self.coef_rounding
        );
        t += &stage("out", &self.out);
        if let Some((a, offset, rounding)) = self.minimax {
            t += &format!(
                "[minimax]\na_format = \"{a}\"\noffset_format = \"{offset}\"\nrounding = \"{rounding}\"\n"
            );
        }
        let [sub, mul, add] = self.latency;
        t += &format!("[latency]\nsub = {sub}\nmul = {mul}\nadd = {add}\n");
        t
    }

    fn stages(&self) -> impl Iterator<Item = &Stage> {
        [&self.t, &self.b, &self.out]
            .into_iter()
            .chain(self.square.iter())
    }

    fn formats(&self) -> Vec<Fmt> {
        let mut v = vec![self.c, self.d, self.coef];
        v.extend(self.stages().map(|s| s.format));
        if let Some((a, o, _)) = self.minimax {
            v.extend([a, o]);
        }
        v
    }

    /// Width of the packed chain bus of `specfx_pipelined` (b and every square).
    fn chain_bus_width(&self) -> i32 {
        self.b.format.width() + self.square.iter().map(|s| s.format.width()).sum::<i32>()
    }

    fn last_square(&self) -> Fmt {
        self.square.last().expect("k >= 1").format
    }
}

/// The widest format of a signedness: 64 bits signed, 63 unsigned.
fn max_width(signed: bool) -> i32 {
    if signed {
        MAX_W
    } else {
        MAX_W - 1
    }
}

/// Bits of `n` (the plain slope `n` with k fraction bits is this wide).
fn bit_len(n: u32) -> i32 {
    (32 - n.leading_zeros()) as i32
}

/// The seeded generator of candidates.
struct Generator {
    rng: ChaCha8Rng,
    count: usize,
}

impl Generator {
    fn new(seed: u64) -> Generator {
        Generator {
            rng: ChaCha8Rng::seed_from_u64(seed),
            count: 0,
        }
    }

    fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        *items.choose(&mut self.rng).expect("non-empty")
    }

    /// A width in 1..=max: often 1 or max, else mostly moderate.
    fn width(&mut self, max: i32) -> i32 {
        match self.rng.gen_range(0..10) {
            0 => 1,
            1 => max,
            _ => self.rng.gen_range(1..=max.min(28)),
        }
    }

    /// Fraction bits for a value of `width` bits: usually 0..=width, sometimes negative (the
    /// LSB above 1), more than the width (every value below 1/2), or `extreme` in magnitude.
    fn frac(&mut self, width: i32, extreme: i32) -> i32 {
        match self.rng.gen_range(0..10) {
            0 | 1 => -self.rng.gen_range(1..=16),
            2 => width + self.rng.gen_range(1..=16),
            3 => self.pick(&[-extreme, extreme]),
            _ => self.rng.gen_range(0..=width),
        }
    }

    fn modes(&mut self) -> (&'static str, &'static str) {
        (self.pick(&ROUNDINGS), self.pick(&OVERFLOWS))
    }

    fn stage(&mut self, max_w: i32, extreme_frac: i32) -> Stage {
        let width = self.width(max_w);
        let signed = self.rng.gen_bool(0.5) || width > max_width(false);
        let frac = self.frac(width, extreme_frac);
        let (rounding, overflow) = self.modes();
        Stage {
            format: Fmt::of_width(signed, width, frac),
            rounding,
            overflow,
        }
    }

    /// c (it must hold 1.0) and d = c - 1 (signed, exact).
    fn c_and_d(&mut self) -> (Fmt, Fmt) {
        let signed = self.rng.gen_bool(0.3);
        let int = if signed {
            self.rng.gen_range(2..=4)
        } else {
            self.rng.gen_range(1..=3)
        };
        // d needs one integer bit more than c's most negative value.
        let d_int = if signed { int + 1 } else { 1 } + self.rng.gen_range(0..=1);
        let frac_max = (MAX_W - d_int).min(max_width(signed) - int).min(62);
        let frac = match self.rng.gen_range(0..8) {
            0 => 0,
            1 => frac_max,
            _ => self.rng.gen_range(1..=20),
        };
        let d_frac = (frac + self.pick(&[0, 0, 1, 3])).min(MAX_W - d_int);
        let c = Fmt { signed, int, frac };
        let d = Fmt {
            signed: true,
            int: d_int,
            frac: d_frac,
        };
        (c, d)
    }

    fn n_set(&mut self, max: u32) -> NSpec {
        let top = self.pick(&[max, max.min(1024), max.min(64)]);
        let kind = self.pick(&[NKind::Range, NKind::List, NKind::Single, NKind::PowersOfTwo]);
        match kind {
            NKind::Range => {
                let lo = self.rng.gen_range(1..=top);
                let hi = (lo + self.rng.gen_range(0..=40)).min(top);
                NSpec {
                    text: format!("{lo}..={hi}"),
                    max: hi,
                    kind,
                }
            }
            NKind::List => {
                let mut v: Vec<u32> = (0..self.rng.gen_range(2..=5))
                    .map(|_| self.rng.gen_range(1..=top))
                    .collect();
                v.push(top);
                v.sort_unstable();
                v.dedup();
                self.list(v, kind)
            }
            NKind::Single => {
                let n = self.rng.gen_range(1..=top);
                self.list(vec![n], kind)
            }
            NKind::PowersOfTwo => self.powers_of_two(top),
        }
    }

    fn powers_of_two(&mut self, max: u32) -> NSpec {
        let mut v: Vec<u32> = (0..bit_len(max))
            .map(|e| 1u32 << e)
            .filter(|_| self.rng.gen_bool(0.5))
            .collect();
        if v.is_empty() {
            v.push(1 << (bit_len(max) - 1));
        }
        self.list(v, NKind::PowersOfTwo)
    }

    fn list(&mut self, v: Vec<u32>, kind: NKind) -> NSpec {
        NSpec {
            text: v.iter().map(u32::to_string).collect::<Vec<_>>().join(","),
            max: *v.last().expect("non-empty"),
            kind,
        }
    }

    /// A coefficient format that holds coef(n) for n up to `n_max` (coef(n) < n / 2 for
    /// every form and source), at most `max_w` bits.
    fn coef(&mut self, n_max: u32, max_w: i32) -> Fmt {
        let signed = self.rng.gen_bool(0.3);
        let int = (bit_len(n_max) - 1).max(1) + i32::from(signed) + self.rng.gen_range(0..=2);
        let frac = match self.rng.gen_range(0..6) {
            0 => -self.rng.gen_range(0..=3).min(int - 1),
            1 => self.rng.gen_range(20..=40),
            _ => self.rng.gen_range(0..=16),
        };
        let frac = frac.min(max_w.min(max_width(signed)) - int);
        Fmt { signed, int, frac }
    }

    fn latency(&mut self) -> u32 {
        if self.rng.gen_bool(0.7) {
            self.rng.gen_range(1..=2)
        } else {
            self.rng.gen_range(3..=8)
        }
    }

    /// The minimax constants' formats: A(n) < n / 2^k + 1 (and A(1) < 1), A(n) + B(n) in
    /// [0.97, 1.04].
    fn minimax_formats(&mut self, k: usize, n_max: u32, max_a_w: i32) -> (Fmt, Fmt, &'static str) {
        let signed = self.rng.gen_bool(0.3);
        let a_int =
            (bit_len(n_max) - k as i32 + 1).max(1) + i32::from(signed) + self.rng.gen_range(0..=1);
        let a_frac = self
            .pick(&[0, 4, 12, 20, 40])
            .min(max_a_w.min(max_width(signed)) - a_int);
        let o_signed = self.rng.gen_bool(0.3);
        let o_int = 1 + i32::from(o_signed);
        let o_frac = self
            .pick(&[0, 3, 16, 30, 62])
            .min(MAX_W - i32::from(!o_signed) - o_int);
        (
            Fmt {
                signed,
                int: a_int,
                frac: a_frac,
            },
            Fmt {
                signed: o_signed,
                int: o_int,
                frac: o_frac,
            },
            self.pick(&ROUNDINGS),
        )
    }

    /// A random candidate with k squarings and multiplier latency `mul`: every choice within
    /// what validation accepts, or close to it.
    fn general(&mut self, shape: Shape, k: usize, mul: u32) -> Candidate {
        self.count += 1;
        let minimax_variant = self.rng.gen_bool(0.25);
        let n = self.n_set(if minimax_variant {
            MINIMAX_N_MAX
        } else {
            65_535
        });
        let (c, d) = self.c_and_d();
        let minimax =
            minimax_variant.then(|| self.minimax_formats(k, n.max, MAX_EXACT - d.width()));
        let t = self.stage(MAX_W, 60);
        let b = self.stage(MAX_EXACT / 2, 512);
        let mut square: Vec<Stage> = (0..k).map(|_| self.stage(MAX_EXACT / 2, 512)).collect();
        let coef = self.coef(n.max, MAX_W);
        let last = square.last_mut().expect("k >= 1");
        if last.format.width() + coef.width() > MAX_EXACT {
            last.format = Fmt::of_width(
                last.format.signed,
                MAX_EXACT - coef.width(),
                last.format.frac,
            );
        }
        let out = self.stage(MAX_W, 512);
        let latency = [self.latency(), mul, self.latency()];
        // A per-n depth on one candidate in three each way, chosen by count (not drawn, so
        // the random stream, and every other choice, is the same with or without it).
        let depth = match self.count % 6 {
            1 if k >= 2 && n.max <= MINIMAX_N_MAX => Some("\"best\"".to_string()),
            3 | 5 if k >= 2 && n.max > 1 => Some(format!(
                "[{{ from = 1, j = {} }}, {{ from = {}, j = {k} }}]",
                1 + self.count % (k - 1),
                n.max
            )),
            _ => None,
        };
        Candidate {
            shape,
            name: format!("gen{}", self.count),
            minimax,
            k,
            cutoff: self.pick(&CUTOFFS),
            n,
            c,
            d,
            t,
            b,
            square,
            coef,
            coef_form: self.pick(&FORMS),
            coef_source: self.pick(&SOURCES),
            coef_rounding: self.pick(&ROUNDINGS),
            out,
            latency,
            depth,
        }
    }

    /// Candidate `i` of a shape class: a general one, then the class's edge. Each class
    /// cycles through k = 1..7 and multiplier latencies 1..8.
    fn candidate(&mut self, shape: Shape, i: usize) -> Candidate {
        let mut c = self.general(shape, 1 + i % 7, 1 + (i % 8) as u32);
        match shape {
            Shape::General => {}
            Shape::ChainBus(total) => {
                // k + 1 positive widths summing to `total`: distinct cut points in 1..total.
                let mut cuts: Vec<i32> = (1..total).collect();
                cuts.shuffle(&mut self.rng);
                cuts.truncate(c.k);
                cuts.sort_unstable();
                cuts.insert(0, 0);
                cuts.push(total);
                let widths: Vec<i32> = cuts.windows(2).map(|w| w[1] - w[0]).collect();
                let resize = |s: &mut Stage, w: i32| {
                    s.format = Fmt::of_width(s.format.signed, w, s.format.frac);
                };
                resize(&mut c.b, widths[0]);
                for (s, &w) in c.square.iter_mut().zip(&widths[1..]) {
                    resize(s, w);
                }
                // The coefficients beside b and each square make a bus of (k + 1) * COEF_W bits:
                // the same total when k + 1 divides it (a coarse coefficient, LSB above 1).
                if total % (c.k as i32 + 1) == 0 {
                    let w = total / (c.k as i32 + 1);
                    c.coef = Fmt::of_width(c.coef.signed, w, w - c.coef.int);
                }
            }
            Shape::OneBitD => {
                // c in uI.0, d in s1.0; a slope of at least 11 bits beside a narrow chain and
                // a 2- or 3-bit coefficient, so that d * slope sets the folded core's widths.
                c.c = Fmt::of_width(false, self.rng.gen_range(1..=3), 0);
                c.d = Fmt::of_width(true, 1, 0);
                self.narrow_chain(&mut c);
                match c.minimax {
                    Some((a, o, r)) => {
                        let w = self.rng.gen_range(20..=max_width(a.signed));
                        c.minimax = Some((Fmt::of_width(a.signed, w, w - a.int), o, r));
                    }
                    None => {
                        let hi = self.rng.gen_range(1024..=65_535);
                        let lo = hi - self.rng.gen_range(0..=40);
                        c.n = NSpec {
                            text: format!("{lo}..={hi}"),
                            max: hi,
                            kind: NKind::Range,
                        };
                    }
                }
                let coef = self.coef(c.n.max, MAX_W);
                let w = 2 + i32::from(coef.signed);
                c.coef = Fmt::of_width(coef.signed, w, w - coef.int);
            }
            Shape::OneBitLastSquare => {
                // A one-bit last square, a narrow chain and a coefficient of 40 bits or more,
                // so that sq_k * coef sets the folded core's widths.
                let signed = self.rng.gen_bool(0.6);
                let frac = self.pick(&[0, 1, 5, -3, 512]);
                self.narrow_chain(&mut c);
                let last = c.square.last_mut().expect("k >= 1");
                last.format = Fmt::of_width(signed, 1, frac);
                let coef = self.coef(c.n.max, MAX_W);
                let w = self.rng.gen_range(40..=max_width(coef.signed));
                c.coef = Fmt::of_width(coef.signed, w, w - coef.int);
            }
            Shape::OneBitCoef => {
                // coef(1) < 1 rounded down: 0 in u0.1, u1.0 and s1.0.
                c.n = self.list(vec![1], NKind::Single);
                c.coef = self.pick(&[
                    Fmt::of_width(false, 1, 1),
                    Fmt::of_width(false, 1, 0),
                    Fmt::of_width(true, 1, 0),
                ]);
                c.coef_rounding = "TRN";
            }
            Shape::Narrowest => {
                // n = 1: the plain slope (1 with k fraction bits) is one bit; minimax A(1) < 1
                // in u0.1 and A(1) + B(1) close to 1 in u1.0.
                c.n = self.list(vec![1], NKind::Single);
                c.c = Fmt::of_width(false, 1, 0);
                c.d = Fmt::of_width(true, 1, 0);
                if let Some((_, _, r)) = c.minimax {
                    c.minimax = Some((Fmt::of_width(false, 1, 1), Fmt::of_width(false, 1, 0), r));
                }
                c.coef = Fmt::of_width(self.rng.gen_bool(0.5), 1, 0);
                c.coef_rounding = "TRN";
                let fracs = [-3, 0, 1, 4];
                for s in [&mut c.t, &mut c.b, &mut c.out]
                    .into_iter()
                    .chain(c.square.iter_mut())
                {
                    s.format = Fmt::of_width(
                        self.rng.gen_bool(0.5),
                        1,
                        *fracs.choose(&mut self.rng).expect("non-empty"),
                    );
                }
            }
            Shape::PowerOfTwoSlopes => {
                c.minimax = None;
                let top = self.pick(&[65_535, 4096, 64, 2]);
                c.n = self.powers_of_two(top);
                c.coef = self.coef(c.n.max, MAX_W - 20);
            }
            Shape::Minimax => {
                c.n = self.n_set(MINIMAX_N_MAX);
                c.coef = self.coef(c.n.max, MAX_W - 20);
                c.minimax = Some(self.minimax_formats(c.k, c.n.max, MAX_EXACT - c.d.width()));
            }
            Shape::Widest => {
                // c u1.62 or s2.61 and d 64 bits; t and out 64 bits; b and every square but
                // the last 63 bits (their squares need 126); the last square and the
                // coefficient 63 bits each; every latency 8.
                let signed_c = self.rng.gen_bool(0.5);
                c.c = Fmt::of_width(signed_c, 63, 62 - i32::from(signed_c));
                c.d = Fmt::of_width(true, 64, c.c.frac);
                c.t.format = Fmt::of_width(true, 64, self.pick(&[60, 62, -60]));
                for s in std::iter::once(&mut c.b).chain(c.square.iter_mut()) {
                    let frac = self.pick(&[512, -512, 62, 0]);
                    s.format = Fmt::of_width(self.rng.gen_bool(0.5), 63, frac);
                }
                let coef = self.coef(c.n.max, 63);
                c.coef = Fmt::of_width(coef.signed, 63, 63 - coef.int);
                c.out.format = Fmt::of_width(true, 64, self.pick(&[512, -512, 0, 64]));
                if let Some((a, o, r)) = c.minimax {
                    let w = max_width(a.signed).min(MAX_EXACT - c.d.width());
                    c.minimax = Some((Fmt::of_width(a.signed, w, w - a.int), o, r));
                }
                c.latency = [8, 8, 8];
            }
        }
        c.name = format!("{}_{shape:?}", c.name).replace(['(', ')'], "");
        c
    }

    /// b and the squares at most 6 bits, so that d's or a constant's width sets the folded
    /// core's operand and product widths.
    fn narrow_chain(&mut self, c: &mut Candidate) {
        let w = self.rng.gen_range(1..=6);
        c.b.format = Fmt::of_width(c.b.format.signed, w, c.b.format.frac.min(w));
        for s in &mut c.square {
            let w = self.rng.gen_range(1..=6);
            s.format = Fmt::of_width(s.format.signed, w, s.format.frac.clamp(-4, w + 2));
        }
    }
}

/// The shape classes, how many candidates each generates and the least number the binary
/// must accept.
const CLASSES: [(Shape, usize, usize); 11] = [
    (Shape::General, 26, 16),
    (Shape::ChainBus(16), 5, 4),
    (Shape::ChainBus(32), 5, 4),
    (Shape::ChainBus(64), 5, 4),
    (Shape::OneBitD, 6, 5),
    (Shape::OneBitLastSquare, 6, 5),
    (Shape::OneBitCoef, 4, 3),
    (Shape::Narrowest, 4, 3),
    (Shape::PowerOfTwoSlopes, 6, 5),
    (Shape::Minimax, 7, 5),
    (Shape::Widest, 5, 3),
];

/// The committed configurations linted every run: the co-simulation ones (two with a per-n
/// depth), and the explicit
/// edge shapes (packed chain bus of 16, 32, 64 bits; one-bit d; one-bit last square; one-bit
/// coefficient; every format one bit; the widest formats).
const FIXED: [&str; 14] = [
    "narrow_trn_wrap.toml",
    "depth_best_k6.toml",
    "depth_steps_signed.toml",
    "conv_sym_k5.toml",
    "minimax_folded.toml",
    "pow2_shift.toml",
    "lint_bus16.toml",
    "lint_bus32.toml",
    "lint_bus64.toml",
    "lint_d1.toml",
    "lint_sq1.toml",
    "lint_coef1.toml",
    "lint_narrowest.toml",
    "lint_widest.toml",
];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn config_path(name: &str) -> PathBuf {
    root().join("tests/configs").join(name)
}

fn temp_dir(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("specfx-lint-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    std::fs::create_dir_all(&p).unwrap();
    p
}

/// `hdl_ref/specfx_dut.v` then `hdl_ref/rtl/*.v`.
fn rtl_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("hdl_ref/rtl"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "v"))
        .collect();
    files.sort();
    files.insert(0, root().join("hdl_ref/specfx_dut.v"));
    files
}

/// Writes the header of `config` for `arch` into `dir`; the binary's output when it refuses.
fn params(config: &Path, arch: &str, dir: &Path) -> Result<(), Output> {
    let header = dir.join("specfx_params.vh");
    let o = specfx(&[
        "hdl",
        "params",
        "--config",
        config.to_str().unwrap(),
        "--arch",
        arch,
        "--out",
        header.to_str().unwrap(),
    ]);
    if o.status.success() {
        Ok(())
    } else {
        Err(o)
    }
}

fn tool_text(tool: &str, o: &Output) -> String {
    format!(
        "{tool} ({}):\n{}{}",
        o.status,
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Lints the DUT and the RTL with the header in `dir` (Icarus; Verilator too when `dut_verilator`),
/// and the parameterized top `specfx_top` with the configuration's `-G` flags (Verilator):
/// every tool's complaints, if any. Verilator sees the same RTL with the same parameter values
/// through the header and through `-G`: the generated configurations lint the RTL through `-G`
/// and the header path through Icarus, the fixed ones through all three.
fn lint(dir: &Path, files: &[PathBuf], top_flags: &[String], dut_verilator: bool) -> Vec<String> {
    let include = format!("-I{}", dir.display());
    let verilator = dut_verilator.then(|| {
        Command::new("verilator")
            .args(["--lint-only", "-Wall", "--top-module", "specfx_dut"])
            .arg(&include)
            .args(files)
            .output()
            .expect("verilator is installed (./scripts/test installs it)")
    });
    let top = Command::new("verilator")
        .args(["--lint-only", "-Wall", "--top-module", "specfx_top"])
        .args(top_flags)
        .args(files.iter().filter(|f| !f.ends_with("specfx_dut.v")))
        .output()
        .expect("verilator is installed (./scripts/test installs it)");
    let icarus = Command::new("iverilog")
        .args(["-g2005", "-Wall", "-o"])
        .arg(dir.join("lint.vvp"))
        .arg(&include)
        .args(files)
        .output()
        .expect("iverilog is installed (./scripts/test installs it)");
    [
        ("verilator", verilator),
        ("verilator (specfx_top, -G parameters)", Some(top)),
        ("iverilog", Some(icarus)),
    ]
    .into_iter()
    .filter_map(|(tool, o)| Some((tool, o?)))
    .filter(|(_, o)| !o.status.success() || !o.stderr.is_empty())
    .map(|(tool, o)| tool_text(tool, &o))
    .collect()
}

/// Lints one configuration file for both architectures; the failures, each with the TOML.
fn lint_config(
    label: &str,
    config: &Path,
    dir: &Path,
    files: &[PathBuf],
    dut_verilator: bool,
) -> Vec<String> {
    let mut failures = Vec::new();
    for arch in ["pipelined", "folded"] {
        if let Err(o) = params(config, arch, dir) {
            failures.push(format!("{label} ({arch}): {}", tool_text("specfx", &o)));
            continue;
        }
        let flags = specfx(&[
            "hdl",
            "params",
            "--config",
            config.to_str().unwrap(),
            "--arch",
            arch,
            "--format",
            "verilator",
        ]);
        let flags: Vec<String> = String::from_utf8_lossy(&flags.stdout)
            .lines()
            .map(str::to_string)
            .collect();
        for complaint in lint(dir, files, &flags, dut_verilator) {
            failures.push(format!(
                "{label} ({arch}): {complaint}\n--- {}\n{}",
                config.display(),
                std::fs::read_to_string(config).unwrap()
            ));
        }
    }
    failures
}

/// The candidates of every class, in a fixed order.
fn candidates() -> Vec<Candidate> {
    let mut g = Generator::new(SEED);
    CLASSES
        .iter()
        .flat_map(|&(shape, n, _)| (0..n).map(move |i| (shape, i)))
        .map(|(shape, i)| g.candidate(shape, i))
        .collect()
}

/// Asserts that the kept candidates still reach every edge the generator aims at.
fn assert_coverage(kept: &[Candidate]) {
    let has = |what: &str, pred: &dyn Fn(&Candidate) -> bool| {
        assert!(
            kept.iter().any(pred),
            "no kept generated configuration has {what}: the generator degraded"
        );
    };
    for k in 1..=7 {
        has(&format!("k = {k}"), &|c| c.k == k);
    }
    for mul in 1..=8 {
        has(&format!("latency.mul = {mul}"), &|c| c.latency[1] == mul);
    }
    for r in ROUNDINGS {
        has(&format!("rounding {r}"), &|c| {
            c.stages().any(|s| s.rounding == r)
        });
    }
    for o in OVERFLOWS {
        has(&format!("overflow {o}"), &|c| {
            c.stages().any(|s| s.overflow == o)
        });
    }
    for cut in CUTOFFS {
        has(&format!("cutoff {cut}"), &|c| c.cutoff == cut);
    }
    for kind in [NKind::Range, NKind::List, NKind::Single, NKind::PowersOfTwo] {
        has(&format!("an n set written as {kind:?}"), &|c| {
            c.n.kind == kind
        });
    }
    has("a per-n depth from a step list", &|c| {
        c.depth.as_deref().is_some_and(|d| d.starts_with('['))
    });
    has("a per-n depth = \"best\"", &|c| {
        c.depth.as_deref() == Some("\"best\"")
    });
    has("the plain variant", &|c| c.minimax.is_none());
    has("the minimax variant", &|c| c.minimax.is_some());
    has("a plain variant with every n a power of two", &|c| {
        c.minimax.is_none() && c.n.kind == NKind::PowersOfTwo
    });
    has("a one-bit format", &|c| {
        c.formats().iter().any(|f| f.width() == 1)
    });
    has("a 64-bit format", &|c| {
        c.formats().iter().any(|f| f.width() == 64)
    });
    has("negative fraction bits", &|c| {
        c.formats().iter().any(|f| f.frac < 0)
    });
    has("fraction bits beyond the width", &|c| {
        c.formats().iter().any(|f| f.frac > f.width())
    });
    has("512 fraction bits", &|c| {
        c.formats().iter().any(|f| f.frac == 512)
    });
    has("-512 fraction bits", &|c| {
        c.formats().iter().any(|f| f.frac == -512)
    });
    has("a signed stage", &|c| c.stages().any(|s| s.format.signed));
    has("an unsigned stage", &|c| {
        c.stages().any(|s| !s.format.signed)
    });
    has("a signed c", &|c| c.c.signed);
    for total in [16, 32, 64] {
        has(&format!("a {total}-bit chain bus"), &|c| {
            c.chain_bus_width() == total
        });
        has(&format!("a {total}-bit coefficient bus"), &|c| {
            (c.k as i32 + 1) * c.coef.width() == total
        });
    }
    has("a one-bit d", &|c| c.d.width() == 1);
    has("a one-bit last square", &|c| c.last_square().width() == 1);
    has("a one-bit coefficient", &|c| c.coef.width() == 1);
    has("every format one bit", &|c| {
        c.formats().iter().all(|f| f.width() == 1)
    });
}

#[test]
fn rtl_is_lint_clean_for_generated_and_edge_configurations() {
    let files = rtl_files();
    let dir = temp_dir("lint");
    let mut failures = Vec::new();

    let mut fixed = 0;
    for name in ["baseline"].into_iter().chain(FIXED) {
        let config = if name == "baseline" {
            let p = dir.join("baseline.toml");
            std::fs::write(&p, "name = \"baseline\"\n").unwrap();
            p
        } else {
            config_path(name)
        };
        failures.extend(lint_config(name, &config, &dir, &files, true));
        fixed += 1;
    }

    // The generated candidates on two workers, each in a directory of its own; the verdicts
    // are put back in the candidates' order.
    let all = candidates();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut verdicts: Vec<(usize, Result<Vec<String>, String>)> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..2)
            .map(|w| {
                let (all, next, files) = (&all, &next, &files);
                s.spawn(move || {
                    let dir = temp_dir(&format!("lint-{w}"));
                    let config = dir.join("generated.toml");
                    let mut out = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(c) = all.get(i) else { break };
                        std::fs::write(&config, c.to_toml()).unwrap();
                        let verdict = match params(&config, "pipelined", &dir) {
                            Err(o) => {
                                let why = String::from_utf8_lossy(&o.stderr);
                                Err(why
                                    .rsplit(".toml: ")
                                    .next()
                                    .unwrap_or_default()
                                    .trim()
                                    .to_string())
                            }
                            Ok(()) => Ok(lint_config(&c.name, &config, &dir, files, false)),
                        };
                        out.push((i, verdict));
                    }
                    std::fs::remove_dir_all(&dir).unwrap();
                    out
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap())
            .collect()
    });
    verdicts.sort_by_key(|v| v.0);
    let mut kept = Vec::new();
    let mut rejected = String::new();
    for (i, verdict) in verdicts {
        let c = &all[i];
        match verdict {
            Err(why) => rejected += &format!("  {} ({:?}): {why}\n", c.name, c.shape),
            Ok(complaints) => {
                failures.extend(complaints);
                kept.push(c.clone());
            }
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();

    let mut table = String::new();
    for (shape, generated, least) in CLASSES {
        let n = kept.iter().filter(|c| c.shape == shape).count();
        table += &format!("  {shape:?}: {n} kept of {generated} (at least {least})\n");
    }
    println!(
        "lint: {fixed} fixed and {} generated configurations (of {}), 2 architectures each\n{table}rejected by validation:\n{rejected}",
        kept.len(),
        all.len()
    );
    assert!(
        failures.is_empty(),
        "{} lint failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
    for (shape, _, least) in CLASSES {
        let n = kept.iter().filter(|c| c.shape == shape).count();
        assert!(
            n >= least,
            "{shape:?}: only {n} generated configurations accepted, expected at least {least}\n{table}"
        );
    }
    assert_coverage(&kept);
}

/// The `N passed, N failed` line of a `scripts/cosim` run.
fn cosim_summary(o: &Output) -> Option<(u64, u64)> {
    let text = String::from_utf8_lossy(&o.stdout);
    let line = text
        .lines()
        .rev()
        .find(|l| l.contains(" passed, ") && l.trim_end().ends_with(" failed"))?;
    let nums: Vec<u64> = line
        .split(|c: char| !c.is_ascii_digit())
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect();
    Some((nums[0], nums[1]))
}

/// The shapes that used to warn, co-simulated in Icarus Verilog against the golden vectors
/// and the cycle model (with bubbles and stalls): quiet and bit- and cycle-exact. Folded for
/// the one-bit factors of the shared multiplier (WIDTH in `specfx_mul.v`), pipelined for the
/// 16-bit chain bus (MULTIDRIVEN in `specfx_pipelined.v`).
#[test]
fn previously_warning_shapes_match_bit_and_cycle() {
    let cases = [
        ("lint_d1.toml", "folded"),
        ("lint_sq1.toml", "folded"),
        ("lint_narrowest.toml", "folded"),
        ("lint_bus16.toml", "pipelined"),
    ];
    for (name, arch) in cases {
        let work = temp_dir(&format!("cosim-{arch}-{name}"));
        let dir = work.join("vectors");
        let config = config_path(name);
        let o = specfx(&[
            "vectors",
            "--config",
            config.to_str().unwrap(),
            "--cases",
            "corner,random:200",
            "--seed",
            "5",
            "--out",
            dir.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", tool_text("specfx vectors", &o));
        let manifest: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap())
                .unwrap();
        let n = manifest["n_vectors"].as_u64().unwrap();
        assert!(n > 0, "{name}: no vectors");
        let o = Command::new(root().join("scripts/cosim"))
            .args(["--vectors", dir.to_str().unwrap(), "--sim", "icarus"])
            .args([
                "--arch", arch, "--seed", "7", "--bubble", "0.3", "--stall", "0.3",
            ])
            .env("SPECFX", env!("CARGO_BIN_EXE_specfx"))
            .output()
            .expect("scripts/cosim runs");
        assert_eq!(
            cosim_summary(&o),
            Some((n, 0)),
            "{name} ({arch}): {}",
            tool_text("scripts/cosim", &o)
        );
        assert!(o.status.success());
        std::fs::remove_dir_all(&work).unwrap();
    }
}
