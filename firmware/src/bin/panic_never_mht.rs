//! Link-time proof that MHT-TBD (Bao et al. 2022: plot censoring, the data-matched Hough
//! transform, condensing, track recovery, confirmation and merging) and the classic Hough
//! TBD (Carlson, Evans, Wilson 1994) contain no reachable panic: `configure`, `reset`,
//! `step` (scans of clutter and target plots, NaN/inf and out-of-area plots, more plots
//! than the capacity, empty scans), `redetect`, `set_gamma1`, the detections and every
//! other public query of `MhtTbd` and `ClassicHough`, and the public Hough helpers
//! (`Geometry`, `Accumulator`, `Censor::step`, `dmht::recover`) with arguments out of
//! their documented ranges, at the firmware's `MhtTbdM4`, the
//! golden case's `MhtTbdSmall`, and `ClassicHoughHost` and
//! `ClassicHoughSmall`, on inputs hidden from the optimiser. As in `panic_never.rs`, the panic
//! handler calls a function that does not exist, so the fat-LTO link fails with an
//! undefined reference to `faint_core_panic_path_survived` if any panic path survives:
//!
//! ```sh
//! cd firmware && cargo run --profile firmware --features panic-never --bin panic-never-mht
//! ```
//!
//! The binary then runs the calls once and exits with status 0 (1 if a result was not
//! the expected `Ok` or `Err`). It prints without `core::fmt`.
#![no_std]
#![no_main]

faint_firmware::panic_never!();

use core::hint::black_box;

use cortex_m_rt::entry;
use faint_core::detect::mht::censoring::Censor;
use faint_core::detect::mht::dmht::{recover, Assoc};
use faint_core::detect::mht::{
    in_area, Accumulator, ClassicHough, ClassicHoughConfig, ClassicHoughHost, ClassicHoughSmall,
    Geometry, MhtConfig, MhtTbd, MhtTbdM4, MhtTbdSmall, Peak, Track,
};
use faint_core::detect::{Detector, Validate};
use faint_core::model::plot::Plot;
use faint_core::rng::Rng;
use faint_core::simulate;
use faint_firmware::semihosting::finish;
use faint_firmware::statics::only_ref;

/// The firmware's shape (`firmware/src/rows/mht.rs`).
type Big = MhtTbdM4;
/// The golden case's shape (`golden/src/mht.rs`).
type Small = MhtTbdSmall;
type ClassicBig = ClassicHoughHost;
type ClassicSmall = ClassicHoughSmall;

/// Plot buffer: more than the largest capacity, for the overflow scan.
const BUF: usize = 600;

static mut BIG: Big = Big::new_unconfigured();
static mut SMALL: Small = Small::new_unconfigured();
static mut CLASSIC_BIG: ClassicBig = ClassicBig::new_unconfigured();
static mut CLASSIC_SMALL: ClassicSmall = ClassicSmall::new_unconfigured();
static mut ACC: Accumulator<256, 180> = Accumulator::new();
static mut CENSOR: Censor<512> = Censor::new();
static mut FLAGS: [[u8; 512]; 8] = [[0; 512]; 8];
static mut PLOTS: [Plot; BUF] = [Plot::new(0.0, 0.0, 0.0); BUF];

#[entry]
fn main() -> ! {
    finish(
        run(),
        b"panic-never-mht: MHT-TBD and the classic Hough TBD linked without a panic path and ran ok\n",
        b"panic-never-mht: a call did not return the expected Ok or Err\n",
    )
}

fn run() -> bool {
    let mut rng = Rng::from_stream(black_box(0x0B40_2022), black_box(7));
    let mut ok = true;
    // SAFETY: single-threaded, `run` is called once: each `&mut` is the only reference
    // to its static.
    let (big, small, cbig, csmall, acc, censor, flags, buf) = unsafe {
        (
            only_ref(&raw mut BIG),
            only_ref(&raw mut SMALL),
            only_ref(&raw mut CLASSIC_BIG),
            only_ref(&raw mut CLASSIC_SMALL),
            only_ref(&raw mut ACC),
            only_ref(&raw mut CENSOR),
            only_ref(&raw mut FLAGS),
            only_ref(&raw mut PLOTS),
        )
    };
    ok &= mht(big, &mut rng, buf);
    ok &= mht(small, &mut rng, buf);
    ok &= classic(cbig, &mut rng, buf);
    ok &= classic(csmall, &mut rng, buf);
    // `ClassicHough::new` by value (the small shape fits the stack).
    let area = black_box([0.0, 1500.0, 0.0, 1500.0]);
    let ccfg = ClassicHoughConfig {
        area,
        n_scans: black_box(4),
        gamma: black_box(3),
    };
    match ClassicSmall::new(ccfg) {
        Ok(mut d) => ok &= classic(&mut d, &mut rng, buf),
        Err(_) => ok = false,
    }
    ok &= ClassicSmall::new(ClassicHoughConfig {
        gamma: black_box(0),
        ..ccfg
    })
    .is_err();
    ok &= helpers::<256, 180>(acc, &mut rng, buf);
    ok &= censoring(censor, flags, &mut rng, buf);
    ok
}

/// What a scan of the exercise holds.
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    /// Clutter and targets.
    Good,
    /// Clutter, targets and invalid plots (NaN, infinite, outside the area).
    Bad,
    /// More plots than any capacity.
    Overflow,
    /// No plot.
    Empty,
}

/// Writes scan `s` of `kind` into `buf`: `clutter` uniform plots over `area`, three
/// constant-velocity targets, and the kind's extras; returns the plot count.
fn make_scan(
    kind: Kind,
    s: usize,
    area: [f32; 4],
    clutter: usize,
    rng: &mut Rng,
    buf: &mut [Plot; BUF],
) -> usize {
    let n = match kind {
        Kind::Empty => 0,
        Kind::Overflow => BUF,
        _ => clutter.min(BUF - 8),
    };
    let Some(out) = buf.get_mut(..n) else {
        return 0;
    };
    let mut n = simulate::clutter_plots(rng, area, out, |r| 1.0 + r.uniform());
    if kind == Kind::Empty || kind == Kind::Overflow {
        return n;
    }
    let (w, h) = (area[1] - area[0], area[3] - area[2]);
    let t = s as f32;
    let targets = [
        (
            area[0] + 0.1 * w + 0.02 * w * t,
            area[2] + 0.2 * h + 0.015 * h * t,
        ),
        (
            area[1] - 0.1 * w - 0.01 * w * t,
            area[2] + 0.1 * h + 0.02 * h * t,
        ),
        (area[0] + 0.5 * w, area[3] - 0.1 * h - 0.02 * h * t),
    ];
    for (x, y) in targets {
        if let Some((x, y)) = simulate::detection(rng, 0.9, x, y, 0.002 * w) {
            if let Some(p) = buf.get_mut(n) {
                *p = Plot::new(5.0, x, y);
                n += 1;
            }
        }
    }
    if kind == Kind::Bad {
        let bad = [
            Plot::new(1.0, black_box(f32::NAN), area[2]),
            Plot::new(1.0, area[0], black_box(f32::INFINITY)),
            Plot::new(black_box(f32::NAN), area[0], area[2]),
            Plot::new(1.0, area[1] + black_box(1.0e3), area[2]),
            Plot::new(1.0, black_box(-0.0), black_box(-3.0e38)),
        ];
        for p in bad {
            if let Some(o) = buf.get_mut(n) {
                *o = p;
                n += 1;
            }
        }
    }
    black_box(n)
}

/// The scan kinds of a period, by scan index.
fn kind_of(s: usize) -> Kind {
    match black_box(s % 11) {
        3 => Kind::Bad,
        5 if s < 12 => Kind::Overflow,
        7 => Kind::Empty,
        _ => Kind::Good,
    }
}

/// MHT-TBD at one shape: several configurations (the preset; a low `gamma_1` so peaks,
/// tracks, merging and the residual rule run; `M = 8`, no smoothing, no look-back, no
/// residual rule; `gamma_1 = n_scans + 1`), two periods each with every scan kind, the
/// queries after every step, `redetect` and `set_gamma1`, `reset`, and rejected
/// configurations.
fn mht<const P: usize, const NS: usize, const R: usize, const A: usize, const T: usize>(
    det: &mut MhtTbd<P, NS, R, A, T>,
    rng: &mut Rng,
    buf: &mut [Plot; BUF],
) -> bool {
    let mut ok = true;
    let mut acc = 0.0f32;
    // unconfigured: an error
    ok &= det.step(black_box(&buf[..3])).is_err();
    let ns = NS.min(30);
    let area = black_box([
        0.0,
        1500.0 + 150.0 * NS as f32,
        0.0,
        1500.0 + 150.0 * NS as f32,
    ]);
    let preset = MhtConfig {
        area,
        n_scans: black_box(ns),
        gamma1: black_box((ns * 2 / 3) as u8),
        ..MhtConfig::sea_clutter()
    };
    let cfgs = [
        preset,
        MhtConfig {
            gamma1: black_box(3),
            gate: black_box(300.0),
            confirm_frac: black_box(0.2),
            ..preset
        },
        MhtConfig {
            m: black_box(8),
            smooth: black_box(false),
            lookback: black_box(false),
            residual: black_box(false),
            gamma1: black_box(4),
            ..preset
        },
        MhtConfig {
            gamma1: black_box((ns + 1) as u8),
            gate: black_box(1.0e4),
            ..preset
        },
    ];
    let clutter = black_box(P / 3);
    for (i, cfg) in cfgs.iter().enumerate() {
        ok &= det.configure(cfg, black_box(i as u64)).is_ok();
        ok &= det.config().validate().is_ok();
        for s in 0..black_box(2 * ns + 1) {
            let n = make_scan(kind_of(s), s % ns, area, clutter, rng, buf);
            let scan = buf.get(..n).unwrap_or(&[]);
            match det.step(black_box(scan)) {
                Ok(r) => {
                    acc += r.plots_in as f32 + f32::from(r.plots_kept) + r.censor.chains as f32;
                    if let Some(p) = r.detection {
                        acc += p.origin.0 + p.drho + f32::from(p.tracks);
                        for g in [black_box(1u8), black_box(3), black_box(200)] {
                            if let Ok(q) = det.redetect(g) {
                                acc += f32::from(q.tracks) + f32::from(q.merged);
                            }
                        }
                        ok &= det.redetect(black_box(0)).is_err();
                        if let Ok(q) = det.redetect(cfg.gamma1) {
                            acc += f32::from(q.tracks);
                        }
                    } else {
                        ok &= det.redetect(black_box(2)).is_err();
                    }
                }
                Err(_) => ok = false,
            }
            acc += queries(det, s);
        }
    }
    ok &= det.set_gamma1(black_box(0)).is_err();
    ok &= det.set_gamma1(black_box(250)).is_ok();
    let n = make_scan(Kind::Good, 0, area, clutter, rng, buf);
    ok &= det.step(black_box(buf.get(..n).unwrap_or(&[]))).is_ok();
    det.reset(black_box(4));
    acc += queries(det, 0);
    ok &= det.step(black_box(&buf[..n.min(5)])).is_ok();
    // rejected configurations
    for bad in [
        MhtConfig {
            m: black_box(2),
            ..preset
        },
        MhtConfig {
            n_scans: black_box(NS + 1),
            ..preset
        },
        MhtConfig {
            gate: black_box(f32::NAN),
            ..preset
        },
        MhtConfig {
            area: [0.0, black_box(3.0e38), 0.0, 1.0],
            ..preset
        },
        MhtConfig {
            gamma1: black_box(255),
            ..preset
        },
    ] {
        ok &= det.configure(&bad, 0).is_err();
        ok &= bad.validate().is_err() || NS < bad.n_scans;
    }
    black_box(acc);
    ok
}

/// Every public query of MHT-TBD at positions hidden from the optimiser.
fn queries<const P: usize, const NS: usize, const R: usize, const A: usize, const T: usize>(
    det: &MhtTbd<P, NS, R, A, T>,
    s: usize,
) -> f32 {
    let mut acc = 0.0f32;
    for d in det.detections() {
        acc += d.score + d.state().iter().sum::<f32>();
    }
    for i in [black_box(0usize), black_box(T), black_box(usize::MAX)] {
        if let Some(d) = det.detection(i) {
            acc += d.score;
        }
    }
    acc += det.detection_count() as f32;
    for t in det.tracks() {
        acc += t.theta + t.c + f32::from(t.n_plots) + f32::from(t.peak.value16);
    }
    for s in [black_box(s), black_box(NS), black_box(usize::MAX)] {
        acc += det.scan_plots(s).len() as f32 + det.effective_count(s) as f32;
        acc += f32::from(u8::from(det.is_effective(s, black_box(3))));
        acc += f32::from(u8::from(det.is_effective(s, black_box(P + 9))));
    }
    let g = det.dmht_geometry();
    acc += g.drho() + g.rho_max() + det.msht_geometry().origin().1;
    let a = det.accumulator();
    acc += f32::from(a.count(black_box(R + 3), black_box(A * 2 + 1)));
    acc += f32::from(a.value16(black_box(7), black_box(usize::MAX)));
    acc
}

/// The classic Hough TBD: two configurations, every scan kind, the queries, `reset`, a
/// rejected configuration.
fn classic<const R: usize, const A: usize, const T: usize>(
    det: &mut ClassicHough<R, A, T>,
    rng: &mut Rng,
    buf: &mut [Plot; BUF],
) -> bool {
    let mut ok = true;
    let mut acc = 0.0f32;
    let area = black_box([-3000.0, 3000.0, 0.0, 6000.0]);
    let base = ClassicHoughConfig {
        area,
        n_scans: black_box(10),
        gamma: black_box(5),
    };
    let cfgs = [
        base,
        ClassicHoughConfig {
            n_scans: black_box(3),
            gamma: black_box(1),
            ..base
        },
    ];
    for (i, cfg) in cfgs.iter().enumerate() {
        ok &= det.configure(cfg, black_box(i as u64)).is_ok();
        ok &= det.config().validate().is_ok();
        for s in 0..black_box(23usize) {
            let n = make_scan(kind_of(s), s, area, black_box(40), rng, buf);
            match det.step(black_box(buf.get(..n).unwrap_or(&[]))) {
                Ok(r) => acc += f32::from(r.plots_used) + f32::from(r.condense.peaks),
                Err(_) => ok = false,
            }
            for d in det.detections() {
                acc += d.score + d.state().iter().sum::<f32>();
            }
            for i in [black_box(0usize), black_box(T), black_box(usize::MAX)] {
                if let Some(d) = det.detection(i) {
                    acc += d.score;
                }
            }
            for p in det.peaks() {
                acc += f32::from(p.raw) + f32::from(p.cells);
            }
            acc += det.detection_count() as f32 + det.geometry().drho();
            acc += f32::from(det.accumulator().count(black_box(R), black_box(1)));
        }
    }
    det.reset(black_box(1));
    ok &= det.step(black_box(&buf[..4])).is_ok();
    ok &= det
        .configure(
            &ClassicHoughConfig {
                n_scans: black_box(0),
                ..base
            },
            0,
        )
        .is_err();
    black_box(acc);
    ok
}

/// The public Hough helpers with arguments in and out of their documented ranges:
/// geometry (degenerate, NaN, huge), the accumulator (add, finish, condense into short
/// and empty outputs), and track recovery with mismatched scans and flags.
fn helpers<const R: usize, const A: usize>(
    acc: &mut Accumulator<R, A>,
    rng: &mut Rng,
    buf: &mut [Plot; BUF],
) -> bool {
    let mut sum = 0.0f32;
    let area = black_box([0.0, 6000.0, 0.0, 6000.0]);
    let geoms = [
        Geometry::<R, A>::for_area(area),
        Geometry::<R, A>::new(black_box(f32::NAN), black_box(1.0), black_box(-5.0)),
        Geometry::<R, A>::new(
            black_box(3.0e38),
            black_box(-3.0e38),
            black_box(f32::INFINITY),
        ),
        Geometry::<R, A>::placeholder(),
    ];
    let pts = [
        (black_box(100.0f32), black_box(200.0f32)),
        (black_box(f32::NAN), black_box(1.0)),
        (black_box(3.0e38), black_box(-3.0e38)),
        (black_box(-0.0), black_box(f32::INFINITY)),
    ];
    for g in &geoms {
        for &(x, y) in &pts {
            for a in [
                black_box(0usize),
                black_box(A - 1),
                black_box(A),
                black_box(usize::MAX),
            ] {
                sum += g.rho(x, y, a) + g.theta(a) + g.trig(a).1;
                sum += g.rho_index_f32(x, y, a) as f32;
                let (xq, yq) = g.quantise(x, y);
                sum += g.rho_index_q(xq, yq, a) as f32;
                sum += g.rho_index_q(black_box(i32::MAX), black_box(i32::MIN), a) as f32;
                sum += g.rho_center(black_box(a));
            }
            let (xq, yq) = g.quantise(x, y);
            let mut curve = [0u16; A];
            g.curve_q(xq, yq, &mut curve);
            sum += f32::from(curve[A / 2]);
        }
        let q = [
            g.quantise(1.0, 2.0),
            g.quantise(black_box(3.0), 4.0),
            (black_box(i32::MIN), black_box(i32::MAX)),
        ];
        let m = black_box(3usize);
        sum += f32::from(u8::from(g.share_cell(q.get(..m).unwrap_or(&[]))));
        sum += f32::from(u8::from(g.share_cell(&[])));
        for (dr, da) in [
            (-1isize, -1isize),
            (1, 1),
            (isize::MIN, isize::MAX),
            (0, black_box(-5)),
        ] {
            for (r, a) in [
                (0usize, 0usize),
                (R - 1, A - 1),
                (R + 4, A + 9),
                (usize::MAX, 1),
            ] {
                if let Some(c) = Geometry::<R, A>::neighbour(black_box(r), black_box(a), dr, da) {
                    sum += c as f32;
                }
            }
        }
        sum += g.origin().0 + g.drho() + g.rho_max();
    }
    // accumulator: one period of 6 scans on the area's grid, then every output size
    let g = &geoms[0];
    let Some(g1) = geoms.get(black_box(1)) else {
        return false;
    };
    acc.reset();
    for s in 0..black_box(6usize) {
        let n = make_scan(kind_of(s), s, area, black_box(60), rng, buf);
        for p in buf.get(..n).unwrap_or(&[]) {
            acc.add_point(g, black_box((s + 1) as u8), p.x, p.y);
            sum += f32::from(u8::from(in_area(p, area)));
        }
        acc.add_point(g1, black_box(0), black_box(f32::NAN), 1.0);
    }
    let mut peaks = [Peak::default(); 8];
    for smooth in [black_box(true), black_box(false)] {
        acc.finish(smooth);
        for (gamma, len) in [
            (black_box(2u8), 8usize),
            (black_box(0), 3),
            (black_box(4), 0),
        ] {
            let out = peaks.get_mut(..black_box(len)).unwrap_or(&mut []);
            let st = acc.condense(gamma, out);
            sum += f32::from(st.peaks) + f32::from(st.dropped) + f32::from(st.stack_overflow);
        }
    }
    sum += f32::from(acc.count(black_box(R * 3), black_box(A + 1)));
    sum += f32::from(acc.value16(black_box(1), black_box(2)));
    // track recovery: scans of the buffer, flags shorter and longer than the scans
    const NS: usize = 6;
    let n = make_scan(Kind::Good, 0, area, black_box(40), rng, buf);
    let (first, rest) = buf.split_at(n.min(BUF / 2));
    let scans: [&[Plot]; NS] = [first, rest, first, &[], first, rest];
    let mut flags = [[0u8; 64]; NS];
    for (i, f) in flags.iter_mut().enumerate() {
        f.fill(black_box((i % 2) as u8));
    }
    let assocs = [
        Assoc {
            d_max: black_box(50.0),
            along_gate: black_box(200.0),
            lookback: black_box(true),
        },
        Assoc {
            d_max: black_box(f32::NAN),
            along_gate: black_box(f32::INFINITY),
            lookback: black_box(false),
        },
    ];
    let mut track = Track::<NS>::default();
    for (i, &pk) in peaks.iter().enumerate() {
        let pk = if i == 7 {
            Peak {
                r: black_box(u16::MAX),
                a: black_box(u16::MAX),
                ..pk
            }
        } else {
            pk
        };
        for assoc in &assocs {
            let nf = black_box(i % (NS + 1));
            let ns = black_box((i * 5) % (NS + 2));
            recover::<R, A, 64, NS>(
                g,
                pk,
                scans.get(..ns).unwrap_or(&scans),
                flags.get(..nf).unwrap_or(&flags),
                assoc,
                &mut track,
            );
            sum += track.theta + track.c + f32::from(track.n_plots) + track.lookback as f32;
            // a track type longer than the scans
            let mut long = Track::<9>::empty();
            recover::<R, A, 64, 9>(g, pk, &scans, &flags, assoc, &mut long);
            sum += f32::from(long.n_effective);
        }
    }
    black_box(sum);
    true
}

/// `Censor::step` directly: a valid sweep over 8 scans at `m = 3..=8`, then arguments out
/// of range (bad `m`, NaN gate, short flags, `s` past the scans, a scan longer than `P`).
fn censoring<const P: usize>(
    censor: &mut Censor<P>,
    flags: &mut [[u8; P]; 8],
    rng: &mut Rng,
    buf: &mut [Plot; BUF],
) -> bool {
    let mut sum = 0u32;
    let area = black_box([0.0, 6000.0, 0.0, 6000.0]);
    let geom = Geometry::<256, 180>::for_area(area);
    let n = make_scan(Kind::Good, 0, area, black_box(P / 4), rng, buf);
    let whole: &[Plot] = &buf[..];
    let (a, b) = whole.split_at(n.min(BUF / 2));
    // `whole` is longer than `P` (600 > 512): its tail is ignored
    let scans: [&[Plot]; 8] = [a, b, whole, b, &[], a, whole, a];
    for m in 3..=black_box(8usize) {
        for s in 0..black_box(8usize) {
            let gate = black_box(if m == 8 { 1.0e9 } else { 150.0 });
            let st = censor.step(&geom, &scans, flags, s, m, gate);
            sum += st.pairs + st.chains + st.newly_effective + st.chain_overflow + st.pair_overflow;
        }
    }
    for (s, m, gate, nf, ns) in [
        (black_box(3usize), black_box(2usize), 100.0, 8usize, 8usize),
        (3, 9, 100.0, 8, 8),
        (3, 3, black_box(f32::NAN), 8, 8),
        (5, 3, 100.0, black_box(2), 8),
        (7, 3, 100.0, 8, black_box(3)),
        (black_box(usize::MAX), 3, 100.0, 8, 8),
        (2, 3, black_box(-1.0), 8, 8),
    ] {
        let scans = scans.get(..ns).unwrap_or(&[]);
        let flags = flags.get_mut(..nf).unwrap_or(&mut []);
        let st = censor.step(&geom, scans, flags, s, m, gate);
        sum += st.pairs + st.chains;
    }
    black_box(sum);
    true
}
