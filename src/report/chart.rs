//! Charts: line, marker and bar series on linear or logarithmic axes, rendered to SVG text or
//! PNG bytes with an embedded font (DejaVu Sans), so output is identical on every machine.
//!
//! The rules every chart follows: colours from the Okabe-Ito palette (safe for colour-blind
//! readers), and no two series drawn alike (past eight series the dash pattern and the marker
//! shape change too); direct labels beside the lines instead of a legend where a chart asks
//! for them; logarithmic axes show exact zeros in a band of their own below the decades;
//! integer axes print integers; histograms are bars; reference lines ("1 lsb8") carry their
//! label. Axes, ticks and labels are laid out here rather than by the drawing library, so each
//! of these rules is written once.

use crate::error::Error;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// The Okabe-Ito palette: black, orange, sky blue, bluish green, yellow, blue, vermillion,
/// reddish purple.
pub const OKABE_ITO: [(u8, u8, u8); 8] = [
    (0, 0, 0),
    (230, 159, 0),
    (86, 180, 233),
    (0, 158, 115),
    (240, 228, 66),
    (0, 114, 178),
    (213, 94, 0),
    (204, 121, 167),
];

/// The order in which series take the palette's colours: yellow, the hardest to see on
/// white, comes last.
const COLOR_ORDER: [usize; 8] = [0, 1, 2, 3, 5, 6, 7, 4];

/// The points no other point beats in both x and y (lower is better in both), sorted by x,
/// duplicates once: the line a Pareto front is drawn as.
///
/// # Examples
/// ```
/// use specfx::report::chart::front_2d;
/// let pts = [(10.0, 0.5), (20.0, 0.2), (20.0, 0.3), (5.0, 0.9), (10.0, 0.5)];
/// assert_eq!(front_2d(&pts), vec![(5.0, 0.9), (10.0, 0.5), (20.0, 0.2)]);
/// ```
pub fn front_2d(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut front: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|&(x, y)| {
            !points
                .iter()
                .any(|&(x2, y2)| x2 <= x && y2 <= y && (x2 < x || y2 < y))
        })
        .collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.total_cmp(&a.1)));
    front.dedup();
    front
}

/// The colour of series `i`: the Okabe-Ito palette, yellow last, repeating after eight.
///
/// # Examples
/// ```
/// use specfx::report::chart::color;
/// assert_eq!(color(0), (0, 0, 0));
/// assert_eq!(color(1), (0xE6, 0x9F, 0x00));
/// assert_eq!(color(7), (0xF0, 0xE4, 0x42));
/// assert_eq!(color(8), color(0));
/// ```
pub fn color(i: usize) -> (u8, u8, u8) {
    OKABE_ITO[COLOR_ORDER[i % COLOR_ORDER.len()]]
}

/// The colour of series `i` of `count`: [`color`]`(i)` (the count is no longer used; the
/// palette is fixed).
pub fn hue(i: usize, _count: usize) -> (u8, u8, u8) {
    color(i)
}

/// The pattern of a line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum Dash {
    /// Unbroken.
    #[default]
    Solid,
    /// Long dashes.
    Dashed,
    /// Dots.
    Dotted,
    /// Dash, dot, dash.
    DashDot,
}

impl Dash {
    /// Every pattern, in the order series take them.
    pub const ALL: [Dash; 4] = [Dash::Solid, Dash::Dashed, Dash::Dotted, Dash::DashDot];

    /// On and off lengths in pixels, repeating (empty: solid).
    fn pattern(self) -> &'static [f64] {
        match self {
            Dash::Solid => &[],
            Dash::Dashed => &[10.0, 6.0],
            Dash::Dotted => &[2.0, 5.0],
            Dash::DashDot => &[10.0, 4.0, 2.0, 4.0],
        }
    }
}

/// The shape of a series' markers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum Marker {
    /// A filled disc.
    #[default]
    Circle,
    /// A filled square.
    Square,
    /// A filled triangle pointing up.
    TriangleUp,
    /// A filled diamond.
    Diamond,
    /// A filled triangle pointing down.
    TriangleDown,
    /// An x.
    Cross,
    /// No markers, even on a short line.
    None,
}

impl Marker {
    /// Every shape, in the order series take them.
    pub const ALL: [Marker; 6] = [
        Marker::Circle,
        Marker::Square,
        Marker::TriangleUp,
        Marker::Diamond,
        Marker::TriangleDown,
        Marker::Cross,
    ];
}

/// The automatic style of series `i`: its [`color`], and past eight series another dash
/// pattern; the marker shape changes with every series. No two of the first 32 are alike.
///
/// # Examples
/// ```
/// use specfx::report::chart::{style, Dash, Marker};
/// assert_eq!(style(0), ((0, 0, 0), Dash::Solid, Marker::Circle));
/// assert_eq!(style(8).1, Dash::Dashed);
/// assert_ne!(style(0), style(8));
/// ```
pub fn style(i: usize) -> ((u8, u8, u8), Dash, Marker) {
    (
        color(i),
        Dash::ALL[(i / 8) % Dash::ALL.len()],
        Marker::ALL[i % Marker::ALL.len()],
    )
}

/// Lines of at most this many points also carry markers.
const MARKED_LINE_POINTS: usize = 60;

/// One series of a chart.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Label (legend or direct label).
    pub label: String,
    /// The (x, y) points, in drawing order.
    pub points: Vec<(f64, f64)>,
    /// Draw a line through the points (else only markers).
    pub line: bool,
    /// RGB colour.
    pub color: (u8, u8, u8),
    /// The line's pattern.
    pub dash: Dash,
    /// The markers' shape (drawn without a line, or on lines of at most 60 points).
    pub marker: Marker,
    /// Draw each point as a bar of this width (in x units) rising from the axis: a
    /// histogram. Lines and markers are then not drawn.
    pub bar_width: Option<f64>,
}

impl Series {
    /// A series in the automatic [`style`] of index `i`.
    pub fn styled(label: &str, points: Vec<(f64, f64)>, line: bool, i: usize) -> Series {
        let (color, dash, marker) = style(i);
        Series {
            label: label.into(),
            points,
            line,
            color,
            dash,
            marker,
            bar_width: None,
        }
    }

    fn marked(&self) -> bool {
        self.bar_width.is_none()
            && self.marker != Marker::None
            && (!self.line || self.points.len() <= MARKED_LINE_POINTS)
    }
}

/// A reference line with its label, e.g. a tolerance of 1 lsb8.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RefLine {
    /// Where it is: in y units on a horizontal line, in x units on a vertical one.
    pub at: f64,
    /// What it is, printed on the line.
    pub label: String,
}

/// A chart: title, axis labels with their units, series, and how to draw them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Chart {
    /// Title at the top.
    pub title: String,
    /// X axis label, with its unit.
    pub x_label: String,
    /// Y axis label, with its unit.
    pub y_label: String,
    /// Logarithmic x axis (exact zeros are shown in a band left of the decades).
    pub log_x: bool,
    /// Logarithmic y axis (exact zeros are shown in a band below the decades).
    pub log_y: bool,
    /// The series.
    pub series: Vec<Series>,
    /// The x axis counts something: ticks only at integers, printed as integers.
    pub x_integer: bool,
    /// The y axis counts something: ticks only at integers, printed as integers.
    pub y_integer: bool,
    /// Horizontal reference lines.
    pub ref_lines: Vec<RefLine>,
    /// Vertical reference lines.
    pub x_ref_lines: Vec<RefLine>,
    /// Label each series beside its last point instead of in a legend box.
    pub direct_labels: bool,
}

/// Chart size in pixels (the SVG uses the same user units).
pub const SIZE: (u32, u32) = (960, 640);

/// Registers the embedded font under `sans-serif` (once).
pub fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .map_err(|_| ())
            .expect("the embedded DejaVu Sans is a valid font");
    });
}

/// Replaces ASCII hyphen-minus signs by U+2212 MINUS SIGN, and `-0` by `0`.
///
/// # Examples
/// ```
/// use specfx::report::chart::minus_sign;
/// assert_eq!(minus_sign("-1.5"), "\u{2212}1.5");
/// assert_eq!(minus_sign("-0.00"), "0.00");
/// assert_eq!(minus_sign("3e-4"), "3e\u{2212}4");
/// ```
pub fn minus_sign(s: &str) -> String {
    let negative_zero = s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.');
    let s = if negative_zero { &s[1..] } else { s };
    s.replace('-', "\u{2212}")
}

/// An absolute lobe value in lsb8 (2^-8, a step of an 8-bit display at the lobe's peak, the
/// unit of `1 lsb8` tolerances), to three significant digits: `1 lsb8`, `0.001 lsb8`.
///
/// # Examples
/// ```
/// use specfx::report::chart::lsb8;
/// assert_eq!(lsb8(1.0 / 256.0), "1 lsb8");
/// assert_eq!(lsb8(1.0 / 256_000.0), "0.001 lsb8");
/// assert_eq!(lsb8(0.017), "4.35 lsb8");
/// assert_eq!(lsb8(0.0), "0 lsb8");
/// ```
pub fn lsb8(v: f64) -> String {
    let x = v / crate::analysis::LSB8;
    let text = if x == 0.0 {
        "0".to_string()
    } else if !(1e-4..1e4).contains(&x.abs()) {
        format!("{x:.2e}")
    } else {
        let decimals = (2 - x.abs().log10().floor() as i32).max(0) as usize;
        let t = format!("{x:.decimals$}");
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    };
    format!("{} lsb8", minus_sign(&text))
}

/// `10^k` written with superscript digits: `10⁻³`.
fn power_of_ten(k: i32) -> String {
    const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::from("10");
    if k < 0 {
        s.push('⁻');
    }
    for d in k.unsigned_abs().to_string().bytes() {
        s.push(SUP[usize::from(d - b'0')]);
    }
    s
}

/// One tick of an axis, at a position on the axis' (possibly logarithmic) scale.
#[derive(Debug, Clone, PartialEq)]
struct Tick {
    at: f64,
    label: Option<String>,
}

/// An axis: the range of its scale (log10 of the value on a logarithmic axis), where exact
/// zeros go on a logarithmic one, and its ticks.
#[derive(Debug, Clone, PartialEq)]
struct Axis {
    log: bool,
    lo: f64,
    hi: f64,
    /// On a logarithmic axis with exact zeros: the scale position of 0, and where the
    /// decades start (the band between `lo` and `decades_lo` holds the zeros).
    zero: Option<(f64, f64)>,
    ticks: Vec<Tick>,
}

/// A value rounded for a tick label with `decimals` decimals.
fn tick_label(v: f64, decimals: usize) -> String {
    minus_sign(&format!("{v:.decimals$}"))
}

/// The smallest step of 1, 2 or 5 times a power of ten that is at least `raw`.
fn nice_step(raw: f64) -> f64 {
    let mag = 10f64.powi(raw.log10().floor() as i32);
    let f = raw / mag;
    let m = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .find(|&m| m >= f)
        .unwrap_or(10.0);
    m * mag
}

impl Axis {
    /// An axis over `values` (the values it must show; non-finite ones are ignored, and on a
    /// logarithmic axis negative ones).
    fn new(values: &[f64], log: bool, integer: bool) -> Axis {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        let mut has_zero = false;
        for &v in values {
            if !v.is_finite() {
                continue;
            }
            if log {
                if v > 0.0 {
                    lo = lo.min(v.log10());
                    hi = hi.max(v.log10());
                } else if v == 0.0 {
                    has_zero = true;
                }
            } else {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        if log {
            Axis::log(lo, hi, has_zero, integer)
        } else {
            Axis::linear(lo, hi, integer)
        }
    }

    fn linear(lo: f64, hi: f64, integer: bool) -> Axis {
        let (lo, hi) = if lo > hi {
            (0.0, 1.0)
        } else if lo == hi {
            let d = if integer {
                1.0
            } else {
                0.5 * lo.abs().max(1.0)
            };
            (lo - d, hi + d)
        } else {
            (lo, hi)
        };
        let mut step = nice_step((hi - lo) / 8.0);
        if integer {
            step = step.max(1.0).round();
        }
        let pad = 0.04 * (hi - lo);
        let (lo, hi) = (lo - pad, hi + pad);
        let decimals = if integer {
            0
        } else {
            (-step.log10().floor()).max(0.0) as usize
        };
        let first = (lo / step).ceil() as i64;
        let last = (hi / step).floor() as i64;
        let ticks = (first..=last)
            .map(|i| {
                let at = i as f64 * step;
                Tick {
                    at,
                    label: Some(tick_label(at, decimals)),
                }
            })
            .collect();
        Axis {
            log: false,
            lo,
            hi,
            zero: None,
            ticks,
        }
    }

    fn log(lo: f64, hi: f64, has_zero: bool, integer: bool) -> Axis {
        let (lo, hi) = if lo > hi {
            (-1.0, 1.0)
        } else if hi - lo < 0.5 {
            let mid = 0.5 * (lo + hi);
            (mid - 0.25, mid + 0.25)
        } else {
            (lo, hi)
        };
        let pad = 0.05 * (hi - lo);
        let (decades_lo, hi) = (lo - pad, hi + pad);
        let span = hi - decades_lo;
        let (lo, zero) = if has_zero {
            let at = decades_lo - 0.1 * span;
            (at - 0.05 * span, Some((at, decades_lo)))
        } else {
            (decades_lo, None)
        };
        let (k0, k1) = (decades_lo.ceil() as i32, hi.floor() as i32);
        // Counts print in full up to 100000; past that 1 and 10 do, and the rest as powers.
        let label_of = |k: i32| {
            let plain = if integer {
                (0..=5).contains(&k) && (k1 <= 5 || k <= 1)
            } else {
                (-2..=3).contains(&k)
            };
            if plain {
                let v = 10f64.powi(k);
                tick_label(v, (-k).max(0) as usize)
            } else {
                power_of_ten(k)
            }
        };
        let n_decades = (k1 - k0 + 1).max(0);
        let every = (n_decades + 9) / 10;
        let mut ticks = Vec::new();
        for k in k0..=k1 {
            ticks.push(Tick {
                at: f64::from(k),
                label: ((k - k0) % every.max(1) == 0).then(|| label_of(k)),
            });
        }
        if n_decades <= 8 {
            // Minor ticks at 2..9 times each power of ten; labelled at 2 and 5 when fewer
            // than two decades are in range.
            let label_minor = n_decades < 2;
            for k in (k0 - 1)..=k1 {
                for m in 2..=9 {
                    let v = f64::from(m) * 10f64.powi(k);
                    let at = v.log10();
                    if at < decades_lo || at > hi {
                        continue;
                    }
                    let label = (label_minor && (m == 2 || m == 5)).then(|| {
                        if integer && k >= 0 {
                            format!("{}", v.round())
                        } else {
                            tick_label(v, (-k).max(0) as usize)
                        }
                    });
                    ticks.push(Tick { at, label });
                }
            }
        }
        if let Some((at, _)) = zero {
            ticks.push(Tick {
                at,
                label: Some("0".into()),
            });
        }
        Axis {
            log: true,
            lo,
            hi,
            zero,
            ticks,
        }
    }

    /// The scale position of a value, or `None` where the axis cannot show it.
    fn map(&self, v: f64) -> Option<f64> {
        if !v.is_finite() {
            None
        } else if !self.log {
            Some(v)
        } else if v > 0.0 {
            Some(v.log10())
        } else if v == 0.0 {
            self.zero.map(|z| z.0)
        } else {
            None
        }
    }

    /// Where a bar rising from this axis starts.
    fn base(&self) -> f64 {
        match (self.log, self.zero) {
            (false, _) => 0f64.clamp(self.lo, self.hi),
            (true, Some((_, decades_lo))) => decades_lo,
            (true, None) => self.lo,
        }
    }
}

/// The plot rectangle in pixels and the axes it maps.
struct Frame {
    left: f64,
    right: f64,
    top: f64,
    bottom: f64,
    x: Axis,
    y: Axis,
}

impl Frame {
    fn px(&self, at: f64) -> f64 {
        self.left + (at - self.x.lo) / (self.x.hi - self.x.lo) * (self.right - self.left)
    }

    fn py(&self, at: f64) -> f64 {
        self.bottom - (at - self.y.lo) / (self.y.hi - self.y.lo) * (self.bottom - self.top)
    }

    /// The pixel of a data point, or `None` where an axis cannot show it.
    fn pixel(&self, (x, y): (f64, f64)) -> Option<(f64, f64)> {
        Some((self.px(self.x.map(x)?), self.py(self.y.map(y)?)))
    }
}

fn ipt((x, y): (f64, f64)) -> (i32, i32) {
    (x.round() as i32, y.round() as i32)
}

/// Cuts a polyline (pixels) into the "on" pieces of a dash pattern.
fn dash_pieces(points: &[(f64, f64)], pattern: &[f64]) -> Vec<Vec<(f64, f64)>> {
    if pattern.is_empty() || points.len() < 2 {
        return vec![points.to_vec()];
    }
    let mut pieces = Vec::new();
    let mut current = vec![points[0]];
    let (mut idx, mut left) = (0, pattern[0]);
    for w in points.windows(2) {
        let (mut a, b) = (w[0], w[1]);
        let mut d = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        while d > left {
            let t = left / d;
            a = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
            d -= left;
            if idx % 2 == 0 {
                current.push(a);
                pieces.push(std::mem::take(&mut current));
            } else {
                current = vec![a];
            }
            idx = (idx + 1) % pattern.len();
            left = pattern[idx];
        }
        left -= d;
        if idx % 2 == 0 {
            current.push(b);
        } else {
            current = vec![b];
        }
    }
    if idx % 2 == 0 && current.len() > 1 {
        pieces.push(current);
    }
    pieces
}

type Res<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

fn draw_polyline<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    points: &[(f64, f64)],
    dash: Dash,
    style: ShapeStyle,
) -> Res<DB> {
    for piece in dash_pieces(points, dash.pattern()) {
        area.draw(&PathElement::new(
            piece.into_iter().map(ipt).collect::<Vec<_>>(),
            style,
        ))?;
    }
    Ok(())
}

fn draw_marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: (f64, f64),
    marker: Marker,
    size: i32,
    color: RGBColor,
) -> Res<DB> {
    let (x, y) = ipt(p);
    let s = size;
    match marker {
        Marker::Circle => area.draw(&Circle::new((x, y), s, color.filled())),
        Marker::Square => area.draw(&Rectangle::new(
            [(x - s + 1, y - s + 1), (x + s - 1, y + s - 1)],
            color.filled(),
        )),
        Marker::TriangleUp => area.draw(&Polygon::new(
            vec![(x, y - s - 1), (x - s - 1, y + s), (x + s + 1, y + s)],
            color.filled(),
        )),
        Marker::TriangleDown => area.draw(&Polygon::new(
            vec![(x, y + s + 1), (x - s - 1, y - s), (x + s + 1, y - s)],
            color.filled(),
        )),
        Marker::Diamond => area.draw(&Polygon::new(
            vec![
                (x, y - s - 1),
                (x + s + 1, y),
                (x, y + s + 1),
                (x - s - 1, y),
            ],
            color.filled(),
        )),
        Marker::None => Ok(()),
        Marker::Cross => {
            let st = color.stroke_width(2);
            area.draw(&PathElement::new(vec![(x - s, y - s), (x + s, y + s)], st))?;
            area.draw(&PathElement::new(vec![(x - s, y + s), (x + s, y - s)], st))
        }
    }
}

/// How each series is drawn: its own style, changed where it would repeat an earlier
/// series' look (same colour, and the same dash on a line, the same marker where markers
/// show).
fn distinct_styles(series: &[Series]) -> Vec<(Dash, Marker)> {
    type Look = ((u8, u8, u8), Option<Dash>, Option<Marker>, bool);
    let look = |s: &Series, dash: Dash, marker: Marker| -> Look {
        (
            s.color,
            (s.line && s.bar_width.is_none()).then_some(dash),
            s.marked().then_some(marker),
            s.bar_width.is_some(),
        )
    };
    let mut seen: Vec<Look> = Vec::new();
    let mut out = Vec::new();
    for s in series {
        let d0 = Dash::ALL.iter().position(|&d| d == s.dash).unwrap_or(0);
        let m0 = Marker::ALL.iter().position(|&m| m == s.marker).unwrap_or(0);
        let keep_marker = s.marker == Marker::None;
        let n = Dash::ALL.len() * Marker::ALL.len();
        let chosen = (0..n)
            .map(|k| {
                (
                    Dash::ALL[(d0 + k) % Dash::ALL.len()],
                    if keep_marker {
                        Marker::None
                    } else {
                        Marker::ALL[(m0 + k + k / 12) % Marker::ALL.len()]
                    },
                )
            })
            .find(|&(d, m)| !seen.contains(&look(s, d, m)))
            .unwrap_or((s.dash, s.marker));
        seen.push(look(s, chosen.0, chosen.1));
        out.push(chosen);
    }
    out
}

/// A series' look, 24 pixels wide from `at` (its left end, vertically centred): a piece of its
/// line, a marker, or a bar.
fn sample_of<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: &Series,
    marked: bool,
    at: (f64, f64),
    width: u32,
    marker: i32,
) -> Res<DB> {
    let c = RGBColor(s.color.0, s.color.1, s.color.2);
    let (x0, y0) = at;
    if s.bar_width.is_some() {
        return area.draw(&Rectangle::new(
            [ipt((x0 + 4.0, y0 - 6.0)), ipt((x0 + 20.0, y0 + 6.0))],
            c.filled(),
        ));
    }
    if s.line {
        draw_polyline(
            area,
            &[(x0, y0), (x0 + 24.0, y0)],
            s.dash,
            c.stroke_width(width),
        )?;
    }
    if marked {
        draw_marker(area, (x0 + 12.0, y0), s.marker, marker, c)?;
    }
    Ok(())
}

/// Draws the look of a series (its line's pattern and colour, its marker, or a bar), 24
/// pixels wide from `at`: for legends drawn outside a chart, such as a figure's shared key.
pub fn draw_sample<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: &Series,
    at: (i32, i32),
) -> Result<(), Error> {
    let marked = s.bar_width.is_none() && s.marker != Marker::None && !s.line;
    sample_of(area, s, marked, (f64::from(at.0), f64::from(at.1)), 2, 4)
        .map_err(|e| render_error(e.to_string()))
}

/// Sizes of the text and margins: full charts, or the compact panels of a multi-panel figure.
struct Sizes {
    title: u32,
    label: u32,
    desc: u32,
    margin: f64,
    line: u32,
    marker: i32,
}

fn font(size: u32) -> TextStyle<'static> {
    TextStyle::from(("sans-serif", size).into_font()).color(&BLACK)
}

/// Spreads label positions (sorted by target) at least `gap` apart inside `[lo, hi]`.
fn spread(targets: &[f64], gap: f64, lo: f64, hi: f64) -> Vec<f64> {
    let mut y: Vec<f64> = targets.iter().map(|t| t.clamp(lo, hi)).collect();
    for i in 1..y.len() {
        y[i] = y[i].max(y[i - 1] + gap);
    }
    if let Some(&last) = y.last() {
        if last > hi {
            let shift = last - hi;
            for v in &mut y {
                *v -= shift;
            }
            for i in (0..y.len().saturating_sub(1)).rev() {
                y[i] = y[i].min(y[i + 1] - gap);
            }
        }
    }
    y
}

/// Draws a chart into a drawing area: a full chart ([`render_svg`], [`render_png`]), or with
/// `compact` one small panel of a figure (smaller text, no legend box).
pub fn draw_chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    chart: &Chart,
    compact: bool,
) -> Result<(), Error> {
    Painter::new(area, chart, compact)
        .draw()
        .map_err(|e| render_error(e.to_string()))
}

/// A chart laid out in its drawing area, drawn in layers by [`Painter::draw`].
struct Painter<'a, DB: DrawingBackend> {
    area: &'a DrawingArea<DB, Shift>,
    chart: &'a Chart,
    compact: bool,
    sz: Sizes,
    w: f64,
    h: f64,
    styles: Vec<(Dash, Marker)>,
    /// The series with a label.
    labelled: Vec<usize>,
    /// The width of the direct labels' gutter on the right (0 without one).
    gutter: f64,
    title_size: u32,
    frame: Frame,
}

impl<'a, DB: DrawingBackend> Painter<'a, DB> {
    /// The layout: the axes over every point, the reference lines and the bars' edges and
    /// base; the title, y tick labels and description on the left, x below, direct labels in
    /// a gutter on the right.
    fn new(area: &'a DrawingArea<DB, Shift>, chart: &'a Chart, compact: bool) -> Self {
        let sz = if compact {
            Sizes {
                title: 15,
                label: 12,
                desc: 12,
                margin: 8.0,
                line: 2,
                marker: 3,
            }
        } else {
            Sizes {
                title: 20,
                label: 14,
                desc: 16,
                margin: 16.0,
                line: 2,
                marker: 4,
            }
        };
        let (w, h) = area.dim_in_pixel();
        let (w, h) = (f64::from(w), f64::from(h));
        let text_w = |s: &str, size: u32| text_width(area, s, size);
        let mut xs = Vec::new();
        let mut ys = Vec::new();
        for s in &chart.series {
            for &(x, y) in &s.points {
                match s.bar_width {
                    Some(bw) => xs.extend([x - 0.5 * bw, x + 0.5 * bw]),
                    None => xs.push(x),
                }
                ys.push(y);
            }
            if s.bar_width.is_some() && !chart.log_y {
                ys.push(0.0);
            }
        }
        ys.extend(chart.ref_lines.iter().map(|r| r.at));
        xs.extend(chart.x_ref_lines.iter().map(|r| r.at));
        let x = Axis::new(&xs, chart.log_x, chart.x_integer);
        let y = Axis::new(&ys, chart.log_y, chart.y_integer);

        let labelled: Vec<usize> = (0..chart.series.len())
            .filter(|&i| !chart.series[i].label.is_empty())
            .collect();
        let gutter = if chart.direct_labels && !compact {
            let widest = labelled
                .iter()
                .filter(|&&i| chart.series[i].line && chart.series[i].bar_width.is_none())
                .map(|&i| text_w(&chart.series[i].label, sz.label))
                .fold(0.0, f64::max);
            if widest > 0.0 {
                (widest + 44.0).min(0.4 * w)
            } else {
                0.0
            }
        } else {
            0.0
        };
        let y_tick_w = y
            .ticks
            .iter()
            .filter_map(|t| t.label.as_deref())
            .map(|l| text_w(l, sz.label))
            .fold(0.0, f64::max);
        let title_size = {
            let mut s = sz.title;
            while s > 10 && text_w(&chart.title, s) > w - 2.0 * sz.margin {
                s -= 1;
            }
            s
        };
        let top = sz.margin + f64::from(title_size) * 1.6;
        let frame = Frame {
            left: sz.margin + f64::from(sz.desc) * 1.5 + y_tick_w + 10.0,
            right: w - sz.margin - gutter,
            top,
            bottom: h - sz.margin - f64::from(sz.label) * 1.4 - f64::from(sz.desc) * 1.5 - 6.0,
            x,
            y,
        };
        Painter {
            area,
            chart,
            compact,
            sz,
            w,
            h,
            styles: distinct_styles(&chart.series),
            labelled,
            gutter,
            title_size,
            frame,
        }
    }

    fn text_w(&self, s: &str, size: u32) -> f64 {
        text_width(self.area, s, size)
    }

    /// The frame's edges: left, right, top, bottom.
    fn edges(&self) -> (f64, f64, f64, f64) {
        let f = &self.frame;
        (f.left, f.right, f.top, f.bottom)
    }

    /// Draws the layers, each over the ones before.
    fn draw(&self) -> Res<DB> {
        self.background()?;
        self.reference_lines()?;
        let (hidden, ends) = self.series()?;
        self.axes()?;
        // What the axes could not show.
        if hidden > 0 {
            let (l, _, _, b) = self.edges();
            self.area.draw(&Text::new(
                format!("{hidden} points not shown (not finite, or negative on a log axis)"),
                ipt((l + 6.0, b - 6.0)),
                font(self.sz.label).pos(Pos::new(HPos::Left, VPos::Bottom)),
            ))?;
        }
        self.labels(&ends)
    }

    /// The white page, the title, the band of exact zeros and the grid.
    fn background(&self) -> Res<DB> {
        let (area, frame) = (self.area, &self.frame);
        let (l, r, t, b) = self.edges();
        area.fill(&WHITE)?;
        area.draw(&Text::new(
            self.chart.title.clone(),
            ipt((0.5 * self.w, self.sz.margin)),
            font(self.title_size).pos(Pos::new(HPos::Center, VPos::Top)),
        ))?;
        let grid = RGBColor(225, 225, 225);
        let minor_grid = RGBColor(242, 242, 242);
        let band = RGBColor(246, 246, 246);
        if let Some((_, decades_lo)) = frame.y.zero {
            let edge = frame.py(decades_lo);
            area.draw(&Rectangle::new(
                [ipt((l, edge)), ipt((r, b))],
                band.filled(),
            ))?;
        }
        if let Some((_, decades_lo)) = frame.x.zero {
            let edge = frame.px(decades_lo);
            area.draw(&Rectangle::new(
                [ipt((l, t)), ipt((edge, b))],
                band.filled(),
            ))?;
        }
        for tick in &frame.x.ticks {
            let px = frame.px(tick.at);
            let c = if tick.label.is_some() {
                grid
            } else {
                minor_grid
            };
            area.draw(&PathElement::new(vec![ipt((px, t)), ipt((px, b))], c))?;
        }
        for tick in &frame.y.ticks {
            let py = frame.py(tick.at);
            let c = if tick.label.is_some() {
                grid
            } else {
                minor_grid
            };
            area.draw(&PathElement::new(vec![ipt((l, py)), ipt((r, py))], c))?;
        }
        Ok(())
    }

    /// The reference lines, dashed, with their labels.
    fn reference_lines(&self) -> Res<DB> {
        let (area, frame, sz) = (self.area, &self.frame, &self.sz);
        let (l, r, t, b) = self.edges();
        let ref_color = RGBColor(85, 85, 85);
        for rl in &self.chart.x_ref_lines {
            if let Some(at) = frame.x.map(rl.at) {
                let px = frame.px(at);
                draw_polyline(
                    area,
                    &[(px, t), (px, b)],
                    Dash::Dashed,
                    ref_color.stroke_width(1),
                )?;
                // Beside the line, on the side with room: left of a negative one, and left of
                // any that would run past the frame.
                let room = r - px > self.text_w(&rl.label, sz.label) + 8.0;
                let (dx, h_pos) = if rl.at < 0.0 || !room {
                    (-4.0, HPos::Right)
                } else {
                    (4.0, HPos::Left)
                };
                area.draw(&Text::new(
                    rl.label.clone(),
                    ipt((px + dx, t + 4.0)),
                    font(sz.label)
                        .color(&ref_color)
                        .pos(Pos::new(h_pos, VPos::Top)),
                ))?;
            }
        }
        for rl in &self.chart.ref_lines {
            if let Some(at) = frame.y.map(rl.at) {
                let py = frame.py(at);
                draw_polyline(
                    area,
                    &[(l, py), (r, py)],
                    Dash::Dashed,
                    ref_color.stroke_width(1),
                )?;
                // The label at the right end, above the line, on a white patch.
                let tw = self.text_w(&rl.label, sz.label);
                let th = f64::from(sz.label);
                area.draw(&Rectangle::new(
                    [
                        ipt((r - tw - 10.0, py - th - 4.0)),
                        ipt((r - 2.0, py - 2.0)),
                    ],
                    WHITE.filled(),
                ))?;
                area.draw(&Text::new(
                    rl.label.clone(),
                    ipt((r - 6.0, py - 3.0)),
                    font(sz.label)
                        .color(&ref_color)
                        .pos(Pos::new(HPos::Right, VPos::Bottom)),
                ))?;
            }
        }
        Ok(())
    }

    /// The series: bars, then lines, then markers on top. Returns how many points the axes
    /// cannot show, and where each series ends (its last shown point).
    #[allow(clippy::type_complexity)]
    fn series(
        &self,
    ) -> Result<(usize, Vec<(usize, (f64, f64))>), DrawingAreaErrorKind<DB::ErrorType>> {
        let (area, frame, chart) = (self.area, &self.frame, self.chart);
        let mut hidden = 0usize;
        let mut ends: Vec<(usize, (f64, f64))> = Vec::new();
        let pixels: Vec<Vec<Option<(f64, f64)>>> = chart
            .series
            .iter()
            .map(|s| s.points.iter().map(|&p| frame.pixel(p)).collect())
            .collect();
        for (s, px) in chart.series.iter().zip(&pixels) {
            hidden += px.iter().filter(|p| p.is_none()).count();
            if let Some(bw) = s.bar_width {
                let c = RGBColor(s.color.0, s.color.1, s.color.2);
                let base = frame.py(frame.y.base());
                for &(x, y) in &s.points {
                    let (Some(x0), Some(x1), Some(y1)) = (
                        frame.x.map(x - 0.5 * bw),
                        frame.x.map(x + 0.5 * bw),
                        frame.y.map(y),
                    ) else {
                        continue;
                    };
                    let (x0, x1) = (frame.px(x0), frame.px(x1));
                    let y1 = frame.py(y1);
                    area.draw(&Rectangle::new(
                        [ipt((x0, y1)), ipt((x1.max(x0 + 1.0), base))],
                        c.filled(),
                    ))?;
                }
            }
        }
        for (i, (s, px)) in chart.series.iter().zip(&pixels).enumerate() {
            if !s.line || s.bar_width.is_some() {
                continue;
            }
            let c = RGBColor(s.color.0, s.color.1, s.color.2);
            // A point the axes cannot show breaks the line.
            for run in px.split(Option::is_none) {
                let run: Vec<(f64, f64)> = run.iter().flatten().copied().collect();
                draw_polyline(area, &run, self.styles[i].0, c.stroke_width(self.sz.line))?;
            }
        }
        for (i, (s, px)) in chart.series.iter().zip(&pixels).enumerate() {
            if s.marked() {
                let c = RGBColor(s.color.0, s.color.1, s.color.2);
                for p in px.iter().flatten() {
                    draw_marker(area, *p, self.styles[i].1, self.sz.marker, c)?;
                }
            }
            if let Some(end) = px.iter().rev().flatten().next() {
                ends.push((i, *end));
            }
        }
        Ok((hidden, ends))
    }

    /// The frame, the zero bands' breaks, ticks and their labels, the axis descriptions.
    fn axes(&self) -> Res<DB> {
        let (area, frame, sz) = (self.area, &self.frame, &self.sz);
        let (l, r, t, b) = self.edges();
        area.draw(&Rectangle::new(
            [ipt((l, t)), ipt((r, b))],
            BLACK.stroke_width(1),
        ))?;
        if let Some((_, decades_lo)) = frame.y.zero {
            let edge = frame.py(decades_lo);
            for x0 in [l, r] {
                area.draw(&PathElement::new(
                    vec![ipt((x0 - 5.0, edge + 3.0)), ipt((x0 + 5.0, edge - 3.0))],
                    BLACK,
                ))?;
            }
        }
        if let Some((_, decades_lo)) = frame.x.zero {
            let edge = frame.px(decades_lo);
            for y0 in [t, b] {
                area.draw(&PathElement::new(
                    vec![ipt((edge - 3.0, y0 + 5.0)), ipt((edge + 3.0, y0 - 5.0))],
                    BLACK,
                ))?;
            }
        }
        for tick in &frame.x.ticks {
            let px = frame.px(tick.at);
            let len = if tick.label.is_some() { 5.0 } else { 3.0 };
            area.draw(&PathElement::new(
                vec![ipt((px, b)), ipt((px, b + len))],
                BLACK,
            ))?;
            if let Some(label) = &tick.label {
                area.draw(&Text::new(
                    label.clone(),
                    ipt((px, b + 7.0)),
                    font(sz.label).pos(Pos::new(HPos::Center, VPos::Top)),
                ))?;
            }
        }
        for tick in &frame.y.ticks {
            let py = frame.py(tick.at);
            let len = if tick.label.is_some() { 5.0 } else { 3.0 };
            area.draw(&PathElement::new(
                vec![ipt((l - len, py)), ipt((l, py))],
                BLACK,
            ))?;
            if let Some(label) = &tick.label {
                area.draw(&Text::new(
                    label.clone(),
                    ipt((l - 7.0, py)),
                    font(sz.label).pos(Pos::new(HPos::Right, VPos::Center)),
                ))?;
            }
        }
        area.draw(&Text::new(
            self.chart.x_label.clone(),
            ipt((0.5 * (l + r), self.h - sz.margin)),
            font(sz.desc).pos(Pos::new(HPos::Center, VPos::Bottom)),
        ))?;
        area.draw(&Text::new(
            self.chart.y_label.clone(),
            ipt((sz.margin, 0.5 * (t + b))),
            font(sz.desc)
                .transform(FontTransform::Rotate270)
                .pos(Pos::new(HPos::Center, VPos::Top)),
        ))?;
        Ok(())
    }

    /// Series `i`'s look, 24 pixels wide from `at`, for a label.
    fn sample(&self, i: usize, at: (f64, f64)) -> Res<DB> {
        let s = &self.chart.series[i];
        let drawn = Series {
            dash: self.styles[i].0,
            marker: self.styles[i].1,
            points: Vec::new(),
            ..s.clone()
        };
        sample_of(
            self.area,
            &drawn,
            s.marked(),
            at,
            self.sz.line,
            self.sz.marker,
        )
    }

    /// Labels: beside each line's end (in the gutter) and each lone point, or a legend box.
    fn labels(&self, ends: &[(usize, (f64, f64))]) -> Res<DB> {
        let chart = self.chart;
        if chart.direct_labels {
            self.direct_labels(ends)
        } else if !self.compact && self.labelled.len() > 1 {
            self.legend()
        } else {
            Ok(())
        }
    }

    /// Each labelled line's label in the gutter, joined to its end; each lone point's beside
    /// it.
    fn direct_labels(&self, ends: &[(usize, (f64, f64))]) -> Res<DB> {
        let (area, chart, sz) = (self.area, self.chart, &self.sz);
        let (_, r, t, b) = self.edges();
        let line_ends: Vec<(usize, (f64, f64))> = ends
            .iter()
            .copied()
            .filter(|&(i, _)| {
                let s = &chart.series[i];
                s.line && s.bar_width.is_none() && !s.label.is_empty()
            })
            .collect();
        if self.gutter > 0.0 {
            let mut order = line_ends.clone();
            order.sort_by(|a, b| a.1 .1.total_cmp(&b.1 .1).then(a.0.cmp(&b.0)));
            let targets: Vec<f64> = order.iter().map(|e| e.1 .1).collect();
            let gap = f64::from(sz.label) + 4.0;
            let placed = spread(&targets, gap, t + 6.0, b - 6.0);
            for ((i, end), ly) in order.iter().zip(placed) {
                let x0 = r + 6.0;
                area.draw(&PathElement::new(
                    vec![ipt((end.0.max(r - 2.0), end.1)), ipt((x0, ly))],
                    RGBColor(150, 150, 150),
                ))?;
                self.sample(*i, (x0, ly))?;
                area.draw(&Text::new(
                    chart.series[*i].label.clone(),
                    ipt((x0 + 30.0, ly)),
                    font(sz.label).pos(Pos::new(HPos::Left, VPos::Center)),
                ))?;
            }
        }
        for &(i, end) in ends {
            let s = &chart.series[i];
            if s.line || s.bar_width.is_some() || s.label.is_empty() {
                continue;
            }
            area.draw(&Text::new(
                s.label.clone(),
                ipt((end.0 + 7.0, end.1 - 4.0)),
                font(sz.label).pos(Pos::new(HPos::Left, VPos::Bottom)),
            ))?;
        }
        Ok(())
    }

    /// A legend box in the frame's top right corner.
    fn legend(&self) -> Res<DB> {
        let (area, chart, sz) = (self.area, self.chart, &self.sz);
        let (_, r, t, _) = self.edges();
        let row = f64::from(sz.label) + 6.0;
        let widest = self
            .labelled
            .iter()
            .map(|&i| self.text_w(&chart.series[i].label, sz.label))
            .fold(0.0, f64::max);
        let (bw, bh) = (widest + 46.0, row * self.labelled.len() as f64 + 8.0);
        let (bx, by) = (r - bw - 10.0, t + 10.0);
        area.draw(&Rectangle::new(
            [ipt((bx, by)), ipt((bx + bw, by + bh))],
            WHITE.mix(0.9).filled(),
        ))?;
        area.draw(&Rectangle::new(
            [ipt((bx, by)), ipt((bx + bw, by + bh))],
            BLACK.stroke_width(1),
        ))?;
        for (k, &i) in self.labelled.iter().enumerate() {
            let yk = by + 4.0 + row * (k as f64 + 0.5);
            self.sample(i, (bx + 6.0, yk))?;
            area.draw(&Text::new(
                chart.series[i].label.clone(),
                ipt((bx + 38.0, yk)),
                font(sz.label).pos(Pos::new(HPos::Left, VPos::Center)),
            ))?;
        }
        Ok(())
    }
}

/// The width of `s` in pixels at `size` in `area`'s font (0 when it cannot be measured).
fn text_width<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, s: &str, size: u32) -> f64 {
    area.estimate_text_size(s, &font(size))
        .map_or(0.0, |(tw, _)| f64::from(tw))
}

/// A drawing library's complaint as the library's error.
pub fn render_error(message: String) -> Error {
    Error::Render { message }
}

/// Renders a chart as SVG text.
pub fn render_svg(chart: &Chart) -> Result<String, Error> {
    register_font();
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, SIZE).into_drawing_area();
        draw_chart(&root, chart, false)?;
        root.present().map_err(|e| render_error(e.to_string()))?;
    }
    text.push('\n');
    Ok(text)
}

/// Renders a chart as PNG bytes.
pub fn render_png(chart: &Chart) -> Result<Vec<u8>, Error> {
    register_font();
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        draw_chart(&root, chart, false)?;
        root.present().map_err(|e| render_error(e.to_string()))?;
    }
    encode_png(&rgb, SIZE)
}

/// Encodes an RGB buffer of `size` pixels as PNG bytes (best compression, deterministic).
pub fn encode_png(rgb: &[u8], size: (u32, u32)) -> Result<Vec<u8>, Error> {
    encode_png_depth(rgb, size, png::BitDepth::Eight)
}

/// [`encode_png`] at 8 or 16 bits per channel (16-bit samples big-endian, as PNG stores them).
pub fn encode_png_depth(
    rgb: &[u8],
    size: (u32, u32),
    depth: png::BitDepth,
) -> Result<Vec<u8>, Error> {
    let (w, h) = size;
    let mut png_bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut png_bytes, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(depth);
        enc.set_compression(png::Compression::Best);
        let mut writer = enc
            .write_header()
            .map_err(|e| render_error(e.to_string()))?;
        writer
            .write_image_data(rgb)
            .map_err(|e| render_error(e.to_string()))?;
    }
    Ok(png_bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart() -> Chart {
        Chart {
            title: "test".into(),
            x_label: "x (units)".into(),
            y_label: "y (units)".into(),
            log_y: true,
            series: vec![Series {
                label: "a".into(),
                points: vec![(1.0, 1e-3), (2.0, 1e-2), (3.0, 0.0)],
                line: true,
                color: (200, 0, 0),
                ..Series::default()
            }],
            ..Chart::default()
        }
    }

    #[test]
    fn svg_and_png_render_deterministically() {
        let svg = render_svg(&chart()).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("x (units)"));
        let png1 = render_png(&chart()).unwrap();
        let png2 = render_png(&chart()).unwrap();
        assert_eq!(&png1[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(png1, png2);
    }

    fn labels(a: &Axis) -> Vec<&str> {
        a.ticks.iter().filter_map(|t| t.label.as_deref()).collect()
    }

    #[test]
    fn integer_axes_print_integers() {
        // 0..=5 wants steps of at least 5/8: 1 (on an integer axis never less than 1).
        let a = Axis::new(&[0.0, 5.0], false, true);
        assert_eq!(labels(&a), ["0", "1", "2", "3", "4", "5"]);
        // 0..=2 wants steps of at least 0.25: 0.5.
        let a = Axis::new(&[0.0, 2.0], false, false);
        assert_eq!(labels(&a), ["0.0", "0.5", "1.0", "1.5", "2.0"]);
    }

    #[test]
    fn negative_ticks_use_the_minus_sign() {
        let a = Axis::new(&[-2000.0, 2000.0], false, true);
        assert!(labels(&a).contains(&"\u{2212}1000"), "{:?}", labels(&a));
        assert!(labels(&a).contains(&"0"));
    }

    #[test]
    fn log_axes_show_exact_zeros_below_the_decades() {
        let a = Axis::new(&[0.0, 1e-3, 1e2], true, false);
        let (zero_at, decades_lo) = a.zero.expect("a zero band");
        assert!(a.lo < zero_at && zero_at < decades_lo && decades_lo < (1e-3f64).log10());
        assert_eq!(a.map(0.0), Some(zero_at));
        assert_eq!(a.map(-1.0), None);
        assert_eq!(
            labels(&a),
            ["10⁻³", "0.01", "0.1", "1", "10", "100", "0"],
            "decades, then the zero"
        );
        // Without zeros there is no band.
        assert_eq!(Axis::new(&[1e-3, 1e2], true, false).zero, None);
    }

    #[test]
    fn integer_log_axes_print_counts() {
        let a = Axis::new(&[1.0, 3e7], true, true);
        assert_eq!(
            labels(&a),
            ["1", "10", "10²", "10³", "10⁴", "10⁵", "10⁶", "10⁷"]
        );
        let a = Axis::new(&[1.0, 3e4], true, true);
        assert_eq!(labels(&a), ["1", "10", "100", "1000", "10000"]);
    }

    #[test]
    fn dash_pieces_follow_the_pattern() {
        // A 30-pixel line with 10 on, 6 off: on 0..10, 16..26, and 32.. is past the end.
        let pieces = dash_pieces(&[(0.0, 0.0), (30.0, 0.0)], &[10.0, 6.0]);
        assert_eq!(
            pieces,
            vec![
                vec![(0.0, 0.0), (10.0, 0.0)],
                vec![(16.0, 0.0), (26.0, 0.0)]
            ]
        );
        // A solid line is one piece.
        assert_eq!(dash_pieces(&[(0.0, 0.0), (5.0, 0.0)], &[]).len(), 1);
    }

    #[test]
    fn no_two_series_look_alike() {
        // Twenty long lines given the same colour and dash all end up distinct.
        let series: Vec<Series> = (0..20)
            .map(|_| Series {
                points: (0..100).map(|i| (f64::from(i), 1.0)).collect(),
                line: true,
                ..Series::default()
            })
            .collect();
        let styles = distinct_styles(&series);
        let dashes: std::collections::HashSet<Dash> = styles.iter().map(|s| s.0).collect();
        assert_eq!(dashes.len(), 4);
        // Long lines show no markers, so only four looks exist for one colour: the rest
        // repeat, but the first four differ.
        assert_eq!(
            styles[..4].iter().map(|s| s.0).collect::<Vec<_>>(),
            Dash::ALL
        );
        // Markers-only series of one colour take every marker shape.
        let dots: Vec<Series> = (0..6)
            .map(|_| Series {
                points: vec![(1.0, 1.0)],
                ..Series::default()
            })
            .collect();
        let shapes: std::collections::HashSet<Marker> =
            distinct_styles(&dots).iter().map(|s| s.1).collect();
        assert_eq!(shapes.len(), 6);
    }

    #[test]
    fn labels_spread_apart_inside_their_range() {
        assert_eq!(
            spread(&[10.0, 11.0, 12.0], 5.0, 0.0, 100.0),
            [10.0, 15.0, 20.0]
        );
        assert_eq!(spread(&[98.0, 99.0], 5.0, 0.0, 100.0), [95.0, 100.0]);
    }
}
