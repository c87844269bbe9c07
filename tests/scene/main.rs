//! Integration tests of scene loading: TOML, glTF/GLB, STL/OBJ meshes, .vs3, patching and their errors.
//!
//! One test binary per area (each links the whole crate once); every file under `tests/scene/` is
//! a module here. Run one with `cargo test --release --test scene <module>::`.
#[path = "../common/mod.rs"]
mod common;
mod gltf_malformed;
mod scene_errors;
mod scene_fuzz;
mod scene_gltf;
mod scene_mesh;
mod scene_patching;
mod scene_toml;
mod scene_vs3;
