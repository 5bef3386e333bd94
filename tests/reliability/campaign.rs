//! The fuzz corpus replayed, and a short campaign over every detector (the CI smoke run;
//! the full campaigns are `faint fuzz`, see docs/reliability.md).

use faint::host::reliability::cli::{fuzz_all, FuzzArgs};
use faint::host::reliability::frames::{complex, plots, reals, Mode};
use faint::host::reliability::{mutate, replay, Finding};
use faint::rng::Rng;

#[test]
fn corpus_replays_clean() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/reliability/corpus");
    let mut n = 0;
    for e in std::fs::read_dir(dir).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_none_or(|x| x != "json") {
            continue;
        }
        let f: Finding = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let t = replay(&f).unwrap();
        assert_eq!(t.cases, 1);
        // A slow step is a wall-clock reading, not asserted in a test: the bound on the
        // work of each slow finding has its own deterministic test in `findings.rs`.
        let failures = t.failures() - t.slow;
        assert_eq!(failures, 0, "{}: {:?}", path.display(), t.findings);
        n += 1;
    }
    assert!(n > 0, "the corpus is empty");
}

/// 48 cases of 8 frames per detector, seed 11: about 5000 frames in all, which covers
/// every frame mode and, across the detectors, a few hundred accepted mutated
/// configurations; any finding but a slow step (a wall-clock reading, not asserted)
/// fails the test with its case.
#[test]
fn smoke_campaign_finds_nothing() {
    let args = FuzzArgs {
        detectors: vec!["all".into()],
        cases: 48,
        frames_per_case: 8,
        seed: 11,
        first: 0,
        out: "unused".into(),
        input: None,
    };
    let tallies = fuzz_all(&args).unwrap();
    assert_eq!(tallies.len(), 14);
    for t in &tallies {
        assert_eq!(t.cases, 48, "{}", t.detector);
        assert!(t.frames > 0, "{}: no configuration accepted", t.detector);
        assert_eq!(
            t.failures() - t.slow,
            0,
            "{}: {:#?}",
            t.detector,
            t.findings
        );
    }
    // The campaign exercises rejections as well as acceptances.
    assert!(tallies.iter().all(|t| t.rejected_config > 0));
    assert!(tallies.iter().map(|t| t.rejected_frames).sum::<u64>() > 100);
}

#[test]
fn campaign_is_deterministic() {
    let args = FuzzArgs {
        detectors: vec!["crpf".into(), "mht".into()],
        cases: 8,
        frames_per_case: 4,
        seed: 3,
        first: 5,
        out: "unused".into(),
        input: None,
    };
    let a = fuzz_all(&args).unwrap();
    let b = fuzz_all(&args).unwrap();
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(
            (x.frames, x.rejected_frames, x.rejected_config),
            (y.frames, y.rejected_frames, y.rejected_config)
        );
    }
}

#[test]
fn generators_draw_every_mode() {
    let mut rng = Rng::seed_from_u64(1);
    let mut seen = std::collections::BTreeSet::new();
    for _ in 0..200 {
        seen.insert(Mode::draw(&mut rng).name());
    }
    assert_eq!(seen.len(), Mode::ALL.len());
    for m in Mode::ALL {
        let r = reals(&mut rng, 100, m, 1.0, true);
        let c = complex(&mut rng, 32, m, 1.0);
        assert_eq!(m == Mode::WrongLength, r.len() != 100, "{m:?}");
        assert_eq!(m == Mode::WrongLength, c.len() != 32, "{m:?}");
        if m == Mode::OneBad {
            assert_eq!(r.iter().filter(|v| !v.is_finite()).count(), 1);
        }
        let _ = plots(&mut rng, [0.0, 1.0, 0.0, 1.0], 16, m);
    }
    let mut v = serde_json::json!({"x": 1.0});
    let changed = mutate::mutate(&mut v, &mut rng);
    assert!(!changed.is_empty() && changed.iter().all(|p| p == "/x"));
}
