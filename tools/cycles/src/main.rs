//! `faint-cycles`: Cortex-M4 and Cortex-M7 cycle estimates of the firmware's measured
//! steps from QEMU's translation-block trace, and per-section code size.
//!
//! ```text
//! faint-cycles run [options] <firmware ELF>    run it on QEMU under the trace, print tables
//! faint-cycles size <firmware ELF>             .text/.rodata/.data/.bss by detector family
//! ```
//!
//! `run` options: `--machine mps2-an386`, `--cpu cortex-m4` (QEMU), `--m4-mhz 168`,
//! `--m7-mhz 480` (clocks of the time columns), `--wait-states 0` (added to every load
//! and pipeline refill), `--div 12` (SDIV/UDIV cycles), `--mispredict 4` (M7),
//! `--hot N` (the N costliest blocks of each region, with their instructions),
//! `--mca-out DIR` (writes each region's costliest loop block as `DIR/<k>.s` and, when
//! `llvm-mca` is on the PATH, compares the model with llvm-mca's Cortex-M4 model on it),
//! `--streams FILE` (writes one line per region with its traced instructions and a digest
//! of its executed instruction stream, to compare two runs, e.g. on `mps2-an386` with
//! `--cpu cortex-m4` and on `mps2-an500` with `--cpu cortex-m7`).
//! The cost model is in `model.rs`; the trace format in `trace.rs`.
//!
//! The firmware brackets each traced region with calls to `faint_cycles_begin` and
//! `faint_cycles_end` and prints one line per region, in order:
//! `region | <kind> | <label> | <expected M4 cycles or -> | <timer instructions>`.
//! Region 0 is empty (kind `base`): its cost, the marker calls, is subtracted from the
//! others. Kind `micro` rows are checked against the expected (TRM) M4 count; the tool
//! fails when one differs, when a region's traced instructions differ from the harness's
//! timer count by more than 16, or when the trace has lines it cannot attribute.

mod elf;
mod model;
mod trace;

use std::io::{BufRead, BufReader, Read};
use std::process::{Command, ExitCode, Stdio};

use model::Params;
use trace::Tracer;

/// Largest allowed |trace - timer| instructions per region: the timer's window also holds
/// the two marker calls and the closure's own call, about 20 instructions more than the
/// empty region the trace subtracts.
const TOLERANCE: u64 = 32;

struct Opts {
    machine: String,
    cpu: String,
    m4_mhz: f64,
    m7_mhz: f64,
    hot: usize,
    mca_out: Option<String>,
    streams: Option<String>,
    p: Params,
}

fn usage() -> String {
    "usage: faint-cycles run [--machine M] [--cpu C] [--m4-mhz F] [--m7-mhz F] [--wait-states N] [--div N] [--mispredict N] [--hot N] [--mca-out DIR] [--streams FILE] <elf> | faint-cycles size <elf>".into()
}

fn main() -> ExitCode {
    match real_main() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("faint-cycles: {e}");
            ExitCode::FAILURE
        }
    }
}

fn real_main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("run") => run(&args[1..]),
        Some("size") => {
            let [path] = &args[1..] else {
                return Err(usage());
            };
            size(path)
        }
        _ => Err(usage()),
    }
}

fn parse_opts(args: &[String]) -> Result<(Opts, String), String> {
    let mut o = Opts {
        machine: "mps2-an386".into(),
        cpu: "cortex-m4".into(),
        m4_mhz: 168.0,
        m7_mhz: 480.0,
        hot: 0,
        mca_out: None,
        streams: None,
        p: Params::default(),
    };
    let mut elf = None;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut val = |name: &str| {
            it.next()
                .cloned()
                .ok_or_else(|| format!("{name} needs a value"))
        };
        let num = |name: &str, v: String| {
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite() && *x >= 0.0)
                .ok_or_else(|| format!("{name}: not a non-negative number: {v}"))
        };
        match a.as_str() {
            "--machine" => o.machine = val(a)?,
            "--cpu" => o.cpu = val(a)?,
            "--m4-mhz" => o.m4_mhz = num(a, val(a)?)?,
            "--m7-mhz" => o.m7_mhz = num(a, val(a)?)?,
            "--wait-states" => o.p.wait_states = num(a, val(a)?)? as u64,
            "--div" => o.p.div = num(a, val(a)?)? as u64,
            "--mispredict" => o.p.mispredict = num(a, val(a)?)? as u64,
            "--hot" => o.hot = num(a, val(a)?)? as usize,
            "--mca-out" => o.mca_out = Some(val(a)?),
            "--streams" => o.streams = Some(val(a)?),
            s if s.starts_with("--") => return Err(format!("unknown option {s}; {}", usage())),
            s => elf = Some(s.to_string()),
        }
    }
    if o.m4_mhz == 0.0 || o.m7_mhz == 0.0 {
        return Err("--m4-mhz and --m7-mhz must be positive".into());
    }
    let elf = elf.ok_or_else(usage)?;
    Ok((o, elf))
}

/// One line the firmware printed for a region.
struct Label {
    kind: String,
    label: String,
    expect: Option<u64>,
    timer: u64,
}

fn labels(stdout: &str) -> Result<Vec<Label>, String> {
    let mut out = Vec::new();
    for l in stdout.lines().filter(|l| l.starts_with("region |")) {
        let f: Vec<&str> = l.split('|').map(str::trim).collect();
        if f.len() != 6 {
            return Err(format!("malformed region line: {l}"));
        }
        out.push(Label {
            kind: f[1].to_string(),
            label: f[2].to_string(),
            expect: f[3].parse().ok(),
            timer: f[4]
                .parse()
                .map_err(|_| format!("malformed instruction count in: {l}"))?,
        });
    }
    Ok(out)
}

fn run(args: &[String]) -> Result<(), String> {
    let (o, elf) = parse_opts(args)?;
    if !std::path::Path::new(&elf).is_file() {
        return Err(format!("no such file: {elf}"));
    }
    let mut child = Command::new("qemu-system-arm")
        .args(["-cpu", &o.cpu, "-machine", &o.machine, "-nographic"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .args(["-icount", "shift=10,align=off,sleep=off"])
        .args(["-d", "in_asm,exec,nochain", "-kernel", &elf])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start qemu-system-arm: {e}"))?;
    let mut out = child.stdout.take().expect("piped stdout");
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = out.read_to_string(&mut s);
        s
    });
    let mut t = Tracer::new(o.p, o.hot > 0 || o.mca_out.is_some());
    t.streams = o.streams.is_some();
    let mut other = Vec::new();
    let mut err = BufReader::with_capacity(1 << 20, child.stderr.take().expect("piped stderr"));
    let mut line = String::new();
    loop {
        line.clear();
        match err.read_line(&mut line) {
            Ok(0) => break,
            Ok(_) => {
                let l = line.trim_end();
                let before = t.lines;
                t.line(l);
                if !(l.starts_with("Trace ")
                    || l.starts_with("0x")
                    || l.starts_with("IN:")
                    || l.starts_with("---")
                    || l.is_empty()
                    || l.starts_with("Stopped"))
                    && other.len() < 20
                {
                    other.push(l.to_string());
                }
                debug_assert!(t.lines > before);
            }
            Err(e) => return Err(format!("reading the trace: {e}")),
        }
    }
    let status = child.wait().map_err(|e| format!("waiting for qemu: {e}"))?;
    let stdout = reader.join().unwrap_or_default();
    if !status.success() || !stdout.lines().any(|l| l == "done") {
        // The regions that completed (their lines were printed) still compare.
        if let (Some(file), Ok(l)) = (&o.streams, labels(&stdout)) {
            streams(file, &t, &l, &o.machine, &o.cpu)?;
        }
        return Err(format!(
            "the firmware failed ({status}); its output:\n{stdout}\n{}",
            other.join("\n")
        ));
    }
    report(&o, &t, &stdout)
}

fn report(o: &Opts, t: &Tracer, stdout: &str) -> Result<(), String> {
    let labels = labels(stdout)?;
    if labels.len() != t.regions.len() {
        return Err(format!(
            "the firmware printed {} region lines, the trace has {} regions",
            labels.len(),
            t.regions.len()
        ));
    }
    if t.unknown > 0 {
        return Err(format!(
            "{} trace lines could not be attributed to a translated block",
            t.unknown
        ));
    }
    let Some(base) = t.regions.first().filter(|_| labels[0].kind == "base") else {
        return Err("region 0 must be the empty `base` region".into());
    };
    if let Some(file) = &o.streams {
        streams(file, t, &labels, &o.machine, &o.cpu)?;
    }
    let mut failures = Vec::new();
    println!("trace: {} lines", t.lines);
    println!(
        "base region (marker calls, subtracted below): {} instructions, {} M4 cycles, {} M7 cycles",
        base.instructions, base.m4, base.m7
    );
    println!();
    println!("| kernel | instructions | M4 cycles (TRM) | M4 cycles (model) | M7 cycles (model) |");
    println!("|---|---:|---:|---:|---:|");
    for (r, l) in t
        .regions
        .iter()
        .zip(&labels)
        .filter(|(_, l)| l.kind == "micro")
    {
        let n = r.instructions.saturating_sub(base.instructions);
        let m4 = r.m4.saturating_sub(base.m4);
        let m7 = r.m7.saturating_sub(base.m7);
        let e = l.expect.map_or("-".into(), |e| e.to_string());
        println!("| {} | {n} | {e} | {m4} | {m7} |", l.label);
        if l.expect.is_some_and(|e| e != m4) {
            failures.push(format!("{}: TRM {e} cycles, model {m4}", l.label));
        }
    }
    println!();
    println!(
        "| measurement | instructions (trace) | instructions (timer) | M4 cycles | M4 cycles / instruction | M4 ms at {} MHz | M7 cycles | M7 cycles / instruction | M7 ms at {} MHz |",
        o.m4_mhz, o.m7_mhz
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut loops = Vec::new();
    for (k, (r, l)) in t.regions.iter().zip(&labels).enumerate() {
        if l.kind != "step" {
            continue;
        }
        let n = r.instructions.saturating_sub(base.instructions);
        let m4 = r.m4.saturating_sub(base.m4);
        let m7 = r.m7.saturating_sub(base.m7);
        let cpi = |c: u64| c as f64 / n.max(1) as f64;
        println!(
            "| {} | {n} | {} | {m4} | {:.2} | {:.3} | {m7} | {:.2} | {:.3} |",
            l.label,
            l.timer,
            cpi(m4),
            m4 as f64 / (o.m4_mhz * 1e3),
            cpi(m7),
            m7 as f64 / (o.m7_mhz * 1e3)
        );
        if n.abs_diff(l.timer) > TOLERANCE {
            failures.push(format!(
                "{}: {n} traced instructions, {} counted by the timer",
                l.label, l.timer
            ));
        }
        if o.hot > 0 {
            hot(t, r, k, o.hot);
        }
        if let Some(dir) = &o.mca_out {
            if let Some(m) = mca(t, r, k, dir)? {
                loops.push((l.label.clone(), m));
            }
        }
    }
    if !loops.is_empty() {
        println!();
        println!("| measurement | costliest loop block | instructions (body) | M4 cycles / iteration, model | M4 cycles / iteration, llvm-mca |");
        println!("|---|---|---:|---:|---:|");
        for (label, m) in &loops {
            println!(
                "| {label} | 0x{:08x} | {} | {} | {} |",
                m.start,
                m.body,
                m.model,
                m.llvm
                    .map_or("(no llvm-mca)".to_string(), |c| format!("{c:.2}"))
            );
        }
    }
    if o.hot > 0 {
        println!();
    }
    if failures.is_empty() {
        Ok(())
    } else {
        Err(format!("model check failed:\n  {}", failures.join("\n  ")))
    }
}

/// Writes one line per region: index, kind, label, traced instructions (the marker calls
/// included) and the stream digest. Two runs of one image execute the same instructions
/// in every region when their files are equal. When the firmware fails, the regions it
/// completed (printed) are written.
fn streams(
    file: &str,
    t: &Tracer,
    labels: &[Label],
    machine: &str,
    cpu: &str,
) -> Result<(), String> {
    let mut s = format!(
        "# executed instruction streams per region (FNV-1a over the addresses), QEMU {machine} {cpu}\n"
    );
    for (k, (r, l)) in t.regions.iter().zip(labels).enumerate() {
        s.push_str(&format!(
            "{k} | {} | {} | {} | {:016x}\n",
            l.kind, l.label, r.instructions, r.stream
        ));
    }
    std::fs::write(file, s).map_err(|e| format!("writing {file}: {e}"))
}

fn ranked(r: &trace::Totals) -> Vec<(usize, u64, u64)> {
    let mut v: Vec<_> = r.per_block.iter().map(|(&b, &(n, c))| (b, n, c)).collect();
    v.sort_by(|a, b| b.2.cmp(&a.2).then(a.0.cmp(&b.0)));
    v
}

fn hot(t: &Tracer, r: &trace::Totals, k: usize, n: usize) {
    for (b, execs, m4) in ranked(r).into_iter().take(n) {
        let (start, text) = t.block_text(b);
        let (c4, c7, len) = t.block_cost(b);
        println!(
            "  region {k} block 0x{start:08x}: {execs} executions, {len} instructions, {c4} M4 / {c7} M7 cycles each without refill, {:.1} % of M4: {}",
            100.0 * m4 as f64 / r.m4.max(1) as f64,
            text.join("; ")
        );
    }
}

/// A loop body compared with llvm-mca.
struct Loop {
    start: u32,
    body: usize,
    model: u64,
    llvm: Option<f64>,
}

/// Writes region `k`'s costliest block that branches back to its own start (a loop) as
/// `DIR/<k>.s` without the loop branch, and runs
/// `llvm-mca -mtriple=thumbv7em-none-eabihf -mcpu=cortex-m4 -iterations=100` on it when
/// `llvm-mca` is on the PATH.
fn mca(t: &Tracer, r: &trace::Totals, k: usize, dir: &str) -> Result<Option<Loop>, String> {
    for (b, execs, _) in ranked(r) {
        let (start, text) = t.block_text(b);
        let last = text.last().cloned().unwrap_or_default();
        if !last.contains(&format!("#0x{start:x}")) || execs < 2 || text.len() < 2 {
            continue;
        }
        let body = &text[..text.len() - 1];
        let model = t.body_m4(b);
        std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {dir}: {e}"))?;
        let file = format!("{dir}/{k}.s");
        let src = format!(
            "@ region {k}, block 0x{start:08x}: model {model} M4 cycles per iteration without the loop branch\n  .syntax unified\n  .thumb\n{}\n",
            body.iter().map(|s| format!("  {s}")).collect::<Vec<_>>().join("\n")
        );
        std::fs::write(&file, src).map_err(|e| format!("writing {file}: {e}"))?;
        let llvm = Command::new("llvm-mca")
            .args([
                "-mtriple=thumbv7em-none-eabihf",
                "-mcpu=cortex-m4",
                "-iterations=100",
                &file,
            ])
            .output()
            .ok()
            .filter(|o| o.status.success())
            .and_then(|o| {
                let out = String::from_utf8_lossy(&o.stdout).into_owned();
                let field = |name: &str| -> Option<f64> {
                    out.lines()
                        .find(|l| l.starts_with(name))
                        .and_then(|l| l.split_whitespace().last())
                        .and_then(|v| v.parse().ok())
                };
                Some(field("Total Cycles:")? / field("Iterations:")?)
            });
        return Ok(Some(Loop {
            start,
            body: body.len(),
            model,
            llvm,
        }));
    }
    Ok(None)
}

/// Families by the words of their symbols (first match wins).
const FAMILIES: [(&str, &[&str]); 7] = [
    (
        "CRPF-TBD, PF-TBD, JOTT, PF-LRT",
        &["crpf", "pf_tbd", "jott", "bernoulli", "pf_lrt"],
    ),
    ("MHT-TBD, classic Hough", &["mht", "hough", "dmht"]),
    (
        "PHD-TBD, PSO-PHD-TBD",
        &["phd", "pso", "dbscan", "kmeans", "ndsort"],
    ),
    ("CBMeMBer", &["cbmember"]),
    ("DP-TBD", &["dp"]),
    (
        "faint-core shared (rng, math, resampling, models)",
        &["faint_core"],
    ),
    (
        "firmware harness, golden cases",
        &["faint_firmware", "faint_golden"],
    ),
];

fn size(path: &str) -> Result<(), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {path}: {e}"))?;
    let (sections, symbols) = elf::read(&bytes).map_err(|e| format!("{path}: {e}"))?;
    let cols = [".text", ".rodata", ".data", ".bss"];
    let col = |s: &elf::Section| -> Option<usize> {
        let n = s.name.as_str();
        if !s.alloc {
            return None;
        }
        if n == ".text" || n == ".vector_table" {
            Some(0)
        } else if n == ".rodata" {
            Some(1)
        } else if n == ".data" {
            Some(2)
        } else if n == ".bss" || n == ".uninit" || n == ".psram" {
            Some(3)
        } else {
            None
        }
    };
    let mut total = [0u64; 4];
    println!("| section | bytes |");
    println!("|---|---:|");
    for s in sections.iter().filter(|s| s.alloc && s.size > 0) {
        println!("| {} | {} |", s.name, s.size);
        if let Some(c) = col(s) {
            total[c] += s.size;
        }
    }
    println!();
    let mut rows = vec![[0u64; 4]; FAMILIES.len() + 1];
    for sym in &symbols {
        let Some(c) = col(&sections[sym.section]) else {
            continue;
        };
        let w = elf::words(&sym.name);
        let fam = FAMILIES
            .iter()
            .position(|(_, keys)| keys.iter().any(|k| w.iter().any(|x| x == k)))
            .unwrap_or(FAMILIES.len());
        rows[fam][c] += sym.size;
    }
    println!("| attributed to (symbol names) | .text | .rodata | .data | .bss | flash (.text + .rodata + .data) |");
    println!("|---|---:|---:|---:|---:|---:|");
    let mut attributed = [0u64; 4];
    for (i, r) in rows.iter().enumerate() {
        let name = FAMILIES
            .get(i)
            .map_or("Rust core, compiler-builtins, libm, cortex-m-rt", |f| f.0);
        println!(
            "| {name} | {} | {} | {} | {} | {} |",
            r[0],
            r[1],
            r[2],
            r[3],
            r[0] + r[1] + r[2]
        );
        for c in 0..4 {
            attributed[c] += r[c];
        }
    }
    let un: Vec<u64> = (0..4)
        .map(|c| total[c].saturating_sub(attributed[c]))
        .collect();
    println!(
        "| no symbol (literal pools, merged constants, padding) | {} | {} | {} | {} | {} |",
        un[0],
        un[1],
        un[2],
        un[3],
        un[0] + un[1] + un[2]
    );
    println!(
        "| image ({}) | {} | {} | {} | {} | {} |",
        cols.join(", "),
        total[0],
        total[1],
        total[2],
        total[3],
        total[0] + total[1] + total[2]
    );
    Ok(())
}
