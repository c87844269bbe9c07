//! Reports: the one place that turns results into bytes (CSV, charts).
pub mod charts;
pub mod csv;
