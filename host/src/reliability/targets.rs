//! The detectors a campaign drives: every entry of `faint detect --list`, built with the
//! host's capacities and the preset configuration, each with its frame generator.
//!
//! The PSO-PHD-TBD cube is shrunk for the campaign (30 x 30 x 20 cells over the preset's
//! extent instead of 142 x 150 x 90) so that a case costs milliseconds; the arithmetic
//! the campaign probes is the same at any size.

use anyhow::{bail, Result};
use faint_core::detect::cbmember::CbmemberConfig;
use faint_core::detect::crpf::{CrpfConfig, CrpfTbd};
use faint_core::detect::dp::{DpConfig, Method};
use faint_core::detect::jott::JottTbd;
use faint_core::detect::mht::MhtConfig;
use faint_core::detect::pf_lrt::PfLrt;
use faint_core::detect::pf_tbd::{GaussConfig, PfTbd};
use faint_core::detect::phd::PhdConfig;
use faint_core::detect::Detector;
use faint_core::model::range_doppler::PointModel;
use faint_core::rng::Rng;
use faint_golden::soak::{
    cbmember_reduced, cube_cells, CLASSIC_PLOTS, DP_SCALE, PHD_REDUCED_CELLS,
};
use serde::Serialize;
use serde_json::Value;

use super::frames::{self, complex, len_or_short, plots, reals, Mode};
use super::soak::{soak, Shape, Soak, WorkCounters};
use super::{fuzz, Options, Tally, Target};
use crate::detect::default_classic;
use crate::instances::boxed;
use crate::instances::cbmember::HostFilter as CbmemberHost;
use crate::instances::mht::{Classic, Mht, PLOTS as MHT_PLOTS};
use crate::instances::phd::HostFilter as PhdHost;
use crate::simulate::dp::{self as sdp, SIDE};
use crate::simulate::phd::{SixTargets, Variant};

/// Particles of the particle-filter detectors in a campaign (the smallest host size).
pub const PARTICLES: usize = 1000;

/// Names of every detector a campaign can drive: those of `faint detect --list`
/// ([`crate::detect::REGISTRY`]), in its order.
pub fn names() -> impl Iterator<Item = &'static str> {
    crate::detect::REGISTRY.iter().map(|e| e.name)
}

/// Largest frame a generator draws; a configuration asking for more gets wrong-length
/// frames (what the detector must reject).
const MAX_FRAME: usize = 1 << 22;

fn to_value<C: Serialize>(c: &C) -> Value {
    serde_json::to_value(c).unwrap_or(Value::Null)
}

fn doppler_crpf(rng: &mut Rng, c: &CrpfConfig, mode: Mode) -> Vec<faint_core::Complex32> {
    complex(rng, len_or_short(Some(c.model.bins), MAX_FRAME), mode, 1.0)
}

fn doppler_gauss(rng: &mut Rng, c: &GaussConfig, mode: Mode) -> Vec<faint_core::Complex32> {
    complex(rng, len_or_short(Some(c.model.bins), MAX_FRAME), mode, 1.0)
}

fn scan_mht(rng: &mut Rng, c: &MhtConfig, mode: Mode) -> Vec<faint_core::model::plot::Plot> {
    plots(rng, c.area, MHT_PLOTS, mode)
}

fn scan_classic(
    rng: &mut Rng,
    c: &faint_core::detect::mht::ClassicHoughConfig,
    mode: Mode,
) -> Vec<faint_core::model::plot::Plot> {
    plots(rng, c.area, CLASSIC_PLOTS, mode)
}

fn cube(rng: &mut Rng, c: &PhdConfig, mode: Mode) -> Vec<f32> {
    frames::cube(rng, c, mode, MAX_FRAME)
}

fn map(rng: &mut Rng, c: &CbmemberConfig, mode: Mode) -> Vec<f32> {
    frames::map(rng, c, mode, MAX_FRAME)
}

fn image(rng: &mut Rng, _c: &DpConfig, mode: Mode) -> Vec<f32> {
    reals(rng, SIDE * SIDE, mode, DP_SCALE, false)
}

/// The PSO-PHD-TBD preset on a 30 x 30 x 20 cube over the same extent.
pub fn small_phd(v: Variant) -> PhdConfig {
    let mut c = SixTargets::new(9.0).config(v);
    c.geometry = cube_cells(c.geometry, [30, 30, 20]);
    c
}

/// [`Shape::Reduced`]'s PHD-TBD / PSO-PHD-TBD: an 8 x 8 x 4 cube over the preset's
/// extent ([`PHD_REDUCED_CELLS`]), 50 particles per target, 25 births (and at least 25
/// particles), at most 32 particles in the swarm.
pub fn reduced_phd(v: Variant) -> PhdConfig {
    let mut c = SixTargets::new(9.0).config(v);
    c.geometry = cube_cells(c.geometry, PHD_REDUCED_CELLS);
    c.particles_per_target = 50;
    c.birth.particles = 25;
    c.min_particles = 25;
    if let Some(p) = c.pso.as_mut() {
        p.max_members = 32;
    }
    c
}

/// The CBMeMBer preset (`model`), and in [`Shape::Reduced`] on a 32 x 64 map over the
/// preset's extent with `L_max = 100`, `L_min = 30` and 30 birth particles
/// ([`cbmember_reduced`], the firmware soak's configuration).
pub fn cbmember_config(model: PointModel, shape: Shape) -> CbmemberConfig {
    match shape {
        Shape::Reduced => cbmember_reduced(model),
        Shape::Preset => CbmemberConfig {
            model,
            ..CbmemberConfig::rotor_uav()
        },
    }
}

/// Side of [`Shape::Reduced`]'s DP-TBD images.
pub use faint_core::detect::dp::preset::REDUCED_SIDE;
use faint_core::detect::dp::preset::{
    Arnold9Reduced as Arnold32, Pulford9Reduced as Pulford32, Second9Reduced as Second32,
};

fn image_reduced(rng: &mut Rng, _c: &DpConfig, mode: Mode) -> Vec<f32> {
    reals(rng, REDUCED_SIDE * REDUCED_SIDE, mode, DP_SCALE, false)
}

/// Two detectors configured with `cfg` (seed 0), on the heap.
fn pair<D: Detector>(cfg: &D::Config) -> Result<(Box<D>, Box<D>)> {
    Ok((boxed::<D>(cfg, 0)?, boxed::<D>(cfg, 0)?))
}

/// What to do with a detector.
#[derive(Debug, Clone, Copy)]
pub enum Job {
    /// A fuzz campaign.
    Fuzz(Options),
    /// A soak run: frames, seed, configuration size.
    Soak(u64, u64, Shape),
}

/// What a [`Job`] measured.
#[derive(Debug, Clone)]
pub enum Outcome {
    /// Of [`Job::Fuzz`].
    Fuzz(Tally),
    /// Of [`Job::Soak`].
    Soak(Soak),
}

fn go<D, T>(
    name: &'static str,
    base: Value,
    frame: fn(&mut Rng, &D::Config, Mode) -> Vec<T>,
    (mut a, mut b): (Box<D>, Box<D>),
    job: &Job,
) -> Outcome
where
    D: Detector<Frame = [T]> + ?Sized,
    D::Config: Serialize + serde::de::DeserializeOwned,
    D::Report: std::fmt::Debug + WorkCounters,
{
    let t = Target { name, base, frame };
    match *job {
        Job::Fuzz(opts) => Outcome::Fuzz(fuzz(&t, a.as_mut(), b.as_mut(), &opts)),
        Job::Soak(frames, seed, shape) => Outcome::Soak(soak(&t, a.as_mut(), frames, seed, shape)),
    }
}

fn boxed2<D: faint_core::detect::dp::DpTrack>(c: &DpConfig) -> Result<(Box<D>, Box<D>)> {
    Ok((sdp::boxed::<D>(c)?, sdp::boxed::<D>(c)?))
}

/// Runs `job` on the detector `name` (one of [`names`]).
pub fn run(name: &str, job: Job) -> Result<Outcome> {
    let name: &'static str = crate::detect::find(name)?.name;
    let reduced = matches!(job, Job::Soak(_, _, Shape::Reduced));
    // Two detectors are built by value (the host filters are large): on a worker stack.
    crate::montecarlo::on_worker_stack(move || {
        let o = &job;
        Ok(match name {
            "crpf" => {
                let c = CrpfConfig::othr();
                go(
                    name,
                    to_value(&c),
                    doppler_crpf,
                    pair::<CrpfTbd<PARTICLES>>(&c)?,
                    o,
                )
            }
            "pf-tbd" | "jott" | "pf-lrt" => {
                let c = GaussConfig::othr(1.0);
                match name {
                    "pf-tbd" => go(
                        name,
                        to_value(&c),
                        doppler_gauss,
                        pair::<PfTbd<PARTICLES>>(&c)?,
                        o,
                    ),
                    "jott" => go(
                        name,
                        to_value(&c),
                        doppler_gauss,
                        pair::<JottTbd<PARTICLES>>(&c)?,
                        o,
                    ),
                    _ => go(
                        name,
                        to_value(&c),
                        doppler_gauss,
                        pair::<PfLrt<PARTICLES>>(&c)?,
                        o,
                    ),
                }
            }
            "mht" => {
                let c = MhtConfig::sea_clutter();
                go(name, to_value(&c), scan_mht, pair::<Mht>(&c)?, o)
            }
            "hough-classic" => {
                let c = default_classic();
                go(name, to_value(&c), scan_classic, pair::<Classic>(&c)?, o)
            }
            "phd-tbd" | "pso-phd-kmeans" | "pso-phd-dbscan" => {
                let v = match name {
                    "phd-tbd" => Variant::PhdTbd,
                    "pso-phd-kmeans" => Variant::PsoKMeans,
                    _ => Variant::PsoDbscan,
                };
                let c = if reduced {
                    reduced_phd(v)
                } else {
                    small_phd(v)
                };
                go(name, to_value(&c), cube, pair::<PhdHost>(&c)?, o)
            }
            "cbmember" | "cbmember-doppler" => {
                let model = if name == "cbmember" {
                    PointModel::Joint
                } else {
                    PointModel::DopplerOnly
                };
                let shape = if reduced {
                    Shape::Reduced
                } else {
                    Shape::Preset
                };
                let c = cbmember_config(model, shape);
                go(name, to_value(&c), map, pair::<CbmemberHost>(&c)?, o)
            }
            "dp-arnold" | "dp-pulford" | "dp-second" => {
                let m = match name {
                    "dp-arnold" => Method::Arnold,
                    "dp-pulford" => Method::Pulford,
                    _ => Method::SecondOrder,
                };
                let c = DpConfig::dim_point(m, 1);
                match (m, reduced) {
                    (Method::Arnold, true) => go(
                        name,
                        to_value(&c),
                        image_reduced,
                        boxed2::<Arnold32>(&c)?,
                        o,
                    ),
                    (Method::Pulford, true) => go(
                        name,
                        to_value(&c),
                        image_reduced,
                        boxed2::<Pulford32>(&c)?,
                        o,
                    ),
                    (_, true) => go(
                        name,
                        to_value(&c),
                        image_reduced,
                        boxed2::<Second32>(&c)?,
                        o,
                    ),
                    _ => match m {
                        Method::Arnold => {
                            go(name, to_value(&c), image, boxed2::<sdp::Arnold9>(&c)?, o)
                        }
                        Method::Pulford => {
                            go(name, to_value(&c), image, boxed2::<sdp::Pulford9>(&c)?, o)
                        }
                        _ => go(name, to_value(&c), image, boxed2::<sdp::Second9>(&c)?, o),
                    },
                }
            }
            other => bail!("unknown detector '{other}'"),
        })
    })
}

#[cfg(test)]
mod tests {
    //! The firmware's soak (`firmware/src/bin/soak.rs`) streams its detectors the frames
    //! of `faint_golden::soak` with that module's sizes and seed; the host's soak draws
    //! them through this file's generators from its own configurations and instance
    //! sizes. These tests check that both draw the same frames bit for bit, i.e. that
    //! the target soaks what the host soaks.
    use super::*;
    use faint_core::model::plot::Plot;
    use faint_core::Complex32;
    use faint_golden::soak as fw;

    /// Frames compared per detector: every branch of the scan-count law (one in 8) and
    /// the strong-return draw (one value in 8) occur many times in 40 frames.
    const FRAMES: usize = 40;

    /// Draws `FRAMES` frames with the host's `host` and the firmware's `target` from one
    /// seed each and compares their bits.
    fn same<T: Copy + Default, const B: usize>(
        name: &str,
        host: impl Fn(&mut Rng) -> Vec<T>,
        target: impl Fn(&mut Rng, &mut [T]) -> usize,
        bits: impl Fn(&T) -> [u32; 3],
    ) {
        let (mut h, mut t) = (Rng::seed_from_u64(fw::SEED), Rng::seed_from_u64(fw::SEED));
        let mut buf = vec![T::default(); B];
        for k in 0..FRAMES {
            let a = host(&mut h);
            let n = target(&mut t, &mut buf);
            let (a, b): (Vec<_>, Vec<_>) = (
                a.iter().map(&bits).collect(),
                buf[..n].iter().map(&bits).collect(),
            );
            assert_eq!(a, b, "{name}: frame {k} differs between host and firmware");
        }
    }

    fn real(x: &f32) -> [u32; 3] {
        [x.to_bits(), 0, 0]
    }

    fn bin(z: &Complex32) -> [u32; 3] {
        [z.re.to_bits(), z.im.to_bits(), 0]
    }

    fn plot(p: &Plot) -> [u32; 3] {
        [p.amplitude.to_bits(), p.x.to_bits(), p.y.to_bits()]
    }

    #[test]
    fn doppler_frames_are_the_firmware_soaks() {
        let crpf = CrpfConfig::othr();
        let gauss = GaussConfig::othr(1.0);
        let target = |r: &mut Rng, o: &mut [Complex32]| fw::complex(r, o, 1.0);
        same::<_, { fw::DOPPLER_BINS }>(
            "crpf",
            |r| doppler_crpf(r, &crpf, Mode::Plausible),
            target,
            bin,
        );
        same::<_, { fw::DOPPLER_BINS }>(
            "pf-tbd, jott, pf-lrt",
            |r| doppler_gauss(r, &gauss, Mode::Plausible),
            target,
            bin,
        );
    }

    #[test]
    fn scans_are_the_firmware_soaks() {
        let mht = MhtConfig::sea_clutter();
        same::<_, { 2 * fw::MHT_PLOTS + 1 }>(
            "mht",
            |r| scan_mht(r, &mht, Mode::Plausible),
            |r, o| fw::plots(r, mht.area, fw::MHT_PLOTS, o),
            plot,
        );
        // The firmware cannot compute the classic threshold (the host's binomial strip
        // model): it carries the value, which must be the host's.
        let classic = default_classic();
        assert_eq!(
            (classic.area, classic.n_scans, classic.gamma),
            (fw::CLASSIC.area, fw::CLASSIC.n_scans, fw::CLASSIC.gamma)
        );
        same::<_, { 2 * fw::CLASSIC_PLOTS + 1 }>(
            "hough-classic",
            |r| scan_classic(r, &classic, Mode::Plausible),
            |r, o| fw::plots(r, fw::CLASSIC.area, fw::CLASSIC_PLOTS, o),
            plot,
        );
    }

    #[test]
    fn reduced_frames_are_the_firmware_soaks() {
        const CELLS: usize =
            fw::PHD_REDUCED_CELLS[0] * fw::PHD_REDUCED_CELLS[1] * fw::PHD_REDUCED_CELLS[2];
        for v in [Variant::PhdTbd, Variant::PsoKMeans, Variant::PsoDbscan] {
            let c = reduced_phd(v);
            same::<_, CELLS>(
                "phd (reduced)",
                |r| cube(r, &c, Mode::Plausible),
                |r, o| fw::reals(r, o, 1.0, true),
                real,
            );
        }
        const PIXELS: usize = fw::CBMEMBER_REDUCED_PIXELS[0] * fw::CBMEMBER_REDUCED_PIXELS[1];
        for model in [PointModel::Joint, PointModel::DopplerOnly] {
            let c = cbmember_config(model, Shape::Reduced);
            same::<_, PIXELS>(
                "cbmember (reduced)",
                |r| map(r, &c, Mode::Plausible),
                |r, o| fw::reals(r, o, 1.0, true),
                real,
            );
        }
        let dp = DpConfig::dim_point(Method::Arnold, 1);
        let target = |r: &mut Rng, o: &mut [f32]| fw::reals(r, o, fw::DP_SCALE, false);
        same::<_, { fw::DP_SIDE * fw::DP_SIDE }>(
            "dp-arnold",
            |r| image(r, &dp, Mode::Plausible),
            target,
            real,
        );
        same::<_, { fw::DP_REDUCED_SIDE * fw::DP_REDUCED_SIDE }>(
            "dp-pulford, dp-second (reduced)",
            |r| image_reduced(r, &dp, Mode::Plausible),
            target,
            real,
        );
    }
}
