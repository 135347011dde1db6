//! Materials: the BRDFs and their local copies ([`brdf`]), measured BRDFs in the MERL format
//! ([`merl`]), and bringing a BRDF into a vertex's frame ([`orient`]).

pub mod brdf;
pub mod merl;
pub mod orient;
