//! Clutter-only diagnostics of MHT-TBD at one lambda: DMHT cell size, the law of a cell's
//! count over all cells against the model's `P0` (eq. 25), and the make-up of each
//! period's largest cell (scans hit, runs of consecutive scans).
//! `cargo run --release --example mht_diag -- LAMBDA TRIALS`
use faint_core::rng::Rng;
use faint_host::analysis::hough_model::CellModel;
use faint_host::reproduce::mht::{detectors, model_params, NR, NT};
use faint_host::scenario::sea_clutter::SeaClutter;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let lambda: f32 = a.get(1).and_then(|s| s.parse().ok()).unwrap_or(164.0);
    let trials: u64 = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(100);
    let mut sc = SeaClutter::paper(lambda);
    sc.n_targets = 0;
    let n = sc.n_scans;
    let cm = CellModel::new(model_params(&sc));
    let mut hist = vec![0u64; n + 1];
    let (mut drho_sum, mut eff_sum) = (0.0f64, 0u64);
    let mut max_hist = vec![0u64; n + 1];
    let (mut runs3_sum, mut iso_sum, mut hits_sum, mut longest_sum) = (0u64, 0u64, 0u64, 0u64);
    for t in 0..trials {
        let mut rng = Rng::from_stream(777, t);
        let tr = sc.generate(&mut rng);
        let Ok((mut m, _)) = detectors(&sc, n as u8, n as u8) else {
            return;
        };
        for s in &tr.scans {
            let _ = m.step(&s.plots);
        }
        let g = m.dmht_geometry();
        drho_sum += f64::from(g.drho());
        let acc = m.accumulator();
        let mut best = (0u8, 0usize, 0usize);
        for aa in 0..NT {
            for r in 0..NR {
                let c = acc.count(r, aa);
                hist[usize::from(c)] += 1;
                if c > best.0 {
                    best = (c, r, aa);
                }
            }
        }
        max_hist[usize::from(best.0)] += 1;
        // scans with an effective plot in the largest cell
        let mut hit = vec![false; n];
        for (si, s) in tr.scans.iter().enumerate() {
            for (k, p) in s.plots.iter().enumerate() {
                if m.is_effective(si, k) {
                    eff_sum += 1;
                    if g.rho_index_f32(p.x, p.y, best.2) == best.1 {
                        hit[si] = true;
                    }
                }
            }
        }
        let (mut run, mut runs3, mut iso, mut longest) = (0usize, 0u64, 0u64, 0usize);
        for h in hit.iter().chain(std::iter::once(&false)) {
            if *h {
                run += 1;
            } else {
                if run >= 3 {
                    runs3 += 1;
                } else {
                    iso += run as u64;
                }
                longest = longest.max(run);
                run = 0;
            }
        }
        runs3_sum += runs3;
        iso_sum += iso;
        longest_sum += longest as u64;
        hits_sum += hit.iter().filter(|h| **h).count() as u64;
    }
    let tf = trials as f64;
    let cells = (NR * NT) as f64 * tf;
    println!(
        "lambda {lambda} trials {trials}: mean DMHT drho {:.2} m, effective plots/scan {:.2}, model p_ch {:.4}, N_c {}, m0-model p0_cross {:.4}",
        drho_sum / tf,
        eff_sum as f64 / tf / n as f64,
        cm.p_ch,
        cm.n_c,
        cm.p0_cross
    );
    println!("gamma  sim_cell_tail  model_cell_tail  sim_grid(max>=g)  model_grid");
    let mut tail = 0u64;
    let mut mtail = 0u64;
    let mut rows = Vec::new();
    for gm in (1..=n).rev() {
        tail += hist[gm];
        mtail += max_hist[gm];
        rows.push(format!(
            "{gm:>5}  {:>13.3e}  {:>15.3e}  {:>16.4}  {:>10.3e}",
            tail as f64 / cells,
            cm.pfa_cell(gm),
            mtail as f64 / tf,
            cm.pfa_grid(gm)
        ));
    }
    for r in rows.iter().rev().take(20) {
        println!("{r}");
    }
    println!(
        "largest cell per period: mean count(scans hit) {:.2}, runs >= 3 scans {:.2}, scans outside such runs {:.2}, longest run {:.2}",
        hits_sum as f64 / tf,
        runs3_sum as f64 / tf,
        iso_sum as f64 / tf,
        longest_sum as f64 / tf
    );
}
