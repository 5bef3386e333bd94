//! Stage 3, detection and track recovery (Bao et al. 2022, §3.2): binary-integration Hough
//! accumulator, 3x3 Gaussian smoothing, threshold, condensing, line-to-plot association.
//!
//! The accumulator is shared with the classic detector (`classic.rs`); the data-matched
//! geometry (origin at the centroid of `S_ep`, rho range = largest distance of an
//! effective plot from it, eq. 7) is built by the detector in `mod.rs`.

use super::geometry::Geometry;
use crate::math;
use crate::model::plot::Plot;

/// Capacity of the flood-fill stack used by condensing.
pub const CONDENSE_STACK: usize = 1024;

/// Sentinel for "no plot" in a track.
pub const NO_PLOT: u16 = u16::MAX;

/// One condensed peak: the strongest cell of a connected above-threshold region.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Peak {
    /// Rho cell.
    pub r: u16,
    /// Theta cell.
    pub a: u16,
    /// Cell value times 16 (smoothed: `sum w * acc` with the weights `[1 2 1]x[1 2 1]`,
    /// which sum to 16; unsmoothed: `16 acc`).
    pub value16: u16,
    /// Raw (unsmoothed) binary-integration count of the peak cell.
    pub raw: u8,
    /// Number of above-threshold cells in the region.
    pub cells: u16,
}

/// Counters of one condensing pass.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct CondenseStats {
    /// Peaks written.
    pub peaks: u16,
    /// Peaks found beyond the output capacity (dropped, weakest first).
    pub dropped: u16,
    /// Cells not expanded because the flood-fill stack was full (their region may then
    /// be split into several peaks).
    pub stack_overflow: u16,
}

/// A binary-integration accumulator over an `R x A` grid.
#[derive(Debug, Clone)]
pub struct Accumulator<const R: usize, const A: usize> {
    acc: [[u8; R]; A],
    /// Per-cell last scan tag during accumulation, visited marks during condensing.
    stamp: [[u8; R]; A],
    value: [[u16; R]; A],
    stack: [u32; CONDENSE_STACK],
}

impl<const R: usize, const A: usize> Default for Accumulator<R, A> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const R: usize, const A: usize> Accumulator<R, A> {
    /// Zeroed accumulator.
    pub const fn new() -> Self {
        Self {
            acc: [[0; R]; A],
            stamp: [[0; R]; A],
            value: [[0; R]; A],
            stack: [0; CONDENSE_STACK],
        }
    }

    /// Clear counts and stamps.
    pub fn reset(&mut self) {
        for row in self.acc.iter_mut() {
            row.fill(0);
        }
        for row in self.stamp.iter_mut() {
            row.fill(0);
        }
    }

    /// Raw count of cell `(r, a)`.
    pub fn count(&self, r: usize, a: usize) -> u8 {
        self.acc[a % A][r % R]
    }

    /// Value (x16) of cell `(r, a)` after `finish`.
    pub fn value16(&self, r: usize, a: usize) -> u16 {
        self.value[a % A][r % R]
    }

    /// Add one point's curve with binary integration: a cell gains at most 1 per scan
    /// tag. `tag` must be nonzero and differ between the scans of one period.
    #[inline]
    pub fn add_point(&mut self, geom: &Geometry<R, A>, tag: u8, x: f32, y: f32) {
        let (xq, yq) = geom.quantise(x, y);
        for a in 0..A {
            let r = geom.rho_index_q(xq, yq, a);
            let st = &mut self.stamp[a][r];
            if *st != tag {
                *st = tag;
                let c = &mut self.acc[a][r];
                *c = c.saturating_add(1);
            }
        }
    }

    /// Compute the cell values: 3x3 Gaussian `[1 2 1]x[1 2 1]` (sum 16) smoothing of the
    /// counts when `smooth`, else `16 * count`. Theta wraps with a rho flip; rho edges
    /// are zero padded.
    pub fn finish(&mut self, smooth: bool) {
        if !smooth {
            for a in 0..A {
                for r in 0..R {
                    self.value[a][r] = 16 * u16::from(self.acc[a][r]);
                }
            }
            return;
        }
        const W: [u16; 3] = [1, 2, 1];
        for a in 0..A {
            // rows a-1, a, a+1 when a is an interior angle
            let rows = match (
                a.checked_sub(1).map(|i| self.acc.get(i)),
                self.acc.get(a + 1),
            ) {
                (Some(Some(lo)), Some(hi)) => Some((lo, &self.acc[a], hi)),
                _ => None,
            };
            for r in 0..R {
                let mut s = 0u16;
                match rows {
                    Some((lo, mid, hi)) if r > 0 && r + 1 < R => {
                        // sum of W[i] (row[r-1] + 2 row[r] + row[r+1]); exact in u16
                        // (at most 16 x 255)
                        let row3 = |row: &[u8; R]| {
                            u16::from(row[r - 1]) + 2 * u16::from(row[r]) + u16::from(row[r + 1])
                        };
                        s = row3(lo) + 2 * row3(mid) + row3(hi);
                    }
                    _ => {
                        for (i, wa) in W.iter().enumerate() {
                            for (j, wr) in W.iter().enumerate() {
                                let c = Geometry::<R, A>::neighbour(
                                    r,
                                    a,
                                    j as isize - 1,
                                    i as isize - 1,
                                );
                                if let Some(&v) = c.and_then(|c| Self::cell(&self.acc, c)) {
                                    s += wa * wr * u16::from(v);
                                }
                            }
                        }
                    }
                }
                self.value[a][r] = s;
            }
        }
    }

    /// Cell `c = a R + r` of a grid; `None` past the grid.
    #[inline(always)]
    fn cell<T>(grid: &[[T; R]; A], c: usize) -> Option<&T> {
        grid.get(c / R).and_then(|row| row.get(c % R))
    }

    /// Threshold and condense: the cells whose binary-integration count is `>= gamma`
    /// are grouped into 8-connected regions (theta wrap included), and each region gives
    /// one peak at its cell of largest value (smoothed value when `finish(true)`, ties by
    /// scan order); peaks sorted by decreasing value into `out`.
    ///
    /// The threshold is applied to the raw count, whose distribution the analytic model
    /// gives (eq. 27-29); the smoothing serves the peak location (paper: "to reduce the
    /// effect of measurement errors"). The smoothed value of a peak is typically ~0.6 of
    /// its count, so thresholding it with the model's `gamma_1` would not hold the
    /// model's `Pfa`.
    pub fn condense(&mut self, gamma: u8, out: &mut [Peak]) -> CondenseStats {
        let mut st = CondenseStats::default();
        for row in self.stamp.iter_mut() {
            row.fill(0);
        }
        let mut n = 0usize;
        let gamma = gamma.max(1);
        for a0 in 0..A {
            for r0 in 0..R {
                if self.stamp[a0][r0] != 0 || self.acc[a0][r0] < gamma {
                    continue;
                }
                self.stamp[a0][r0] = 1;
                let mut best = Peak {
                    r: r0 as u16,
                    a: a0 as u16,
                    value16: self.value[a0][r0],
                    raw: self.acc[a0][r0],
                    cells: 0,
                };
                let mut sp = 0usize;
                self.stack[sp] = (a0 * R + r0) as u32;
                sp += 1;
                while sp > 0 {
                    sp -= 1;
                    let Some(&c) = self.stack.get(sp) else {
                        break;
                    };
                    let (a, r) = (c as usize / R, c as usize % R);
                    // a < A for every stacked cell
                    if a >= A {
                        continue;
                    }
                    best.cells = best.cells.saturating_add(1);
                    let v = self.value[a][r];
                    if v > best.value16 || (v == best.value16 && self.acc[a][r] > best.raw) {
                        best.value16 = v;
                        best.r = r as u16;
                        best.a = a as u16;
                        best.raw = self.acc[a][r];
                    }
                    for da in -1isize..=1 {
                        for dr in -1isize..=1 {
                            if da == 0 && dr == 0 {
                                continue;
                            }
                            let Some(nc) = Geometry::<R, A>::neighbour(r, a, dr, da) else {
                                continue;
                            };
                            let (na, nr) = (nc / R, nc % R);
                            if na >= A || self.stamp[na][nr] != 0 || self.acc[na][nr] < gamma {
                                continue;
                            }
                            if sp < CONDENSE_STACK {
                                self.stamp[na][nr] = 1;
                                self.stack[sp] = nc as u32;
                                sp += 1;
                            } else {
                                st.stack_overflow = st.stack_overflow.saturating_add(1);
                            }
                        }
                    }
                }
                // insert keeping `out[..n]` sorted by decreasing value
                if n < out.len() {
                    out[n] = best;
                    n += 1;
                } else if let Some(last) = out.last_mut() {
                    st.dropped = st.dropped.saturating_add(1);
                    if best.value16 > last.value16 {
                        *last = best;
                    } else {
                        continue;
                    }
                } else {
                    st.dropped = st.dropped.saturating_add(1);
                    continue;
                }
                let mut i = n - 1;
                while i > 0 {
                    match (out.get(i - 1), out.get(i)) {
                        (Some(x), Some(y)) if x.value16 < y.value16 => out.swap(i - 1, i),
                        _ => break,
                    }
                    i -= 1;
                }
            }
        }
        st.peaks = n as u16;
        st
    }
}

/// A recovered track: the peak's line and one plot (or none) per scan (eq. 10).
#[derive(Debug, Clone, Copy)]
pub struct Track<const NS: usize> {
    /// The condensed peak.
    pub peak: Peak,
    /// Line `x cos(theta) + y sin(theta) = c` (eq. 8).
    pub theta: f32,
    /// `C = x0 cos(theta_m) + y0 sin(theta_m) + rho_m` (eq. 8).
    pub c: f32,
    /// Plot index in each scan, or [`NO_PLOT`].
    pub plots: [u16; NS],
    /// Bit `s` set: the plot of scan `s` came from the look-back into the pre-detection
    /// plots (no effective plot was within reach).
    pub lookback: u64,
    /// Number of associated plots.
    pub n_plots: u16,
    /// Associated plots that are effective plots.
    pub n_effective: u16,
}

impl<const NS: usize> Track<NS> {
    /// An empty track.
    pub const fn empty() -> Self {
        Self {
            peak: Peak {
                r: 0,
                a: 0,
                value16: 0,
                raw: 0,
                cells: 0,
            },
            theta: 0.0,
            c: 0.0,
            plots: [NO_PLOT; NS],
            lookback: 0,
            n_plots: 0,
            n_effective: 0,
        }
    }
}

impl<const NS: usize> Default for Track<NS> {
    fn default() -> Self {
        Self {
            peak: Peak::default(),
            theta: 0.0,
            c: 0.0,
            plots: [NO_PLOT; NS],
            lookback: 0,
            n_plots: 0,
            n_effective: 0,
        }
    }
}

/// Association parameters.
#[derive(Debug, Clone, Copy)]
pub struct Assoc {
    /// Largest plot-to-line distance `D_max` (eq. 9), m.
    pub d_max: f32,
    /// Largest along-line distance from the track's predicted position, m.
    pub along_gate: f32,
    /// Look back into the pre-detection plots when no effective plot qualifies.
    pub lookback: bool,
}

/// Least-squares `t = alpha + beta s` through `(s, t)` pairs; `None` with fewer than 2
/// distinct scans.
fn fit(ts: &[(f32, f32)]) -> Option<(f32, f32)> {
    if ts.len() < 2 {
        return None;
    }
    let n = ts.len() as f32;
    let (ms, mt) = ts
        .iter()
        .fold((0.0, 0.0), |(a, b), &(s, t)| (a + s / n, b + t / n));
    let (mut sst, mut sss) = (0.0f32, 0.0f32);
    for &(s, t) in ts {
        sst += (s - ms) * (t - mt);
        sss += (s - ms) * (s - ms);
    }
    if sss <= 0.0 {
        return None;
    }
    let beta = sst / sss;
    Some((mt - beta * ms, beta))
}

/// Consensus fit of `t = alpha + beta s`: every pair of points with `|beta| <= gate`
/// proposes a line, the one with most points within `gate` wins (ties: first), and the
/// least-squares fit of its inliers is returned. Robust to clutter plots far along the
/// line. `O(n^3)` with `n <= NS`.
fn fit_consensus(ts: &[(f32, f32)], gate: f32, inl: &mut [(f32, f32)]) -> Option<(f32, f32)> {
    let n = ts.len();
    let mut best = (0usize, 0.0f32, 0.0f32);
    for i in 0..n {
        for j in (i + 1)..n {
            let ds = ts[j].0 - ts[i].0;
            if ds == 0.0 {
                continue;
            }
            let be = (ts[j].1 - ts[i].1) / ds;
            if math_abs(be) > gate {
                continue;
            }
            let al = ts[i].1 - be * ts[i].0;
            let cnt = ts
                .iter()
                .filter(|&&(s, t)| math_abs(t - al - be * s) <= gate)
                .count();
            if cnt > best.0 {
                best = (cnt, al, be);
            }
        }
    }
    if best.0 < 2 {
        return fit(ts);
    }
    let mut k = 0;
    for &(s, t) in ts {
        if math_abs(t - best.1 - best.2 * s) <= gate && k < inl.len() {
            inl[k] = (s, t);
            k += 1;
        }
    }
    fit(inl.get(..k).unwrap_or(&[]))
}

/// Total-least-squares line through points: `(theta, c)` with `theta in [0, pi)` the
/// normal angle, or `None` with fewer than 2 points.
fn tls(pts: &[(f32, f32)]) -> Option<(f32, f32)> {
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f32;
    let (mx, my) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), &(x, y)| (a + x / n, b + y / n));
    let (mut sxx, mut syy, mut sxy) = (0.0f32, 0.0f32, 0.0f32);
    for &(x, y) in pts {
        sxx += (x - mx) * (x - mx);
        syy += (y - my) * (y - my);
        sxy += (x - mx) * (y - my);
    }
    // principal direction phi, normal theta = phi + pi/2
    let phi = 0.5 * math::atan2(2.0 * sxy, sxx - syy);
    let mut th = phi + 0.5 * math::PI;
    if th >= math::PI {
        th -= math::PI;
    }
    if th < 0.0 {
        th += math::PI;
    }
    if !th.is_finite() {
        return None;
    }
    let c = mx * math::cos(th) + my * math::sin(th);
    Some((th, c))
}

/// Track recovery for one peak (eq. 8-9): per scan, the effective plot nearest the line
/// within `D_max`; if none, the nearest pre-detection plot within `D_max` (look-back).
///
/// Beyond the paper (the peak's cell centre is a coarse line and the line crosses the
/// whole area): pass 1 associates effective plots to the peak's line (eq. 8-9) and fits
/// their along-line coordinate against the scan index (constant velocity) by consensus
/// (clutter plots far along the line are outliers); pass 2 re-associates with
/// `|t - t_pred| <= along_gate` as well, the line is refined by total least squares
/// through those plots and the motion refitted; pass 3 associates to the refined line,
/// with the look-back.
/// The track's `theta`, `c` are the refined line. Scan `s` uses the flags `flags[s]`; the
/// scans past `flags.len()`, past `NS`, and the plots past `P` of a scan are not
/// associated.
#[allow(clippy::too_many_arguments)]
pub fn recover<const R: usize, const A: usize, const P: usize, const NS: usize>(
    geom: &Geometry<R, A>,
    peak: Peak,
    scans: &[&[Plot]],
    flags: &[[u8; P]],
    assoc: &Assoc,
    track: &mut Track<NS>,
) {
    let a = usize::from(peak.a);
    let (mut c, mut s) = geom.trig(a);
    let (x0, y0) = geom.origin();
    let mut cc = x0 * c + y0 * s + geom.rho_center(usize::from(peak.r));
    track.peak = peak;
    track.theta = geom.theta(a);
    track.c = cc;
    let mut ts = [(0.0f32, 0.0f32); NS];
    let mut xy = [(0.0f32, 0.0f32); NS];
    let mut inl = [(0.0f32, 0.0f32); NS];
    let mut pred: Option<(f32, f32)> = None;
    for pass in 0..3 {
        let mut nt = 0usize;
        track.plots = [NO_PLOT; NS];
        track.lookback = 0;
        track.n_plots = 0;
        track.n_effective = 0;
        let look = pass == 2 && assoc.lookback && pred.is_some();
        let rows = scans.iter().zip(flags).zip(track.plots.iter_mut());
        for (si, ((scan, fl), plot)) in rows.enumerate() {
            let tp = pred.map(|(al, be)| al + be * si as f32);
            let mut best = (f32::INFINITY, NO_PLOT, false, (0.0f32, 0.0f32));
            for want_eff in [true, false] {
                if !want_eff && (!look || best.1 != NO_PLOT) {
                    break;
                }
                for (k, (p, &f)) in scan.iter().zip(fl).enumerate() {
                    let eff = f & super::censoring::FLAG_EFFECTIVE != 0;
                    if eff != want_eff {
                        continue;
                    }
                    let d = math_abs(p.x * c + p.y * s - cc);
                    if d > assoc.d_max {
                        continue;
                    }
                    let mut score = d;
                    if let Some(tp) = tp {
                        let t = -p.x * s + p.y * c;
                        let e = math_abs(t - tp);
                        if e > assoc.along_gate {
                            continue;
                        }
                        score = math::sqrt(d * d + e * e);
                    }
                    if score < best.0 {
                        best = (score, k as u16, !want_eff, (p.x, p.y));
                    }
                }
            }
            if best.1 != NO_PLOT {
                *plot = best.1;
                track.n_plots += 1;
                if best.2 {
                    track.lookback |= 1u64 << (si % 64);
                } else if let (Some(q), Some(t)) = (xy.get_mut(nt), ts.get_mut(nt)) {
                    // nt <= si < NS
                    track.n_effective += 1;
                    *q = best.3;
                    *t = (si as f32, 0.0);
                    nt += 1;
                }
            }
        }
        let (xy, ts) = (
            xy.get(..nt).unwrap_or(&[]),
            ts.get_mut(..nt).unwrap_or(&mut []),
        );
        if pass == 2 {
            break;
        }
        if pass == 1 {
            // refine the line through the gated plots
            if let Some((th, c2)) = tls(xy) {
                track.theta = th;
                track.c = c2;
                cc = c2;
                c = math::cos(th);
                s = math::sin(th);
            }
        }
        for (t, p) in ts.iter_mut().zip(xy) {
            t.1 = -p.0 * s + p.1 * c;
        }
        let f = if pass == 0 {
            fit_consensus(ts, assoc.along_gate, &mut inl)
        } else {
            fit(ts)
        };
        match f {
            Some(f) => pred = Some(f),
            None => break,
        }
    }
}

#[inline]
fn math_abs(v: f32) -> f32 {
    if v < 0.0 {
        -v
    } else {
        v
    }
}
