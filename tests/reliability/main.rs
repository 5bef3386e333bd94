//! Reliability: regression tests for every configuration that validated but misbehaved,
//! the replay of the fuzz corpus, and a short fuzz campaign over every detector.
//!
//! `cargo test` builds with overflow checks and debug assertions on (the test profile
//! inherits them from `dev` and is optimised), so an arithmetic overflow here is a panic,
//! as on a checked firmware build. `checked_build` proves it.

mod campaign;
mod findings;
mod guided;

#[test]
fn checked_build() {
    assert!(
        faint::host::reliability::overflow_checks_on(),
        "the reliability tests must run with overflow checks on"
    );
    const { assert!(cfg!(debug_assertions)) };
}
