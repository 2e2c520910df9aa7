# SPDX-License-Identifier: Apache-2.0
"""Converts a machine file of format 1 (the estimators' settings per step and
in encoder counts) to format 2 (per second, in metres and in the machine's
own friction levels; docs/machine-file.md, "Estimator settings in physical
units"), keeping every setting the firmware receives the same float32.

    python firmware/design/upgrade_machine.py OLD.json NEW.json

Each new value is written with the fewest significant digits that give the
old per-step value's float32 back on this machine (machine.set_est_per_step); the file is checked by the
loader before it is written (through a temporary file and a rename)."""
import argparse
import copy
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import machine  # noqa: E402

# format 1's fields (under estimator.<est>.) and the est_per_step keys they were
V1_FIELDS = {
    "pf": {"q_var.theta_counts2": "q_theta_counts2", "x0_std.theta_counts": "x0_theta_counts",
           "x0_std.omega_rad_per_s": "x0_omega_radps", "x0_std.z_m": "x0_z_m", "x0_std.gp_N": "x0_gp_N",
           "adapt.alpha": "adapt_alpha"},
    "ukf": {"q_var.theta_rad2": "q_theta_rad2", "p0_var.theta_counts2": "p0_theta_counts2",
            "p0_var.omega_rad2_per_s2": "p0_omega_rad2ps2", "p0_var.z_m2": "p0_z_m2", "p0_var.gp_N2": "p0_gp_N2"},
    "both": {"q_var.omega_rad2_per_s2": "q_omega_rad2ps2", "q_var.z_m2": "q_z_m2", "q_var.gp_N2": "q_gp_N2",
             "r_var_counts2": "r_counts2", "gp0_N": "gp0_N", "gp_min_N": "gp_min_N", "gp_max_N": "gp_max_N",
             "delay_id.q_force_N2_per_s": "dlyid_q_force_N2ps"},
}


def _get(d, dotted):
    for k in dotted.split("."):
        if not isinstance(d, dict) or k not in d:
            return None
        d = d[k]
    return d


def _pop(d, dotted):
    ks = dotted.split(".")
    for k in ks[:-1]:
        d = d[k]
    d.pop(ks[-1])


def upgrade(raw):
    """A format-2 dict from a format-1 dict (raises ValueError on a file that cannot be converted)."""
    new = copy.deepcopy(raw)
    new["format_version"] = machine.FORMAT_VERSION
    prov = new.get("provenance", {})
    for est in ("pf", "ukf"):
        e = new["estimator"][est]
        old_vals = {}
        renamed = {}
        for field, key in {**V1_FIELDS[est], **V1_FIELDS["both"]}.items():
            v = _get(raw["estimator"][est], field)
            if v is None:
                if field.startswith("delay_id.") and "delay_id" not in raw["estimator"][est]:
                    continue  # no delay identification
                raise ValueError("field estimator.%s.%s: missing" % (est, field))
            old_vals[key] = float(v)
            _pop(e, field)
            renamed[field] = key
        for sec in ("q_var", "x0_std", "p0_var"):
            if sec in e and not e[sec]:
                del e[sec]
        machine.set_est_per_step(new, est, old_vals)
        for field, key in renamed.items():
            old_p = "estimator.%s.%s" % (est, field)
            if old_p in prov:
                prov["estimator.%s.%s" % (est, machine.PER_STEP_FIELD[key])] = prov.pop(old_p)
    if prov:
        new["provenance"] = dict(sorted(prov.items()))
    return _in_schema_order(new, machine.SCHEMA)


def _in_schema_order(d, schema):
    """d's keys in the schema's order (unknown keys last), recursively: a readable file."""
    if isinstance(schema, machine.Optional):
        schema = schema.section
    if not isinstance(d, dict) or not isinstance(schema, dict):
        return d
    keys = [k for k in schema if k in d] + [k for k in d if k not in schema]
    return {k: _in_schema_order(d[k], schema.get(k)) for k in keys}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old", help="machine file of format 1")
    ap.add_argument("new", help="the format-2 file to write")
    a = ap.parse_args()
    try:
        with open(a.old, "r", encoding="utf-8") as f:
            raw = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        sys.exit("%s: %s" % (a.old, e))
    if not isinstance(raw, dict) or raw.get("format_version") != 1:
        sys.exit("%s: field format_version: not 1 (this converts format 1 only)" % a.old)
    try:
        new = upgrade(raw)
    except (KeyError, TypeError, ValueError, ZeroDivisionError) as e:
        sys.exit("%s: cannot convert: %s" % (a.old, e))
    text = json.dumps(new, indent=2) + "\n"
    machine.write_atomic(a.new, text)
    try:
        machine.load(a.new)
    except machine.MachineError as e:
        os.remove(a.new)
        sys.exit("\n".join(e.lines))
    print("%s -> %s (format %d)" % (a.old, a.new, machine.FORMAT_VERSION))


if __name__ == "__main__":
    main()
