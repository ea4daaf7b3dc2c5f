//! CSV output through the `csv` crate in specfx's dialect ([`CsvWriter`]: every file specfx
//! writes as CSV goes through it), below every module that writes CSV (`golden/`, `report/`).
//!
//! Numbers are formatted to text by the callers (`{:e}`, `{}`: shortest round-trip), so the
//! writer only decides quoting: a field is quoted when it holds a comma, a quote (doubled) or a
//! line break, and written as it is otherwise. Lines end in `\n`; every record has as many
//! fields as the first.

use std::io::{self, Write};

/// A CSV writer over any `io::Write` in specfx's dialect (see the module docs).
///
/// # Examples
/// ```
/// use specfx::csv_dialect::CsvWriter;
/// let mut out = Vec::new();
/// let mut w = CsvWriter::new(&mut out);
/// w.record(["name", "value"]).unwrap();
/// w.record(["a,b", "say \"hi\""]).unwrap();
/// w.record(["plain", "1e-3"]).unwrap();
/// w.finish().unwrap();
/// assert_eq!(
///     String::from_utf8(out).unwrap(),
///     "name,value\n\"a,b\",\"say \"\"hi\"\"\"\nplain,1e-3\n"
/// );
/// ```
pub struct CsvWriter<W: Write> {
    inner: ::csv::Writer<W>,
}

impl<W: Write> CsvWriter<W> {
    /// A writer into `w`, with specfx's dialect.
    pub fn new(w: W) -> Self {
        CsvWriter {
            inner: ::csv::WriterBuilder::new()
                .terminator(::csv::Terminator::Any(b'\n'))
                .quote_style(::csv::QuoteStyle::Necessary)
                .flexible(false)
                .from_writer(w),
        }
    }

    /// Writes one record (the header is the first).
    ///
    /// # Errors
    /// The underlying writer's error; a record whose length differs from the first's (a
    /// programming error) as `InvalidInput`.
    pub fn record<I, T>(&mut self, fields: I) -> io::Result<()>
    where
        I: IntoIterator<Item = T>,
        T: AsRef<[u8]>,
    {
        self.inner.write_record(fields).map_err(into_io)
    }

    /// Writes one field of the current record; [`CsvWriter::end_record`] ends it. For writers
    /// that produce fields one at a time without collecting them.
    pub fn field(&mut self, field: impl AsRef<[u8]>) -> io::Result<()> {
        self.inner.write_field(field).map_err(into_io)
    }

    /// Ends the record begun by [`CsvWriter::field`].
    pub fn end_record(&mut self) -> io::Result<()> {
        self.inner.write_record(None::<&[u8]>).map_err(into_io)
    }

    /// Flushes what is buffered into the underlying writer and returns it.
    pub fn finish(self) -> io::Result<W> {
        self.inner.into_inner().map_err(|e| e.into_error())
    }
}

/// The csv crate's error as an `io::Error`, keeping an I/O error's kind (a broken pipe stays
/// one).
fn into_io(e: ::csv::Error) -> io::Error {
    let message = e.to_string();
    match e.into_kind() {
        ::csv::ErrorKind::Io(io) => io,
        _ => io::Error::new(io::ErrorKind::InvalidInput, message),
    }
}
