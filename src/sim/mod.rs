//! Simulation: scenario files, analytic trajectories, the IMU simulator that injects any spec
//! term, and the seeded random-number generator.

pub mod budget;
pub mod hidden;
pub mod rng;
pub mod scenario;
pub mod simulator;
pub mod trajectory;
