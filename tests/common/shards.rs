//! The equality test every sharded command shares: `n` shards merged by `faint merge`
//! write the same outputs as one unsharded run, every CSV and JSON file byte for byte.
//! Included with `#[path = "../common/shards.rs"] mod shards;`.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `faint --quiet <args>` with the extra environment `env`; panics with its output
/// unless it succeeds.
fn run(args: &[String], env: &[(&str, String)]) {
    let out = Command::new(env!("CARGO_BIN_EXE_faint"))
        .arg("--quiet")
        .args(args)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("JOB_COMPLETION_INDEX")
        .envs(env.iter().map(|(k, v)| (k, v)))
        .output()
        .expect("run faint");
    assert!(
        out.status.success(),
        "faint {args:?} {env:?}: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Every file under `dir`, relative to it, sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push(p.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    out.sort();
    out
}

/// Runs `faint <args> --out <root>/whole` once, then `n` shards of the same command with
/// `--out <root>/sharded` (shard 0 through SLURM's array variables, shard 1 through a
/// Kubernetes Indexed Job's, the others through `--shard i/n`), merges the folder
/// `shards(<root>/sharded)` with `faint merge`, and asserts that the merged run wrote
/// the same files as the whole run (shard files aside) with every `.csv` and `.json`
/// equal byte for byte (plots and Markdown tables may carry timings). `out` is the
/// command's output option (`--out`, or a file for `faint calibrate`: then `whole` and
/// `sharded` are file names). Returns the number of files compared.
pub fn assert_merged_equals_whole(
    root: &Path,
    args: &[&str],
    n: usize,
    out_file: Option<&str>,
    shards: impl Fn(&Path) -> PathBuf,
) -> usize {
    let target = |name: &str| match out_file {
        Some(f) => root.join(name).join(f),
        None => root.join(name),
    };
    let with_out = |name: &str| -> Vec<String> {
        let mut v: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        v.push("--out".into());
        v.push(target(name).display().to_string());
        v
    };
    run(&with_out("whole"), &[]);
    for i in 0..n {
        let mut a = with_out("sharded");
        let env: Vec<(&str, String)> = match i {
            0 => vec![
                ("SLURM_ARRAY_TASK_ID", "0".into()),
                ("SLURM_ARRAY_TASK_COUNT", n.to_string()),
                ("SLURM_ARRAY_TASK_MIN", "0".into()),
            ],
            1 => vec![
                ("JOB_COMPLETION_INDEX", "1".into()),
                ("FAINT_SHARD_COUNT", n.to_string()),
            ],
            _ => {
                a.push("--shard".into());
                a.push(format!("{i}/{n}"));
                vec![]
            }
        };
        run(&a, &env);
    }
    let shard_dir = shards(&target("sharded"));
    let found = std::fs::read_dir(&shard_dir)
        .unwrap_or_else(|e| panic!("{}: {e}", shard_dir.display()))
        .count();
    assert_eq!(found, n, "{}", shard_dir.display());
    run(&["merge".into(), shard_dir.display().to_string()], &[]);
    let (whole, sharded) = (root.join("whole"), root.join("sharded"));
    let a = files(&whole);
    let b: Vec<PathBuf> = files(&sharded)
        .into_iter()
        .filter(|p| !p.starts_with(shard_dir.strip_prefix(&sharded).unwrap()))
        .collect();
    assert_eq!(a, b, "the merged run wrote other files");
    let mut compared = 0;
    for f in &a {
        if matches!(f.extension().and_then(|e| e.to_str()), Some("csv" | "json")) {
            let (x, y) = (
                std::fs::read(whole.join(f)).unwrap(),
                std::fs::read(sharded.join(f)).unwrap(),
            );
            assert!(
                x == y,
                "{} differs between the whole and the merged run",
                f.display()
            );
            compared += 1;
        }
    }
    assert!(compared > 0, "no CSV or JSON output to compare");
    compared
}
