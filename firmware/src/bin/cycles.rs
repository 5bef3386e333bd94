//! Regions for the cycle model (`tools/cycles`, `faint-cycles run`): microbenchmarks whose
//! Cortex-M4 cycle counts the Technical Reference Manual fixes, and one `step` per frame
//! of each detector family in the instruction table's configurations, fewer frames.
//!
//! Each region is bracketed by calls to [`faint_cycles_begin`] and [`faint_cycles_end`];
//! `faint-cycles` runs this image on QEMU with `-d in_asm,exec,nochain`, costs every
//! translation block executed between the two calls and prints the tables. The image
//! prints one line per region, in order:
//! `region | <kind> | <label> | <expected M4 cycles or -> | <instructions (timer)>`.
//! Region 0 is empty (`base`): the marker calls, which the tool subtracts.
//!
//! **Microbenchmarks** (`micro`): hand-written kernels between the markers inside one
//! `asm!` block, so nothing the compiler emits is counted. The expected M4 count is the
//! TRM's (Arm DDI 0439, 3.3.1 Table 3-1, 3.3.2, 7.2.3 Table 7-1) under the model's stated
//! choices: P = 1 for a 16-bit or word-aligned target, one more for an unaligned 32-bit
//! target and for a register target (BX), SDIV/UDIV at the worst case 12.
//!
//! **Detector steps** (`step`): the same detector types, configurations, seeds and frames
//! as the instruction table's modules (`src/rows/crpf.rs`, `mht.rs`, `phd.rs`,
//! `cbmember.rs`, `dp.rs`), with fewer frames where a frame costs tens of millions of instructions (the
//! trace runs at about 0.6 M translation blocks per second). Each step is also measured
//! with the harness's timer: the tool fails if the traced and timed counts differ.
#![no_std]
#![no_main]

use core::arch::asm;
use core::hint::black_box;
use core::mem::MaybeUninit;

use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use faint_core::detect::cbmember::CbmemberTbdM4;
use faint_core::detect::crpf::{CrpfConfig, CrpfTbd1000, CrpfTbd6000};
use faint_core::detect::dp::{DpConfig, DpTrack, Method};
use faint_core::detect::jott::JottTbd1000;
use faint_core::detect::mht::{MhtConfig, MhtTbdM4};
use faint_core::detect::pf_lrt::PfLrt1000;
use faint_core::detect::pf_tbd::{GaussConfig, PfTbd1000};
use faint_core::detect::phd::SmcPhdTbdM4;
use faint_core::detect::Detector;
use faint_core::dp_tbd;
use faint_core::model::doppler::{DopplerModel, DopplerReport, Window};
use faint_core::model::plot::Plot;
use faint_core::model::range_doppler::PointModel;
use faint_core::rng::Rng;
use faint_core::Complex32;

use faint_firmware::harness::{self, check, measure};
use faint_firmware::semihosting::exit_success;
use faint_firmware::statics::{only_ref, Static};
use faint_firmware::text::Text;

faint_firmware::report_panics!();

/// Start of a traced region (the tool finds it by name in the trace).
#[no_mangle]
#[inline(never)]
pub extern "C" fn faint_cycles_begin() {
    // SAFETY: a `nop`; it keeps the call from being optimised out, and the two markers'
    // bodies differ, so the linker cannot fold them into one address.
    unsafe { asm!("nop", options(nostack, preserves_flags)) }
}

/// End of a traced region.
#[no_mangle]
#[inline(never)]
pub extern "C" fn faint_cycles_end() {
    // SAFETY: as above.
    unsafe { asm!("nop", "nop", options(nostack, preserves_flags)) }
}

/// Prints the line of one region.
fn region(kind: &str, label: &str, expect: Option<u64>, timer: u64) {
    match expect {
        Some(e) => hprintln!("region | {} | {} | {} | {} |", kind, label, e, timer),
        None => hprintln!("region | {} | {} | - | {} |", kind, label, timer),
    }
}

/// Measures `f` as a `step` region: timer count and trace markers around it.
fn step<R>(label: &str, f: impl FnOnce() -> R) -> R {
    let (r, m) = measure(|| {
        faint_cycles_begin();
        let r = f();
        faint_cycles_end();
        r
    });
    region("step", label, None, m.instructions);
    r
}

/// A microbenchmark: `$kernel` (asm lines) between the markers, the TRM's M4 count.
macro_rules! micro {
    ($label:expr, $expect:expr, [$($kernel:literal),* $(,)?] $(, $($op:tt)*)?) => {{
        let ((), m) = measure(|| {
            // SAFETY: the kernels read and write only the buffer passed in r4 and the
            // registers declared clobbered; the marker calls follow the C ABI.
            unsafe {
                asm!(
                    ".p2align 2",
                    "bl faint_cycles_begin",
                    $($kernel,)*
                    "bl faint_cycles_end",
                    $($($op)*,)?
                    // The C ABI's caller-saved registers (`clobber_abi("C")` would also
                    // name d16-d31, which this FPU does not have).
                    out("r0") _, out("r1") _, out("r2") _, out("r3") _, out("r12") _, out("lr") _,
                    out("s0") _, out("s1") _, out("s2") _, out("s3") _, out("s4") _, out("s5") _,
                    out("s6") _, out("s7") _, out("s8") _, out("s9") _, out("s10") _,
                    out("s11") _, out("s12") _, out("s13") _, out("s14") _, out("s15") _,
                )
            }
        });
        region("micro", $label, Some($expect), m.instructions);
    }};
}

static mut BUF: [u32; 16] = [0; 16];

fn micros() {
    let buf = &raw mut BUF;
    // SAFETY: single-threaded; the buffer is only used here.
    unsafe {
        (*buf)[0] = buf as u32;
        (*buf)[1] = buf as u32;
    }
    let p = buf as u32;
    // Empty region: the marker calls only (subtracted from every other region).
    let ((), m) = measure(|| unsafe {
        asm!(
            ".p2align 2",
            "bl faint_cycles_begin",
            "bl faint_cycles_end",
            out("r0") _, out("r1") _, out("r2") _, out("r3") _, out("r12") _, out("lr") _,
        )
    });
    region("base", "empty", None, m.instructions);
    // 3.3.2: neighbouring single loads pipeline: 2 + 7 x 1.
    micro!(
        "8 LDR back to back, independent addresses",
        9,
        [
            "ldr r0, [r4]",
            "ldr r1, [r4, #4]",
            "ldr r2, [r4, #8]",
            "ldr r3, [r4, #12]",
            "ldr r0, [r4, #16]",
            "ldr r1, [r4, #20]",
            "ldr r2, [r4, #24]",
            "ldr r3, [r4, #28]"
        ],
        in("r4") p
    );
    // A load whose address is the previous load's result does not pipeline: 8 x 2.
    micro!(
        "8 LDR, each address the previous load's result",
        16,
        [
            "ldr r0, [r4]",
            "ldr r0, [r0]",
            "ldr r0, [r0]",
            "ldr r0, [r0]",
            "ldr r0, [r0]",
            "ldr r0, [r0]",
            "ldr r0, [r0]",
            "ldr r0, [r0]"
        ],
        in("r4") p
    );
    // 3.3.2: an address from the previous data-processing result stalls one cycle:
    // 4 x (1 + 2 + 1).
    micro!(
        "4 x (ADD; LDR from its result)",
        16,
        [
            "adds r0, r4, #0",
            "ldr r1, [r0]",
            "adds r0, r4, #4",
            "ldr r1, [r0]",
            "adds r0, r4, #8",
            "ldr r1, [r0]",
            "adds r0, r4, #12",
            "ldr r1, [r0]"
        ],
        in("r4") p
    );
    // STR with an immediate offset: 1 each (write buffer).
    micro!(
        "8 STR, immediate offsets",
        8,
        [
            "str r0, [r4]",
            "str r0, [r4, #4]",
            "str r0, [r4, #8]",
            "str r0, [r4, #12]",
            "str r0, [r4, #16]",
            "str r0, [r4, #20]",
            "str r0, [r4, #24]",
            "str r0, [r4, #28]"
        ],
        in("r4") p
    );
    // LDM/STM: 1 + N.
    micro!(
        "LDM of 8 registers",
        9,
        ["ldm r4, {{r0, r1, r2, r3, r5, r8, r10, r11}}"],
        in("r4") p, out("r5") _, out("r8") _, out("r10") _, out("r11") _
    );
    micro!(
        "STM of 4 registers, then LDM of 2",
        8,
        ["stm r4, {{r0, r1, r2, r3}}", "ldm r4, {{r0, r1}}"],
        in("r4") p
    );
    micro!(
        "PUSH 4, POP 4",
        10,
        ["push {{r0, r1, r2, r3}}", "pop {{r0, r1, r2, r3}}"]
    );
    micro!("LDRD", 3, ["ldrd r0, r1, [r4]"], in("r4") p);
    // Multiplies are single-cycle on the M4 (MUL, MLA, UMULL, SMLAL).
    micro!(
        "MUL, MLA, UMULL, SMLAL",
        4,
        [
            "muls r0, r1, r0",
            "mla r0, r1, r2, r0",
            "umull r0, r1, r2, r3",
            "smlal r0, r1, r2, r3"
        ]
    );
    // SDIV/UDIV: 2..12, the model's stated worst case 12.
    micro!(
        "UDIV, SDIV (model: worst case 12 each)",
        24,
        ["udiv r0, r1, r2", "sdiv r0, r1, r2"]
    );
    // FPU (7.2.3 Table 7-1): VADD, VMUL 1; VMLA 3; VDIV, VSQRT 14.
    micro!(
        "4 VADD/VMUL",
        4,
        [
            "vadd.f32 s0, s1, s2",
            "vmul.f32 s3, s1, s2",
            "vadd.f32 s4, s1, s2",
            "vmul.f32 s5, s1, s2"
        ]
    );
    micro!(
        "4 VMLA",
        12,
        [
            "vmla.f32 s0, s1, s2",
            "vmla.f32 s3, s1, s2",
            "vmla.f32 s4, s1, s2",
            "vmla.f32 s5, s1, s2"
        ]
    );
    micro!(
        "VDIV chain of 4",
        56,
        [
            "vdiv.f32 s0, s0, s1",
            "vdiv.f32 s0, s0, s1",
            "vdiv.f32 s0, s0, s1",
            "vdiv.f32 s0, s0, s1"
        ]
    );
    micro!("VSQRT x 2", 28, ["vsqrt.f32 s0, s1", "vsqrt.f32 s2, s3"]);
    // VLDR pipelines like LDR (the model's choice): 2 + 3 x 1; VLDM 1 + N.
    micro!(
        "4 VLDR back to back",
        5,
        [
            "vldr s0, [r4]",
            "vldr s1, [r4, #4]",
            "vldr s2, [r4, #8]",
            "vldr s3, [r4, #12]"
        ],
        in("r4") p
    );
    micro!(
        "VLDM of 8 singles",
        9,
        ["vldmia r4, {{s0-s7}}"],
        in("r4") p
    );
    micro!(
        "VMOV core to single x 2, VMOV two cores to double",
        4,
        ["vmov s0, r0", "vmov s1, r1", "vmov d1, r0, r1"]
    );
    // Taken branches: 1 + P. MOVS, then a SUBS/BNE loop of 8 iterations with a 16-bit
    // target: 1 + 8 x 2 + 7 x 1.
    micro!(
        "SUBS/BNE loop, 8 iterations (16-bit target, P = 1)",
        24,
        ["movs r0, #8", "2:", "subs r0, #1", "bne 2b"]
    );
    // The same loop with a 32-bit target at a halfword (not word) address: P = 2.
    // The loop head is `movs` (16-bit, word-aligned) then the 32-bit `subs.w`.
    micro!(
        "SUBS.W/BNE loop, 8 iterations (unaligned 32-bit target, P = 2)",
        1 + 8 * 2 + 7 * 2,
        ["movs r0, #8", "2:", "subs.w r0, r0, #1", "bne 2b"]
    );
    // BL to a local function and BX LR back (register target: P = 2), then B forward
    // to a word-aligned 32-bit target (P = 1): (1 + 1) + (1 + 2) + 1 (nop) + (1 + 1).
    micro!(
        "BL, BX LR, B",
        8,
        ["bl 3f", "nop", "b 4f", "3:", "bx lr", ".p2align 2", "4:"]
    );
}

// ---- detector steps ----------------------------------------------------------------

static mut CRPF_1000: CrpfTbd1000 = CrpfTbd1000::new_unconfigured();
static mut PF_1000: PfTbd1000 = PfTbd1000::new_unconfigured();
static mut JOTT_1000: JottTbd1000 = JottTbd1000::new_unconfigured();
static mut LRT_1000: PfLrt1000 = PfLrt1000::new_unconfigured();
static mut CRPF_6000: CrpfTbd6000 = CrpfTbd6000::new_unconfigured();

/// `src/rows/crpf.rs`'s single-frame row: 6 warm-up frames, then frame 7 measured.
fn crpf_one(
    label: &str,
    step_fn: &mut dyn FnMut(&[Complex32]) -> faint_core::Result<DopplerReport>,
    model: &DopplerModel,
) {
    use faint_golden::crpf::{frame, target, BIN_VAR};
    const SEED: u64 = 0x00C0_57F1_17E2_2017;
    let mut rng = Rng::from_stream(SEED, 1);
    let mut z = [Complex32::new(0.0, 0.0); 32];
    for k in 0..6 {
        let (fd, amp) = target(k);
        frame(model, fd, amp, BIN_VAR, &mut rng, &mut z);
        check(step_fn(&z));
    }
    let (fd, amp) = target(6);
    frame(model, fd, amp, BIN_VAR, &mut rng, &mut z);
    check(step(label, || step_fn(black_box(&z))));
}

fn crpf() {
    use faint_golden::crpf::BIN_VAR;
    const SEED: u64 = 0x00C0_57F1_17E2_2017;
    let model = check(DopplerModel::new(32, 0.02, Window::Hamming));
    let g = GaussConfig::othr(BIN_VAR);
    // SAFETY: single-threaded; each static is referenced only here, once.
    let (c1, pf, jott, lrt, c6) = unsafe {
        (
            only_ref(&raw mut CRPF_1000),
            only_ref(&raw mut PF_1000),
            only_ref(&raw mut JOTT_1000),
            only_ref(&raw mut LRT_1000),
            only_ref(&raw mut CRPF_6000),
        )
    };
    check(c1.configure(&CrpfConfig::othr(), SEED));
    crpf_one(
        "CRPF-TBD step, N 1000 (32 bins)",
        &mut |z| c1.step(z),
        &model,
    );
    check(pf.configure(&g, SEED));
    crpf_one("PF-TBD step, N 1000 (32 bins)", &mut |z| pf.step(z), &model);
    check(jott.configure(&g, SEED));
    crpf_one("JOTT step, N 1000 (32 bins)", &mut |z| jott.step(z), &model);
    check(lrt.configure(&g, SEED));
    crpf_one(
        "PF-LRT step, N 1000 (32 bins)",
        &mut |z| lrt.step(z),
        &model,
    );
    check(c6.configure(&CrpfConfig::othr(), SEED));
    crpf_one(
        "CRPF-TBD step, N 6000 (32 bins)",
        &mut |z| c6.step(z),
        &model,
    );
}

type Mht = MhtTbdM4;
static MHT: Static<Mht> = Static::new(Mht::new_unconfigured());
static SCAN: Static<[Plot; 512]> = Static::new([Plot::new(0.0, 0.0, 0.0); 512]);

/// `src/rows/mht.rs`: 29 censoring scans (scan 2 traced), then the period end (traced).
fn mht() {
    let det = MHT.take();
    let buf = SCAN.take();
    let mut cfg = MhtConfig::sea_clutter();
    cfg.gamma1 = 22;
    check(det.configure(&cfg, 0));
    let mut rng = Rng::from_stream(faint_golden::mht::COST_SEED, 0);
    for s in 0..29 {
        let n = faint_golden::mht::cost_scan(&mut rng, s, buf);
        if s == 2 {
            check(step("MHT-TBD censoring step, scan 2 (lambda 398)", || {
                det.step(&buf[..n])
            }));
        } else {
            let (r, _) = measure(|| det.step(&buf[..n]));
            check(r);
        }
    }
    let n = faint_golden::mht::cost_scan(&mut rng, 29, buf);
    check(step(
        "MHT-TBD period end: censoring + DMHT + peaks + association",
        || det.step(&buf[..n]),
    ));
}

type Phd = SmcPhdTbdM4;
const PHD_CELLS: usize = faint_golden::phd::FIRMWARE_WINDOW.len();
static mut PHD: Phd = Phd::new_unconfigured();
static CUBE: Static<[f32; PHD_CELLS]> = Static::new([0.0; PHD_CELLS]);

/// `src/rows/phd.rs`: PHD-TBD frames 0-1 and PSO-PHD-TBD (K-means) frames 0-1 (frame 1 is the
/// first with the swarm), each frame traced.
fn phd() {
    use faint_golden::phd::{config, cube, ALGORITHMS, FIRMWARE_WINDOW};
    const SEED: u64 = 0x0002_0019_9E1D_7BD0;
    // SAFETY: single-threaded; the static is referenced only here, once.
    let det = unsafe { only_ref(&raw mut PHD) };
    let buf = CUBE.take();
    let mut label = Text::<96>::new();
    for (alg, frames) in ALGORITHMS.into_iter().zip([2usize, 2]) {
        let cfg = config(FIRMWARE_WINDOW, alg, 1000, 500, 8);
        check(det.configure(&cfg, SEED));
        let mut rng = Rng::from_stream(SEED, 1);
        for k in 0..frames {
            cube(&FIRMWARE_WINDOW, k, &mut rng, buf);
            label.clear();
            let _ = core::fmt::write(
                &mut label,
                format_args!("{} step, frame {k} (32^3 cells)", alg.name),
            );
            check(step(label.as_str(), || det.step(black_box(&buf[..]))));
        }
    }
}

type Cbm = CbmemberTbdM4;
static mut CBM: Cbm = Cbm::new_unconfigured();
static MAP: Static<[f32; 256 * 512]> = Static::new([0.0; 256 * 512]);

/// `src/rows/cbmember.rs`: joint model at 1000 particles, frames 0-1 (frame 1 traced).
fn cbmember() {
    use faint_golden::cbmember::{config, map};
    const SEED: u64 = 0x0003_CB3E_3BE7_2023;
    // SAFETY: single-threaded; the static is referenced only here, once.
    let det = unsafe { only_ref(&raw mut CBM) };
    let z = MAP.take();
    let g = faint_core::detect::cbmember::CbmemberConfig::rotor_uav().geometry;
    let cfg = config(g, PointModel::Joint, 1000, 450);
    check(det.configure(&cfg, SEED));
    let mut rng = Rng::from_stream(SEED, 1);
    for k in 0..2 {
        map(&cfg.geometry, k, &mut rng, &mut z[..]);
        if k == 1 {
            check(step("cbmember joint, 1000 step, frame 1 (256x512)", || {
                det.step(black_box(&z[..]))
            }));
        } else {
            check(measure(|| det.step(black_box(&z[..]))).0);
        }
    }
}

const M: usize = 128;
type A9 = dp_tbd!(Arnold, M, 9, 8);
type P9 = dp_tbd!(Pulford, M, 9, 8);
type S9 = dp_tbd!(SecondOrder, M, 9, 8);
#[link_section = ".psram"]
static mut DP_A9: MaybeUninit<A9> = MaybeUninit::uninit();
#[link_section = ".psram"]
static mut DP_P9: MaybeUninit<P9> = MaybeUninit::uninit();
#[link_section = ".psram"]
static mut DP_S9: MaybeUninit<S9> = MaybeUninit::uninit();
#[link_section = ".psram"]
static mut IMAGE: [f32; M * M] = [0.0; M * M];
// The all-zero value of each DP detector is valid (checked at compile time).
const _: A9 = unsafe { MaybeUninit::zeroed().assume_init() };
const _: P9 = unsafe { MaybeUninit::zeroed().assume_init() };
const _: S9 = unsafe { MaybeUninit::zeroed().assume_init() };

/// `src/rows/dp.rs`: frames 1..=`last` from `configure`, frames 3..=`last` traced.
fn dp_rows<D: DpTrack>(name: &str, det: &mut D, cfg: DpConfig, last: usize) {
    use faint_golden::dp::{frame, SIGMA};
    const SEED: u64 = 0x0004_D9B8_CDB8_7468;
    // SAFETY: single-threaded; the image is used by one detector at a time.
    let image = unsafe { only_ref(&raw mut IMAGE) };
    check(det.configure(&cfg, 0));
    let mut rng = Rng::from_stream(SEED, 1);
    let mut label = Text::<96>::new();
    for k in 0..last {
        frame(M, k, 2.0 * SIGMA, &mut rng, &mut image[..]);
        if k >= 2 {
            label.clear();
            let _ = core::fmt::write(&mut label, format_args!("{name}, frame {}", k + 1));
            check(step(label.as_str(), || det.step(black_box(&image[..]))));
        } else {
            check(measure(|| det.step(black_box(&image[..]))).0);
        }
    }
}

/// Zeroes `*p` in place (no copy on the stack) and returns it.
///
/// # Safety
/// `p` points to a static of type `T` that nothing else references, and an all-zero `T`
/// is valid.
unsafe fn zeroed_in<T>(p: *mut T) -> &'static mut T {
    // SAFETY: the caller's contract.
    unsafe {
        core::ptr::write_bytes(p, 0, 1);
        &mut *p
    }
}

fn dp() {
    // SAFETY: single-threaded; each static is zeroed (a valid detector, checked above)
    // and referenced only here, once.
    let (a9, p9, s9) = unsafe {
        (
            zeroed_in::<A9>((&raw mut DP_A9).cast()),
            zeroed_in::<P9>((&raw mut DP_P9).cast()),
            zeroed_in::<S9>((&raw mut DP_S9).cast()),
        )
    };
    dp_rows(
        "DP-TBD first order 3x3 i16, 128x128, L 8",
        a9,
        DpConfig::dim_point(Method::Arnold, 1),
        8,
    );
    dp_rows(
        "DP-TBD Pulford 3x3 i16, 128x128, L 8",
        p9,
        DpConfig::dim_point(Method::Pulford, 1),
        3,
    );
    dp_rows(
        "DP-TBD second order 3x3/3x3 i16, 128x128, L 8",
        s9,
        DpConfig::dim_point(Method::SecondOrder, 1),
        3,
    );
}

#[entry]
fn main() -> ! {
    harness::init();
    hprintln!("faint cycles regions: Cortex-M4F on QEMU mps2-an386, -icount shift=10");
    micros();
    crpf();
    mht();
    dp();
    cbmember();
    phd();
    hprintln!("done");
    exit_success()
}
