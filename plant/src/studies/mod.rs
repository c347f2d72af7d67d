//! The studies built on runs: the report card ([`assess`]), comparisons ([`compare`]), soaks
//! ([`soak`]), sweeps and ensembles on the point-grid engine ([`sweep`], [`ensemble`],
//! [`grid`]), benches ([`bench`]), Campbell diagrams ([`campbell`]), the linear plant
//! ([`linear`]), robustness ([`robustness`]), a law against a run ([`check`]), the fixed-step
//! methods' limits ([`stability`]). The top layer: nothing below imports them.

pub mod assess;
pub mod bench;
pub mod campbell;
pub mod check;
pub mod compare;
pub mod ensemble;
pub mod grid;
pub mod linear;
pub mod robustness;
pub mod soak;
pub mod stability;
pub mod sweep;
