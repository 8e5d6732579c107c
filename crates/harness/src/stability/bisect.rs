//! Geometric bisection for the largest stable value of a parameter (a time-step multiple,
//! a Reynolds number): stability is assumed to be lost once, somewhere in a bracket.

use serde::{Deserialize, Serialize};

/// Where the largest stable value lies after a bisection.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Bracket {
    /// Stable at `stable`, unstable at `unstable` (`stable < unstable`); the largest stable
    /// value is in between.
    Found {
        /// Largest value found stable.
        stable: f64,
        /// Smallest value found unstable.
        unstable: f64,
    },
    /// Stable even at the top of the search range: the largest stable value is at least this.
    AtLeast(f64),
    /// Unstable even at the bottom of the search range: the largest stable value is below this.
    Below(f64),
}

impl Bracket {
    /// The largest value found stable, if any.
    pub fn stable(&self) -> Option<f64> {
        match *self {
            Bracket::Found { stable, .. } | Bracket::AtLeast(stable) => Some(stable),
            Bracket::Below(_) => None,
        }
    }

    /// The bracket as text, e.g. `[1.19, 1.41)`, `≥ 5`, `< 0.25`.
    pub fn describe(&self) -> String {
        match *self {
            Bracket::Found { stable, unstable } => format!("[{}, {})", sig3(stable), sig3(unstable)),
            Bracket::AtLeast(v) => format!("≥ {}", sig3(v)),
            Bracket::Below(v) => format!("< {}", sig3(v)),
        }
    }
}

/// A number to 3 significant digits, without trailing zeros (`1.19`, `400`, `0.0123`).
pub fn sig3(v: f64) -> String {
    if !v.is_finite() || v == 0.0 {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s }
}

/// Bisects `[lo, hi]` (`0 < lo < hi`) in log space for the largest value where `stable`
/// holds: first `hi` (stable: done, [`Bracket::AtLeast`]), then `lo` (unstable: done,
/// [`Bracket::Below`]), then `iterations` geometric midpoints, each halving the bracket's
/// log-width (the final ratio unstable/stable is `(hi/lo)^(1/2^iterations)`).
///
/// `stable` may record what it ran; it is called once per tried value, in order.
pub fn bisect(lo: f64, hi: f64, iterations: usize, mut stable: impl FnMut(f64) -> bool) -> Bracket {
    let mut b = Bisection::new(lo, hi, iterations);
    while let Some(value) = b.next_value() {
        b.record(stable(value));
    }
    b.bracket().expect("a finished bisection has a bracket")
}

/// [`bisect`] one value at a time, so that several bisections can advance together (their
/// trials run as one batch): ask [`Bisection::next_value`], run it, [`Bisection::record`]
/// the verdict.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bisection {
    lo: f64,
    hi: f64,
    /// Midpoints left.
    left: usize,
    state: State,
}

/// Where a bisection stands.
#[derive(Debug, Clone, Copy, PartialEq)]
enum State {
    /// `hi` not tried yet.
    Top,
    /// `hi` unstable, `lo` not tried yet.
    Bottom,
    /// Stable at the first, unstable at the second; the midpoint is next.
    Between(f64, f64),
    /// Done.
    Done(Bracket),
}

impl Bisection {
    /// A bisection of `[lo, hi]` (`0 < lo < hi`) with `iterations` midpoints at most.
    pub fn new(lo: f64, hi: f64, iterations: usize) -> Self {
        assert!(lo > 0.0 && hi > lo, "bisect needs 0 < lo < hi, got [{lo}, {hi}]");
        Bisection { lo, hi, left: iterations, state: State::Top }
    }

    /// The value to try next; `None` when done.
    pub fn next_value(&self) -> Option<f64> {
        match self.state {
            State::Top => Some(self.hi),
            State::Bottom => Some(self.lo),
            State::Between(s, u) if self.left > 0 => Some((s * u).sqrt()),
            State::Between(..) | State::Done(_) => None,
        }
    }

    /// Records whether the value [`Bisection::next_value`] gave was stable.
    pub fn record(&mut self, stable: bool) {
        self.state = match self.state {
            State::Top if stable => State::Done(Bracket::AtLeast(self.hi)),
            State::Top => State::Bottom,
            State::Bottom if stable => State::Between(self.lo, self.hi),
            State::Bottom => State::Done(Bracket::Below(self.lo)),
            State::Between(s, u) => {
                let mid = (s * u).sqrt();
                self.left = self.left.saturating_sub(1);
                if stable { State::Between(mid, u) } else { State::Between(s, mid) }
            }
            done @ State::Done(_) => done,
        };
    }

    /// The result, once done.
    pub fn bracket(&self) -> Option<Bracket> {
        match self.state {
            State::Done(b) => Some(b),
            State::Between(stable, unstable) if self.left == 0 => Some(Bracket::Found { stable, unstable }),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brackets_a_threshold_to_the_promised_ratio() {
        let mut tried = Vec::new();
        let b = bisect(0.25, 4.0, 4, |k| {
            tried.push(k);
            k <= 1.3
        });
        let Bracket::Found { stable, unstable } = b else { panic!("{b:?}") };
        assert!(stable <= 1.3 && unstable > 1.3, "{b:?}");
        // log-width 16^(1/16): the ratio is 2^(1/4).
        assert!((unstable / stable - 2f64.powf(0.25)).abs() < 1e-12, "{}", unstable / stable);
        assert_eq!(tried.len(), 2 + 4, "both ends, then one run per iteration");
        assert_eq!(&tried[..3], &[4.0, 0.25, 1.0]);
        assert_eq!(b.stable(), Some(stable));
        assert_eq!(b.describe(), format!("[{}, {})", sig3(stable), sig3(unstable)));
    }

    #[test]
    fn ends_of_the_range_stop_early() {
        let mut n = 0;
        assert_eq!(
            bisect(1.0, 10.0, 5, |_| {
                n += 1;
                true
            }),
            Bracket::AtLeast(10.0)
        );
        assert_eq!(n, 1);
        let b = bisect(1.0, 10.0, 5, |_| false);
        assert_eq!(b, Bracket::Below(1.0));
        assert_eq!(b.stable(), None);
        assert_eq!(b.describe(), "< 1");
        assert_eq!(Bracket::AtLeast(4000.0).describe(), "≥ 4000");
    }

    #[test]
    fn zero_iterations_give_the_ends() {
        assert_eq!(bisect(2.0, 8.0, 0, |k| k < 5.0), Bracket::Found { stable: 2.0, unstable: 8.0 });
    }

    #[test]
    #[should_panic(expected = "0 < lo < hi")]
    fn rejects_an_empty_range() {
        bisect(2.0, 2.0, 3, |_| true);
    }

    #[test]
    fn three_significant_digits() {
        assert_eq!(sig3(1.18920711), "1.19");
        assert_eq!(sig3(400.0), "400");
        assert_eq!(sig3(0.012345), "0.0123");
        assert_eq!(sig3(1264.9), "1265");
        assert_eq!(sig3(5.0), "5");
    }
}
