//! Integration tests of scene loading: TOML, glTF/GLB, STL/OBJ meshes, .vs3, patching and their errors.
//!
//! Every file under `tests/scene/` is a module here, and this area a module of the one
//! integration-test binary (`tests/integration.rs`). Run one with
//! `cargo test --release --test integration scene::<module>::`.
mod gltf_malformed;
mod scene_errors;
mod scene_fuzz;
mod scene_gltf;
mod scene_mesh;
mod scene_patching;
mod scene_toml;
mod scene_vs3;
