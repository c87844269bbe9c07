//! Time and memory of the result writers on a large scene (no view factors computed): a room
//! whose six walls are split into `n`×`n` patches each (6n² patches, default n = 180 → 194,400),
//! with smooth synthetic values. Writes `--vtk`-style .vtu and a rendered PNG to a temp dir.
//! `cargo run --release --features studies --example vtk_render_scaling [n] [vtk|render|both|none]`, under
//! `/usr/bin/time -v` for the peak RSS.
use lambert::report::render::{self, camera::Camera};
use lambert::report::vtk::{self, VtkFields};
use std::time::Instant;

fn main() {
    let n: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(180);
    let mode = std::env::args().nth(2).unwrap_or_else(|| "both".into());
    let faces = [
        ("floor", "[0,0,0]", "[1,0,0]", "[0,1,0]"),
        ("ceiling", "[0,0,1]", "[0,1,0]", "[1,0,0]"),
        ("wall_y0", "[0,0,0]", "[0,0,1]", "[1,0,0]"),
        ("wall_y1", "[0,1,0]", "[1,0,0]", "[0,0,1]"),
        ("wall_x0", "[0,0,0]", "[0,1,0]", "[0,0,1]"),
        ("wall_x1", "[1,0,0]", "[0,0,1]", "[0,1,0]"),
    ];
    let mut toml = String::from("title = \"scaling room\"\n");
    for (name, o, u, v) in faces {
        toml += &format!(
            "[[surface]]\nname = \"{name}\"\nrectangle = {{ origin = {o}, u = {u}, v = {v} }}\nsubdivide = [{n}, {n}]\n"
        );
    }
    let t = Instant::now();
    let scene =
        lambert::scene::toml_scene::from_str(std::path::Path::new("scaling.toml"), &toml).expect("scene");
    let load = t.elapsed().as_secs_f64();
    let values: Vec<f64> = scene
        .patches
        .iter()
        .map(|p| {
            let c = p.polygon.centroid();
            300.0 + 700.0 * (1.0 - c.z) * (1.0 + 0.2 * (6.0 * c.x).sin() * (5.0 * c.y).cos())
        })
        .collect();
    let mut fields = VtkFields::default();
    for name in
        ["emissivity", "temperature", "heat_flux", "heat_rate", "radiosity", "irradiation", "patch_area"]
    {
        fields.real.push((name.into(), values.clone()));
    }
    fields.int.push(("surface_index".into(), scene.patches.iter().map(|p| p.surface as i32).collect()));
    fields.int.push(("patch_index".into(), (0..scene.patches.len() as i32).collect()));
    let dir = tempfile::tempdir().expect("temp dir");
    let vtu = dir.path().join("room.vtu");
    let t = Instant::now();
    if mode == "vtk" || mode == "both" {
        vtk::write(&vtu, &scene, &fields).expect("vtu");
    }
    let write = t.elapsed().as_secs_f64();
    let bytes = std::fs::metadata(&vtu).map(|m| m.len()).unwrap_or(0);
    let opts = render::Options {
        size: (1000, 720),
        camera: Camera::frame(&scene),
        two_sided: false,
        range: None,
        field: "temperature".into(),
        unit: "K".into(),
        caption: "scaling room".into(),
        flat: false,
        fit: true,
    };
    let t = Instant::now();
    if mode == "render" || mode == "both" {
        let img = render::render(&scene, &values, &opts).expect("render");
        render::write_png(&img, &dir.path().join("room.png")).expect("png");
    }
    let pic = t.elapsed().as_secs_f64();
    println!(
        "patches {}  load {load:.2} s  vtu write {write:.2} s ({:.0} patches/s, {:.1} MB)  render+png {pic:.2} s",
        scene.patches.len(),
        scene.patches.len() as f64 / write,
        bytes as f64 / 1e6
    );
}
