//! The coverage-guided fuzz path (`faint_host::reliability::guided`, driven by the
//! `fuzz/` targets) on the stable toolchain: every detector's fuzz shape accepts its
//! preset, random inputs find nothing, and the checks catch what they are meant to catch.

use faint::detect::dp::{DpConfig, Method};
use faint::detect::{Detection, Detector, ScoreKind};
use faint::host::reliability::frames::reals;
use faint::host::reliability::guided::{self, by_name, run, Spec};
use faint::host::reliability::Kind;
use faint::rng::Rng;
use faint::{Error, Result};

fn names() -> impl Iterator<Item = &'static str> {
    faint::host::detect::REGISTRY.iter().map(|e| e.name)
}

/// Runs `f` on a thread with a 256 MB stack (the host filters are large values).
fn big_stack<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    faint::host::montecarlo::on_worker_stack(f)
}

#[test]
fn every_fuzz_shape_accepts_its_preset() {
    big_stack(|| {
        for name in names() {
            let f = by_name(name).unwrap_or_else(|| panic!("no guided target for {name}"));
            // An empty input is the preset with no event; a one-byte DP input picks q_B.
            for data in [&[][..], &[1u8][..]] {
                let s = f(data).unwrap_or_else(|e| panic!("{name}: {e}"));
                assert!(s.accepted, "{name}: the fuzz shape rejects its preset");
            }
            // A few zero bytes: preset, plausible frames.
            let s = f(&[0u8; 64]).unwrap();
            assert!(s.frames > 0 && s.rejected_frames == 0, "{name}: {s:?}");
        }
    });
}

/// 96 random inputs of up to 384 bytes per detector, seed 12: no finding. (The fuzz
/// campaigns run millions, see docs/reliability.md; this is the CI smoke run.)
#[test]
fn random_inputs_find_nothing() {
    big_stack(|| {
        let mut rng = Rng::seed_from_u64(12);
        let (mut compared, mut rejected, mut accepted) = (0, 0, 0);
        for name in names() {
            let f = by_name(name).unwrap();
            for _ in 0..96 {
                let n = rng.below(385) as usize;
                let data: Vec<u8> = (0..n).map(|_| rng.next_u32() as u8).collect();
                match f(&data) {
                    Ok(s) => {
                        compared += s.compared;
                        rejected += s.rejected_frames + s.rejected_configs;
                        accepted += usize::from(s.accepted);
                    }
                    Err(e) => panic!("{name}: input {}: {e}", guided::to_hex(&data)),
                }
            }
        }
        // The inputs reach accepted configurations, rejections and twin comparisons.
        assert!(accepted > 200, "{accepted}");
        assert!(rejected > 100, "{rejected}");
        assert!(compared > 100, "{compared}");
    });
}

/// A detector that breaks the promises on purpose: an empty frame is rejected after the
/// frame count has advanced, and a frame of exactly 7 values reports NaN.
struct Broken {
    cfg: DpConfig,
    frames: u32,
    last: f32,
}

impl Detector for Broken {
    type Frame = [f32];
    type Config = DpConfig;
    type Report = (u32, f32);
    const STATE: &'static [&'static str] = &["x"];
    const SCORE: ScoreKind = ScoreKind::Merit;
    const UNCONFIGURED: Self = Broken {
        cfg: DpConfig::dim_point(Method::Arnold, 1),
        frames: 0,
        last: 0.0,
    };

    fn configure(&mut self, cfg: &DpConfig, _seed: u64) -> Result<()> {
        self.cfg = *cfg;
        self.frames = 0;
        Ok(())
    }
    fn config(&self) -> &DpConfig {
        &self.cfg
    }
    fn reset(&mut self, _seed: u64) {
        self.frames = 0;
    }
    fn step(&mut self, frame: &[f32]) -> Result<(u32, f32)> {
        self.frames += 1;
        if frame.is_empty() {
            return Err(Error::Empty);
        }
        self.last = if frame.len() == 7 { f32::NAN } else { 0.0 };
        Ok((self.frames, self.last))
    }
    fn detection_count(&self) -> usize {
        1
    }
    fn detection(&self, i: usize) -> Option<Detection> {
        (i == 0).then(|| Detection::new(&[self.frames as f32], 1.0, None))
    }
}

#[test]
fn the_checks_catch_a_state_change_on_error_and_a_nan() {
    let spec: Spec<Broken, f32> = Spec {
        name: "broken",
        bases: vec![DpConfig::dim_point(Method::Arnold, 1)],
        frame: |rng, _c, mode| reals(rng, 16, mode, 1.0, false),
        max_events: 8,
    };
    let new = || Broken::UNCONFIGURED;
    let mut pairs = vec![(Box::new(new()), Box::new(new()))];
    let mut rng = Rng::seed_from_u64(13);
    let mut kinds = std::collections::BTreeSet::new();
    for _ in 0..2000 {
        let n = rng.below(200) as usize;
        let data: Vec<u8> = (0..n).map(|_| rng.next_u32() as u8).collect();
        if let Err(e) = run(&spec, &mut pairs, &data) {
            kinds.insert(format!("{:?}", e.kind));
        }
    }
    assert!(
        kinds.contains(&format!("{:?}", Kind::ChangedOnError)),
        "{kinds:?}"
    );
    assert!(
        kinds.contains(&format!("{:?}", Kind::NonFinite)),
        "{kinds:?}"
    );
}
