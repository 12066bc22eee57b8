//! Bad spec input fails with one message naming the file, the line, the item and the problem;
//! a new term is one spec entry.

use sinsmodel_codegen::{generate, Layout, Spec};
use std::path::{Path, PathBuf};

fn spec_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../model-spec")
}

/// Copies the real spec into a temp dir, applies `edit(file name, text) -> text`, loads it.
fn load_edited(
    edit: impl Fn(&str, String) -> String,
) -> (
    tempfile::TempDir,
    Result<Spec, sinsmodel_codegen::SpecError>,
) {
    let dir = tempfile::tempdir().unwrap();
    for f in sinsmodel_codegen::spec::SPEC_FILES {
        let text = std::fs::read_to_string(spec_dir().join(f)).unwrap();
        std::fs::write(dir.path().join(f), edit(f, text)).unwrap();
    }
    let r = Spec::load(dir.path());
    (dir, r)
}

/// 1-based line of the last line containing `needle`.
fn line_of(dir: &Path, file: &str, needle: &str) -> usize {
    let text = std::fs::read_to_string(dir.join(file)).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    lines
        .iter()
        .rposition(|l| l.contains(needle))
        .expect("needle present")
        + 1
}

fn expect_error(file: &str, from: &str, to: &str, needle_line: &str, item: &str, problem: &str) {
    let (dir, r) = load_edited(|f, t| {
        if f == file {
            t.replacen(from, to, 1)
        } else {
            t
        }
    });
    let e = r.expect_err("the edited spec must be rejected");
    let msg = e.to_string();
    assert!(msg.contains(file), "message names the file: {msg}");
    assert!(msg.contains(item), "message names the item `{item}`: {msg}");
    assert!(
        msg.contains(problem),
        "message names the problem `{problem}`: {msg}"
    );
    let want = line_of(dir.path(), file, needle_line);
    assert_eq!(e.line, want, "line of: {msg}");
}

#[test]
fn the_real_spec_loads() {
    let spec = Spec::load(&spec_dir()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(spec.nav_states.len(), 9);
    // counts are derived, not hard-coded: the library is exactly the terms no preset contains
    for t in &spec.terms {
        let in_preset = spec.presets.iter().any(|p| p.states.contains(&t.name));
        assert_eq!(
            t.library, !in_preset,
            "term `{}`: `library = true` exactly when no preset has it",
            t.name
        );
    }
    let p31 = spec.presets.iter().find(|p| p.name == "P31").unwrap();
    assert_eq!(
        p31.states.len(),
        31,
        "P31 (written as base P28 + d) has 31 states"
    );
    let names: Vec<_> = spec.presets.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["P13", "P24", "P28", "P31"]);
}

#[test]
fn unknown_symbol_in_a_regressor() {
    expect_error(
        "terms.toml",
        "regressor = \"f.x * f.y\"",
        "regressor = \"f.x * g.y\"",
        "g.y",
        "term `kaq_x_xy`",
        "unknown signal `g.y`",
    );
}

#[test]
fn unknown_symbol_in_the_navigation_block() {
    expect_error(
        "navigation.toml",
        "expr = \"vn / rm\"",
        "expr = \"vn / rmm\"",
        "vn / rmm",
        "A entry (phi_n, phi_d)",
        "unknown symbol `rmm`",
    );
}

#[test]
fn syntax_error_in_an_expression() {
    expect_error(
        "terms.toml",
        "regressor = \"w.x\"",
        "regressor = \"w.x *\"",
        "regressor = \"w.x *\"",
        "term `kg_11`",
        "syntax error",
    );
}

#[test]
fn a_limit_below_the_prior() {
    expect_error(
        "terms.toml",
        "limit = \"100 ms\"",
        "limit = \"0.1 ms\"",
        "limit = \"0.1 ms\"",
        "term `tau_x`",
        "limit must be larger than sigma",
    );
}

#[test]
fn duplicate_term_name() {
    expect_error(
        "terms.toml",
        "name = \"eps_y\"",
        "name = \"eps_x\"",
        "name = \"eps_x\"",
        "term `eps_x`",
        "duplicate name",
    );
}

#[test]
fn preset_naming_a_missing_term() {
    expect_error(
        "presets.toml",
        "\nterms = [\"d_x\", \"d_y\", \"d_z\"]",
        "\nterms = [\"d_x\", \"d_y\", \"d_q\"]",
        "name = \"P31\"",
        "preset `P31`",
        "missing term `d_q`",
    );
}

#[test]
fn wrong_sensor_and_axis() {
    expect_error(
        "terms.toml",
        "sensor = \"accel\"",
        "sensor = \"acel\"",
        "acel",
        "term `nabla_x`",
        "unknown sensor `acel`",
    );
    expect_error(
        "terms.toml",
        "axis = \"z\"",
        "axis = \"w\"",
        "axis = \"w\"",
        "term `eps_z`",
        "unknown axis `w`",
    );
}

#[test]
fn wrong_unit() {
    expect_error(
        "terms.toml",
        "sigma = \"0.02 deg/h\"",
        "sigma = \"0.02 m/s\"",
        "0.02 m/s",
        "term `eps_x`",
        "dimension",
    );
}

#[test]
fn malformed_toml() {
    let (_d, r) = load_edited(|f, t| {
        if f == "presets.toml" {
            t.replacen("states = [", "states = [[", 1)
        } else {
            t
        }
    });
    let msg = r.unwrap_err().to_string();
    assert!(msg.contains("presets.toml:"), "{msg}");
}

#[test]
fn missing_spec_file() {
    let dir = tempfile::tempdir().unwrap();
    let msg = Spec::load(dir.path()).unwrap_err().to_string();
    assert!(
        msg.contains("navigation.toml") && msg.contains("cannot read"),
        "{msg}"
    );
}

/// Adding a term is one entry in terms.toml: its column appears in the generated code and in
/// any model that adds it, with nothing else edited.
#[test]
fn a_new_term_is_one_spec_entry() {
    let entry = "\n[[term]]\nname = \"kgt_x\"\nsensor = \"gyro\"\naxis = \"x\"\nregressor = \"w.x * f.z\"\nunit = \"s^2/m\"\ndisplay = \"s^2/m\"\nsigma = \"1e-6 s^2/m\"\ngroup = \"test\"\nlibrary = true\ndoc = \"test term\"\n";
    let (_d, r) = load_edited(|f, t| if f == "terms.toml" { t + entry } else { t });
    let spec = r.unwrap_or_else(|e| panic!("{e}"));
    let t = spec.term_index("kgt_x").expect("new term loaded");
    let files = generate(&spec);
    let common = &files.iter().find(|f| f.module == "common").unwrap().text;
    assert!(
        common.contains("name: \"kgt_x\""),
        "catalogue lists the new term"
    );
    assert!(
        common.contains("// A[phi_n][kgt_x] = -C11 * <w.x * f.z>"),
        "column comment present"
    );
    assert!(common.contains("w.x * f.z"), "regressor evaluated");
    // in a model P28 + kgt_x, the new column fills the three attitude rows with -C[:,0] <w.x f.z>
    let p28 = spec.presets.iter().position(|p| p.name == "P28").unwrap();
    let mut layout = Layout::preset(&spec, p28, false);
    layout.states.push(sinsmodel_codegen::StateRef::Term(t));
    let col = layout.states.len() - 1;
    let entries: Vec<_> = layout
        .a_entries(&spec)
        .into_iter()
        .filter(|e| e.col == col)
        .collect();
    let rows: Vec<_> = entries
        .iter()
        .map(|e| layout.state_name(&spec, e.row))
        .collect();
    assert_eq!(rows, ["phi_n", "phi_e", "phi_d"]);
    assert_eq!(entries[2].comment, "-C31 * <w.x * f.z>");
}

/// A term's unit times its regressor's dimension must be the sensor's (issue: `m` for an
/// accelerometer regressor `f.y * f.z` used to load).
#[test]
fn unit_inconsistent_with_the_regressor_and_sensor() {
    expect_error(
        "terms.toml",
        "unit = \"s^2/m\"\ndisplay = \"ug/g^2\"",
        "unit = \"m*1\"\ndisplay = \"m\"",
        "unit = \"m*1\"",
        "term `d_x`",
        "an accelerometer error is in m/s^2: the unit should be m^-1*s^2",
    );
    // a gyro term with an accelerometer's unit
    expect_error(
        "terms.toml",
        "unit = \"rad/s\"",
        "unit = \"m/s^2*1\"",
        "unit = \"m/s^2*1\"",
        "term `eps_x`",
        "a gyro error is in rad/s",
    );
}

#[test]
fn powi_exponent_is_bounded() {
    expect_error(
        "terms.toml",
        "regressor = \"f.x.powi(2)\"",
        "regressor = \"f.x.powi(2147483647)\"",
        "2147483647",
        "term `d_x`",
        "out of range",
    );
}

#[test]
fn preset_with_an_unknown_base_or_both_forms() {
    expect_error(
        "presets.toml",
        "\nbase = \"P28\"",
        "\nbase = \"P99\"",
        "base = \"P99\"",
        "preset `P31`",
        "base `P99` is not a preset defined above it",
    );
    expect_error(
        "presets.toml",
        "name = \"P13\"",
        "name = \"P28\"",
        "name = \"P28\"",
        "preset `P28`",
        "duplicate preset",
    );
}

#[test]
fn white_noise_source_must_exist_and_fit_the_state() {
    expect_error(
        "navigation.toml",
        "white_noise = \"gyro_arw\"",
        "white_noise = \"gyro_arv\"",
        "gyro_arv",
        "state `phi_n`",
        "unknown source `gyro_arv`",
    );
    expect_error(
        "navigation.toml",
        "white_noise = \"gyro_arw\"",
        "white_noise = \"accel_vrw\"",
        "name = \"phi_n\"",
        "state `phi_n`",
        "cannot be driven",
    );
}

/// A user preset written as base + terms compiles to its own generated module.
#[test]
fn a_user_preset_compiles_to_its_own_kernels() {
    let entry = "\n[[preset]]\nname = \"P28kaq\"\ndoc = \"test\"\nbase = \"P28\"\nterms = [\"kaq_x_xy\", \"kgf_xz\"]\n";
    let (_d, r) = load_edited(|f, t| if f == "presets.toml" { t + entry } else { t });
    let spec = r.unwrap_or_else(|e| panic!("{e}"));
    let files = generate(&spec);
    let m = files
        .iter()
        .find(|f| f.module == "p28kaq")
        .expect("module for the user preset");
    assert!(m.text.contains("pub const N: usize = 30;"), "30 states");
    assert!(files.iter().any(|f| f.module == "p28kaq_vertical"));
    // and the library flag check of `the_real_spec_loads` would now flag the two terms
    assert!(spec.terms.iter().any(|t| t.name == "kaq_x_xy" && t.library));
}

#[test]
fn grade_errors_name_the_grade_and_the_problem() {
    expect_error(
        "grades.toml",
        "\"gyro bias\" = \"1 deg/h\"",
        "\"gyro bias\" = \"1 mg\"",
        "\"gyro bias\" = \"1 mg\"",
        "grade `tactical`",
        "groups.\"gyro bias\" for term `eps_x`",
    );
    expect_error(
        "grades.toml",
        "\"accel bias\" = \"1 mg\"",
        "\"accel biases\" = \"1 mg\"",
        "accel biases",
        "grade `tactical`",
        "no term has group `accel biases`",
    );
    expect_error(
        "grades.toml",
        "phi_d = \"1 deg\"",
        "phi_z = \"1 deg\"",
        "phi_z",
        "grade `tactical`",
        "no navigation state `phi_z`",
    );
    expect_error(
        "grades.toml",
        "unlisted = { gyro = 50.0,",
        "unlisted = { gyro = -50.0,",
        "gyro = -50.0",
        "grade `tactical`",
        "positive and finite",
    );
    expect_error(
        "grades.toml",
        "name = \"mems\"",
        "name = \"navigation\"",
        "name = \"navigation\"",
        "grade `navigation`",
        "duplicate grade",
    );
    expect_error(
        "terms.toml",
        "doc = \"x gyro constant bias\"",
        "doc = \"x gyro constant bias\"\ngrade_sigma = { consumer = \"1 deg/s\" }",
        "consumer",
        "term `eps_x`",
        "no grade `consumer` in grades.toml",
    );
    expect_error(
        "terms.toml",
        "doc = \"x gyro constant bias\"",
        "doc = \"x gyro constant bias\"\ngrade_sigma = { mems = \"1 mg\" }",
        "grade_sigma = { mems",
        "term `eps_x`",
        "grade_sigma.mems",
    );
}

#[test]
fn a_term_prior_comes_from_the_term_then_its_group_then_the_unlisted_rule() {
    use sinsmodel_codegen::grades::GradeRule;
    let (_dir, r) = load_edited(|f, t| match f {
        "terms.toml" => t.replacen(
            "doc = \"y gyro constant bias\"",
            "doc = \"y gyro constant bias\"\ngrade_sigma = { mems = \"2 deg/s\" }",
            1,
        ),
        "grades.toml" => t.replacen("\"gyro g^2-sensitivity\" = \"0.01 deg/s/g^2\"\n", "", 1),
        _ => t,
    });
    let spec = r.unwrap_or_else(|e| panic!("{e}"));
    let mems = spec.grades.iter().find(|g| g.name == "mems").unwrap();
    let t = |n: &str| spec.term_index(n).unwrap();
    assert_eq!(mems.term_rule[t("eps_y")], GradeRule::Term);
    assert!((mems.term_sigma[t("eps_y")] - 2f64.to_radians()).abs() < 1e-15);
    assert_eq!(mems.term_rule[t("eps_x")], GradeRule::Group);
    assert!((mems.term_sigma[t("eps_x")] - 0.5f64.to_radians()).abs() < 1e-15);
    // the group no longer listed: its navigation prior times the gyro factor (1000)
    assert_eq!(mems.term_rule[t("kgq_x")], GradeRule::Unlisted);
    let k = t("kgq_x");
    assert_eq!(mems.term_sigma[k], spec.terms[k].sigma * 1000.0);
    // the tactical grade is untouched by the mems entry
    let tactical = spec.grades.iter().find(|g| g.name == "tactical").unwrap();
    assert_eq!(tactical.term_rule[t("eps_y")], GradeRule::Group);
}

#[test]
fn residual_errors_name_the_measurement_and_the_record() {
    expect_error(
        "measurements.toml",
        "residual = \"h - aid.h\"",
        "residual = \"h - aid.vd\"",
        "h - aid.vd",
        "measurement `pos_h`",
        "`aid.vd` is not in a position fix",
    );
    expect_error(
        "measurements.toml",
        "residual = \"vn - aid.vn\"",
        "residual = \"vn - aid.speed\"",
        "aid.speed",
        "measurement `vel_ne`",
        "unknown field `aid.speed`",
    );
    expect_error(
        "measurements.toml",
        "aiding = \"velocity\"",
        "aiding = \"sonar\"",
        "sonar",
        "measurement `vel_ne`",
        "unknown record `sonar`",
    );
    expect_error(
        "measurements.toml",
        "residual_sigma = \"aid.sigma_n\"",
        "residual_sigma = \"omega\"",
        "residual_sigma = \"omega\"",
        "measurement `pos_ne`",
        "residual_sigma: unknown symbol `omega`",
    );
}

#[test]
fn gnss_terms_are_checked() {
    // an H entry whose unit does not match the row: a time offset [s] times a velocity is m,
    // but a velocity row is in m/s
    expect_error(
        "terms.toml",
        "{ row = \"dv_n\", expr = \"-a_n\" }",
        "{ row = \"dv_n\", expr = \"-vn\" }",
        "{ row = \"dv_n\", expr = \"-vn\" }",
        "term `dt_gnss`",
        "but the row is in m/s",
    );
    expect_error(
        "terms.toml",
        "{ row = \"dp_e\", expr = \"-ve\" }",
        "{ row = \"dp_x\", expr = \"-ve\" }",
        "dp_x",
        "term `dt_gnss`",
        "unknown measurement row `dp_x`",
    );
    expect_error(
        "terms.toml",
        "{ row = \"dp_e\", expr = \"-ve\" }",
        "{ row = \"dp_n\", expr = \"-ve\" }",
        "{ row = \"dp_n\", expr = \"-ve\" }",
        "term `dt_gnss`",
        "entered twice",
    );
    expect_error(
        "terms.toml",
        "sensor = \"gnss\"\nunit = \"s\"",
        "sensor = \"gnss\"\nregressor = \"1\"\nunit = \"s\"",
        "regressor = \"1\"",
        "term `dt_gnss`",
        "enters the measurements, not A",
    );
    expect_error(
        "terms.toml",
        "regressor = \"-(w.x.powi(2) + w.y.powi(2))\"",
        "regressor = \"-(w.x.powi(2) + w.y.powi(2))\"\nh = [{ row = \"dp_n\", expr = \"1.0\" }]",
        "h = [{ row = \"dp_n\"",
        "term `size_z`",
        "`h` belongs to `sensor = \"gnss\"` terms",
    );
    expect_error(
        "terms.toml",
        "{ row = \"dp_n\", expr = \"-c11\" }",
        "{ row = \"dp_n\", expr = \"-c11 * f.x\" }",
        "-c11 * f.x",
        "term `lever_x`",
        "h[dp_n]",
    );
}
