//! Monte Carlo runner: trials in parallel, reproducible per-trial seeds.
//!
//! Trial `i` of a run with master seed `s` always gets `Rng::from_stream(s, i)`, whatever
//! the thread count or scheduling, and results come back in trial order, so a run is
//! bit-for-bit reproducible with `RAYON_NUM_THREADS=1` or with every core.
//!
//! Every thread faint starts for detector work is started here, with one stack size,
//! [`WORKER_STACK`]: the trial workers of [`run_trials`] and [`pool`], and the single
//! threads of [`on_worker_stack`]. Rayon's and std's 2 MiB default is not enough: a
//! detector is built by value (`new` returns it in a `Result`, the caller moves it into a
//! `Box`), so a construction path holds several copies of it at once on the stack.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;

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

/// Copies of one detector that a construction path may hold on the stack at once. The
/// release build of `MhtTbd::new` and its caller held 4.4 copies of the 465 KiB
/// detector (frames of 946 KB and 1.14 MB, read with gdb), which overflowed rayon's
/// 2 MiB worker stack; 8 leaves room for deeper paths and other optimisation levels.
pub const STACK_COPIES: usize = 8;

/// The largest detector the host builds by value, in bytes: the second-order DP-TBD of
/// the DP reproduction (`simulate::dp::Second25`, 6.3 MB); the PHD host filter is 3.1 MB.
/// A unit test checks this bound against `size_of` of every detector type the host builds
/// by value. The larger DP detectors of `faint detect` (`simulate::dp::*At256`,
/// `*At512`, up to 100 MB) are never built by value: `simulate::dp::boxed` zeroes and
/// configures them in place on the heap (tested on a 256 KiB stack).
pub const LARGEST_DETECTOR: usize = 7 << 20;

/// Stack of every worker thread faint starts: [`STACK_COPIES`] copies of
/// [`LARGEST_DETECTOR`] plus 8 MiB for everything else (64 MiB). It is address space:
/// only the pages a thread touches are committed.
pub const WORKER_STACK: usize = STACK_COPIES * LARGEST_DETECTOR + (8 << 20);

/// The pool every Monte Carlo runs on: one thread per core (or `RAYON_NUM_THREADS`), each
/// with [`WORKER_STACK`]. Built on first use.
pub fn pool() -> &'static rayon::ThreadPool {
    static POOL: OnceLock<rayon::ThreadPool> = OnceLock::new();
    POOL.get_or_init(|| {
        rayon::ThreadPoolBuilder::new()
            .stack_size(WORKER_STACK)
            .thread_name(|i| format!("faint-worker-{i}"))
            .build()
            // Only fails when the OS refuses threads; nothing can run without them.
            .unwrap_or_else(|e| panic!("cannot start the worker threads: {e}"))
    })
}

/// Runs `f` on a new thread with a [`WORKER_STACK`] stack and returns its result (for
/// single runs that build a detector outside [`run_trials`]). A panic in `f` is resumed
/// on the caller's thread.
pub fn on_worker_stack<T, F>(f: F) -> T
where
    T: Send,
    F: FnOnce() -> T + Send,
{
    std::thread::scope(|s| {
        let h = std::thread::Builder::new()
            .name("faint-single".into())
            .stack_size(WORKER_STACK)
            .spawn_scoped(s, f)
            .unwrap_or_else(|e| panic!("cannot start a worker thread: {e}"));
        match h.join() {
            Ok(v) => v,
            Err(p) => std::panic::resume_unwind(p),
        }
    })
}

/// Runs `trials` trials of `f` in parallel and returns their results in trial order.
///
/// `f(i, rng)` gets the trial index and the trial's own stream
/// `Rng::from_stream(master_seed, i)`. A progress bar labelled `label` is drawn on a
/// terminal. The trials run on [`pool`], or on the caller's rayon pool when called from
/// one (a test that pins the thread count).
pub fn run_trials<T, F>(master_seed: u64, trials: usize, label: &str, f: F) -> Vec<T>
where
    T: Send,
    F: Fn(usize, &mut Rng) -> T + Sync,
{
    run_trial_range(master_seed, 0..trials, label, f)
}

/// [`run_trials`] for the trials `range` only (one shard of a run, [`crate::shard`]):
/// trial `i` still gets `Rng::from_stream(master_seed, i)`, so its result is the one the
/// whole run computes.
pub fn run_trial_range<T, F>(
    master_seed: u64,
    range: std::ops::Range<usize>,
    label: &str,
    f: F,
) -> Vec<T>
where
    T: Send,
    F: Fn(usize, &mut Rng) -> T + Sync,
{
    let pb = progress_bar(label, range.len());
    let go = || -> Vec<T> {
        range
            .clone()
            .into_par_iter()
            .map(|i| {
                let mut rng = Rng::from_stream(master_seed, i as u64);
                let r = f(i, &mut rng);
                pb.inc(1);
                r
            })
            .collect()
    };
    let out = if rayon::current_thread_index().is_some() {
        go()
    } else {
        pool().install(go)
    };
    pb.finish_and_clear();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_largest_detector_bounds_every_host_instance() {
        use faint_core::detect::crpf::CrpfTbd;
        use faint_core::detect::jott::JottTbd;
        use faint_core::detect::pf_lrt::PfLrt;
        use faint_core::detect::pf_tbd::PfTbd;
        use std::mem::size_of;
        let sizes = [
            size_of::<crate::instances::mht::Mht>(),
            size_of::<crate::instances::mht::Classic>(),
            size_of::<crate::instances::phd::HostFilter>(),
            size_of::<crate::instances::cbmember::HostFilter>(),
            size_of::<crate::instances::cbmember::HostFilterComplex>(),
            size_of::<crate::instances::cbmember::HostFilterU8>(),
            size_of::<crate::simulate::dp::Arnold25>(),
            size_of::<crate::simulate::dp::Pulford25>(),
            size_of::<crate::simulate::dp::Second25>(),
            size_of::<crate::reliability::guided::Phd>(),
            size_of::<crate::reliability::guided::Cbm>(),
            size_of::<crate::simulate::dp::fuzz::Second25>(),
            size_of::<CrpfTbd<6000>>(),
            size_of::<PfTbd<6000>>(),
            size_of::<JottTbd<6000>>(),
            size_of::<PfLrt<6000>>(),
        ];
        let largest = sizes.iter().copied().max().unwrap();
        assert!(
            largest <= LARGEST_DETECTOR,
            "{largest} B > {LARGEST_DETECTOR} B"
        );
        // The bound is tight enough to mean something (within 2x of the real largest).
        assert!(2 * largest > LARGEST_DETECTOR, "{largest} B");
    }

    /// Regression: `faint reproduce mht` overflowed rayon's 2 MiB worker stack in the
    /// release build (4.4 copies of the 465 KiB MHT-TBD). Every trial now has
    /// `WORKER_STACK`; a trial that uses 32 MiB of stack (would abort the test binary on
    /// a 2 MiB stack) runs, on the pool and on a single worker thread.
    #[test]
    fn trials_and_single_runs_have_the_worker_stack() {
        fn deep() -> u64 {
            let buf = std::hint::black_box([7u8; 32 << 20]);
            buf.iter().step_by(4096).map(|&b| u64::from(b)).sum()
        }
        set_quiet(true);
        let r = run_trials(3, 4, "stack", |_, _| deep());
        assert_eq!(r, vec![7 * 8192; 4]);
        assert_eq!(on_worker_stack(deep), 7 * 8192);
        // The MHT-TBD of the reproduction is built on a worker, as `reproduce mht` does.
        let built = run_trials(5, 2, "mht", |_, _| {
            let cfg = faint_core::detect::mht::MhtConfig::sea_clutter();
            crate::instances::mht::Mht::new(cfg).map(Box::new).is_ok()
        });
        assert_eq!(built, vec![true, true]);
    }

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
