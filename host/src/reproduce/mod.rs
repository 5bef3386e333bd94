//! Reproductions of the papers' figures and tables, one module per paper, each behind
//! `faint reproduce <name>`: every one writes CSV, SVG charts and a Markdown table with
//! the paper's numbers next to ours.

pub mod cbmember;
pub mod crpf;
pub mod dp;
pub mod mht;
pub mod phd;
