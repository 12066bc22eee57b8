"""Overlapping Allan deviation of `sinsmodel allan` against the allantools package (pinned in
tools/requirements.txt) on the same data: the τ list must be allantools' default ("octave") and
every ADEV must agree to 1e-9 relative.

Run: target/tools-venv/bin/python -m unittest tools/test_allan.py (needs SINSMODEL_BIN).
"""

import json
import math
import os
import subprocess
import tempfile
import unittest

import allantools
import numpy as np

HERE = os.path.dirname(__file__)
BIN = os.environ.get("SINSMODEL_BIN") or subprocess.run(
    [os.path.join(os.path.dirname(os.path.abspath(__file__)), "sinsmodel-bin")],
    check=True, capture_output=True, text=True).stdout.strip()
PSINS = os.path.join(HERE, "..", "..", "shared", "data", "psins-lasergyro", "lasergyro.imu")
NAMES = ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]


def run_allan(path, out):
    subprocess.run([BIN, "allan", "--imu", path, "--json", out], check=True, capture_output=True)
    with open(out) as fh:
        return json.load(fh)


def compare(test, ours, rates, dt):
    for k, name in enumerate(NAMES):
        # allantools gets the mean-removed rates (ADEV is invariant to the mean): on the raw
        # accelerometer z channel (-9.8 m/s^2) its own phase accumulation loses ~6e-8 relative
        y = rates[:, k] - np.mean(rates[:, k])
        taus, dev, _, _ = allantools.oadev(y, rate=1.0 / dt, data_type="freq")
        test.assertEqual(len(taus), len(ours["tau_s"]), name)
        np.testing.assert_allclose(ours["tau_s"], taus, rtol=1e-12)
        rel = np.max(np.abs(np.array(ours["adev"][name]) - dev) / dev)
        test.assertLess(rel, 1e-9, f"{name}: worst relative difference {rel:.3e}")


class AllanAgainstAllantools(unittest.TestCase):
    def test_random_series_in_the_text_format(self):
        rng = np.random.default_rng(4)
        n, dt = 20000, 0.01
        inc = np.column_stack([rng.normal(0, 1e-5, (n, 3)) + 1e-6, rng.normal(0, 1e-3, (n, 3)) + [0, 0, -0.098]])
        inc[:, 0] += np.cumsum(rng.normal(0, 1e-8, n))  # a random walk on gyro x
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "imu.txt")
            t = dt * np.arange(1, n + 1)
            np.savetxt(path, np.column_stack([t, inc]), fmt="%.17g")
            ours = run_allan(path, os.path.join(d, "a.json"))
        compare(self, ours, inc / dt, dt)

    def test_lasergyro_log(self):
        counts = []
        header = []
        with open(PSINS) as fh:
            for line in fh:
                s = line.strip()
                if not s or s.startswith("%"):
                    continue
                vals = [float(x) for x in s.split()]
                if len(header) < 3:
                    header.append(vals)
                else:
                    counts.append(vals)
        c = np.array(counts)
        g = header[1][5]
        dt = header[1][4] * 1e-3
        gs = np.array(header[2][:3]) * math.pi / 180 / 3600
        acs = np.array(header[2][3:]) * 1e-6 * g
        # PSINS X-right, Y-forward, Z-up -> FRD
        th = np.column_stack([c[:, 1] * gs[1], c[:, 0] * gs[0], -c[:, 2] * gs[2]])
        dv = np.column_stack([c[:, 4] * acs[1], c[:, 3] * acs[0], -c[:, 5] * acs[2]])
        with tempfile.TemporaryDirectory() as d:
            ours = run_allan(PSINS, os.path.join(d, "a.json"))
        self.assertAlmostEqual(ours["rate_hz"], 100.0, places=6)
        compare(self, ours, np.column_stack([th, dv]) / dt, dt)


if __name__ == "__main__":
    unittest.main()
