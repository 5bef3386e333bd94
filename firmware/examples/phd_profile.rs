//! PHD-TBD's frames, or one stage of each frame, bracketed by the cycle tool's markers
//! for `faint-cycles run --hot N` (per-block instruction counts of the bracketed code:
//! where a stage's instructions go, instruction by instruction). The filter, scene and
//! seed are the PHD rows' (PHD-TBD, `SmcPhdTbdM4`). `LIKPROF_STAGE` (read at build time):
//! the bracketed stage is the one that follows the end of the stage with this `PhdStage`
//! index (2, the births: PHD-TBD's likelihood; unset: the whole step); `LIKPROF_FRAMES`:
//! the frames (10). From the repository's root:
//!
//! ```text
//! cd firmware && LIKPROF_STAGE=2 LIKPROF_FRAMES=4 cargo build -q --profile firmware --example phd_profile
//! target/tools/release/faint-cycles run --hot 45 target/thumbv7em-none-eabihf/firmware/examples/phd_profile
//! ```
#![no_std]
#![no_main]

use core::arch::asm;
use core::hint::black_box;

use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use faint_core::detect::phd::SmcPhdTbdM4;
use faint_core::detect::Detector;
use faint_core::rng::Rng;

use faint_firmware::harness::{self, check, measure};
use faint_firmware::semihosting::exit_success;
use faint_firmware::statics::{only_ref, Static};
use faint_firmware::timer;

faint_firmware::report_panics!();

#[no_mangle]
#[inline(never)]
pub extern "C" fn faint_cycles_begin() {
    unsafe { asm!("nop", options(nostack, preserves_flags)) }
}

#[no_mangle]
#[inline(never)]
pub extern "C" fn faint_cycles_end() {
    unsafe { asm!("nop", "nop", options(nostack, preserves_flags)) }
}

type Phd = SmcPhdTbdM4;
const PHD_CELLS: usize = faint_golden::phd::FIRMWARE_WINDOW.len();
static mut PHD: Phd = Phd::new_unconfigured();
static CUBE: Static<[f32; PHD_CELLS]> = Static::new([0.0; PHD_CELLS]);

#[entry]
fn main() -> ! {
    harness::init();
    hprintln!("likprof");
    let ((), m) = measure(|| unsafe {
        asm!(
            ".p2align 2",
            "bl faint_cycles_begin",
            "bl faint_cycles_end",
            out("r0") _, out("r1") _, out("r2") _, out("r3") _, out("r12") _, out("lr") _,
        )
    });
    hprintln!("region | base | empty | - | {} |", m.instructions);
    use faint_golden::phd::{config, cube, ALGORITHMS, FIRMWARE_WINDOW};
    const SEED: u64 = 0x0002_0019_9E1D_7BD0;
    let det = unsafe { only_ref(&raw mut PHD) };
    let buf = CUBE.take();
    let alg = ALGORITHMS[0];
    let frames: usize = option_env!("LIKPROF_FRAMES")
        .and_then(|s| s.parse().ok())
        .unwrap_or(10);
    let stage: u32 = option_env!("LIKPROF_STAGE")
        .and_then(|s| s.parse().ok())
        .unwrap_or(99);
    let cfg = config(FIRMWARE_WINDOW, alg, 1000, 500, 8);
    check(det.configure(&cfg, SEED));
    let mut rng = Rng::from_stream(SEED, 1);
    for k in 0..frames {
        cube(&FIRMWARE_WINDOW, k, &mut rng, buf);
        if stage == 99 {
            let (r, m) = measure(|| {
                faint_cycles_begin();
                let r = det.step(black_box(&buf[..]));
                faint_cycles_end();
                r
            });
            let _ = check(r);
            hprintln!(
                "region | step | PHD-TBD frame {} | - | {} |",
                k,
                m.instructions
            );
        } else {
            let mut on = false;
            let mut t = timer::now();
            let mut got = 0u32;
            let r = det.step_probed(black_box(&buf[..]), |s| {
                let idx = s as u32;
                if on {
                    faint_cycles_end();
                    got = timer::elapsed(t, timer::now());
                    on = false;
                }
                if idx == stage {
                    t = timer::now();
                    faint_cycles_begin();
                    on = true;
                }
            });
            let _ = check(r);
            hprintln!(
                "region | step | PHD-TBD frame {} stage after {} | - | {} |",
                k,
                stage,
                got
            );
        }
    }
    hprintln!("done");
    exit_success()
}
