//! Plots: the output of a pre-detector (CFAR + plot extractor), one list per scan.

/// One pre-detected plot `s = [a, x, y]` (Bao et al. 2022, eq. 3): amplitude and two Cartesian
/// coordinates in metres. A scan is a borrowed slice `&[Plot]`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Plot {
    /// Amplitude (any unit; carried through, not used by the Hough stages).
    pub amplitude: f32,
    /// x coordinate (m).
    pub x: f32,
    /// y coordinate (m).
    pub y: f32,
}

impl Plot {
    /// A plot from its amplitude and coordinates.
    pub const fn new(amplitude: f32, x: f32, y: f32) -> Self {
        Self { amplitude, x, y }
    }

    /// A plot from the paper's row `[a, x, y]`.
    pub const fn from_array(s: [f32; 3]) -> Self {
        Self::new(s[0], s[1], s[2])
    }

    /// The row `[a, x, y]`.
    pub const fn to_array(self) -> [f32; 3] {
        [self.amplitude, self.x, self.y]
    }

    /// True when every field is finite.
    pub fn is_finite(&self) -> bool {
        self.amplitude.is_finite() && self.x.is_finite() && self.y.is_finite()
    }

    /// Squared distance to another plot (m^2).
    pub fn dist2(&self, o: &Plot) -> f32 {
        let dx = self.x - o.x;
        let dy = self.y - o.y;
        dx * dx + dy * dy
    }
}
