//! Monte Carlo runner: trials in parallel, reproducible per-trial seeds.
//!
//! Trial `i` of a run with master seed `s` always gets `Rng::from_stream(s, i)`, whatever
//! the thread count or scheduling, and results come back in trial order, so a run is
//! bit-for-bit reproducible with `RAYON_NUM_THREADS=1` or with every core.

use std::sync::atomic::{AtomicBool, Ordering};

use faint_core::rng::Rng;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

static QUIET: AtomicBool = AtomicBool::new(false);

/// Hides progress bars process-wide (for `--quiet` and for tests).
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// True after [`set_quiet`]`(true)`.
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// A progress bar of `n` steps labelled `label`, drawn on stderr when it is a terminal and
/// hidden after [`set_quiet`]`(true)`.
pub fn progress_bar(label: &str, n: usize) -> ProgressBar {
    let target = if QUIET.load(Ordering::Relaxed) {
        ProgressDrawTarget::hidden()
    } else {
        // Draws only when stderr is a terminal; invisible in CI logs and pipes.
        ProgressDrawTarget::stderr()
    };
    let pb = ProgressBar::with_draw_target(Some(n as u64), target);
    if let Ok(style) = ProgressStyle::with_template(
        "{prefix:>24} [{elapsed_precise}] {wide_bar} {pos}/{len} (eta {eta})",
    ) {
        pb.set_style(style);
    }
    pb.set_prefix(label.to_string());
    pb
}

/// Runs `trials` trials of `f` in parallel and returns their results in trial order.
///
/// `f(i, rng)` gets the trial index and the trial's own stream
/// `Rng::from_stream(master_seed, i)`. A progress bar labelled `label` is drawn on a
/// terminal.
pub fn run_trials<T, F>(master_seed: u64, trials: usize, label: &str, f: F) -> Vec<T>
where
    T: Send,
    F: Fn(usize, &mut Rng) -> T + Sync,
{
    let pb = progress_bar(label, trials);
    let out: Vec<T> = (0..trials)
        .into_par_iter()
        .map(|i| {
            let mut rng = Rng::from_stream(master_seed, i as u64);
            let r = f(i, &mut rng);
            pb.inc(1);
            r
        })
        .collect();
    pb.finish_and_clear();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_results_on_one_and_many_threads() {
        set_quiet(true);
        let work = |i: usize, rng: &mut Rng| -> (usize, u32, f32) {
            let mut acc = 0.0f32;
            for _ in 0..(100 + i % 37) {
                acc += rng.normal();
            }
            (i, rng.next_u32(), acc)
        };
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| run_trials(99, 500, "t1", work));
        let many = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap()
            .install(|| run_trials(99, 500, "t4", work));
        assert_eq!(one.len(), 500);
        for (a, b) in one.iter().zip(&many) {
            assert_eq!(a.0, b.0);
            assert_eq!(a.1, b.1);
            assert_eq!(a.2.to_bits(), b.2.to_bits());
        }
        assert!(one.iter().enumerate().all(|(i, r)| r.0 == i));
        // Different master seeds give different trials.
        let other = run_trials(100, 3, "t", work);
        assert_ne!(other[0].1, one[0].1);
    }
}
