//! Reproductions of the papers' figures and tables, one module per paper, each behind
//! `faint reproduce <name>`: every one writes CSV, SVG charts and a Markdown table with
//! the paper's numbers next to ours.

pub mod cbmember;
pub mod crpf;
pub mod dp;
pub mod mht;
pub mod phd;

use std::path::Path;

use crate::shard::Merged;

/// The commands of the sharded reproductions, as shard files name them.
pub const COMMANDS: [&str; 5] = [
    crpf::COMMAND,
    mht::COMMAND,
    phd::COMMAND,
    cbmember::COMMAND,
    dp::COMMAND,
];

/// `faint merge` of a reproduction's shards, by the command their header names: the
/// outputs of the unsharded run, written where it writes them (under `out` if given).
pub fn merge(m: &Merged, out: Option<&Path>) -> anyhow::Result<()> {
    match m.run.command.as_str() {
        crpf::COMMAND => crpf::merge(m, out),
        mht::COMMAND => mht::merge(m, out),
        phd::COMMAND => phd::merge(m, out),
        cbmember::COMMAND => cbmember::merge(m, out),
        dp::COMMAND => dp::merge(m, out),
        other => anyhow::bail!(
            "{}: shards of `faint {other}`, which is not a reproduction",
            m.files[0].display()
        ),
    }
}
