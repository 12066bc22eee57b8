"""tools/kf-gins-compare hands KF-GINS the data and configuration it reads, and refuses a run
that stopped early.

KF-GINS itself is not in this repository: a stand-in reads the configuration the tool wrote,
checks the files it names the way KF-GINS's readers would need them (no header lines, seven
numbers a row, the start time on the first IMU row) and writes a row per epoch.

Run: SINSMODEL_BIN=target/release/sinsmodel python3 -m unittest tools/test_kf_gins_compare.py
"""
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "tools", "kf-gins-compare")
BIN = os.environ.get("SINSMODEL_BIN", os.path.join(ROOT, "target", "release", "sinsmodel"))

STAND_IN = """#!{python}
import os, sys
cfg = {{}}
for line in open(sys.argv[1]):
    if ":" in line and not line.startswith(" "):
        k, v = line.split(":", 1)
        cfg[k.strip()] = v.strip().strip('"')
rows = []
for name in ("imupath", "gnsspath"):
    with open(cfg[name]) as f:
        lines = f.read().splitlines()
    for k, line in enumerate(lines, 1):
        vals = [float(x) for x in line.split()]  # a '#' line fails here
        if len(vals) != 7:
            sys.exit(f"{{name}} line {{k}}: {{len(vals)}} numbers")
    rows.append(lines)
imu = rows[0]
if float(cfg["starttime"]) != float(imu[0].split()[0]):
    sys.exit("starttime is not the first IMU time")
if cfg["imudatarate"] != "200" or cfg["imudatalen"] != "7":
    sys.exit("rate or row length")
keep = len(imu) - 1 - {short}
mark = os.path.join(cfg["outputpath"], "..", "called-once")
if {once} and os.path.exists(mark):
    sys.exit(0)  # a later run that writes nothing
open(mark, "w").close()
with open(os.path.join(cfg["outputpath"], "KF_GINS_Navresult.nav"), "w") as f:
    f.writelines(line + "\\n" for line in imu[1:1 + keep])
"""


class KfGinsCompare(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.tmp.cleanup()

    def stand_in(self, short, once=False):
        path = os.path.join(self.tmp.name, f"kf-gins-{short}-{once}")
        with open(path, "w") as f:
            f.write(STAND_IN.format(python=sys.executable, short=short, once=once))
        os.chmod(path, 0o755)
        return path

    def run_tool(self, kf, *extra):
        sm = [] if "--sinsmodel" in extra else ["--sinsmodel", BIN]
        return subprocess.run(
            [sys.executable, SCRIPT, "--kf-gins", kf, *sm, "--seconds", "20",
             "--runs", "1", "--dir", os.path.join(self.tmp.name, "w"), *extra],
            capture_output=True, text=True)

    def test_kf_gins_gets_what_it_reads_and_both_are_timed(self):
        r = self.run_tool(self.stand_in(0))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("4000 epochs", r.stdout)
        self.assertRegex(r.stdout, r"sinsmodel +\d+\.\d+ s fastest")
        self.assertRegex(r.stdout, r"KF-GINS +\d+\.\d+ s fastest")
        self.assertIn("KF_GINS_Navresult.nav (3999 rows)", r.stdout)
        self.assertRegex(r.stdout, r"KF-GINS / sinsmodel, fastest runs: \d+\.\dx")

    def test_a_run_that_stopped_early_is_refused(self):
        r = self.run_tool(self.stand_in(100))
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("KF_GINS_Navresult.nav has 3899 rows (3999 expected)", r.stderr)
        self.assertNotIn("fastest runs", r.stdout)
        # every run is checked, not the last one's files alone
        r = self.run_tool(self.stand_in(0, once=True), "--runs", "2")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("KF-GINS wrote nothing", r.stderr)
        self.assertNotIn("fastest runs", r.stdout)

    def test_not_sinsmodel_and_a_foreign_directory_are_refused(self):
        r = self.run_tool(self.stand_in(0), "--sinsmodel", "/bin/true")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("is --sinsmodel /bin/true sinsmodel?", r.stderr)
        mine = os.path.join(self.tmp.name, "mine")
        os.makedirs(mine)
        with open(os.path.join(mine, "scenario.toml"), "w") as f:
            f.write("mine\n")
        r = subprocess.run([sys.executable, SCRIPT, "--kf-gins", self.stand_in(0), "--sinsmodel", BIN,
                            "--seconds", "20", "--runs", "1", "--dir", mine], capture_output=True, text=True)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("--dir", r.stderr)
        with open(os.path.join(mine, "scenario.toml")) as f:
            self.assertEqual(f.read(), "mine\n")

    def test_bad_arguments_are_refused(self):
        r = self.run_tool(os.path.join(self.tmp.name, "missing"))
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("--kf-gins", r.stderr)
        r = self.run_tool(self.stand_in(0), "--seconds", "3600000")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("--seconds", r.stderr)


if __name__ == "__main__":
    unittest.main()
