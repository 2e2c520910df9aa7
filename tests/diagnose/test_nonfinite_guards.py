# SPDX-License-Identifier: Apache-2.0
"""The diagnosis's guards against a non-finite result: a closed-loop
re-simulation that runs away is an error ("diverged"), never a report with
relative errors of inf or nan (a controller whose loop is unstable at the
log's period once gave relerr_position_percent = inf with no error: its
positions stayed finite, around 1e200 m, and only the norms overflowed)."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_model import synthetic_log  # noqa: E402

from bristle.diagnose import closedloop, logreader, signals  # noqa: E402

PARAMS = {"Meff_kg": 1.0, "sigma2_Nspm": 10.0, "Fc_N": 1.0, "Fs_N": 1.2, "vs_mps": 0.01, "sigma1_Nspm": 0.0,
          "sigma0_Npm": 1e5}
CTRL = {"type": "emps_pd", "dt_s": 0.001, "kp_1ps": 160.0, "kv": 100.0, "gain_N": 1.0, "u_max": 500.0}


class NonFiniteTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        t, pos = synthetic_log()
        cls.prep = signals.Prepared(logreader.Log("synthetic", t, pos, pos, np.ones_like(t), 1e-3, len(t)))

    def test_stable_loop_is_finite(self):
        r = closedloop.resimulate(self.prep, PARAMS, dict(CTRL))
        self.assertTrue(np.isfinite(r["relerr_position_percent"]))

    def test_runaway_loop_is_an_error(self):
        # unstable at 1 ms, no saturation that matters: finite but huge positions
        for kp, kv, umax in ((1e3, 1e4, 1e300), (1e6, 1e6, 1e300)):
            with self.assertRaises(closedloop.ControllerError, msg=(kp, kv)) as cm:
                closedloop.resimulate(self.prep, PARAMS, dict(CTRL, kp_1ps=kp, kv=kv, u_max=umax))
            self.assertIn("diverged", str(cm.exception))

    def test_massless_model_is_a_named_divergence(self):
        # a fit with the mass on its floor (1e-9 kg) on an encoder's log: the state turns NaN, which once reached
        # the encoder's floor() as "cannot convert float NaN to integer" (5 fleet axes) instead of this error
        t, pos = synthetic_log()
        q = 1e-6
        posq = np.floor(pos / q) * q
        prep = signals.Prepared(logreader.Log("synthetic", t, posq, posq, np.ones_like(t), 1e-3, len(t)))
        self.assertGreater(closedloop.position_quantum(prep.pos), 0.0)
        with self.assertRaises(closedloop.ControllerError) as cm:
            closedloop.resimulate(prep, dict(PARAMS, Meff_kg=1e-9, sigma1_Nspm=5e3), dict(CTRL))
        self.assertIn("diverged at", str(cm.exception))


if __name__ == "__main__":
    unittest.main()
