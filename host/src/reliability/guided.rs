//! Coverage-guided fuzzing: the bytes of one libFuzzer input (the `fuzz/` crate, built
//! with cargo-fuzz on a nightly toolchain) decide a configuration and a sequence of
//! events, and every step is checked against the promise of the core. The decoding and
//! the checks live here, on the stable toolchain, so that `cargo test` replays a
//! fuzzer's reproducer byte for byte (`tests/reliability`).
//!
//! Decoding, through [`arbitrary::Unstructured`] (an exhausted input reads as zeros, so
//! a short input is the preset with plausible frames):
//!
//! 1. a base configuration (the preset, or a preset variant with another enum arm), then
//!    0 to 4 leaf edits on its serde tree: any number or flag is replaced by raw bits
//!    (NaN, infinities and subnormals included), an extreme, a power-of-ten rescale, a
//!    negation, a neighbour (a few ULPs or a few counts away) or a small value; the
//!    result goes through the configuration's own `configure` (hence `validate`);
//! 2. the detector's seed;
//! 3. events until the input ends (at most [`Spec::max_events`]): a frame (drawn in one
//!    of the seven [`Mode`]s from a seed the input gives, then cut or extended, and
//!    patched at input-chosen positions with input-chosen values), a reconfiguration
//!    (more leaf edits on the current configuration) or a reset.
//!
//! Properties checked after every event (a violation is a [`Failure`]):
//!
//! - no panic (the fuzz build has overflow checks and debug assertions on);
//! - no NaN or infinity in a report or a detection, existences in `[0, 1]`
//!   ([`check_outputs`]);
//! - a rejected frame or configuration leaves the detector unchanged: at the first
//!   rejection a twin is configured with the first configuration and seed and replays
//!   the accepted events; from then on it follows every accepted event, and after each
//!   accepted frame (and on one extra plausible frame at the end of the input) both must
//!   report the same bits ([`twin_check`]). Inputs without a rejection cost one detector.

use std::cell::RefCell;
use std::fmt::{self, Debug};
use std::thread::LocalKey;

use arbitrary::Unstructured;
use faint_core::detect::cbmember::{CbmemberConfig, CbmemberTbd, Likelihood};
use faint_core::detect::crpf::{CrpfConfig, CrpfTbd, Weighting};
use faint_core::detect::dp::{DpConfig, Method, Transition};
use faint_core::detect::jott::JottTbd;
use faint_core::detect::mht::{ClassicHoughConfig, MhtConfig};
use faint_core::detect::pf_lrt::PfLrt;
use faint_core::detect::pf_tbd::{BirthProposal, GaussConfig, PfTbd};
use faint_core::detect::phd::{BirthMode, PhdConfig, SmcPhdTbd};
use faint_core::detect::Detector;
use faint_core::model::doppler::Window;
use faint_core::model::plot::Plot;
use faint_core::model::range_doppler::PointModel;
use faint_core::rng::Rng;
use faint_core::Complex32;
use serde::de::DeserializeOwned;
use serde::Serialize;
use serde_value::Value as Tree;

use super::frames::{self, complex, len_or_short, plots, reals, Mode, BAD, EXTREMES};
use super::mutate::{FLOATS, INTS};
use super::{check_outputs, outputs, twin_check, Kind};
use crate::instances::mht::{Classic, Mht, PLOTS as MHT_PLOTS};
use crate::simulate::dp::fuzz::{
    Arnold25, Arnold9, Pulford25, Pulford9, Second25, Second9, SIDE as DP_SIDE,
};
use crate::simulate::phd::{SixTargets, Variant};

/// What one input did (for the fuzz targets' statistics and the replay tests).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Summary {
    /// The first configuration parsed and `configure` accepted it.
    pub accepted: bool,
    /// Frames stepped.
    pub frames: usize,
    /// Frames rejected with a typed error.
    pub rejected_frames: usize,
    /// Reconfigurations accepted / rejected.
    pub reconfigured: usize,
    /// See [`Summary::reconfigured`].
    pub rejected_configs: usize,
    /// Resets.
    pub resets: usize,
    /// Frames the twin compared (0: no rejection in the input).
    pub compared: usize,
}

/// A property violated by one input.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    /// What went wrong.
    pub kind: Kind,
    /// 0-based event of the input (`None`: at the end-of-input comparison).
    pub event: Option<usize>,
    /// The offending output, or what disagreed.
    pub message: String,
    /// The configuration in use (Debug text).
    pub config: String,
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:?} at event {:?}: {}\nconfiguration: {}",
            self.kind, self.event, self.message, self.config
        )
    }
}

/// One element of a frame that the input can write.
pub trait Element: Clone {
    /// A value from the input: raw bits, an extreme, a NaN/inf or a quarter-step count.
    fn from_input(u: &mut Unstructured<'_>) -> arbitrary::Result<Self>;
}

fn any_f32(u: &mut Unstructured<'_>) -> arbitrary::Result<f32> {
    Ok(match u.int_in_range(0u8..=3)? {
        0 => f32::from_bits(u.arbitrary()?),
        1 => *u.choose(&EXTREMES)?,
        2 => *u.choose(&BAD)?,
        _ => f32::from(u.arbitrary::<i16>()?) * 0.25,
    })
}

impl Element for f32 {
    fn from_input(u: &mut Unstructured<'_>) -> arbitrary::Result<Self> {
        any_f32(u)
    }
}

impl Element for Complex32 {
    fn from_input(u: &mut Unstructured<'_>) -> arbitrary::Result<Self> {
        Ok(Complex32::new(any_f32(u)?, any_f32(u)?))
    }
}

impl Element for Plot {
    fn from_input(u: &mut Unstructured<'_>) -> arbitrary::Result<Self> {
        Ok(Plot::new(any_f32(u)?, any_f32(u)?, any_f32(u)?))
    }
}

/// How one detector is fuzzed.
pub struct Spec<D: Detector + ?Sized, T> {
    /// Detector name (as in `faint detect --list`).
    pub name: &'static str,
    /// Base configurations the input chooses from (the preset first).
    pub bases: Vec<D::Config>,
    /// Draws one frame for a configuration (the generators of [`super::frames`]).
    pub frame: fn(&mut Rng, &D::Config, Mode) -> Vec<T>,
    /// Events per input at most.
    pub max_events: usize,
}

impl<D: Detector + ?Sized, T> Debug for Spec<D, T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Spec").field("name", &self.name).finish()
    }
}

fn count_leaves(v: &Tree) -> usize {
    match v {
        Tree::Seq(s) => s.iter().map(count_leaves).sum(),
        Tree::Map(m) => m.values().map(count_leaves).sum(),
        Tree::Option(Some(x)) | Tree::Newtype(x) => count_leaves(x),
        Tree::Bool(_)
        | Tree::U8(_)
        | Tree::U16(_)
        | Tree::U32(_)
        | Tree::U64(_)
        | Tree::I8(_)
        | Tree::I16(_)
        | Tree::I32(_)
        | Tree::I64(_)
        | Tree::F32(_)
        | Tree::F64(_) => 1,
        _ => 0,
    }
}

/// The `k`-th leaf (in [`count_leaves`] order).
fn nth_leaf<'a>(v: &'a mut Tree, k: &mut usize) -> Option<&'a mut Tree> {
    match v {
        Tree::Seq(s) => s.iter_mut().find_map(|x| nth_leaf(x, k)),
        Tree::Map(m) => m.values_mut().find_map(|x| nth_leaf(x, k)),
        Tree::Option(Some(x)) | Tree::Newtype(x) => nth_leaf(x, k),
        _ if count_leaves(v) == 1 => {
            if *k == 0 {
                Some(v)
            } else {
                *k -= 1;
                None
            }
        }
        _ => None,
    }
}

fn edit_u64(x: u64, u: &mut Unstructured<'_>) -> arbitrary::Result<u64> {
    Ok(match u.int_in_range(0u8..=4)? {
        0 => u.arbitrary()?,
        1 => *u.choose(&INTS)?,
        2 => x.wrapping_add(i64::from(u.arbitrary::<i8>()?) as u64),
        3 => {
            if u.arbitrary()? {
                x.wrapping_mul(2)
            } else {
                x / 2
            }
        }
        _ => u.int_in_range(0..=16)?,
    })
}

fn edit_f32(x: f32, u: &mut Unstructured<'_>) -> arbitrary::Result<f32> {
    Ok(match u.int_in_range(0u8..=6)? {
        0 => f32::from_bits(u.arbitrary()?),
        1 => *u.choose(&FLOATS)? as f32,
        2 => x * 10f32.powi(u.int_in_range(-12..=12)?),
        3 => -x,
        4 => f32::from_bits(
            x.to_bits()
                .wrapping_add(i32::from(u.arbitrary::<i8>()?) as u32),
        ),
        5 => f32::from(u.arbitrary::<i16>()?) * 0.25,
        _ => x * (1.0 + f32::from(u.arbitrary::<i8>()?) / 128.0),
    })
}

fn edit_leaf(v: &Tree, u: &mut Unstructured<'_>) -> arbitrary::Result<Tree> {
    Ok(match *v {
        Tree::Bool(b) => Tree::Bool(!b),
        Tree::U8(x) => Tree::U8(edit_u64(x.into(), u)? as u8),
        Tree::U16(x) => Tree::U16(edit_u64(x.into(), u)? as u16),
        Tree::U32(x) => Tree::U32(edit_u64(x.into(), u)? as u32),
        Tree::U64(x) => Tree::U64(edit_u64(x, u)?),
        Tree::I8(x) => Tree::I8(edit_u64(x as u64, u)? as i8),
        Tree::I16(x) => Tree::I16(edit_u64(x as u64, u)? as i16),
        Tree::I32(x) => Tree::I32(edit_u64(x as u64, u)? as i32),
        Tree::I64(x) => Tree::I64(edit_u64(x as u64, u)? as i64),
        Tree::F32(x) => Tree::F32(edit_f32(x, u)?),
        Tree::F64(x) => Tree::F64(f64::from(edit_f32(x as f32, u)?)),
        ref other => other.clone(),
    })
}

/// `base` with 0 to 4 leaf edits read from `u`; `None` if the result does not parse.
pub fn edit_config<C: Serialize + DeserializeOwned>(
    base: &C,
    u: &mut Unstructured<'_>,
) -> Option<C> {
    let mut tree = serde_value::to_value(base).ok()?;
    let n = count_leaves(&tree);
    let edits = u.int_in_range(0u8..=4).ok()?;
    for _ in 0..edits {
        let mut k = u.choose_index(n).ok()?;
        let leaf = nth_leaf(&mut tree, &mut k)?;
        *leaf = edit_leaf(leaf, u).ok()?;
    }
    tree.deserialize_into().ok()
}

/// One frame for `cfg` as the input describes it.
fn decode_frame<C, T: Element>(
    u: &mut Unstructured<'_>,
    cfg: &C,
    draw: fn(&mut Rng, &C, Mode) -> Vec<T>,
) -> arbitrary::Result<Vec<T>> {
    let mode = *u.choose(&Mode::ALL)?;
    let seed = u.arbitrary::<u32>()?;
    let mut f = draw(&mut Rng::seed_from_u64(seed.into()), cfg, mode);
    match u.int_in_range(0u8..=7)? {
        6 => {
            let n = u.int_in_range(0..=f.len())?;
            f.truncate(n);
        }
        7 => {
            for _ in 0..u.int_in_range(1u8..=4)? {
                f.push(T::from_input(u)?);
            }
        }
        _ => {}
    }
    for _ in 0..u.int_in_range(0u8..=15)? {
        if f.is_empty() {
            break;
        }
        let i = u.choose_index(f.len())?;
        f[i] = T::from_input(u)?;
    }
    Ok(f)
}

/// An accepted event, kept until a twin is needed.
enum Accepted<C, T> {
    Frame(Vec<T>),
    Configure(C, u64),
    Reset(u64),
}

/// Detector pairs a fuzz target keeps: an input runs on the pair whose detector already
/// holds its first configuration (restarted with `reset`, which the core documents as
/// `configure` with the same configuration: it spares the per-configuration tables,
/// e.g. the Doppler response table, of which a Doppler-frame detector's `configure`
/// spends most of an input's time), else on the next pair in turn, configured.
pub const SLOTS: usize = 8;

/// `a` and `b` are the same configuration: the same Debug text (the shortest text that
/// reads back to the same bits; `-0.0` and `0.0` differ; NaN payloads do not count).
fn same<C: Debug>(a: &C, b: &C) -> bool {
    format!("{a:?}") == format!("{b:?}")
}

/// Restarts `d` with `cfg` and `seed`: `reset` if it already holds `cfg`, else `configure`.
fn restart<D: Detector + ?Sized>(d: &mut D, cfg: &D::Config, seed: u64) -> faint_core::Result<()>
where
    D::Config: Debug,
{
    if same(d.config(), cfg) {
        d.reset(seed);
        Ok(())
    } else {
        d.configure(cfg, seed)
    }
}

/// Runs one input on one of `pairs` (a detector and its twin, see [`SLOTS`]).
pub fn run<D, T>(
    spec: &Spec<D, T>,
    pairs: &mut [(Box<D>, Box<D>)],
    data: &[u8],
) -> Result<Summary, Failure>
where
    D: Detector<Frame = [T]> + ?Sized,
    D::Config: Serialize + DeserializeOwned + Debug,
    D::Report: Debug,
    T: Element,
{
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let mut u = Unstructured::new(data);
    let mut s = Summary::default();
    let Ok(base) = u.choose(&spec.bases) else {
        return Ok(s);
    };
    let Some(cfg0) = edit_config(base, &mut u) else {
        return Ok(s);
    };
    let seed0 = u.arbitrary::<u64>().unwrap_or(0);
    if pairs.is_empty() {
        return Ok(s);
    }
    let slot = match pairs.iter().position(|(a, _)| same(a.config(), &cfg0)) {
        Some(i) => i,
        None => NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed) % pairs.len(),
    };
    let (a, b) = &mut pairs[slot];
    let (a, b) = (a.as_mut(), b.as_mut());
    if restart(a, &cfg0, seed0).is_err() {
        return Ok(s);
    }
    s.accepted = true;
    let mut cur = cfg0;
    let mut log: Vec<Accepted<D::Config, T>> = Vec::new();
    let mut twin = false;
    let fail = |kind, event, message: String, cfg: &D::Config| Failure {
        kind,
        event,
        message,
        config: format!("{cfg:?}"),
    };
    // Brings the twin to `a`'s state before the rejection: the first configuration, then
    // every accepted event.
    let start_twin = |b: &mut D, log: &mut Vec<Accepted<D::Config, T>>, event, cur: &D::Config| {
        let problem = |m: &str| Err(fail(Kind::ChangedOnError, Some(event), m.into(), cur));
        if restart(b, &cfg0, seed0).is_err() {
            return problem("the twin rejected the first configuration");
        }
        for e in log.drain(..) {
            match e {
                Accepted::Frame(f) => {
                    if b.step(&f).is_err() {
                        return problem("the twin rejected a frame the detector accepted");
                    }
                }
                Accepted::Configure(c, seed) => {
                    if b.configure(&c, seed).is_err() {
                        return problem("the twin rejected a configuration the detector accepted");
                    }
                }
                Accepted::Reset(seed) => b.reset(seed),
            }
        }
        Ok(())
    };
    for event in 0..spec.max_events {
        if u.is_empty() {
            break;
        }
        let tag = u.arbitrary::<u8>().unwrap_or(0) % 16;
        if tag == 14 {
            let Some(c) = edit_config(&cur, &mut u) else {
                continue;
            };
            let seed = u.arbitrary::<u64>().unwrap_or(0);
            if a.configure(&c, seed).is_ok() {
                s.reconfigured += 1;
                cur = c;
                if !twin {
                    log.push(Accepted::Configure(c, seed));
                } else if b.configure(&c, seed).is_err() {
                    let m = "the twin rejected a configuration the detector accepted";
                    return Err(fail(Kind::ChangedOnError, Some(event), m.into(), &cur));
                }
            } else {
                s.rejected_configs += 1;
                if !twin {
                    start_twin(b, &mut log, event, &cur)?;
                    twin = true;
                }
            }
            continue;
        }
        if tag == 15 {
            let seed = u.arbitrary::<u64>().unwrap_or(0);
            s.resets += 1;
            a.reset(seed);
            if twin {
                b.reset(seed);
            } else {
                log.push(Accepted::Reset(seed));
            }
            continue;
        }
        let Ok(frame) = decode_frame(&mut u, &cur, spec.frame) else {
            break;
        };
        s.frames += 1;
        match a.step(&frame) {
            Err(_) => {
                s.rejected_frames += 1;
                if !twin {
                    start_twin(b, &mut log, event, &cur)?;
                    twin = true;
                }
            }
            Ok(r) => {
                if let Some((kind, m)) = check_outputs(a, &r) {
                    return Err(fail(kind, Some(event), m, &cur));
                }
                if twin {
                    s.compared += 1;
                    if let Some((kind, m)) = twin_check(b, &frame, &outputs(a, &r), true) {
                        return Err(fail(kind, Some(event), m, &cur));
                    }
                } else {
                    log.push(Accepted::Frame(frame));
                }
            }
        }
    }
    if twin {
        // One more plausible frame, so that a rejection at the end of the input is
        // compared too.
        let frame = (spec.frame)(&mut Rng::seed_from_u64(0), &cur, Mode::Plausible);
        let ra = a.step(&frame);
        let rb = b.step(&frame);
        let same = match (&ra, &rb) {
            (Ok(x), Ok(y)) => {
                if let Some((kind, m)) = check_outputs(a, x) {
                    return Err(fail(kind, None, m, &cur));
                }
                s.compared += 1;
                outputs(a, x) == outputs(b, y)
            }
            (Err(x), Err(y)) => x == y,
            _ => false,
        };
        if !same {
            let m = format!("after a rejection, last frame: {ra:?} | twin: {rb:?}");
            return Err(fail(Kind::ChangedOnError, None, m, &cur));
        }
    }
    Ok(s)
}

/// The [`SLOTS`] detector pairs of a target, built once per thread (every input starts
/// from `configure` or `reset`, which restart a detector as a new one would start).
type Pairs<D> = RefCell<Vec<(Box<D>, Box<D>)>>;

fn with_pairs<D: 'static, R>(
    key: &'static LocalKey<Pairs<D>>,
    make: impl Fn() -> Box<D>,
    f: impl FnOnce(&mut [(Box<D>, Box<D>)]) -> R,
) -> R {
    key.with(|p| {
        let mut p = p.borrow_mut();
        while p.len() < SLOTS {
            p.push((make(), make()));
        }
        f(&mut p)
    })
}

/// A detector configured with a fuzz shape's own preset (seed 0), on the heap.
fn preset<D: Detector>(cfg: &D::Config) -> Box<D> {
    match crate::instances::boxed::<D>(cfg, 0) {
        Ok(d) => d,
        Err(e) => panic!("the fuzz shape rejects its own preset: {e}"),
    }
}

fn built<D>(r: faint_core::Result<D>) -> Box<D> {
    match r {
        Ok(d) => Box::new(d),
        Err(e) => panic!("the fuzz shape rejects its own preset: {e}"),
    }
}

// --- The shapes -------------------------------------------------------------------------

/// Particles of the Doppler-frame detectors (CRPF-TBD, PF-TBD, JOTT, PF-LRT).
pub const PARTICLES: usize = 64;

/// Bins per frame of the Doppler-frame detectors' bases (the preset has 32): the
/// response table `configure` builds costs `641 m` double-precision `sincos`, most of an
/// input's time at 32 bins; the loops over bins are the same at 8 (an edit of `bins`
/// still reaches 5..=512 and beyond).
pub const DOPPLER_BINS: usize = 8;

/// Plot capacity of the classic Hough transform (its host value).
pub const CLASSIC_PLOTS: usize = 64;

/// PHD-TBD / PSO-PHD-TBD: particles, swarm entries, points, targets.
pub type Phd = SmcPhdTbd<512, 1024, 10, 16>;
/// PHD cube: range x Doppler x azimuth cells over the preset's extent.
pub const PHD_CUBE: [usize; 3] = [10, 10, 8];

/// CBMeMBer: components, particles per component, block sums.
pub type Cbm = CbmemberTbd<4, 128, 512, [f32]>;
/// CBMeMBer map: range x velocity bins over the preset's extent.
pub const CBM_MAP: [usize; 2] = [32, 64];

/// Largest frame a generator draws (a configuration asking for more gets short frames).
const MAX_FRAME: usize = 1 << 16;

fn doppler<C>(bins: fn(&C) -> usize) -> impl Fn(&mut Rng, &C, Mode) -> Vec<Complex32> {
    move |rng, c, mode| complex(rng, len_or_short(Some(bins(c)), MAX_FRAME), mode, 1.0)
}

fn crpf_frame(rng: &mut Rng, c: &CrpfConfig, mode: Mode) -> Vec<Complex32> {
    doppler(|c: &CrpfConfig| c.model.bins)(rng, c, mode)
}

fn gauss_frame(rng: &mut Rng, c: &GaussConfig, mode: Mode) -> Vec<Complex32> {
    doppler(|c: &GaussConfig| c.model.bins)(rng, c, mode)
}

fn mht_frame(rng: &mut Rng, c: &MhtConfig, mode: Mode) -> Vec<Plot> {
    plots(rng, c.area, MHT_PLOTS, mode)
}

fn classic_frame(rng: &mut Rng, c: &ClassicHoughConfig, mode: Mode) -> Vec<Plot> {
    plots(rng, c.area, CLASSIC_PLOTS, mode)
}

fn phd_frame(rng: &mut Rng, c: &PhdConfig, mode: Mode) -> Vec<f32> {
    frames::cube(rng, c, mode, MAX_FRAME)
}

fn cbm_frame(rng: &mut Rng, c: &CbmemberConfig, mode: Mode) -> Vec<f32> {
    frames::map(rng, c, mode, MAX_FRAME)
}

fn dp_frame(rng: &mut Rng, _c: &DpConfig, mode: Mode) -> Vec<f32> {
    reals(rng, DP_SIDE * DP_SIDE, mode, 1.5, false)
}

/// The CRPF-TBD preset and variants: the shifted weighting (eq. 5), a forgetting factor,
/// the other two windows.
pub fn crpf_bases() -> Vec<CrpfConfig> {
    let mut p = CrpfConfig::othr();
    p.model.bins = DOPPLER_BINS;
    let mut v = vec![p; 5];
    v[1].weighting = Weighting::Shifted { gamma: 0.5 };
    v[2].lambda = 0.5;
    v[3].model.window = Window::Rectangular;
    v[4].model.window = Window::Hann;
    v
}

/// The Gaussian comparators' preset, the other two windows and the fixed-share birth
/// proposal (its share is a leaf the edits reach).
pub fn gauss_bases() -> Vec<GaussConfig> {
    let mut p = GaussConfig::othr(1.0);
    p.model.bins = DOPPLER_BINS;
    let mut v = vec![p; 4];
    v[1].model.window = Window::Rectangular;
    v[2].model.window = Window::Hann;
    v[3].birth = BirthProposal::FixedShare(0.1);
    v
}

/// The MHT-TBD preset and a four-scan period (so that a short input reaches the period
/// end: integration, extraction, association).
pub fn mht_bases() -> Vec<MhtConfig> {
    let p = MhtConfig::sea_clutter();
    let mut short = p;
    short.n_scans = 4;
    short.gamma1 = 3;
    short.min_track_plots = 2;
    vec![p, short]
}

/// The classic Hough preset and a four-scan period.
pub fn classic_bases() -> Vec<ClassicHoughConfig> {
    let p = crate::detect::default_classic();
    let mut short = p;
    short.n_scans = 4;
    short.gamma = 3;
    vec![p, short]
}

/// The PHD preset of `v` on a [`PHD_CUBE`] cube over the same extent, with the particle
/// counts scaled to the [`Phd`] capacity; and the same with Gaussian births.
pub fn phd_bases(v: Variant) -> Vec<PhdConfig> {
    let mut c = SixTargets::new(9.0).config(v);
    let g = &mut c.geometry;
    let (r, d, a) = (
        g.range_cell * g.n_range as f32,
        g.doppler_cell * g.n_doppler as f32,
        g.azimuth_cell_deg * g.n_azimuth as f32,
    );
    [g.n_range, g.n_doppler, g.n_azimuth] = PHD_CUBE;
    g.range_cell = r / PHD_CUBE[0] as f32;
    g.doppler_cell = d / PHD_CUBE[1] as f32;
    g.azimuth_cell_deg = a / PHD_CUBE[2] as f32;
    c.birth.particles = 100;
    c.min_particles = 100;
    c.particles_per_target = 150;
    if let Some(p) = c.pso.as_mut() {
        p.max_members = p.max_members.min(256);
    }
    let mut gauss = c;
    gauss.birth.mode = BirthMode::Gaussian;
    vec![c, gauss]
}

/// The CBMeMBer preset (`model`) on a [`CBM_MAP`] map over the same extent with the
/// particle counts scaled to the [`Cbm`] capacity; the exact likelihood; estimated
/// blade counts.
pub fn cbm_bases(model: PointModel) -> Vec<CbmemberConfig> {
    let mut c = CbmemberConfig {
        model,
        ..CbmemberConfig::rotor_uav()
    };
    let g = &mut c.geometry;
    g.range_bin *= (g.n_range / CBM_MAP[0]) as f32;
    g.velocity_bin *= (g.n_velocity / CBM_MAP[1]) as f32;
    [g.n_range, g.n_velocity] = CBM_MAP;
    c.max_particles = 128;
    c.min_particles = 40;
    c.birth.particles = 40;
    let mut exact = c;
    exact.likelihood = Likelihood::Exact;
    let mut blades = c;
    blades.estimate_blades = true;
    vec![c, exact, blades]
}

/// The DP-TBD preset of `m` (1 px/frame) and the hard transition window.
pub fn dp_bases(m: Method) -> Vec<DpConfig> {
    let c = DpConfig::dim_point(m, 1);
    let mut hard = c;
    hard.transition = Transition::Hard;
    vec![c, hard]
}

macro_rules! thread_pair {
    ($key:ident, $t:ty) => {
        thread_local! { static $key: Pairs<$t> = const { RefCell::new(Vec::new()) }; }
    };
}

thread_pair!(CRPF, CrpfTbd<PARTICLES>);
thread_pair!(PF_TBD, PfTbd<PARTICLES>);
thread_pair!(JOTT, JottTbd<PARTICLES>);
thread_pair!(PF_LRT, PfLrt<PARTICLES>);
thread_pair!(MHT, Mht);
thread_pair!(CLASSIC, Classic);
thread_pair!(PHD, Phd);
thread_pair!(CBM, Cbm);
thread_pair!(ARNOLD9, Arnold9);
thread_pair!(ARNOLD25, Arnold25);
thread_pair!(PULFORD9, Pulford9);
thread_pair!(PULFORD25, Pulford25);
thread_pair!(SECOND9, Second9);
thread_pair!(SECOND25, Second25);

/// Events per input at most.
pub const MAX_EVENTS: usize = 32;

fn spec<D: Detector + ?Sized, T>(
    name: &'static str,
    bases: Vec<D::Config>,
    frame: fn(&mut Rng, &D::Config, Mode) -> Vec<T>,
) -> Spec<D, T> {
    Spec {
        name,
        bases,
        frame,
        max_events: MAX_EVENTS,
    }
}

/// CRPF-TBD on one input.
pub fn crpf(data: &[u8]) -> Result<Summary, Failure> {
    let s = spec("crpf", crpf_bases(), crpf_frame);
    let make = || preset::<CrpfTbd<PARTICLES>>(&crpf_bases()[0]);
    with_pairs(&CRPF, make, |p| run(&s, p, data))
}

/// PF-TBD on one input.
pub fn pf_tbd(data: &[u8]) -> Result<Summary, Failure> {
    let s = spec("pf-tbd", gauss_bases(), gauss_frame);
    let make = || preset::<PfTbd<PARTICLES>>(&gauss_bases()[0]);
    with_pairs(&PF_TBD, make, |p| run(&s, p, data))
}

/// JOTT on one input.
pub fn jott(data: &[u8]) -> Result<Summary, Failure> {
    let s = spec("jott", gauss_bases(), gauss_frame);
    let make = || preset::<JottTbd<PARTICLES>>(&gauss_bases()[0]);
    with_pairs(&JOTT, make, |p| run(&s, p, data))
}

/// PF-LRT on one input.
pub fn pf_lrt(data: &[u8]) -> Result<Summary, Failure> {
    let s = spec("pf-lrt", gauss_bases(), gauss_frame);
    let make = || preset::<PfLrt<PARTICLES>>(&gauss_bases()[0]);
    with_pairs(&PF_LRT, make, |p| run(&s, p, data))
}

/// MHT-TBD (the host's capacities) on one input.
pub fn mht(data: &[u8]) -> Result<Summary, Failure> {
    let s = spec("mht", mht_bases(), mht_frame);
    let make = || preset::<Mht>(&MhtConfig::sea_clutter());
    with_pairs(&MHT, make, |p| run(&s, p, data))
}

/// The classic Hough transform (the host's capacities) on one input.
pub fn hough_classic(data: &[u8]) -> Result<Summary, Failure> {
    // The preset's threshold comes from a binomial tail: computed once.
    static BASES: std::sync::OnceLock<Vec<ClassicHoughConfig>> = std::sync::OnceLock::new();
    let bases = BASES.get_or_init(classic_bases);
    let s = spec("hough-classic", bases.clone(), classic_frame);
    let make = || preset::<Classic>(&bases[0]);
    with_pairs(&CLASSIC, make, |p| run(&s, p, data))
}

fn phd(name: &'static str, v: Variant, data: &[u8]) -> Result<Summary, Failure> {
    let s = spec(name, phd_bases(v), phd_frame);
    let make = || preset::<Phd>(&phd_bases(Variant::PhdTbd)[0]);
    with_pairs(&PHD, make, |p| run(&s, p, data))
}

/// PHD-TBD on one input.
pub fn phd_tbd(data: &[u8]) -> Result<Summary, Failure> {
    phd("phd-tbd", Variant::PhdTbd, data)
}

/// PSO-PHD-TBD with K-means extraction on one input.
pub fn pso_phd_kmeans(data: &[u8]) -> Result<Summary, Failure> {
    phd("pso-phd-kmeans", Variant::PsoKMeans, data)
}

/// PSO-PHD-TBD with DBSCAN extraction on one input.
pub fn pso_phd_dbscan(data: &[u8]) -> Result<Summary, Failure> {
    phd("pso-phd-dbscan", Variant::PsoDbscan, data)
}

fn cbm(name: &'static str, model: PointModel, data: &[u8]) -> Result<Summary, Failure> {
    let s = spec(name, cbm_bases(model), cbm_frame);
    let make = || preset::<Cbm>(&cbm_bases(PointModel::Joint)[0]);
    with_pairs(&CBM, make, |p| run(&s, p, data))
}

/// CBMeMBer (joint model) on one input.
pub fn cbmember(data: &[u8]) -> Result<Summary, Failure> {
    cbm("cbmember", PointModel::Joint, data)
}

/// CBMeMBer (Doppler-only model) on one input.
pub fn cbmember_doppler(data: &[u8]) -> Result<Summary, Failure> {
    cbm("cbmember-doppler", PointModel::DopplerOnly, data)
}

/// The first byte of a DP-TBD input chooses `q_B` (even: 9, odd: 25).
fn dp_split(data: &[u8]) -> (bool, &[u8]) {
    match data.split_first() {
        Some((q, rest)) => (q & 1 == 1, rest),
        None => (false, data),
    }
}

macro_rules! dp_fn {
    ($(#[$doc:meta])* $f:ident, $name:literal, $m:expr, $k9:ident, $t9:ty, $k25:ident, $t25:ty) => {
        $(#[$doc])*
        pub fn $f(data: &[u8]) -> Result<Summary, Failure> {
            let (wide, rest) = dp_split(data);
            let c = DpConfig::dim_point($m, 1);
            if wide {
                let s = spec::<$t25, f32>($name, dp_bases($m), dp_frame);
                with_pairs(&$k25, || built(<$t25>::new(c)), |p| run(&s, p, rest))
            } else {
                let s = spec::<$t9, f32>($name, dp_bases($m), dp_frame);
                with_pairs(&$k9, || built(<$t9>::new(c)), |p| run(&s, p, rest))
            }
        }
    };
}

dp_fn!(
    /// DP-TBD, Arnold's recursion, on one input.
    dp_arnold, "dp-arnold", Method::Arnold, ARNOLD9, Arnold9, ARNOLD25, Arnold25
);
dp_fn!(
    /// DP-TBD, Pulford's recursion, on one input.
    dp_pulford, "dp-pulford", Method::Pulford, PULFORD9, Pulford9, PULFORD25, Pulford25
);
dp_fn!(
    /// DP-TBD, the second-order recursion, on one input.
    dp_second, "dp-second", Method::SecondOrder, SECOND9, Second9, SECOND25, Second25
);

/// A fuzz target's body: one input on one detector.
pub type Target = fn(&[u8]) -> Result<Summary, Failure>;

/// The function of detector `name` (one of `faint detect --list`).
pub fn by_name(name: &str) -> Option<Target> {
    Some(match name {
        "crpf" => crpf,
        "pf-tbd" => pf_tbd,
        "jott" => jott,
        "pf-lrt" => pf_lrt,
        "mht" => mht,
        "hough-classic" => hough_classic,
        "phd-tbd" => phd_tbd,
        "pso-phd-kmeans" => pso_phd_kmeans,
        "pso-phd-dbscan" => pso_phd_dbscan,
        "cbmember" => cbmember,
        "cbmember-doppler" => cbmember_doppler,
        "dp-arnold" => dp_arnold,
        "dp-pulford" => dp_pulford,
        "dp-second" => dp_second,
        _ => return None,
    })
}

/// `data` as lowercase hex (how a [`super::Finding`] stores a guided input).
pub fn to_hex(data: &[u8]) -> String {
    data.iter().map(|b| format!("{b:02x}")).collect()
}

/// The bytes of [`to_hex`]'s text.
pub fn from_hex(s: &str) -> anyhow::Result<Vec<u8>> {
    anyhow::ensure!(s.len().is_multiple_of(2), "odd hex length");
    (0..s.len())
        .step_by(2)
        .map(|i| Ok(u8::from_str_radix(s.get(i..i + 2).unwrap_or("?"), 16)?))
        .collect()
}

/// Runs `data` on detector `name` (on a thread with a large stack, as the campaign
/// does) and returns its finding, if any, in the corpus format ([`super::Finding`]): a
/// panic is caught and reported as [`Kind::Panic`].
pub fn finding(name: &str, data: &[u8]) -> anyhow::Result<Option<super::Finding>> {
    let detector: &'static str = crate::detect::find(name)?.name;
    let f = by_name(detector).ok_or_else(|| anyhow::anyhow!("no guided target '{name}'"))?;
    let hex = to_hex(data);
    let data = data.to_vec();
    let r = crate::montecarlo::on_worker_stack(move || super::catch(|| f(&data)));
    let (kind, message, config) = match r {
        Ok(Ok(_)) => return Ok(None),
        Ok(Err(e)) => (e.kind, e.message, e.config),
        Err(msg) => (Kind::Panic, msg, String::new()),
    };
    Ok(Some(super::Finding {
        detector: detector.to_string(),
        kind,
        seed: 0,
        case: 0,
        frames_per_case: 0,
        frame: None,
        mode: None,
        message,
        mutated: Vec::new(),
        config: serde_json::Value::String(config),
        input: Some(hex),
    }))
}

/// The body of a fuzz target: runs `f` on `data` and panics on a [`Failure`] (libFuzzer
/// then saves the input). The first call checks that overflow checks are on.
pub fn fuzz(f: Target, data: &[u8]) {
    static CHECKED: std::sync::Once = std::sync::Once::new();
    CHECKED.call_once(|| {
        assert!(
            super::overflow_checks_on() && cfg!(debug_assertions),
            "build the fuzz targets with overflow checks and debug assertions on"
        );
    });
    if let Err(e) = f(data) {
        panic!("{e}");
    }
}
