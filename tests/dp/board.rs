//! `faint reproduce dp --second-bits 8`: the second order with `i8` merit cells (the
//! STM32H743's `dp-second:128:8`) on the frames of the `i16` run; the first orders are
//! untouched.

use faint::host::reproduce::dp::{target_run, Second9I8, Variant, I8_LSB};
use faint::host::simulate::dp::{DimPoint, Second9};
use faint::rng::Rng;

use super::{faint, s, temp};

#[test]
fn second_bits_8_changes_only_the_second_order() {
    assert!(size_of::<Second9I8>() < size_of::<Second9>());
    let sc = DimPoint::default();
    let v8 = Variant {
        second_i8: true,
        ..Variant::default()
    };
    let rng = || Rng::from_stream(DimPoint::target_seed(5, 1), 2);
    let a = target_run(&sc, 1, 2.5, &Variant::default(), &mut rng()).unwrap();
    let b = target_run(&sc, 1, 2.5, &v8, &mut rng()).unwrap();
    assert_eq!(a[0], b[0], "Arnold");
    assert_eq!(a[1], b[1], "Pulford");
    assert_ne!(a[2], b[2], "second order");
    // its merits are whole multiples of the i8 LSB, which the i16 run's are not
    let on_lsb = |m: &f32| (m / I8_LSB).fract() == 0.0;
    assert!(b[2].best.iter().all(on_lsb), "{:?}", b[2].best);
    assert!(!a[2].best.iter().all(on_lsb));
}

#[test]
fn second_bits_flag_runs_and_is_checked() {
    let dir = temp("second-bits");
    let (code, _, err) = faint(&[
        "reproduce",
        "dp",
        "--quick",
        "--runs",
        "2",
        "--snr",
        "2.5:2.5:1",
        "--frames",
        "4",
        "--no-fig5",
        "--second-bits",
        "8",
        "--out",
        s(&dir),
    ]);
    assert_eq!(code, 0, "{err}");
    let md = std::fs::read_to_string(dir.join("summary.md")).unwrap();
    assert!(md.contains("second-order merits: i8, LSB 0.25"), "{md}");
    let (code, _, err) = faint(&["reproduce", "dp", "--quick", "--second-bits", "12"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--second-bits must be 8 or 16, got 12"),
        "{err}"
    );
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
