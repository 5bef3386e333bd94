//! Link-time proof that the PHD family (Pei et al. 2019: SMC-PHD-TBD, PSO-PHD-TBD with
//! K-means, PSO-PHD-TBD with DBSCAN) contains no reachable panic: `configure`, `reset`,
//! `step` (the golden scene's frames, frames of zeros and of huge finite powers, NaN,
//! infinite, negative, short and long frames), the detections and every other public
//! query of `SmcPhdTbd`, with Gaussian and measurement-driven births, the swarm with and
//! without point refinement, single-cell and merged-cell normalisation, and rejected
//! configurations, at the firmware's `SmcPhdTbdM4`, the golden case's
//! `SmcPhdTbd<256, 256, 4, 4>` and a one-target, one-point `SmcPhdTbd<64, 16, 1, 1>`;
//! plus the public building blocks (`Swarm`, `non_dominated_sort`, `crowding_distance`,
//! `ndsort::rank_sorted`, `Dbscan`, `KMeans`) with workspaces shorter than their inputs,
//! on inputs hidden from the optimiser. As in `panic_never.rs`, the panic handler calls a
//! function that does not exist, so the fat-LTO link fails with an undefined reference to
//! `faint_core_panic_path_survived` if any panic path survives:
//!
//! ```sh
//! cd firmware && cargo run --profile firmware --features panic-never --bin panic-never-phd
//! ```
//!
//! The binary then runs the calls once and exits with status 0 (1 if a result was not
//! the expected `Ok` or `Err`). It prints without `core::fmt`.
#![no_std]
#![no_main]

faint_firmware::panic_never!();

use core::hint::black_box;

use cortex_m_rt::entry;
use faint_core::detect::phd::dbscan::{Dbscan, DbscanParams};
use faint_core::detect::phd::kmeans::KMeans;
use faint_core::detect::phd::ndsort::non_dominated_sort;
use faint_core::detect::phd::ndsort::{rank_sorted, Workspace};
use faint_core::detect::phd::pso::{crowding_distance, PsoConfig, Swarm};
use faint_core::detect::phd::{BirthMode, SmcPhdTbd, SmcPhdTbdM4, SmcPhdTbdSmall};
use faint_core::detect::Detector;
use faint_core::model::power_cube::CubeGeometry;
use faint_core::rng::Rng;
use faint_firmware::semihosting::finish;
use faint_firmware::statics::only_ref;
use faint_golden::phd::{config, cube, ALGORITHMS, FIRMWARE_WINDOW, GOLDEN_WINDOW};

/// The firmware's shape (`firmware/src/rows/phd.rs`).
type Big = SmcPhdTbdM4;
/// The golden case's shape (`golden/src/phd.rs`).
type Small = SmcPhdTbdSmall;
/// One target, one swarm point.
type Tiny = SmcPhdTbd<64, 16, 1, 1>;

/// Cube buffer: one cell more than the firmware window, for the long frame.
const CELLS: usize = 32 * 32 * 32 + 1;

static mut BIG: Big = Big::new_unconfigured();
static mut SMALL: Small = Small::new_unconfigured();
static mut TINY: Tiny = Tiny::new_unconfigured();
static mut SWARM: Swarm<64, 4> = Swarm::new();
static mut DBSCAN: Dbscan<128> = Dbscan::new();
static mut KMEANS: KMeans<128, 4> = KMeans::new();
static mut CUBE: [f32; CELLS] = [0.0; CELLS];

#[entry]
fn main() -> ! {
    finish(
        run(),
        b"panic-never-phd: PHD-TBD, PSO-PHD-TBD (K-means) and PSO-PHD-TBD (DBSCAN) linked without a panic path and ran ok\n",
        b"panic-never-phd: a call did not return the expected Ok or Err\n",
    )
}

fn run() -> bool {
    let mut rng = Rng::from_stream(black_box(0x0002_0019_9E1D_7BD0), black_box(3));
    let mut ok = true;
    // SAFETY: single-threaded, `run` is called once: each `&mut` is the only reference
    // to its static.
    let (big, small, tiny, swarm, dbscan, kmeans, buf) = unsafe {
        (
            only_ref(&raw mut BIG),
            only_ref(&raw mut SMALL),
            only_ref(&raw mut TINY),
            only_ref(&raw mut SWARM),
            only_ref(&raw mut DBSCAN),
            only_ref(&raw mut KMEANS),
            only_ref(&raw mut CUBE),
        )
    };
    // The firmware's shape and counts on its window: two scene frames per variant (the
    // PSO frames cost ~1e8 instructions each).
    ok &= filter(big, FIRMWARE_WINDOW, 1000, 500, 8, 2, &mut rng, buf);
    ok &= filter(small, GOLDEN_WINDOW, 60, 64, 4, 10, &mut rng, buf);
    ok &= filter(tiny, GOLDEN_WINDOW, 20, 24, 1, 4, &mut rng, buf);
    ok &= helpers(swarm, dbscan, kmeans, &mut rng);
    ok
}

/// Every algorithm (and DBSCAN without the swarm) on `frames` scene frames of window `g`,
/// then the bad frames, the queries, a reset, the variants and rejected configurations.
#[allow(clippy::too_many_arguments)]
fn filter<const N: usize, const S: usize, const M: usize, const K: usize>(
    det: &mut SmcPhdTbd<N, S, M, K>,
    g: CubeGeometry,
    per_target: usize,
    births: usize,
    points: usize,
    frames: usize,
    rng: &mut Rng,
    buf: &mut [f32],
) -> bool {
    let mut ok = true;
    let g = black_box(g);
    let len = g.len();
    let mut algs = ALGORITHMS;
    let mut dbscan_only = ALGORITHMS[2];
    dbscan_only.pso = false;
    let n_algs = algs.len();
    for v in 0..n_algs + 1 {
        let alg = match algs.get_mut(v) {
            Some(a) => *a,
            None => dbscan_only,
        };
        let mut cfg = config(
            g,
            alg,
            black_box(per_target),
            black_box(births),
            black_box(points),
        );
        if v == 1 {
            cfg.birth.mode = BirthMode::Gaussian;
            cfg.merge_adjacent_cells = false;
        }
        if v == 2 {
            if let Some(p) = cfg.pso.as_mut() {
                p.refine_points = false;
                p.max_members = black_box(usize::MAX);
            }
            cfg.birth.mode = BirthMode::Measurement {
                cells: 16,
                tangential_std: 40.0,
                pair_max_speed: 30.0,
            };
        }
        let cfg = black_box(cfg);
        ok &= det.configure(&cfg, black_box(11)).is_ok();
        let mut scene = Rng::from_stream(black_box(5), black_box(500));
        for k in 0..black_box(frames) {
            if let Some(b) = buf.get_mut(..len) {
                cube(&g, k, &mut scene, b);
            }
            ok &= det.step(black_box(buf.get(..len).unwrap_or(&[]))).is_ok();
            ok &= queries(det);
        }
        ok &= bad_frames(det, len, rng, buf);
        det.reset(black_box(12));
        ok &= det.step(buf.get(..len).unwrap_or(&[])).is_ok();
        ok &= queries(det);
    }
    // Rejected configurations leave the filter as it was.
    let good = config(g, ALGORITHMS[1], per_target, births, points);
    let mut bad = good;
    bad.particles_per_target = black_box(0);
    ok &= det.configure(&bad, 1).is_err();
    let mut bad = good;
    bad.pso = Some(PsoConfig {
        points: black_box(M + 1),
        ..PsoConfig::paper()
    });
    ok &= det.configure(&bad, 1).is_err();
    let mut bad = good;
    bad.birth.particles = black_box(N);
    ok &= det.configure(&bad, 1).is_err();
    let mut bad = good;
    bad.noise_var = black_box(f32::NAN);
    ok &= det.configure(&bad, 1).is_err();
    ok &= queries(det);
    ok
}

/// Frames of zeros and of huge finite powers (steps), NaN, infinite and negative cells,
/// short, long and empty frames (errors).
fn bad_frames<const N: usize, const S: usize, const M: usize, const K: usize>(
    det: &mut SmcPhdTbd<N, S, M, K>,
    len: usize,
    rng: &mut Rng,
    buf: &mut [f32],
) -> bool {
    let mut ok = true;
    for v in [0.0, f32::MAX, 3.0e38, 1.0e-40] {
        for z in buf.iter_mut() {
            *z = black_box(v) * rng.uniform();
        }
        ok &= det.step(buf.get(..len).unwrap_or(&[])).is_ok();
        ok &= queries(det);
    }
    let at = black_box(len / 3);
    for v in [f32::NAN, f32::INFINITY, -1.0] {
        if let Some(z) = buf.get_mut(at) {
            *z = black_box(v);
        }
        ok &= det.step(buf.get(..len).unwrap_or(&[])).is_err();
    }
    if let Some(z) = buf.get_mut(at) {
        *z = 1.0;
    }
    ok &= det
        .step(buf.get(..black_box(len).saturating_sub(1)).unwrap_or(&[]))
        .is_err();
    ok &= det
        .step(buf.get(..black_box(len) + 1).unwrap_or(&[]))
        .is_err();
    ok &= det.step(black_box(&[])).is_err();
    ok
}

/// Every query; false if one is inconsistent.
fn queries<const N: usize, const S: usize, const M: usize, const K: usize>(
    det: &SmcPhdTbd<N, S, M, K>,
) -> bool {
    let mut acc = 0.0f32;
    let n = det.detection_count();
    for i in 0..black_box(n + 2) {
        if let Some(d) = det.detection(i) {
            acc += d.score + d.state().iter().sum::<f32>();
        }
    }
    for e in det.estimates() {
        acc += e.state[0] + e.support as f32;
    }
    let (x, w) = det.particles();
    acc += x.len() as f32 + w.iter().sum::<f32>();
    acc += det.measurement_points().len() as f32;
    acc += det.config().noise_var;
    black_box(acc);
    det.estimates().len() == n && det.detection(n).is_none()
}

/// The public building blocks with hidden sizes, short workspaces and odd arguments.
fn helpers(
    swarm: &mut Swarm<64, 4>,
    dbscan: &mut Dbscan<128>,
    kmeans: &mut KMeans<128, 4>,
    rng: &mut Rng,
) -> bool {
    let mut ok = true;
    // Swarm: 32 parents in groups 0..5 (ids >= M share the last group), four points.
    let points = [[10.0, 10.0], [40.0, 12.0], [25.0, 30.0], [60.0, 60.0]];
    let cfg = black_box(PsoConfig {
        points: 4,
        ..PsoConfig::paper()
    });
    for p in 0..black_box(4usize) {
        let pts = points.get(..p + 1).unwrap_or(&points);
        swarm.clear();
        for i in 0..black_box(40u32) {
            let pos = [rng.uniform_range(0.0, 70.0), rng.uniform_range(0.0, 70.0)];
            ok &= swarm.push(pos, 0.01, i, (i % 6) as u16) == (i < 32);
        }
        let r = swarm.run(&cfg, pts, rng);
        ok &= r.generations >= cfg.generations;
        let m = black_box(pts.len() + 3);
        for i in 0..black_box(swarm.len + 2) {
            let (j, v) = swarm.best_objective(i.min(63), m);
            black_box((j, v));
        }
    }
    ok &= Swarm::<64, 4>::capacity() == 32;
    swarm.clear();
    ok &= swarm.run(&cfg, &[], rng).generations == 0;

    // Non-dominated sort and crowding distance, workspaces shorter than the input.
    let mut f = [[0.0f32; 3]; 40];
    for r in f.iter_mut() {
        for v in r.iter_mut() {
            *v = (rng.uniform() * 4.0) as u32 as f32;
        }
    }
    let mut rank = [0u32; 40];
    let mut order = [0u32; 40];
    let mut next = [0u32; 40];
    let mut head = [0u32; 40];
    let mut crowd = [0.0f32; 40];
    for m in 0..black_box(5usize) {
        let cut = black_box(40 - m * 3);
        let fronts = non_dominated_sort(
            &f,
            m,
            &mut rank,
            order.get_mut(..cut).unwrap_or(&mut []),
            &mut next,
            &mut head,
        );
        ok &= fronts <= 40;
        crowding_distance(
            &f,
            m,
            &[0.5, 0.25, 0.25],
            &rank,
            1.0e9,
            crowd.get_mut(..cut).unwrap_or(&mut []),
            &mut order,
        );
        let mut scratch = [0u32; 40];
        let mut order1 = [0u32; 40];
        let mut fen = [0u32; 40];
        let fr = rank_sorted(
            black_box(40),
            m,
            |p, j| f.get(p).and_then(|r| r.get(j)).copied().unwrap_or(0.0),
            &mut rank,
            Workspace {
                work: order.get_mut(..cut).unwrap_or(&mut []),
                scratch: &mut scratch,
                order1: &mut order1,
                fenwick: &mut fen,
            },
        );
        ok &= fr <= 40;
    }

    // DBSCAN and K-means: clustered points, a NaN, too many points, bad parameters.
    let mut pts = [[0.0f32; 2]; 130];
    for (i, p) in pts.iter_mut().enumerate() {
        let c = (i % 3) as f32 * 50.0;
        *p = [c + rng.normal(), c + rng.normal()];
    }
    let params = black_box(DbscanParams {
        eps: 3.0,
        min_pts: 4,
    });
    let n = black_box(128usize);
    let mut members = 0usize;
    let r = dbscan.run(pts.get(..n).unwrap_or(&[]), &params, |m| members += m.len());
    ok &= matches!(r, Ok(c) if c >= 1);
    ok &= dbscan.run(&pts, &params, |_| {}).is_err();
    ok &= dbscan
        .run(
            pts.get(..n).unwrap_or(&[]),
            &DbscanParams {
                eps: black_box(-1.0),
                min_pts: 4,
            },
            |_| {},
        )
        .is_err();
    ok &= kmeans
        .run(
            pts.get(..n).unwrap_or(&[]),
            black_box(3),
            black_box(20),
            rng,
        )
        .is_ok();
    ok &= kmeans
        .run(
            pts.get(..n).unwrap_or(&[]),
            black_box(9),
            black_box(20),
            rng,
        )
        .is_ok();
    ok &= kmeans.run(&pts, 3, 20, rng).is_err();
    if let Some(p) = pts.get_mut(black_box(7)) {
        *p = [f32::NAN, 0.0];
    }
    ok &= dbscan
        .run(pts.get(..n).unwrap_or(&[]), &params, |_| {})
        .is_err();
    ok &= kmeans.run(pts.get(..n).unwrap_or(&[]), 3, 20, rng).is_err();
    black_box(members);
    ok
}
