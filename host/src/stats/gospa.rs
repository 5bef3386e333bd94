//! GOSPA: the generalized optimal sub-pattern assignment metric with `alpha = 2`
//! (Rahmathullah, Garcia-Fernandez, Svensson, FUSION 2017).
//!
//! For truth `X` (`|X| = m`), estimates `Y` (`|Y| = n`), cut-off `c > 0`, order `p >= 1`:
//! ```text
//! GOSPA^p = min_gamma  sum_{(i,j) in gamma} d(x_i, y_j)^p  +  (c^p / 2) (m + n - 2 |gamma|)
//! ```
//! over partial injective assignments `gamma` of truth to estimates. An assigned pair at
//! `d >= c` costs no less than a miss plus a false target (`c^p/2 + c^p/2`), so pairs at
//! `d >= c` are reported as one missed target and one false target. The minimum is
//! found by the Hungarian method of [`super::ospa::assignment`] on the cost
//! `min(d, c)^p` (the smaller set into the larger), plus `c^p/2` for each unmatched
//! point of the larger set.
//!
//! The three terms are reported as p-th powers, which add up to `total^p`:
//! `localisation = sum d^p` over pairs at `d < c`, `missed = (c^p/2) n_missed`,
//! `false_targets = (c^p/2) n_false`. For `m = n`, `GOSPA^p = n OSPA^p`.

use serde::Serialize;

use super::ospa::assignment;

/// GOSPA distance and its decomposition (p-th powers: `total^p = localisation + missed
/// + false_targets`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Gospa {
    /// The GOSPA distance `(localisation + missed + false_targets)^(1/p)`.
    pub total: f64,
    /// `sum d^p` over the assigned pairs (all at `d < c`).
    pub localisation: f64,
    /// `(c^p / 2) n_missed`.
    pub missed: f64,
    /// `(c^p / 2) n_false`.
    pub false_targets: f64,
    /// Number of assigned truth-estimate pairs.
    pub assigned: usize,
    /// Truth points left unassigned.
    pub n_missed: usize,
    /// Estimates left unassigned.
    pub n_false: usize,
}

/// GOSPA between point sets in `D` dimensions with Euclidean base distance.
pub fn gospa<const D: usize>(truth: &[[f64; D]], est: &[[f64; D]], c: f64, p: f64) -> Gospa {
    gospa_with(truth, est, c, p, euclid)
}

/// GOSPA with any base metric `dist(truth, estimate)`. `c` and `p` must be positive and
/// finite (`p >= 1` for a metric); a NaN distance counts as `>= c` (a miss and a false).
pub fn gospa_with<T>(
    truth: &[T],
    est: &[T],
    c: f64,
    p: f64,
    dist: impl Fn(&T, &T) -> f64,
) -> Gospa {
    let (m, n) = (truth.len(), est.len());
    let swap = m > n;
    let (rows, cols) = if swap { (n, m) } else { (m, n) };
    // d[r * cols + q] = distance between row r and column q of the smaller-by-larger matrix.
    let mut d = Vec::with_capacity(rows * cols);
    for r in 0..rows {
        for q in 0..cols {
            let v = if swap {
                dist(&truth[q], &est[r])
            } else {
                dist(&truth[r], &est[q])
            };
            d.push(if v.is_nan() { c } else { v });
        }
    }
    let cost: Vec<f64> = d.iter().map(|&v| v.min(c).powf(p)).collect();
    // Costs are finite and non-negative by construction, so this cannot fail.
    let col_of = assignment(&cost, rows, cols)
        .map(|(cols, _)| cols)
        .unwrap_or_default();
    let mut localisation = 0.0;
    let mut assigned = 0;
    for (r, &q) in col_of.iter().enumerate() {
        let v = d[r * cols + q];
        if v < c {
            localisation += v.powf(p);
            assigned += 1;
        }
    }
    let half = c.powf(p) / 2.0;
    let (n_missed, n_false) = (m - assigned, n - assigned);
    let missed = half * n_missed as f64;
    let false_targets = half * n_false as f64;
    Gospa {
        total: (localisation + missed + false_targets).powf(1.0 / p),
        localisation,
        missed,
        false_targets,
        assigned,
        n_missed,
        n_false,
    }
}

/// GOSPA frame by frame. When one list is shorter, its missing frames count as empty
/// sets (no truth, or no estimates), so the result has the longer list's length.
pub fn gospa_per_frame<const D: usize>(
    truth: &[Vec<[f64; D]>],
    est: &[Vec<[f64; D]>],
    c: f64,
    p: f64,
) -> Vec<Gospa> {
    (0..truth.len().max(est.len()))
        .map(|k| {
            let x = truth.get(k).map_or(&[][..], Vec::as_slice);
            let y = est.get(k).map_or(&[][..], Vec::as_slice);
            gospa(x, y, c, p)
        })
        .collect()
}

fn euclid<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(u, v)| (u - v) * (u - v))
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::ospa::ospa;
    use faint_core::rng::Rng;
    use proptest::prelude::*;

    /// Best partial assignment found by depth-first search.
    struct Best {
        total: f64,
        localisation: f64,
        assigned: usize,
    }

    /// Reference straight from the definition: every partial injective assignment of
    /// truth to estimates, raw distances (no cut-off), `c^p/2` per unassigned point.
    fn brute<const D: usize>(x: &[[f64; D]], y: &[[f64; D]], c: f64, p: f64) -> Best {
        struct Search<'a, const D: usize> {
            x: &'a [[f64; D]],
            y: &'a [[f64; D]],
            half: f64,
            p: f64,
            used: Vec<bool>,
            best: Best,
        }
        impl<const D: usize> Search<'_, D> {
            fn go(&mut self, i: usize, loc: f64, a: usize) {
                if i == self.x.len() {
                    let unassigned = (self.x.len() - a) + (self.y.len() - a);
                    let total = loc + self.half * unassigned as f64;
                    if total < self.best.total {
                        self.best = Best {
                            total,
                            localisation: loc,
                            assigned: a,
                        };
                    }
                    return;
                }
                self.go(i + 1, loc, a);
                for j in 0..self.y.len() {
                    if !self.used[j] {
                        self.used[j] = true;
                        let dp = euclid(&self.x[i], &self.y[j]).powf(self.p);
                        self.go(i + 1, loc + dp, a + 1);
                        self.used[j] = false;
                    }
                }
            }
        }
        let mut s = Search {
            x,
            y,
            half: c.powf(p) / 2.0,
            p,
            used: vec![false; y.len()],
            best: Best {
                total: f64::INFINITY,
                localisation: 0.0,
                assigned: 0,
            },
        };
        s.go(0, 0.0, 0);
        s.best
    }

    fn random_set(rng: &mut Rng, n: usize, grid: bool) -> Vec<[f64; 2]> {
        (0..n)
            .map(|_| {
                if grid {
                    [rng.below(5) as f64, rng.below(5) as f64]
                } else {
                    [
                        f64::from(rng.uniform_range(-10.0, 10.0)),
                        f64::from(rng.uniform_range(-10.0, 10.0)),
                    ]
                }
            })
            .collect()
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn gospa_matches_brute_force() {
        let mut rng = Rng::seed_from_u64(17);
        for case in 0..3000 {
            // Every fourth case on an integer grid: exact ties and distances equal to c.
            let grid = case % 4 == 0;
            let (m, n) = (rng.below(6) as usize, rng.below(6) as usize);
            let x = random_set(&mut rng, m, grid);
            let y = random_set(&mut rng, n, grid);
            let c = [1.0, 2.0, 3.0, 5.0, 30.0][rng.below(5) as usize];
            let p = [1.0, 2.0, 3.0][rng.below(3) as usize];
            let g = gospa(&x, &y, c, p);
            let b = brute(&x, &y, c, p);
            let half = c.powf(p) / 2.0;
            assert!(
                close(g.total.powf(p), b.total),
                "case {case}: {} vs {}",
                g.total.powf(p),
                b.total
            );
            assert_eq!(g.assigned + g.n_missed, x.len());
            assert_eq!(g.assigned + g.n_false, y.len());
            assert_eq!(g.missed, half * g.n_missed as f64);
            assert_eq!(g.false_targets, half * g.n_false as f64);
            assert!(close(
                g.total.powf(p),
                g.localisation + g.missed + g.false_targets
            ));
            if !grid {
                // Continuous points: the optimum is unique, so is its decomposition.
                assert_eq!(g.assigned, b.assigned, "case {case}");
                assert!(close(g.localisation, b.localisation), "case {case}");
            }
        }
    }

    #[test]
    fn empty_and_hand_computed_cases() {
        let c = 10.0;
        let g = gospa::<2>(&[], &[], c, 2.0);
        assert_eq!(
            g,
            Gospa {
                total: 0.0,
                localisation: 0.0,
                missed: 0.0,
                false_targets: 0.0,
                assigned: 0,
                n_missed: 0,
                n_false: 0
            }
        );
        // Two truths, no estimates: 2 c^p / 2 = c^p, total c.
        let g = gospa(&[[0.0, 0.0], [5.0, 5.0]], &[], c, 2.0);
        assert_eq!((g.n_missed, g.n_false, g.assigned), (2, 0, 0));
        assert!(close(g.total, c) && g.missed == 100.0 && g.false_targets == 0.0);
        // No truth, three estimates: total (3 c^p / 2)^(1/p).
        let g = gospa(&[], &[[0.0], [1.0], [2.0]], c, 1.0);
        assert_eq!((g.n_missed, g.n_false), (0, 3));
        assert!(close(g.total, 15.0));
        // One pair at distance 3: total 3.
        let g = gospa(&[[0.0, 0.0]], &[[3.0, 0.0]], c, 2.0);
        assert_eq!((g.assigned, g.n_missed, g.n_false), (1, 0, 0));
        assert!(close(g.total, 3.0) && close(g.localisation, 9.0));
        // A pair at distance >= c (here exactly c, and beyond): a miss plus a false.
        for far in [10.0, 20.0] {
            let g = gospa(&[[0.0]], &[[far]], c, 2.0);
            assert_eq!((g.assigned, g.n_missed, g.n_false), (0, 1, 1));
            assert_eq!(g.localisation, 0.0);
            assert!(close(g.total, c));
        }
        // X = {0}, Y = {3, 100}: 0 -> 3 (9) plus one false (50): sqrt(59).
        let g = gospa(&[[0.0]], &[[3.0], [100.0]], c, 2.0);
        assert_eq!((g.assigned, g.n_missed, g.n_false), (1, 0, 1));
        assert!(close(g.total, 59.0f64.sqrt()));
        // Swapping the sets swaps missed and false.
        let h = gospa(&[[3.0], [100.0]], &[[0.0]], c, 2.0);
        assert_eq!((h.n_missed, h.n_false), (1, 0));
        assert!(close(g.total, h.total));
        // NaN distance: a miss and a false.
        let g = gospa_with(&[0.0], &[1.0], c, 2.0, |_, _| f64::NAN);
        assert_eq!((g.assigned, g.n_missed, g.n_false), (0, 1, 1));
    }

    #[test]
    fn equal_cardinalities_give_n_times_ospa() {
        let mut rng = Rng::seed_from_u64(29);
        for _ in 0..500 {
            let n = 1 + rng.below(6) as usize;
            let x = random_set(&mut rng, n, false);
            let y = random_set(&mut rng, n, false);
            let c = [1.0, 4.0, 30.0][rng.below(3) as usize];
            let p = [1.0, 2.0, 3.0][rng.below(3) as usize];
            let g = gospa(&x, &y, c, p).total.powf(p);
            let o = ospa(&x, &y, c, p).distance.powf(p);
            assert!(close(g, n as f64 * o), "{g} vs {n} * {o}");
        }
    }

    #[test]
    fn per_frame_pads_the_shorter_list() {
        let truth = vec![vec![[0.0, 0.0]], vec![], vec![[1.0, 1.0]]];
        let est = vec![vec![[0.0, 1.0]]];
        let g = gospa_per_frame(&truth, &est, 10.0, 2.0);
        assert_eq!(g.len(), 3);
        assert!(close(g[0].total, 1.0));
        assert_eq!(g[1].total, 0.0);
        assert_eq!((g[2].n_missed, g[2].n_false), (1, 0));
    }

    fn set() -> impl Strategy<Value = Vec<[f64; 2]>> {
        prop::collection::vec(prop::array::uniform2(-50.0f64..50.0), 0..5)
    }

    proptest! {
        #[test]
        fn metric_axioms(x in set(), y in set(), z in set()) {
            let (c, p) = (20.0, 2.0);
            let dxy = gospa(&x, &y, c, p).total;
            let dyx = gospa(&y, &x, c, p).total;
            let dxz = gospa(&x, &z, c, p).total;
            let dzy = gospa(&z, &y, c, p).total;
            prop_assert!(gospa(&x, &x, c, p).total.abs() < 1e-9);
            prop_assert!((dxy - dyx).abs() < 1e-9);
            prop_assert!(dxy <= dxz + dzy + 1e-9, "triangle {dxy} > {dxz} + {dzy}");
        }
    }
}
