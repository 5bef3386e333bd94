//! The STM32H743's CBMeMBer filter (`CbmemberTbdM4`: 1000 particles per component) is
//! the reproduction's 1000-particle filter (the host's 1500-particle capacity configured
//! with `L_max = 1000`): the capacity alone changes no number.

use faint::detect::cbmember::{CbmemberTbdHost, CbmemberTbdM4};
use faint::detect::Detector;
use faint::host::instances::boxed;
use faint::host::simulate::cbmember::{MapSource, RotorUav};
use faint::model::range_doppler::PointModel;
use faint::rng::Rng;

#[test]
fn the_board_filter_equals_the_host_filter_at_1000_particles() {
    let sc = RotorUav::new(-12.0);
    let cfg = sc.config(PointModel::Joint, 1000);
    let mut board = boxed::<CbmemberTbdM4>(&cfg, 9).unwrap();
    let mut host = boxed::<CbmemberTbdHost>(&cfg, 9).unwrap();
    let mut src = MapSource::new(&sc);
    let mut rng = Rng::from_stream(2024, 0);
    let mut map = Vec::new();
    let mut reported = 0;
    for (k, t) in sc.truth().iter().enumerate().take(12) {
        src.power(&sc, t, k, &mut rng, &mut map);
        let a = board.step(&map[..]).unwrap();
        let b = host.step(&map[..]).unwrap();
        assert_eq!(format!("{a:?}"), format!("{b:?}"), "frame {k}");
        let da: Vec<_> = board.detections().map(|d| format!("{d:?}")).collect();
        let db: Vec<_> = host.detections().map(|d| format!("{d:?}")).collect();
        assert_eq!(da, db, "frame {k}");
        reported += da.len();
    }
    assert!(reported > 0, "nothing reported: the comparison is empty");
}
