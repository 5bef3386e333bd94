//! Output of frames and plot lists in exactly the formats [`super::input`] reads:
//! little-endian C-order `.npy` arrays (written with `npyz`) and `scan,amplitude,x,y` CSV.
//!
//! The writers refuse what the readers refuse (no frames, ragged frames, NaN/inf), so a
//! written file always reads back, bit for bit. The content is `.npy` whatever the
//! extension; the readers tell the format by the content. Missing parent folders are
//! created; every error is one line naming the file.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use anyhow::{anyhow, bail, Result};
use faint_core::model::plot::Plot;
use faint_core::Complex32;
use npyz::{DType, TypeStr, WriteOptions, WriterBuilder};

/// Writes `frames` as a `(K, m)` complex64 `.npy` array, C order. Every frame must have
/// the same length `m >= 1`, `K >= 1`, and every sample must be finite.
pub fn write_complex_frames(path: &Path, frames: &[Vec<Complex32>]) -> Result<()> {
    let p = path.display();
    let m = frames.first().map_or(0, Vec::len);
    if frames.is_empty() || m == 0 {
        bail!(
            "{p}: nothing to write: {} frames of length {m}",
            frames.len()
        );
    }
    for (k, f) in frames.iter().enumerate() {
        if f.len() != m {
            bail!("{p}: frame {k} has {} samples, frame 0 has {m}", f.len());
        }
        if let Some(i) = f
            .iter()
            .position(|z| !(z.re.is_finite() && z.im.is_finite()))
        {
            bail!(
                "{p}: frame {k}, index {i} is not finite ({}); not written",
                f[i]
            );
        }
    }
    write_npy(path, "<c8", &[frames.len(), m], frames.iter().flatten())
}

/// Writes `data` as a float32 `.npy` array of `shape` (C order, `K = shape[0]` first).
/// `shape` needs at least one axis, no zero axis, and `data.len()` equal to its product;
/// every value must be finite.
pub fn write_real_frames(path: &Path, shape: &[usize], data: &[f32]) -> Result<()> {
    let p = path.display();
    let n: usize = shape.iter().product();
    if shape.is_empty() || n == 0 {
        bail!("{p}: nothing to write: shape {shape:?}");
    }
    if n != data.len() {
        bail!(
            "{p}: shape {shape:?} holds {n} values, {} given",
            data.len()
        );
    }
    if let Some(i) = data.iter().position(|v| !v.is_finite()) {
        let len = n / shape[0];
        bail!(
            "{p}: frame {}, index {} is not finite ({}); not written",
            i / len,
            i % len,
            data[i]
        );
    }
    write_npy(path, "<f4", shape, data.iter())
}

/// Writes `scans` as CSV `scan,amplitude,x,y`, scans numbered from 0. An empty scan is
/// written as the row `k,,,` so the number of scans reads back. Values are printed in the
/// shortest form that parses back to the same `f32`.
pub fn write_plots(path: &Path, scans: &[Vec<Plot>]) -> Result<()> {
    let p = path.display();
    if scans.is_empty() {
        bail!("{p}: nothing to write: no scans");
    }
    for (k, s) in scans.iter().enumerate() {
        if let Some(j) = s.iter().position(|pl| !pl.is_finite()) {
            bail!(
                "{p}: scan {k}, plot {j} is not finite ({:?}); not written",
                s[j]
            );
        }
    }
    let mut w = create(path)?;
    let mut text = String::from("scan,amplitude,x,y\n");
    for (k, s) in scans.iter().enumerate() {
        if s.is_empty() {
            text.push_str(&format!("{k},,,\n"));
        }
        for pl in s {
            text.push_str(&format!("{k},{},{},{}\n", pl.amplitude, pl.x, pl.y));
        }
    }
    w.write_all(text.as_bytes())
        .and_then(|()| w.flush())
        .map_err(|e| anyhow!("{p}: cannot write: {e}"))
}

fn create(path: &Path) -> Result<BufWriter<File>> {
    super::ensure_parent(path).map_err(|e| anyhow!("{}: cannot write: {e:#}", path.display()))?;
    File::create(path)
        .map(BufWriter::new)
        .map_err(|e| anyhow!("{}: cannot create: {e}", path.display()))
}

fn write_npy<'a, T>(
    path: &Path,
    dtype: &str,
    shape: &[usize],
    items: impl Iterator<Item = &'a T>,
) -> Result<()>
where
    T: npyz::Serialize + 'a,
{
    let p = path.display();
    let ty: TypeStr = dtype
        .parse()
        .map_err(|e| anyhow!("{p}: bad dtype {dtype}: {e}"))?;
    let shape: Vec<u64> = shape.iter().map(|&n| n as u64).collect();
    let mut file = create(path)?;
    let mut w = WriteOptions::new()
        .dtype(DType::Plain(ty))
        .shape(&shape)
        .writer(&mut file)
        .begin_nd()
        .map_err(|e| anyhow!("{p}: cannot write: {e}"))?;
    for x in items {
        w.push(x).map_err(|e| anyhow!("{p}: cannot write: {e}"))?;
    }
    w.finish().map_err(|e| anyhow!("{p}: cannot write: {e}"))?;
    file.flush().map_err(|e| anyhow!("{p}: cannot write: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::input::{read_complex_frames, read_plots, read_real_frames};
    use faint_core::rng::Rng;

    fn tmp(name: &str) -> std::path::PathBuf {
        std::env::temp_dir()
            .join(format!("faint-output-{}", std::process::id()))
            .join(name)
    }

    fn bits(v: &[f32]) -> Vec<u32> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    #[test]
    fn complex_frames_round_trip_bit_for_bit() {
        let mut rng = Rng::seed_from_u64(3);
        let frames: Vec<Vec<Complex32>> = (0..4)
            .map(|_| {
                (0..7)
                    .map(|_| Complex32::new(rng.normal() * 1e3, rng.normal() * 1e-30))
                    .collect()
            })
            .collect();
        let mut frames = frames;
        frames[0][0] = Complex32::new(-0.0, f32::MIN_POSITIVE / 4.0);
        frames[0][1] = Complex32::new(f32::MAX, f32::MIN);
        let path = tmp("sub/complex.npy");
        write_complex_frames(&path, &frames).unwrap();
        let f = read_complex_frames(&path).unwrap();
        assert_eq!(f.shape, [4, 7]);
        let flat: Vec<Complex32> = frames.iter().flatten().copied().collect();
        let re = |v: &[Complex32]| bits(&v.iter().flat_map(|z| [z.re, z.im]).collect::<Vec<_>>());
        assert_eq!(re(&f.data), re(&flat));
    }

    #[test]
    fn real_frames_round_trip_bit_for_bit() {
        let mut rng = Rng::seed_from_u64(5);
        let shape = [3, 2, 4, 5];
        let mut data: Vec<f32> = (0..120).map(|_| rng.normal()).collect();
        data[7] = -0.0;
        data[8] = 1e-45;
        let path = tmp("cube.npy");
        write_real_frames(&path, &shape, &data).unwrap();
        let f = read_real_frames(&path, 4).unwrap();
        assert_eq!(f.shape, shape);
        assert_eq!(bits(&f.data), bits(&data));
    }

    #[test]
    fn plots_round_trip_bit_for_bit() {
        let mut rng = Rng::seed_from_u64(7);
        let mut scans: Vec<Vec<Plot>> = (0..5)
            .map(|k| {
                (0..k % 3)
                    .map(|_| Plot::new(rng.uniform(), rng.normal() * 1e4, rng.normal() * 1e-3))
                    .collect()
            })
            .collect();
        scans[1].push(Plot::new(-0.0, 1e-45, f32::MAX));
        scans.push(vec![]);
        let path = tmp("plots.csv");
        write_plots(&path, &scans).unwrap();
        let back = read_plots(&path).unwrap();
        assert_eq!(back.len(), scans.len());
        for (a, b) in back.iter().zip(&scans) {
            let flat = |s: &[Plot]| bits(&s.iter().flat_map(|p| p.to_array()).collect::<Vec<_>>());
            assert_eq!(flat(a), flat(b));
        }
    }

    #[test]
    fn refusals_and_unwritable_paths_name_the_file() {
        let one = |r: Result<()>, word: &str, name: &str| {
            let e = format!("{:#}", r.unwrap_err());
            assert!(
                !e.contains('\n') && e.contains(word) && e.contains(name),
                "{e}"
            );
        };
        let blocker = tmp("blocker");
        fs_write(&blocker);
        let under = blocker.join("x.npy");
        one(
            write_complex_frames(&under, &[vec![Complex32::new(1.0, 0.0)]]),
            "cannot",
            "blocker/x.npy",
        );
        one(
            write_real_frames(&under, &[1, 1], &[1.0]),
            "cannot",
            "x.npy",
        );
        one(write_plots(&under, &[vec![]]), "cannot", "x.npy");
        let p = tmp("r.npy");
        one(write_complex_frames(&p, &[]), "nothing to write", "r.npy");
        one(
            write_complex_frames(&p, &[vec![Complex32::new(0.0, 0.0)], vec![]]),
            "frame 1 has 0 samples",
            "r.npy",
        );
        one(
            write_complex_frames(&p, &[vec![Complex32::new(f32::NAN, 0.0)]]),
            "not finite",
            "r.npy",
        );
        one(
            write_real_frames(&p, &[2, 2], &[1.0; 3]),
            "holds 4 values",
            "r.npy",
        );
        one(
            write_real_frames(&p, &[0, 2], &[]),
            "nothing to write",
            "r.npy",
        );
        one(write_plots(&p, &[]), "no scans", "r.npy");
        one(
            write_plots(&p, &[vec![Plot::new(f32::INFINITY, 0.0, 0.0)]]),
            "not finite",
            "r.npy",
        );
    }

    fn fs_write(path: &Path) {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, b"a file, not a folder").unwrap();
    }
}
