//! Static RAM of each detector configuration (`size_of`), against the per-particle
//! budget the docs state: CRPF-TBD 41 B/particle (28 B particle state + 1 B existence
//! flag + 4 B log weight + 4 B weight + 4 B ancestor), PF-TBD 28 B (16 + 12), JOTT and PF-LRT 24 B (12 + 12), plus a
//! fixed part under 11 KB (the response table as 128 interpolation rows of 5 bins x 4
//! f32, 10 KB) besides the tables of the cached projection (3.5 KB per model at the
//! 512-bin capacity, CRPF-TBD's 20 KB cache and 4 KB previous frame, the comparators'
//! 8 KB whitener).

use faint::detect::crpf::CrpfTbd;
use faint::detect::jott::JottTbd;
use faint::detect::pf_lrt::PfLrt;
use faint::detect::pf_tbd::PfTbd;
use faint::model::doppler::MAX_BINS;
use std::mem::size_of;

fn check(name: &str, n: usize, size: usize, per: usize) {
    // Every model holds the 1.5 KB table of the quadratic ||h||^2 and the 2 KB bin
    // table (u16 per position, 2 MAX_BINS); CRPF-TBD also the 20 KB projection cache
    // (1024 x 20 B + the frame stamp) and its previous frame (MAX_BINS complex bins).
    let cache = 1536
        + 2 * 2 * MAX_BINS
        + if name == "CRPF-TBD" {
            1024 * 20 + 4 + 8 * MAX_BINS
        } else {
            // The comparators' whitener (window-aware likelihood): kernel and whitened
            // frame, MAX_BINS complex bins each, and its bin count.
            2 * 8 * MAX_BINS + 8
        };
    let fixed = size as isize - (per * n) as isize - cache as isize;
    println!("{name:9} N = {n:5}: {size:7} B ({per} B/particle + {fixed} B)");
    assert!(
        (0..11 * 1024).contains(&fixed),
        "{name} {n}: fixed part {fixed}"
    );
}

#[test]
fn static_ram_per_configuration() {
    check("CRPF-TBD", 1000, size_of::<CrpfTbd<1000>>(), 41);
    check("CRPF-TBD", 6000, size_of::<CrpfTbd<6000>>(), 41);
    check("PF-TBD", 1000, size_of::<PfTbd<1000>>(), 28);
    check("PF-TBD", 6000, size_of::<PfTbd<6000>>(), 28);
    check("JOTT", 1000, size_of::<JottTbd<1000>>(), 24);
    check("JOTT", 6000, size_of::<JottTbd<6000>>(), 24);
    check("PF-LRT", 1000, size_of::<PfLrt<1000>>(), 24);
    check("PF-LRT", 6000, size_of::<PfLrt<6000>>(), 24);
}
