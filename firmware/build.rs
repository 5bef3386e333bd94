//! Puts the board's `memory.x` where cortex-m-rt's `link.x` looks for it, and writes the
//! `fit` image's configuration.
//!
//! - `FAINT_BOARD` unset: `memory.x` (QEMU `mps2-an385`, `an386`, `an500`) for every
//!   target but the Cortex-M33 (`thumbv8m.main-*`), which runs on `mps2-an505`
//!   (`targets/mps2-an505/memory.x`). No `memory.x` may sit at the workspace root: the
//!   linker runs there and looks in its working directory before the search path, so a
//!   file there would override every board.
//!   `FAINT_BOARD=<part>`: `boards/<part>/memory.x` (`stm32f407`, `stm32h743`,
//!   `atsame70q21`), and `cfg(faint_board = "<part>")` for the code.
//! - `FAINT_FIT=<detector>[:<n>[:<n>...]]` (the `fit` bin; default `crpf:1000`): the
//!   detector family as `cfg(faint_fit = "<detector>")` and its sizes as `fit::P`.
//! - `FAINT_FIT_STATE`, `FAINT_FIT_FRAME`: the output section of the detector's state and
//!   of its input frame (`ram`, the default, is `.uninit` in the board's RAM region; else
//!   one of the board's sections, e.g. `.ccm`, `.axisram`, `.sram123`, `.sram4`).
//!
//! - `FAINT_FIT_STACK` (a board; default `8K`): the stack room the board's `memory.x`
//!   keeps free at the top of RAM (`_fit_stack_reserve`), so that a configuration whose
//!   statics leave less fails to link.
//!
//! Bad values fail the build with one line naming the variable.

use std::{env, fs, path::PathBuf, process::exit};

/// Boards with a profile under `boards/` and the extra sections their `memory.x` maps.
const BOARDS: [(&str, &[&str]); 3] = [
    ("stm32f407", &[".ccm"]),
    ("stm32h743", &[".axisram", ".sram123", ".sram4"]),
    ("atsame70q21", &[]),
];

/// Detector families of the `fit` bin and how many sizes each takes.
const FAMILIES: [(&str, usize); 12] = [
    ("crpf", 1),
    ("pf-tbd", 1),
    ("jott", 1),
    ("pf-lrt", 1),
    ("mht", 1),
    ("hough", 0),
    ("phd", 3),
    ("pso-phd", 3),
    ("cbmember", 1),
    ("dp-first", 2),
    ("dp-pulford", 1),
    ("dp-second", 2),
];

fn fail(msg: String) -> ! {
    eprintln!("error: {msg}");
    println!("cargo:warning={msg}");
    exit(1)
}

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    for v in [
        "FAINT_BOARD",
        "FAINT_FIT",
        "FAINT_FIT_STATE",
        "FAINT_FIT_FRAME",
        "FAINT_FIT_STACK",
    ] {
        println!("cargo:rerun-if-env-changed={v}");
    }
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=targets");
    println!("cargo:rerun-if-changed=boards");
    let boards: Vec<&str> = BOARDS.iter().map(|b| b.0).collect();
    println!(
        "cargo::rustc-check-cfg=cfg(faint_board, values(none(), {}))",
        quoted(&boards)
    );
    let families: Vec<&str> = FAMILIES.iter().map(|f| f.0).collect();
    println!(
        "cargo::rustc-check-cfg=cfg(faint_fit, values({}))",
        quoted(&families)
    );

    let board = env::var("FAINT_BOARD").unwrap_or_default();
    let sections: &[&str] = if board.is_empty() {
        let target = env::var("TARGET").unwrap_or_default();
        let memory = if target.starts_with("thumbv8m.main-") {
            "targets/mps2-an505/memory.x"
        } else {
            "memory.x"
        };
        fs::copy(memory, out.join("memory.x")).expect("copy the board's memory.x into OUT_DIR");
        &[]
    } else {
        let Some((_, sections)) = BOARDS.iter().find(|b| b.0 == board) else {
            fail(format!(
                "FAINT_BOARD={board}: not a board profile (one of {})",
                boards.join(", ")
            ))
        };
        let src = format!("boards/{board}/memory.x");
        println!("cargo:rerun-if-changed={src}");
        let text = fs::read_to_string(&src).expect("read the board's memory.x");
        let stack = env::var("FAINT_FIT_STACK").unwrap_or_else(|_| "8K".into());
        if !stack
            .trim_end_matches('K')
            .chars()
            .all(|c| c.is_ascii_digit())
            || stack.is_empty()
        {
            fail(format!(
                "FAINT_FIT_STACK={stack}: not a byte count (e.g. 8192 or 8K)"
            ));
        }
        let text = text.replace(
            "_fit_stack_reserve = 8K;",
            &format!("_fit_stack_reserve = {stack};"),
        );
        fs::write(out.join("memory.x"), text).expect("write the board's memory.x into OUT_DIR");
        println!("cargo:rustc-cfg=faint_board");
        println!("cargo:rustc-cfg=faint_board=\"{board}\"");
        sections
    };
    println!("cargo:rustc-link-search={}", out.display());

    let spec = env::var("FAINT_FIT").unwrap_or_else(|_| "crpf:1000".into());
    let mut parts = spec.split(':');
    let family = parts.next().unwrap_or_default().to_string();
    let Some(&(_, n_params)) = FAMILIES.iter().find(|f| f.0 == family) else {
        fail(format!(
            "FAINT_FIT={spec}: unknown detector {family} (one of {})",
            families.join(", ")
        ))
    };
    let params: Vec<usize> = parts
        .map(|p| {
            p.parse::<usize>()
                .ok()
                .filter(|&n| n > 0 && n <= 1 << 24)
                .unwrap_or_else(|| {
                    fail(format!(
                        "FAINT_FIT={spec}: size {p} is not a whole number in 1..=16777216"
                    ))
                })
        })
        .collect();
    if params.len() != n_params {
        fail(format!(
            "FAINT_FIT={spec}: {family} takes {n_params} size(s) after the name, got {}",
            params.len()
        ));
    }
    println!("cargo:rustc-cfg=faint_fit=\"{family}\"");
    let section = |var: &str| -> String {
        match env::var(var).unwrap_or_default().as_str() {
            "" | "ram" => ".uninit.fit".into(),
            s if sections.contains(&s) => s.to_string(),
            s => fail(format!(
                "{var}={s}: not a section of board {} (ram{}{})",
                if board.is_empty() {
                    "mps2-an386"
                } else {
                    &board
                },
                if sections.is_empty() { "" } else { ", " },
                sections.join(", ")
            )),
        }
    };
    let state = section("FAINT_FIT_STATE");
    let frame = section("FAINT_FIT_FRAME");
    let mut p = params.clone();
    p.resize(4, 0);
    let code = format!(
        "/// The configuration this image was built for (`FAINT_FIT`).\n\
         pub const SPEC: &str = \"{spec}\";\n\
         /// The board profile (`FAINT_BOARD`).\n\
         pub const BOARD: &str = \"{}\";\n\
         /// The sizes after the detector's name (zero past the last).\n\
         pub const P: [usize; 4] = {p:?};\n\
         /// Sections of the state and the frame.\n\
         pub const SECTIONS: [&str; 2] = [\"{state}\", \"{frame}\"];\n\
         /// Places a `static` in the state's section.\n\
         macro_rules! state_static {{ ($i:item) => {{ #[link_section = \"{state}\"] $i }}; }}\n\
         /// Places a `static` in the frame's section.\n\
         macro_rules! frame_static {{ ($i:item) => {{ #[link_section = \"{frame}\"] $i }}; }}\n",
        if board.is_empty() {
            "mps2-an386"
        } else {
            &board
        }
    );
    fs::write(out.join("fit.rs"), code).expect("write fit.rs into OUT_DIR");
}

fn quoted(v: &[&str]) -> String {
    v.iter()
        .map(|s| format!("\"{s}\""))
        .collect::<Vec<_>>()
        .join(", ")
}
