//! Renders results as text tables (comfy-table), CSV (the csv crate) and charts into any writer or
//! buffer; never opens files.
pub mod budget;
pub mod calibrate;
pub mod chart;
pub mod check;
pub mod cluster;
pub mod cost;
pub mod csv;
pub mod doc;
pub mod fit;
pub mod furnace;
pub mod index;
pub mod optimize;
pub mod paper;
pub mod scene;
pub mod stability;
pub mod sweep;
pub mod table;
pub mod tradeoff;

use crate::error::Error;

/// A file rendered into memory, `(name, bytes)`; a result is a list of them, written by one
/// call ([`crate::output::write_all_in`]).
pub type File = (String, Vec<u8>);

/// What a writer function renders into memory (which cannot fail).
pub fn in_memory(render: impl FnOnce(&mut Vec<u8>) -> std::io::Result<()>) -> Vec<u8> {
    let mut buf = Vec::new();
    render(&mut buf).expect("writing into memory cannot fail");
    buf
}

/// The file `name` holding `value` as pretty JSON and a newline.
pub fn json_file(name: &str, value: &impl serde::Serialize) -> Result<File, Error> {
    let mut json = serde_json::to_vec_pretty(value).map_err(|e| Error::Render {
        message: format!("{name}: {e}"),
    })?;
    json.push(b'\n');
    Ok((name.to_string(), json))
}

/// A chart as the files `stem.svg` and `stem.png`, and the SVG's text (a page inlines it).
pub fn chart_files(stem: &str, chart: &chart::Chart) -> Result<(String, [File; 2]), Error> {
    let svg = chart::render_svg(chart)?;
    let png = chart::render_png(chart)?;
    let files = [
        (format!("{stem}.svg"), svg.clone().into_bytes()),
        (format!("{stem}.png"), png),
    ];
    Ok((svg, files))
}
