//! The programs a documented command finds first on its `PATH` in CI: `faint` (the
//! release binary, in smoke form), `cargo` (pointed at this workspace, benches in test
//! mode, `cargo run -- ...` of the CLI through `faint`) and two helpers. They are bash
//! scripts written into a temporary folder by [`install`].

use std::path::{Path, PathBuf};

/// Options of `faint reproduce` that set a run count, an SNR grid or a Pfa (which the
/// smaller counts cannot resolve): CI drops them and adds `--quick`, whose values take
/// their place (the smoke form of a reproduction).
pub const RUN_COUNTS: &[&str] = &[
    "--pfa",
    "--snr-db",
    "--snr",
    "--trials",
    "--h0-trials",
    "--null-trials",
    "--runs",
    "--noise-runs",
    "--calib-periods",
    "--calib-check",
    "--sweep-h0-trials",
    "--sweep-trials",
];

/// Options of `faint evaluate` that set its size: CI drops them and adds
/// [`EVALUATE_SMOKE`] (the harness end to end, too few runs for a claim).
pub const EVALUATE_COUNTS: &[&str] = &["--pfa", "--runs", "--snr-db", "--frames"];
/// The smoke form of `faint evaluate`.
pub const EVALUATE_SMOKE: &str = "--pfa 0.2 --runs 50 --snr-db 20 --frames 4";

/// `faint soak --frames` and the firmware soak's `frames=` are capped at this many
/// frames per detector; `faint fuzz --cases` at [`FUZZ_CASES`].
pub const SOAK_FRAMES: u64 = 200;
/// Cap of `faint fuzz --cases`.
pub const FUZZ_CASES: u64 = 32;

/// Exit status of a shim that refuses a command CI cannot run (a nightly toolchain, an
/// install): the block must carry a "CI skips" marker.
pub const REFUSED: i32 = 97;

const FAINT: &str = r#"#!/usr/bin/env bash
# `faint` as CI runs the documented commands: the binary in FAINT_DOC_BIN (release) with
# reproductions in their smoke form (run counts, SNR grids and Pfa dropped, --quick added),
# evaluations in theirs (size options replaced by a small fixed set) and soak/fuzz counts
# capped.
set -euo pipefail
sub=""
for a in "$@"; do case "$a" in -*) ;; *) sub="$a"; break ;; esac; done
out=()
drop=0
cap_next=""
quick=0
for a in "$@"; do
    if [ "$drop" = 1 ]; then drop=0; continue; fi
    if [ -n "$cap_next" ]; then
        if [ "$a" -gt "$cap_next" ] 2>/dev/null; then a="$cap_next"; fi
        cap_next=""; out+=("$a"); continue
    fi
    case "$sub:$a" in
        reproduce:--quick) quick=1 ;;
        @RUN_COUNTS@) drop=1; continue ;;
        @RUN_COUNTS_EQ@) continue ;;
        @EVALUATE_COUNTS@) drop=1; continue ;;
        @EVALUATE_COUNTS_EQ@) continue ;;
        soak:--frames) cap_next=@SOAK@ ;;
        soak:--frames=*) n="${a#--frames=}"; if [ "$n" -gt @SOAK@ ] 2>/dev/null; then a="--frames=@SOAK@"; fi ;;
        fuzz:--cases) cap_next=@FUZZ@ ;;
        fuzz:--cases=*) n="${a#--cases=}"; if [ "$n" -gt @FUZZ@ ] 2>/dev/null; then a="--cases=@FUZZ@"; fi ;;
    esac
    out+=("$a")
done
if [ "$sub" = reproduce ] && [ "$quick" = 0 ]; then out+=("--quick"); fi
case " $* " in *" --help "*|*" -h "*) ;;
    *) if [ "$sub" = evaluate ]; then out+=(@EVALUATE_SMOKE@); fi
       if [ "$sub" = soak ] && [[ " $* " != *" --frames"* ]]; then out+=(--frames @SOAK@); fi
       if [ "$sub" = fuzz ] && [[ " $* " != *" --cases"* ]]; then out+=(--cases @FUZZ@); fi ;;
esac
exec "$FAINT_DOC_BIN" "${out[@]}"
"#;

const CARGO: &str = r#"#!/usr/bin/env bash
# `cargo` as CI runs the documented commands: outside the repository it is pointed at the
# workspace; `cargo run -- ...` of the CLI goes through the `faint` shim (release) or
# builds the named profile first; benches run once each (criterion --test); the firmware
# soak's frames are capped. A toolchain override (+nightly) or an install is refused.
set -euo pipefail
real="$FAINT_DOC_CARGO"
case "${1:-}" in
    +*) echo "doc-commands: '$1' needs a toolchain CI does not install: mark the command 'CI skips'" >&2; exit @REFUSED@ ;;
    install) echo "doc-commands: 'cargo install' is not run in CI: mark the command 'CI skips'" >&2; exit @REFUSED@ ;;
esac
sub="${1:-}"; shift || true
here="$(pwd -P)"
extra=()
case "$here/" in "$FAINT_DOC_REPO"/*) ;; *) extra=(--manifest-path "$FAINT_DOC_REPO/Cargo.toml") ;; esac
pre=(); post=(); dashes=0
for a in "$@"; do
    if [ "$dashes" = 0 ] && [ "$a" = -- ]; then dashes=1; continue; fi
    if [ "$dashes" = 0 ]; then pre+=("$a"); else post+=("$a"); fi
done
example=""; bin=""; profile=""
prev=""
for a in "${pre[@]}"; do
    case "$prev" in --example) example="$a" ;; --bin) bin="$a" ;; --profile) profile="$a" ;; esac
    case "$a" in --release|-r) profile=release ;; --example=*) example="${a#*=}" ;; --bin=*) bin="${a#*=}" ;; --profile=*) profile="${a#*=}" ;; esac
    prev="$a"
done
if [ "$sub" = run ] && [ -z "$example" ] && { [ -z "$bin" ] || [ "$bin" = faint ]; } \
    && [ "$here" != "$FAINT_DOC_REPO/firmware" ]; then
    case "$profile" in
        release) exec faint "${post[@]}" ;;
        "") ;;
        *) "$real" build -q "${extra[@]}" --profile "$profile" --bin faint
           FAINT_DOC_BIN="$FAINT_DOC_REPO/target/$profile/faint" exec faint "${post[@]}" ;;
    esac
fi
if [ "$sub" = run ] && [ "$bin" = soak ] && [ "$here" = "$FAINT_DOC_REPO/firmware" ]; then
    new=(); prev=""; seen=0
    for a in "${post[@]}"; do
        if [ "$prev" = -append ]; then
            seen=1; words=(); has=0
            for w in $a; do
                case "$w" in frames=*) has=1; n="${w#frames=}"; if [ "$n" -gt @SOAK@ ]; then w="frames=@SOAK@"; fi ;; esac
                words+=("$w")
            done
            if [ "$has" = 0 ]; then words+=("frames=@SOAK@"); fi
            a="${words[*]}"
        fi
        new+=("$a"); prev="$a"
    done
    if [ "$seen" = 0 ]; then new+=(-append "frames=@SOAK@"); fi
    post=("${new[@]}"); dashes=1
fi
if [ "$sub" = bench ]; then
    new=(); skip=0
    for a in "${post[@]}"; do
        if [ "$skip" = 1 ]; then skip=0; continue; fi
        case "$a" in --warm-up-time|--measurement-time|--sample-size) skip=1; continue ;; esac
        new+=("$a")
    done
    post=("${new[@]}" --test); dashes=1
fi
if [ "$dashes" = 1 ]; then
    exec "$real" "$sub" "${extra[@]}" "${pre[@]}" -- "${post[@]}"
fi
exec "$real" "$sub" "${extra[@]}" "${pre[@]}"
"#;

const EXAMPLE: &str = r#"#!/usr/bin/env bash
# target/release/examples/NAME as CI runs it: built (release) and run by cargo.
set -euo pipefail
name="$1"; shift
exec "$FAINT_DOC_CARGO" run -q --release --manifest-path "$FAINT_DOC_REPO/Cargo.toml" --example "$name" -- "$@"
"#;

/// Writes the shims into `dir` (created) and returns it, for the front of `PATH`.
pub fn install(dir: &Path) -> std::io::Result<PathBuf> {
    use std::os::unix::fs::PermissionsExt;
    std::fs::create_dir_all(dir)?;
    let plain: Vec<String> = RUN_COUNTS
        .iter()
        .map(|o| format!("reproduce:{o}"))
        .collect();
    let eq: Vec<String> = RUN_COUNTS
        .iter()
        .map(|o| format!("reproduce:{o}=*"))
        .collect();
    let ev: Vec<String> = EVALUATE_COUNTS
        .iter()
        .map(|o| format!("evaluate:{o}"))
        .collect();
    let ev_eq: Vec<String> = EVALUATE_COUNTS
        .iter()
        .map(|o| format!("evaluate:{o}=*"))
        .collect();
    let fill = |s: &str| {
        s.replace("@RUN_COUNTS@", &plain.join("|"))
            .replace("@EVALUATE_COUNTS@", &ev.join("|"))
            .replace("@EVALUATE_COUNTS_EQ@", &ev_eq.join("|"))
            .replace("@EVALUATE_SMOKE@", EVALUATE_SMOKE)
            .replace("@RUN_COUNTS_EQ@", &eq.join("|"))
            .replace("@SOAK@", &SOAK_FRAMES.to_string())
            .replace("@FUZZ@", &FUZZ_CASES.to_string())
            .replace("@REFUSED@", &REFUSED.to_string())
    };
    for (name, text) in [
        ("faint", FAINT),
        ("cargo", CARGO),
        ("faint-example", EXAMPLE),
    ] {
        let p = dir.join(name);
        std::fs::write(&p, fill(text))?;
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755))?;
    }
    Ok(dir.to_path_buf())
}
