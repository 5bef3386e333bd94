//! `faint reproduce mht` in shards: three shards merged by `faint merge` write the outputs
//! of the unsharded run byte for byte (every CSV and `summary.md`), whatever the shard
//! sizes (5 scoring trials per lambda as 1 + 2 + 2, 4 clutter-only as 1 + 1 + 2), with
//! the model's thresholds and with `gamma_1` calibrated by simulation (computed by every
//! shard); and a shard of another reproduction is refused by name.

use std::path::Path;

use crate::common::{faint_quiet, s, temp};
use crate::merge::{assert_merged_equals_whole_but, Volatile};

/// MHT's outputs hold no timing: everything is compared, Markdown included.
const ALL: Volatile = Volatile {
    markdown: true,
    columns: &[],
    lines: &[],
};

#[test]
fn three_shards_merge_into_the_unsharded_run() {
    let root = temp("mht", "shards");
    let args = [
        "reproduce",
        "mht",
        "--quick",
        "--lambda",
        "80",
        "--lambda",
        "237",
        "--trials",
        "5",
        "--null-trials",
        "4",
        "--seed",
        "3",
    ];
    let n = assert_merged_equals_whole_but(&root, &args, 3, None, |o| o.join("shards"), &ALL);
    // trials_lambda80, trials_lambda237, summary, null_pfa, calib, model_curves, summary.md.
    assert!(n >= 6, "{n}");
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn three_shards_with_a_simulated_gamma() {
    let root = temp("mht", "shards-sim");
    let args = [
        "reproduce",
        "mht",
        "--quick",
        "--lambda",
        "80",
        "--trials",
        "4",
        "--null-trials",
        "4",
        "--gamma-from",
        "sim",
        "--calib-periods",
        "20",
        "--calib-check",
        "10",
    ];
    assert_merged_equals_whole_but(&root, &args, 3, None, |o| o.join("shards"), &ALL);
    let calib = std::fs::read_to_string(root.join("sharded").join("calib.csv")).unwrap();
    assert!(calib.lines().count() > 2, "{calib}");
    let _ = std::fs::remove_dir_all(&root);
}

/// Shard 1 of 2 of `reproduce mht` and shard 0 of 2 of `reproduce cbmember` (its only
/// batch, the one timing trial, falls to shard 1: this shard runs nothing) do not merge:
/// one line naming a file and both commands.
#[test]
fn a_shard_of_another_reproduction_is_refused() {
    let root = temp("mht", "shards-foreign");
    let (a, b) = (root.join("mht"), root.join("cbmember"));
    let run = |args: &[&str], out: &Path| {
        let mut v = args.to_vec();
        v.extend(["--out", s(out)]);
        let (code, _, err) = faint_quiet(&v);
        assert_eq!(code, 0, "{err}");
    };
    run(
        &[
            "reproduce",
            "mht",
            "--quick",
            "--lambda",
            "80",
            "--trials",
            "2",
            "--null-trials",
            "2",
            "--shard",
            "1/2",
        ],
        &a,
    );
    run(
        &[
            "reproduce",
            "cbmember",
            "--quick",
            "--sets",
            "timing",
            "--timing-frames",
            "1",
            "--shard",
            "0/2",
        ],
        &b,
    );
    let (sa, sb) = (a.join("shards"), b.join("shards"));
    let (code, _, err) = faint_quiet(&["merge", s(&sa), s(&sb)]);
    assert_ne!(code, 0);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("shard-1-of-2.faint-shard")
            && err.contains("a shard of `faint reproduce cbmember`, not of `faint reproduce mht`"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&root);
}
