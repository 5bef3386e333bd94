//! Cost of the `faint-core` primitives every particle filter is built from.
//!
//! Inputs are generated from fixed seeds before each measurement (not measured); each
//! row measures one call on the same data every run. Log weights are `N(0, 3^2)` (a
//! likelihood spread that keeps many particles alive), weights are their normalisation.

use core::hint::black_box;
use core::mem::size_of;

use faint_core::math;
use faint_core::particles::{self, Scheme};
use faint_core::rng::Rng;

use faint_firmware::harness::{check, measure, row};
use faint_firmware::statics::Static;

const SEED: u64 = 0x00FA_1A7F_0F1E_7A11;

/// A particle-filter state as the detectors use it: position, velocity in 2-D.
type State4 = [f32; 4];

struct Draws<const N: usize> {
    out: [f32; N],
}

struct Resampling<const N: usize> {
    weights: [f32; N],
    ancestors: [u16; N],
}

struct LogWeights<const N: usize> {
    logs: [f32; N],
    weights: [f32; N],
}

struct Gather<const N: usize> {
    states: [State4; N],
    ancestors: [u16; N],
}

static DRAWS: Static<Draws<1000>> = Static::new(Draws { out: [0.0; 1000] });
static RS_1000: Static<Resampling<1000>> = Static::new(Resampling {
    weights: [0.0; 1000],
    ancestors: [0; 1000],
});
static RS_6000: Static<Resampling<6000>> = Static::new(Resampling {
    weights: [0.0; 6000],
    ancestors: [0; 6000],
});
static LW_1000: Static<LogWeights<1000>> = Static::new(LogWeights {
    logs: [0.0; 1000],
    weights: [0.0; 1000],
});
static LW_6000: Static<LogWeights<6000>> = Static::new(LogWeights {
    logs: [0.0; 6000],
    weights: [0.0; 6000],
});
static GATHER_6000: Static<Gather<6000>> = Static::new(Gather {
    states: [[0.0; 4]; 6000],
    ancestors: [0; 6000],
});

/// Prints the primitives' rows.
pub fn run() {
    let rng_ram = size_of::<Rng>();

    let d = DRAWS.take();
    let mut rng = Rng::from_stream(SEED, 0);
    let ((), m) = measure(|| d.out.iter_mut().for_each(|x| *x = rng.normal()));
    row(
        "Rng::normal (fill 1000)",
        1000,
        "draw",
        m,
        size_of::<Draws<1000>>() + rng_ram,
    );
    let ((), m) = measure(|| d.out.iter_mut().for_each(|x| *x = rng.uniform()));
    row(
        "Rng::uniform (fill 1000)",
        1000,
        "draw",
        m,
        size_of::<Draws<1000>>() + rng_ram,
    );
    let ((), m) = measure(|| d.out.iter_mut().for_each(|x| *x = rng.exponential()));
    row(
        "Rng::exponential (fill 1000)",
        1000,
        "draw",
        m,
        size_of::<Draws<1000>>() + rng_ram,
    );
    let ((), m) = measure(|| d.out.iter_mut().for_each(|x| *x = math::exp(*x - 4.0)));
    row(
        "math::exp (in place, 1000)",
        1000,
        "call",
        m,
        size_of::<Draws<1000>>(),
    );

    let lw = LW_1000.take();
    fill_logs(&mut lw.logs, 1);
    let (r, m) = measure(|| math::normalize_log_weights(&lw.logs, &mut lw.weights));
    check(r);
    row(
        "normalize_log_weights N=1000",
        1000,
        "particle",
        m,
        size_of::<LogWeights<1000>>(),
    );

    let lw6 = LW_6000.take();
    fill_logs(&mut lw6.logs, 2);
    let (r, m) = measure(|| math::normalize_log_weights(&lw6.logs, &mut lw6.weights));
    check(r);
    row(
        "normalize_log_weights N=6000",
        6000,
        "particle",
        m,
        size_of::<LogWeights<6000>>(),
    );

    let rs = RS_1000.take();
    rs.weights.copy_from_slice(&lw.weights);
    let mut rng = Rng::from_stream(SEED, 3);
    let (r, m) = measure(|| {
        particles::resample(Scheme::Systematic, &rs.weights, &mut rs.ancestors, &mut rng)
    });
    check(r);
    row(
        "resample systematic N=1000 (u16)",
        1000,
        "particle",
        m,
        size_of::<Resampling<1000>>() + rng_ram,
    );
    let (r, m) =
        measure(|| particles::resample(Scheme::Residual, &rs.weights, &mut rs.ancestors, &mut rng));
    check(r);
    row(
        "resample residual N=1000 (u16)",
        1000,
        "particle",
        m,
        size_of::<Resampling<1000>>() + rng_ram,
    );

    let rs6 = RS_6000.take();
    rs6.weights.copy_from_slice(&lw6.weights);
    let (r, m) = measure(|| {
        particles::resample(
            Scheme::Systematic,
            &rs6.weights,
            &mut rs6.ancestors,
            &mut rng,
        )
    });
    check(r);
    row(
        "resample systematic N=6000 (u16)",
        6000,
        "particle",
        m,
        size_of::<Resampling<6000>>() + rng_ram,
    );

    let g = GATHER_6000.take();
    for (i, s) in g.states.iter_mut().enumerate() {
        let x = i as f32;
        *s = [x, 0.5 * x, -x, 1.0];
    }
    g.ancestors.copy_from_slice(&rs6.ancestors);
    let (r, m) = measure(|| particles::gather_in_place(&mut g.states, &g.ancestors));
    check(r);
    row(
        "gather_in_place N=6000 ([f32; 4], u16)",
        6000,
        "particle",
        m,
        size_of::<Gather<6000>>(),
    );

    let (ess, m) = measure(|| particles::effective_sample_size(black_box(&lw6.weights)));
    assert!(ess > 1.0, "effective sample size {ess}");
    row(
        "effective_sample_size N=6000",
        6000,
        "particle",
        m,
        size_of::<[f32; 6000]>(),
    );
}

fn fill_logs(logs: &mut [f32], stream: u64) {
    let mut rng = Rng::from_stream(SEED, 100 + stream);
    for l in logs.iter_mut() {
        *l = rng.gaussian(0.0, 3.0);
    }
}
