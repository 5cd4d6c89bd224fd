//! # rothe
//!
//! A finite-element solver for the dynamics of deformable bodies, built to account for
//! where the energy goes. In space: plane-stress or plane-strain elements (Quad4,
//! Tri3) and bars; in time: the Rothe method, i.e. backward Euler in displacement
//! form (eqs. 8-10 of the paper in `../shared/paper`),
//!
//! `M (u_s − 2u_{s−1} + u_{s−2})/h² + C (u_s − u_{s−1})/h + f_int(u_s) = f_ext(t_s)`,
//!
//! with an energy ledger ([`energy`]) whose balance closes to round-off for linear
//! problems because it books the scheme's own numerical loss as its own line.
//!
//! Data flows one way: scenario file ([`config`]) → validated [`model::Model`] →
//! integrator ([`time`]) whose implicit steps go through one equilibrium loop
//! ([`nonlinear`]) → ledger ([`energy`]) and output ([`output`]). The pieces:
//! [`mesh`] (nodes, blocks, sets, generators, Gmsh), [`fe`] (reference elements,
//! element matrices), [`material`] (constitutive models, Gauss-point store,
//! material-point driver), [`assembly`] (pattern, parallel scatter, Gauss-point loop,
//! loads), [`system`] (free dofs and the factorised effective matrix), [`linsolve`]
//! (faer and CHOLMOD Cholesky behind one trait). [`run`] ties them together the way
//! the `rothe` command does. `ARCHITECTURE.md` in the repository draws the layers and
//! says where to start to add a material, a time scheme or a constraint type.

// Element and material kernels index small fixed-size arrays by component: index
// loops read like the formulas they implement.
#![allow(clippy::needless_range_loop)]

pub mod assembly;
pub mod check;
pub mod config;
pub mod contact;
pub mod energy;
pub mod error;
pub mod fe;
pub mod halves;
pub mod linsolve;
pub mod material;
pub mod memory;
pub mod mesh;
pub mod model;
pub mod nonlinear;
pub mod output;
pub mod plot;
pub mod run;
pub mod study;
pub mod system;
pub mod time;
#[doc(hidden)]
pub mod workload;

pub use error::{Error, Result};
