//! The firmware's CBMeMBer filter (`firmware/src/rows/cbmember.rs`): `configure` on
//! `new_unconfigured()` (how the firmware keeps it in `.bss`) behaves exactly as `new`, and its static
//! RAM stays within the 256 KiB goal for a 1000-particle joint filter.

use std::mem::size_of;

use faint_core::detect::cbmember::{CbmemberConfig, CbmemberTbdM4, CbmemberTbdSmall};
use faint_core::detect::Detector;
use faint_core::model::range_doppler::PointModel;
use faint_core::rng::Rng;
use faint_golden::cbmember::{config, map, GOLDEN_WINDOW};

type Firmware = CbmemberTbdM4;
type Small = CbmemberTbdSmall;

#[test]
fn firmware_filter_fits_256_kib() {
    // 64-bit host: a few usize fields are wider than on the target (180 520 B there).
    let n = size_of::<Firmware>();
    assert!(n <= 256 * 1024, "{n} B");
    let g = CbmemberConfig::rotor_uav().geometry;
    let cfg = config(g, PointModel::Joint, 1000, 450);
    let mut f = Box::new(Firmware::new(cfg, 1).unwrap());
    f.configure(&cfg, 2).unwrap();
    // The preset's 1500 particles do not fit this capacity: a typed error.
    assert!(f.configure(&CbmemberConfig::rotor_uav(), 2).is_err());
}

#[test]
fn configure_on_zero_equals_new() {
    let cfg = config(GOLDEN_WINDOW, PointModel::Joint, 96, 48);
    let mut a = Box::new(Small::new_unconfigured());
    a.configure(&cfg, 9).unwrap();
    let mut b = Small::new(cfg, 9).unwrap();
    let mut rng = Rng::seed_from_u64(4);
    let mut z = vec![0f32; GOLDEN_WINDOW.len()];
    for k in 0..6 {
        map(&GOLDEN_WINDOW, k, &mut rng, &mut z);
        assert_eq!(a.step(&z).unwrap(), b.step(&z).unwrap());
        assert_eq!(
            a.estimates().collect::<Vec<_>>(),
            b.estimates().collect::<Vec<_>>()
        );
    }
}
