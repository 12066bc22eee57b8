//! sinsmodel: an error-model compiler and model-discovery tool for strapdown inertial
//! navigation systems. Frames: NED navigation, FRD body; SI units and radians inside.

pub mod aiding;
pub mod align;
pub mod allan;
pub mod atomic_file;
pub mod attitude;
pub mod catalog;
pub mod covariance;
pub mod earth;
pub mod filter;
pub mod fixed;
pub mod generated;
pub mod imu;
pub mod jacobian;
pub mod model;
pub mod mounting;
pub mod nav_point;
pub mod plot;
pub mod progress;
pub mod readers;
pub mod reproduce;
pub mod rng;
pub mod scenario;
pub mod simulator;
pub mod strapdown;
pub mod trajectory;
pub mod truth;
pub mod units;
