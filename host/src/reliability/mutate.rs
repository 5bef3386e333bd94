//! Configuration mutation: a detector's configuration as JSON, with a few of its numbers
//! (or flags) replaced by values chosen to break arithmetic.
//!
//! Every leaf is reachable: the mutator collects the JSON pointers of all numbers and
//! booleans and rewrites one to three of them. Floats become an extreme (`0`, `-0`, the
//! smallest normal, `1e-30`, `1e30`, `3e38`, their negatives), a power-of-ten rescale of
//! the preset value (`x * 10^k`, `k in [-12, 12]`), or the negative of the preset value.
//! Integers become a small count (0-5), a power of two, the preset value plus or minus
//! one, or a limit (`u16::MAX`, `u32::MAX`, `u64::MAX`). A float written where an
//! integer is expected (and the reverse) is left to the parser to reject.

use faint_core::rng::Rng;
use serde_json::{Number, Value};

/// Float replacements that stress the arithmetic.
pub const FLOATS: [f64; 16] = [
    0.0,
    -0.0,
    1.175_494_4e-38,
    1e-30,
    1e-9,
    1e-3,
    0.5,
    1.0,
    2.0,
    1e6,
    1e21,
    1e30,
    3e38,
    -1.0,
    -1e30,
    -3e38,
];

/// Integer replacements.
pub const INTS: [u64; 16] = [
    0,
    1,
    2,
    3,
    4,
    5,
    8,
    64,
    255,
    256,
    4096,
    65_535,
    65_536,
    1_000_000,
    u32::MAX as u64,
    u64::MAX,
];

/// JSON pointers of every number and boolean leaf of `v`.
pub fn leaves(v: &Value) -> Vec<String> {
    fn walk(v: &Value, path: &mut String, out: &mut Vec<String>) {
        match v {
            Value::Number(_) | Value::Bool(_) => out.push(path.clone()),
            Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    let n = path.len();
                    path.push('/');
                    path.push_str(&i.to_string());
                    walk(x, path, out);
                    path.truncate(n);
                }
            }
            Value::Object(o) => {
                for (k, x) in o {
                    let n = path.len();
                    path.push('/');
                    path.push_str(&k.replace('~', "~0").replace('/', "~1"));
                    walk(x, path, out);
                    path.truncate(n);
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(v, &mut String::new(), &mut out);
    out
}

/// Rewrites one to three leaves of `v` (see the module doc). Returns the pointers changed.
pub fn mutate(v: &mut Value, rng: &mut Rng) -> Vec<String> {
    let all = leaves(v);
    if all.is_empty() {
        return Vec::new();
    }
    let n = 1 + rng.below(3) as usize;
    let mut changed = Vec::with_capacity(n);
    for _ in 0..n {
        let p = &all[rng.below(all.len() as u32) as usize];
        if let Some(leaf) = v.pointer_mut(p) {
            *leaf = mutate_leaf(leaf, rng);
            changed.push(p.clone());
        }
    }
    changed
}

fn pick<T: Copy>(rng: &mut Rng, xs: &[T]) -> T {
    xs[rng.below(xs.len() as u32) as usize]
}

fn float(x: f64) -> Value {
    Number::from_f64(x).map_or(Value::Null, Value::Number)
}

fn mutate_leaf(leaf: &Value, rng: &mut Rng) -> Value {
    match leaf {
        Value::Bool(b) => Value::Bool(!b),
        Value::Number(n) if n.is_u64() || n.is_i64() => {
            let x = n.as_i64().unwrap_or(i64::MAX);
            match rng.below(8) {
                0..=3 => Value::from(pick(rng, &INTS)),
                4 => Value::from(x.saturating_add(1)),
                5 => Value::from(x.saturating_sub(1)),
                6 => Value::from(x.saturating_mul(2)),
                _ => Value::from(-x),
            }
        }
        Value::Number(n) => {
            let x = n.as_f64().unwrap_or(0.0);
            match rng.below(8) {
                0..=3 => float(pick(rng, &FLOATS)),
                4 | 5 => {
                    let k = rng.below(25) as i32 - 12;
                    float(x * 10f64.powi(k))
                }
                6 => float(-x),
                _ => float(x * (1.0 + 1e-6)),
            }
        }
        other => other.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_leaf_is_found_and_changed() {
        let v: Value = serde_json::json!({"a": 1.5, "b": [1, 2, {"c": true}], "d/e": 3});
        let l = leaves(&v);
        assert_eq!(l, ["/a", "/b/0", "/b/1", "/b/2/c", "/d~1e"]);
        let mut rng = Rng::seed_from_u64(1);
        let mut hit = std::collections::BTreeSet::new();
        for _ in 0..200 {
            let mut w = v.clone();
            for p in mutate(&mut w, &mut rng) {
                hit.insert(p);
            }
        }
        assert_eq!(hit.len(), l.len());
    }
}
