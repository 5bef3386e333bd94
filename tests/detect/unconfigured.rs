//! Every detector's `new_unconfigured()` (the one way to build one in place: a `static`
//! on a target, `faint_host::instances` on the host) refuses to work until `configure`
//! succeeds: `step` returns a typed error, `detections` is empty and `reset` keeps it
//! unconfigured; after `configure` it runs exactly as `new` would have built it.

use faint::detect::cbmember::CbmemberTbd;
use faint::detect::crpf::{CrpfConfig, CrpfTbd};
use faint::detect::jott::JottTbd;
use faint::detect::mht::{ClassicHough, ClassicHoughConfig, MhtConfig, MhtTbd};
use faint::detect::pf_lrt::PfLrt;
use faint::detect::pf_tbd::{GaussConfig, PfTbd};
use faint::detect::phd::SmcPhdTbd;
use faint::detect::{Detector, Validate};
use faint::host::instances::{boxed, unconfigured};
use faint::model::plot::Plot;
use faint::Complex32;

/// `step` on frames of the configured detector's shape fails (`must_err`; the classic
/// Hough transform has no unconfigured check), and any step leaves no detection; so
/// after `reset` too. An empty frame matches the empty unconfigured shape of some
/// detectors: it may succeed, doing nothing.
fn refuses<D: Detector>(frames: &[&D::Frame], empty: &D::Frame, must_err: bool) {
    let mut d = unconfigured::<D>();
    for round in 0..2 {
        for f in frames {
            let r = d.step(f);
            assert!(
                !must_err || r.is_err(),
                "{}: round {round}: an unconfigured step succeeded",
                std::any::type_name::<D>()
            );
            assert_eq!(d.detection_count(), 0);
            assert!(d.detection(0).is_none());
        }
        let _ = d.step(empty);
        assert_eq!(d.detections().count(), 0);
        d.reset(7);
    }
}

/// `boxed(cfg, seed)` (unconfigured, then `configure`) reports bit for bit what
/// `new`-built detectors report, frame by frame.
fn same_as_new<D: Detector>(mut by_new: D, cfg: &D::Config, seed: u64, frames: &[&D::Frame])
where
    D::Report: std::fmt::Debug + PartialEq,
{
    assert!(cfg.validate().is_ok());
    let mut b = boxed::<D>(cfg, seed).unwrap();
    for f in frames {
        let (x, y) = (by_new.step(f), b.step(f));
        assert_eq!(format!("{x:?}"), format!("{y:?}"));
        let dx: Vec<_> = by_new.detections().collect();
        let dy: Vec<_> = b.detections().collect();
        assert_eq!(dx, dy);
    }
}

fn doppler_frames() -> Vec<Vec<Complex32>> {
    (0..6)
        .map(|k| {
            (0..32)
                .map(|i| Complex32::new(((i * 7 + k) % 5) as f32, ((i + 3 * k) % 4) as f32))
                .collect()
        })
        .collect()
}

#[test]
fn doppler_detectors() {
    let owned = doppler_frames();
    let frames: Vec<&[Complex32]> = owned.iter().map(|f| f.as_slice()).collect();
    refuses::<CrpfTbd<64>>(&frames, &[], true);
    refuses::<PfTbd<64>>(&frames, &[], true);
    refuses::<JottTbd<64>>(&frames, &[], true);
    refuses::<PfLrt<64>>(&frames, &[], true);
    let c = CrpfConfig::othr();
    let g = GaussConfig::othr(12.7);
    same_as_new(CrpfTbd::<64>::new(c, 3).unwrap(), &c, 3, &frames);
    same_as_new(PfTbd::<64>::new(g, 3).unwrap(), &g, 3, &frames);
    same_as_new(JottTbd::<64>::new(g, 3).unwrap(), &g, 3, &frames);
    same_as_new(PfLrt::<64>::new(g, 3).unwrap(), &g, 3, &frames);
}

#[test]
fn hough_detectors() {
    let scans: Vec<Vec<Plot>> = (0..12)
        .map(|s| {
            (0..20)
                .map(|i| {
                    let (x, y) = ((i * 997 + s * 131) % 6000, (i * 577 + s * 71) % 6000);
                    Plot::new(1.0, x as f32, y as f32)
                })
                .chain([Plot::new(5.0, 1000.0 + 20.0 * s as f32, 2000.0)])
                .collect()
        })
        .collect();
    let frames: Vec<&[Plot]> = scans.iter().map(|s| s.as_slice()).collect();
    refuses::<MhtTbd<32, 12, 64, 45, 8>>(&frames, &[], true);
    let m = MhtConfig {
        area: [0.0, 6000.0, 0.0, 6000.0],
        n_scans: 10,
        gamma1: 6,
        ..MhtConfig::sea_clutter()
    };
    same_as_new(MhtTbd::<32, 12, 64, 45, 8>::new(m).unwrap(), &m, 0, &frames);
    // The classic Hough transform has no unconfigured check: with the all-zero (empty)
    // surveillance area every plot is outside it, so its steps count them as invalid
    // and never detect.
    refuses::<ClassicHough<64, 45, 8>>(&frames, &[], false);
    let c = ClassicHoughConfig {
        area: m.area,
        n_scans: 10,
        gamma: 6,
    };
    same_as_new(ClassicHough::<64, 45, 8>::new(c).unwrap(), &c, 0, &frames);
}

/// (`configure` on them against `new`: `golden/tests/phd_static.rs`,
/// `tests/cbmember/filter.rs`.)
#[test]
fn power_map_detectors() {
    let cube = vec![1.0f32; 8 * 8 * 4];
    refuses::<SmcPhdTbd<64, 16, 2, 2>>(&[&cube[..]], &[], true);
    let map = vec![1.0f32; 32 * 128];
    refuses::<CbmemberTbd<2, 64, 256>>(&[&map[..]], &[], true);
}
