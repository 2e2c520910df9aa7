# SPDX-License-Identifier: Apache-2.0
"""What sim/studies/diagnose_control.py --check reads of a diagnosis
(docs/diagnose.md, "The lead over a diagnosed dead time"):

- the dead time of its model.json (params.delay_s; 0 without one), which
  decides whether the lead's check is "not worse" or "keeps the lock";
- a compensation lead its machine.json switched on, for either estimator,
  is a failure that names the field; both at 0 pass.
"""
import json
import os
import sys
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "sim", "studies"))
import diagnose_control  # noqa: E402


def write(folder, name, doc):
    with open(os.path.join(folder, name), "w") as f:
        json.dump(doc, f)


class ControlCheck(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.d = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def test_dead_time(self):
        write(self.d, "model.json", {"causes": ["actuator_delay"], "params": {"Fc_N": 7.0, "delay_s": 0.00299433}})
        self.assertEqual(diagnose_control.diagnosed_dead_time_s(self.d), 0.00299433)
        write(self.d, "model.json", {"causes": ["offset"], "params": {"Fc_N": 7.0, "offset_N": 2.5}})
        self.assertEqual(diagnose_control.diagnosed_dead_time_s(self.d), 0.0)

    def test_lead_written(self):
        est = {"pf": {"comp_ahead_periods": 0.0}, "ukf": {"comp_ahead_periods": 0.0}}
        write(self.d, "machine.json", {"estimator": est})
        self.assertEqual(diagnose_control.lead_written("offset", self.d), [])
        for e in ("pf", "ukf"):
            bad = json.loads(json.dumps(est))
            bad[e]["comp_ahead_periods"] = 0.5
            write(self.d, "machine.json", {"estimator": bad})
            fails = diagnose_control.lead_written("offset", self.d)
            self.assertEqual(len(fails), 1)
            self.assertIn(f"estimator.{e}.comp_ahead_periods 0.5", fails[0])


if __name__ == "__main__":
    unittest.main()
