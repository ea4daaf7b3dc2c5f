//! Plain text tables for the terminal, laid out by comfy-table: borderless columns, at their
//! content's width or fitted into a given width by wrapping cells.
//!
//! The width is the caller's choice, never looked up here: `None` lays every column out at the
//! width of its widest cell (what the commands print into a pipe or a file: the same bytes on
//! every run, wherever it runs), `Some(w)` wraps cells so that every line of the table has at
//! most `w` characters (what the commands print on a terminal `w` columns wide). No colour or
//! other escape sequence is ever written.

use std::io::{self, Write};

use comfy_table::{CellAlignment, ColumnConstraint, ContentArrangement, Table, TableComponent};

/// How a column's cells are aligned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Align {
    /// Text columns: names, formats.
    Left,
    /// Number columns.
    Right,
}

/// A character that never appears in a cell: comfy-table draws it between rows, and
/// [`TextTable::write`] replaces those lines by the notes of the row above (or drops them).
const ROW_BREAK: char = '\u{1f}';

/// The narrowest a text column is wrapped to while the number columns keep their width.
const MIN_TEXT_COLUMN: usize = 6;

/// A text table: a header row, rows of cells, and notes under any row.
///
/// Columns are separated by one space (`gap` more where asked), lines are indented by
/// `indent` spaces and carry no trailing spaces.
///
/// # Examples
/// ```
/// use specfx::report::table::{Align, TextTable};
/// let mut t = TextTable::new(&[("stage", Align::Left), ("max |err|", Align::Right)]);
/// t.row(["d", "0.000e0"]);
/// t.row(["sq1", "2.276e-5"]);
/// t.note("^ a note under sq1");
/// let mut out = Vec::new();
/// t.write(&mut out, None).unwrap();
/// assert_eq!(
///     String::from_utf8(out).unwrap(),
///     "stage max |err|\n\
///      d       0.000e0\n\
///      sq1    2.276e-5\n\
///      ^ a note under sq1\n"
/// );
/// ```
#[derive(Debug, Clone)]
pub struct TextTable {
    header: Vec<String>,
    align: Vec<Align>,
    gaps: Vec<usize>,
    rows: Vec<Vec<String>>,
    /// `notes[i]`: the lines written under row `i`.
    notes: Vec<Vec<String>>,
    indent: usize,
    note_indent: usize,
}

impl TextTable {
    /// A table with these columns (header text, alignment) and no rows.
    pub fn new(columns: &[(&str, Align)]) -> Self {
        TextTable {
            header: columns.iter().map(|(h, _)| clean(h)).collect(),
            align: columns.iter().map(|&(_, a)| a).collect(),
            gaps: vec![0; columns.len()],
            rows: Vec::new(),
            notes: Vec::new(),
            indent: 0,
            note_indent: 0,
        }
    }

    /// Indents every line of the table by `spaces`.
    pub fn indent(mut self, spaces: usize) -> Self {
        self.indent = spaces;
        self
    }

    /// Indents the notes by `spaces` (counted from the line's start, not from the table's
    /// indent).
    pub fn note_indent(mut self, spaces: usize) -> Self {
        self.note_indent = spaces;
        self
    }

    /// Puts `spaces` more spaces before column `column` (so 1 gives a two-space gap): a
    /// visual group.
    pub fn gap_before(mut self, column: usize, spaces: usize) -> Self {
        self.gaps[column] = spaces;
        self
    }

    /// Appends a row; it has as many cells as the table has columns.
    ///
    /// # Panics
    /// When the number of cells differs from the number of columns (a programming error).
    pub fn row<S: AsRef<str>>(&mut self, cells: impl IntoIterator<Item = S>) {
        let cells: Vec<String> = cells.into_iter().map(|c| clean(c.as_ref())).collect();
        assert_eq!(
            cells.len(),
            self.header.len(),
            "a row of {} cells in a table of {} columns",
            cells.len(),
            self.header.len()
        );
        self.rows.push(cells);
        self.notes.push(Vec::new());
    }

    /// Adds a line under the last row (it stays under that row however the cells wrap).
    ///
    /// # Panics
    /// Before the first row (a programming error).
    pub fn note(&mut self, line: impl Into<String>) {
        self.notes
            .last_mut()
            .expect("a note follows a row")
            .push(line.into());
    }

    /// The number of rows.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether the table has no rows.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Writes the table: with `width` `None` every column at its widest cell's width; with
    /// `Some(w)` cells wrapped (at spaces where they can be, anywhere where they cannot) so
    /// that every line has at most `w` characters, notes word-wrapped too, as long as `w`
    /// leaves every column one character and its separator (below that, lines are as narrow
    /// as comfy-table can make them). A table narrower than `w` is written as with `None`.
    pub fn write(&self, w: &mut impl Write, width: Option<u16>) -> io::Result<()> {
        let mut table = Table::new();
        table
            .load_preset(comfy_table::presets::NOTHING)
            .set_style(TableComponent::HorizontalLines, ROW_BREAK)
            .set_header(self.header.clone());
        for row in &self.rows {
            table.add_row(row.clone());
        }
        for (i, column) in table.column_iter_mut().enumerate() {
            // One space between columns: no padding on the left of a cell but its gap, one on
            // the right.
            column.set_padding((self.gaps[i] as u16, 1));
            column.set_cell_alignment(match self.align[i] {
                Align::Left => CellAlignment::Left,
                Align::Right => CellAlignment::Right,
            });
        }
        if let Some(w) = width {
            self.arrange(&mut table, w);
        }
        let pad = " ".repeat(self.indent);
        let mut row_idx = 0;
        for line in table.lines() {
            if line.contains(ROW_BREAK) {
                self.write_notes(w, row_idx, width)?;
                row_idx += 1;
                continue;
            }
            let line = line.trim_end();
            if line.is_empty() {
                writeln!(w)?;
            } else {
                writeln!(w, "{pad}{line}")?;
            }
        }
        if !self.rows.is_empty() {
            self.write_notes(w, self.rows.len() - 1, width)?;
        }
        Ok(())
    }

    /// Fits `table` into `width` characters (with the indent). A table that fits is left at
    /// its content's width. Otherwise the number columns keep their widest cell's width (their
    /// headers wrap at spaces) and only the text columns wrap, while that leaves each text
    /// column [`MIN_TEXT_COLUMN`] characters; failing that, every column wraps (comfy-table's
    /// dynamic arrangement).
    fn arrange(&self, table: &mut Table, width: u16) {
        let content = table.column_max_content_widths();
        let n = self.header.len();
        let natural = self.indent
            + content.iter().map(|&c| usize::from(c)).sum::<usize>()
            + self.gaps.iter().sum::<usize>()
            + n.saturating_sub(1);
        if natural <= usize::from(width) {
            return;
        }
        // The last column's right padding is trimmed, so the table may use one more.
        let available = usize::from(width).saturating_sub(self.indent) + 1;
        table.set_content_arrangement(ContentArrangement::Dynamic);
        table.set_width(u16::try_from(available).unwrap_or(u16::MAX));
        let number_width = |i: usize| -> usize {
            let longest_word = self.header[i]
                .split(' ')
                .map(|w| w.chars().count())
                .max()
                .unwrap_or(0);
            self.rows
                .iter()
                .map(|r| r[i].chars().count())
                .max()
                .unwrap_or(0)
                .max(longest_word)
        };
        let fixed: usize = (0..n)
            .map(|i| match self.align[i] {
                Align::Right => number_width(i),
                Align::Left => MIN_TEXT_COLUMN,
            } + self.gaps[i]
                + 1)
            .sum();
        if fixed <= available {
            for i in (0..n).filter(|&i| self.align[i] == Align::Right) {
                let w = u16::try_from(number_width(i) + self.gaps[i] + 1).unwrap_or(u16::MAX);
                if let Some(column) = table.column_mut(i) {
                    column.set_constraint(ColumnConstraint::Absolute(comfy_table::Width::Fixed(w)));
                }
            }
        }
    }

    fn write_notes(
        &self,
        w: &mut impl Write,
        row_idx: usize,
        width: Option<u16>,
    ) -> io::Result<()> {
        let pad = " ".repeat(self.note_indent);
        for note in &self.notes[row_idx] {
            match width {
                None => writeln!(w, "{pad}{note}")?,
                Some(width) => {
                    // Continuation lines hang under the note's first word's end (`^ `).
                    let hang = note.find(' ').map_or(0, |i| i + 1);
                    let lines = wrap_words(
                        note,
                        usize::from(width).saturating_sub(self.note_indent),
                        hang,
                    );
                    for (i, l) in lines.iter().enumerate() {
                        let extra = if i == 0 { 0 } else { hang };
                        writeln!(w, "{pad}{}{l}", " ".repeat(extra))?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// A cell's text on one line: tabs and line breaks become spaces, and [`ROW_BREAK`] cannot
/// appear.
fn clean(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// Splits `text` into lines of at most `width` characters at spaces (a word longer than a line
/// is cut); lines after the first are `hang` characters narrower (the caller indents them).
fn wrap_words(text: &str, width: usize, hang: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        let room = |lines: &Vec<String>| {
            if lines.is_empty() {
                width.max(1)
            } else {
                width.saturating_sub(hang).max(1)
            }
        };
        let mut word: String = word.to_string();
        loop {
            let len = line.chars().count();
            let wlen = word.chars().count();
            let sep = usize::from(len > 0);
            if len + sep + wlen <= room(&lines) {
                if sep == 1 {
                    line.push(' ');
                }
                line.push_str(&word);
                break;
            }
            if len > 0 {
                lines.push(std::mem::take(&mut line));
                continue;
            }
            // A word wider than a whole line: cut it.
            let cut: String = word.chars().take(room(&lines)).collect();
            word = word.chars().skip(room(&lines)).collect();
            lines.push(cut);
            if word.is_empty() {
                break;
            }
        }
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    fn render(t: &TextTable, width: Option<u16>) -> String {
        let mut out = Vec::new();
        t.write(&mut out, width).unwrap();
        String::from_utf8(out).unwrap()
    }

    /// A table shaped like the check's: twelve columns, some wide, a note under one row.
    fn wide() -> TextTable {
        let mut t = TextTable::new(&[
            ("stage", Align::Left),
            ("format", Align::Left),
            ("max |err|", Align::Right),
            ("mean err", Align::Right),
            ("rms err", Align::Right),
            ("max ulp", Align::Right),
            ("correct", Align::Right),
            ("faithful", Align::Right),
            ("worst input", Align::Left),
            ("sat", Align::Right),
            ("wrap", Align::Right),
            ("zero", Align::Right),
        ])
        .indent(2)
        .note_indent(8)
        .gap_before(8, 1);
        for (i, stage) in ["d", "t", "b", "sq1", "sq2", "out"].iter().enumerate() {
            t.row([
                stage.to_string(),
                "s2.16".into(),
                format!("{}.000e-{i}", i + 1),
                "1.31e-1".into(),
                "3.591e-1".into(),
                "131072.0000".into(),
                "79.454%".into(),
                "100.000%".into(),
                format!("n=1024 c_raw={}", 32000 + i),
                "329896".into(),
                "0".into(),
                "0".into(),
            ]);
            if *stage == "t" {
                t.note("^ t saturated 329896 times, always at its minimum -2: harmless, since t_min + offset <= 0 gives a base <= 0 that the clamp cuts to 0 anyway");
            }
        }
        t
    }

    /// The non-space characters of a text, sorted: wrapping moves characters, never adds or
    /// drops one.
    fn ink(text: &str) -> Vec<char> {
        let mut v: Vec<char> = text.chars().filter(|c| !c.is_whitespace()).collect();
        v.sort_unstable();
        v
    }

    #[test]
    fn without_a_width_columns_take_their_widest_cell_and_the_bytes_never_change() {
        let mut t = TextTable::new(&[("a", Align::Left), ("bb", Align::Right), ("c", Align::Left)])
            .indent(2)
            .note_indent(4)
            .gap_before(2, 1);
        t.row(["xyz", "1", "p"]);
        t.note("^ under xyz");
        t.row(["q", "12345", "long cell"]);
        // Column widths 3, 5, 9; one space between columns, two before c; no trailing spaces.
        let want = "  a      bb  c\n  xyz     1  p\n    ^ under xyz\n  q   12345  long cell\n";
        assert_eq!(render(&t, None), want);
        assert_eq!(render(&wide(), None), render(&wide(), None));
        // A width the table fits in changes nothing.
        assert_eq!(render(&t, Some(22)), want);
        assert_eq!(render(&wide(), Some(200)), render(&wide(), None));
    }

    #[test]
    fn with_a_width_every_line_fits_and_nothing_is_lost() {
        let piped = render(&wide(), None);
        let natural = piped
            .lines()
            .filter(|l| !l.contains('^'))
            .map(|l| l.chars().count())
            .max()
            .unwrap();
        assert_eq!(natural, 108);
        // 12 columns of at least one character and a separator, the gap and the indent.
        let narrowest = 2 + 12 * 2 + 1;
        for width in narrowest..=piped.lines().map(|l| l.chars().count()).max().unwrap() + 2 {
            let text = render(&wide(), Some(width as u16));
            for line in text.lines() {
                assert!(
                    line.chars().count() <= width,
                    "width {width}: '{line}'\n{text}"
                );
                assert_eq!(line, line.trim_end(), "width {width}: trailing spaces");
            }
            assert_eq!(ink(&text), ink(&piped), "width {width}\n{text}");
            // The note stays between the rows t and b.
            let lines: Vec<&str> = text.lines().collect();
            let row = |stage: &str| {
                lines
                    .iter()
                    .position(|l| l.starts_with(&format!("  {stage} ")))
                    .unwrap()
            };
            let note = lines
                .iter()
                .position(|l| l.starts_with("        ^ t"))
                .unwrap();
            assert!(row("t") < note && note < row("b"), "width {width}\n{text}");
        }
    }

    #[test]
    fn number_columns_keep_their_width_while_text_columns_can_wrap() {
        // Natural width 108 (the rows of the piped form); at 100 only "worst input" and the
        // number headers wider than their numbers wrap.
        let text = render(&wide(), Some(100));
        assert!(text.contains(" 131072.0000 "), "{text}");
        assert!(text.contains(" 1.000e-0 "), "{text}");
        assert!(text.lines().any(|l| l.trim() == "c_raw=32000"), "{text}");
    }

    #[test]
    fn notes_wrap_at_spaces_under_their_first_word() {
        assert_eq!(
            wrap_words("^ aa bbb cc dddddddd", 8, 2),
            ["^ aa bbb", "cc", "dddddd", "dd"]
        );
        assert_eq!(wrap_words("short", 80, 2), ["short"]);
        let mut t = TextTable::new(&[("a", Align::Left)]);
        t.row(["x"]);
        t.note("^ one two three");
        assert_eq!(render(&t, Some(9)), "a\nx\n^ one two\n  three\n");
    }
}
