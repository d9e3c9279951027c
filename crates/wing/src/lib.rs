//! # flapssm-wing — the flapping-wing domain
//!
//! Euler-angle kinematics of a wing, random wing trajectories, the virtual robotic wing
//! (aerodynamics at three fidelities plus the experiment's sensor chain), quasi-steady
//! features, aerodynamic coefficients and stroke cycles. Uses `flapssm-data` for files.
#![warn(missing_docs)]

pub mod aero;
mod check;
pub mod cycles;
pub mod dataset;
pub mod differentiate;
pub mod features;
pub mod hovering2d;
pub mod input_jacobian;
pub mod kinematics;
pub mod lattice;
pub mod mount;
pub mod rig;
pub mod sensor;
pub mod stroke_loads;
pub mod trajectories;
mod vec3;
pub mod virtual_wing;
pub mod vortex;
