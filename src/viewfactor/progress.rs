//! Progress of a long view-factor run, counted on work done (patch pairs) as rows finish
//! inside a batch: a bar on a terminal once the run passes [`BAR_DELAY`]; without a terminal
//! (a log file, CI) one line every [`LOG_EVERY`] (`LAMBERT_PROGRESS_EVERY` seconds overrides
//! it); nothing with `--quiet`. A reporter thread reads an atomic counter, so the workers
//! only add to it and the numbers never depend on the report.
//!
//! **Time left.** Pairs differ in cost by orders of magnitude (a clear pair is one contour
//! integral, a pair behind a meshed part hundreds of shadow viewpoints), and the costly ones
//! often finish last. The estimate therefore takes the slower of the mean rate so far and the
//! rate over the last [`RATE_WINDOW`]; when no row finished within that window it says so
//! instead of printing a time.
//!
//! **Watching from another thread.** A caller that shows progress itself (the Python package's
//! callback) runs the work inside [`watching`]: every [`Progress`] started on that thread
//! then also counts into the caller's [`Watch`], which the caller polls.
use std::cell::RefCell;
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
/// The recent rate is measured over this much time: long enough to span a few rows, short
/// enough to notice within a log interval or two that the remaining pairs cost more.
pub const RATE_WINDOW: Duration = Duration::from_secs(30);
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

/// Counts a caller polls from another thread while work runs under [`watching`]: the current
/// stage's units done and total, and how many stages have started.
#[derive(Debug, Default)]
pub struct Watch {
    done: AtomicU64,
    total: AtomicU64,
    stages: AtomicU64,
    what: Mutex<&'static str>,
}

/// One reading of a [`Watch`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reading {
    /// Stages started so far (a new [`Progress`] is a new stage).
    pub stages: u64,
    /// Units done in the current stage (at most `total`).
    pub done: u64,
    /// Units in the current stage.
    pub total: u64,
    /// What the units are ("pairs").
    pub what: &'static str,
}

impl Watch {
    /// The current counts.
    pub fn read(&self) -> Reading {
        let total = self.total.load(Ordering::Relaxed);
        Reading {
            stages: self.stages.load(Ordering::Relaxed),
            done: self.done.load(Ordering::Relaxed).min(total),
            total,
            what: *self.what.lock().unwrap_or_else(|e| e.into_inner()),
        }
    }
    fn begin(&self, total: u64, what: &'static str) {
        *self.what.lock().unwrap_or_else(|e| e.into_inner()) = what;
        self.done.store(0, Ordering::Relaxed);
        self.total.store(total, Ordering::Relaxed);
        self.stages.fetch_add(1, Ordering::Relaxed);
    }
}

thread_local! {
    static WATCH: RefCell<Option<Arc<Watch>>> = const { RefCell::new(None) };
}

/// Runs `f` with every [`Progress`] it starts on this thread also counting into `watch`.
pub fn watching<T>(watch: &Arc<Watch>, f: impl FnOnce() -> T) -> T {
    let before = WATCH.with(|w| w.replace(Some(Arc::clone(watch))));
    struct Restore(Option<Arc<Watch>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let before = self.0.take();
            WATCH.with(|w| *w.borrow_mut() = before);
        }
    }
    let _restore = Restore(before);
    f()
}

/// A running progress report; [`Progress::add`] from any thread, dropped (or
/// [`Progress::finish`]) when the work is done.
pub struct Progress {
    shared: Arc<Shared>,
    reporter: Option<JoinHandle<()>>,
    watch: Option<Arc<Watch>>,
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
        let watch = WATCH.with(|w| w.borrow().clone());
        if let Some(w) = &watch {
            w.begin(total, what);
        }
        Progress { shared, reporter, watch }
    }

    /// Records `n` more units done.
    pub fn add(&self, n: u64) {
        self.shared.done.fetch_add(n, Ordering::Relaxed);
        if let Some(w) = &self.watch {
            w.done.fetch_add(n, Ordering::Relaxed);
        }
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
    let mut history = History::default();
    let mut stopped = s.stop.lock().unwrap_or_else(|e| e.into_inner());
    while !*stopped {
        stopped = s.wake.wait_timeout(stopped, POLL).unwrap_or_else(|e| e.into_inner()).0;
        if *stopped {
            break;
        }
        let (done, elapsed) = (s.done.load(Ordering::Relaxed).min(total), start.elapsed());
        history.push(elapsed, done);
        match mode {
            Mode::Bar if elapsed >= BAR_DELAY => {
                let b = bar.get_or_insert_with(|| new_bar(total, what));
                b.set_position(done);
                b.set_message(time_left(done, total, elapsed, history.recent()));
            }
            Mode::Log(every) if elapsed >= next_log => {
                eprintln!("lambert: progress: {}", line(done, total, what, elapsed, history.recent()));
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
    let template = format!("{{elapsed_precise}} [{{bar:40}}] {{percent}}% of {{human_len}} {what}, {{msg}}");
    if let Ok(style) = indicatif::ProgressStyle::with_template(&template) {
        b.set_style(style.progress_chars("=> "));
    }
    b
}

/// (elapsed, done) samples of the last [`RATE_WINDOW`], one per second.
#[derive(Debug, Default)]
struct History {
    samples: std::collections::VecDeque<(Duration, u64)>,
}

impl History {
    fn push(&mut self, t: Duration, done: u64) {
        if self.samples.back().is_none_or(|&(last, _)| t >= last + Duration::from_secs(1)) {
            self.samples.push_back((t, done));
        }
        while self.samples.len() > 2 && self.samples[1].0 + RATE_WINDOW <= t {
            self.samples.pop_front();
        }
    }
    /// The recent progress (Δt, Δdone) when the samples span the whole window.
    fn recent(&self) -> Option<(Duration, u64)> {
        let (&(t0, d0), &(t1, d1)) = (self.samples.front()?, self.samples.back()?);
        (t1 - t0 >= RATE_WINDOW).then(|| (t1 - t0, d1 - d0))
    }
}

/// The remaining time at the slower of the mean rate so far and the `recent` rate (Δt, Δdone
/// over [`RATE_WINDOW`]), or why there is none.
pub fn time_left(done: u64, total: u64, elapsed: Duration, recent: Option<(Duration, u64)>) -> String {
    if done == 0 {
        return "rate not known yet".into();
    }
    let mean = done as f64 / elapsed.as_secs_f64().max(1e-9);
    let rate = match recent {
        Some((_, 0)) => {
            return format!(
                "none finished in the last {:.0} s (the remaining ones cost more)",
                RATE_WINDOW.as_secs_f64()
            )
        }
        Some((dt, dd)) => mean.min(dd as f64 / dt.as_secs_f64()),
        None => mean,
    };
    format!("about {:.0} s left", total.saturating_sub(done) as f64 / rate)
}

/// One log line: share done, counts, elapsed and the remaining time ([`time_left`]).
pub fn line(done: u64, total: u64, what: &str, elapsed: Duration, recent: Option<(Duration, u64)>) -> String {
    let share = done as f64 / total.max(1) as f64;
    let secs = elapsed.as_secs_f64();
    let left = time_left(done, total, elapsed, recent);
    format!("{:.1}% of {total} {what} ({done} done), {secs:.0} s elapsed, {left}", 100.0 * share)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_log_line_gives_share_counts_and_time_left() {
        let l = line(250, 1000, "pairs", Duration::from_secs(10), None);
        assert_eq!(l, "25.0% of 1000 pairs (250 done), 10 s elapsed, about 30 s left");
        assert!(line(0, 1000, "pairs", Duration::from_secs(10), None).ends_with("rate not known yet"));
    }

    #[test]
    fn the_time_left_follows_the_slower_recent_rate() {
        // 950 of 1000 pairs in 10 s, then 10 more in the last 30 s: the mean rate (24/s) would
        // say 2 s; the recent one (1/3 per s) says 120 s.
        let (elapsed, recent) = (Duration::from_secs(40), Some((Duration::from_secs(30), 10)));
        assert_eq!(time_left(960, 1000, elapsed, recent), "about 120 s left");
        // Nothing finished within the window: no time is claimed.
        let stalled = time_left(950, 1000, elapsed, Some((Duration::from_secs(30), 0)));
        assert!(stalled.starts_with("none finished in the last 30 s"), "{stalled}");
        // A recent rate above the mean does not shorten the estimate.
        assert_eq!(
            time_left(500, 1000, Duration::from_secs(100), Some((Duration::from_secs(30), 300))),
            "about 100 s left"
        );
    }

    #[test]
    fn the_history_spans_the_window_once_it_has_passed() {
        let mut h = History::default();
        for s in 0..=40u64 {
            h.push(Duration::from_secs(s), if s < 10 { 95 * s } else { 950 });
        }
        assert_eq!(h.recent(), Some((Duration::from_secs(30), 0)));
        let mut young = History::default();
        young.push(Duration::ZERO, 0);
        young.push(Duration::from_secs(5), 10);
        assert_eq!(young.recent(), None);
    }

    #[test]
    fn a_watch_sees_each_stage_started_under_it_and_nothing_outside() {
        let watch = Arc::new(Watch::default());
        let outside = Progress::start(5, "pairs", Mode::Off);
        outside.add(5);
        assert_eq!(watch.read().stages, 0);
        watching(&watch, || {
            let p = Progress::start(100, "pairs", Mode::Off);
            std::thread::scope(|s| {
                s.spawn(|| p.add(30));
                s.spawn(|| p.add(12));
            });
            assert_eq!(watch.read(), Reading { stages: 1, done: 42, total: 100, what: "pairs" });
            let q = Progress::start(7, "point-patch pairs", Mode::Off);
            q.add(7);
        });
        assert_eq!(watch.read(), Reading { stages: 2, done: 7, total: 7, what: "point-patch pairs" });
        // The thread's watch is gone after the call.
        Progress::start(3, "pairs", Mode::Off).add(3);
        assert_eq!(watch.read().stages, 2);
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
