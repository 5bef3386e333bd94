//! DP-TBD (Barniv 1985, Arnold et al. 1993; Pulford, La Scala 2010; Wang, Zhang 2016): the
//! recursions against exhaustive search, bad input, and properties. One test binary for
//! the family.

mod analysis;
mod detector;
