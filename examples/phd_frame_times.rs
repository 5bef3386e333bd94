//! Per-frame CPU time of the three PSO-PHD-TBD variants on the `six-targets` preset at
//! 9 dB, over the same 3 runs of 40 frames as `cargo bench --bench phd` (truth and cubes
//! from `Rng::seed_from_u64(70 + seed)`, filter seed `seed`): mean, worst frame, and the
//! frames above 10 ms with their swarm size and generations.
//!
//! `cargo run --release --example phd_frame_times [VARIANT [force]]` (VARIANT: `phd`,
//! `kmeans`, `dbscan`, `all`; default all three; `force`: the swarm's stop threshold is
//! set above the largest fitness, so every frame with a swarm runs `max_generations`
//! (20) generations instead of `gen = 10` and stopping: the swarm's worst case). `FAINT_SWARM_CAP=N`: at most `N` particles in the
//! swarm (`PsoConfig::max_members`; 0 = all gated particles; default the preset's 512). `FAINT_RUNS=1` measures the first run only (for
//! instruction profiles under callgrind). CPU time is the thread's, so time spent waiting for a
//! core on a loaded machine is not counted (Linux x86_64 / aarch64 only).
use faint_core::detect::Detector;
use faint_core::rng::Rng;
use faint_host::instances::phd::HostFilter;
use faint_host::simulate::phd::{SixTargets, Variant};

/// This thread's CPU time in ns (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`, exact to the
/// ns; `/proc/thread-self/schedstat`, used by the bench for the mean, only advances at
/// scheduler ticks, so single frames read in multiples of ~4 ms).
fn thread_cpu_ns() -> u64 {
    (faint_host::timing::thread_cpu_seconds() * 1e9) as u64
}

fn run() {
    let which = std::env::args().nth(1).filter(|w| w != "all");
    let force = std::env::args().nth(2).as_deref() == Some("force");
    // `FAINT_RUNS=1` (first run only) keeps instruction profiles (callgrind) short.
    let runs: u64 = std::env::var("FAINT_RUNS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(3);
    let mut sc = SixTargets::new(9.0);
    if let Some(cap) = std::env::var("FAINT_SWARM_CAP")
        .ok()
        .and_then(|c| c.parse::<usize>().ok())
    {
        sc.swarm_cap = cap;
    }
    for v in Variant::ALL {
        let tag = match v {
            Variant::PhdTbd => "phd",
            Variant::PsoKMeans => "kmeans",
            Variant::PsoDbscan => "dbscan",
            Variant::PhdDbscan => "phd-dbscan",
        };
        if which.as_deref().is_some_and(|w| w != tag) {
            continue;
        }
        let mut times = Vec::new();
        let mut hash = 0x811C_9DC5u32;
        for seed in 0..runs {
            let mut rng = Rng::seed_from_u64(70 + seed);
            let truth = sc.truth(&mut rng);
            let mut cfg = sc.config(v);
            if force {
                if let Some(p) = cfg.pso.as_mut() {
                    p.threshold = 2.0;
                }
            }
            let mut f = Box::new(HostFilter::new(cfg, seed).unwrap());
            let mut cube = Vec::new();
            for (k, frame) in truth.iter().enumerate() {
                sc.cube(frame, &mut rng, &mut cube);
                let t0 = thread_cpu_ns();
                let r = f.step(&cube).unwrap();
                let ns = thread_cpu_ns() - t0;
                // FNV-1a over the report and the estimates' bits: equal hashes before and
                // after an optimisation show that it did not change the results.
                let mut words = vec![r.n_hat as u32, r.mass.to_bits(), r.particles as u32];
                for e in f.estimates() {
                    words.extend(e.state.iter().map(|v| v.to_bits()));
                    words.push(e.support);
                }
                for w in words {
                    for b in w.to_le_bytes() {
                        hash = (hash ^ u32::from(b)).wrapping_mul(0x0100_0193);
                    }
                }
                times.push((ns, seed, k + 1, r.particles, r.swarm, r.pso_generations));
            }
        }
        let mean = times.iter().map(|t| t.0).sum::<u64>() as f64 / times.len() as f64 / 1e6;
        let worst = times.iter().max_by_key(|t| t.0).copied().unwrap();
        println!(
            "{}: mean {:.2} ms, worst {:.2} ms (run {}, frame {}, {} particles, swarm {}, {} generations), {} of {} frames above 10 ms, results hash {:08x}",
            v.name(),
            mean,
            worst.0 as f64 / 1e6,
            worst.1,
            worst.2,
            worst.3,
            worst.4,
            worst.5,
            times.iter().filter(|t| t.0 > 10_000_000).count(),
            times.len(),
            hash
        );
        for t in times.iter().filter(|t| t.0 > 10_000_000) {
            println!(
                "  run {} frame {:2}: {:7.2} ms, {} particles, swarm {}, {} generations",
                t.1,
                t.2,
                t.0 as f64 / 1e6,
                t.3,
                t.4,
                t.5
            );
        }
    }
}

fn main() {
    // The host filter is ~5 MB of fixed arrays: run on a thread with a big stack.
    std::thread::Builder::new()
        .stack_size(512 << 20)
        .spawn(run)
        .unwrap()
        .join()
        .unwrap();
}
