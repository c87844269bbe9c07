//! Low-level clap arguments, mirroring docs/SPEC.md; no logic here. Every choice option is the
//! library's own enum (clap's `ValueEnum`, [`lambert::choice`]), so `--help` lists its values.
use clap::{Args, Parser, Subcommand};
use lambert::exchange::Enforce;
use lambert::plan::Store;
use lambert::report::decks::DeckFormat;
use lambert::report::render::values::Field;
use lambert::scene::mesh_model::Unit;
use lambert::solve::Solver;
use lambert::viewfactor::Method;
use std::path::PathBuf;

/// Diffuse view factors and gray-body radiative exchange.
#[derive(Debug, Parser)]
#[command(name = "lambert", version, about, propagate_version = true)]
pub struct Cli {
    /// Print only errors and warnings: no progress report (a bar on a terminal, else a line
    /// per phase and every 10 s of a long run) and no summary lines; any subcommand.
    #[arg(short, long, global = true)]
    pub quiet: bool,
    /// The subcommand.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands of docs/SPEC.md.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Compute the view-factor matrix of a scene and write it as CSV.
    Viewfactors(ViewfactorsArgs),
    /// Join the part files of `viewfactors --shard` runs into the CSV of a single run.
    Merge(MergeArgs),
    /// Compute view factors, then solve the radiation exchange.
    Solve(SolveArgs),
    /// Run the textbook validation suite in cases/.
    Validate(ValidateArgs),
    /// Draw a `solve` result on the scene as a false-colour PNG picture.
    Render(RenderArgs),
}

/// Options of a bare mesh scene (.stl, .obj, .gltf, .glb).
#[derive(Debug, Args)]
pub struct MeshArgs {
    /// Length unit of a bare STL or OBJ scene's coordinates [default: m].
    #[arg(long, value_enum)]
    pub unit: Option<Unit>,
    /// Repair a bare mesh scene: orient consistently and outward, drop duplicate faces and
    /// slivers (each change is reported).
    #[arg(long)]
    pub repair: bool,
}

/// Options shared by `viewfactors` and `solve`. Numeric options take negative numbers as values
/// (`--tolerance -1`), so that lambert's own range check answers instead of clap's `-- -1` tip.
#[derive(Debug, Args)]
pub struct CommonArgs {
    /// Scene file: .toml, .gltf, .glb, .stl, .obj or a View3D .vs3.
    pub scene: PathBuf,
    /// Bare mesh scene options.
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// View-factor method.
    #[arg(short, long, value_enum, default_value_t = Method::Auto)]
    pub method: Method,
    /// Rays or points per patch for the Monte Carlo methods (at most 100000000).
    #[arg(long, allow_negative_numbers = true)]
    pub samples: Option<usize>,
    /// Pixels along a hemicube face or the single plane.
    #[arg(long, allow_negative_numbers = true)]
    pub resolution: Option<usize>,
    /// Absolute accuracy goal on each F for `auto`, at least 1e-13 [default: 1e-4].
    #[arg(long, allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
    /// Random seed; the same seed gives the same result on any thread count.
    #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
    pub seed: u64,
    /// Worker threads, 1 to 1024 (default: all cores).
    #[arg(long, allow_negative_numbers = true)]
    pub threads: Option<usize>,
    /// Enforcement of the view factors [default: none for `viewfactors`; for `solve`, closure in
    /// a closed scene and reciprocity in an open one, where the ambient takes the rest].
    #[arg(long, value_enum)]
    pub enforce: Option<Enforce>,
    /// Report per patch (`surface#k`) instead of per surface.
    #[arg(long)]
    pub patches: bool,
    /// CSV output file; stdout when absent or `-`.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Also write the results on the patch polygons for ParaView: VTK XML, .vtu or .vtp.
    #[arg(long, value_name = "FILE")]
    pub vtk: Option<PathBuf>,
    /// Let glTF buffer files be absolute paths or lie outside the glTF file's folder (`..`).
    #[arg(long)]
    pub allow_outside_paths: bool,
}

/// `lambert viewfactors`.
#[derive(Debug, Args)]
pub struct ViewfactorsArgs {
    /// Shared options.
    #[command(flatten)]
    pub common: CommonArgs,
    /// Factors from points instead: a CSV with columns x,y,z,nx,ny,nz (m, the scene's frame)
    /// and optionally name; one row per point and surface (or patch) it sees.
    #[arg(long, value_name = "CSV")]
    pub points: Option<PathBuf>,
    /// Compute only shard I of K (I = 0 to K-1) of the view-factor rows, the rows MPI rank I of
    /// K computes, and write them to -o as a part file for `lambert merge`.
    #[arg(long, value_name = "I/K", allow_hyphen_values = true)]
    pub shard: Option<String>,
}

/// `lambert merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The part files of every shard of one `viewfactors --shard` run, in any order.
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// CSV output file; stdout when absent or `-`.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// The scene file, when it has moved since the shards ran [default: the path the parts
    /// record]; it must hold the same geometry.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Worker threads for the enforcement and output, 1 to 1024 (default: all cores).
    #[arg(long, allow_negative_numbers = true)]
    pub threads: Option<usize>,
}

/// `lambert solve`.
#[derive(Debug, Args)]
pub struct SolveArgs {
    /// Shared options.
    #[command(flatten)]
    pub common: CommonArgs,
    /// Reuse a `viewfactors` CSV instead of recomputing.
    #[arg(long)]
    pub viewfactors: Option<PathBuf>,
    /// Write radiative conductances RADK_ij = A_i ε_i B_ij: CSV `from,to,radk`, a SINDA/FLUINT
    /// conductor block or an ESATAN GR block, chosen by the extension or --format.
    #[arg(long)]
    pub conductances: Option<PathBuf>,
    /// Format of --conductances [default: from the file extension].
    #[arg(long, value_enum)]
    pub format: Option<DeckFormat>,
    /// Linear solver.
    #[arg(long, value_enum, default_value_t = Solver::Direct)]
    pub solver: Solver,
    /// Exchange store.
    #[arg(long, value_enum, default_value_t = Store::Auto)]
    pub exchange: Store,
}

/// `lambert validate`.
#[derive(Debug, Args)]
pub struct ValidateArgs {
    /// Folder of cases.
    #[arg(long, default_value = "cases")]
    pub cases: PathBuf,
    /// Folder for the report and charts [default: validation; with --quick, a scratch folder
    /// in the system's temporary directory, so the committed full report stays].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// A fast subset for CI.
    #[arg(long)]
    pub quick: bool,
}

/// `lambert render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Scene file: .toml, .gltf, .glb, .stl, .obj or a View3D .vs3 (the one the result was solved
    /// on).
    pub scene: PathBuf,
    /// Bare mesh scene options (as given to `solve`).
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// A `solve` CSV, per surface or per patch (`--patches`).
    pub result: PathBuf,
    /// Column to show.
    #[arg(long, value_enum, default_value_t = Field::Temperature)]
    pub field: Field,
    /// PNG picture to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Camera, any of "eye=x,y,z target=x,y,z up=x,y,z fov=degrees" (default: diagonal view,
    /// z up). The picture is zoomed to fit the scene unless fov= is given.
    #[arg(long)]
    pub camera: Option<String>,
    /// Picture size WIDTHxHEIGHT in pixels, colour bar included.
    #[arg(long, default_value = "1000x720")]
    pub size: String,
    /// Colour range MIN,MAX (default: the range of the surfaces that show).
    #[arg(long, allow_hyphen_values = true)]
    pub range: Option<String>,
    /// Show back faces in grey instead of hiding them.
    #[arg(long)]
    pub two_sided: bool,
    /// Plain false colour, without the headlight shading (exact colour reading).
    #[arg(long)]
    pub flat: bool,
    /// Let glTF buffer files be absolute paths or lie outside the glTF file's folder (`..`).
    #[arg(long)]
    pub allow_outside_paths: bool,
}

/// The command line's spelling of a library option keyword ([`lambert::error::opt`]): its flag,
/// `allow_outside_paths` → `--allow-outside-paths`.
pub fn flag(keyword: &str) -> String {
    format!("--{}", keyword.replace('_', "-"))
}
