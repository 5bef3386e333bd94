//! DP-TBD: dynamic-programming track-before-detect of a dim point target in a sequence of
//! `M x M` intensity images, three recursions behind one configuration ([`DpConfig`]):
//!
//! | type | recursion | paper |
//! |---|---|---|
//! | [`ArnoldDp`] | first order, hard `q_B` window | Barniv 1985; Arnold, Shaw, Pasternack 1993 |
//! | [`PulfordDp`] | first order, Kalman velocity gate | Pulford, La Scala 2010 (after Tonissen, Evans 1996) |
//! | [`SecondOrderDp`] | second order over state pairs | Wang, Zhang 2016 (eq. 12-17) |
//!
//! ```text
//! merit (eq. 5, T(z) = z):   s(theta(n..1)) = sum_k T(z_k(theta(k))) [+ sum_k ln p(.) (second order)]
//! first order (eq. 8-9):     I_k(t) = T(z_k(t)) + max_{t' in R_B(t)} I_{k-1}(t')
//! Pulford:                   t' in R_B(t) with t in R_t'(k-1) = 3x3 around t''s Kalman prediction
//! second order (eq. 13-15):  I_k(t, t') = T(z_k(t)) + max_{t'' in R_I} [I_{k-1}(t', t'') + g(e)]
//!                            t' in R_B(t),  R_I = 3x3 around 2 t' - t,  e = t'' - (2 t' - t)
//! transition (eq. 16-17):    g(e) = (sigma^2 / a_design) ln p(e),
//!                            p(e) = exp(-|e|^2 / (2 sigma_I^2)) / sum_{R_I} exp(.),  sigma_I = Delta/2
//! ```
//!
//! A pixel is indexed `(x, y)` = (column, row) of the row-major image; pixel `(x, y)`
//! covers `[x, x+1) x [y, y+1)` and its centre is `(x + 0.5, y + 0.5)`. Windows are
//! clipped at the image edges (a state whose predecessor would lie outside does not
//! exist).
//!
//! ## Integer merits
//! Each pixel is quantised once, `q = round(z / lsb)` (halves to even), clamped to
//! `+-C::ZMAX` LSB ([`MeritCell`]); the recursion then runs in exact integer arithmetic
//! on cells of type `C` (`i16` by default, `i8` to halve the merit memory). After each
//! frame the stored merits are kept relative to the previous frame's best (an exact
//! integer offset, summed in an `i64`), so they stay in range however many frames run:
//! a merit is exact unless it falls more than `C::FLOOR + C::ZMAX` LSB below the best
//! of its frame (`-16384` LSB for `i16`: 1024 intensity units at the preset's
//! `lsb = 1/16`), where it is held at the floor. Such a state is far from every track
//! that can matter; the recursion stays monotone (a larger input never lowers a merit).
//! The second-order transition term is an integer table `g(e)` (LSB) of the same units.
//!
//! ## Bad input
//! A frame of the wrong length is `Error::LengthMismatch`, a NaN or infinite pixel is
//! `Error::NonFinite`, both before any state changes. Finite pixels beyond `ZMAX` LSB
//! (e.g. `1e30`) are clamped and counted in [`DpReport::clamped`], a documented recovery
//! (clamping keeps the recursion monotone); [`first_clamped`] finds such a pixel before a
//! frame is run, for a caller that must refuse it instead. An image of equal
//! values gives every interior state the same merit; ties are broken deterministically
//! (a fixed candidate order, documented per recursion). `L = 0`, a window larger than
//! the image, a method that is not the detector's, or a bad value are
//! `Error::InvalidConfig` from [`Detector::configure`].
//!
//! ## Capacities and memory (all fixed at compile time)
//! A detector's type carries `SIDE` (`M`, the image side), `WINDOW` (`q_B`), `HISTORY`
//! (`L`, the length of a recoverable track in frames), the back-pointer storage `WORDS`
//! (`W`, derived) and the merit cell `C`. Name one with [`dp_tbd!`](crate::dp_tbd),
//! which computes `W`, or take a [`preset`]:
//!
//! ```
//! use faint_core::detect::dp::{DpConfig, Method};
//! use faint_core::detect::Detector;
//! static mut DET: faint_core::dp_tbd!(Arnold, 32, 9, 8) = faint_core::detect::dp::ArnoldDp::new_unconfigured();
//! let mut small = <faint_core::dp_tbd!(Pulford, 16, 9, 4)>::new_unconfigured();
//! small.configure(&DpConfig::dim_point(Method::Pulford, 1), 0)?;
//! # Ok::<(), faint_core::Error>(())
//! ```
//!
//! The first order keeps `L - 1` frames of back-pointers, the second order `L - 2` (its
//! state holds the last two positions); a track ending at frame `k` is recovered over
//! frames `max(1, k - L + 1) ..= k`. See each type for its formula; the const functions
//! [`arnold_words`], [`pulford_words`], [`second_order_words`] give `W` (in `u32` words),
//! which the type must match (checked at compile time).
//!
//! ## Files
//! One [`DpTbd`] (`detector.rs`) implements [`Detector`] and [`DpTrack`] for the three
//! methods over a per-method [`Recursion`] (`arnold.rs`, `pulford.rs`, `second/`);
//! `config.rs` holds the configuration, `quant.rs` the merit cells and quantiser,
//! `bits.rs` the back-pointer bit packing, `capacity.rs` the sizes and [`dp_tbd!`](crate::dp_tbd),
//! [`preset`] the instances that host and firmware share.

mod arnold;
mod bits;
mod capacity;
mod config;
mod detector;
pub mod preset;
mod pulford;
mod quant;
mod second;

pub use arnold::{ArnoldDp, ArnoldRecursion};
pub use capacity::{
    arnold_bytes, arnold_words, pulford_bytes, pulford_words, second_order_bytes,
    second_order_words, FIXED_BYTES,
};
pub use config::{transition_table, DpConfig, Method, Transition, MAX_ENDS};
pub use detector::{DpReport, DpTbd, DpTrack, Recursion, TrackEnd};
pub use pulford::{PulfordDp, PulfordRecursion};
pub use quant::{first_clamped, MeritCell};
pub use second::{SecondOrderDp, SecondOrderRecursion};

#[cfg(doc)]
use crate::detect::Detector;
