//! `faint reproduce crpf` in shards: three shards merged by `faint merge` write the
//! CSVs of the unsharded run byte for byte (H0 statistics, calibration, Pd versus SNR,
//! SNR at Pd, the Fig. 5 sweeps), whatever the shard sizes (here 13 + 13 + 14 H0 runs, 2 + 3 + 3 H1
//! runs per point, 3 + 4 + 4 H0 runs per sweep configuration).

use crate::common::temp;
use crate::merge::assert_merged_equals_whole;

#[test]
fn three_shards_merge_into_the_unsharded_run() {
    let root = temp("crpf", "shards");
    let args = [
        "reproduce",
        "crpf",
        "--quick",
        "--noise",
        "cgg",
        "--trials",
        "8",
        "--h0-trials",
        "40",
        "--snr-db",
        "4:12:8",
        "--sweep-h0-trials",
        "11",
        "--sweep-trials",
        "3",
        "--seed",
        "7",
    ];
    let n = assert_merged_equals_whole(&root, &args, 3, None, |out| {
        out.join("cgg_n100").join("shards")
    });
    // h0_stats, calibration, pd_vs_snr, snr_at_pd, fig5_sweeps.
    assert_eq!(n, 5);
    let _ = std::fs::remove_dir_all(&root);
}
