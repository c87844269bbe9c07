//! Reports: the one place that turns results into bytes (CSV).
pub mod csv;
