//! Result writers behind one trait: each output format is a [`Writer`] that takes the run's
//! [`Results`] and writes its file into a planned [`OutputSet`] slot (checked before work,
//! written as a temporary, renamed on commit). The CLI routes (`viewfactors`, `solve` on every
//! store, `render`) only choose which writers a run's flags ask for and hand them the results,
//! so a new format is its own writer plus the flag that asks for it.
//!
//! - [`Table`]: the CSV of SPEC (view factors, packed or by rows; the per-surface solution);
//! - [`Vtk`]: the VTK results mesh (`.vtu` or `.vtp`);
//! - [`Deck`]: the conductance deck (CSV, SINDA, ESATAN);
//! - [`Png`]: a rendered picture.
use super::decks::{DeckFormat, DeckInfo};
use super::outputs::OutputSet;
use super::render::Image;
use super::vtk::VtkKind;
use crate::plan::{Matrix, VfOutcome};
use crate::scene::{fingerprint, Scene};
use crate::solve::conductance::Conductances;
use crate::solve::Solution;
use crate::{Error, Result};
use std::io::Write;
use std::path::Path;

/// What a run hands its writers.
#[derive(Debug, Clone, Copy)]
pub enum Results<'a> {
    /// A view-factor run.
    ViewFactors {
        /// The scene.
        scene: &'a Scene,
        /// The factors with their raw row sums.
        outcome: &'a VfOutcome,
    },
    /// A solution, at the level it is written.
    Solution {
        /// The scene.
        scene: &'a Scene,
        /// Per node radiosity, heat flux, heat rate and temperature.
        solution: &'a Solution,
    },
    /// Radiative conductances for a thermal network.
    Conductances {
        /// RADK_ij.
        matrix: &'a Conductances,
        /// Scene and title for the deck's header.
        info: &'a DeckInfo,
    },
    /// A rendered picture.
    Picture(&'a Image),
}

impl Results<'_> {
    /// What these results are, for the message of a writer that cannot write them.
    fn kind(&self) -> &'static str {
        match self {
            Results::ViewFactors { .. } => "view factors",
            Results::Solution { .. } => "a solution",
            Results::Conductances { .. } => "conductances",
            Results::Picture(_) => "a picture",
        }
    }
}

/// One output format.
pub trait Writer {
    /// The output's key in the [`OutputSet`] (`output`, `vtk`, `conductances`).
    fn key(&self) -> &'static str;
    /// Writes `results` to `w` (`path` names the file in messages).
    fn write(&self, w: &mut dyn Write, path: &Path, results: &Results) -> Result<()>;
}

/// Writes `results` with every writer, in order, into `outs` (committed by the caller).
pub fn write_all(outs: &mut OutputSet, writers: &[&dyn Writer], results: &Results) -> Result<()> {
    for writer in writers {
        outs.write(writer.key(), |w, p| writer.write(w, p, results))?;
    }
    Ok(())
}

fn unsupported(format: &str, results: &Results) -> Error {
    Error::Compute(format!("the {format} writer cannot write {}", results.kind()))
}

/// The CSV tables of SPEC: view factors (with the scene's geometry stamp) or a solution.
#[derive(Debug, Clone, Copy)]
pub struct Table;

impl Writer for Table {
    fn key(&self) -> &'static str {
        "output"
    }
    fn write(&self, w: &mut dyn Write, path: &Path, results: &Results) -> Result<()> {
        match *results {
            Results::ViewFactors { scene, outcome } => {
                let open = !scene.is_closed();
                let geometry = fingerprint::geometry(scene);
                match &outcome.matrix {
                    Matrix::Packed { triangle, names } => {
                        super::dense_csv::write_triangle(w, triangle, names, open, &geometry, path)
                    }
                    Matrix::Rows(vf) => super::csv::write_viewfactors(w, vf, open, &geometry, path),
                }
            }
            Results::Solution { solution, .. } => super::solve_csv::write_solution(w, solution, path),
            _ => Err(unsupported("CSV table", results)),
        }
    }
}

/// The VTK results mesh: per-patch view-factor fields or the solution's fields.
#[derive(Debug, Clone, Copy)]
pub struct Vtk(pub VtkKind);

impl Writer for Vtk {
    fn key(&self) -> &'static str {
        "vtk"
    }
    fn write(&self, w: &mut dyn Write, path: &Path, results: &Results) -> Result<()> {
        let (scene, fields) = match *results {
            Results::ViewFactors { scene, outcome } => (
                scene,
                super::vtk::viewfactor_fields(scene, &outcome.to_viewfactors(), &outcome.raw_row_sums),
            ),
            Results::Solution { scene, solution } => (scene, super::vtk::solution_fields(scene, solution)),
            _ => return Err(unsupported("VTK", results)),
        };
        super::vtk::write_to(w, path, self.0, scene, &fields)
    }
}

/// The conductance deck in its format.
#[derive(Debug, Clone, Copy)]
pub struct Deck(pub DeckFormat);

impl Writer for Deck {
    fn key(&self) -> &'static str {
        "conductances"
    }
    fn write(&self, w: &mut dyn Write, path: &Path, results: &Results) -> Result<()> {
        match *results {
            Results::Conductances { matrix, info } => super::decks::write(self.0, w, matrix, info, path),
            _ => Err(unsupported("conductance deck", results)),
        }
    }
}

/// A rendered picture as PNG.
#[derive(Debug, Clone, Copy)]
pub struct Png;

impl Writer for Png {
    fn key(&self) -> &'static str {
        "output"
    }
    fn write(&self, w: &mut dyn Write, path: &Path, results: &Results) -> Result<()> {
        match *results {
            Results::Picture(img) => super::render::encode_png(img, w, path),
            _ => Err(unsupported("PNG", results)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A writer handed results it has no form for says so instead of writing a wrong file.
    #[test]
    fn a_writer_refuses_results_it_cannot_write() {
        let img = Image { w: 1, h: 1, rgb: vec![0, 0, 0], range: (0.0, 1.0) };
        let pic = Results::Picture(&img);
        let mut buf = Vec::new();
        for (writer, name) in [
            (&Table as &dyn Writer, "CSV table"),
            (&Vtk(VtkKind::PolyData), "VTK"),
            (&Deck(DeckFormat::Csv), "conductance deck"),
        ] {
            let e = writer.write(&mut buf, Path::new("x"), &pic).unwrap_err().to_string();
            assert!(e.contains(&format!("the {name} writer cannot write a picture")), "{e}");
        }
        assert!(buf.is_empty());
        Png.write(&mut buf, Path::new("x.png"), &pic).expect("png");
        assert!(buf.starts_with(b"\x89PNG"));
    }
}
