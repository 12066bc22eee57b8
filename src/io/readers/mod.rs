//! Readers for measured data in other people's formats, producing the project's own types
//! (FRD body increments, NED, SI).

pub mod gnss_imu;
pub mod matlab;
pub mod psins;
pub mod rtklib;
