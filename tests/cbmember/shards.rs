//! `faint reproduce cbmember` in shards: three shards merged by `faint merge` write the
//! outputs of the unsharded run (4 runs per SNR point as 1 + 1 + 2; the base and
//! target-free sets; Table 3's timing, one trial, in the last shard), every CSV and
//! `summary.md` byte for byte but Table 3's CPU times, which no two runs share.

use crate::common::temp;
use crate::merge::{assert_merged_equals_whole_but, Volatile};

#[test]
fn three_shards_merge_into_the_unsharded_run() {
    let root = temp("cbmember", "shards");
    let args = [
        "reproduce",
        "cbmember",
        "--quick",
        "--runs",
        "4",
        "--sets",
        "base,fa,timing",
        "--timing-frames",
        "2",
    ];
    let timing = Volatile {
        markdown: true,
        columns: &[
            "ms_per_frame",
            "speed_up",
            "ms per frame (ours)",
            "paper / ours",
        ],
        lines: &[],
    };
    let n = assert_merged_equals_whole_but(&root, &args, 3, None, |o| o.join("shards"), &timing);
    // curves.csv, table3.csv, summary.md.
    assert_eq!(n, 3);
    let _ = std::fs::remove_dir_all(&root);
}
