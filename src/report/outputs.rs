//! The files of one run, safe by construction: planned and checked before any work, written
//! as temporaries, and put in place together once every one of them has been written.
//!
//! - [`OutputSet::plan`]: every output's folder exists and is writable, no output is a folder,
//!   and no two outputs are one file (usage errors, exit 2, naming both flags);
//! - [`OutputSet::check_inputs`]: no output is an input of the run (scene, model files,
//!   buffers, a saved result), compared by inode and by canonical path, so hard links,
//!   symbolic links and `./` spellings are caught;
//! - [`OutputSet::write`]: one output through its writer, into `<name>.partial` beside its
//!   target (a rename is atomic only within one file system). A target that exists and is
//!   not a regular file (`/dev/null`, a FIFO) is written in place, as is stdout: write those
//!   last, so that a failing file write comes before anything reaches them;
//! - [`OutputSet::commit`]: the renames, one after the other, once all are written.
//!
//! A failed run (the set dropped uncommitted) removes its temporaries and leaves every earlier
//! output as it was. A killed run leaves at most `<name>.partial` files, which the next run
//! writing that output replaces. The renames themselves follow one another within
//! microseconds; a kill between two of them is the one moment at which a new file can sit
//! beside an old one.
//!
//! [`ABORT_ENV`] is a test hook: the process aborts right after writing the named temporary,
//! as a kill -9 would, to test what a killed run leaves behind.
use crate::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Test hook: `LAMBERT_TEST_ABORT_AT=<key>` aborts the process right after the temporary of
/// the output with that key (`output`, `vtk`, `conductances`) has been written.
pub const ABORT_ENV: &str = "LAMBERT_TEST_ABORT_AT";
/// Suffix of the temporaries beside their targets.
pub const PARTIAL_SUFFIX: &str = ".partial";

/// One output a run asks for.
#[derive(Debug, Clone, PartialEq)]
pub struct Output {
    /// Short key (the long flag without dashes; [`ABORT_ENV`] names it).
    pub key: String,
    /// The option as the caller names it, for messages: a flag (`-o`, `--vtk`) from the
    /// command line, an option mark ([`crate::error::opt`]) from the library.
    pub flag: String,
    /// What is written there, for messages ("view-factor CSV").
    pub what: String,
    /// The file; `None` is stdout.
    pub path: Option<PathBuf>,
}

impl Output {
    /// An output at `path`; `-` means stdout.
    pub fn new(key: &str, flag: &str, what: &str, path: &Path) -> Self {
        let path = (path.as_os_str() != "-").then(|| path.to_path_buf());
        Self { key: key.into(), flag: flag.into(), what: what.into(), path }
    }
    /// An output to stdout.
    pub fn stdout(key: &str, flag: &str, what: &str) -> Self {
        Self { key: key.into(), flag: flag.into(), what: what.into(), path: None }
    }
    /// The same output described as `what`.
    pub fn described(mut self, what: &str) -> Self {
        self.what = what.into();
        self
    }
}

/// One input of a run, for the check that no output overwrites it.
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    /// What it is, for messages ("the scene file").
    pub what: String,
    /// The file.
    pub path: PathBuf,
}

impl Input {
    /// An input `what` at `path`.
    pub fn new(what: impl Into<String>, path: impl Into<PathBuf>) -> Self {
        Self { what: what.into(), path: path.into() }
    }
}

/// Where an output's bytes go.
#[derive(Debug)]
enum Sink {
    /// Standard output.
    Stdout,
    /// An existing device or FIFO, written directly (a rename would replace it with a file).
    InPlace(PathBuf),
    /// A temporary renamed over `target` at commit; `written` once it is complete.
    Staged { target: PathBuf, tmp: PathBuf, created: bool, written: bool },
}

#[derive(Debug)]
struct Slot {
    out: Output,
    sink: Sink,
}

/// The checked outputs of one run (see the module docs).
#[derive(Debug)]
pub struct OutputSet {
    slots: Vec<Slot>,
}

fn usage(msg: String) -> Error {
    Error::Usage(msg)
}

/// The folder a file lands in (`.` for a bare name).
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// `path` with [`PARTIAL_SUFFIX`] appended to its file name.
pub fn partial_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(PARTIAL_SUFFIX);
    path.with_file_name(name)
}

/// Whether the process may create files in `dir` (write and search permission, a writable
/// file system).
#[cfg(unix)]
fn writable_dir(dir: &Path) -> std::io::Result<()> {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(dir.as_os_str().as_bytes()).map_err(std::io::Error::other)?;
    // SAFETY: `c` is a valid NUL-terminated path that outlives the call.
    let r = unsafe { libc::access(c.as_ptr(), libc::W_OK | libc::X_OK) };
    if r == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

#[cfg(not(unix))]
fn writable_dir(dir: &Path) -> std::io::Result<()> {
    let m = std::fs::metadata(dir)?;
    if m.permissions().readonly() {
        Err(std::io::Error::new(std::io::ErrorKind::PermissionDenied, "read-only folder"))
    } else {
        Ok(())
    }
}

/// The canonical form of `path`, also for a file that does not exist yet (its folder
/// canonicalised, the name appended).
fn canonical(path: &Path) -> PathBuf {
    if let Ok(c) = std::fs::canonicalize(path) {
        return c;
    }
    let name = path.file_name().map(PathBuf::from).unwrap_or_default();
    match std::fs::canonicalize(folder_of(path)) {
        Ok(dir) => dir.join(name),
        Err(_) => std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf()),
    }
}

/// True when `a` and `b` are one file: the same inode when both exist, else the same
/// canonical path.
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
    }
    canonical(a) == canonical(b)
}

/// True for a character device (`/dev/null`): writing it twice loses nothing.
fn is_char_device(path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        std::fs::metadata(path).is_ok_and(|m| m.file_type().is_char_device())
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        false
    }
}

/// Checks one output file and decides how it is written.
fn sink_for(out: &Output, path: &Path) -> Result<Sink> {
    let shown = path.display();
    let flag = &out.flag;
    let meta = std::fs::metadata(path);
    if meta.as_ref().is_ok_and(|m| m.is_dir()) || path.as_os_str().to_string_lossy().ends_with('/') {
        return Err(usage(format!("{flag} {shown}: this is a folder; name the {} file to write", out.what)));
    }
    if meta.as_ref().is_ok_and(|m| !m.is_file()) {
        return Ok(Sink::InPlace(path.to_path_buf()));
    }
    // An existing symbolic link is written through: its target is replaced, the link stays.
    let target = if meta.is_ok() && std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink())
    {
        std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
    } else {
        path.to_path_buf()
    };
    let dir = folder_of(&target);
    match std::fs::metadata(&dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(usage(format!("{flag} {shown}: '{}' is not a folder", dir.display())));
        }
        Err(_) => {
            return Err(usage(format!(
                "{flag} {shown}: the folder '{}' does not exist; create it first (nothing was computed)",
                dir.display()
            )));
        }
    }
    writable_dir(&dir).map_err(|e| {
        usage(format!("{flag} {shown}: cannot write into the folder '{}': {e}", dir.display()))
    })?;
    let tmp = partial_path(&target);
    Ok(Sink::Staged { target, tmp, created: false, written: false })
}

impl OutputSet {
    /// Checks `outputs` before any work: folders exist and are writable, no output is a
    /// folder, no two outputs are one file.
    pub fn plan(outputs: Vec<Output>) -> Result<Self> {
        let mut slots = Vec::with_capacity(outputs.len());
        for out in outputs {
            let sink = match &out.path {
                None => Sink::Stdout,
                Some(p) => sink_for(&out, p)?,
            };
            slots.push(Slot { out, sink });
        }
        for (i, a) in slots.iter().enumerate() {
            for b in &slots[i + 1..] {
                let (Some(pa), Some(pb)) = (&a.out.path, &b.out.path) else { continue };
                if same_file(pa, pb) && !is_char_device(pa) {
                    return Err(usage(format!(
                        "{} {} and {} {} are the same file: the {} would overwrite the {}; give each \
                         its own file",
                        a.out.flag,
                        pa.display(),
                        b.out.flag,
                        pb.display(),
                        b.out.what,
                        a.out.what
                    )));
                }
            }
        }
        Ok(Self { slots })
    }

    /// Refuses an output that is one of `inputs` (by inode or canonical path), naming both.
    pub fn check_inputs(&self, inputs: &[Input]) -> Result<()> {
        for slot in &self.slots {
            let Some(p) = &slot.out.path else { continue };
            for input in inputs {
                if same_file(p, &input.path) {
                    return Err(usage(format!(
                        "{} {} is {} ({}): writing the {} there would destroy it; choose another file",
                        slot.out.flag,
                        p.display(),
                        input.what,
                        input.path.display(),
                        slot.out.what
                    )));
                }
            }
        }
        Ok(())
    }

    /// Writes output `key` through `f` (which gets the writer and the path to name in its
    /// errors): into its temporary, or in place for stdout and devices. Errors name the path
    /// and what was being written.
    pub fn write(&mut self, key: &str, f: impl FnOnce(&mut dyn Write, &Path) -> Result<()>) -> Result<()> {
        // Under mpirun, rank 0 alone writes (the other ranks' copies of the run are identical).
        if !crate::distributed::writes_outputs() {
            return Ok(());
        }
        let Some(slot) = self.slots.iter_mut().find(|s| s.out.key == key) else {
            return Err(Error::Compute(format!("output '{key}' was not planned")));
        };
        let shown = slot.out.path.clone().unwrap_or_else(|| PathBuf::from("<stdout>"));
        let context = |e: Error| annotate(e, &slot.out);
        match &mut slot.sink {
            Sink::Stdout => {
                let stdout = std::io::stdout();
                let mut lock = stdout.lock();
                f(&mut lock, &shown)
                    .and_then(|_| lock.flush().map_err(|e| io_err(&shown, e)))
                    .map_err(context)
            }
            Sink::InPlace(path) => {
                let file = std::fs::File::create(&*path).map_err(|e| context(io_err(&shown, e)))?;
                let mut w = std::io::BufWriter::new(file);
                f(&mut w, &shown).and_then(|_| w.flush().map_err(|e| io_err(&shown, e))).map_err(context)
            }
            Sink::Staged { tmp, created, written, .. } => {
                // A temporary left by a killed run (or a stray link) is replaced, never followed.
                match std::fs::remove_file(&*tmp) {
                    Ok(()) => {}
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                    Err(e) => return Err(context(io_err(tmp, e))),
                }
                let file = std::fs::OpenOptions::new()
                    .write(true)
                    .create_new(true)
                    .open(&*tmp)
                    .map_err(|e| context(io_err(tmp, e)))?;
                *created = true;
                let mut w = std::io::BufWriter::new(file);
                f(&mut w, &shown).and_then(|_| w.flush().map_err(|e| io_err(&shown, e))).map_err(context)?;
                drop(w);
                *written = true;
                if std::env::var(ABORT_ENV).is_ok_and(|k| k == key) {
                    eprintln!("lambert: {ABORT_ENV}={key}: aborting after writing {}", tmp.display());
                    std::process::abort();
                }
                Ok(())
            }
        }
    }

    /// Puts every written temporary in place (renames); after this the set removes nothing.
    pub fn commit(mut self) -> Result<()> {
        for slot in &mut self.slots {
            if let Sink::Staged { target, tmp, created, written } = &mut slot.sink {
                if *written {
                    std::fs::rename(&*tmp, &*target).map_err(|e| annotate(io_err(target, e), &slot.out))?;
                    *created = false;
                }
            }
        }
        Ok(())
    }
}

impl Drop for OutputSet {
    /// An uncommitted set (a failed run) removes its temporaries.
    fn drop(&mut self) {
        for slot in &self.slots {
            if let Sink::Staged { tmp, created: true, .. } = &slot.sink {
                let _ = std::fs::remove_file(tmp);
            }
        }
    }
}

fn io_err(path: &Path, source: std::io::Error) -> Error {
    Error::Io { path: path.to_path_buf(), source }
}

/// Adds what was being written (and the flag) to an I/O error.
fn annotate(e: Error, out: &Output) -> Error {
    match e {
        Error::Io { path, source } => Error::Io {
            path,
            source: std::io::Error::new(
                source.kind(),
                format!("cannot write the {} ({}): {source}", out.what, out.flag),
            ),
        },
        other => other,
    }
}

/// Writes one file at `path` through `f`, staged and renamed on success (the one-output
/// case of [`OutputSet`], for library callers).
pub fn write_file(
    key: &str,
    flag: &str,
    what: &str,
    path: &Path,
    f: impl FnOnce(&mut dyn Write, &Path) -> Result<()>,
) -> Result<()> {
    let mut set = OutputSet::plan(vec![Output::new(key, flag, what, path)])?;
    set.write(key, f)?;
    set.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn put(w: &mut dyn Write, p: &Path, text: &str) -> Result<()> {
        w.write_all(text.as_bytes()).map_err(|e| io_err(p, e))
    }

    fn out(key: &str, path: &Path) -> Output {
        Output::new(key, &format!("--{key}"), &format!("{key} file"), path)
    }

    #[test]
    fn a_missing_folder_is_refused_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("nodir/x.csv");
        let e = OutputSet::plan(vec![out("output", &p)]).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let msg = e.to_string();
        assert!(msg.contains("--output") && msg.contains("nodir") && msg.contains("does not exist"), "{msg}");
    }

    #[test]
    fn a_folder_as_output_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let e = OutputSet::plan(vec![out("vtk", dir.path())]).unwrap_err();
        assert!(e.to_string().contains("this is a folder"), "{e}");
    }

    #[test]
    fn two_outputs_to_one_file_are_refused_also_through_a_link() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("x.csv");
        let e = OutputSet::plan(vec![out("output", &a), out("conductances", &dir.path().join("./x.csv"))])
            .unwrap_err();
        assert!(e.to_string().contains("--output") && e.to_string().contains("--conductances"), "{e}");
        std::fs::write(&a, "x").unwrap();
        let link = dir.path().join("hard.csv");
        std::fs::hard_link(&a, &link).unwrap();
        let e = OutputSet::plan(vec![out("output", &a), out("vtk", &link)]).unwrap_err();
        assert!(e.to_string().contains("same file"), "{e}");
        // Two writes into /dev/null lose nothing.
        let null = Path::new("/dev/null");
        if null.exists() {
            OutputSet::plan(vec![out("output", null), out("conductances", null)]).unwrap();
        }
    }

    #[test]
    fn an_input_is_never_an_output() {
        let dir = tempfile::tempdir().unwrap();
        let scene = dir.path().join("s.toml");
        std::fs::write(&scene, "title = \"t\"\n").unwrap();
        let set = OutputSet::plan(vec![out("output", &scene)]).unwrap();
        let e = set.check_inputs(&[Input::new("the scene file", &scene)]).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("--output") && msg.contains("the scene file") && msg.contains("destroy"),
            "{msg}"
        );
        assert_eq!(e.exit_code(), 2);
        #[cfg(unix)]
        {
            let link = dir.path().join("link.toml");
            std::os::unix::fs::symlink(&scene, &link).unwrap();
            let set = OutputSet::plan(vec![out("output", &link)]).unwrap();
            assert!(set.check_inputs(&[Input::new("the scene file", &scene)]).is_err());
        }
        drop(set);
        assert_eq!(std::fs::read_to_string(&scene).unwrap(), "title = \"t\"\n");
    }

    #[test]
    fn outputs_appear_only_at_commit_and_a_failed_run_leaves_the_old_files() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.csv"), dir.path().join("b.vtu"));
        std::fs::write(&a, "old a").unwrap();
        std::fs::write(&b, "old b").unwrap();
        // The second writer fails: both files keep their old contents, no temporary is left.
        {
            let mut set = OutputSet::plan(vec![out("output", &a), out("vtk", &b)]).unwrap();
            set.write("output", |w, p| put(w, p, "new a")).unwrap();
            let e = set.write("vtk", |_, p| Err(io_err(p, std::io::Error::other("disk full")))).unwrap_err();
            assert!(e.to_string().contains("cannot write the vtk file (--vtk)"), "{e}");
        }
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "old b");
        assert!(!partial_path(&a).exists() && !partial_path(&b).exists());
        // Both written: nothing changes before the commit, everything after it.
        let mut set = OutputSet::plan(vec![out("output", &a), out("vtk", &b)]).unwrap();
        set.write("output", |w, p| put(w, p, "new a")).unwrap();
        set.write("vtk", |w, p| put(w, p, "new b")).unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        set.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "new b");
        assert!(!partial_path(&a).exists() && !partial_path(&b).exists());
    }

    #[test]
    fn a_leftover_temporary_is_replaced_and_a_link_is_written_through() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.csv");
        std::fs::write(partial_path(&a), "stale").unwrap();
        write_file("output", "-o", "CSV", &a, |w, p| put(w, p, "fresh")).unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "fresh");
        assert!(!partial_path(&a).exists());
        #[cfg(unix)]
        {
            let link = dir.path().join("link.csv");
            std::os::unix::fs::symlink(&a, &link).unwrap();
            write_file("output", "-o", "CSV", &link, |w, p| put(w, p, "again")).unwrap();
            assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
            assert_eq!(std::fs::read_to_string(&a).unwrap(), "again");
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_read_only_folder_is_refused_up_front() {
        // Root may write anywhere but a read-only file system; /proc is one for new files.
        let dir = tempfile::tempdir().unwrap();
        let ro = dir.path().join("ro");
        std::fs::create_dir(&ro).unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
        let p = ro.join("x.csv");
        let can_write = std::fs::write(ro.join("probe"), "x").is_ok();
        let planned = OutputSet::plan(vec![out("output", &p)]);
        assert_eq!(planned.is_ok(), can_write, "{planned:?}");
        if let Err(e) = planned {
            assert!(e.to_string().contains("cannot write into the folder"), "{e}");
        }
    }
}
