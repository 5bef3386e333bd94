//! `configure` restarts a detector in place exactly as `new` builds one, including
//! from `new_unconfigured()` on the heap (`faint_host::instances`; the firmware keeps
//! the same value in `static` memory).

use faint::detect::crpf::{CrpfConfig, CrpfTbd, Weighting};
use faint::detect::jott::JottTbd;
use faint::detect::pf_lrt::PfLrt;
use faint::detect::pf_tbd::{GaussConfig, PfTbd};
use faint::detect::Detector;
use faint::host::instances::unconfigured;
use faint::model::doppler::{DopplerModel, DopplerReport, Window};
use faint::rng::Rng;
use faint::Complex32;

const N: usize = 64;

fn frames() -> Vec<[Complex32; 32]> {
    let model = DopplerModel::new(32, 0.02, Window::Hamming).unwrap();
    let mut rng = Rng::seed_from_u64(77);
    (0..8)
        .map(|k| {
            let mut z = [Complex32::new(0.0, 0.0); 32];
            for c in z.iter_mut() {
                *c = Complex32::new(2.5 * rng.normal(), 2.5 * rng.normal());
            }
            if k >= 2 {
                let mut h = [Complex32::new(0.0, 0.0); 5];
                let first = model.response(4.0 + 0.3 * k as f32, 1.2, &mut h);
                for (j, v) in h.iter().enumerate() {
                    z[(first + j) % 32] += *v;
                }
            }
            z
        })
        .collect()
}

fn run<D: Detector<Frame = [Complex32], Report = DopplerReport>>(d: &mut D) -> Vec<DopplerReport> {
    frames().iter().map(|z| d.step(z).unwrap()).collect()
}

#[test]
fn reconfigure_equals_new() {
    let cfg = CrpfConfig::othr();
    let seed = 2017;
    let want = run(&mut CrpfTbd::<N>::new(cfg, seed).unwrap());
    // From zero.
    let mut z = unconfigured::<CrpfTbd<N>>();
    z.configure(&cfg, seed).unwrap();
    assert_eq!(run(&mut *z), want);
    // From a detector with another config, mid-run.
    let other = CrpfConfig {
        lambda: 0.3,
        weighting: Weighting::Shifted { gamma: 0.5 },
        ..cfg
    };
    let mut d = CrpfTbd::<N>::new(other, 5).unwrap();
    let _ = run(&mut d);
    d.configure(&cfg, seed).unwrap();
    assert_eq!(run(&mut d), want);
    // A bad config is rejected and leaves the detector as it was.
    let before = d.clone();
    let bad = CrpfConfig { p: -1.0, ..cfg };
    assert!(d.configure(&bad, 1).is_err());
    assert_eq!(d.config(), before.config());
    assert_eq!(d.frame(), before.frame());

    let g = GaussConfig::othr(12.7);
    let want = run(&mut PfTbd::<N>::new(g, seed).unwrap());
    let mut z = unconfigured::<PfTbd<N>>();
    z.configure(&g, seed).unwrap();
    assert_eq!(run(&mut *z), want);

    let want = run(&mut JottTbd::<N>::new(g, seed).unwrap());
    let mut z = unconfigured::<JottTbd<N>>();
    z.configure(&g, seed).unwrap();
    assert_eq!(run(&mut *z), want);

    let want = run(&mut PfLrt::<N>::new(g, seed).unwrap());
    let mut z = unconfigured::<PfLrt<N>>();
    z.configure(&g, seed).unwrap();
    assert_eq!(run(&mut *z), want);
    let bad = GaussConfig {
        noise_var: 0.0,
        ..g
    };
    assert!(z.configure(&bad, 1).is_err());
}

/// `configure` reuses the response table when bins, sample interval and window are
/// unchanged and rebuilds it otherwise: a detector reconfigured from another frame format
/// (window or sample interval), or from the same one with other settings, reports exactly
/// what a new detector does.
#[test]
fn reconfigure_reuses_the_table_only_for_the_same_frame_format() {
    let seed = 11;
    let cfg = CrpfConfig::othr();
    let hann = CrpfConfig {
        model: faint::model::doppler::ModelConfig {
            window: Window::Hann,
            ..cfg.model
        },
        ..cfg
    };
    let slower = CrpfConfig {
        model: faint::model::doppler::ModelConfig {
            ts: cfg.model.ts * 0.8,
            ..cfg.model
        },
        ..cfg
    };
    let same_table = CrpfConfig { lambda: 0.3, ..cfg };
    for target in [cfg, hann, slower, same_table] {
        let want = run(&mut CrpfTbd::<N>::new(target, seed).unwrap());
        for from in [cfg, hann, slower, same_table] {
            let mut d = CrpfTbd::<N>::new(from, 3).unwrap();
            let _ = run(&mut d);
            d.configure(&target, seed).unwrap();
            assert_eq!(run(&mut d), want, "{from:?} -> {target:?}");
        }
    }

    let g = GaussConfig::othr(12.7);
    let g_hann = GaussConfig {
        model: hann.model,
        ..g
    };
    let g_slower = GaussConfig {
        model: slower.model,
        ..g
    };
    let g_var = GaussConfig {
        noise_var: 3.0,
        ..g
    };
    fn check<D>(make: impl Fn(GaussConfig, u64) -> D, cfgs: [GaussConfig; 4])
    where
        D: Detector<Frame = [Complex32], Report = DopplerReport, Config = GaussConfig>,
    {
        for target in cfgs {
            let want = run(&mut make(target, 11));
            for from in cfgs {
                let mut d = make(from, 3);
                let _ = run(&mut d);
                d.configure(&target, 11).unwrap();
                assert_eq!(run(&mut d), want, "{from:?} -> {target:?}");
            }
        }
    }
    let cfgs = [g, g_hann, g_slower, g_var];
    check(|c, s| PfTbd::<N>::new(c, s).unwrap(), cfgs);
    check(|c, s| JottTbd::<N>::new(c, s).unwrap(), cfgs);
    check(|c, s| PfLrt::<N>::new(c, s).unwrap(), cfgs);
}
