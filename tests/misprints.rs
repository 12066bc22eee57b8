//! Each misprint of the paper's printed A(t) (DESIGN §4 table) has a test that would catch it:
//! the generated entry equals the corrected formula and differs from the printed one at a point
//! where the two differ.

use nalgebra::Vector3;
use sinsmodel::model::Model;
use sinsmodel::nav::attitude::dcm_from_euler;
use sinsmodel::nav::earth::OMEGA;
use sinsmodel::nav::nav_point::NavPoint;

struct Filled {
    m: Model,
    a: Vec<f64>,
    nav: NavPoint,
    f: Vector3<f64>,
    w: Vector3<f64>,
}

impl Filled {
    fn new(model: &str) -> Filled {
        let m = Model::parse(model).unwrap();
        let c = dcm_from_euler(0.3, -0.2, 1.1);
        let f = Vector3::new(3.0, -2.0, -9.0);
        let w = Vector3::new(0.2, -0.4, 0.7);
        let nav = NavPoint::new(0.6, 250.0, Vector3::new(120.0, 80.0, -3.0), &c, &f);
        let mut acc = m.accumulator();
        acc.add(&sinsmodel::model::ImuSignals::new(f, w));
        let mut a = vec![0.0; m.n() * m.n()];
        m.fill_a(&nav, &acc.mean(), &mut a);
        Filled { m, a, nav, f, w }
    }
    fn at(&self, row: &str, col: &str) -> f64 {
        let n = self.m.n();
        self.a[self.m.index_of(row).unwrap() * n + self.m.index_of(col).unwrap()]
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs())
}

#[test]
fn misprint_1_phi_d_dlat_uses_cos_squared() {
    let x = Filled::new("P31");
    let (lat, ve, rn) = (x.nav.lat, x.nav.v_ned[1], x.nav.rn);
    let correct = -OMEGA * lat.cos() - ve / (rn * lat.cos().powi(2));
    let printed = -OMEGA * lat.cos() - ve / (rn * (2.0 * lat).cos());
    assert!(close(x.at("phi_d", "dlat"), correct));
    assert!(!close(x.at("phi_d", "dlat"), printed));
}

#[test]
fn misprint_2_dv_n_dlat_has_no_tan() {
    let x = Filled::new("P31");
    let (lat, ve, rn) = (x.nav.lat, x.nav.v_ned[1], x.nav.rn);
    let correct = -ve * (2.0 * OMEGA * lat.cos() + ve / (rn * lat.cos().powi(2)));
    let printed = -ve * (2.0 * OMEGA * lat.cos() + ve * lat.tan() / (rn * lat.cos().powi(2)));
    assert!(close(x.at("dv_n", "dlat"), correct));
    assert!(!close(x.at("dv_n", "dlat"), printed));
}

#[test]
fn misprint_3_gyro_scale_block_uses_the_right_dcm_element() {
    // phi rows, kg_32 column (z gyro, regressor w_y): -C[:,3] w_y; the print has C12 w_y in row 3.
    let x = Filled::new("P31");
    let c = &x.nav.c;
    assert!(close(x.at("phi_d", "kg_32"), -c[2][2] * x.w.y));
    assert!(!close(x.at("phi_d", "kg_32"), -c[0][1] * x.w.y));
    for (k, row) in ["phi_n", "phi_e", "phi_d"].iter().enumerate() {
        assert!(close(x.at(row, "kg_22"), -c[k][1] * x.w.y));
        assert!(close(x.at(row, "kg_32"), -c[k][2] * x.w.y));
        assert!(close(x.at(row, "kg_33"), -c[k][2] * x.w.z));
        assert!(close(x.at(row, "kg_21"), -c[k][1] * x.w.x));
    }
}

#[test]
fn misprint_4_all_parameter_rows_are_zero() {
    // The print's last block row is 0(2x3); it must be 0(24x3): every one of the 24 parameter
    // rows of P31 is zero, including under the d columns.
    let x = Filled::new("P31");
    let n = x.m.n();
    assert_eq!(n, 31);
    for i in 7..n {
        assert!(
            x.a[i * n..(i + 1) * n].iter().all(|v| *v == 0.0),
            "row {}",
            x.m.names[i]
        );
    }
    assert!(x.at("dv_n", "d_x") != 0.0);
}

#[test]
fn misprint_5_quadratic_term_uses_the_square() {
    let x = Filled::new("P31");
    let c = &x.nav.c;
    for (i, d) in ["d_x", "d_y", "d_z"].iter().enumerate() {
        for (k, row) in ["dv_n", "dv_e"].iter().enumerate() {
            assert!(close(x.at(row, d), c[k][i] * x.f[i] * x.f[i]), "{row} {d}");
            assert!(!close(x.at(row, d), c[k][i] * x.f[i]), "{row} {d}");
        }
    }
}

#[test]
fn misprint_6_height_error_rate_is_minus_dv_d() {
    // dh' = -dv_d: the dh row has exactly one non-zero, -1 under dv_d, whatever v_D is.
    let x = Filled::new("P31+vertical");
    let n = x.m.n();
    let row = x.m.index_of("dh").unwrap();
    let nz: Vec<(usize, f64)> = (0..n)
        .map(|j| (j, x.a[row * n + j]))
        .filter(|(_, v)| *v != 0.0)
        .collect();
    assert_eq!(nz, vec![(x.m.index_of("dv_d").unwrap(), -1.0)]);
    assert!(x.nav.v_ned[2] != 0.0);
}
