//! Per-frame diagnostics of the PHD-TBD filter on one seed of the six-targets preset:
//! per true target the particle mass and count within 40 m, the log likelihood ratio at
//! the true state, total mass and N_hat. `cargo run --release --example phd_diag -- SNR SEED VARIANT LAMBDA`
use faint_core::detect::Detector;
use faint_core::model::power_cube::{PowerCube, RadarCoords};
use faint_core::rng::Rng;
use faint_host::instances::phd::HostFilter;
use faint_host::simulate::phd::{SixTargets, Variant};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let snr: f64 = a.get(1).and_then(|s| s.parse().ok()).unwrap_or(9.0);
    let seed: u64 = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let v = match a.get(3).map(|s| s.as_str()) {
        Some("pso") => Variant::PsoDbscan,
        _ => Variant::PhdTbd,
    };
    let lambda: Option<f32> = a.get(4).and_then(|s| s.parse().ok());
    let sc = SixTargets::new(snr);
    let mut cfg = sc.config(v);
    if let Some(l) = lambda {
        cfg.clutter_lambda = l;
    }
    // Optional PSO fitness gate override (diagnostic only).
    if let (Some(gate), Some(p)) = (
        a.get(5).and_then(|s| s.parse::<f32>().ok()),
        cfg.pso.as_mut(),
    ) {
        p.gate = gate;
    }
    // Seeds >= 500 replay `tests/phd_filter.rs` (one stream for truth and cubes).
    let mut seed_rng = Rng::from_stream(2019, seed);
    let (truth, mut cube_rng, fseed) = if seed >= 500 {
        let mut r = Rng::seed_from_u64(seed);
        let t = sc.truth(&mut r);
        (t, r, 40 + seed - 500)
    } else {
        let mut truth_rng = seed_rng.fork(1);
        let t = sc.truth(&mut truth_rng);
        (t, seed_rng.fork(2), seed_rng.fork(10).next_u64())
    };
    let mut f = Box::new(HostFilter::new(cfg, fseed).unwrap());
    let mut cube = Vec::new();
    let g = sc.geometry();
    let psf = sc.psf();
    for (k, frame) in truth.iter().enumerate() {
        sc.cube(frame, &mut cube_rng, &mut cube);
        let rep = f.step(&cube).unwrap();
        let pc = PowerCube::new(&cube, g).unwrap();
        let (x, w) = f.particles();
        let mut line = format!(
            "k={:2} N={} nhat={} mass={:.2} np={:5} sw={} gen={} |",
            k + 1,
            frame.len(),
            rep.n_hat,
            rep.mass,
            x.len(),
            rep.swarm,
            rep.pso_generations
        );
        for t in frame {
            let s = t.state;
            let c = RadarCoords::from_state(s[0] as f32, s[1] as f32, s[2] as f32, s[3] as f32);
            let llr = pc.log_lr(&psf, &c, (sc.power() as f32).sqrt(), 1.0);
            let mut m = 0.0f32;
            let mut cnt = 0;
            let mut dv = 0.0f32;
            for (p, &wi) in x.iter().zip(w) {
                let d = ((p[0] as f64 - s[0]).powi(2) + (p[2] as f64 - s[2]).powi(2)).sqrt();
                if d < 40.0 {
                    m += wi;
                    cnt += 1;
                    dv += (((p[1] as f64 - s[1]).powi(2) + (p[3] as f64 - s[3]).powi(2)).sqrt())
                        as f32;
                }
            }
            let dv = if cnt > 0 { dv / cnt as f32 } else { f32::NAN };
            line += &format!(
                " T{} llr={:5.1} m={:.2} n={:4} dv={:4.1} |",
                t.id + 1,
                llr,
                m,
                cnt,
                dv
            );
        }
        let zp = f.measurement_points();
        line += " Z:";
        for z in zp {
            let dmin = frame
                .iter()
                .map(|t| {
                    ((z[0] as f64 - t.state[0]).powi(2) + (z[1] as f64 - t.state[2]).powi(2)).sqrt()
                })
                .fold(f64::INFINITY, f64::min);
            line += &format!(" {:.0}", dmin);
        }
        let est = f.estimates();
        line += " est:";
        for e in est {
            let dmin = frame
                .iter()
                .map(|t| {
                    ((e.state[0] as f64 - t.state[0]).powi(2)
                        + (e.state[2] as f64 - t.state[2]).powi(2))
                    .sqrt()
                })
                .fold(f64::INFINITY, f64::min);
            line += &format!(
                " {:.0}({})@({:.0},{:.0})",
                dmin, e.support, e.state[0], e.state[2]
            );
        }
        println!("{line}");
    }
}
