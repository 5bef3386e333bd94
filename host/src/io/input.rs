//! Input: frames and plot lists recorded by users, from NumPy `.npy`/`.npz` files (read
//! with `npyz`) and CSV plot lists (read with `csv`).
//!
//! Every reader returns its data in C order (last axis fastest) whatever the file's
//! order, and fails with one line naming the file and the problem: missing or unreadable
//! file, not a NumPy file or truncated, wrong dtype, wrong rank, empty array, NaN/inf
//! sample, malformed CSV row. Detector-specific checks (a frame length that must equal a
//! configuration's bins, say) are the caller's.
//!
//! The file's format is told by its first bytes, not its extension: `\x93NUMPY` is a
//! `.npy` array, `PK` a `.npz` archive. From an archive the array named `frames` is read,
//! or else its only array.

use std::fs;
use std::io::Cursor;
use std::path::Path;

use anyhow::{anyhow, bail, Result};
use faint_core::model::plot::Plot;
use faint_core::Complex32;
use npyz::{DType, NpyFile, TypeChar};
use num_complex::Complex64;

/// A stack of frames read from a file: `frames() x frame_len()` values, row-major (C
/// order) whatever the file's order. `shape[0]` is the number of frames `K`, the other
/// axes are one frame's: `[K, m]` complex bins, `[K, R, D, A]` cubes, `[K, M, M]` images.
#[derive(Debug, Clone, PartialEq)]
pub struct Frames<T> {
    /// The samples, frame after frame, each frame in C order.
    pub data: Vec<T>,
    /// The shape, `K` first.
    pub shape: Vec<usize>,
}

impl<T> Frames<T> {
    /// Number of frames `K = shape[0]`.
    pub fn frames(&self) -> usize {
        self.shape.first().copied().unwrap_or(0)
    }

    /// Values in one frame: the product of `shape[1..]`.
    pub fn frame_len(&self) -> usize {
        self.shape.iter().skip(1).product()
    }

    /// Frame `k` as a slice of `frame_len()` values. Panics if `k >= frames()`.
    pub fn frame(&self, k: usize) -> &[T] {
        let n = self.frame_len();
        &self.data[k * n..(k + 1) * n]
    }
}

/// Reads complex frames: a `(K, m)` complex64 array, or a `(K, m, 2)` float32 array of
/// I/Q pairs (`[.., 0]` in-phase, `[.., 1]` quadrature). complex128 and float64 are
/// accepted and narrowed to `f32` (round to nearest). Returns shape `[K, m]`.
pub fn read_complex_frames(path: &Path) -> Result<Frames<Complex32>> {
    const WANTED: &str = "(K, m) complex64 or (K, m, 2) float32";
    let arr = read_array(path)?;
    let fail = |msg: String| anyhow!("{}: {msg}", path.display());
    let wrong_rank = || {
        fail(format!(
            "expected {WANTED}, found {} shape {}",
            arr.dtype,
            fmt_shape(&arr.shape)
        ))
    };
    let iq = matches!(arr.data, Data::F32(_) | Data::F64(_));
    let shape = match arr.data {
        Data::C64(_) | Data::C128(_) if arr.shape.len() == 2 => arr.shape.clone(),
        Data::F32(_) | Data::F64(_) if arr.shape.len() == 3 && arr.shape[2] == 2 => {
            arr.shape[..2].to_vec()
        }
        Data::Other => {
            return Err(fail(format!(
                "dtype {} is not accepted; expected {WANTED} \
                 (complex128 and float64 are narrowed)",
                arr.dtype
            )))
        }
        _ => return Err(wrong_rank()),
    };
    check_not_empty(path, &arr.shape)?;
    let narrowed = arr.narrowed();
    let data: Vec<Complex32> = match arr.data {
        Data::C64(v) => v,
        Data::C128(v) => v
            .iter()
            .map(|z| Complex32::new(z.re as f32, z.im as f32))
            .collect(),
        data => data
            .into_f32()
            .chunks_exact(2)
            .map(|iq| Complex32::new(iq[0], iq[1]))
            .collect(),
    };
    let frames = Frames { data, shape };
    let m = frames.frame_len();
    for (n, z) in frames.data.iter().enumerate() {
        for (part, v) in [("I", z.re), ("Q", z.im)] {
            if !v.is_finite() {
                let (k, i) = (n / m, n % m);
                let what = non_finite_name(v, narrowed);
                return Err(fail(if iq {
                    format!("frame {k}, bin {i} ({part}) is {what}")
                } else {
                    let part = if part == "I" { "real" } else { "imaginary" };
                    format!("frame {k}, index {i} is {what} ({part} part)")
                }));
            }
        }
    }
    Ok(frames)
}

/// Reads real frames: a float32 array (float64 accepted and narrowed) of exactly `rank`
/// axes, `K` first: rank 2 for `(K, m)` power frames, 3 for `(K, M, M)` images, 4 for
/// `(K, R, D, A)` cubes.
pub fn read_real_frames(path: &Path, rank: usize) -> Result<Frames<f32>> {
    if rank == 0 {
        bail!(
            "{}: rank 0 requested; frames need rank >= 1 (K first)",
            path.display()
        );
    }
    let wanted = {
        let axes: Vec<String> = std::iter::once("K".to_string())
            .chain((1..rank).map(|i| format!("n{i}")))
            .collect();
        fmt_axes(&axes)
    };
    let arr = read_array(path)?;
    let fail = |msg: String| anyhow!("{}: {msg}", path.display());
    if !matches!(arr.data, Data::F32(_) | Data::F64(_)) {
        return Err(fail(format!(
            "dtype {} is not accepted; expected float32 {wanted} (float64 is narrowed)",
            arr.dtype
        )));
    }
    if arr.shape.len() != rank {
        return Err(fail(format!(
            "expected float32 {wanted}, found {} shape {}",
            arr.dtype,
            fmt_shape(&arr.shape)
        )));
    }
    check_not_empty(path, &arr.shape)?;
    let narrowed = arr.narrowed();
    let frames = Frames {
        data: arr.data.into_f32(),
        shape: arr.shape,
    };
    let len = frames.frame_len();
    if let Some(n) = frames.data.iter().position(|v| !v.is_finite()) {
        let (k, i) = (n / len, n % len);
        let what = non_finite_name(frames.data[n], narrowed);
        let at = if rank > 2 {
            format!(" {}", fmt_index(i, &frames.shape[1..]))
        } else {
            String::new()
        };
        return Err(fail(format!("frame {k}, index {i}{at} is {what}")));
    }
    Ok(frames)
}

/// Reads a CSV plot list with the header `scan,amplitude,x,y`, one plot a row.
///
/// Scans are numbered from 0; scan numbers must be non-decreasing integers below
/// 10,000,000. The result has `last scan + 1` scans; a scan with no rows is an empty
/// list. A row `k,,,` (scan number, the three other fields empty) declares scan `k` with
/// no plots, so trailing empty scans can be recorded. Fields may be padded by spaces.
pub fn read_plots(path: &Path) -> Result<Vec<Vec<Plot>>> {
    const HEADER: [&str; 4] = ["scan", "amplitude", "x", "y"];
    const MAX_SCANS: u64 = 10_000_000;
    let p = path.display();
    let bytes = read_bytes(path)?;
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(&bytes[..]);
    let header = rdr
        .headers()
        .map_err(|e| anyhow!("{p}: cannot read the CSV header: {e}"))?
        .clone();
    if header.is_empty() {
        bail!(
            "{p}: empty file, expected the header `{}`",
            HEADER.join(",")
        );
    }
    if header.iter().collect::<Vec<_>>() != HEADER {
        let found: Vec<&str> = header.iter().collect();
        bail!(
            "{p}: wrong CSV header `{}`, expected `{}`",
            found.join(","),
            HEADER.join(",")
        );
    }
    let mut scans: Vec<Vec<Plot>> = Vec::new();
    for (row, rec) in rdr.records().enumerate() {
        let row = row + 1;
        let rec = rec.map_err(|e| anyhow!("{p}: row {row}: cannot read CSV: {e}"))?;
        let line = rec.position().map_or(row as u64 + 1, |pos| pos.line());
        let at = format!("{p}: row {row} (line {line})");
        if rec.len() != HEADER.len() {
            bail!(
                "{at}: {} columns, expected {} ({})",
                rec.len(),
                HEADER.len(),
                HEADER.join(",")
            );
        }
        let scan: u64 = rec[0].parse().map_err(|_| {
            anyhow!(
                "{at}: non-numeric scan `{}` (scans are integers from 0)",
                &rec[0]
            )
        })?;
        if scan >= MAX_SCANS {
            bail!("{at}: scan {scan} is too large (limit {MAX_SCANS})");
        }
        let scan = scan as usize;
        if scan + 1 < scans.len() {
            bail!(
                "{at}: decreasing scan number {scan} after {} (scan numbers must not decrease)",
                scans.len() - 1
            );
        }
        if scans.len() <= scan {
            scans.resize_with(scan + 1, Vec::new);
        }
        if rec.iter().skip(1).all(str::is_empty) {
            continue;
        }
        let mut v = [0.0f32; 3];
        for (j, slot) in v.iter_mut().enumerate() {
            let (name, text) = (HEADER[j + 1], &rec[j + 1]);
            let x: f32 = text
                .parse()
                .map_err(|_| anyhow!("{at}: non-numeric {name} `{text}`"))?;
            if !x.is_finite() {
                bail!("{at}: {name} is {}", non_finite_name(x, false));
            }
            *slot = x;
        }
        scans[scan].push(Plot::from_array(v));
    }
    if scans.is_empty() {
        bail!("{p}: no plots and no scans: the file is empty below its header");
    }
    Ok(scans)
}

/// The samples of an array, by dtype, in the file's storage order until [`read_array`]
/// puts them in C order.
enum Data {
    F32(Vec<f32>),
    F64(Vec<f64>),
    C64(Vec<Complex32>),
    C128(Vec<Complex64>),
    Other,
}

impl Data {
    fn into_f32(self) -> Vec<f32> {
        match self {
            Data::F32(v) => v,
            Data::F64(v) => v.into_iter().map(|x| x as f32).collect(),
            _ => Vec::new(),
        }
    }
}

/// One array in C order, with its numpy dtype name (`complex64`, `int32`, ...).
struct Array {
    data: Data,
    shape: Vec<usize>,
    dtype: String,
}

impl Array {
    /// True when the samples are 64-bit floats that reading narrows to 32 bits.
    fn narrowed(&self) -> bool {
        matches!(self.data, Data::F64(_) | Data::C128(_))
    }
}

fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    fs::read(path).map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            anyhow!("{}: file not found", path.display())
        } else {
            anyhow!("{}: cannot read: {e}", path.display())
        }
    })
}

fn read_array(path: &Path) -> Result<Array> {
    let p = path.display();
    let bytes = read_bytes(path)?;
    if bytes.starts_with(b"\x93NUMPY") {
        let npy = NpyFile::new(&bytes[..])
            .map_err(|e| anyhow!("{p}: not a valid .npy file (bad or truncated header): {e}"))?;
        decode(path, npy)
    } else if bytes.starts_with(b"PK") {
        let mut npz = zip::ZipArchive::new(Cursor::new(&bytes[..]))
            .map_err(|e| anyhow!("{p}: not a valid .npz archive: {e}"))?;
        let mut names: Vec<String> = npz
            .file_names()
            .filter_map(|n| Some(n.ok()?.strip_suffix(".npy")?.to_string()))
            .collect();
        names.sort();
        let name = if names.iter().any(|n| n == "frames") {
            "frames".to_string()
        } else if names.len() == 1 {
            names[0].clone()
        } else if names.is_empty() {
            bail!("{p}: the .npz archive holds no arrays");
        } else {
            bail!(
                "{p}: the .npz archive holds arrays {}; expected one named `frames` or a \
                 single array",
                names.join(", ")
            );
        };
        let mut entry = npz
            .by_name(&format!("{name}.npy"))
            .map_err(|e| anyhow!("{p}: array `{name}` cannot be read from the archive: {e}"))?;
        let mut inner = Vec::new();
        std::io::Read::read_to_end(&mut entry, &mut inner)
            .map_err(|e| anyhow!("{p}: array `{name}` cannot be decompressed: {e}"))?;
        let npy = NpyFile::new(&inner[..])
            .map_err(|e| anyhow!("{p}: array `{name}` is not a valid .npy entry: {e}"))?;
        decode(path, npy).map_err(|e| anyhow!("{e} (array `{name}`)"))
    } else {
        bail!("{p}: not a NumPy .npy or .npz file (no \\x93NUMPY or PK signature)");
    }
}

fn decode(path: &Path, npy: NpyFile<&[u8]>) -> Result<Array> {
    let p = path.display();
    let dtype = npy.dtype();
    let dtype_name = dtype_name(&dtype);
    let shape = npy
        .shape()
        .iter()
        .map(|&n| usize::try_from(n))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|_| anyhow!("{p}: shape {:?} is too large", npy.shape()))?;
    let strides: Vec<usize> = npy.strides().iter().map(|&s| s as usize).collect();
    let c_order = npy.order() == npyz::Order::C || shape.len() < 2;
    let count = npy.len();
    let truncated = |e: std::io::Error| {
        anyhow!(
            "{p}: truncated: shape {} needs {count} {dtype_name} samples, the file ends \
             before ({e})",
            fmt_shape(&shape)
        )
    };
    let size = match &dtype {
        DType::Plain(t) => Some((t.type_char(), t.size_field())),
        _ => None,
    };
    // Little-endian float32 / complex64 (what NumPy writes on every common machine):
    // decoded straight from the bytes, about 10x faster than element by element.
    let little = dtype.descr().starts_with('<');
    let data = match size {
        Some((TypeChar::Float, 4)) if little => Data::F32(
            read_le(npy, count, 4, |b| {
                f32::from_le_bytes([b[0], b[1], b[2], b[3]])
            })
            .map_err(truncated)?,
        ),
        Some((TypeChar::Complex, 8)) if little => Data::C64(
            read_le(npy, count, 8, |b| {
                Complex32::new(
                    f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                    f32::from_le_bytes([b[4], b[5], b[6], b[7]]),
                )
            })
            .map_err(truncated)?,
        ),
        Some((TypeChar::Float, 4)) => Data::F32(npy.into_vec().map_err(truncated)?),
        Some((TypeChar::Float, 8)) => Data::F64(npy.into_vec().map_err(truncated)?),
        Some((TypeChar::Complex, 8)) => Data::C64(npy.into_vec().map_err(truncated)?),
        Some((TypeChar::Complex, 16)) => Data::C128(npy.into_vec().map_err(truncated)?),
        _ => Data::Other,
    };
    let data = if c_order {
        data
    } else {
        match data {
            Data::F32(v) => Data::F32(to_c_order(&v, &shape, &strides)),
            Data::F64(v) => Data::F64(to_c_order(&v, &shape, &strides)),
            Data::C64(v) => Data::C64(to_c_order(&v, &shape, &strides)),
            Data::C128(v) => Data::C128(to_c_order(&v, &shape, &strides)),
            Data::Other => Data::Other,
        }
    };
    Ok(Array {
        data,
        shape,
        dtype: dtype_name,
    })
}

/// Decodes `count` elements of `size` bytes from the data part of `npy` (in memory) with
/// `f`.
fn read_le<T>(
    npy: NpyFile<&[u8]>,
    count: u64,
    size: usize,
    f: impl Fn(&[u8]) -> T,
) -> std::io::Result<Vec<T>> {
    let n = usize::try_from(count).map_err(|_| std::io::Error::other("too many samples"))?;
    let bytes = n
        .checked_mul(size)
        .ok_or_else(|| std::io::Error::other("too many samples"))?;
    let raw = npy.into_inner();
    let data = raw
        .get(..bytes)
        .ok_or_else(|| std::io::Error::from(std::io::ErrorKind::UnexpectedEof))?;
    Ok(data.chunks_exact(size).map(f).collect())
}

/// Gathers `data` (element at index `i` stored at `sum_k i_k strides[k]`) into C order.
fn to_c_order<T: Copy>(data: &[T], shape: &[usize], strides: &[usize]) -> Vec<T> {
    let total: usize = shape.iter().product();
    let mut out = Vec::with_capacity(total);
    if total == 0 {
        return out;
    }
    let mut idx = vec![0usize; shape.len()];
    let mut off = 0usize;
    for _ in 0..total {
        out.push(data[off]);
        // Odometer over the C-order index, last axis fastest.
        for k in (0..shape.len()).rev() {
            idx[k] += 1;
            off += strides[k];
            if idx[k] < shape[k] {
                break;
            }
            off -= strides[k] * shape[k];
            idx[k] = 0;
        }
    }
    out
}

fn check_not_empty(path: &Path, shape: &[usize]) -> Result<()> {
    if shape.contains(&0) {
        bail!(
            "{}: the array is empty, shape {} (K = 0 frames or frame length 0)",
            path.display(),
            fmt_shape(shape)
        );
    }
    Ok(())
}

/// NumPy's name of a dtype: `complex64`, `float32`, `int32`, `>f4` is `float32 (big-endian)`.
fn dtype_name(d: &DType) -> String {
    match d {
        DType::Plain(t) => {
            let bits = t.size_field() * 8;
            match t.type_char() {
                TypeChar::Bool => "bool".to_string(),
                TypeChar::Int => format!("int{bits}"),
                TypeChar::Uint => format!("uint{bits}"),
                TypeChar::Float => format!("float{bits}"),
                TypeChar::Complex => format!("complex{bits}"),
                _ => format!("`{t}`"),
            }
        }
        _ => format!("structured `{}`", d.descr()),
    }
}

/// `NaN`, `inf` or `-inf`; after narrowing from 64 bits, an inf may also be a finite
/// value beyond the float32 range.
fn non_finite_name(v: f32, narrowed: bool) -> &'static str {
    match (v.is_nan(), v > 0.0, narrowed) {
        (true, _, _) => "NaN",
        (false, true, false) => "inf",
        (false, false, false) => "-inf",
        (false, true, true) => "inf (or beyond the float32 range)",
        (false, false, true) => "-inf (or beyond the float32 range)",
    }
}

/// A shape as NumPy prints it: `(3, 8)`, `(3,)`.
fn fmt_shape(shape: &[usize]) -> String {
    fmt_axes(&shape.iter().map(|n| n.to_string()).collect::<Vec<_>>())
}

fn fmt_axes(axes: &[String]) -> String {
    match axes {
        [n] => format!("({n},)"),
        _ => format!("({})", axes.join(", ")),
    }
}

/// The multi-index `[i1, i2, ..]` of flat index `i` in a C-order frame of `shape`.
fn fmt_index(mut i: usize, shape: &[usize]) -> String {
    let mut idx = vec![0usize; shape.len()];
    for (k, &n) in shape.iter().enumerate().rev() {
        idx[k] = i % n;
        i /= n;
    }
    format!(
        "[{}]",
        idx.iter()
            .map(|n| n.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn data(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/data")
            .join(name)
    }

    /// The error of `r`, checked to be one line naming `name` and containing `word`.
    fn err<T: std::fmt::Debug>(r: Result<T>, name: &str, word: &str) -> String {
        let e = format!("{:#}", r.expect_err("expected an error"));
        assert!(!e.contains('\n'), "more than one line: {e}");
        assert!(e.contains(name), "no file name {name} in: {e}");
        assert!(e.contains(word), "no `{word}` in: {e}");
        e
    }

    /// z[k, i] = (100 k + i) + 0.25 i j, as written by make.py.
    fn expected_complex(k_max: usize, m: usize) -> Vec<Complex32> {
        (0..k_max)
            .flat_map(|k| {
                (0..m).map(move |i| Complex32::new((100 * k + i) as f32, 0.25 * i as f32))
            })
            .collect()
    }

    #[test]
    fn complex_frames_c_fortran_big_endian_iq_npz() {
        let want = expected_complex(3, 8);
        for name in [
            "complex_c.npy",
            "complex_f.npy",
            "complex_be.npy",
            "iq_c.npy",
            "iq_f.npy",
            "iq_f64.npy",
            "frames.npz",
            "single.npz",
        ] {
            let f = read_complex_frames(&data(name)).unwrap_or_else(|e| panic!("{e:#}"));
            assert_eq!(f.shape, [3, 8], "{name}");
            assert_eq!((f.frames(), f.frame_len()), (3, 8), "{name}");
            assert_eq!(f.data, want, "{name}");
            assert_eq!(f.frame(1)[5], Complex32::new(105.0, 1.25), "{name}");
        }
    }

    #[test]
    fn complex128_is_narrowed() {
        let f = read_complex_frames(&data("complex128.npy")).unwrap();
        assert_eq!(f.shape, [2, 4]);
        let want: Vec<Complex32> = (0..2)
            .flat_map(|k| {
                (0..4).map(move |i| {
                    let re = (100 * k + i) as f64 + 0.1;
                    Complex32::new(re as f32, 0.25 * i as f32)
                })
            })
            .collect();
        assert_eq!(f.data, want);
    }

    #[test]
    fn real_cubes_and_images() {
        let c = read_real_frames(&data("cube_c.npy"), 4).unwrap();
        let f = read_real_frames(&data("cube_f.npy"), 4).unwrap();
        assert_eq!(c.shape, [2, 3, 4, 5]);
        assert_eq!(c, f);
        assert_eq!(c.frame_len(), 60);
        let mut n = 0;
        for k in 0..2 {
            for r in 0..3 {
                for d in 0..4 {
                    for a in 0..5 {
                        let v = (1000 * k + 100 * r + 10 * d + a) as f32 + 0.5;
                        assert_eq!(c.data[n], v);
                        n += 1;
                    }
                }
            }
        }
        let im = read_real_frames(&data("image.npy"), 3).unwrap();
        let im64 = read_real_frames(&data("image_f64.npy"), 3).unwrap();
        assert_eq!(im.shape, [2, 6, 6]);
        assert_eq!(im, im64);
        assert_eq!(im.frame(1)[2 * 6 + 3], 123.25);
        assert_eq!(im.data[35], 55.25);
    }

    #[test]
    fn bad_npy_files_name_the_file_and_the_problem() {
        let e = err(
            read_complex_frames(&data("missing.npy")),
            "missing.npy",
            "not found",
        );
        assert!(e.ends_with("file not found"));
        err(
            read_complex_frames(&data("truncated.npy")),
            "truncated.npy",
            "truncated: shape (3, 8) needs 24 complex64 samples",
        );
        err(
            read_complex_frames(&data("text.npy")),
            "text.npy",
            "not a NumPy",
        );
        let e = err(
            read_complex_frames(&data("int32.npy")),
            "int32.npy",
            "dtype int32",
        );
        assert!(e.contains("expected (K, m) complex64"), "{e}");
        err(
            read_real_frames(&data("int32.npy"), 2),
            "int32.npy",
            "dtype int32",
        );
        err(
            read_complex_frames(&data("rank1.npy")),
            "rank1.npy",
            "expected (K, m) complex64 or (K, m, 2) float32, found complex64 shape (3,)",
        );
        err(
            read_complex_frames(&data("rank3.npy")),
            "rank3.npy",
            "found complex64 shape (3, 4, 5)",
        );
        err(
            read_complex_frames(&data("cube_c.npy")),
            "cube_c.npy",
            "found float32 shape (2, 3, 4, 5)",
        );
        err(
            read_real_frames(&data("cube_c.npy"), 3),
            "cube_c.npy",
            "expected float32 (K, n1, n2), found float32 shape (2, 3, 4, 5)",
        );
        err(
            read_real_frames(&data("complex_c.npy"), 2),
            "complex_c.npy",
            "dtype complex64",
        );
        err(
            read_complex_frames(&data("empty.npy")),
            "empty.npy",
            "empty, shape (0, 8)",
        );
        err(
            read_complex_frames(&data("nan.npy")),
            "nan.npy",
            "frame 1, index 5 is NaN",
        );
        err(
            read_complex_frames(&data("iq_inf.npy")),
            "iq_inf.npy",
            "frame 2, bin 3 (Q) is inf",
        );
        err(
            read_complex_frames(&data("ambiguous.npz")),
            "ambiguous.npz",
            "holds arrays a, b",
        );
        err(
            read_real_frames(&data("image.npy"), 0),
            "image.npy",
            "rank 0",
        );
    }

    #[test]
    fn real_nan_names_frame_index_and_position() {
        let dir = std::env::temp_dir().join(format!("faint-input-{}", std::process::id()));
        let path = dir.join("cube_nan.npy");
        let mut v = vec![1.0f32; 2 * 3 * 4];
        v[12 + 7] = f32::NEG_INFINITY;
        crate::io::output::write_real_frames(&path, &[2, 3, 4], &v).unwrap_err();
        // The writer refuses it, so write a good file and poke the sample in its bytes.
        v[12 + 7] = 1.0;
        crate::io::output::write_real_frames(&path, &[2, 3, 4], &v).unwrap();
        let mut bytes = fs::read(&path).unwrap();
        let at = bytes.len() - 4 * (24 - 19);
        bytes[at..at + 4].copy_from_slice(&f32::NEG_INFINITY.to_le_bytes());
        fs::write(&path, bytes).unwrap();
        err(
            read_real_frames(&path, 3),
            "cube_nan.npy",
            "frame 1, index 7 [1, 3] is -inf",
        );
        fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn plots_csv() {
        let s = read_plots(&data("plots.csv")).unwrap();
        assert_eq!(
            s,
            vec![
                vec![Plot::new(1.5, 10.0, 20.0), Plot::new(2.25, -3.5, 4.0)],
                vec![],
                vec![Plot::new(3.0, 100.125, -7.0)],
                vec![],
            ]
        );
    }

    #[test]
    fn bad_plots_csv_name_the_file_and_the_problem() {
        err(read_plots(&data("missing.csv")), "missing.csv", "not found");
        err(
            read_plots(&data("plots_header.csv")),
            "plots_header.csv",
            "wrong CSV header `scan,amp,x,y`, expected `scan,amplitude,x,y`",
        );
        err(
            read_plots(&data("plots_nan.csv")),
            "plots_nan.csv",
            "row 2 (line 3): amplitude is NaN",
        );
        err(
            read_plots(&data("plots_text.csv")),
            "plots_text.csv",
            "row 2 (line 3): non-numeric x `abc`",
        );
        err(
            read_plots(&data("plots_decreasing.csv")),
            "plots_decreasing.csv",
            "decreasing scan number",
        );
        err(
            read_plots(&data("plots_columns.csv")),
            "plots_columns.csv",
            "row 2 (line 3): 5 columns, expected 4",
        );
        err(
            read_plots(&data("text.npy")),
            "text.npy",
            "wrong CSV header",
        );
    }

    #[test]
    fn fortran_gather_matches_the_definition() {
        // 2 x 3 x 4 array stored Fortran order: element (i, j, k) at i + 2 j + 6 k.
        let shape = [2, 3, 4];
        let strides = [1, 2, 6];
        let stored: Vec<usize> = (0..24).collect();
        let c = to_c_order(&stored, &shape, &strides);
        let mut n = 0;
        for i in 0..2 {
            for j in 0..3 {
                for k in 0..4 {
                    assert_eq!(c[n], i + 2 * j + 6 * k);
                    n += 1;
                }
            }
        }
    }
}
