//! Checks and parsers of command-line values, shared by every command. Each error is
//! one line naming the argument and the value.

use std::fs;
use std::ops::RangeInclusive;
use std::path::Path;

use anyhow::{bail, ensure, Context, Result};

/// Most points a grid `a:b:step` may have.
pub const MAX_GRID_POINTS: usize = 1000;

/// Most Monte Carlo runs (trials, runs, periods) a count argument may ask for.
pub const MAX_RUNS: usize = 1_000_000;

/// SNR values in dB every command accepts.
pub const SNR_DB: RangeInclusive<f64> = -60.0..=60.0;

/// Parses a number of argument `name`: finite, else an error naming both.
pub fn number(name: &str, s: &str) -> Result<f64> {
    let x: f64 = match s.trim().parse() {
        Ok(x) => x,
        Err(_) => bail!("{name}: '{}' is not a number", s.trim()),
    };
    finite(name, x)
}

/// `x` as a short text: plain, or with an exponent when very large or small.
fn show(x: f64) -> String {
    let a = x.abs();
    if a != 0.0 && a.is_finite() && !(1e-4..1e15).contains(&a) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// `x` if finite, else an error naming `name` and the value.
pub fn finite(name: &str, x: f64) -> Result<f64> {
    ensure!(x.is_finite(), "{name}: '{x}' is not a finite number");
    Ok(x)
}

/// `x` if finite and within `range` (`unit` follows the range in the message).
pub fn within(name: &str, x: f64, range: RangeInclusive<f64>, unit: &str) -> Result<f64> {
    finite(name, x)?;
    ensure!(
        range.contains(&x),
        "{name} must lie in [{}, {}]{unit}, got {}",
        range.start(),
        range.end(),
        show(x)
    );
    Ok(x)
}

/// An SNR in dB: finite and within [`SNR_DB`].
pub fn snr_db(name: &str, x: f64) -> Result<f64> {
    within(name, x, SNR_DB, " dB")
}

/// A probability strictly inside `(0, 1)`.
pub fn probability(name: &str, p: f64) -> Result<f64> {
    ensure!(
        p > 0.0 && p < 1.0,
        "{name} must lie in (0, 1), got {}",
        show(p)
    );
    Ok(p)
}

/// A count within `range` (zero is an error unless `range` starts at 0).
pub fn count(name: &str, n: usize, range: RangeInclusive<usize>) -> Result<usize> {
    ensure!(
        range.contains(&n),
        "{name} must lie in {}..={}, got {n}",
        range.start(),
        range.end()
    );
    Ok(n)
}

/// A Monte Carlo count: `1..=`[`MAX_RUNS`].
pub fn runs(name: &str, n: usize) -> Result<usize> {
    count(name, n, 1..=MAX_RUNS)
}

/// Parses the grid `a:b:step` of argument `name` into `a, a + step, ..., <= b`: finite
/// numbers, `step > 0`, `a <= b`, at most [`MAX_GRID_POINTS`] points.
pub fn grid(name: &str, s: &str) -> Result<Vec<f64>> {
    let parts: Vec<&str> = s.split(':').collect();
    ensure!(parts.len() == 3, "{name}: '{s}' is not a grid a:b:step");
    let mut p = [0.0; 3];
    for (x, part) in p.iter_mut().zip(&parts) {
        *x = number(name, part)?;
    }
    let [a, b, step] = p;
    ensure!(step > 0.0, "{name}: '{s}' needs step > 0");
    ensure!(a <= b, "{name}: '{s}' needs a <= b");
    let n = ((b - a) / step + 1e-9).floor() + 1.0;
    ensure!(
        n <= MAX_GRID_POINTS as f64,
        "{name}: '{s}' has {n} points, at most {MAX_GRID_POINTS}"
    );
    Ok((0..n as usize).map(|i| a + i as f64 * step).collect())
}

/// Creates the output folder `dir` and checks that it can be written, naming it otherwise.
pub fn out_dir(dir: &Path) -> Result<()> {
    fs::create_dir_all(dir)
        .with_context(|| format!("--out {}: cannot create the folder", dir.display()))?;
    let probe = dir.join(".faint-write-test");
    fs::write(&probe, b"")
        .with_context(|| format!("--out {}: the folder is not writable", dir.display()))?;
    fs::remove_file(&probe).ok();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids() {
        assert_eq!(grid("--g", "0:4:2").unwrap(), vec![0.0, 2.0, 4.0]);
        assert_eq!(grid("--g", "-2:-2:1").unwrap(), vec![-2.0]);
        for (s, msg) in [
            ("0:4", "--g: '0:4' is not a grid a:b:step"),
            ("0:4:0", "--g: '0:4:0' needs step > 0"),
            ("4:0:1", "--g: '4:0:1' needs a <= b"),
            ("a:1:1", "--g: 'a' is not a number"),
            ("0:1:inf", "--g: 'inf' is not a finite number"),
            (
                "0:1e9:1",
                "--g: '0:1e9:1' has 1000000001 points, at most 1000",
            ),
        ] {
            assert_eq!(grid("--g", s).unwrap_err().to_string(), msg);
        }
    }

    #[test]
    fn counts_and_probabilities() {
        assert!(runs("--runs", 0).is_err());
        assert_eq!(runs("--runs", 1).unwrap(), 1);
        assert!(runs("--runs", MAX_RUNS + 1).is_err());
        assert!(probability("--pfa", 1.0).is_err());
        assert!(probability("--pfa", f64::NAN).is_err());
        assert_eq!(
            snr_db("--snr-db", 1e300).unwrap_err().to_string(),
            "--snr-db must lie in [-60, 60] dB, got 1e300"
        );
        assert!(snr_db("--snr-db", f64::NAN).is_err());
    }
}
