//! `faint reproduce crpf --quick` end to end: every output file is written and the CSVs
//! hold finite Pd values for every method and SNR point.

use faint::host::cli::grid;
use faint::host::montecarlo::set_quiet;
use faint::host::reproduce::crpf::{run, Args, METHODS};
use faint::host::simulate::crpf::Noise;

#[test]
fn quick_reproduction_writes_every_output() {
    set_quiet(true);
    let out = std::env::temp_dir().join(format!("faint_crpf_quick_{}", std::process::id()));
    let args = Args {
        particles: None,
        trials: None,
        h0_trials: None,
        pfa: None,
        noise: Noise::Cgg,
        snr_db: None,
        out: out.clone(),
        seed: 5,
        sweeps: false,
        sweep_h0_trials: None,
        sweep_trials: None,
        comparator_var: Default::default(),
        comparator_likelihood: Default::default(),
        window: Default::default(),
        phase: Default::default(),
        echo_phase: Default::default(),
        birth_proposal: "exact".into(),
        quick: true,
        shard: Default::default(),
    };
    run(&args).unwrap();
    let d = out.join("cgg_n100");
    for f in [
        "h0_stats.csv",
        "calibration.csv",
        "pd_vs_snr.csv",
        "snr_at_pd.csv",
        "table.md",
        "fig1_h0_statistics.svg",
        "fig4_pd_vs_snr.svg",
    ] {
        assert!(d.join(f).exists(), "{f} missing");
    }
    for f in ["fig5_sweeps.csv", "fig5_r_th.svg", "fig5_lambda.svg"] {
        assert!(out.join("sweeps_n100").join(f).exists(), "{f} missing");
    }
    let pd = std::fs::read_to_string(d.join("pd_vs_snr.csv")).unwrap();
    // Header + 5 methods x 5 SNR points (0:16:4).
    assert_eq!(pd.lines().count(), 1 + METHODS.len() * 5);
    assert!(!pd.contains("NaN"));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn snr_grid_parsing() {
    let g = |s: &str| grid("--snr-db", s);
    assert_eq!(g("0:4:2").unwrap(), vec![0.0, 2.0, 4.0]);
    assert_eq!(g("-2:-2:1").unwrap(), vec![-2.0]);
    assert!(g("0:4").is_err());
    assert!(g("0:4:0").is_err());
    assert!(g("4:0:1").is_err());
    assert!(g("a:b:c").is_err());
    assert!(g("0:1:inf").is_err());
}
