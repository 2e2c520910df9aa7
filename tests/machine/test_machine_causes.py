# SPDX-License-Identifier: Apache-2.0
"""The estimators as the image has them (label `machine`; docs/fleet.md, "The
estimators as the image has them"): `br_robust_run --machine-causes` gives the
PF's and the UKF's estimation model the build's machine-file causes
(BR_MACHINE_CAUSES), the image's estimator, instead of the thesis model.

A host build for the reference machine with an actuator delay of DELAY_S in
its causes (written below the work folder, never the source tree), on the
reference plant with that delay, the delay identification off (so that the
estimators start and stay at the delay the model gives them):
- with --machine-causes each estimator's contour RMS is below the one on the
  thesis model (which believes the torque acts at once), and the JSON says
  "estimator_causes": "machine";
- without it the JSON says "thesis".

Usage: test_machine_causes.py --src SRC --work DIR"""
import argparse
import json
import os
import subprocess
import sys

ARGS = argparse.ArgumentParser()
ARGS.add_argument("--src", required=True)
ARGS.add_argument("--work", required=True)
A = ARGS.parse_args()
sys.path.insert(0, os.path.join(A.src, "sim", "studies"))
import machine_chain  # noqa: E402

DELAY_S = 2.0e-3  # 1.33 PF periods, 2 control periods of the reference machine
ESTIMATORS = ("hinf_ukf", "hinf_pf")


def main():
    os.makedirs(A.work, exist_ok=True)
    with open(os.path.join(A.src, "machines", "reference.json"), encoding="utf-8") as f:
        m = json.load(f)
    m["name"] = "reference-causes-delay"
    m["causes"] = {"actuator_delay": {"delay_s": DELAY_S}}
    given = os.path.join(A.work, "delay.json")
    with open(given, "w", encoding="utf-8") as f:
        json.dump(m, f, indent=2)
    plant = os.path.join(A.work, "plant.json")
    machine_chain.truth_model(given, plant, A.src)  # the reference plant with the delay
    exe = machine_chain.host_build(argparse.Namespace(src=A.src), given, os.path.join(A.work, "host"),
                                   "br_robust_run")
    out = {}
    for label, extra in (("thesis", []), ("machine", ["--machine-causes"])):
        js = os.path.join(A.work, "%s.json" % label)
        r = subprocess.run([exe, "--plant", plant, "--only", ",".join(ESTIMATORS), "--delay-id", "0", "--json", js,
                            *extra], capture_output=True, text=True)
        if r.returncode != 0:
            print("br_robust_run %s: exit %d\n%s%s" % (label, r.returncode, r.stdout, r.stderr))
            return 1
        with open(js, encoding="utf-8") as f:
            out[label] = json.load(f)
    fails = []
    for label in out:
        if out[label].get("estimator_causes") != label:
            fails.append("%s run: estimator_causes %r" % (label, out[label].get("estimator_causes")))
    for est in ESTIMATORS:
        t, c = out["thesis"]["controllers"][est], out["machine"]["controllers"][est]
        if c.get("faulted"):
            fails.append("%s with the machine's causes faulted: %s at %s s" % (est, c.get("fault_cause"),
                                                                             c.get("fault_t_s")))
            continue
        rt = float("inf") if t.get("faulted") else t["contour_rms_m"]
        print("%s: thesis model %s, machine's causes %.4g m" % (
            est, "%.4g m" % rt if rt != float("inf") else "faulted (%s)" % t.get("fault_cause"), c["contour_rms_m"]))
        if not c["contour_rms_m"] < rt:
            fails.append("%s: the machine's delay in the model did not help (%.4g m, thesis model %.4g m)"
                         % (est, c["contour_rms_m"], rt))
    for f in fails:
        print("FAIL: " + f)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
