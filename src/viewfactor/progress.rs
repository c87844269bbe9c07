//! Progress of a long view-factor run, counted on work done (patch pairs) as rows finish
//! inside a batch: a bar on a terminal once the run passes [`BAR_DELAY`]; without a terminal
//! (a log file, CI) one line every [`LOG_EVERY`] (`LAMBERT_PROGRESS_EVERY` seconds overrides
//! it); nothing with `--quiet`. A reporter thread reads an atomic counter, so the workers
//! only add to it and the numbers never depend on the report.
use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// A bar appears only for runs longer than this: short runs stay silent.
pub const BAR_DELAY: Duration = Duration::from_secs(1);
/// Without a terminal, one line per this interval: often enough to show life in a log,
/// rare enough not to flood it.
pub const LOG_EVERY: Duration = Duration::from_secs(10);
/// How often the reporter looks at the counter (the bar redraws at most this often).
const POLL: Duration = Duration::from_millis(100);
/// Environment variable: the log interval in seconds.
pub const EVERY_ENV: &str = "LAMBERT_PROGRESS_EVERY";

/// Where progress goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Nothing (`--quiet`, or a library caller).
    Off,
    /// A bar on a terminal.
    Bar,
    /// A line per interval on stderr.
    Log(Duration),
}

impl Mode {
    /// The mode for stderr: off when not `enabled`, a bar on a terminal, else log lines.
    pub fn for_stderr(enabled: bool) -> Mode {
        if !enabled {
            Mode::Off
        } else if std::io::stderr().is_terminal() {
            Mode::Bar
        } else {
            let every = std::env::var(EVERY_ENV)
                .ok()
                .and_then(|v| v.parse::<f64>().ok())
                .filter(|s| s.is_finite() && *s > 0.0)
                .map_or(LOG_EVERY, Duration::from_secs_f64);
            Mode::Log(every)
        }
    }
}

struct Shared {
    done: AtomicU64,
    stop: Mutex<bool>,
    wake: Condvar,
}

/// A running progress report; [`Progress::add`] from any thread, dropped (or
/// [`Progress::finish`]) when the work is done.
pub struct Progress {
    shared: Arc<Shared>,
    reporter: Option<JoinHandle<()>>,
}

impl Progress {
    /// Starts reporting `total` units of `what` (e.g. "pairs").
    pub fn start(total: u64, what: &'static str, mode: Mode) -> Progress {
        let shared =
            Arc::new(Shared { done: AtomicU64::new(0), stop: Mutex::new(false), wake: Condvar::new() });
        let reporter = (mode != Mode::Off && total > 0).then(|| {
            let s = Arc::clone(&shared);
            std::thread::spawn(move || report(&s, total, what, mode))
        });
        Progress { shared, reporter }
    }

    /// Records `n` more units done.
    pub fn add(&self, n: u64) {
        self.shared.done.fetch_add(n, Ordering::Relaxed);
    }

    /// Units done so far.
    pub fn done(&self) -> u64 {
        self.shared.done.load(Ordering::Relaxed)
    }

    /// Stops the report and clears the bar.
    pub fn finish(self) {}
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some(h) = self.reporter.take() {
            *self.shared.stop.lock().unwrap_or_else(|e| e.into_inner()) = true;
            self.shared.wake.notify_all();
            let _ = h.join();
        }
    }
}

/// The reporter thread: polls the counter until stopped.
fn report(s: &Shared, total: u64, what: &'static str, mode: Mode) {
    let start = Instant::now();
    let mut bar: Option<indicatif::ProgressBar> = None;
    let mut next_log = match mode {
        Mode::Log(every) => every,
        _ => Duration::MAX,
    };
    let mut stopped = s.stop.lock().unwrap_or_else(|e| e.into_inner());
    while !*stopped {
        stopped = s.wake.wait_timeout(stopped, POLL).unwrap_or_else(|e| e.into_inner()).0;
        if *stopped {
            break;
        }
        let (done, elapsed) = (s.done.load(Ordering::Relaxed).min(total), start.elapsed());
        match mode {
            Mode::Bar if elapsed >= BAR_DELAY => {
                let b = bar.get_or_insert_with(|| new_bar(total, what));
                b.set_position(done);
            }
            Mode::Log(every) if elapsed >= next_log => {
                eprintln!("lambert: progress: {}", line(done, total, what, elapsed));
                while next_log <= elapsed {
                    next_log += every;
                }
            }
            _ => {}
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
}

fn new_bar(total: u64, what: &str) -> indicatif::ProgressBar {
    let b = indicatif::ProgressBar::with_draw_target(Some(total), indicatif::ProgressDrawTarget::stderr());
    let template =
        format!("{{elapsed_precise}} [{{bar:40}}] {{percent}}% of {{human_len}} {what}, eta {{eta}}");
    if let Ok(style) = indicatif::ProgressStyle::with_template(&template) {
        b.set_style(style.progress_chars("=> "));
    }
    b
}

/// One log line: share done, counts, elapsed and the remaining time at the mean rate so far.
pub fn line(done: u64, total: u64, what: &str, elapsed: Duration) -> String {
    let share = done as f64 / total.max(1) as f64;
    let secs = elapsed.as_secs_f64();
    let left = if done > 0 {
        format!("about {:.0} s left", secs * (1.0 - share) / share)
    } else {
        "rate not known yet".into()
    };
    format!("{:.1}% of {total} {what} ({done} done), {secs:.0} s elapsed, {left}", 100.0 * share)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_log_line_gives_share_counts_and_time_left() {
        let l = line(250, 1000, "pairs", Duration::from_secs(10));
        assert_eq!(l, "25.0% of 1000 pairs (250 done), 10 s elapsed, about 30 s left");
        assert!(line(0, 1000, "pairs", Duration::from_secs(10)).ends_with("rate not known yet"));
    }

    #[test]
    fn work_is_counted_from_many_threads_and_off_spawns_nothing() {
        let p = Progress::start(1000, "pairs", Mode::Off);
        assert!(p.reporter.is_none());
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| (0..250).for_each(|_| p.add(1)));
            }
        });
        assert_eq!(p.done(), 1000);
        let q = Progress::start(10, "pairs", Mode::Log(Duration::from_secs(3600)));
        assert!(q.reporter.is_some());
        q.finish();
    }
}
