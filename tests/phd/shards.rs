//! `faint reproduce phd` in shards: three shards merged by `faint merge` write the
//! outputs of the unsharded run (2 runs per SNR as 0 + 1 + 1: a shard may hold no run of
//! a batch; two SNRs), every CSV and
//! `table.md` byte for byte but the filters' wall time per run (Table 4), which no two
//! runs share.

use crate::common::temp;
use crate::merge::{assert_merged_equals_whole_but, Volatile};

#[test]
fn three_shards_merge_into_the_unsharded_run() {
    let root = temp("phd", "shards");
    let args = [
        "reproduce",
        "phd",
        "--quick",
        "--snr-db",
        "9,5",
        "--runs",
        "2",
        "--variants",
        "phd-tbd,pso-phd-dbscan",
        "--birth-particles",
        "100",
        "--particles-per-target",
        "100",
    ];
    let timing = Volatile {
        markdown: true,
        columns: &[
            "seconds_per_run",
            "ms_per_frame",
            "s per 40-frame run (ours, 1 core)",
        ],
        lines: &[],
    };
    let n = assert_merged_equals_whole_but(&root, &args, 3, None, |o| o.join("shards"), &timing);
    // frames.csv, summary.csv, table.md.
    assert_eq!(n, 3);
    let _ = std::fs::remove_dir_all(&root);
}
