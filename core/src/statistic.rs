//! Test statistics over a sequence of `K` per-frame existence probabilities
//! (Lu, Wang, Zhang 2017, eq. 13 and eq. 14).

use crate::{Error, Result};

/// Largest `K` that [`d_k`] sorts in its fixed buffer.
pub const MAX_FRAMES: usize = 256;

fn check(values: &[f32]) -> Result<()> {
    if values.is_empty() {
        return Err(Error::Empty);
    }
    if values.iter().any(|v| !v.is_finite()) {
        return Err(Error::NonFinite);
    }
    Ok(())
}

/// `zeta_K = max_k P_E^k` (eq. 13, "-max"). Errors: [`Error::Empty`] for `K = 0`,
/// [`Error::NonFinite`].
pub fn zeta_k(values: &[f32]) -> Result<f32> {
    check(values)?;
    Ok(values.iter().fold(f32::NEG_INFINITY, |a, &b| a.max(b)))
}

/// The zero-based sorted indices `D_K` averages: the middle 4 for even `K >= 4`
/// (`K/2 - 2 ..= K/2 + 1`, i.e. 14..=17 for `K = 32`), the middle 3 for odd `K >= 3`
/// (`(K-1)/2 - 1 ..= (K-1)/2 + 1`), all values for `K <= 2` (empty for `K = 0`).
pub fn middle_range(k: usize) -> core::ops::Range<usize> {
    match k {
        0..=2 => 0..k,
        _ if k.is_multiple_of(2) => k / 2 - 2..k / 2 + 2,
        _ => (k - 1) / 2 - 1..(k - 1) / 2 + 2,
    }
}

/// `D_K = mean of the middle values of sort(P_E^1..P_E^K)` (eq. 14, "-mean"); see
/// [`middle_range`]. Errors: [`Error::Empty`], [`Error::NonFinite`],
/// [`Error::Capacity`] for `K > MAX_FRAMES`.
pub fn d_k(values: &[f32]) -> Result<f32> {
    check(values)?;
    if values.len() > MAX_FRAMES {
        return Err(Error::Capacity {
            capacity: MAX_FRAMES,
            requested: values.len(),
        });
    }
    let mut buf = [0.0f32; MAX_FRAMES];
    let s = &mut buf[..values.len()];
    s.copy_from_slice(values);
    s.sort_unstable_by(|a, b| a.total_cmp(b));
    let r = middle_range(values.len());
    let n = r.len() as f32;
    let mut acc = 0.0f32;
    for i in r {
        acc += s[i];
    }
    Ok(acc / n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn middle_of_32_is_14_to_17() {
        assert_eq!(middle_range(32), 14..18);
        assert_eq!(middle_range(5), 1..4);
        assert_eq!(middle_range(2), 0..2);
        let v: [f32; 32] = core::array::from_fn(|i| (31 - i) as f32);
        assert_eq!(d_k(&v).unwrap(), (14.0 + 15.0 + 16.0 + 17.0) / 4.0);
        assert_eq!(zeta_k(&v).unwrap(), 31.0);
        assert_eq!(d_k(&[]), Err(Error::Empty));
        assert_eq!(zeta_k(&[1.0, f32::NAN]), Err(Error::NonFinite));
    }
}
