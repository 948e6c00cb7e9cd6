//! Correction algorithms (`DESIGN.md` §4.4; Ozbulut et al. 2013/2014): Shepard and first-order MLS density
//! filters, XSPH and artificial particle displacement (APD).

pub mod apd;
pub mod density_filter;
pub mod mls;
pub mod xsph;
