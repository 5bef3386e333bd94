//! The equality test every sharded command shares: `n` shards merged by `faint merge`
//! write the same outputs as one unsharded run, every CSV and JSON file byte for byte
//! (and, where asked, every Markdown file), wall-clock timing columns aside.
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
    assert_merged_equals_whole_but(root, args, n, out_file, shards, &Volatile::default())
}

/// What differs between two runs of one command by nature, left out of the comparison:
/// wall-clock timings and the command line a summary quotes.
#[derive(Debug, Default)]
pub struct Volatile<'a> {
    /// Compare the Markdown files (`.md`) too.
    pub markdown: bool,
    /// Columns blanked in every CSV file and Markdown table that has them (by header).
    pub columns: &'a [&'a str],
    /// Markdown lines starting with one of these are left out.
    pub lines: &'a [&'a str],
}

impl Volatile<'_> {
    /// The text of a CSV file with the volatile columns blanked.
    fn csv(&self, text: &str) -> String {
        let mut lines = text.lines();
        let Some(head) = lines.next() else {
            return String::new();
        };
        let cells = |l: &str| -> Vec<String> { l.split(',').map(str::to_string).collect() };
        let masked: Vec<usize> = cells(head)
            .iter()
            .enumerate()
            .filter(|(_, c)| self.columns.contains(&c.as_str()))
            .map(|(i, _)| i)
            .collect();
        let mut out = vec![head.to_string()];
        for l in lines {
            let mut c = cells(l);
            for &i in &masked {
                if let Some(x) = c.get_mut(i) {
                    x.clear();
                }
            }
            out.push(c.join(","));
        }
        out.join("\n")
    }

    /// The text of a Markdown file with the volatile lines left out and the volatile
    /// columns of its tables blanked.
    fn markdown(&self, text: &str) -> String {
        let lines: Vec<&str> = text.lines().collect();
        let mut masked: Vec<usize> = Vec::new();
        let mut out = Vec::new();
        for (k, l) in lines.iter().enumerate() {
            if self.lines.iter().any(|p| l.starts_with(p)) {
                continue;
            }
            if !l.starts_with('|') {
                masked.clear();
                out.push(l.to_string());
                continue;
            }
            let mut cells: Vec<String> = l.split('|').map(|c| c.trim().to_string()).collect();
            if lines
                .get(k + 1)
                .is_some_and(|n| n.starts_with("|-") || n.starts_with("| -"))
            {
                masked = cells
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| self.columns.contains(&c.as_str()))
                    .map(|(i, _)| i)
                    .collect();
            } else {
                for &i in &masked {
                    if let Some(x) = cells.get_mut(i) {
                        x.clear();
                    }
                }
            }
            out.push(cells.join("|"));
        }
        out.join("\n")
    }
}

/// [`assert_merged_equals_whole`] leaving out what `volatile` names (the Markdown files
/// compared too when it says so).
pub fn assert_merged_equals_whole_but(
    root: &Path,
    args: &[&str],
    n: usize,
    out_file: Option<&str>,
    shards: impl Fn(&Path) -> PathBuf,
    volatile: &Volatile,
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
        let ext = f.extension().and_then(|e| e.to_str());
        let compared_kind = match ext {
            Some("csv" | "json") => true,
            Some("md") => volatile.markdown,
            _ => false,
        };
        if !compared_kind {
            continue;
        }
        let (x, y) = (
            std::fs::read(whole.join(f)).unwrap(),
            std::fs::read(sharded.join(f)).unwrap(),
        );
        let (x, y) = if volatile.columns.is_empty() && volatile.lines.is_empty() {
            (x, y)
        } else {
            let text = |b: Vec<u8>| String::from_utf8(b).expect("UTF-8 output");
            let f = |t: String| match ext {
                Some("csv") => volatile.csv(&t),
                Some("md") => volatile.markdown(&t),
                _ => t,
            };
            (f(text(x)).into_bytes(), f(text(y)).into_bytes())
        };
        assert!(
            x == y,
            "{} differs between the whole and the merged run",
            f.display()
        );
        compared += 1;
    }
    assert!(compared > 0, "no CSV or JSON output to compare");
    compared
}
