//! Finds the commands a document tells its reader to run.
//!
//! - Every fenced block whose language is `sh` (or `bash`, `shell`, `console`) is a
//!   script, run line by line in one shell. A line `# CI skips this block: REASON` in it
//!   skips the block; a command whose comment is `# CI skips this: REASON` is left out; a
//!   command whose comment is `# CI runs: COMMAND` is replaced by COMMAND (a smoke form
//!   named in the document).
//! - An inline code span outside fences that starts like a command (`faint `, `cargo `,
//!   `cd `, `nice `, `./target/`, `target/`, `.ci/run`, or `VAR=value` before one of
//!   them) is a one-line script, unless it is a synopsis (placeholders `<...>`, `[...]`,
//!   `...`, `|`, `*`, a capitalised placeholder word, a trailing `--`) or a fragment
//!   (`nice -n 10`), or the bare name of a subcommand (`faint detect`), which is checked
//!   to exist with `--help`.

/// What one documented command is, and so what CI does with it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Kind {
    /// A script: fenced block or inline command.
    Script,
    /// A fenced block marked `CI skips this block`, with the reason.
    Skipped(String),
    /// A synopsis or a fragment: shows a form, not a command; never run.
    Synopsis,
    /// `faint <subcommand>`: checked with `faint <subcommand> --help`.
    Name,
}

/// One command line of a block after joining `\` continuations.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Line {
    /// 1-based line in the document where it starts.
    pub at: usize,
    /// The command without its trailing comment.
    pub command: String,
    /// The trailing comment, without `#`.
    pub comment: Option<String>,
}

impl Line {
    /// The reason of a `CI skips this: REASON` marker.
    pub fn skip_reason(&self) -> Option<&str> {
        self.comment
            .as_deref()
            .and_then(|c| c.trim().strip_prefix("CI skips this:"))
            .map(str::trim)
    }

    /// The smoke form of a `CI runs: COMMAND` marker.
    pub fn smoke(&self) -> Option<&str> {
        self.comment
            .as_deref()
            .and_then(|c| c.trim().strip_prefix("CI runs:"))
            .map(str::trim)
    }
}

/// One documented command: a block or an inline span.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Item {
    /// Document, relative to the repository.
    pub doc: String,
    /// 1-based line of the fence or the span.
    pub at: usize,
    /// True for a fenced block.
    pub block: bool,
    /// What CI does with it.
    pub kind: Kind,
    /// The lines (one for an inline span).
    pub lines: Vec<Line>,
}

impl Item {
    /// `doc:line`.
    pub fn place(&self) -> String {
        format!("{}:{}", self.doc, self.at)
    }
}

const SHELLS: &[&str] = &["sh", "bash", "shell", "console"];
const STARTS: &[&str] = &[
    "faint ",
    "cargo ",
    "cd ",
    "nice ",
    "./target/",
    "target/",
    ".ci/run",
];

/// Splits `s` at its first `#` that starts a shell comment (outside quotes, after
/// whitespace or at the start).
pub fn split_comment(s: &str) -> (&str, Option<&str>) {
    let (mut single, mut double) = (false, false);
    let mut prev = ' ';
    for (i, c) in s.char_indices() {
        match c {
            '\'' if !double => single = !single,
            '"' if !single => double = !double,
            '#' if !single && !double && prev.is_whitespace() => {
                return (s[..i].trim_end(), Some(&s[i + 1..]));
            }
            _ => {}
        }
        prev = c;
    }
    (s.trim_end(), None)
}

/// The commands of one block's text (lines after the opening fence).
fn block_lines(first: usize, body: &[&str]) -> Vec<Line> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < body.len() {
        let at = first + i;
        let mut text = body[i].to_string();
        while text.trim_end().ends_with('\\') && i + 1 < body.len() {
            let t = text.trim_end();
            text = format!("{} {}", &t[..t.len() - 1].trim_end(), body[i + 1].trim());
            i += 1;
        }
        i += 1;
        let (cmd, comment) = split_comment(&text);
        out.push(Line {
            at,
            command: cmd.trim().to_string(),
            comment: comment.map(|c| c.trim().to_string()),
        });
    }
    out
}

fn is_env_word(w: &str) -> bool {
    match w.split_once('=') {
        Some((k, _)) => {
            !k.is_empty()
                && k.chars()
                    .all(|c| c.is_ascii_uppercase() || c == '_' || c.is_ascii_digit())
        }
        None => false,
    }
}

/// True if an inline span reads as a command.
fn looks_like_command(span: &str) -> bool {
    let words: Vec<&str> = span.split_whitespace().collect();
    let first = words.iter().position(|w| !is_env_word(w));
    match first {
        Some(k) => {
            let rest = words[k..].join(" ");
            // A bare folder (`target/ci/`) or a data file (`target/ci/run.txt`) is a path,
            // not a command.
            let last = rest.rsplit('/').next().unwrap_or("");
            let path = !rest.contains(' ') && (rest.ends_with('/') || last.contains('.'));
            !path && (rest == ".ci/run" || STARTS.iter().any(|s| rest.starts_with(s)))
        }
        None => false,
    }
}

/// A form, not a command: placeholders or a trailing `--`, or a fragment.
fn is_synopsis(span: &str) -> bool {
    let words: Vec<&str> = span.split_whitespace().collect();
    // An upper-case word that is not an option (`N`, `FILE`, `VAR=N`) stands for a value.
    let upper = |v: &str| {
        let core = v.trim_matches(|c: char| !c.is_alphanumeric());
        !core.is_empty()
            && core
                .chars()
                .all(|c| c.is_ascii_uppercase() || c == '_' || c.is_ascii_digit())
            && core.chars().any(|c| c.is_ascii_uppercase())
    };
    let placeholder = words.iter().skip(1).any(|w| {
        !w.starts_with('-')
            && match w.split_once('=') {
                Some((_, v)) => upper(v),
                None => upper(w),
            }
    }) || words
        .first()
        .and_then(|w| w.split_once('='))
        .is_some_and(|(_, v)| upper(v));
    span.contains('<')
        || span.contains('[')
        || span.contains("...")
        || span.contains('|')
        || span.contains('*')
        || span.trim_end().ends_with("--")
        || placeholder
        || (words.first() == Some(&"nice") && words.len() <= 3)
}

/// A line of a block that shows a form: a `<placeholder>`, an optional `[-...]` or `...`.
pub fn is_block_synopsis(cmd: &str) -> bool {
    let b = cmd.as_bytes();
    let angle = b
        .windows(2)
        .any(|w| w[0] == b'<' && w[1].is_ascii_alphabetic());
    angle || cmd.contains("[-") || cmd.contains("...")
}

/// Every documented command of the markdown `text` of `doc`.
pub fn items(doc: &str, text: &str) -> Vec<Item> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let l = lines[i];
        if let Some(info) = l.trim_start().strip_prefix("```") {
            let lang = info.trim().to_string();
            let start = i;
            let mut j = i + 1;
            while j < lines.len() && !lines[j].trim_start().starts_with("```") {
                j += 1;
            }
            if SHELLS.contains(&lang.as_str()) {
                let body = block_lines(start + 2, &lines[start + 1..j.min(lines.len())]);
                let skip = body.iter().find_map(|b| {
                    if b.command.is_empty() {
                        b.comment
                            .as_deref()
                            .and_then(|c| c.trim().strip_prefix("CI skips this block:"))
                            .map(|r| r.trim().to_string())
                    } else {
                        None
                    }
                });
                out.push(Item {
                    doc: doc.to_string(),
                    at: start + 1,
                    block: true,
                    kind: match skip {
                        Some(r) => Kind::Skipped(r),
                        None => Kind::Script,
                    },
                    lines: body,
                });
            }
            i = j + 1;
            continue;
        }
        // Inline spans (single backticks) on a prose line.
        let mut rest = l;
        while let Some(a) = rest.find('`') {
            let after = &rest[a + 1..];
            let Some(b) = after.find('`') else { break };
            let span = after[..b].trim();
            rest = &after[b + 1..];
            if !looks_like_command(span) {
                continue;
            }
            let words: Vec<&str> = span.split_whitespace().collect();
            let kind = if is_synopsis(span) {
                Kind::Synopsis
            } else if words.len() == 2
                && words[0] == "faint"
                && words[1].chars().all(|c| c.is_ascii_lowercase() || c == '-')
            {
                Kind::Name
            } else {
                Kind::Script
            };
            out.push(Item {
                doc: doc.to_string(),
                at: i + 1,
                block: false,
                kind,
                lines: vec![Line {
                    at: i + 1,
                    command: span.to_string(),
                    comment: None,
                }],
            });
        }
        i += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_spans_and_markers() {
        let md = "Run `faint reproduce crpf --quick` or see `faint detect`.\n\
                  A form: `faint detect <name> --input FILE`, a path `faint_core::x`.\n\
                  ```sh\n\
                  faint simulate othr --out a.npy   # writes a.npy\n\
                  faint reproduce crpf --runs 9 \\\n    --out o   # CI runs: faint reproduce crpf --quick\n\
                  faint fuzz x     # CI skips this: needs nightly\n\
                  ```\n\
                  ```sh\n\
                  # CI skips this block: hours\n\
                  faint reproduce phd\n\
                  ```\n\
                  ```rust\n\
                  let x = 1;\n\
                  ```\n";
        let it = items("d.md", md);
        let kinds: Vec<&Kind> = it.iter().map(|i| &i.kind).collect();
        assert_eq!(
            kinds,
            [
                &Kind::Script,
                &Kind::Name,
                &Kind::Synopsis,
                &Kind::Script,
                &Kind::Skipped("hours".into())
            ]
        );
        let b = &it[3];
        assert_eq!(b.at, 3);
        assert_eq!(b.lines.len(), 3);
        assert_eq!(b.lines[0].comment.as_deref(), Some("writes a.npy"));
        assert_eq!(b.lines[1].command, "faint reproduce crpf --runs 9 --out o");
        assert_eq!(b.lines[1].smoke(), Some("faint reproduce crpf --quick"));
        assert_eq!(b.lines[2].skip_reason(), Some("needs nightly"));
        assert_eq!(
            split_comment("echo \"a # b\" # c"),
            ("echo \"a # b\"", Some(" c"))
        );
        assert!(is_synopsis("nice -n 10"));
        assert!(!looks_like_command("target/ci/doc-commands.txt"));
        assert!(!looks_like_command("target/ci/"));
        assert!(looks_like_command("target/checked/faint soak crpf"));
        assert!(looks_like_command("./target/release/faint"));
        assert!(is_synopsis("cargo run --release --"));
        assert!(!is_synopsis("FAINT_RUNS=1 cargo run --release --example x"));
    }
}
