//! Soak on the emulated Cortex-M4F: every detector of `faint detect --list` streamed
//! `frames` plausible frames without a reset, in the sizes below (the loop, its counts
//! and its stack window: `faint_firmware::soak`).
//!
//! ```sh
//! cd firmware && cargo run -q --profile firmware --bin soak
//! cd firmware && cargo run -q --profile firmware --bin soak -- -append "frames=200000 only=pf-lrt"
//! ```
//!
//! Arguments (QEMU's `-append`, read through semihosting): `frames=N` (default 10 000)
//! and `only=a,b` (names as in `faint detect --list`; default all). The diagnostic
//! variants `pf-lrt-fixed-rate` and `pf-lrt-fixed-amp` run only when named.
//!
//! **Frames** are those of the host's `faint soak` (mode `Plausible`, one stream
//! `Rng::seed_from_u64(1)`, detector seed 1), drawn by the same code,
//! `faint_golden::soak`: noise at the preset's scale, one value in 8 with a strong
//! return added (ten times the noise std); Doppler frames of 32 complex bins, power maps
//! and cubes `|x|^2`, DP images of signed values (std 1.5), and plot lists of 0 to twice
//! the capacity. The Doppler-frame filters (1000 particles), MHT-TBD and the classic
//! Hough TBD have the host's types and configuration, so they see the host soak's frames
//! bit for bit (a host test checks the sizes and configurations against the host's).
//!
//! **Sizes** (the preset would take hours under QEMU for some):
//! - CRPF-TBD, PF-TBD, JOTT, PF-LRT: `N = 1000`, the OTHR preset (noise variance 1).
//! - MHT-TBD `MhtTbdHost` and `ClassicHoughHost` with the
//!   host's sea-clutter configurations.
//! - PHD-TBD, PSO-PHD-TBD (K-means, DBSCAN): `SmcPhdTbdSoak` with the golden
//!   scene's filter settings (`faint_golden::phd::config`: 50 particles per target, 25
//!   births, at most 32 swarm particles) on an 8 x 8 x 4 window of the golden scene's cells
//!   (the sizes of the host's `faint soak --shape reduced`, the golden scene's settings).
//! - CBMeMBer (joint, Doppler-only): `CbmemberTbdSoak`, the `rotor-uav` preset on
//!   a 32 x 64 map over the preset's extent, `L_max = 100`, `L_min = 30`, 30 births
//!   (the host's `faint soak --shape reduced`, `faint_golden::soak::cbmember_reduced`).
//! - DP-TBD: the first order on 128 x 128 images (the preset), Pulford and the second order
//!   on 32 x 32 images (the host's `--shape reduced`); `q_B = 9`, `L = 40`.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use faint_core::detect::cbmember::CbmemberTbdSoak;
use faint_core::detect::crpf::{CrpfConfig, CrpfTbd};
use faint_core::detect::dp::preset::{Arnold9, Pulford9Reduced, Second9Reduced};
use faint_core::detect::dp::{DpConfig, Method};
use faint_core::detect::jott::JottTbd;
use faint_core::detect::mht::{ClassicHoughHost, MhtConfig, MhtTbdHost};
use faint_core::detect::pf_lrt::PfLrt;
use faint_core::detect::pf_tbd::{GaussConfig, PfTbd};
use faint_core::detect::phd::{PhdConfig, SmcPhdTbdSoak};
use faint_core::model::doppler::DopplerReport;
use faint_core::model::plot::Plot;
use faint_core::model::power_cube::CubeGeometry;
use faint_core::model::range_doppler::PointModel;
use faint_core::rng::Rng;
use faint_core::Complex32;
use faint_firmware::harness;
use faint_firmware::semihosting::exit_success;
use faint_firmware::soak::args::Args;
use faint_firmware::soak::{self, soak, Spec, BLOCKS};
use faint_firmware::statics::Static;
use faint_firmware::timer;
use faint_golden::soak::{
    cbmember_reduced, complex, plots, reals, CBMEMBER_REDUCED_PIXELS, CLASSIC as CLASSIC_CFG,
    CLASSIC_PLOTS, DOPPLER_BINS, DP_REDUCED_SIDE, DP_SCALE, DP_SIDE, MHT_PLOTS, PHD_REDUCED_CELLS,
    SEED,
};

faint_firmware::report_panics!();

// ---------------------------------------------------------------------------------------
// The detectors, each a `static` of its unconfigured constant set up in place by
// `configure` (all-zero bits, in `.bss`, but MHT-TBD's).

const N: usize = 1000;
type Mht = MhtTbdHost;
type Classic = ClassicHoughHost;
type Phd = SmcPhdTbdSoak;
type Cbm = CbmemberTbdSoak;
const SIDE: usize = faint_core::detect::dp::preset::SIDE;
const SMALL: usize = faint_core::detect::dp::preset::REDUCED_SIDE;
type Arnold = Arnold9;
type Pulford = Pulford9Reduced;
type Second = Second9Reduced;

static CRPF: Static<CrpfTbd<N>> = Static::new(CrpfTbd::new_unconfigured());
static PF: Static<PfTbd<N>> = Static::new(PfTbd::new_unconfigured());
static JOTT: Static<JottTbd<N>> = Static::new(JottTbd::new_unconfigured());
static LRT: Static<PfLrt<N>> = Static::new(PfLrt::new_unconfigured());
static LRT_FIXED_RATE: Static<PfLrt<N>> = Static::new(PfLrt::new_unconfigured());
static LRT_FIXED_AMP: Static<PfLrt<N>> = Static::new(PfLrt::new_unconfigured());
static MHT: Static<Mht> = Static::new(Mht::new_unconfigured());
static CLASSIC: Static<Classic> = Static::new(Classic::new_unconfigured());
static PHD: Static<Phd> = Static::new(Phd::new_unconfigured());
static CBM: Static<Cbm> = Static::new(Cbm::new_unconfigured());
static ARNOLD: Static<Arnold> = Static::new(Arnold::new_unconfigured());
static PULFORD: Static<Pulford> = Static::new(Pulford::new_unconfigured());
static SECOND: Static<Second> = Static::new(Second::new_unconfigured());

const PHD_CELLS: usize = PHD_REDUCED_CELLS[0] * PHD_REDUCED_CELLS[1] * PHD_REDUCED_CELLS[2];
const MAP: usize = CBMEMBER_REDUCED_PIXELS[0] * CBMEMBER_REDUCED_PIXELS[1];
const PLOTS: usize = 2 * MHT_PLOTS + 1;
// The DP images are the shared soak sizes.
const _: () = assert!(SIDE == DP_SIDE && SMALL == DP_REDUCED_SIDE);
static DOPPLER_BUF: Static<[Complex32; DOPPLER_BINS]> =
    Static::new([Complex32::new(0.0, 0.0); DOPPLER_BINS]);
static PLOT_BUF: Static<[Plot; PLOTS]> = Static::new([Plot::new(0.0, 0.0, 0.0); PLOTS]);
static REAL_BUF: Static<[f32; SIDE * SIDE]> = Static::new([0.0; SIDE * SIDE]);

fn doppler_work(r: &DopplerReport) -> (f32, f32) {
    match r.estimate {
        Some(x) => (if x[1] < 0.0 { -x[1] } else { x[1] }, x[2]),
        None => (0.0, 0.0),
    }
}

/// The golden PHD scene's 8 x 8 x 4 cells around its targets.
const PHD_WINDOW: CubeGeometry = CubeGeometry {
    n_range: PHD_REDUCED_CELLS[0],
    n_doppler: PHD_REDUCED_CELLS[1],
    n_azimuth: PHD_REDUCED_CELLS[2],
    ..faint_golden::phd::GOLDEN_WINDOW
};

fn phd_config(alg: usize) -> PhdConfig {
    let mut c =
        faint_golden::phd::config(PHD_WINDOW, faint_golden::phd::ALGORITHMS[alg], 50, 25, 8);
    if let Some(p) = c.pso.as_mut() {
        p.max_members = 32;
    }
    c
}

#[entry]
fn main() -> ! {
    harness::init();
    soak::start();
    let args = Args::read();
    let c_start = timer::coarse();
    hprintln!(
        "faint soak on QEMU mps2-an386 (-icount shift=10): {} frames per detector, {} blocks",
        args.frames,
        BLOCKS
    );
    soak::table_header();
    let zb = DOPPLER_BUF.take();
    let pb = PLOT_BUF.take();
    let rb = REAL_BUF.take();

    let gauss = GaussConfig::othr(1.0);
    let mut dframe = |rng: &mut Rng, out: &mut [Complex32]| complex(rng, out, 1.0);
    if args.selected("crpf") {
        soak(
            &args,
            SEED,
            CRPF.take(),
            &CrpfConfig::othr(),
            Spec {
                name: "crpf",
                shape: "N = 1000, 32 bins",
                frame: &mut dframe,
                buf: &mut zb[..],
                work: doppler_work,
                work_names: ("|fda|", "A"),
            },
        );
    }
    if args.selected("pf-tbd") {
        soak(
            &args,
            SEED,
            PF.take(),
            &gauss,
            Spec {
                name: "pf-tbd",
                shape: "N = 1000, 32 bins",
                frame: &mut dframe,
                buf: &mut zb[..],
                work: doppler_work,
                work_names: ("|fda|", "A"),
            },
        );
    }
    if args.selected("jott") {
        soak(
            &args,
            SEED,
            JOTT.take(),
            &gauss,
            Spec {
                name: "jott",
                shape: "N = 1000, 32 bins",
                frame: &mut dframe,
                buf: &mut zb[..],
                work: doppler_work,
                work_names: ("|fda|", "A"),
            },
        );
    }
    if args.selected("pf-lrt") {
        soak(
            &args,
            SEED,
            LRT.take(),
            &gauss,
            Spec {
                name: "pf-lrt",
                shape: "N = 1000, 32 bins",
                frame: &mut dframe,
                buf: &mut zb[..],
                work: doppler_work,
                work_names: ("|fda|", "A"),
            },
        );
    }
    // Diagnostic variants of PF-LRT (only when named): no Doppler-rate random walk
    // (`accel_std = 0`: every particle keeps the Doppler rate of its prior draw), and no
    // amplitude random walk (`amp_std = 0`).
    for (name, det, cfg) in [
        (
            "pf-lrt-fixed-rate",
            &LRT_FIXED_RATE,
            GaussConfig {
                model: faint_core::model::doppler::ModelConfig {
                    accel_std: 0.0,
                    ..gauss.model
                },
                ..gauss
            },
        ),
        (
            "pf-lrt-fixed-amp",
            &LRT_FIXED_AMP,
            GaussConfig {
                model: faint_core::model::doppler::ModelConfig {
                    amp_std: 0.0,
                    ..gauss.model
                },
                ..gauss
            },
        ),
    ] {
        if args.named(name) {
            soak(
                &args,
                SEED,
                det.take(),
                &cfg,
                Spec {
                    name,
                    shape: "N = 1000, 32 bins",
                    frame: &mut dframe,
                    buf: &mut zb[..],
                    work: doppler_work,
                    work_names: ("|fda|", "A"),
                },
            );
        }
    }
    if args.selected("mht") {
        let cfg = MhtConfig::sea_clutter();
        let area = cfg.area;
        let mut f = |rng: &mut Rng, out: &mut [Plot]| plots(rng, area, MHT_PLOTS, out);
        soak(
            &args,
            SEED,
            MHT.take(),
            &cfg,
            Spec {
                name: "mht",
                shape: "P = 640, 256 x 180",
                frame: &mut f,
                buf: &mut pb[..],
                work: |r| (r.plots_kept as f32, r.censor.chains as f32),
                work_names: ("plots kept", "chains"),
            },
        );
    }
    if args.selected("hough-classic") {
        let area = CLASSIC_CFG.area;
        let mut f = |rng: &mut Rng, out: &mut [Plot]| plots(rng, area, CLASSIC_PLOTS, out);
        soak(
            &args,
            SEED,
            CLASSIC.take(),
            &CLASSIC_CFG,
            Spec {
                name: "hough-classic",
                shape: "256 x 180",
                frame: &mut f,
                buf: &mut pb[..],
                work: |r| (r.plots_used as f32, r.condense.peaks as f32),
                work_names: ("plots", "peaks"),
            },
        );
    }
    let phd_names = ["phd-tbd", "pso-phd-kmeans", "pso-phd-dbscan"];
    if phd_names.iter().any(|n| args.selected(n)) {
        let det = PHD.take();
        for (alg, name) in phd_names.iter().enumerate() {
            if !args.selected(name) {
                continue;
            }
            let mut f =
                |rng: &mut Rng, out: &mut [f32]| reals(rng, &mut out[..PHD_CELLS], 1.0, true);
            soak(
                &args,
                SEED,
                det,
                &phd_config(alg),
                Spec {
                    name,
                    shape: "8 x 8 x 4 cells, 50 per target",
                    frame: &mut f,
                    buf: &mut rb[..],
                    work: |r| (r.particles as f32, r.n_hat as f32),
                    work_names: ("particles", "N_hat"),
                },
            );
        }
    }
    let cbm_names = [
        ("cbmember", PointModel::Joint),
        ("cbmember-doppler", PointModel::DopplerOnly),
    ];
    if cbm_names.iter().any(|(n, _)| args.selected(n)) {
        let det = CBM.take();
        for (name, model) in cbm_names {
            if !args.selected(name) {
                continue;
            }
            let mut f = |rng: &mut Rng, out: &mut [f32]| reals(rng, &mut out[..MAP], 1.0, true);
            soak(
                &args,
                SEED,
                det,
                &cbmember_reduced(model),
                Spec {
                    name,
                    shape: "32 x 64 map, L_max 100",
                    frame: &mut f,
                    buf: &mut rb[..],
                    work: |r| (r.components as f32, r.particles as f32),
                    work_names: ("components", "particles"),
                },
            );
        }
    }
    if args.selected("dp-arnold") {
        let mut f =
            |rng: &mut Rng, out: &mut [f32]| reals(rng, &mut out[..SIDE * SIDE], DP_SCALE, false);
        soak(
            &args,
            SEED,
            ARNOLD.take(),
            &DpConfig::dim_point(Method::Arnold, 1),
            Spec {
                name: "dp-arnold",
                shape: "128 x 128",
                frame: &mut f,
                buf: &mut rb[..],
                work: |r| (r.best.merit, r.clamped as f32),
                work_names: ("best merit", "clamped"),
            },
        );
    }
    let mut small =
        |rng: &mut Rng, out: &mut [f32]| reals(rng, &mut out[..SMALL * SMALL], DP_SCALE, false);
    if args.selected("dp-pulford") {
        soak(
            &args,
            SEED,
            PULFORD.take(),
            &DpConfig::dim_point(Method::Pulford, 1),
            Spec {
                name: "dp-pulford",
                shape: "32 x 32",
                frame: &mut small,
                buf: &mut rb[..],
                work: |r| (r.best.merit, r.clamped as f32),
                work_names: ("best merit", "clamped"),
            },
        );
    }
    if args.selected("dp-second") {
        soak(
            &args,
            SEED,
            SECOND.take(),
            &DpConfig::dim_point(Method::SecondOrder, 1),
            Spec {
                name: "dp-second",
                shape: "32 x 32",
                frame: &mut small,
                buf: &mut rb[..],
                work: |r| (r.best.merit, r.clamped as f32),
                work_names: ("best merit", "clamped"),
            },
        );
    }
    hprintln!("static RAM (.data + .bss): {} bytes", harness::static_ram());
    hprintln!(
        "instructions executed in all (dual timer, 10 per tick): {}",
        u64::from(c_start.wrapping_sub(timer::coarse())) * 10
    );
    hprintln!("done");
    exit_success()
}
