//! Every relative link of the Markdown documents resolves: the file exists and, for a
//! `#fragment` into a Markdown file, a heading of that file has that anchor. Anchors are
//! made as GitHub makes them: lowercase; letters, digits, `-` and `_` kept, spaces turned
//! into `-`, everything else dropped; a repeated heading gets `-1`, `-2`, ...

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The anchor GitHub gives a heading's text.
pub fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of a Markdown text's headings (outside fenced blocks), with GitHub's
/// suffixes for repeats.
pub fn anchors(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced || !line.starts_with('#') {
            continue;
        }
        let title = line.trim_start_matches('#');
        if !title.starts_with(' ') {
            continue;
        }
        let base = slug(title);
        let mut s = base.clone();
        let mut n = 0;
        while out.contains(&s) {
            n += 1;
            s = format!("{base}-{n}");
        }
        out.insert(s);
    }
    out
}

/// The relative link targets `](target)` of a Markdown text, outside fenced blocks and
/// inline code.
pub fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        // Drop inline code spans so `a[i](j)`-like code is not read as a link.
        let mut plain = String::new();
        for (i, part) in line.split('`').enumerate() {
            if i % 2 == 0 {
                plain.push_str(part);
            }
        }
        let mut rest = plain.as_str();
        while let Some(at) = rest.find("](") {
            rest = &rest[at + 2..];
            let Some(end) = rest.find(')') else { break };
            let target = rest[..end].split_whitespace().next().unwrap_or("");
            if !target.is_empty() && !target.contains("://") && !target.starts_with("mailto:") {
                out.push(target.to_string());
            }
            rest = &rest[end..];
        }
    }
    out
}

/// Every broken link of the document `doc` (a path relative to `root`), as
/// `doc: target (why)`.
pub fn broken(root: &Path, doc: &str) -> Vec<String> {
    let text = std::fs::read_to_string(root.join(doc)).unwrap_or_default();
    let dir: PathBuf = root
        .join(doc)
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let mut bad = Vec::new();
    for target in links(&text) {
        let (path, fragment) = match target.split_once('#') {
            Some((p, f)) => (p, Some(f)),
            None => (target.as_str(), None),
        };
        let file = if path.is_empty() {
            root.join(doc)
        } else {
            dir.join(path)
        };
        if !file.exists() {
            bad.push(format!("{doc}: {target} (no such file)"));
            continue;
        }
        if let Some(f) = fragment {
            if file.extension().is_some_and(|e| e == "md") {
                let heads = anchors(&std::fs::read_to_string(&file).unwrap_or_default());
                if !heads.contains(f) {
                    bad.push(format!("{doc}: {target} (no heading with that anchor)"));
                }
            }
        }
    }
    bad
}

#[test]
fn slugs_follow_github() {
    assert_eq!(
        slug(" The comparators' likelihood (`likelihood: independent | window`)"),
        "the-comparators-likelihood-likelihood-independent--window"
    );
    assert_eq!(
        slug(" Cortex-M4F: instructions per frame, static RAM"),
        "cortex-m4f-instructions-per-frame-static-ram"
    );
    let a = anchors("# A\n## Results\n```\n# not a heading\n```\n### Results\n");
    assert!(a.contains("results") && a.contains("results-1") && !a.contains("not-a-heading"));
    assert_eq!(
        links("see [x](a.md#b), `[y](z.md)` and [w](https://e.org)"),
        vec!["a.md#b"]
    );
}
