"""Self-test of tools/verify_jacobians.py: it passes on the generated model and fails on each of
the paper's printed misprints (DESIGN §4) fed to it as a deliberately wrong A.

Run: target/tools-venv/bin/python -m unittest tools/test_verify_jacobians.py (needs SINSMODEL_BIN).
"""

import contextlib
import io
import os
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.dirname(__file__))
import verify_jacobians as vj  # noqa: E402

BIN = os.environ.get("SINSMODEL_BIN") or subprocess.run(
    [os.path.join(os.path.dirname(os.path.abspath(__file__)), "sinsmodel-bin")],
    check=True, capture_output=True, text=True).stdout.strip()


def run(*args):
    old = sys.argv
    sys.argv = ["verify_jacobians.py", "--bin", BIN, "--points", "25", *args]
    out = io.StringIO()
    try:
        with contextlib.redirect_stdout(out):
            code = vj.main()
    finally:
        sys.argv = old
    return code, out.getvalue()


class MisprintsAreCaught(unittest.TestCase):
    def test_correct_model_passes(self):
        code, out = run("--models", "P31", "P31+vertical")
        self.assertEqual(code, 0, out)

    def check_fails(self, k, model, names=None):
        """The check fails and, where `names` is given, the message names that entry."""
        code, out = run("--corrupt", str(k), "--models", model)
        self.assertEqual(code, 1, f"misprint {k} not caught:\n{out}")
        if names:
            self.assertIn(f"at {names}:", out, f"misprint {k}: wrong entry named:\n{out}")
            self.assertNotIn("np.float64", out, "plain floats in the report")

    def test_misprint_1_cos2L(self):
        self.check_fails(1, "P31", "A[phi_d][dlat]")

    def test_misprint_2_tan_in_dv_n_dlat(self):
        self.check_fails(2, "P31", "A[dv_n][dlat]")

    def test_misprint_3_c12_in_gyro_scale_block(self):
        self.check_fails(3, "P31", "A[phi_d][kg_32]")

    def test_misprint_4_parameter_rows(self):
        self.check_fails(4, "P31")

    def test_misprint_5_linear_instead_of_quadratic(self):
        self.check_fails(5, "P31")

    def test_misprint_6_dh_rate(self):
        self.check_fails(6, "P31+vertical", "A[dh][dv_d]")

    def test_wrong_radius_in_h_is_named_in_h(self):
        self.check_fails(7, "P31", "H[pos_ne][0][dlat]")

    def test_time_offset_without_coriolis_is_named_in_h(self):
        self.check_fails(8, "P31+dt_gnss", "H[vel_ne][0][dt_gnss]")

    def test_reversed_lever_arm_velocity_is_named_in_h(self):
        self.check_fails(9, "P31+lever_y", "H[vel_ne][0][lever_y]")

    def test_reversed_tangential_inner_lever_arm_is_named(self):
        code, out = run("--corrupt", "10", "--models", "P31+size_x_y")
        self.assertEqual(code, 1, f"reversed tangential part not caught:\n{out}")
        self.assertIn("][size_x_y]:", out, f"wrong entry named:\n{out}")

    def test_reversed_accelerometer_delay_is_named(self):
        code, out = run("--corrupt", "11", "--models", "P31+tau_y")
        self.assertEqual(code, 1, f"reversed delay not caught:\n{out}")
        self.assertIn("][tau_y]:", out, f"wrong entry named:\n{out}")

    def test_reversed_reference_mounting_is_named_in_h(self):
        self.check_fails(12, "P13+vertical+mount_z", "H[vel_body][1][mount_z]")

    def test_body_velocity_attitude_convention_is_checked(self):
        code, out = run("--corrupt", "13", "--models", "P13+vertical")
        self.assertEqual(code, 1, f"reversed attitude convention not caught:\n{out}")
        self.assertIn("H[vel_body]", out, f"wrong entry named:\n{out}")

    def test_reference_time_offset_without_frame_rate_is_named(self):
        code, out = run("--corrupt", "14", "--models", "P13+vertical+dt_ref")
        self.assertEqual(code, 1, f"missing frame rate not caught:\n{out}")
        self.assertIn("][dt_ref]:", out, f"wrong entry named:\n{out}")

    def test_attitude_mounting_through_the_wrong_side_of_c_is_named(self):
        code, out = run("--corrupt", "15", "--models", "P13+att_mount_x")
        self.assertEqual(code, 1, f"transposed attitude mounting not caught:\n{out}")
        self.assertIn("][att_mount_x]:", out, f"wrong entry named:\n{out}")

    def test_attitude_time_offset_without_frame_rate_is_named(self):
        code, out = run("--corrupt", "16", "--models", "P13+dt_att")
        self.assertEqual(code, 1, f"missing frame rate not caught:\n{out}")
        self.assertIn("][dt_att]:", out, f"wrong entry named:\n{out}")

    def test_every_spec_term_is_checked_by_default(self):
        models = vj.default_models()
        named = {s for m in models for s in m.split("+")} | {s for m in models for s in vj.PRESETS.get(m.split("+")[0], [])}
        self.assertEqual(set(vj.TERMS) - named, set())


class RegressorTranslation(unittest.TestCase):
    def test_translates_the_spec_grammar(self):
        import casadi as ca
        f, w, dw = ca.DM([1.5, -2.0, 3.0]), ca.DM([0.1, 0.2, -0.3]), ca.DM([4.0, 5.0, 6.0])
        for text, want in [("1", 1.0), ("f.x * f.y", -3.0), ("f.z.powi(2)", 9.0), ("f.y.abs()", 2.0),
                           ("f.y * f.y.abs()", -4.0), ("-(w.y.powi(2) + w.z.powi(2))", -0.13),
                           ("f.x / 2.0 - w.x", 0.65), ("w.x * w.y - dw.z", -5.98), ("-df.y", -8.0)]:
            got = float(vj.translate_regressor(text, "t")(f, w, dw, ca.DM([7.0, 8.0, 9.0])))
            self.assertAlmostEqual(got, want, places=12, msg=text)

    def test_rejects_what_it_cannot_translate(self):
        for text in ["f.x.exp()", "g.y", "f.x ** 2", "f.x.powi(h)", "import os", "f[0]", "lat", "dw.q"]:
            with self.assertRaises(vj.SpecTranslationError, msg=text):
                vj.translate_regressor(text, "t")


if __name__ == "__main__":
    unittest.main()
