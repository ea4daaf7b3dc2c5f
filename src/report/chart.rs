//! Charts: scatter and line series on linear or logarithmic axes, rendered to SVG text or PNG
//! bytes with an embedded font (DejaVu Sans), so output is identical on every machine.

use crate::error::Error;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;

/// One series of a chart.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// The (x, y) points, in drawing order.
    pub points: Vec<(f64, f64)>,
    /// Draw a line through the points (else only markers).
    pub line: bool,
    /// RGB colour.
    pub color: (u8, u8, u8),
}

/// A chart: title, axis labels with their units, and series.
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    /// Title at the top.
    pub title: String,
    /// X axis label, with its unit.
    pub x_label: String,
    /// Y axis label, with its unit.
    pub y_label: String,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// The series.
    pub series: Vec<Series>,
}

/// The Okabe-Ito palette (colour-blind safe): black, orange, sky blue, bluish green, yellow,
/// blue, vermillion, reddish purple.
pub const PALETTE: [(u8, u8, u8); 8] = [
    (0, 0, 0),
    (230, 159, 0),
    (86, 180, 233),
    (0, 158, 115),
    (240, 228, 66),
    (0, 114, 178),
    (213, 94, 0),
    (204, 121, 167),
];

/// A colour for series `i` of `count`, evenly spaced in hue (HSL with s = 0.7, l = 0.45).
pub fn hue(i: usize, count: usize) -> (u8, u8, u8) {
    let h = i as f64 / count.max(1) as f64;
    let (s, l) = (0.7, 0.45);
    let q = if l < 0.5 {
        l * (1.0 + s)
    } else {
        l + s - l * s
    };
    let p = 2.0 * l - q;
    let channel = |t: f64| {
        let t = t.rem_euclid(1.0);
        let v = if t < 1.0 / 6.0 {
            p + (q - p) * 6.0 * t
        } else if t < 0.5 {
            q
        } else if t < 2.0 / 3.0 {
            p + (q - p) * (2.0 / 3.0 - t) * 6.0
        } else {
            p
        };
        (v * 255.0).round() as u8
    };
    (channel(h + 1.0 / 3.0), channel(h), channel(h - 1.0 / 3.0))
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

fn ranges(chart: &Chart) -> ((f64, f64), (f64, f64)) {
    let pts = chart.series.iter().flat_map(|s| s.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in pts {
        if !x.is_finite()
            || !y.is_finite()
            || (chart.log_y && y <= 0.0)
            || (chart.log_x && x <= 0.0)
        {
            continue;
        }
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        return ((0.0, 1.0), (if chart.log_y { 1e-3 } else { 0.0 }, 1.0));
    }
    let pad = |lo: f64, hi: f64| {
        let d = if hi > lo {
            0.05 * (hi - lo)
        } else {
            0.5 * lo.abs().max(1.0)
        };
        (lo - d, hi + d)
    };
    let xr = if chart.log_x {
        (x0 / 1.2, x1 * 1.2)
    } else {
        pad(x0, x1)
    };
    let yr = if chart.log_y {
        (y0 / 1.5, y1 * 1.5)
    } else {
        pad(y0, y1)
    };
    (xr, yr)
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, chart: &Chart) -> Result<(), Error> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| render_error(e.to_string());
    root.fill(&WHITE).map_err(err)?;
    let ((x0, x1), (y0, y1)) = ranges(chart);
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(&chart.title, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(84);
    macro_rules! body {
        ($ctx:expr) => {{
            let mut ctx = $ctx;
            let y_fmt = |y: &f64| {
                if chart.log_y {
                    format!("{y:.0e}")
                } else {
                    format!("{y}")
                }
            };
            ctx.configure_mesh()
                .y_label_formatter(&y_fmt)
                .x_desc(&chart.x_label)
                .y_desc(&chart.y_label)
                .label_style(("sans-serif", 14))
                .axis_desc_style(("sans-serif", 16))
                .draw()
                .map_err(err)?;
            for s in &chart.series {
                let color = RGBColor(s.color.0, s.color.1, s.color.2);
                let pts: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|&(x, y)| {
                        x.is_finite()
                            && y.is_finite()
                            && (!chart.log_y || y > 0.0)
                            && (!chart.log_x || x > 0.0)
                    })
                    .collect();
                if s.line {
                    ctx.draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                        .map_err(err)?
                        .label(s.label.clone())
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2))
                        });
                }
                // Markers, unless a long line would be buried under them.
                if !s.line || pts.len() <= 60 {
                    let markers = ctx
                        .draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))
                        .map_err(err)?;
                    if !s.line {
                        markers
                            .label(s.label.clone())
                            .legend(move |(x, y)| Circle::new((x + 8, y), 4, color.filled()));
                    }
                }
            }
            ctx.configure_series_labels()
                .label_font(("sans-serif", 14))
                .background_style(WHITE.mix(0.9))
                .border_style(BLACK)
                .draw()
                .map_err(err)?;
        }};
    }
    match (chart.log_x, chart.log_y) {
        (false, false) => body!(builder.build_cartesian_2d(x0..x1, y0..y1).map_err(err)?),
        (false, true) => body!(builder
            .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
            .map_err(err)?),
        (true, false) => body!(builder
            .build_cartesian_2d((x0..x1).log_scale(), y0..y1)
            .map_err(err)?),
        (true, true) => body!(builder
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(err)?),
    }
    root.present().map_err(err)
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
        draw(root, chart)?;
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
        draw(root, chart)?;
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
            log_x: false,
            log_y: true,
            series: vec![Series {
                label: "a".into(),
                points: vec![(1.0, 1e-3), (2.0, 1e-2), (3.0, 0.0)],
                line: true,
                color: (200, 0, 0),
            }],
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
}
