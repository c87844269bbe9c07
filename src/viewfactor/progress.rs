//! Progress of a run, by phase ([`Phase`]: loading, BVH and blockers, view factors,
//! enforcement, solve, writing) and, inside the view-factor phase, by work done as rows finish.
//! A reporter thread reads counters only, so the workers only add to them and the numbers never
//! depend on the report.
//!
//! Where it goes ([`Mode`]): on a terminal, a bar (or a spinner for a phase without counts)
//! whose prefix names the phase, once the phase passes [`BAR_DELAY`]; without a terminal (a
//! log file, CI), a line when a phase has run [`BAR_DELAY`], one every [`LOG_EVERY`] while
//! rows finish (`LAMBERT_PROGRESS_EVERY` seconds overrides it), and one with the phase's time
//! when it ends; nothing with `--quiet`. Short phases stay silent.
//!
//! **Phases.** The library says where a run is with [`enter`]; a caller that draws it (the
//! CLI) installs a [`Display`] on its thread first, a caller that polls (the Python binding's
//! callback) runs the work under [`watching`]. Without either, [`enter`] costs nothing.
//!
//! **Time left.** Pairs differ in cost by orders of magnitude (a clear pair is one contour
//! integral, a pair behind a meshed part hundreds of shadow viewpoints), and the costly ones
//! often finish last. Each row therefore carries an estimated cost (the kernel's
//! [`crate::viewfactor::row::RowKernel::row_costs`]); the time left is the estimated cost
//! of the remaining rows over the measured cost rate, which corrects the estimate's scale.
//! The rate is the slower of the mean so far and the rate over the last [`RATE_WINDOW`]; when
//! no row finished within that window the report says so instead of printing a time.
use std::cell::RefCell;
use std::fmt;
use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// A bar appears only for phases longer than this: short runs stay silent.
pub const BAR_DELAY: Duration = Duration::from_secs(1);
/// Without a terminal, one line per this interval: often enough to show life in a log,
/// rare enough not to flood it.
pub const LOG_EVERY: Duration = Duration::from_secs(10);
/// How often the reporter looks at the counters (the bar redraws at most this often).
const POLL: Duration = Duration::from_millis(100);
/// The recent rate is measured over this much time: long enough to span a few rows, short
/// enough to notice within a log interval or two that the remaining rows cost more.
pub const RATE_WINDOW: Duration = Duration::from_secs(30);
/// Environment variable: the log interval in seconds (a shorter one also lowers the time a
/// phase must run before the log names it, [`BAR_DELAY`], to the interval).
pub const EVERY_ENV: &str = "LAMBERT_PROGRESS_EVERY";

/// Phases of a run, in the order a run meets them (a run may skip some).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Loading the scene.
    Load,
    /// Building the blockers, their BVH and the method's tables.
    Bvh,
    /// Computing view factors (or links).
    ViewFactors,
    /// Enforcing reciprocity / closure.
    Enforcement,
    /// Solving the radiosity system.
    Solve,
    /// Writing results.
    Write,
}

impl Phase {
    /// The phase's name as the report prints it.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Load => "loading",
            Phase::Bvh => "bvh",
            Phase::ViewFactors => "view factors",
            Phase::Enforcement => "enforcement",
            Phase::Solve => "solve",
            Phase::Write => "writing",
        }
    }
}

impl fmt::Display for Phase {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

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

/// The counters of one counted stage (the rows of a view-factor run).
#[derive(Debug)]
struct Counts {
    /// Units done (pairs).
    done: AtomicU64,
    /// Estimated cost of the rows done.
    cost: AtomicU64,
    /// Units in the stage.
    total: u64,
    /// Estimated cost of every row.
    total_cost: u64,
    /// What the units are ("pairs").
    what: &'static str,
}

/// What the reporter thread reads: the phases entered (with their start since the display
/// started) and the counted stage running, if any.
#[derive(Debug, Default)]
struct State {
    phases: Vec<(Phase, Duration)>,
    stage: Option<(Arc<Counts>, Duration)>,
}

struct Shared {
    state: Mutex<State>,
    stop: Mutex<bool>,
    wake: Condvar,
    start: Instant,
    bar: Mutex<Option<indicatif::ProgressBar>>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl Shared {
    fn new() -> Arc<Shared> {
        Arc::new(Shared {
            state: Mutex::new(State::default()),
            stop: Mutex::new(false),
            wake: Condvar::new(),
            start: Instant::now(),
            bar: Mutex::new(None),
        })
    }
}

/// The drawing of a whole run on stderr, installed on the calling thread: [`enter`] and every
/// [`Progress`] started on this thread report to it until it is dropped.
pub struct Display {
    shared: Arc<Shared>,
    reporter: Option<JoinHandle<()>>,
    before: Option<Arc<Shared>>,
}

thread_local! {
    static DISPLAY: RefCell<Option<Arc<Shared>>> = const { RefCell::new(None) };
    static WATCH: RefCell<Option<Arc<Watch>>> = const { RefCell::new(None) };
}

impl Display {
    /// Starts drawing in `mode` (nothing is installed for [`Mode::Off`]).
    pub fn start(mode: Mode) -> Display {
        let shared = Shared::new();
        let reporter = (mode != Mode::Off).then(|| {
            let s = Arc::clone(&shared);
            std::thread::spawn(move || report(&s, mode, true))
        });
        let before = match reporter {
            Some(_) => DISPLAY.with(|d| d.replace(Some(Arc::clone(&shared)))),
            None => None,
        };
        Display { shared, reporter, before }
    }

    /// Runs `f` (which prints lines on stderr) with the bar of this thread's display hidden.
    pub fn suspend<R>(f: impl FnOnce() -> R) -> R {
        let shared = DISPLAY.with(|d| d.borrow().clone());
        let bar = shared.as_ref().and_then(|s| lock(&s.bar).clone());
        match bar {
            Some(b) => b.suspend(f),
            None => f(),
        }
    }
}

impl Drop for Display {
    fn drop(&mut self) {
        if let Some(h) = self.reporter.take() {
            DISPLAY.with(|d| *d.borrow_mut() = self.before.take());
            *lock(&self.shared.stop) = true;
            self.shared.wake.notify_all();
            let _ = h.join();
        }
    }
}

/// True when a display draws this thread's progress (a run without `--quiet`): callers skip
/// work that only feeds the drawing, such as the rows' cost estimates.
pub fn displayed() -> bool {
    DISPLAY.with(|d| d.borrow().is_some())
}

/// The run on this thread enters `phase`: its display and watch hear it.
pub fn enter(phase: Phase) {
    if let Some(s) = DISPLAY.with(|d| d.borrow().clone()) {
        let at = s.start.elapsed();
        lock(&s.state).phases.push((phase, at));
    }
    if let Some(w) = WATCH.with(|w| w.borrow().clone()) {
        lock(&w.phases).push(phase);
    }
}

/// Counts a caller polls from another thread while work runs under [`watching`]: the phases
/// entered, the current stage's units done and total, and how many stages have started.
#[derive(Debug, Default)]
pub struct Watch {
    done: AtomicU64,
    total: AtomicU64,
    stages: AtomicU64,
    what: Mutex<&'static str>,
    phases: Mutex<Vec<Phase>>,
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
    /// Phases entered so far ([`Watch::phases`] lists them).
    pub phases: usize,
}

impl Watch {
    /// The current counts.
    pub fn read(&self) -> Reading {
        let total = self.total.load(Ordering::Relaxed);
        Reading {
            stages: self.stages.load(Ordering::Relaxed),
            done: self.done.load(Ordering::Relaxed).min(total),
            total,
            what: *lock(&self.what),
            phases: lock(&self.phases).len(),
        }
    }
    /// The phases entered from the `from`-th on, in order.
    pub fn phases(&self, from: usize) -> Vec<Phase> {
        lock(&self.phases).get(from..).map_or_else(Vec::new, <[Phase]>::to_vec)
    }
    fn begin(&self, total: u64, what: &'static str) {
        *lock(&self.what) = what;
        self.done.store(0, Ordering::Relaxed);
        self.total.store(total, Ordering::Relaxed);
        self.stages.fetch_add(1, Ordering::Relaxed);
    }
}

/// Runs `f` with every [`Progress`] it starts and every phase it enters on this thread also
/// reported to `watch`.
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

/// A running count of work; [`Progress::add`] from any thread, dropped (or
/// [`Progress::finish`]) when the work is done. Reports to this thread's [`Display`] when one
/// is installed, else draws by itself in the given mode.
pub struct Progress {
    counts: Arc<Counts>,
    /// The display it reports to (its own when none was installed).
    shared: Arc<Shared>,
    /// Its own reporter, when no display was installed.
    reporter: Option<JoinHandle<()>>,
    watch: Option<Arc<Watch>>,
}

impl Progress {
    /// Starts reporting `total` units of `what` (e.g. "pairs"), each unit of equal cost.
    pub fn start(total: u64, what: &'static str, mode: Mode) -> Progress {
        Self::start_costed(total, what, mode, total)
    }

    /// Starts reporting `total` units of `what` whose estimated cost adds up to `total_cost`
    /// ([`Progress::add_costed`] says the cost of each piece done).
    pub fn start_costed(total: u64, what: &'static str, mode: Mode, total_cost: u64) -> Progress {
        let counts =
            Arc::new(Counts { done: AtomicU64::new(0), cost: AtomicU64::new(0), total, total_cost, what });
        let installed = DISPLAY.with(|d| d.borrow().clone());
        let (shared, reporter) = match installed {
            Some(s) => (s, None),
            None => {
                let s = Shared::new();
                let reporter = (mode != Mode::Off && total > 0).then(|| {
                    let r = Arc::clone(&s);
                    std::thread::spawn(move || report(&r, mode, false))
                });
                (s, reporter)
            }
        };
        let at = shared.start.elapsed();
        lock(&shared.state).stage = Some((Arc::clone(&counts), at));
        let watch = WATCH.with(|w| w.borrow().clone());
        if let Some(w) = &watch {
            w.begin(total, what);
        }
        Progress { counts, shared, reporter, watch }
    }

    /// Records `n` more units done.
    pub fn add(&self, n: u64) {
        self.add_costed(n, n);
    }

    /// Records `n` more units done, of estimated cost `cost`.
    pub fn add_costed(&self, n: u64, cost: u64) {
        self.counts.done.fetch_add(n, Ordering::Relaxed);
        self.counts.cost.fetch_add(cost, Ordering::Relaxed);
        if let Some(w) = &self.watch {
            w.done.fetch_add(n, Ordering::Relaxed);
        }
    }

    /// Units done so far.
    pub fn done(&self) -> u64 {
        self.counts.done.load(Ordering::Relaxed)
    }

    /// Stops the report and clears the bar.
    pub fn finish(self) {}
}

impl Drop for Progress {
    fn drop(&mut self) {
        {
            let mut st = lock(&self.shared.state);
            if st.stage.as_ref().is_some_and(|(c, _)| Arc::ptr_eq(c, &self.counts)) {
                st.stage = None;
            }
        }
        if let Some(h) = self.reporter.take() {
            *lock(&self.shared.stop) = true;
            self.shared.wake.notify_all();
            let _ = h.join();
        }
    }
}

/// The reporter thread: polls the state until stopped, and draws or logs what changed.
/// `phased`: a whole-run [`Display`] (lines name the phase), else one stage by itself.
fn report(s: &Shared, mode: Mode, phased: bool) {
    let mut view = View::new(mode, phased);
    let mut stopped = lock(&s.stop);
    loop {
        stopped = s.wake.wait_timeout(stopped, POLL).unwrap_or_else(|e| e.into_inner()).0;
        let now = s.start.elapsed();
        let lines = {
            let st = lock(&s.state);
            let stage = st.stage.as_ref().map(|(c, at)| (&**c, *at));
            view.tick(now, &st.phases, stage, *stopped)
        };
        if mode == Mode::Bar {
            view.draw(s);
        } else {
            for l in lines {
                eprintln!("{l}");
            }
        }
        if *stopped {
            break;
        }
    }
    if let Some(b) = lock(&s.bar).take() {
        b.finish_and_clear();
    }
}

/// What the bar shows.
#[derive(Debug, Clone, PartialEq)]
enum Shown {
    /// Nothing (the phase has not run [`BAR_DELAY`] yet).
    Nothing,
    /// A phase without counts: a spinner with the phase's name.
    Spinner(Option<Phase>),
    /// Counts: the phase, units done and total, what they are, the time left.
    Counts(Option<Phase>, u64, u64, &'static str, String),
}

/// The reporter's memory between polls; [`View::tick`] turns a state into log lines (and the
/// bar's content) without reading a clock, so tests drive it with made-up times.
struct View {
    mode: Mode,
    phased: bool,
    /// How long a phase runs before it shows: [`BAR_DELAY`], or a shorter log interval.
    delay: Duration,
    /// Phases whose end has been handled.
    closed: usize,
    /// The phase whose start line was printed.
    announced: Option<usize>,
    /// The stage being followed (its start), its next log time and its rate history.
    stage: Option<Duration>,
    next_log: Duration,
    history: History,
    /// What the bar should show, and what it is drawn for (phase index, stage start).
    shown: Shown,
    key: Option<(usize, Option<Duration>)>,
    drawn: Option<(usize, Option<Duration>)>,
    /// How long what the bar shows has run (a new bar starts its clock there).
    age: Duration,
}

impl View {
    fn new(mode: Mode, phased: bool) -> View {
        let delay = match mode {
            Mode::Log(every) => every.min(BAR_DELAY),
            _ => BAR_DELAY,
        };
        View {
            mode,
            phased,
            delay,
            closed: 0,
            announced: None,
            stage: None,
            next_log: Duration::MAX,
            history: History::default(),
            shown: Shown::Nothing,
            key: None,
            drawn: None,
            age: Duration::ZERO,
        }
    }

    /// One poll at `now`: `phases` entered (with their starts), the counted stage (with its
    /// start), whether the run has stopped. Returns the log lines to print.
    fn tick(
        &mut self,
        now: Duration,
        phases: &[(Phase, Duration)],
        stage: Option<(&Counts, Duration)>,
        stopped: bool,
    ) -> Vec<String> {
        let mut lines = Vec::new();
        let log = matches!(self.mode, Mode::Log(_));
        // Phases that ended: their time when they took longer than the delay.
        let open = if stopped { phases.len() } else { phases.len().saturating_sub(1) };
        for k in self.closed..open {
            let end = phases.get(k + 1).map_or(now, |p| p.1);
            let took = end.saturating_sub(phases[k].1);
            if log && took >= self.delay {
                lines.push(format!("lambert: progress: {} took {:.1} s", phases[k].0, took.as_secs_f64()));
            }
        }
        self.closed = self.closed.max(open);
        let current = if stopped { None } else { phases.len().checked_sub(1) };
        let phase = current.map(|k| phases[k]);
        // A phase that has run the delay says so once.
        if let (Some(k), Some((p, at))) = (current, phase) {
            if log && self.announced != Some(k) && now.saturating_sub(at) >= self.delay {
                lines.push(format!("lambert: progress: {p} (started at {:.1} s)", at.as_secs_f64()));
                self.announced = Some(k);
            }
        }
        // The counted stage: its rate history, log lines and bar.
        let stage = stage.filter(|_| !stopped);
        let stage_at = stage.map(|(_, at)| at);
        if stage_at != self.stage {
            self.stage = stage_at;
            self.history = History::default();
            self.next_log = match self.mode {
                Mode::Log(every) => every,
                _ => Duration::MAX,
            };
        }
        let since = phase.map(|p| p.1).into_iter().chain(stage_at).fold(Duration::ZERO, Duration::max);
        self.age = now.saturating_sub(since);
        self.key = current.map(|k| (k, stage_at)).or(stage_at.map(|at| (usize::MAX, Some(at))));
        let name = phase.map(|p| p.0).filter(|_| self.phased);
        self.shown = Shown::Nothing;
        if let Some((c, at)) = stage {
            let elapsed = now.saturating_sub(at);
            let (done, cost) = (c.done.load(Ordering::Relaxed).min(c.total), c.cost.load(Ordering::Relaxed));
            let cost = cost.min(c.total_cost);
            self.history.push(elapsed, cost);
            let left = time_left(cost, c.total_cost, elapsed, self.history.recent());
            if let Mode::Log(every) = self.mode {
                if elapsed >= self.next_log {
                    let prefix = name.map_or(String::new(), |p| format!("{p}: "));
                    lines.push(format!(
                        "lambert: progress: {prefix}{}",
                        line(done, c.total, c.what, elapsed, &left)
                    ));
                    while self.next_log <= elapsed {
                        self.next_log += every;
                    }
                }
            }
            if now.saturating_sub(since) >= self.delay {
                self.shown = Shown::Counts(name, done, c.total, c.what, left);
            }
        } else if self.phased && phase.is_some_and(|(_, at)| now.saturating_sub(at) >= self.delay) {
            self.shown = Shown::Spinner(name);
        }
        lines
    }

    /// Draws [`View::shown`] on the terminal (a new bar when the phase or stage changed).
    fn draw(&mut self, s: &Shared) {
        let mut bar = lock(&s.bar);
        if self.drawn != self.key || self.shown == Shown::Nothing {
            if let Some(b) = bar.take() {
                b.finish_and_clear();
            }
            self.drawn = None;
        }
        match &self.shown {
            Shown::Nothing => {}
            Shown::Spinner(p) => {
                let b = bar.get_or_insert_with(|| new_bar(None, *p, "").with_elapsed(self.age));
                b.tick();
            }
            Shown::Counts(p, done, total, what, left) => {
                let b = bar.get_or_insert_with(|| new_bar(Some(*total), *p, what).with_elapsed(self.age));
                b.set_position(*done);
                b.set_message(left.clone());
            }
        }
        if bar.is_some() {
            self.drawn = self.key;
        }
    }
}

/// A bar of `total` units of `what` (a spinner when `None`), its prefix naming `phase`.
fn new_bar(total: Option<u64>, phase: Option<Phase>, what: &str) -> indicatif::ProgressBar {
    let b = indicatif::ProgressBar::with_draw_target(total, indicatif::ProgressDrawTarget::stderr());
    let prefix = phase.map_or(String::new(), |p| format!("{p}: "));
    let template = match total {
        Some(_) => {
            format!("{prefix}{{elapsed_precise}} [{{bar:40}}] {{percent}}% of {{human_len}} {what}, {{msg}}")
        }
        None => format!("{prefix}{{elapsed_precise}} {{spinner}}"),
    };
    if let Ok(style) = indicatif::ProgressStyle::with_template(&template) {
        b.set_style(style.progress_chars("=> "));
    }
    b
}

/// (elapsed, cost done) samples of the last [`RATE_WINDOW`], one per second.
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

/// The remaining time of a stage with `done` of `total` cost units done after `elapsed`: the
/// remaining cost at the slower of the mean rate so far and the `recent` rate (Δt, Δdone over
/// [`RATE_WINDOW`]), or why there is none. Units of equal cost make this a count of pairs.
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

/// One log line: share done, counts, elapsed and the remaining time `left` ([`time_left`]).
pub fn line(done: u64, total: u64, what: &str, elapsed: Duration, left: &str) -> String {
    let share = done as f64 / total.max(1) as f64;
    let secs = elapsed.as_secs_f64();
    format!("{:.1}% of {total} {what} ({done} done), {secs:.0} s elapsed, {left}", 100.0 * share)
}

#[cfg(test)]
mod tests;
