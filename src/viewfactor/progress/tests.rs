//! Tests of the progress report: log lines, the cost-weighted time left on a made-up clock,
//! phases, and the watch.
use super::*;

/// Counters of a stage of `total` units costing `total_cost`.
fn counts(total: u64, total_cost: u64) -> Counts {
    Counts { done: AtomicU64::new(0), cost: AtomicU64::new(0), total, total_cost, what: "pairs" }
}

/// Seconds of "about N s left" (`None` for any other message).
fn seconds_left(msg: &str) -> Option<f64> {
    msg.strip_prefix("about ")?.strip_suffix(" s left")?.parse().ok()
}

#[test]
fn a_log_line_gives_share_counts_and_time_left() {
    let left = time_left(250, 1000, Duration::from_secs(10), None);
    assert_eq!(left, "about 30 s left");
    let l = line(250, 1000, "pairs", Duration::from_secs(10), &left);
    assert_eq!(l, "25.0% of 1000 pairs (250 done), 10 s elapsed, about 30 s left");
    assert_eq!(time_left(0, 1000, Duration::from_secs(10), None), "rate not known yet");
}

#[test]
fn the_time_left_follows_the_slower_recent_rate() {
    // 950 of 1000 units in 10 s, then 10 more in the last 30 s: the mean rate (24/s) would
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

/// Rows of equal pair count whose last 5 % carry most of the cost: 950 rows of cost 1, then
/// 50 of cost 200 (91 % of the cost). One unit of estimated cost takes `secs_per_unit` of
/// (made-up) time: the scale the report must find by itself.
struct Schedule {
    costs: Vec<u64>,
    secs_per_unit: f64,
}

impl Schedule {
    fn last_five_percent_costly(secs_per_unit: f64) -> Schedule {
        let costs = (0..1000).map(|i| if i < 950 { 1 } else { 200 }).collect();
        Schedule { costs, secs_per_unit }
    }
    fn total_secs(&self) -> f64 {
        self.costs.iter().sum::<u64>() as f64 * self.secs_per_unit
    }
    /// (rows, cost) finished by time `t` (rows run one after another).
    fn at(&self, t: f64) -> (u64, u64) {
        let (mut clock, mut rows, mut cost) = (0.0, 0, 0);
        for &c in &self.costs {
            clock += c as f64 * self.secs_per_unit;
            if clock > t {
                break;
            }
            rows += 1;
            cost += c;
        }
        (rows, cost)
    }
}

#[test]
fn the_time_left_counts_the_cost_of_the_remaining_rows_not_their_number() {
    const PAIRS_PER_ROW: u64 = 10;
    for secs_per_unit in [2.5e-3, 0.1] {
        let sched = Schedule::last_five_percent_costly(secs_per_unit);
        let total = sched.total_secs();
        let c = counts(1000 * PAIRS_PER_ROW, sched.costs.iter().sum());
        let mut view = View::new(Mode::Log(Duration::from_secs(3600)), true);
        let phases = [(Phase::ViewFactors, Duration::ZERO)];
        // The reporter polls every 0.1 s of made-up time; checks at 10 %, 50 % and 90 % of it.
        let checkpoint = |share: f64| (share * total / 0.1).round() as u64;
        let checkpoints = [0.1, 0.5, 0.9].map(checkpoint);
        let mut checked = 0;
        for step in 1.. {
            let t = 0.1 * step as f64;
            if t >= total {
                break;
            }
            let (rows, cost) = sched.at(t);
            c.done.store(rows * PAIRS_PER_ROW, Ordering::Relaxed);
            c.cost.store(cost, Ordering::Relaxed);
            view.tick(Duration::from_secs_f64(t), &phases, Some((&c, Duration::ZERO)), false);
            if !checkpoints.contains(&step) {
                continue;
            }
            let Shown::Counts(Some(Phase::ViewFactors), _, _, _, left) = &view.shown else {
                panic!("no bar content at {t} s: {:?}", view.shown);
            };
            let truth = total - t;
            let est = seconds_left(left).unwrap_or_else(|| panic!("no time at {t} s: {left}"));
            // Never optimistic beyond 10 %; pessimistic by at most 2x, which the recent rate
            // costs when each costly row takes two-thirds of its window (one worker here):
            // 2.7 s: 28 s left (truth 24.7), 13.7 s: 14 (13.7), 24.6 s: 3 (2.8) at 2.5 ms per
            // unit; 110 s: 1887 (986), 548 s: 840 (548), 986 s: 180 (110) at 0.1 s per unit.
            let ratio = est / truth;
            assert!(
                (0.9..=2.0).contains(&ratio),
                "at {t:.1} of {total:.1} s: {est} s left, truth {truth:.1} s"
            );
            checked += 1;
            // With 90 % of the time still to come, the count of pairs alone says a tenth of
            // that or less (95 % of the pairs are done): the failure this estimate avoids.
            if step == checkpoints[0] {
                let by_pairs =
                    time_left(rows * PAIRS_PER_ROW, 1000 * PAIRS_PER_ROW, Duration::from_secs_f64(t), None);
                assert!(rows >= 950 && seconds_left(&by_pairs).unwrap() <= 0.1 * truth, "{rows}: {by_pairs}");
            }
        }
        assert_eq!(checked, 3, "each checkpoint seen once");
    }
}

#[test]
fn a_log_names_long_phases_when_they_start_and_their_time_when_they_end() {
    let s = |x: f64| Duration::from_secs_f64(x);
    let mut view = View::new(Mode::Log(Duration::from_secs(10)), true);
    let mut phases = vec![(Phase::Load, s(0.0))];
    assert!(view.tick(s(0.1), &phases, None, false).is_empty());
    // Loading took 0.3 s: nothing; the solve passes the delay and says so once.
    phases.push((Phase::Solve, s(0.3)));
    assert!(view.tick(s(0.4), &phases, None, false).is_empty());
    assert_eq!(view.tick(s(1.4), &phases, None, false), ["lambert: progress: solve (started at 0.3 s)"]);
    assert!(view.tick(s(5.0), &phases, None, false).is_empty());
    // The solve ends at 8.9 s (8.6 s long); writing is short.
    phases.push((Phase::Write, s(8.9)));
    assert_eq!(view.tick(s(9.0), &phases, None, false), ["lambert: progress: solve took 8.6 s"]);
    assert!(view.tick(s(9.2), &phases, None, true).is_empty());
}

#[test]
fn a_counted_stage_logs_its_lines_under_its_phase_name() {
    let s = |x: u64| Duration::from_secs(x);
    let mut view = View::new(Mode::Log(s(10)), true);
    let phases = [(Phase::Bvh, s(0)), (Phase::ViewFactors, s(2))];
    let c = counts(100, 100);
    c.done.store(40, Ordering::Relaxed);
    c.cost.store(40, Ordering::Relaxed);
    let lines = view.tick(s(12), &phases, Some((&c, s(2))), false);
    assert_eq!(
        lines,
        [
            "lambert: progress: bvh took 2.0 s",
            "lambert: progress: view factors (started at 2.0 s)",
            "lambert: progress: view factors: 40.0% of 100 pairs (40 done), 10 s elapsed, about 15 s left",
        ]
    );
    // A stage by itself (no display) logs as before, without a phase.
    let mut alone = View::new(Mode::Log(s(10)), false);
    let lines = alone.tick(s(10), &[], Some((&c, s(0))), false);
    assert_eq!(lines, ["lambert: progress: 40.0% of 100 pairs (40 done), 10 s elapsed, about 15 s left"]);
}

#[test]
fn a_terminal_shows_a_spinner_for_a_long_phase_and_a_bar_for_counts() {
    let s = |x: f64| Duration::from_secs_f64(x);
    let mut view = View::new(Mode::Bar, true);
    let phases = [(Phase::Solve, s(0.0))];
    assert!(view.tick(s(0.5), &phases, None, false).is_empty());
    assert_eq!(view.shown, Shown::Nothing);
    view.tick(s(1.5), &phases, None, false);
    assert_eq!(view.shown, Shown::Spinner(Some(Phase::Solve)));
    let c = counts(10, 10);
    let phases = [(Phase::Solve, s(0.0)), (Phase::ViewFactors, s(2.0))];
    view.tick(s(2.5), &phases, Some((&c, s(2.0))), false);
    assert_eq!(view.shown, Shown::Nothing, "a new phase waits for the delay again");
    view.tick(s(3.5), &phases, Some((&c, s(2.0))), false);
    assert!(
        matches!(view.shown, Shown::Counts(Some(Phase::ViewFactors), 0, 10, "pairs", _)),
        "{:?}",
        view.shown
    );
}

#[test]
fn a_watch_sees_each_stage_and_phase_started_under_it_and_nothing_outside() {
    let watch = Arc::new(Watch::default());
    let outside = Progress::start(5, "pairs", Mode::Off);
    outside.add(5);
    enter(Phase::Solve);
    assert_eq!((watch.read().stages, watch.read().phases), (0, 0));
    watching(&watch, || {
        enter(Phase::Bvh);
        enter(Phase::ViewFactors);
        let p = Progress::start(100, "pairs", Mode::Off);
        std::thread::scope(|s| {
            s.spawn(|| p.add(30));
            s.spawn(|| p.add(12));
        });
        assert_eq!(watch.read(), Reading { stages: 1, done: 42, total: 100, what: "pairs", phases: 2 });
        let q = Progress::start(7, "point-patch pairs", Mode::Off);
        q.add(7);
        enter(Phase::Enforcement);
    });
    assert_eq!(watch.read(), Reading { stages: 2, done: 7, total: 7, what: "point-patch pairs", phases: 3 });
    assert_eq!(watch.phases(1), [Phase::ViewFactors, Phase::Enforcement]);
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

#[test]
fn a_stage_under_a_display_reports_to_it_and_leaves_it_when_done() {
    let display = Display::start(Mode::Log(Duration::from_secs(3600)));
    enter(Phase::ViewFactors);
    let p = Progress::start_costed(10, "pairs", Mode::Log(Duration::from_secs(3600)), 500);
    assert!(p.reporter.is_none(), "the display draws it");
    p.add_costed(4, 300);
    {
        let st = lock(&display.shared.state);
        assert_eq!(st.phases.iter().map(|p| p.0).collect::<Vec<_>>(), [Phase::ViewFactors]);
        let (c, _) = st.stage.as_ref().expect("stage");
        assert_eq!((c.done.load(Ordering::Relaxed), c.cost.load(Ordering::Relaxed)), (4, 300));
    }
    drop(p);
    assert!(lock(&display.shared.state).stage.is_none());
    drop(display);
    // Without a display, a stage draws by itself again.
    assert!(Progress::start(10, "pairs", Mode::Log(Duration::from_secs(3600))).reporter.is_some());
}

#[test]
fn a_display_is_seen_only_while_it_draws() {
    assert!(!displayed());
    {
        let _quiet = Display::start(Mode::Off);
        assert!(!displayed(), "an Off display installs nothing");
        let _lines = Display::start(Mode::Log(std::time::Duration::from_secs(3600)));
        assert!(displayed());
    }
    assert!(!displayed(), "dropping the display uninstalls it");
}
