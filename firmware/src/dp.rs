//! Cost of DP-TBD (Barniv 1985 / Arnold et al. 1993, Pulford and La Scala 2010, Wang and
//! Zhang 2016) per frame on the Cortex-M4F: 128 x 128 images of the `faint_golden::dp`
//! scene (noise `N(0, 1.5^2)`, one target at SNR 2), tracks over `L = 8` frames.
//!
//! Rows: the first-order DP with `q_B = 9` and 25, the second order `q_B = q_I = 9` with
//! `i16` and with `i8` merits, and the Pulford DP (`q_B = 9`) at 64 x 64 (its per-state
//! Kalman filters, 24 B each, do not fit beside the other rows at 128 x 128). Each
//! detector runs 8 frames from `configure`; frames 3..=8 (the recursion's steady state,
//! pointers and transition term in use) are measured one `step` at a time (the scene
//! generation is not measured): mean and worst frame. The detectors are all-zero
//! `static`s (`unconfigured()` is a `const`), the static RAM column their `size_of` plus
//! the frame buffer (64 KiB at 128 x 128).

use core::hint::black_box;
use core::mem::size_of;

use cortex_m_semihosting::hprintln;
use faint_core::detect::dp::{
    arnold_words, pulford_words, second_order_words, ArnoldDp, DpConfig, DpTrack, Method,
    PulfordDp, SecondOrderDp,
};
use faint_core::rng::Rng;
use faint_golden::dp::{frame, SIGMA};

use crate::harness::{check, measure, row, Measurement, Static};

const SEED: u64 = 0x0004_D9B8_CDB8_7468;
const M: usize = 128;
const MP: usize = 64;
const L: usize = 8;
const FRAMES: usize = 8;

type A9 = ArnoldDp<M, 9, L, { arnold_words(M, 9, L) }>;
type A25 = ArnoldDp<M, 25, L, { arnold_words(M, 25, L) }>;
type S9 = SecondOrderDp<M, 9, L, { second_order_words(M, 9, L) }>;
type S9i8 = SecondOrderDp<M, 9, L, { second_order_words(M, 9, L) }, i8>;
type P9 = PulfordDp<MP, 9, L, { pulford_words(MP, 9, L) }>;

static A9_DET: Static<A9> = Static::new(A9::unconfigured());
static A25_DET: Static<A25> = Static::new(A25::unconfigured());
static S9_DET: Static<S9> = Static::new(S9::unconfigured());
static S9I8_DET: Static<S9i8> = Static::new(S9i8::unconfigured());
static P9_DET: Static<P9> = Static::new(P9::unconfigured());
static IMAGE: Static<[f32; M * M]> = Static::new([0.0; M * M]);

/// Runs `FRAMES` frames of the scene through `det`, measuring frames 3..=FRAMES.
fn rows<D: DpTrack>(
    name: &str,
    det: &mut D,
    cfg: DpConfig,
    m: usize,
    image: &mut [f32],
    ram: usize,
) {
    check(det.configure(&cfg, 0));
    let mut rng = Rng::from_stream(SEED, 1);
    let z = image.get_mut(..m * m).unwrap_or(&mut []);
    let mut sum = 0u64;
    let mut worst = Measurement {
        instructions: 0,
        stack_bytes: 0,
    };
    let mut stack = 0;
    let mut best = (0u16, 0u16);
    for k in 0..FRAMES {
        frame(m, k, 2.0 * SIGMA, &mut rng, z);
        let step = &mut |f: &[f32]| det.step(f);
        let step: &mut dyn FnMut(&[f32]) -> faint_core::Result<_> = step;
        let (r, meas) = measure(|| step(black_box(&*z)));
        let rep = check(r);
        best = (rep.best.x, rep.best.y);
        if k >= 2 {
            sum += meas.instructions;
            stack = stack.max(meas.stack_bytes);
            if meas.instructions > worst.instructions {
                worst = meas;
            }
        }
    }
    let n = (FRAMES - 2) as u64;
    let px = (m * m) as u32;
    let mut label = crate::harness::Text::<96>::new();
    let _ = core::fmt::write(
        &mut label,
        format_args!("{name}, mean of frames 3-{FRAMES}"),
    );
    row(
        label.as_str(),
        px,
        "pixel",
        Measurement {
            instructions: sum / n,
            stack_bytes: stack,
        },
        ram,
    );
    label.clear();
    let _ = core::fmt::write(
        &mut label,
        format_args!("{name}, worst of frames 3-{FRAMES}"),
    );
    row(label.as_str(), px, "pixel", worst, ram);
    let (tx, ty) = faint_golden::dp::target(m, FRAMES - 1);
    hprintln!(
        "{}: best end after frame {} at ({}, {}), target at ({}, {})",
        name,
        FRAMES,
        best.0,
        best.1,
        tx as u32,
        ty as u32
    );
}

/// Prints the DP-TBD rows. Call once (it takes the statics).
pub fn run() {
    let image = IMAGE.take();
    let img = size_of::<[f32; M * M]>();
    let arnold = DpConfig::dim_point(Method::Arnold, 1);
    let second = DpConfig::dim_point(Method::SecondOrder, 1);
    let pulford = DpConfig::dim_point(Method::Pulford, 1);
    rows(
        "DP-TBD first order 3x3, 128x128, L 8",
        A9_DET.take(),
        arnold,
        M,
        image,
        size_of::<A9>() + img,
    );
    rows(
        "DP-TBD first order 5x5, 128x128, L 8",
        A25_DET.take(),
        DpConfig::dim_point(Method::Arnold, 2),
        M,
        image,
        size_of::<A25>() + img,
    );
    rows(
        "DP-TBD second order 3x3/3x3 i16, 128x128, L 8",
        S9_DET.take(),
        second,
        M,
        image,
        size_of::<S9>() + img,
    );
    rows(
        "DP-TBD second order 3x3/3x3 i8, 128x128, L 8",
        S9I8_DET.take(),
        DpConfig {
            lsb: 0.25,
            ..second
        },
        M,
        image,
        size_of::<S9i8>() + img,
    );
    rows(
        "DP-TBD Pulford 3x3, 64x64, L 8",
        P9_DET.take(),
        pulford,
        MP,
        image,
        size_of::<P9>() + size_of::<[f32; MP * MP]>(),
    );
    hprintln!(
        "DP-TBD statics (B): first order 3x3 {}, 5x5 {}, second order i16 {}, i8 {}, Pulford 64x64 {}, image {}",
        size_of::<A9>(),
        size_of::<A25>(),
        size_of::<S9>(),
        size_of::<S9i8>(),
        size_of::<P9>(),
        img
    );
}
