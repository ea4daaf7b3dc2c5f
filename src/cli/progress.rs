//! Progress of long commands, on stderr only: a bar with a message, elapsed time and ETA on a
//! terminal; off a terminal a line at every tenth of the work (`sweep: 40% (7/16 points),
//! eta 12s`), the same lines on every run apart from the times; nothing with `--quiet`.
//!
//! Every bar belongs to one [`indicatif::MultiProgress`], so a command's bar and the bar of a
//! step it runs (`report` running `stability`) stack, and log lines print above them.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};

use super::logging::{settings, Verbosity};

static BARS: OnceLock<MultiProgress> = OnceLock::new();

fn bars() -> &'static MultiProgress {
    BARS.get_or_init(|| MultiProgress::with_draw_target(ProgressDrawTarget::stderr()))
}

/// Runs `print` with the bars hidden (a log line prints above them, not through them).
pub fn suspend<R>(print: impl FnOnce() -> R) -> R {
    match BARS.get() {
        Some(m) => m.suspend(print),
        None => print(),
    }
}

/// How a [`Progress`] shows itself.
enum Show {
    /// An indicatif bar (stderr is a terminal).
    Bar(ProgressBar),
    /// A line at every tenth (stderr is a file or a pipe).
    Lines(Mutex<Tenths>),
    /// Nothing (`--quiet`, or work too small to show).
    Off,
}

/// The progress of one long piece of work: `len` steps of a `unit` ("points", "rows").
/// Shared between threads (`&Progress` is `Sync`); cleared when dropped.
pub struct Progress {
    label: String,
    unit: String,
    show: Show,
    pos: AtomicU64,
    len: AtomicU64,
    /// Where this run started (a resumed sweep starts at what is done), for the rate.
    first: Arc<AtomicU64>,
    start: Instant,
}

impl Progress {
    /// Starts showing the progress of `len` steps (`len` may be set later with
    /// [`Progress::set_len`]); `label` starts every line ("sweep"), `unit` names the steps.
    pub fn new(label: &str, unit: &str, len: u64) -> Progress {
        let s = settings();
        let first = Arc::new(AtomicU64::new(0));
        let show = if s.verbosity == Verbosity::Quiet {
            Show::Off
        } else if s.stderr_terminal {
            let bar = bars().add(ProgressBar::new(len));
            // The ETA at the mean rate of this run, as off a terminal (indicatif's own
            // estimate swings widely when steps are uneven, as the report's are).
            let since = Arc::clone(&first);
            let eta = move |state: &ProgressState, w: &mut dyn std::fmt::Write| {
                let done = state.pos().saturating_sub(since.load(Ordering::Relaxed));
                let left = state.len().unwrap_or(0).saturating_sub(state.pos());
                let _ = match mean_rate_eta(state.elapsed(), done, left) {
                    Some(d) => write!(w, "{}", human(d, false)),
                    None => write!(w, "-"),
                };
            };
            bar.set_style(
                ProgressStyle::with_template(&format!(
                    "{label} [{{bar:30}}] {{pos}}/{{len}} {unit}, {{elapsed}}, eta {{mean_eta}} {{wide_msg}}"
                ))
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .with_key("mean_eta", eta)
                .progress_chars("=> "),
            );
            bar.enable_steady_tick(Duration::from_millis(500));
            Show::Bar(bar)
        } else {
            Show::Lines(Mutex::new(Tenths::new(len, 0)))
        };
        Progress {
            label: label.to_string(),
            unit: unit.to_string(),
            show,
            pos: AtomicU64::new(0),
            len: AtomicU64::new(len),
            first,
            start: Instant::now(),
        }
    }

    /// A progress that shows nothing (work known to be short).
    pub fn off(label: &str, unit: &str, len: u64) -> Progress {
        Progress {
            label: label.to_string(),
            unit: unit.to_string(),
            show: Show::Off,
            pos: AtomicU64::new(0),
            len: AtomicU64::new(len),
            first: Arc::new(AtomicU64::new(0)),
            start: Instant::now(),
        }
    }

    /// Starts at `done` steps already done (a resumed run), without a line for them.
    pub fn resumed_at(self, done: u64) -> Progress {
        self.pos.store(done, Ordering::Relaxed);
        self.first.store(done, Ordering::Relaxed);
        match &self.show {
            Show::Bar(b) => b.set_position(done),
            Show::Lines(t) => {
                let len = self.len.load(Ordering::Relaxed);
                *t.lock().expect("progress lock") = Tenths::new(len, done);
            }
            Show::Off => {}
        }
        self
    }

    /// Sets the number of steps (once known).
    pub fn set_len(&self, len: u64) {
        if self.len.swap(len, Ordering::Relaxed) == len {
            return;
        }
        match &self.show {
            Show::Bar(b) => b.set_length(len),
            Show::Lines(t) => t.lock().expect("progress lock").len = len,
            Show::Off => {}
        }
    }

    /// The message shown beside the bar on a terminal (what is being done now); lines off a
    /// terminal do not carry it (commands log what they do as they go).
    pub fn set_message(&self, message: impl Into<String>) {
        if let Show::Bar(b) = &self.show {
            b.set_message(message.into());
        }
    }

    /// `n` more steps done.
    pub fn inc(&self, n: u64) {
        let pos = self.pos.fetch_add(n, Ordering::Relaxed) + n;
        self.show_position(pos);
    }

    /// `pos` steps done in all (never moves back).
    pub fn set_position(&self, pos: u64) {
        let pos = self.pos.fetch_max(pos, Ordering::Relaxed).max(pos);
        self.show_position(pos);
    }

    fn show_position(&self, pos: u64) {
        match &self.show {
            Show::Bar(b) => b.set_position(pos),
            Show::Lines(t) => {
                // The lock orders the lines: every tenth once, in order, whatever the threads.
                let mut tenths = t.lock().expect("progress lock");
                let reached = tenths.reach(pos);
                if reached.is_empty() {
                    return;
                }
                let eta = self.eta(pos);
                let len = tenths.len;
                let taken = self.start.elapsed();
                for tenth in reached {
                    let line = tenth_line(&self.label, &self.unit, tenth, len, eta, taken);
                    {
                        use std::io::Write as _;
                        let _ = writeln!(std::io::stderr(), "{line}");
                    }
                }
            }
            Show::Off => {}
        }
    }

    /// The time left at this run's rate so far, once a step is done.
    fn eta(&self, pos: u64) -> Option<Duration> {
        let done = pos.saturating_sub(self.first.load(Ordering::Relaxed));
        let len = self.len.load(Ordering::Relaxed);
        mean_rate_eta(self.start.elapsed(), done, len.saturating_sub(pos))
    }

    /// Clears the bar and logs (with `-v`) how long the work took.
    pub fn finish(self) {
        log::debug!(
            "{}: {} {} in {}",
            self.label,
            self.pos.load(Ordering::Relaxed),
            self.unit,
            human(self.start.elapsed(), true)
        );
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Show::Bar(b) = &self.show {
            b.finish_and_clear();
            bars().remove(b);
        }
    }
}

/// Which tenths of the work have been announced off a terminal.
#[derive(Debug)]
struct Tenths {
    len: u64,
    announced: u64,
}

impl Tenths {
    /// `len` steps, `done` of them done before this run (their tenths are not announced).
    fn new(len: u64, done: u64) -> Tenths {
        let mut t = Tenths { len, announced: 0 };
        t.announced = t.tenth(done);
        t
    }

    /// The whole tenths of the work `pos` steps reach (0 while the length is unknown).
    fn tenth(&self, pos: u64) -> u64 {
        if self.len == 0 {
            0
        } else {
            (u128::from(pos.min(self.len)) * 10 / u128::from(self.len)) as u64
        }
    }

    /// The tenths newly reached at `pos`, in order; each is returned once, and a tenth is
    /// left out when the next one starts at the same step (short work: 4 of 8 steps is 50%,
    /// announced as such rather than also as 40%).
    fn reach(&mut self, pos: u64) -> Vec<u64> {
        let now = self.tenth(pos);
        let first = |t: u64| first_step(t, self.len);
        let new: Vec<u64> = (self.announced + 1..=now)
            .filter(|&t| t == 10 || first(t) != first(t + 1))
            .collect();
        self.announced = self.announced.max(now);
        new
    }
}

/// The first of `len` steps that reaches `tenth` of them: ceil(tenth * len / 10).
fn first_step(tenth: u64, len: u64) -> u64 {
    (u128::from(tenth) * u128::from(len)).div_ceil(10) as u64
}

/// The line announcing `tenth` of `len` steps: the count is the first step that reaches it
/// (so the line is the same whatever the threads), then the estimated time left, or the
/// time taken at 100%.
fn tenth_line(
    label: &str,
    unit: &str,
    tenth: u64,
    len: u64,
    eta: Option<Duration>,
    taken: Duration,
) -> String {
    let count = first_step(tenth, len);
    let time = if tenth >= 10 {
        format!(", took {}", human(taken, false))
    } else {
        eta.map_or(String::new(), |d| format!(", eta {}", human(d, false)))
    };
    format!("{label}: {}% ({count}/{len} {unit}){time}", tenth * 10)
}

/// The time `left` steps take at the mean rate of `done` steps in `elapsed`; none before the
/// first step.
fn mean_rate_eta(elapsed: Duration, done: u64, left: u64) -> Option<Duration> {
    (done > 0).then(|| elapsed.mul_f64(left as f64 / done as f64))
}

/// A duration for people: `850ms` (only when `fine`), `12s`, `3m05s`, `1h02m`.
fn human(d: Duration, fine: bool) -> String {
    let s = d.as_secs();
    if fine && s < 10 {
        format!("{:.3}s", d.as_secs_f64())
    } else if s < 60 {
        format!("{s}s")
    } else if s < 3600 {
        format!("{}m{:02}s", s / 60, s % 60)
    } else {
        format!("{}h{:02}m", s / 3600, (s % 3600) / 60)
    }
}

/// A command's steps (the report's): a line each on stderr, a bar over them on a terminal (a
/// line every tenth elsewhere), and with `-v` how long each took.
pub struct Steps {
    label: &'static str,
    bar: Progress,
    current: Option<(String, std::time::Instant)>,
}

impl Steps {
    /// Starts showing `count` steps of `label` (`specfx report`).
    pub fn new(label: &'static str, count: u64) -> Steps {
        Steps {
            label,
            bar: Progress::new(label.trim_start_matches("specfx "), "steps", count),
            current: None,
        }
    }

    /// Ends the step under way and starts the next, logged at `level`.
    pub fn start_at(&mut self, level: log::Level, msg: &str) {
        self.end_current();
        log::log!(level, "{}: {msg}", self.label);
        self.bar.set_message(msg.to_string());
        self.current = Some((msg.to_string(), std::time::Instant::now()));
    }

    /// Ends the step under way and starts the next.
    pub fn start(&mut self, msg: &str) {
        self.start_at(log::Level::Info, msg);
    }

    /// A part of the step under way, logged and shown but not counted.
    pub fn part(&self, msg: &str) {
        log::info!("{}: {msg}", self.label);
        self.bar.set_message(msg.to_string());
    }

    fn end_current(&mut self) {
        if let Some((msg, start)) = self.current.take() {
            log::debug!(
                "{}: {:.3}s for: {msg}",
                self.label,
                start.elapsed().as_secs_f64()
            );
            self.bar.inc(1);
        }
    }

    pub fn finish(mut self) {
        self.end_current();
        self.bar.finish();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_tenth_is_announced_once_in_order() {
        // 16 steps one by one: the tenth t is first reached at step ceil(16 t / 10).
        let mut t = Tenths::new(16, 0);
        let mut seen = Vec::new();
        for pos in 1..=16 {
            for tenth in t.reach(pos) {
                seen.push((tenth, pos));
            }
        }
        let want: Vec<(u64, u64)> = [2, 4, 5, 7, 8, 10, 12, 13, 15, 16]
            .iter()
            .enumerate()
            .map(|(i, &p)| (i as u64 + 1, p))
            .collect();
        assert_eq!(seen, want);
        // A jump announces every tenth it passes; going back or repeating announces nothing.
        let mut t = Tenths::new(1000, 0);
        assert_eq!(t.reach(350), vec![1, 2, 3]);
        assert!(t.reach(300).is_empty());
        assert!(t.reach(399).is_empty());
        assert_eq!(t.reach(5000), vec![4, 5, 6, 7, 8, 9, 10]);
        // Short work: a tenth starting at the same step as the next is left out.
        let mut t = Tenths::new(8, 0);
        let seen: Vec<Vec<u64>> = (1..=8).map(|pos| t.reach(pos)).collect();
        let want: Vec<Vec<u64>> = vec![
            vec![1],
            vec![2],
            vec![3],
            vec![5],
            vec![6],
            vec![7],
            vec![8],
            vec![10],
        ];
        assert_eq!(seen, want);
        // A resumed run does not announce what was done before it; no length, no lines.
        let mut t = Tenths::new(10, 5);
        assert_eq!(t.reach(6), vec![6]);
        let mut t = Tenths::new(0, 0);
        assert!(t.reach(7).is_empty());
    }

    #[test]
    fn lines_name_the_first_step_of_their_tenth() {
        let s = Duration::from_secs;
        assert_eq!(
            tenth_line("sweep", "points", 4, 3000, Some(s(12)), s(8)),
            "sweep: 40% (1200/3000 points), eta 12s"
        );
        assert_eq!(
            tenth_line("sweep", "points", 3, 16, None, s(1)),
            "sweep: 30% (5/16 points)"
        );
        assert_eq!(
            tenth_line("trace", "rows", 10, 7, Some(s(0)), s(185)),
            "trace: 100% (7/7 rows), took 3m05s"
        );
    }

    #[test]
    fn the_eta_is_the_mean_rate_of_this_run() {
        let s = Duration::from_secs;
        // 4 steps in 10 s: 6 more take 15 s.
        assert_eq!(mean_rate_eta(s(10), 4, 6), Some(s(15)));
        assert_eq!(mean_rate_eta(s(10), 0, 6), None);
        assert_eq!(mean_rate_eta(s(10), 3, 0), Some(s(0)));
    }

    #[test]
    fn durations_read_well() {
        assert_eq!(human(Duration::from_millis(850), true), "0.850s");
        assert_eq!(human(Duration::from_millis(850), false), "0s");
        assert_eq!(human(Duration::from_secs(59), false), "59s");
        assert_eq!(human(Duration::from_secs(61), false), "1m01s");
        assert_eq!(human(Duration::from_secs(3720), true), "1h02m");
    }
}
