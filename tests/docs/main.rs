//! The documents are tests: every command that README.md, docs/*.md,
//! docs/measurements/*.md, firmware/README.md and fuzz/README.md tell a user to run.
//!
//! `cargo test` checks that every documented command is classified (a script CI runs, a
//! synopsis, a subcommand's name, or a block the document marks `CI skips this block:
//! REASON`) and that `.ci/run` runs the ignored test below. CI runs that test on the
//! release profile, where `faint` is the release binary users build:
//!
//! ```sh
//! cargo test --release --test docs -- --ignored --nocapture
//! ```
//!
//! It runs each document's commands in document order, in a scratch folder of its own
//! (with `firmware`, `fuzz` and `target` linked in), through the shims of [`shims`]:
//! `faint reproduce` in its smoke form (`--quick` in place of the run counts), `faint
//! evaluate` in its (`shims::EVALUATE_SMOKE` in place of its size options), soak and
//! fuzz counts capped, benches once each. A command that `.ci/run` itself runs (the
//! test, lint and firmware steps) is not run twice. A command that fails fails the test,
//! with its output. `FAINT_DOC_ONLY=docs/crpf.md` runs one document's commands;
//! `FAINT_DOC_KEEP=1` keeps the scratch folders (their path is printed).

mod extract;
mod links;
mod shims;

use extract::{items, Item, Kind};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The documents whose commands are tests.
fn documents() -> Vec<String> {
    let mut docs = vec!["README.md".to_string()];
    // docs/*.md (the user guides) and docs/measurements/*.md (the measurement records).
    for dir in ["docs", "docs/measurements"] {
        let Ok(entries) = std::fs::read_dir(repo().join(dir)) else {
            continue;
        };
        let mut pages: Vec<String> = entries
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".md"))
            .map(|n| format!("{dir}/{n}"))
            .collect();
        pages.sort();
        docs.extend(pages);
    }
    docs.push("firmware/README.md".into());
    docs.push("fuzz/README.md".into());
    docs
}

fn all_items() -> Vec<Item> {
    documents()
        .iter()
        .flat_map(|d| {
            let text = std::fs::read_to_string(repo().join(d)).expect("read a document");
            items(d, &text)
        })
        .collect()
}

/// `s` with `timeout N ` prefixes and cargo's `-q` dropped and whitespace collapsed: the
/// form in which a documented command is looked up in `.ci/run`.
fn normalise(s: &str) -> String {
    let words: Vec<&str> = s.split_whitespace().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < words.len() {
        if words[i] == "timeout" && i + 1 < words.len() && words[i + 1].parse::<u32>().is_ok() {
            i += 2;
            continue;
        }
        if words[i] != "-q" {
            out.push(words[i].trim_start_matches('('));
        }
        i += 1;
    }
    out.join(" ")
}

/// The text of `.ci/run`, normalised, without its comments.
fn ci_text() -> String {
    let text = std::fs::read_to_string(repo().join(".ci/run")).expect(".ci/run");
    let text = text
        .replace("\"$TARGET\"", "thumbv7em-none-eabihf")
        .replace("$TARGET", "thumbv7em-none-eabihf");
    text.lines()
        .map(|l| extract::split_comment(l).0)
        .map(normalise)
        .collect::<Vec<_>>()
        .join("\n")
}

/// True if `.ci/run` runs `command` itself (it is `.ci/run`, or its text is in it).
fn run_by_ci(command: &str, ci: &str) -> bool {
    let n = normalise(command);
    let after_env = n
        .split_whitespace()
        .find(|w| !w.contains('='))
        .unwrap_or("");
    // The command as a whole shell word sequence of a `.ci/run` line: at its end, or
    // before a `)`, a redirection, a pipe or a continuation.
    let ends = [")", " >", " 2>", " |", " \\", " &&"];
    // A shell keyword closing a loop or a branch (`done`, `fi`) is part of its block's
    // script, never a command of its own (`.ci/run` has such lines too).
    if matches!(
        n.trim(),
        "done" | "fi" | "esac" | "else" | "then" | "do" | "}"
    ) {
        return false;
    }
    after_env == ".ci/run"
        || ci.lines().any(|l| {
            l.match_indices(n.as_str()).any(|(i, _)| {
                let rest = &l[i + n.len()..];
                let start_ok = i == 0 || l[..i].ends_with(' ') || l[..i].ends_with('(');
                start_ok && (rest.is_empty() || ends.iter().any(|e| rest.starts_with(e)))
            })
        })
}

/// Every Markdown file of the repository (not under `target/` or a hidden folder).
fn markdown_files(dir: &Path, rel: &str, out: &mut Vec<String>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.filter_map(|e| e.ok()) {
        let name = e.file_name().to_string_lossy().into_owned();
        let path = if rel.is_empty() {
            name.clone()
        } else {
            format!("{rel}/{name}")
        };
        if name.starts_with('.') || name == "target" {
            continue;
        }
        if e.file_type().is_ok_and(|t| t.is_dir()) {
            markdown_files(&e.path(), &path, out);
        } else if name.ends_with(".md") {
            out.push(path);
        }
    }
}

#[test]
fn every_relative_link_resolves() {
    let mut docs = Vec::new();
    markdown_files(&repo(), "", &mut docs);
    docs.sort();
    assert!(docs.iter().any(|d| d == "README.md"), "{docs:?}");
    let bad: Vec<String> = docs
        .iter()
        .flat_map(|d| links::broken(&repo(), d))
        .collect();
    assert!(
        bad.is_empty(),
        "{} broken links:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn every_documented_command_is_classified() {
    let all = all_items();
    let ci = ci_text();
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for it in &all {
        let k = match &it.kind {
            Kind::Script => {
                for l in &it.lines {
                    if let Some(r) = l.skip_reason() {
                        assert!(
                            !r.is_empty(),
                            "{}: 'CI skips this:' needs a reason",
                            it.place()
                        );
                    }
                    if let Some(s) = l.smoke() {
                        assert!(!s.is_empty(), "{}: 'CI runs:' needs a command", it.place());
                    }
                }
                let commands = it.lines.iter().filter(|l| !l.command.is_empty()).count();
                let by_ci = it
                    .lines
                    .iter()
                    .filter(|l| !l.command.is_empty() && run_by_ci(&l.command, &ci))
                    .count();
                if commands > 0 && by_ci == commands {
                    "run by .ci/run"
                } else {
                    "run"
                }
            }
            Kind::Skipped(r) => {
                assert!(
                    r.len() >= 8,
                    "{}: a skipped block needs its reason",
                    it.place()
                );
                "skipped"
            }
            Kind::Synopsis => "synopsis",
            Kind::Name => "name",
        };
        *counts.entry(k).or_default() += 1;
    }
    eprintln!("{} documented commands: {counts:?}", all.len());
    assert!(counts.get("run").copied().unwrap_or(0) >= 20, "{counts:?}");
    // The release run below is part of CI.
    let ci_script = std::fs::read_to_string(repo().join(".ci/run")).expect(".ci/run");
    assert!(
        ci_script.contains("cargo test --release --test docs -- --ignored"),
        ".ci/run must run the documented commands on the release binary"
    );
}

/// A scratch folder for one document's commands, with the repository's `firmware`,
/// `fuzz` and `target` linked in.
fn scratch(root: &Path, doc: &str) -> PathBuf {
    let d = root.join(doc.replace(['/', '.'], "_"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch folder");
    for name in ["docs", "firmware", "fuzz", "target"] {
        std::os::unix::fs::symlink(repo().join(name), d.join(name)).expect("link");
    }
    d
}

/// `cd DIR` alone: it moves the lines after it, so it always runs.
fn is_bare_cd(cmd: &str) -> bool {
    cmd.starts_with("cd ") && !cmd.contains("&&") && !cmd.contains(';')
}

/// A script's text for bash (release-binary paths through the shims, markers applied)
/// and the number of its commands that CI runs here (0: all run by `.ci/run` itself).
fn script(it: &Item, ci: &str, skipped: &mut Vec<String>) -> (String, usize) {
    let mut s = String::from("set -eo pipefail\n");
    let mut here = 0;
    for l in &it.lines {
        if l.command.is_empty() {
            continue;
        }
        let cmd = if extract::is_block_synopsis(&l.command) {
            continue;
        } else if let Some(r) = l.skip_reason() {
            skipped.push(format!("{}:{} `{}`: {r}", it.doc, l.at, l.command));
            continue;
        } else if let Some(smoke) = l.smoke() {
            smoke.to_string()
        } else if !is_bare_cd(&l.command) && run_by_ci(&l.command, ci) {
            // `.ci/run` runs it (tests, lints, firmware).
            continue;
        } else {
            l.command.clone()
        };
        // `cd DIR && ...` is a one-liner from the document's folder: it must not move the
        // lines after it.
        let cmd = if cmd.starts_with("cd ") && cmd.contains("&&") {
            format!("( {cmd} )")
        } else {
            cmd
        };
        let cmd = cmd
            .replace("./target/release/examples/", "faint-example ")
            .replace("target/release/examples/", "faint-example ")
            .replace("./target/release/faint", "faint")
            .replace("target/release/faint", "faint")
            .replace(
                "./target/checked/faint",
                "env FAINT_DOC_BIN=\"$FAINT_DOC_REPO/target/checked/faint\" faint",
            )
            .replace(
                "target/checked/faint",
                "env FAINT_DOC_BIN=\"$FAINT_DOC_REPO/target/checked/faint\" faint",
            );
        s.push_str(&cmd);
        s.push('\n');
        here += 1;
    }
    (s, here)
}

#[test]
#[ignore = "runs every documented command on the release binary (minutes); CI runs it with --release"]
fn documented_commands_run() {
    let root = std::env::temp_dir().join(format!("faint-doc-commands-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let bin = shims::install(&root.join("bin")).expect("shims");
    let real_cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let ci = ci_text();
    let only = std::env::var("FAINT_DOC_ONLY").ok();
    let all: Vec<Item> = all_items()
        .into_iter()
        .filter(|it| only.as_deref().is_none_or(|d| it.doc == d))
        .collect();
    let mut skipped: Vec<String> = Vec::new();
    let mut failed: Vec<String> = Vec::new();
    let mut ran = 0usize;
    let mut by_ci = 0usize;
    let mut seen: BTreeMap<String, String> = BTreeMap::new();
    let t_all = Instant::now();
    let mut dirs: BTreeMap<String, PathBuf> = BTreeMap::new();
    for it in &all {
        let dir = dirs
            .entry(it.doc.clone())
            .or_insert_with(|| scratch(&root, &it.doc))
            .clone();
        let (text, here) = match &it.kind {
            Kind::Skipped(r) => {
                skipped.push(format!("{} (block): {r}", it.place()));
                continue;
            }
            Kind::Synopsis => continue,
            Kind::Name => (format!("{} --help >/dev/null\n", it.lines[0].command), 1),
            Kind::Script => script(it, &ci, &mut skipped),
        };
        if here == 0 {
            by_ci += 1;
            continue;
        }
        // The same command in another place (or another document) runs once.
        if !it.block {
            if let Some(first) = seen.get(&text) {
                eprintln!("same    {} (as {first})", it.place());
                continue;
            }
            seen.insert(text.clone(), it.place());
        }
        let t = Instant::now();
        let out = Command::new("bash")
            .arg("-c")
            .arg(&text)
            .current_dir(&dir)
            .env("PATH", &path)
            .env("FAINT_DOC_REPO", repo())
            .env("FAINT_DOC_CARGO", &real_cargo)
            .env("FAINT_DOC_BIN", env!("CARGO_BIN_EXE_faint"))
            .env_remove("CARGO_TARGET_DIR")
            .output()
            .expect("run bash");
        ran += 1;
        let secs = t.elapsed().as_secs_f64();
        let first_line = it
            .lines
            .iter()
            .find(|l| !l.command.is_empty())
            .map(|l| l.command.as_str())
            .unwrap_or("");
        if out.status.success() {
            eprintln!("ok      {:>6.1} s  {}  {}", secs, it.place(), first_line);
        } else {
            let err = String::from_utf8_lossy(&out.stderr);
            let tail: Vec<&str> = err.lines().rev().take(15).collect();
            let tail: Vec<&str> = tail.into_iter().rev().collect();
            eprintln!(
                "FAILED  {:>6.1} s  {}  {}\n{}",
                secs,
                it.place(),
                first_line,
                tail.join("\n")
            );
            failed.push(format!(
                "{} `{}` (exit {:?})",
                it.place(),
                first_line,
                out.status.code()
            ));
        }
    }
    eprintln!(
        "\n{} documented items: {ran} scripts ran, {by_ci} run by .ci/run itself, {} skipped, {} failed, in {:.0} s",
        all.len(),
        skipped.len(),
        failed.len(),
        t_all.elapsed().as_secs_f64()
    );
    for s in &skipped {
        eprintln!("skipped {s}");
    }
    if std::env::var_os("FAINT_DOC_KEEP").is_some() {
        eprintln!("scratch folders kept in {}", root.display());
    } else {
        let _ = std::fs::remove_dir_all(&root);
    }
    assert!(
        failed.is_empty(),
        "documented commands that fail:\n{}",
        failed.join("\n")
    );
}
