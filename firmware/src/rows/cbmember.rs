//! Cost of CBMeMBer TBD with the joint Doppler / micro-Doppler model (rotor-UAV paper,
//! 2023) on the Cortex-M4F: `CbmemberTbdM4` (4 Bernoulli components of up
//! to 1000 particles, 256 x 32 block sums) on the full 256 x 512 `rotor-uav` map at
//! -10 dB (the scene of `faint_golden::cbmember`), joint at 700 and 1000 particles,
//! Doppler-only at 1000, and joint at 1000 on the quantised `u8` map.
//!
//! The filter is an all-zero `static` set up in place by `configure`; its size is the
//! rows' static RAM. The map is **not** counted: it is the radar's input, which on a
//! board sits in external SDRAM or in the DMA buffer of the range-Doppler processor (the
//! filter only borrows it; `f32` map 512 KiB, `u8` map 128 KiB, separate statics here).
//! Every `step` is measured (map generation is not); rows: mean and worst of frames 1..F-1
//! (frame 0 holds only the first birth), per frame and per particle updated.

use core::hint::black_box;
use core::mem::size_of;

use cortex_m_semihosting::hprintln;
use faint_core::detect::cbmember::{CbmemberConfig, CbmemberTbdM4};
use faint_core::detect::Detector;
use faint_core::model::range_doppler::{quantise, Dequant, PointModel, PowerMap};
use faint_core::rng::Rng;
use faint_golden::cbmember::{config, map};

use faint_firmware::harness::{check, measure, row, Measurement};
use faint_firmware::statics::Static;
use faint_firmware::text::Text;

const SEED: u64 = 0x0003_CB3E_3BE7_2023;
/// Frames per variant.
const FRAMES: usize = 6;
const PIXELS: usize = 256 * 512;

type Det = CbmemberTbdM4;
type DetU8 = CbmemberTbdM4<[u8]>;

// All-zero bits (in `.bss`); `configure` sets them up before any `step`.
static DET: Static<Det> = Static::new(Det::new_unconfigured());
static DET_U8: Static<DetU8> = Static::new(DetU8::new_unconfigured());
static MAP: Static<[f32; PIXELS]> = Static::new([0.0; PIXELS]);
static MAP_U8: Static<[u8; PIXELS]> = Static::new([0; PIXELS]);

/// Prints the rows. Call once (it takes the statics).
pub fn run() {
    let det = DET.take();
    let det_u8 = DET_U8.take();
    let z = MAP.take();
    let q = MAP_U8.take();
    hprintln!(
        "CBMeMBer statics: CbmemberTbd<4, 1000, 8192> {} B (the u8-map filter the same); maps outside the count: f32 {} B, u8 {} B",
        size_of::<Det>(),
        size_of::<[f32; PIXELS]>(),
        size_of::<[u8; PIXELS]>()
    );
    let g = faint_core::detect::cbmember::CbmemberConfig::rotor_uav().geometry;
    for (name, model, particles) in [
        ("joint, 700", PointModel::Joint, 700usize),
        ("joint, 1000", PointModel::Joint, 1000),
        ("Doppler-only, 1000", PointModel::DopplerOnly, 1000),
    ] {
        let cfg = config(g, model, particles, 450);
        variant(det, z, None, name, cfg);
    }
    let cfg = config(g, PointModel::Joint, 1000, 450);
    variant_u8(det_u8, z, q, "joint u8 map, 1000", cfg);
}

fn variant(det: &mut Det, z: &mut [f32; PIXELS], _q: Option<()>, name: &str, cfg: CbmemberConfig) {
    check(det.configure(&cfg, SEED));
    let mut rng = Rng::from_stream(SEED, 1);
    let mut stats = Stats::new();
    for k in 0..FRAMES {
        map(&cfg.geometry, k, &mut rng, &mut z[..]);
        let (r, m) = measure(|| det.step(black_box(&z[..])));
        let r = check(r);
        stats.add(k, r.particles as u32, r.reported, m);
    }
    stats.print(name, size_of::<Det>());
}

fn variant_u8(
    det: &mut DetU8,
    z: &mut [f32; PIXELS],
    q: &mut [u8; PIXELS],
    name: &str,
    cfg: CbmemberConfig,
) {
    check(det.configure(&cfg, SEED));
    let dq = Dequant::new(cfg.noise_var, cfg.quant_step);
    let mut rng = Rng::from_stream(SEED, 1);
    let mut stats = Stats::new();
    for k in 0..FRAMES {
        map(&cfg.geometry, k, &mut rng, &mut z[..]);
        for (o, &p) in q.iter_mut().zip(z.iter()) {
            *o = quantise(p * dq.scale, cfg.quant_step);
        }
        debug_assert_eq!(q[..].pixel_count(), PIXELS);
        let (r, m) = measure(|| det.step(black_box(&q[..])));
        let r = check(r);
        stats.add(k, r.particles as u32, r.reported, m);
    }
    stats.print(name, size_of::<DetU8>());
}

struct Stats {
    sum: u64,
    parts: u32,
    n: u32,
    worst: Measurement,
    worst_parts: u32,
    stack: u32,
    reported: [usize; FRAMES],
}

impl Stats {
    fn new() -> Self {
        Self {
            sum: 0,
            parts: 0,
            n: 0,
            worst: Measurement {
                instructions: 0,
                stack_bytes: 0,
            },
            worst_parts: 0,
            stack: 0,
            reported: [0; FRAMES],
        }
    }

    fn add(&mut self, k: usize, parts: u32, reported: usize, m: Measurement) {
        if let Some(r) = self.reported.get_mut(k) {
            *r = reported;
        }
        self.stack = self.stack.max(m.stack_bytes);
        if k == 0 {
            return;
        }
        self.sum += m.instructions;
        self.parts += parts;
        self.n += 1;
        if m.instructions > self.worst.instructions {
            self.worst = m;
            self.worst_parts = parts;
        }
    }

    fn print(&self, name: &str, ram: usize) {
        let n = self.n.max(1);
        let mean = Measurement {
            instructions: self.sum / u64::from(n),
            stack_bytes: self.stack,
        };
        let mut label = Text::<128>::new();
        let _ = core::fmt::Write::write_fmt(
            &mut label,
            format_args!(
                "cbmember {name} step, mean of frames 1-{} (256x512)",
                FRAMES - 1
            ),
        );
        row(label.as_str(), self.parts / n, "particle", mean, ram);
        label.clear();
        let _ = core::fmt::Write::write_fmt(
            &mut label,
            format_args!(
                "cbmember {name} step, worst of frames 1-{} (256x512)",
                FRAMES - 1
            ),
        );
        row(
            label.as_str(),
            self.worst_parts,
            "particle",
            self.worst,
            ram,
        );
        hprintln!("cbmember {}: reported per frame {:?}", name, &self.reported);
    }
}
