"""tools/filter-ab times two sinsmodel binaries on issue 27's job and refuses one whose outputs
differ from the other's.

Run: SINSMODEL_BIN=target/release/sinsmodel python3 -m unittest tools/test_filter_ab.py
"""
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "tools", "filter-ab")
BIN = os.environ.get("SINSMODEL_BIN", os.path.join(ROOT, "target", "release", "sinsmodel"))

# a "binary" that is sinsmodel but leaves one more byte in nav.txt after a filter run
CHANGED = """#!/bin/sh
"{bin}" "$@" || exit $?
if [ "$1" = filter ]; then
  while [ $# -gt 1 ]; do [ "$1" = --out ] && out=$2; shift; done
  printf x >> "$out/nav.txt"
fi
"""


class FilterAb(unittest.TestCase):
    def run_tool(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)

    def test_the_same_binary_twice_is_identical(self):
        p = self.run_tool("--before", BIN, "--after", BIN, "--seconds", "20", "--runs", "2")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("byte-identical in every run", p.stdout)
        self.assertIn("before / after (medians):", p.stdout)
        self.assertIn("run 2: after", p.stderr)

    def test_other_bytes_are_named_and_fail(self):
        with tempfile.TemporaryDirectory() as d:
            changed = os.path.join(d, "changed")
            with open(changed, "w") as f:
                f.write(CHANGED.format(bin=BIN))
            os.chmod(changed, 0o755)
            p = self.run_tool("--before", BIN, "--after", changed, "--seconds", "20", "--runs", "1")
            self.assertEqual(p.returncode, 1, p.stderr)
            self.assertIn("wrote other bytes than --before's first run in: nav.txt", p.stderr)
            self.assertIn("DIFFERENT", p.stdout)

    def test_bad_options_are_refused_with_their_names(self):
        p = self.run_tool("--before", BIN, "--after", "/nonexistent/sinsmodel")
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("tools/filter-ab: --after /nonexistent/sinsmodel: no such file", p.stderr)
        p = self.run_tool("--before", BIN, "--after", BIN, "--seconds", "3")
        self.assertIn("--seconds 3.0: give the data's length in seconds", p.stderr)


if __name__ == "__main__":
    unittest.main()
