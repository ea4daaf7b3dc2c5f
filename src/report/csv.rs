//! CSV renderings of reference results: per-n method errors and normalisation coefficients.

use std::io::{self, Write};

use crate::analysis::methods::MethodErrors;
use crate::reference::normalisation::{coefficient, CoefSource, Form};

/// Writes one row per exponent: `n`, then one column per method (max |error| over c).
pub fn write_method_errors(
    w: &mut impl Write,
    ns: &[u32],
    errs: &[MethodErrors],
) -> io::Result<()> {
    write!(w, "n")?;
    for e in errs {
        write!(w, ",{}", e.method)?;
    }
    writeln!(w)?;
    for (i, n) in ns.iter().enumerate() {
        write!(w, "{n}")?;
        for e in errs {
            write!(w, ",{:e}", e.per_n[i])?;
        }
        writeln!(w)?;
    }
    Ok(())
}

/// Writes `form,n,classic,paper,exact` rows (exact for m = 2^k) for every form and exponent.
pub fn write_coefficients(w: &mut impl Write, ns: &[u32], k: u32) -> io::Result<()> {
    writeln!(w, "form,n,classic,paper,exact_m{}", 1u32 << k)?;
    for form in Form::ALL {
        for &n in ns {
            let nf = f64::from(n);
            writeln!(
                w,
                "{form},{n},{:e},{:e},{:e}",
                coefficient(form, CoefSource::Classic, nf, k),
                coefficient(form, CoefSource::Paper, nf, k),
                coefficient(form, CoefSource::Exact, nf, k)
            )?;
        }
    }
    Ok(())
}
