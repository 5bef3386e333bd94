//! The Gaussian comparators' noise model in `faint reproduce crpf`: where their per-bin
//! variance comes from, which likelihood they use and their birth proposal
//! (`--comparator-var`, `--comparator-likelihood`, `--birth-proposal`).

use faint_core::detect::pf_tbd::BirthProposal;
use serde::{Deserialize, Serialize};

/// Where the Gaussian comparators' per-bin noise variance comes from (`--comparator-var`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum VarSource {
    /// Estimated from the run's K frames, `sum_k ||z_k||^2 / (K m)` (includes the target).
    #[default]
    Run,
    /// The scene's true per-bin variance (time-domain variance times `sum w^2`).
    True,
}

/// The Gaussian comparators' likelihood (`--comparator-likelihood`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Likelihood {
    /// Independent bins of the windowed frame (the preset).
    #[default]
    Independent,
    /// The window's bin covariance taken into account (`GaussConfig::likelihood` =
    /// `window`: each frame whitened in the detectors' step, the rectangular window's
    /// response; the exact Gaussian likelihood under the correlated bins).
    Window,
}

/// The comparators' noise model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ComparatorModel {
    /// Variance source.
    pub var: VarSource,
    /// Likelihood.
    pub likelihood: Likelihood,
    /// The scene's time-domain noise variance (for [`VarSource::True`]).
    pub time_var: f64,
    /// Birth proposal of PF-TBD and JOTT (`--birth-proposal`).
    pub birth: BirthProposal,
}

impl Default for ComparatorModel {
    fn default() -> Self {
        Self {
            var: VarSource::Run,
            likelihood: Likelihood::Independent,
            time_var: 1.0,
            birth: BirthProposal::Exact,
        }
    }
}

/// Whether (and how) the Gaussian comparators run: `true` is the default
/// [`ComparatorModel`], `false` CRPF-TBD alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Comparators(pub Option<ComparatorModel>);

impl From<bool> for Comparators {
    fn from(on: bool) -> Self {
        Self(on.then(ComparatorModel::default))
    }
}

impl From<ComparatorModel> for Comparators {
    fn from(m: ComparatorModel) -> Self {
        Self(Some(m))
    }
}
