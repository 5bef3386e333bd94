//! Which of Pei et al.'s three algorithms a configuration runs (shared by the host preset,
//! the golden scene and the firmware rows).

/// Which of the paper's three algorithms.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    /// SMC-PHD TBD without PSO, K-means extraction.
    PhdTbd,
    /// PSO-PHD-TBD with K-means extraction.
    PsoKMeans,
    /// PSO-PHD-TBD with DBSCAN extraction (the paper's proposal).
    PsoDbscan,
}

impl Variant {
    /// All three, in the paper's order.
    pub const ALL: [Variant; 3] = [Variant::PhdTbd, Variant::PsoKMeans, Variant::PsoDbscan];

    /// Display name.
    pub fn name(self) -> &'static str {
        match self {
            Variant::PhdTbd => "PHD-TBD",
            Variant::PsoKMeans => "PSO-PHD-TBD (K-means)",
            Variant::PsoDbscan => "PSO-PHD-TBD (DBSCAN)",
        }
    }
}
