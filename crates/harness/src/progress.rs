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

    /// A bar counting the runs of a case.
    pub fn case_bar(&self, case: &str, runs: usize) -> ProgressBar {
        let bar = self.multi.add(ProgressBar::new(runs as u64));
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix:>20.bold} [{bar:30.green/white}] {pos}/{len} runs {elapsed_precise} {msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar.set_prefix(case.to_string());
        bar
    }

    /// A bar for one run, in simulated time.
    pub fn run_bar(&self, slug: &str) -> RunBar {
        let bar = self.multi.add(ProgressBar::new(TICKS));
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix:>20} [{bar:30.cyan/blue}] {percent:>3}% t={msg} {elapsed}/{duration}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar.set_prefix(slug.to_string());
        RunBar { bar, last: u64::MAX }
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
}

impl RunBar {
    /// Removes the bar.
    pub fn finish(self) {
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
        }
    }
}
