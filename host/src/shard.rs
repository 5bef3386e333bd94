//! Sharded Monte Carlo: one run's trials split over processes or machines, then merged
//! into the outputs of the unsharded run, bit for bit.
//!
//! A run is a list of batches, each `trials` trials of one master seed; trial `t` of a
//! batch always draws from `Rng::from_stream(master, t)` ([`crate::montecarlo`]), so it
//! gives the same result whichever process runs it. Shard `i` of `n` runs trials
//! `floor(t i / n) .. floor(t (i + 1) / n)` of every batch ([`Shard::range`]) and writes
//! their raw results to a shard file ([`write()`]): CBOR, whose floats round-trip bit for
//! bit (NaN and infinities included), with the command, its full argument set, the run's
//! fixed inputs (`meta`), the binary's version and identity ([`build_id`]) and the format
//! version. [`read`] checks that a set of shard files is one whole run (one command,
//! arguments, inputs, version and binary; every shard exactly once) and joins the batches in trial order; the command
//! then computes its thresholds, rates, tables and plots from them exactly as the
//! unsharded run does from its own.
//!
//! With no `--shard`, the shard comes from the scheduler ([`Shard::from_env`]): SLURM
//! job arrays (`SLURM_ARRAY_TASK_ID`, `SLURM_ARRAY_TASK_COUNT`, with
//! `SLURM_ARRAY_TASK_MIN` and `SLURM_ARRAY_TASK_STEP` when set) or Kubernetes Indexed
//! Jobs (`JOB_COMPLETION_INDEX`, with the count in [`COUNT_VAR`]).

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use anyhow::{bail, ensure, Context, Result};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// Version of the shard file layout; [`read`] refuses any other.
pub const FORMAT: u32 = 2;

/// Extension of shard files.
pub const EXT: &str = "faint-shard";

/// Most shards a run may be split into.
pub const MAX_SHARDS: usize = 100_000;

/// Environment variable holding the shard count of a Kubernetes Indexed Job (set it to
/// the Job's `completions`; Kubernetes gives only the index, `JOB_COMPLETION_INDEX`).
pub const COUNT_VAR: &str = "FAINT_SHARD_COUNT";

const MAGIC: &str = "faint shard";

/// The version written into shard files and required of them by [`read`].
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The identity of the running binary: the FNV-1a 64-bit hash of its executable file,
/// in hex, or `None` when the file cannot be read. Two builds of the same version from
/// different sources (or compilers, or options) differ here, so `faint merge` refuses
/// shards that another binary wrote even when the version matches.
pub fn build_id() -> Option<&'static str> {
    static ID: std::sync::OnceLock<Option<String>> = std::sync::OnceLock::new();
    ID.get_or_init(|| {
        let bytes = std::fs::read(std::env::current_exe().ok()?).ok()?;
        Some(format!("{:016x}", fnv1a64(&bytes)))
    })
    .as_deref()
}

/// FNV-1a, 64 bits (offset basis 0xcbf29ce484222325, prime 0x100000001b3).
fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Shard `index` of `count` (0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This shard, `0..count`.
    pub index: usize,
    /// Shards in the run.
    pub count: usize,
}

/// The `--shard` option every sharded command flattens into its arguments.
#[derive(clap::Args, Debug, Clone, Default, PartialEq, Eq)]
pub struct ShardArg {
    /// Run only shard I of N (0 <= I < N <= 100000) of the Monte Carlo trials and write
    /// their raw results to a shard file for `faint merge`; `off` runs everything even
    /// inside a scheduler's array [default: from SLURM_ARRAY_TASK_ID /
    /// SLURM_ARRAY_TASK_COUNT or JOB_COMPLETION_INDEX / FAINT_SHARD_COUNT, else off].
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
}

impl ShardArg {
    /// The shard to run: `--shard`, else the scheduler's environment, else none.
    pub fn resolve(&self) -> Result<Option<Shard>> {
        match self.shard.as_deref() {
            Some("off") => Ok(None),
            Some(s) => Shard::parse(s).map(Some),
            None => Shard::from_env(|k| std::env::var(k).ok()),
        }
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// A checked shard: `1 <= count <= MAX_SHARDS`, `index < count`; `what` names the
    /// source in the error.
    pub fn new(index: usize, count: usize, what: &str) -> Result<Self> {
        ensure!(
            (1..=MAX_SHARDS).contains(&count),
            "{what}: the shard count must lie in 1..={MAX_SHARDS}, got {count}"
        );
        ensure!(
            index < count,
            "{what}: shard {index} of {count} does not exist (shards are 0..{})",
            count - 1
        );
        Ok(Self { index, count })
    }

    /// Parses `--shard I/N`.
    pub fn parse(s: &str) -> Result<Self> {
        let what = format!("--shard {s}");
        let Some((i, n)) = s.split_once('/') else {
            bail!("{what}: not I/N (for example 0/4) or off");
        };
        let num = |x: &str| -> Result<usize> {
            x.trim()
                .parse()
                .map_err(|_| anyhow::anyhow!("{what}: '{x}' is not a whole number"))
        };
        Self::new(num(i)?, num(n)?, &what)
    }

    /// The shard given by a scheduler's environment (`var` reads a variable): a SLURM
    /// job array's `SLURM_ARRAY_TASK_ID` and `SLURM_ARRAY_TASK_COUNT` (the index counted
    /// from `SLURM_ARRAY_TASK_MIN` in steps of `SLURM_ARRAY_TASK_STEP`, when set), else a
    /// Kubernetes Indexed Job's `JOB_COMPLETION_INDEX` with the count in [`COUNT_VAR`];
    /// `None` outside both.
    pub fn from_env(var: impl Fn(&str) -> Option<String>) -> Result<Option<Self>> {
        let num = |k: &str| -> Result<Option<usize>> {
            match var(k) {
                None => Ok(None),
                Some(v) => v
                    .trim()
                    .parse()
                    .map(Some)
                    .map_err(|_| anyhow::anyhow!("{k}={v}: not a whole number")),
            }
        };
        if let Some(id) = num("SLURM_ARRAY_TASK_ID")? {
            let Some(count) = num("SLURM_ARRAY_TASK_COUNT")? else {
                bail!("SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not: give --shard I/N");
            };
            let min = num("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
            let step = num("SLURM_ARRAY_TASK_STEP")?.unwrap_or(1).max(1);
            ensure!(
                id >= min && (id - min) % step == 0,
                "SLURM_ARRAY_TASK_ID={id} is not on the array's grid (min {min}, step {step}): give --shard I/N"
            );
            let what = format!(
                "SLURM_ARRAY_TASK_ID={id} of SLURM_ARRAY_TASK_COUNT={count} (submit with --array=0-{})",
                count.saturating_sub(1)
            );
            return Self::new((id - min) / step, count, &what).map(Some);
        }
        if let Some(index) = num("JOB_COMPLETION_INDEX")? {
            let Some(count) = num(COUNT_VAR)? else {
                bail!("JOB_COMPLETION_INDEX is set but {COUNT_VAR} is not: set it to the Job's completions, or give --shard I/N");
            };
            let what = format!("JOB_COMPLETION_INDEX={index} of {COUNT_VAR}={count}");
            return Self::new(index, count, &what).map(Some);
        }
        Ok(None)
    }

    /// The trials of a batch of `trials` this shard runs:
    /// `floor(trials index / count) .. floor(trials (index + 1) / count)`. The ranges of
    /// the `count` shards tile `0..trials`, each one trial longer than another at most.
    pub fn range(&self, trials: usize) -> Range<usize> {
        let at = |i: usize| (trials as u128 * i as u128 / self.count as u128) as usize;
        at(self.index)..at(self.index + 1)
    }

    /// The shard file's name, `shard-<i>-of-<n>.faint-shard` (zero-padded to `n`'s width,
    /// so the names sort in index order).
    pub fn file_name(&self) -> String {
        let w = self.count.to_string().len();
        format!("shard-{:0w$}-of-{}.{EXT}", self.index, self.count, w = w)
    }
}

/// The trials of one batch: all of them (`first == 0`, `results.len() == trials`) or one
/// shard's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Batch<T> {
    /// Name of the batch, unique in its run (for example `h0`, `snr 4`).
    pub key: String,
    /// Trials of the whole batch.
    pub trials: usize,
    /// Index of the first trial held.
    pub first: usize,
    /// Results of trials `first..first + results.len()`, in trial order.
    pub results: Vec<T>,
}

impl<T> Batch<T> {
    /// The trials of batch `key` that `shard` runs (all of them for `None`), each result
    /// `f(range)` in trial order.
    pub fn run<E>(
        key: impl Into<String>,
        trials: usize,
        shard: Option<Shard>,
        f: impl FnOnce(Range<usize>) -> std::result::Result<Vec<T>, E>,
    ) -> std::result::Result<Self, E> {
        let range = shard.map_or(0..trials, |s| s.range(trials));
        let first = range.start;
        Ok(Self {
            key: key.into(),
            trials,
            first,
            results: f(range)?,
        })
    }
}

impl<T: Serialize> Batch<T> {
    /// The batch with its results as CBOR values: batches of different record types (a
    /// command's trial loops and its one-off parts) then share one run and one shard file.
    pub fn into_values(self) -> Result<Batch<ciborium::Value>> {
        let results = self
            .results
            .iter()
            .map(|r| {
                ciborium::Value::serialized(r)
                    .map_err(|e| anyhow::anyhow!("batch {}: cannot encode: {e}", self.key))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Batch {
            key: self.key,
            trials: self.trials,
            first: self.first,
            results,
        })
    }
}

/// The whole batches of a run by key, each decoded into its own record type: those one
/// process ran ([`Batches::whole`]) or those `faint merge` joined ([`Merged::batches`]).
/// A command computes its outputs from them by one code path whichever way they came.
#[derive(Debug)]
pub struct Batches {
    what: String,
    batches: Vec<Batch<ciborium::Value>>,
}

impl Batches {
    /// The batches of an unsharded run.
    pub fn whole(batches: Vec<Batch<ciborium::Value>>) -> Self {
        Self {
            what: "this run".into(),
            batches,
        }
    }

    /// The keys of the batches, in order.
    pub fn keys(&self) -> Vec<&str> {
        self.batches.iter().map(|b| b.key.as_str()).collect()
    }

    /// Checks that the batches are exactly `keys`, in order (the batches the command's
    /// arguments define).
    pub fn expect(&self, keys: &[String]) -> Result<()> {
        let have = self.keys();
        ensure!(
            have == keys.iter().map(String::as_str).collect::<Vec<_>>(),
            "{}: its batches ({}) are not the ones its arguments define ({})",
            self.what,
            have.join(", "),
            keys.join(", ")
        );
        Ok(())
    }

    /// The results of batch `key`, in trial order.
    pub fn get<T: DeserializeOwned>(&self, key: &str) -> Result<Vec<T>> {
        let b = self
            .batches
            .iter()
            .find(|b| b.key == key)
            .ok_or_else(|| anyhow::anyhow!("{}: no batch {key}", self.what))?;
        b.results
            .iter()
            .map(|v| v.deserialized::<T>())
            .collect::<std::result::Result<Vec<T>, _>>()
            .map_err(|e| anyhow::anyhow!("{}: batch {key}: unreadable results: {e}", self.what))
    }
}

/// What makes shards parts of one run: the command, its arguments and the inputs fixed
/// before the trials. The arguments and inputs are kept as CBOR, whose floats
/// round-trip exactly (JSON text would not promise it).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Run {
    /// The command, as typed (`reproduce crpf`, `calibrate`).
    pub command: String,
    /// Its arguments (every option, given or default; `--shard` left out), CBOR.
    args: Vec<u8>,
    /// What the command fixed before the trials (for example a noise model estimated on
    /// the input), identical in every shard; CBOR, `null` if nothing.
    meta: Vec<u8>,
}

fn cbor(v: &impl Serialize) -> Result<Vec<u8>> {
    let mut buf = Vec::new();
    ciborium::into_writer(v, &mut buf).map_err(|e| anyhow::anyhow!("cannot encode: {e}"))?;
    Ok(buf)
}

fn uncbor<T: DeserializeOwned>(bytes: &[u8], what: &str) -> Result<T> {
    ciborium::from_reader(bytes).map_err(|e| anyhow::anyhow!("unreadable {what}: {e}"))
}

impl Run {
    /// A run of `command` with arguments `args` and no meta.
    pub fn new(command: &str, args: &impl Serialize) -> Result<Self> {
        Ok(Self {
            command: command.to_string(),
            args: cbor(args)?,
            meta: cbor(&())?,
        })
    }

    /// The run with `meta`, the inputs it fixed before the trials.
    pub fn with_meta(self, meta: &impl Serialize) -> Result<Self> {
        Ok(Self {
            meta: cbor(meta)?,
            ..self
        })
    }

    /// The arguments, decoded.
    pub fn args<T: DeserializeOwned>(&self) -> Result<T> {
        uncbor(&self.args, "arguments")
    }

    /// The meta, decoded.
    pub fn meta<T: DeserializeOwned>(&self) -> Result<T> {
        uncbor(&self.meta, "inputs")
    }
}

#[derive(Debug, Serialize, Deserialize)]
struct Header {
    magic: String,
    format: u32,
    version: String,
    /// [`build_id`] of the binary that wrote the file.
    build: Option<String>,
    run: Run,
    shard: Shard,
    /// Wall-clock seconds the shard's runs took.
    seconds: f64,
}

#[derive(Debug, Serialize)]
struct FileRef<'a, T> {
    header: Header,
    batches: &'a [Batch<T>],
}

#[derive(Debug, Deserialize)]
struct File<T> {
    header: Header,
    batches: Vec<Batch<T>>,
}

/// Writes the batches of `shard` of `run`, which took `seconds` of wall-clock time, into
/// `dir` (created) as [`Shard::file_name`]; returns the file's path. The file is written under a temporary
/// name and renamed, so a reader never sees half of it.
pub fn write<T: Serialize>(
    dir: &Path,
    run: &Run,
    shard: Shard,
    seconds: f64,
    batches: &[Batch<T>],
) -> Result<PathBuf> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{}: cannot create the shard folder", dir.display()))?;
    let path = dir.join(shard.file_name());
    let tmp = dir.join(format!(".{}.tmp-{}", shard.file_name(), std::process::id()));
    let file = FileRef {
        header: Header {
            magic: MAGIC.into(),
            format: FORMAT,
            version: VERSION.into(),
            build: build_id().map(str::to_string),
            run: run.clone(),
            shard,
            seconds,
        },
        batches,
    };
    let mut buf = Vec::new();
    ciborium::into_writer(&file, &mut buf)
        .map_err(|e| anyhow::anyhow!("{}: cannot encode: {e}", path.display()))?;
    std::fs::write(&tmp, &buf).with_context(|| format!("cannot write {}", tmp.display()))?;
    std::fs::rename(&tmp, &path).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(path)
}

/// The shards of one run joined: the run and every batch whole, in trial order.
#[derive(Debug)]
pub struct Merged {
    /// The run they belong to.
    pub run: Run,
    /// Shards merged.
    pub count: usize,
    /// Files merged, in shard order.
    pub files: Vec<PathBuf>,
    /// Sum of the shards' wall-clock seconds.
    pub seconds: f64,
    batches: Vec<Batch<ciborium::Value>>,
}

impl Merged {
    /// The results of every batch, in the order of `keys` (the batches the command's
    /// arguments define): an error if the shards hold other batches.
    pub fn results<T: DeserializeOwned>(&self, keys: &[String]) -> Result<Vec<Vec<T>>> {
        let have: Vec<&str> = self.batches.iter().map(|b| b.key.as_str()).collect();
        ensure!(
            have == keys.iter().map(String::as_str).collect::<Vec<_>>(),
            "{}: its batches ({}) are not the ones its arguments define ({})",
            self.files[0].display(),
            have.join(", "),
            keys.join(", ")
        );
        self.batches
            .iter()
            .map(|b| {
                b.results
                    .iter()
                    .map(|v| v.deserialized::<T>())
                    .collect::<std::result::Result<Vec<T>, _>>()
                    .map_err(|e| {
                        anyhow::anyhow!(
                            "{}: batch {}: unreadable results: {e}",
                            self.files[0].display(),
                            b.key
                        )
                    })
            })
            .collect()
    }
}

impl Merged {
    /// The joined batches, checked to be exactly `keys` in order, for a command whose
    /// batches hold different record types ([`Batch::into_values`]).
    pub fn batches(&self, keys: &[String]) -> Result<Batches> {
        let b = Batches {
            what: self.files[0].display().to_string(),
            batches: self.batches.clone(),
        };
        b.expect(keys)?;
        Ok(b)
    }
}

/// Writes a shard of `command` (arguments `args`, fixed inputs `meta`) begun at `t0` to
/// `dir` and prints where it went and how to merge it: the last step of every sharded
/// reproduction.
pub fn finish<T: Serialize>(
    dir: &Path,
    run: &Run,
    shard: Shard,
    t0: std::time::Instant,
    batches: &[Batch<T>],
) -> Result<PathBuf> {
    let seconds = t0.elapsed().as_secs_f64();
    let path = write(dir, run, shard, seconds, batches)?;
    let runs: usize = batches.iter().map(|b| b.results.len()).sum();
    println!(
        "shard {shard}: {runs} runs in {seconds:.1} s written to {}; merge with `faint merge {}`",
        path.display(),
        dir.display()
    );
    Ok(path)
}

/// The shard files named by `inputs`: each a shard file, or a folder whose
/// `*.faint-shard` files are taken (not its sub-folders).
pub fn files(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    ensure!(!inputs.is_empty(), "no shard files or folders given");
    let mut out = Vec::new();
    for p in inputs {
        if p.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(p)
                .with_context(|| format!("{}: cannot read the folder", p.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|f| f.is_file() && f.extension().is_some_and(|e| e == EXT))
                .collect();
            ensure!(!found.is_empty(), "{}: no .{EXT} files in it", p.display());
            found.sort();
            out.extend(found);
        } else {
            ensure!(p.is_file(), "{}: no such file or folder", p.display());
            out.push(p.clone());
        }
    }
    Ok(out)
}

fn load(path: &Path) -> Result<File<ciborium::Value>> {
    let bytes = std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
    // The header alone first: a foreign format is named before the body is decoded.
    #[derive(Deserialize)]
    struct Head {
        header: ciborium::Value,
    }
    let not = || anyhow::anyhow!("{}: not a faint shard file", path.display());
    let head: Head = ciborium::from_reader(bytes.as_slice()).map_err(|_| not())?;
    let magic = head
        .header
        .as_map()
        .and_then(|m| {
            m.iter()
                .find(|(k, _)| k.as_text() == Some("magic"))
                .and_then(|(_, v)| v.as_text().map(str::to_string))
        })
        .ok_or_else(not)?;
    ensure!(magic == MAGIC, "{}: not a faint shard file", path.display());
    let format = head
        .header
        .as_map()
        .and_then(|m| {
            m.iter()
                .find(|(k, _)| k.as_text() == Some("format"))
                .and_then(|(_, v)| v.as_integer())
        })
        .and_then(|i| u32::try_from(i).ok())
        .ok_or_else(not)?;
    ensure!(
        format == FORMAT,
        "{}: shard format {format}, this faint reads format {FORMAT}",
        path.display()
    );
    ciborium::from_reader(bytes.as_slice())
        .map_err(|e| anyhow::anyhow!("{}: a damaged shard file ({e})", path.display()))
}

/// The first option whose value differs between two argument sets (CBOR maps), as
/// `--name A here, B`.
fn first_difference(a: &[u8], b: &[u8]) -> String {
    let parse = |s: &[u8]| -> BTreeMap<String, serde_json::Value> {
        uncbor(s, "arguments").unwrap_or_default()
    };
    let (a, b) = (parse(a), parse(b));
    let keys: std::collections::BTreeSet<&String> = a.keys().chain(b.keys()).collect();
    for k in keys {
        let (x, y) = (a.get(k), b.get(k));
        if x != y {
            let show = |v: Option<&serde_json::Value>| match v {
                None | Some(serde_json::Value::Null) => "not given".to_string(),
                Some(v) => v.to_string(),
            };
            return format!("--{} {} here, {}", k.replace('_', "-"), show(x), show(y));
        }
    }
    "other arguments".into()
}

/// Reads the shard files of `inputs` ([`files`]) and joins them, after checking that
/// they are one whole run: the same command, arguments and inputs, written by this
/// version and this binary of faint ([`build_id`]; not checked where a binary cannot read
/// its own file), with every shard `0..n` exactly once and every batch's trials where
/// its shard puts them. Each failure is one line naming the file (or the missing shard).
pub fn read(inputs: &[PathBuf]) -> Result<Merged> {
    let paths = files(inputs)?;
    let mut loaded: Vec<(PathBuf, File<ciborium::Value>)> = Vec::with_capacity(paths.len());
    for p in &paths {
        let f = load(p)?;
        ensure!(
            f.header.version == VERSION,
            "{}: written by faint {}, this is faint {VERSION}: merge with the binary that ran the shards",
            p.display(),
            f.header.version
        );
        if let (Some(theirs), Some(ours)) = (f.header.build.as_deref(), build_id()) {
            ensure!(
                theirs == ours,
                "{}: written by another build of faint {VERSION} (binary {theirs}, this one is {ours}): merge with the binary that ran the shards",
                p.display()
            );
        }
        loaded.push((p.clone(), f));
    }
    let (p0, f0) = &loaded[0];
    let (run, count) = (f0.header.run.clone(), f0.header.shard.count);
    let mut by_index: Vec<Option<usize>> = vec![None; count];
    for (n, (p, f)) in loaded.iter().enumerate() {
        let h = &f.header;
        ensure!(
            h.run.command == run.command,
            "{}: a shard of `faint {}`, not of `faint {}` like {}",
            p.display(),
            h.run.command,
            run.command,
            p0.display()
        );
        ensure!(
            h.run.args == run.args,
            "{}: a shard of another run ({} in {})",
            p.display(),
            first_difference(&h.run.args, &run.args),
            p0.display()
        );
        ensure!(
            h.run.meta == run.meta,
            "{}: a shard of another run (its inputs differ from those of {})",
            p.display(),
            p0.display()
        );
        ensure!(
            h.shard.count == count,
            "{}: shard {}, but {} is one of {count} shards",
            p.display(),
            h.shard,
            p0.display()
        );
        ensure!(
            h.shard.index < count,
            "{}: shard {} does not exist",
            p.display(),
            h.shard
        );
        if let Some(prev) = by_index[h.shard.index] {
            bail!(
                "{}: shard {} is given twice (also {})",
                p.display(),
                h.shard,
                loaded[prev].0.display()
            );
        }
        by_index[h.shard.index] = Some(n);
    }
    let missing: Vec<String> = by_index
        .iter()
        .enumerate()
        .filter(|(_, s)| s.is_none())
        .map(|(i, _)| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        let list = if missing.len() > 4 {
            format!(
                "{}, ... ({} in all)",
                missing[..4].join(", "),
                missing.len()
            )
        } else {
            missing.join(", ")
        };
        let given: Vec<String> = inputs.iter().map(|p| p.display().to_string()).collect();
        bail!(
            "shard{} {list} {} missing from {} ({} of the {count} shards of `faint {}` found)",
            if missing.len() > 1 { "s" } else { "" },
            if missing.len() > 1 { "are" } else { "is" },
            given.join(" "),
            count - missing.len(),
            run.command
        );
    }
    let order: Vec<usize> = by_index.into_iter().flatten().collect();
    let mut joined: Vec<Batch<ciborium::Value>> = Vec::new();
    let mut files = Vec::with_capacity(count);
    let mut seconds = 0.0;
    for (i, &n) in order.iter().enumerate() {
        let (p, f) = &mut loaded[n];
        let shard = f.header.shard;
        if i == 0 {
            joined = f
                .batches
                .iter()
                .map(|b| Batch {
                    key: b.key.clone(),
                    trials: b.trials,
                    first: 0,
                    results: Vec::with_capacity(b.trials),
                })
                .collect();
        }
        ensure!(
            f.batches.len() == joined.len()
                && f.batches.iter().zip(&joined).all(|(b, j)| b.key == j.key),
            "{}: its batches are not those of {}",
            p.display(),
            loaded_name(&paths, order[0])
        );
        for (b, j) in std::mem::take(&mut f.batches)
            .into_iter()
            .zip(joined.iter_mut())
        {
            let want = shard.range(j.trials);
            ensure!(
                b.trials == j.trials && b.first == want.start && b.results.len() == want.len(),
                "{}: batch {} holds trials {}..{} of {}, shard {shard} must hold {}..{} of {}",
                p.display(),
                b.key,
                b.first,
                b.first + b.results.len(),
                b.trials,
                want.start,
                want.end,
                j.trials
            );
            j.results.extend(b.results);
        }
        files.push(p.clone());
        seconds += f.header.seconds;
    }
    Ok(Merged {
        run,
        count,
        files,
        seconds,
        batches: joined,
    })
}

fn loaded_name(paths: &[PathBuf], n: usize) -> String {
    paths[n].display().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_tile_every_batch() {
        for trials in [0usize, 1, 5, 7, 400, 1_000_000] {
            for count in [1usize, 2, 3, 4, 8, 9, 100] {
                let mut next = 0;
                for index in 0..count {
                    let r = Shard { index, count }.range(trials);
                    assert_eq!(r.start, next);
                    assert!(r.len() <= trials / count + 1);
                    next = r.end;
                }
                assert_eq!(next, trials);
            }
        }
    }

    #[test]
    fn parses_and_rejects() {
        assert_eq!(Shard::parse("2/8").unwrap(), Shard { index: 2, count: 8 });
        for (s, msg) in [
            (
                "8/8",
                "--shard 8/8: shard 8 of 8 does not exist (shards are 0..7)",
            ),
            (
                "1/0",
                "--shard 1/0: the shard count must lie in 1..=100000, got 0",
            ),
            ("a/4", "--shard a/4: 'a' is not a whole number"),
            ("3", "--shard 3: not I/N (for example 0/4) or off"),
        ] {
            assert_eq!(Shard::parse(s).unwrap_err().to_string(), msg);
        }
        assert_eq!(
            ShardArg {
                shard: Some("off".into())
            }
            .resolve()
            .unwrap(),
            None
        );
    }

    #[test]
    fn scheduler_environments() {
        let env = |pairs: &'static [(&'static str, &'static str)]| {
            move |k: &str| {
                pairs
                    .iter()
                    .find(|(n, _)| *n == k)
                    .map(|(_, v)| v.to_string())
            }
        };
        assert_eq!(Shard::from_env(env(&[])).unwrap(), None);
        let s = Shard::from_env(env(&[
            ("SLURM_ARRAY_TASK_ID", "3"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
            ("SLURM_ARRAY_TASK_MIN", "0"),
        ]));
        assert_eq!(s.unwrap(), Some(Shard { index: 3, count: 4 }));
        // --array=1-4: the index is counted from the array's first id.
        let s = Shard::from_env(env(&[
            ("SLURM_ARRAY_TASK_ID", "4"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
        ]));
        assert_eq!(s.unwrap(), Some(Shard { index: 3, count: 4 }));
        let e = Shard::from_env(env(&[("SLURM_ARRAY_TASK_ID", "4")])).unwrap_err();
        assert!(
            e.to_string().contains("SLURM_ARRAY_TASK_COUNT is not"),
            "{e}"
        );
        let e = Shard::from_env(env(&[
            ("SLURM_ARRAY_TASK_ID", "4"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ]))
        .unwrap_err();
        assert!(e.to_string().contains("does not exist"), "{e}");
        let s = Shard::from_env(env(&[
            ("JOB_COMPLETION_INDEX", "1"),
            ("FAINT_SHARD_COUNT", "8"),
        ]));
        assert_eq!(s.unwrap(), Some(Shard { index: 1, count: 8 }));
        let e = Shard::from_env(env(&[("JOB_COMPLETION_INDEX", "1")])).unwrap_err();
        assert!(e.to_string().contains("FAINT_SHARD_COUNT is not"), "{e}");
    }

    fn temp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("faint-shard-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    /// Floats come back bit for bit, NaN payloads, signed zeros and infinities included.
    #[test]
    fn files_round_trip_and_join_in_trial_order() {
        let dir = temp("join");
        let run = Run::new("test", &serde_json::json!({"trials": 7})).unwrap();
        let value = |t: usize| -> f64 {
            match t {
                0 => f64::from_bits(0x7ff8_0000_dead_beef),
                1 => -0.0,
                2 => f64::NEG_INFINITY,
                t => (t as f64).sqrt() * 1e-300,
            }
        };
        for index in [2usize, 0, 1] {
            let shard = Shard { index, count: 3 };
            let b = Batch::run("a", 7, Some(shard), |r| {
                Ok::<_, ()>(r.map(value).collect::<Vec<f64>>())
            })
            .unwrap();
            write(&dir, &run, shard, 1.0, &[b]).unwrap();
        }
        let m = read(std::slice::from_ref(&dir)).unwrap();
        assert_eq!(m.count, 3);
        assert_eq!(m.seconds, 3.0);
        let r: Vec<Vec<f64>> = m.results(&["a".to_string()]).unwrap();
        let bits: Vec<u64> = r[0].iter().map(|x| x.to_bits()).collect();
        let want: Vec<u64> = (0..7).map(|t| value(t).to_bits()).collect();
        assert_eq!(bits, want);
        assert!(m.results::<f64>(&["b".to_string()]).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Batches of different record types share one shard file ([`Batch::into_values`]);
    /// merged, each decodes into its own type, bit for bit and in trial order, and a
    /// one-trial batch lands in exactly one shard (the last).
    #[test]
    fn batches_of_different_record_types_join() {
        let dir = temp("mixed");
        let run = Run::new("test", &serde_json::json!({"trials": 5})).unwrap();
        let rows = |r: Range<usize>| -> Vec<Vec<f32>> {
            r.map(|t| vec![t as f32 / 3.0, f32::NEG_INFINITY]).collect()
        };
        for index in 0..3 {
            let shard = Shard { index, count: 3 };
            let a = Batch::run("a", 5, Some(shard), |r| Ok::<_, ()>(rows(r))).unwrap();
            let b = Batch::run("once", 1, Some(shard), |r| {
                Ok::<_, ()>(r.map(|_| "timed".to_string()).collect::<Vec<_>>())
            })
            .unwrap();
            assert_eq!(b.results.len(), usize::from(index == 2));
            let batches = [a.into_values().unwrap(), b.into_values().unwrap()];
            write(&dir, &run, shard, 1.0, &batches).unwrap();
        }
        let keys = ["a".to_string(), "once".to_string()];
        let m = read(std::slice::from_ref(&dir)).unwrap();
        let b = m.batches(&keys).unwrap();
        let a: Vec<Vec<f32>> = b.get("a").unwrap();
        let bits =
            |v: &[Vec<f32>]| -> Vec<u32> { v.iter().flatten().map(|x| x.to_bits()).collect() };
        assert_eq!(bits(&a), bits(&rows(0..5)));
        assert_eq!(b.get::<String>("once").unwrap(), vec!["timed".to_string()]);
        assert!(b.get::<String>("a").is_err());
        assert!(m.batches(&keys[..1]).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The FNV-1a reference values (Fowler, Noll, Vo; the `""` and `"a"` test vectors).
    #[test]
    fn fnv1a64_matches_the_reference_vectors() {
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x8594_4171_f739_67e8);
    }

    /// A shard of the same version but written by another binary is refused, by name;
    /// one written by this binary (the test executable) is read.
    #[test]
    fn another_binarys_shards_are_refused() {
        let ours = build_id().expect("a test binary can read itself");
        let dir = temp("build");
        let run = Run::new("test", &serde_json::json!({"trials": 4, "seed": 1})).unwrap();
        let put = |index: usize, build: &str| {
            let shard = Shard { index, count: 2 };
            let b =
                Batch::run("a", 4, Some(shard), |r| Ok::<_, ()>(r.collect::<Vec<_>>())).unwrap();
            let file = FileRef {
                header: Header {
                    magic: MAGIC.into(),
                    format: FORMAT,
                    version: VERSION.into(),
                    build: Some(build.into()),
                    run: run.clone(),
                    shard,
                    seconds: 1.0,
                },
                batches: &[b],
            };
            let mut buf = Vec::new();
            ciborium::into_writer(&file, &mut buf).unwrap();
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(dir.join(shard.file_name()), buf).unwrap();
        };
        put(0, ours);
        put(1, ours);
        assert!(read(std::slice::from_ref(&dir)).is_ok());
        put(1, "0123456789abcdef");
        let e = read(std::slice::from_ref(&dir)).unwrap_err().to_string();
        assert!(
            e.contains("written by another build of faint") && e.contains("0123456789abcdef"),
            "{e}"
        );
        assert!(!e.contains('\n'));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn missing_duplicated_and_foreign_shards_are_named() {
        let dir = temp("bad");
        let run = Run::new("test", &serde_json::json!({"trials": 4, "seed": 1})).unwrap();
        let put = |dir: &Path, run: &Run, index: usize, count: usize| {
            let shard = Shard { index, count };
            let b =
                Batch::run("a", 4, Some(shard), |r| Ok::<_, ()>(r.collect::<Vec<_>>())).unwrap();
            write(dir, run, shard, 1.0, &[b]).unwrap()
        };
        put(&dir, &run, 0, 2);
        let e = read(std::slice::from_ref(&dir)).unwrap_err().to_string();
        assert!(e.starts_with("shard 1/2 is missing from"), "{e}");
        assert!(
            e.ends_with("(1 of the 2 shards of `faint test` found)"),
            "{e}"
        );
        assert!(!e.contains('\n'));
        let other = temp("bad-copy");
        let p1 = put(&other, &run, 1, 2);
        let copy = dir.join("copy.faint-shard");
        std::fs::copy(put(&temp("bad-dup"), &run, 0, 2), &copy).unwrap();
        let e = read(&[dir.clone(), p1.clone()]).unwrap_err().to_string();
        assert!(e.contains("shard 0/2 is given twice"), "{e}");
        std::fs::remove_file(&copy).unwrap();
        assert!(read(&[dir.clone(), p1.clone()]).is_ok());
        let foreign = Run::new("test", &serde_json::json!({"trials": 4, "seed": 2})).unwrap();
        let f = put(&temp("bad-foreign"), &foreign, 1, 2);
        let e = read(&[dir.clone(), f]).unwrap_err().to_string();
        assert!(
            e.contains("a shard of another run (--seed 2 here, 1 in"),
            "{e}"
        );
        let f = put(&temp("bad-count"), &run, 1, 3);
        let e = read(&[dir.clone(), f]).unwrap_err().to_string();
        assert!(e.contains("shard 1/3, but"), "{e}");
        let junk = temp("bad-junk");
        std::fs::create_dir_all(&junk).unwrap();
        std::fs::write(junk.join("x.faint-shard"), b"hello").unwrap();
        let e = read(std::slice::from_ref(&junk)).unwrap_err().to_string();
        assert!(e.ends_with("x.faint-shard: not a faint shard file"), "{e}");
        for d in [
            "bad",
            "bad-copy",
            "bad-dup",
            "bad-foreign",
            "bad-count",
            "bad-junk",
        ] {
            let _ = std::fs::remove_dir_all(temp(d));
        }
    }
}
