//! Correction algorithms (`DESIGN.md` §4.4; Ozbulut et al. 2013/2014): Shepard density filter and XSPH.

pub mod density_filter;
pub mod xsph;
