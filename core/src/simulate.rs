//! Simulation of scenes without allocation, shared by the host's simulators, the golden cases
//! and the firmware's measured scenes, so that all three draw the same numbers in the same
//! order: clutter plots, noisy detections of a target, and a target's returns in a power
//! cube.

use crate::math;
use crate::model::plot::Plot;
use crate::rng::Rng;
use crate::Complex32;

/// Fills `out` with clutter plots uniform over `area = [x_min, x_max, y_min, y_max]`, the
/// amplitude of each from `amplitude` (drawn after its position); returns how many were
/// written (`out.len()`).
pub fn clutter_plots(
    rng: &mut Rng,
    area: [f32; 4],
    out: &mut [Plot],
    mut amplitude: impl FnMut(&mut Rng) -> f32,
) -> usize {
    for o in out.iter_mut() {
        let x = rng.uniform_range(area[0], area[1]);
        let y = rng.uniform_range(area[2], area[3]);
        *o = Plot::new(amplitude(rng), x, y);
    }
    out.len()
}

/// A target at `(x, y)` detected with probability `pd`: `Some` position with Gaussian
/// noise of standard deviation `sigma` per axis (one Bernoulli draw, then x, then y).
#[inline]
pub fn detection(rng: &mut Rng, pd: f32, x: f32, y: f32, sigma: f32) -> Option<(f32, f32)> {
    if rng.bernoulli(pd) {
        let dx = sigma * rng.normal();
        let dy = sigma * rng.normal();
        Some((x + dx, y + dy))
    } else {
        None
    }
}

/// Writes targets' returns into a cube of noise-only powers (Pei et al. 2019, eq. 2):
/// `cells` holds `(cell index, A_t h_t)` of every cell a target spreads into, in the order
/// the targets were spread; cells named more than once sum their terms in that order,
/// then each gets one complex Gaussian noise sample of variance `noise_var` per component
/// and its power `|sum_t A_t h_t + n|^2` (in increasing cell order). `cells` is reordered
/// (sorted by cell, ties kept in order: the position in `order` breaks them); indices
/// beyond `cube` are skipped. `order` must be at least as long as `cells` (scratch).
pub fn cube_returns(
    cube: &mut [f32],
    cells: &mut [(usize, Complex32)],
    order: &mut [u32],
    noise_var: f32,
    rng: &mut Rng,
) {
    let n = cells.len().min(order.len());
    let (cells, order) = (&mut cells[..n], &mut order[..n]);
    for (k, o) in order.iter_mut().enumerate() {
        *o = k as u32;
    }
    // A stable sort by cell without allocation: sort the positions by (cell, position).
    crate::sort::sort_unstable_by_key(order, |&k| {
        (cells.get(k as usize).map_or(usize::MAX, |c| c.0), k)
    });
    let sd = math::sqrt(noise_var);
    let mut i = 0;
    while i < n {
        let Some(&(idx, _)) = order.get(i).and_then(|&k| cells.get(k as usize)) else {
            break;
        };
        let mut s = Complex32::new(0.0, 0.0);
        while let Some(&(j, a)) = order.get(i).and_then(|&k| cells.get(k as usize)) {
            if j != idx {
                break;
            }
            s += a;
            i += 1;
        }
        let noise = Complex32::new(sd * rng.normal(), sd * rng.normal());
        if let Some(z) = cube.get_mut(idx) {
            *z = (s + noise).norm_sqr();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_returns_sum_ties_in_order() {
        // Two targets share cell 3: its power is |a + b + n|^2, summed a then b.
        let mut cube = [0.5f32; 6];
        let a = Complex32::new(1.0, 0.0);
        let b = Complex32::new(0.0, 2.0);
        let mut cells = [(3usize, a), (1, a), (3, b), (9, b)];
        let mut order = [0u32; 4];
        let mut rng = Rng::seed_from_u64(1);
        let mut r2 = rng.clone();
        cube_returns(&mut cube, &mut cells, &mut order, 0.25, &mut rng);
        // Cell 1 first, then 3, then 9 (skipped but its noise is drawn).
        let n1 = Complex32::new(0.5 * r2.normal(), 0.5 * r2.normal());
        let n3 = Complex32::new(0.5 * r2.normal(), 0.5 * r2.normal());
        assert_eq!(cube[1], (a + n1).norm_sqr());
        assert_eq!(cube[3], (a + b + n3).norm_sqr());
        assert_eq!(cube[0], 0.5);
        let _ = r2.normal();
        let _ = r2.normal();
        assert_eq!(rng, r2);
    }
}
