//! DBSCAN's pending-member search against the search it replaced
//! (`dbscan_reference.rs`: every query read every member of each cell of its 5 x 5 block
//! that still had a free point): the same labels, the same clusters in the same order,
//! each with the same members in the same order (the filter sums an estimate over its
//! cluster's members in that order, so the estimates keep their bits), on random point
//! sets with blobs, background, duplicates, lattice ties and copies at consecutive indices
//! (proptest), and on particle clouds the size of the filter's.

use super::dbscan_reference;
use faint::detect::phd::dbscan::{Dbscan, DbscanParams};
use faint::rng::Rng;
use proptest::prelude::*;

/// (labels, members of each cluster in call order, cluster count) of both versions.
type Out = (Vec<i32>, Vec<Vec<u32>>, usize);

fn new_search<const N: usize>(db: &mut Dbscan<N>, pts: &[[f32; 2]], p: &DbscanParams) -> Out {
    let mut clusters = Vec::new();
    let k = db.run(pts, p, |m| clusters.push(m.to_vec())).unwrap();
    (db.labels[..pts.len()].to_vec(), clusters, k)
}

fn old_search<const N: usize>(
    db: &mut dbscan_reference::Dbscan<N>,
    pts: &[[f32; 2]],
    p: &DbscanParams,
) -> Out {
    let mut clusters = Vec::new();
    let k = db.run(pts, p, |m| clusters.push(m.to_vec())).unwrap();
    (db.labels[..pts.len()].to_vec(), clusters, k)
}

/// Each point of `p` repeated 1 to `copies` times at consecutive indices, as a resampled
/// particle cloud holds its copies of one particle, cut to `n` points.
fn with_copies(rng: &mut Rng, p: Vec<[f32; 2]>, copies: u32, n: usize) -> Vec<[f32; 2]> {
    let mut out = Vec::with_capacity(n);
    for q in p {
        for _ in 0..1 + rng.below(copies.max(1)) {
            out.push(q);
        }
    }
    out.truncate(n);
    out
}

/// Blobs of spread `spread` (metres) plus a uniform background over `extent`, snapped to
/// a lattice of `lattice` metres when it is positive (ties and duplicates).
fn points(
    rng: &mut Rng,
    n: usize,
    blobs: usize,
    spread: f32,
    extent: f32,
    lattice: f32,
) -> Vec<[f32; 2]> {
    let centres: Vec<[f32; 2]> = (0..blobs.max(1))
        .map(|_| {
            [
                rng.uniform_range(0.0, extent),
                rng.uniform_range(0.0, extent),
            ]
        })
        .collect();
    (0..n)
        .map(|_| {
            let mut p = if rng.bernoulli(0.15) {
                [
                    rng.uniform_range(0.0, extent),
                    rng.uniform_range(0.0, extent),
                ]
            } else {
                let c = centres[rng.below(centres.len() as u32) as usize];
                [c[0] + spread * rng.normal(), c[1] + spread * rng.normal()]
            };
            if lattice > 0.0 {
                p = [
                    (p[0] / lattice).round() * lattice,
                    (p[1] / lattice).round() * lattice,
                ];
            }
            p
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn pending_search_equals_the_full_scan(
        seed in any::<u64>(),
        n in 1usize..1500,
        blobs in 1usize..7,
        spread in 0.3f32..30.0,
        extent in 10.0f32..3000.0,
        lattice in prop_oneof![Just(0.0f32), 0.5f32..4.0],
        eps in 0.3f32..12.0,
        min_pts in 1usize..20,
        copies in prop_oneof![Just(1u32), 2u32..40],
    ) {
        let mut rng = Rng::seed_from_u64(seed);
        let pts = points(&mut rng, n, blobs, spread, extent, lattice);
        let pts = with_copies(&mut rng, pts, copies, n);
        let p = DbscanParams { eps, min_pts };
        let mut new = Box::new(Dbscan::<1500>::new());
        let mut old = Box::new(dbscan_reference::Dbscan::<1500>::new());
        let a = new_search(&mut new, &pts, &p);
        let b = old_search(&mut old, &pts, &p);
        prop_assert_eq!(a, b);
    }
}

/// The filter's case: 6144 points in clouds of a few metres (the preset's eps 5 m,
/// min_pts 10), the workspace reused from run to run as the filter does.
#[test]
fn pending_search_equals_the_full_scan_on_particle_clouds() {
    let mut rng = Rng::seed_from_u64(2026);
    let mut new = Box::new(Dbscan::<6144>::new());
    let mut old = Box::new(dbscan_reference::Dbscan::<6144>::new());
    for case in 0..40 {
        let n = 500 + rng.below(5645) as usize;
        let spread = rng.uniform_range(1.0, 25.0);
        let blobs = 1 + rng.below(6) as usize;
        let pts = points(&mut rng, n, blobs, spread, 2800.0, 0.0);
        // Copies at consecutive indices (resampling) in most cases, up to 400 of one
        // particle.
        let copies = [1, 4, 50, 400][case % 4];
        let pts = with_copies(&mut rng, pts, copies, n);
        for (eps, min_pts) in [
            (5.0, 10),
            (rng.uniform_range(1.0, 10.0), 1 + rng.below(30) as usize),
        ] {
            let p = DbscanParams { eps, min_pts };
            let a = new_search(&mut new, &pts, &p);
            let b = old_search(&mut old, &pts, &p);
            assert_eq!(a, b, "case {case}, eps {eps}, min_pts {min_pts}");
        }
    }
}
