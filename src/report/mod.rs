//! Renders results as text tables (comfy-table), CSV (the csv crate) and charts into any writer or
//! buffer; never opens files.
pub mod budget;
pub mod calibrate;
pub mod chart;
pub mod check;
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
