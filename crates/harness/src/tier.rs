//! The sweep tiers: how much of each case (and study) a run covers.

use serde::{Deserialize, Serialize};

/// A sweep tier (CASES.md): `quick` is CI, `default` the papers' spacings, `full` the
/// extended sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Tier {
    /// CI tier (`--quick`).
    Quick,
    /// The papers' spacings (no flag).
    Default,
    /// Finer spacings and long runs (`--full`).
    Full,
}

impl Tier {
    /// Every tier, from the quickest.
    pub const ALL: [Tier; 3] = [Tier::Quick, Tier::Default, Tier::Full];

    /// The tier's name as written in files.
    pub fn name(self) -> &'static str {
        match self {
            Tier::Quick => "quick",
            Tier::Default => "default",
            Tier::Full => "full",
        }
    }
}

impl std::fmt::Display for Tier {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
