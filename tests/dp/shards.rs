//! `faint reproduce dp` in shards: three shards merged by `faint merge` write the
//! outputs of the unsharded run (5 target runs per point as 1 + 2 + 2, 100 + 100
//! noise-only runs as 33 + 33 + 34, 4 frames; Fig. 5 computed by the merge), every CSV and
//! `summary.md` byte for byte but the command line the summary quotes.

use crate::common::temp;
use crate::merge::{assert_merged_equals_whole_but, Volatile};

#[test]
fn three_shards_merge_into_the_unsharded_run() {
    let root = temp("dp", "shards");
    let args = [
        "reproduce",
        "dp",
        "--quick",
        "--runs",
        "5",
        "--snr",
        "2.0:2.5:0.5",
        "--frames",
        "4",
    ];
    let command = Volatile {
        markdown: true,
        columns: &[],
        lines: &["Command: "],
    };
    let n = assert_merged_equals_whole_but(&root, &args, 3, None, |o| o.join("shards"), &command);
    // thresholds.csv, fig6_fig7.csv, runs.csv, fig5.csv, summary.md.
    assert_eq!(n, 5);
    let _ = std::fs::remove_dir_all(&root);
}
