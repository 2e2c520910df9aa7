# SPDX-License-Identifier: Apache-2.0
"""robustness.py --check-safe (the CI's robustness_small): an estimator run that
goes on with a contour RMS above H-inf only's is a failure; the same run
stopped safe by the lock monitor, or better than H-inf only, is not."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "sim", "studies"))
import robustness  # noqa: E402


def run(rms, fault=0):
    return {"contour_rms_m": rms, "fault_status": fault, "outlier_steps": 0, "n_samples": 8001}


def plant(i, **runs):
    return {"i": i, "runs": {"hinf_only": run(2e-6), **runs}}


def main():
    ok = [plant(0, hinf_ukf=run(5e-8), hinf_pf=run(3e-6, fault=-6))]  # a safe stop is no failure
    assert robustness.safety_failures(ok) == [], robustness.safety_failures(ok)
    bad = ok + [plant(1, hinf_ukf=run(5e-8), hinf_pf=run(3e-6))]       # worse, and it went on
    f = robustness.safety_failures(bad)
    assert len(f) == 1 and "hinf_pf" in f[0] and "plant 1" in f[0], f
    assert robustness.lost(bad[1]["runs"]["hinf_pf"], 2e-6) == "worse_than_hinf_only"
    assert robustness.lost(ok[0]["runs"]["hinf_pf"], 2e-6) == "fault"
    print("robustness check: safety failures found as expected")


if __name__ == "__main__":
    main()
