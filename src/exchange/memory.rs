//! Memory a run may still allocate: the smallest of the machine's free memory and the
//! process's own limits, so that a store that cannot fit is refused before it is allocated
//! instead of aborting the process half-way.
//!
//! - free memory: `MemAvailable` of /proc/meminfo;
//! - `RLIMIT_AS` (`ulimit -v`) less the address space in use (`VmSize`);
//! - `RLIMIT_DATA` (`ulimit -d`; Linux counts private mappings, so every large allocation)
//!   less the data in use (`VmData`);
//! - the memory cgroup of the process and its ancestors: cgroup v2 `memory.max` less
//!   `memory.current`, cgroup v1 `memory.limit_in_bytes` less `memory.usage_in_bytes`, both less
//!   the reclaimable inactive file cache of `memory.stat`.
//!
//! Cgroup files are looked up under the usual mount points (/sys/fs/cgroup for v2, its
//! `unified` folder on hybrid systems, /sys/fs/cgroup/memory for v1) at the path that
//! /proc/self/cgroup gives, then at each ancestor up to the mount's root (inside a container
//! the mount's root is the container's own group).
use std::path::{Path, PathBuf};

/// Environment variable overriding the available memory in bytes (tests, batch schedulers).
pub const MEM_AVAILABLE_ENV: &str = "LAMBERT_MEM_AVAILABLE";
/// A cgroup v1 limit at or above this is "no limit" (the kernel writes 2^63 rounded to pages).
const CGROUP_V1_UNLIMITED: u64 = 1 << 62;

/// What bounds the memory available to the run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bound {
    /// The environment override [`MEM_AVAILABLE_ENV`].
    Override,
    /// The machine's free memory.
    Free,
    /// The address-space limit.
    AddressSpace,
    /// The data-segment limit.
    Data,
    /// The memory cgroup's limit.
    Cgroup,
}

impl std::fmt::Display for Bound {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Bound::Override => "set by LAMBERT_MEM_AVAILABLE",
            Bound::Free => "the machine's free memory, MemAvailable",
            Bound::AddressSpace => "what the process's address-space limit leaves, RLIMIT_AS or ulimit -v",
            Bound::Data => "what the process's data limit leaves, RLIMIT_DATA or ulimit -d",
            Bound::Cgroup => "what the memory cgroup's limit leaves, memory.max or memory.limit_in_bytes",
        })
    }
}

/// Bytes the run may still allocate and what bounds them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Available {
    /// Bytes.
    pub bytes: u64,
    /// The tightest bound.
    pub bound: Bound,
}

/// The memory available to this run: the override, else the smallest of the bounds in the
/// module docs; `None` when none is known (the checks are then skipped).
pub fn available() -> Option<Available> {
    if let Ok(v) = std::env::var(MEM_AVAILABLE_ENV) {
        return v.trim().parse().ok().map(|bytes| Available { bytes, bound: Bound::Override });
    }
    let read = |p: &Path| std::fs::read_to_string(p).ok();
    let status = read(Path::new("/proc/self/status")).unwrap_or_default();
    let mut found: Vec<Available> = Vec::new();
    let meminfo = read(Path::new("/proc/meminfo")).unwrap_or_default();
    if let Some(kb) = field_kb(&meminfo, "MemAvailable:") {
        found.push(Available { bytes: kb * 1024, bound: Bound::Free });
    }
    for (limit, used, bound) in [
        (rlimit(Resource::AddressSpace), field_kb(&status, "VmSize:"), Bound::AddressSpace),
        (rlimit(Resource::Data), field_kb(&status, "VmData:"), Bound::Data),
    ] {
        if let Some(limit) = limit {
            let bytes = limit.saturating_sub(used.unwrap_or(0) * 1024);
            found.push(Available { bytes, bound });
        }
    }
    let groups = read(Path::new("/proc/self/cgroup")).unwrap_or_default();
    if let Some(bytes) = cgroup_headroom(&groups, Path::new("/sys/fs/cgroup"), &read) {
        found.push(Available { bytes, bound: Bound::Cgroup });
    }
    found.into_iter().min_by_key(|a| a.bytes)
}

/// The number of kB after `key` in a /proc file (`MemAvailable:  123 kB`).
pub fn field_kb(text: &str, key: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(key))?;
    line[key.len()..].split_whitespace().next()?.parse().ok()
}

/// The resource limits read.
#[derive(Debug, Clone, Copy)]
enum Resource {
    AddressSpace,
    Data,
}

/// The soft limit of `r` in bytes; `None` when unlimited or unknown.
#[cfg(unix)]
fn rlimit(r: Resource) -> Option<u64> {
    let resource = match r {
        Resource::AddressSpace => libc::RLIMIT_AS,
        Resource::Data => libc::RLIMIT_DATA,
    };
    let mut lim = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
    // SAFETY: `lim` is a valid, writable rlimit for the call to fill.
    let r = unsafe { libc::getrlimit(resource, &mut lim) };
    // `rlim_t` is not u64 on every target.
    #[allow(clippy::unnecessary_cast)]
    let cur = lim.rlim_cur as u64;
    (r == 0 && lim.rlim_cur != libc::RLIM_INFINITY).then_some(cur)
}

#[cfg(not(unix))]
fn rlimit(_: Resource) -> Option<u64> {
    None
}

/// The group paths of /proc/self/cgroup: the v2 path (`0::/path`) and the v1 memory
/// controller's path (`N:memory:/path`, also in a list such as `memory,cpu`).
pub fn parse_proc_cgroup(text: &str) -> (Option<String>, Option<String>) {
    let (mut v2, mut v1) = (None, None);
    for line in text.lines() {
        let mut parts = line.splitn(3, ':');
        let (Some(id), Some(controllers), Some(path)) = (parts.next(), parts.next(), parts.next()) else {
            continue;
        };
        if id == "0" && controllers.is_empty() {
            v2 = Some(path.to_string());
        } else if controllers.split(',').any(|c| c == "memory") {
            v1 = Some(path.to_string());
        }
    }
    (v2, v1)
}

/// A cgroup v2 `memory.max` value: bytes, or `None` for `max`.
pub fn parse_v2_max(text: &str) -> Option<u64> {
    let t = text.trim();
    if t == "max" {
        None
    } else {
        t.parse().ok()
    }
}

/// A cgroup v1 `memory.limit_in_bytes` value: bytes, or `None` for the "unlimited" value.
pub fn parse_v1_limit(text: &str) -> Option<u64> {
    text.trim().parse().ok().filter(|&b| b < CGROUP_V1_UNLIMITED)
}

/// `dir` joined with the group path, then each ancestor up to `mount` itself.
fn group_dirs(mount: &Path, group: &str) -> Vec<PathBuf> {
    let mut dirs = Vec::new();
    let mut rel = PathBuf::from(group.trim_start_matches('/'));
    loop {
        dirs.push(mount.join(&rel));
        if !rel.pop() {
            break;
        }
    }
    dirs.dedup();
    dirs
}

/// Bytes left under the tightest memory cgroup limit found under `root` for the groups of
/// `proc_cgroup` (see the module docs); `read` reads a file (tests pass a fake tree).
pub fn cgroup_headroom(
    proc_cgroup: &str,
    root: &Path,
    read: &dyn Fn(&Path) -> Option<String>,
) -> Option<u64> {
    let (v2, v1) = parse_proc_cgroup(proc_cgroup);
    let mut best: Option<u64> = None;
    let mut consider = |dir: &Path, limit: Option<u64>, usage: &str, inactive: &str| {
        let Some(limit) = limit else { return };
        let used = read(&dir.join(usage)).and_then(|t| t.trim().parse::<u64>().ok()).unwrap_or(0);
        let cache = read(&dir.join("memory.stat")).and_then(|t| stat_value(&t, inactive)).unwrap_or(0);
        let left = limit.saturating_sub(used.saturating_sub(cache));
        best = Some(best.map_or(left, |b| b.min(left)));
    };
    if let Some(g) = &v2 {
        for mount in [root.to_path_buf(), root.join("unified")] {
            for dir in group_dirs(&mount, g) {
                let limit = read(&dir.join("memory.max")).and_then(|t| parse_v2_max(&t));
                consider(&dir, limit, "memory.current", "inactive_file");
            }
        }
    }
    if let Some(g) = &v1 {
        for dir in group_dirs(&root.join("memory"), g) {
            let limit = read(&dir.join("memory.limit_in_bytes")).and_then(|t| parse_v1_limit(&t));
            consider(&dir, limit, "memory.usage_in_bytes", "total_inactive_file");
        }
    }
    best
}

/// The value of `key` in a `memory.stat` file (`key value` lines).
fn stat_value(text: &str, key: &str) -> Option<u64> {
    text.lines().find_map(|l| {
        let (k, v) = l.split_once(' ')?;
        (k == key).then(|| v.trim().parse().ok()).flatten()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn tree(files: &[(&str, &str)]) -> impl Fn(&Path) -> Option<String> {
        let map: HashMap<PathBuf, String> =
            files.iter().map(|(p, t)| (PathBuf::from(p), t.to_string())).collect();
        move |p: &Path| map.get(p).cloned()
    }

    #[test]
    fn proc_files_parse() {
        let status = "Name:\tlambert\nVmSize:\t  3896 kB\nVmData:\t     428 kB\n";
        assert_eq!(field_kb(status, "VmSize:"), Some(3896));
        assert_eq!(field_kb(status, "VmData:"), Some(428));
        assert_eq!(field_kb(status, "VmRSS:"), None);
        let groups = "9:name=systemd:/\n4:memory:/batch/job7\n1:cpu,cpuacct:/\n0::/user.slice/run-1.scope\n";
        assert_eq!(
            parse_proc_cgroup(groups),
            (Some("/user.slice/run-1.scope".into()), Some("/batch/job7".into()))
        );
        assert_eq!(parse_proc_cgroup("3:cpu,memory:/a\n"), (None, Some("/a".into())));
        assert_eq!(parse_v2_max("max\n"), None);
        assert_eq!(parse_v2_max("4294967296\n"), Some(4294967296));
        assert_eq!(parse_v1_limit("9223372036854771712\n"), None);
        assert_eq!(parse_v1_limit("2147483648"), Some(2147483648));
    }

    #[test]
    fn cgroup_v2_takes_the_tightest_ancestor_less_the_working_set() {
        let read = tree(&[
            ("/cg/user.slice/run-1.scope/memory.max", "max\n"),
            ("/cg/user.slice/memory.max", "8000000000\n"),
            ("/cg/user.slice/memory.current", "3000000000\n"),
            ("/cg/user.slice/memory.stat", "anon 1\ninactive_file 1000000000\nactive_file 5\n"),
        ]);
        // 8 GB limit, 3 GB charged of which 1 GB is reclaimable cache: 6 GB left.
        assert_eq!(
            cgroup_headroom("0::/user.slice/run-1.scope\n", Path::new("/cg"), &read),
            Some(6_000_000_000)
        );
        // No limit anywhere: nothing known.
        let none = tree(&[("/cg/memory.max", "max")]);
        assert_eq!(cgroup_headroom("0::/\n", Path::new("/cg"), &none), None);
    }

    #[test]
    fn cgroup_v1_and_a_container_root() {
        let read = tree(&[
            ("/cg/memory/memory.limit_in_bytes", "9223372036854771712\n"),
            ("/cg/memory/job/memory.limit_in_bytes", "4000000000\n"),
            ("/cg/memory/job/memory.usage_in_bytes", "500000000\n"),
            ("/cg/memory/job/memory.stat", "cache 9\ntotal_inactive_file 100000000\n"),
        ]);
        assert_eq!(cgroup_headroom("4:memory:/job\n", Path::new("/cg"), &read), Some(3_600_000_000));
        // Inside a container the group's path is not under the mount; its root holds the limit.
        let inside = tree(&[("/cg/memory/memory.limit_in_bytes", "2000000000\n")]);
        assert_eq!(cgroup_headroom("4:memory:/docker/abc\n", Path::new("/cg"), &inside), Some(2_000_000_000));
    }
}
