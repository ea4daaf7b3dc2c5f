//! Renders results as text tables and CSV into any writer; never opens files.
pub mod check;
pub mod csv;
pub mod paper;
