//! View3D `.vs3` input files (NIST View3D 3.x/4.x, `getdat.c`) as a model: formats `F 3`
//! (vertices `V` and surfaces `S i v1 v2 v3 v4 base cmb emit name`) and `F 3a` (BLAST form:
//! `S i R|Q|T base cmb emit name`, then `x0 y0 z0 azimuth tilt` and the local shape), with
//! obstructions `O`, combined surfaces (`cmb`, summed into the earlier surface they name, as
//! View3D does), titles `T` and the control values `encl`, `emit` and `eps`.
//!
//! Records: the first character of the first word of a line names it (case-insensitive);
//! fields may continue onto the next lines; the rest of a record's last line is ignored; `!`
//! starts a comment; `E`/`*` ends the data. What View3D has and lambert cannot express
//! (subsurfaces with `base > 0`, mask `M` and null `N` surfaces) is refused naming the
//! record; controls that only steer View3D's own integrator or output are reported and
//! ignored. Each record is one polygon (View3D requires quadrilaterals planar and convex), so
//! a quadrilateral is one patch; a surface that combines several records (`cmb`) is a mesh of
//! their polygons, one patch each, with the one boundary condition of the surface.
use super::gltf_scene::{MeshSurface, Model};
use super::props::{Layer, Role};
use crate::error::InputError;
use crate::geometry::{DVec3, Polygon};
use std::path::{Path, PathBuf};

/// What the control record `C` asks of a run.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Controls {
    /// `encl = 1`: the surfaces form a closed enclosure (View3D then normalises rows).
    pub enclosure: bool,
    /// `emit = 1`: View3D would write script-F exchange factors.
    pub emittances: bool,
    /// `eps`: View3D's convergence goal, the `auto` tolerance it corresponds to.
    pub eps: Option<f64>,
}

/// A loaded `.vs3` file.
#[derive(Debug, Clone)]
pub struct Vs3 {
    /// Its surfaces (combined surfaces merged) and obstructions as a model.
    pub model: Model,
    /// The last `T` record.
    pub title: Option<String>,
    /// Control values.
    pub controls: Controls,
    /// Notes: ignored controls, clamped emittances, renamed surfaces.
    pub warnings: Vec<String>,
}

/// View3D clamps emittances into this range (`GetSrfD`); lambert keeps (0, 1] and clamps
/// only what lies outside it, as View3D would.
const EMIT_MIN: f64 = 0.001;

/// One word with its 1-based line and whether it starts the line.
#[derive(Debug, Clone, Copy)]
struct Word<'a> {
    text: &'a str,
    line: usize,
    first: bool,
}

struct Reader<'a> {
    path: &'a Path,
    /// The text's lines, comments cut (a title keeps its commas).
    lines: Vec<&'a str>,
    words: Vec<Word<'a>>,
    at: usize,
}

impl<'a> Reader<'a> {
    fn new(path: &'a Path, text: &'a str) -> Self {
        let (mut words, mut lines) = (Vec::new(), Vec::new());
        for (k, line) in text.lines().enumerate() {
            let body = line.split('!').next().unwrap_or("");
            lines.push(body);
            let mut first = true;
            for w in body.split([' ', '\t', ',', '\r']).filter(|w| !w.is_empty()) {
                words.push(Word { text: w, line: k + 1, first });
                first = false;
            }
        }
        Self { path, lines, words, at: 0 }
    }

    fn err(&self, line: usize, problem: impl Into<String>) -> InputError {
        InputError::file(self.path, problem).at_line(line)
    }

    /// The next field of the record that started at `line`, possibly on a following line.
    fn field(&mut self, line: usize, what: &str) -> Result<Word<'a>, InputError> {
        let w = self
            .words
            .get(self.at)
            .copied()
            .filter(|w| !(w.first && w.text.starts_with(char::is_alphabetic)));
        match w {
            Some(w) => {
                self.at += 1;
                Ok(w)
            }
            None => Err(self.err(line, format!("the record is truncated: {what} is missing"))),
        }
    }

    fn number(&mut self, line: usize, what: &str) -> Result<f64, InputError> {
        let w = self.field(line, what)?;
        match w.text.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(self.err(w.line, format!("{what} '{}' is not a finite number", w.text))),
        }
    }

    fn index(&mut self, line: usize, what: &str) -> Result<usize, InputError> {
        let w = self.field(line, what)?;
        w.text
            .parse::<usize>()
            .map_err(|_| self.err(w.line, format!("{what} '{}' is not a whole number", w.text)))
    }

    /// Skips the rest of the line the record ended on.
    fn end_record(&mut self) {
        let last = self.at.checked_sub(1).map(|k| self.words[k].line).unwrap_or(0);
        while self.words.get(self.at).is_some_and(|w| !w.first || w.line == last) {
            self.at += 1;
        }
    }
}

/// One radiating or obstruction record before vertices are resolved.
struct Record {
    line: usize,
    obstruction: bool,
    corners: Corners,
    combine: usize,
    emit: f64,
    name: String,
}

enum Corners {
    /// Vertex numbers (`F 3`; 3 or 4).
    Indices(Vec<usize>),
    /// Coordinates (`F 3a`).
    Points(Vec<DVec3>),
}

/// Loads a `.vs3` file.
pub fn load(path: &Path) -> Result<Vs3, InputError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| InputError::file(path, format!("cannot read the View3D file: {e}")))?;
    parse(path, &text)
}

/// Parses `.vs3` text as if read from `path`.
pub fn parse(path: &Path, text: &str) -> Result<Vs3, InputError> {
    let mut r = Reader::new(path, text);
    let (mut title, mut controls, mut warnings) = (None, Controls::default(), Vec::new());
    let mut format: Option<bool> = None; // Some(true) = F 3a
    let mut vertices: Vec<DVec3> = Vec::new();
    let mut records: Vec<Record> = Vec::new();
    while let Some(w) = r.words.get(r.at).copied() {
        r.at += 1;
        let line = w.line;
        let kind = w.text.chars().next().unwrap_or(' ').to_ascii_uppercase();
        match kind {
            'E' | '*' => break,
            '/' | 'X' => {}
            'T' => {
                // The rest of the raw line after the record's first word.
                let raw = r.lines[line - 1].trim_start();
                title = Some(raw[w.text.len()..].trim().to_string());
            }
            'F' => {
                let f = r.field(line, "the geometry format")?;
                format = Some(match f.text {
                    "3" => false,
                    t if t.eq_ignore_ascii_case("3a") => true,
                    t => {
                        return Err(r.err(
                            line,
                            format!("geometry format 'F {t}' is not supported; lambert reads F 3 and F 3a"),
                        ))
                    }
                });
            }
            'C' => {
                let mut words: Vec<&str> = Vec::new();
                for x in r.words[r.at..].iter().take_while(|x| x.line == line) {
                    words.extend(x.text.split('=').filter(|s| !s.is_empty()));
                }
                for pair in words.chunks(2) {
                    let (key, value) = (pair[0], pair.get(1).copied().unwrap_or(""));
                    let bad = || r.err(line, format!("control value `{key}={value}` is not a number"));
                    match key.to_ascii_lowercase().as_str() {
                        "encl" => controls.enclosure = value.parse::<i64>().map_err(|_| bad())? != 0,
                        "emit" => controls.emittances = value.parse::<i64>().map_err(|_| bad())? != 0,
                        "eps" => {
                            let e = value.parse::<f64>().map_err(|_| bad())?;
                            if !(e.is_finite() && e > 0.0 && e < 1.0) {
                                return Err(r.err(line, format!("control eps={value} must be in (0, 1)")));
                            }
                            controls.eps = Some(e);
                        }
                        "maxu" | "maxo" | "mino" | "list" | "out" | "prjd" | "maxv" | "row" | "col" => {
                            warnings.push(format!(
                                "{}: line {line}: control `{key}={value}` steers View3D's own integrator or output and is ignored",
                                path.display()
                            ))
                        }
                        _ => warnings.push(format!("{}: line {line}: unknown control word `{key}` ignored", path.display())),
                    }
                }
            }
            'V' => {
                if format == Some(true) {
                    return Err(r.err(
                        line,
                        "a V (vertex) record in an F 3a file, which gives coordinates per surface",
                    ));
                }
                let i = r.index(line, "the vertex number")?;
                if i != vertices.len() + 1 {
                    return Err(r.err(
                        line,
                        format!("vertex {i} is out of sequence: expected {}", vertices.len() + 1),
                    ));
                }
                let p = DVec3::new(r.number(line, "x")?, r.number(line, "y")?, r.number(line, "z")?);
                vertices.push(p);
            }
            'S' | 'O' => {
                let obstruction = kind == 'O';
                let Some(f3a) = format else {
                    return Err(r.err(line, "a surface record before the `F 3` or `F 3a` record"));
                };
                let i = r.index(line, "the surface number")?;
                if i != records.len() + 1 {
                    return Err(r.err(
                        line,
                        format!("surface {i} is out of sequence: expected {}", records.len() + 1),
                    ));
                }
                if !obstruction && records.iter().any(|x| x.obstruction) {
                    return Err(r.err(
                        line,
                        format!("surface {i}: radiating surfaces must come before obstructions (O)"),
                    ));
                }
                let shape = if f3a {
                    Some(r.field(line, "the shape (R, Q or T)")?.text.to_ascii_uppercase())
                } else {
                    None
                };
                let indices = if f3a {
                    Vec::new()
                } else {
                    let mut v = Vec::new();
                    for k in 1..=4 {
                        v.push(r.index(line, &format!("vertex {k}"))?);
                    }
                    if v[3] == 0 {
                        v.pop();
                    }
                    v
                };
                let (mut combine, mut emit, mut name) = (0, 1.0, format!("obstruction_{i}"));
                if !obstruction {
                    let base = r.index(line, "the base surface")?;
                    if base > 0 {
                        return Err(r.err(
                            line,
                            format!(
                                "surface {i} is a subsurface of surface {base}: lambert has no polygons with holes; \
                                 split the base surface around it into separate surfaces"
                            ),
                        ));
                    }
                    combine = r.index(line, "the combine surface")?;
                    emit = r.number(line, "the emittance")?;
                    name = r.field(line, "the surface name")?.text.to_string();
                }
                let corners = match shape.as_deref() {
                    None => Corners::Indices(indices),
                    Some(s) => Corners::Points(blast_corners(&mut r, line, s)?),
                };
                records.push(Record { line, obstruction, corners, combine, emit, name });
            }
            'M' | 'N' => {
                return Err(r.err(
                    line,
                    format!(
                        "{} surfaces are not supported: lambert has no masks or holes; model the opening as \
                         separate surfaces",
                        if kind == 'M' { "mask (M)" } else { "null (N)" }
                    ),
                ));
            }
            _ => return Err(r.err(line, format!("unknown record '{}'", w.text))),
        }
        r.end_record();
    }
    if format.is_none() {
        return Err(InputError::file(path, "no `F 3` or `F 3a` record: this is not a View3D 3-D input file"));
    }
    let model = build(path, &vertices, &records, &mut warnings)?;
    Ok(Vs3 { model, title, controls, warnings })
}

/// `F 3a` shape: `x0 y0 z0 azimuth tilt`, then `w h` (R) or 3 (T) or 4 (Q) local (x, y)
/// pairs, placed as View3D's `GetVS3Da` does (azimuth clockwise from +y, tilt 0 = facing up).
fn blast_corners(r: &mut Reader, line: usize, shape: &str) -> Result<Vec<DVec3>, InputError> {
    let o = DVec3::new(r.number(line, "x0")?, r.number(line, "y0")?, r.number(line, "z0")?);
    let (azm, tilt) = (r.number(line, "the azimuth")?.to_radians(), r.number(line, "the tilt")?.to_radians());
    let local: Vec<(f64, f64)> = match shape {
        "R" => {
            let (w, h) = (r.number(line, "the width")?, r.number(line, "the height")?);
            vec![(0.0, h), (0.0, 0.0), (w, 0.0), (w, h)]
        }
        "T" | "Q" => {
            let n = if shape == "T" { 3 } else { 4 };
            let mut v = Vec::new();
            for k in 1..=n {
                v.push((r.number(line, &format!("local x{k}"))?, r.number(line, &format!("local y{k}"))?));
            }
            v
        }
        s => return Err(r.err(line, format!("shape '{s}' is not R, Q or T"))),
    };
    let (ca, sa, ct, st) = (-azm.cos(), azm.sin(), tilt.cos(), tilt.sin());
    Ok(local
        .into_iter()
        .map(|(x, y)| o + DVec3::new(x * ca - y * ct * sa, x * sa + y * ct * ca, y * st))
        .collect())
}

/// Resolves vertices, merges combined surfaces and makes the model.
fn build(
    path: &Path,
    vertices: &[DVec3],
    records: &[Record],
    warnings: &mut Vec<String>,
) -> Result<Model, InputError> {
    let err = |rec: &Record, p: String| InputError::surface(path, rec.name.clone(), p).at_line(rec.line);
    let mut pieces: Vec<Polygon> = Vec::with_capacity(records.len());
    for (k, rec) in records.iter().enumerate() {
        let pts: Vec<DVec3> = match &rec.corners {
            Corners::Points(p) => p.clone(),
            Corners::Indices(ix) => ix
                .iter()
                .map(|&v| {
                    vertices.get(v.wrapping_sub(1)).copied().ok_or_else(|| {
                        err(
                            rec,
                            format!(
                                "surface {}: vertex {v} is missing (the file defines {})",
                                k + 1,
                                vertices.len()
                            ),
                        )
                    })
                })
                .collect::<Result<_, _>>()?,
        };
        // One polygon per record: a quadrilateral is one patch with one heat balance, as in
        // View3D, so results never depend on a diagonal. Planarity and area are checked as for
        // any scene polygon.
        let polygon = Polygon::new(pts)
            .map_err(|e| err(rec, format!("surface {}: {}", k + 1, super::validate::polygon_problem(&e))))?;
        pieces.push(polygon);
    }
    let mut surfaces: Vec<MeshSurface> = Vec::new();
    let mut slot = vec![usize::MAX; records.len()];
    for (k, rec) in records.iter().enumerate() {
        if rec.combine > 0 {
            let target = rec.combine - 1;
            if target >= k || records[target].obstruction {
                return Err(err(
                    rec,
                    format!(
                        "surface {} combines into {}, which is not an earlier radiating surface",
                        k + 1,
                        rec.combine
                    ),
                ));
            }
            if records[target].combine > 0 {
                return Err(err(
                    rec,
                    format!(
                        "surface {} combines into {}, which is itself combined: chains are not allowed",
                        k + 1,
                        rec.combine
                    ),
                ));
            }
            if records[target].emit != rec.emit {
                warnings.push(format!(
                    "{}: line {}: surface {} ({}) has emittance {} but combines into {} ({}) with {}; the combined surface keeps {}",
                    path.display(), rec.line, k + 1, rec.name, rec.emit, rec.combine, records[target].name, records[target].emit, records[target].emit
                ));
            }
            surfaces[slot[target]].triangles.push(pieces[k].clone());
            continue;
        }
        let mut extras = Layer::new("the View3D file", path, Some(rec.line));
        if rec.obstruction {
            extras.role = Some(Role::Obstruction);
        } else {
            let e = rec.emit.clamp(EMIT_MIN, 1.0);
            if e != rec.emit {
                warnings.push(format!(
                    "{}: line {}: surface {} emittance {} clamped to {e}",
                    path.display(),
                    rec.line,
                    rec.name,
                    rec.emit
                ));
            }
            extras.emissivity = Some(e);
        }
        let mut name = rec.name.clone();
        if name == "ambient" || name.contains('#') || surfaces.iter().any(|s| s.name == name) {
            name = format!("{}_{}", rec.name.replace('#', "_"), k + 1);
            warnings.push(format!(
                "{}: line {}: surface {} renamed '{name}' (names must be unique and not 'ambient')",
                path.display(),
                rec.line,
                rec.name
            ));
        }
        slot[k] = surfaces.len();
        surfaces.push(MeshSurface { name, triangles: vec![pieces[k].clone()], dropped: 0, extras });
    }
    Ok(Model { file: PathBuf::from(path), surfaces, extra_files: Vec::new() })
}
