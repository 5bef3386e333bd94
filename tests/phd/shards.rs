//! `faint reproduce phd` in shards: three shards merged by `faint merge` write the
//! outputs of the unsharded run (2 runs per SNR as 0 + 1 + 1: a shard may hold no run of
//! a batch; two SNRs), every CSV and
//! `table.md` byte for byte but the filters' wall time per run (Table 4), which no two
//! runs share.

use crate::common::{faint_quiet, s, temp};
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
    let n = assert_merged_equals_whole_but(&root, &args, 3, None, |o| o.join("shards"), &TIMING);
    // frames.csv, summary.csv, table.md.
    assert_eq!(n, 3);
    let _ = std::fs::remove_dir_all(&root);
}

/// The wall-clock columns, measured where the runs ran: left out of the comparison.
const TIMING: Volatile = Volatile {
    markdown: true,
    columns: &[
        "seconds_per_run",
        "ms_per_frame",
        "s per 40-frame run (ours, 1 core)",
    ],
    lines: &[],
};

/// The same on physics cubes (`--cubes physics`: the physics simulator's renderer), two
/// shards, one SNR, one algorithm.
#[test]
fn two_shards_on_physics_cubes_merge_into_the_unsharded_run() {
    let root = temp("phd", "shards-physics");
    let args = [
        "reproduce",
        "phd",
        "--quick",
        "--cubes",
        "physics",
        "--runs",
        "2",
        "--variants",
        "phd-tbd",
        "--birth-particles",
        "100",
        "--particles-per-target",
        "100",
    ];
    let n = assert_merged_equals_whole_but(&root, &args, 2, None, |o| o.join("shards"), &TIMING);
    assert_eq!(n, 3);
    let table = std::fs::read_to_string(root.join("whole").join("table.md")).unwrap();
    assert!(
        table.starts_with("Cubes from the physics simulator"),
        "{table}"
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// Shards of the same run but for `--cubes` (shard 0 of 2 on model cubes, shard 1 of 2
/// on physics cubes) do not merge: one line naming `--cubes`.
#[test]
fn shards_of_different_cubes_are_refused() {
    let root = temp("phd", "shards-cubes");
    for (cubes, shard) in [("model", "0/2"), ("physics", "1/2")] {
        let (code, _, err) = faint_quiet(&[
            "reproduce",
            "phd",
            "--quick",
            "--runs",
            "2",
            "--variants",
            "phd-tbd",
            "--birth-particles",
            "100",
            "--particles-per-target",
            "100",
            "--cubes",
            cubes,
            "--shard",
            shard,
            "--out",
            s(&root),
        ]);
        assert_eq!(code, 0, "{err}");
    }
    let (code, _, err) = faint_quiet(&["merge", s(&root.join("shards"))]);
    assert_ne!(code, 0);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("a shard of another run (--cubes ")
            && err.contains("\"physics\"")
            && err.contains("\"model\""),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&root);
}
