"""tools/eval-tables refuses what it cannot do and never runs a campaign on --dry-run.

Run: python3 -m unittest tools/test_eval_tables.py (needs the campaigns' results in
docs/explain-eval/, which the repository holds).
"""
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "tools", "eval-tables")
DOC = os.path.join(ROOT, "docs", "explain.md")


def md5(path):
    with open(path, "rb") as f:
        return hashlib.md5(f.read()).hexdigest()


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


class EvalTables(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        # a stand-in binary that only leaves a mark when it is called
        self.mark = os.path.join(self.tmp.name, "called")
        self.fake = os.path.join(self.tmp.name, "fake-sinsmodel")
        with open(self.fake, "w") as f:
            f.write(f"#!/bin/sh\ntouch '{self.mark}'\nexit 3\n")
        os.chmod(self.fake, 0o755)
        self.doc = md5(DOC)

    def tearDown(self):
        self.assertEqual(md5(DOC), self.doc, "docs/explain.md changed")
        self.tmp.cleanup()

    def test_dry_run_runs_nothing_and_prints_the_tables(self):
        r = run("--dry-run", "--bin", self.fake)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertFalse(os.path.exists(self.mark), "a dry run called the binary")
        self.assertIn("eval-tables:begin", r.stdout)
        for name in ("sensor-600", "sensor-300", "sensor-1200", "all-600"):
            self.assertIn(name, r.stdout)

    def test_unknown_or_empty_campaign_names_are_refused(self):
        for only, says in (("nosuch", "unknown campaign 'nosuch'"), ("", "give campaign names"),
                           ("sensor-600,", "give campaign names")):
            r = run("--only", only, "--bin", self.fake)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn(says, r.stderr)
            self.assertNotIn("Traceback", r.stderr)
        self.assertFalse(os.path.exists(self.mark))

    def test_from_disk_with_a_dry_run_or_campaigns_to_run_is_refused(self):
        for args, says in ((("--from-disk", "--dry-run"), "give one"),
                           (("--from-disk", "--only", "sensor-300"), "runs nothing")):
            r = run(*args, "--bin", self.fake)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn(says, r.stderr)
            self.assertNotIn("Traceback", r.stderr)
        self.assertFalse(os.path.exists(self.mark))

    def test_a_failed_campaign_leaves_no_directory_of_its_own_behind(self):
        r = run("--only", "sensor-300", "--bin", self.fake)
        self.assertNotEqual(r.returncode, 0)
        left = [d for d in os.listdir(os.path.join(ROOT, "docs", "explain-eval"))
                if "-running-" in d]
        self.assertEqual(left, [], "a run that wrote nothing left its directory")

    def test_results_of_another_campaign_replace_nothing(self):
        # a stand-in that writes a summary of another seed, with a cases.json that claims to be
        # sensor-300's, and exits 0
        camp = os.path.join(ROOT, "docs", "explain-eval", "sensor-300")
        wrong = os.path.join(self.tmp.name, "wrong-sinsmodel")
        with open(wrong, "w") as f:
            f.write("#!/bin/sh\nfor a; do out=$a; done\nmkdir -p \"$out\"\n"
                    f"cp '{camp}/cases.json' \"$out/cases.json\"\n"
                    "echo '{\"seed\": 9, \"cases\": 200}' > \"$out/eval.json\"\n")
        os.chmod(wrong, 0o755)
        before = {f: md5(os.path.join(camp, f)) for f in os.listdir(camp)}
        stamps = os.path.join(ROOT, "docs", "explain-eval", "measured.json")
        stamped = md5(stamps)
        r = run("--only", "sensor-300", "--bin", wrong)
        kept = [d for d in os.listdir(os.path.dirname(camp)) if "-running-" in d]
        for d in kept:
            shutil.rmtree(os.path.join(os.path.dirname(camp), d))
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("not the campaign's", r.stderr)
        self.assertIn("seed 9", r.stderr)
        self.assertNotIn("Traceback", r.stderr)
        self.assertEqual(len(kept), 1, "the new results are kept for a look, once")
        self.assertEqual({f: md5(os.path.join(camp, f)) for f in os.listdir(camp)}, before)
        self.assertEqual(md5(stamps), stamped)

    def test_a_program_that_cannot_be_run_is_named(self):
        noexec = os.path.join(self.tmp.name, "no-shebang")
        with open(noexec, "w") as f:
            f.write("echo hello\n")
        os.chmod(noexec, 0o755)
        r = run("--only", "sensor-300", "--bin", noexec)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("cannot be run", r.stderr)
        self.assertNotIn("Traceback", r.stderr)
        left = [d for d in os.listdir(os.path.join(ROOT, "docs", "explain-eval"))
                if "-running-" in d]
        self.assertEqual(left, [])

    def test_a_missing_binary_is_named(self):
        r = run("--only", "sensor-300", "--bin", os.path.join(self.tmp.name, "nope"))
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("no executable there", r.stderr)
        self.assertNotIn("Traceback", r.stderr)

    def test_a_campaign_that_writes_nothing_leaves_the_doc_alone(self):
        ok = os.path.join(self.tmp.name, "silent-sinsmodel")
        with open(ok, "w") as f:
            f.write("#!/bin/sh\nexit 0\n")
        os.chmod(ok, 0o755)
        stamps = os.path.join(ROOT, "docs", "explain-eval", "measured.json")
        before = md5(stamps)
        r = run("--only", "sensor-300", "--bin", ok)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("wrote no new", r.stderr)
        self.assertEqual(md5(stamps), before)

    def test_a_failing_campaign_leaves_the_doc_alone(self):
        r = run("--only", "sensor-300", "--bin", self.fake)
        self.assertNotEqual(r.returncode, 0)
        self.assertTrue(os.path.exists(self.mark))
        self.assertIn("failed (exit 3", r.stderr)


if __name__ == "__main__":
    unittest.main()
