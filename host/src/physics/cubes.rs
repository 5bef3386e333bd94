//! Range x Doppler x azimuth power cubes from the physics: a point target's complex echo,
//! spread by the range, Doppler and azimuth responses, in complex white Gaussian noise.
//!
//! Cube `(R, D, A)` per frame, C order (range, then Doppler, then azimuth); cell `i` of an
//! axis spans `[start + i size, start + (i + 1) size)` with its centre at
//! `start + (i + 0.5) size` (the configuration's `geometry`). A target at range `r`,
//! radial velocity `d` and azimuth `b` sits at the fractional cell coordinates
//!
//! ```text
//! u_r = (r - range_start) / range_cell - 0.5     (integer: a cell centre)
//! u_d = (d - doppler_start) / doppler_cell - 0.5
//! u_b = (b - azimuth_start) / azimuth_cell - 0.5
//! ```
//!
//! and cell `(i, j, l)` holds
//!
//! ```text
//! c_ijl = a_k exp(j phi_k) S(i - u_r) S(j - u_d) S(l - u_b) + w_ijl,   z_ijl = |c_ijl|^2
//! S(u) = sin(pi u) / (pi u)   (S(0) = 1), zero beyond 8 cells from the target's cell
//! ```
//!
//! With [`Response::Gaussian`] the factor of each axis is instead the separable point
//! spread of Pei et al. (2019), eq. 3, in cell units,
//!
//! ```text
//! G(u) = exp(-u^2 / (2 s^2)),   s the axis' standard deviation in cells
//! ```
//!
//! (the paper's loss factor `L` over a cell of size `R` is `L = R / s^2`: eq. 3 writes
//! `(r_i - r)^2 L_r / (2R)`), cut `ceil(6 s)` cells from the target's cell (beyond, the
//! amplitude is below `exp(-18) = 1.5e-8` of the peak).
//!
//! `S` is the response of a resolution-limited axis sampled once per resolution cell
//! (pulse compression in range, the coherent Doppler filter, the aperture in azimuth; the
//! Dirichlet kernel of a long DFT is this sinc). `w` is complex white Gaussian, each of I
//! and Q `N(0, P / 2)`, so a noise cell's power is exponential with mean `P`; `phi_k` is
//! uniform in `[0, 2 pi)`, independent per frame. The Doppler axis is not wrapped: the
//! spread stops at the cube's edges (the target's radial velocity stays inside it).
//!
//! SNR = the peak-cell power over the noise power for a target at a cell centre,
//! `a^2 / P` (there every other cell of the spread gets `S(n) = 0`): the `SNR` of the
//! six-targets preset of Pei et al. (2019), whose intensity `I = a^2` is in units of `P`.
//!
//! Geometry: radar at the origin, azimuth in degrees counter-clockwise from +x,
//! `r = sqrt(x^2 + y^2)`, `b = atan2(y, x)`, radial velocity `d = (x vx + y vy) / r`
//! positive when receding. Motion: constant velocity, `p_k = p_0 + v k dt`. The start is
//! uniform in range and azimuth over the cube's extent, the heading uniform in
//! `[0, 2 pi)` and the speed uniform in `speed`; the draw is repeated until every frame's
//! range, azimuth and radial velocity lie inside the cube (after 10 000 failed draws the
//! target stands still at its last start). Truth columns `x_m,y_m` (m). Amplitude:
//! Swerling 0/1/3, one draw per frame.

use anyhow::{ensure, Result};
use faint_core::rng::Rng;

use super::Swerling;

/// Cells of the sinc spread on each side of the target's cell.
pub const REACH: isize = 8;

/// Largest standard deviation (cells) of a [`Response::Gaussian`] axis.
pub const MAX_GAUSSIAN_STD: f64 = 16.0;

/// The response of every axis to a point target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Response {
    /// `S(u) = sin(pi u) / (pi u)` per axis, cut [`REACH`] cells from the target's cell.
    Sinc,
    /// Eq. 3 of Pei et al. (2019): `exp(-u^2 / (2 s^2))` per axis, `s` = `std` (cells;
    /// range, Doppler, azimuth), cut `ceil(6 s)` cells from the target's cell.
    Gaussian {
        /// Standard deviation per axis (cells): range, Doppler, azimuth.
        std: [f64; 3],
    },
}

impl Response {
    /// Parses `sinc` or `gauss:SR,SD,SB` (standard deviations in cells).
    pub fn parse(s: &str) -> Result<Self> {
        let s = s.trim();
        if s == "sinc" {
            return Ok(Self::Sinc);
        }
        let Some(list) = s.strip_prefix("gauss:") else {
            anyhow::bail!("--cube-spread '{s}': must be 'sinc' or 'gauss:SR,SD,SB' (std in cells)");
        };
        let v: Vec<f64> = list
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| anyhow::anyhow!("--cube-spread '{s}': the three stds must be numbers"))?;
        let std: [f64; 3] = v.try_into().map_err(|_| {
            anyhow::anyhow!("--cube-spread '{s}': give three stds (range, Doppler, azimuth)")
        })?;
        let r = Self::Gaussian { std };
        r.validate()?;
        Ok(r)
    }

    fn validate(&self) -> Result<()> {
        if let Self::Gaussian { std } = self {
            ensure!(
                std.iter()
                    .all(|s| s.is_finite() && *s > 0.0 && *s <= MAX_GAUSSIAN_STD),
                "--cube-spread gauss:{},{},{}: each std must be in (0, {MAX_GAUSSIAN_STD}] cells",
                std[0],
                std[1],
                std[2]
            );
        }
        Ok(())
    }
}

/// `sin(pi u) / (pi u)`, 1 at 0.
pub fn sinc(u: f64) -> f64 {
    if u.abs() < 1e-12 {
        1.0
    } else {
        let x = std::f64::consts::PI * u;
        x.sin() / x
    }
}

/// One axis of the cube: `n` cells of `size` from `start`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    /// Cells.
    pub n: usize,
    /// Lower edge of cell 0.
    pub start: f64,
    /// Cell size.
    pub size: f64,
}

impl Axis {
    /// The end of the last cell.
    pub fn end(&self) -> f64 {
        self.start + self.n as f64 * self.size
    }

    /// The fractional cell coordinate of `v` (an integer at a cell centre).
    pub fn coord(&self, v: f64) -> f64 {
        (v - self.start) / self.size - 0.5
    }

    /// True if `v` lies in `[start, end)`.
    pub fn contains(&self, v: f64) -> bool {
        v >= self.start && v < self.end()
    }

    /// The cells `lo..hi` within the response's reach of the cell holding coordinate `u`,
    /// and their factors: `S(i - u)` (`std = None`) or `exp(-(i - u)^2 / (2 std^2))`.
    fn spread(&self, u: f64, std: Option<f64>) -> AxisSpread {
        let c = u.round() as isize;
        let reach = std.map_or(REACH, |s| (6.0 * s).ceil() as isize);
        let lo = (c - reach).max(0);
        let hi = (c + reach + 1).min(self.n as isize);
        if lo >= hi {
            return (0, Vec::new());
        }
        let f = |i: isize| {
            let d = i as f64 - u;
            match std {
                None => sinc(d),
                Some(s) => (-0.5 * d * d / (s * s)).exp(),
            }
        };
        (lo as usize, (lo..hi).map(f).collect())
    }

    fn validate(&self, name: &str) -> Result<()> {
        ensure!(
            (1..=1 << 16).contains(&self.n),
            "{name}: {} cells, must be in 1..=65536",
            self.n
        );
        ensure!(
            self.start.is_finite() && self.size.is_finite() && self.size > 0.0,
            "{name}: start {} and cell size {} must be finite, the size > 0",
            self.start,
            self.size
        );
        Ok(())
    }
}

/// One axis' spread of an echo: its first cell and the factors from there.
type AxisSpread = (usize, Vec<f64>);

/// The power-cube simulator's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubePhysics {
    /// Range axis (m).
    pub range: Axis,
    /// Radial-velocity axis (m/s, positive receding).
    pub doppler: Axis,
    /// Azimuth axis (deg, counter-clockwise from +x).
    pub azimuth: Axis,
    /// Frame interval `dt` (s).
    pub dt: f64,
    /// Noise power per cell `P = E|w|^2`.
    pub noise_power: f64,
    /// Target speed range (m/s).
    pub speed: (f64, f64),
    /// Amplitude fluctuation.
    pub swerling: Swerling,
    /// Response of each axis to the point target.
    pub response: Response,
}

/// One simulated target's state at a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubeTruth {
    /// Position `[x, y]` (m).
    pub position: [f64; 2],
    /// Velocity `[vx, vy]` (m/s).
    pub velocity: [f64; 2],
    /// Range, radial velocity, azimuth (m, m/s, deg).
    pub radar: [f64; 3],
    /// Amplitude of this frame `a_k`.
    pub amplitude: f64,
}

impl CubePhysics {
    /// Cube axes as given, `dt` 1 s, unit noise power, speed uniform in `[0, 50]` m/s,
    /// Swerling 0, sinc response.
    pub fn new(range: Axis, doppler: Axis, azimuth: Axis) -> Self {
        Self {
            range,
            doppler,
            azimuth,
            dt: 1.0,
            noise_power: 1.0,
            speed: (0.0, 50.0),
            swerling: Swerling::Zero,
            response: Response::Sinc,
        }
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        self.range.validate("range")?;
        self.doppler.validate("doppler")?;
        self.azimuth.validate("azimuth")?;
        self.response.validate()?;
        let cells = self.range.n * self.doppler.n * self.azimuth.n;
        ensure!(
            cells <= 1 << 28,
            "cube of {cells} cells: at most 2^28 per frame"
        );
        ensure!(
            self.range.start >= 0.0,
            "range_start {}: must be >= 0",
            self.range.start
        );
        ensure!(
            self.dt.is_finite() && self.dt > 0.0,
            "dt {}: must be finite and > 0",
            self.dt
        );
        ensure!(
            self.noise_power.is_finite() && self.noise_power >= 0.0,
            "noise power {}: must be finite and >= 0",
            self.noise_power
        );
        ensure!(
            self.speed.0.is_finite()
                && self.speed.1.is_finite()
                && 0.0 <= self.speed.0
                && self.speed.0 <= self.speed.1,
            "speed range {:?}: must be finite, >= 0 and ordered",
            self.speed
        );
        Ok(())
    }

    /// Cells per frame.
    pub fn cells(&self) -> usize {
        self.range.n * self.doppler.n * self.azimuth.n
    }

    /// Amplitude `a` of the SNR `snr_db` (`a^2 / P`, see the module docs).
    pub fn amplitude(&self, snr_db: f64) -> f64 {
        (10f64.powf(snr_db / 10.0) * self.noise_power).sqrt()
    }

    /// Range, radial velocity and azimuth (deg) of a position and velocity.
    pub fn radar(p: [f64; 2], v: [f64; 2]) -> [f64; 3] {
        let r = p[0].hypot(p[1]);
        let d = if r > 1e-9 {
            (p[0] * v[0] + p[1] * v[1]) / r
        } else {
            0.0
        };
        [r, d, p[1].atan2(p[0]).to_degrees()]
    }

    fn inside(&self, q: [f64; 3]) -> bool {
        self.range.contains(q[0]) && self.doppler.contains(q[1]) && self.azimuth.contains(q[2])
    }

    /// Distance in cells between two positions: `sqrt((dr / range_cell)^2 + (db /
    /// azimuth_cell)^2)` with `r`, `b` the range and azimuth of each.
    pub fn cell_distance(&self, a: [f64; 2], b: [f64; 2]) -> f64 {
        let (ra, rb) = (a[0].hypot(a[1]), b[0].hypot(b[1]));
        let mut db = (a[1].atan2(a[0]) - b[1].atan2(b[0])).to_degrees();
        db = (db + 180.0).rem_euclid(360.0) - 180.0;
        ((ra - rb) / self.range.size).hypot(db / self.azimuth.size)
    }

    /// Draws a start and velocity whose path stays inside the cube for `frames` frames.
    fn draw_path(&self, frames: usize, rng: &mut Rng) -> ([f64; 2], [f64; 2]) {
        let u = |rng: &mut Rng| f64::from(rng.uniform());
        let mut last = ([0.0; 2], [0.0; 2]);
        for _ in 0..10_000 {
            let r = self.range.start + self.range.n as f64 * self.range.size * u(rng);
            let b = (self.azimuth.start + self.azimuth.n as f64 * self.azimuth.size * u(rng))
                .to_radians();
            let p = [r * b.cos(), r * b.sin()];
            let hd = 2.0 * std::f64::consts::PI * u(rng);
            let s = self.speed.0 + (self.speed.1 - self.speed.0) * u(rng);
            let v = [s * hd.cos(), s * hd.sin()];
            last = (p, [0.0; 2]);
            let ok = (0..frames.max(1)).all(|k| {
                let t = k as f64 * self.dt;
                self.inside(Self::radar([p[0] + v[0] * t, p[1] + v[1] * t], v))
            });
            if ok {
                return (p, v);
            }
        }
        last
    }

    /// Simulates `frames` cubes (frame-major, `frames * R * D * A` powers); `amplitude =
    /// None` is noise only. Returns the powers and, with a target, its state per frame.
    pub fn simulate(
        &self,
        frames: usize,
        amplitude: Option<f64>,
        rng: &mut Rng,
    ) -> (Vec<f32>, Vec<CubeTruth>) {
        let n = self.cells();
        let path = amplitude.map(|a| (a, self.draw_path(frames, rng)));
        let mut out = Vec::with_capacity(frames * n);
        let mut truth = Vec::new();
        for k in 0..frames {
            let echo = path.map(|(a, (p0, v))| {
                let t = k as f64 * self.dt;
                let p = [p0[0] + v[0] * t, p0[1] + v[1] * t];
                let q = Self::radar(p, v);
                let ak = a * self.swerling.draw(rng);
                truth.push(CubeTruth {
                    position: p,
                    velocity: v,
                    radar: q,
                    amplitude: ak,
                });
                (ak, q)
            });
            self.push_frame(echo.as_slice(), rng, &mut out);
        }
        (out, truth)
    }

    /// One cube of a target at position `p` with velocity `v` and amplitude `a` (before
    /// its Swerling draw), wherever it is (for tests and diagnosis).
    pub fn frame_at(&self, p: [f64; 2], v: [f64; 2], a: f64, rng: &mut Rng) -> Vec<f32> {
        let ak = a * self.swerling.draw(rng);
        let mut out = Vec::with_capacity(self.cells());
        self.push_frame(&[(ak, Self::radar(p, v))], rng, &mut out);
        out
    }

    /// Appends one cube: noise, plus the echo of each `(a_k, q)` of `echoes` (amplitude
    /// `a_k` after its Swerling draw, radar coordinates `q` = range, radial velocity,
    /// azimuth) with a fresh random phase each. The phases are drawn in `echoes` order,
    /// then each cell's noise I and Q, and the echoes add coherently in the cells their
    /// spreads share: several targets in one frame, as in
    /// `faint reproduce phd --cubes physics`.
    pub fn push_frame(&self, echoes: &[(f64, [f64; 3])], rng: &mut Rng, out: &mut Vec<f32>) {
        let (nr, nd, na) = (self.range.n, self.doppler.n, self.azimuth.n);
        let sd = (0.5 * self.noise_power).sqrt();
        let std = match self.response {
            Response::Sinc => [None; 3],
            Response::Gaussian { std } => std.map(Some),
        };
        // Each echo's I and Q and its spread per axis (first cell, factors).
        let echoes: Vec<(f64, f64, [AxisSpread; 3])> = echoes
            .iter()
            .map(|&(ak, q)| {
                let phi = 2.0 * std::f64::consts::PI * f64::from(rng.uniform());
                let s = [
                    self.range.spread(self.range.coord(q[0]), std[0]),
                    self.doppler.spread(self.doppler.coord(q[1]), std[1]),
                    self.azimuth.spread(self.azimuth.coord(q[2]), std[2]),
                ];
                (ak * phi.cos(), ak * phi.sin(), s)
            })
            .collect();
        // The echoes whose spread covers the row, with the row's factor `S_r S_d`.
        let mut row: Vec<(f64, f64, &AxisSpread, f64)> = Vec::new();
        for i in 0..nr {
            for j in 0..nd {
                row.clear();
                row.extend(echoes.iter().filter_map(|(er, ei, s)| {
                    let fr = s[0].1.get(i.checked_sub(s[0].0)?)?;
                    let fd = s[1].1.get(j.checked_sub(s[1].0)?)?;
                    Some((*er, *ei, &s[2], fr * fd))
                }));
                for l in 0..na {
                    let mut re = sd * f64::from(rng.normal());
                    let mut im = sd * f64::from(rng.normal());
                    for &(er, ei, sb, g) in &row {
                        if let Some(fb) = l.checked_sub(sb.0).and_then(|x| sb.1.get(x)) {
                            re += er * g * fb;
                            im += ei * g * fb;
                        }
                    }
                    out.push((re * re + im * im) as f32);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small cube: 24 range cells of 20 m from 500 m, 40 Doppler cells of 1 m/s from
    /// -20 m/s, 16 azimuth cells of 1 deg from 10 deg.
    fn small() -> CubePhysics {
        CubePhysics {
            speed: (0.0, 15.0),
            ..CubePhysics::new(
                Axis {
                    n: 24,
                    start: 500.0,
                    size: 20.0,
                },
                Axis {
                    n: 40,
                    start: -20.0,
                    size: 1.0,
                },
                Axis {
                    n: 16,
                    start: 10.0,
                    size: 1.0,
                },
            )
        }
    }

    /// The cell index of `(i, j, l)`.
    fn idx(p: &CubePhysics, i: usize, j: usize, l: usize) -> usize {
        (i * p.doppler.n + j) * p.azimuth.n + l
    }

    /// Noise only: `|w|^2` is exponential with mean `P`. 60 frames of 15 360 cells: the
    /// mean's relative std is 1/sqrt(921 600) = 0.1 % (tolerance 0.5 %); the exceedance
    /// probabilities `exp(-t)` have std at most 0.0005 (tolerance 0.003).
    #[test]
    fn noise_cell_power_is_exponential_with_mean_p() {
        let p = CubePhysics {
            noise_power: 2.5,
            ..small()
        };
        let mut rng = Rng::seed_from_u64(4);
        let (z, t) = p.simulate(60, None, &mut rng);
        assert!(t.is_empty());
        assert_eq!(z.len(), 60 * p.cells());
        let x: Vec<f64> = z.iter().map(|&v| f64::from(v) / 2.5).collect();
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        assert!((mean - 1.0).abs() < 0.005, "{mean}");
        for th in [0.5, 1.0, 2.0, 4.0] {
            let got = x.iter().filter(|&&v| v > th).count() as f64 / x.len() as f64;
            assert!((got - (-th).exp()).abs() < 0.003, "P(>{th}) = {got}");
        }
    }

    /// Noise off, a target on a cell centre in all three axes: the peak cell holds `a^2`
    /// (the SNR definition, `S(0) = 1`) and every other cell nothing (`S(n) = 0` for
    /// integer `n`; 1e-12 of `a^2` covers the f64 sinc at integers). Half a cell off in
    /// Doppler the two cells either side share it, `S(1/2)^2 = 4 / pi^2` each.
    #[test]
    fn a_cell_centred_target_puts_a_squared_in_one_cell() {
        let p = CubePhysics {
            noise_power: 0.0,
            ..small()
        };
        let mut rng = Rng::seed_from_u64(1);
        let (i, j, l) = (10usize, 24usize, 5usize);
        let r = 710.0;
        let b = 15.5f64.to_radians();
        let pos = [r * b.cos(), r * b.sin()];
        let a = 3.0;
        for (d, cells) in [(4.5, vec![(j, 1.0)]), (4.0, vec![(j - 1, 4.0), (j, 4.0)])] {
            let z = p.frame_at(pos, [d * b.cos(), d * b.sin()], a, &mut rng);
            let total: f64 = z.iter().map(|&v| f64::from(v)).sum();
            let mut want_total = 0.0;
            for (jj, share) in cells {
                let share = if share == 1.0 {
                    1.0
                } else {
                    share / std::f64::consts::PI.powi(2)
                };
                let got = f64::from(z[idx(&p, i, jj, l)]);
                assert!((got - a * a * share).abs() < 1e-5 * a * a, "{d}: {got}");
                want_total += a * a * share;
            }
            if d == 4.5 {
                assert!((total - want_total).abs() < 1e-5 * a * a, "{total}");
            }
        }
    }

    /// With noise at 40 dB, a target drawn anywhere peaks in the cell holding the truth
    /// when the truth lies more than 0.05 cell from every cell boundary (then the cell's
    /// signal amplitude beats its neighbour's by at least `2 * 0.05 * |S'(1/2)| = 0.12`
    /// of the peak `a S S`, `a S S >= 100 * 0.41`: about 5 noise std), and within one
    /// cell on every axis always; the path stays inside the cube at constant velocity.
    #[test]
    fn the_peak_lands_in_the_cell_holding_the_truth() {
        let p = CubePhysics {
            noise_power: 1.0,
            ..small()
        };
        let mut rng = Rng::seed_from_u64(6);
        let a = p.amplitude(40.0);
        let mut exact = 0;
        for _ in 0..40 {
            let (z, t) = p.simulate(3, Some(a), &mut rng);
            for (k, tr) in t.iter().enumerate() {
                let f = &z[k * p.cells()..(k + 1) * p.cells()];
                let best = f
                    .iter()
                    .enumerate()
                    .fold((0, f32::MIN), |b, (i, &v)| if v > b.1 { (i, v) } else { b })
                    .0;
                let (bi, bj, bl) = (
                    best / (p.doppler.n * p.azimuth.n),
                    best / p.azimuth.n % p.doppler.n,
                    best % p.azimuth.n,
                );
                let u = [
                    p.range.coord(tr.radar[0]),
                    p.doppler.coord(tr.radar[1]),
                    p.azimuth.coord(tr.radar[2]),
                ];
                let clear = u.iter().all(|x| (x - x.round()).abs() < 0.45);
                for (got, x) in [bi, bj, bl].iter().zip(u) {
                    let d = (*got as f64 - x.round()).abs();
                    assert!(d <= if clear { 0.0 } else { 1.0 }, "{tr:?} {u:?} {best}");
                }
                exact += usize::from(clear);
                assert!(p.inside(tr.radar), "{tr:?}");
            }
            // Constant velocity.
            let d = [
                t[1].position[0] - t[0].position[0],
                t[2].position[0] - t[1].position[0],
            ];
            assert!((d[0] - d[1]).abs() < 1e-9);
        }
        assert!(exact > 60, "{exact} of 120 clear of the boundaries");
    }

    /// Peak SNR at a cell centre: `E z_peak = a^2 + P`. The target is put on a cell centre
    /// in range and azimuth and on a Doppler centre by its radial velocity (speed chosen
    /// radial); 4000 frames at SNR 10 dB: `z_peak / P` has mean 11 and std
    /// sqrt(1 + 2 * 10) = 4.6 (non-central chi-square, 2 dof, scaled), so the mean's std
    /// is 0.072; tolerance 0.3 (4 std).
    #[test]
    fn a_cell_centred_target_has_the_stated_peak_snr() {
        let p = CubePhysics {
            noise_power: 1.0,
            ..small()
        };
        let mut rng = Rng::seed_from_u64(12);
        let a = p.amplitude(10.0);
        let (i, j, l) = (10usize, 24usize, 5usize);
        let r = p.range.start + (i as f64 + 0.5) * p.range.size;
        let b = (p.azimuth.start + (l as f64 + 0.5) * p.azimuth.size).to_radians();
        let d = p.doppler.start + (j as f64 + 0.5) * p.doppler.size;
        let mut sum = 0.0;
        let n = 4000;
        for _ in 0..n {
            let pos = [r * b.cos(), r * b.sin()];
            let vel = [d * b.cos(), d * b.sin()];
            let z = p.frame_at(pos, vel, a, &mut rng);
            sum += f64::from(z[idx(&p, i, j, l)]);
        }
        let mean = sum / n as f64;
        assert!((mean - 11.0).abs() < 0.3, "{mean}");
    }
}
