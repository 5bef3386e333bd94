//! The cubes of `faint reproduce phd` (`--cubes`): the preset's own measurement model,
//! or the physics simulator of power cubes ([`crate::physics::cubes`]) on the same truth.
//!
//! `model` (the default) draws each frame from the filter's model (Pei et al. 2019,
//! eq. 2-3): every target's complex amplitude `A exp(j phi)` spread by the one-cell
//! Gaussian point spread `h = exp(-(delta_r^2 + delta_d^2 + delta_b^2) / 2)` (`delta`
//! the distance in cells from the target to each cell's centre), plus complex Gaussian
//! noise of variance `sigma^2` per component.
//!
//! `physics` renders the same targets with the physics simulator: each axis' response
//! is the sinc of a resolution-limited axis, `S(u) = sin(pi u) / (pi u)` at the
//! sub-cell offset `u`, cut 8 cells from the target's cell; a fresh uniform phase per
//! target and frame; complex white Gaussian noise of power `P_n = 2 sigma^2` per cell.
//!
//! SNR: both are the peak-cell power of a target at a cell centre over the noise power
//! per cell. The preset's `SNR = A^2 / (2 sigma^2)` (`h = 1` in the target's own cell at
//! a cell centre); the physics simulator's `SNR = a^2 / P_n` (`S(0) = 1`). With
//! `P_n = 2 sigma^2` and `a = A = sqrt(2 sigma^2 10^(SNR/10))` the two are the same
//! number. At a sub-cell offset the peak cell holds `A^2 h^2` in the model, whose
//! neighbours get `exp(-1/2)` of the amplitude at a cell centre, and `a^2 S(u_r)^2
//! S(u_d)^2 S(u_b)^2` in the physics, whose neighbours get nothing at a cell centre.

use faint_core::rng::Rng;
use serde::{Deserialize, Serialize};

use crate::physics::cubes::{Axis, CubePhysics, Response};
use crate::physics::Swerling;
use crate::simulate::phd::{SixTargets, TruthTarget};

/// Where the reproduction's cubes come from (`--cubes`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Cubes {
    /// The filter's own model: one-cell Gaussian spread (the preset, Pei et al. 2019).
    #[default]
    Model,
    /// The physics simulator: sinc response per axis at the sub-cell offset, random
    /// phase per frame, complex Gaussian noise; same targets, SNRs and seeds.
    Physics,
}

impl Cubes {
    /// The words the charts' titles and the table add for these cubes (none for the
    /// model, whose outputs are those of the preset).
    pub(super) fn label(self) -> &'static str {
        match self {
            Cubes::Model => "",
            Cubes::Physics => ", physics cubes",
        }
    }
}

/// The physics simulator of the preset `sc`: its geometry, noise power `2 sigma^2` per
/// cell, sinc response, Swerling 0.
pub fn physics(sc: &SixTargets) -> CubePhysics {
    let g = sc.geometry();
    let axis = |n: usize, start: f32, size: f32| Axis {
        n,
        start: f64::from(start),
        size: f64::from(size),
    };
    CubePhysics {
        dt: sc.dt,
        noise_power: 2.0 * sc.noise_var,
        swerling: Swerling::Zero,
        response: Response::Sinc,
        ..CubePhysics::new(
            axis(g.n_range, g.range_start, g.range_cell),
            axis(g.n_doppler, g.doppler_start, g.doppler_cell),
            axis(g.n_azimuth, g.azimuth_start_deg, g.azimuth_cell_deg),
        )
    }
}

/// Fills `cube` with one frame of `targets` (state `[x, vx, y, vy]`) rendered by the
/// physics simulator `p` at amplitude `a` each.
pub fn render(
    p: &CubePhysics,
    a: f64,
    targets: &[TruthTarget],
    rng: &mut Rng,
    cube: &mut Vec<f32>,
) {
    let echoes: Vec<(f64, [f64; 3])> = targets
        .iter()
        .map(|t| {
            let s = t.state;
            (a, CubePhysics::radar([s[0], s[2]], [s[1], s[3]]))
        })
        .collect();
    cube.clear();
    p.push_frame(&echoes, rng, cube);
}

/// One run's frame source.
pub(super) enum Renderer {
    /// The preset's [`SixTargets::cube`].
    Model,
    /// The physics simulator and the targets' amplitude.
    Physics(CubePhysics, f64),
}

impl Renderer {
    /// The renderer of `cubes` for the preset `sc`.
    pub(super) fn new(cubes: Cubes, sc: &SixTargets) -> Self {
        match cubes {
            Cubes::Model => Renderer::Model,
            Cubes::Physics => {
                let p = physics(sc);
                let a = p.amplitude(sc.snr_db);
                Renderer::Physics(p, a)
            }
        }
    }

    /// Fills `cube` with the frame of `targets`.
    pub(super) fn frame(
        &self,
        sc: &SixTargets,
        targets: &[TruthTarget],
        rng: &mut Rng,
        cube: &mut Vec<f32>,
    ) {
        match self {
            Renderer::Model => sc.cube(targets, rng, cube),
            Renderer::Physics(p, a) => render(p, *a, targets, rng, cube),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::cubes::sinc;

    /// A target at the fractional cell coordinates `u` (range, Doppler, azimuth; an
    /// integer is a cell centre) of the preset's cube.
    fn target(sc: &SixTargets, u: [f64; 3]) -> TruthTarget {
        let g = sc.geometry();
        let at = |start: f32, size: f32, u: f64| f64::from(start) + (u + 0.5) * f64::from(size);
        let r = at(g.range_start, g.range_cell, u[0]);
        let d = at(g.doppler_start, g.doppler_cell, u[1]);
        let b = at(g.azimuth_start_deg, g.azimuth_cell_deg, u[2]).to_radians();
        TruthTarget {
            id: 0,
            state: [r * b.cos(), d * b.cos(), r * b.sin(), d * b.sin()],
        }
    }

    fn idx(sc: &SixTargets, i: usize, j: usize, l: usize) -> usize {
        let g = sc.geometry();
        (i * g.n_doppler + j) * g.n_azimuth + l
    }

    /// The physics amplitude gives the preset's SNR: `a^2 / P_n = A^2 / (2 sigma^2)`,
    /// with `a^2 = A^2` (only f64 rounding apart).
    #[test]
    fn the_snr_is_the_presets() {
        for snr in [5.0, 7.0, 9.0] {
            let sc = SixTargets::new(snr);
            let p = physics(&sc);
            let a = p.amplitude(snr);
            assert!((a * a - sc.power()).abs() < 1e-12 * sc.power(), "{snr}");
            let want = 10f64.powf(snr / 10.0);
            assert!((a * a / p.noise_power - want).abs() < 1e-12 * want);
        }
    }

    /// Noise off: a target at a cell centre puts its whole power `P` in its cell (the
    /// sinc is 0 at every other integer offset; 1e-6 of `P` covers the f32 cube and the
    /// f64 sinc at integers); a quarter cell off in range the power of range cell `n`
    /// is `P S(n - 1/4)^2` (same tolerance), the other axes still centred; two targets
    /// far apart are both rendered.
    #[test]
    fn a_centred_target_fills_one_cell_and_an_offset_one_spreads_by_the_sinc() {
        let sc = SixTargets::new(9.0);
        let p = CubePhysics {
            noise_power: 0.0,
            ..physics(&sc)
        };
        // The amplitude of 9 dB over the preset's noise power (this `p` has none).
        let a = physics(&sc).amplitude(9.0);
        let power = a * a;
        let mut rng = Rng::seed_from_u64(3);
        let mut cube = Vec::new();
        render(
            &p,
            a,
            &[target(&sc, [50.0, 85.0, 45.0])],
            &mut rng,
            &mut cube,
        );
        assert_eq!(cube.len(), sc.geometry().len());
        let total: f64 = cube.iter().map(|&z| f64::from(z)).sum();
        let peak = f64::from(cube[idx(&sc, 50, 85, 45)]);
        assert!((peak - power).abs() < 1e-6 * power, "{peak} vs {power}");
        assert!((total - power).abs() < 1e-6 * power, "{total} vs {power}");

        render(
            &p,
            a,
            &[target(&sc, [50.25, 85.0, 45.0])],
            &mut rng,
            &mut cube,
        );
        for i in 42..=58usize {
            let want = power * sinc(i as f64 - 50.25).powi(2);
            let got = f64::from(cube[idx(&sc, i, 85, 45)]);
            assert!(
                (got - want).abs() < 1e-6 * power,
                "cell {i}: {got} vs {want}"
            );
        }
        // Beyond the reach of 8 cells, nothing.
        assert_eq!(cube[idx(&sc, 59, 85, 45)], 0.0);
        assert_eq!(cube[idx(&sc, 41, 85, 45)], 0.0);

        let far = target(&sc, [25.0, 85.0, 45.0]);
        render(
            &p,
            a,
            &[target(&sc, [50.0, 85.0, 45.0]), far],
            &mut rng,
            &mut cube,
        );
        let total: f64 = cube.iter().map(|&z| f64::from(z)).sum();
        assert!((total - 2.0 * power).abs() < 1e-5 * power, "{total}");
        assert!((f64::from(cube[idx(&sc, 25, 85, 45)]) - power).abs() < 1e-6 * power);
    }

    /// With noise, the physics cube's noise cells are exponential with mean
    /// `P_n = 2 sigma^2`, the model cube's mean: over the 1.917 M cells of one
    /// noise-only frame the mean's relative std is 1 / sqrt(1.917e6) = 0.07 %
    /// (tolerance 0.5 %).
    #[test]
    fn the_noise_power_is_the_models() {
        let sc = SixTargets::new(9.0);
        let mut rng = Rng::seed_from_u64(8);
        let mut cube = Vec::new();
        Renderer::new(Cubes::Physics, &sc).frame(&sc, &[], &mut rng, &mut cube);
        let mean = cube.iter().map(|&z| f64::from(z)).sum::<f64>() / cube.len() as f64;
        assert!((mean - 2.0 * sc.noise_var).abs() < 0.005 * 2.0, "{mean}");
    }
}

#[cfg(test)]
mod relation {
    use crate::physics::cubes::{sinc, REACH};

    /// Means over the sub-cell offset `u` (uniform in `[-1/2, 1/2]`, 10 001 points) of
    /// one axis' `f(u)`.
    fn mean(f: impl Fn(f64) -> f64) -> f64 {
        let n = 10_000;
        (0..=n).map(|k| f(-0.5 + k as f64 / n as f64)).sum::<f64>() / (n + 1) as f64
    }

    /// The numbers docs/phd.md relates the two cubes by, from the responses themselves
    /// (the axes' factors are independent, so a three-axis mean is the cube of one axis'
    /// mean; a target `u` cells from its cell's centre, the model's `h_i = exp(-(i -
    /// u)^2 / 2)` on its 3 cells `i = -1, 0, 1`, the sinc `S(i - u)` on 17):
    /// - the model's energy `sum h^2` over the peak power at a cell centre: 5.02
    ///   (+7.0 dB); the sinc's `sum S^2` is 1 less what lies beyond 8 cells: 0.965
    ///   (-0.15 dB), so equal energy is 7.2 dB more peak SNR on the physics cubes;
    /// - the sinc's peak-cell power, `max_i S(i - u)^2`: 0.463 (-3.34 dB, the straddle
    ///   loss);
    /// - the intensity of the one-cell response that fits the sinc response best in
    ///   least squares on the filter's 27 cells, `(sum h S / sum h^2)^2`: 0.045 of the
    ///   target power (-13.5 dB), the `--filter-intensity-db -13.5` of the ablation.
    ///
    /// Run with `--nocapture` to print them; the bounds are their printed values
    /// rounded (a quadrature of 10 001 points is exact to far better than 1e-3 here).
    #[test]
    fn the_energy_straddle_and_fitted_intensity() {
        let cells = [-1.0, 0.0, 1.0];
        let h = |i: f64, u: f64| (-0.5 * (i - u) * (i - u)).exp();
        let energy = mean(|u| cells.iter().map(|&i| h(i, u).powi(2)).sum()).powi(3);
        let sinc_energy =
            mean(|u| (-REACH..=REACH).map(|i| sinc(i as f64 - u).powi(2)).sum()).powi(3);
        let peak = mean(|u| {
            (-1..=1)
                .map(|i| sinc(i as f64 - u).powi(2))
                .fold(0.0, f64::max)
        })
        .powi(3);
        let fit = mean(|u| {
            let hs: f64 = cells.iter().map(|&i| h(i, u) * sinc(i - u)).sum();
            let hh: f64 = cells.iter().map(|&i| h(i, u).powi(2)).sum();
            (hs / hh).powi(2)
        })
        .powi(3);
        let db = |x: f64| 10.0 * x.log10();
        eprintln!(
            "model energy {energy:.3} ({:.2} dB), sinc energy {sinc_energy:.3}, sinc peak {peak:.3} ({:.2} dB), fitted intensity {fit:.4} ({:.2} dB)",
            db(energy),
            db(peak),
            db(fit)
        );
        assert!((energy - 5.02).abs() < 0.005, "{energy}");
        assert!((sinc_energy - 0.965).abs() < 0.001, "{sinc_energy}");
        assert!((peak - 0.463).abs() < 0.001, "{peak}");
        assert!((db(fit) + 13.5).abs() < 0.05, "{fit}");
    }
}
