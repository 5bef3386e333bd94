//! The `Detector` trait's detections agree with each family's report, after every step
//! (a regression test: CRPF-TBD once reported no detection because its last report was
//! not kept).

use faint::detect::crpf::{CrpfConfig, CrpfTbd};
use faint::detect::jott::JottTbd;
use faint::detect::mht::MhtConfig;
use faint::detect::pf_lrt::PfLrt;
use faint::detect::pf_tbd::{GaussConfig, PfTbd};
use faint::detect::{run, Detector, ScoreKind};
use faint::host::instances::mht::Mht;
use faint::host::simulate::crpf::{Noise, Othr};
use faint::host::simulate::mht::SeaClutter;
use faint::model::doppler::DopplerReport;
use faint::rng::Rng;
use faint::Complex32;

fn check_doppler<D: Detector<Frame = [Complex32], Report = DopplerReport>>(
    det: &mut D,
    frames: &[Vec<Complex32>],
) {
    let mut seen = 0;
    run(det, frames.iter().map(|f| f.as_slice()), |_, det, rep| {
        let dets: Vec<_> = det.detections().collect();
        assert_eq!(dets.len(), det.detection_count());
        assert_eq!(dets.len(), usize::from(rep.estimate.is_some()));
        if let (Some(d), Some(x)) = (dets.first(), rep.estimate) {
            assert_eq!(d.state(), &x[..]);
            let want = match D::SCORE {
                ScoreKind::LogLikelihoodRatio => rep.log_lr,
                _ => rep.existence,
            };
            assert_eq!(d.score.to_bits(), want.to_bits());
            seen += 1;
        }
        assert!(det.detection(dets.len()).is_none());
    })
    .unwrap();
    assert!(seen > 0);
}

#[test]
fn doppler_detections_are_the_reports() {
    let run0 = Othr::default().simulate(Some(12.0), Noise::Gaussian, &mut Rng::seed_from_u64(4));
    let g = GaussConfig::othr(12.7);
    check_doppler(
        &mut *Box::new(CrpfTbd::<1000>::new(CrpfConfig::othr(), 1).unwrap()),
        &run0.frames,
    );
    check_doppler(
        &mut *Box::new(PfTbd::<1000>::new(g, 1).unwrap()),
        &run0.frames,
    );
    check_doppler(
        &mut *Box::new(JottTbd::<1000>::new(g, 1).unwrap()),
        &run0.frames,
    );
    check_doppler(
        &mut *Box::new(PfLrt::<1000>::new(g, 1).unwrap()),
        &run0.frames,
    );
}

#[test]
fn mht_detections_are_the_period_tracks() {
    let trial = SeaClutter::paper(80.0).generate(&mut Rng::seed_from_u64(3));
    let mut det = Box::new(Mht::new(MhtConfig::sea_clutter()).unwrap());
    let mut periods = 0;
    run(
        det.as_mut(),
        trial.scans.iter().map(|s| s.plots.as_slice()),
        |_, det, rep| {
            match rep.detection {
                None => assert_eq!(det.detection_count(), 0),
                Some(p) => {
                    periods += 1;
                    assert_eq!(det.detection_count(), usize::from(p.tracks));
                    for (i, d) in det.detections().enumerate() {
                        let t = d.track.unwrap();
                        assert_eq!(t.id as usize, i);
                        assert_eq!(t.len, u32::from(det.tracks()[i].n_plots));
                        assert_eq!(d.score, f32::from(det.tracks()[i].peak.raw));
                        // The track's last plot lies in the area.
                        let x = d.state();
                        assert!((0.0..=6000.0).contains(&x[0]) && (0.0..=6000.0).contains(&x[1]));
                    }
                }
            }
        },
    )
    .unwrap();
    assert_eq!(periods, 1);
    // A reset starts a new period: no detections until it completes.
    det.reset(0);
    assert_eq!(det.detection_count(), 0);
}
