# SPDX-License-Identifier: Apache-2.0
"""The machine file with the variances `make tune MACHINE=` found for it
(docs/tuning.md, "Another machine"): the given file's copy, its estimator
settings replaced by the tuned ones, in the file's physical units
(machine.set_est_per_step) and marked "derived" in its provenance.

    python firmware/design/tuned_machine.py --machine FILE --pf PF_TUNED.h --ukf UKF_TUNED.h --out OUT.json

The headers are br_tune_est's (sim/apps/br_tune_est.c): per-step variances in
rad units. OUT is written through a temporary file and a rename, then loaded."""
import argparse
import json
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import machine  # noqa: E402

# br_tune_est's names -> est_per_step's keys (R: rad^2 -> counts^2 below)
KEYS = {"q_theta": "q_theta_rad2", "q_omega": "q_omega_rad2ps2", "q_z": "q_z_m2", "q_gp": "q_gp_N2", "r": "r_counts2"}
DEFINE = re.compile(r"#define BR_(PF|UKF)_TUNED_(\w+) \(([-+0-9.eE]+)f\)")


def read_tuned(path, est):
    """The per-step values of a tuned header, by est_per_step's keys (R still in rad^2)."""
    try:
        with open(path, "r", encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise ValueError("%s: cannot read: %s" % (path, e.strerror or e))
    out = {}
    for m in DEFINE.finditer(text):
        if m.group(1) != est.upper() or m.group(2) not in KEYS:
            raise ValueError("%s: %s is not a value of the %s tuning" % (path, m.group(0), est))
        out[KEYS[m.group(2)]] = float(m.group(3))
    want = {KEYS[k] for k in KEYS if est == "ukf" or k != "q_theta"}
    if set(out) != want:
        raise ValueError("%s: expected %s, found %s" % (path, sorted(want), sorted(out)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--machine", required=True)
    ap.add_argument("--pf", required=True, help="br_pf_tuned.h of the tuning")
    ap.add_argument("--ukf", required=True, help="br_ukf_tuned.h of the tuning")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    m = machine.load_or_exit(a.machine)
    with open(a.machine, "r", encoding="utf-8") as f:
        raw = json.load(f)
    rpc2 = machine.params(m)["rad_per_count"] ** 2
    prov = raw.setdefault("provenance", {})
    try:
        for est, path in (("pf", a.pf), ("ukf", a.ukf)):
            vals = read_tuned(path, est)
            vals["r_counts2"] /= rpc2
            for field in machine.set_est_per_step(raw, est, vals):
                prov[field] = "derived"
    except ValueError as e:
        sys.exit("tuned_machine.py: %s" % e)
    raw["provenance"] = dict(sorted(prov.items()))
    note = "; estimator noise variances tuned by make tune MACHINE= (docs/tuning.md, \"Another machine\")"
    if note not in raw.get("source", ""):
        raw["source"] = raw.get("source", "") + note
    machine.write_atomic(a.out, json.dumps(raw, indent=2) + "\n")
    machine.load_or_exit(a.out)
    print("wrote %s: %s with the tuned estimator settings; build its image with: make firmware MACHINE=%s"
          % (a.out, machine.display_name(a.machine), a.out))


if __name__ == "__main__":
    main()
