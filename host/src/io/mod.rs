//! Output: CSV and JSON files, Markdown tables, and SVG charts ([`chart`]); recorded
//! frames and plot lists read from `.npy`/`.npz`/CSV ([`input`]) and written in the same
//! formats ([`output`]).
//!
//! Every writer creates missing parent folders and names the file in its error.

use std::fs;
use std::path::Path;

use anyhow::{Context, Result};
use serde::Serialize;

pub mod chart;
pub mod input;
pub mod output;

fn ensure_parent(path: &Path) -> Result<()> {
    if let Some(dir) = path.parent() {
        if !dir.as_os_str().is_empty() {
            fs::create_dir_all(dir)
                .with_context(|| format!("cannot create folder {}", dir.display()))?;
        }
    }
    Ok(())
}

/// Writes `rows` as CSV with a header from the field names of `S`.
pub fn write_csv<S: Serialize>(path: impl AsRef<Path>, rows: &[S]) -> Result<()> {
    let path = path.as_ref();
    ensure_parent(path)?;
    let mut w = csv::Writer::from_path(path)
        .with_context(|| format!("cannot create {}", path.display()))?;
    for r in rows {
        w.serialize(r)
            .with_context(|| format!("cannot write a row to {}", path.display()))?;
    }
    w.flush()
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

/// Writes `value` as pretty-printed JSON.
pub fn write_json<T: Serialize + ?Sized>(path: impl AsRef<Path>, value: &T) -> Result<()> {
    let path = path.as_ref();
    ensure_parent(path)?;
    let s = serde_json::to_string_pretty(value)?;
    fs::write(path, s + "\n").with_context(|| format!("cannot write {}", path.display()))
}

/// Writes a text file (Markdown tables, notes).
pub fn write_text(path: impl AsRef<Path>, text: &str) -> Result<()> {
    let path = path.as_ref();
    ensure_parent(path)?;
    fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))
}

/// A GitHub-flavoured Markdown table. Pipes inside cells are escaped.
pub fn markdown_table(header: &[&str], rows: &[Vec<String>]) -> String {
    let esc = |s: &str| s.replace('|', "\\|");
    let mut out = String::new();
    out.push_str("| ");
    out.push_str(
        &header
            .iter()
            .map(|h| esc(h))
            .collect::<Vec<_>>()
            .join(" | "),
    );
    out.push_str(" |\n|");
    for _ in header {
        out.push_str("---|");
    }
    out.push('\n');
    for r in rows {
        out.push_str("| ");
        out.push_str(&r.iter().map(|c| esc(c)).collect::<Vec<_>>().join(" | "));
        out.push_str(" |\n");
    }
    out
}

/// Formats an optional number with `digits` decimals, `-` for `None` or non-finite.
pub fn fmt_opt(x: Option<f64>, digits: usize) -> String {
    match x {
        Some(v) if v.is_finite() => format!("{v:.digits$}"),
        _ => "-".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize)]
    struct Row {
        snr_db: f64,
        pd: f64,
    }

    #[test]
    fn csv_json_markdown_roundtrip() {
        let dir = std::env::temp_dir().join(format!("faint-io-{}", std::process::id()));
        let p = dir.join("sub/curve.csv");
        write_csv(
            &p,
            &[
                Row {
                    snr_db: 1.0,
                    pd: 0.5,
                },
                Row {
                    snr_db: 2.0,
                    pd: 0.75,
                },
            ],
        )
        .unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert_eq!(text, "snr_db,pd\n1.0,0.5\n2.0,0.75\n");
        write_json(dir.join("a.json"), &[1, 2]).unwrap();
        let md = markdown_table(&["a", "b|c"], &[vec!["1".into(), "2".into()]]);
        assert_eq!(md, "| a | b\\|c |\n|---|---|\n| 1 | 2 |\n");
        assert_eq!(fmt_opt(None, 2), "-");
        assert_eq!(fmt_opt(Some(1.234), 1), "1.2");
        std::fs::remove_dir_all(&dir).ok();
    }
}
