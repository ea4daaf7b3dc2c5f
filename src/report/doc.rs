//! A small document model (headings, paragraphs, tables, figures) rendered to Markdown or to
//! one self-contained HTML page, so a report is written once and read either way.

use std::io::{self, Write};

/// One block of a document.
#[derive(Debug, Clone, PartialEq)]
pub enum Block {
    /// A heading of level 1..=3.
    Heading(u8, String),
    /// A paragraph of plain text (`code` spans in backquotes are kept as code).
    Paragraph(String),
    /// A table: a header row and body rows of the same length.
    Table {
        /// Column titles.
        header: Vec<String>,
        /// Body rows.
        rows: Vec<Vec<String>>,
    },
    /// A figure: a chart written beside the document as `<stem>.svg` and `<stem>.png`.
    Figure {
        /// The file stem.
        stem: String,
        /// The caption.
        caption: String,
    },
    /// An image file beside the document, linked rather than inlined (for documents with
    /// many large images).
    Image {
        /// The file name, relative to the document.
        src: String,
        /// The caption.
        caption: String,
    },
}

/// Escapes text for Markdown outside its `code` spans: `&`, `<` and `>` as entities (no raw
/// HTML such as `<script>` gets through), `\\`, `[` and `]` with a backslash (no links or
/// images). Code spans are kept as they are: Markdown shows their content literally. A control
/// character (a line break, a tab) is shown as its Rust escape (`\n`) everywhere, so that text
/// cannot start a heading, a list or a table row of its own.
///
/// # Examples
/// ```
/// use specfx::report::doc::md_escape;
/// assert_eq!(md_escape("<img onerror=x> [a](b) `<b>`"), "&lt;img onerror=x&gt; \\[a\\](b) `<b>`");
/// assert_eq!(md_escape("a\n# b `c\nd`"), "a\\\\n# b `c\\nd`");
/// ```
pub fn md_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for (i, part) in s.split('`').enumerate() {
        if i > 0 {
            out.push('`');
        }
        if i % 2 == 1 {
            for ch in part.chars() {
                if ch.is_control() {
                    out.extend(ch.escape_debug());
                } else {
                    out.push(ch);
                }
            }
            continue;
        }
        for ch in part.chars() {
            match ch {
                // The escape's backslash escaped in turn, so that Markdown shows `\n`.
                _ if ch.is_control() => {
                    out.push_str(&ch.escape_debug().to_string().replace('\\', "\\\\"))
                }
                '&' => out.push_str("&amp;"),
                '<' => out.push_str("&lt;"),
                '>' => out.push_str("&gt;"),
                '\\' | '[' | ']' => {
                    out.push('\\');
                    out.push(ch);
                }
                _ => out.push(ch),
            }
        }
    }
    out
}

fn md_cell(s: &str) -> String {
    md_escape(s).replace('|', "\\|")
}

/// Renders a document as GitHub-flavoured Markdown; figures link their SVG file.
///
/// # Examples
/// ```
/// use specfx::report::doc::{write_markdown, Block};
/// let doc = [
///     Block::Heading(1, "Budget".into()),
///     Block::Table { header: vec!["stage".into(), "|err|".into()], rows: vec![vec!["t".into(), "1e-5".into()]] },
/// ];
/// let mut out = Vec::new();
/// write_markdown(&mut out, &doc).unwrap();
/// let text = String::from_utf8(out).unwrap();
/// assert!(text.starts_with("# Budget\n"));
/// assert!(text.contains("| stage | \\|err\\| |\n| --- | --- |\n| t | 1e-5 |\n"));
/// ```
pub fn write_markdown(w: &mut impl Write, doc: &[Block]) -> io::Result<()> {
    for (i, block) in doc.iter().enumerate() {
        if i > 0 {
            writeln!(w)?;
        }
        match block {
            Block::Heading(level, text) => {
                writeln!(w, "{} {}", "#".repeat(usize::from(*level)), md_escape(text))?;
            }
            Block::Paragraph(text) => writeln!(w, "{}", md_escape(text))?,
            Block::Table { header, rows } => {
                let line = |cells: &[String]| {
                    let cells: Vec<String> = cells.iter().map(|c| md_cell(c)).collect();
                    format!("| {} |", cells.join(" | "))
                };
                writeln!(w, "{}", line(header))?;
                writeln!(w, "|{}", " --- |".repeat(header.len()))?;
                for row in rows {
                    writeln!(w, "{}", line(row))?;
                }
            }
            Block::Figure { stem, caption } => {
                writeln!(w, "![{}]({stem}.svg)", md_escape(caption))?;
            }
            Block::Image { src, caption } => {
                writeln!(w, "![{}]({src})", md_escape(caption))?;
            }
        }
    }
    Ok(())
}

/// Escapes text for HTML.
pub fn html_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            _ => out.push(ch),
        }
    }
    out
}

/// Writes the minus signs of numbers as U+2212 (a browser never breaks a line after it): a
/// `-` before a digit or a point, at the start, after a space or an opening bracket, after
/// `=`, or in an exponent (`1.5e-3`). Hyphens and spaced binary minus signs stay.
///
/// # Examples
/// ```
/// use specfx::report::doc::number_minus;
/// assert_eq!(number_minus("-1.5e-3 (n = -2)"), "\u{2212}1.5e\u{2212}3 (n = \u{2212}2)");
/// assert_eq!(number_minus("fixed - f64, cs16-paper, x-1"), "fixed - f64, cs16-paper, x-1");
/// ```
pub fn number_minus(s: &str) -> String {
    let chars: Vec<char> = s.chars().collect();
    let mut out = String::with_capacity(s.len());
    for (i, &ch) in chars.iter().enumerate() {
        let next_is_number = chars
            .get(i + 1)
            .is_some_and(|c| c.is_ascii_digit() || *c == '.');
        let prev = if i > 0 { Some(chars[i - 1]) } else { None };
        let exponent = matches!(prev, Some('e' | 'E'))
            && i >= 2
            && (chars[i - 2].is_ascii_digit() || chars[i - 2] == '.');
        let opens = match prev {
            None => true,
            Some(p) => p.is_whitespace() || matches!(p, '(' | '[' | '=' | ',' | ';' | ':'),
        };
        if ch == '-' && next_is_number && (opens || exponent) {
            out.push('\u{2212}');
        } else {
            out.push(ch);
        }
    }
    out
}

/// Escapes text and turns `code` spans into `<code>` elements; numbers outside code get
/// U+2212 minus signs ([`number_minus`]).
fn html_text(s: &str) -> String {
    let mut out = String::new();
    for (i, part) in s.split('`').enumerate() {
        if i % 2 == 1 {
            out.push_str("<code>");
            out.push_str(&html_escape(part));
            out.push_str("</code>");
        } else {
            out.push_str(&html_escape(&number_minus(part)));
        }
    }
    out
}

/// Whether a table cell holds a number (or a short figure such as `12.5%`, `< 1e-11`,
/// `16..=1024`) that must stay on one line.
fn numeric_cell(s: &str) -> bool {
    let t = s.trim();
    let starts = t
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_digit() || matches!(c, '-' | '+' | '.' | '<' | '>' | '±'));
    starts && t.chars().count() <= 32
}

const STYLE: &str =
    "body{font-family:sans-serif;max-width:1000px;margin:2em auto;padding:0 1em;color:#222}\
.table{overflow-x:auto;margin:1em 0}table{border-collapse:collapse;font-size:90%}\
td,th{border:1px solid #bbb;padding:3px 5px;text-align:left;vertical-align:top}\
td.num{white-space:nowrap;text-align:right}th{background:#eee}\
figure{margin:1em 0}figcaption{font-size:90%;color:#555}svg,img{max-width:100%;height:auto}\
code{background:#f3f3f3;padding:0 3px}";

/// Renders a document as one self-contained HTML page: every figure's SVG is inlined, found
/// by its stem through `svg_of`.
///
/// # Examples
/// ```
/// use specfx::report::doc::{write_html, Block};
/// let doc = [Block::Paragraph("a <= b".into()), Block::Figure { stem: "h".into(), caption: "H".into() }];
/// let mut out = Vec::new();
/// write_html(&mut out, "T", &doc, |stem| (stem == "h").then(|| "<svg></svg>".to_string())).unwrap();
/// let text = String::from_utf8(out).unwrap();
/// assert!(text.contains("<p>a &lt;= b</p>"));
/// assert!(text.contains("<svg></svg>"));
/// ```
pub fn write_html(
    w: &mut impl Write,
    title: &str,
    doc: &[Block],
    svg_of: impl Fn(&str) -> Option<String>,
) -> io::Result<()> {
    writeln!(w, "<!DOCTYPE html>")?;
    writeln!(
        w,
        "<html><head><meta charset=\"utf-8\"><title>{}</title><style>{STYLE}</style></head><body>",
        html_escape(title)
    )?;
    for block in doc {
        match block {
            Block::Heading(level, text) => {
                writeln!(w, "<h{level}>{}</h{level}>", html_text(text))?;
            }
            Block::Paragraph(text) => writeln!(w, "<p>{}</p>", html_text(text))?,
            Block::Table { header, rows } => {
                // A wide table scrolls inside its box; the page never does.
                writeln!(w, "<div class=\"table\"><table>")?;
                let cells: String = header
                    .iter()
                    .map(|c| format!("<th>{}</th>", html_text(c)))
                    .collect();
                writeln!(w, "<tr>{cells}</tr>")?;
                for row in rows {
                    let cells: String = row
                        .iter()
                        .map(|c| {
                            let class = if numeric_cell(c) {
                                " class=\"num\""
                            } else {
                                ""
                            };
                            format!("<td{class}>{}</td>", html_text(c))
                        })
                        .collect();
                    writeln!(w, "<tr>{cells}</tr>")?;
                }
                writeln!(w, "</table></div>")?;
            }
            Block::Figure { stem, caption } => {
                writeln!(w, "<figure>")?;
                match svg_of(stem) {
                    // The SVG's own XML is inlined as is; it starts at its <svg> element.
                    Some(svg) => w.write_all(svg.trim_end().as_bytes())?,
                    None => write!(w, "<p>(figure {} missing)</p>", html_escape(stem))?,
                }
                writeln!(
                    w,
                    "\n<figcaption>{}</figcaption></figure>",
                    html_text(caption)
                )?;
            }
            Block::Image { src, caption } => {
                writeln!(
                    w,
                    "<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
                    html_escape(src),
                    html_escape(caption),
                    html_text(caption)
                )?;
            }
        }
    }
    writeln!(w, "</body></html>")
}
