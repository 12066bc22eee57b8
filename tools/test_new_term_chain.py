"""A new error term is one `[[term]]` entry: added to a temporary copy of the spec (nothing else
edited), it goes through the whole chain — build (codegen), `model show`, `jacobian`, the CasADi
check (which must check the new term), a simulation with the term injected, a filter that
estimates it, and `--grade mems` priors for it from the spec's grades file alone. The same copy
also moves the height measurement's residual in measurements.toml, and the filter's innovations
move with it: the residual the filter forms comes from the spec, not from code.

The copy shares the project's target directory (its crates are compiled once, only the copy's
own packages are rebuilt); its binary is renamed `sinsmodel-chain` so the project's own
`sinsmodel` binary is never replaced.

Run: target/tools-venv/bin/python -m unittest -v tools/test_new_term_chain.py
"""

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
TARGET = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))

# a fourth-order x accelerometer term: rectifies under x vibration (<f_x^4> = 3 A^4 / 8 for a sine)
NEW_TERM = """
[[term]]
name = "k4_x"
sensor = "accel"
axis = "x"
regressor = "f.x.powi(4)"
unit = "s^6/m^3"
display = "ug/g^4"
sigma = "1e-8 s^6/m^3"
group = "test: fourth-order"
library = true
doc = "x accelerometer fourth-order term (added by the chain test)"
"""
HEIGHT_SHIFT = 20.0  # m, added to the height residual in the copy's measurements.toml
TRUE_K4 = 3e-9  # s^6/m^3: 1.37 mg at 6 g, 0.09 mg at 3 g

SCENARIO = """name = "chain"
imu_rate_hz = 2000.0
truth_rate_hz = 1.0
seed = 11

[start]
lat_deg = 28.22
lon_deg = 112.99

[[segment]]
kind = "rest"
duration_s = 1200.0

[[vibration]]
kind = "sine"
axis = "x"
amplitude = "6 g"
freq_hz = 90.0
schedule = [[200.0, 500.0, 1.0], [700.0, 1000.0, 0.5]]

[errors]
nabla_x = "50 ug"
k4_x = "{k4} s^6/m^3"

[noise]
arw = "0.01 deg/sqrt(h)"
vrw = "10 ug/sqrt(Hz)"

[gnss]
rate_hz = 1.0
sigma_ne = "0.1 m"
""".format(k4=TRUE_K4)


# level rest with GNSS: nothing excites k4_x (f_x = 0), so its sigma stays at the prior
REST = """name = "rest"
imu_rate_hz = 100.0
truth_rate_hz = 1.0
seed = 5

[start]
lat_deg = 28.22
lon_deg = 112.99

[[segment]]
kind = "rest"
duration_s = 20.0

[gnss]
rate_hz = 1.0
sigma_ne = "0.5 m"
sigma_d = "1 m"
"""


def run(cmd, **kw):
    res = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if res.returncode != 0:
        raise AssertionError(f"{' '.join(map(str, cmd))} failed ({res.returncode}):\n{res.stdout}\n{res.stderr}")
    return res.stdout


class NewTermThroughTheChain(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="sinsmodel-chain-")
        crate = os.path.join(cls.tmp, "crate")
        os.mkdir(crate)
        for f in ["Cargo.toml", "Cargo.lock", "build.rs"]:
            shutil.copy(os.path.join(ROOT, f), crate)
        for d in ["src", "codegen", "units", "model-spec", "benches"]:
            shutil.copytree(os.path.join(ROOT, d), os.path.join(crate, d),
                            ignore=shutil.ignore_patterns("target"))
        # the spec edits: one [[term]] entry, and the height measurement's residual offset by
        # HEIGHT_SHIFT (only the +vertical run of test_6 forms that measurement)
        with open(os.path.join(crate, "model-spec", "terms.toml"), "a") as fh:
            fh.write(NEW_TERM)
        meas = os.path.join(crate, "model-spec", "measurements.toml")
        with open(meas) as fh:
            text = fh.read()
        assert 'residual = "h - aid.h"' in text
        with open(meas, "w") as fh:
            fh.write(text.replace('residual = "h - aid.h"', f'residual = "h - aid.h + {HEIGHT_SHIFT}"'))
        # not a spec edit: the copy's binary gets its own name, so the project's is not replaced
        manifest = os.path.join(crate, "Cargo.toml")
        with open(manifest) as fh:
            text = fh.read()
        text = text.replace('[[bin]]\nname = "sinsmodel"', '[[bin]]\nname = "sinsmodel-chain"')
        text = text.replace('default-run = "sinsmodel"', 'default-run = "sinsmodel-chain"')
        with open(manifest, "w") as fh:
            fh.write(text)
        out = run(["cargo", "build", "--quiet", "--offline", "--manifest-path", manifest, "--bin", "sinsmodel-chain",
                   "--message-format=json"], env={**os.environ, "CARGO_TARGET_DIR": TARGET})
        exe = None
        for line in out.splitlines():
            try:
                m = json.loads(line)
            except ValueError:
                continue
            if m.get("reason") == "compiler-artifact" and m.get("executable"):
                exe = m["executable"]
        assert exe, "cargo reported no executable for the copy"
        cls.bin = exe
        cls.crate = crate
        cls.spec = os.path.join(crate, "model-spec")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_1_model_show_lists_the_term(self):
        out = run([self.bin, "model", "show", "P31+k4_x"])
        self.assertIn("k4_x", out)
        self.assertIn("32", out)  # 31 + 1 states
        lst = run([self.bin, "model", "list"])
        self.assertIn("k4_x", lst)

    def test_2_jacobian_has_the_column(self):
        pt = os.path.join(self.tmp, "point.json")
        f_x = 30.0
        with open(pt, "w") as fh:
            json.dump([{"lat_deg": 28.0, "h_m": 10.0, "v_ned": [0, 0, 0], "euler_deg": [0, 0, 0],
                        "f_b": [f_x, 0.0, -9.8], "w_b": [0, 0, 0]}], fh)
        out = json.loads(run([self.bin, "jacobian", "--model", "P31+k4_x", "--at", pt]))[0]
        j = out["states"].index("k4_x")
        i = out["states"].index("dv_n")
        # level, yaw 0: C = I, so A[dv_n][k4_x] = <f_x^4>
        self.assertAlmostEqual(out["a"][i][j], f_x ** 4, delta=1e-9 * f_x ** 4)

    def test_3_casadi_check_checks_the_term(self):
        py = sys.executable
        with open(os.path.join(self.spec, "terms.toml")) as fh:
            n_terms = fh.read().count("[[term]]")
        out = run([py, os.path.join(ROOT, "tools", "verify_jacobians.py"), "--bin", self.bin, "--points", "15"],
                  env={**os.environ, "SINSMODEL_SPEC_DIR": self.spec})
        self.assertIn(f"spec terms checked: {n_terms} of {n_terms}", out, out)
        self.assertRegex(out, r"ok\s+P31\+<\d+ terms>", out)
        self.assertIn("PASSED", out, out)

    def test_4_simulate_and_estimate(self):
        scen = os.path.join(self.tmp, "chain.toml")
        with open(scen, "w") as fh:
            fh.write(SCENARIO)
        sim = os.path.join(self.tmp, "sim")
        run([self.bin, "simulate", scen, "--out", sim])
        fil = os.path.join(self.tmp, "filter")
        run([self.bin, "filter", "--model", "P28+k4_x", "--imu", os.path.join(sim, "imu.txt"),
             "--aid", os.path.join(sim, "gnss.txt"), "--truth", os.path.join(sim, "truth.txt"), "--out", fil])
        with open(os.path.join(fil, "states.txt")) as fh:
            lines = fh.readlines()
        rows = [ln.split() for ln in lines if not ln.startswith("#")]
        header = [ln for ln in lines if ln.startswith("# t")][0].split()[1:]
        names = [re.sub(r"\[.*\]$", "", h) for h in header]
        k, s = names.index("k4_x"), names.index("sigma_k4_x")
        est, sig = float(rows[-1][k]), float(rows[-1][s])
        print(f"k4_x: true {TRUE_K4:.3e}, estimated {est:.3e} +- {sig:.1e} s^6/m^3", file=sys.stderr)
        self.assertLess(sig, 0.1 * TRUE_K4, "the data determine the new term")
        self.assertLess(abs(est - TRUE_K4), max(3 * sig, 0.05 * TRUE_K4), "estimate within 3 sigma / 5 %")

    def test_5_grade_prior_from_the_spec(self):
        # the new group is in no grade's list: its prior under --grade mems is the navigation
        # prior times the accelerometer factor of grades.toml's `unlisted` rule
        with open(os.path.join(self.spec, "grades.toml"), "rb") as fh:
            import tomllib
            grades = {g["name"]: g for g in tomllib.load(fh)["grade"]}
        factor = grades["mems"]["unlisted"]["accel"]
        self.assertNotIn("test: fourth-order", grades["mems"].get("groups", {}))
        scen = os.path.join(self.tmp, "rest.toml")
        with open(scen, "w") as fh:
            fh.write(REST)
        sim = os.path.join(self.tmp, "rest")
        run([self.bin, "simulate", scen, "--out", sim])

        def first_sigma(extra, out):
            run([self.bin, "filter", "--model", "P13+k4_x", "--imu", os.path.join(sim, "imu.txt"),
                 "--aid", os.path.join(sim, "gnss.txt"), "--init", "28.22,112.99,0,0,0,0", "--out", out] + extra)
            with open(os.path.join(out, "states.txt")) as fh:
                lines = fh.readlines()
            header = [ln for ln in lines if ln.startswith("# t")][0].split()[1:]
            names = [re.sub(r"\[.*\]$", "", h) for h in header]
            row = [ln.split() for ln in lines if not ln.startswith("#")][0]
            return float(row[names.index("sigma_k4_x")])

        nav = first_sigma([], os.path.join(self.tmp, "f_nav"))
        mems = first_sigma(["--grade", "mems"], os.path.join(self.tmp, "f_mems"))
        print(f"k4_x prior: navigation {nav:.6e}, mems {mems:.6e} (factor {factor})", file=sys.stderr)
        # at rest, level, f_x = 0: nothing observes k4_x, its sigma stays at the prior
        self.assertAlmostEqual(nav, 1e-8, delta=1e-12)
        self.assertAlmostEqual(mems / nav, factor, delta=1e-4 * factor)

    def test_6_residual_from_the_spec(self):
        sim = os.path.join(self.tmp, "rest")
        if not os.path.isdir(sim):
            self.test_5_grade_prior_from_the_spec()
        out = os.path.join(self.tmp, "f_vertical")
        run([self.bin, "filter", "--model", "P13+vertical", "--imu", os.path.join(sim, "imu.txt"),
             "--aid", os.path.join(sim, "gnss.txt"), "--init", "28.22,112.99,0,0,0,0", "--out", out])
        with open(os.path.join(out, "innovations.txt")) as fh:
            rows = [ln.split() for ln in fh if not ln.startswith("#")]
        first_h = [float(r[3]) for r in rows if r[1] == "pos_h"][0]
        first_n = [float(r[3]) for r in rows if r[1] == "pos_ne"][0]
        print(f"first innovations: height {first_h:.3f} m (residual shifted by {HEIGHT_SHIFT} m), north {first_n:.3f} m",
              file=sys.stderr)
        # the simulated fixes have 1 m height noise: the first height innovation is the shift
        self.assertLess(abs(first_h - HEIGHT_SHIFT), 5.0)
        self.assertLess(abs(first_n), 5.0, "the untouched measurement is not moved")


if __name__ == "__main__":
    unittest.main()
