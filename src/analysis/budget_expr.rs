//! Error budgets as users write them (`shape_total <= 1 lsb8 and luts <= 800 on ice40`): the
//! metrics a budget can bound, its bounds, their parsing and canonical form, and a candidate's
//! verdict against them (the check's figures, the analytic cost, yosys's counts through a
//! [`Synthesise`] closure). `optimize`, `budget` and `fit` judge by it.

use std::fmt;
use std::str::FromStr;

use serde::Serialize;

use crate::analysis::check::OutputFigures;
use crate::cycle::Arch;
use crate::error::Error;
use crate::hdl::cost::{analytic_cost, AnalyticCost, Target};
use crate::pipeline::Datapath;

/// A quantity a budget can bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// max |fixed lobe - cos^n| (`shape_total`).
    ShapeTotal,
    /// max |fixed lobe - f64 lobe| (`shape_quant`).
    ShapeQuant,
    /// max output error in output LSBs (`out`, unit `ulp`).
    Out,
    /// Share of outputs correctly rounded (`correct`, a fraction or a percentage).
    Correct,
    /// max |output - exact normalised cos^n| in output LSBs (`out_total`, unit `ulp`).
    OutTotal,
    /// The same relative to the exact normalised peak coef(n) (`out_rel`, a fraction or %).
    OutRel,
    /// Effective bits of the normalised output, -log2 of `out_rel` (`effective_bits >= 8`).
    EffectiveBits,
    /// Analytic LUTs on a target (`luts <= 800 on ice40`), of the budget's microarchitecture.
    Luts(Target),
    /// Analytic DSP blocks on a target (`dsps <= 8 on ice40`).
    Dsps(Target),
    /// Analytic register bits on a target (`ffs <= 400 on ice40`).
    Ffs(Target),
    /// yosys's LUTs (gates for generic) on a target (`yosys_luts <= 800 on ice40`).
    YosysLuts(Target),
    /// yosys's DSP blocks on a target (`yosys_dsps <= 8 on ice40`).
    YosysDsps(Target),
    /// yosys's flip-flops on a target (`yosys_ffs <= 400 on ice40`).
    YosysFfs(Target),
}

/// Synthesises a datapath on a target and returns yosys's figures: the command supplies it
/// (the library starts no process) for budgets with yosys ceilings.
pub type Synthesise<'a> =
    &'a (dyn Fn(&Datapath, Arch, Target) -> Result<crate::hdl::cost::CostFigures, Error> + Sync);

impl fmt::Display for Metric {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Metric::ShapeTotal => f.write_str("shape_total"),
            Metric::ShapeQuant => f.write_str("shape_quant"),
            Metric::Out => f.write_str("out"),
            Metric::Correct => f.write_str("correct"),
            Metric::OutTotal => f.write_str("out_total"),
            Metric::OutRel => f.write_str("out_rel"),
            Metric::EffectiveBits => f.write_str("effective_bits"),
            Metric::Luts(t) => write!(f, "luts on {}", t.name()),
            Metric::Dsps(t) => write!(f, "dsps on {}", t.name()),
            Metric::Ffs(t) => write!(f, "ffs on {}", t.name()),
            Metric::YosysLuts(t) => write!(f, "yosys_luts on {}", t.name()),
            Metric::YosysDsps(t) => write!(f, "yosys_dsps on {}", t.name()),
            Metric::YosysFfs(t) => write!(f, "yosys_ffs on {}", t.name()),
        }
    }
}

impl Metric {
    /// Whether the metric is a cost ceiling (evaluated from the formats, no check needed).
    pub fn is_cost(self) -> bool {
        matches!(self, Metric::Luts(_) | Metric::Dsps(_) | Metric::Ffs(_)) || self.is_yosys()
    }

    /// Whether the metric is a yosys ceiling (measured by synthesis, not the model).
    pub fn is_yosys(self) -> bool {
        matches!(
            self,
            Metric::YosysLuts(_) | Metric::YosysDsps(_) | Metric::YosysFfs(_)
        )
    }

    /// Whether the bound is a floor (`>=`: `correct`, `effective_bits`) rather than a ceiling.
    pub fn is_floor(self) -> bool {
        matches!(self, Metric::Correct | Metric::EffectiveBits)
    }

    /// How a limit of the metric is written: its unit, or why it takes a bare number. A bound
    /// on a metric with a unit must name it (`shape_total <= 1` is refused, never read as an
    /// absolute 1.0).
    ///
    /// # Examples
    /// ```
    /// use specfx::analysis::budget_expr::Metric;
    /// assert_eq!(Metric::Out.units(), "ulp (output LSBs), e.g. 'out <= 1 ulp'");
    /// ```
    pub fn units(self) -> &'static str {
        match self {
            Metric::ShapeTotal => "lsbN (2^-N, N in 1..=64), e.g. 'shape_total <= 1 lsb8'",
            Metric::ShapeQuant => "lsbN (2^-N, N in 1..=64), e.g. 'shape_quant <= 0.5 lsb8'",
            Metric::Out => "ulp (output LSBs), e.g. 'out <= 1 ulp'",
            Metric::OutTotal => "ulp (output LSBs), e.g. 'out_total <= 4 ulp'",
            Metric::Correct => "% or a fraction, e.g. 'correct >= 99%' or 'correct >= 0.99'",
            Metric::OutRel => "% or a fraction, e.g. 'out_rel <= 1%' or 'out_rel <= 0.01'",
            Metric::EffectiveBits => "a number of bits, no unit, e.g. 'effective_bits >= 8'",
            _ => "a whole number of cells, no unit, e.g. 'luts <= 800 on ice40'",
        }
    }

    /// Whether the metric measures the normalised output against exact normalised cos^n.
    pub fn is_normalised(self) -> bool {
        matches!(
            self,
            Metric::OutTotal | Metric::OutRel | Metric::EffectiveBits
        )
    }
}

/// One bound: `metric <= value` (or `>=` for `correct`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Bound {
    /// The metric.
    pub metric: Metric,
    /// The limit, in the metric's own unit (absolute, LSBs or a fraction).
    pub limit: f64,
}

/// An error budget: every bound must hold.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Budget {
    /// The text it was parsed from.
    pub text: String,
    /// The bounds.
    pub bounds: Vec<Bound>,
    /// The microarchitecture cost ceilings are counted on (pipelined unless the command sets
    /// it, as `optimize --arch` does).
    pub arch: Arch,
}

impl FromStr for Budget {
    type Err = Error;
    /// Parses `shape_total <= 1 lsb8`, `shape_quant <= 0.5 lsb8`, `out <= 1 ulp`,
    /// `correct >= 99%` (or `0.99`), the normalised output against exact normalised cos^n
    /// `out_total <= 4 ulp`, `out_rel <= 1%`, `effective_bits >= 8`, and cost ceilings `luts <= 800 on ice40`, `dsps <= 8 on
    /// ice40`, `ffs <= 400 on xilinx` (analytic; target ice40 when `on` is left out),
    /// several joined by `,` or `and`. `lsbN` is 2^-N. A metric with a unit needs it
    /// ([`Metric::units`]): `shape_total <= 1` and `out <= 1` are refused.
    ///
    /// # Examples
    /// ```
    /// use specfx::analysis::budget_expr::Budget;
    /// let b: Budget = "shape_total <= 1 lsb8".parse().unwrap();
    /// assert_eq!(b.bounds[0].limit, 1.0 / 256.0);
    /// let e = "shape_total <= 1".parse::<Budget>().unwrap_err().to_string();
    /// assert!(e.starts_with("budget: 'shape_total <= 1' is a bare number: shape_total takes lsbN"), "{e}");
    /// ```
    fn from_str(s: &str) -> Result<Self, Error> {
        let (text, bounds) = parse_bounds(
            s,
            &["<=", ">="],
            "'shape_total <= 1 lsb8', 'out <= 1 ulp', 'correct >= 99%', 'dsps <= 8 on ice40'",
            parse_bound,
        )?;
        Ok(Budget {
            text,
            bounds,
            arch: Arch::Pipelined,
        })
    }
}

/// One bound of a [`Budget`]: `lhs op rhs` of the expression's `part`, `bad` the error of a
/// malformed one.
fn parse_bound(b: &RawBound<'_>, bad: &dyn Fn(&str) -> Error) -> Result<Bound, Error> {
    let RawBound { part, lhs, op, rhs } = *b;
    let on = rhs.split_once(" on ");
    let (rhs, target) = match on {
        Some((r, t)) => (
            r,
            t.trim()
                .parse::<Target>()
                .map_err(|e| bad(&e.to_string()))?,
        ),
        None => (rhs, Target::Ice40),
    };
    let metric = match lhs.trim() {
        "luts" => Metric::Luts(target),
        "dsps" => Metric::Dsps(target),
        "ffs" => Metric::Ffs(target),
        "yosys_luts" => Metric::YosysLuts(target),
        "yosys_dsps" => Metric::YosysDsps(target),
        "yosys_ffs" => Metric::YosysFfs(target),
        "shape_total" => Metric::ShapeTotal,
        "shape_quant" => Metric::ShapeQuant,
        "out" => Metric::Out,
        "correct" => Metric::Correct,
        "out_total" => Metric::OutTotal,
        "out_rel" => Metric::OutRel,
        "effective_bits" => Metric::EffectiveBits,
        other => return Err(bad(&format!("unknown metric '{other}'"))),
    };
    if on.is_some() && !metric.is_cost() {
        return Err(bad(
            "only luts, dsps, ffs and their yosys_ forms take 'on TARGET'",
        ));
    }
    let want_op = if metric.is_floor() { ">=" } else { "<=" };
    if op != want_op {
        return Err(bad(&format!("{} takes {want_op}", lhs.trim())));
    }
    let rhs = rhs.trim();
    let unit_at = rhs
        .find("lsb")
        .or_else(|| rhs.find("ulp"))
        .or_else(|| rhs.find('%'))
        .or_else(|| rhs.find(char::is_whitespace));
    let (number, unit) = match unit_at {
        Some(i) => (rhs[..i].trim(), rhs[i..].trim()),
        None => (rhs, ""),
    };
    let value: f64 = number.parse().map_err(|_| bad("no number"))?;
    if !value.is_finite() || value < 0.0 {
        return Err(bad("the limit must be a finite number >= 0"));
    }
    let name = lhs.trim();
    let bare_ok = matches!(
        metric,
        Metric::Correct | Metric::OutRel | Metric::EffectiveBits
    ) || metric.is_cost();
    // A unit error says which units the metric takes, not the general examples.
    let bad_unit = |why: String| Error::Config {
        key: "budget".into(),
        problem: format!("'{part}' {why}: {name} takes {}", metric.units()),
    };
    if unit.is_empty() && !bare_ok {
        return Err(bad_unit("is a bare number".into()));
    }
    let limit = match (metric, unit) {
        (Metric::ShapeTotal | Metric::ShapeQuant, u) if u.starts_with("lsb") => {
            let bits: i32 = u[3..]
                .parse()
                .ok()
                .filter(|b| (1..=64).contains(b))
                .ok_or_else(|| bad("lsbN needs a number N in 1..=64"))?;
            value * (-f64::from(bits)).exp2()
        }
        (Metric::Out | Metric::OutTotal, "ulp") => value,
        (Metric::Correct | Metric::OutRel, "%") => value / 100.0,
        (Metric::Correct | Metric::OutRel, "") => value,
        (Metric::EffectiveBits, "") => value,
        (m, "") if m.is_cost() => value,
        _ => {
            return Err(bad_unit(format!("has the unit '{unit}'")));
        }
    };
    if metric.is_cost() && value.fract() != 0.0 {
        return Err(bad("a count of cells is a whole number"));
    }
    if metric == Metric::Correct && limit > 1.0 {
        return Err(bad("a share of inputs is at most 100%"));
    }
    if metric == Metric::EffectiveBits && limit > 64.0 {
        return Err(bad("effective bits are at most 64"));
    }
    Ok(Bound { metric, limit })
}

/// A bound of a budget expression as a parser receives it: its whole text (`part`), the
/// metric's text (`lhs`), the operator and the limit's text (`rhs`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RawBound<'a> {
    pub part: &'a str,
    pub lhs: &'a str,
    pub op: &'static str,
    pub rhs: &'a str,
}

/// The skeleton of the budget parsers ([`Budget`], `scene::fit::ImageBudget`): the bounds of
/// `s` ([`bound_parts`]), each split at the first of `ops` it holds and parsed by `bound`, with
/// the expression's canonical text (the bounds joined by ` and `). Every error is one line
/// under the key `budget`: why, in which bound, and `examples` of good ones.
pub(crate) fn parse_bounds<B>(
    s: &str,
    ops: &[&'static str],
    examples: &str,
    bound: impl Fn(&RawBound<'_>, &dyn Fn(&str) -> Error) -> Result<B, Error>,
) -> Result<(String, Vec<B>), Error> {
    let bad = |part: &str, why: &str| Error::Config {
        key: "budget".into(),
        problem: format!("{why} in '{part}'; expected e.g. {examples}"),
    };
    let parts = bound_parts(s).map_err(|why| bad(s.trim(), &why))?;
    let mut bounds = Vec::with_capacity(parts.len());
    for part in &parts {
        let part = part.as_str();
        let Some((lhs, op, rhs)) = ops
            .iter()
            .find_map(|&op| part.split_once(op).map(|(l, r)| (l, op, r)))
        else {
            return Err(bad(part, &format!("no {}", ops.join(" or "))));
        };
        if ops.iter().any(|op| rhs.contains(op)) {
            return Err(bad(part, "two bounds need ',' or 'and' between them"));
        }
        let raw = RawBound { part, lhs, op, rhs };
        bounds.push(bound(&raw, &|why| bad(part, why))?);
    }
    // One canonical spelling: no newline or other separator survives into a report.
    Ok((parts.join(" and "), bounds))
}

/// The bounds of a budget expression: the parts between `,` and the word `and`, each with its
/// words joined by single spaces.
///
/// # Errors
/// An empty part (a separator at either end, or two in a row) is refused, with why;
/// [`parse_bounds`] puts it in its error.
fn bound_parts(s: &str) -> Result<Vec<String>, String> {
    let mut parts = Vec::new();
    for piece in s.split(',') {
        let mut words: Vec<&str> = Vec::new();
        for word in piece.split_whitespace() {
            if word == "and" {
                parts.push(words.join(" "));
                words.clear();
            } else {
                words.push(word);
            }
        }
        parts.push(words.join(" "));
    }
    if parts.iter().any(String::is_empty) {
        return Err("an empty bound (',' or 'and' with nothing before or after it)".into());
    }
    Ok(parts)
}

impl fmt::Display for Budget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

/// The value of a metric: from a check's output figures, or for a cost ceiling the analytic
/// cost of the datapath on `arch` and the metric's target. A yosys ceiling is measured by
/// synthesis ([`Budget::cost_verdict`] with a [`Synthesise`]): here it is NaN, which meets no
/// bound.
pub fn metric_value(r: &OutputFigures, dp: &Datapath, arch: Arch, metric: Metric) -> f64 {
    match metric {
        Metric::ShapeTotal => r.shape_total_max_abs,
        Metric::ShapeQuant => r.shape_quant_max_abs,
        Metric::Out => r.out_max_ulp,
        Metric::Correct => r.out_correctly_rounded,
        Metric::OutTotal => r.norm_total_max_abs / dp.config().out.format.lsb(),
        Metric::OutRel => r.norm_total_rel,
        Metric::EffectiveBits => r.effective_bits(),
        Metric::Luts(_) | Metric::Dsps(_) | Metric::Ffs(_) => cost_value(dp, arch, metric),
        Metric::YosysLuts(_) | Metric::YosysDsps(_) | Metric::YosysFfs(_) => f64::NAN,
    }
}

/// A cost ceiling's value: the analytic cost on the metric's target.
fn cost_value(dp: &Datapath, arch: Arch, metric: Metric) -> f64 {
    let (target, pick): (Target, fn(&AnalyticCost) -> u64) = match metric {
        Metric::Luts(t) => (t, |c| c.luts),
        Metric::Dsps(t) => (t, |c| c.dsps),
        Metric::Ffs(t) => (t, |c| c.ffs),
        _ => unreachable!("a cost metric"),
    };
    pick(&analytic_cost(dp, arch, target)) as f64
}

impl Budget {
    /// The bounds in one notation, sorted (`shape_total <= 0.00390625`, `luts on ice40 <=
    /// 800`): the same budget written differently gives the same list.
    ///
    /// # Examples
    /// ```
    /// use specfx::analysis::budget_expr::Budget;
    /// let a: Budget = "shape_total <= 1 lsb8, correct >= 99%".parse().unwrap();
    /// let b: Budget = "correct >= 0.99 and shape_total<=0.5 lsb7".parse().unwrap();
    /// assert_eq!(a.canonical(), ["correct >= 0.99", "shape_total <= 0.00390625"]);
    /// assert_eq!(a.canonical(), b.canonical());
    /// ```
    pub fn canonical(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .bounds
            .iter()
            .map(|b| {
                let op = if b.metric.is_floor() { ">=" } else { "<=" };
                format!("{} {op} {}", b.metric, b.limit)
            })
            .collect();
        v.sort();
        v.dedup();
        v
    }

    /// Whether a bound holds for a value.
    fn holds(b: &Bound, v: f64) -> bool {
        if b.metric.is_floor() {
            v >= b.limit
        } else {
            v <= b.limit
        }
    }

    /// A bound's value/limit ratio (limit/value for `correct`): at most 1 when it holds.
    fn ratio(b: &Bound, v: f64) -> f64 {
        if b.metric.is_floor() {
            b.limit / v.max(1e-300)
        } else {
            v / b.limit.max(1e-300)
        }
    }

    /// Whether a datapath and its check meet every bound but the yosys ceilings (which
    /// [`Budget::cost_verdict`] measures by synthesis).
    pub fn met_by(&self, r: &OutputFigures, dp: &Datapath) -> bool {
        self.bounds
            .iter()
            .filter(|b| !b.metric.is_yosys())
            .all(|b| Self::holds(b, metric_value(r, dp, self.arch, b.metric)))
    }

    /// How far a datapath and its check are from the budget (yosys ceilings aside): the
    /// largest ratio; at most 1 when met.
    pub fn excess(&self, r: &OutputFigures, dp: &Datapath) -> f64 {
        self.bounds
            .iter()
            .filter(|b| !b.metric.is_yosys())
            .map(|b| Self::ratio(b, metric_value(r, dp, self.arch, b.metric)))
            .fold(0.0, f64::max)
    }

    /// The budget without its cost ceilings.
    pub fn without_costs(&self) -> Budget {
        Budget {
            text: self.text.clone(),
            bounds: self
                .bounds
                .iter()
                .filter(|b| !b.metric.is_cost())
                .copied()
                .collect(),
            arch: self.arch,
        }
    }

    /// Each cost ceiling of the budget with its value for `dp`, in the budget's order: the
    /// analytic cost, or yosys's count measured with `synth` (one synthesis per target; an
    /// error without it).
    pub fn cost_values(
        &self,
        dp: &Datapath,
        synth: Option<Synthesise>,
    ) -> Result<Vec<(Bound, f64)>, Error> {
        let mut synthesised: Vec<(Target, crate::hdl::cost::CostFigures)> = Vec::new();
        let mut costs: Vec<(Bound, f64)> = Vec::new();
        for b in self.bounds.iter().filter(|b| b.metric.is_cost()) {
            let v = match b.metric {
                Metric::YosysLuts(t) | Metric::YosysDsps(t) | Metric::YosysFfs(t) => {
                    let synth = synth.ok_or_else(|| Error::Tool {
                        tool: "yosys",
                        message: format!("the budget's {} needs synthesis", b.metric),
                    })?;
                    let figures = match synthesised.iter().find(|(x, _)| *x == t) {
                        Some((_, f)) => *f,
                        None => {
                            let f = synth(dp, self.arch, t)?;
                            synthesised.push((t, f));
                            f
                        }
                    };
                    let count = match b.metric {
                        Metric::YosysLuts(_) => figures.luts,
                        Metric::YosysDsps(_) => figures.dsps,
                        _ => figures.ffs,
                    };
                    count as f64
                }
                m => cost_value(dp, self.arch, m),
            };
            costs.push((*b, v));
        }
        Ok(costs)
    }

    /// The cost ceilings alone: whether they hold, and their largest ratio (no check needed);
    /// yosys ceilings are measured with `synth` (one synthesis per target), and are an error
    /// without it.
    pub fn cost_verdict(&self, dp: &Datapath, synth: Option<Synthesise>) -> Result<Verdict, Error> {
        let costs = self.cost_values(dp, synth)?;
        let costs: Vec<(&Bound, f64)> = costs.iter().map(|(b, v)| (b, *v)).collect();
        Ok(Verdict {
            feasible: costs.iter().all(|&(b, v)| Self::holds(b, v)),
            excess: costs
                .iter()
                .map(|&(b, v)| Self::ratio(b, v))
                .fold(0.0, f64::max),
        })
    }
}

/// Whether a candidate meets the budget, and how far it is from it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Verdict {
    /// It meets every bound.
    pub feasible: bool,
    /// The largest ratio value/limit over the bounds (at most 1 when feasible).
    pub excess: f64,
}

#[cfg(test)]
mod tests {
    use super::{bound_parts, Budget, Metric};

    /// A metric with a unit needs it: a bare number is refused with the units it takes, never
    /// read as an absolute value (`shape_total <= 1` was 1.0, 256 lsb8). Metrics without a
    /// unit (shares as fractions, effective bits, cell counts) take a bare number.
    #[test]
    fn a_bare_number_is_refused_where_the_metric_has_a_unit() {
        for (text, metric, units) in [
            (
                "shape_total <= 1",
                "shape_total",
                "lsbN (2^-N, N in 1..=64)",
            ),
            (
                "shape_quant <= 0.5",
                "shape_quant",
                "lsbN (2^-N, N in 1..=64)",
            ),
            ("out <= 1", "out", "ulp (output LSBs)"),
            ("out_total <= 4", "out_total", "ulp (output LSBs)"),
        ] {
            let e = text.parse::<Budget>().unwrap_err().to_string();
            assert!(
                e.starts_with(&format!(
                    "budget: '{text}' is a bare number: {metric} takes {units}, e.g. '"
                )),
                "{e}"
            );
        }
        let e = "shape_total <= 1 parsecs"
            .parse::<Budget>()
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(
                "budget: 'shape_total <= 1 parsecs' has the unit 'parsecs': shape_total takes lsbN"
            ),
            "{e}"
        );
        // Hand values: 1 lsb8 = 2^-8, 0.5 lsb7 = 2^-8, 3 ulp = 3, 99% = 0.99.
        let b: Budget = "shape_total <= 1 lsb8, shape_quant <= 0.5 lsb7, out <= 3 ulp, out_total <= 2ulp, correct >= 99%, out_rel <= 0.01, effective_bits >= 8, luts <= 800"
            .parse()
            .unwrap();
        let limits: Vec<(Metric, f64)> = b.bounds.iter().map(|b| (b.metric, b.limit)).collect();
        assert_eq!(
            limits,
            [
                (Metric::ShapeTotal, 0.00390625),
                (Metric::ShapeQuant, 0.00390625),
                (Metric::Out, 3.0),
                (Metric::OutTotal, 2.0),
                (Metric::Correct, 0.99),
                (Metric::OutRel, 0.01),
                (Metric::EffectiveBits, 8.0),
                (Metric::Luts(crate::hdl::cost::Target::Ice40), 800.0),
            ]
        );
    }

    #[test]
    fn bounds_are_split_at_commas_and_the_word_and() {
        assert_eq!(
            bound_parts("a <= 1 lsb8 and  b>=2,c <= 3").unwrap(),
            ["a <= 1 lsb8", "b>=2", "c <= 3"]
        );
        assert!(bound_parts("a <= 1 lsb8 and").is_err());
        assert!(bound_parts("a <= 1, , b <= 2").is_err());
    }
}
