//! Cost of DP-TBD (Barniv 1985 / Arnold et al. 1993, Pulford and La Scala 2010, Wang and
//! Zhang 2016) per frame on the Cortex-M4F: 128 x 128 images of the `faint_golden::dp`
//! scene (noise `N(0, 1.5^2)`, one target at SNR 2 moving at (0.8, 0.5) px/frame), tracks
//! over `L = 8` frames.
//!
//! Rows: the first order with `q_B = 9` and 25 (`i16` merits, and `q_B = 9` with `i8`),
//! the Pulford DP with `q_B = 9`, and the second order `q_B = q_I = 9` with `i16` and
//! `i8` merits. Each detector runs 8 frames from `configure`; frames 3..=8 (the
//! recursion's steady state: back-pointers and the transition term in use) are measured
//! one `step` at a time (scene generation is not measured): mean and worst frame.
//!
//! **Memory.** The detectors run one after another, so they share one arena sized for the
//! largest of them (before each detector it is zeroed and used as that detector: an
//! all-zero value is a valid unconfigured detector, checked at compile time below; then
//! `configure` sets it up in place). The arena and the frame buffer live in the board's
//! 16 MiB PSRAM at `0x2100_0000` (section `.psram` of `memory.x`, which QEMU models): the
//! 4 MiB data RAM holds the other families' statics (3.6 MB), and the largest DP
//! detector (the second order with `i16` merits, 577 KB) plus the 64 KiB frame would not
//! fit beside them and the stack. The static RAM column is the detector's own `size_of`
//! plus the frame buffer.

use core::hint::black_box;
use core::mem::{align_of, size_of, MaybeUninit};

use cortex_m_semihosting::hprintln;
use faint_core::detect::dp::{
    arnold_words, pulford_words, second_order_words, ArnoldDp, DpConfig, DpTrack, Method,
    PulfordDp, SecondOrderDp,
};
use faint_core::rng::Rng;
use faint_golden::dp::{frame, target, SIGMA};

use core::sync::atomic::{AtomicBool, Ordering};

use faint_firmware::harness::{check, measure, row, Measurement};
use faint_firmware::text::Text;

const SEED: u64 = 0x0004_D9B8_CDB8_7468;
const M: usize = 128;
const L: usize = 8;
const FRAMES: usize = 8;
/// Frames before the measured ones (frame 1 only quantises, frame 2 has no transition
/// term in the second order).
const WARM: usize = 2;

type A9 = ArnoldDp<M, 9, L, { arnold_words(M, 9, L) }>;
type A9i8 = ArnoldDp<M, 9, L, { arnold_words(M, 9, L) }, i8>;
type A25 = ArnoldDp<M, 25, L, { arnold_words(M, 25, L) }>;
type P9 = PulfordDp<M, 9, L, { pulford_words(M, 9, L) }>;
type S9 = SecondOrderDp<M, 9, L, { second_order_words(M, 9, L) }>;
type S9i8 = SecondOrderDp<M, 9, L, { second_order_words(M, 9, L) }, i8>;

const fn max(a: usize, b: usize) -> usize {
    if a > b {
        a
    } else {
        b
    }
}

/// Bytes of the arena: the largest detector.
const ARENA: usize = max(
    max(max(size_of::<A9>(), size_of::<A9i8>()), size_of::<A25>()),
    max(max(size_of::<P9>(), size_of::<S9>()), size_of::<S9i8>()),
);
const ALIGN: usize = 8;

#[repr(C, align(8))]
struct Arena([u8; ARENA]);

/// Not zeroed by the start-up code: `run` zeroes what it uses.
#[link_section = ".psram"]
static mut ARENA_BUF: MaybeUninit<Arena> = MaybeUninit::uninit();
#[link_section = ".psram"]
static mut IMAGE: MaybeUninit<[f32; M * M]> = MaybeUninit::uninit();
static TAKEN: AtomicBool = AtomicBool::new(false);

// The const evaluator rejects (compile error) an all-zero bit pattern that is not a
// valid value of every field (the config's enums, `bool`s), so these prove that a zeroed
// arena is a valid value of each detector type used below.
const _: A9 = unsafe { MaybeUninit::zeroed().assume_init() };
const _: A9i8 = unsafe { MaybeUninit::zeroed().assume_init() };
const _: A25 = unsafe { MaybeUninit::zeroed().assume_init() };
const _: P9 = unsafe { MaybeUninit::zeroed().assume_init() };
const _: S9 = unsafe { MaybeUninit::zeroed().assume_init() };
const _: S9i8 = unsafe { MaybeUninit::zeroed().assume_init() };

/// The arena, zeroed, as a `D`.
///
/// # Safety
/// An all-zero `D` must be a valid value (one of the checked types above).
unsafe fn zeroed<D>(arena: &mut Arena) -> &mut D {
    const {
        assert!(size_of::<D>() <= ARENA && align_of::<D>() <= ALIGN);
    }
    let p = arena.0.as_mut_ptr();
    // SAFETY: `p` is valid for `ARENA >= size_of::<D>()` bytes and aligned to
    // `ALIGN >= align_of::<D>()`; the zeroed bytes are a valid `D` (caller); the returned
    // borrow is the arena's, so nothing else reads the bytes while it lives.
    unsafe {
        core::ptr::write_bytes(p, 0, size_of::<D>());
        &mut *p.cast::<D>()
    }
}

/// Frame `k` of the scene (one out-of-line copy for all rows, so the generator's inlining
/// elsewhere in the image, e.g. in the primitives' rows, does not change).
#[inline(never)]
fn scene(k: usize, rng: &mut Rng, image: &mut [f32; M * M]) {
    frame(M, k, 2.0 * SIGMA, rng, &mut image[..]);
}

/// Runs `FRAMES` frames of the scene through `det`, measuring frames `WARM+1..=FRAMES`.
#[inline(never)]
fn rows<D: DpTrack>(name: &str, det: &mut D, cfg: DpConfig, image: &mut [f32; M * M]) {
    check(det.configure(&cfg, 0));
    let mut rng = Rng::from_stream(SEED, 1);
    let mut sum = 0u64;
    let mut worst = Measurement {
        instructions: 0,
        stack_bytes: 0,
    };
    let mut stack = 0;
    let mut best = (0u16, 0u16);
    for k in 0..FRAMES {
        scene(k, &mut rng, image);
        let (r, meas) = measure(|| det.step(black_box(&image[..])));
        let rep = check(r);
        best = (rep.best.x, rep.best.y);
        if k >= WARM {
            sum += meas.instructions;
            stack = stack.max(meas.stack_bytes);
            if meas.instructions > worst.instructions {
                worst = meas;
            }
        }
    }
    let n = (FRAMES - WARM) as u64;
    let ram = size_of::<D>() + size_of::<[f32; M * M]>();
    let mut label = Text::<96>::new();
    let _ = core::fmt::write(
        &mut label,
        format_args!("{name}, mean of frames {}-{FRAMES}", WARM + 1),
    );
    let mean = Measurement {
        instructions: sum / n,
        stack_bytes: stack,
    };
    row(label.as_str(), (M * M) as u32, "pixel", mean, ram);
    label.clear();
    let _ = core::fmt::write(
        &mut label,
        format_args!("{name}, worst of frames {}-{FRAMES}", WARM + 1),
    );
    row(label.as_str(), (M * M) as u32, "pixel", worst, ram);
    let (tx, ty) = target(M, FRAMES - 1);
    hprintln!(
        "{}: best end after frame {} at ({}, {}), target pixel ({}, {})",
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
    assert!(!TAKEN.swap(true, Ordering::AcqRel), "dp::run called twice");
    // SAFETY: the flag above makes these the only references to the two statics; both are
    // zeroed before use (an all-zero `[f32; N]` and `[u8; N]` are valid).
    let (arena, image) = unsafe {
        let a = &mut *core::ptr::addr_of_mut!(ARENA_BUF);
        let i = &mut *core::ptr::addr_of_mut!(IMAGE);
        core::ptr::write_bytes(a.as_mut_ptr(), 0, 1);
        core::ptr::write_bytes(i.as_mut_ptr(), 0, 1);
        (a.assume_init_mut(), i.assume_init_mut())
    };
    let arnold = DpConfig::dim_point(Method::Arnold, 1);
    let pulford = DpConfig::dim_point(Method::Pulford, 1);
    let second = DpConfig::dim_point(Method::SecondOrder, 1);
    // i8 cells hold +-63 LSB per pixel: a coarser LSB keeps the scene in range.
    let coarse = 0.25;
    // SAFETY (each `zeroed`): the type is one of the all-zero-checked types above.
    let det = unsafe { zeroed::<A9>(arena) };
    rows(
        "DP-TBD first order 3x3 i16, 128x128, L 8",
        det,
        arnold,
        image,
    );
    let det = unsafe { zeroed::<A9i8>(arena) };
    let cfg = DpConfig {
        lsb: coarse,
        ..arnold
    };
    rows("DP-TBD first order 3x3 i8, 128x128, L 8", det, cfg, image);
    let det = unsafe { zeroed::<A25>(arena) };
    let cfg = DpConfig::dim_point(Method::Arnold, 2);
    rows("DP-TBD first order 5x5 i16, 128x128, L 8", det, cfg, image);
    let det = unsafe { zeroed::<P9>(arena) };
    rows("DP-TBD Pulford 3x3 i16, 128x128, L 8", det, pulford, image);
    let det = unsafe { zeroed::<S9>(arena) };
    rows(
        "DP-TBD second order 3x3/3x3 i16, 128x128, L 8",
        det,
        second,
        image,
    );
    let det = unsafe { zeroed::<S9i8>(arena) };
    let cfg = DpConfig {
        lsb: coarse,
        ..second
    };
    rows(
        "DP-TBD second order 3x3/3x3 i8, 128x128, L 8",
        det,
        cfg,
        image,
    );
    hprintln!(
        "DP-TBD statics (B): first order 3x3 i16 {}, i8 {}, 5x5 {}, Pulford 3x3 {}, second order i16 {}, i8 {}; shared arena {}, image {}",
        size_of::<A9>(),
        size_of::<A9i8>(),
        size_of::<A25>(),
        size_of::<P9>(),
        size_of::<S9>(),
        size_of::<S9i8>(),
        ARENA,
        size_of::<[f32; M * M]>()
    );
}
