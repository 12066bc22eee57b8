//! Navigation: the WGS-84 Earth model, attitude conversions, the linearisation point of A(t)
//! and H, and the strapdown navigator (NED navigation frame, FRD body frame).

pub mod attitude;
pub mod earth;
pub mod free_inertial;
pub mod nav_point;
pub mod nav_rows;
pub mod strapdown;
