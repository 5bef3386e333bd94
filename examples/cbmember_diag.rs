//! CBMeMBer diagnostics on the `rotor-uav` preset: per-frame existence, estimate and
//! time of the joint and Doppler-only filters on one run, and the log-LR of the truth by
//! the exact and blocked forms.
//!
//! `cargo run --release --example cbmember_diag -- [snr_db] [seed] [particles] [bins]`

use std::time::Instant;

use faint::detect::cbmember::Likelihood;
use faint::detect::Detector;
use faint::host::instances::cbmember::HostFilter;
use faint::host::simulate::cbmember::{MapSource, RotorUav};
use faint::model::range_doppler::{
    log_lr_blocked, log_lr_exact, peak_snr, BlockMap, Dequant, Kernel, PointModel,
};
use faint::rng::Rng;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let snr: f64 = a.get(1).and_then(|s| s.parse().ok()).unwrap_or(-10.0);
    let seed: u64 = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let particles: usize = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(1500);
    let bins: usize = a.get(4).and_then(|s| s.parse().ok()).unwrap_or(16);
    let sc = RotorUav::new(snr);
    let truth = sc.truth();
    let mut src = MapSource::new(&sc);
    let mut rng = Rng::from_stream(seed, 0);
    let mut filters: Vec<(&str, Box<HostFilter>)> = [
        ("joint", PointModel::Joint),
        ("doppler", PointModel::DopplerOnly),
    ]
    .iter()
    .map(|&(n, m)| {
        let mut c = sc.config(m, particles);
        c.likelihood = if bins == 0 {
            Likelihood::Exact
        } else {
            Likelihood::Blocked { bins }
        };
        (n, Box::new(HostFilter::new(c, seed).unwrap()))
    })
    .collect();
    let g = sc.geometry();
    let cfg = sc.filter;
    let dq = Dequant::new(cfg.noise_var, cfg.quant_step);
    let mut map = Vec::new();
    let mut times = [0f64; 2];
    for (k, t) in truth.iter().enumerate() {
        src.power(&sc, t, k, &mut rng, &mut map);
        // LR of the truth, both forms.
        let lit = sc.lit(t);
        let amp = peak_snr(cfg.gain * 0.5 / cfg.noise_var, 1.0, t.range as f32);
        let mut h = vec![0f32; 1024];
        let mut p = vec![0f32; 1024];
        let ke = Kernel::new(&g, &cfg.spread, 1);
        let ex = log_lr_exact(
            &map[..],
            &dq,
            &g,
            &ke,
            amp,
            t.range as f32,
            &lit.vels[..lit.n],
            &mut h,
        );
        let ex_body = log_lr_exact(
            &map[..],
            &dq,
            &g,
            &ke,
            amp,
            t.range as f32,
            &lit.vels[..1],
            &mut h,
        );
        let mut buf = vec![0f32; 8192];
        let kb = Kernel::new(&g, &cfg.spread, 16);
        let bm = BlockMap::build(&map[..], &dq, &g, 16, &mut buf).unwrap();
        let bl = log_lr_blocked(
            &bm,
            &g,
            &kb,
            amp,
            t.range as f32,
            &lit.vels[..lit.n],
            &mut h,
            &mut p,
        );
        let mut line = format!("k {k:2} lr_exact {ex:8.2} body {ex_body:8.2} blocked16 {bl:8.2} |");
        for (i, (name, f)) in filters.iter_mut().enumerate() {
            let t0 = Instant::now();
            let rep = f.step(&map[..]).unwrap();
            times[i] += t0.elapsed().as_secs_f64();
            let best = f.estimates().fold(
                None,
                |b: Option<faint::detect::cbmember::Estimate>, e| match b {
                    Some(x) if x.existence >= e.existence => Some(x),
                    _ => Some(e),
                },
            );
            if rep.reported > 1 && std::env::var("DIAG_DUP").is_ok() {
                for k2 in 0..rep.reported {
                    if let Some(e) = f.reported(k2) {
                        line += &format!(
                            " [{name} dup id {} age {} r {:.3} dr {:.2} dv {:.2}]",
                            e.id,
                            e.age,
                            e.existence,
                            e.state[0] as f64 - t.range,
                            e.state[1] as f64 - t.velocity
                        );
                    }
                }
            }
            if let Some(e) = best {
                line += &format!(
                    " {name}: r {:.3} n {} dr {:6.2} dv {:5.2} V {:4.1} w {:.3} comps {} parts {}|",
                    e.existence,
                    rep.reported,
                    e.state[0] as f64 - t.range,
                    e.state[1] as f64 - t.velocity,
                    e.state[3],
                    e.state[4],
                    rep.components,
                    rep.particles
                );
            }
        }
        println!("{line}");
    }
    println!(
        "ms per frame: joint {:.3}, doppler {:.3}",
        1e3 * times[0] / truth.len() as f64,
        1e3 * times[1] / truth.len() as f64
    );
}
