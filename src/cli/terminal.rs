//! The width that tables printed on stdout are fitted into: the terminal's, or none when
//! stdout is a pipe or a file (then tables are as wide as their content, the same bytes on
//! every run).

use std::io::IsTerminal;

/// The terminal's width in columns when stdout is a terminal whose size is known; `None`
/// otherwise (a pipe, a file, an unknown size).
pub fn table_width() -> Option<u16> {
    if !std::io::stdout().is_terminal() {
        return None;
    }
    console::Term::stdout()
        .size_checked()
        .map(|(_rows, columns)| columns)
        .filter(|&c| c > 0)
}
