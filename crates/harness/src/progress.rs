//! Progress display: an `indicatif` bar per case and per run, fed by the solver's
//! [`meniscus::Observer`].

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Resolution of a run bar (time is shown as a fraction of the end time).
const TICKS: u64 = 1000;

/// The progress display of a validation (hidden when `visible` is false or stderr is
/// not a terminal).
#[derive(Debug, Clone)]
pub struct Progress {
    multi: MultiProgress,
    /// Whether [`Progress::println`] prints.
    lines: bool,
}

impl Progress {
    /// A display on stderr, or a hidden one (whose lines still go to stderr).
    pub fn new(visible: bool) -> Self {
        let target = if visible { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() };
        Progress { multi: MultiProgress::with_draw_target(target), lines: true }
    }

    /// No bars and no lines.
    pub fn silent() -> Self {
        Progress { multi: MultiProgress::with_draw_target(ProgressDrawTarget::hidden()), lines: false }
    }

    /// The bar of a batch of `runs` runs, `units` long (the runs' summed estimated cost):
    /// shows the runs done and the ETA at the rate the units have been going.
    pub fn batch_bar(&self, name: &str, units: u64, runs: usize) -> ProgressBar {
        let bar = self.multi.add(ProgressBar::new(units.max(1)));
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix:>20.bold} [{bar:30.green/white}] {percent:>3}% {msg} {elapsed_precise} ETA {eta_precise}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar.set_prefix(name.to_string());
        bar.set_message(format!("0/{runs} runs"));
        bar
    }

    /// A bar for one run, in simulated time; with `batch` (the batch's bar and the run's
    /// units of it), the batch's bar advances with the run.
    pub fn run_bar(&self, slug: &str, batch: Option<(ProgressBar, u64)>) -> RunBar {
        let bar = self.multi.add(ProgressBar::new(TICKS));
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix:>20} [{bar:30.cyan/blue}] {percent:>3}% t={msg} {elapsed}/{duration}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar.set_prefix(slug.to_string());
        RunBar { bar, last: u64::MAX, batch: batch.map(|(bar, units)| (bar, units, 0)) }
    }

    /// Prints a line above the bars, or plainly to stderr when the bars are hidden (so CI
    /// logs still show one line per run); nothing when [`Progress::silent`].
    pub fn println(&self, line: &str) {
        if !self.lines {
            return;
        }
        if self.multi.is_hidden() {
            eprintln!("{line}");
        } else {
            let _ = self.multi.println(line);
        }
    }
}

/// A run's bar, as a solver observer.
#[derive(Debug)]
pub struct RunBar {
    bar: ProgressBar,
    last: u64,
    /// The batch's bar, the run's units of it and those already credited.
    batch: Option<(ProgressBar, u64, u64)>,
}

impl RunBar {
    /// Removes the bar and credits the batch with the rest of the run's units.
    pub fn finish(self) {
        if let Some((batch, units, credited)) = &self.batch {
            batch.inc(units.saturating_sub(*credited));
        }
        self.bar.finish_and_clear();
    }
}

impl meniscus::Observer for RunBar {
    fn progress(&mut self, _step: usize, time: f64, t_end: f64) {
        let pos = if t_end > 0.0 { ((time / t_end).clamp(0.0, 1.0) * TICKS as f64) as u64 } else { TICKS };
        if pos != self.last {
            self.last = pos;
            self.bar.set_position(pos);
            self.bar.set_message(format!("{time:.3e}"));
            if let Some((batch, units, credited)) = &mut self.batch {
                let due = *units * pos / TICKS;
                if due > *credited {
                    batch.inc(due - *credited);
                    *credited = due;
                }
            }
        }
    }
}
