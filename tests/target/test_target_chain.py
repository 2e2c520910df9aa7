# SPDX-License-Identifier: Apache-2.0
"""ctest target_chain (docs/link.md, "The chain on a running target"): the
short version of `make target-chain`, each step the command a user runs:

1. the identification run (one cycle of br_simlog's moves, about 10 s) of
   the production application over the link (br_link_sim, H-inf only, its
   plant with a planted 2.5 N offset the machine file does not know),
   recorded by bristle-link into the measured-log CSV;
2. the diagnosis on it: machine.json names the offset, within 10 % of the
   planted force (the nominal machine file has none);
3. the image in the loop built for that machine.json;
4. 2 s of the circle in the loop (H-inf + UKF) on the same plant with the
   nominal image (bit for bit the simulator's, or target_chain.py exits 1)
   and with the diagnosed one: neither faulted, the diagnosed image's
   contour RMS below the nominal one's.

Usage: test_target_chain.py --sim DIR --pil BR_PIL --image ELF --work DIR"""
import argparse
import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
CHAIN = os.path.join(ROOT, "sim", "studies", "target_chain.py")
OFFSET_N = 2.5     # the planted cause (the test's input)
OFFSET_TOL = 0.10  # relative: detection-limits.md finds offsets of 0.1 N; 10 % of 2.5 N is a wide margin
CIRCLE_S = 2.0


def step(*cmd):
    print("$ " + " ".join(cmd), flush=True)
    r = subprocess.run(cmd, cwd=ROOT, env=dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"),
                                               MPLBACKEND="Agg"))
    if r.returncode != 0:
        sys.exit("FAIL: exit %d: %s" % (r.returncode, " ".join(cmd)))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--sim", required=True, help="the host build's sim/ folder")
    p.add_argument("--pil", required=True)
    p.add_argument("--image", required=True, help="the nominal machine's br_pil_mps2.elf")
    p.add_argument("--work", required=True)
    a = p.parse_args()
    if shutil.which(os.environ.get("BR_QEMU", "qemu-system-arm")) is None:
        sys.exit("FAIL: no qemu-system-arm (make deps installs it)")
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    plant = "offset=%g" % OFFSET_N
    py = sys.executable
    step(py, CHAIN, "ident", "--bin", a.sim, "--work", a.work, "--plant", plant, "--cycles", "1")
    diag = os.path.join(a.work, "diagnose")
    step(py, "-m", "bristle.diagnose", "diagnose", "--log", os.path.join(a.work, "ident.csv"), "--out", diag,
         "--machine", "machines/reference.json", "--no-plots", "-q")
    machine = json.load(open(os.path.join(diag, "machine.json")))
    nominal = json.load(open(os.path.join(ROOT, "machines", "reference.json")))
    ok = True
    found = machine.get("causes", {}).get("offset", {}).get("offset_N")
    print("offset: planted %g N, the nominal machine %s, the diagnosis %s N" %
          (OFFSET_N, nominal.get("causes", {}).get("offset"), found))
    if "offset" in nominal.get("causes", {}) or found is None or abs(found / OFFSET_N - 1) > OFFSET_TOL:
        print("FAIL: the diagnosis did not find the planted offset within %g %%" % (100 * OFFSET_TOL))
        ok = False
    step(py, CHAIN, "image", "--src", ROOT, "--machine", os.path.join(diag, "machine.json"),
         "--dir", os.path.join(a.work, "cm7"))
    after = os.path.join(a.work, "cm7", "target", "mps2", "br_pil_mps2.elf")
    step(py, CHAIN, "circles", "--pil", a.pil, "--before", a.image, "--after", after, "--work",
         os.path.join(a.work, "circle"), "--plant", plant, "--est", "ukf", "--duration", str(CIRCLE_S))
    s = json.load(open(os.path.join(a.work, "circle", "summary.json")))
    b, d = s["before"]["contour_rms_m"], s["after"]["contour_rms_m"]
    print("contour RMS over %g s: nominal image %.3e m, diagnosed image %.3e m" % (CIRCLE_S, b, d))
    if not d < b:
        print("FAIL: the diagnosed machine's image does not track the circle better")
        ok = False
    print("target_chain: " + ("ok" if ok else "FAILED"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
