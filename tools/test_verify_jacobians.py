"""Self-test of tools/verify_jacobians.py: it passes on the generated model and fails on each of
the paper's printed misprints (DESIGN §4) fed to it as a deliberately wrong A.

Run: target/tools-venv/bin/python -m unittest tools/test_verify_jacobians.py (needs SINSMODEL_BIN).
"""

import contextlib
import io
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(__file__))
import verify_jacobians as vj  # noqa: E402

BIN = os.environ.get("SINSMODEL_BIN", os.path.join(os.path.dirname(__file__), "..", "target", "debug", "sinsmodel"))


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

    def check_fails(self, k, model):
        code, out = run("--corrupt", str(k), "--models", model)
        self.assertEqual(code, 1, f"misprint {k} not caught:\n{out}")

    def test_misprint_1_cos2L(self):
        self.check_fails(1, "P31")

    def test_misprint_2_tan_in_dv_n_dlat(self):
        self.check_fails(2, "P31")

    def test_misprint_3_c12_in_gyro_scale_block(self):
        self.check_fails(3, "P31")

    def test_misprint_4_parameter_rows(self):
        self.check_fails(4, "P31")

    def test_misprint_5_linear_instead_of_quadratic(self):
        self.check_fails(5, "P31")

    def test_misprint_6_dh_rate(self):
        self.check_fails(6, "P31+vertical")


if __name__ == "__main__":
    unittest.main()
