//! # rothe
//!
//! A finite-element solver for the dynamics and contact of deformable bodies, built
//! to account for where the energy goes. In space: plane stress, plane strain and
//! solids (Quad4, Tri3, Hex8, Tet4) and bars; in time: the Rothe method, i.e.
//! backward Euler in displacement form (eqs. 8-10 of the paper in `../shared/paper`),
//!
//! `M (u_s − 2u_{s−1} + u_{s−2})/h² + C (u_s − u_{s−1})/h + f_int(u_s) = f_ext(t_s)`,
//!
//! the trapezoidal rule and generalized-α beside it, and central differences for
//! comparison; contact as a convex program per step or kinematically; an energy
//! ledger ([`energy`]) whose balance closes to round-off for linear problems because
//! it books each scheme's own numerical loss as its own line.
//!
//! Data flows one way: scenario file ([`config`]) → validated [`model::Model`] →
//! integrator ([`time`]) whose implicit steps go through one equilibrium loop
//! ([`nonlinear`]) → ledger ([`energy`]) and output ([`output`]). The floors, from
//! the ground: [`fe`] (reference elements, and the kinematics of plane stress, plane
//! strain and solids behind one trait: where the dimension enters), [`mesh`],
//! [`material`] (the constitutive interface, one file per model, the Gauss-point
//! store), [`assembly`] (pattern, parallel scatter, Gauss-point pass, nonlocal
//! averaging, loads), [`system`] and [`linsolve`] (the factorised effective matrix;
//! faer, CHOLMOD and rothe's own supernodal solves), [`nonlinear`], [`contact`],
//! [`time`], [`output`]; on top the applications: [`run`] (what `rothe run` does),
//! [`check`], [`point_driver`] (`rothe material`), [`study`] and [`plot`].
//! `ARCHITECTURE.md` in the repository draws the floors and says where a dimension,
//! a material, a scheme and an element enter.

// Element and material kernels index small fixed-size arrays by component: index
// loops read like the formulas they implement.
#![warn(missing_docs)]
#![allow(clippy::needless_range_loop)]

pub mod assembly;
pub mod buffers;
pub mod check;
pub mod config;
pub mod contact;
pub mod energy;
pub mod error;
pub mod fe;
pub mod geometry;
pub mod halves;
pub mod linsolve;
pub mod material;
pub mod memory;
pub mod mesh;
pub mod modal;
pub mod model;
pub mod nonlinear;
pub mod output;
pub mod plot;
pub mod point_driver;
pub mod run;
pub mod simd;
pub mod study;
pub mod system;
pub mod time;

pub use error::{Error, Result};
