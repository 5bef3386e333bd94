//! PSO-PHD-TBD building blocks against brute-force references: grid DBSCAN versus the
//! O(N^2) textbook DBSCAN, ENS-BS and divide-and-conquer non-dominated sorting versus
//! O(N^2) peeling; swarm invariants (proptest).

use faint::detect::phd::dbscan::{Dbscan, DbscanParams, NOISE};
use faint::detect::phd::ndsort::{dominates, non_dominated_sort};
use faint::detect::phd::pso::crowding_distance;
use faint::rng::Rng;

/// Textbook DBSCAN: neighbour lists by all-pairs scan.
fn brute_dbscan(p: &[[f32; 2]], eps: f32, min_pts: usize) -> (Vec<bool>, Vec<i32>) {
    let n = p.len();
    let e2 = eps * eps;
    let nb: Vec<Vec<usize>> = (0..n)
        .map(|i| {
            (0..n)
                .filter(|&j| {
                    let (dx, dy) = (p[i][0] - p[j][0], p[i][1] - p[j][1]);
                    dx * dx + dy * dy <= e2
                })
                .collect()
        })
        .collect();
    let core: Vec<bool> = nb.iter().map(|v| v.len() >= min_pts).collect();
    let mut lab = vec![-2i32; n];
    let mut c = 0;
    for i in 0..n {
        if lab[i] != -2 {
            continue;
        }
        if !core[i] {
            lab[i] = -1;
            continue;
        }
        lab[i] = c;
        let mut st = vec![i];
        while let Some(q) = st.pop() {
            if !core[q] {
                continue;
            }
            for &o in &nb[q] {
                if lab[o] < 0 {
                    lab[o] = c;
                    st.push(o);
                }
            }
        }
        c += 1;
    }
    (core, lab)
}

fn random_points(rng: &mut Rng, n: usize) -> Vec<[f32; 2]> {
    // Blobs of varying spread plus uniform background, on a coarse lattice sometimes so
    // that exact ties and duplicates occur.
    let blobs = 1 + rng.below(6) as usize;
    let centres: Vec<[f32; 2]> = (0..blobs)
        .map(|_| [rng.uniform_range(0.0, 200.0), rng.uniform_range(0.0, 200.0)])
        .collect();
    let lattice = rng.bernoulli(0.3);
    (0..n)
        .map(|_| {
            let mut p = if rng.bernoulli(0.2) {
                [rng.uniform_range(0.0, 200.0), rng.uniform_range(0.0, 200.0)]
            } else {
                let c = centres[rng.below(blobs as u32) as usize];
                let s = rng.uniform_range(0.5, 8.0);
                [c[0] + s * rng.normal(), c[1] + s * rng.normal()]
            };
            if lattice {
                p = [(p[0]).round(), (p[1]).round()];
            }
            p
        })
        .collect()
}

#[test]
fn grid_dbscan_matches_brute_force() {
    let mut rng = Rng::seed_from_u64(2024);
    let mut db = Box::new(Dbscan::<2048>::new());
    for case in 0..300 {
        let n = 1 + rng.below(1500) as usize;
        let pts = random_points(&mut rng, n);
        let eps = rng.uniform_range(0.5, 8.0);
        let min_pts = 1 + rng.below(15) as usize;
        let (core, lab) = brute_dbscan(&pts, eps, min_pts);
        let mut sizes = Vec::new();
        let k = db
            .run(&pts, &DbscanParams { eps, min_pts }, |m| {
                sizes.push(m.len())
            })
            .unwrap();
        let got = &db.labels[..n];
        let nclus = lab.iter().copied().max().map_or(0, |m| m + 1) as usize;
        assert_eq!(k, nclus, "case {case}: cluster count");
        assert_eq!(
            sizes.iter().sum::<usize>(),
            got.iter().filter(|&&l| l >= 0).count()
        );
        // Same noise points.
        for i in 0..n {
            assert_eq!(
                got[i] == NOISE,
                lab[i] == -1,
                "case {case}: noise point {i}"
            );
        }
        // Same partition of core points (labels may be permuted).
        let mut map = vec![-1i32; nclus];
        for i in 0..n {
            if core[i] {
                let b = lab[i] as usize;
                if map[b] < 0 {
                    map[b] = got[i];
                }
                assert_eq!(map[b], got[i], "case {case}: core point {i}");
            }
        }
        // Border points belong to a cluster with a core point within eps.
        for i in 0..n {
            if !core[i] && got[i] >= 0 {
                let ok = (0..n).any(|j| {
                    core[j] && got[j] == got[i] && {
                        let (dx, dy) = (pts[i][0] - pts[j][0], pts[i][1] - pts[j][1]);
                        dx * dx + dy * dy <= eps * eps
                    }
                });
                assert!(ok, "case {case}: border point {i}");
            }
        }
    }
}

#[test]
fn dbscan_rejects_bad_input() {
    let mut db = Box::new(Dbscan::<16>::new());
    let p = DbscanParams {
        eps: 1.0,
        min_pts: 2,
    };
    assert!(db.run(&[[0.0, f32::NAN]], &p, |_| {}).is_err());
    assert!(db.run(&[[0.0, 0.0]; 17], &p, |_| {}).is_err());
    assert!(db
        .run(
            &[[0.0, 0.0]],
            &DbscanParams {
                eps: 0.0,
                min_pts: 2
            },
            |_| {}
        )
        .is_err());
    assert_eq!(db.run(&[], &p, |_| {}).unwrap(), 0);
}

/// Reference ranks by repeated peeling of the non-dominated set.
fn brute_ranks<const M: usize>(f: &[[f32; M]], m: usize) -> Vec<u32> {
    let n = f.len();
    let mut rank = vec![u32::MAX; n];
    let mut r = 0;
    while rank.contains(&u32::MAX) {
        let cur: Vec<usize> = (0..n)
            .filter(|&i| {
                rank[i] == u32::MAX
                    && !(0..n).any(|j| rank[j] == u32::MAX && dominates(&f[j][..m], &f[i][..m]))
            })
            .collect();
        for i in cur {
            rank[i] = r;
        }
        r += 1;
    }
    rank
}

#[test]
fn ens_bs_sort_matches_brute_force_ranking() {
    let mut rng = Rng::seed_from_u64(77);
    for case in 0..400 {
        let n = 1 + rng.below(300) as usize;
        let m = 1 + rng.below(4) as usize;
        let levels = if rng.bernoulli(0.5) { 4.0 } else { 1000.0 };
        let f: Vec<[f32; 4]> = (0..n)
            .map(|_| {
                let mut v = [0.0f32; 4];
                for x in v.iter_mut() {
                    *x = (rng.uniform() * levels).floor() / levels;
                }
                v
            })
            .collect();
        let (mut rank, mut order, mut next, mut head) =
            (vec![0u32; n], vec![0u32; n], vec![0u32; n], vec![0u32; n]);
        let fronts = non_dominated_sort(&f, m, &mut rank, &mut order, &mut next, &mut head);
        let want = brute_ranks(&f, m);
        assert_eq!(rank, want, "case {case} (n={n}, m={m})");
        assert_eq!(fronts as u32, want.iter().max().unwrap() + 1);
    }
}

#[test]
fn crowding_gives_boundaries_the_maximum_and_inner_points_the_weighted_gap() {
    // One front, one objective: points 0, 1, 3, 6 -> inner gaps (3-0)/6, (6-1)/6.
    let f = [[0.0f32], [1.0], [3.0], [6.0]];
    let rank = [0u32; 4];
    let mut crowd = [0.0f32; 4];
    let mut order = [0u32; 4];
    crowding_distance(&f, 1, &[2.0], &rank, 1e9, &mut crowd, &mut order);
    assert_eq!(crowd[0], 1e9);
    assert_eq!(crowd[3], 1e9);
    assert!((crowd[1] - 2.0 * 3.0 / 6.0).abs() < 1e-6);
    assert!((crowd[2] - 2.0 * 5.0 / 6.0).abs() < 1e-6);
}

#[test]
fn divide_and_conquer_ranks_match_brute_force_with_ties_and_many_objectives() {
    // Random sets with few levels (many ties and duplicates) and with many levels, up to
    // 8 objectives, sizes around the small-case cut-offs and well above them.
    use faint::detect::phd::ndsort::{rank_sorted, Workspace};
    let mut rng = Rng::seed_from_u64(78);
    for case in 0..300 {
        let n = 1 + rng.below(if case % 3 == 0 { 600 } else { 120 }) as usize;
        let m = 1 + rng.below(8) as usize;
        let levels = [3.0f32, 6.0, 1000.0][rng.below(3) as usize];
        let mut f: Vec<[f32; 8]> = (0..n)
            .map(|_| {
                let mut v = [0.0f32; 8];
                for x in v.iter_mut() {
                    *x = (rng.uniform() * levels).floor() / levels;
                }
                v
            })
            .collect();
        // Lexicographically descending on the first m objectives.
        f.sort_by(|a, b| {
            for j in 0..m {
                match b[j].partial_cmp(&a[j]).unwrap() {
                    std::cmp::Ordering::Equal => continue,
                    o => return o,
                }
            }
            std::cmp::Ordering::Equal
        });
        let (mut rank, mut work, mut scratch, mut ord1) =
            (vec![0u32; n], vec![0u32; n], vec![0u32; n], vec![0u32; n]);
        // Garbage in the Fenwick workspace: the sort must clear it itself.
        let mut fen = vec![7u32; n];
        let ws = Workspace {
            work: &mut work,
            scratch: &mut scratch,
            order1: &mut ord1,
            fenwick: &mut fen,
        };
        let fronts = rank_sorted(n, m, |p, j| f[p][j], &mut rank, ws);
        let want = brute_ranks(&f, m);
        assert_eq!(rank, want, "case {case} (n={n}, m={m}, levels={levels})");
        assert_eq!(fronts as u32, want.iter().max().unwrap() + 1);
    }
}

mod swarm_props {
    use faint::detect::phd::pso::{PsoConfig, Swarm};
    use faint::rng::Rng;
    use proptest::prelude::*;

    type Sw = Swarm<1024, 8>;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// Swarm invariants over random points and parents: the parent count and each
        /// group's count are kept, every entry keeps its source's weight, positions and
        /// fitness stay finite (fitness in [0, 1]), and the same seed gives the same swarm.
        #[test]
        fn swarm_keeps_counts_weights_and_is_deterministic(
            seed in any::<u64>(),
            n_points in 1usize..=8,
            n in 1usize..400,
            spread in 1.0f32..80.0,
        ) {
            let mut rng = Rng::seed_from_u64(seed);
            let points: Vec<[f32; 2]> = (0..n_points)
                .map(|_| [rng.uniform_range(0.0, 300.0), rng.uniform_range(0.0, 300.0)])
                .collect();
            let mut parents = Vec::new();
            for i in 0..n {
                let g = rng.below(n_points as u32) as usize;
                let p = [
                    points[g][0] + spread * rng.normal(),
                    points[g][1] + spread * rng.normal(),
                ];
                parents.push((p, 0.5 + rng.uniform(), i as u32, g as u16));
            }
            let cfg = PsoConfig::paper();
            let run = |s: u64| {
                let mut sw = Box::new(Sw::new());
                for &(p, w, src, g) in &parents {
                    assert!(sw.push(p, w, src, g));
                }
                let rep = sw.run(&cfg, &points, &mut Rng::seed_from_u64(s));
                (sw, rep)
            };
            let (a, rep) = run(seed ^ 1);
            prop_assert_eq!(a.len, n);
            prop_assert!(rep.generations >= cfg.generations.min(cfg.max_generations));
            let mut per_group = vec![0usize; n_points];
            let mut want = vec![0usize; n_points];
            for &(_, _, _, g) in &parents {
                want[g as usize] += 1;
            }
            for k in 0..a.len {
                let src = a.src[k] as usize;
                let (_, w, _, g) = parents[src];
                per_group[g as usize] += 1;
                prop_assert_eq!(a.weight[k], w);
                prop_assert!(a.pos[k][0].is_finite() && a.pos[k][1].is_finite());
                for &f in &a.fit[k][..n_points] {
                    prop_assert!((0.0..=1.0).contains(&f));
                }
            }
            prop_assert_eq!(per_group, want);
            let (b, _) = run(seed ^ 1);
            for k in 0..n {
                prop_assert_eq!(a.pos[k][0].to_bits(), b.pos[k][0].to_bits());
                prop_assert_eq!(a.pos[k][1].to_bits(), b.pos[k][1].to_bits());
                prop_assert_eq!(a.src[k], b.src[k]);
            }
        }
    }
}
