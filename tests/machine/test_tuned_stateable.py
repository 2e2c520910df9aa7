#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The committed tuned headers (firmware/gen/bristle_gen/est/br_{pf,ukf}_tuned.h,
`make tune`) are settings the reference machine's file can state: each R at or
above the encoder's quantisation, 1/12 count^2 (docs/machine-file.md: R = 1/12
count^2 + position_noise_m2; the tuner's floor, docs/tuning.md "A plant with
an actuator delay, and R's floor"), and the file's physical settings written
from them (tuned_machine.py's machine.set_est_per_step) give their per-step
values back. A header below the floor (the UKF of branch tune-hw-ukf, R 0.012
count^2) is refused.

Usage: test_tuned_stateable.py"""
import copy
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import REPO, check, result  # noqa: E402
import machine  # noqa: E402
import tuned_machine  # noqa: E402

GEN = os.path.join(REPO, "firmware", "gen", "bristle_gen", "est")
REFERENCE = os.path.join(REPO, "machines", "reference.json")
# the UKF's R of branch tune-hw-ukf's header (docs/tuning.md), rad^2
R_BELOW_FLOOR_RAD2 = 4.474242699e-13


def main():
    with open(REFERENCE, "r", encoding="utf-8") as f:
        raw = json.load(f)
    rpc2 = machine.params(machine.load(REFERENCE))["rad_per_count"] ** 2
    for est in ("pf", "ukf"):
        vals = tuned_machine.read_tuned(os.path.join(GEN, "br_%s_tuned.h" % est), est)
        vals["r_counts2"] /= rpc2
        check(vals["r_counts2"] >= machine.QUANT_COUNTS2,
              "%s: R %.4f count^2 >= the quantisation's 1/12" % (est, vals["r_counts2"]))
        mine = copy.deepcopy(raw)
        try:
            machine.set_est_per_step(mine, est, vals)
            got = machine.est_per_step(mine, est)
            same = all(np.float32(got[k]) == np.float32(v) for k, v in vals.items())
        except ValueError as e:
            print(e)
            same = False
        check(same, "%s: the reference file states the committed tuning and gives it back" % est)
    bad = tuned_machine.read_tuned(os.path.join(GEN, "br_ukf_tuned.h"), "ukf")
    bad["r_counts2"] = R_BELOW_FLOOR_RAD2 / rpc2
    try:
        machine.set_est_per_step(copy.deepcopy(raw), "ukf", bad)
        refused = False
    except ValueError as e:
        refused = "quantisation" in str(e)
    check(refused, "an R of %.4f count^2 (below the quantisation) is refused" % bad["r_counts2"])
    return result()


if __name__ == "__main__":
    sys.exit(main())
