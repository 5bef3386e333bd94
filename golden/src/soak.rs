//! The soak's plausible frames and reduced configurations, one copy for the host's
//! `faint soak` and the firmware's `soak` binary: the same generator code on both sides,
//! so a detector on the target sees the host soak's frames bit for bit.
//!
//! A plausible value is noise at the preset's scale `s`, one value in 8 with a strong
//! return of `10 s` added:
//!
//! ```text
//! x = s n + 10 s b,           n ~ N(0, 1), b ~ Bernoulli(1/8)   (signed amplitudes)
//! x = (s n)^2 + (10 s b)^2                                       (powers, `positive`)
//! ```
//!
//! drawn in that order (`normal`, then `below(8)`). Complex bins are two values (real,
//! imaginary); a scan of plots holds 0 to `2 capacity + 1` plots uniform over the area
//! with amplitudes `1 + Exp(1)` ([`plot_count`], [`plot_inside`]).
//!
//! The reduced configurations ([`cbmember_reduced`], [`cube_cells`]) keep a preset's
//! model and extent on fewer cells, so that a soak of 1e6 frames costs minutes; the
//! constants below are the firmware soak's sizes, which the host's soak checks against
//! its own (a host test).

use faint_core::detect::cbmember::CbmemberConfig;
use faint_core::detect::mht::ClassicHoughConfig;
use faint_core::model::plot::Plot;
use faint_core::model::power_cube::CubeGeometry;
use faint_core::model::range_doppler::{PointModel, RdGeometry};
use faint_core::rng::Rng;
use faint_core::Complex32;

/// Seed of the frames and of the detectors (`faint soak`'s default).
pub const SEED: u64 = 1;
/// Bins of a Doppler frame (the OTHR preset's).
pub const DOPPLER_BINS: usize = 32;
/// Plot capacity of the MHT-TBD soak (a scan holds up to `2 MHT_PLOTS + 1` plots).
pub const MHT_PLOTS: usize = 640;
/// Plot capacity the classic Hough TBD's scans are drawn for.
pub const CLASSIC_PLOTS: usize = 64;
/// Noise standard deviation of a DP-TBD image.
pub const DP_SCALE: f32 = 1.5;
/// Side of the DP-TBD preset's images.
pub const DP_SIDE: usize = 128;
/// Side of the reduced DP-TBD images.
pub const DP_REDUCED_SIDE: usize = 32;
/// Cells (range, Doppler, azimuth) of the reduced PHD-TBD / PSO-PHD-TBD cube.
pub const PHD_REDUCED_CELLS: [usize; 3] = [8, 8, 4];
/// Pixels (range, velocity) of the reduced CBMeMBer map.
pub const CBMEMBER_REDUCED_PIXELS: [usize; 2] = [32, 64];

/// The classic Hough TBD's default (`faint detect hough-classic`'s configuration): the
/// sea-clutter area and period and the threshold of the binomial strip model at 80 plots
/// per scan.
pub const CLASSIC: ClassicHoughConfig = ClassicHoughConfig {
    area: [0.0, 6000.0, 0.0, 6000.0],
    n_scans: 30,
    gamma: 28,
};

/// One plausible value at scale `s` (a power `|.|^2` of both terms when `positive`).
#[inline]
pub fn plausible(rng: &mut Rng, s: f32, positive: bool) -> f32 {
    let x = rng.normal() * s;
    let strong = if rng.below(8) == 0 { 10.0 * s } else { 0.0 };
    if positive {
        x * x + strong * strong
    } else {
        x + strong
    }
}

/// Fills `out` with plausible values; returns its length.
pub fn reals(rng: &mut Rng, out: &mut [f32], s: f32, positive: bool) -> usize {
    for o in out.iter_mut() {
        *o = plausible(rng, s, positive);
    }
    out.len()
}

/// Fills `out` with plausible complex bins (real, then imaginary part); returns its length.
pub fn complex(rng: &mut Rng, out: &mut [Complex32], s: f32) -> usize {
    for o in out.iter_mut() {
        let re = plausible(rng, s, false);
        let im = plausible(rng, s, false);
        *o = Complex32::new(re, im);
    }
    out.len()
}

/// The number of plots of a scan: none one time in 8, over `capacity` one time in 8,
/// otherwise up to `min(capacity, 64)`.
pub fn plot_count(rng: &mut Rng, capacity: usize) -> usize {
    match rng.below(8) {
        0 => 0,
        1 => capacity + 1 + rng.below(capacity as u32 + 1) as usize,
        _ => rng.below(capacity.min(64) as u32 + 1) as usize,
    }
}

/// One plot uniform over `area = [x0, x1, y0, y1]` (either order), amplitude `1 + Exp(1)`.
pub fn plot_inside(rng: &mut Rng, area: [f32; 4]) -> Plot {
    let a = 1.0 + rng.exponential();
    let x = rng.uniform_range(area[0].min(area[1]), area[1].max(area[0]));
    let y = rng.uniform_range(area[2].min(area[3]), area[3].max(area[2]));
    Plot::new(a, x, y)
}

/// A plausible scan into `out` ([`plot_count`] plots, at most `out.len()`); returns its
/// length.
pub fn plots(rng: &mut Rng, area: [f32; 4], capacity: usize, out: &mut [Plot]) -> usize {
    let n = plot_count(rng, capacity).min(out.len());
    for o in out[..n].iter_mut() {
        *o = plot_inside(rng, area);
    }
    n
}

/// `g` on `n = [range, Doppler, azimuth]` cells over the same extent (cell sizes
/// `extent / n`).
pub fn cube_cells(g: CubeGeometry, n: [usize; 3]) -> CubeGeometry {
    let (r, d, a) = (
        g.range_cell * g.n_range as f32,
        g.doppler_cell * g.n_doppler as f32,
        g.azimuth_cell_deg * g.n_azimuth as f32,
    );
    CubeGeometry {
        n_range: n[0],
        n_doppler: n[1],
        n_azimuth: n[2],
        range_cell: r / n[0] as f32,
        doppler_cell: d / n[1] as f32,
        azimuth_cell_deg: a / n[2] as f32,
        ..g
    }
}

/// `g` on `n = [range, velocity]` pixels over the same extent (bins scaled by
/// `n_old / n`).
pub fn map_pixels(g: RdGeometry, n: [usize; 2]) -> RdGeometry {
    RdGeometry {
        n_range: n[0],
        n_velocity: n[1],
        range_bin: g.range_bin * (g.n_range as f32 / n[0] as f32),
        velocity_bin: g.velocity_bin * (g.n_velocity as f32 / n[1] as f32),
        ..g
    }
}

/// The reduced CBMeMBer configuration: the `rotor-uav` preset with `model` on a
/// [`CBMEMBER_REDUCED_PIXELS`] map over the preset's extent, `L_max = 100`,
/// `L_min = 30` and 30 birth particles.
pub fn cbmember_reduced(model: PointModel) -> CbmemberConfig {
    let mut c = CbmemberConfig {
        model,
        ..CbmemberConfig::rotor_uav()
    };
    c.geometry = map_pixels(c.geometry, CBMEMBER_REDUCED_PIXELS);
    c.max_particles = 100;
    c.min_particles = 30;
    c.birth.particles = 30;
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reduced map keeps the preset's extent: for the `rotor-uav` preset (power-of-two
    /// sizes) the scaled bins are exact, so the extents agree to the bit.
    #[test]
    fn reduced_map_keeps_the_extent() {
        let p = CbmemberConfig::rotor_uav().geometry;
        let g = cbmember_reduced(PointModel::Joint).geometry;
        assert_eq!(
            g.range_bin * g.n_range as f32,
            p.range_bin * p.n_range as f32
        );
        assert_eq!(
            g.velocity_bin * g.n_velocity as f32,
            p.velocity_bin * p.n_velocity as f32
        );
        assert_eq!(
            (g.range_start, g.velocity_start),
            (p.range_start, p.velocity_start)
        );
    }

    /// A scan never exceeds its buffer, and the count law's three branches are reached.
    #[test]
    fn scans_fit_the_buffer() {
        let mut rng = Rng::seed_from_u64(SEED);
        let mut out = [Plot::new(0.0, 0.0, 0.0); 2 * MHT_PLOTS + 1];
        let (mut empty, mut over) = (0, 0);
        for _ in 0..400 {
            let n = plots(&mut rng, CLASSIC.area, MHT_PLOTS, &mut out);
            empty += usize::from(n == 0);
            over += usize::from(n > MHT_PLOTS);
            assert!(out[..n].iter().all(|p| p.amplitude >= 1.0
                && (0.0..=6000.0).contains(&p.x)
                && (0.0..=6000.0).contains(&p.y)));
        }
        // 400 scans, P(empty) >= 1/8: fewer than 20 (mean 50+) is a broken count law.
        assert!(empty > 20 && over > 20, "empty {empty}, over {over}");
    }
}
