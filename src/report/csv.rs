//! The CSV renderings of reference results: the minimax table, per-n method errors and
//! normalisation coefficients, through [`CsvWriter`] (`crate::csv_dialect`, re-exported here).

use std::io::{self, Write};

pub use crate::csv_dialect::CsvWriter;

use crate::analysis::methods::MethodErrors;
use crate::reference::minimax::{MinimaxFit, TABLE_HEADER};
use crate::reference::normalisation::{coefficient, CoefSource, Form};

/// Writes a minimax table: the [`TABLE_HEADER`] line, then one row per fit (the format of
/// `data/minimax.csv`, which [`crate::reference::minimax::parse_table`] reads).
pub fn write_minimax_table(w: &mut impl Write, fits: &[MinimaxFit]) -> io::Result<()> {
    let mut csv = CsvWriter::new(w);
    csv.record(TABLE_HEADER.split(','))?;
    for f in fits {
        csv.record(f.csv_fields())?;
    }
    csv.finish().map(drop)
}

/// Writes one row per exponent: `n`, then one column per method (max |error| over c).
pub fn write_method_errors(
    w: &mut impl Write,
    ns: &[u32],
    errs: &[MethodErrors],
) -> io::Result<()> {
    let mut csv = CsvWriter::new(w);
    csv.record(std::iter::once("n".to_string()).chain(errs.iter().map(|e| e.method.to_string())))?;
    for (i, n) in ns.iter().enumerate() {
        csv.record(
            std::iter::once(n.to_string()).chain(errs.iter().map(|e| format!("{:e}", e.per_n[i]))),
        )?;
    }
    csv.finish().map(drop)
}

/// Writes `form,n,classic,paper,exact` rows (exact for m = 2^k) for every form and exponent.
pub fn write_coefficients(w: &mut impl Write, ns: &[u32], k: u32) -> io::Result<()> {
    let mut csv = CsvWriter::new(w);
    csv.record([
        "form".to_string(),
        "n".into(),
        "classic".into(),
        "paper".into(),
        format!("exact_m{}", 1u32 << k),
    ])?;
    for form in Form::ALL {
        for &n in ns {
            let nf = f64::from(n);
            csv.record([
                form.to_string(),
                n.to_string(),
                format!("{:e}", coefficient(form, CoefSource::Classic, nf, k)),
                format!("{:e}", coefficient(form, CoefSource::Paper, nf, k)),
                format!("{:e}", coefficient(form, CoefSource::Exact, nf, k)),
            ])?;
        }
    }
    csv.finish().map(drop)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::minimax::parse_table;

    /// What `specfx minimax --write` writes, the library reads back bit for bit.
    #[test]
    fn a_minimax_table_round_trips() {
        let fits = [
            MinimaxFit {
                n: 16,
                k: 4,
                a: 1.0000000000000002,
                b: -0.1,
                max_abs_err: 1e-300,
                plain_max_abs_err: 3.0e-3,
            },
            MinimaxFit {
                n: 4096,
                k: 7,
                a: 32.5,
                b: -31.5,
                max_abs_err: 0.0,
                plain_max_abs_err: f64::MIN_POSITIVE,
            },
        ];
        let mut out = Vec::new();
        write_minimax_table(&mut out, &fits).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert!(text.starts_with("k,n,a,b,max_abs_err,plain_max_abs_err\n4,16,1.0000000000000002e0,-1e-1,1e-300,3e-3\n"), "{text}");
        assert_eq!(parse_table(&text).unwrap(), fits);
    }

    /// A bad table names the line and the column.
    #[test]
    fn a_bad_minimax_table_names_line_and_column() {
        let head = "k,n,a,b,max_abs_err,plain_max_abs_err\n";
        let e = parse_table(&format!("{head}4,16,1,2,3,4\n4,17,1,2\n")).unwrap_err();
        assert!(e.to_string().contains("line 3: expected 6"), "{e}");
        let e = parse_table(&format!("{head}4,16,1,2,3,4\n4,-17,1,2,3,4\n")).unwrap_err();
        assert!(
            e.to_string()
                .contains("line 3 column 2: expected an integer, got '-17'"),
            "{e}"
        );
        let e = parse_table("k,n\n").unwrap_err();
        assert!(e.to_string().contains("line 1: expected header"), "{e}");
    }
}
