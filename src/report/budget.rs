//! The error-budget report: its document (tables, prose) and its charts, from a
//! [`BudgetReport`].

use crate::analysis::budget::{BudgetReport, Histogram, PerN};
use crate::analysis::check::Input;
use crate::analysis::LSB8;
use crate::report::chart::{Chart, Dash, RefLine, Series};
use crate::report::doc::Block;

fn e(x: f64) -> String {
    format!("{x:.3e}")
}

fn ulp(x: f64) -> String {
    format!("{x:.3}")
}

fn at(i: &Input) -> String {
    format!("n = {}, c = {:.6} (code {})", i.n, i.c, i.c_raw)
}

/// A histogram as bars, one per non-empty bin (an absent bar is an empty bin).
fn histogram_series(h: &Histogram, label: &str, i: usize) -> Series {
    Series {
        bar_width: Some(h.bin_width),
        ..Series::styled(
            label,
            h.counts
                .iter()
                .enumerate()
                .filter(|&(_, &c)| c > 0)
                .map(|(i, &c)| (h.lo + (i as f64 + 0.5) * h.bin_width, c as f64))
                .collect(),
            false,
            i,
        )
    }
}

/// The "1 lsb8" reference line.
fn one_lsb8() -> Vec<RefLine> {
    vec![RefLine {
        at: 1.0,
        label: "1 lsb8".into(),
    }]
}

/// Bin widths as text: `16`, `0.0625`.
fn width(w: f64) -> String {
    format!("{w}")
}

/// The report's charts, each with the file stem it is written under. Lobe errors are in
/// lsb8 (2^-8) with the 1 lsb8 line drawn; output errors in output LSBs.
///
/// # Examples
/// ```
/// use specfx::analysis::budget::analyse;
/// use specfx::pipeline::{Config, Datapath};
/// use specfx::report::budget::charts;
/// let mut cfg = Config::baseline();
/// cfg.n = "32".parse().unwrap();
/// let r = analyse(&Datapath::new(cfg).unwrap(), None).unwrap();
/// let stems: Vec<String> = charts(&r).into_iter().map(|(s, _)| s).collect();
/// assert_eq!(
///     stems,
///     ["histogram_out", "histogram_shape", "error_vs_c", "error_vs_n", "output_error_vs_c", "output_error_vs_n"]
/// );
/// ```
pub fn charts(r: &BudgetReport) -> Vec<(String, Chart)> {
    let h_out = Chart {
        title: format!("{}: output error against the f64 model", r.config),
        x_label: format!(
            "fixed output \u{2212} f64 output (output LSBs; bins of {})",
            width(r.histogram_out.bin_width)
        ),
        y_label: "evaluations (count, log scale)".into(),
        log_y: true,
        x_integer: r.histogram_out.bin_width.fract() == 0.0,
        y_integer: true,
        series: vec![histogram_series(&r.histogram_out, "output error", 5)],
        ..Chart::default()
    };
    let h_shape = Chart {
        title: format!("{}: lobe error against cos^n", r.config),
        x_label: format!(
            "fixed lobe \u{2212} cos^n (lsb8 = 2^-8; bins of {})",
            width(r.histogram_shape.bin_width)
        ),
        y_label: "evaluations (count, log scale)".into(),
        log_y: true,
        x_integer: r.histogram_shape.bin_width.fract() == 0.0,
        y_integer: true,
        series: vec![histogram_series(&r.histogram_shape, "lobe error", 1)],
        x_ref_lines: vec![
            RefLine {
                at: -1.0,
                label: "\u{2212}1 lsb8".into(),
            },
            RefLine {
                at: 1.0,
                label: "1 lsb8".into(),
            },
        ],
        ..Chart::default()
    };
    let mid = |lo: f64, hi: f64| 0.5 * (lo + hi);
    let vs_c = Chart {
        title: format!(
            "{}: largest lobe error per interval of c, over every n",
            r.config
        ),
        x_label: "c = cos(theta) (interval midpoint)".into(),
        y_label: "max |fixed lobe \u{2212} cos^n| (lsb8, log scale)".into(),
        log_y: true,
        series: vec![Series::styled(
            "lobe vs cos^n",
            r.per_c
                .iter()
                .map(|p| (mid(p.c_lo, p.c_hi), p.shape_total_max_abs / LSB8))
                .collect(),
            true,
            0,
        )],
        ref_lines: one_lsb8(),
        direct_labels: true,
        ..Chart::default()
    };
    let per_n = |label: &str, i: usize, dash: Dash, f: &dyn Fn(&PerN) -> f64| Series {
        dash,
        ..Series::styled(
            label,
            r.per_n.iter().map(|p| (f64::from(p.n), f(p))).collect(),
            true,
            i,
        )
    };
    let vs_n = Chart {
        title: format!("{}: largest lobe error per exponent", r.config),
        x_label: "exponent n".into(),
        y_label: "max |error| over c (lsb8, log scale)".into(),
        log_y: true,
        x_integer: true,
        series: vec![
            per_n("total: fixed lobe vs cos^n", 0, Dash::Solid, &|p| {
                p.shape_total_max_abs / LSB8
            }),
            per_n("approximation: f64 lobe vs cos^n", 1, Dash::Dashed, &|p| {
                p.shape_approx_max_abs / LSB8
            }),
            per_n("quantization: fixed vs f64 lobe", 2, Dash::Dotted, &|p| {
                p.shape_quant_max_abs / LSB8
            }),
        ],
        ref_lines: one_lsb8(),
        direct_labels: true,
        ..Chart::default()
    };
    let out_c = Chart {
        title: format!(
            "{}: largest output quantization error per interval of c, over every n",
            r.config
        ),
        x_label: "c = cos(theta) (interval midpoint)".into(),
        y_label: "max |fixed output \u{2212} f64 model| (output LSBs, log scale)".into(),
        log_y: true,
        series: vec![Series::styled(
            "output vs f64 model",
            r.per_c
                .iter()
                .map(|p| (mid(p.c_lo, p.c_hi), p.out_quant_max_ulp))
                .collect(),
            true,
            5,
        )],
        direct_labels: true,
        ..Chart::default()
    };
    let out_n = Chart {
        title: format!(
            "{}: largest output quantization error per exponent",
            r.config
        ),
        x_label: "exponent n".into(),
        y_label: "max |fixed output \u{2212} f64 model| over c (output LSBs, log scale)".into(),
        log_y: true,
        x_integer: true,
        series: vec![per_n("output vs f64 model", 5, Dash::Solid, &|p| {
            p.out_quant_max_ulp
        })],
        direct_labels: true,
        ..Chart::default()
    };
    vec![
        ("histogram_out".into(), h_out),
        ("histogram_shape".into(), h_shape),
        ("error_vs_c".into(), vs_c),
        ("error_vs_n".into(), vs_n),
        ("output_error_vs_c".into(), out_c),
        ("output_error_vs_n".into(), out_n),
    ]
}

fn s(x: &str) -> String {
    x.to_string()
}

/// The report as a document; figures refer to the stems of [`charts`].
pub fn document(r: &BudgetReport) -> Vec<Block> {
    let c = &r.check;
    let mut doc = vec![
        Block::Heading(1, format!("Error budget: {}", r.config)),
        Block::Paragraph(format!(
            "{} evaluations: {} input codes up to 1.0 for each of {} exponents (n = {}). Output LSB = {}.",
            c.n_evaluations,
            c.n_input_codes,
            c.n_exponents,
            c.n_set,
            e(r.out_lsb)
        )),
    ];
    match (&r.budget, r.pass) {
        (Some(text), Some(pass)) => {
            doc.push(Block::Heading(2, "Verdict".into()));
            doc.push(Block::Paragraph(format!(
                "Budget `{text}`: **{}**.",
                if pass { "PASS" } else { "FAIL" }
            )));
            doc.push(Block::Table {
                header: vec![s("metric"), s("limit"), s("measured"), s("verdict")],
                rows: r
                    .bounds
                    .iter()
                    .map(|b| {
                        vec![
                            b.metric.to_string(),
                            format!("{:.6e}", b.limit),
                            format!("{:.6e}", b.value),
                            s(if b.pass { "pass" } else { "FAIL" }),
                        ]
                    })
                    .collect(),
            });
        }
        _ => doc.push(Block::Paragraph(
            "No budget given (`--budget`, e.g. `shape_total <= 1 lsb8, out <= 1 ulp`): figures only."
                .into(),
        )),
    }

    let a = &r.attribution;
    doc.push(Block::Heading(
        2,
        "Where the output error comes from".into(),
    ));
    doc.push(Block::Paragraph(
        "Each row quantizes one source as the datapath does and keeps every other exact (f64); the error is that model's output minus the f64 model's output. The last row is the datapath itself, every source quantized."
            .into(),
    ));
    let mut rows: Vec<Vec<String>> = a
        .sources
        .iter()
        .chain(std::iter::once(&a.total))
        .map(|st| {
            let share = if a.sum_of_max_abs > 0.0 {
                format!("{:.1}%", 100.0 * st.max_abs / a.sum_of_max_abs)
            } else {
                s("-")
            };
            vec![
                if st.source == "all" {
                    s("all (measured)")
                } else {
                    st.source.clone()
                },
                st.format.clone(),
                st.rounding.clone(),
                e(st.max_abs),
                ulp(st.max_ulp),
                share,
                e(st.mean),
                e(st.rms),
                at(&st.worst),
            ]
        })
        .collect();
    if let Some(last) = rows.last_mut() {
        last[5] = s("");
    }
    doc.push(Block::Table {
        header: vec![
            s("source"),
            s("format"),
            s("rounding"),
            s("max |err|"),
            s("max (LSB)"),
            s("share of sum"),
            s("mean (bias)"),
            s("RMS"),
            s("worst input"),
        ],
        rows,
    });
    doc.push(Block::Paragraph(format!(
        "Sum of the sources' max |err|: {} against the measured max {} (first order, the measured max cannot exceed the sum by more than the residual). Root sum of squares of the sources' RMS: {} against the measured RMS {}. Residual, the largest |total - sum of the parts| at one input: {} at {}.",
        e(a.sum_of_max_abs),
        e(a.total.max_abs),
        e(a.rss_of_rms),
        e(a.total.rms),
        e(a.residual_max_abs),
        at(&a.residual_worst)
    )));

    doc.push(Block::Paragraph(
        "One source at a time counts twice an error that a later stage would absorb (a stage that rounds a value already on its grid adds nothing in the datapath, but rounds the exact value in its own row). The incremental view quantizes the sources cumulatively in pipeline order: each row is what that source adds on top of the ones before it, and the rows add up to the measured error exactly, input by input."
            .into(),
    ));
    doc.push(Block::Table {
        header: vec![
            s("source"),
            s("adds max |err|"),
            s("max (LSB)"),
            s("mean (bias)"),
            s("RMS"),
            s("worst input"),
        ],
        rows: a
            .incremental
            .iter()
            .map(|st| {
                vec![
                    st.source.clone(),
                    e(st.max_abs),
                    ulp(st.max_ulp),
                    e(st.mean),
                    e(st.rms),
                    at(&st.worst),
                ]
            })
            .collect(),
    });

    let sp = &r.split;
    doc.push(Block::Heading(2, "Approximation and quantization".into()));
    doc.push(Block::Table {
        header: vec![s("error"), s("max |err|"), s("worst input")],
        rows: vec![
            vec![
                s("output: approximation (f64 model - coef cos^n)"),
                e(sp.approx_max_abs),
                at(&sp.approx_worst),
            ],
            vec![
                s("output: quantization (fixed - f64 model)"),
                e(sp.quant_max_abs),
                at(&sp.quant_worst),
            ],
            vec![
                s("output: total (fixed - coef cos^n)"),
                e(sp.total_max_abs),
                at(&sp.total_worst),
            ],
            vec![
                s("lobe: approximation (f64 lobe - cos^n)"),
                e(c.shape_approx_max_abs),
                at(&c.shape_approx_worst),
            ],
            vec![
                s("lobe: quantization (fixed lobe - f64 lobe)"),
                e(c.shape_quant_max_abs),
                at(&c.shape_quant_worst),
            ],
            vec![
                s("lobe: total (fixed lobe - cos^n)"),
                e(c.shape_total_max_abs),
                at(&c.shape_total_worst),
            ],
        ],
    });

    doc.push(Block::Heading(2, "Headroom and overflow".into()));
    doc.push(Block::Paragraph(
        "The range each stage's values took against its format's range. Spare integer bits could be removed without changing any result; a stage that saturates or wraps has none. Noise fraction bits are the low fraction bits below the stage's worst error against the same algorithm in f64 (floor of log2 of its max error in its own LSBs): they carry only the rounding noise of the stages before, so narrowing them costs little accuracy (not measured where the stage overflowed)."
            .into(),
    ));
    doc.push(Block::Table {
        header: vec![
            s("stage"),
            s("format"),
            s("seen min"),
            s("seen max"),
            s("format range"),
            s("int bits"),
            s("needed"),
            s("spare"),
            s("noise frac bits"),
            s("wrapped"),
            s("saturated"),
            s("zeroed"),
        ],
        rows: r
            .headroom
            .iter()
            .map(|h| {
                vec![
                    h.stage.clone(),
                    h.format.clone(),
                    format!("{}", h.seen_min),
                    format!("{}", h.seen_max),
                    format!("{} ..= {}", h.format_min, h.format_max),
                    h.int_bits.to_string(),
                    h.int_bits_needed.to_string(),
                    h.spare_int_bits.to_string(),
                    h.wasted_frac_bits
                        .map_or("- (overflowed)".to_string(), |b| b.to_string()),
                    h.wrapped.to_string(),
                    h.saturated.to_string(),
                    h.zeroed.to_string(),
                ]
            })
            .collect(),
    });

    doc.push(Block::Heading(2, "Formal bound (gappa)".into()));
    if r.formal.is_empty() {
        doc.push(Block::Paragraph(
            r.formal_note
                .clone()
                .unwrap_or_else(|| "Not computed.".into()),
        ));
    } else {
        doc.push(Block::Paragraph(
            "A bound on |fixed output - f64 model output| proved by gappa for every input of each exponent below, beside the exhaustive maximum (which it must not be below)."
                .into(),
        ));
        doc.push(Block::Table {
            header: vec![
                s("n"),
                s("proved bound"),
                s("proved (LSB)"),
                s("exhaustive (LSB)"),
                s("how"),
            ],
            rows: r
                .formal
                .iter()
                .map(|f| {
                    vec![
                        f.n.to_string(),
                        e(f.bound),
                        ulp(f.bound_ulp),
                        ulp(f.exhaustive_ulp),
                        f.how.clone(),
                    ]
                })
                .collect(),
        });
        if let Some(note) = &r.formal_note {
            doc.push(Block::Paragraph(note.clone()));
        }
    }

    doc.push(Block::Heading(2, "Distributions".into()));
    for (stem, chart) in charts(r) {
        doc.push(Block::Figure {
            stem,
            caption: chart.title,
        });
    }
    let h = &r.histogram_out;
    if h.below + h.above > 0 {
        doc.push(Block::Paragraph(format!(
            "{} output errors fall outside the histogram's range of ±{} LSB.",
            h.below + h.above,
            -h.lo
        )));
    }
    if !c.notes.is_empty() {
        doc.push(Block::Heading(2, "Notes".into()));
        for note in &c.notes {
            doc.push(Block::Paragraph(note.clone()));
        }
    }
    doc
}

/// Every file of a budget report's directory, rendered in memory as `(name, bytes)`: the
/// charts (SVG and PNG), `budget.md` and `budget.html` (the document, ending with the
/// provenance's line; the HTML embeds the SVG charts), `budget.json`, and the provenance's
/// two files.
pub fn budget_files(
    r: &BudgetReport,
    provenance: &crate::provenance::Provenance,
) -> Result<Vec<(String, Vec<u8>)>, crate::error::Error> {
    use crate::report::chart::{render_png, render_svg};
    use crate::report::doc::{write_html, write_markdown};
    let mut files = Vec::new();
    let mut svgs = Vec::new();
    for (stem, chart) in charts(r) {
        let svg = render_svg(&chart)?;
        files.push((format!("{stem}.svg"), svg.clone().into_bytes()));
        files.push((format!("{stem}.png"), render_png(&chart)?));
        svgs.push((stem, svg));
    }
    let mut doc = document(r);
    doc.push(Block::Paragraph(provenance.line()));
    let mut md = Vec::new();
    write_markdown(&mut md, &doc).expect("writing into memory cannot fail");
    let mut html = Vec::new();
    write_html(
        &mut html,
        &format!("Error budget: {}", r.config),
        &doc,
        |stem| {
            svgs.iter()
                .find(|(s, _)| s == stem)
                .map(|(_, svg)| svg.clone())
        },
    )
    .expect("writing into memory cannot fail");
    let mut json = serde_json::to_vec_pretty(r).map_err(|e| crate::error::Error::Render {
        message: format!("budget.json: {e}"),
    })?;
    json.push(b'\n');
    files.push(("budget.md".into(), md));
    files.push(("budget.html".into(), html));
    files.push(("budget.json".into(), json));
    files.extend(provenance.files());
    Ok(files)
}
