//! Reports: the one place that turns results into bytes (CSV, charts) and reads saved results
//! back.
//! - [`csv`]: the `viewfactors` matrix;
//! - [`solve_csv`]: the `solve` table and radiative conductances;
//! - [`read_vf`]: a saved `viewfactors` CSV, matched to a scene (`solve --viewfactors`);
//! - [`charts`]: log–log charts of the validation studies (SVG, PNG).
pub mod charts;
pub mod csv;
pub mod read_vf;
pub mod solve_csv;
