//! Fitting a datapath to a scene: image-space budgets, the judge that renders a candidate
//! datapath's image from traced fragments and compares it with f64 cos^n, the f64 floor of
//! each algorithm, and the search space (only the scene's exponents, the input, coefficient
//! and output formats searched as well as the internal stages).
//!
//! Every figure is over every input the scene produces: each candidate's image is shaded from
//! every fragment and light with the datapath's bit-accurate output for that input's code.

use std::fmt;
use std::str::FromStr;

use serde::Serialize;

use crate::analysis::budget_expr::Verdict;
use crate::analysis::optimize::{
    combine, search, start_of, Algorithm, Candidate, Choices, Knob, SearchResult, Space,
};
use crate::error::Error;
use crate::fixed::Rounding;
use crate::pipeline::walk::Stage;
use crate::pipeline::{Config, Datapath, Variant};
use crate::scene::render::{
    cos_n_lobe, difference_of, flip_of, image_error_of, DatapathLobe, Encoder, Fragments,
    ImageError, ModelLobe,
};
use crate::scene::Scene;

/// An image-space quantity a budget bounds (every one against the f64 cos^n image).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ImageMetric {
    /// The largest channel difference of any pixel, in display LSBs (`max_lsb`).
    MaxLsb,
    /// The mean over covered pixels of the largest channel difference (`mean_lsb`).
    MeanLsb,
    /// The share of covered pixels with any channel different (`differing`).
    Differing,
    /// The mean FLIP over covered pixels (`flip`).
    Flip,
}

impl ImageMetric {
    /// The name in budget expressions.
    pub fn name(self) -> &'static str {
        match self {
            ImageMetric::MaxLsb => "max_lsb",
            ImageMetric::MeanLsb => "mean_lsb",
            ImageMetric::Differing => "differing",
            ImageMetric::Flip => "flip",
        }
    }

    /// The metric's value in an image's figures.
    pub fn of(self, e: &ImageError) -> f64 {
        match self {
            ImageMetric::MaxLsb => f64::from(e.max_lsb),
            ImageMetric::MeanLsb => e.mean_lsb,
            ImageMetric::Differing => e.differing,
            ImageMetric::Flip => e.flip_mean,
        }
    }
}

/// One bound `metric <= limit`, over every covered pixel or one material's
/// (`metric[material] <= limit`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImageBound {
    /// The metric.
    pub metric: ImageMetric,
    /// The material whose pixels it covers (`None`: every covered pixel).
    pub material: Option<String>,
    /// The limit (LSBs, a fraction, or a FLIP value).
    pub limit: f64,
}

/// An image-space budget: every bound must hold over the covered pixels.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImageBudget {
    /// The budget as text (`max_lsb <= 31 and differing <= 13.3% and flip <= 0.0141`).
    pub text: String,
    /// The bounds.
    pub bounds: Vec<ImageBound>,
}

impl FromStr for ImageBudget {
    type Err = Error;
    /// Parses `max_lsb <= 2`, `mean_lsb <= 0.1`, `differing <= 1%` (or `0.01`), `flip <=
    /// 0.01`, each over every covered pixel or one material's (`max_lsb[vessel] <= 4`),
    /// several joined by `and` or `,`.
    fn from_str(s: &str) -> Result<Self, Error> {
        let (text, bounds) = crate::analysis::budget_expr::parse_bounds(
            s,
            &["<="],
            "'max_lsb <= 2 and differing <= 1% and flip <= 0.01' (metrics max_lsb, mean_lsb, differing, flip; metric[material] for one material)",
            parse_image_bound,
        )?;
        Ok(ImageBudget { text, bounds })
    }
}

/// One bound of an [`ImageBudget`]: `lhs <= rhs`, `bad` the error of a malformed one.
fn parse_image_bound(
    b: &crate::analysis::budget_expr::RawBound<'_>,
    bad: &dyn Fn(&str) -> Error,
) -> Result<ImageBound, Error> {
    let lhs = b.lhs.trim();
    let (name, material) = match lhs.split_once('[') {
        Some((name, rest)) => match rest.strip_suffix(']') {
            Some(m) if !m.trim().is_empty() => (name.trim(), Some(m.trim().to_string())),
            _ => return Err(bad("a material is written metric[name]")),
        },
        None => (lhs, None),
    };
    let metric = match name {
        "max_lsb" => ImageMetric::MaxLsb,
        "mean_lsb" => ImageMetric::MeanLsb,
        "differing" => ImageMetric::Differing,
        "flip" => ImageMetric::Flip,
        other => return Err(bad(&format!("unknown metric '{other}'"))),
    };
    let rhs = b.rhs.trim();
    let (number, percent) = match rhs.strip_suffix('%') {
        Some(n) if metric == ImageMetric::Differing => (n.trim(), true),
        Some(_) => return Err(bad("only differing takes a percentage")),
        None => (rhs, false),
    };
    let value: f64 = number
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite() && *v >= 0.0)
        .ok_or_else(|| bad("no non-negative number"))?;
    let limit = if percent { value / 100.0 } else { value };
    if metric == ImageMetric::Differing && limit > 1.0 {
        return Err(bad("a share of pixels is at most 100% (or 1)"));
    }
    Ok(ImageBound {
        metric,
        material,
        limit,
    })
}

impl fmt::Display for ImageBudget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

impl ImageBudget {
    /// The bounds in one notation, sorted (`differing <= 0.05`, `max_lsb[vessel] <= 4`): the
    /// same budget written differently gives the same list.
    ///
    /// # Examples
    /// ```
    /// use specfx::scene::fit::ImageBudget;
    /// let a: ImageBudget = "max_lsb <= 8 and differing <= 5%".parse().unwrap();
    /// let b: ImageBudget = "differing<=0.05, max_lsb <= 8".parse().unwrap();
    /// assert_eq!(a.canonical(), ["differing <= 0.05", "max_lsb <= 8"]);
    /// assert_eq!(a.canonical(), b.canonical());
    /// ```
    pub fn canonical(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .bounds
            .iter()
            .map(|b| match &b.material {
                Some(m) => format!("{}[{m}] <= {}", b.metric.name(), b.limit),
                None => format!("{} <= {}", b.metric.name(), b.limit),
            })
            .collect();
        v.sort();
        v.dedup();
        v
    }

    /// "No worse than `figures`" for every material: each material's max LSBs, differing share
    /// and FLIP mean as its limits (the default budget of `fit`, with the generic datapath's
    /// figures; limits rounded up to readable figures, which the generic datapath still meets).
    pub fn no_worse_than(scene: &Scene, figures: &SceneFigures) -> ImageBudget {
        let up = |x: f64, digits: i32| {
            let scale = 10f64.powi(digits);
            (x * scale).ceil() / scale
        };
        let mut bounds = Vec::new();
        let mut text = Vec::new();
        for (m, e) in scene.materials.iter().zip(&figures.materials) {
            let (differing, flip) = (up(100.0 * e.differing, 2), up(e.flip_mean, 5));
            let name = Some(m.name.clone());
            bounds.push(ImageBound {
                metric: ImageMetric::MaxLsb,
                material: name.clone(),
                limit: f64::from(e.max_lsb),
            });
            bounds.push(ImageBound {
                metric: ImageMetric::Differing,
                material: name.clone(),
                limit: differing / 100.0,
            });
            bounds.push(ImageBound {
                metric: ImageMetric::Flip,
                material: name,
                limit: flip,
            });
            text.push(format!(
                "max_lsb[{0}] <= {1} and differing[{0}] <= {differing}% and flip[{0}] <= {flip}",
                m.name, e.max_lsb
            ));
        }
        ImageBudget {
            text: text.join(" and "),
            bounds,
        }
    }

    /// Checks that every material a bound names is in the scene.
    pub fn check_materials(&self, scene: &Scene) -> Result<(), Error> {
        for b in &self.bounds {
            if let Some(m) = &b.material {
                if scene.material_index(m).is_none() {
                    let names: Vec<&str> =
                        scene.materials.iter().map(|m| m.name.as_str()).collect();
                    return Err(Error::Config {
                        key: "budget".into(),
                        problem: format!(
                            "no material '{m}' in the scene (it has: {})",
                            names.join(", ")
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// Whether FLIP must be computed to judge.
    pub fn needs_flip(&self) -> bool {
        self.bounds.iter().any(|b| b.metric == ImageMetric::Flip)
    }

    /// A bound's value in a scene's figures.
    fn value(b: &ImageBound, scene: &Scene, f: &SceneFigures) -> f64 {
        let e = match &b.material {
            None => &f.all,
            Some(m) => &f.materials[scene.material_index(m).expect("checked materials")],
        };
        b.metric.of(e)
    }

    /// Whether the figures meet every bound.
    pub fn met_by(&self, scene: &Scene, f: &SceneFigures) -> bool {
        self.bounds
            .iter()
            .all(|b| Self::value(b, scene, f) <= b.limit)
    }

    /// The largest value/limit ratio (at most 1 when met; a zero limit counts a non-zero
    /// value as a ratio of value / 1e-12).
    pub fn excess(&self, scene: &Scene, f: &SceneFigures) -> f64 {
        self.bounds
            .iter()
            .map(|b| Self::value(b, scene, f) / b.limit.max(1e-12))
            .fold(0.0, f64::max)
    }

    /// The budget's bounds without FLIP.
    pub fn without_flip(&self) -> ImageBudget {
        ImageBudget {
            text: self.text.clone(),
            bounds: self
                .bounds
                .iter()
                .filter(|b| b.metric != ImageMetric::Flip)
                .cloned()
                .collect(),
        }
    }
}

/// An image's figures against the reference: every covered pixel, and each material's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SceneFigures {
    /// Over every covered pixel.
    pub all: ImageError,
    /// Per material, in the scene's order.
    pub materials: Vec<ImageError>,
}

/// Judges datapaths on a traced scene: the datapath's image against the f64 cos^n image.
pub struct SceneJudge<'a> {
    scene: &'a Scene,
    frags: &'a Fragments,
    /// The f64 cos^n image (display codes).
    pub reference: Vec<[u16; 3]>,
    /// Pixels with a specular term (the only ones a datapath changes).
    lit: Vec<u32>,
}

impl<'a> SceneJudge<'a> {
    /// The judge of a scene, against cos^n with the classic coefficient of `form`.
    pub fn new(
        scene: &'a Scene,
        frags: &'a Fragments,
        form: crate::reference::normalisation::Form,
    ) -> SceneJudge<'a> {
        let reference = frags.shade(&cos_n_lobe(scene, form));
        let lit = (0..frags.base.len())
            .filter(|&p| !frags.terms_of(p).is_empty())
            .map(|p| p as u32)
            .collect();
        SceneJudge {
            scene,
            frags,
            reference,
            lit,
        }
    }

    /// The image of a lobe: the reference everywhere no light adds a specular term.
    pub fn image(&self, lobe: &(dyn Fn(usize, f64) -> f64 + Sync)) -> Vec<[u16; 3]> {
        use rayon::prelude::*;
        let f = self.frags;
        let enc = Encoder::of(f.bits);
        let lit: Vec<(u32, [u16; 3])> = self
            .lit
            .par_iter()
            .map(|&p| {
                let mut rad = f.base[p as usize];
                for t in f.terms_of(p as usize) {
                    let f_s = lobe(usize::from(t.material), t.c);
                    for (r, w) in rad.iter_mut().zip(t.weight) {
                        *r += f_s * w;
                    }
                }
                (p, rad.map(|x| enc.encode(x)))
            })
            .collect();
        let mut image = self.reference.clone();
        for (p, c) in lit {
            image[p as usize] = c;
        }
        image
    }

    /// The datapath's image.
    pub fn datapath_image(&self, dp: &Datapath) -> Vec<[u16; 3]> {
        let table = DatapathLobe::new(dp, self.scene);
        self.image(&|m, c| table.eval(m, c))
    }

    /// The f64 model image of a datapath's algorithm and coefficient (its floor).
    pub fn model_image(&self, dp: &Datapath) -> Vec<[u16; 3]> {
        let model = ModelLobe::new(dp, self.scene);
        self.image(&|m, c| model.eval(m, c))
    }

    /// An image's figures against the reference, with FLIP when asked (else FLIP means 0).
    pub fn figures(&self, image: &[[u16; 3]], flip: bool) -> SceneFigures {
        let flip = if flip { self.flip(image) } else { Vec::new() };
        let diff = difference_of(image, &self.reference);
        let material = &self.frags.material;
        SceneFigures {
            all: image_error_of(material, &diff, None, &flip),
            materials: (0..self.scene.materials.len())
                .map(|m| image_error_of(material, &diff, Some(m as u16), &flip))
                .collect(),
        }
    }

    /// Per-pixel FLIP of an image against the reference.
    pub fn flip(&self, image: &[[u16; 3]]) -> Vec<f32> {
        let f = self.frags;
        flip_of((f.width, f.height, f.bits), image, &self.reference)
    }

    /// The verdict of an image on a budget (FLIP computed only when the other bounds hold).
    pub fn verdict(&self, image: &[[u16; 3]], budget: &ImageBudget) -> Verdict {
        let scene = self.scene;
        let cheap = self.figures(image, false);
        let rest = budget.without_flip();
        if !rest.met_by(scene, &cheap) || !budget.needs_flip() {
            return Verdict {
                feasible: budget.met_by(scene, &cheap),
                excess: budget.excess(scene, &cheap),
            };
        }
        let full = self.figures(image, true);
        Verdict {
            feasible: budget.met_by(scene, &full),
            excess: budget.excess(scene, &full),
        }
    }
}

/// The f64 floor of one algorithm on the scene: the image of its f64 model (no quantization).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Floor {
    /// Squarings.
    pub k: u32,
    /// Variant.
    pub variant: Variant,
    /// Each exponent at its own best depth (`depth = "best"`; the twin of a fixed-depth
    /// algorithm, listed only when some exponent of the scene squares fewer than k times).
    pub per_n: bool,
    /// The f64 model image's figures against cos^n (`None`: the algorithm is not valid for
    /// the scene's exponents; `reason` says why).
    pub figures: Option<SceneFigures>,
    /// Why there are no figures.
    pub reason: Option<String>,
    /// Whether the floor meets the budget (the search tries only those that do).
    pub meets: bool,
}

/// The f64 floor of every algorithm (k = 1..=7, plain and minimax, fixed and per-n depth:
/// [`Algorithm::all`]) on the scene.
pub fn floors(
    judge: &SceneJudge<'_>,
    base: &Config,
    budget: &ImageBudget,
    start_frac: i32,
) -> Vec<Floor> {
    let algorithms = Algorithm::every(base);
    let mut v = Vec::new();
    for a in algorithms {
        let Algorithm { k, variant, per_n } = a;
        {
            let dp = start_of(base, a, start_frac).and_then(Datapath::new);
            let floor = match dp {
                Err(e) => Floor {
                    k,
                    variant,
                    per_n,
                    figures: None,
                    reason: Some(e.to_string()),
                    meets: false,
                },
                Ok(dp) => {
                    let image = judge.model_image(&dp);
                    let e = judge.figures(&image, budget.needs_flip());
                    Floor {
                        k,
                        variant,
                        per_n,
                        meets: budget.met_by(judge.scene, &e),
                        figures: Some(e),
                        reason: None,
                    }
                }
            };
            v.push(floor);
        }
    }
    v
}

/// The search space of one algorithm: the internal stages from `start_frac` fraction bits,
/// then the input's fraction bits, the coefficient's integer and fraction bits and the
/// output's; TRN or RND everywhere, then per-stage rounding moves; overflow modes are kept
/// (a scene proves nothing about inputs it does not produce).
pub fn fit_space(k: u32, variant: Variant, per_n: bool, start_frac: i32) -> Space {
    let mut extra_knobs = vec![
        Knob::InputFrac,
        Knob::CoefInt,
        Knob::CoefFrac,
        Knob::Frac(Stage::Out),
        Knob::OutInt,
    ];
    if variant == Variant::Minimax {
        extra_knobs.extend([Knob::MinimaxSlopeFrac, Knob::MinimaxOffsetFrac]);
    }
    Space {
        choices: Choices {
            k: vec![k],
            variants: vec![variant],
            per_n: vec![per_n],
            roundings: vec![Rounding::Trn, Rounding::Rnd],
        },
        start_frac,
        extra_knobs,
        local_roundings: vec![Rounding::Trn, Rounding::Rnd],
        overflow_moves: false,
        arch: crate::cycle::Arch::Pipelined,
    }
}

/// The search's objective: the analytic LUTs of the pipelined datapath on `target` plus its
/// constant ROM's (the figures `fit` reports).
pub fn objective(dp: &Datapath, target: crate::hdl::cost::Target) -> u64 {
    crate::hdl::cost::analytic_cost(dp, crate::cycle::Arch::Pipelined, target).luts
        + crate::hdl::rom::constant_rom(dp, target).luts
}

/// What the fit's search found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitSearch {
    /// The cheapest datapath meeting the budget, if any.
    pub best: Option<Candidate>,
    /// The closest one otherwise.
    pub closest: Option<Candidate>,
    /// Candidates judged.
    pub n_evaluations: u64,
    /// Why the answer is minimal within the search.
    pub minimality: Vec<String>,
}

/// Searches every fixed-depth algorithm whose floor meets the budget (in parallel, results
/// combined in the floors' order), then, when none has an answer, the per-n-depth ones
/// (each of the scene's exponents at its own best depth: bypass multiplexers are paid for only
/// where they are what meets the budget), then the base itself: the cheapest datapath by
/// [`objective`] whose image meets `budget` on every input of the scene.
///
/// FLIP is the costly metric (a full-image filter); each algorithm is first searched with
/// the budget's other bounds, and its answer checked with FLIP too; only when that fails is
/// the algorithm searched again with the whole budget. Minimality holds either way: a point
/// that breaks the looser budget breaks the whole one.
pub fn fit_search(
    judge: &SceneJudge<'_>,
    base: &Config,
    budget: &ImageBudget,
    floors: &[Floor],
    start_frac: i32,
    target: crate::hdl::cost::Target,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<FitSearch, Error> {
    use rayon::prelude::*;
    let cheap = budget.without_flip();
    let group = |per_n: bool| -> Vec<Result<(SearchResult, u64), Error>> {
        floors
            .par_iter()
            .filter(|f| f.meets && f.per_n == per_n)
            .map(|f| {
                let name = format!(
                    "k = {}, {}{}",
                    f.k,
                    f.variant.name(),
                    if f.per_n { ", per-n depth" } else { "" }
                );
                let space = fit_space(f.k, f.variant, f.per_n, start_frac);
                let mut cost =
                    |dp: &Datapath| -> Result<f64, Error> { Ok(objective(dp, target) as f64) };
                let mut lines = |line: &str| progress(&format!("{name}: {line}"));
                let run = |b: &ImageBudget,
                           cost: &mut dyn FnMut(&Datapath) -> Result<f64, Error>,
                           lines: &mut dyn FnMut(&str)| {
                    let mut j = |dp: &Datapath| -> Result<Verdict, Error> {
                        Ok(judge.verdict(&judge.datapath_image(dp), b))
                    };
                    search(base, &space, &mut j, cost, lines)
                };
                let mut r = run(&cheap, &mut cost, &mut lines)?;
                let mut extra = 0;
                if budget.needs_flip() {
                    if let Some(b) = &r.best {
                        extra += 1;
                        let dp = Datapath::new(b.config.clone())?;
                        if !judge.verdict(&judge.datapath_image(&dp), budget).feasible {
                            progress(&format!(
                                "{name}: FLIP breaks the budget, searching again with it"
                            ));
                            let n = r.n_evaluations;
                            r = run(budget, &mut cost, &mut lines)?;
                            extra += n;
                        }
                    }
                }
                progress(&format!(
                    "{name}: {}",
                    r.best
                        .as_ref()
                        .map_or("nothing fits".to_string(), |b| format!(
                            "{:.0} LUTs",
                            b.cost
                        ))
                ));
                Ok((r, extra))
            })
            .collect()
    };
    let mut searched = Vec::new();
    let mut extra = 0;
    for r in group(false) {
        let (r, e) = r?;
        searched.push(r);
        extra += e;
    }
    if searched.iter().all(|r| r.best.is_none()) {
        for r in group(true) {
            let (r, e) = r?;
            searched.push(r);
            extra += e;
        }
    }
    let c = combine(searched);
    let mut out = FitSearch {
        best: c.best,
        closest: c.closest,
        n_evaluations: c.n_evaluations + extra,
        minimality: c.minimality,
    };
    // The base restricted to the scene's exponents renders the scene exactly as the generic
    // datapath does: a candidate too, so a budget the generic datapath meets has an answer.
    let dp = Datapath::new(base.clone())?;
    let v = judge.verdict(&judge.datapath_image(&dp), budget);
    out.n_evaluations += 1;
    let cost = objective(&dp, target) as f64;
    if v.feasible && out.best.as_ref().is_none_or(|b| cost < b.cost) {
        out.minimality = vec![
            "the base datapath restricted to the scene's exponents: no searched point was cheaper"
                .into(),
        ];
        out.best = Some(Candidate {
            config: base.clone(),
            cost,
            feasible: true,
            excess: v.excess,
            arch: crate::cycle::Arch::Pipelined,
        });
    }
    Ok(out)
}
