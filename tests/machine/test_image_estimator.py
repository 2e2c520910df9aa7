# SPDX-License-Identifier: Apache-2.0
"""The image follows the machine file's control.estimator (docs/configure.md,
"The image's estimator"): a machine file that lists only pf is refused for the
STM32G474 with the reason, and one that puts ukf first builds an STM32H743
image that runs the UKF at control.period_s (its PF state, br_image_pf in AXI
SRAM, is not linked); make firmware's lines name the friction transient over
the estimator's period and warn where the fleet's PF mostly stopped. Cross
builds into WORK, never the source tree.

Usage: test_image_estimator.py --src REPO --work DIR"""
import argparse
import json
import os
import subprocess
import sys


def build(src, work, name, machine, preset, target):
    d = os.path.join(work, name)
    path = os.path.join(work, name + ".json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(machine, f, indent=1)
    r = subprocess.run(["cmake", "--preset", preset, "-B", d, "-DBR_MACHINE=" + path, "-DBR_PYTHON=" + sys.executable],
                       cwd=src, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("configure %s failed:\n%s%s" % (name, r.stdout, r.stderr))
    r = subprocess.run(["cmake", "--build", d, "--target", target], capture_output=True, text=True)
    return r, d


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--src", required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    with open(os.path.join(a.src, "machines", "reference.json"), encoding="utf-8") as f:
        ref = json.load(f)
    fails = []
    pf_only = dict(ref, name="pfonly", control=dict(ref["control"], estimator="pf"))
    r, _ = build(a.src, a.work, "pfonly", pf_only, "cm4-release", "br_image_stm32g4")
    out = r.stdout + r.stderr
    if r.returncode == 0 or "cannot run the PF" not in out:
        fails.append("STM32G474 with control.estimator = pf: expected a refusal naming the PF, got exit %d:\n%s"
                     % (r.returncode, out[-2000:]))
    ukf_first = dict(ref, name="ukffirst", control=dict(ref["control"], estimator="ukf,pf"))
    r, d = build(a.src, a.work, "ukffirst", ukf_first, "cm7-release", "br_image_stm32h7")
    if r.returncode != 0:
        fails.append("STM32H743 with control.estimator = ukf,pf: build failed:\n" + (r.stdout + r.stderr)[-2000:])
    else:
        img = os.path.join(d, "hal", "stm32h7", "br_image_stm32h7.elf")
        # the AXI SRAM also holds the recorder's ring and the USART's buffers:
        # the PF's state is looked for by its symbol
        syms = subprocess.run(["arm-none-eabi-nm", "-S", img], capture_output=True, text=True, check=True).stdout
        pf = [ln for ln in syms.splitlines() if ln.endswith(" br_image_pf")]
        if pf:
            fails.append("the UKF image still holds the PF's state: %s" % pf[0])
    # make firmware's line (firmware/design/image_info.py) says what the images run
    info = os.path.join(a.src, "firmware", "design", "image_info.py")
    r = subprocess.run([sys.executable, info, os.path.join(a.work, "ukffirst.json"), "stm32h7"],
                       capture_output=True, text=True)
    if r.returncode != 0 or "estimator: ukf at 1 ms" not in r.stdout:
        fails.append("image_info.py on the UKF-first file: %r %r" % (r.stdout, r.stderr))
    r = subprocess.run([sys.executable, info, os.path.join(a.work, "pfonly.json"), "stm32g4"],
                       capture_output=True, text=True)
    if r.returncode == 0 or "the stm32g4 image runs ukf, none" not in r.stderr:
        fails.append("image_info.py on the PF-only file for the G474: %r %r" % (r.stdout, r.stderr))
    # the friction transient: the reference's d without a warning; a table 50 times lighter (d 50 times the
    # reference's) warned about
    r = subprocess.run([sys.executable, info, os.path.join(a.src, "machines", "reference.json"), "stm32h7"],
                       capture_output=True, text=True)
    if r.returncode != 0 or "1 times the reference machine's" not in r.stdout or "warning" in r.stdout:
        fails.append("image_info.py on the reference: %r %r" % (r.stdout, r.stderr))
    mech = ref["mechanics"]
    light = dict(ref, name="light", mechanics=dict(mech, table_mass_kg=mech["table_mass_kg"] / 50.0,
                                                    inertia_kgm2=mech["inertia_kgm2"] / 50.0))
    path = os.path.join(a.work, "light.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(light, f, indent=1)
    r = subprocess.run([sys.executable, info, path, "stm32h7"], capture_output=True, text=True)
    if r.returncode != 0 or "50 times the reference machine's" not in r.stdout or "warning: " not in r.stdout:
        fails.append("image_info.py on a 50 times lighter table: %r %r" % (r.stdout, r.stderr))
    for f_ in fails:
        print("FAIL: " + f_, file=sys.stderr)
    print("image estimator: %d failures" % len(fails))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
