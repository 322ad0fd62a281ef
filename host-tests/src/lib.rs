//! Host side of `mccs`: the `f64` reference implementation, parameter files, and the
//! `mccs` command-line tool. The reference is written independently of the fixed-point
//! core (it shares only the parameter struct and its validation rules) so that the
//! tests can catch the core's mistakes.
#![deny(missing_docs)]

pub mod arm;
pub mod cli;
pub mod eigenvalues;
pub mod fit;
pub mod fuzz_checks;
pub mod link;
pub mod patch;
pub mod reference;
pub mod replay;
pub mod roam;
pub mod stability;
pub mod view;

pub use mccs_client::{paramfile, trajectory};
